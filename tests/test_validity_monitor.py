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
    as the n² formula where that formula neither over- nor underflows: random clouds at
    scales 1e-100..1e100, repeated rows (converged clusters), collinear rows, one row,
    NaN (1e±300: tests/test_scale_monitors.py, against the exact diameter)."""
    from rescon.consensus.metrics import diameter

    rng = np.random.default_rng(seed)
    for t in range(150):
        n, d = int(rng.integers(1, 80)), int(rng.integers(1, 4))
        X = rng.normal(size=(n, d)) * 10.0 ** float(rng.integers(-100, 100))
        if t % 4 == 1:
            X = np.repeat(X[:2], 7, axis=0)
        elif t % 4 == 2:
            X = np.outer(rng.normal(size=n), rng.normal(size=d))
        with np.errstate(all="ignore"):
            assert diameter(X) == _diameter_n2(X)
    assert np.isnan(diameter(np.array([[np.nan, 1.0], [0.0, 0.0], [1.0, 1.0]])))


@pytest.mark.parametrize("seed", range(5))
def test_edge_distances_within_their_bound(seed):
    """In the plane, states a facet proves outside get the edge distance: within
    edge_error of the exact projection's distance, at scales 1e-40..1e40; zero exactly
    for the states in the hull."""
    rng = np.random.default_rng(seed)
    for _ in range(8):
        scale = 10.0 ** float(rng.integers(-40, 40))
        mon = ValidityMonitor(rng.normal(size=(int(rng.integers(3, 30)), 2)) * scale)
        X = rng.normal(size=(40, 2)) * scale * rng.choice([0.3, 1.0, 3.0, 1e3], size=(40, 1))
        fast = mon.distances(X)
        exact = np.array([mon.distance(x) for x in X])
        assert np.all(np.abs(fast - exact) <= mon.edge_error(X))
        assert np.array_equal(fast == 0, exact == 0)


def test_far_states_need_no_exact_projection(monkeypatch):
    """States that left the hull (RMDO's agents heading to X*): no exact projection
    (it took ~1.5 ms per state, 1.5 s per step at N = 1000)."""
    rng = np.random.default_rng(0)
    mon = ValidityMonitor(rng.uniform(0, 10, size=(200, 2)))
    X = rng.uniform(20, 30, size=(500, 2))
    exact = np.array([mon.distance(x) for x in X])
    monkeypatch.setattr(mon, "distance", lambda x: pytest.fail("exact path taken"))
    assert np.all(np.abs(mon.distances(X) - exact) <= mon.edge_error(X))


def test_boundary_and_extreme_states_take_the_exact_path():
    """On an edge, one ulp outside it, or at magnitudes beyond 1e±100 the filter cannot
    place the state or the bound does not apply: the exact distance is used."""
    mon = ValidityMonitor(np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]]))
    on_edge = np.array([[1.5, 1.5], [1.0, 0.0]])
    assert mon.distances(on_edge).tolist() == [0.0, 0.0]
    out = np.array([[np.nextafter(1.5, 2), 1.5], [1.0, -2.0**-1074], [1e120, 0.0]])
    assert mon.distances(out).tolist() == [mon.distance(x) for x in out]
    assert mon.distances(out)[[0, 2]].min() > 0
    tiny = ValidityMonitor(np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]]) * 1e-200)
    x = np.array([[4e-200, 4e-200]])
    assert tiny.distances(x).tolist() == [tiny.distance(x[0])] and np.isinf(tiny.edge_error(x))


def test_run_leaving_the_hull_same_states_validity_within_bound(monkeypatch):
    """The paper's example with zero-fill under the mean filter leaves the benign hull:
    the states are those of the exact-validity run, the validity within edge_error."""
    from rescon.consensus.engine import simulate
    from rescon.consensus.scenario import Scenario

    sc = Scenario.paper_example(check_robustness=False, steps=30, algorithm="mean",
                                policy="zero")
    fast = simulate(sc)
    mon = ValidityMonitor(fast.states[0, fast.benign])
    monkeypatch.setattr("rescon.consensus._validity_monitor._polygon_edges", lambda hull: None)
    exact = simulate(sc)
    assert np.array_equal(fast.states, exact.states)
    assert exact.metrics["validity"].max() > 1  # the case does leave the hull
    xb = fast.states[:, fast.benign].reshape(-1, 2)
    err = mon.edge_error(xb).reshape(len(fast.times), -1)
    diff = np.abs(fast.metrics["validity_per_agent"] - exact.metrics["validity_per_agent"])
    assert np.all(diff <= err) and np.any(diff > 0)
