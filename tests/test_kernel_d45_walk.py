"""The rows outside the defining set S by walks on the vertex graph the closure proves
(:func:`rescon.geometry._candidates.graph_top`, :func:`rescon.geometry.fastpath.
_outside_feasible`), issue 13 §3: a row the walk proves slack is slack at every exact
vertex (integer oracle over all pairs), on benchmark and hostile clouds at scales
2^±990; with the walk proving nothing (forced) the kernels are still the exact
clipping's; a halfspace cutting the kernel is refused."""

from __future__ import annotations

import dataclasses
from fractions import Fraction

import numpy as np
import pytest

import rescon
from rescon.geometry import _candidates, fastpath
from tests.test_kernel_d45_around2 import _cloud, _same_as_clipping


def _captured(X: np.ndarray, F: int, monkeypatch) -> dict:
    """The arguments of the fast path's last _outside_feasible call (and its answer)."""
    seen: dict = {}
    real = fastpath._outside_feasible

    def spy(H, scale, verts, W, basis, S, Vx, coarse, c, floor, edges, k):
        ok = real(H, scale, verts, W, basis, S, Vx, coarse, c, floor, edges, k)
        seen.update(H=H, scale=scale, verts=verts, W=W, basis=basis, S=S, Vx=Vx,
                    coarse=coarse, c=c, floor=floor, edges=edges, k=k, ok=ok)
        return ok

    with monkeypatch.context() as mp:
        mp.setattr(fastpath, "_outside_feasible", spy)
        rescon.safe_kernel(X, F)
    assert seen, "the fast path did not reach the walks"
    return seen


def _csr(edges):
    sizes = np.array([len(e) for e in edges], dtype=np.int64)
    ptr = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    nbr = np.array([u for e in edges for u in e], dtype=np.int64)
    return ptr, nbr


def _tops(got: dict, rows: np.ndarray) -> np.ndarray:
    H = got["H"]
    ptr, nbr = _csr(got["edges"])
    return _candidates.graph_top(H.af[rows], H.bf[rows], H.af_abs[rows], H.b_abs[rows],
                                 got["Vx"], ptr, nbr, H.c_err, got["c"], got["floor"])


def _exact_slacks(got: dict, rows: np.ndarray) -> list[list[Fraction]]:
    """(a·y − b·w) / w for every row and vertex (the row's exact slack, a positive
    multiple of what its floats approximate)."""
    H = got["H"]
    out = []
    for h in rows.tolist():
        a, b = H.exact(h)
        out.append([Fraction(sum(x * y for x, y in zip(a, v[1:], strict=True)) - b * v[0],
                             v[0]) for v in got["verts"]])
    return out


WALKED = [("gaussian", 4, 22, 2, 1.0), ("cube", 4, 20, 3, 1.0), ("sphere", 4, 20, 1, 1.0),
          ("converged", 4, 20, 2, 1.0), ("duplicates", 4, 30, 3, 1.0),
          ("attack", 4, 18, 3, 1.0), ("nearsame", 4, 20, 2, 1.0), ("integer", 4, 20, 3, 1.0),
          ("tiny", 4, 20, 2, 1.0), ("subnormal", 4, 20, 2, 1.0), ("huge", 4, 20, 2, 1.0),
          ("gaussian", 4, 22, 2, 2.0**990), ("converged", 4, 20, 2, 2.0**-990),
          ("duplicates", 4, 30, 3, 2.0**-990), ("gaussian", 5, 13, 1, 1.0),
          ("nearsame", 5, 13, 1, 1.0)]


@pytest.mark.parametrize("kind,d,n,F,scale", WALKED)
def test_rows_the_walk_proves_are_at_their_maximum(kind, d, n, F, scale, monkeypatch):
    """Over every valid row (those of S too, tight on whole facets): where the walk
    proves a value t, t is the float slack of a vertex at which the row's exact slack is
    largest, and t < −coarse only for rows slack at every vertex; the maximum float
    slack is within two row bounds of t."""
    got = _captured(_cloud(kind, d, n, F) * scale, F, monkeypatch)
    assert got["ok"]
    H, Vx, coarse = got["H"], got["Vx"], got["coarse"]
    rows = np.arange(len(H))
    top = _tops(got, rows)
    proven = np.flatnonzero(np.isfinite(top))
    assert len(proven) > 0
    exact = _exact_slacks(got, rows[proven])
    s = np.zeros((len(proven), len(Vx)))  # summed in _slack's order (no BLAS)
    for j in range(Vx.shape[1]):
        s += H.af[proven, j][:, None] * Vx[:, j][None, :]
    s -= H.bf[proven][:, None]
    for i, h in enumerate(proven.tolist()):
        best = max(exact[i])
        at = [v for v, x in enumerate(exact[i]) if x == best]
        assert any(s[i, v] == top[h] for v in at), h
        if top[h] < -coarse[h]:
            assert best < 0, h
        assert abs(s[i].max() - top[h]) <= 2 * coarse[h], h


@pytest.mark.parametrize("kind,d,n,F,scale", [("gaussian", 4, 22, 2, 1.0),
                                              ("converged", 4, 20, 2, 2.0**990),
                                              ("duplicates", 4, 30, 3, 2.0**-990),
                                              ("flat", 4, 20, 2, 1.0),
                                              ("gaussian", 5, 13, 1, 1.0)])
@pytest.mark.parametrize("force", ["nothing proven", "tiny raised"])
def test_kernels_without_the_walk_are_the_exact_clipping(kind, d, n, F, scale, force,
                                                         monkeypatch):
    """The walk forced to prove nothing — graph_top all +inf, or its comparisons made
    impossible (WALK_TINY huge) — every row outside S is decided pair by pair: the same
    kernel, bit for bit, as the exact clipping."""
    if force == "nothing proven":
        monkeypatch.setattr(_candidates, "graph_top",
                            lambda A, *args: np.full(len(A), np.inf))
    else:
        monkeypatch.setattr(_candidates, "WALK_TINY", 1e300)
    _same_as_clipping(_cloud(kind, d, n, F) * scale, F, monkeypatch)


def test_the_walk_proves_most_rows_outside_s(monkeypatch):
    """Without it the walks would not pay: on a benchmark cloud all but a few rows
    outside S are proven slack by their walk."""
    got = _captured(_cloud("gaussian", 4, 30, 3), 3, monkeypatch)
    outside = np.setdiff1d(np.arange(len(got["H"])), got["S"])
    top = _tops(got, outside)
    assert (top < -got["coarse"][outside]).mean() > 0.9


@pytest.mark.parametrize("kind,d,n,F,scale", [("gaussian", 4, 22, 2, 1.0),
                                              ("cube", 4, 20, 3, 2.0**-990),
                                              ("gaussian", 5, 13, 1, 1.0)])
def test_a_row_cutting_the_kernel_is_refused(kind, d, n, F, scale, monkeypatch):
    """Each facet row of S reversed (the same hyperplane, the other side: a halfspace
    that cuts off every vertex off the facet) and added as a row outside S:
    _outside_feasible refuses; the rows as they are pass."""
    got = _captured(_cloud(kind, d, n, F) * scale, F, monkeypatch)
    H = got["H"]
    args = [got[x] for x in ("scale", "verts", "W", "basis", "S", "Vx")]
    rest = [got[x] for x in ("c", "floor", "edges", "k")]
    assert fastpath._outside_feasible(H, *args, got["coarse"], *rest)
    for h in got["S"][:: max(1, len(got["S"]) // 6)].tolist():
        R = dataclasses.replace(
            H, through=np.vstack([H.through, H.through[h:h + 1]]),
            sign=np.append(H.sign, -H.sign[h]), af=np.vstack([H.af, -H.af[h:h + 1]]),
            bf=np.append(H.bf, -H.bf[h]), af_abs=np.vstack([H.af_abs, H.af_abs[h:h + 1]]),
            b_abs=np.append(H.b_abs, H.b_abs[h]), outside=np.append(H.outside, 0),
            _cache={})
        coarse = np.append(got["coarse"], got["coarse"][h])
        assert not fastpath._outside_feasible(R, *args, coarse, *rest), h
