"""Hostile review V18 of the validity monitor's tree searches outside many-vertex hulls
(issue 13; M2's c853a14, 65db167, 532e359, 1dc1b7a): :meth:`ValidityMonitor.distances`
with the trees against the dense path (the trees switched off, as
tests/test_metrics_fast_distances.py does) bit for bit on hostile polygons and
polytopes (hypothesis), against exact Fractions outside, and the memory of the trees
when nothing can be pruned (states 1e8 beyond a thin hull: N·h pairs at once before
the fix)."""

from __future__ import annotations

import warnings
from fractions import Fraction

import networkx as nx
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_metrics_review import _seg2
from test_review_v13 import _close

from rescon.consensus import _distance_trees, _validity_monitor
from rescon.consensus._validity_monitor import BLOCK
from rescon.consensus.engine import simulate
from rescon.consensus.metrics import ValidityMonitor
from rescon.consensus.scenario import Scenario


def _dense(mon: ValidityMonitor, S: np.ndarray) -> np.ndarray:
    """distances() with both trees off: the O(N·h) path, the oracle of the trees."""
    trees = mon._edge_tree, mon._tri_tree
    mon._edge_tree = mon._tri_tree = None
    try:
        return mon.distances(S)
    finally:
        mon._edge_tree, mon._tri_tree = trees


def _spy(monkeypatch, name: str) -> list[int]:
    """Record the number of broadcast (row, item) pairs of each call of <name> (the
    validity monitor's, and the dense path's in _distance_trees)."""
    sizes: list[int] = []
    real = getattr(_distance_trees, name)

    def spy(X, P, *rest):
        sizes.append(int(np.prod(np.broadcast_shapes(X.shape, P.shape)[:-1])))
        return real(X, P, *rest)

    for module in (_validity_monitor, _distance_trees):
        monkeypatch.setattr(module, name, spy)
    return sizes


# --------------------------------------------------------------------------- #
# broke (fixed): N·h pairs at once when no box can be left out
# --------------------------------------------------------------------------- #


def test_thin_polygon_far_states_never_hold_n_by_h_pairs(monkeypatch):
    """2000 states 1e8 beyond a parabola 1e-13 thin and 2 long (3001 vertices): every
    edge is within the bound's rounding (~4e-7) of every other (their distances differ
    by ≤ 1/(2·1e8)), so no box is left out and _descend returned all 6·10⁶ pairs at
    once — one _edge_float call over them, ~0.9 GB peak RSS (10 000 states around a
    5000-gon: ~7 GB), where edge_distances takes BLOCK pairs at a time. Failed before
    the fix (a call of 6 002 000 pairs); now every call holds ≤ BLOCK pairs, and the
    floats are the dense path's."""
    t = np.linspace(-1, 1, 3001)
    mon = ValidityMonitor(np.c_[t, 1e-13 * t**2])
    S = np.c_[np.random.default_rng(0).uniform(-1, 1, 2000), np.full(2000, -1e8)]
    sizes = _spy(monkeypatch, "_edge_float")
    got = mon.distances(S)
    assert sum(sizes) > 2000 * 3000  # nothing left out: the tree compares every edge
    assert max(sizes) <= BLOCK, max(sizes)
    monkeypatch.undo()
    assert np.array_equal(got, _dense(mon, S))


def test_flat_polytope_far_states_never_hold_n_by_t_pairs(monkeypatch):
    """The same in R³: 300 states 1e8 beyond a disc 1e-13 thin (600 points, ~1200
    triangles): no box left out, 1.3·10⁵ (row, triangle) pairs in one _closest_points
    call (~20 temporaries of 3 floats each) where triangle_distances takes BLOCK/16
    pairs at a time. Failed before the fix; now ≤ BLOCK/16 pairs per call, and the
    same floats and verdicts as the dense path."""
    rng = np.random.default_rng(3)
    a = rng.uniform(0, 2 * np.pi, 600)
    r = np.sqrt(rng.uniform(0, 1, 600))
    X0 = np.c_[r * np.cos(a), r * np.sin(a), 1e-13 * rng.uniform(-1, 1, 600)]
    X0[:200, :2] /= np.linalg.norm(X0[:200, :2], axis=1)[:, None]
    mon = ValidityMonitor(X0)
    assert mon._tri_tree is not None
    S = np.c_[rng.uniform(-0.5, 0.5, (300, 2)), np.full(300, 1e8)]
    sizes = _spy(monkeypatch, "_closest_points")
    fast, known, dist = mon._nearest_triangles(S)
    assert known.all()
    assert max(sizes) <= BLOCK // 16, max(sizes)
    monkeypatch.undo()
    want, err = mon.triangle_distances(S)
    assert np.array_equal(dist, want) and np.array_equal(fast, want > err)


def test_seed_triangles_of_many_states_are_taken_in_blocks(monkeypatch):
    """The seeds of _nearest_triangles (the CONE_STEPS + 1 = 9 triangles of each
    row's walk) went through one _closest_points call for all rows: 9N pairs of ~20
    temporaries, 134 MB peak (tracemalloc) for 40 000 states outside a sphere of 2000
    points against 15 MB for triangle_distances. Failed before the fix (90 000 seed
    pairs in one call for 10 000 states; 311 260 descended pairs at 1dc1b7a); now
    ≤ BLOCK/16 pairs per call (28 MB there), and the same floats and verdicts."""
    rng = np.random.default_rng(2)
    X0 = _polytope("sphere", 400, rng)
    mon = ValidityMonitor(X0)
    S = _polytope("sphere", 10_000, rng) * 1.01
    sizes = _spy(monkeypatch, "_closest_points")
    fast, known, dist = mon._nearest_triangles(S)
    assert known.all() and max(sizes) <= BLOCK // 16, max(sizes)
    monkeypatch.undo()
    want, err = mon.triangle_distances(S[:500])
    assert np.array_equal(dist[:500], want) and np.array_equal(fast[:500], want > err)


# --------------------------------------------------------------------------- #
# held: hostile polygons, bit for bit against the dense path (hypothesis)
# --------------------------------------------------------------------------- #


def _polygon(kind: str, n: int, rng) -> np.ndarray:
    if kind == "circle":
        a = np.sort(rng.uniform(0, 2 * np.pi, n))
        return np.c_[np.cos(a), np.sin(a)]
    if kind == "thin":  # width 1e-13 · length: the mean's cone is a sliver
        t = np.linspace(-1, 1, n)
        return np.c_[t, 1e-13 * t**2]
    if kind == "thin circle":  # a circle squashed to 1e-13: the mean on its edges
        a = np.sort(rng.uniform(0, 2 * np.pi, n))
        return np.c_[np.cos(a), 1e-13 * np.sin(a)]
    if kind == "integer circle":  # rounded: duplicates and collinear runs of vertices
        a = np.sort(rng.uniform(0, 2 * np.pi, n))
        return np.round(np.c_[np.cos(a), np.sin(a)] * 300)
    if kind == "regular":  # a regular integer polygon plus the midpoints of its edges
        a = 2 * np.pi * np.arange(n // 2) / (n // 2)
        V = np.round(np.c_[np.cos(a), np.sin(a)] * 2**20) * 2
        return np.vstack([V, (V + np.roll(V, -1, axis=0)) / 2])
    a = np.sort(rng.uniform(0, 2 * np.pi, n))  # ellipse 1e-8 thin
    return np.c_[1e-8 * np.cos(a), np.sin(a)]


def _states(X0: np.ndarray, mon: ValidityMonitor, rng, m: int) -> np.ndarray:
    """States just outside (1 ulp, a few ulps past a vertex away from the mean), far
    (1e10 … 1e16 hull sizes), on edges' lines beyond their ends, at the mean's direction
    to a vertex (the cone boundaries), and inside."""
    c = X0.mean(axis=0)
    V = mon._edges[0]
    size = float(np.abs(V - c).max())
    pick = V[rng.integers(0, len(V), m)]
    away = np.sign(pick - c)
    out = [pick + away * np.spacing(pick) * rng.integers(1, 4, (m, 1)),
           np.nextafter(pick, pick + away),
           c + (pick - c) * (1 + 2.0**-52),
           c + (pick - c) * 10.0 ** rng.uniform(10, 16, (m, 1)),
           c + rng.standard_normal((m, 2)) * size * 10.0 ** rng.uniform(0, 16, (m, 1))]
    P, Q = mon._edges
    k = rng.integers(0, len(P), m)
    out += [P[k] + rng.integers(2, 5, (m, 1)) * (Q[k] - P[k]), P[k] - (Q[k] - P[k])]
    out += [c + (pick - c) * rng.uniform(0, 1.5, (m, 1))]
    S = np.vstack(out)
    return S[np.isfinite(S).all(axis=1)]


@settings(max_examples=30, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.sampled_from(["circle", "thin", "thin circle", "integer circle", "regular",
                        "ellipse"]),
       st.integers(65, 2500),
       st.sampled_from([1.0, 1e-150, 1e150, 2.0**-1000, 1e-90, 1e90, 3.0, 1e-5]),
       st.sampled_from([0.0, 1e-300, 5e-324, 1e6]),
       st.integers(0, 2**32 - 1))
def test_polygon_trees_are_the_dense_path_bit_for_bit(kind, n, scale, offset, seed):
    """distances() with the tree equals the dense path, bit for bit, on hostile
    polygons of 65–5000 vertices at 1e±150, 2^-1000, with subnormal offsets and states
    1 ulp outside, 1e10–1e16 hull sizes away, on edges' lines, at cone boundaries."""
    rng = np.random.default_rng(seed)
    X0 = _polygon(kind, n, rng) * scale + offset
    if not np.isfinite(X0).all():
        return
    mon = ValidityMonitor(X0)
    if mon._edge_tree is None:
        return
    S = _states(X0, mon, rng, 40)
    _same_as_dense(mon, S)


def _same_as_dense(mon: ValidityMonitor, S: np.ndarray) -> None:
    """The rows the tree answers are the rows the dense path answers by edge_distances
    (a facet proves them outside, edge_error finite, distance > 0), with its floats;
    the rest go to the dense path in distances() too. surely_inside, which skips the
    facet loop for rows the cone facet proves outside, decides as with the tree off.
    (Not distances() itself: the exact projections of the rows no float path answers
    take seconds on hulls of thousands of vertices.)"""
    sure = mon.surely_inside(S)
    trees = mon._edge_tree
    mon._edge_tree = None
    try:
        assert np.array_equal(sure, mon.surely_inside(S))
    finally:
        mon._edge_tree = trees
    fast, dist = mon._nearest_edges(S[~sure])
    want, err = mon.edge_distances(S[~sure][fast])
    assert np.array_equal(dist[fast], want)
    assert mon._surely_outside(S[~sure][fast]).all() and np.isfinite(err).all()
    assert (want > 0).all()


def test_a_5000_gon_and_1e16_states_bit_for_bit():
    """The largest case: a 5000-gon at 1e-150 with a subnormal offset."""
    rng = np.random.default_rng(11)
    X0 = _polygon("circle", 5000, rng) * 1e-150 + 5e-324
    mon = ValidityMonitor(X0)
    S = _states(X0, mon, rng, 300)
    _same_as_dense(mon, S)


@pytest.mark.parametrize("kind", ["circle", "thin", "regular", "ellipse"])
def test_polygon_distances_against_fractions(kind):
    """Outside: within edge_error of the exact min over the exact edges of the exact
    segment distance (Fractions); 0 iff the exact hull test says inside."""
    rng = np.random.default_rng(len(kind))
    X0 = _polygon(kind, 200, rng)
    mon = ValidityMonitor(X0)
    assert mon._edge_tree is not None
    S = _states(X0, mon, rng, 6)
    got = mon.distances(S)
    P, Q = mon._edges
    for g, x in zip(got, S):
        if mon.hull.contains(x):
            assert g == 0
            continue
        xf = [Fraction(v) for v in x]
        sq = min(_seg2(xf, [Fraction(v) for v in p], [Fraction(v) for v in q])
                 for p, q in zip(P, Q))
        want = float(Fraction(sq) ** 0.5) if sq else 0.0
        assert g > 0 and _close(g, max(want, 5e-324), max(np.abs(X0).max(),
                                                          np.abs(x).max())), (g, want, x)


# --------------------------------------------------------------------------- #
# held: hostile polytopes, bit for bit against the dense path
# --------------------------------------------------------------------------- #


def _polytope(kind: str, n: int, rng) -> np.ndarray:
    if kind == "sphere":
        X = rng.standard_normal((n, 3))
        return X / np.linalg.norm(X, axis=1)[:, None]
    if kind == "ellipsoid":
        X = rng.standard_normal((n, 3))
        return X / np.linalg.norm(X, axis=1)[:, None] * [1e-9, 1.0, 3.0]
    k = max(3, round(n ** (1 / 3)))  # a cube of grid points: coplanar faces, ties
    g = np.arange(k, dtype=float)
    return np.array(np.meshgrid(g, g, g)).reshape(3, -1).T


@settings(max_examples=12, deadline=None, suppress_health_check=list(HealthCheck))
@given(st.sampled_from(["sphere", "ellipsoid", "cube"]), st.integers(70, 500),
       st.sampled_from([1.0, 1e-90, 1e90, 2.0**-300, 7.0]), st.integers(0, 2**32 - 1))
def test_polytope_trees_are_the_dense_path_bit_for_bit(kind, n, scale, seed):
    """_nearest_triangles' δ and verdicts are triangle_distances' bit for bit (ties on
    the cube's coplanar faces: the first triangle, as argmin) for states 1 ulp off,
    far (1e10–1e16), on the lines through two vertices, on face-normal rays."""
    rng = np.random.default_rng(seed)
    X0 = _polytope(kind, n, rng) * scale
    mon = ValidityMonitor(X0)
    if mon._tri_tree is None:
        return
    c = X0.mean(axis=0)
    V = mon.hull.vertices
    size = float(np.abs(V - c).max())
    m = 12
    pick = V[rng.integers(0, len(V), m)]
    other = V[rng.integers(0, len(V), m)]
    S = np.vstack([np.nextafter(pick, pick + np.sign(pick - c)),
                   c + (pick - c) * (1 + 2.0**-50),
                   c + (pick - c) * 10.0 ** rng.uniform(10, 16, (m, 1)),
                   c + rng.standard_normal((m, 3)) * size * 10.0 ** rng.uniform(0, 8, (m, 1)),
                   pick + 2 * (other - pick),
                   c + (pick - c) * rng.uniform(0.5, 1.5, (m, 1))])
    S = S[np.isfinite(S).all(axis=1)]
    fast, known, dist = mon._nearest_triangles(S)
    want, err = mon.triangle_distances(S[known])
    assert np.array_equal(dist[known], want) and np.array_equal(fast[known], want > err)
    rows = np.flatnonzero(fast)[:8]  # the whole path on a few (exact distances are slow)
    assert np.array_equal(mon.distances(S[rows]), _dense(mon, S[rows]))


# --------------------------------------------------------------------------- #
# held: a simulate run's validity metric, trees on and off
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("d", [2, 3])
def test_simulate_validity_is_the_same_with_the_trees_off(monkeypatch, d):
    """80 agents on a circle (a sphere), a ring, F = 0, the paper's residual 0.1^t
    pushing every state out of H: the per-agent validity distances (hundreds > 0)
    are bit for bit those of the run with the trees switched off."""
    X = np.random.default_rng(3).standard_normal((80, d))
    x0 = X / np.linalg.norm(X, axis=1)[:, None]
    sc = Scenario(graph=nx.cycle_graph(80), x0=x0, F=0, steps=5, check_robustness=False)
    assert ValidityMonitor(x0)._edge_tree is not None or ValidityMonitor(x0)._tri_tree is not None

    def run():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return np.asarray(simulate(sc, metrics="validity").metrics["validity_per_agent"])

    got = run()
    monkeypatch.setattr(_validity_monitor, "_edge_tree", lambda *a: None)
    monkeypatch.setattr(_validity_monitor, "_triangle_tree", lambda *a: None)
    assert ValidityMonitor(x0)._edge_tree is None and ValidityMonitor(x0)._tri_tree is None
    assert (got > 0).sum() > 100
    assert np.array_equal(got, run())
