"""Hostile review of the checker's adjacency / normal-fan path (issue 13 §4): forged
safe-kernel certificates must never be valid, rescon's own must never be invalid.

The forgeries are built here in exact rationals, independently of rescon; the truth of
a claim "v ∈ Ψ(X, F)" is decided by brute force (Carathéodory + hitting sets)."""

from __future__ import annotations

import copy
from fractions import Fraction

import numpy as np
import pytest
from conftest import solve_exact
from hypothesis import given, settings
from hypothesis import strategies as st
from rescon_certificates.check import check

import rescon


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _sub(a, b):
    return [x - y for x, y in zip(a, b)]


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _mat(A, x):
    return [_dot(row, x) for row in A]


def _forged_pyramid(F: int, A: list[list[int]]) -> dict:
    """P = the pyramid over an octagon with apex v = (0, 0, 1), mapped by x -> A x.

    Each base corner is a data point F + 1 times (depth >= F + 1) and F points sit just
    outside the middle of each side facet: every facet has <= F points strictly outside,
    but nothing lies above v, so the halfspace {z >= 1} holds no point: v has depth 0 and
    the claim Ψ = P is false.  A is chosen so that the axis depth test does not see it."""
    base = [(3, 0), (2, 2), (0, 3), (-2, 2), (-3, 0), (-2, -2), (0, -3), (2, -2)]
    B = [[Fraction(x), Fraction(y), Fraction(0)] for x, y in base]
    v = [Fraction(0), Fraction(0), Fraction(1)]
    m = len(B)
    facets = [([0, 0, -1], 0)]
    points = [b for b in B for _ in range(F + 1)]
    for k in range(m):
        b1, b2 = B[k], B[(k + 1) % m]
        a = _cross(_sub(b1, v), _sub(b2, v))
        if a[2] < 0:
            a = [-t for t in a]
        facets.append((a, _dot(a, v)))
        centre = [(x + y + z) / 3 for x, y, z in zip(b1, b2, v)]
        points += [[c + t / 50 for c, t in zip(centre, a)]] * F
    V = B + [v]
    adj = [[(k - 1) % m, (k + 1) % m, m] for k in range(m)] + [list(range(m))]
    # x -> A x maps a·x <= b to (a A^-1)·x <= b; with the adjugate: (a adj(A))·x <= b det(A)
    cols = [[row[j] for row in A] for j in range(3)]
    adjA = [_cross(cols[(i + 1) % 3], cols[(i + 2) % 3]) for i in range(3)]  # rows of adj(A)
    det = _dot(cols[0], _cross(cols[1], cols[2]))
    s = 1 if det > 0 else -1

    def q(t):
        return str(Fraction(t))

    return {"rescon_certificate": 1, "kind": "safe_kernel", "F": F, "dim": 3,
            "points": [[q(t) for t in _mat(A, p)] for p in points],
            "vertices": [[q(t) for t in _mat(A, x)] for x in V],
            "equalities": [],
            "facets": [{"a": [q(s * t) for t in [_dot(a, [adjA[i][j] for i in range(3)])
                                                 for j in range(3)]],
                        "b": q(s * b * det)} for a, b in facets],
            "adjacency": adj, "proof": {"method": "halfspaces"}}


def test_zero_facet_does_not_blind_the_normal_fan():
    """A facet 0·x <= 0 (valid, tight everywhere) listed first made the d = 3 normal fan
    sweep a degenerate arc (both ends the zero vector) and call the depth-0 apex of this
    pyramid a kernel vertex: the false certificate was 'valid'."""
    for F, A in ((1, [[2, 0, -2], [0, -2, -2], [0, 1, -2]]),
                 (2, [[-3, 2, 3], [-2, -2, -2], [3, 1, 0]])):
        cert = _forged_pyramid(F, A)
        res = check(cert)
        assert res.verdict == "invalid" and "Tukey depth is at most 0" in res.reason, res.reason
        cert["facets"].insert(0, {"a": [0, 0, 0], "b": 0})
        res = check(cert)
        assert res.verdict == "invalid" and "Tukey depth is at most 0" in res.reason, res.reason


def in_kernel(X, F, v) -> bool:
    """v ∈ Ψ(X, F) by brute force: the simplices of data points holding v
    (Carathéodory); v is in every conv(S), |S| = n − F, iff no F indices hit them all."""
    from itertools import combinations

    n, d = len(X), len(v)
    hits = []
    for k in range(1, d + 2):
        for T in combinations(range(n), k):
            lam = solve_exact([[X[i][j] for i in T] for j in range(d)] + [[1] * k], list(v) + [1])
            if lam is not None and min(lam) >= 0:
                hits.append(set(T))
    return bool(hits) and not any(all(h & set(R) for h in hits)
                                  for R in combinations(range(n), F))


def _mutations(c: dict):
    """False or unproved variants of a true certificate: enlarged / shrunk about the
    vertex mean, the claim for F + 1, a facet or a vertex dropped, a vertex moved to the
    middle of an edge, a zero facet, the adjacency rotated."""
    V = [[Fraction(t) for t in v] for v in c["vertices"]]
    d = len(V[0])
    mean = [sum(v[j] for v in V) / len(V) for j in range(d)]
    for f in (Fraction(1001, 1000), Fraction(999, 1000)):
        m = copy.deepcopy(c)
        m["vertices"] = [[str(mean[j] + f * (v[j] - mean[j])) for j in range(d)] for v in V]
        for h in m["facets"]:
            am = sum(Fraction(a) * x for a, x in zip(h["a"], mean))
            h["b"] = str(am + f * (Fraction(h["b"]) - am))
        yield m
    yield {**copy.deepcopy(c), "F": c["F"] + 1}
    if c["facets"]:
        yield {**copy.deepcopy(c), "facets": c["facets"][1:]}
    yield {**copy.deepcopy(c), "facets": [{"a": [0] * d, "b": 0}] + c["facets"]}
    if len(V) > 1:
        m = copy.deepcopy(c)
        m["vertices"].pop()
        m["adjacency"] = [[j for j in a if j != len(V) - 1] for a in m["adjacency"][:-1]]
        yield m
        j = c["adjacency"][0][0]
        m = copy.deepcopy(c)
        m["vertices"][0] = [str((a + b) / 2) for a, b in zip(V[0], V[j])]
        yield m
        yield {**copy.deepcopy(c), "adjacency": c["adjacency"][1:] + c["adjacency"][:1]}


@pytest.mark.slow
@settings(max_examples=12, deadline=None)
@given(seed=st.integers(0, 10**6), d=st.sampled_from([2, 3]),
       kind=st.sampled_from(["gauss", "int", "dup", "flat"]))
def test_checker_verdicts_agree_with_brute_force(seed, d, kind):
    """rescon's certificates are valid; a mutated one is valid only if its claim is true
    (every vertex in Ψ by brute force, and the vertices are Ψ's exact vertices)."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(d + 2, 10 if d == 3 else 12))
    if kind == "gauss":
        X = rng.standard_normal((n, d))
    elif kind == "int":
        X = rng.integers(-3, 4, (n, d)).astype(float)
    elif kind == "dup":
        X = rng.integers(-2, 3, (n, d)).astype(float)
        X[n // 2:] = X[: n - n // 2]
    else:
        Y = rng.integers(-3, 4, (n, d - 1)).astype(float)
        X = np.c_[Y, Y @ rng.integers(-2, 3, d - 1)]
    F = int(rng.integers(0, n // (d + 1) + 1))
    K = rescon.safe_kernel(X, F)
    if K.is_empty:
        return
    c = K.certificate
    assert check(c).verdict == "valid"
    Xq = [[Fraction(t) for t in p] for p in X]
    for m in _mutations(c):
        if check(m).verdict != "valid":
            continue
        Km = rescon.safe_kernel(X, m["F"])
        V = [tuple(Fraction(t) for t in v) for v in m["vertices"]]
        assert set(V) == set(Km.exact_vertices)
        assert all(in_kernel(Xq, m["F"], v) for v in V)
