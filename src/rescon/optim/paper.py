"""The paper's ten costs (SPEC §5), keyed by node label as in
:meth:`rescon.Scenario.paper_example` (benign agents 1, 3, …, 11)."""

from __future__ import annotations

from ..errors import InputError
from .cost import cost
from .oracle import Oracle

__all__ = ["PAPER_COSTS", "paper_costs"]

#: f_i as written in the paper's table; f_7 depends only on x1 (sic)
PAPER_COSTS = {
    1: "x1^2 + x2^2",
    3: "abs(x1 + x2)",
    4: "sqrt(x1^2 + x2^2)",
    5: "(x1 - 1)^2 + (x2 - 0.5)^2",
    6: "max(x1, x2)",
    7: "(x1 + 0.3)^2 + (x1 - 0.2)^2",
    8: "abs(x1) + abs(x2)",
    9: "abs(x1) + x2^2",
    10: "x1^2 + x2^2 + abs(x1 - x2)",
    11: "max(abs(x1), abs(x2))",
}

#: the other reading of f_7, with its second square in x2
F7_X2 = "(x1 + 0.3)^2 + (x2 - 0.2)^2"


def paper_costs(f7: str = "as-written") -> dict[int, Oracle]:
    """The paper's costs as atom oracles over x ∈ R², one per benign agent.

    Parameters
    ----------
    f7 : "as-written" (default: (x1 + 0.3)² + (x1 − 0.2)², as the table prints it) or
        "x2" ((x1 + 0.3)² + (x2 − 0.2)², the likely intended one).

    Notes
    -----
    f_6 = max(x1, x2) is unbounded below and the individual minimisers differ (f_1 at
    the origin, f_5 at (1, 0.5)), as SPEC §5 notes — yet the costs *are* F-redundant
    (F = 2): every 8 of the 10 sum to a function whose argmin is exactly {(0, 0)} (both
    readings of f_7; ``check_redundancy(paper_costs(), 2)`` proves it, exactly), while
    they are not 2F = 4-redundant (an exact witness).

    Examples
    --------
    >>> costs = paper_costs()
    >>> sorted(costs), costs[6].value([[1.0, 2.0]]).tolist()
    ([1, 3, 4, 5, 6, 7, 8, 9, 10, 11], [2.0])
    """
    if f7 not in ("as-written", "x2"):
        raise InputError(f"f7 must be 'as-written' or 'x2'; got {f7!r}")
    src = dict(PAPER_COSTS)
    if f7 == "x2":
        src[7] = F7_X2
    return {i: cost(s, d=2, name=f"cost of agent {i}") for i, s in src.items()}
