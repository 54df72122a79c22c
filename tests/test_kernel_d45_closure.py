"""The combinatorial closure of non-simple vertices (:mod:`rescon.geometry._closure`)
against the integer double description on every non-simple vertex of many kernels,
tampered tight sets, modular ranks that fall short, and whole kernels against the exact
clipping."""

from __future__ import annotations

import numpy as np
import pytest

import rescon
from rescon.geometry import _closure, fastpath
from rescon.geometry.polytope import PRIME, _bits
from tests.test_kernel_d45_around2 import _cloud, _same_as_clipping


def _recorded(monkeypatch) -> list:
    """Records the arguments of every closure of the fast path, with the start rays of
    the double description of every non-simple vertex."""
    seen = []
    real = fastpath._closed

    def closed(tight, basis, normals, k, start_rays, pairs=None):
        non_simple = [v for v, t in enumerate(tight) if t.bit_count() > k]
        starts = start_rays([basis[v] for v in non_simple])
        seen.append((tight, basis, normals, k, dict(zip(non_simple, starts, strict=True))))
        return real(tight, basis, normals, k, start_rays, pairs)

    monkeypatch.setattr(fastpath, "_closed", closed)
    return seen


def _dd_ends(tight, basis, normals, k, v, start) -> list[int] | None:
    """The other ends of v's rays from the double description, each the one vertex u ≠ v
    holding the ray's tight rows (brute force), or None if a ray has none."""
    out = set()
    for Z in fastpath._tangent_rays(normals, basis[v], list(_bits(tight[v])), k, start):
        holders = [u for u, t in enumerate(tight) if u != v and t & Z == Z]
        if len(holders) != 1:
            return None
        out.add(holders[0])
    return sorted(out)


def _agrees_with_the_double_description(tight, basis, normals, k, starts) -> int:
    """Where the check concludes, its ends are the double description's at a non-simple
    vertex; a simple one is settled iff one vertex holds each k − 1 of its rows (brute
    force), and its ends are those. Returns how many non-simple vertices it settled."""
    ok, ends = _closure.combinatorial_rays(tight, normals, k)
    for v, (passed, us) in enumerate(zip(ok.tolist(), ends, strict=True)):
        if v in starts:
            want = _dd_ends(tight, basis, normals, k, v, starts[v])
        else:
            holders = [[u for u, t in enumerate(tight) if u != v and t & Z == Z]
                       for Z in (tight[v] & ~(1 << h) for h in _bits(tight[v]))]
            want = sorted(u for us in holders for u in us)
            assert passed == all(len(us) == 1 for us in holders)
        if passed:
            assert us == want, v
        else:
            assert us == []
    return int(ok[sorted(starts)].sum())


CLOUDS = [("gaussian", 3, 30, 3), ("cube", 3, 30, 2), ("sphere", 3, 30, 1),
          ("integer", 3, 24, 2), ("lattice", 3, 27, 3),
          ("gaussian", 4, 22, 2), ("cube", 4, 20, 3), ("sphere", 4, 20, 1),
          ("attack", 4, 20, 2), ("converged", 5, 16, 1), ("grid", 4, 20, 2),
          ("tiny", 4, 20, 2), ("huge", 4, 20, 2), ("nearsame", 4, 20, 2),
          ("integer", 4, 20, 3), ("cell24", 4, 28, 4), ("lattice", 4, 27, 4),
          ("gaussian", 5, 14, 1), ("sphere", 5, 14, 1), ("cube", 5, 14, 1),
          ("integer", 5, 14, 1), ("nearsame", 5, 13, 1), ("lattice", 5, 40, 3)]


@pytest.mark.parametrize("kind,d,n,F", CLOUDS)
def test_settled_vertices_have_the_double_descriptions_edges(kind, d, n, F, monkeypatch):
    """On every non-simple vertex of the kernel the check either defers or gives the
    neighbours the double description gives: benchmark families in d = 3–5, integer
    data, converged and nearly identical points, magnitudes 1e-300 and 1e300, the
    24-cell and lattices (very non-simple vertices)."""
    seen = _recorded(monkeypatch)
    rescon.safe_kernel(_cloud(kind, d, n, F), F)
    assert seen
    for tight, basis, normals, k, starts in seen:
        _agrees_with_the_double_description(tight, basis, normals, k, starts)


@pytest.mark.parametrize("kind,d,n,F", [("sphere", 4, 30, 1), ("cube", 5, 16, 1),
                                        ("lattice", 4, 27, 4), ("cell24", 4, 28, 4)])
def test_the_check_settles_non_simple_vertices(kind, d, n, F, monkeypatch):
    """The check concludes where the double description was needed (every non-simple
    vertex of these kernels), and the kernel is certified."""
    seen = _recorded(monkeypatch)
    rescon.safe_kernel(_cloud(kind, d, n, F), F)
    tight, basis, normals, k, starts = seen[-1]
    assert starts
    assert _agrees_with_the_double_description(tight, basis, normals, k, starts) == len(starts)


def _pyramid(scale: int = 1):
    """The square pyramid over [−1, 1]² × {0} with apex (0, 0, 1): rows x + z ≤ 1 (its
    normal times ``scale``), −x + z ≤ 1, y + z ≤ 1, −y + z ≤ 1, −z ≤ 0. Vertices: the
    apex (4 rows, non-simple) and the corners (3 rows)."""
    normals = [(scale, 0, scale), (-1, 0, 1), (0, 1, 1), (0, -1, 1), (0, 0, -1)]
    apex = 0b01111
    corners = [0b10101, 0b10110, 0b11010, 0b11001]  # (1,1), (−1,1), (−1,−1), (1,−1)
    return [apex, *corners], normals


def test_pyramid_apex_is_settled_with_its_four_corners():
    tight, normals = _pyramid()
    ok, ends = _closure.combinatorial_rays(tight, normals, 3)
    assert ok.all() and ends[0] == [1, 2, 3, 4] and ends[1] == [0, 2, 4]


def test_a_modular_rank_that_falls_short_is_not_counted():
    """Row x + z ≤ 1 scaled by the prime: its normal is 0 modulo the prime, so the
    shared rows with the corners on it have modular rank 1 < 2 — those corners are not
    found, and the check defers instead of settling the apex."""
    tight, normals = _pyramid(PRIME)
    ok, ends = _closure.combinatorial_rays(tight, normals, 3)
    assert not ok[0] and ends[0] == []
    R = np.array([[x % PRIME for x in a] for a in normals], dtype=np.int64)
    work = np.empty_like(R)
    assert not _closure._rank_at_least(R, 0b00101, 2, work)  # x + z and y + z
    assert _closure._rank_at_least(R, 0b00110, 2, work)


@pytest.mark.parametrize("corner", range(1, 5))
def test_a_missing_corner_is_refused(corner):
    tight, normals = _pyramid()
    tight = tight[:corner] + tight[corner + 1:]
    ok, _ = _closure.combinatorial_rays(tight, normals, 3)
    assert not ok[0] and not ok.all()


def test_a_fake_neighbour_on_an_edge_is_refused():
    """A point inside the edge from the apex to a corner, tight on the edge's rows: the
    ray's zero set appears twice, which distinct faces never do."""
    tight, normals = _pyramid()
    ok, _ = _closure.combinatorial_rays([*tight, 0b00101], normals, 3)
    assert ok.tolist() == [False, False, True, True, True, False]  # (1, 1) too


def _kernel_closure(kind, d, n, F, monkeypatch):
    seen = _recorded(monkeypatch)
    rescon.safe_kernel(_cloud(kind, d, n, F), F)
    monkeypatch.undo()
    return seen[-1]


@pytest.mark.parametrize("kind,d,n,F", [("sphere", 4, 30, 1), ("lattice", 4, 27, 4),
                                        ("cube", 5, 16, 1)])
def test_tampered_tight_sets_are_refused(kind, d, n, F, monkeypatch):
    """Removing a proposed vertex (a neighbour of every tenth non-simple one), or a
    tight row of that neighbour that the rank of their shared rows needs, makes the
    closure refuse; with a copy of the neighbour the non-simple vertex's check defers."""
    tight, basis, normals, k, starts = _kernel_closure(kind, d, n, F, monkeypatch)

    by_basis = {tuple(basis[v]): start for v, start in starts.items()}

    def closed(tight, basis):  # the double description starts from the recorded rays
        return fastpath._closed(tight, basis, normals, k,
                                lambda bs: [by_basis[tuple(b)] for b in bs])

    edges = closed(tight, basis)
    assert edges is not None
    vs = sorted(starts)[::10]
    for v in vs:
        u = edges[v][0]
        dropped = [t for w, t in enumerate(tight) if w != u]
        kept = [b for w, b in enumerate(basis) if w != u]
        assert closed(dropped, kept) is None
        for h in _bits(tight[v] & tight[u]):
            shared = [normals[g] for g in _bits(tight[v] & tight[u] & ~(1 << h))]
            if _rank(shared) < k - 1:  # h is needed: without it u is off v's ray
                bad = list(tight)
                bad[u] &= ~(1 << h)
                assert closed(bad, basis) is None
                break
        # a copy of u: v's check defers (the double description takes either copy)
        ok, _ = _closure.combinatorial_rays([*tight, tight[u]], normals, k)
        assert not ok[v]


def _rank(rows) -> int:
    from fractions import Fraction

    M = [[Fraction(x) for x in r] for r in rows]
    rank = 0
    for c in range(len(M[0]) if M else 0):
        piv = next((i for i in range(rank, len(M)) if M[i][c]), None)
        if piv is None:
            continue
        M[rank], M[piv] = M[piv], M[rank]
        for i in range(len(M)):
            if i != rank and M[i][c]:
                f = M[i][c] / M[rank][c]
                M[i] = [a - f * b for a, b in zip(M[i], M[rank], strict=True)]
        rank += 1
    return rank


@pytest.mark.parametrize("kind,d,n,F", [("sphere", 4, 30, 1), ("cube", 4, 30, 3),
                                        ("lattice", 4, 27, 4), ("cell24", 4, 28, 4),
                                        ("gaussian", 5, 16, 1), ("integer", 5, 14, 1),
                                        ("tiny", 4, 20, 2), ("huge", 4, 20, 2)])
def test_kernels_bit_identical_to_the_exact_clipping(kind, d, n, F, monkeypatch):
    _same_as_clipping(_cloud(kind, d, n, F), F, monkeypatch)


def _octahedral_pyramid():
    """The pyramid in ℝ⁴ over the octahedron |x| + |y| + |z| ≤ 1 (w = 0) with apex
    (0, 0, 0, 1): rows s·(x, y, z) + w ≤ 1 for s ∈ {±1}³ and −w ≤ 0. Every vertex is
    non-simple (the apex on 8 rows, the base vertices on 5), and every ray of the
    apex's cone is non-simple in its cross-section (4 rows of rank 3): the check
    recurses into the face figures."""
    signs = [(a, b, c) for a in (1, -1) for b in (1, -1) for c in (1, -1)]
    rows = [((*s, 1), 1) for s in signs] + [((0, 0, 0, -1), 0)]
    verts = [(0, 0, 0, 1)] + [tuple(s * (i == j) for j in range(3)) + (0,)
                              for i in range(3) for s in (1, -1)]
    tight = [sum(1 << h for h, (a, b) in enumerate(rows)
                 if sum(x * y for x, y in zip(a, v, strict=True)) == b) for v in verts]
    return tight, [a for a, _ in rows]


def test_octahedral_pyramid_is_settled_through_the_face_figures():
    tight, normals = _octahedral_pyramid()
    assert [t.bit_count() for t in tight] == [8, 5, 5, 5, 5, 5, 5]
    ok, ends = _closure.combinatorial_rays(tight, normals, 4)
    assert ok.all()
    assert ends[0] == [1, 2, 3, 4, 5, 6]
    assert ends[1] == [0, 3, 4, 5, 6]  # e1: the apex and ±e2, ±e3


@pytest.mark.parametrize("gone", range(1, 7))
def test_octahedral_pyramid_without_a_base_vertex_is_refused(gone):
    tight, normals = _octahedral_pyramid()
    tight = tight[:gone] + tight[gone + 1:]
    ok, _ = _closure.combinatorial_rays(tight, normals, 4)
    assert not ok[0]


@pytest.mark.parametrize("kind,d,n,F", [("sphere", 4, 20, 1), ("cell24", 4, 28, 4),
                                        ("nearsame", 5, 13, 1)])
def test_the_double_description_where_the_check_defers(kind, d, n, F, monkeypatch):
    """With the check deferring at every non-simple vertex (none defers on these clouds
    otherwise), their double descriptions give the same kernel as the exact clipping."""
    deferred = defer_non_simple(monkeypatch)
    _same_as_clipping(_cloud(kind, d, n, F), F, monkeypatch)
    assert deferred and deferred[-1] > 0


def defer_non_simple(monkeypatch) -> list[int]:
    """Make the closure's combinatorial check defer at every non-simple vertex (more
    than k tight rows), so the integer double description decides them; returns the
    list to which each check appends how many it deferred."""
    real = _closure.combinatorial_rays
    deferred: list[int] = []

    def deferring(tight, normals, k, pairs=None):
        ok, ends = real(tight, normals, k, pairs)
        wide = np.array([t.bit_count() > k for t in tight], dtype=bool)
        deferred.append(int(wide.sum()))
        return ok & ~wide, [[] if w else us for w, us in zip(wide.tolist(), ends, strict=True)]

    monkeypatch.setattr(_closure, "combinatorial_rays", deferring)
    return deferred
