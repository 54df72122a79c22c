"""Exceptions raised by rescon.

Every error derives from :class:`RESCONError`; subclasses also inherit the
matching builtin so that ``except ValueError`` keeps working for bad input.
"""

from __future__ import annotations

__all__ = [
    "RESCONError",
    "InputError",
    "GraphFormatError",
    "SolverError",
    "SolverNotFound",
    "CertificateError",
    "TimeLimitReached",
    "EmptyKernel",
    "MissingDependency",
]


class RESCONError(Exception):
    """Base class of every exception rescon raises on purpose."""


class InputError(RESCONError, ValueError):
    """An argument or input file is malformed or out of range."""


class GraphFormatError(InputError):
    """A graph file cannot be parsed; the message names the file and line."""


class SolverError(RESCONError, RuntimeError):
    """A solver failed or returned a status rescon cannot use."""


class SolverNotFound(SolverError):
    """A requested backend is unknown or not installed."""


class CertificateError(RESCONError, ValueError):
    """A certificate could not be produced or is malformed."""


class TimeLimitReached(RESCONError, RuntimeError):
    """A time limit stopped a computation before it had an answer to return."""


class EmptyKernel(RESCONError, ValueError):
    """The safe kernel Ψ(X, F) is empty, so it has no point (F is too large for X)."""


class MissingDependency(RESCONError, ImportError):
    """An optional dependency (an extra such as ``rescon[plot]``) is not installed; the
    message says what to install."""
