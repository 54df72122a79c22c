"""Figures of a consensus run: each coordinate against time, and the diameter."""

from __future__ import annotations

from typing import Any

import numpy as np

from . import figure_path, pyplot

__all__ = ["plot_trajectory"]


def plot_trajectory(traj: Any, *, path: Any = None, log_diameter: bool = True) -> Any:
    """One panel per coordinate (benign agents blue, adversaries red dashed, as in the
    paper's Figs. 3–4) and one for the benign diameter. Saves to ``path`` if given
    (:func:`rescon.plot.figure_path`)."""
    path = None if path is None else figure_path(path)
    plt = pyplot(path)

    t, X = traj.times, traj.states
    d = X.shape[2]
    benign = set(traj.benign.tolist())
    fig, axes = plt.subplots(d + 1, 1, figsize=(7, 2.4 * (d + 1)), sharex=True)
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
    ax.set_xlabel("t (s)")
    info = traj.info
    fig.suptitle(f"{info.get('algorithm', '')}, policy {info.get('policy', '')}, "
                 f"F = {info.get('F', '')}", fontsize=9)
    fig.tight_layout()
    if path is not None:
        fig.savefig(path, dpi=120)
    return fig
