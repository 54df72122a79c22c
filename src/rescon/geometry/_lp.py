"""The margin LP of a halfspace system, by row generation on HiGHS.

    max t  s.t.  a_i·x + w_i t ≤ b_i  (all rows i),   lo ≤ x ≤ hi,   t ≥ t_min

With unit rows and w = 1 this is the Chebyshev centre of {A x ≤ b}; with w = ‖a_i‖
and t free, t* < 0 says the halfspaces have no common point in the box, and the
positive duals name at most k + 1 of them that already have none (the support of a
Farkas certificate, which callers check exactly — nothing here decides a
combinatorial question).

The safe-kernel systems have thousands of rows in k ≤ 5 variables and only k + 1
matter, so the LP is solved on the rows nearest a deep point (the caller's; by default
the box centre), the rows its solution violates are added (at most ``ADD_ROWS`` per
round, most violated first), and HiGHS re-solves from the previous basis: a few small
solves instead of one large one (measured: 2–3 ms instead of 12 ms for 3 200 rows in
R⁴). The box keeps every partial LP bounded; callers pass one containing the sets they
study (the data's bounding box contains Ψ), so it does not change the answer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..models.backends import silent_highs

__all__ = ["Margin", "max_margin"]

#: rows in the first partial LP, and at most this many added per round
FIRST_ROWS = 50
ADD_ROWS = 50
#: a row counts as violated when it is off by more than this (relative to 1 + |b_i|):
#: HiGHS's own primal feasibility tolerance — a smaller violation would not move its
#: solution, and adding such rows only costs rounds (a kernel 1e-7 wide has
#: thousands; the caller re-solves tiny kernels at their own scale)
VIOLATION = 1e-7


@dataclass(frozen=True)
class Margin:
    x: np.ndarray  # (k,)
    t: float
    duals: np.ndarray  # (m,) ≥ 0, nonzero only on rows of the last partial LP
    bounded_by_box: bool  # some box bound has a nonzero reduced cost at the optimum


def max_margin(A: np.ndarray, b: np.ndarray, w: np.ndarray, lo: np.ndarray,
               hi: np.ndarray, centre: np.ndarray | None = None, t_min: float | None = None,
               stop_below: float | None = None) -> Margin | None:
    """The margin LP above, or None if HiGHS does not report an optimum (e.g. t ≥ t_min
    infeasible). ``centre`` (default: the box's): the first rows are those with the
    least slack there. ``stop_below``: return as soon as a partial LP has t* < stop_below
    (its rows already have no common point with margin ≥ stop_below; the duals
    refer to them)."""
    import highspy

    m, k = A.shape
    inf = highspy.kHighsInf
    h = silent_highs()
    h.setOptionValue("presolve", "off")
    cost = np.zeros(k + 1)
    cost[k] = -1.0
    h.addCols(k + 1, cost, np.r_[lo, -inf if t_min is None else t_min], np.r_[hi, inf],
              0, np.zeros(0, dtype=np.int32), np.zeros(0, dtype=np.int32), np.zeros(0))
    M = np.hstack([A, w[:, None]])
    most = max(FIRST_ROWS, ADD_ROWS)
    starts = np.arange(0, most * (k + 1), k + 1, dtype=np.int32)
    columns = np.tile(np.arange(k + 1, dtype=np.int32), most)
    added: list[np.ndarray] = []
    in_lp = np.zeros(m, dtype=np.bool_)

    def add(rows: np.ndarray) -> None:
        r = len(rows)
        h.addRows(r, np.full(r, -inf), b[rows], r * (k + 1), starts[:r],
                  columns[: r * (k + 1)], M[rows].ravel())
        in_lp[rows] = True
        added.append(rows)

    if centre is None:
        centre = (lo + hi) / 2.0
    add(_smallest((b - A @ centre) / w, FIRST_ROWS))
    tol = VIOLATION * (1.0 + np.abs(b))
    while True:
        h.run()
        if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
            return None
        z = np.array(h.getSolution().col_value)
        if stop_below is not None and z[k] < stop_below:
            break
        excess = M @ z - b
        bad = np.flatnonzero((excess > tol) & ~in_lp)
        if not len(bad):
            break
        add(bad[_smallest(-excess[bad], ADD_ROWS)])
    solution = h.getSolution()
    duals = np.zeros(m)
    duals[np.concatenate(added)] = -np.array(solution.row_dual)
    boxed = bool(np.any(np.abs(np.array(solution.col_dual)[:k]) > 0.0))
    return Margin(z[:k], float(z[k]), np.maximum(duals, 0.0), boxed)


def _smallest(v: np.ndarray, m: int) -> np.ndarray:
    """np.argsort(v, kind="stable")[:m] — the indices of the m smallest entries, ties
    by index — without sorting all of v: the entries ≤ the m-th smallest value (a
    partition, O(len v)) are the only ones that can be among them, and their stable
    sort orders them as the full one does. NaN (last in both) as the full sort."""
    if len(v) <= m:
        return np.argsort(v, kind="stable")
    kth = np.partition(v, m - 1)[m - 1]
    if np.isnan(kth):
        return np.argsort(v, kind="stable")[:m]
    near = np.flatnonzero(v <= kth)  # increasing: ties stay in index order
    return near[np.argsort(v[near], kind="stable")[:m]]
