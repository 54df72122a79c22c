"""The margin LP by row generation (geometry/_lp.py) against one full LP (scipy/HiGHS)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

from rescon.geometry import _lp
from rescon.geometry._lp import max_margin


def _full_lp(A, b, w, lo, hi, t_min):
    k = A.shape[1]
    c = np.zeros(k + 1)
    c[-1] = -1.0
    res = linprog(c, A_ub=np.hstack([A, w[:, None]]), b_ub=b,
                  bounds=list(zip(lo, hi)) + [(t_min, None)], method="highs")
    return res


def _system(rng, m, k, offset):
    """m unit rows (the first 2k: ±e_j, so the set is bounded) at distance ~offset from
    the origin (t* > 0) — or, with a negative offset, pushed past it (t* < 0)."""
    A = rng.standard_normal((m, k))
    A[: 2 * k] = np.vstack([np.eye(k), -np.eye(k)])
    A /= np.linalg.norm(A, axis=1)[:, None]
    return A, offset + 0.1 * rng.random(m)


@pytest.mark.parametrize("m,k", [(6, 2), (60, 3), (3000, 4), (800, 5)])
def test_chebyshev_centre_matches_one_full_lp(m, k):
    rng = np.random.default_rng(m + k)
    A, b = _system(rng, m, k, 1.0)
    lo, hi = np.full(k, -10.0), np.full(k, 10.0)
    got = max_margin(A, b, np.ones(m), lo, hi, t_min=0.0)
    ref = _full_lp(A, b, np.ones(m), lo, hi, 0.0)
    assert got is not None and ref.status == 0
    assert got.t == pytest.approx(ref.x[-1], abs=1e-8)
    # the ball lies in every row, not only in the generated ones
    assert np.all(A @ got.x + got.t <= b + 1e-8)
    assert not got.bounded_by_box
    # the duals certify optimality: Σ λ_i a_i = 0, Σ λ_i = 1, Σ λ_i b_i = t*
    lam = got.duals
    assert np.all(lam >= 0)
    assert np.allclose(lam @ A, 0.0, atol=1e-8)
    assert lam.sum() == pytest.approx(1.0)
    assert lam @ b == pytest.approx(got.t, abs=1e-8)


def test_row_generation_takes_several_rounds(monkeypatch):
    """With few rows per round the answer is the same as the full LP's."""
    monkeypatch.setattr(_lp, "FIRST_ROWS", 3)
    monkeypatch.setattr(_lp, "ADD_ROWS", 2)
    rng = np.random.default_rng(7)
    A, b = _system(rng, 500, 3, 1.0)
    lo, hi = np.full(3, -5.0), np.full(3, 5.0)
    got = max_margin(A, b, np.ones(500), lo, hi, t_min=0.0)
    ref = _full_lp(A, b, np.ones(500), lo, hi, 0.0)
    assert got.t == pytest.approx(ref.x[-1], abs=1e-8)
    assert np.count_nonzero(got.duals) <= 4


def test_infeasible_system_stops_early_with_an_infeasible_subsystem():
    """t* < 0: the rows with positive duals already have no common point."""
    rng = np.random.default_rng(3)
    A, b = _system(rng, 2000, 4, -0.5)
    w = np.linalg.norm(A, axis=1)
    lo, hi = np.full(4, -10.0), np.full(4, 10.0)
    got = max_margin(A, b, w, lo, hi, stop_below=0.0)
    assert got is not None and got.t < 0
    support = np.flatnonzero(got.duals > 1e-12 * got.duals.max())
    assert 0 < len(support) <= 5
    sub = _full_lp(A[support], b[support], w[support], lo, hi, None)
    assert sub.status == 0 and sub.x[-1] < 0, "the support alone is infeasible"
    assert np.allclose(got.duals[support] @ A[support], 0.0, atol=1e-8)


def test_empty_set_with_t_min_zero_is_none():
    A = np.array([[1.0, 0.0], [-1.0, 0.0]])
    b = np.array([-1.0, -1.0])  # x ≤ −1 and x ≥ 1
    assert max_margin(A, b, np.ones(2), np.full(2, -5.0), np.full(2, 5.0), t_min=0.0) is None


def test_box_bound_is_reported():
    """A single row leaves x on the box: the margin is bounded by the box, said so."""
    A = np.array([[1.0, 0.0]])
    got = max_margin(A, np.array([0.0]), np.ones(1), np.full(2, -1.0), np.full(2, 1.0))
    assert got.t == pytest.approx(1.0) and got.bounded_by_box
