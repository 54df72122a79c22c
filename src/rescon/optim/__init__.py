"""rescon.optim: RMDO (Algorithm 2) — subgradient oracles, step sizes, the paper's costs,
r-redundancy.

``optim`` imports ``consensus``; ``consensus`` never imports ``optim``.
"""

from __future__ import annotations

from .cost import cost
from .files import RMDOFile, read_costs, read_rmdo
from .oracle import Oracle, SubgradientOracle, check_subgradient
from .paper import paper_costs
from .redundancy import RedundancyReport, check_redundancy

__all__ = ["Oracle", "RMDOFile", "RedundancyReport", "SubgradientOracle", "check_redundancy",
           "check_subgradient", "cost", "paper_costs", "read_costs", "read_rmdo"]
