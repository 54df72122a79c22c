"""The groups of chunks in the row maxima (:func:`rescon.geometry._candidates.
ball_groups`, :func:`row_top`): each group's ball holds its points, and row_top with
the groups is an upper bound that equals the maximum wherever that may be ≥ 0 —
the same there as without groups (GROUP_CHUNKS = 1 tests every chunk's own ball,
whose bounds row_top used alone before), on clouds with duplicates and tiny/huge
coordinates too."""

from __future__ import annotations

import numpy as np
import pytest

from rescon.geometry import _candidates
from rescon.geometry._candidates import ball_chunks, ball_groups, row_top


@pytest.mark.parametrize("n,per", [(1, 8), (40, 8), (1000, 8), (1000, 3), (257, 1)])
def test_groups_cover_their_points_within_their_radius(n, per):
    V = np.random.default_rng(n).normal(size=(n, 5))
    V[n // 2:] = V[: n - n // 2]  # repeats
    order, starts, _, _ = ball_chunks(V)
    W = V[order]
    groups, centres, radii = ball_groups(W, starts, per)
    assert groups[0] == 0 and groups[-1] == len(starts) - 1
    assert np.all(np.diff(groups) >= 1) and np.all(np.diff(groups) <= per)
    for g in range(len(groups) - 1):
        P = W[starts[groups[g]]:starts[groups[g + 1]]]
        assert np.linalg.norm(P - centres[g], axis=1).max() <= radii[g] * (1 + 1e-12)


@pytest.mark.parametrize("scale", [1.0, 1e-150, 1e150])
@pytest.mark.parametrize("seed", range(3))
def test_row_top_with_groups_is_the_maximum_where_it_may_be_nonnegative(seed, scale,
                                                                         monkeypatch):
    rng = np.random.default_rng(seed)
    V = rng.normal(size=(3000, 4)) * scale
    A = rng.normal(size=(400, 4))
    best = (A @ V.T).max(axis=1)
    b = best + rng.normal(size=400) * scale * 0.3  # some rows violated, some close
    b[:20] = best[:20]  # tight at a point
    want = best - b
    for parallel in (True, False):
        top = row_top(A, b, V, 0.0, parallel)
        monkeypatch.setattr(_candidates, "GROUP_CHUNKS", 1)
        alone = row_top(A, b, V, 0.0, parallel)
        monkeypatch.undo()
        err = 1e-14 * (np.abs(A) @ np.abs(V).max(axis=0) + np.abs(b))
        assert np.all(top >= want - err)
        assert np.array_equal(top >= 0, alone >= 0)
        assert np.array_equal(top[top >= 0], alone[alone >= 0])
        assert np.all(top[want >= 0] == alone[want >= 0])
