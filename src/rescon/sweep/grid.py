"""Sweep grids: ``[base]`` (a scenario file's tables), ``[axes]`` (dotted scenario keys →
lists of values, the grid is their product) and ``[run]`` (``repetitions``,
``epsilon``), read from TOML or given as the same dict (DESIGN.md, ``rescon sweep``).

A cell is plain data — ``{"cell", "params", "repetition", "seed", "spec", "path",
"epsilon"}`` — so any Dask scheduler can ship it to :func:`rescon.sweep.cell.run_cell`.
"""

from __future__ import annotations

import copy
import hashlib
import itertools
import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._validate import integer, positive
from ..consensus.scenario import _TOP, RMDO_TABLES, read_toml
from ..errors import InputError

__all__ = ["EPSILON", "Grid", "read_grid"]

#: default ε of ε-consensus: steps_to_consensus is the first step k with
#: diameter(t_k) ≤ ε · diameter(t_0)
EPSILON = 1e-6
_TABLES = _TOP | set(RMDO_TABLES)
_RUN = {"repetitions", "epsilon"}


@dataclass(frozen=True)
class Grid:
    """A parsed grid: ``base`` tables, ``axes`` (key → values, in the given order),
    ``repetitions``, ``epsilon``, ``path`` (names in ``base`` are relative to its
    directory) and ``digest`` (SHA-256 of the canonical JSON of base, axes and run)."""

    base: dict[str, Any]
    axes: dict[str, list[Any]]
    repetitions: int
    epsilon: float
    path: str
    digest: str

    def cells(self) -> list[dict[str, Any]]:
        """One spec per (axes point, repetition), in a fixed order; the run's seed is
        scenario.seed (base or axis, default 0) + repetition."""
        out = []
        points = itertools.product(*self.axes.values())
        for point, rep in itertools.product(points, range(self.repetitions)):
            params = dict(zip(self.axes, point, strict=True))
            spec = copy.deepcopy(self.base)
            for key, value in params.items():
                if key == "dos":  # the whole [[dos]] array of attacks
                    spec["dos"] = copy.deepcopy(value)
                    continue
                table, name = key.split(".", 1)
                spec.setdefault(table, {})[name] = copy.deepcopy(value)
            sc = spec.setdefault("scenario", {})
            seed = sc.get("seed", 0)
            if isinstance(seed, int) and not isinstance(seed, bool):
                sc["seed"] = seed + rep
            out.append({"cell": len(out), "params": params, "repetition": rep,
                        "seed": sc.get("seed"), "spec": spec, "path": self.path,
                        "epsilon": self.epsilon})
        return out


def read_grid(grid: str | Path | Mapping[str, Any]) -> Grid:
    """A grid from a TOML file or a dict; bad input is a one-line InputError naming the
    key (unknown table or key, an axis that is not a list or is empty, a bad
    ``repetitions``). Cells whose scenario is invalid are not refused here: the sweep
    records them as failed."""
    if isinstance(grid, Mapping):
        data, path, where = grid, Path.cwd() / "grid", "grid"
    elif isinstance(grid, (str, Path)):
        path = Path(grid)
        data, where = read_toml(path), str(path)
    else:
        raise InputError(f"grid must be a TOML file name or a dict; got {type(grid).__name__}")
    extra = sorted(set(data) - {"base", "axes", "run"})
    if extra:
        raise InputError(f"{where}: unknown keys {extra} (allowed: base, axes, run)")
    base = _mapping(data.get("base", {}), f"{where} [base]")
    bad = sorted(set(base) - _TABLES)
    if bad:
        raise InputError(f"{where} [base]: unknown tables {bad} (allowed: {sorted(_TABLES)})")
    axes = {k: _axis(k, v, f"{where} [axes]")
            for k, v in _mapping(data.get("axes", {}), f"{where} [axes]").items()}
    run = _mapping(data.get("run", {}), f"{where} [run]")
    bad = sorted(set(run) - _RUN)
    if bad:
        raise InputError(f"{where} [run]: unknown keys {bad} (allowed: {sorted(_RUN)})")
    reps = integer("repetitions", run.get("repetitions", 1), low=1)
    eps = positive("epsilon", run.get("epsilon", EPSILON), what="number")
    if eps >= 1:
        raise InputError(f"{where} [run]: epsilon must be in (0, 1); got {eps!r}")
    canon = {"base": base, "axes": axes, "run": {"repetitions": reps, "epsilon": eps}}
    try:
        text = json.dumps(canon, sort_keys=True, separators=(",", ":"), allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{where}: a grid is plain data (numbers, strings, lists, "
                         f"tables): {exc}") from None
    return Grid(dict(base), axes, reps, eps, str(path),
                hashlib.sha256(text.encode()).hexdigest())


def _mapping(value: Any, where: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise InputError(f"{where}: must be a table; got {value!r}")
    return value


def _axis(key: str, values: Any, where: str) -> list[Any]:
    """An axis: "table.key" with a known scenario table (or "dos": each value a whole
    [[dos]] array), and a non-empty list."""
    table, _, name = key.partition(".")
    if key != "dos" and not (table in _TABLES - {"dos"} and name):
        raise InputError(f"{where}: axis {key!r} must be a dotted scenario key "
                         f"'table.key' with table one of {sorted(_TABLES - {'dos'})}, or 'dos'")
    if not isinstance(values, list) or not values:
        raise InputError(f"{where}: axis {key!r} must be a non-empty list; got {values!r}")
    return list(values)
