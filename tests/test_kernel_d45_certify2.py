"""The certification of the d = 4-5 fast path (issue 13 §3) on very non-simple inputs:
vertices and rays of row sets in which 2, 3, …, k rows share data points, the packed
tight bitsets, the vectorised other ends of the rays, and whole kernels of lattice
and 24-cell clouds, against independent exact computations and the exact clipping."""

from __future__ import annotations

import itertools
import random
from fractions import Fraction

import numpy as np
import pytest

from rescon.geometry import fastpath
from rescon.geometry.exact import nullspace_exact
from rescon.geometry.polytope import _bits, tight_pairs
from tests.test_kernel_d45 import _halfspaces
from tests.test_kernel_d45_certify import _reference_vertex


def _lattice(d: int, seed: int) -> np.ndarray:
    """Integer points in a small box: many hyperplanes through common points, so row
    sets with groups of 2, 3, …, k rows sharing k − |G| + 1 points."""
    rng = np.random.default_rng(seed)
    return rng.integers(-2, 3, size=(14 + 2 * d, d)).astype(float)


def _ternary(n: int, d: int, seed: int) -> np.ndarray:
    """Points of {−1, 0, 1}^d: in d = 5 hundreds of vertices with 6 to 20 tight rows."""
    return np.random.default_rng(seed).integers(-1, 2, size=(n, d)).astype(float)


def _grouped_bases(H, k: int, size: int, rng, limit: int = 60) -> list[list[int]]:
    """Row sets whose first ``size`` rows all pass through k − size + 1 common data
    points (the rest random)."""
    by_points: dict[tuple[int, ...], list[int]] = {}
    for h in range(len(H)):
        for sub in itertools.combinations(sorted(H.through[h].tolist()), k - size + 1):
            by_points.setdefault(sub, []).append(h)
    out = []
    for hs in by_points.values():
        if len(hs) >= size:
            rest = rng.choice(len(H), size=k - size, replace=False).tolist()
            out.append([*rng.choice(hs, size=size, replace=False).tolist(), *rest])
        if len(out) == limit:
            break
    return out


@pytest.mark.parametrize("d,F,seed", [(4, 2, 1), (4, 3, 2), (5, 2, 3)])
def test_vertices_of_rows_sharing_points_equal_the_null_space(d, F, seed):
    H, hull, _, _ = _halfspaces(_lattice(d, seed), F)
    k = hull.dim
    rng = np.random.default_rng(seed)
    for size in range(2, k + 1):
        bases = _grouped_bases(H, k, size, rng)
        got = fastpath._solve_all(H, bases, k)
        want = [_reference_vertex(H, T) if len(set(T)) == k else None for T in bases]
        assert got == want
    # groups of three or more rows exist in these clouds and meet in a point
    assert any(v is not None for v in fastpath._solve_all(H, _grouped_bases(H, k, 3, rng), k))


@pytest.mark.parametrize("d,F,seed", [(4, 2, 4), (5, 2, 5)])
def test_rays_of_rows_sharing_points_are_the_null_directions(d, F, seed):
    H, hull, _, _ = _halfspaces(_lattice(d, seed), F)
    k = hull.dim
    rng = np.random.default_rng(seed)
    tries = [T for size in range(2, k + 1) for T in _grouped_bases(H, k, size, rng, 20)]
    bases = [T for T, v in zip(tries, fastpath._solve_all(H, tries, k), strict=True)
             if v is not None]
    S_set = sorted({h for T in bases for h in T})
    where = {h: i for i, h in enumerate(S_set)}
    normals = [H.exact(h)[0] for h in S_set]
    got = fastpath._simplicial_rays(H, S_set, normals, [[where[h] for h in T] for T in bases], k)
    assert len(bases) > 10
    for T, rays in zip(bases, got, strict=True):
        for h, d_ in zip(T, rays, strict=True):
            ns = nullspace_exact([[Fraction(v) for v in H.exact(g)[0]] for g in T if g != h])
            assert len(ns) == 1
            ratio = {Fraction(x) / y for x, y in zip(d_, ns[0], strict=True) if y != 0}
            assert len(ratio) == 1 and all(x == 0 for x, y in zip(d_, ns[0], strict=True)
                                           if y == 0)
            assert fastpath._dot(H.exact(h)[0], d_) < 0


def test_bitsets_equal_bit_by_bit_sums():
    rng = random.Random(2)
    for _ in range(100):
        n, width = rng.randint(1, 30), rng.randint(1, 200)
        pairs = [(rng.randrange(n), rng.randrange(width)) for _ in range(rng.randint(0, 90))]
        vs = np.array([v for v, _ in pairs], dtype=np.int64)
        hs = np.array([h for _, h in pairs], dtype=np.int64)
        want = [0] * n
        for v, h in pairs:
            want[v] |= 1 << h
        tight, (v_of, h_of) = fastpath._tight_sets(vs, hs, n, width)
        assert tight == want
        want_v, want_h = tight_pairs(want)
        assert tight == want
        assert v_of.tolist() == want_v.tolist() and h_of.tolist() == want_h.tolist()


def _brute_end(tight: list[int], v: int, Z: int) -> set[int]:
    return {u for u, t in enumerate(tight) if u != v and t & Z == Z}


@pytest.mark.parametrize("X,F", [(_lattice(4, 6), 2), (_ternary(14, 5, 1), 1)])
def test_other_ends_are_the_vertices_on_each_ray(X, F):
    """Every ray of every vertex (simple ones: drop one basis row; non-simple ones:
    their double description) ends at the one other vertex holding its tight rows,
    vectorised where the ray's tight set is its key, scanned otherwise; a set of rows
    no other vertex holds gives None."""
    H, hull, _, unit = _halfspaces(X, F)
    k = hull.dim
    first = np.flatnonzero(H.outside == F)
    P = fastpath.certified_kernel(H, k, unit, first)
    assert P is not None
    basis = [sorted(_bits(t))[:k] for t in P.tight]  # unused for simple vertices' keys
    index = fastpath._RayIndex(P.tight, basis, len(P.a), k)
    rays = [(vi, P.tight[vi] ^ (1 << j)) for vi in index.simple.tolist()
            for j in _bits(P.tight[vi])]
    ends = index.other_ends([vi for vi, _ in rays], [Z for _, Z in rays])
    for (vi, Z), u in zip(rays, ends, strict=True):
        assert _brute_end(P.tight, vi, Z) == {u}
    ray_v, ray_z = [], []
    for vi in index.non_simple:
        for u in P.edges[vi]:
            ray_v.append(vi)
            ray_z.append(P.tight[vi] & P.tight[u])
    assert any(Z.bit_count() == k - 1 for Z in ray_z)
    assert any(Z.bit_count() > k - 1 for Z in ray_z)
    got = index.other_ends(ray_v, ray_z)
    for v, Z, u in zip(ray_v, ray_z, got, strict=True):
        assert _brute_end(P.tight, v, Z) == {u}
    # all of v's rows (rank k) hold at v alone: that "ray" leads nowhere
    assert index.other_ends([ray_v[0]], [P.tight[ray_v[0]]]) is None


def _cell24() -> np.ndarray:
    """The 24-cell's vertices (permutations of (±1, ±1, 0, 0)) and its centre twice:
    hyperplanes through many of them at once, so vertices with many tight rows."""
    pts = {tuple(v) for i, j in itertools.combinations(range(4), 2)
           for si in (-1, 1) for sj in (-1, 1)
           for v in [[si if c == i else sj if c == j else 0 for c in range(4)]]}
    return np.array(sorted(pts) + [[0, 0, 0, 0]] * 2, dtype=float)


@pytest.mark.parametrize("X,F,fast", [
    (_lattice(4, 8), 2, True), (_lattice(4, 9), 4, True), (_ternary(14, 5, 1), 1, True),
    (_cell24(), 3, True), (_cell24() * 2.0**-1000, 3, True),
    (np.random.default_rng(12).normal(size=(5, 4)), 0, False),  # n = d + 1
])
def test_very_non_simple_kernels_are_bit_identical_to_exact_clipping(X, F, fast,
                                                                      monkeypatch):
    """The certified fast path (when it runs: not for n = d + 1) gives the exact
    clipping's answer where many rows meet at each vertex."""
    import rescon
    from rescon.geometry import kernel as km
    from tests.test_kernels_d45_fast import _public

    made = []
    certify = km.certified_kernel
    monkeypatch.setattr(km, "certified_kernel", lambda *a: made.append(certify(*a)) or made[-1])
    got = rescon.safe_kernel(X, F)
    assert (len(made) == 1 and made[0] is not None
            and any(t.bit_count() > made[0].k for t in made[0].tight)) == fast
    monkeypatch.setattr(km, "certified_kernel", lambda *a: None)
    assert _public(got) == _public(rescon.safe_kernel(X, F))


def test_cross_all_is_the_signed_maximal_minors():
    """x_j = (−1)^j det R_{−j} for m × (m + 1) integer matrices, m = 1..5, against
    Bareiss determinants (entries of 80 bits and a dependent pair of rows: x = 0)."""
    from rescon.geometry.exact import cross_all
    from rescon.geometry.halfspaces import _int_det

    rng = random.Random(3)
    for m in range(1, 6):
        mats = [[[rng.randint(-2**80, 2**80) for _ in range(m + 1)] for _ in range(m)]
                for _ in range(30)]
        if m >= 2:
            mats.append([mats[0][0], [3 * v for v in mats[0][0]], *mats[0][2:]])
        R = np.empty((len(mats), m, m + 1), dtype=object)
        R[:] = mats
        want = [[(-1) ** j * _int_det([row[:j] + row[j + 1:] for row in M])
                 for j in range(m + 1)] for M in mats]
        assert cross_all(R).tolist() == want
        if m >= 2:
            assert want[-1] == [0] * (m + 1)
