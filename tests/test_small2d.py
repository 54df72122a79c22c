"""The planar batch path: exact decisions, float geometry, certified error bounds."""

from __future__ import annotations

import numpy as np
import pytest

import rescon
from rescon.geometry._small2d import FLAT, OK, project_small_2d


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


def test_degenerate_sets_are_declined_or_right():
    """Collinear points, duplicates and integer grids: the path either declines (the
    caller goes exact) or agrees with the exact answer."""
    rng = np.random.default_rng(3)
    sets = [np.column_stack([np.arange(7.0), 2 * np.arange(7.0)]),
            np.repeat(rng.normal(size=(2, 2)), [4, 3], axis=0),
            rng.integers(0, 3, size=(7, 2)).astype(float),
            np.array([[0, 0], [1, 0], [1, 1], [0, 1.0]])]
    for Y in sets:
        F = 1 if len(Y) == 4 else 2
        out, err, status = run(Y[None], F)
        if status[0] == OK:
            exact = rescon.safe_kernel(Y, F).point("project")[0]
            assert np.abs(exact - out[0]).max() <= err[0] + 1e-300
    # the square: the diagonals cross at its centre (Radon point)
    out, err, status = run(np.array([[[0, 0], [1, 0], [1, 1], [0, 1.0]]]), 1)
    assert status[0] in (OK, FLAT)
    if status[0] == OK:
        assert np.allclose(out[0], [0.5, 0.5], atol=err[0] + 1e-300)


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
