"""The result of a run: states over time, who is benign, and the metrics per step."""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError

__all__ = ["Trajectory"]


@dataclass(frozen=True)
class Trajectory:
    """States x_i(t_k) of every agent, k = 0..K.

    Attributes
    ----------
    times : (K+1,) t_k = k T.
    states : (K+1, N, d); adversaries' rows hold what they sent (their own value for
        a function of time; NaN when nothing finite was sent).
    nodes : the N node labels, in row order.
    benign : indices of the benign agents.
    metrics : per step (the first four only if chosen: ``simulate(metrics=...)``,
        default all) — ``spread`` (K+1, d) per-coordinate max − min over benign
        agents, ``diameter`` (K+1,), ``validity`` (K+1,) the largest distance of a benign
        state to conv(benign initial states), ``validity_per_agent`` (K+1, |B|),
        ``blocked_links`` (K+1,) links under DoS at t_k, ``starved`` (K+1,) benign
        agents that held their state for lack of usable values; an RMDO run
        (:func:`rescon.rmdo`) adds ``cost`` (K+1, |B|), ``cost_at_mean``, ``cost_rate``
        and, when X* is known, ``distance_to_optimum`` and ``optimality_gap``.
    info : the scenario's settings and the assumptions it violates.
    sent : (K+1, |A|, 2, d) or None; what each adversary (the non-benign rows, in row
        order) sent at t_k: ``sent[k, j, 0]`` / ``sent[k, j, 1]`` the per-coordinate
        min / max of its finite messages over its receivers (NaN when nothing finite
        was sent or it has no receiver). A two-faced adversary's band; O(K·|A|·d).
    """

    times: np.ndarray
    states: np.ndarray
    nodes: tuple[Any, ...]
    benign: np.ndarray
    metrics: dict[str, np.ndarray] = field(repr=False)
    info: dict[str, Any] = field(default_factory=dict, repr=False)
    seconds: float = 0.0
    sent: np.ndarray | None = field(default=None, repr=False)

    @property
    def max_validity(self) -> float:
        """max over time and benign agents of the distance to conv(initial benign)."""
        return float(self._metric("validity").max())

    @property
    def final_diameter(self) -> float:
        return float(self._metric("diameter")[-1])

    def _metric(self, name: str) -> np.ndarray:
        """``metrics[name]``, or an InputError saying the monitor did not run."""
        if name not in self.metrics:
            raise InputError(f"the {name!r} monitor did not run: simulate with metrics= "
                             f"including {name!r} (or the default, every monitor)")
        return self.metrics[name]

    def __repr__(self) -> str:
        """A one-line summary (the arrays are in the attributes, not in the repr)."""
        K, N, d = self.states.shape
        shown = [f"steps={max(K - 1, 0)}", f"N={N}", f"d={d}", f"benign={len(self.benign)}"]
        diameter, validity = self.metrics.get("diameter"), self.metrics.get("validity")
        if diameter is not None and np.size(diameter):
            shown.append(f"final_diameter={float(diameter[-1]):.2g}")
        if validity is not None and np.size(validity):
            shown.append(f"max_validity={float(np.max(validity)):.2g}")
        return f"Trajectory({', '.join(shown)}, seconds={self.seconds:.2g})"

    @property
    def adversary_rows(self) -> np.ndarray:
        """Row indices of the adversaries (the rows not in ``benign``), in row order."""
        return np.setdiff1d(np.arange(len(self.nodes)), self.benign)

    def to_json(self) -> dict[str, Any]:
        """JSON-ready dict of plain Python types (:func:`rescon.io.to_jsonable`: numpy
        labels and values as Python scalars, arrays as nested lists, NaN and ±inf as
        null)."""
        from ..io import to_jsonable

        out: dict[str, Any] = {
            "nodes": self.nodes, "benign": [self.nodes[i] for i in self.benign],
            "times": self.times, "states": self.states, "metrics": self.metrics,
            "info": self.info, "seconds": self.seconds}
        if self.sent is not None:
            out["sent"] = {"nodes": [self.nodes[i] for i in self.adversary_rows],
                           "min": self.sent[:, :, 0], "max": self.sent[:, :, 1]}
        return to_jsonable(out)

    def to_csv(self, path: str | Path) -> Path:
        """One row per (step, agent): k, t, node, benign, x_1..x_d (missing parent
        directories are created, as for every output: :func:`rescon.io.output_path`)."""
        from ..io import output_path

        p = output_path(path, "path")
        d = self.states.shape[2]
        benign = set(self.benign.tolist())
        with p.open("w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["k", "t", "node", "benign"] + [f"x{p + 1}" for p in range(d)])
            for k, t in enumerate(self.times):
                for i, node in enumerate(self.nodes):
                    w.writerow([k, t, node, int(i in benign)] + self.states[k, i].tolist())
        return p

    def plot(self, path: str | Path | None = None, *, log_diameter: bool = True) -> Any:
        """x(1), x(2), ... against t (benign agents blue, one legend entry; initial
        states × benign, ○ adversarial; each adversary its own style; a two-faced one
        as the band of what it sent, from ``sent``; a panel whose adversaries would
        flatten the benign curves zooms on them, with a full-range panel below) and the
        diameter (log scale, exact zeros marked at a floor); for an RMDO run also the
        global cost and its change rate (the paper's Figs. 3–4, 6–7; see
        :func:`rescon.plot.consensus.plot_trajectory`). Returns the matplotlib Figure."""
        from ..plot.consensus import plot_trajectory

        return plot_trajectory(self, path=path, log_diameter=log_diameter)
