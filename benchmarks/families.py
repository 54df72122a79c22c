"""Graph families of BENCHMARKS.md §1 with fixed seeds (seed = 1000·n + i).

Self-contained (networkx + numpy only; does not use ``rescon.graphs.generators``).
Convention: a DiGraph edge ``(u, v)`` means v receives u's state.

Each family yields :class:`Instance` tuples ``(name, params, G, known_rho)`` where
``params`` holds the family parameters plus ``n`` (actual node count), ``instance``
(i) and ``seed``; ``known_rho`` is the closed-form robustness when one is known
(and was checked against the exhaustive baseline on small n in
``tests/test_benchmark_baselines.py``), else None.

Closed forms used:

* complete K_n: rho = ceil(n/2), s*(rho) = n;
* undirected circulant C_n(1..k): rho = k for n >= 2k+2 (for n <= 2k+1 it is K_n);
* directed circulant, i receives from i-1..i-k (n > k): rho = ceil(k/2) for odd k,
  k/2 for even k and even n, k/2 + 1 for even k and odd n;
* Barabási–Albert grown from K_{2m-1}: rho = m (K_{2m-1} is m-robust, each new node
  has m >= r + s - 1 in-neighbours; the last node has degree m);
* directed growth from K_{2k-1}, each new node receiving from k earlier nodes: rho = k;
* two K_m joined by b disjoint perfect matchings (n = 2m, b <= m): rho = b
  (S1, S2 = the two cliques gives max e = b) although min degree is m - 1 + b.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any, NamedTuple

import networkx as nx
import numpy as np

__all__ = [
    "Instance",
    "Family",
    "FAMILIES",
    "STRUCTURED",
    "instances",
    "make_instance",
    "variant_label",
    "known_s_star",
    "seed_for",
]


class Instance(NamedTuple):
    name: str
    params: dict[str, Any]
    G: nx.Graph
    known_rho: int | None


MakeFn = Callable[[int, int, dict[str, Any]], "tuple[nx.Graph, int | None] | None"]


@dataclass(frozen=True)
class Family:
    """A named graph family.

    ``make(n, seed, params)`` returns ``(G, known_rho)`` or None when the family
    has no member of that size for those parameters. ``deterministic`` families
    (no randomness) produce a single instance per size whatever ``--instances``
    says. ``structured`` families have constructive certificates and are run to
    n = 1000.
    """

    name: str
    variants: tuple[dict[str, Any], ...]
    make: MakeFn
    structured: bool = False
    deterministic: bool = False
    description: str = ""


def seed_for(n: int, i: int) -> int:
    """The fixed seed of instance i at size n (BENCHMARKS.md §1)."""
    return 1000 * n + i


def _rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def _digraph(n: int) -> nx.DiGraph:
    G = nx.DiGraph()
    G.add_nodes_from(range(n))
    return G


# --------------------------------------------------------------------------- makers


def _er(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, None]:
    return nx.gnp_random_graph(n, p["p"], seed=seed), None


def _er_directed(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, None]:
    return nx.gnp_random_graph(n, p["p"], seed=seed, directed=True), None


def _k_in(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, None] | None:
    k = p["k"]
    if n <= k:
        return None
    rng = _rng(seed)
    G = _digraph(n)
    for v in range(n):
        others = np.array([u for u in range(n) if u != v])
        for u in rng.choice(others, size=k, replace=False):
            G.add_edge(int(u), v)  # v receives from u
    return G, None


def _k_out(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, None] | None:
    k = p["k"]
    if n <= k:
        return None
    rng = _rng(seed)
    G = _digraph(n)
    for u in range(n):
        others = np.array([w for w in range(n) if w != u])
        for w in rng.choice(others, size=k, replace=False):
            G.add_edge(u, int(w))  # w receives from u
    return G, None


def _circulant(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, int] | None:
    k = p["k"]
    if n < 3:
        return None
    G = nx.circulant_graph(n, range(1, k + 1))
    return G, (k if n >= 2 * k + 2 else math.ceil(n / 2))


def _directed_circulant_rho(n: int, k: int) -> int:
    if k % 2:
        return (k + 1) // 2
    return k // 2 if n % 2 == 0 else k // 2 + 1


def _circulant_directed(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, int] | None:
    k = p["k"]
    if n <= k:
        return None
    G = _digraph(n)
    G.add_edges_from(((i - j) % n, i) for i in range(n) for j in range(1, k + 1))
    return G, _directed_circulant_rho(n, k)


def _complete(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, int]:
    return nx.complete_graph(n), math.ceil(n / 2)


def _ba(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, int] | None:
    m = p["m"]
    if n <= 2 * m - 1:
        return None
    G = nx.barabasi_albert_graph(n, m, seed=seed, initial_graph=nx.complete_graph(2 * m - 1))
    return G, m


def _growth_directed(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, int] | None:
    k = p["k"]
    n0 = 2 * k - 1
    if n <= n0:
        return None
    rng = _rng(seed)
    G = _digraph(n)
    G.add_edges_from((u, v) for u in range(n0) for v in range(n0) if u != v)
    for v in range(n0, n):
        for u in rng.choice(v, size=k, replace=False):
            G.add_edge(int(u), v)  # new node v receives from k earlier nodes
    return G, k


def _two_cliques(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, int] | None:
    b = p["b"]
    m = n // 2  # odd n is rounded down to 2m (the instance's params record the real n)
    if b > m or m < 2:
        return None
    rng = _rng(seed)
    perm = rng.permutation(m)
    G = nx.Graph()
    G.add_nodes_from(range(2 * m))
    G.add_edges_from((u, v) for u in range(m) for v in range(u + 1, m))
    G.add_edges_from((m + u, m + v) for u in range(m) for v in range(u + 1, m))
    # matching j pairs i with perm[(i + j) mod m]; distinct j give disjoint matchings
    G.add_edges_from((i, m + int(perm[(i + j) % m])) for i in range(m) for j in range(b))
    return G, b


def _geometric(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, None]:
    return nx.random_geometric_graph(n, p["radius"], seed=seed), None


def _watts_strogatz(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, None] | None:
    if n <= p["k"]:
        return None
    return nx.watts_strogatz_graph(n, p["k"], p["p"], seed=seed), None


def _random_regular(n: int, seed: int, p: dict[str, Any]) -> tuple[nx.Graph, None] | None:
    d = p["d"]
    if n <= d or (n * d) % 2:
        return None
    return nx.random_regular_graph(d, n, seed=seed), None


# --------------------------------------------------------------------------- registry

FAMILIES: dict[str, Family] = {
    f.name: f
    for f in [
        Family("er", ({"p": 0.3}, {"p": 0.5}, {"p": 0.8}), _er,
               description="Erdős–Rényi gnp_random_graph(n, p), undirected"),
        Family("er_directed", ({"p": 0.3}, {"p": 0.5}, {"p": 0.8}), _er_directed,
               description="gnp_random_graph(n, p, directed=True)"),
        Family("k_in", ({"k": 3}, {"k": 4}, {"k": 5}), _k_in,
               description="each node receives from k uniformly random other nodes"),
        Family("k_out", ({"k": 3}, {"k": 4}, {"k": 5}), _k_out,
               description="each node sends to k uniformly random other nodes"),
        Family("circulant", ({"k": 2}, {"k": 3}, {"k": 4}), _circulant,
               structured=True, deterministic=True,
               description="circulant_graph(n, range(1, k+1)); rho = k for n >= 2k+2"),
        Family("circulant_directed", ({"k": 2}, {"k": 3}, {"k": 4}, {"k": 5}),
               _circulant_directed, structured=True, deterministic=True,
               description="i receives from i-1..i-k"),
        Family("complete", ({},), _complete, structured=True, deterministic=True,
               description="K_n; rho = ceil(n/2), s* = n"),
        Family("ba", ({"m": 2}, {"m": 3}, {"m": 4}), _ba, structured=True,
               description="barabasi_albert_graph(n, m, initial_graph=K_{2m-1}); rho = m"),
        Family("growth_directed", ({"k": 2}, {"k": 3}, {"k": 4}), _growth_directed,
               structured=True,
               description="K_{2k-1} then each new node receives from k earlier nodes; rho = k"),
        Family("two_cliques", ({"b": 1}, {"b": 2}, {"b": 3}), _two_cliques, structured=True,
               description="two K_m joined by b disjoint perfect matchings (n = 2m); rho = b"),
        Family("geometric", ({"radius": 0.3}, {"radius": 0.5}), _geometric,
               description="random_geometric_graph(n, radius) in the unit square"),
        Family("watts_strogatz", ({"k": 6, "p": 0.1}, {"k": 6, "p": 0.3}), _watts_strogatz,
               description="watts_strogatz_graph(n, 6, p)"),
        Family("random_regular", ({"d": 4}, {"d": 8}), _random_regular,
               description="random_regular_graph(d, n)"),
    ]
}

#: Families with constructive certificates (BENCHMARKS.md: run to n = 1000).
STRUCTURED: tuple[str, ...] = tuple(name for name, f in FAMILIES.items() if f.structured)


def variant_label(params: dict[str, Any]) -> str:
    """Family parameters as ``"k=3,p=0.1"`` (without n, instance, seed)."""
    skip = {"n", "instance", "seed"}
    return ",".join(f"{k}={v}" for k, v in sorted(params.items()) if k not in skip)


def make_instance(name: str, variant: dict[str, Any], n: int, i: int) -> Instance | None:
    """Instance i of family ``name`` with parameters ``variant`` at requested size n."""
    fam = FAMILIES[name]
    seed = seed_for(n, i)
    out = fam.make(n, seed, dict(variant))
    if out is None:
        return None
    G, known = out
    params = dict(variant)
    params.update(n=G.number_of_nodes(), instance=i, seed=seed)
    return Instance(name, params, G, known)


def instances(
    names: Iterable[str] | None = None,
    sizes: Iterable[int] = (10, 15, 20, 25, 30),
    k: int = 10,
    variants: dict[str, list[dict[str, Any]]] | None = None,
) -> Iterator[Instance]:
    """Yield instances for every family in ``names`` (default: all), every variant,
    every size, ``k`` instances each (one for deterministic families).

    ``variants`` optionally overrides a family's parameter list.
    """
    names = list(FAMILIES) if names is None else list(names)
    unknown = [x for x in names if x not in FAMILIES]
    if unknown:
        raise KeyError(f"unknown families {unknown}; known: {sorted(FAMILIES)}")
    for name in names:
        fam = FAMILIES[name]
        vs = (variants or {}).get(name, list(fam.variants))
        for variant in vs:
            for n in sizes:
                for i in range(1 if fam.deterministic else k):
                    inst = make_instance(name, variant, n, i)
                    if inst is not None:
                        yield inst


def known_s_star(inst: Instance) -> int | None:
    """Closed-form s*(rho) where known: n for complete graphs."""
    G = inst.G
    n = G.number_of_nodes()
    m = sum(1 for u, v in G.edges() if u != v)
    full = n * (n - 1) if G.is_directed() else n * (n - 1) // 2
    return n if m == full else None
