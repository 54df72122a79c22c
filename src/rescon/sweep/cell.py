"""One sweep cell: a pure function spec dict → row dict (no state but its argument), so
any Dask worker can run it. Everything it returns is plain data.

Every row has every column of :data:`METRICS`; the columns of the other kinds are null:

* consensus: ``final_diameter``, ``max_validity``, ``steps_to_consensus``,
  ``blocked_links``, ``final_gap`` (RMDO);
* robustness: ``rho`` (ρ(G), null when a time limit left it open), ``s_star``
  (s*(ρ)), ``exact``, ``method`` (the exact methods that ran), ``certificate_valid``
  and ``certificate_verdict`` (the standalone checker's verdict on the certificate,
  "valid" / "invalid" / "unchecked"; null with ``check = false``);
* kernel: ``dim`` (−1 when empty), ``is_empty``, ``n_vertices``,
  ``certificate_valid``, ``certificate_verdict``.
"""

from __future__ import annotations

import math
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError

__all__ = ["METRICS", "failed_row", "run_cell", "steps_to_consensus"]

#: the result columns of a row, after the axes, ``repetition`` and ``seed``
METRICS = ("status", "error", "final_diameter", "max_validity", "steps_to_consensus",
           "blocked_links", "final_gap", "rho", "s_star", "exact", "method",
           "certificate_valid", "certificate_verdict", "dim", "is_empty", "n_vertices",
           "seconds", "rescon_version")
_RESULTS = METRICS[2:-2]  # the columns a kind fills (null otherwise)


def steps_to_consensus(diameter: np.ndarray, epsilon: float) -> int | None:
    """The first step k with diameter(t_k) ≤ ε · diameter(t_0) (0 when the benign agents
    start together), None if no step reaches it. NaN diameters never count."""
    hit = np.flatnonzero(diameter <= epsilon * diameter[0])
    return int(hit[0]) if hit.size else None


def run_cell(cell: dict[str, Any]) -> dict[str, Any]:
    """Run one cell (:meth:`rescon.sweep.grid.Grid.cells`) and return its row. Any
    exception — an invalid scenario included — is recorded: status "failed", error
    "<Type>: <message>" (first line), metrics null; it never escapes."""
    t0 = time.perf_counter()
    try:
        run = _KIND_RUNS[cell.get("kind", "consensus")]
        metrics = run(cell["spec"], Path(cell["path"]), cell["epsilon"])
    except Exception as exc:  # noqa: BLE001 (a failing cell is recorded, not raised)
        return failed_row(cell, exc, time.perf_counter() - t0)
    return _row(cell, status="ok", error=None, **metrics,
                seconds=time.perf_counter() - t0)


def failed_row(cell: dict[str, Any], exc: BaseException,
               seconds: float | None = None) -> dict[str, Any]:
    """The row of a cell that raised ``exc`` — in the cell, or as the worker running it
    died (Dask's KilledWorker) —: status "failed", error "<Type>: <first line>"."""
    message = str(exc).splitlines()[0] if str(exc) else ""
    return _row(cell, status="failed", error=f"{type(exc).__name__}: {message}",
                seconds=seconds)


def _row(cell: dict[str, Any], **results: Any) -> dict[str, Any]:
    """A row: the cell's axis values, repetition and seed, then every column of
    :data:`METRICS` (null unless in ``results``)."""
    from .. import __version__

    return {**cell["params"], "repetition": cell["repetition"], "seed": cell["seed"],
            **dict.fromkeys(_RESULTS), **results, "rescon_version": __version__}


def _run(spec: dict[str, Any], path: Path, epsilon: float) -> dict[str, Any]:
    """Algorithm 1 / a baseline (no [costs]) or RMDO ([costs]) on the cell's spec; the
    theorems' assumption checks run as the scenario asks, their warnings are silenced
    (a sweep reports numbers, not warnings)."""
    from ..consensus.engine import simulate
    from ..consensus.scenario import Scenario

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if "costs" in spec:
            from ..optim.files import rmdo_from_dict
            from ..optim.rmdo import rmdo

            f = rmdo_from_dict(spec, path=path)
            tr = rmdo(f.scenario, f.costs, step_size=f.step_size, progress=False)
        else:
            sc = Scenario.from_dict(spec, base=path.parent, where=str(path))
            tr = simulate(sc, progress=False)
    m = tr.metrics
    gap = m.get("optimality_gap")
    return {"final_diameter": _num(tr.final_diameter), "max_validity": _num(tr.max_validity),
            "steps_to_consensus": steps_to_consensus(m["diameter"], epsilon),
            "blocked_links": int(np.sum(m["blocked_links"])),
            "final_gap": None if gap is None else _num(float(gap[-1]))}


def _robustness(spec: dict[str, Any], path: Path, epsilon: float) -> dict[str, Any]:
    """ρ(G) and s*(ρ) of [graph] (a generator, a file or edges: the scenario parser's
    [graph]) by :func:`rescon.robustness` ([robustness] method, time_limit), its
    certificate checked by the standalone checker unless [robustness] check = false."""
    from ..consensus.scenario import _graph
    from ..graphs.robustness import robustness

    opts = spec.get("robustness", {})
    graph = dict(spec.get("graph", {}))
    if "generator" not in graph:  # a file or edge list draws nothing from the cell's seed
        graph.pop("seed", None)
    G = _graph(graph, path.parent, "[graph]", 0)
    rep = robustness(G, method=opts.get("method", "auto"),
                     time_limit=opts.get("time_limit"), progress=False)
    return {"rho": rep.r_max, "s_star": rep.s_max, "exact": rep.exact,
            "method": rep.method, **_verdict(rep.certificate, opts)}


def _kernel(spec: dict[str, Any], path: Path, epsilon: float) -> dict[str, Any]:
    """The safe kernel Ψ(X, F) of the [points] cloud (:func:`rescon.sweep.clouds.cloud`)
    with [kernel] F, its certificate checked unless [kernel] check = false."""
    from ..geometry.kernel import safe_kernel
    from .clouds import cloud

    opts = spec.get("kernel", {})
    if "F" not in opts:
        raise InputError("[kernel]: needs F (the number of points an adversary may move)")
    K = safe_kernel(cloud(spec.get("points", {}), where="[points]"), opts["F"])
    return {"dim": K.dim, "is_empty": K.is_empty, "n_vertices": len(K.vertices),
            **_verdict(K.certificate, opts)}


def _verdict(certificate: dict[str, Any], opts: dict[str, Any]) -> dict[str, Any]:
    """certificate_valid / certificate_verdict of the standalone checker (both null
    when ``opts["check"]`` is false)."""
    check = opts.get("check", True)
    if not isinstance(check, bool):
        raise InputError(f"check must be true or false; got {check!r}")
    if not check:
        return {"certificate_valid": None, "certificate_verdict": None}
    from ..certify import check_certificate

    res = check_certificate(certificate)
    return {"certificate_valid": res.valid, "certificate_verdict": res.verdict}


_KIND_RUNS = {"consensus": _run, "robustness": _robustness, "kernel": _kernel}


def _num(x: float) -> float | None:
    """A float, NaN as None (null in the table)."""
    return None if math.isnan(x) else x
