"""Algorithm 2 (RMDO) on the consensus engine, and its cost metrics.

Steps 1–3 of Algorithm 1 give every benign agent its auxiliary point x̃_i; then

    z_i = α_i x_i + (1 − α_i) x̃_i,     x_i ← z_i − β_k d_i,     d_i ∈ ∂f_i(z_i)

(SPEC §4; no residual ε: Algorithm 2 has none). :class:`SubgradientStep` is that
update rule and :class:`CostMonitor` the per-step cost metrics; both are passed to
:func:`rescon.consensus.engine.run`, the one loop behind :func:`rescon.simulate`
(``optim`` imports ``consensus``, never the reverse).

Subgradients of a step are computed for all moving agents together: agents whose
oracles are library atoms of one structure (:func:`rescon.optim.atoms.signature`: same
classes, same shapes; e.g. one ``½‖x − c_i‖² + |a_iᵀx − b_i|`` per agent) are evaluated
in one vectorised call with their data stacked (:class:`rescon.optim.atoms.Stacked`),
the others in one call per distinct oracle on the stacked points of the agents that
share it. The global cost F = Σ_{j∈B} f_j of the metrics is built once as one merged
oracle (:class:`rescon.optim.atoms.Merged`).
"""

from __future__ import annotations

import dataclasses
import math
import time
import warnings
from collections.abc import Callable, Hashable, Mapping, Sequence
from fractions import Fraction
from typing import Any

import numpy as np

from ..consensus.engine import ConsensusMonitor, run
from ..consensus.scenario import STATE_LIMIT, Scenario, ScenarioWarning
from ..consensus.trajectory import Trajectory
from ..errors import InputError
from . import atoms
from .cost import cost
from .oracle import Oracle
from .steps import step_size as as_step_size

__all__ = ["CostMonitor", "Optimum", "SubgradientStep", "rmdo"]


def rmdo(scenario: Scenario, costs: Mapping[Hashable, Any], *, step_size: Any = "paper",
         optimum: Any = None, metrics: Sequence[str] | str | None = None,
         progress: bool | None = None) -> Trajectory:
    """Run Algorithm 2 (resilient multi-dimensional distributed optimisation).

    Parameters
    ----------
    scenario : the graph, attacks, filter (``algorithm``), α, T and steps; its
        ``residual`` is not used (Algorithm 2 has no ε).
    costs : mapping node → f_i, every benign node included (adversaries' entries are
        ignored); each value is anything :func:`rescon.cost` accepts. Agents given the
        same Oracle object (or the same expression string) share one oracle, called
        once per step on their stacked points.
    step_size : "paper" (β_k = 1/(5 t_k + 1)), a positive number (constant), a callable
        k ↦ β_k or a :class:`rescon.optim.steps.StepSize`. Violations of Assumption 5
        (non-increasing, Σβ = ∞, Σβ² < ∞) are issued as :class:`ScenarioWarning`.
    optimum : a point of X* = argmin Σ_{i∈B} f_i if known (then X* is taken to be that
        point). Otherwise X* is computed exactly when every cost is a quadratic or affine
        atom (rational linear algebra on the atoms' data), else numerically
        (:class:`Optimum`; ``info["optimum"]`` says which).
    metrics : the consensus monitors to run, as in :func:`rescon.simulate` (a list of
        names or one comma-separated string: "spread",
        "diameter", "validity"; default every one); the cost metrics always run.
    progress : a progress bar on stderr (default: when stderr is a terminal).

    Returns
    -------
    Trajectory whose ``metrics`` hold, besides the consensus metrics, ``cost``
    (K+1, |B|) the global cost F(x_i) = Σ_{j∈B} f_j(x_i) at every benign state,
    ``cost_at_mean`` (K+1,) F at the benign mean x̄, ``cost_rate`` (K+1,)
    (F(x̄(t_k)) − F(x̄(t_{k−1})))/T (NaN at k = 0), and when X* is known and nonempty
    ``distance_to_optimum`` (K+1,) max_i dist(x_i, X*) and ``optimality_gap`` (K+1,)
    max_i F(x_i) − F*.

    Raises
    ------
    InputError
        ``costs`` not a mapping, a benign agent without a cost, a cost of the wrong
        dimension, a bad step size, a bad ``optimum``, or an oracle that fails, returns
        NaN/inf or the wrong shape during the run, or a subgradient step that overflows
        or leaves |x| ≤ 1e150 (:data:`~rescon.consensus.scenario.STATE_LIMIT`, the
        bound on initial states; the message names the agent, the step and the point,
        with a hint when the iterates diverged; nothing reaches the states).

    Examples
    --------
    >>> import networkx as nx, rescon
    >>> sc = rescon.Scenario(graph=nx.complete_graph(4), x0=[[0.0], [1.0], [2.0], [3.0]],
    ...                      F=0, steps=300, check_robustness=False)
    >>> tr = rescon.rmdo(sc, {i: "(x1 - 1)^2" for i in range(4)})
    >>> tr.info["optimum"]["point"], bool(tr.metrics["distance_to_optimum"][-1] < 0.01)
    ([1.0], True)
    """
    t0 = time.perf_counter()
    sc = scenario
    if not isinstance(sc, Scenario):
        raise InputError(f"scenario must be a rescon.Scenario; got {type(sc).__name__}")
    problems = sc.warn()
    groups = _groups(sc, costs)
    beta = as_step_size(step_size)
    betas = beta.values(np.arange(sc.steps), sc.T)
    violated = beta.assumption5(sc.T)
    for msg in violated:
        warnings.warn(f"Assumption 5: {msg}", ScenarioWarning, stacklevel=2)
    benign = [v for v in sc.nodes if v not in sc.adversaries]
    F = GlobalCost(groups, sc.d)
    x0 = sc.x0[[sc.nodes.index(v) for v in benign]]
    opt = Optimum.find(groups, F, sc.d, optimum, x0)
    reach = _reach(x0, opt)
    rule = SubgradientStep(groups, len(sc.nodes), betas, sc.nodes, reach)
    monitor = CostMonitor(F, sc.steps, sc.T, len(benign), opt, reach)
    info = {"assumptions_violated": problems, "update": "rmdo", "step_size": repr(beta),
            "assumption5_violated": violated, "oracles": len(groups), "optimum": opt.info}
    tr = run(sc, rule, monitors=[ConsensusMonitor(sc, metrics), monitor], progress=progress,
             info=info, started=t0)
    monitor.remeasure(tr.states, tr.benign)
    return dataclasses.replace(tr, seconds=time.perf_counter() - t0)


class _Group:
    """One oracle and the agents (row indices in node order, and labels) that use it."""

    def __init__(self, oracle: Oracle) -> None:
        self.oracle = oracle
        self.rows = np.empty(0, dtype=np.int64)
        self.labels: list[Hashable] = []

    def add(self, row: int, label: Hashable) -> None:
        self.rows = np.append(self.rows, row)
        self.labels.append(label)


def _groups(sc: Scenario, costs: Any) -> list[_Group]:
    """The benign agents' oracles, one group per distinct oracle (same object, or the
    same expression string), in node order."""
    if not isinstance(costs, Mapping):
        raise InputError(f"costs must be a mapping node -> cost; got {type(costs).__name__}")
    unknown = [v for v in costs if v not in sc.graph]
    if unknown:
        raise InputError(f"costs: {unknown[:5]} are not nodes of the graph")
    benign = [v for v in sc.nodes if v not in sc.adversaries]
    missing = [v for v in benign if v not in costs]
    if missing:
        raise InputError(f"costs: no cost for benign agent(s) {missing[:5]}")
    made: dict[Any, _Group] = {}
    for v in benign:
        spec = costs[v]
        key = spec if isinstance(spec, str) else id(spec)
        if key not in made:
            made[key] = _Group(cost(spec, d=sc.d, name=f"cost of agent {v!r}"))
        made[key].add(sc.nodes.index(v), v)
    return list(made.values())


def _call(oracle: Oracle, method: str, Z: np.ndarray, who: Callable[[int], Hashable],
          where: str, reach: float | None = None) -> np.ndarray:
    """``oracle.<method>(Z)`` (checked by the oracle); on failure an InputError naming
    the agent ``who(r)`` of the first row r that fails on its own, ``where`` (the step)
    and the point (with :func:`_divergence_hint` against ``reach``)."""
    try:
        with np.errstate(over="ignore", invalid="ignore"):  # NaN/inf answers are checked
            return getattr(oracle, method)(Z)
    except Exception as exc:  # a user's oracle may raise anything: report where
        r = next((r for r in range(len(Z)) if not _works(oracle, method, Z[r:r + 1])), 0)
        why = str(exc) if isinstance(exc, InputError) else f"{type(exc).__name__}: {exc}"
        raise InputError(f"{method} of the cost of agent {who(r)!r} {where}, point "
                         f"{Z[r].tolist()}: {why}{_divergence_hint(Z[r], reach)}") from exc


#: steps per block when distances are re-measured against an improved X*
REMEASURE_BLOCK = 4096

#: a failing point this many times farther out than every initial state and X* is
#: reported as a diverging run (only the wording of the error depends on it)
DIVERGED = 2.0**20


def _reach(x0: np.ndarray, opt: Optimum) -> float:
    """The largest |coordinate| of the benign initial states and of X*'s point (when
    known): where a converging run stays within a bounded factor (Algorithm 2 moves
    from the initial hull towards X*), the scale of :func:`_divergence_hint`."""
    reach = float(np.abs(x0).max(initial=0.0))
    if opt.known:
        reach = max(reach, float(np.abs(opt.point).max(initial=0.0)))
    return reach


def _divergence_hint(point: np.ndarray, reach: float | None) -> str:
    """A hint for an error at ``point`` during a run whose initial states and X* lie
    within max-norm ``reach`` (:func:`_reach`): when the point is more than DIVERGED
    times farther out, the iterates have run away (Algorithm 2 stays between the
    initial hull and X* when β_k·‖∂f‖ is small against them), so the step size is too
    large for the costs' scale. No hint when ``reach`` is 0 (nothing to compare with)."""
    if not reach:
        return ""
    size = float(np.max(np.abs(point), initial=0.0))
    if not size > DIVERGED * reach:
        return ""
    return (f" — the iterates diverged (max |x| = {size:.3g}; the initial states and X* "
            f"lie within {reach:.3g}): the step size is too large for these costs; try a "
            "smaller step_size")


def _works(oracle: Oracle, method: str, Z: np.ndarray) -> bool:
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            getattr(oracle, method)(Z)
    except Exception:  # noqa: BLE001 (only locating the row; the caller reports the error)
        return False
    return True


class SubgradientStep:
    """Algorithm 2's update x_i ← z_i − β_k d_i, d_i ∈ ∂f_i(z_i) (``betas[k]`` = β_k).

    Groups whose oracles share one atom signature form a pack, evaluated in one
    :class:`~rescon.optim.atoms.Stacked` call (agent row i with its own oracle's data);
    every other group is evaluated in one call of its oracle. A pack that answers
    NaN/inf is re-evaluated group by group through the oracles' checked calls, so that
    a subgradient that is not finite or of the wrong shape, or a step that overflows or
    leaves |x| ≤ STATE_LIMIT (the bound on initial states,
    :data:`rescon.consensus.scenario.STATE_LIMIT`, under which the monitors' distances
    stay finite), is an InputError naming the agent, the step and the point
    (``reach``: the scale of :func:`_divergence_hint`)."""

    name = "rmdo"

    def __init__(self, groups: list[_Group], n: int, betas: np.ndarray,
                 nodes: list[Hashable], reach: float | None = None) -> None:
        self.groups, self.betas, self.nodes, self.reach = groups, betas, nodes, reach
        self.group_of = np.full(n, -1, dtype=np.int64)
        by_sig: dict[Hashable, list[int]] = {}
        for g, grp in enumerate(groups):
            self.group_of[grp.rows] = g
            sig = atoms.signature(grp.oracle)
            if sig is not None:
                by_sig.setdefault(sig, []).append(g)
        packed = [gs for gs in by_sig.values() if len(gs) > 1]
        self.packs = [atoms.Stacked([groups[g].oracle for g in gs]) for gs in packed]
        self.pack_of = np.full(len(groups), -1, dtype=np.int64)
        self.member = np.zeros(len(groups), dtype=np.int64)
        for p, gs in enumerate(packed):
            self.pack_of[gs], self.member[gs] = p, np.arange(len(gs))

    def __call__(self, k: int, t: float, z: np.ndarray, agents: np.ndarray) -> np.ndarray:
        D = np.empty_like(z)
        gid = self.group_of[agents]
        pid = self.pack_of[gid]
        for p in np.unique(pid[pid >= 0]):
            sel = np.flatnonzero(pid == p)
            with np.errstate(all="ignore"):
                D[sel] = self.packs[p].subgradient(z[sel], self.member[gid[sel]])
            if not np.isfinite(D[sel]).all():
                self._per_group(D, k, t, z, agents, sel)
        self._per_group(D, k, t, z, agents, np.flatnonzero(pid < 0))
        with np.errstate(over="ignore", invalid="ignore"):
            new = z - self.betas[k] * D
        inf = np.flatnonzero(~np.isfinite(new).all(axis=1))
        bad = inf if inf.size else np.flatnonzero((np.abs(new) > STATE_LIMIT).any(axis=1))
        if bad.size:
            r = int(bad[0])
            what = ("overflows" if inf.size else f"leaves the states' bound |x| <= "
                    f"{STATE_LIMIT:g} (new point {new[r].tolist()})")
            raise InputError(f"the subgradient step of agent {self.nodes[agents[r]]!r} at step "
                             f"{k} (t = {t:g}) {what}: point {z[r].tolist()}, β = "
                             f"{self.betas[k]:g}, subgradient {D[r].tolist()}"
                             f"{_divergence_hint(z[r] if inf.size else new[r], self.reach)}")
        return new

    def _per_group(self, D: np.ndarray, k: int, t: float, z: np.ndarray, agents: np.ndarray,
                   rows: np.ndarray) -> None:
        """D[rows] by one checked call per group (its oracle on its agents' points)."""
        gid = self.group_of[agents[rows]]
        for g in np.unique(gid):
            sel = rows[gid == g]
            D[sel] = _call(self.groups[g].oracle, "subgradient", z[sel],
                           lambda r, sel=sel: self.nodes[agents[sel[r]]], _at(k, t),
                           self.reach)


class CostMonitor:
    """Per step: F(x_i) = Σ_{j∈B} f_j(x_i) for every benign state (``cost``), F at the
    benign mean (``cost_at_mean``), its change rate (``cost_rate``), and with a known
    nonempty X* ``distance_to_optimum`` and ``optimality_gap`` (see :func:`rmdo`). F is
    evaluated once per step on all benign states and their mean (:class:`GlobalCost`)."""

    def __init__(self, F: GlobalCost, steps: int, T: float, n_benign: int,
                 optimum: Optimum, reach: float | None = None) -> None:
        self.F, self.T, self.optimum, self.reach = F, T, optimum, reach
        K = steps
        self.metrics = {"cost": np.empty((K + 1, n_benign)), "cost_at_mean": np.empty(K + 1),
                        "cost_rate": np.full(K + 1, np.nan)}
        if optimum.known:
            self.metrics["distance_to_optimum"] = np.empty(K + 1)
            self.metrics["optimality_gap"] = np.empty(K + 1)

    def record(self, k: int, t: float, xb: np.ndarray) -> None:
        P = np.vstack([xb, xb.mean(axis=0)])
        F = self.F(P, _at(k, t), self.reach)
        m = self.metrics
        m["cost"][k], m["cost_at_mean"][k] = F[:-1], F[-1]
        if k:
            m["cost_rate"][k] = _rate(F[-1], m["cost_at_mean"][k - 1], self.T, k)
        if self.optimum.known:
            i = int(np.argmin(F[:-1]))
            self.optimum.improve(k, xb[i], float(F[i]))
            m["distance_to_optimum"][k] = self.optimum.distance(xb).max()
            m["optimality_gap"][k] = F[:-1].max() - self.optimum.value

    def remeasure(self, states: np.ndarray, benign: np.ndarray) -> None:
        """``distance_to_optimum`` and ``optimality_gap`` of every step against the final
        X* when a benign state improved it during the run (``states`` (K+1, N, d) every
        agent's, ``benign`` the rows to measure); steps are taken in blocks (memory: one
        block of benign states and its distances; nothing when X* was not improved)."""
        if "improved" not in self.optimum.info:  # set by Optimum.improve
            return
        m = self.metrics
        m["optimality_gap"][:] = m["cost"].max(axis=1) - self.optimum.value
        for k in range(0, len(states), REMEASURE_BLOCK):
            X = states[k:k + REMEASURE_BLOCK][:, benign]
            dist = self.optimum.distance(X.reshape(-1, X.shape[2]))
            m["distance_to_optimum"][k:k + len(X)] = dist.reshape(len(X), -1).max(axis=1)


def _rate(new: float, old: float, T: float, k: int) -> float:
    """(new − old)/T, the float nearest the real quotient: computed in floats, and
    exactly (rationals) when that overflows (ΔF past the float range, T tiny).

    Raises
    ------
    InputError
        The real quotient itself is beyond the float range (|ΔF|/T > 1.8e308)."""
    with np.errstate(over="ignore", invalid="ignore"):
        r = (new - old) / T
    if math.isfinite(r):
        return r
    try:
        return float((Fraction(new) - Fraction(old)) / Fraction(T))
    except OverflowError:
        raise InputError(f"cost_rate overflows at step {k}: (F(x̄(t_k)) − F(x̄(t_k−1)))/T "
                         f"= ({new:g} − {old:g})/{T:g} is beyond the float range; "
                         "use a larger T") from None


def _at(k: int, t: float) -> str:
    return f"at step {k} (t = {t:g})"


class GlobalCost:
    """F(p) = Σ_{j∈B} f_j(p) = Σ over distinct oracles of (number of agents sharing it)
    × f, built once as one :class:`~rescon.optim.atoms.Merged` oracle (how it sums: see
    there). Should that fail or answer NaN/inf, :func:`global_cost` is called instead,
    so that the error names the agent, ``where`` (the step) and the point."""

    def __init__(self, groups: list[_Group], d: int) -> None:
        self.groups = groups
        self.merged = atoms.Merged([(len(g.rows), g.oracle) for g in groups], d)

    def __call__(self, P: np.ndarray, where: str = "while computing X*",
                 reach: float | None = None) -> np.ndarray:
        """F at the rows of P, finite.

        Raises
        ------
        InputError
            An oracle fails or answers NaN/inf (naming the agent), or the terms are
            finite but their sum passes the float range (naming the point)."""
        F = self.values(P, where, reach)
        bad = np.flatnonzero(~np.isfinite(F))
        if bad.size:
            raise InputError(f"the global cost F = Σ f_j overflows {where} at the point "
                             f"{P[int(bad[0])].tolist()}: every f_j is finite there but "
                             "their sum passes the float range (1.8e308); rescale the costs")
        return F

    def values(self, P: np.ndarray, where: str = "while computing X*",
               reach: float | None = None) -> np.ndarray:
        """F at the rows of P, ±inf or NaN where the finite terms' sum overflows
        (InputError when an oracle fails or answers NaN/inf)."""
        try:
            with np.errstate(all="ignore"):
                F = self.merged.value(P)
            if np.isfinite(F).all():
                return F
        except Exception:  # noqa: BLE001 (re-evaluated below, which names the agent)
            pass
        with np.errstate(all="ignore"):
            return global_cost(self.groups, P, where, reach)


def global_cost(groups: list[_Group], P: np.ndarray, where: str = "while computing X*",
                reach: float | None = None) -> np.ndarray:
    """F(p) = Σ_{j∈B} f_j(p) at every row of ``P``: Σ over distinct oracles of
    (number of agents sharing it) × its values (one checked call per oracle; ``reach``
    as in :func:`_call`)."""
    F = np.zeros(len(P))
    for grp in groups:
        F += len(grp.rows) * _call(grp.oracle, "value", P, lambda r, grp=grp: grp.labels[0],
                                   where, reach)
    return F


class Optimum:
    """X* = argmin F, F = Σ_{i∈B} f_i, as far as it is known.

    ``known`` (X* nonempty and found), ``value`` F* (F at the float point of X* used),
    ``distance(X)`` (rows' distances to X*), ``info`` (JSON-ready: ``method`` "given",
    "exact (quadratic)" or "numerical (...)", ``exact``, ``point``, ``value``, and
    ``dimension`` of X* or ``reason`` when X* is empty or not found).

    A numerical X* is only an estimate: should a benign state reach a lower F during
    the run, that state becomes the estimate (:meth:`improve`; ``info`` says which
    state, step and by how much) and :func:`rmdo` measures ``distance_to_optimum`` and
    ``optimality_gap`` of the whole run against the final estimate
    (:meth:`CostMonitor.remeasure`): the gap is never negative, and a state that ties
    F* up to rounding (flat argmins) becomes the estimate too — another point of the
    same argmin, F* changed by that rounding only."""

    def __init__(self, point: np.ndarray | None, basis: np.ndarray | None, value: float,
                 info: dict[str, Any]) -> None:
        self.point, self.basis, self.value, self.info = point, basis, value, info
        self.known = point is not None

    def improve(self, k: int, x: np.ndarray, f: float) -> bool:
        """Make the benign state ``x`` (F = ``f``) at step k the estimate of a numerical
        X* when ``f`` < F*; True if it did (``info`` records the step, the point, the
        value and the first estimate's value)."""
        if not (self.info.get("method", "").startswith("numerical") and f < self.value):
            return False
        first = self.info.pop("estimated_value", self.value)
        self.point, self.value = np.array(x, dtype=float), f
        self.info.update(point=self.point.tolist(), value=f, estimated_value=first,
                         improved=f"by a benign state at step {k} (Nelder-Mead's value "
                                  f"{first:.17g}); distances and gaps of the whole run are "
                                  "measured against it")
        return True

    def distance(self, X: np.ndarray) -> np.ndarray:
        """‖(x − x₀) − U Uᵀ(x − x₀)‖ for X* = x₀ + range(U) (U orthonormal, maybe empty).

        Each row r = x − x₀ is scaled by 2^-e, e the exponent of max |r| (exact but for
        subnormal entries), so that the squares neither overflow (x₀ at 1e200) nor
        underflow; the norm is then scaled back by 2^e (inf only when the distance
        itself is past the float range)."""
        R = X - self.point
        e = np.frexp(np.abs(R).max(axis=1))[1]
        R = np.ldexp(R, -e[:, None])
        if self.basis is not None and self.basis.size:
            R = R - (R @ self.basis) @ self.basis.T
        with np.errstate(over="ignore"):
            return np.ldexp(np.linalg.norm(R, axis=1), e)

    @classmethod
    def find(cls, groups: list[_Group], F: GlobalCost, d: int, given: Any, x0: np.ndarray
             ) -> Optimum:
        """From ``given`` (a point), else exactly for quadratic/affine atoms, else
        numerically from the benign initial states ``x0``; F* by ``F``."""
        if given is not None:
            p = _given_point(given, d)
            val = float(F(p[None])[0])
            return cls(p, None, val, {"method": "given", "exact": False, "point": p.tolist(),
                                      "value": val})
        H = _quadratic_hessian(groups, d)
        if H is not None:
            return cls._exact(F, d, *H)
        return cls._numerical(F, x0)

    @classmethod
    def _exact(cls, F: GlobalCost, d: int, H: list[list[Fraction]],
               g: list[Fraction]) -> Optimum:
        """F(x) = ½ xᵀHx + gᵀx + const with H ⪰ 0 (exact rationals of the atoms' float
        data): X* = {x : Hx = −g}, solved by exact row reduction; empty (F unbounded
        below) when −g ∉ range(H)."""
        from ..geometry.exact import _rref, nullspace_exact

        A = [row + [-gi] for row, gi in zip(H, g, strict=True)]
        pivots = _rref(A, d)
        info: dict[str, Any] = {"method": "exact (quadratic)", "exact": True}
        # X* exactly; ``point`` is its float rounding (distances are float computations)
        if any(A[i][d] != 0 for i in range(len(pivots), d)):
            info["reason"] = "F is unbounded below (−∇ of its linear part ∉ range of its Hessian)"
            return cls(None, None, -math.inf, info)
        x = [Fraction(0)] * d
        for i, c in enumerate(pivots):
            x[c] = A[i][d]
        p = np.array([float(v) for v in x])
        null = nullspace_exact(H)
        U = np.linalg.qr(np.array(null, dtype=float).T)[0] if null else None
        val = float(F(p[None])[0])
        info.update(point=p.tolist(), value=val, dimension=len(null))
        return cls(p, U, val, info)

    @classmethod
    def _numerical(cls, F: GlobalCost, x0: np.ndarray) -> Optimum:
        """Nelder–Mead (scipy) in a scaled frame x = c + s·y, restarted until F stops
        decreasing; X* is taken as the point found (a numerical estimate).

        F can look flat in floats near the benign mean m when its argmin is far (its
        ulp there exceeds its change), so the scale is probed first: c is the best of m
        and m ± s e_i, s = 2^(8j) s₀ (s₀ the power of two just above 1 + max |x0|,
        while finite), and s the probe step of the best. Each round minimises y ↦ F(c + s y)
        from y = 0 with scipy's default initial simplex (a simplex of size 1/2 ran into
        maxfev on the paper's costs: 16 000 evaluations, 2 s) and xatol 1e-12 (relative
        to s), then recentres c on the answer and sets s to the power of two ≥ its move (at
        least 1e-12 s). Points where F overflows count as +inf (probes also where it
        fails: a cost's domain may be bounded); a minimiser past |x| ≤
        :data:`STATE_LIMIT` (where no state can go) is "not found"."""
        from scipy.optimize import minimize

        def Fx(x: np.ndarray, probe: bool = False) -> float:
            """F(x); +inf where it overflows (and, for a probe, where an oracle fails
            or answers NaN: a cost's domain may be bounded); else such an oracle
            raises the named InputError of :meth:`GlobalCost.values`."""
            if not np.isfinite(x).all():
                return math.inf
            try:
                v = float(F.values(x[None])[0])
            except InputError:
                if not probe:
                    raise
                v = math.nan
            return math.inf if math.isnan(v) else v

        d = x0.shape[1]
        s0 = math.ldexp(1.0, math.frexp(1.0 + float(np.abs(x0).max()))[1])
        x, s = x0.mean(axis=0), s0
        best = Fx(x)
        for j in range(0, 1024 - math.frexp(s0)[1], 8):
            step = math.ldexp(s0, j)
            for i in range(d):
                for sign in (1.0, -1.0):
                    y = x0.mean(axis=0)
                    y[i] += sign * step
                    v = Fx(y, probe=True)
                    if v < best:
                        x, s, best = y, step, v
        for _ in range(10):
            res = minimize(lambda y, c=x, s=s: Fx(c + s * y), np.zeros(d),
                           method="Nelder-Mead",
                           options={"xatol": 1e-12, "fatol": 0.0,
                                    "maxiter": 4000 * d, "maxfev": 8000 * d})
            if not res.fun < best:
                break
            move = s * np.abs(res.x).max()
            x, best = x + s * res.x, float(res.fun)
            s = math.ldexp(1.0, math.frexp(max(move, 1e-12 * s))[1])
        info: dict[str, Any] = {"method": "numerical (scipy Nelder-Mead, restarted)",
                                "exact": False}
        if not (math.isfinite(best) and np.abs(x).max() <= STATE_LIMIT):
            info["reason"] = ("no minimiser found with |x| <= 1e150 (the state limit): F "
                              "may be unbounded below")
            return cls(None, None, -math.inf, info)
        info.update(point=x.tolist(), value=best,
                    note="distances are to this point; X* may contain more")
        return cls(np.asarray(x, dtype=float), None, best, info)


def _given_point(value: Any, d: int) -> np.ndarray:
    try:
        p = np.array(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InputError(f"optimum must be a point of R^{d}; got {type(value).__name__}") from None
    if p.shape != (d,) or not np.isfinite(p).all():
        raise InputError(f"optimum must be a finite point of R^{d}; got {value!r}")
    return p


def _quadratic_hessian(groups: list[_Group], d: int
                       ) -> tuple[list[list[Fraction]], list[Fraction]] | None:
    """(H, g) with Σ_{i∈B} f_i = ½ xᵀHx + gᵀx + const, exactly from the atoms' data as
    given (``Atom.exact``: a cost string's 0.3 is 3/10), when every cost is built of
    Quadratic / Affine atoms, sums and scalings; else None."""
    H = [[Fraction(0)] * d for _ in range(d)]
    g = [Fraction(0)] * d
    for grp in groups:
        if not _add_quadratic(grp.oracle, Fraction(len(grp.rows)), H, g):
            return None
    return H, g


def _add_quadratic(o: Any, w: Fraction, H: list[list[Fraction]], g: list[Fraction]) -> bool:
    """Add w·f's (Hessian, linear part) to (H, g); False when f is not a known quadratic.
    Quadratic ½(x − c)ᵀQ(x − c) + qᵀx: Hessian Q, linear part q − Qc; Affine aᵀx + b: a."""
    if isinstance(o, atoms.Quadratic):
        Q, c, q = o.exact["Q"], o.exact["c"], o.exact["q"]
        for i, row in enumerate(Q):
            g[i] += w * (q[i] - sum(a * b for a, b in zip(row, c, strict=True)))
            for j, v in enumerate(row):
                H[i][j] += w * v
        return True
    if isinstance(o, atoms.Affine):
        for i, v in enumerate(o.exact["a"]):
            g[i] += w * v
        return True
    if isinstance(o, atoms.Scaled):
        return _add_quadratic(o.term, w * o.exact["coef"], H, g)
    if isinstance(o, atoms.Sum):
        return all(_add_quadratic(t, w, H, g) for t in o.terms)
    return False
