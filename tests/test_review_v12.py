"""Hostile review (helper V12) of the d = 4–5 fast path's keyed closure
(:func:`rescon.geometry._closure._simple_ends`), the tight pairs read off the packed
bitsets (:func:`rescon.geometry.fastpath._tight_sets`), the proposals' basis array
(:func:`rescon.geometry.fastpath._basis_array`) and the grouped balls of the row maxima
(:func:`rescon.geometry._candidates.row_top`), against the scan, brute force and the
exact clipping."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

from rescon._rounding import underflow_floor
from rescon.geometry import _candidates
from rescon.geometry._candidates import row_top


def _exact_tops(A: np.ndarray, b: np.ndarray, V: np.ndarray) -> list[Fraction]:
    """max_v a·v − b per row, exactly (the floats' rational values)."""
    return [max(sum((Fraction(x) * Fraction(y) for x, y in zip(a, v, strict=True)),
                    Fraction(0)) for v in V.tolist()) - Fraction(bb)
            for a, bb in zip(A.tolist(), b.tolist(), strict=True)]


@pytest.mark.parametrize("scale", [1e-150, 1e-170, 1e-200, 1e-300])
@pytest.mark.parametrize("per", [1, 8])
def test_row_top_bounds_a_cluster_whose_radius_underflows(scale, per, monkeypatch):
    """A cluster of points ~``scale`` around the origin beside a point at 0.9 (the fast
    path's window puts the largest coordinate near 1): the squares of the cluster's
    offsets underflow, its chunks' radii came out 0 and every row tight a hair above
    the cluster was bounded ~‖a‖·scale below 0 — a cut missed, far beyond the floor
    (the underflow term of polynomials; a square root of an underflowed sum errs by
    up to ~2^-537). Per chunk (per = 1) as much as with the groups: the chunks' balls
    had it before this session. (The fast path's own row bound, ≥ 1e-15 · max |V|,
    hides it unless every proposed vertex is that small.)"""
    monkeypatch.setattr(_candidates, "GROUP_CHUNKS", per)
    rng = np.random.default_rng(3)
    V = np.vstack([rng.normal(size=(200, 4)) * scale, [[0.9, 0.0, 0.0, 0.0]]])
    A = rng.normal(size=(30, 4))
    A[:, 0] = -np.abs(A[:, 0]) - 1.0  # the far point lies far below every row
    best = _exact_tops(A, np.zeros(30), V)
    b = np.array([float(x) for x in best]) - 1e-3 * scale
    want = _exact_tops(A, b, V)
    assert all(w > 0 for w in want)
    floor = underflow_floor(4, 1.0)
    for parallel in (True, False):
        top = row_top(A, b, V, floor, parallel)
        assert all(t >= 0 for t in top.tolist())


@pytest.mark.parametrize("scale", [1e-170, 1e-300])
def test_row_top_bounds_rows_whose_norm_underflows(scale):
    """Rows of entries ~``scale`` (‖a‖ underflowed to ~0) over a unit cloud: each row
    tight a hair above its best point must be bounded ≥ 0."""
    rng = np.random.default_rng(5)
    V = rng.normal(size=(300, 4))
    A = rng.normal(size=(20, 4)) * scale
    best = _exact_tops(A, np.zeros(20), V)
    b = np.array([float(x) for x in best]) * (1 - 1e-6)
    b = np.where(b > 0, b, np.array([float(x) for x in best]) * (1 + 1e-6))
    want = _exact_tops(A, b, V)
    assert all(w > 0 for w in want)
    for parallel in (True, False):
        top = row_top(A, b, V, underflow_floor(4, float(np.abs(V).max())), parallel)
        assert all(t >= 0 for t in top.tolist())
