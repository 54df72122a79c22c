"""Figures of a consensus run: each coordinate against time, and the diameter; for an
RMDO run also the global cost and its change rate (the paper's Figs. 6–7).

Conventions (those of the paper's figures): benign agents are thin blue lines with one
legend entry, initial states are marked × (benign) and ○ (adversarial), each adversary
has its own colour, line style and marker. A two-faced adversary is drawn as what it
sent: the band between the smallest and largest message of each step
(``Trajectory.sent``), not as their mean. When the adversaries would squeeze the
benign curves into less than half of a panel, the panel's y-limits follow the benign
agents (adversaries off the scale marked ▲/▼ at the edge) and a second, shorter panel
shows the full range. A log axis that would have to show an exact 0 stops one decade
below the smallest positive value (:func:`log_floor`) and marks the zeros there.
Times, and each coordinate, whose largest magnitude (a coordinate: over the benign
agents) lies outside [1e-100, 1e100] are drawn in units of 10^k
(:func:`rescon.plot.unit_exponent`), named in the axis label ("t (×1e-300 s)").
The legend has one entry per adversary up to :data:`ADVERSARY_ENTRIES` adversaries,
then one for all; labels longer than :data:`LABEL_CHARS` end in "…", and the legend
has as many columns (≤ :data:`LEGEND_COLUMNS`) as fit in the figure's width.
"""

from __future__ import annotations

import dataclasses
import math
from typing import Any

import numpy as np

from .._validate import flag
from . import figure_path, in_units, new_figure, unit_exponent, unit_label

__all__ = ["log_floor", "plot_log_clipped", "plot_trajectory"]

BENIGN = "tab:blue"
#: (colour, line style, marker) of the j-th adversary, cycled.
ADVERSARY_STYLES = (("tab:red", "--", "s"), ("tab:orange", "-.", "^"),
                    ("tab:purple", ":", "D"), ("tab:brown", (0, (5, 1, 1, 1)), "v"),
                    ("tab:pink", "--", "P"), ("tab:olive", "-.", "X"))
#: a panel zooms on the benign agents when they would fill less than this share of it.
ZOOM_SHARE = 0.5
#: at most this many markers along one curve (line markers, off-scale marks).
MARKS = 12
LEGEND_COLUMNS = 3
#: up to this many adversaries each get a legend entry; more share one.
ADVERSARY_ENTRIES = 10
#: legend labels longer than this end in "…".
LABEL_CHARS = 48


def plot_trajectory(traj: Any, *, path: Any = None, log_diameter: bool = True) -> Any:
    """One panel per coordinate x(p) (a second, shorter panel with the full range when
    the adversaries would flatten the benign curves) and one for the benign diameter;
    when the run has cost metrics (:func:`rescon.rmdo`), two more: the global cost
    Σ_{i∈B} f_i at the benign mean (with F* when known) and its change rate (the
    paper's Fig. 7). One legend for the figure. Saves to ``path`` if given
    (:func:`rescon.plot.figure_path`; a figure of its own, outside pyplot); returns the
    matplotlib Figure."""
    log_diameter = flag("log_diameter", log_diameter)
    path = None if path is None else figure_path(path)
    d = traj.states.shape[2]
    k_t, ks = _units(traj)
    view, banded = _drawn(traj, k_t, ks), _banded(traj)
    limits = [_benign_limits(view, p) for p in range(d)]
    rows: list[tuple[str, Any]] = []
    for p in range(d):
        rows.append(("coord", p))
        if limits[p] is not None:
            rows.append(("full", p))
    if "diameter" in traj.metrics:
        rows.append(("diameter", None))
    if "cost_at_mean" in traj.metrics:
        rows += [("cost", None), ("rate", None)]
    heights = [0.6 if kind == "full" else 1.0 for kind, _ in rows]
    fig = new_figure(path, figsize=(7, 0.3 + 2.3 * sum(heights)))
    axes = fig.subplots(len(rows), 1, sharex=True, gridspec_kw={"height_ratios": heights},
                        squeeze=False)
    t = view.times
    for ax, (kind, p) in zip(axes[:, 0], rows, strict=True):
        if kind == "coord":
            _coordinate_panel(ax, view, p, limits[p], banded=banded, k=ks[p])
        elif kind == "full":
            _coordinate_panel(ax, view, p, None, banded=banded, k=ks[p], zoom=limits[p])
        elif kind == "diameter":
            _diameter_panel(ax, t, traj, log_diameter)
        elif kind == "cost":
            _cost_panel(ax, t, traj)
        else:
            _rate_panel(ax, t, traj)
    axes[-1, 0].set_xlabel(unit_label("t", k_t, "s"))
    _figure_legend(fig, axes[:, 0])
    fig.suptitle(_title(traj.info), fontsize=9)
    if path is not None:
        fig.savefig(path, dpi=120)
    return fig


def _title(info: dict[str, Any]) -> str:
    """Which algorithm, policy and F the run used."""
    what = "Algorithm 2 (RMDO)" if info.get("update") == "rmdo" else "Algorithm 1"
    algorithm = info.get("algorithm", "")
    if algorithm and algorithm != "alg1":
        what = f"{what}, filter {algorithm}"
    return f"{what}, policy {info.get('policy', '')}, F = {info.get('F', '')}"


# --------------------------------------------------------------------------- units


def _units(traj: Any) -> tuple[int, list[int]]:
    """The exponents of the drawing units (:func:`rescon.plot.unit_exponent`): k_t of
    the times and, per coordinate p, k_p of the benign states (of every value drawn
    in p when no benign one is finite), so that ordinary benign values are drawn as
    they are whatever the adversaries send."""
    ks = []
    for p in range(traj.states.shape[2]):
        benign = traj.states[:, traj.benign, p]
        ks.append(unit_exponent(benign) if np.isfinite(benign).any()
                  else unit_exponent(traj.states[:, :, p], *_adversary_values(traj, p)))
    return unit_exponent(traj.times), ks


def _drawn(traj: Any, k_t: int, ks: list[int]) -> Any:
    """``traj`` with times in units of 10^k_t and coordinate p of ``states`` and
    ``sent`` in units of 10^k_p (:func:`rescon.plot.in_units`); a value beyond the
    float limit in these units (an adversary far from the benign scale) is drawn at
    it, ±1.797e308."""
    if k_t == 0 and not any(ks):
        return traj
    top = np.finfo(float).max

    def scaled(a: np.ndarray) -> np.ndarray:  # ±inf as given stays ±inf (undrawn)
        out = np.stack([in_units(a[..., p], k) for p, k in enumerate(ks)], axis=-1)
        return np.where(np.isfinite(a), np.clip(out, -top, top), out)

    return dataclasses.replace(traj, times=in_units(traj.times, k_t),
                               states=scaled(traj.states),
                               sent=None if traj.sent is None else scaled(traj.sent))


# --------------------------------------------------------------------------- states


def _adversary_style(j: int) -> tuple[Any, Any, str]:
    """(colour, line style, marker) of the j-th adversary."""
    return ADVERSARY_STYLES[j % len(ADVERSARY_STYLES)]


def _banded(traj: Any) -> np.ndarray:
    """(|A|, d) booleans: did adversary j send different values to different receivers
    in coordinate p at some step (its ``sent`` min ≠ max)? Decided on the values as
    sent, before any drawing unit (where a narrow band can round to one value)."""
    d = traj.states.shape[2]
    if traj.sent is None:
        return np.zeros((len(traj.adversary_rows), d), dtype=bool)
    lo, hi = traj.sent[:, :, 0, :], traj.sent[:, :, 1, :]
    return ((lo != hi) & np.isfinite(lo) & np.isfinite(hi)).any(axis=0)


def _sent_band(traj: Any, j: int, p: int, banded: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray] | None:
    """(min, max) over receivers of adversary j's messages in coordinate p per step
    (``traj`` as drawn), or None when it sent one value to everyone at every step
    (``banded``, :func:`_banded`; then its row of ``states`` is what it sent)."""
    if not banded[j, p]:
        return None
    return traj.sent[:, j, 0, p], traj.sent[:, j, 1, p]


def _finite_range(*arrays: np.ndarray) -> tuple[float, float] | None:
    """(min, max) of the finite entries of ``arrays``, None when there are none."""
    vals = np.concatenate([np.ravel(a) for a in arrays])
    vals = vals[np.isfinite(vals)]
    return (float(vals.min()), float(vals.max())) if vals.size else None


def _padded(lo: float, hi: float) -> tuple[float, float]:
    """[lo, hi] widened by 5 % of its span on each side (by 1 % of |lo| + 1 if flat)."""
    pad = 0.05 * (hi - lo) if hi > lo else 0.01 * abs(lo) + 1.0
    return lo - pad, hi + pad


def _adversary_values(traj: Any, p: int) -> list[np.ndarray]:
    """Every value the adversaries are drawn at in coordinate p."""
    rows = traj.adversary_rows
    out = [traj.states[:, rows, p]]
    if traj.sent is not None:
        out.append(traj.sent[:, :, :, p])
    return out


def _benign_limits(traj: Any, p: int) -> tuple[float, float] | None:
    """y-limits from the benign agents in coordinate p when the adversaries would
    squeeze the benign range into less than :data:`ZOOM_SHARE` of the axis, else None
    (all agents fit)."""
    benign = _finite_range(traj.states[:, traj.benign, p])
    if benign is None or not len(traj.adversary_rows):
        return None
    every = _finite_range(np.asarray(benign), *_adversary_values(traj, p))
    lo, hi = _padded(*benign)
    with np.errstate(over="ignore"):
        full = max(every[1], hi) - min(every[0], lo)
    return (lo, hi) if not math.isfinite(full) or (hi - lo) < ZOOM_SHARE * full else None


def _coordinate_panel(ax: Any, traj: Any, p: int, limits: tuple[float, float] | None, *,
                      banded: np.ndarray, k: int = 0,
                      zoom: tuple[float, float] | None = None) -> None:
    """x_i(p) against t (``traj`` as drawn, coordinate p in units of 10^k): benign
    agents, adversaries (lines or sent bands; one legend entry each up to
    :data:`ADVERSARY_ENTRIES`, else one for all), initial states; with ``limits`` the
    y-axis follows the benign agents and off-scale adversary values are marked at the
    edge; ``zoom`` (on the full-range panel) shades the zoomed window."""
    t, X = traj.times, traj.states
    each = len(traj.adversary_rows) <= ADVERSARY_ENTRIES
    bands = False
    step = max(1, len(t) // MARKS)
    if zoom is not None:
        _full_scale(ax, traj, p, zoom)
    from matplotlib.collections import LineCollection

    curves = np.stack(np.broadcast_arrays(t[:, None], X[:, traj.benign, p]), axis=-1)
    ax.add_collection(LineCollection(curves.transpose(1, 0, 2), colors=BENIGN, lw=0.8,
                                     alpha=0.9, label="benign agents"))
    ax.scatter(np.full(len(traj.benign), t[0]), X[0, traj.benign, p], marker="x",
               color=BENIGN, s=28, lw=1.2, zorder=4, label="x_i(0), benign")
    for j, i in enumerate(traj.adversary_rows):
        colour, ls, marker = _adversary_style(j)
        band = _sent_band(traj, j, p, banded)
        bands = bands or band is not None
        name = f"adversary {traj.nodes[i]}" if each else None
        if band is None:
            ax.plot(t, X[:, i, p], color=colour, ls=ls, lw=1.1, marker=marker, ms=4,
                    markevery=step, label=name)
            start = [X[0, i, p]]
        else:
            ax.fill_between(t, band[0], band[1], color=colour, alpha=0.15, lw=0,
                            label=f"{name}: range sent" if each else None)
            for edge in band:
                ax.plot(t, edge, color=colour, ls=ls, lw=0.7, marker=marker, ms=3,
                        markevery=step)
            start = [band[0][0], band[1][0]]
        ax.scatter(np.full(len(start), t[0]), start, marker="o", facecolors="none",
                   edgecolors=colour, s=36, lw=1.2, zorder=4, label="x_i(0), adversary")
        if limits is not None:
            hi_vals = X[:, i, p] if band is None else band[1]
            lo_vals = X[:, i, p] if band is None else band[0]
            _mark_off_scale(ax, t, hi_vals, lo_vals, limits, colour)
    if not each:
        _collective_entry(ax, len(traj.adversary_rows), bands)
    suffix = (", benign range" if limits is not None
              else ", full range" if zoom is not None else "")
    ax.set_ylabel(unit_label(f"x({p + 1})", k) + suffix)
    if limits is not None:
        ax.set_ylim(*limits)
        ax.scatter([], [], marker="^", color="0.4", s=22,
                   label="adversary off the scale (▲ above, ▼ below)")
    if zoom is not None:
        ax.axhspan(*zoom, color="0.5", alpha=0.15, lw=0, zorder=0)


def _collective_entry(ax: Any, n: int, bands: bool) -> None:
    """The one legend entry of n > :data:`ADVERSARY_ENTRIES` adversaries (and of their
    sent bands): empty artists, nothing drawn."""
    colour, ls, _ = _adversary_style(0)
    ax.plot([], [], color=colour, ls=ls, lw=1.1, label=f"{n} adversaries (styles cycled)")
    if bands:
        ax.fill_between([], [], [], color=colour, alpha=0.15, lw=0,
                        label="adversaries: range sent")


def _mark_off_scale(ax: Any, t: np.ndarray, hi_vals: np.ndarray, lo_vals: np.ndarray,
                    limits: tuple[float, float], colour: Any) -> None:
    """▲ at the top edge where ``hi_vals`` > the upper limit, ▼ at the bottom edge where
    ``lo_vals`` < the lower limit (at most :data:`MARKS` of each, evenly spread)."""
    edge = ax.get_xaxis_transform()  # x in data, y in axes fraction
    for vals, y, marker in ((hi_vals, 0.985, "^"), (lo_vals, 0.015, "v")):
        with np.errstate(invalid="ignore"):
            out = np.flatnonzero(vals > limits[1] if marker == "^" else vals < limits[0])
        if out.size:
            pick = out[np.linspace(0, out.size - 1, min(MARKS, out.size)).round().astype(int)]
            ax.scatter(t[pick], np.full(pick.size, y), marker=marker, color=colour, s=22,
                       transform=edge, clip_on=False, zorder=5)


def _full_scale(ax: Any, traj: Any, p: int, zoom: tuple[float, float]) -> None:
    """Before anything is drawn on the full-range panel: when the adversaries reach
    beyond 10³ times the benign scale, a symmetric log y-scale (linear up to the benign
    scale) with fixed limits at the extreme finite values, so that values up to the
    float limit draw (a linear autoscale would overflow); else the linear autoscale."""
    every = _finite_range(np.asarray(zoom), *_adversary_values(traj, p))
    scale = max(abs(zoom[0]), abs(zoom[1]), zoom[1] - zoom[0])
    top = max(abs(every[0]), abs(every[1]))
    if top > 1e3 * scale:
        from matplotlib.ticker import FixedLocator

        ax.set_yscale("symlog", linthresh=scale)
        ax.set_ylim(*every)
        exps = np.unique(np.linspace(math.ceil(math.log10(scale)), math.floor(math.log10(top)),
                                     4).round())
        ticks = [s * 10.0 ** e for s in (-1, 1) for e in exps if every[0] <= s * 10.0 ** e
                 <= every[1]]
        ax.yaxis.set_major_locator(FixedLocator(ticks))


# --------------------------------------------------------------------------- log axes


def log_floor(*series: Any) -> float | None:
    """The lower limit of a log axis showing ``series`` when one of them reaches an
    exact 0: a power of ten at least one decade below the smallest positive finite
    value m (10^(⌊log₁₀ m⌋ − 1) ≤ m/10), or 1e-16 (the power of ten below the machine
    ε) when no value is positive; never below the smallest positive float (m deep in
    the subnormals); None when no value is 0 (the axis may autoscale)."""
    vals = np.concatenate([np.ravel(np.asarray(s, dtype=float)) for s in series])
    vals = vals[np.isfinite(vals)]
    if not np.any(vals == 0.0):
        return None
    pos = vals[vals > 0.0]
    m = float(pos.min()) if pos.size else 10.0 * np.finfo(float).eps
    e = math.floor(math.log10(m)) - 1
    while e > -324 and 10.0**e > m / 10:  # log10 rounds up just below a power of ten
        e -= 1
    return max(10.0**e, float(np.nextafter(0.0, 1.0)))


def plot_log_clipped(ax: Any, t: Any, y: Any, floor: float | None, *, label: str | None = None,
                     **style: Any) -> Any:
    """Plot ``y`` ≥ 0 against ``t`` on ``ax``'s log scale, exact zeros drawn at
    ``floor`` (:func:`log_floor` of everything on the axis) with a ▼ where each run of
    zeros starts; the axis' lower limit is set just below the floor (floor / 2) so the
    zeros stand off the frame. Returns the line."""
    y = np.asarray(y, dtype=float)
    ax.set_yscale("log")
    if floor is None:
        return ax.plot(t, y, label=label, **style)[0]
    zero = y == 0.0
    line = ax.plot(t, np.where(zero, floor, y), label=label, **style)[0]
    starts = np.flatnonzero(zero & ~np.concatenate([[False], zero[:-1]]))
    if starts.size:
        zero_label = "exactly 0 (drawn at the axis floor)"
        ax.scatter(np.asarray(t)[starts], np.full(starts.size, floor), marker="v", s=40,
                   color=line.get_color(), zorder=5, clip_on=False,
                   label=None if zero_label in ax.get_legend_handles_labels()[1]
                   else zero_label)
    ax.set_ylim(bottom=floor / 2 or floor)
    return line


def _dot(t: Any) -> dict[str, Any]:
    """Line style keywords that make a one-point line visible (a dot): a line of one
    point draws nothing."""
    return {"marker": "o", "ms": 4} if len(t) == 1 else {}


def _diameter_panel(ax: Any, t: np.ndarray, traj: Any, log: bool) -> None:
    """The benign diameter against the drawn times ``t`` (in units of 10^k beyond
    1e±100, :func:`rescon.plot.unit_exponent`); on a log axis exact zeros sit at
    :func:`log_floor`."""
    k = unit_exponent(traj.metrics["diameter"])
    dia = in_units(traj.metrics["diameter"], k)
    dot = _dot(t)
    if log:
        plot_log_clipped(ax, t, dia, log_floor(dia), color="k", lw=1.2,
                         label="benign diameter", **dot)
        zero = np.flatnonzero(dia == 0.0)
        if zero.size:
            ax.text(0.99, 0.95, f"diameter exactly 0 at {zero.size} of {len(t)} steps, "
                    f"first at t = {traj.times[zero[0]]:g} s", transform=ax.transAxes,
                    ha="right", va="top", fontsize=7)
    else:
        ax.plot(t, dia, color="k", lw=1.2, label="benign diameter", **dot)
    ax.set_ylabel(unit_label("diameter (benign)", k))


# --------------------------------------------------------------------------- cost


def _cost_panel(ax: Any, t: np.ndarray, traj: Any) -> None:
    """F(x̄(t_k)) and the range of F(x_i) over benign agents against the drawn times
    ``t``, F* dotted when known, in units of 10^k beyond 1e±100; a log, symmetric log
    or linear scale (:func:`_cost_scale`)."""
    m = traj.metrics
    value = traj.info.get("optimum", {}).get("value")
    known = value is not None and np.isfinite(value)
    k = unit_exponent(m["cost"], m["cost_at_mean"], *([[value]] if known else []))
    cost, at_mean = in_units(m["cost"], k), in_units(m["cost_at_mean"], k)
    ax.fill_between(t, cost.min(axis=1), cost.max(axis=1), color=BENIGN,
                    alpha=0.2, lw=0, label="F(x_i), i benign")
    ax.plot(t, at_mean, color=BENIGN, label="F(benign mean)", **_dot(t))
    shown = [cost, at_mean]
    if known:
        star = in_units(np.asarray([value]), k)
        ax.axhline(float(star[0]), color="k", ls=":", lw=0.9, label="F*")
        shown.append(star)
    ax.set_yscale(_cost_scale(_finite_range(*shown)))
    ax.set_ylabel(unit_label("global cost", k))


def _cost_scale(finite: tuple[float, float] | None) -> str:
    """The y scale of the cost panel: log for positive values spanning a decade, symlog
    for values reaching 0 or negative ones spanning a decade, else linear: a one-sided
    range within a decade (−800 … −740, 500 … 510) holds no power of ten, so a log
    axis would show no tick."""
    if finite is None:
        return "linear"
    lo, hi = finite
    if lo > 0:
        return "log" if hi >= 10 * lo else "linear"
    return "symlog" if hi >= 0 or lo <= 10 * hi else "linear"


def _rate_panel(ax: Any, t: np.ndarray, traj: Any) -> None:
    """(F(x̄(t_k)) − F(x̄(t_{k−1})))/T against the drawn times ``t`` on a symmetric log
    scale, in units of 10^k beyond 1e±100."""
    k = unit_exponent(traj.metrics["cost_rate"])
    ax.plot(t, in_units(traj.metrics["cost_rate"], k), color="tab:green",
            label="change rate", **_dot(t))
    ax.axhline(0.0, color="0.6", lw=0.6)
    ax.set_yscale("symlog")
    ax.set_ylabel(unit_label("change rate", k, "1/s"))


# --------------------------------------------------------------------------- legend


def _short(label: str) -> str:
    """``label`` cut to :data:`LABEL_CHARS` characters, the last one "…"."""
    return label if len(label) <= LABEL_CHARS else label[:LABEL_CHARS - 1] + "…"


def _figure_legend(fig: Any, axes: Any) -> None:
    """One legend under the title's place, above the panels (laid out below it; the
    title comes after the layout): every distinct label once, in drawing order,
    shortened (:func:`_short`), in the most columns (≤ :data:`LEGEND_COLUMNS`) that
    fit in the figure's width."""
    seen: dict[str, Any] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            seen.setdefault(label, handle)
    ncol = max(1, min(LEGEND_COLUMNS, len(seen)))
    while True:
        legend = fig.legend(list(seen.values()), [_short(s) for s in seen],
                            loc="upper center", fontsize=7, ncol=ncol, frameon=False,
                            bbox_to_anchor=(0.5, 1.0 - 0.36 / fig.get_figheight()))
        box = legend.get_window_extent()  # the figure's renderer, on any canvas
        if ncol == 1 or box.width <= fig.bbox.width:
            break
        legend.remove()
        ncol -= 1
    fig.tight_layout(rect=(0, 0, 1, fig.transFigure.inverted().transform(box.p0)[1]))
