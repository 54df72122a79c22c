"""Figures (matplotlib, the optional ``rescon[plot]`` extra, imported lazily).

:func:`pyplot` and :func:`figure_path` are the two doors every figure goes through:
the first says how to install matplotlib when it is missing, the second checks the
file name before any work is done (a format matplotlib can write, parent directories
created by the rule of :func:`rescon.io.output_path`).
"""

from __future__ import annotations

import importlib.util
import os
from pathlib import Path
from typing import Any

from ..errors import InputError, MissingDependency

__all__ = ["figure_path", "pyplot"]

INSTALL = "install rescon[plot] (pip install 'rescon[plot]') to draw figures"


def _require_matplotlib() -> None:
    if importlib.util.find_spec("matplotlib") is None:
        raise MissingDependency(f"matplotlib is not installed: {INSTALL}")


def pyplot(path: Any = None) -> Any:
    """``matplotlib.pyplot``; with a file to write, on the non-interactive Agg backend."""
    _require_matplotlib()
    import matplotlib

    if path is not None:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


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
