"""RMDO files: a scenario TOML with ``[costs]`` and ``[step_size]``, and costs files.

An RMDO file is a scenario file (README, "Scenario files"; parsed by the scenario
parser itself) with two more tables::

    [costs]                       # one of, or a mix of (a node given twice is refused):
    1 = "(x1 - 1)^2 + x2^2"       #   per agent (key = node label as in [initial]) an
    2 = "abs(x1 + x2)"            #   expression in the grammar of rescon.optim.expr
    module = "mycosts:build"      #   "pkg.mod:function", called with no arguments and
                                  #   returning a mapping node -> anything rescon.cost
                                  #   accepts (this RUNS THE USER'S CODE; the file's
                                  #   directory is searched first for pkg)
    # paper = true                #   the paper's ten costs (rescon.optim.paper_costs),
    # f7 = "x2"                   #   alone; f7 = "as-written" (default) or "x2"
    [step_size]
    kind = "paper"                # 1/(5 t_k + 1) (the default without [step_size]);
                                  # "harmonic" (a, b): 1/(a t_k + b); "sqrt_decay" (c):
                                  # c/sqrt(k + 1); "constant" (value)

``module``, ``paper``, ``f7`` and ``algorithm`` are reserved: they are not node labels.
``algorithm = "rmdo"`` (its only value) may mark the table, as sweep grids do
(``[base.costs]``, DESIGN.md). Agents given the same expression string share one
oracle (one call per step for all of them).

[costs] is what makes a file an RMDO file: ``rescon rmdo`` requires it, and
``Scenario.from_toml`` / ``rescon simulate`` refuse a file that has it (Algorithm 1
would silently ignore the costs). Examples: ``examples/scenarios/paper_rmdo.toml``,
``rmdo_quadratic.toml``.

A costs file (``rescon redundancy``) is ``[costs]`` and an optional top-level ``d``
(default: the largest variable index its expressions use), or a whole RMDO file (its
benign agents' costs, d of its states; as for ``rescon rmdo``, every benign agent needs
a cost).
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Hashable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .._validate import integer
from ..consensus.scenario import RMDO_TABLES, Scenario, _from_dict, _keys, _label, _table, read_toml
from ..errors import InputError
from .cost import cost
from .oracle import Oracle
from .paper import paper_costs
from .steps import StepSize, constant, harmonic, sqrt_decay

__all__ = ["RMDOFile", "read_costs", "read_rmdo", "rmdo_from_dict"]

_RESERVED = {"module", "paper", "f7", "algorithm"}
#: [step_size] kinds → (their parameters, the preset built from them)
_STEP_KINDS: dict[str, tuple[tuple[str, ...], Any]] = {
    "paper": ((), lambda: harmonic(5.0, 1.0)),
    "harmonic": (("a", "b"), harmonic),
    "sqrt_decay": (("c",), sqrt_decay),
    "constant": (("value",), constant),
}


@dataclass(frozen=True)
class RMDOFile:
    """What an RMDO file describes: ``rescon.rmdo(f.scenario, f.costs,
    step_size=f.step_size)`` runs it."""

    scenario: Scenario
    costs: dict[Hashable, Oracle]
    step_size: StepSize


def read_rmdo(path: str | Path) -> RMDOFile:
    """Read an RMDO file (format: module docstring).

    Raises
    ------
    InputError
        One line naming the file: anything the scenario parser refuses, no [costs], an
        unparsable or non-convex expression (with its position), a cost of the wrong
        dimension, a module that cannot be imported or whose function fails, a bad
        [step_size], a benign agent without a cost.
    """
    data = read_toml(path, "RMDO file")  # refuses a non-path, a directory, an unreadable file
    return rmdo_from_dict(data, path=Path(path))


def rmdo_from_dict(data: Mapping[str, Any], *, path: str | Path = "rmdo") -> RMDOFile:
    """An RMDO file's tables as a dict, by the parser of :func:`read_rmdo` (sweep grids
    use it: costs as expression strings are plain data). ``path``: the file the data
    came from, real or notional — its directory resolves the file and module names the
    data gives, its name prefixes error messages."""
    p = Path(path)
    data = dict(data)
    if "costs" not in data:
        raise InputError(f"{p}: an RMDO file needs a [costs] table (one cost per benign "
                         "agent); without it, run Algorithm 1 with `rescon simulate`")
    tables = {k: _table(data, k, str(p)) for k in RMDO_TABLES}
    for k in RMDO_TABLES:
        data.pop(k, None)
    sc = _from_dict(data, p.parent, str(p))
    costs = _costs(tables["costs"], p, sc.d, sc.graph)
    missing = [v for v in sc.benign if v not in costs]
    if missing:  # rescon.rmdo would refuse it without naming the file
        raise InputError(f"{p} [costs]: no cost for benign agent(s) {missing[:5]}")
    return RMDOFile(sc, costs, _step_size(tables["step_size"], f"{p} [step_size]"))


def read_costs(path: str | Path) -> tuple[dict[Hashable, Oracle], int]:
    """The costs of a costs file and their dimension d (format: module docstring).

    Raises
    ------
    InputError
        One line naming the file: what :func:`read_rmdo` refuses, a benign agent of an
        RMDO file without a cost (as :func:`rescon.rmdo` refuses it), no [costs], a bad
        ``d``, a cost the expression parser or :func:`rescon.cost` refuses.
    """
    data = read_toml(path, "costs file")  # refuses a non-path, a directory, an unreadable file
    p = Path(path)
    if set(data) & {"scenario", "graph", "initial"}:  # an RMDO file: its benign agents'
        f = read_rmdo(p)  # it refuses a benign agent without a cost
        keep = set(f.scenario.benign)
        return {v: o for v, o in f.costs.items() if v in keep}, f.scenario.d
    _keys(data, {"d", "costs"}, str(p))
    if "costs" not in data:
        raise InputError(f"{p}: a costs file needs a [costs] table")
    table = _table(data, "costs", str(p))
    if "d" in data:
        d = _dimension(data["d"], p)
        return _costs(table, p, d), d
    guess = _costs(table, p, None)
    dims = {o.d for o in guess.values() if o.d is not None}
    if not dims:
        raise InputError(f"{p}: give the dimension: d = <number> before [costs]")
    d = max(dims)
    return _costs(table, p, d), d


def _dimension(value: Any, p: Path) -> int:
    try:
        return integer("d", value, low=1)
    except InputError as exc:
        raise InputError(f"{p}: {exc}") from None


def _costs(table: Mapping[str, Any], p: Path, d: int | None, nodes: Any = None
           ) -> dict[Hashable, Oracle]:
    """[costs] as oracles over R^d, one per distinct source (same string or object);
    with ``nodes`` (the scenario's graph), agents that are not nodes are refused first."""
    where = f"{p} [costs]"
    if table.get("algorithm", "rmdo") != "rmdo":
        raise InputError(f"{where}: algorithm must be \"rmdo\" (or left out); got "
                         f"{table['algorithm']!r}")
    table = {k: v for k, v in table.items() if k != "algorithm"}
    if "paper" in table or "f7" in table:
        return _paper(table, where)
    try:
        specs: dict[Hashable, Any] = {_label(k, None if nodes is None else set(nodes)): v
                                      for k, v in table.items() if k not in _RESERVED}
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    if "module" in table:
        for v, spec in _module(table["module"], p.parent, where).items():
            if v in specs:
                raise InputError(f"{where}: agent {v!r} has a cost in the file and one from "
                                 f"module {table['module']!r}")
            specs[v] = spec
    unknown = [v for v in specs if nodes is not None and v not in nodes]
    if unknown:
        raise InputError(f"{where}: {unknown[:5]} are not nodes of the graph (the keys "
                         f"{sorted(_RESERVED)} are reserved, the others are node labels)")
    made: dict[Any, Oracle] = {}
    out = {}
    for v, spec in specs.items():
        key = spec if isinstance(spec, str) else id(spec)
        if key not in made:
            made[key] = cost(spec, d=d, name=f"{where} agent {v!r}")
        out[v] = made[key]
    return out


def _paper(table: Mapping[str, Any], where: str) -> dict[Hashable, Oracle]:
    """``paper = true`` (+ ``f7``): the paper's ten costs, alone."""
    _keys(table, {"paper", "f7"}, f"{where} (with paper = true)")
    if table.get("paper") is not True:
        raise InputError(f"{where}: f7 selects a reading of the paper's costs: it needs "
                         f"paper = true; got paper = {table.get('paper')!r}")
    try:
        return dict(paper_costs(table.get("f7", "as-written")))
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None


def _module(ref: Any, base: Path, where: str) -> Mapping[Hashable, Any]:
    """The mapping returned by the user's ``pkg.mod:function()`` (their code runs here),
    imported with ``base`` (the file's directory) first on the module search path."""
    if not (isinstance(ref, str) and ref.count(":") == 1 and all(ref.split(":"))):
        raise InputError(f"{where}: module must be \"pkg.mod:function\"; got {ref!r}")
    mod_name, fn_name = ref.split(":")
    sys.path.insert(0, str(base.resolve()))
    try:
        mod = importlib.import_module(mod_name)
    except Exception as exc:  # noqa: BLE001 (the user's module may raise anything)
        raise InputError(f"{where}: module {mod_name!r} cannot be imported "
                         f"({type(exc).__name__}: {exc})") from None
    finally:
        sys.path.remove(str(base.resolve()))
    fn = getattr(mod, fn_name, None)
    if not callable(fn):
        raise InputError(f"{where}: module {mod_name!r} has no function {fn_name!r}")
    try:
        costs = fn()
    except Exception as exc:  # noqa: BLE001 (the user's function may raise anything)
        raise InputError(f"{where}: {ref}() failed ({type(exc).__name__}: {exc})") from None
    if not isinstance(costs, Mapping):
        raise InputError(f"{where}: {ref}() must return a mapping node -> cost; got "
                         f"{type(costs).__name__}")
    return costs


def _step_size(table: Mapping[str, Any], where: str) -> StepSize:
    """[step_size] → the preset it names (module docstring); absent: the paper's."""
    kind = table.get("kind", "paper")
    if not isinstance(kind, str) or kind not in _STEP_KINDS:  # a TOML list is unhashable
        raise InputError(f"{where}: kind must be one of {', '.join(_STEP_KINDS)}; got {kind!r}")
    params, make = _STEP_KINDS[kind]
    _keys(table, {"kind", *params}, f"{where} (kind = {kind!r})")
    missing = [k for k in params if k not in table]
    if missing:
        raise InputError(f"{where}: kind = {kind!r} needs {', '.join(params)}; missing "
                         f"{', '.join(missing)}")
    try:
        return make(*(table[k] for k in params))
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
