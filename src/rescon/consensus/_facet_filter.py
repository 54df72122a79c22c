"""The float filter of exact facets: the sign of a·x − β proven from floats.

Each exact facet a·x ≤ β is divided exactly by top = max|a_j| and each quotient
rounded once (:func:`_filter_rows`, :func:`_quotient`): Â has entries in [−1, 1], b̂ is
±inf beyond the float range. For a float row x, S = fl(Â x − b̂) is within
((d + 2)u + O(u²))(|Â|·|x| + |b̂|) of a·x/top − β/top — the rounding of the entries,
then the d + 1 terms of the dot product — plus (d + 2)(‖x‖∞ + 1)·2^-1074 for gradual
underflow; :func:`_slack_bound` doubles the first term, which covers the rounding of
the bound itself. S < −bound thus proves x strictly inside the facet, S > bound
strictly outside; overflow makes the bound inf or S NaN, and proves nothing. Used by
:func:`certified_hull` (rows proven in the proposed hull) and by the validity monitor
(:meth:`ValidityMonitor.surely_inside`, its fan and cone-facet tests).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from .._rounding import MIN_SUBNORMAL, UNIT_ROUNDOFF


def _slacks(A: np.ndarray, b: np.ndarray, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """fl(Â x − b̂) per row of ``states`` and facet (Â, b̂), and its error bound
    (:meth:`ValidityMonitor.surely_inside`)."""
    with np.errstate(over="ignore", invalid="ignore", under="ignore"):
        S = states @ A.T - b
        bound = _slack_bound(states.shape[1], np.abs(states) @ np.abs(A).T, np.abs(b),
                             np.abs(states).max(axis=1)[:, None])
    return S, bound


def _slack_bound(d: int, abs_dot: np.ndarray, abs_b: np.ndarray,
                 top: np.ndarray) -> np.ndarray:
    """Error bound of fl(â·x − b̂) in R^d from |â|·|x| (``abs_dot``), |b̂| and
    max |x_p| (``top``): 2(d+2)u(|â|·|x| + |b̂|) + (d+2)·2^-1074·(max |x_p| + 1), the
    last term for gradual underflow (one rule for :func:`_slacks` and the fan test).
    Its products round to subnormals by design: numpy's underflow flag is ignored here,
    whatever the caller's ``np.seterr`` (V38: ``all="raise"`` stopped every run)."""
    with np.errstate(under="ignore"):
        return (2 * (d + 2) * UNIT_ROUNDOFF * (abs_dot + abs_b)
                + (d + 2) * MIN_SUBNORMAL * (top + 1))


def _filter_rows(facets) -> tuple[np.ndarray, np.ndarray]:
    """Floats of the exact facets a·x ≤ β, each divided exactly by max|a_j| (so the
    entries of Â are in [−1, 1]; b̂ is ±inf beyond the float range), each quotient
    rounded once (:func:`_quotient`)."""
    tops = [max(map(abs, a)) for a, _ in facets]
    A = np.array([[_quotient(v, top) for v in a] for (a, _), top in zip(facets, tops)])
    return A, np.array(
        [_quotient(beta, top) for (_, beta), top in zip(facets, tops)], dtype=np.float64)


def _quotient(v: Fraction, w: Fraction) -> float:
    """v / w (w > 0) correctly rounded (Python's int / int, no Fraction built: 20 000
    facets took 1.3 s), ±inf beyond the float range."""
    num, den = v.numerator * w.denominator, v.denominator * w.numerator
    try:
        return num / den
    except OverflowError:
        return math.inf if num > 0 else -math.inf
