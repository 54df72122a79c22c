"""Figure of a safe kernel: the points, the kernel polytope and a chosen point.

Axes are labelled x₁, x₂ (, x₃) and drawn to equal scale; in 3-D the kernel's faces
are its exact facets (vertex–facet incidence decided in exact rationals), each one
translucent polygon with its edges, seen from a fixed oblique angle. Coordinates whose
largest magnitude lies outside [1e-100, 1e100] are drawn in units of 10^k, one k for
every axis (:func:`rescon.plot.unit_exponent`), named in the labels ("x₁ (×1e-300)").
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import InputError
from . import figure_path, in_units, new_figure, unit_exponent, unit_label

__all__ = ["plot_kernel"]

#: default 3-D view (elevation, azimuth) in degrees: oblique, no face seen edge-on.
VIEW = (22.0, -58.0)
KERNEL = "tab:blue"
AXIS_LABELS = ("x₁", "x₂", "x₃")


def _ordered_polygon(V: np.ndarray) -> np.ndarray:
    """Vertices of a planar convex polygon (in any dimension) in cyclic order: by angle
    around their mean in the plane of their two leading principal directions."""
    c = V.mean(axis=0)
    P = (V - c) @ np.linalg.svd(V - c)[2][:2].T
    return V[np.argsort(np.arctan2(P[:, 1], P[:, 0]))]


def _faces(K: Any, V: np.ndarray) -> list[np.ndarray]:
    """The 2-faces of a 3-dimensional kernel in R³ as rows of ``V`` (its vertices, as
    drawn): for each exact facet a·x ≤ b the vertices with a·v = b exactly
    (Fractions), in cyclic order."""
    faces = []
    for a, b in K._exact.facets:
        on = [i for i, v in enumerate(K.exact_vertices)
              if sum(ai * vi for ai, vi in zip(a, v, strict=True)) == b]
        faces.append(_ordered_polygon(V[on]))
    return faces


def _equal_aspect(ax: Any, X: np.ndarray) -> None:
    """One unit is as long on every axis (3-D: the box aspect follows the data's extents,
    every extent at least 1 % of the largest so a flat cloud stays visible, and 5 %
    margins on each side)."""
    if X.shape[1] == 2:
        ax.set_aspect("equal", adjustable="datalim")
        return
    lo, hi = X.min(axis=0), X.max(axis=0)
    span = hi - lo
    span = np.maximum(span, 0.01 * span.max()) if span.max() > 0 else np.ones(3)
    mid, half = (lo + hi) / 2, 0.55 * span
    ax.set_xlim(mid[0] - half[0], mid[0] + half[0])
    ax.set_ylim(mid[1] - half[1], mid[1] + half[1])
    ax.set_zlim(mid[2] - half[2], mid[2] + half[2])
    ax.set_box_aspect(tuple(span / span.max()))
    from matplotlib.ticker import MaxNLocator

    for axis, share in zip((ax.xaxis, ax.yaxis, ax.zaxis), span / span.max(), strict=True):
        axis.set_major_locator(MaxNLocator(max(2, round(6 * share))))


def _draw_kernel(ax: Any, K: Any, V: np.ndarray, d: int, label: str) -> None:
    """Ψ, its vertices drawn at ``V``: a filled polygon (dim 2), translucent exact faces
    (dim 3), a segment or a point (dim 1, 0), or only a legend entry (empty)."""
    if K.dim == 3:
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection

        ax.add_collection3d(Poly3DCollection(_faces(K, V), alpha=0.25, facecolor=KERNEL,
                                             edgecolor="navy", linewidths=0.8, label=label))
    elif K.dim == 2:
        P = _ordered_polygon(V)
        if d == 2:
            ax.fill(P[:, 0], P[:, 1], alpha=0.35, facecolor=KERNEL, edgecolor="navy",
                    label=label)
        else:
            from mpl_toolkits.mplot3d.art3d import Poly3DCollection

            ax.add_collection3d(Poly3DCollection([P], alpha=0.35, facecolor=KERNEL,
                                                 edgecolor="navy", label=label))
    elif len(V):
        ax.plot(*V.T, "-o", color=KERNEL, label=label)
    else:
        ax.plot([], [], color=KERNEL, label=label)


def plot_kernel(K: Any, *, ax: Any = None, point: Any = None, path: Any = None,
                view: tuple[float, float] | None = None) -> Any:
    """Draw K.points, Ψ and ``point`` (d = 2 or 3), axes labelled x₁, x₂ (, x₃) at
    equal scale; in 3-D seen from ``view`` = (elevation, azimuth) in degrees
    (default :data:`VIEW`); coordinates beyond 1e±100 in units of 10^k
    (:func:`rescon.plot.unit_exponent`, named in the axis labels). Saves to ``path``
    when given (:func:`rescon.plot.figure_path`; a figure of its own, outside pyplot);
    returns the matplotlib Axes."""
    d = K.points.shape[1]
    if d not in (2, 3):
        raise InputError(f"plot draws d = 2 or 3 only; got d = {d}")
    path = None if path is None else figure_path(path)
    point = None if point is None else np.asarray(point, dtype=float).reshape(1, d)
    k = unit_exponent(K.points, *([] if point is None else [point]))
    X = in_units(K.points, k)
    if ax is None:
        fig = new_figure(path, figsize=(5.5, 5.5))
        ax = fig.add_subplot(projection="3d" if d == 3 else None)
    extra = {"depthshade": False} if d == 3 else {}
    ax.scatter(*X.T, s=14, c="0.25", label=f"points (n = {len(X)})", **extra)
    label = f"safe kernel Ψ, F = {K.F}" + (" (empty)" if K.is_empty else f", dim {K.dim}")
    _draw_kernel(ax, K, in_units(K.vertices, k), d, label)
    if point is not None:
        ax.scatter(*in_units(point, k).T, s=80, marker="*", c="tab:red",
                   label="kernel point", zorder=5, **extra)
    for axis, name in zip(("x", "y", "z"), AXIS_LABELS[:d], strict=False):
        getattr(ax, f"set_{axis}label")(unit_label(name, k))
    _equal_aspect(ax, X)
    if d == 3:
        ax.view_init(*(VIEW if view is None else view))
    ax.legend(loc="best", fontsize=8)
    if path is not None:
        ax.figure.savefig(path, dpi=120, bbox_inches="tight")
    return ax
