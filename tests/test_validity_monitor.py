"""The validity monitor's float filter proves "inside" only where it is (issue 10 §4:
the metric that shows whether a centre leaves the benign hull)."""

from __future__ import annotations

import numpy as np
import pytest

from rescon.consensus.metrics import ValidityMonitor

TINY = 2.0**-1074  # the subnormal grid


def _grid(n: int) -> np.ndarray:
    return np.array([[i, j] for i in range(n + 1) for j in range(n + 1)], dtype=float)


@pytest.mark.parametrize("seed", range(6))
def test_subnormal_hull_no_false_inside(seed):
    """Hull and states on the subnormal grid, where the relative rounding bound does
    not hold: every state the filter passes is inside, and the distances equal the
    exact ones (the filter used to pass states outside the hull as distance 0)."""
    V = np.random.default_rng(seed).integers(0, 40, size=(4, 2)).astype(float) * TINY
    mon = ValidityMonitor(V)
    states = _grid(40) * TINY
    sure = mon.surely_inside(states)
    assert all(mon.hull.contains(p) for p in states[sure])
    exact = np.array([mon.distance(p) for p in states])
    assert np.array_equal(mon.distances(states), exact)


def test_filter_passes_interior_states_at_every_scale():
    """The filter still does its job: interior states are proven inside without exact
    work, at ordinary, huge and tiny scales (3-D)."""
    rng = np.random.default_rng(1)
    X = rng.normal(size=(20, 3))
    inner = 0.05 * rng.normal(size=(50, 3))
    for k in (0, 900, -900):
        mon = ValidityMonitor(np.ldexp(X, k))
        assert mon.surely_inside(np.ldexp(inner, k)).all()
        assert not mon.surely_inside(np.ldexp(X, k) * 1.5).all()


def test_filter_declines_on_a_flat_hull():
    mon = ValidityMonitor(np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]))
    assert not mon.surely_inside(np.array([[1.0, 1.0]])).any()
    assert mon.distances(np.array([[1.0, 1.0], [0.0, 1.0]]))[0] == 0.0


def _diameter_n2(X: np.ndarray) -> float:
    diff = X[:, None, :] - X[None, :, :]
    return float(np.sqrt((diff**2).sum(axis=2)).max())


@pytest.mark.parametrize("seed", range(4))
def test_diameter_same_float_as_all_pairs(seed):
    """The pruned diameter (only rows that can end one are compared) is the same float
    as the n² formula: random clouds at scales 1e-300..1e300, repeated rows (converged
    clusters), collinear rows, one row, NaN."""
    from rescon.consensus.metrics import diameter

    rng = np.random.default_rng(seed)
    for t in range(150):
        n, d = int(rng.integers(1, 80)), int(rng.integers(1, 4))
        X = rng.normal(size=(n, d)) * 10.0 ** float(rng.integers(-300, 300))
        if t % 4 == 1:
            X = np.repeat(X[:2], 7, axis=0)
        elif t % 4 == 2:
            X = np.outer(rng.normal(size=n), rng.normal(size=d))
        with np.errstate(all="ignore"):
            assert diameter(X) == _diameter_n2(X)
    assert np.isnan(diameter(np.array([[np.nan, 1.0], [0.0, 0.0], [1.0, 1.0]])))
