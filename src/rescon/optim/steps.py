"""Step sizes β_k of Algorithm 2 and the paper's Assumption 5.

Assumption 5: β_k > 0 is non-increasing, Σ_k β_k = ∞ and Σ_k β_k² < ∞. With
t_k = k T (T the sampling period):

========================  ======================  =====================================
preset                     β_k                     Assumption 5 (decided analytically)
========================  ======================  =====================================
``"paper"``                1/(5 t_k + 1)           holds
``harmonic(a, b)``         1/(a t_k + b)           holds iff a > 0 (a = 0: constant)
``sqrt_decay(c)``          c/√(k + 1)              fails: Σβ² = c² Σ 1/(k+1) = ∞
``constant(c)`` / number   c                       fails: Σβ² = ∞
callable k ↦ β_k           user's                  checked on a horizon (below)
========================  ======================  =====================================

A callable cannot be decided from finitely many values: on k = 0..K its values must
be finite and ≥ 0 (else InputError), non-increasing is checked exactly on those
values, and the two sums are judged by the tail exponent p̂ = log₂(β_{K/2}/β_K) (β_k
≈ C k^−p̂): p̂ > 1 suggests Σβ < ∞, p̂ ≤ ½ suggests Σβ² = ∞. Those two are estimates
and their messages say so. Violations are returned as strings; the caller turns them
into warnings (as :class:`rescon.Scenario` does for the other assumptions).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from .. import _validate
from ..errors import InputError

__all__ = ["StepSize", "constant", "harmonic", "sqrt_decay", "step_size"]


class StepSize:
    """β_k for k = 0, 1, …; ``values(k, T)`` on an integer array, ``assumption5(T,
    horizon)`` → the list of violated conditions (empty when Assumption 5 holds)."""

    def values(self, k: Any, T: float = 1.0) -> np.ndarray:
        raise NotImplementedError

    def assumption5(self, T: float = 1.0, horizon: int = 10_000) -> list[str]:
        raise NotImplementedError

    def __call__(self, k: int, T: float = 1.0) -> float:
        return float(self.values(np.array([k]), T)[0])


class Harmonic(StepSize):
    """β_k = 1/(a t_k + b), a ≥ 0, b > 0."""

    def __init__(self, a: float, b: float) -> None:
        self.a = _validate.nonnegative("a", a)
        self.b = _validate.positive("b", b)

    def values(self, k: Any, T: float = 1.0) -> np.ndarray:
        return 1.0 / (self.a * T * np.asarray(k, dtype=float) + self.b)

    def assumption5(self, T: float = 1.0, horizon: int = 10_000) -> list[str]:
        if self.a == 0:
            return [(f"step size 1/({self.a:g} t_k + {self.b:g}) is constant: Σβ² = ∞ "
                    f"(Assumption 5 needs a > 0)")]
        return []

    def __repr__(self) -> str:
        return f"harmonic({self.a:g}, {self.b:g})"


class SqrtDecay(StepSize):
    """β_k = c/√(k + 1), c > 0."""

    def __init__(self, c: float) -> None:
        self.c = _validate.positive("c", c)

    def values(self, k: Any, T: float = 1.0) -> np.ndarray:
        return self.c / np.sqrt(np.asarray(k, dtype=float) + 1.0)

    def assumption5(self, T: float = 1.0, horizon: int = 10_000) -> list[str]:
        return [(f"step size {self.c:g}/√(k+1): Σβ² = {self.c:g}² Σ 1/(k+1) = ∞ "
                f"(Assumption 5 needs Σβ² < ∞)")]

    def __repr__(self) -> str:
        return f"sqrt_decay({self.c:g})"


class Constant(StepSize):
    """β_k = c > 0."""

    def __init__(self, c: float) -> None:
        self.c = _validate.positive("step_size", c)

    def values(self, k: Any, T: float = 1.0) -> np.ndarray:
        return np.full(np.shape(k), self.c)

    def assumption5(self, T: float = 1.0, horizon: int = 10_000) -> list[str]:
        return [(f"constant step size {self.c:g}: Σβ² = ∞ (Assumption 5 needs Σβ² < ∞); "
                f"expect convergence only to a neighbourhood of the optimum")]

    def __repr__(self) -> str:
        return f"constant({self.c:g})"


class FromCallable(StepSize):
    """β_k = fn(k) for a user callable (checked when evaluated)."""

    def __init__(self, fn: Callable[[int], float]) -> None:
        self.fn = fn

    def values(self, k: Any, T: float = 1.0) -> np.ndarray:
        ks = np.asarray(k).reshape(-1)
        out = np.empty(ks.shape)
        for j, kk in enumerate(ks):
            v = self.fn(int(kk))
            try:
                out[j] = float(v)
            except (TypeError, ValueError):
                raise InputError(f"step_size({int(kk)}) must be a real number; got "
                                 f"{v!r}") from None
            if not (math.isfinite(out[j]) and out[j] >= 0):
                raise InputError(f"step_size({int(kk)}) must be a finite number >= 0; "
                                 f"got {v!r}")
        return out.reshape(np.shape(k))

    def assumption5(self, T: float = 1.0, horizon: int = 10_000) -> list[str]:
        K = _validate.integer("horizon", horizon, low=2)
        beta = self.values(np.arange(K + 1), T)
        out = []
        up = np.flatnonzero(beta[1:] > beta[:-1])
        if up.size:
            k = int(up[0])
            out.append(f"step size is not non-increasing: β_{k + 1} = {beta[k + 1]:g} > "
                       f"β_{k} = {beta[k]:g}")
        if beta[K] == 0:
            return out + [f"step size reaches 0 by k = {K}: Σβ may be finite"]
        p = math.log2(beta[K // 2] / beta[K]) if beta[K // 2] > 0 else math.inf
        where = f"(estimated on k ≤ {K} from β_k ≈ C k^-{p:.3g}; not decidable from values)"
        if p > 1:
            out.append(f"step size may be summable, Σβ < ∞ {where}")
        if p <= 0.5:
            out.append(f"step size may not be square-summable, Σβ² = ∞ {where}")
        return out

    def __repr__(self) -> str:
        return f"step_size({getattr(self.fn, '__name__', 'callable')})"


def harmonic(a: float, b: float) -> StepSize:
    """β_k = 1/(a t_k + b), t_k = k T; the paper's is ``harmonic(5, 1)``."""
    return Harmonic(a, b)


def sqrt_decay(c: float) -> StepSize:
    """β_k = c/√(k + 1) (not square-summable: violates Assumption 5)."""
    return SqrtDecay(c)


def constant(c: float) -> StepSize:
    """β_k = c (not square-summable: violates Assumption 5)."""
    return Constant(c)


def step_size(spec: Any) -> StepSize:
    """``spec`` as a :class:`StepSize`: "paper" (1/(5 t_k + 1)), a positive number
    (constant), a callable k ↦ β_k, or a StepSize.

    Raises
    ------
    InputError
        Anything else, a number ≤ 0 or not finite.
    """
    if isinstance(spec, StepSize):
        return spec
    if isinstance(spec, str):
        if spec != "paper":
            raise InputError(f"step_size must be 'paper', a positive number or a callable "
                             f"k -> beta_k; got {spec!r}")
        return Harmonic(5.0, 1.0)
    if isinstance(spec, (int, float, np.integer, np.floating)) and not isinstance(spec, bool):
        return Constant(spec)
    if callable(spec):
        return FromCallable(spec)
    raise InputError(f"step_size must be 'paper', a positive number or a callable "
                     f"k -> beta_k; got {type(spec).__name__}")
