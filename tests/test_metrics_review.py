"""Hostile review of the engine's monitors (issue 13 §1): validity distances and the
diameter against an independent exact brute force (Fractions: a state is in the hull
iff it is in the hull of d + 1 initial states (Carathéodory); outside, its distance is
the least distance to a segment / triangle of initial states)."""

from __future__ import annotations

import math
from fractions import Fraction
from itertools import combinations, combinations_with_replacement

import numpy as np
import pytest
from conftest import solve_exact
from hypothesis import example, given, settings
from hypothesis import strategies as st

from rescon.consensus.metrics import ValidityMonitor, diameter


def _in_hull(P, x) -> bool:
    d = len(x)
    for k in range(1, d + 2):
        for T in combinations(P, k):
            lam = solve_exact([[p[j] for p in T] for j in range(d)] + [[1] * k], list(x) + [1])
            if lam is not None and min(lam) >= 0:
                return True
    return False


def _seg2(x, p, q):
    e = [b - a for a, b in zip(p, q)]
    w = [a - b for a, b in zip(x, p)]
    ee = sum(t * t for t in e)
    t = 0 if ee == 0 else min(Fraction(1), max(Fraction(0), sum(map(
        lambda a, b: a * b, w, e)) / ee))
    return sum((a - t * b) ** 2 for a, b in zip(w, e))


def _tri2(x, a, b, c):
    e0, e1 = [q - p for p, q in zip(a, b)], [q - p for p, q in zip(a, c)]
    w = [q - p for p, q in zip(a, x)]
    g00, g01, g11 = (sum(i * j for i, j in zip(u, v)) for u, v in ((e0, e0), (e0, e1), (e1, e1)))
    r0, r1 = sum(i * j for i, j in zip(e0, w)), sum(i * j for i, j in zip(e1, w))
    best = min(_seg2(x, a, b), _seg2(x, a, c), _seg2(x, b, c))
    det = g00 * g11 - g01 * g01
    if det:
        s, t = (r0 * g11 - r1 * g01) / det, (g00 * r1 - g01 * r0) / det
        if s >= 0 and t >= 0 and s + t <= 1:
            best = min(best, sum((xi - ai - s * u - t * v) ** 2
                                 for xi, ai, u, v in zip(x, a, e0, e1)))
    return best


def exact_distance(initial: np.ndarray, x: np.ndarray) -> float:
    """dist(x, conv initial) (d = 2, 3) as the float nearest its exact value (0 iff in)."""
    P = [[Fraction(t) for t in p] for p in initial]
    xq = [Fraction(t) for t in x]
    if _in_hull(P, xq):
        return 0.0
    if len(xq) == 2:
        sq = min(_seg2(xq, p, q) for p, q in combinations_with_replacement(P, 2))
    else:
        sq = min(_tri2(xq, *t) for t in combinations_with_replacement(P, 3))
    e = (sq.numerator.bit_length() - sq.denominator.bit_length()) // 2
    return math.ldexp(math.sqrt(float(sq / Fraction(4) ** e)), e)


def _agrees(got: float, want: float, bound: float = 0.0) -> bool:
    """Equal zeros, or within 1e-14 relative (two subnormal steps below 1e-308) plus
    ``bound``, the monitor's documented absolute error of its fast distances."""
    return got == want == 0 or (want > 0 and
                                abs(got - want) <= 1e-14 * want + 2**-1073 + bound)


def test_state_just_outside_a_flat_hull_is_not_at_distance_zero():
    """The exact projection y of a state outside a segment rounded to the state itself,
    so x − fl(y) was 0: 'distance 0 exactly when inside' was broken (8e-22 at 1e-5)."""
    X0 = np.array([[2.5e-05, -5e-06], [-3.5000000000000004e-05, 2.5e-05]])
    x = np.array([-5.000000000000001e-06, 1e-05])
    mon = ValidityMonitor(X0)
    want = exact_distance(X0, x)
    assert want > 0
    assert _agrees(mon.distance(x), want)
    assert _agrees(mon.distances(x[None])[0], want)


@pytest.mark.parametrize("scale", [1e-300, 1e-150, 1e-5, 1.0, 1e5, 1e150, 1e300])
@pytest.mark.parametrize("d", [2, 3])
def test_float_mean_of_a_flat_hull_at_every_magnitude(scale, d):
    """The float mean of coplanar / collinear initial states is generally just off their
    plane: its distance is tiny but not 0."""
    rng = np.random.default_rng(d)
    Y = rng.integers(-3, 4, (6, d - 1)).astype(float)
    X0 = np.c_[Y, Y @ rng.integers(1, 3, d - 1) / 3] * scale
    S = np.vstack([X0.mean(axis=0), X0[:3] * 0.7, X0[:1] * (1 + 1e-9)])
    got = ValidityMonitor(X0).distances(S)
    for g, x in zip(got, S):
        assert _agrees(g, exact_distance(X0, x)), (g, exact_distance(X0, x), x)


@settings(max_examples=30, deadline=None)
@example(seed=113155, d=3, kind="gauss", scale=1e-05)  # a triangle distance 6 ulps off
@given(seed=st.integers(0, 10**6), d=st.sampled_from([2, 3]),
       kind=st.sampled_from(["gauss", "int", "flat", "dup", "same"]),
       scale=st.sampled_from([1e-300, 1e-5, 1.0, 1e150, 1e300]))
def test_validity_distances_agree_with_brute_force(seed, d, kind, scale):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 7))
    if kind == "gauss":
        X0 = rng.standard_normal((n, d))
    elif kind == "int":
        X0 = rng.integers(-3, 4, (n, d)).astype(float)
    elif kind == "flat":
        Y = rng.integers(-3, 4, (n, d - 1)).astype(float)
        X0 = np.c_[Y, Y @ rng.integers(-2, 3, d - 1) / 3]
    elif kind == "dup":
        X0 = np.repeat(rng.standard_normal((max(1, n // 2), d)), 2, axis=0)
    else:
        X0 = np.tile(rng.standard_normal(d), (n, 1))
    X0 = X0 * scale
    S = np.vstack([X0[rng.integers(0, len(X0), 2)] * rng.uniform(0.5, 1.5, (2, 1)),
                   rng.standard_normal((2, d)) * scale, X0.mean(axis=0, keepdims=True)])
    mon = ValidityMonitor(X0)
    got = mon.distances(S)
    # fast edge / triangle distances are within their documented absolute bounds
    # (ValidityMonitor.edge_error for polygons, triangle_distances' error in R³);
    # elsewhere the exact one rounded
    if mon._edges is not None:
        err = mon.edge_error(S)
    elif mon._triangles is not None:
        err = mon.triangle_distances(S)[1]
    else:
        err = np.zeros(len(S))
    for g, x, e in zip(got, S, err):
        want = exact_distance(X0, x)
        assert (g == 0) == (want == 0), (g, want, x)  # 0 exactly when inside
        assert _agrees(g, want, e if np.isfinite(e) else 0.0), (g, want, x)


def _exact_diameter(X: np.ndarray) -> float:
    P = [[Fraction(t) for t in p] for p in X]
    sq = max(sum((a - b) ** 2 for a, b in zip(p, q)) for p in P for q in P)
    if sq == 0:
        return 0.0
    e = (sq.numerator.bit_length() - sq.denominator.bit_length()) // 2
    return math.ldexp(math.sqrt(float(sq / Fraction(4) ** e)), e)


@pytest.mark.parametrize("rows", [
    [[1.0, 1e-200], [1.0, 2e-200]],
    [[0.3, 1e-200], [0.3, 2e-200], [0.3, 3e-200]],
    [[0.3, -1.7, 5e-170], [0.3, -1.7, -5e-170], [0.3, -1.7, 0.0]],
    [[1e300, 1e-300], [1e300, 0.0]],
])
def test_diameter_of_tiny_differences_beside_large_coordinates(rows):
    """Rows equal but in a coordinate ~1e-200 (states converging along one axis): the
    squares of the differences underflowed and the diameter was 0."""
    X = np.array(rows)
    assert _agrees(diameter(X), _exact_diameter(X))


@pytest.mark.parametrize(("n", "d"), [(10000, 2), (3000, 3)])
def test_diameter_of_identical_rows_compares_no_pairs(monkeypatch, n, d):
    """Converged (bit-identical) states: their float mean is off by a rounding, so they
    did not count as converged and all n² pairs were compared (5 s at N = 10 000 in the
    plane, every step of a converged run)."""
    from rescon.consensus import metrics

    seen = []
    real = metrics._pairwise_max
    monkeypatch.setattr(metrics, "_pairwise_max",
                        lambda P, X, *a, **k: seen.append(len(P) * len(X)) or real(P, X, *a, **k))
    X = np.tile([0.3, -1.7, 2.1][:d], (n, 1))
    assert diameter(X) == 0.0
    assert sum(seen) <= 4 * n, seen
    X[::2] += 2.0**-50  # two distinct values
    assert _agrees(diameter(X), _exact_diameter(X[:2]))
    assert sum(seen) <= 8 * n, seen


def test_polygon_edges_of_a_large_polygon_are_found_by_their_float_slack():
    """Initial states on a circle (every state a hull vertex): the edge ends were found by
    testing every vertex against every facet exactly (8 s to set up the monitor of a
    1000-gon at load 5, 32 s for 2000); now ~2 exact tests per facet, same edges."""
    import time

    from rescon.consensus._validity_monitor import _polygon_edges

    th = np.linspace(0, 2 * np.pi, 1000, endpoint=False)
    X = np.c_[np.cos(th), np.sin(th)]
    t = time.perf_counter()
    mon = ValidityMonitor(X)
    assert time.perf_counter() - t < 4.0
    P, Q = _polygon_edges(mon.hull)
    V = mon.hull.exact_vertices
    for (a, beta), p, q in list(zip(mon.hull._exact.facets, P, Q))[::40]:
        on = [v for v in V if a[0] * v[0] + a[1] * v[1] == beta]
        assert len(on) == 2 and {tuple(map(float, v)) for v in on} == {tuple(p), tuple(q)}
    x = np.array([[1.5, 0.25]])
    assert _agrees(mon.distances(x)[0], exact_distance(X[np.abs(th - 0.165) < 0.03], x[0]))
