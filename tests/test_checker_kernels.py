"""Tests of the safe-kernel certificate kinds of the standalone checker
(certificates/kernels.py, registered in certificates/check.py).

Psi(X, F) = intersection of conv(S) over the S ⊆ X with |S| = n - F.  The oracle here
decides "x ∈ conv(S)" exactly (phase-1 simplex over Fractions, Bland's rule) for every
S, independently of the checker's halfspace characterisation; an independent generator
(nullspaces by Fraction RREF) builds safe_kernel / kernel_empty certificates and the
oracle confirms them.  Tampered certificates must be rejected with a reason.
"""

from __future__ import annotations

import ast
import copy
import importlib.util
import json
import math
import random
import subprocess
import sys
import time
from fractions import Fraction
from itertools import combinations
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CERT_DIR = ROOT / "certificates"
CHECK_PY = CERT_DIR / "check.py"
KERNELS_PY = CERT_DIR / "kernels.py"
SCHEMA = CERT_DIR / "schema" / "certificate.schema.json"
EXAMPLES = sorted((CERT_DIR / "examples").glob("*.json"))
KERNEL_KINDS = {"kernel_point", "kernel_empty", "safe_kernel"}


def _load_checker():
    """The checker file of this repository (not whatever copy may be installed)."""
    name = "_rescon_certificates_check_kernels_under_test"
    spec = importlib.util.spec_from_file_location(name, CHECK_PY)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


C = _load_checker()
check = C.check
K = sys.modules["_rescon_certificates_check_kernels_under_test_kernels"]


# --------------------------------------------------------------------------- #
# exact oracle: x ∈ conv(S) by a phase-1 simplex, Psi by all (n - F)-subsets
# --------------------------------------------------------------------------- #


def hull_weights(pts, x):
    """Weights lam >= 0, sum 1, sum lam_i p_i = x (exact Fractions), or None."""
    n, d = len(pts), len(x)
    rows = [[Fraction(p[j]) for p in pts] + [Fraction(x[j])] for j in range(d)]
    rows.append([Fraction(1)] * n + [Fraction(1)])
    rows = [[-t for t in r] if r[-1] < 0 else r for r in rows]
    m = len(rows)
    T = [r[:n] + [Fraction(int(i == k)) for k in range(m)] + [r[-1]] for i, r in enumerate(rows)]
    basis = [n + i for i in range(m)]
    obj = [-sum(T[i][j] for i in range(m)) for j in range(n)] + [Fraction(0)] * m
    obj.append(-sum(T[i][-1] for i in range(m)))
    while True:
        enter = next((j for j in range(n + m) if obj[j] < 0), None)
        if enter is None:
            break
        best = None
        for i in range(m):
            if T[i][enter] > 0:
                ratio = T[i][-1] / T[i][enter]
                if best is None or ratio < best[0] or (ratio == best[0] and
                                                       basis[i] < basis[best[1]]):
                    best = (ratio, i)
        r = best[1]  # phase 1 is bounded below by 0
        piv = T[r][enter]
        T[r] = [t / piv for t in T[r]]
        for i in range(m):
            if i != r and T[i][enter]:
                f = T[i][enter]
                T[i] = [a - f * b for a, b in zip(T[i], T[r])]
        f = obj[enter]
        obj = [a - f * b for a, b in zip(obj, T[r])]
        basis[r] = enter
    if obj[-1] != 0:
        return None
    lam = [Fraction(0)] * n
    for i, j in enumerate(basis):
        if j < n:
            lam[j] = T[i][-1]
    assert sum(lam) == 1 and all(t >= 0 for t in lam)
    assert all(sum(w * Fraction(p[j]) for w, p in zip(lam, pts)) == Fraction(x[j])
               for j in range(d))
    return lam


def in_kernel_brute(pts, F, x) -> bool:
    n = len(pts)
    return all(hull_weights([pts[i] for i in S], x) is not None
               for S in combinations(range(n), n - F))


def tverberg_parts(pts, F, x):
    """F + 1 disjoint index groups with x in each hull (exact weights), or None."""
    n = len(pts)
    good = {}
    for mask in range(1, 1 << n):
        idx = [i for i in range(n) if mask >> i & 1]
        lam = hull_weights([pts[i] for i in idx], x)
        if lam is not None:
            good[mask] = (idx, lam)

    def search(used, need):
        if need == 0:
            return []
        for mask, part in good.items():
            if not mask & used:
                rest = search(used | mask, need - 1)
                if rest is not None:
                    return [part] + rest
        return None

    found = search(0, F + 1)
    if found is None:
        return None
    return [{"indices": idx, "weights": [str(w) for w in lam]} for idx, lam in found]


# --------------------------------------------------------------------------- #
# independent generator of kernel descriptions (Fraction RREF)
# --------------------------------------------------------------------------- #


def rref(M, ncols):
    A = [[Fraction(t) for t in r] for r in M]
    piv = []
    r = 0
    for c in range(ncols):
        p = next((i for i in range(r, len(A)) if A[i][c]), None)
        if p is None:
            continue
        A[r], A[p] = A[p], A[r]
        A[r] = [t / A[r][c] for t in A[r]]
        for i in range(len(A)):
            if i != r and A[i][c]:
                f = A[i][c]
                A[i] = [a - f * b for a, b in zip(A[i], A[r])]
        piv.append(c)
        r += 1
    return A[:r], piv


def nullspace(M, ncols):
    R, piv = rref(M, ncols) if M else ([], [])
    free = [c for c in range(ncols) if c not in piv]
    out = []
    for f in free:
        v = [Fraction(0)] * ncols
        v[f] = Fraction(1)
        for row, c in zip(R, piv):
            v[c] = -row[f]
        out.append(v)
    return out


def dot(a, b):
    return sum(Fraction(x) * Fraction(y) for x, y in zip(a, b))


def primitive(a, b):
    """Scale (a, b) to coprime integers (positive factor): a canonical key."""
    vals = list(a) + [b]
    den = math.lcm(*[Fraction(t).denominator for t in vals])
    ints = [int(Fraction(t) * den) for t in vals]
    g = math.gcd(*ints) or 1
    ints = [t // g for t in ints]
    return tuple(ints[:-1]), ints[-1]


def describe(pts, F):
    """(equalities, facets, vertices) of Psi by theorem (b), built independently."""
    d = len(pts[0])
    p0 = pts[0]
    diffs = [[Fraction(p[j]) - Fraction(p0[j]) for j in range(d)] for p in pts[1:]]
    comp = nullspace(diffs, d) if diffs else nullspace([[0] * d], d)
    equalities = [primitive(e, dot(e, p0)) for e in comp]
    k = d - len(comp)
    distinct = sorted({tuple(Fraction(t) for t in p) for p in pts})
    facets = set()
    for S in combinations(distinct, k):
        rows = [list(e) for e in comp] + [[a - b for a, b in zip(q, S[0])] for q in S[1:]]
        ns = nullspace(rows, d)
        if len(ns) != 1:
            continue
        a = ns[0]
        b = dot(a, S[0])
        plus = sum(1 for p in pts if dot(a, p) > b)
        minus = sum(1 for p in pts if dot(a, p) < b)
        if plus <= F:
            facets.add(primitive(a, b))
        if minus <= F:
            facets.add(primitive([-t for t in a], -b))
    facets = sorted(facets)
    verts = set()
    for S in combinations(facets, k):
        rows = [list(a) + [b] for a, b in equalities] + [list(a) + [b] for a, b in S]
        R, piv = rref(rows, d + 1)
        if piv != list(range(d)):
            continue  # singular (or inconsistent)
        v = tuple(R[j][d] for j in range(d))
        if all(dot(a, v) <= b for a, b in facets) and all(dot(a, v) == b for a, b in equalities):
            verts.add(v)
    return equalities, facets, sorted(verts)


def aff_dim(vs):
    if len(vs) <= 1:
        return 0
    return len(rref([[a - b for a, b in zip(v, vs[0])] for v in vs[1:]], len(vs[0]))[1])


def farkas(equalities, facets, d):
    """Multipliers proving {equalities, facets} infeasible (a minimal subsystem)."""
    for size in range(1, d + 2):
        for T in combinations(facets, size):
            cols = [a for a, _ in T] + [a for a, _ in equalities]
            M = [[col[j] for col in cols] for j in range(d)]
            ns = nullspace(M, len(cols))
            if len(ns) != 1:
                continue
            z = ns[0]
            if all(t <= 0 for t in z[:size]):
                z = [-t for t in z]
            if not all(t >= 0 for t in z[:size]):
                continue
            rhs = sum(t * b for t, (_, b) in zip(z, list(T) + list(equalities)))
            if rhs < 0:
                return list(T), z[:size], z[size:]
    return None


def jnum(t):
    t = Fraction(t)
    return int(t) if t.denominator == 1 else str(t)


def jvec(v):
    return [jnum(t) for t in v]


def jcons(cons):
    return [{"a": jvec(a), "b": jnum(b)} for a, b in cons]


def kernel_cert(pts, F, proof=None):
    """A safe_kernel certificate (or kernel_empty when Psi = ∅) built by describe()."""
    d = len(pts[0])
    eqs, facets, verts = describe(pts, F)
    base = {"rescon_certificate": 1, "points": [jvec(p) for p in pts], "F": F}
    if not verts:
        T, lam, mu = farkas(eqs, facets, d)
        return dict(base, kind="kernel_empty", halfspaces=jcons(T), multipliers=jvec(lam),
                    equalities=jcons(eqs), eq_multipliers=jvec(mu))
    return dict(base, kind="safe_kernel", dim=aff_dim(verts), vertices=[jvec(v) for v in verts],
                equalities=jcons(eqs), facets=jcons(facets),
                proof=proof or {"method": "halfspaces"})


def point_cert(pts, F, x, proof=None):
    return {"rescon_certificate": 1, "kind": "kernel_point", "points": [jvec(p) for p in pts],
            "F": F, "x": jvec(x), "proof": proof or {"method": "halfspaces"}}


# --------------------------------------------------------------------------- #
# random point sets with many ties
# --------------------------------------------------------------------------- #


def random_points(rng, d, n):
    kind = rng.random()
    if kind < 0.25 and d >= 2:  # on a line
        base = [rng.randint(-2, 2) for _ in range(d)]
        step = [rng.randint(-2, 2) for _ in range(d)]
        return [tuple(b + t * s for b, s in zip(base, step))
                for t in (rng.randint(-2, 2) for _ in range(n))]
    if kind < 0.4 and d == 3:  # on a plane
        u, v = [rng.randint(-1, 1) for _ in range(3)], [rng.randint(-1, 1) for _ in range(3)]
        return [tuple(s * a + t * b for a, b in zip(u, v))
                for s, t in ((rng.randint(-2, 2), rng.randint(-2, 2)) for _ in range(n))]
    hi = {1: 4, 2: 3, 3: 2}[d]
    pts = [tuple(rng.randint(0, hi) for _ in range(d)) for _ in range(n)]
    if rng.random() < 0.3:  # duplicates
        pts[-1] = pts[0]
    return pts


def probe_points(rng, pts, verts):
    """Data points, midpoints, centroids, kernel vertices and random rational points."""
    d = len(pts[0])
    cand = {tuple(Fraction(t) for t in p) for p in pts}
    for p, q in combinations(pts, 2):
        cand.add(tuple(Fraction(a + b, 2) for a, b in zip(p, q)))
    cand.add(tuple(Fraction(sum(p[j] for p in pts), len(pts)) for j in range(d)))
    cand.update(verts)
    for v in verts:  # just next to a vertex
        cand.add(tuple(t + Fraction(rng.choice([-1, 1]), 97) * (j == 0)
                       for j, t in enumerate(v)))
    cand = sorted(cand)
    rng.shuffle(cand)
    return cand[:14]


# --------------------------------------------------------------------------- #
# the checker's characterisation (b) against the oracle
# --------------------------------------------------------------------------- #


def test_halfspaces_agree_with_brute_force():
    rng = random.Random(2024)
    counts = {True: 0, False: 0}
    for trial in range(240):
        d = (1, 2, 2, 3)[trial % 4]
        n = rng.randint(1, 7 if d < 3 else 6)
        pts = random_points(rng, d, n)
        F = rng.randrange(n)
        _, _, verts = describe(pts, F)
        for x in probe_points(rng, pts, verts):
            expect = in_kernel_brute(pts, F, x)
            res = check(point_cert(pts, F, x))
            assert res.valid == expect, (pts, F, x, res.reason)
            assert res.trusted == ()
            if not expect:
                assert "not in the safe kernel" in res.reason
            counts[expect] += 1
    assert counts[True] > 400 and counts[False] > 400, counts


def test_halfspaces_agree_with_brute_force_in_higher_dimensions():
    """d = 4, 5: normals by cofactor determinants (Bareiss) instead of closed forms."""
    rng = random.Random(3)
    counts = {True: 0, False: 0}
    for trial in range(40):
        d = rng.choice([4, 5])
        n = rng.randint(d + 1, d + 3)
        pts = [tuple(rng.randint(0, 2) for _ in range(d)) for _ in range(n)]
        if trial % 4 == 0:  # inside a 3-flat of R^d
            pts = [p[:3] + (p[0] - p[1],) * (d - 3) for p in pts]
        F = rng.randrange(min(n, 3))
        for x in probe_points(rng, pts, [])[:8]:
            expect = in_kernel_brute(pts, F, x)
            res = check(point_cert(pts, F, x))
            assert res.valid == expect, (pts, F, x, res.reason)
            counts[expect] += 1
    assert counts[True] > 40 and counts[False] > 40, counts


def test_generated_certificates_are_valid_and_agree_with_oracle():
    rng = random.Random(7)
    seen = set()
    for trial in range(80):
        d = (1, 2, 2, 3)[trial % 4]
        n = rng.randint(1, 6 if d < 3 else 5)
        pts = random_points(rng, d, n)
        F = rng.randrange(n)
        cert = kernel_cert(pts, F)
        res = check(cert)
        assert res.valid, (pts, F, res.reason)
        seen.add((cert["kind"], cert.get("dim")))
        if cert["kind"] == "safe_kernel":
            verts = [tuple(Fraction(t) for t in v) for v in cert["vertices"]]
            for v in verts:  # the generator is right: its vertices are in Psi
                assert in_kernel_brute(pts, F, v)
            eqs, facets, _ = describe(pts, F)
            for x in probe_points(rng, pts, verts):  # and Psi = P
                inside = all(dot(a, x) <= b for a, b in facets) and \
                    all(dot(a, x) == b for a, b in eqs)
                assert inside == in_kernel_brute(pts, F, x), (pts, F, x)
            assert "safe kernel = conv of" in res.reason
            # tampering: a vertex dropped, moved, or an extra point listed
            if len(verts) > 1:
                bad = copy.deepcopy(cert)
                del bad["vertices"][rng.randrange(len(verts))]
                assert not check(bad).valid
            bad = copy.deepcopy(cert)
            i = rng.randrange(len(verts))
            bad["vertices"][i] = jvec([t + Fraction(rng.choice([-1, 1]), 101) * (j == 0)
                                       for j, t in enumerate(verts[i])])
            assert not check(bad).valid
            bad = copy.deepcopy(cert)
            bad["vertices"].append(jvec([sum(t) / len(verts) + Fraction(1, 7) * (j == 0)
                                         for j, t in enumerate(zip(*verts))]))
            assert not check(bad).valid
        else:
            for x in probe_points(rng, pts, []):
                assert not in_kernel_brute(pts, F, x)
            assert "empty" in res.reason
    kinds = {k for k, _ in seen}
    dims = {dm for k, dm in seen if k == "safe_kernel"}
    assert kinds == {"safe_kernel", "kernel_empty"} and {0, 1, 2} <= dims, seen


def test_tverberg_partitions_found_by_search_are_accepted():
    rng = random.Random(11)
    found = 0
    for trial in range(40):
        d = (1, 2)[trial % 2]
        n = rng.randint(3, 6)
        pts = random_points(rng, d, n)
        F = rng.randrange(min(n, 3))
        _, _, verts = describe(pts, F)
        for x in verts[:2]:
            parts = tverberg_parts(pts, F, x)
            if parts is None:
                continue
            found += 1
            res = check(point_cert(pts, F, x, {"method": "tverberg", "parts": parts}))
            assert res.valid and "tverberg" in res.reason, res.reason
            assert check(point_cert(pts, F, x)).valid
    assert found >= 15, found


# --------------------------------------------------------------------------- #
# hand-made certificates, including degenerate point sets
# --------------------------------------------------------------------------- #

SQUARE = [[0, 0], [1, 0], [0, 1], [1, 1]]
DIAGONALS = [{"indices": [0, 3], "weights": ["1/2", "1/2"]},
             {"indices": [1, 2], "weights": ["1/2", "1/2"]}]


def square_kernel():
    return {"rescon_certificate": 1, "kind": "safe_kernel", "points": copy.deepcopy(SQUARE),
            "F": 1, "dim": 0, "vertices": [["1/2", "1/2"]], "equalities": [],
            "facets": [{"a": [1, 1], "b": 1}, {"a": [-1, -1], "b": -1},
                       {"a": [1, -1], "b": 0}, {"a": [-1, 1], "b": 0}],
            "proof": {"method": "halfspaces"}}


def square_point():
    return {"rescon_certificate": 1, "kind": "kernel_point", "points": copy.deepcopy(SQUARE),
            "F": 1, "x": ["1/2", 0.5],
            "proof": {"method": "tverberg", "parts": copy.deepcopy(DIAGONALS)}}


def triangle_empty():
    return {"rescon_certificate": 1, "kind": "kernel_empty", "points": [[0, 0], [1, 0], [0, 1]],
            "F": 1, "halfspaces": [{"a": [0, 1], "b": 0}, {"a": [1, 0], "b": 0},
                                   {"a": [-1, -1], "b": -1}],
            "multipliers": [1, 1, 1], "equalities": [], "eq_multipliers": []}


def triangle_hull():
    """F = 0: Psi = conv(X), the triangle (0,0), (2,0), (0,2)."""
    return {"rescon_certificate": 1, "kind": "safe_kernel", "points": [[0, 0], [2, 0], [0, 2]],
            "F": 0, "dim": 2, "vertices": [[0, 0], [2, 0], [0, 2]], "equalities": [],
            "facets": [{"a": [-1, 0], "b": 0}, {"a": [0, -1], "b": 0}, {"a": [1, 1], "b": 2}],
            "proof": {"method": "halfspaces"}}


def collinear_kernel():
    return {"rescon_certificate": 1, "kind": "safe_kernel", "points": [[0, 0], [1, 1], [2, 2]],
            "F": 1, "dim": 0, "vertices": [[1, 1]], "equalities": [{"a": [1, -1], "b": 0}],
            "facets": [{"a": [1, 0], "b": 1}, {"a": [-1, 0], "b": -1}],
            "proof": {"method": "tverberg", "vertex_parts": [[
                {"indices": [1], "weights": [1]},
                {"indices": [0, 2], "weights": ["1/2", "1/2"]}]]}}


def test_hand_made_valid_certificates():
    for cert in (square_kernel(), square_point(), triangle_empty(), triangle_hull(),
                 collinear_kernel()):
        res = check(cert)
        assert res.valid and res.trusted == (), (cert["kind"], res.reason)
    assert check(square_kernel()).reason == \
        "safe kernel = conv of 1 vertex, dim 0 (n=4, d=2, F=1; halfspaces)"
    assert check(square_point()).reason == \
        "x is in the safe kernel (n=4, d=2, F=1; tverberg)"
    assert check(triangle_hull()).reason.startswith("safe kernel = conv of 3 vertices, dim 2")
    # the square's center by halfspaces; its kernel also with Tverberg parts
    c = square_point()
    c["proof"] = {"method": "halfspaces"}
    assert check(c).valid
    c = square_kernel()
    c["proof"] = {"method": "tverberg", "vertex_parts": [copy.deepcopy(DIAGONALS)]}
    assert check(c).valid
    # square with F = 2: empty (x <= 0 and x >= 1 both have 2 points outside)
    c = triangle_empty()
    c.update(points=copy.deepcopy(SQUARE), F=2,
             halfspaces=[{"a": [1, 0], "b": 0}, {"a": [-1, 0], "b": -1}], multipliers=[1, 1])
    assert check(c).valid


def test_degenerate_point_sets():
    cases = [
        ([(3, 3)], 0),  # n = 1
        ([(1, 2, 3)] * 4, 2),  # all points equal, d = 3
        ([(0, 0), (0, 0), (1, 1), (2, 2), (2, 2)], 2),  # duplicates on a line
        ([(0, 0), (1, 1), (2, 2)], 1),
        ([(0, 0), (1, 2), (2, 4), (3, 6), (5, 10)], 1),
        ([(0, 0, 0), (2, 0, 2), (0, 2, 2), (2, 2, 4), (1, 1, 2)], 1),  # plane z = x + y
        ([(0, 0, 0), (2, 0, 2), (0, 2, 2), (2, 2, 4), (1, 1, 2), (1, 1, 2)], 2),
        ([(0,), (1,), (1,), (4,), (9,)], 1),  # d = 1
        ([(0,), (1,), (1,), (4,), (9,)], 2),
        ([(0,), (5,)], 1),  # d = 1, empty
        ([(0, 0), (4, 0), (0, 4), (4, 4), (1, 3)], 0),  # F = 0: the hull
        ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], 0),  # tetrahedron hull
        ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], 1),  # empty
    ]
    for pts, F in cases:
        cert = kernel_cert(pts, F)
        res = check(cert)
        assert res.valid, (pts, F, res.reason)
        if cert["kind"] == "safe_kernel":
            for v in cert["vertices"]:
                v = [Fraction(t) for t in v]
                assert in_kernel_brute(pts, F, v)
                assert check(point_cert(pts, F, v)).valid
    # exact expectations for a few
    assert kernel_cert([(0, 0), (1, 1), (2, 2)], 1)["vertices"] == [[1, 1]]
    assert kernel_cert([(1, 2, 3)] * 4, 2)["vertices"] == [[1, 2, 3]]
    assert kernel_cert([(0,), (1,), (1,), (4,), (9,)], 2)["vertices"] == [[1]]
    assert kernel_cert([(0,), (1,), (1,), (4,), (9,)], 1)["vertices"] == [[1], [4]]
    hull = kernel_cert([(0, 0), (4, 0), (0, 4), (4, 4), (1, 3)], 0)
    assert sorted(map(tuple, hull["vertices"])) == [(0, 0), (0, 4), (4, 0), (4, 4)]
    assert hull["dim"] == 2
    plane = kernel_cert([(0, 0, 0), (2, 0, 2), (0, 2, 2), (2, 2, 4), (1, 1, 2)], 1)
    assert plane["vertices"] == [[1, 1, 2]] and len(plane["equalities"]) == 1
    plane = kernel_cert([(0, 0, 0), (2, 0, 2), (0, 2, 2), (2, 2, 4), (1, 1, 2)], 0)
    assert plane["dim"] == 2 and len(plane["vertices"]) == 4
    # a point of the plane set's kernel off the plane is rejected: not in aff(X)
    res = check(point_cert([(0, 0, 0), (2, 0, 2), (0, 2, 2), (2, 2, 4)], 0, (1, 1, 3)))
    assert not res.valid and "affine hull" in res.reason
    # all points equal: only that point (the linear-time axis test already refutes it)
    res = check(point_cert([(1, 2)] * 3, 1, (1, Fraction(5, 2))))
    assert res.verdict == "invalid" and "not in the safe kernel" in res.reason


# --------------------------------------------------------------------------- #
# tampering
# --------------------------------------------------------------------------- #


def _at(cert, path):
    for k in path[:-1]:
        cert = cert[k]
    return cert, path[-1]


def _set(path, value):
    def f(c):
        obj, k = _at(c, path)
        obj[k] = value
    return f


def _del(path):
    def f(c):
        obj, k = _at(c, path)
        del obj[k]
    return f


def _append(path, value):
    def f(c):
        obj, k = _at(c, path)
        obj[k].append(value)
    return f


def _do(*fs):
    def f(c):
        for g in fs:
            g(c)
    return f


TAMPER = {
    # ---- kernel_point (square, F = 1, Tverberg diagonals) ----
    "point: x moved off the center": (
        square_point, _set(["x"], ["1/2", "500001/1000000"]), "is not x"),
    "point: x moved, halfspaces": (
        square_point, _do(_set(["x"], ["1/2", "500001/1000000"]),
                          _set(["proof"], {"method": "halfspaces"})), "not in the safe kernel"),
    "point: x a corner, halfspaces": (
        square_point, _do(_set(["x"], [0, 0]), _set(["proof"], {"method": "halfspaces"})),
        "not in the safe kernel"),
    "point: wrong weights": (
        square_point, _set(["proof", "parts", 0, "weights"], ["1/3", "2/3"]), "is not x"),
    "point: weights do not sum to 1": (
        square_point, _set(["proof", "parts", 0, "weights"], ["1/2", "1/4"]), "sum to 3/4"),
    "point: negative weight": (
        square_point, _set(["proof", "parts", 0, "weights"], ["3/2", "-1/2"]), "negative"),
    "point: overlapping parts": (
        square_point, _set(["proof", "parts", 1, "indices"], [1, 0]), "already used by"),
    "point: repeated index in a part": (
        square_point, _set(["proof", "parts", 0, "indices"], [0, 0]), "this part"),
    "point: too few parts": (
        square_point, _set(["proof", "parts"], DIAGONALS[:1]), "at least F + 1 = 2"),
    "point: too few parts for F = 2": (
        square_point, _set(["F"], 2), "at least F + 1 = 3"),
    "point: empty part": (
        square_point, _set(["proof", "parts", 1], {"indices": [], "weights": []}), "is empty"),
    "point: index out of range": (
        square_point, _set(["proof", "parts", 1, "indices"], [1, 4]), "out of range"),
    "point: index not integer": (
        square_point, _set(["proof", "parts", 1, "indices"], [1, 2.0]), "must be an integer"),
    "point: weight count": (
        square_point, _set(["proof", "parts", 1, "weights"], ["1/2"]), "2 indices but 1 weights"),
    "point: part extra key": (
        square_point, _set(["proof", "parts", 1, "note"], 1), "unknown key 'note'"),
    "point: parts missing": (
        square_point, _del(["proof", "parts"]), "missing key 'parts'"),
    "point: halfspaces with parts": (
        square_point, _set(["proof", "method"], "halfspaces"), "unknown key 'parts'"),
    "point: unknown method": (
        square_point, _set(["proof", "method"], "magic"), "unknown proof method 'magic'"),
    "point: method missing": (
        square_point, _del(["proof", "method"]), "missing key 'method'"),
    "point: proof not object": (
        square_point, _set(["proof"], "tverberg"), "must be a JSON object"),
    "point: x wrong length": (
        square_point, _set(["x"], [0, 0, 0]), "x has 3 coordinates, expected d = 2"),
    "point: F = n": (square_point, _set(["F"], 4), "out of range"),
    "point: F negative": (square_point, _set(["F"], -1), "out of range"),
    "point: F boolean": (square_point, _set(["F"], True), "must be an integer"),
    "point: points empty": (square_point, _set(["points"], []), "points is empty"),
    "point: points ragged": (
        square_point, _set(["points", 2], [0, 1, 2]), "points[2] has 3 coordinates"),
    "point: points d = 9": (
        square_point, _set(["points"], [[0] * 9]), "dimension d must be 1..8"),
    "point: points d = 0": (
        square_point, _set(["points"], [[]]), "dimension d must be 1..8"),
    "point: points not array": (square_point, _set(["points"], {}), "must be an array"),
    "point: extra key": (square_point, _set(["extra"], 1), "unknown key 'extra'"),
    "point: x missing": (square_point, _del(["x"]), "missing key 'x'"),
    # ---- number encoding ----
    "number: denominator 0": (square_point, _set(["x", 0], "1/0"), "denominator 0"),
    "number: decimal string": (square_point, _set(["x", 0], "0.5"), "not a rational string"),
    "number: plus sign": (square_point, _set(["x", 0], "+1/2"), "not a rational string"),
    "number: spaces": (square_point, _set(["x", 0], " 1/2"), "not a rational string"),
    "number: negative denominator": (square_point, _set(["x", 0], "1/-2"),
                                     "not a rational string"),
    "number: word": (square_point, _set(["x", 0], "half"), "not a rational string"),
    "number: empty string": (square_point, _set(["x", 0], ""), "not a rational string"),
    "number: NaN": (square_point, _set(["x", 0], float("nan")), "not a finite number"),
    "number: inf": (square_point, _set(["points", 1, 0], float("inf")), "not a finite number"),
    "number: -inf weight": (square_point, _set(["proof", "parts", 0, "weights", 0],
                                               float("-inf")), "not a finite number"),
    "number: boolean": (square_point, _set(["x", 1], True), "got boolean"),
    "number: null": (square_point, _set(["x", 1], None), "got null"),
    "number: array": (square_point, _set(["x", 1], [1]), "got array"),
    "number: huge string": (square_point, _set(["x", 1], "1" * (K.MAX_RATIONAL_CHARS + 1)),
                            f"{K.MAX_RATIONAL_CHARS + 1} characters"),
    "number: too many digits": (square_point, _set(["x", 1], "1/" + "3" * 10_000),
                                "10000 decimal digits"),
    "number: 5000 digits are read": (square_point, _set(["x", 1], "1/" + "3" * 5000),
                                     "is not x = (1/2, <a number with thousands of digits>)"),
    "number: long but fine": (square_point, _set(["x", 1], "1" + "0" * 1999 + "1/2" + "0" * 2000),
                              "is not x = (1/2, 100000000000000000..."),
    "number: float not exactly 1/2": (square_point, _set(["x", 0], 0.1 * 5 + 1e-16),
                                      "is not x"),
    # ---- kernel_empty (triangle, F = 1) ----
    "empty: halfspace with F + 1 points outside": (
        triangle_empty, _set(["halfspaces", 0], {"a": [0, 1], "b": -1}), "more than F = 1"),
    "empty: negative multiplier": (
        triangle_empty, _set(["multipliers", 0], -1), "negative"),
    "empty: sum not zero": (
        triangle_empty, _set(["multipliers", 0], 2), "is not 0"),
    "empty: sum not negative": (
        triangle_empty, _set(["halfspaces", 2, "b"], 0), "is not < 0"),
    "empty: multiplier count": (
        triangle_empty, _set(["multipliers"], [1, 1]), "expected 3"),
    "empty: eq_multiplier count": (
        triangle_empty, _set(["eq_multipliers"], [1]), "expected 0"),
    "empty: equality not holding": (
        triangle_empty, _do(_set(["equalities"], [{"a": [1, 0], "b": 0}]),
                            _set(["eq_multipliers"], [0])), "does not hold at points[1]"),
    "empty: equality used to cheat": (
        triangle_empty, _do(_set(["equalities"], [{"a": [0, 0], "b": 1}]),
                            _set(["eq_multipliers"], [-1]), _set(["multipliers"], [0, 0, 0])),
        "does not hold at points[0]"),
    "empty: halfspace missing b": (
        triangle_empty, _del(["halfspaces", 0, "b"]), "missing key 'b'"),
    "empty: halfspace a wrong length": (
        triangle_empty, _set(["halfspaces", 0, "a"], [1]), "expected d = 2"),
    "empty: equalities missing": (triangle_empty, _del(["equalities"]),
                                  "missing key 'equalities'"),
    "empty: nonempty kernel (square, F = 1)": (
        triangle_empty, _do(_set(["points"], copy.deepcopy(SQUARE)),
                            _set(["halfspaces"], [{"a": [1, 1], "b": 1},
                                                  {"a": [-1, -1], "b": -1}]),
                            _set(["multipliers"], [1, 1])), "is not < 0"),
    "empty: triangle with F = 0": (triangle_empty, _set(["F"], 0), "more than F = 0"),
    # ---- safe_kernel ----
    "kernel: facet with F + 1 points outside": (
        square_kernel, _set(["facets", 0], {"a": [1, 1], "b": "1/2"}), "more than F = 1"),
    "kernel: facet dropped (P unbounded)": (
        square_kernel, _del(["facets", 1]), "P is unbounded"),
    "kernel: two facets dropped (P unbounded)": (
        square_kernel, _do(_del(["facets", 3]), _del(["facets", 1])), "P is unbounded"),
    "kernel: two facets dropped (not a vertex)": (
        square_kernel, _do(_del(["facets", 3]), _del(["facets", 2])), "is not a vertex of P"),
    "kernel: vertex moved": (
        square_kernel, _set(["vertices", 0], ["1/2", "1/3"]), "violates facets"),
    "kernel: extra vertex outside P": (
        square_kernel, _append(["vertices"], [1, 1]), "violates facets"),
    "kernel: vertex repeated": (
        square_kernel, _append(["vertices"], [0.5, "1/2"]), "repeats vertices[0]"),
    "kernel: no vertices": (square_kernel, _set(["vertices"], []), "vertices is empty"),
    "kernel: wrong dim": (square_kernel, _set(["dim"], 1), "dim = 1 but"),
    "kernel: dim above d": (square_kernel, _set(["dim"], 3), "out of range"),
    "kernel: hull claimed for F = 1": (
        triangle_hull, _set(["F"], 1), "not in the safe kernel"),
    "kernel: square hull claimed for F = 1": (
        square_kernel, _do(_set(["vertices"], copy.deepcopy(SQUARE)), _set(["dim"], 2),
                           _set(["facets"], [{"a": [-1, 0], "b": 0}, {"a": [0, -1], "b": 0},
                                             {"a": [1, 0], "b": 1}, {"a": [0, 1], "b": 1}])),
        "vertices[0] is not in the safe kernel: its Tukey depth is at most 1 <= F = 1"),
    "kernel: missing vertex": (triangle_hull, _del(["vertices", 2]), "not listed in vertices"),
    "kernel: non-vertex listed": (
        triangle_hull, _append(["vertices"], [1, 0]), "is not a vertex of P"),
    "kernel: interior point listed": (
        triangle_hull, _append(["vertices"], ["1/2", "1/2"]), "is not a vertex of P"),
    "kernel: hull facet dropped": (triangle_hull, _del(["facets", 2]), "is not a vertex of P"),
    "kernel: hull facet loosened": (
        triangle_hull, _set(["facets", 2, "b"], 3), "is not a vertex of P"),
    "kernel: collinear equality dropped": (
        collinear_kernel, _set(["equalities"], []), "is not a vertex of P"),
    "kernel: collinear equality false": (
        collinear_kernel, _set(["equalities", 0], {"a": [1, -2], "b": -1}),
        "does not hold at points[0]"),
    "kernel: collinear facet dropped": (
        collinear_kernel, _del(["facets", 1]), "P is unbounded: direction (-1, -1)"),
    "kernel: collinear both facets dropped": (
        collinear_kernel, _set(["facets"], []), "is not a vertex of P"),
    "kernel: vertex_parts count": (
        collinear_kernel, _append(["proof", "vertex_parts"], []), "expected one per vertex"),
    "kernel: vertex_parts overlapping": (
        collinear_kernel, _set(["proof", "vertex_parts", 0, 1, "indices"], [0, 1]),
        "already used by"),
    "kernel: vertex_parts wrong point": (
        collinear_kernel, _set(["proof", "vertex_parts", 0, 1, "weights"], ["1/4", "3/4"]),
        "is not vertices[0] = (1, 1)"),
    "kernel: tverberg missing vertex_parts": (
        collinear_kernel, _del(["proof", "vertex_parts"]), "missing key 'vertex_parts'"),
    "kernel: facets missing": (square_kernel, _del(["facets"]), "missing key 'facets'"),
    "kernel: facet not object": (square_kernel, _set(["facets", 0], [1, 1, 1]),
                                 "must be a JSON object"),
}


@pytest.mark.parametrize("name", sorted(TAMPER))
def test_tampered_certificates_are_rejected(name):
    make, f, needle = TAMPER[name]
    cert = make()
    assert check(cert).valid, name
    f(cert)
    res = check(cert)
    assert not res.valid, name
    assert needle in res.reason, res.reason
    assert "\n" not in res.reason


def test_rational_encodings_accepted():
    for x in (["2/4", "1/2"], [0.5, 0.5], ["0001/0002", 0.5], ["-1/2", "-1/2"]):
        c = square_point()
        c["x"] = x
        res = check(c)
        assert res.valid == (x[0] != "-1/2"), (x, res.reason)
    c = square_point()
    c["points"] = [[-1, "-0/7"], [1, 0], [0, 1.0], [-0.0, 1]]
    c["x"] = [0, "0/3"]
    c["proof"]["parts"] = [{"indices": [0, 1], "weights": ["1/2", "1/2"]},
                           {"indices": [2], "weights": [1]}]
    res = check(c)
    assert not res.valid and "parts[1]: sum of weights * points = (0, 1)" in res.reason
    assert K._rat("-3/4", "w") == Fraction(-3, 4)
    assert K._rat("-0/5", "w") == 0
    assert K._rat(0.1, "w") == Fraction(0.1) != Fraction(1, 10)
    assert K._rat(-7, "w") == -7


def test_empty_with_equalities():
    """Collinear points with F too large: Farkas needs the equality (any sign)."""
    pts = [(0, 0), (1, 1), (2, 2), (3, 3)]
    cert = kernel_cert(pts, 2)
    assert cert["kind"] == "kernel_empty"
    assert check(cert).valid
    hand = {"rescon_certificate": 1, "kind": "kernel_empty", "points": [[0, 0], [1, 1], [3, 3]],
            "F": 1, "halfspaces": [{"a": [1, 1], "b": 0}, {"a": [0, -1], "b": -3}],
            "multipliers": [1, 2], "equalities": [{"a": [1, -1], "b": 0}],
            "eq_multipliers": [-1]}
    # the Farkas sums hold, but x + y <= 0 (outside: 2 points!) is invalid
    assert check(hand).verdict == "invalid"
    assert "more than F = 1" in check(hand).reason
    hand["halfspaces"] = [{"a": [1, 0], "b": 1}, {"a": [0, -1], "b": -1}]
    hand["multipliers"] = [1, 1]
    res = check(hand)  # x <= 1, y >= 1 meet x = y in (1, 1): not empty -> sum not < 0
    assert not res.valid and "is not < 0" in res.reason
    hand["halfspaces"] = [{"a": [1, 0], "b": 0}, {"a": [0, -1], "b": -1}]
    hand["points"] = [[0, 0], [1, 1], [2, 2]]
    # x <= 0 (outside: 2 points) invalid for F = 1
    assert "more than F = 1" in check(hand).reason
    hand["F"] = 2
    hand["points"] = [[0, 0], [1, 1], [2, 2], [3, 3]]
    hand["halfspaces"] = [{"a": [1, 0], "b": 1}, {"a": [0, -1], "b": -2}]
    res = check(hand)  # x <= 1, y >= 2, x - y = 0: (1, 0)+(0, -1)-(1, -1) = 0, 1 - 2 < 0
    assert res.valid, res.reason


# --------------------------------------------------------------------------- #
# limits
# --------------------------------------------------------------------------- #


def test_halfspaces_trusted_beyond_the_limit():
    rng = random.Random(5)
    pts = [(rng.randint(0, 10**6), rng.randint(0, 10**6), rng.randint(0, 10**6))
           for _ in range(300)]
    assert math.comb(300, 3) * 301 > K.MAX_HALFSPACE_WORK
    res = check(point_cert(pts, 1, pts[0]))  # not refuted, not verified: unchecked
    assert res.verdict == "unchecked" and not res.valid and res.trusted == ("halfspaces",)
    assert "halfspaces: not checked" in res.reason
    assert res.unchecked[0].startswith("x in the safe kernel (proof 'halfspaces'): enumerating")
    # the affine-hull part is still checked: points on a plane, x off it (inside the box)
    flat = [(x, y, x + y) for x, y, _ in pts]
    res = check(point_cert(flat, 1, (500_000, 500_000, 1_000_001)))
    assert res.verdict == "invalid" and "affine hull" in res.reason
    # Tverberg proofs are never trusted
    res = check(point_cert(pts, 1, pts[0], {"method": "tverberg", "parts": [
        {"indices": [0], "weights": [1]}, {"indices": [1], "weights": [1]}]}))
    assert not res.valid and "is not x" in res.reason


def test_one_dimensional_kernels_are_checked_for_large_n():
    """k = 1 (d = 1, or collinear points): Psi = [F+1-th smallest, F+1-th largest]."""
    rng = random.Random(9)
    for d in (1, 2, 3):
        for _ in range(6):
            n = rng.randint(500, 3000)
            ts = [rng.randint(-50, 50) for _ in range(n)]
            F = rng.randrange(n)
            direction = (3, -1, 2)[:d]
            pts = [tuple(t * c + 1 for c in direction) for t in ts]
            srt = sorted(ts)
            lo, hi = srt[F], srt[n - 1 - F]
            for t in {lo, hi, lo - Fraction(1, 3), hi + Fraction(1, 3), (lo + hi) / 2}:
                x = tuple(t * c + 1 for c in direction)
                res = check(point_cert(pts, F, x))
                assert res.valid == (lo <= t <= hi), (d, n, F, t, lo, hi, res.reason)
                assert res.trusted == ()


def unit_cube_kernel() -> tuple[dict, list[dict]]:
    """The safe kernel of the unit cube's corners with F = 0 (the cube) and its facets."""
    cube = [(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
    facets = [{"a": [s if j == i else 0 for j in range(3)], "b": max(s, 0)}
              for i in range(3) for s in (1, -1)]
    cert = {"rescon_certificate": 1, "kind": "safe_kernel", "points": [list(p) for p in cube],
            "F": 0, "dim": 3, "vertices": [list(p) for p in cube], "equalities": [],
            "facets": facets, "proof": {"method": "halfspaces"}}
    return cert, facets


def test_polytope_enumeration_limit():
    cert, facets = unit_cube_kernel()
    assert check(cert).valid
    cert["facets"] = facets + [{"a": [1, 1, 1], "b": 3 + i} for i in range(400)]
    res = check(cert)  # too large is not invalid: the enumeration part is unchecked
    assert res.verdict == "unchecked" and res.trusted == ("vertex enumeration",), res
    assert "enumerating 11153835 subsets of the 406 facets" in res.unchecked[0]


def test_vertex_test_beyond_its_limit_leaves_the_enumeration_unchecked(monkeypatch):
    cert, facets = unit_cube_kernel()
    assert check(cert).verdict == "valid"
    monkeypatch.setattr(K, "MAX_EVAL_WORK", 100)  # 8 vertices x (6 + 9) = 120 > 100
    res = check(cert)
    assert res.verdict == "unchecked", res
    assert res.trusted == ("vertex test", "vertex enumeration"), res.trusted
    cert["vertices"][0] = [0, 0, 2]  # a wrong vertex is still refuted by the cheap parts
    assert check(cert).verdict == "invalid"


def test_resource_limits():
    c = square_point()
    c["points"] = [[0, 0]] * (K.MAX_POINTS + 1)
    res = check(c)
    assert res.verdict == "unchecked" and "exceeds the checker's limit" in res.reason
    c = triangle_empty()
    c["halfspaces"] = [{"a": [0, 0], "b": 0}] * (K.MAX_CONSTRAINTS + 1)
    res = check(c)
    assert res.verdict == "unchecked" and res.trusted == ("size limit",), res


# --------------------------------------------------------------------------- #
# verdicts: cheap refutations first, bounded time on huge numbers
# --------------------------------------------------------------------------- #


def gaussian_cloud(seed, n, d, scale=1.0):
    rng = random.Random(seed)
    return [tuple(rng.gauss(0, 1) * scale for _ in range(d)) for _ in range(n)]


def test_wrong_kernel_beyond_the_enumeration_limit_is_refuted():
    """The bounding box of 200 Gaussian points x 2^600 with F = 20 (what a float
    overflow once returned) has corners of Tukey depth 1: an axis halfspace refutes it,
    although the halfspace enumeration is far beyond its limit."""
    d, F = 3, 20
    pts = gaussian_cloud(1, 200, d, 2.0**600)
    lo = [min(p[j] for p in pts) for j in range(d)]
    hi = [max(p[j] for p in pts) for j in range(d)]
    corners = [[(lo, hi)[(m >> j) & 1][j] for j in range(d)] for m in range(1 << d)]
    box = [{"a": [s if j == i else 0 for j in range(d)], "b": s * (hi if s > 0 else lo)[i]}
           for i in range(d) for s in (1, -1)]
    cert = {"rescon_certificate": 1, "kind": "safe_kernel", "points": [list(p) for p in pts],
            "F": F, "dim": d, "vertices": corners, "equalities": [], "facets": box,
            "proof": {"method": "halfspaces"}}
    t0 = time.perf_counter()
    res = check(json.loads(json.dumps(cert)))
    assert res.verdict == "invalid" and "Tukey depth is at most 1" in res.reason, res
    assert time.perf_counter() - t0 < 10


def test_point_outside_the_hull_is_refuted_cheaply():
    """200 points, F = 199: only a point equal to every data point has depth 200."""
    pts = gaussian_cloud(2, 200, 3)
    for x in ((5.0, 5.0, 5.0), (0.0, 0.0, 0.0), pts[0]):
        res = check(point_cert(pts, 199, x))
        assert res.verdict == "invalid" and "Tukey depth" in res.reason, (x, res)
    # a true claim beyond the limit is unchecked, not valid and not invalid
    sym = [p for q in gaussian_cloud(3, 150, 3) for p in (q, tuple(-t for t in q))]
    res = check(point_cert(sym, 1, (0, 0, 0)))
    assert res.verdict == "unchecked" and res.trusted == ("halfspaces",), res


def big_denominator_cloud(seed, pairs, digits):
    """A centrally symmetric cloud (so the origin has depth >= n/2) whose coordinates
    have distinct denominators of ``digits`` digits."""
    rng = random.Random(seed)
    pts = []
    for _ in range(pairs):
        p = [Fraction(rng.randint(-9, 9)) + Fraction(1, rng.randrange(10**(digits - 1),
                                                                        10**digits))
             for _ in range(3)]
        pts += [p, [-t for t in p]]
    return pts


def test_large_distinct_denominators_answer_quickly():
    """40 points with distinct 400-digit denominators took 111 s (every number scaled by
    one common denominator); 120 points with 4000-digit ones, hours.  Now the common
    denominator is bounded (MAX_SCALE_BITS) and the part beyond it is unchecked."""
    for pairs, digits in ((20, 400), (60, 4000)):
        cert = point_cert(big_denominator_cloud(pairs, pairs, digits), 1, (0, 0, 0))
        t0 = time.perf_counter()
        res = check(cert)
        assert time.perf_counter() - t0 < 10, (pairs, digits)
        assert res.verdict == "unchecked" and res.trusted == ("bit size",), res
        assert f"exceeds the checker's limit of {K.MAX_SCALE_BITS} bits" in res.unchecked[0]
    # the cheap test still refutes a false claim on the same data
    pts = big_denominator_cloud(7, 20, 400)
    res = check(point_cert(pts, 1, (100, 0, 0)))
    assert res.verdict == "invalid" and "Tukey depth is at most 0" in res.reason
    # a Tverberg proof whose sums need a huge common denominator: unchecked, quickly
    parts = [{"indices": [2 * i, 2 * i + 1], "weights": ["1/2", "1/2"]} for i in range(20)]
    res = check(point_cert(pts, 1, (0, 0, 0), {"method": "tverberg", "parts": parts}))
    assert res.verdict == "valid", res  # each part alone is small: exact
    big = [{"indices": list(range(40)), "weights": ["1/40"] * 40}] * 2
    res = check(point_cert(pts, 1, (0, 0, 0), {"method": "tverberg", "parts": big}))
    assert res.verdict == "invalid" and "already used" in res.reason


def test_kernel_empty_with_a_wrong_farkas_sum_is_refuted_first():
    """A 2.4 MB kernel_empty with a trivially wrong Farkas sum took > 120 s (its
    halfspaces were evaluated at every point first, over one huge common denominator)."""
    rng = random.Random(4)
    pts = big_denominator_cloud(4, 60, 1000)
    H = [{"a": [f"1/{rng.randrange(10**999, 10**1000)}", 1, 0], "b": 100} for _ in range(300)]
    cert = {"rescon_certificate": 1, "kind": "kernel_empty",
            "points": [[jnum(t) for t in p] for p in pts], "F": 1, "halfspaces": H,
            "multipliers": [1] * len(H), "equalities": [], "eq_multipliers": []}
    assert len(json.dumps(cert)) > 600_000
    t0 = time.perf_counter()
    res = check(cert)
    assert res.verdict == "invalid" and "Farkas" in res.reason, res
    assert "modulo the prime" in res.reason
    assert time.perf_counter() - t0 < 10
    # right sums, constraints not evaluable within the bit-size limit: unchecked
    cert["halfspaces"] = [{"a": [1, 0, 0], "b": -1000}, {"a": [-1, 0, 0], "b": -1000}]
    cert["multipliers"] = [1, 1]
    res = check(cert)
    assert res.verdict == "unchecked" and res.trusted == ("bit size",), res
    cert["points"] = [[0, 0, 0]] * 3  # small points: the halfspaces are refuted
    res = check(cert)
    assert res.verdict == "invalid" and "more than F = 1" in res.reason, res


def test_farkas_modular_test_never_rejects_a_right_sum():
    """Sums that cancel exactly pass the modular test whatever the denominators (also
    denominators divisible by the prime, where it is skipped)."""
    p = K.FARKAS_PRIME
    for q in (3, 10**40 + 7, p, 2 * p):
        t = Fraction(1, q)
        cert = {"rescon_certificate": 1, "kind": "kernel_empty", "points": [[0], [1], [2]],
                "F": 1, "halfspaces": [{"a": [jnum(t)], "b": 0}, {"a": [jnum(-t)], "b": jnum(-t)}],
                "multipliers": [1, 1], "equalities": [], "eq_multipliers": []}
        res = check(cert)  # x <= 0 (2 points outside) and x >= 1 (1 point outside)
        assert res.verdict == "invalid" and "more than F = 1" in res.reason, (q, res)
        cert["F"] = 2
        assert check(cert).verdict == "valid", q


# --------------------------------------------------------------------------- #
# module structure, examples, schema, command line
# --------------------------------------------------------------------------- #


def test_kernels_module_is_stdlib_only():
    tree = ast.parse(KERNELS_PY.read_text())
    mods = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            mods.update(a.name.split(".")[0] for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            mods.add((node.module or "").split(".")[0])
    stdlib = {"__future__", "bisect", "collections", "fractions", "itertools", "math",
              "operator", "re", "typing"}
    assert mods <= stdlib, mods
    assert KERNEL_KINDS <= set(C.KINDS)


def test_package_import_binds_the_same_exception():
    """Inside a package check.py imports .kernels; a kernel-kind rejection is caught."""
    spec = importlib.util.spec_from_file_location(
        "_rescon_certificates_pkg_kernels_under_test", CERT_DIR / "__init__.py",
        submodule_search_locations=[str(CERT_DIR)])
    pkg = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = pkg
    spec.loader.exec_module(pkg)
    kern = sys.modules[spec.name + ".kernels"]
    assert kern.Invalid is sys.modules[spec.name + ".check"].Invalid
    assert pkg.check(square_kernel()).valid
    bad = square_kernel()
    bad["dim"] = 2
    res = pkg.check(bad)
    assert not res.valid and "dim = 2 but" in res.reason


def _validator():
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(SCHEMA.read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def test_kernel_examples_and_schema():
    v = _validator()
    kinds = set()
    for path in EXAMPLES:
        cert = json.loads(path.read_text())
        if cert["kind"] in KERNEL_KINDS:
            v.validate(cert)
            assert check(cert).valid, path.name
            kinds.add(cert["kind"])
    assert kinds == KERNEL_KINDS
    certs = [square_kernel(), square_point(), triangle_empty(), triangle_hull(),
             collinear_kernel()]
    rng = random.Random(3)
    for trial in range(10):
        pts = random_points(rng, 2, 5)
        certs.append(kernel_cert(pts, trial % 3))
    for c in certs:
        v.validate(c)
    bad = square_point()
    bad["x"][0] = "0.5"
    assert not v.is_valid(bad)
    bad = square_point()
    bad["proof"]["method"] = "magic"
    assert not v.is_valid(bad)
    bad = triangle_empty()
    bad["extra"] = 1
    assert not v.is_valid(bad)


def _run(path):
    return subprocess.run([sys.executable, str(CHECK_PY), str(path)],
                          check=False, capture_output=True, text=True, timeout=60)


def test_cli_on_kernel_certificates(tmp_path):
    for path in EXAMPLES:
        if json.loads(path.read_text())["kind"] in KERNEL_KINDS:
            p = _run(path)
            assert p.returncode == 0 and p.stdout.strip() == "valid", (path, p.stderr)
    bad = tmp_path / "bad.json"
    c = square_kernel()
    c["vertices"] = [["1/2", "1/3"]]
    bad.write_text(json.dumps(c))
    p = _run(bad)
    assert p.returncode == 1 and p.stderr.startswith("invalid: vertices[0]"), p.stderr
    trusted = tmp_path / "trusted.json"
    rng = random.Random(5)
    pts = [(rng.randint(0, 99), rng.randint(0, 99), rng.randint(0, 99)) for _ in range(300)]
    trusted.write_text(json.dumps(point_cert(pts, 1, pts[0])))
    p = _run(trusted)
    lines = p.stdout.splitlines()
    assert p.returncode == 3 and lines[0] == "unchecked" and len(lines) == 2, p.stdout
    assert lines[1].startswith("not checked: x in the safe kernel (proof 'halfspaces')")
    nan = tmp_path / "nan.json"
    nan.write_text('{"rescon_certificate": 1, "kind": "kernel_point", "points": [[NaN]]}')
    assert _run(nan).returncode == 2


def test_halfspace_enumeration_counts_the_cost_of_each_normal():
    """20 integer points in R^8 and their mean (F = 0): C(20, 8) = 125 970 hyperplanes,
    each normal 8 determinants of order 7. The work estimate counted only the point
    classifications (2.6·10^6 < 3·10^6) and the check took 27 s for a 1 KB certificate;
    now it is over the limit (unchecked) and answers at once. Just inside the limit
    (14 points) the enumeration still runs and is valid."""
    rng = random.Random(1)
    for u, expect in ((20, "unchecked"), (14, "valid")):
        pts = [[rng.randint(-1000, 1000) for _ in range(8)] for _ in range(u)]
        x = [f"{sum(p[j] for p in pts)}/{u}" for j in range(8)]
        cert = {"rescon_certificate": 1, "kind": "kernel_point", "points": pts, "F": 0,
                "x": x, "proof": {"method": "halfspaces"}}
        t0 = time.perf_counter()
        res = check(cert)
        assert res.verdict == expect and time.perf_counter() - t0 < 5, (u, res)
