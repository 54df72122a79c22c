"""One registry of solver backends: name → capabilities, availability, install hint.

Availability is checked with :func:`importlib.util.find_spec`, so listing backends
never imports a heavy module. There is no silent fallback: asking for a backend
that is unknown, missing or lacks a capability raises :class:`SolverNotFound`
naming the backends that would do.
"""

from __future__ import annotations

import contextlib
import functools
import importlib.util
import threading
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from ..errors import SolverNotFound

__all__ = ["BACKENDS", "Backend", "available_backends", "require_backend",
           "silent_highs", "silent_highs_inside"]

@dataclass(frozen=True)
class Backend:
    """A solver backend: ``module`` is what must be importable."""

    name: str
    module: str
    capabilities: frozenset[str]
    install: str

    def is_available(self) -> bool:
        return importlib.util.find_spec(self.module) is not None


BACKENDS: dict[str, Backend] = {
    b.name: b
    for b in (
        Backend("highs", "highspy", frozenset({"LP", "QP", "MILP"}), "pip install highspy"),
        Backend("clarabel", "clarabel", frozenset({"LP", "QP", "SOCP"}), "pip install clarabel"),
        Backend("proxsuite", "proxsuite", frozenset({"QP", "batch"}), "pip install proxsuite"),
        Backend("cvxpy", "cvxpy", frozenset({"LP", "QP", "SOCP", "model"}), "pip install cvxpy"),
        Backend("casadi", "casadi", frozenset({"LP", "QP", "model"}), "pip install casadi"),
    )
}


def available_backends(capability: str | None = None) -> list[str]:
    """Names of the installed backends (with ``capability``, if given)."""
    return [
        name
        for name, b in BACKENDS.items()
        if (capability is None or capability in b.capabilities) and b.is_available()
    ]


def require_backend(name: str, capability: str) -> Backend:
    """The backend ``name`` if it is known, installed and has ``capability``.

    Raises
    ------
    SolverNotFound
        Naming the installed backends with that capability and how to install ``name``.
    """
    ok = available_backends(capability)
    b = BACKENDS.get(name)
    if b is None:
        raise SolverNotFound(
            f"unknown backend {name!r}; backends with {capability}: {ok or 'none installed'}"
        )
    if capability not in b.capabilities:
        raise SolverNotFound(
            f"backend {name!r} cannot solve {capability}; use one of {ok or 'none installed'}"
        )
    if not b.is_available():
        raise SolverNotFound(
            f"backend {name!r} is not installed ({b.install}); available for {capability}: "
            f"{ok or 'none'}"
        )
    return b


def silent_highs() -> Any:
    """A new ``highspy.Highs`` that never writes to stdout: every HiGHS model rescon
    builds comes from here.

    HiGHS logs its banner ("Running HiGHS …", C-level stdout) at the first method call
    on an instance while ``output_flag`` is true; in highspy 1.16 that call is the
    wrapper's own ``enableCallbacks()`` inside ``Highs.__init__``, so setting the option
    after construction is too late. The subclass turns the output off inside that
    first call, before anything is logged; the option is set again afterwards in case
    a highspy version constructs differently.
    """
    h = _silent_highs_class()()
    h.setOptionValue("output_flag", False)
    return h


_SWAP = threading.RLock()


@contextlib.contextmanager
def silent_highs_inside() -> Iterator[None]:
    """Within the block, ``highspy.Highs()`` builds :func:`silent_highs` instances: for
    libraries that construct their own model (CVXPY's HiGHS interface calls
    ``highspy.Highs()`` at solve time, and the banner comes before any option it
    passes). The class is swapped back on exit; blocks run one at a time."""
    import highspy

    with _SWAP:
        saved = highspy.Highs
        highspy.Highs = _silent_highs_class()
        try:
            yield
        finally:
            highspy.Highs = saved


@functools.cache
def _silent_highs_class() -> type:
    import highspy

    class SilentHighs(highspy.Highs):  # type: ignore[misc]
        def enableCallbacks(self) -> None:
            self.setOptionValue("output_flag", False)
            super().enableCallbacks()

    return SilentHighs
