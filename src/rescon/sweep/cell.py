"""One sweep cell: a pure function spec dict → row dict (no state but its argument), so
any Dask worker can run it. Everything it returns is plain data."""

from __future__ import annotations

import math
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["METRICS", "run_cell", "steps_to_consensus"]

#: the result columns of a row, after the axes, ``repetition`` and ``seed``
METRICS = ("status", "error", "final_diameter", "max_validity", "steps_to_consensus",
           "blocked_links", "final_gap", "seconds", "rescon_version")


def steps_to_consensus(diameter: np.ndarray, epsilon: float) -> int | None:
    """The first step k with diameter(t_k) ≤ ε · diameter(t_0) (0 when the benign agents
    start together), None if no step reaches it. NaN diameters never count."""
    hit = np.flatnonzero(diameter <= epsilon * diameter[0])
    return int(hit[0]) if hit.size else None


def run_cell(cell: dict[str, Any]) -> dict[str, Any]:
    """Run one cell (:meth:`rescon.sweep.grid.Grid.cells`) and return its row. Any
    exception — an invalid scenario included — is recorded: status "failed", error
    "<Type>: <message>" (first line), metrics null; it never escapes."""
    from .. import __version__

    row: dict[str, Any] = {**{k: cell["params"][k] for k in cell["params"]},
                           "repetition": cell["repetition"], "seed": cell["seed"]}
    t0 = time.perf_counter()
    try:
        metrics = _run(cell["spec"], Path(cell["path"]), cell["epsilon"])
        row.update(status="ok", error=None, **metrics)
    except Exception as exc:  # noqa: BLE001 (a failing cell is recorded, not raised)
        message = str(exc).splitlines()[0] if str(exc) else ""
        row.update(status="failed", error=f"{type(exc).__name__}: {message}",
                   final_diameter=None, max_validity=None, steps_to_consensus=None,
                   blocked_links=None, final_gap=None)
    row.update(seconds=time.perf_counter() - t0, rescon_version=__version__)
    return row


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


def _num(x: float) -> float | None:
    """A float, NaN as None (null in the table)."""
    return None if math.isnan(x) else x
