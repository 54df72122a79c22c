"""The monitors at the hostile edges of issue 13 §1: initial states that are all hull
vertices. In R³ the benign hull comes from Qhull's triangulated boundary certified
exactly (1000 states on a sphere were refused: ~1.7e11 kernel steps); in the plane the
diameter of states on a circle takes its centre from an exact rotating-calipers pair
(10 000 random states on a circle compared all pairs, ~2-5 s per step)."""

from __future__ import annotations

import math
from fractions import Fraction
from unittest import mock

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from rescon.consensus import _hull_surface, _initial_hull, metrics
from rescon.consensus.metrics import ValidityMonitor, certified_hull, diameter
from rescon.geometry.exact import exact_points
from rescon.geometry.kernel import safe_kernel
from tests.test_hull_vertices import _facet_set, assert_is_the_exact_hull


def _sphere(n: int, radius: float = 1.0, seed: int = 0) -> np.ndarray:
    X = np.random.default_rng(seed).normal(size=(n, 3))
    return X / np.linalg.norm(X, axis=1)[:, None] * radius




@st.composite
def spatial_sets(draw) -> np.ndarray:
    """Small sets in R³: random, on a sphere, on a small grid (coplanar facets, points
    inside facets and edges, duplicates), a cube's corners and points on its faces;
    scaled by 1, 1e-300, 1e300 or 2^-1000."""
    n = draw(st.integers(5, 40))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    kind = draw(st.sampled_from(["normal", "sphere", "grid", "cube"]))
    if kind == "normal":
        X = rng.normal(size=(n, 3))
    elif kind == "sphere":
        X = _sphere(n, seed=int(rng.integers(2**31)))
    elif kind == "grid":
        X = rng.integers(-2, 3, size=(n, 3)).astype(float)
    else:
        corners = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)])
        faces = rng.integers(0, 2, size=(n, 3)) * rng.choice([0.0, 0.5, 1.0], size=(n, 3))
        X = np.r_[corners, faces].astype(float)
    return X * draw(st.sampled_from([1.0, 1e-300, 1e300, 2.0**-1000]))


@settings(max_examples=50, deadline=None)
@given(spatial_sets(), st.integers(0, 3))
def test_certified_surface_hull_is_the_exact_hull(X, seed):
    """The certified-surface hull is the exact polytope safe_kernel(X, 0): exact vertices,
    exact facets, exact membership, a certificate the checker accepts (or both refuse
    a facet whose float row overflows). A flat X (the grid kind can draw 5 coplanar
    points) gets None, as documented, and ``certified_hull`` leaves it to safe_kernel —
    which the clean-clone CI of b681b37 drew: the test asserted a surface hull."""
    assert_is_the_exact_hull(_surface_or_flat, X, seed)


def _surface_or_flat(X: np.ndarray):
    """_exact_polytope(X); where it is None, X must be flat, and then certified_hull's
    answer (safe_kernel's path) is the one compared."""
    hull = _initial_hull._exact_polytope(X)
    if hull is None:
        assert safe_kernel(X, 0).dim < 3
        hull = certified_hull(X)
    return hull


def test_a_flat_spatial_set_is_left_to_the_kernel():
    """The set the CI drew (5 coplanar grid points): no surface hull, the exact one from
    certified_hull."""
    X = np.array([[0.0, 1.0, 0.0], [1.0, -1.0, -1.0], [-2.0, -1.0, 2.0], [-1.0, -1.0, 1.0],
                  [-2.0, -2.0, 2.0]])
    assert _initial_hull._exact_polytope(X) is None
    assert certified_hull(X).exact_vertices == safe_kernel(X, 0).exact_vertices


def test_flat_sets_are_left_to_the_kernel():
    """Coplanar states (no 3-D surface to certify) take the former path, same hull."""
    rng = np.random.default_rng(1)
    X = np.c_[rng.normal(size=(200, 2)), np.full(200, 3.0)]
    assert _initial_hull._exact_polytope(X) is None
    hull = certified_hull(X)
    assert hull.dim == 2 and _facet_set(hull) == _facet_set(safe_kernel(X[
        _initial_hull._proposed_rows(X)], 0))


def _surface(U: np.ndarray) -> np.ndarray:
    return ConvexHull(U).simplices


def test_certification_refuses_wrong_surfaces():
    """Each condition of _certified_surface rejects a surface that breaks it: a missing
    triangle (not closed), a dent (a corner pushed inwards: not locally convex), two
    nested tetrahedra (closed, convex, o inside both: the ray meets two), a row left
    outside (the hull of all but it); the true hull passes."""
    U = np.unique(_sphere(60, seed=3), axis=0)
    T = _surface(U)
    assert _hull_surface._certified_surface(U, T) is not None
    assert _hull_surface._certified_surface(U, T[1:]) is None
    dented = U.copy()
    dented[T[0, 0]] *= 0.9
    assert _hull_surface._certified_surface(dented, T) is None
    cube = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)], float)
    outer = np.array([[3.0, 3, 3], [3, -3, -3], [-3, 3, -3], [-3, -3, 3]])
    nested = np.unique(np.r_[outer, outer / 3.0], axis=0)
    first = [np.flatnonzero((nested == r).all(axis=1))[0] for r in outer]
    second = [np.flatnonzero((nested == r / 3.0).all(axis=1))[0] for r in outer]
    tets = np.array([[q[i] for i in face] for q in (first, second)
                     for face in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3))])
    assert _hull_surface._certified_surface(nested, tets) is None
    U2 = np.unique(np.r_[cube, [[0.0, 0.0, 5.0]]], axis=0)
    far = np.flatnonzero((U2 == [0.0, 0.0, 5.0]).all(axis=1))[0]
    keep = np.delete(np.arange(len(U2)), far)
    partial = keep[_surface(U2[keep])]
    assert _hull_surface._certified_surface(U2, partial) is None


@pytest.mark.parametrize("n", [1000, pytest.param(10_000, marks=pytest.mark.slow)])
def test_sphere_is_not_refused(n):
    """1000 and 10 000 states on a sphere (all hull vertices): no safe kernel (1000 was
    refused), initial states at distance 0 without an exact test, states inside
    proven by the cone filter, states outside at their distance."""
    X = _sphere(n)
    with mock.patch.object(_initial_hull, "safe_kernel", side_effect=AssertionError("kernel")):
        mon = ValidityMonitor(X)
    assert mon.hull.dim == 3 and len(mon.hull.exact_vertices) == n
    assert set(mon.hull.exact_vertices) == {tuple(map(Fraction, x)) for x in X.tolist()}
    with mock.patch.object(mon, "distance", side_effect=AssertionError("exact")):
        assert (mon.distances(X) == 0).all()
        assert (mon.distances(X * 0.99) == 0).all()
    assert mon._in_cones(_sphere(n, 0.98, seed=9)).all()  # no per-facet test
    out = X[:: n // 4] * 1.01
    dist = mon.distances(out)
    assert (dist > 0).all()
    exact = np.array([mon.distance(x) for x in out])
    _, err = mon.triangle_distances(out)
    assert np.all(np.abs(dist - exact) <= err)


@pytest.mark.parametrize("scale", [1.0, 1e-120, 1e120, 1e-300, 1e300])
def test_cone_filter_is_sound(scale):
    """States near the boundary of a 300-vertex polytope at every magnitude: every
    state the cone filter proves inside is in the hull (exact), and it proves nearly
    every state clearly inside."""
    rng = np.random.default_rng(5)
    X = _sphere(300, scale) * rng.uniform(0.999, 1.0, size=(300, 1))
    mon = ValidityMonitor(X)
    assert mon._cones is not None
    S = X[rng.integers(0, 300, 150)] * rng.uniform(0.99, 1.01, size=(150, 1))
    cone = mon._in_cones(S)
    assert all(mon.hull.contains(x) for x in S[cone])
    deep = S[rng.integers(0, 150, 100)] * 0.5
    assert mon._in_cones(deep).all()


@pytest.mark.parametrize("seed", range(2))
def test_validity_distances_unchanged_in_space(seed):
    """Distances of random states to the hull of 150 initial states (random, sphere,
    grid with coplanar facets and duplicates): equal to those of the monitor built from
    the safe kernel of every initial state (the path before)."""
    rng = np.random.default_rng(seed)
    for X in (rng.normal(size=(150, 3)), _sphere(150, 10.0 ** rng.integers(-30, 30)),
              rng.integers(0, 4, size=(150, 3)).astype(float)):
        S = X[rng.integers(0, len(X), 60)] * rng.choice([0.3, 0.99, 1.0, 1.01, 2.0],
                                                        size=(60, 1))
        new = ValidityMonitor(X)
        with mock.patch.object(_initial_hull, "PROPOSE_MIN", 10**9):
            old = ValidityMonitor(X)
        assert _facet_set(new.hull) == _facet_set(old.hull)
        dist, before = new.distances(S), old.distances(S)
        assert np.array_equal(dist == 0, before == 0)
        _, err = new.triangle_distances(S)
        _, err_old = old.triangle_distances(S)
        far = dist > 0
        assert np.all(np.abs(dist - before)[far] <= (err + err_old)[far])


def _circle(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = rng.uniform(0.0, 2.0 * np.pi, n)
    return np.c_[np.cos(t), np.sin(t)] * 3.0 + [1.0, 2.0]


@pytest.mark.slow
def test_random_circle_diameter_compares_few_pairs():
    """10 000 random states on a circle: the windows about the mean (off the circle's
    centre by ~1e-3 of the radius) took every pair (~2-5 s); about the calipers'
    diametral midpoint a few pairs per state, the same float as all pairs."""
    X = _circle(10_000, 0)
    every_pair = metrics._pairwise_max(X, X)
    with mock.patch.object(metrics, "_pairwise_max", side_effect=AssertionError("n²")):
        assert diameter(X) == every_pair


def _exact_sq_diameter(X: np.ndarray) -> Fraction:
    P = exact_points(X)
    best = max(sum((a - b) ** 2 for a, b in zip(p, q)) for p in P.ints for q in P.ints)
    return Fraction(best, P.scale**2)


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 60), st.integers(0, 2**32 - 1),
       st.sampled_from(["circle", "grid", "line", "point", "polygon"]),
       st.sampled_from([1.0, 1e-300, 1e300, 2.0**-900]))
def test_caliper_pair_is_diametral(n, seed, kind, scale):
    """The calipers' pair is at the exact diameter (brute force over all pairs, exact
    integers): random points on a circle, a small grid (collinear runs, parallel
    edges), a line, one point, a regular polygon (many equal antipodal pairs)."""
    rng = np.random.default_rng(seed)
    if kind == "circle":
        X = _circle(n, seed)
    elif kind == "grid":
        X = rng.integers(-3, 4, size=(n, 2)).astype(float)
    elif kind == "line":
        X = np.outer(rng.integers(-9, 10, size=n), [1.0, 3.0])
    elif kind == "point":
        X = np.ones((n, 2))
    else:
        t = 2 * np.pi * np.arange(n) / n
        X = np.c_[np.cos(t), np.sin(t)]
    K = np.unique(X * scale, axis=0)
    i, j = metrics._caliper_pair(K)
    P = exact_points(K)
    pair = sum((a - b) ** 2 for a, b in zip(P.ints[i], P.ints[j]))
    assert Fraction(pair, P.scale**2) == _exact_sq_diameter(K)


@settings(max_examples=40, deadline=None)
@given(st.integers(3, 40), st.integers(0, 2**32 - 1),
       st.sampled_from([1.0, 1e-300, 1e300]))
def test_caliper_diameter_is_the_float_of_all_pairs(n, seed, scale):
    """The plane's diameter through the calipers (forced, ANGULAR_MIN = 0) equals the
    all-pairs float on circles with noise, at every magnitude (1e300: both scaled)."""
    rng = np.random.default_rng(seed)
    X = (_circle(n, seed) + rng.normal(size=(n, 2)) * 10.0 ** -rng.integers(3, 16)) * scale
    top = np.abs(X).max()
    e = int(np.frexp(top)[1])
    Y = np.ldexp(X, -e)
    with mock.patch.object(metrics, "ANGULAR_MIN", 0):
        D = diameter(X)
    assert D == math.ldexp(metrics._pairwise_max(Y, Y), e)


@pytest.mark.parametrize("scale", [1e-300, 1e300, 2.0**-1000])
def test_monitor_at_every_magnitude(scale):
    """Initial states on a sphere (with duplicates) at 1e-300, 1e300 and 2^-1000;
    states converged to one point (the centre, or beside a vertex), repeated initial
    states and states outside: the same zeros and distances as the monitor built from
    the safe kernel of every initial state (beyond 1e±100 both take the exact
    projection)."""
    X = _sphere(120, scale, seed=2)
    X = np.r_[X, X[:30]]
    new = ValidityMonitor(X)
    with mock.patch.object(_initial_hull, "PROPOSE_MIN", 10**9):
        old = ValidityMonitor(X)
    assert _facet_set(new.hull) == _facet_set(old.hull)
    S = np.r_[np.zeros((4, 3)), np.repeat(X[:1] * 0.999, 4, axis=0), X[::7] * 1.5, X[40:60]]
    dist = new.distances(S)
    assert np.array_equal(dist, old.distances(S))
    assert np.array_equal(dist == 0, np.array([new.hull.contains(x) for x in S]))


def test_fallback_in_space_still_corrects_its_proposal():
    """When no surface is certified (here forced), R³ falls back to the safe kernel of
    Qhull's vertices, completed by the exact certification (a proposal of 4 rows)."""
    X = np.random.default_rng(4).normal(size=(120, 3))
    with mock.patch.object(_initial_hull, "_exact_polytope", return_value=None), \
            mock.patch.object(_initial_hull, "_proposed_rows", lambda X: np.arange(4)):
        hull = certified_hull(X)
    assert "cones" not in hull._cache
    assert _facet_set(hull) == _facet_set(_initial_hull._exact_polytope(X))
