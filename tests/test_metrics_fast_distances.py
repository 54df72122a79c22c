"""The validity monitor when states leave a hull of many vertices (issue 13, review
V13): distances in O(log h) per state, the same floats as the O(N·h) path
(:meth:`ValidityMonitor.edge_distances`, the oracle here) and, on small hulls with the
fast path forced, the Fractions brute force of tests/test_review_v13.py; and the
``metrics`` names of :func:`monitor_names`."""

from __future__ import annotations

import numpy as np
import pytest
from test_review_v13 import _close, _distance, _few_points

from rescon.consensus import _distance_trees, _validity_monitor, metrics
from rescon.consensus.metrics import ValidityMonitor, monitor_names
from rescon.errors import InputError


def _circle(n: int, d: int = 2, seed: int = 1) -> np.ndarray:
    X = np.random.default_rng(seed).standard_normal((n, d))
    return X / np.linalg.norm(X, axis=1)[:, None]


def _setups():
    """(name, initial states, states): polygons of > INNER_FACETS vertices — a circle,
    a thin parabola (width 1e-13 · length), an ellipse 1e-8 thin at 1e±90, an integer
    circle with states exactly on its edges' lines beyond their ends — and states just
    outside, far, mixed, at 1e99, 1e150 and subnormal offsets (the last ones are not
    fast: edge_error is inf or the facet cannot prove them outside)."""
    rng = np.random.default_rng(5)
    X = _circle(3000)
    yield "circle just outside", X, X * (1 + 2.0**-20)
    yield "circle far", X, X * 1e3 + rng.standard_normal(X.shape)
    yield "circle mixed", X, rng.standard_normal((3000, 2)) * 1.2
    yield "circle 1e99", X, X * 1e99
    yield "circle 1e150", X, X * 1e150
    yield "circle subnormal offsets", X, X + 1e-300
    yield "circle one ulp", X, X * (1 + 2.0**-52)
    t = np.linspace(-1, 1, 3001)
    Y = np.c_[t, 1e-13 * t**2]
    yield "thin parabola", Y, rng.standard_normal((2000, 2))
    yield "thin parabola near", Y, rng.standard_normal((2000, 2)) * 1e-14
    E = np.c_[np.cos(np.linspace(0, 6.28, 2000)) * 1e-8, np.sin(np.linspace(0, 6.28, 2000))]
    yield "ellipse", E, rng.standard_normal((2000, 2))
    yield "ellipse 1e90", E * 1e90, rng.standard_normal((2000, 2)) * 1e90
    yield "ellipse 1e-90", E * 1e-90, rng.standard_normal((2000, 2)) * 1e-90
    R = np.round(X * 1e6)
    P, Q = ValidityMonitor(R)._edges
    yield "edge lines beyond ends", R, np.vstack([P + 2 * (Q - P), Q + 3 * (Q - P),
                                                   P - (Q - P)])
    yield "integer circle scaled", R, R * (1 + 1e-9)


SETUPS = list(_setups())


@pytest.mark.parametrize("i", range(len(SETUPS)), ids=[s[0] for s in SETUPS])
def test_nearest_edges_are_the_edge_distances_bit_for_bit(i):
    """Every row the tree answers gets the float of the O(N·h) path: edge_distances,
    bit for bit, proven outside by a facet and edge_error finite (the old path's
    condition); the rows left out are exactly those it would not answer fast or
    the guess could not prove outside — none for states well outside a circle or on
    the edges' lines beyond their ends."""
    name, X0, S = SETUPS[i]
    mon = ValidityMonitor(X0)
    assert mon._edge_tree is not None
    fast, dist = mon._nearest_edges(S)
    want, err = mon.edge_distances(S[fast])
    assert np.array_equal(dist[fast], want)
    assert mon._surely_outside(S[fast]).all() and np.isfinite(err).all()
    assert (want > 0).all()
    if name in ("circle just outside", "circle far", "edge lines beyond ends"):
        assert fast.all()


def test_outside_guess_never_claims_an_inside_state():
    """The cone facet's filter says "outside" only for states outside (exact test)."""
    X = np.round(_circle(300) * 1e3)
    mon = ValidityMonitor(X)
    S = np.random.default_rng(2).integers(-1100, 1100, (3000, 2)).astype(float)
    out = mon._outside_guess(S)[0]
    assert out.any()
    assert not any(mon.hull.contains(x) for x in S[out])


def test_no_n_by_h_work_outside_a_10000_gon(monkeypatch):
    """V13: 10 000 states just outside a 10 000-gon took 11.5 CPU-s per step (slacks of
    every state against every facet, twice, and edge_distances against every edge:
    3·10⁸ pairs). Now the facet slacks and the edge distances touch O(N log h) pairs
    (spy on both); the distances are those of the old path (edge_distances on a
    sample)."""
    X0 = _circle(10_000)
    mon = ValidityMonitor(X0)
    S = X0 * (1 + 2.0**-20)
    pairs, seen = [], set()
    real_slacks, real_edges = _validity_monitor._slacks, _validity_monitor._edge_float
    monkeypatch.setattr(_validity_monitor, "_slacks", lambda A, b, X: seen.add("slacks") or
                        pairs.append(len(A) * len(X)) or real_slacks(A, b, X))
    monkeypatch.setattr(_validity_monitor, "_edge_float", lambda X, P, Q: seen.add("edges") or
                        pairs.append(np.broadcast_shapes(X.shape, P.shape)[:-1])
                        or real_edges(X, P, Q))
    got = mon.distances(S)
    assert seen == {"slacks", "edges"}  # the spies sit where the monitor looks them up
    total = sum(int(np.prod(p)) for p in pairs)
    assert total < 200 * len(S), total
    sample = np.arange(0, 10_000, 97)
    assert np.array_equal(got[sample], mon.edge_distances(S[sample])[0])


def _initial_and_states(rng, d: int, kind: str, m: int):
    """70 initial rows at m distinct points of ``kind`` (:func:`_few_points`) at a
    random magnitude 1e-300 … 1e300, and states: inside, a few ulps off, on a line
    through two of the points beyond them, far outside and at other magnitudes."""
    scale = 1.0 if kind == "subnormal" else float(
        rng.choice([1e-300, 2.0**-1000, 1e-5, 1.0, 1e100, 1e300]))
    B = _few_points(rng, d, kind, m) * scale
    X0 = B[np.r_[np.arange(m), rng.integers(0, m, 70 - m)]]
    i, j = rng.integers(0, m, 2)
    S = np.vstack([rng.dirichlet(np.ones(m), size=2) @ B,
                   B[rng.integers(0, m, 3)] * rng.uniform(0.5, 1.5, (3, 1)),
                   B[i] + 2 * (B[j] - B[i]), 2 * B[i] - B[j],
                   rng.standard_normal((3, d)) * scale,
                   B[:1] + np.spacing(B[:1]) * rng.integers(-2, 3, (1, d)),
                   rng.standard_normal((1, d)) * float(rng.choice([1e-320, 1e-300, 1e300]))])
    return X0, S[np.isfinite(S).all(axis=1)]


@pytest.mark.parametrize("seed", range(24))
def test_small_polygons_through_the_tree_agree_with_brute_force(monkeypatch, seed):
    """The tree forced on small polygons (INNER_FACETS = 3): 70 initial rows at 6–12
    distinct points — general, a few ulps apart, subnormal, collinear (flat: no tree)
    — at 1e-300 … 1e300; states inside, a few ulps off, on an edge's line beyond its
    end, far outside and at other magnitudes: every distance as the Fractions brute
    force (0 iff inside, else within the fast bound)."""
    monkeypatch.setattr(_validity_monitor, "INNER_FACETS", 3)
    rng = np.random.default_rng(seed)
    X0, S = _initial_and_states(rng, 2, ("gauss", "ulps", "subnormal", "line")[seed % 4],
                                int(rng.integers(6, 13)))
    mon = ValidityMonitor(X0)
    if mon._edge_tree is not None:
        fast, dist = mon._nearest_edges(S)
        assert np.array_equal(dist[fast], mon.edge_distances(S[fast])[0])
    got = mon.distances(S)
    M = np.abs(X0).max()
    for g, x in zip(got, S):
        want = _distance(X0, x)
        assert _close(g, want, max(M, np.abs(x).max())), (g, want, x)


# --------------------------------------------------------------------------- #
# monitor_names
# --------------------------------------------------------------------------- #


def test_monitor_names_refuses_bytes_naming_them():
    """b"spread" was iterated as integer codes: "unknown name(s) 100, 101, …"."""
    with pytest.raises(InputError, match=r"metrics must be .*got b'spread'") as info:
        monitor_names(b"spread")
    assert "100" not in str(info.value)


def test_monitor_names_reads_the_cli_comma_form():
    """ "validity,spread" was one unknown name; the CLI splits on commas, and the API
    (which the CLI is a thin layer over) reads the same form."""
    assert monitor_names("validity,spread") == ("spread", "validity")
    assert monitor_names(" diameter , validity ") == ("diameter", "validity")
    assert monitor_names(["spread", "diameter,validity"]) == metrics.MONITORS
    with pytest.raises(InputError, match="unknown name.*'bogus'"):
        monitor_names("validity,bogus")
    with pytest.raises(InputError, match="names no monitor"):
        monitor_names(" , ")
    with pytest.raises(InputError, match="metrics must be"):
        monitor_names(["spread", 3])


# --------------------------------------------------------------------------- #
# R³: the tree of triangle boxes
# --------------------------------------------------------------------------- #


def _setups3():
    """(name, initial states, states) in R³: a sphere of 800 points (~1600
    triangles), a 1e-8-flat ellipsoid (at 1e90 too), a cylinder, a cube of grid points
    (coplanar corners on each face), and states just outside, far, mixed, at 1e99."""
    rng = np.random.default_rng(7)
    X = _circle(800, 3)
    yield "sphere just outside", X, X * (1 + 2.0**-20)
    yield "sphere far", X, X * 1e3 + rng.standard_normal(X.shape)
    yield "sphere mixed", X, rng.standard_normal((800, 3)) * 1.2
    yield "sphere 1e99", X, X * 1e99
    E = X * [1e-8, 1.0, 1.0]
    yield "flat ellipsoid", E, rng.standard_normal((800, 3))
    yield "flat ellipsoid 1e90", E * 1e90, rng.standard_normal((800, 3)) * 1e90
    t = rng.uniform(0, 2 * np.pi, 800)
    yield "cylinder", np.c_[np.cos(t), np.sin(t), rng.choice([-1.0, 1.0], 800)], \
        rng.standard_normal((800, 3)) * 2
    G = rng.integers(-5, 6, (1500, 3)).astype(float)
    yield "grid cube", G, rng.integers(-8, 9, (800, 3)).astype(float)
    yield "grid cube faces", G, rng.integers(-8, 9, (800, 3)) * 1e-3 + 5


SETUPS3 = list(_setups3())


@pytest.mark.parametrize("i", range(len(SETUPS3)), ids=[s[0] for s in SETUPS3])
def test_nearest_triangles_are_triangle_distances_bit_for_bit(i):
    """The rows the tree settles get triangle_distances' δ bit for bit and its verdict
    (δ > bound: fast, else the exact path), proven outside by a facet as
    _surely_outside proves them; distances() equals the dense path's (the tree off)."""
    name, X0, S = SETUPS3[i]
    mon = ValidityMonitor(X0)
    assert mon._tri_tree is not None
    fast, known, dist = mon._nearest_triangles(S)
    want, err = mon.triangle_distances(S[known])
    assert np.array_equal(dist[known], want)
    assert np.array_equal(fast[known], want > err)
    assert mon._surely_outside(S[known]).all()
    if name in ("sphere just outside", "sphere far"):
        assert fast.all()
    if "1e90" not in name:  # exact projections of ~500 states: slow
        got = mon.distances(S)
        mon._tri_tree = None
        assert np.array_equal(got, mon.distances(S))


def test_no_n_by_t_work_outside_a_sphere(monkeypatch):
    """V13: 1000 states just outside the hull of 1000 points on a sphere (~2000
    triangles) took ~0.8 CPU-s per step (every state against every triangle). Now
    O(log T) closest-point evaluations per state (spy; the dense path takes 2·10⁶)."""
    X0 = _circle(1000, 3)
    mon = ValidityMonitor(X0)
    S = X0 * (1 + 2.0**-20)
    pairs = []
    real = _distance_trees._closest_points
    for module in (_validity_monitor, _distance_trees):  # the tree's and the dense path's
        monkeypatch.setattr(module, "_closest_points", lambda x, A, B, C: pairs.append(
            np.broadcast_shapes(x.shape, A.shape)[:-1]) or real(x, A, B, C))
    got = mon.distances(S)
    assert pairs  # the spy is where the monitor looks it up
    assert sum(int(np.prod(p)) for p in pairs) < 200 * len(S), pairs
    assert (got > 0).all()


@pytest.mark.parametrize("seed", range(12))
def test_small_polytopes_through_the_tree_agree_with_brute_force(seed):
    """70 initial rows at 4–9 distinct points in R³ (past PROPOSE_MIN: the certified
    surface and its tree) — general, a few ulps apart, subnormal — at 1e-300 … 1e300;
    states inside, a few ulps off, on a line through two corners beyond them, far
    outside and at other magnitudes: every distance as the Fractions brute force."""
    rng = np.random.default_rng(100 + seed)
    X0, S = _initial_and_states(rng, 3, ("gauss", "ulps", "subnormal")[seed % 3],
                                int(rng.integers(4, 10)))
    mon = ValidityMonitor(X0)
    if mon._tri_tree is not None:
        fast, known, dist = mon._nearest_triangles(S)
        want, err = mon.triangle_distances(S[known])
        assert np.array_equal(dist[known], want) and np.array_equal(fast[known], want > err)
    got = mon.distances(S)
    M = np.abs(X0).max()
    for g, x in zip(got, S):
        want = _distance(X0, x)
        assert _close(g, want, max(M, np.abs(x).max())), (g, want, x)
