"""The spatial batch path: exact halfspaces, a batched QP, a checked KKT polish."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import rescon
from rescon.geometry._small3d import project_small_3d


def _gaussian(rng, m):
    return rng.normal(size=(m, 3)) * 3 + 1


def _converged(rng, m):
    """A cluster a few ulps wide and up to two far points."""
    c = rng.normal(size=3)
    Y = c + rng.integers(-3, 4, size=(m, 3)) * np.spacing(np.abs(c).max())
    k = rng.integers(0, 3)
    Y[:k] = rng.normal(size=(k, 3)) * 100
    return rng.permutation(Y)


def _grid(rng, m):
    return rng.integers(0, 3, size=(m, 3)).astype(float)


def _duplicates(rng, m):
    return rng.normal(size=(4, 3))[rng.integers(0, 4, size=m)]


@pytest.mark.parametrize("family,least", [(_gaussian, 0.9), (_converged, 0.0), (_grid, 0.0),
                                          (_duplicates, 0.15)])
@pytest.mark.parametrize("m,F", [(5, 1), (9, 2), (13, 3)])
def test_found_points_are_the_exact_projection(family, least, m, F):
    """Whatever the path answers is the exact point of Ψ nearest the mean to ~1e-12 of
    the data scale (the polish solves the exact KKT system in floats); what it declines
    the engine computes exactly."""
    rng = np.random.default_rng(m + 100 * F)
    B = np.stack([family(rng, m) for _ in range(60)])
    out, found = project_small_3d(B, F)
    assert found.mean() >= least
    for b in np.flatnonzero(found):
        exact = rescon.safe_kernel(B[b], F).point("project")[0]
        assert np.abs(exact - out[b]).max() <= 1e-12 * (1 + np.abs(B[b]).max())


def test_engine_fast_and_exact_agree_in_space():
    from rescon.consensus.adversaries import Constant
    from rescon.consensus.engine import simulate
    from rescon.consensus.scenario import Scenario
    from rescon.graphs.generators import circulant

    G = circulant(20, 6)
    x0 = np.random.default_rng(5).uniform(0, 10, size=(20, 3))
    runs = {}
    for kp in ("project", "project-exact"):
        sc = Scenario(graph=G, x0=x0, F=1, adversaries={0: Constant([40.0, -5.0, 3.0])},
                      steps=6, residual="none", kernel_point=kp)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            runs[kp] = simulate(sc).states
    assert np.abs(runs["project"] - runs["project-exact"]).max() < 1e-9


def test_active_set_and_qp_agree():
    """The numba dual active-set method and the QP fallback give the same polished
    points (both checked against the KKT conditions)."""
    from rescon.geometry._small3d import OK, by_qp, halfspaces_3d, nearest_points

    rng = np.random.default_rng(9)
    Ys = rng.normal(size=(40, 9, 3))
    H = 9 * 8 * 7 // 3
    normals, offsets = np.empty((40, H, 3)), np.empty((40, H))
    count, status = np.zeros(40, dtype=np.int64), np.empty(40, dtype=np.int64)
    halfspaces_3d(Ys, 2, normals, offsets, count, status, np.empty((40, 3)), np.empty(40))
    local, solved = np.zeros((40, 3)), np.zeros(40, dtype=bool)
    nearest_points(normals, offsets, count, status, local, solved)
    assert solved[status == OK].all()
    qp = by_qp(normals, offsets, count, list(np.flatnonzero(status == OK)))
    for b, y in qp.items():
        assert y is not None and np.abs(y - local[b]).max() < 1e-12
