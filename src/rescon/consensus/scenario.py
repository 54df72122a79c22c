"""A consensus experiment: graph, initial states, attacks, algorithm and its parameters.

Build one in Python (:class:`Scenario`), from a TOML file (:meth:`Scenario.from_toml`,
format in the README) or take the paper's example (:meth:`Scenario.paper_example`,
SPEC §5). Inputs are validated once, here; assumptions of the paper's theorems that
the scenario violates (Assumption 2, the F-local / F-total model, ((d+1)F+1)-
robustness for F-local and (dF+1, F+1)-robustness for F-total, Assumption 3 on the
DoS attacks, benign agents whose in-links are all blocked for the whole run) are
reported as :class:`ScenarioWarning` with their witnesses, and conditions that could
not be decided are reported as such, with what is known — the run still goes ahead,
because showing what happens then is the point.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import tomllib
import warnings
from collections.abc import Callable, Collection, Hashable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import networkx as nx
import numpy as np

from .._labels import sorted_labels
from .._validate import integer, positive, real
from ..errors import InputError
from ..geometry._budget import require
from .adversaries import Behaviour, behaviour_from_dict, paper_adversaries
from .dos import DoSAttack, _attacks, attack_from_dict, paper_attacks

__all__ = ["ALGORITHMS", "CENTRES", "POLICIES", "Scenario", "ScenarioWarning"]

POLICIES = ("hold", "zero", "drop")
ALGORITHMS = ("alg1", "kernel", "wmsr", "mean")
CENTRES = ("box", "mean", "centroid")
KERNEL_POINTS = ("project", "project-exact", "vertex-mean")
#: seconds the robustness condition of the theorems may take before it is reported as
#: not decided (with bounds)
ROBUSTNESS_SECONDS = 5.0
_BOUNDS_SECONDS = 0.01  # rescon.robustness past this: the polynomial bounds only
_DOS_CHUNK = 4096  # update times per blocked-mask block in the cut-off check


class ScenarioWarning(UserWarning):
    """An assumption of the convergence theorems does not hold for this scenario."""


#: largest |entry| of an initial state (and of an RMDO iterate: optim/rmdo.py refuses
#: one beyond it): distances between states are computed in floats, and
#: Σ_p (x_p − y_p)² ≤ d·(2·10^150)² stays finite for any d below 4·10^7
STATE_LIMIT = 1e150


def _reals(name: str, value: Any) -> np.ndarray:
    """``value`` as a float array whose every entry is a real number (no bool, string,
    complex or None, which numpy would convert or refuse with its own error)."""
    if isinstance(value, np.ndarray) and value.dtype.kind in "iuf":
        return value.astype(np.float64)
    try:
        obj = np.asarray(value, dtype=object)
    except ValueError:  # ragged nesting numpy cannot even hold as objects
        raise InputError(f"{name} must be an array of real numbers; got {value!r}") from None
    return np.array([real(name, v) for v in obj.reshape(-1)],
                    dtype=np.float64).reshape(obj.shape)


def _state(name: str, value: Any) -> np.ndarray:
    """One initial state: a real number or a flat list of real numbers, as a (d,) array."""
    arr = _reals(name, value)
    if arr.ndim > 1:
        raise InputError(f"{name} must be a flat list of real numbers; got shape {arr.shape}")
    return arr.reshape(-1)


def _memory_bytes() -> int:
    """This machine's physical memory (2^36 bytes where the OS does not say)."""
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return 2**36


def _check_trajectory_size(steps: int, n: int, d: int, adversaries: int) -> None:
    """Refuse a run whose trajectory cannot fit in memory: it holds K + 1 states of
    N·d floats, plus per step the spread (d), per-agent validity (≤ N), 4 scalars and
    the range (low, high) of what each of the |A| adversaries sent (2·|A|·d), i.e.
    8·(K + 1)·(N·d + N + d + 4 + 2·|A|·d) bytes."""
    need = 8 * (steps + 1) * (n * d + n + d + 4 + 2 * adversaries * d)
    have = _memory_bytes()
    if need > have:
        raise InputError(f"steps = {steps}: the trajectory would need {_bytes(need)} "
                         f"(8·(steps+1)·(N·d + N + d + 4 + 2·|A|·d) bytes, N = {n}, d = {d}, "
                         f"|A| = {adversaries}), more than this machine's {_bytes(have)} of "
                         f"memory")


def _bytes(b: float) -> str:
    """``b`` bytes in binary units, 3 significant digits (e.g. "2.84 PiB")."""
    units = ("B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB")
    k = 0
    while b >= 1024 and k < len(units) - 1:
        b, k = b / 1024, k + 1
    return f"{b:.3g} {units[k]}"


@dataclass(frozen=True)
class Residual:
    """ε(t) = r^t (r ∈ (0, 1)), or ε ≡ 0 when r = 0: a picklable callable whose spec
    (:meth:`spec`) reads back through :func:`_residual`."""

    r: float = 0.0

    def __call__(self, t: float) -> float:
        return self.r**t if self.r else 0.0

    def spec(self) -> str:
        """"none" or "r^t" (r written so that float() gives r back exactly)."""
        return f"{self.r!r}^t" if self.r else "none"


def _residual(spec: Any) -> Callable[[float], float]:
    """ε(t): "none" (0), "0.1^t" / a number r ∈ (0, 1) (r^t), or a callable."""
    if callable(spec):
        return spec
    if spec in (None, "none", 0, 0.0):
        return Residual()
    if isinstance(spec, str) and spec.endswith("^t"):
        try:
            spec = float(spec[:-2])
        except ValueError:
            raise InputError(f"residual must be 'none', 'r^t' or a number r in (0, 1); "
                             f"got {spec!r}") from None
    if isinstance(spec, (int, float)) and not isinstance(spec, bool) and 0 < spec < 1:
        return Residual(float(spec))
    raise InputError(f"residual must be 'none', 'r^t' or a number r in (0, 1); got {spec!r}")


@dataclass(frozen=True)
class Scenario:
    """One run of Algorithm 1 (or a baseline).

    Parameters
    ----------
    graph : networkx.DiGraph (an undirected Graph counts both ways); edge (u, v):
        v receives u's state.
    x0 : mapping node → initial state (d,), or an (N, d) array in ``graph`` node order.
        Adversaries' rows are only used for plotting before they first send.
    F : the adversary bound of the algorithm.
    adversaries : mapping node → behaviour (:mod:`rescon.consensus.adversaries`).
    dos : DoS attacks; their links (i, j) = agent i's link from j, in node labels.
    T : sampling period (s); t_k = k T.
    steps : number of updates K (the trajectory has K + 1 states).
    model : "local" or "total" (F-local / F-total), checked against the graph.
    policy : what a blocked link delivers: "hold" (the last value received before the
        attack — Algorithm 1), "zero" (the zero vector — the baseline the paper shows
        failing) or "drop" (nothing).
    algorithm : "alg1" (Algorithm 1), "kernel" (a safe-kernel point of all received
        values, Yan et al. 2022), "wmsr" (coordinate-wise W-MSR) or "mean".
    centre : Cen(Λ) of Algorithm 1: "mean" (default: the mean of the 2d points of Λ,
        inside conv Λ as the validity proof needs), "centroid" (the centroid of conv Λ,
        the paper's definition, exact, d ≤ 3; slower) or "box" ((min + max)/2 per
        coordinate, what the agreement proof computes; it can leave conv Λ and the
        benign hull).
    alpha : α_i, a number, a mapping node → number, or one number per node in node
        order (what the field holds after construction, so ``dataclasses.replace``
        works); must satisfy α_i < c and 1 − α_i < c.
    c : the constant 0.5 < c < 1 of the convergence theorem.
    residual : ε_i(t_k) added to every coordinate: "0.1^t" (the paper), "none", a
        number r (r^t) or a callable t → float.
    seed : seed of the one numpy Generator behind every random choice.
    kernel_point : which point of Ψ(Y, F) the algorithm picks: "project" (closest to
        the mean of Y; in the plane by the batch path — exact decisions, float geometry
        within a certified ~1e-15 relative bound — else exactly), "project-exact" (the
        same point, all in exact arithmetic) or "vertex-mean".
    check_robustness : let :meth:`assumptions` decide the graph condition of the
        theorems (up to :data:`ROBUSTNESS_SECONDS`, then bounds); False skips it.
    """

    graph: Any
    x0: Any
    F: int
    adversaries: Mapping[Hashable, Any] = field(default_factory=dict)
    dos: tuple[DoSAttack, ...] = ()
    T: float = 0.5
    steps: int = 200
    model: str = "local"
    policy: str = "hold"
    algorithm: str = "alg1"
    centre: str = "mean"
    alpha: Any = 0.5
    c: float = 0.75
    residual: Any = "0.1^t"
    seed: int = 0
    kernel_point: str = "project"
    check_robustness: bool = True

    def __post_init__(self) -> None:
        G = self.graph
        if not isinstance(G, (nx.Graph, nx.DiGraph)) or G.number_of_nodes() < 2:
            raise InputError(f"graph must be a networkx graph with at least 2 nodes; got "
                             f"{type(G).__name__}")
        D = G if G.is_directed() else G.to_directed()
        object.__setattr__(self, "graph", nx.DiGraph(D))
        nodes = list(self.graph.nodes)
        object.__setattr__(self, "x0", self._states(nodes))
        for name in ("F", "steps", "seed"):
            object.__setattr__(self, name, integer(name, getattr(self, name), low=0))
        object.__setattr__(self, "T", positive("T", self.T, what="number of seconds"))
        try:
            horizon = self.steps * self.T
        except OverflowError:  # steps beyond the float range
            horizon = math.inf
        if not math.isfinite(horizon):
            raise InputError(f"steps·T = {self.steps}·{self.T:g} passes the float range: the "
                             f"step times t_k = k·T must be finite numbers of seconds")
        if not isinstance(self.check_robustness, bool):
            raise InputError(f"check_robustness must be True or False; got "
                             f"{self.check_robustness!r}")
        for name, value, allowed in (("model", self.model, ("local", "total")),
                                     ("policy", self.policy, POLICIES),
                                     ("algorithm", self.algorithm, ALGORITHMS),
                                     ("centre", self.centre, CENTRES),
                                     ("kernel_point", self.kernel_point, KERNEL_POINTS)):
            if value not in allowed:
                raise InputError(f"{name} must be one of {', '.join(allowed)}; got {value!r}")
        if self.centre == "centroid" and self.d > 3:
            raise InputError(f"centre 'centroid' is computed for d <= 3; got d = {self.d} "
                             "(use 'mean')")
        if not isinstance(self.adversaries, Mapping):
            raise InputError("adversaries must be a mapping node -> Behaviour; got "
                             f"{type(self.adversaries).__name__}")
        unknown = [a for a in self.adversaries if a not in self.graph]
        if unknown:
            raise InputError(f"adversaries {unknown} are not nodes of the graph")
        for a, beh in self.adversaries.items():
            if not isinstance(beh, Behaviour):
                raise InputError(f"adversaries[{a!r}] must be a Behaviour; got {beh!r}")
        object.__setattr__(self, "dos", _attacks(self.dos))
        for att in self.dos:
            missing = [(i, j) for i, j in att.links if not self.graph.has_edge(j, i)]
            if missing:
                raise InputError(f"DoS attack {att.name!r}: links {missing} (i, j) = agent "
                                 "i's link from j are not edges j -> i of the graph")
        object.__setattr__(self, "alpha", self._alphas(nodes))
        object.__setattr__(self, "residual", _residual(self.residual))
        benign = [v for v in nodes if v not in self.adversaries]
        _check_trajectory_size(self.steps, len(nodes), self.d, len(nodes) - len(benign))
        low = [v for v in benign if self.graph.in_degree(v) <= self.F]
        if low:
            raise InputError(f"F = {self.F} must be below every benign agent's in-degree; "
                             f"agents {low[:5]} have in-degree <= F")

    # ------------------------------------------------------------------ #

    @property
    def nodes(self) -> list[Hashable]:
        return list(self.graph.nodes)

    @property
    def d(self) -> int:
        return self.x0.shape[1]

    @property
    def benign(self) -> list[Hashable]:
        return [v for v in self.graph.nodes if v not in self.adversaries]

    def _states(self, nodes: list[Hashable]) -> np.ndarray:
        x0 = self.x0
        if isinstance(x0, Mapping):
            missing = [v for v in nodes if v not in x0]
            extra = [v for v in x0 if v not in self.graph]
            if extra:
                raise InputError(f"x0 has states for {extra}, which are not nodes of the graph")
            if missing:
                raise InputError(f"x0 has no state for nodes {missing[:5]}")
            rows = [_state(f"x0[{v!r}]", x0[v]) for v in nodes]
            if len({r.shape for r in rows}) != 1:
                raise InputError("x0: every state must have the same dimension d; got "
                                 f"{sorted({r.shape[0] for r in rows})}")
            arr = np.array(rows)
        else:
            arr = _reals("x0", x0)
            if arr.ndim != 2 or arr.shape[0] != len(nodes):
                raise InputError(f"x0 must have shape (N, d) = ({len(nodes)}, d); got "
                                 f"{arr.shape}")
        if arr.shape[1] < 1 or not np.isfinite(arr).all():
            raise InputError(f"x0 must be finite with d >= 1; got shape {arr.shape}")
        top = float(np.abs(arr).max())
        if top > STATE_LIMIT:
            raise InputError(f"x0 entries must be at most {STATE_LIMIT:g} in absolute value "
                             "(squared distances between states must be finite floats); "
                             f"got {top:g}")
        arr.setflags(write=False)
        return arr

    def _alphas(self, nodes: list[Hashable]) -> np.ndarray:
        c = real("c", self.c)
        if not 0.5 < c < 1:
            raise InputError(f"c must satisfy 0.5 < c < 1; got {self.c!r}")
        a = self.alpha
        if isinstance(a, Mapping):
            arr = np.array([real(f"alpha[{v!r}]", a.get(v, 0.5)) for v in nodes])
        elif not isinstance(a, str) and np.ndim(a) == 1:
            if len(a) != len(nodes):
                raise InputError(f"alpha must be a number, a mapping node -> number or "
                                 f"{len(nodes)} numbers in node order; got {len(a)} numbers")
            arr = np.array([real(f"alpha[{v!r}]", x) for v, x in zip(nodes, a, strict=True)])
        else:
            arr = np.full(len(nodes), real("alpha", a))
        bad = [v for v, x in zip(nodes, arr, strict=True) if not (x < c and 1 - x < c)]
        if bad:
            raise InputError(f"alpha must satisfy alpha < c and 1 - alpha < c (c = {c}); "
                             f"agents {bad[:5]} violate it")
        arr.setflags(write=False)
        return arr

    # ------------------------------------------------------------------ #

    def assumptions(self) -> list[str]:
        """The theorem assumptions this scenario violates, each with its witness, and
        the ones that could not be decided, each with what is known."""
        from ..graphs.attacks import check_assumption2, check_attack_model

        out = []
        a2 = check_assumption2(self.graph, self.d, self.F, adversaries=list(self.adversaries))
        if not a2.holds:
            out.append(f"Assumption 2 fails: (d+1)F+1 = {a2.required} in-neighbours needed; "
                       f"(agent, in-degree): {list(a2.violations)[:5]}")
        am = check_attack_model(self.graph, list(self.adversaries), self.F, model=self.model)
        if not am.holds:
            out.append(f"the adversaries are not F-{self.model} (F = {self.F}): "
                       f"{list(am.violations)[:5]}")
        if self.check_robustness:
            out.extend(self._robustness_problems())
        if self.dos:
            out.extend(self._dos_problems())
        return out

    def _robustness_problems(self) -> list[str]:
        """The graph condition of the theorems: ((d+1)F+1)-robust for the F-local model,
        (dF+1, F+1)-robust for the F-total one. Decided by :func:`is_rs_robust` within
        :data:`ROBUSTNESS_SECONDS` at any N; when that stops undecided, the polynomial
        bounds r_lower ≤ ρ(G) ≤ r_upper of :func:`rescon.robustness` are reported
        (r-robust ⇒ (r', s)-robust for r' + s − 1 ≤ r, so ρ ≥ r + s − 1 would settle it)."""
        from ..graphs.robustness import is_rs_robust, robustness

        d, F = self.d, self.F
        if self.model == "local":
            r, s, need = (d + 1) * F + 1, 1, f"{(d + 1) * F + 1}-robust (= (d+1)F+1)"
        else:
            r, s, need = d * F + 1, F + 1, f"({d * F + 1}, {F + 1})-robust (= (dF+1, F+1))"
        res = is_rs_robust(self.graph, r, s, time_limit=ROBUSTNESS_SECONDS)
        witness = res.witness
        if res.holds is None:
            rep = robustness(self.graph, time_limit=_BOUNDS_SECONDS, progress=False)
            if rep.r_lower >= r + s - 1:
                return []
            if rep.r_upper >= r:
                return [(f"not decided within {ROBUSTNESS_SECONDS:g} s whether the graph is "
                         f"{need} as the theorems need for the F-{self.model} model: "
                         f"{rep.r_lower} <= rho(G) <= {rep.r_upper} (rho >= {r + s - 1} "
                         f"suffices, rho < {r} fails)")]
            witness = rep.witness  # G is not (r_upper + 1)-robust, r_upper + 1 <= r
        elif res.holds:
            return []
        return [(f"the graph is not {need} as the theorems need for the F-{self.model} "
                 f"model; witness S1 = {sorted_labels(witness[0])}, "
                 f"S2 = {sorted_labels(witness[1])}")]

    def _dos_problems(self) -> list[str]:
        """Assumption 3 for some T_d > 1, μ_d > 0 (it holds iff the long-run blocked
        fraction of Π_D is below 1, :func:`check_assumption3`), and benign agents whose
        in-links are all blocked at every update t_k = kT, k < steps."""
        from .dos import check_assumption3

        out = []
        horizon = self.steps * self.T
        a3 = check_assumption3(self.dos, horizon, T_d=math.inf)
        if a3.any_T_d_works is False:
            w = a3.witness
            seen = (f"; on [0, {horizon:g}] s: [{w.t1:g}, {w.t2:g}] s holds {w.blocked:g} s "
                    "blocked" if w is not None else "")
            out.append("Assumption 3 fails: the DoS attacks block links for a long-run "
                       f"fraction {a3.long_run_fraction} of the time, so no T_d > 1, "
                       f"mu_d > 0 bound |Pi_D(t1, t2)| <= mu_d + (t2 - t1)/T_d{seen}")
        elif a3.any_T_d_works is None:
            out.append(f"Assumption 3 not decided: {' '.join(a3.notes)}")
        cut = self._cut_off_agents()
        if cut:
            out.append("DoS blocks every in-link of benign agents at every update "
                       f"(t_k = kT, k < {self.steps}): {cut[:5]}")
        return out

    def _cut_off_agents(self) -> list[Hashable]:
        """Benign agents all of whose in-links are blocked at every update time."""
        from .dos import blocked_mask_series

        links = [(i, j) for j, i in self.graph.edges if i != j]
        index = {link: k for k, link in enumerate(links)}
        always = np.full(len(links), self.steps > 0)
        for k0 in range(0, self.steps, _DOS_CHUNK):
            ts = np.arange(k0, min(k0 + _DOS_CHUNK, self.steps)) * self.T
            always &= blocked_mask_series(self.dos, index, ts).all(axis=0)
            if not always.any():
                return []
        cut = []
        for i in self.benign:
            ins = [index[(i, j)] for j in self.graph.predecessors(i) if j != i]
            if ins and always[ins].all():
                cut.append(i)
        return cut

    def warn(self) -> list[str]:
        """Issue a ScenarioWarning for every violated assumption; returns them."""
        problems = self.assumptions()
        for p in problems:
            warnings.warn(p, ScenarioWarning, stacklevel=3)
        return problems

    # ------------------------------------------------------------------ #

    @classmethod
    def paper_example(cls, **overrides: Any) -> Scenario:
        """SPEC §5: N = 12, d = 2, F = 2, adversaries 2 and 12, T = 0.5 s, α = 0.5,
        residual 0.1^t, DoS_1..3 on the table's links with the documented periodic
        timing of :func:`rescon.consensus.dos.paper_schedules`. The adversaries' own
        in-neighbours are not in the paper (they do not matter for the dynamics);
        every other agent is taken as one."""
        table = {1: (2, 3, 5, 7, 9, 10, 11, 12), 3: (1, 2, 4, 5, 6, 7, 11),
                 4: (2, 3, 5, 8, 9, 10, 12), 5: (1, 3, 4, 6, 7, 11, 12),
                 6: (2, 3, 5, 7, 9, 10, 11), 7: (1, 2, 3, 5, 8, 9, 10, 11),
                 8: (2, 3, 5, 7, 9, 11, 12), 9: (1, 3, 5, 7, 8, 10, 12),
                 10: (1, 3, 5, 7, 9, 11, 12), 11: (1, 3, 4, 5, 8, 9, 12)}
        G = nx.DiGraph()
        G.add_nodes_from(range(1, 13))
        for i, nbrs in table.items():
            G.add_edges_from((j, i) for j in nbrs)
        for adv in (2, 12):
            G.add_edges_from((j, adv) for j in range(1, 13) if j != adv)
        x0 = {1: (0, 0), 3: (0, 4), 4: (2, 8), 5: (4, 12), 6: (6, 18), 7: (8, 10),
              8: (10, 7), 9: (10, 6), 10: (10, 2), 11: (10, 0)}
        adversaries = paper_adversaries()
        for a, beh in adversaries.items():
            x0[a] = tuple(np.asarray(beh.f(0.0), dtype=float))
        kw: dict[str, Any] = {"graph": G, "x0": x0, "F": 2, "adversaries": adversaries,
                              "dos": tuple(paper_attacks()), "T": 0.5, "steps": 200,
                              "alpha": 0.5, "residual": "0.1^t"}
        kw.update(overrides)
        return cls(**kw)

    @classmethod
    def from_toml(cls, path: str | Path) -> Scenario:
        """Read a scenario file (format: README, "Scenario files"). A file with
        [costs] or [step_size] describes an RMDO run and is refused here: read it with
        :func:`rescon.optim.read_rmdo` (``rescon rmdo``)."""
        data = read_toml(path)
        p = Path(path)
        return cls.from_dict(data, base=p.parent, where=str(p))

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], *, base: str | Path = ".",
                  where: str = "scenario") -> Scenario:
        """The scenario of a scenario file's tables as a dict ({"scenario": {...},
        "graph": {...}, "initial": {...}, "adversaries": {...}, "dos": [...]}) — the one
        parser behind :meth:`from_toml` and sweep grids; files it names are relative to
        ``base``; ``where`` prefixes error messages."""
        if not isinstance(data, Mapping):
            raise InputError(f"{where}: a scenario must be a dict of tables; got "
                             f"{type(data).__name__}")
        return _from_dict(data, Path(base), where)

    def to_dict(self) -> dict[str, Any]:
        """This scenario as plain data (lists, numbers, strings; TOML-ready with node
        labels as keys): ``Scenario.from_dict(s.to_dict())`` rebuilds it. A callable
        residual or a behaviour without a dict form (e.g. a TwoFaced given a Python
        function) has none: InputError naming it."""
        if not isinstance(self.residual, Residual):
            raise InputError("residual: a callable residual has no dict form (use 'none', "
                             "'r^t' or a number r)")
        alpha = (float(self.alpha[0]) if (self.alpha == self.alpha[0]).all()
                 else {str(v): float(a) for v, a in zip(self.nodes, self.alpha, strict=True)})
        sc = {"F": self.F, "T": self.T, "steps": self.steps, "model": self.model,
              "policy": self.policy, "algorithm": self.algorithm, "centre": self.centre,
              "alpha": alpha, "c": float(self.c), "residual": self.residual.spec(),
              "seed": self.seed, "kernel_point": self.kernel_point,
              "check_robustness": self.check_robustness}
        return {"scenario": sc,
                "graph": {"nodes": self.nodes, "edges": [[u, v] for u, v in self.graph.edges]},
                "initial": {str(v): x.tolist() for v, x in zip(self.nodes, self.x0,
                                                                 strict=True)},
                "adversaries": {str(v): _behaviour_dict(v, b)
                                for v, b in self.adversaries.items()},
                "dos": [{"name": a.name, "links": sorted([i, j] for i, j in a.links),
                         "schedule": a.schedule.to_dict()} for a in self.dos]}


def read_toml(path: Any, what: str = "scenario file") -> dict:
    """The parsed TOML of a scenario (or costs, RMDO, sweep grid: ``what``) file, read as
    UTF-8 with an optional byte-order mark (as :mod:`rescon.io` reads graph and point
    files); a path that is not a str / os.PathLike, a directory, a missing, undecodable
    or malformed file is an InputError naming it (:func:`rescon.io.input_file`)."""
    from ..io import input_file

    path = input_file(path, what, missing=f"{{path}}: no such {what}")
    try:
        return tomllib.loads(path.read_text(encoding="utf-8-sig"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{path}: malformed TOML ({exc})") from None
    except OSError as exc:  # unreadable (permissions), or gone since input_file looked
        raise InputError(f"{path}: cannot read the {what} "
                         f"({exc.strerror or exc})") from None


_TOP = {"scenario", "graph", "initial", "adversaries", "dos"}
#: top-level tables of an RMDO file (:func:`rescon.optim.read_rmdo`), not of a scenario
RMDO_TABLES = ("costs", "step_size")
_SCENARIO = {"F", "T", "steps", "model", "policy", "algorithm", "centre", "alpha", "c",
             "residual", "seed", "kernel_point", "paper_example", "check_robustness"}
_GRAPH = {"edgelist", "edges", "undirected", "nodes"}


def _behaviour_dict(node: Hashable, beh: Behaviour) -> dict[str, Any]:
    """``beh.to_dict()`` when it reads back to an equal behaviour, else InputError."""
    try:
        d = beh.to_dict()
        same = behaviour_from_dict(d) == beh
    except (InputError, TypeError, ValueError):
        same = False
    if not same:
        raise InputError(f"adversaries[{node!r}]: {type(beh).__name__} has no dict form "
                         "(a Python function is not data)")
    return d


def _keys(d: Mapping, allowed: set[str], where: str) -> None:
    extra = sorted(set(d) - allowed)
    if extra:
        raise InputError(f"{where}: unknown keys {extra} (allowed: {sorted(allowed)})")


def _label(text: str, nodes: Collection[Hashable] | None = None) -> Hashable:
    """A TOML key (always a string) as a node label. With the graph's ``nodes``: the
    node spelled so — the string itself when it is a node (a named graph's node "1"),
    else the int it spells (decimal digits, ASCII, optional minus); a graph with both
    is ambiguous (refused). Without them: the int when the key spells one."""
    number: int | None = None
    if re.fullmatch(r"-?[0-9]+", text):
        with contextlib.suppress(ValueError):  # beyond Python's int-string limit: a name
            number = int(text)
    if nodes is None or number is None:
        return text if number is None else number
    if text in nodes and number in nodes:
        raise InputError(f"key {text!r} names two nodes of the graph, the string {text!r} "
                         f"and the integer {number}: give the graph labels of one kind")
    return text if text in nodes else number


def _table(data: Mapping, key: str, where: str) -> dict:
    """``data[key]`` as a TOML table ({} when absent)."""
    value = data.get(key, {})
    if not isinstance(value, dict):
        raise InputError(f"{where}: [{key}] must be a table; got {value!r}")
    return value


def _flag(table: Mapping, key: str, where: str) -> bool:
    """A boolean key (false when absent): "yes", 1 … are refused, not read as true."""
    value = table.get(key, False)
    if not isinstance(value, bool):
        raise InputError(f"{where}: {key} must be true or false; got {value!r}")
    return value


def _path(table: Mapping, key: str, base: Path, where: str) -> Path:
    """A file named by a string key, relative to the scenario file's directory."""
    value = table[key]
    if not isinstance(value, str) or not value:
        raise InputError(f"{where}: {key} must be a file name (a string); got {value!r}")
    return base / value


def _from_dict(data: Mapping, base: Path, where: str) -> Scenario:
    """The scenario of a parsed TOML file (format: README, "Scenario files").

    ``paper_example = true`` takes the paper's graph, states, adversaries and DoS
    attacks: a file that also gives [graph], [initial], [adversaries] or [[dos]] is
    refused rather than half used. [costs] / [step_size] (an RMDO file) are refused,
    not ignored: Algorithm 1 would silently run without the costs."""
    rmdo = [f"[{k}]" for k in RMDO_TABLES if k in data]
    if rmdo:
        raise InputError(f"{where}: {' and '.join(rmdo)} make this an RMDO file: run it with "
                         "`rescon rmdo` (rescon.optim.read_rmdo); `rescon simulate` runs "
                         "Algorithm 1, which has no costs")
    _keys(data, _TOP, where)
    sc = dict(_table(data, "scenario", where))
    _keys(sc, _SCENARIO, f"{where} [scenario]")
    if _flag(sc, "paper_example", f"{where} [scenario]"):
        del sc["paper_example"]
        given = [f"[{k}]" for k in ("graph", "initial", "adversaries") if k in data]
        given += ["[[dos]]"] * ("dos" in data)
        if given:
            raise InputError(f"{where}: paper_example = true takes the paper's graph, "
                             f"states, adversaries and DoS attacks; remove {', '.join(given)}")
        return Scenario.paper_example(**_alpha_by_label(sc, None, where))
    sc.pop("paper_example", None)
    if "graph" not in data or "initial" not in data or "F" not in sc:
        raise InputError(f"{where}: needs [graph], [initial] and scenario.F "
                         "(or scenario.paper_example = true)")
    seed = integer(f"{where} [scenario] seed", sc.get("seed", 0), low=0)
    G = _graph(_table(data, "graph", where), base, f"{where} [graph]", seed)
    nodes = set(G)
    adversaries = {}
    for k, v in _table(data, "adversaries", where).items():
        try:
            adversaries[_label(k, nodes)] = behaviour_from_dict(v)
        except InputError as exc:
            raise InputError(f"{where} [adversaries.{k}]: {exc}") from None
    return Scenario(graph=G, x0=_initial(_table(data, "initial", where), base,
                                         f"{where} [initial]", list(G), seed),
                    adversaries=adversaries, dos=_dos(data.get("dos", []), where),
                    **_alpha_by_label(sc, nodes, where))


def _alpha_by_label(sc: dict, nodes: set[Hashable] | None, where: str) -> dict:
    """[scenario] with a table ``alpha`` keyed by node labels (:func:`_label`)."""
    if isinstance(sc.get("alpha"), Mapping):  # TOML keys are strings
        try:
            sc["alpha"] = {_label(k, nodes): v for k, v in sc["alpha"].items()}
        except InputError as exc:
            raise InputError(f"{where} [scenario] alpha: {exc}") from None
    return sc


def _graph(g: Mapping, base: Path, where: str, seed: int) -> nx.DiGraph:
    """[graph]: ``edgelist`` (a graph file, any format of :func:`rescon.io.read_graph`)
    or ``edges`` (a list of [u, v], u → v, labels integers or strings); ``undirected``;
    ``nodes`` (with ``edges``, optional): every label in the order of the agents'
    indices (the order of first appearance in ``edges`` otherwise). Or ``generator``
    and its parameters (:mod:`rescon.graphs.named`), random from ``seed`` (the
    scenario's) unless the table gives its own ``seed``."""
    if "generator" in g:
        from ..graphs.named import generate

        return generate(g, seed, where=where)
    _keys(g, _GRAPH, where)
    undirected = _flag(g, "undirected", where)
    if ("edgelist" in g) == ("edges" in g):
        raise InputError(f"{where}: give one of 'edgelist' (a file) or 'edges'")
    if "edgelist" in g:
        from ..io import read_graph

        if "nodes" in g:
            raise InputError(f"{where}: nodes goes with edges, not with edgelist")
        return read_graph(_path(g, "edgelist", base, where), undirected=undirected)
    edges = g["edges"]
    if not isinstance(edges, list):
        raise InputError(f"{where}: edges must be a list of [u, v]; got {edges!r}")
    G = nx.DiGraph()
    G.add_nodes_from(_node_list(g.get("nodes", []), where))
    for e in edges:
        if not (isinstance(e, list) and len(e) == 2 and all(
                isinstance(v, (int, str)) and not isinstance(v, bool) for v in e)):
            raise InputError(f"{where}: edges: each edge is [u, v] with integer or string "
                             f"labels; got {e!r}")
        G.add_edge(e[0], e[1])
    return G.to_undirected().to_directed() if undirected else G


def _node_list(nodes: Any, where: str) -> list[Hashable]:
    """[graph] nodes: a list of distinct integer or string labels."""
    if not (isinstance(nodes, list) and all(isinstance(v, (int, str)) and not isinstance(
            v, bool) for v in nodes) and len(set(nodes)) == len(nodes)):
        raise InputError(f"{where}: nodes must be a list of distinct integer or string "
                         f"labels; got {nodes!r}")
    return nodes


def _initial(init: Mapping, base: Path, where: str, nodes: list[Hashable],
             seed: int) -> Any:
    """[initial]: ``file`` (points, one row per node in graph order), ``random`` (a
    seeded uniform box, :func:`_random_states`) or one key per node holding its state
    (a number or a list of numbers)."""
    if isinstance(init.get("random"), Mapping):
        if len(init) > 1:
            raise InputError(f"{where}: give either random or one state per node, not both")
        return _random_states(init["random"], len(nodes), seed, f"{where} random")
    if "file" in init:
        if len(init) > 1:
            raise InputError(f"{where}: give either file or one state per node, not both")
        from ..io import read_points

        return read_points(_path(init, "file", base, where))
    names = set(nodes)
    try:
        labels = {k: _label(k, names) for k in init}
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    return {labels[k]: _state(f"{where} {k}", v) for k, v in init.items()}


def _random_states(box: Mapping, n: int, seed: int, where: str) -> np.ndarray:
    """``random = {low, high, d, seed}``: n states drawn uniformly from the box
    [low, high]^d (low, high: numbers, or lists of d numbers, then d may be omitted)
    with ``numpy.random.default_rng([seed, 2])`` (stream 2 of the scenario seed unless
    the table gives its own ``seed``), one row per node in graph order."""
    _keys(box, {"low", "high", "d", "seed"}, where)
    if "low" not in box or "high" not in box:
        raise InputError(f"{where}: needs low and high (numbers or lists of d numbers)")
    low, high = _reals(f"{where} low", box["low"]), _reals(f"{where} high", box["high"])
    sizes = {a.size for a in (low, high) if a.ndim == 1}
    d = integer(f"{where} d", box["d"], low=1) if "d" in box else max(sizes, default=1)
    if max(low.ndim, high.ndim) > 1 or sizes - {d}:
        raise InputError(f"{where}: low and high must be numbers or lists of the same "
                         f"length d; got low = {box['low']!r}, high = {box['high']!r}")
    if not (np.isfinite(low).all() and np.isfinite(high).all() and (low <= high).all()):
        raise InputError(f"{where}: needs finite low <= high; got low = {box['low']!r}, "
                         f"high = {box['high']!r}")
    seed = integer(f"{where} seed", box.get("seed", seed), low=0)
    require(f"{where}: {n} states in dimension {d}", n * d, 8 * n * d, "reduce d")
    return np.random.default_rng([seed, 2]).uniform(low, high, size=(n, d))


def _dos(attacks: Any, where: str) -> tuple[DoSAttack, ...]:
    """[[dos]]: an array of tables {name (default DoS_m), links = [[i, j], …], schedule}."""
    if not isinstance(attacks, list):
        raise InputError(f"{where}: dos must be an array of tables [[dos]]; got {attacks!r}")
    out = []
    for m, att in enumerate(attacks, start=1):
        here = f"{where} [[dos]] #{m}"
        if not isinstance(att, dict):
            raise InputError(f"{here}: must be a table; got {att!r}")
        try:
            out.append(attack_from_dict({"name": f"DoS_{m}", **att}))
        except InputError as exc:
            raise InputError(f"{here}: {exc}") from None
    return tuple(out)
