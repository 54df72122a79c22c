"""rescon: resilient multi-agent consensus and distributed optimisation with certificates.

Graph convention: a networkx DiGraph edge ``(u, v)`` means **v receives u's state**.
Every answer that can be certified carries a JSON-ready certificate, checked by the
standalone checker in ``certificates/`` (see :func:`check_certificate`).
"""

from __future__ import annotations

from . import sweep  # callable: rescon.sweep(grid, ...) is rescon.sweep.sweep
from .certify import CheckResult, check_certificate
from .consensus.engine import simulate
from .consensus.scenario import Scenario, ScenarioWarning
from .consensus.trajectory import Trajectory
from .errors import (
    CertificateError,
    EmptyKernel,
    GraphFormatError,
    InputError,
    MissingDependency,
    RESCONError,
    SolverError,
    SolverNotFound,
    TimeLimitReached,
)
from .geometry.kernel import SafeKernel, kernel_point, kernel_points, safe_kernel
from .geometry.tverberg import TverbergPartition, tverberg_partition
from .graphs.attacks import check_assumption2, check_attack_model
from .graphs.robustness import (
    RobustnessCheck,
    RobustnessReport,
    is_r_robust,
    is_rs_robust,
    max_s,
    robustness,
)
from .graphs.sarymsakov import is_sarymsakov
from .optim import check_subgradient, cost
from .optim.redundancy import RedundancyReport, check_redundancy
from .optim.rmdo import rmdo
from .paper import PaperReport, reproduce_paper

__version__ = "0.1.0"

__all__ = [
    "CertificateError",
    "CheckResult",
    "EmptyKernel",
    "GraphFormatError",
    "InputError",
    "MissingDependency",
    "PaperReport",
    "RESCONError",
    "RedundancyReport",
    "RobustnessCheck",
    "RobustnessReport",
    "SafeKernel",
    "Scenario",
    "ScenarioWarning",
    "SolverError",
    "SolverNotFound",
    "TimeLimitReached",
    "Trajectory",
    "TverbergPartition",
    "check_assumption2",
    "check_attack_model",
    "check_certificate",
    "check_redundancy",
    "check_subgradient",
    "cost",
    "is_r_robust",
    "is_rs_robust",
    "is_sarymsakov",
    "kernel_point",
    "kernel_points",
    "max_s",
    "reproduce_paper",
    "rmdo",
    "robustness",
    "safe_kernel",
    "simulate",
    "sweep",
    "tverberg_partition",
]
