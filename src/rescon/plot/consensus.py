"""Figures of a consensus run: each coordinate against time, and the diameter; for an
RMDO run also the global cost and its change rate (the paper's Figs. 6–7)."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import figure_path, pyplot

__all__ = ["plot_trajectory"]


def plot_trajectory(traj: Any, *, path: Any = None, log_diameter: bool = True) -> Any:
    """One panel per coordinate (benign agents blue, adversaries red dashed, as in the
    paper's Figs. 3–4) and one for the benign diameter; when the run has cost metrics
    (:func:`rescon.rmdo`), two more: the global cost Σ_{i∈B} f_i at the benign mean
    (with F* when known) and its change rate (the paper's Fig. 7). Saves to ``path``
    if given (:func:`rescon.plot.figure_path`)."""
    path = None if path is None else figure_path(path)
    plt = pyplot(path)

    t, X = traj.times, traj.states
    d = X.shape[2]
    benign = set(traj.benign.tolist())
    panels = d + 1 + 2 * ("cost_at_mean" in traj.metrics)
    fig, axes = plt.subplots(panels, 1, figsize=(7, 2.4 * panels), sharex=True)
    for p in range(d):
        ax = axes[p]
        for i, node in enumerate(traj.nodes):
            if i in benign:
                ax.plot(t, X[:, i, p], color="tab:blue", lw=0.9)
            else:
                ax.plot(t, X[:, i, p], color="tab:red", lw=0.9, ls="--", label=f"adversary {node}")
        ax.set_ylabel(f"x({p + 1})")
        if len(benign) < len(traj.nodes):
            ax.legend(loc="best", fontsize=7)
    ax = axes[d]
    dia = np.maximum(traj.metrics["diameter"], np.finfo(float).tiny)
    ax.plot(t, dia, color="k")
    if log_diameter:
        ax.set_yscale("log")
    ax.set_ylabel("diameter (benign)")
    if panels > d + 1:
        _cost_panels(axes[d + 1], axes[d + 2], traj)
    axes[-1].set_xlabel("t (s)")
    info = traj.info
    fig.suptitle(f"{info.get('algorithm', '')}, policy {info.get('policy', '')}, "
                 f"F = {info.get('F', '')}", fontsize=9)
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=120)
    return fig


def _cost_panels(ax_cost: Any, ax_rate: Any, traj: Any) -> None:
    """F(x̄(t_k)) (and the range of F(x_i) over benign agents, F* dashed when known)
    and its change rate (F(x̄(t_k)) − F(x̄(t_{k−1})))/T on a symmetric log scale."""
    t, m = traj.times, traj.metrics
    ax_cost.fill_between(t, m["cost"].min(axis=1), m["cost"].max(axis=1), color="tab:blue",
                         alpha=0.2, lw=0, label="F(x_i), i benign")
    ax_cost.plot(t, m["cost_at_mean"], color="tab:blue", label="F(mean)")
    value = traj.info.get("optimum", {}).get("value")
    if value is not None and np.isfinite(value):
        ax_cost.axhline(value, color="k", ls=":", lw=0.9, label="F*")
    ax_cost.set_yscale("symlog")
    ax_cost.set_ylabel("global cost")
    ax_cost.legend(loc="best", fontsize=7)
    ax_rate.plot(t, m["cost_rate"], color="tab:green")
    ax_rate.set_yscale("symlog")
    ax_rate.set_ylabel("change rate (1/s)")
