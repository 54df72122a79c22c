"""rescon.optim: RMDO (Algorithm 2) — subgradient oracles, step sizes, the paper's costs.

``optim`` imports ``consensus``; ``consensus`` never imports ``optim``.
"""

from __future__ import annotations

from .cost import cost
from .files import RMDOFile, read_costs, read_rmdo
from .oracle import Oracle, SubgradientOracle, check_subgradient
from .paper import paper_costs

__all__ = ["Oracle", "RMDOFile", "SubgradientOracle", "check_subgradient", "cost",
           "paper_costs", "read_costs", "read_rmdo"]
