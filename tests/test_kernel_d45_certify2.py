"""The faster certification of the d = 4-5 fast path (issue 13 §3): vertices and rays
through the largest group of rows sharing data points, the packed tight bitsets, and
the vectorised other ends of the rays, against independent exact computations."""

from __future__ import annotations

import itertools
import random
from fractions import Fraction

import numpy as np
import pytest

from rescon.geometry import fastpath
from rescon.geometry.exact import nullspace_exact
from rescon.geometry.polytope import _bits
from tests.test_kernel_d45 import _halfspaces
from tests.test_kernel_d45_certify import _reference_vertex


def _lattice(d: int, seed: int) -> np.ndarray:
    """Integer points in a small box: many hyperplanes through common points, so row
    sets with groups of 2, 3, …, k rows sharing k − |G| + 1 points."""
    rng = np.random.default_rng(seed)
    return rng.integers(-2, 3, size=(14 + 2 * d, d)).astype(float)


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
def test_vertices_through_larger_groups_equal_the_null_space(d, F, seed):
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
def test_rays_through_larger_groups_are_the_null_directions(d, F, seed):
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
        assert fastpath._bitsets(vs, hs, n, width) == want


def _brute_end(tight: list[int], v: int, Z: int) -> set[int]:
    return {u for u, t in enumerate(tight) if u != v and t & Z == Z}


@pytest.mark.parametrize("d,F,seed", [(4, 2, 6), (5, 1, 7)])
def test_other_ends_are_the_vertices_on_each_ray(d, F, seed):
    """Every ray of every vertex (simple ones: drop one basis row; non-simple ones:
    their double description) ends at the one other vertex holding its tight rows,
    vectorised where the ray's tight set is its key, scanned otherwise; a set of rows
    no other vertex holds gives None."""
    H, hull, _, unit = _halfspaces(_lattice(d, seed), F)
    k = hull.dim
    first = np.flatnonzero(H.outside == F)
    P = fastpath.certified_kernel(H, k, unit, first)
    assert P is not None
    basis = [sorted(_bits(t))[:k] for t in P.tight]  # unused for simple vertices' keys
    index = fastpath._RayIndex(P.tight, basis, len(P.a), k)
    simple = index.simple.tolist()
    ends = index.simple_ends()
    for vi, us in zip(simple, ends, strict=True):
        for j, u in zip(sorted(_bits(P.tight[vi])), us, strict=True):
            assert _brute_end(P.tight, vi, P.tight[vi] ^ (1 << j)) == {u}
    ray_v, ray_z = [], []
    for vi in index.non_simple:
        for u in P.edges[vi]:
            ray_v.append(vi)
            ray_z.append(P.tight[vi] & P.tight[u])
    assert any(Z.bit_count() == k - 1 for Z in ray_z)
    assert any(Z.bit_count() > k - 1 for Z in ray_z) or d == 5
    got = index.other_ends(ray_v, ray_z)
    for v, Z, u in zip(ray_v, ray_z, got, strict=True):
        assert _brute_end(P.tight, v, Z) == {u}
    # all of v's rows (rank k) hold at v alone: that "ray" leads nowhere
    assert index.other_ends([ray_v[0]], [P.tight[ray_v[0]]]) is None
