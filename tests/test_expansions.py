"""Exact planar predicates by floating-point expansions, against Fractions."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rescon.geometry._expansions import PARALLEL, orient, side_of_meet


def sign(x):
    return (x > 0) - (x < 0)


def exact_orient(a, b, c):
    a, b, c = ([Fraction(v) for v in p] for p in (a, b, c))
    return sign((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))


def exact_side_of_meet(b1, u1, b2, u2, b5, u5):
    """Meeting point by Cramer's rule in Fractions, then its side of line 5."""
    b1, u1, b2, u2, b5, u5 = ([Fraction(v) for v in p] for p in (b1, u1, b2, u2, b5, u5))
    D = u1[0] * u2[1] - u1[1] * u2[0]
    if D == 0:
        return PARALLEL
    t = ((b2[0] - b1[0]) * u2[1] - (b2[1] - b1[1]) * u2[0]) / D
    v = [b1[k] + t * u1[k] for k in range(2)]
    return sign(u5[0] * (v[1] - b5[1]) - u5[1] * (v[0] - b5[0]))


def as_expansion(p, q):
    """Direction q − p with two-term components, as the planar path builds it."""
    from rescon.geometry._expansions import difference

    u = np.empty((2, 2))
    difference(q[0], p[0], u[0])
    difference(q[1], p[1], u[1])
    return u


# the predicates are exact for nonzero |coordinates| in [2^-120, 2^120] (the planar path
# declines other inputs): products of four differences neither underflow nor overflow
coords = st.one_of(st.integers(-4, 4).map(float),
                   st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False).filter(
                       lambda v: v == 0 or abs(v) >= 2.0**-120),
                   st.integers(-4, 4).map(lambda k: 1.0 + k * 2.0**-52))
point = st.tuples(coords, coords)


@settings(max_examples=400, deadline=None)
@given(point, point, point)
def test_orient_is_exact(a, b, c):
    assert orient(*a, *b, *c) == exact_orient(a, b, c)


@settings(max_examples=300, deadline=None)
@given(point, point, point, point, point, point)
def test_side_of_meet_is_exact(p1, q1, p2, q2, p5, q5):
    args = (np.array(p1), as_expansion(p1, q1), np.array(p2), as_expansion(p2, q2),
            np.array(p5), as_expansion(p5, q5))
    def direction(p, q):
        return [Fraction(q[k]) - Fraction(p[k]) for k in range(2)]

    want = exact_side_of_meet(p1, direction(p1, q1), p2, direction(p2, q2),
                              p5, direction(p5, q5))
    assert side_of_meet(*args) == want


@pytest.mark.parametrize("eps", [0.0, 2.0**-50, -(2.0**-50)])
def test_meeting_point_on_a_third_line(eps):
    """Lines y = x and y = 1 − x meet at (½, ½); the line x = ½ (+eps) passes through
    it (or just misses it): the sign is 0 (or the exact side)."""
    args = (np.array([0.0, 0.0]), as_expansion((0.0, 0.0), (1.0, 1.0)),
            np.array([0.0, 1.0]), as_expansion((0.0, 1.0), (1.0, 0.0)),
            np.array([0.5 + eps, 0.0]), as_expansion((0.5 + eps, 0.0), (0.5 + eps, 1.0)))
    assert side_of_meet(*args) == sign(eps)  # (0, 1) × (v − b5) = −(½ − (½ + eps))


def test_parallel_lines_have_no_meeting_point():
    u = as_expansion((0.0, 0.0), (1.0, 2.0))
    assert side_of_meet(np.zeros(2), u, np.array([1.0, 0.0]), u, np.zeros(2), u) == PARALLEL


def test_normals_and_side_counts_in_space_are_exact():
    """Rounded exact normals (≤ 2 ulps per component, however close to collinear) and
    exact side counts, on a cluster 1e-7 wide with far points, against Fractions."""
    import itertools

    from rescon.geometry._expansions import normals3, side_counts

    rng = np.random.default_rng(0)
    c = rng.uniform(-1, 1, 3)
    Y = np.vstack([c + rng.uniform(-1e-7, 1e-7, (9, 3)), c + rng.normal(size=(3, 3)) * 5])
    Y[3] = Y[1] + (Y[2] - Y[1]) * 0.5  # nearly collinear with 1 and 2 (rounded midpoint)
    Y[4] = Y[1]  # a copy: triples through both are dependent
    subsets = np.array(list(itertools.combinations(range(len(Y)), 3)), dtype=np.int32)
    N = np.empty((len(subsets), 3))
    normals3(Y, subsets, N)
    plus, minus = np.zeros(len(subsets), np.int64), np.zeros(len(subsets), np.int64)
    dependent = np.zeros(len(subsets), bool)
    side_counts(Y, np.ones(len(Y), np.int64), subsets, len(Y), plus, minus, dependent)
    for t, (i, j, k) in enumerate(subsets):
        P = [[Fraction(v) for v in Y[r]] for r in (i, j, k)]
        u = [P[1][a] - P[0][a] for a in range(3)]
        w = [P[2][a] - P[0][a] for a in range(3)]
        C = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]]
        for a in range(3):
            assert abs(Fraction(N[t, a]) - C[a]) <= abs(C[a]) * Fraction(2, 2**53)
        assert dependent[t] == (C == [0, 0, 0])
        if not dependent[t]:
            s = [sum(C[a] * (Fraction(Y[q, a]) - P[0][a]) for a in range(3))
                 for q in range(len(Y)) if q not in (i, j, k)]
            assert (plus[t], minus[t]) == (sum(v > 0 for v in s), sum(v < 0 for v in s))


def test_side_counts_in_the_plane_are_exact():
    """Collinear triples and copies on a small grid, and a point a few ulps off a line."""
    import itertools

    from rescon.geometry._expansions import side_counts

    rng = np.random.default_rng(5)
    Y = rng.integers(0, 4, size=(14, 2)).astype(float) / 3.0  # thirds: rounded, near-collinear
    Y[13] = Y[0] + (Y[1] - Y[0]) * 0.5 + np.array([2.0**-52, 0.0])
    subsets = np.array(list(itertools.combinations(range(len(Y)), 2)), dtype=np.int32)
    plus, minus = np.zeros(len(subsets), np.int64), np.zeros(len(subsets), np.int64)
    dependent = np.zeros(len(subsets), bool)
    side_counts(Y, np.ones(len(Y), np.int64), subsets, len(Y), plus, minus, dependent)
    for t, (i, j) in enumerate(subsets):
        s = [exact_orient(Y[i], Y[j], Y[q]) for q in range(len(Y)) if q not in (i, j)]
        assert dependent[t] == (tuple(Y[i]) == tuple(Y[j]))
        if not dependent[t]:
            assert (plus[t], minus[t]) == (s.count(1), s.count(-1))
