"""Figure of a safe kernel: the points, the kernel polytope and a chosen point."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from . import figure_path, pyplot

__all__ = ["plot_kernel"]


def _ordered_polygon(V: np.ndarray) -> np.ndarray:
    """Vertices of a convex polygon in counter-clockwise order."""
    c = V.mean(axis=0)
    return V[np.argsort(np.arctan2(V[:, 1] - c[1], V[:, 0] - c[0]))]


def plot_kernel(K: Any, *, ax: Any = None, point: Any = None, path: Any = None) -> Any:
    """Draw K.points, Ψ (filled polygon / polytope hull) and ``point`` (d = 2 or 3).
    Saves to ``path`` when given (:func:`rescon.plot.figure_path`); returns the
    matplotlib Axes."""
    X = K.points
    d = X.shape[1]
    if d not in (2, 3):
        raise InputError(f"plot draws d = 2 or 3 only; got d = {d}")
    path = None if path is None else figure_path(path)
    plt = pyplot(path if ax is None else None)
    if ax is None:
        fig = plt.figure(figsize=(5, 5))
        ax = fig.add_subplot(projection="3d" if d == 3 else None)
    ax.scatter(*X.T, s=12, c="0.3", label=f"points (n={len(X)})")
    V = K.vertices
    label = f"safe kernel, F={K.F}" + (" (empty)" if K.is_empty else f", dim {K.dim}")
    if d == 2 and len(V) >= 3:
        P = _ordered_polygon(V)
        ax.fill(P[:, 0], P[:, 1], alpha=0.35, color="tab:blue", label=label)
    elif d == 3 and K.dim == 3:
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection
        from scipy.spatial import ConvexHull

        hull = ConvexHull(V)
        ax.add_collection3d(Poly3DCollection([V[s] for s in hull.simplices], alpha=0.3,
                                             facecolor="tab:blue", label=label))
    elif len(V):
        P = _ordered_polygon(V) if d == 2 and len(V) > 2 else V
        ax.plot(*P.T, "-o", color="tab:blue", label=label)
    else:
        ax.plot([], [], color="tab:blue", label=label)
    if point is not None:
        ax.scatter(*np.asarray(point, dtype=float).reshape(d, 1), s=60, marker="*",
                   c="tab:red", label="kernel point", zorder=5)
    ax.legend(loc="best", fontsize=8)
    if path is not None:
        ax.figure.savefig(path, dpi=120, bbox_inches="tight")
    return ax
