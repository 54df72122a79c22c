"""Sweep grids: ``[base]`` (a scenario file's tables), ``[axes]`` (dotted scenario keys →
lists of values, the grid is their product) and ``[run]`` (``kind``, ``repetitions``,
``epsilon``), read from TOML or given as the same dict (DESIGN.md, ``rescon sweep``).

``[run] kind`` says what a cell computes (:data:`KINDS`): "consensus" (default: a
scenario run by Algorithm 1, a baseline or RMDO; tables of a scenario / RMDO file),
"robustness" (ρ and s* of ``[graph]``, a generator or a file, with ``[robustness]``
method, time_limit) or "kernel" (the safe kernel of a generated point cloud
``[points]`` generator, n, d with ``[kernel]`` F). An axis key is dotted as in TOML:
``"graph.n"``, ``"graph.circulant.k"`` (a nested table) — its first part names a table
of the kind, and keys of the fixed tables are checked here, so a misspelt axis is a
grid error, not a column of failed cells.

A cell is plain data — ``{"cell", "kind", "params", "repetition", "seed", "spec",
"path", "epsilon"}`` — so any Dask scheduler can ship it to
:func:`rescon.sweep.cell.run_cell`.
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
from ..consensus.scenario import _GRAPH, _SCENARIO, _TOP, RMDO_TABLES, read_toml
from ..errors import InputError
from ..graphs.named import GENERATORS
from .clouds import CLOUDS

__all__ = ["EPSILON", "KINDS", "MAX_CELLS", "Grid", "read_grid"]

#: default ε of ε-consensus: steps_to_consensus is the first step k with
#: diameter(t_k) ≤ ε · diameter(t_0)
EPSILON = 1e-6
#: the most cells a grid may have (the axes' product × repetitions): its cells are built
#: in memory before the first runs, ~1 kB each (a typo such as repetitions = 10⁹ would
#: take the machine's memory before any check)
MAX_CELLS = 10**6
_TABLES = _TOP | set(RMDO_TABLES)
_RUN = {"kind", "repetitions", "epsilon"}
_GENERATED = {"generator", "seed", *GENERATORS,
              *(k for _, req, opt in GENERATORS.values() for k in (*req, *opt))}
#: kind → (its tables, the (table, key) of the seed a repetition adds to)
KINDS: dict[str, tuple[frozenset[str], tuple[str, str]]] = {
    "consensus": (frozenset(_TABLES), ("scenario", "seed")),
    "robustness": (frozenset({"graph", "robustness"}), ("graph", "seed")),
    "kernel": (frozenset({"points", "kernel"}), ("points", "seed")),
}
_NAMED = {"graph.generator": GENERATORS, "points.generator": CLOUDS}
#: the keys of the tables whose keys are fixed (others, like [initial], name nodes)
KEYS: dict[str, frozenset[str]] = {
    "scenario": frozenset(_SCENARIO), "graph": frozenset(_GRAPH | _GENERATED),
    "robustness": frozenset({"method", "time_limit", "check"}),
    "points": frozenset({"generator", "n", "d", "seed"}),
    "kernel": frozenset({"F", "check"}),
}


@dataclass(frozen=True)
class Grid:
    """A parsed grid: ``base`` tables, ``axes`` (key → values, in the given order),
    ``repetitions``, ``epsilon``, ``path`` (names in ``base`` are relative to its
    directory), ``digest`` (SHA-256 of the canonical JSON of base, axes and run, and of
    the axis order, which numbers the cells, when it is not the sorted one) and
    ``kind`` (:data:`KINDS`)."""

    base: dict[str, Any]
    axes: dict[str, list[Any]]
    repetitions: int
    epsilon: float
    path: str
    digest: str
    kind: str = "consensus"

    def cells(self) -> list[dict[str, Any]]:
        """One spec per (axes point, repetition), in a fixed order; the run's seed is
        the kind's seed key (scenario.seed, graph.seed or points.seed; base or axis,
        default 0) + repetition."""
        out = []
        seed_table, seed_key = KINDS[self.kind][1]
        points = itertools.product(*self.axes.values())
        for point, rep in itertools.product(points, range(self.repetitions)):
            params = dict(zip(self.axes, point, strict=True))
            spec = copy.deepcopy(self.base)
            for key, value in params.items():
                _put(spec, key, copy.deepcopy(value))
            table = spec.setdefault(seed_table, {})
            seed = table.get(seed_key, 0)
            if isinstance(seed, int) and not isinstance(seed, bool):
                table[seed_key] = seed + rep
            out.append({"cell": len(out), "kind": self.kind, "params": params,
                        "repetition": rep, "seed": table.get(seed_key), "spec": spec,
                        "path": self.path, "epsilon": self.epsilon})
        return out


def _put(spec: dict[str, Any], key: str, value: Any) -> None:
    """``spec[a][b][c] = value`` for the axis key "a.b.c" (TOML's dotted keys: missing
    tables are created); "dos" replaces the whole [[dos]] array of attacks."""
    if key == "dos":
        spec["dos"] = value
        return
    *tables, name = key.split(".")
    for t in tables:
        spec = spec.setdefault(t, {})
        if not isinstance(spec, dict):
            raise InputError(f"axis {key!r}: {t} is not a table in [base]")
    spec[name] = value


def read_grid(grid: str | Path | Mapping[str, Any]) -> Grid:
    """A grid from a TOML file or a dict; bad input is a one-line InputError naming the
    key (unknown table or key, an axis that is not a list or is empty, a bad
    ``repetitions``). Cells whose scenario is invalid are not refused here: the sweep
    records them as failed."""
    if isinstance(grid, Mapping):
        data, path, where = grid, Path.cwd() / "grid", "grid"
    elif isinstance(grid, (str, Path)):
        path = Path(grid)
        data, where = read_toml(path, "sweep grid"), str(path)
    else:
        raise InputError(f"grid must be a TOML file name or a dict; got {type(grid).__name__}")
    extra = sorted(set(data) - {"base", "axes", "run"})
    if extra:
        raise InputError(f"{where}: unknown keys {extra} (allowed: base, axes, run)")
    run = _mapping(data.get("run", {}), f"{where} [run]")
    bad = sorted(set(run) - _RUN)
    if bad:
        raise InputError(f"{where} [run]: unknown keys {bad} (allowed: {sorted(_RUN)})")
    kind = run.get("kind", "consensus")
    if not isinstance(kind, str) or kind not in KINDS:
        raise InputError(f"{where} [run]: kind must be one of {', '.join(KINDS)}; "
                         f"got {kind!r}")
    tables = KINDS[kind][0]
    base = _mapping(data.get("base", {}), f"{where} [base]")
    bad = sorted(set(base) - tables)
    if bad:
        raise InputError(f"{where} [base]: unknown tables {bad} for kind {kind!r} "
                         f"(allowed: {sorted(tables)})")
    for name in sorted(set(base) & set(KEYS)):
        _known(name, _mapping(base[name], f"{where} [base.{name}]"), f"{where} [base]")
    for gen, params in base.get("graph", {}).items():
        if gen in GENERATORS and isinstance(params, Mapping):
            for param in params:
                _parameter(f"graph.{gen}.{param}", f"{where} [base.graph.{gen}]")
    axes = {k: _axis(k, v, tables, f"{where} [axes]")
            for k, v in _mapping(data.get("axes", {}), f"{where} [axes]").items()}
    reps = integer("repetitions", run.get("repetitions", 1), low=1)
    _size(axes, reps, where)
    eps = positive("epsilon", run.get("epsilon", EPSILON), what="number")
    if eps >= 1:
        raise InputError(f"{where} [run]: epsilon must be in (0, 1); got {eps!r}")
    canon_run = {"repetitions": reps, "epsilon": eps}
    if kind != "consensus":  # the digests of consensus grids stay what they were
        canon_run["kind"] = kind
    canon = {"base": base, "axes": axes, "run": canon_run}
    if list(axes) != sorted(axes):  # cells are numbered in axis order (sorted: as before)
        canon["order"] = list(axes)
    try:
        text = json.dumps(canon, sort_keys=True, separators=(",", ":"), allow_nan=False)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{where}: a grid is plain data (numbers, strings, lists, "
                         f"tables): {exc}") from None
    return Grid(dict(base), axes, reps, eps, str(path),
                hashlib.sha256(text.encode()).hexdigest(), kind)


def _mapping(value: Any, where: str) -> Mapping[str, Any]:
    if not isinstance(value, Mapping):
        raise InputError(f"{where}: must be a table; got {value!r}")
    return value


def _size(axes: Mapping[str, list[Any]], reps: int, where: str) -> None:
    """Refuse a grid of more than :data:`MAX_CELLS` cells (Π |axis| × repetitions),
    naming the factors."""
    cells = reps
    for values in axes.values():
        cells *= len(values)
    if cells > MAX_CELLS:
        sizes = ", ".join(f"{k!r}: {len(v)}" for k, v in axes.items())
        raise InputError(f"{where}: {cells} cells (axes {{{sizes}}} × repetitions = "
                         f"{reps}) exceed the limit of {MAX_CELLS} cells; split the grid")


def _axis(key: Any, values: Any, tables: frozenset[str], where: str) -> list[Any]:
    """An axis: "table.key[.key…]" with a table of the kind (or "dos": each value a
    whole [[dos]] array), a known key for the fixed tables (:data:`KEYS`), and a
    non-empty list; a "graph.generator" or "points.generator" axis names known
    generators."""
    if not isinstance(key, str):
        raise InputError(f"{where}: axis {key!r} must be a dotted key 'table.key' (a "
                         f"string); got a {type(key).__name__}")
    table, _, name = key.partition(".")
    named = sorted(tables - {"dos"})
    if not (key == "dos" and "dos" in tables) and not (table in named and name):
        raise InputError(f"{where}: axis {key!r} must be a dotted key 'table.key' with "
                         f"table one of {named}" + (", or 'dos'" if "dos" in tables else ""))
    if not isinstance(values, list) or not values:
        raise InputError(f"{where}: axis {key!r} must be a non-empty list; got {values!r}")
    if table in KEYS:
        _known(table, {name.split(".")[0]: None}, where)
    _parameter(key, where)
    known = _NAMED.get(key)
    bad = [v for v in values if not isinstance(v, str) or v not in known] if known else []
    if bad:
        raise InputError(f"{where}: axis {key!r}: unknown generators {bad} "
                         f"(available: {', '.join(known)})")
    return list(values)


def _parameter(key: str, where: str) -> None:
    """A key "graph.<generator>.<name>" names a parameter of that generator (its
    sub-table is read only when it runs: a misspelt name would silently change nothing
    in the cells of the other generators)."""
    parts = key.split(".")
    if parts[0] == "graph" and len(parts) > 2 and parts[1] in GENERATORS:
        _, required, optional = GENERATORS[parts[1]]
        if len(parts) > 3 or parts[2] not in required + optional:
            raise InputError(f"{where}: {key!r}: {parts[1]} takes "
                             f"{', '.join(required + optional)}")


def _known(table: str, keys: Mapping[str, Any], where: str) -> None:
    """The keys of a fixed table (:data:`KEYS`) are known ones."""
    bad = sorted(set(keys) - KEYS[table])
    if bad:
        raise InputError(f"{where}: unknown keys {bad} in {table} (allowed: "
                         f"{sorted(KEYS[table])})")
