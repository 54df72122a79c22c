"""The validity monitor's benign hull when the initial states are all hull vertices
(issue 13 §1): in the plane the hull comes from an exact monotone chain, not from the
O(n³) safe kernel of its vertices (10 000 states on a circle were refused)."""

from __future__ import annotations

from fractions import Fraction
from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rescon import check_certificate
from rescon.consensus import _initial_hull
from rescon.consensus.metrics import ValidityMonitor, certified_hull
from rescon.errors import InputError
from rescon.geometry.kernel import safe_kernel


def _facet_set(hull) -> set:
    """The exact facets a·x ≤ β, each scaled to max|a_j| = 1 (a unique form)."""
    return {(tuple(v / top for v in a), beta / top)
            for a, beta in hull._exact.facets for top in (max(map(abs, a)),)}


def _circle(n: int, radius: float = 1.0) -> np.ndarray:
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    return np.c_[np.cos(t), np.sin(t)] * radius


@st.composite
def planar_sets(draw) -> np.ndarray:
    """Small planar sets: random, on a small grid (collinear runs, duplicates), on a
    line, one repeated point; scaled by 1, 1e-300 or 1e300."""
    n = draw(st.integers(1, 30))
    seed = draw(st.integers(0, 2**32 - 1))
    kind = draw(st.sampled_from(["normal", "grid", "line", "point"]))
    rng = np.random.default_rng(seed)
    if kind == "normal":
        X = rng.normal(size=(n, 2))
    elif kind == "grid":
        X = rng.integers(-3, 4, size=(n, 2)).astype(float)
    elif kind == "line":
        X = np.outer(rng.integers(-9, 10, size=n), rng.integers(-3, 4, size=2)).astype(float)
    else:
        X = np.repeat(rng.normal(size=(1, 2)), n, axis=0)
    return X * draw(st.sampled_from([1.0, 1e-300, 1e300]))


@settings(max_examples=60, deadline=None)
@given(planar_sets(), st.integers(0, 3))
def test_chain_hull_is_the_exact_hull(X, seed):
    """The monotone-chain hull is the exact polytope safe_kernel(X, 0): dimension,
    exact vertices, exact facets, exact membership and a valid certificate."""
    assert_is_the_exact_hull(_initial_hull._exact_polygon, X, seed)


def assert_is_the_exact_hull(build, X: np.ndarray, seed: int) -> None:
    """``build(X)`` is the exact polytope safe_kernel(X, 0): dimension, exact vertices,
    exact facets, exact membership of X and of scaled copies of its points, and a
    certificate the checker accepts — or both refuse (a facet's float row overflows)."""
    try:
        exact = safe_kernel(X, 0)
    except InputError:  # a facet's float row overflows (1e300): both refuse alike
        with pytest.raises(InputError):
            build(X)
        return
    hull = build(X)
    assert hull is not None
    assert hull.dim == exact.dim
    assert hull.exact_vertices == exact.exact_vertices
    assert np.array_equal(hull.vertices, exact.vertices)
    assert _facet_set(hull) == _facet_set(exact)
    rng = np.random.default_rng(seed)
    S = np.r_[X, X[rng.integers(0, len(X), 8)] * rng.choice([0.5, 1.0, 1.5], size=(8, 1))]
    assert [hull.contains(x) for x in S] == [exact.contains(x) for x in S]
    assert check_certificate(hull.certificate).valid


def test_circle_is_not_refused():
    """10 000 and 2000 states on a circle (all hull vertices): no safe kernel of the
    vertices (it refused 10 000: ~5.6e9 steps; 2000 took 45 s), the exact polygon of
    every point, initial states at distance 0, states outside at their distance."""
    for n in (10_000, 2000):
        X = _circle(n)
        with mock.patch.object(_initial_hull, "safe_kernel", side_effect=AssertionError("kernel")):
            mon = ValidityMonitor(X)
        assert mon.hull.dim == 2 and len(mon.hull.exact_vertices) == n
        assert set(mon.hull.exact_vertices) == {tuple(map(Fraction, x)) for x in X.tolist()}
        assert (mon.distances(X) == 0).all()
        out = X[::997] * 1.001
        dist = mon.distances(out)
        assert (dist > 0).all()
        assert (mon.distances(X * 0.999) == 0).all()
    exact = np.array([mon.distance(x) for x in out])  # the 2000-gon's exact projections
    assert np.all(np.abs(dist - exact) <= mon.edge_error(out))


def test_circle_certificate_checks():
    """The certificate of a 300-gon (facets, adjacency of the cycle) passes the checker."""
    result = check_certificate(certified_hull(_circle(300, 1e-200)).certificate)
    assert result.valid and not result.unchecked


@pytest.mark.parametrize("seed", range(3))
def test_validity_distances_unchanged(seed):
    """Distances of random states to the hull of 150 initial states (random, grid with
    collinear runs and duplicates, circle): equal to those of the monitor built from
    the safe kernel of every initial state (the path before): zero for the same states,
    the others within the certified edge error (the float edge distance may take an
    edge's ends in the other order)."""
    rng = np.random.default_rng(seed)
    for X in (rng.normal(size=(150, 2)), rng.integers(0, 6, size=(150, 2)).astype(float),
              _circle(150, 10.0 ** rng.integers(-30, 30))):
        S = X[rng.integers(0, len(X), 80)] * rng.choice([0.3, 0.99, 1.0, 1.01, 2.0],
                                                        size=(80, 1))
        new = ValidityMonitor(X)
        with mock.patch.object(_initial_hull, "PROPOSE_MIN", 10**9):
            old = ValidityMonitor(X)
        assert _facet_set(new.hull) == _facet_set(old.hull)
        dist, before = new.distances(S), old.distances(S)
        assert np.array_equal(dist == 0, before == 0)
        assert np.all(np.abs(dist - before) <= 2 * new.edge_error(S))


@pytest.mark.parametrize("scale", [1.0, 1e-120, 1e120])
def test_fan_filter_is_sound(scale):
    """States near the boundary of a 300-gon (past the inner polygon): every state the
    fan filter proves inside is in the hull (exact), and it proves nearly every state
    clearly inside (no h-facet test per state: the 10 000-gon's 0.34 s per step)."""
    rng = np.random.default_rng(7)
    X = _circle(300, scale) * rng.uniform(0.999, 1.0, size=(300, 1))
    mon = ValidityMonitor(X)
    S = X[rng.integers(0, 300, 400)] * rng.uniform(0.99, 1.01, size=(400, 1))
    fan = mon._in_fan(S)
    assert all(mon.hull.contains(x) for x in S[fan])
    inside = np.array([mon.hull.contains(x) for x in S])
    assert fan.sum() >= 0.9 * inside.sum()
    assert np.array_equal(mon.distances(S) == 0, inside)
