"""Input validation shared by every public function: one message style, one place.

Each helper takes the argument's name and the value that came, and either returns it
in canonical form or raises :class:`~rescon.errors.InputError` with a one-line message
naming the argument, what was expected and what came
(``"F must be an integer >= 0; got 2.5"``). Booleans are never numbers here.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from .errors import InputError

__all__ = ["integer", "real", "positive", "nonnegative"]


def integer(name: str, value: Any, *, low: int | None = None, high: int | None = None) -> int:
    """``value`` as a Python int with ``low ≤ value ≤ high`` (each bound optional)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InputError(f"{name} must be an integer{_range(low, high)}; got {value!r}")
    value = int(value)
    if (low is not None and value < low) or (high is not None and value > high):
        raise InputError(f"{name} must be an integer{_range(low, high)}; got {value}")
    return value


def real(name: str, value: Any) -> float:
    """``value`` as a float (an int, float or numpy real; not a bool, not a string)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(f"{name} must be a real number; got {value!r}")
    try:
        return float(value)
    except OverflowError:
        raise InputError(f"{name} must be a real number within the float range; "
                         f"got {value!r}") from None


def positive(name: str, value: Any, *, what: str = "finite number") -> float:
    """A finite real > 0 (``what`` names the kind in the message, e.g. "number of seconds")."""
    return _bounded(name, value, lambda v: v > 0, f"a positive {what}")


def nonnegative(name: str, value: Any, *, what: str = "finite number") -> float:
    """A finite real ≥ 0."""
    return _bounded(name, value, lambda v: v >= 0, f"a {what} >= 0")


def _bounded(name: str, value: Any, ok: Callable[[float], bool], expected: str) -> float:
    is_real = isinstance(value, (int, float, np.integer, np.floating))
    v = real(name, value) if is_real and not isinstance(value, bool) else math.nan
    if not (math.isfinite(v) and ok(v)):
        raise InputError(f"{name} must be {expected}; got {value!r}")
    return v


def _range(low: int | None, high: int | None) -> str:
    if low is not None and high is not None:
        return f" in [{low}, {high}]"
    if low is not None:
        return f" >= {low}"
    if high is not None:
        return f" <= {high}"
    return ""
