"""Constants of IEEE-754 double arithmetic that the float filters rely on.

Every float filter in rescon bounds its rounding error with the unit roundoff
u = 2^-53 (|fl(a ∘ b) − a ∘ b| ≤ u |a ∘ b| for normal results) and is trusted only
where no intermediate value overflowed to ±inf or fell below the normal range, where
that bound does not hold; there the decision is made exactly.
"""

from __future__ import annotations

import math
import sys

#: unit roundoff of IEEE-754 binary64 (round to nearest)
UNIT_ROUNDOFF = 2.0**-53
#: smallest positive normal double, 2^-1022: below it the relative bound above fails
MIN_NORMAL = sys.float_info.min
#: largest finite double, (2 − 2^-52)·2^1023
MAX_FINITE = sys.float_info.max
#: smallest positive (subnormal) double, 2^-1074: the spacing of the subnormal range
MIN_SUBNORMAL = 2.0**-1074


def underflow_floor(k: int, M: float) -> float:
    """An absolute error term that covers gradual underflow in the filters' polynomial
    expressions in k coordinates of magnitude ≤ M (degree ≤ k + 2, at most
    (k + 2)^(k + 2) products): a multiplication whose result is subnormal errs by up to
    2^-1075 absolutely (additions and subtractions are exact there), an input rounded
    into the subnormal range likewise, and each later factor (≤ 2 max(M, 1)) scales
    that error. Hence |error| ≤ (k + 2)^(k + 2) · (2 max(M, 1))^(k + 2) · 2^-1070.
    Negligible beside any normal-range value; +inf (every decision undecided) when the
    bound itself would overflow or M is not finite."""
    if not math.isfinite(M):
        return math.inf
    e = (k + 2) * (math.log2(k + 2) + 1.0 + math.log2(max(M, 1.0))) - 1070.0
    return math.ldexp(1.0, math.ceil(e)) if e < 1000.0 else math.inf
