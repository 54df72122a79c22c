"""Constants of IEEE-754 double arithmetic that the float filters rely on.

Every float filter in rescon bounds its rounding error with the unit roundoff
u = 2^-53 (|fl(a ∘ b) − a ∘ b| ≤ u |a ∘ b| for normal results) and is trusted only
where no intermediate value overflowed to ±inf or fell below the normal range, where
that bound does not hold; there the decision is made exactly.
"""

from __future__ import annotations

import sys

#: unit roundoff of IEEE-754 binary64 (round to nearest)
UNIT_ROUNDOFF = 2.0**-53
#: smallest positive normal double, 2^-1022: below it the relative bound above fails
MIN_NORMAL = sys.float_info.min
#: largest finite double, (2 − 2^-52)·2^1023
MAX_FINITE = sys.float_info.max
