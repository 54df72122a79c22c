"""MILP path for robustness (any n), solved by HiGHS through the backend registry.

Improves on the Usevitch–Panagou formulation (whose LP bound is 0) with

* tight big-M: for i ∈ S_k with y_{k,i} = 0 (i closed), |N(i) \\ S_k| ≤ r − 1 is
  written M_i b_{k,i} − Σ_{j∈N(i)} b_{k,j} − M_i y_{k,i} ≤ 0 with M_i = d_i − r + 1
  (the published model uses n − 1);
* y_{k,i} ≤ b_{k,i} and an explicit closed member of each set, Σ_i (b_{k,i} − y_{k,i}) ≥ 1;
* symmetry breaking: the first node of S1 ∪ S2 is in S1, b_{2,j} ≤ Σ_{i<j} b_{1,i};
* the known bounds as cuts: L ≤ Σ y ≤ U − 1 (U = cost of the best known pair), so
  HiGHS only has to beat the incumbent, and infeasibility proves optimality.

Variables: b1, b2 ∈ {0,1}^n (membership), y1, y2 ∈ {0,1}^n (reachable members,
omitted for r-robustness where every member must be closed).
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import SolverError
from ..models.backends import require_backend, silent_highs
from .indexed import IndexedGraph

__all__ = ["MilpOutcome", "RobustnessMilp", "milp_min_cost"]


@dataclass(frozen=True)
class MilpOutcome:
    """``status`` ∈ {"optimal", "infeasible", "time_limit"}; ``pair`` = (S1, S2) of the
    best solution found (cost ``cost``), None when infeasible or none found."""

    status: str
    cost: int | None
    pair: tuple[frozenset[int], frozenset[int]] | None
    seconds: float


def _rows(ig: IndexedGraph, r: int, with_y: bool):
    """Constraint rows (lower, upper, {col: coef}) of the model; columns are
    b1 = 0..n-1, b2 = n..2n-1, y1 = 2n.., y2 = 3n.."""
    n = ig.n
    inf = np.inf
    b = (0, n)
    y = (2 * n, 3 * n)
    rows: list[tuple[float, float, dict[int, float]]] = []
    for k in range(2):
        for i in range(n):
            M = len(ig.in_nbrs[i]) - r + 1
            if M <= 0:
                continue  # i has fewer than r in-neighbours: always closed
            row = {b[k] + i: float(M)}
            for j in ig.in_nbrs[i]:
                row[b[k] + j] = -1.0
            if with_y:
                row[y[k] + i] = -float(M)
            rows.append((-inf, 0.0, row))
        if with_y:
            for i in range(n):
                rows.append((-inf, 0.0, {y[k] + i: 1.0, b[k] + i: -1.0}))
            anchor = {b[k] + i: 1.0 for i in range(n)}
            anchor.update({y[k] + i: -1.0 for i in range(n)})
            rows.append((1.0, inf, anchor))
        else:
            rows.append((1.0, inf, {b[k] + i: 1.0 for i in range(n)}))
    for i in range(n):
        rows.append((-inf, 1.0, {b[0] + i: 1.0, b[1] + i: 1.0}))
    for j in range(n):
        row = {b[1] + j: 1.0}
        for i in range(j):
            row[b[0] + i] = -1.0
        rows.append((-inf, 0.0, row))
    return rows


PROGRESS_SECONDS = 0.2


class RobustnessMilp:
    """The robustness MILP, built once, solved synchronously or in the background.

    Minimises |reach_r(S1)| + |reach_r(S2)| over pairs with a closed member each,
    subject to lower ≤ cost ≤ upper − 1. With ``decision_only`` (upper = 1) the
    model has no y: it asks whether two disjoint nonempty r-closed sets exist, i.e.
    whether G is *not* r-robust. Infeasible means every such pair costs ≥ ``upper``.
    ``start()`` runs HiGHS in its own thread (HiGHS releases the GIL), so the
    combinatorial search can race it on the other core. ``on_progress`` (from HiGHS's
    thread, at most every ``PROGRESS_SECONDS``) gets the dual bound's share of
    [lower, upper] and the branch-and-bound nodes so far.
    """

    def __init__(self, ig: IndexedGraph, r: int, *, upper: int, lower: int = 0,
                 decision_only: bool = False, time_limit: float | None = None,
                 on_progress: Callable[[float, int], None] | None = None) -> None:
        require_backend("highs", "MILP")
        import highspy

        self._highspy = highspy
        n = ig.n
        self.n = n
        self.with_y = not decision_only
        ncol = 4 * n if self.with_y else 2 * n
        rows = _rows(ig, r, self.with_y)
        if self.with_y:
            rows.append((float(lower), float(upper - 1), {2 * n + i: 1.0 for i in range(2 * n)}))
        h = silent_highs()
        # one thread: the MILP races a search on the other core, and HiGHS's own
        # worker threads would take that core from it (max_s(ER(25, 0.5), 3): 5.0 s
        # with the default threads, 1.3 s with one)
        h.setOptionValue("threads", 1)
        h.setOptionValue("mip_rel_gap", 0.0)
        if time_limit is not None:
            h.setOptionValue("time_limit", float(max(time_limit, 0.01)))
        h.HandleUserInterrupt = True  # lets cancel() stop a background solve
        h.addVars(ncol, np.zeros(ncol), np.ones(ncol))
        h.changeColsIntegrality(ncol, np.arange(ncol, dtype=np.int32),
                                np.full(ncol, highspy.HighsVarType.kInteger))
        if self.with_y:
            h.changeColsCost(2 * n, np.arange(2 * n, 4 * n, dtype=np.int32), np.ones(2 * n))
        starts, index, value, lo, up = [], [], [], [], []
        for low, high, row in rows:
            starts.append(len(index))
            index.extend(row.keys())
            value.extend(row.values())
            lo.append(low)
            up.append(high)
        h.addRows(len(rows), np.array(lo), np.array(up), len(index),
                  np.array(starts, dtype=np.int32), np.array(index, dtype=np.int32),
                  np.array(value, dtype=np.float64))
        self.h = h
        self._thread = None
        self._unpresolved = False  # presolve switched off after a solve error
        self._t0 = 0.0
        if on_progress is not None:
            self._span = (lower, max(upper - lower, 1), on_progress)
            self._last = 0.0
            h.cbMipInterrupt.subscribe(self._report)

    def _report(self, event: Any) -> None:
        """HiGHS's MIP callback → ``on_progress`` (throttled)."""
        now = time.perf_counter()
        if now - self._last < PROGRESS_SECONDS:
            return
        self._last = now
        lower, span, on_progress = self._span
        dual = event.data_out.mip_dual_bound
        share = min(max((dual - lower) / span, 0.0), 1.0) if math.isfinite(dual) else 0.0
        on_progress(share, int(event.data_out.mip_node_count))

    def start(self) -> None:
        """Solve in a thread of our own (highspy's startSolve shares class-level locks
        between instances, so two solves in one process would interfere)."""
        self._t0 = time.perf_counter()
        self._thread = threading.Thread(target=self.h.run, daemon=True)
        self._thread.start()

    def running(self) -> bool:
        return self._thread is not None and self._thread.is_alive()

    def started(self) -> bool:
        return self._t0 > 0.0

    def cancel(self) -> None:
        """Stop a background solve (through HiGHS's interrupt callback) and wait."""
        if self._thread is not None:
            self.h.cancelSolve()
            self._thread.join()
            self._thread = None

    def outcome(self) -> MilpOutcome:
        """Wait for the solve and map HiGHS's status onto the shared status set."""
        if self._thread is None:
            self.start()
        thread = self._thread
        if thread is None:
            raise SolverError("the robustness MILP did not start")
        thread.join()
        self._thread = None
        seconds = time.perf_counter() - self._t0
        h = self.h
        S = self._highspy.HighsModelStatus
        status = h.getModelStatus()
        if status == S.kSolveError and not self._unpresolved:
            # HiGHS 1.16's presolve can reduce a model to empty with a point that breaks
            # a row and report a solve error (5 nodes, tests/test_review_v6.py): once more
            # without presolve
            self._unpresolved = True
            h.setOptionValue("presolve", "off")
            self.start()
            return self.outcome()
        if status in (S.kInfeasible, S.kUnboundedOrInfeasible):
            # every variable is a bounded binary: the model cannot be unbounded
            return MilpOutcome("infeasible", None, None, seconds)
        if status not in (S.kOptimal, S.kTimeLimit, S.kInterrupt):
            raise SolverError(f"HiGHS returned {h.modelStatusToString(status)} "
                              "on the robustness MILP")
        if h.getInfo().primal_solution_status != 2:
            return MilpOutcome("time_limit", None, None, seconds)
        n = self.n
        x = np.asarray(h.getSolution().col_value)
        S1 = frozenset(int(i) for i in np.flatnonzero(x[:n] > 0.5))
        S2 = frozenset(int(i) for i in np.flatnonzero(x[n:2 * n] > 0.5))
        cost = int(round(x[2 * n:].sum())) if self.with_y else 0
        return MilpOutcome("optimal" if status == S.kOptimal else "time_limit", cost,
                           (S1, S2), seconds)


def milp_min_cost(
    ig: IndexedGraph,
    r: int,
    *,
    upper: int,
    lower: int = 0,
    decision_only: bool = False,
    time_limit: float | None = None,
    on_progress: Callable[[float, int], None] | None = None,
) -> MilpOutcome:
    """Solve :class:`RobustnessMilp` and wait for the answer (none, and no model built,
    when ``time_limit`` is 0: a model of a dense n = 800 graph takes ~1 s to build)."""
    if time_limit is not None and time_limit <= 0:
        return MilpOutcome("time_limit", None, None, 0.0)
    return RobustnessMilp(ig, r, upper=upper, lower=lower, decision_only=decision_only,
                          time_limit=time_limit, on_progress=on_progress).outcome()
