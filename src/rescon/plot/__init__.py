"""Figures (matplotlib, the optional ``rescon[plot]`` extra, imported lazily).

:func:`pyplot`, :func:`new_figure` and :func:`figure_path` are the doors every figure
goes through: the first two say how to install matplotlib when it is missing (a
figure for a file is drawn on its own Agg canvas, leaving pyplot's backend and figure
list alone), the third checks the file name before any work is done (a format
matplotlib can write, parent directories created by the rule of
:func:`rescon.io.output_path`). :func:`unit_exponent` and :func:`in_units` draw values
far from 1 (beyond 1e±100: matplotlib widens any axis range below ~2e-287 and
overflows on spans beyond the float limit) in scaled units, named by
:func:`unit_label`.
"""

from __future__ import annotations

import importlib.util
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError, MissingDependency

__all__ = ["figure_path", "in_units", "new_figure", "pyplot", "unit_exponent", "unit_label"]

INSTALL = "install rescon[plot] (pip install 'rescon[plot]') to draw figures"
#: values whose largest magnitude lies in [1/SAFE, SAFE] (or is 0) are drawn as they are.
SAFE = 1e100


def _require_matplotlib() -> None:
    if importlib.util.find_spec("matplotlib") is None:
        raise MissingDependency(f"matplotlib is not installed: {INSTALL}")


def pyplot() -> Any:
    """``matplotlib.pyplot``, on the caller's backend (figures shown, not written: those
    come from :func:`new_figure` with a path)."""
    _require_matplotlib()
    import matplotlib.pyplot as plt

    return plt


def new_figure(path: Any = None, **kwargs: Any) -> Any:
    """A matplotlib Figure(``**kwargs``): with a file to write (``path``), one on its own
    Agg canvas, outside pyplot (the caller's backend and open figures are left as they
    are); without one, ``pyplot.figure(**kwargs)`` (shown by the caller's backend)."""
    _require_matplotlib()
    if path is None:
        return pyplot().figure(**kwargs)
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(**kwargs)
    FigureCanvasAgg(fig)
    return fig


def unit_exponent(*arrays: Any) -> int:
    """The k of the drawing unit 10^k of ``arrays``' finite values: 0 when their largest
    magnitude m is 0 or within [1e-100, 1e100], else ⌊log₁₀ m⌋ (the values are then
    drawn as v / 10^k, of magnitude in [1, 10)). m is a max of |v|, never a difference,
    so it does not overflow."""
    vals = np.concatenate([np.ravel(np.asarray(a, dtype=float)) for a in arrays] or [[]])
    vals = np.abs(vals[np.isfinite(vals)])
    m = float(vals.max()) if vals.size else 0.0
    return 0 if m == 0.0 or 1 / SAFE <= m <= SAFE else math.floor(math.log10(m))


def in_units(values: Any, k: int) -> np.ndarray:
    """``values`` / 10^k as floats, computed as v · 10^(−h) · 10^(−(k−h)), h = ⌊k/2⌋, so
    that neither factor over- or underflows for any |k| ≤ 324 (10^k itself may);
    values beyond the float limit in these units become ±inf."""
    v = np.asarray(values, dtype=float)
    if k == 0:
        return v
    h = k // 2
    with np.errstate(over="ignore", under="ignore"):
        return v * 10.0 ** (-h) * 10.0 ** (-(k - h))


def unit_label(name: str, k: int, unit: str = "") -> str:
    """An axis label naming its unit: ``name (unit)``, or ``name (×1ek unit)`` when the
    values are drawn in units of 10^k (:func:`unit_exponent`)."""
    scale = f"×1e{k}" if k else ""
    inside = " ".join(part for part in (scale, unit) if part)
    return f"{name} ({inside})" if inside else name


def figure_path(path: Any, what: str = "path") -> Path:
    """``path`` as a figure file: its suffix names a format matplotlib writes (png,
    pdf, svg, …); missing parent directories are created.

    Raises
    ------
    MissingDependency
        matplotlib is not installed.
    InputError
        No suffix or an unsupported one, or not a usable file path (names ``what``).
    """
    from ..io import output_path

    _require_matplotlib()
    from matplotlib.backend_bases import FigureCanvasBase

    formats = sorted(FigureCanvasBase.get_supported_filetypes())
    ok = isinstance(path, (str, os.PathLike))
    suffix = Path(os.fspath(path)).suffix.lower().lstrip(".") if ok else ""
    if suffix not in formats:
        raise InputError(f"{what} must end in a figure format matplotlib writes "
                         f"({', '.join('.' + f for f in formats)}); got {path!r}")
    return output_path(path, what)
