"""Safe-kernel certificates checked at the speed they are made (issue 13 §4).

A ``safe_kernel`` certificate carries the vertex adjacency, which proves P = conv(V)
without enumerating C(m, d) facet subsets, and for full-dimensional kernels in d = 2, 3
the checker proves V ⊆ Ψ by the normal fan of P instead of enumerating the C(n, d)
hyperplanes through data points. Old certificates (no adjacency) are checked as before.
"""

from __future__ import annotations

import copy
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rescon_certificates.check import check

import rescon


def _kernel(seed: int, n: int, d: int, F: int, sphere: bool = False) -> rescon.SafeKernel:
    X = np.random.default_rng(seed).standard_normal((n, d))
    if sphere:
        X /= np.linalg.norm(X, axis=1, keepdims=True)
    return rescon.safe_kernel(X, F)


@pytest.fixture(scope="module")
def cube3():
    """A d = 3 kernel with a few dozen vertices (its certificate, copied per test)."""
    return _kernel(3, 20, 3, 2).certificate


@pytest.mark.parametrize(("n", "d", "F", "sphere"), [(1000, 2, 100, False), (100, 3, 10, False),
                                                    (100, 3, 20, True)])
def test_large_kernels_are_verified(n, d, F, sphere):
    """Before: 'unchecked' (C(n, d) hyperplanes and C(m, d) facet subsets beyond the work
    limits); now valid by the adjacency and the normal fan."""
    K = _kernel(n + d, n, d, F, sphere)
    assert K.dim == d
    res = check(K.certificate)
    assert res.verdict == "valid", (res.reason, res.unchecked)
    assert "normal fan" in res.reason


def test_old_certificates_are_checked_as_before(cube3):
    """Without 'adjacency' the vertex enumeration runs (valid while within its work limit,
    unchecked beyond it: never invalid)."""
    old = {k: v for k, v in cube3.items() if k != "adjacency"}
    assert check(old).verdict == "valid"
    big = _kernel(5, 50, 3, 5).certificate
    assert check(big).verdict == "valid"
    del big["adjacency"]
    res = check(big)
    assert res.verdict == "unchecked" and "vertex enumeration" in res.trusted


def _neighbours(c: dict, i: int) -> tuple[list[int], int]:
    """(adjacency[i], a vertex index that is neither i nor one of its neighbours)."""
    adj = c["adjacency"][i]
    other = next(j for j in range(len(c["vertices"])) if j != i and j not in adj)
    return adj, other


def _forge(c):
    adj, other = _neighbours(c, 0)
    adj[0] = other


def _drop_neighbour(c):
    c["adjacency"][0].pop()


def _extra_neighbour(c):
    adj, other = _neighbours(c, 0)
    adj.append(other)


def _twice(c):
    c["adjacency"][0].append(c["adjacency"][0][0])


def _drop_facet(c):
    c["facets"].pop(0)


def _move_vertex(c):
    c["vertices"][0] = [str(Fraction(t) + Fraction(1, 10**9)) for t in c["vertices"][0]]


def _wrong_incidence(c):
    """Tilt a facet through vertex 0 so that it is no longer tight there (every vertex
    still satisfies it): the incidence at vertex 0 changes."""
    i = next(j for j, h in enumerate(c["facets"])
             if sum(Fraction(a) * Fraction(x) for a, x in zip(h["a"], c["vertices"][0]))
             == Fraction(h["b"]))
    c["facets"][i]["b"] = str(Fraction(c["facets"][i]["b"]) + Fraction(1, 10**6))


TAMPER = {
    "forged adjacency": (_forge, "is not joined to vertices[0] by an edge of P"),
    "dropped neighbour": (_drop_neighbour, "no vertex listed along the edge of P"),
    "extra neighbour": (_extra_neighbour, "is not joined to vertices[0] by an edge of P"),
    "neighbour twice": (_twice, "along the same edge of P"),
    "short adjacency": (lambda c: c["adjacency"].pop(), "expected one per vertex"),
    "neighbour out of range": (lambda c: c["adjacency"][0].append(len(c["vertices"])),
                               "adjacency[0]"),
    "adjacency not a list": (lambda c: c.__setitem__("adjacency", {}), "adjacency"),
    "dropped facet": (_drop_facet, ""),
    "moved vertex": (_move_vertex, "vertices[0]"),
    "wrong incidence": (_wrong_incidence, "vertices[0]"),
}


@pytest.mark.parametrize("name", sorted(TAMPER))
def test_tampered_adjacency_certificates_are_rejected(cube3, name):
    f, needle = TAMPER[name]
    c = copy.deepcopy(cube3)
    assert check(c).valid
    f(c)
    res = check(c)
    assert res.verdict == "invalid", (name, res.verdict, res.reason)
    assert needle in res.reason, res.reason


def _scaled_claim(K: rescon.SafeKernel, factor: Fraction) -> dict:
    """K's certificate with P scaled by ``factor`` about the (float) mean of its vertices
    (the adjacency stays right; the claim is false for factor ≠ 1)."""
    V = K.exact_vertices
    d = len(V[0])
    c0 = [Fraction(t) for t in K.vertices.mean(axis=0)]
    cert = copy.deepcopy(K.certificate)
    cert["vertices"] = [[str(c0[j] + factor * (v[j] - c0[j])) for j in range(d)] for v in V]
    for h in cert["facets"]:
        ac = sum(Fraction(a) * x for a, x in zip(h["a"], c0))
        h["b"] = str(ac + factor * (Fraction(h["b"]) - ac))
    return cert


def test_enlarged_kernel_is_refuted_by_the_normal_fan():
    """Facets moved out by 1e-6 keep at most F points outside (no data point in between),
    so only the vertex test can refute the claim."""
    K = _kernel(7, 60, 3, 6)
    res = check(_scaled_claim(K, 1 + Fraction(1, 10**6)))
    assert res.verdict == "invalid" and "Tukey depth is at most" in res.reason, res.reason


@settings(max_examples=25, deadline=None)
@given(d=st.sampled_from([2, 3]), seed=st.integers(0, 10**6), integer=st.booleans())
def test_normal_fan_agrees_with_the_exact_kernel(d, seed, integer):
    """Correct certificates are valid; Ψ(X, F − 1) claimed as Ψ(X, F) is valid iff the
    two kernels are equal (decided by the exact kernel); an enlarged kernel is never
    valid."""
    rng = np.random.default_rng(seed)
    n = int(rng.integers(d + 3, 10 if d == 3 else 16))
    X = rng.integers(-3, 4, (n, d)).astype(float) if integer else rng.standard_normal((n, d))
    F = int(rng.integers(1, max(2, n // (d + 1))))
    big, small = rescon.safe_kernel(X, F - 1), rescon.safe_kernel(X, F)
    for K in (big, small):
        if not K.is_empty:
            assert check(K.certificate).verdict == "valid"
    if big.dim == d and not small.is_empty:
        claim = copy.deepcopy(big.certificate)
        claim["F"] = F
        inside = all(small._exact.contains(v) for v in big.exact_vertices)
        assert (check(claim).verdict == "valid") == inside
        assert check(_scaled_claim(big, Fraction(1001, 1000))).verdict == "invalid"


def test_normal_fan_work_is_bounded_before_it_is_spent(cube3, monkeypatch):
    """Beyond the work limit the vertex test is unchecked without sweeping any circle:
    the K² sweeps of a vertex are charged before they run (an adversary's n = 10^5
    points crossing one normal cone would otherwise cost 10^10 steps)."""
    from rescon_certificates import kernels

    calls = []
    real = kernels._arc_min
    monkeypatch.setattr(kernels, "_arc_min", lambda pairs: calls.append(1) or real(pairs))
    n, d = len(cube3["points"]), 3
    monkeypatch.setattr(kernels, "MAX_EVAL_WORK", len(cube3["vertices"]) * n * (d + 2))
    res = check(copy.deepcopy(cube3))
    assert res.verdict == "unchecked" and res.trusted == ("halfspaces",), res.unchecked
    assert calls == []


@pytest.mark.parametrize(("n", "d", "F"), [(1000, 2, 100), (100, 3, 10)])
def test_large_kernel_points_are_verified(n, d, F):
    """A kernel point's certificate carries the kernel ("kernel" proof); before, the
    checker enumerated C(n, d) hyperplanes and answered 'unchecked' at these sizes."""
    X = np.random.default_rng(n).standard_normal((n, d))
    _, cert = rescon.kernel_point(X, F)
    assert cert["proof"]["method"] == "kernel"
    res = check(cert)
    assert res.verdict == "valid", (res.reason, res.unchecked)


def _point_outside(c):
    """x moved along the normal of a facet it is not on, just past it (so outside Ψ = P)."""
    x = [Fraction(t) for t in c["x"]]
    for h in c["proof"]["facets"]:
        a = [Fraction(t) for t in h["a"]]
        step = (Fraction(h["b"]) - sum(s * t for s, t in zip(a, x))) / sum(t * t for t in a)
        if step > 0:
            c["x"] = [str(t + step * (1 + Fraction(1, 10**6)) * s) for t, s in zip(x, a)]
            return


POINT_TAMPER = {
    "x outside the kernel": (_point_outside, "is not in the kernel: it violates proof.facets["),
    "kernel of F - 1": (lambda c: c.__setitem__("F", c["F"] + 1), "proof: "),
    "forged adjacency": (lambda c: _forge(c["proof"]), "proof: adjacency[0] lists"),
    "moved vertex": (lambda c: _move_vertex(c["proof"]), "proof: vertices[0]"),
    "missing adjacency": (lambda c: c["proof"].pop("adjacency"), "missing key 'adjacency'"),
}


@pytest.mark.parametrize("name", sorted(POINT_TAMPER))
def test_tampered_kernel_point_proofs_are_rejected(name):
    X = np.random.default_rng(11).standard_normal((24, 3))
    _, cert = rescon.kernel_point(X, 2)
    assert check(cert).valid
    f, needle = POINT_TAMPER[name]
    f(cert)
    res = check(cert)
    assert res.verdict == "invalid" and needle in res.reason, (name, res.reason)


@pytest.mark.slow
def test_d4_kernel_points_carry_the_kernel():
    """In d = 4 the checker's normal fan makes the "kernel" proof checkable; before, a
    kernel point of n = 40 points carried the (b) proof, whose C(40, 4) hyperplanes are
    beyond the checker's enumeration limit ('unchecked')."""
    X = np.random.default_rng(40).standard_normal((40, 4))
    _, cert = rescon.kernel_point(X, 1)
    assert cert["proof"]["method"] == "kernel"
    res = check(cert)
    assert res.verdict == "valid", (res.reason, res.unchecked)
