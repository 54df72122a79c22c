"""Normalise a networkx graph into the indexed form every robustness routine uses.

Convention (SPEC §1): a DiGraph edge ``(u, v)`` means **v receives u's state**, so
u is an in-neighbour of v. Undirected graphs count both ways; self-loops are ignored;
parallel edges of a multigraph count once.
"""

from __future__ import annotations

import itertools
from collections.abc import Hashable
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import networkx as nx
import numpy as np

from .._validate import flag
from ..errors import InputError

__all__ = ["IndexedGraph", "index_graph"]


@dataclass(frozen=True)
class IndexedGraph:
    """A graph on nodes ``0..n-1`` with in-neighbour sets.

    Attributes
    ----------
    nodes : tuple
        The user's node labels; index i stands for ``nodes[i]``.
    in_nbrs : tuple of frozenset of int
        ``in_nbrs[i]`` = indices of the in-neighbours of i (no self-loops).
    """

    nodes: tuple[Hashable, ...]
    in_nbrs: tuple[frozenset[int], ...]

    @property
    def n(self) -> int:
        return len(self.nodes)

    @cached_property
    def in_degrees(self) -> tuple[int, ...]:
        """In-degrees, computed once (the bounds read them per node and per r)."""
        return tuple(len(s) for s in self.in_nbrs)

    def edge_arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """The edges u → v as two int64 arrays (U, V), grouped by v."""
        count = sum(self.in_degrees)
        U = np.fromiter(itertools.chain.from_iterable(self.in_nbrs), dtype=np.int64,
                        count=count)
        V = np.repeat(np.arange(self.n, dtype=np.int64), self.in_degrees)
        return U, V

    def in_masks(self) -> list[int]:
        """In-neighbour sets as Python-int bitmasks (bit j set iff j → i)."""
        return [sum(1 << j for j in s) for s in self.in_nbrs]

    def edges(self) -> list[list[int]]:
        """Edges ``[u, v]`` (u → v) in index form, sorted."""
        U, V = self.edge_arrays()
        order = np.lexsort((V, U))
        return np.column_stack((U[order], V[order])).tolist()

    def labels(self, indices: Any) -> list[Hashable]:
        """Map node indices back to the user's labels (sorted by index)."""
        return [self.nodes[i] for i in sorted(indices)]

    def graph_json(self) -> dict[str, Any]:
        """The ``graph`` object of a certificate (certificates/FORMAT.md)."""
        return {"n": self.n, "nodes": [_json_label(v) for v in self.nodes], "edges": self.edges()}

    def induced(self, order: list[int]) -> IndexedGraph:
        """Subgraph induced on ``order``, re-indexed so that ``order[j]`` becomes j."""
        pos = {v: j for j, v in enumerate(order)}
        return IndexedGraph(
            nodes=tuple(self.nodes[v] for v in order),
            in_nbrs=tuple(frozenset(pos[u] for u in self.in_nbrs[v] if u in pos) for v in order),
        )


def _json_label(label: Hashable) -> Any:
    if isinstance(label, bool) or not isinstance(label, (int, str)):
        return str(label)
    return label


def index_graph(G: Any, *, undirected: bool | None = None, min_nodes: int = 2) -> IndexedGraph:
    """Validate ``G`` and return its :class:`IndexedGraph`.

    Parameters
    ----------
    G : networkx.Graph or networkx.DiGraph (multigraphs allowed)
        Edge ``(u, v)`` of a DiGraph: v receives u. Undirected edges count both ways.
    undirected : bool, optional
        Force treating a DiGraph's edges as undirected (both directions). True, False
        or None only ("no", 0, 1 … are refused, not read by their truth value).
    min_nodes : int
        Fewer nodes raise :class:`InputError` (robustness needs a pair of disjoint
        nonempty sets, so at least 2 nodes).

    Raises
    ------
    InputError
        ``G`` is not a networkx graph, has fewer than ``min_nodes`` nodes, or
        ``undirected`` is not True, False or None.
    """
    undirected = None if undirected is None else flag("undirected", undirected)
    if not isinstance(G, nx.Graph):
        raise InputError(f"G must be a networkx Graph or DiGraph; got {type(G).__name__}")
    n = G.number_of_nodes()
    if n < min_nodes:
        raise InputError(
            f"G must have at least {min_nodes} nodes for this question; got {n}"
        )
    nodes = tuple(G.nodes())
    pos = {v: i for i, v in enumerate(nodes)}
    both = undirected or not G.is_directed()
    in_sets: list[set[int]] = [set() for _ in range(n)]
    for u, v in G.edges():
        if u == v:
            continue
        in_sets[pos[v]].add(pos[u])
        if both:
            in_sets[pos[u]].add(pos[v])
    return IndexedGraph(nodes=nodes, in_nbrs=tuple(frozenset(s) for s in in_sets))
