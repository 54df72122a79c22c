"""The certification of the d = 4-5 fast path (issue 13 §3): its exact vertices from
the data points (:func:`fastpath._meet`), the modular independence test, and the
closure, against independent exact computations."""

from __future__ import annotations

import itertools
import random
from fractions import Fraction
from math import gcd

import numpy as np
import pytest

import rescon
from rescon.geometry import fastpath
from rescon.geometry import kernel as km
from rescon.geometry.exact import nullspace_exact
from rescon.geometry.halfspaces import _int_det
from tests.test_kernel_d45 import _both_paths, _halfspaces, _primitive_verts, bases
from tests.test_kernels_d45_fast import _cloud, _public


def _reference_vertex(H, T):
    """The primitive (w, y), w > 0, spanning the null space of the rows (−b, a) of T,
    by exact Gaussian elimination; None unless it is one finite point."""
    rows = [[-b, *a] for a, b in map(H.exact, T)]
    ns = nullspace_exact([[Fraction(v) for v in r] for r in rows])
    if len(ns) != 1 or ns[0][0] == 0:
        return None
    x = ns[0]
    den = 1
    for v in x:
        den = den * v.denominator // gcd(den, v.denominator)
    z = [int(v * den) for v in x]
    g = gcd(*z) * (1 if z[0] > 0 else -1)
    return tuple(v // g for v in z)


def _clouds():
    rng = np.random.default_rng(11)
    yield rng.normal(size=(16, 4)), 2
    yield rng.normal(size=(11, 5)), 1
    yield rng.normal(size=(14, 3)), 2
    yield rng.normal(size=(12, 2)), 2
    yield rng.integers(-3, 4, size=(18, 4)).astype(float), 2  # ties, duplicates
    yield rng.normal(size=(12, 4)) * 10.0 ** rng.integers(-300, 300, size=(12, 1)), 1
    yield 1.0 + 1e-13 * rng.normal(size=(13, 4)), 1  # converged states


@pytest.mark.parametrize("case", range(7))
def test_vertices_through_the_data_points_equal_the_null_space(case):
    X, F = list(_clouds())[case]
    H, hull, _, _ = _halfspaces(X, F)
    k = hull.dim
    rng = np.random.default_rng(case)
    m = len(H)
    bases = [sorted(rng.choice(m, size=k, replace=False).tolist()) for _ in range(150)]
    # rows sharing k − 1 data points (the paired case) and dependent sets
    by_points = {}
    for h in range(m):
        for sub in itertools.combinations(sorted(H.through[h].tolist()), k - 1):
            by_points.setdefault(sub, []).append(h)
    for hs in list(by_points.values())[:200]:
        if len(hs) >= 2:
            rest = rng.choice(m, size=k - 2, replace=False).tolist()
            bases.append([hs[0], hs[1], *rest])
    bases.append([0] * k)  # one row k times: no single point
    bases.append([*rng.choice(m, size=k - 1, replace=False).tolist(),
                  int(rng.integers(m))])
    got = fastpath._solve_all(H, bases, k)
    want = [_reference_vertex(H, T) if len(set(T)) == k else None for T in bases]
    assert got == want
    assert any(v is not None for v in got)


def test_det_mod_equals_the_exact_determinant():
    rng = random.Random(4)
    p = fastpath.PRIME
    for m in (1, 2, 3, 4, 5):
        mats = [[[rng.randint(-2**70, 2**70) for _ in range(m)] for _ in range(m)]
                for _ in range(40)]
        mats.append([[1] * m for _ in range(m)])  # singular
        A = np.array([[[v % p for v in row] for row in M] for M in mats], dtype=np.int64)
        assert fastpath._det_mod(A, p).tolist() == [_int_det(M) % p for M in mats]


@pytest.mark.parametrize("case", range(7))
def test_simplicial_rays_through_the_data_points_are_the_null_directions(case):
    """Each ray of a basis's simplicial cone spans the null space of the other k − 1
    normals and points into a_h·d < 0 (brute force: exact elimination)."""
    X, F = list(_clouds())[case]
    H, hull, _, _ = _halfspaces(X, F)
    k = hull.dim
    rng = np.random.default_rng(case)
    tries = [sorted(rng.choice(len(H), size=k, replace=False).tolist()) for _ in range(80)]
    bases = [T for T, v in zip(tries, fastpath._solve_all(H, tries, k), strict=True)
             if v is not None]
    S_set = sorted({h for T in bases for h in T})
    where = {h: i for i, h in enumerate(S_set)}
    normals = [H.exact(h)[0] for h in S_set]
    pos = [[where[h] for h in T] for T in bases]
    got = fastpath._simplicial_rays(H, S_set, normals, pos, k)
    assert len(got) == len(bases) > 0
    for T, rays in zip(bases, got, strict=True):
        for h, d in zip(T, rays, strict=True):
            ns = nullspace_exact([[Fraction(v) for v in H.exact(g)[0]] for g in T if g != h])
            assert len(ns) == 1
            # d is a positive multiple of ±ns[0], on the side a_h·d < 0
            ratio = {Fraction(x) / y for x, y in zip(d, ns[0], strict=True) if y != 0}
            assert len(ratio) == 1 and all(x == 0 for x, y in zip(d, ns[0], strict=True)
                                           if y == 0)
            assert fastpath._dot(H.exact(h)[0], d) < 0


def test_members_of_bitsets_equal_the_bit_by_bit_lists():
    from rescon.geometry.polytope import _bits, members_of, tight_pairs

    rng = random.Random(1)
    for _ in range(200):
        tight = [rng.getrandbits(rng.choice([0, 3, 8, 9, 64, 700, 3000]))
                 for _ in range(rng.randint(0, 30))]
        want: dict[int, list[int]] = {}
        for i, t in enumerate(tight):
            for h in _bits(t):
                want.setdefault(h, []).append(i)
        got = members_of(tight)
        assert got == want and list(got) == sorted(want)
        vs, hs = tight_pairs(tight)
        assert list(zip(vs.tolist(), hs.tolist(), strict=True)) == [
            (i, h) for i, t in enumerate(tight) for h in sorted(_bits(t))]


@pytest.mark.parametrize("was_on", [True, False])
def test_the_fast_path_leaves_the_collector_as_it_found_it(was_on):
    import gc

    H, hull, _, unit = _halfspaces(np.random.default_rng(2).normal(size=(14, 4)), 1)
    first = np.flatnonzero(H.outside == 1)
    (gc.enable if was_on else gc.disable)()
    try:
        assert fastpath.certified_kernel(H, hull.dim, unit, first) is not None
        assert gc.isenabled() == was_on
    finally:
        gc.enable()


@pytest.mark.parametrize("kind,d,n,F", [
    ("gaussian", 5, 13, 1), ("sphere", 5, 12, 2), ("tiny", 5, 12, 1), ("huge", 5, 12, 1),
    ("integers", 5, 13, 1), ("duplicated", 5, 20, 2), ("converged", 5, 12, 1),
    ("gaussian", 4, 5, 0), ("gaussian", 5, 6, 0), ("integers", 4, 20, 3),
])
def test_d5_and_hostile_kernels_are_bit_identical_to_exact_clipping(kind, d, n, F,
                                                                   monkeypatch):
    X = _cloud(kind, d, n, 7)
    fast = rescon.safe_kernel(X, F)
    monkeypatch.setattr(km, "certified_kernel", lambda *a: None)
    slow = rescon.safe_kernel(X, F)
    assert _public(fast) == _public(slow)


def test_mixed_magnitudes_are_bit_identical_to_exact_clipping(monkeypatch):
    rng = np.random.default_rng(8)
    X = rng.normal(size=(14, 4)) * 10.0 ** rng.integers(-300, 300, size=(14, 4))
    fast = rescon.safe_kernel(X, 1)
    monkeypatch.setattr(km, "certified_kernel", lambda *a: None)
    assert _public(fast) == _public(rescon.safe_kernel(X, 1))


def test_a_moved_vertex_is_refused():
    """A proposal whose rows are changed so that it names another point: the proof
    refuses it (an infeasible point, or a true vertex left out)."""
    X = np.random.default_rng(3).normal(size=(20, 4))
    _, slow, H, unit, first = _both_paths(X, 1)
    _, facets = fastpath._propose(H, first)
    honest = fastpath._certify(H, 4, unit, first, facets)
    assert honest is not None and set(_primitive_verts(honest)) == set(slow.verts)
    moved = 0
    rng = np.random.default_rng(0)
    for p in rng.permutation(len(facets))[:15].tolist():
        lied = [list(f) for f in facets]
        lied[p] = [*lied[p][:3], int(rng.integers(len(first)))]
        v = fastpath._solve_all(H, [[int(first[i]) for i in lied[p]]], 4)[0]
        if v is None or v in _primitive_verts(honest):
            continue
        moved += 1
        assert fastpath._certify(H, 4, unit, first, lied) is None
    assert moved > 0


def test_bases_pick_independent_rows_of_each_proposal():
    """k distinct rows of T, independent even when T repeats directions (rows 0-2 are
    one normal at three scales: a pivoted QR takes at most one of them)."""
    from types import SimpleNamespace

    rng = np.random.default_rng(6)
    for k in (3, 4, 5):
        af = rng.normal(size=(40, k))
        af[1], af[2] = 3.0 * af[0], -0.5 * af[0]
        H = SimpleNamespace(af=af)
        Ts = [[0, 1, 2, *rng.choice(np.arange(3, 40), size=int(rng.integers(k - 1, k + 5)),
                                    replace=False).tolist()] for _ in range(60)]
        Ts += [rng.choice(40, size=k, replace=False).tolist() for _ in range(5)]
        got = bases(H, Ts, k)
        for T, B in zip(Ts, got, strict=True):
            assert len(set(B)) == k and set(B) <= set(T)
            assert len(T) > k or B == T
            assert len({0, 1, 2} & set(B)) <= 1
            assert np.linalg.svd(af[B], compute_uv=False)[-1] > 1e-6
