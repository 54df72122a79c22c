"""The spatial batch path: exact halfspaces, a batched QP, a checked KKT polish."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import rescon
from rescon.geometry._small2d import ACCEPT_REL
from rescon.geometry._small3d import project_small_3d


def half_ulps(x):
    """How far the exact path's float point may lie from the exact rational one (it is
    rounded to nearest): the bounds certify the distance to the latter."""
    return np.linalg.norm(np.spacing(np.abs(x))) / 2


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
    """Whatever the path answers is the exact point of Ψ nearest the mean within its
    certified bound, itself at most ACCEPT_REL of the answer's magnitude; what it
    declines the engine computes exactly."""
    rng = np.random.default_rng(m + 100 * F)
    B = np.stack([family(rng, m) for _ in range(60)])
    out, err, found = project_small_3d(B, F)
    assert found.mean() >= least
    for b in np.flatnonzero(found):
        exact = rescon.safe_kernel(B[b], F).point("project")[0]
        assert np.linalg.norm(exact - out[b]) <= err[b] + half_ulps(exact)
        assert err[b] <= ACCEPT_REL * np.abs(out[b]).max()


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


def test_active_set_and_qp_hints_certify_the_same_point():
    """The numba dual active-set method and the QP fallback propose hints from which
    the certificate gives the same point (within both bounds)."""
    from rescon.geometry._small3d import (
        OK,
        _planes,
        by_qp,
        certify_all,
        halfspaces_3d,
        nearest_points,
    )

    rng = np.random.default_rng(9)
    Ys = rng.normal(size=(40, 9, 3)) * 0.1
    H = 9 * 8 * 7 // 3
    normals, offsets = np.empty((40, H, 3)), np.empty((40, H))
    count, status = np.zeros(40, dtype=np.int64), np.empty(40, dtype=np.int64)
    origin, scale, planes = np.empty((40, 3)), np.empty(40), _planes(40, H)
    halfspaces_3d(Ys, 2, normals, offsets, count, status, origin, scale, planes)
    local, solved = np.zeros((40, 3)), np.zeros(40, dtype=bool)
    nearest_points(normals, offsets, count, status, local, solved)
    assert solved[status == OK].all()
    sets = np.flatnonzero(status == OK)
    hints = {"gi": local[sets], "qp": by_qp(normals, offsets, count, sets)}
    res = {}
    for name, h in hints.items():
        out, err = np.zeros((len(sets), 3)), np.full(len(sets), np.inf)
        certify_all(Ys[sets], 2, tuple(a[sets] for a in planes), count[sets], status[sets],
                    origin[sets] + scale[sets, None] * h, scale[sets],
                    np.ones(len(sets), dtype=bool), out, err)
        res[name] = out, err
    both = np.isfinite(res["gi"][1]) & np.isfinite(res["qp"][1])
    assert both.mean() > 0.9
    gap = np.linalg.norm(res["gi"][0] - res["qp"][0], axis=1)
    assert (gap[both] <= res["gi"][1][both] + res["qp"][1][both]).all()


def test_converging_states_are_certified_or_declined_never_raise():
    """Issue 10 §1: five states converging in R³ made the dual active-set method call
    numpy's solve on a singular matrix (LinAlgError)."""
    Y = np.array([[1.8305279198741478, 3.7285884794087423, 2.466209479743424],
                  [1.7836211578114338, 3.6780975858810208, 2.644198920662587],
                  [1.7690624484622555, 3.654171253815685, 2.6624776488537107],
                  [1.683395574565291, 3.498274608668926, 2.69163076060083],
                  [1.6633763037083742, 3.4647538256923007, 2.711605983958983]])
    out, err, found = project_small_3d(Y[None], 1)
    exact = rescon.kernel_point(Y, 1)[0]
    assert not found[0] or np.linalg.norm(out[0] - exact) <= err[0] + half_ulps(exact)


@pytest.mark.parametrize("flat", [1.0, 1e-4, 1e-8, 1e-12])
def test_five_points_flat_or_not_give_the_radon_point(flat):
    """Five points with F = 1 (each agent's sets for d = 3, F = 1): Ψ is one Radon point,
    certified to a few ulps of itself however nearly coplanar the points are (converging
    states flatten to ~1e-12 before they meet) — and equal to the exact point."""
    rng = np.random.default_rng(int(-np.log10(flat)))
    B = rng.normal(size=(40, 5, 3))
    B[..., 2] *= flat
    B += rng.uniform(-10, 10, size=3)
    B[:10, 0] = B[:10, 1:].mean(axis=1) + 1e-3 * rng.normal(size=(10, 3)) * flat
    out, err, found = project_small_3d(B, 1)
    assert found.all()
    for b in range(len(B)):
        exact = rescon.safe_kernel(B[b], 1).point("project")[0]
        assert np.linalg.norm(exact - out[b]) <= err[b] + half_ulps(exact)
        assert err[b] <= 1e-14 * np.abs(out[b]).max()
