"""Graphs named in data: ``{"generator": "ba_robust", "n": 30, "m": 4}`` → a graph.

The one place where a scenario file's or a sweep grid's ``[graph] generator = ...``
becomes a networkx graph, so TOML, dicts and sweep cells validate it the same way.

Generators (every one takes ``n``, the number of nodes):

=====================  =======================  ===========================================
name                   parameters               graph
=====================  =======================  ===========================================
``ba_robust``          n, m                     :func:`~rescon.graphs.generators.ba_robust`
``directed_growth``    n, k                     :func:`~.generators.directed_growth`
``circulant``          n, k [, directed]        :func:`~.generators.circulant`
``two_cliques``        n (even), b              :func:`~.generators.two_cliques`, m = n/2
``erdos_renyi``        n, p [, directed]        G(n, p), ``networkx.gnp_random_graph``
``random_geometric``   n, radius [, dim]        unit cube, ``networkx.random_geometric_graph``
``complete``           n                        K_n
=====================  =======================  ===========================================

Parameters come from the table itself and from a sub-table named after the generator
(``[graph.circulant] k = 4``), so a sweep axis over ``graph.generator`` can give each
generator its own parameters; keys of the other generators' sub-tables are ignored.
Randomness: ``numpy.random.default_rng([seed, 1])`` (stream 1 of the scenario seed).
A graph whose estimated size exceeds the one budget (:mod:`rescon.geometry._budget`:
links × :data:`LINK_BYTES` bytes, node pairs drawn in Python) is refused before it is
built, with the estimate in the message.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import networkx as nx
import numpy as np

from .._validate import integer, real
from ..errors import InputError
from ..geometry._budget import PYTHON_STEP, require
from . import generators as gen

__all__ = ["GENERATORS", "generate"]

#: stream of the graph in default_rng([seed, stream]) (the initial states use 2)
GRAPH_STREAM = 1


def _ba(p: dict, rng: np.random.Generator) -> nx.Graph:
    return gen.ba_robust(p["n"], p["m"], seed=rng)


def _growth(p: dict, rng: np.random.Generator) -> nx.Graph:
    return gen.directed_growth(p["n"], p["k"], seed=rng)


def _circulant(p: dict, rng: np.random.Generator) -> nx.Graph:
    return gen.circulant(p["n"], p["k"], directed=p.get("directed", False))


def _cliques(p: dict, rng: np.random.Generator) -> nx.Graph:
    n = p["n"]
    if n % 2:
        raise InputError(f"n must be even for two_cliques (two cliques of n/2); got {n}")
    return gen.two_cliques(n // 2, p["b"], seed=rng)


def _gnp(p: dict, rng: np.random.Generator) -> nx.Graph:
    return nx.gnp_random_graph(p["n"], p["p"], seed=_nx_seed(rng),
                               directed=p.get("directed", False))


def _geometric(p: dict, rng: np.random.Generator) -> nx.Graph:
    return nx.random_geometric_graph(p["n"], p["radius"], dim=p.get("dim", 2),
                                     seed=_nx_seed(rng))


def _complete(p: dict, rng: np.random.Generator) -> nx.Graph:
    return nx.complete_graph(p["n"])


#: name → (builder, required parameters, optional parameters)
GENERATORS: dict[str, tuple[Callable[[dict, np.random.Generator], nx.Graph],
                            tuple[str, ...], tuple[str, ...]]] = {
    "ba_robust": (_ba, ("n", "m"), ()),
    "directed_growth": (_growth, ("n", "k"), ()),
    "circulant": (_circulant, ("n", "k"), ("directed",)),
    "two_cliques": (_cliques, ("n", "b"), ()),
    "erdos_renyi": (_gnp, ("n", "p"), ("directed",)),
    "random_geometric": (_geometric, ("n", "radius"), ("dim",)),
    "complete": (_complete, ("n",), ()),
}
_INTEGERS = {"n": 2, "m": 1, "k": 1, "b": 0, "dim": 1}
_FLAGS = {"directed"}
#: bytes of one directed link of a networkx graph (measured: ~140 per undirected edge
#: stored twice, ~210 per DiGraph edge), with room for the copies a scenario makes
LINK_BYTES = 256


def _size(name: str, p: dict) -> tuple[float, float]:
    """(links, pair draws): upper estimates of the directed links of generator ``name``
    (an undirected edge counts twice) and of the node pairs it draws in Python
    (G(n, p) draws all n(n − 1)/2 pairs whatever p)."""
    n = p["n"]
    links = {"ba_robust": lambda: 2 * p["m"] * n + 4 * p["m"] ** 2,
             "directed_growth": lambda: p["k"] * n + 4 * p["k"] ** 2,
             "circulant": lambda: 2 * p["k"] * n,
             "two_cliques": lambda: n * n / 2 + p["b"] * n,
             "erdos_renyi": lambda: p["p"] * n * n,
             "random_geometric": lambda: n * n * min(1.0, (2 * p["radius"]) ** p.get("dim", 2)),
             "complete": lambda: n * n}[name]()
    return links, (n * n / 2 if name == "erdos_renyi" else links)


def generate(table: Mapping[str, Any], seed: int, *, where: str = "graph") -> nx.Graph:
    """The graph of ``table`` (``generator`` plus its parameters, optional ``seed``
    overriding ``seed``), with one-line InputErrors naming the key: an unknown generator
    (listing the available ones), a missing, unknown or ill-typed parameter."""
    name = table.get("generator")
    if name not in GENERATORS:
        raise InputError(f"{where}: generator must be one of {', '.join(GENERATORS)}; "
                         f"got {name!r}")
    build, required, optional = GENERATORS[name]
    params = {k: v for k, v in table.items()
              if k not in GENERATORS and k not in ("generator", "seed")}
    own = table.get(name, {})
    if not isinstance(own, Mapping):
        raise InputError(f"{where}: {name} must be a table of {name}'s parameters; got {own!r}")
    params.update(own)
    allowed = required + optional
    extra = sorted(set(params) - set(allowed))
    if extra:
        raise InputError(f"{where}: {extra} are not parameters of generator {name!r} "
                         f"(it takes {', '.join(allowed)})")
    missing = [k for k in required if k not in params]
    if missing:
        raise InputError(f"{where}: generator {name!r} needs {', '.join(missing)}")
    checked = {k: _param(k, v, where) for k, v in params.items()}
    links, draws = _size(name, checked)
    require(f"{where}: generator {name!r} with n = {checked['n']} (~{links:.2g} links)",
            draws * PYTHON_STEP, links * LINK_BYTES, "reduce n (or the degree)")
    seed = integer(f"{where}: seed", table.get("seed", seed), low=0)
    try:
        return build(checked, np.random.default_rng([seed, GRAPH_STREAM]))
    except InputError as exc:
        raise InputError(f"{where}: {name}: {exc}") from None


def _param(key: str, value: Any, where: str) -> Any:
    """A generator parameter checked by its name: integers (n ≥ 2, m, k ≥ 1, b ≥ 0,
    dim ≥ 1), flags (directed), p ∈ [0, 1], radius > 0."""
    if key in _INTEGERS:
        return integer(f"{where}: {key}", value, low=_INTEGERS[key])
    if key in _FLAGS:
        if not isinstance(value, bool):
            raise InputError(f"{where}: {key} must be true or false; got {value!r}")
        return value
    x = real(f"{where}: {key}", value)
    if key == "p" and not 0 <= x <= 1:
        raise InputError(f"{where}: p must be a probability in [0, 1]; got {value!r}")
    if key == "radius" and not x > 0:
        raise InputError(f"{where}: radius must be a number > 0; got {value!r}")
    return x


def _nx_seed(rng: np.random.Generator) -> int:
    """An integer seed for a networkx generator, drawn from ``rng``."""
    return int(rng.integers(2**63))
