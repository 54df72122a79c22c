"""rescon: resilient multi-agent consensus and distributed optimisation with certificates.

Graph convention: a networkx DiGraph edge ``(u, v)`` means **v receives u's state**.
Every answer that can be certified carries a JSON-ready certificate, checked by the
standalone checker in ``certificates/`` (see :func:`check_certificate`).

``import rescon`` loads nothing heavy: each public name is imported from its module on
first use (PEP 562), so networkx, scipy, numba, Dask and matplotlib load only when a
call needs them.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

#: public name -> the module that defines it (imported on first access)
_HOME = {
    "CheckResult": "certify",
    "check_certificate": "certify",
    "simulate": "consensus.engine",
    "Scenario": "consensus.scenario",
    "ScenarioWarning": "consensus.scenario",
    "Trajectory": "consensus.trajectory",
    "CertificateError": "errors",
    "EmptyKernel": "errors",
    "GraphFormatError": "errors",
    "InputError": "errors",
    "MissingDependency": "errors",
    "RESCONError": "errors",
    "SolverError": "errors",
    "SolverNotFound": "errors",
    "TimeLimitReached": "errors",
    "SafeKernel": "geometry.kernel",
    "kernel_point": "geometry.kernel",
    "kernel_points": "geometry.kernel",
    "safe_kernel": "geometry.kernel",
    "TverbergPartition": "geometry.tverberg",
    "tverberg_partition": "geometry.tverberg",
    "check_assumption2": "graphs.attacks",
    "check_attack_model": "graphs.attacks",
    "RobustnessCheck": "graphs.robustness",
    "RobustnessReport": "graphs.robustness",
    "is_r_robust": "graphs.robustness",
    "is_rs_robust": "graphs.robustness",
    "max_s": "graphs.robustness",
    "robustness": "graphs.robustness",
    "is_sarymsakov": "graphs.sarymsakov",
    "check_subgradient": "optim",
    "cost": "optim",
    "RedundancyReport": "optim.redundancy",
    "check_redundancy": "optim.redundancy",
    "rmdo": "optim.rmdo",
    "PaperReport": "paper",
    "reproduce_paper": "paper",
}

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


def __getattr__(name: str) -> Any:
    """A public name from its module, or a subpackage (``rescon.sweep`` is callable:
    ``rescon.sweep(grid, ...)`` is :func:`rescon.sweep.sweep`)."""
    home = _HOME.get(name)
    if home is None:
        if name.startswith("__"):  # probes such as __wrapped__ are not submodules
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
        try:
            return importlib.import_module(f"{__name__}.{name}")
        except ModuleNotFoundError as exc:
            if exc.name != f"{__name__}.{name}":
                raise
            raise AttributeError(f"module {__name__!r} has no attribute {name!r}") from None
    value = getattr(importlib.import_module(f"{__name__}.{home}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})


if TYPE_CHECKING:  # what static tools see; at run time, __getattr__ above
    from . import sweep
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
