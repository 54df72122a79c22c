"""Input validation shared by every public function: one message style, one place.

Each helper takes the argument's name and the value that came, and either returns it
in canonical form or raises :class:`~rescon.errors.InputError` with a one-line message
naming the argument, what was expected and what came
(``"F must be an integer >= 0; got 2.5"``). Booleans are never numbers here.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from fractions import Fraction
from typing import Any

import numpy as np

from .errors import InputError

__all__ = ["check_F", "check_points", "flag", "integer", "nonnegative", "positive", "real"]


def flag(name: str, value: Any) -> bool:
    """``value`` as a bool: True or False (numpy's too); "no", 0, None … are refused rather
    than read by their truth value."""
    if not isinstance(value, (bool, np.bool_)):
        raise InputError(f"{name} must be True or False; got {value!r}")
    return bool(value)


def integer(name: str, value: Any, *, low: int | None = None, high: int | None = None) -> int:
    """``value`` as a Python int with ``low ≤ value ≤ high`` (each bound optional)."""
    expected = _integer_kind(low, high)
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise InputError(f"{name} must be {expected}; got {value!r}")
    value = int(value)
    if (low is not None and value < low) or (high is not None and value > high):
        raise InputError(f"{name} must be {expected}; got {value!r}")
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
    return _bounded(name, value, lambda v: v > 0, f"a {what} > 0")


def nonnegative(name: str, value: Any, *, what: str = "finite number") -> float:
    """A finite real ≥ 0."""
    return _bounded(name, value, lambda v: v >= 0, f"a {what} >= 0")


def _bounded(name: str, value: Any, ok: Callable[[float], bool], expected: str) -> float:
    v = real(name, value)
    if not (math.isfinite(v) and ok(v)):
        raise InputError(f"{name} must be {expected}; got {value!r}")
    return v


def _integer_kind(low: int | None, high: int | None) -> str:
    if low == 0 and high is None:
        return "a nonnegative integer"
    return "an integer" + _range(low, high)


def check_points(X: Any, name: str = "X") -> np.ndarray:
    """X as a finite float array (n, d), n ≥ 1, d ≥ 1, or InputError saying what came.

    Every entry must be a float64 exactly: complex numbers, integers above 2^53 (or
    Fractions, long doubles) that a float cannot hold are refused, not rounded — the
    kernel is exact for the floats it is given, and its certificate states them."""
    try:
        raw = np.asarray(X)
        complex_ = raw.dtype.kind == "c" or (raw.dtype == object and any(
            isinstance(v, (complex, np.complexfloating)) for v in raw.flat))
        arr = None if complex_ else np.array(raw, dtype=np.float64)
        if raw.dtype.kind == "b":
            raise TypeError("booleans are not numbers here")
    except OverflowError:
        raise InputError(f"{name} has an entry outside the float64 range") from None
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a finite (n, d) array of numbers; got "
                         f"{type(X).__name__} that is not numeric ({exc})") from None
    if arr is None:
        raise InputError(f"{name} must be real; got complex entries")
    _check_exact_floats(raw, arr, name)
    if arr.ndim != 2:
        raise InputError(f"{name} must be a finite (n, d) array; got shape {arr.shape}")
    n, d = arr.shape
    if n == 0 or d == 0:
        raise InputError(f"{name} must be a finite (n, d) array with n >= 1 points in d >= 1 "
                         f"dimensions; got shape {arr.shape}")
    bad = ~np.isfinite(arr)
    if bad.any():
        nan = int(np.isnan(arr).sum())
        raise InputError(f"{name} must be finite; got shape {arr.shape} with {nan} NaN and "
                         f"{int(bad.sum()) - nan} infinite entries")
    return arr


def check_point(x: Any, d: int, name: str = "x") -> np.ndarray:
    """x as a finite float64 point of dimension d, each entry exactly a float (as
    :func:`check_points`), or a one-line InputError naming ``name``."""
    try:
        arr = check_points(np.reshape(np.asarray(x), (1, -1)), name)
    except (InputError, TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a finite point of dimension {d}: {exc}") from None
    if arr.shape != (1, d):
        raise InputError(f"{name} must be a finite point of dimension {d}; got "
                         f"{arr.shape[1]} coordinates")
    return arr[0]


def _check_exact_floats(raw: np.ndarray, arr: np.ndarray, name: str) -> None:
    """InputError when a finite entry of ``raw`` is not exactly its float64 ``arr``
    (integer dtypes: only |v| > 2^53 can differ; object: each entry as a Fraction)."""
    kind = raw.dtype.kind
    flat_raw, flat = raw.ravel(), arr.ravel()
    if kind in "iu":
        suspects = np.flatnonzero(np.abs(flat) >= 2.0**53)
    elif kind == "f" and raw.dtype.itemsize > 8:
        suspects = np.flatnonzero(np.isfinite(flat) & (flat.astype(raw.dtype) != flat_raw))
    elif kind == "O":
        suspects = np.flatnonzero(np.isfinite(flat))
    else:
        return
    for i in suspects.tolist():
        v = flat_raw[i]
        if kind == "f" or Fraction(v) != Fraction(float(flat[i])):
            text = str(v) if len(str(v)) <= 24 else f"{str(v)[:20]}… ({len(str(v))} chars)"
            raise InputError(f"{name}[{i // arr.shape[-1]}, {i % arr.shape[-1]}] = {text} is "
                             f"not exactly a float64 (it would be rounded); give floats, "
                             f"or integers of magnitude at most 2^53")


def check_F(F: Any, n: int) -> int:
    """F as an int with 0 ≤ F < n."""
    if isinstance(F, bool) or not isinstance(F, (int, np.integer)):
        raise InputError(f"F must be an integer 0 <= F < n = {n}; got {F!r}")
    F = int(F)
    if not 0 <= F < n:
        raise InputError(f"F must satisfy 0 <= F < n = {n}; got F = {F}")
    return F


def _range(low: int | None, high: int | None) -> str:
    if low is not None and high is not None:
        return f" in [{low}, {high}]"
    if low is not None:
        return f" >= {low}"
    if high is not None:
        return f" <= {high}"
    return ""
