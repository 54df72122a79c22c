"""The batch kernel-point paths at every magnitude: an answer they give is the exact
projection within a certified bound relative to the answer itself (issue 10 §2) —
far points (1e10 … 1e300), subnormal and mixed magnitudes, converged states."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from rescon.consensus.engine import _kernel_points
from rescon.geometry._small2d import ACCEPT_REL, OK, project_small_2d
from rescon.geometry._small3d import project_small_3d


def batch(Ys, F):
    """(points, error bounds (2-norm in space, max norm in the plane), accepted); the
    2-norm is taken scaled by the largest component (no overflow)."""
    Ys = np.ascontiguousarray(Ys, dtype=np.float64)
    if Ys.shape[2] == 3:
        return project_small_3d(Ys, F)
    out = np.zeros((len(Ys), 2))
    err = np.zeros(len(Ys))
    status = np.zeros(len(Ys), dtype=np.int64)
    project_small_2d(Ys, F, out, err, status)
    return out, err, (status == OK) & (err <= ACCEPT_REL * np.abs(out).max(axis=1))


def exact(Y, F):
    return rescon.safe_kernel(Y, F).point("project")[0]


def assert_certified(Ys, F):
    out, err, found = batch(Ys, F)
    for b in np.flatnonzero(found):
        x = exact(Ys[b], F)
        diff = out[b] - x
        big = np.abs(diff).max()
        dist = big * np.linalg.norm(diff / big) if big and len(x) == 3 else big
        rounding = np.spacing(np.abs(x)).max() * (len(x) ** 0.5) / 2  # x itself rounded
        assert dist <= err[b] * (1 + 1e-9) + rounding, (b, out[b], x, err[b])
        assert err[b] <= ACCEPT_REL * np.abs(out[b]).max()
    return found


def cloud(rng, d, F, far, magnitudes):
    """(d+1)F+1 points: benign ones in [−10, 10]^d and ``far`` of them at the given
    magnitudes (random signs, per coordinate)."""
    m = (d + 1) * F + 1
    Y = rng.uniform(-10, 10, size=(m, d))
    for q in range(far):
        Y[q] = rng.choice([-1.0, 1.0], size=d) * magnitudes[q] * rng.uniform(1, 2, size=d)
    return rng.permutation(Y)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), d=st.sampled_from([2, 3]), F=st.sampled_from([1, 2]),
       exps=st.lists(st.integers(10, 300), min_size=2, max_size=2))
def test_far_points_never_loosen_the_answer(seed, d, F, exps):
    rng = np.random.default_rng(seed)
    Ys = np.stack([cloud(rng, d, F, F, [10.0**e for e in exps]) for _ in range(6)])
    assert_certified(Ys, F)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), d=st.sampled_from([2, 3]),
       gap=st.integers(7, 13))
def test_converged_states(seed, d, gap):
    """States 1e-7 … 1e-13 apart around a common point, with and without one far
    adversary value: certified or declined, never off."""
    rng = np.random.default_rng(seed)
    F = 1
    m = (d + 1) * F + 1
    c = rng.uniform(-10, 10, size=d)
    Ys = c + rng.normal(size=(8, m, d)) * 10.0**-gap
    Ys[4:, 0] = rng.uniform(1e3, 1e20, size=(4, 1)) * rng.choice([-1, 1], size=(4, d))
    assert_certified(Ys, F)


@pytest.mark.parametrize("d", [2, 3])
def test_subnormal_and_mixed_magnitudes(d):
    rng = np.random.default_rng(d)
    F = 1
    m = (d + 1) * F + 2
    sets = []
    for scale in (1e-300, 1e-5, 1.0, 1e5, 1e300):
        Y = rng.normal(size=(m, d)) * scale
        sets.append(Y)
        Z = Y.copy()
        Z[0, 0] = 5e-324  # a subnormal coordinate
        sets.append(Z)
        W = rng.normal(size=(m, d))
        W[:2] *= scale  # two points at another magnitude
        sets.append(W)
    assert_certified(np.stack(sets), F)


def test_3d_far_adversary_is_declined_or_exact():
    """Issue 10 §2: one adversary value at 1e20 among four benign points in [−10, 10]³
    gave [40960, 28672, 16384] (the exact point is a benign data point)."""
    Y = np.array([[2.739234, -4.604266, -9.18053], [-9.669447, 6.265405, 8.255112],
                  [2.132716, 4.589931, 0.8724998], [8.701448, 6.317071, -9.94523],
                  [1e20, 1e20, 1e20]])
    pt = _kernel_points([Y], 1, "project", {})[0]
    assert np.array_equal(pt, exact(Y, 1))
    assert np.array_equal(pt, [2.132716, 4.589931, 0.8724998])


def test_2d_far_adversaries_give_the_exact_point():
    """Issue 10 §2: 5 points in [−10, 10]² and 2 at ±1e20 (F = 2) made the planar batch
    path return a vertex of Ψ that is not the nearest one."""
    rng = np.random.default_rng(11)
    for _ in range(20):
        Y = np.vstack([rng.uniform(-10, 10, size=(5, 2)), [[1e20, 1e20], [-1e20, 1e20]]])
        pt = _kernel_points([Y], 2, "project", {})[0]
        x = exact(Y, 2)
        assert np.abs(pt - x).max() <= ACCEPT_REL * np.abs(x).max()


def test_2d_error_bound_is_read():
    """Issue 10 §2: the engine used a planar batch point whatever its error bound (4
    points 1e-12 off a line, F = 1: bound 2e-3, point 1.4e-5 outside Ψ)."""
    rng = np.random.default_rng(3)
    for _ in range(30):
        t = rng.uniform(-5, 5, size=4)
        Y = np.column_stack([t, 2 * t + 1 + rng.normal(size=4) * 1e-12])
        x = exact(Y, 1)
        pt = _kernel_points([Y], 1, "project", {})[0]
        assert np.abs(pt - x).max() <= ACCEPT_REL * np.abs(x).max()
