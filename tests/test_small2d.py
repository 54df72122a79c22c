"""The planar batch path: exact decisions, float geometry, certified error bounds."""

from __future__ import annotations

import numpy as np
import pytest

import rescon
from rescon.geometry._small2d import OK, OUT_OF_RANGE, project_small_2d


def run(B, F):
    B = np.ascontiguousarray(B, dtype=np.float64)
    out = np.zeros((len(B), 2))
    err = np.zeros(len(B))
    status = np.zeros(len(B), dtype=np.int64)
    project_small_2d(B, F, out, err, status)
    return out, err, status


@pytest.mark.parametrize("m,F", [(4, 1), (7, 2), (10, 3), (8, 1)])
def test_matches_exact_projection_within_its_bound(m, F):
    B = np.random.default_rng(m * 10 + F).normal(size=(150, m, 2)) * 3 + 1
    out, err, status = run(B, F)
    assert (status == OK).mean() > 0.5
    for b in np.flatnonzero(status == OK):
        exact = rescon.safe_kernel(B[b], F).point("project")[0]
        assert np.abs(exact - out[b]).max() <= err[b] + 1e-300
        assert err[b] < 1e-5 * (1 + np.abs(B[b]).max())


def _grid(rng, m):
    return rng.integers(0, 4, size=(m, 2)).astype(float)


def _converged(rng, m):
    """A cluster a few ulps wide (states after consensus) and up to two far points."""
    c = rng.normal(size=2) * 5
    Y = c + rng.integers(-3, 4, size=(m, 2)) * np.spacing(np.abs(c).max()) * rng.integers(1, 4)
    k = rng.integers(0, 3)
    Y[:k] = rng.normal(size=(k, 2)) * 100
    return rng.permutation(Y)


def _duplicates(rng, m):
    return rng.normal(size=(3, 2))[rng.integers(0, 3, size=m)]


def _collinear(rng, m):
    t = rng.integers(-5, 6, size=m).astype(float)
    if rng.random() < 0.5:
        return np.column_stack([t, 3 * t + 1])
    return np.column_stack([t * 0 + 2, t])


@pytest.mark.parametrize("family", [_grid, _converged, _duplicates, _collinear])
@pytest.mark.parametrize("m,F", [(7, 2), (4, 1), (10, 3)])
def test_degenerate_sets_are_right_or_declined(family, m, F):
    """Integer grids, ulp-wide clusters, duplicates, collinear sets: every side decision
    is exact (expansions), so whatever the path answers is the exact point within its
    bound, and it answers most of them (the rest go to the exact path)."""
    rng = np.random.default_rng(m * 7 + F)
    B = np.stack([family(rng, m) for _ in range(120)])
    out, err, status = run(B, F)
    assert (status == OK).mean() >= 0.3
    for b in np.flatnonzero(status == OK):
        exact = rescon.safe_kernel(B[b], F).point("project")[0]
        assert np.abs(exact - out[b]).max() <= err[b] + 1e-300


def test_square_gives_the_crossing_of_its_diagonals():
    out, err, status = run(np.array([[[0, 0], [1, 0], [1, 1], [0, 1.0]]]), 1)
    assert status[0] == OK
    assert np.allclose(out[0], [0.5, 0.5], atol=err[0] + 1e-300)


def test_coordinates_outside_the_safe_range_are_declined():
    Y = np.array([[[1e-200, 0], [1, 0], [1, 1], [0, 1.0], [2, 2], [3, 1], [0.5, 3]]])
    assert run(Y, 2)[2][0] == OUT_OF_RANGE


def test_engine_fast_and_exact_kernel_points_agree():
    import warnings

    from rescon.consensus.adversaries import Constant
    from rescon.consensus.engine import simulate
    from rescon.consensus.scenario import Scenario
    from rescon.graphs.generators import circulant

    G = circulant(20, 5)
    x0 = np.random.default_rng(4).uniform(0, 10, size=(20, 2))
    runs = {}
    for kp in ("project", "project-exact"):
        for F in (1, 2):
            sc = Scenario(graph=G, x0=x0, F=F, adversaries={0: Constant([40.0, -5.0])},
                          steps=12, residual="none", kernel_point=kp)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                runs[kp, F] = simulate(sc).states
    for F in (1, 2):
        assert np.abs(runs["project", F] - runs["project-exact", F]).max() < 1e-9
