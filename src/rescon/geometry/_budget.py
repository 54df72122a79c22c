"""One budget for every table and scan that grows exponentially with the dimension.

The safe-kernel pipeline has several steps whose size is C(n, k), 3^d, (k − 1)! or
2^k: the candidate hyperplanes, the quick emptiness directions, the permutations of
a cofactor expansion, the vertices of the bounding box. Each estimates its work
(elementary steps: a point-hyperplane test, a float multiply-add; a step in Python
integers counts :data:`PYTHON_STEP`) and its largest table (bytes) *before* building
anything, and

* :func:`require` refuses (InputError, one line naming the step and the estimate)
  what the answer needs but the budget cannot hold;
* :func:`fits` (with a ``share`` of the budget) lets a step that is only an
  optimisation be skipped instead.
"""

from __future__ import annotations

from ..errors import InputError

__all__ = ["MAX_BYTES", "MAX_WORK", "PYTHON_STEP", "fits", "require"]

#: elementary steps the pipeline may spend (4e9 numba point tests: seconds to a minute)
MAX_WORK = 4_000_000_000
#: bytes any one table may take
MAX_BYTES = 2**31
#: one step in Python integers (big-int arithmetic, interpreter) in elementary steps
PYTHON_STEP = 100


def fits(work: float, nbytes: float, share: float = 1.0) -> bool:
    """Whether ``work`` steps and a table of ``nbytes`` bytes fit in ``share`` of the
    budget."""
    return work <= share * MAX_WORK and nbytes <= share * MAX_BYTES


def require(what: str, work: float, nbytes: float, hint: str) -> None:
    """InputError unless :func:`fits`; ``what`` names the step, ``hint`` the remedy."""
    need = [f"about {work:.2e} steps (limit {MAX_WORK:.0e})"] if work > MAX_WORK else []
    if nbytes > MAX_BYTES:
        need.append(f"a table of {nbytes / 2**30:.3g} GiB (limit {MAX_BYTES / 2**30:.0f} GiB)")
    if need:
        raise InputError(f"{what} needs {' and '.join(need)}; {hint}")
