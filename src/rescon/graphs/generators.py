"""Graphs of known robustness, for tests, benchmarks and examples.

Every generator stores the robustness :math:`\\rho(G)` (the largest r such that G
is r-robust, SPEC §1) in ``G.graph["rho"]``. Where a constructive ordering
exists it also stores ``G.graph["construction_order"]`` (a list of all nodes) and
``G.graph["seed_size"]`` = m: the first m nodes of the order induce a complete
graph with :math:`m \\ge 2\\rho - 1` (so the seed is ρ-robust, as
:math:`K_m` is :math:`\\lceil m/2 \\rceil`-robust) and every later node has at
least ρ in-neighbours among the nodes before it. Adding such a node preserves
ρ-robustness, so the ordering is a positive certificate (certificates/FORMAT.md,
proof method ``construction``).

Every formula is checked against an exhaustive search in tests/test_generators.py
(circulants: every k for n ≤ 15; growth generators: n ≤ 12; two cliques: m ≤ 6);
the Notes give a proof where one is known.
"""

from __future__ import annotations

import math
from typing import Any

import networkx as nx
import numpy as np

from .._validate import flag, integer
from ..errors import InputError

__all__ = ["ba_robust", "circulant", "directed_growth", "two_cliques"]

Seed = int | np.random.Generator | None


def ba_robust(n: int, m: int, *, seed: Seed = None) -> nx.Graph:
    """Barabási–Albert graph grown from :math:`K_{2m-1}`; ρ = m.

    Start from the complete graph on nodes ``0..s-1``, :math:`s = \\max(2, 2m - 1)`
    (:math:`K_2` for m = 1: preferential attachment needs a seed with edges);
    each new node ``v = s, ..., n-1`` attaches to m distinct earlier nodes chosen with
    probability proportional to their degree (``networkx.barabasi_albert_graph``
    with ``initial_graph=complete_graph(s)``).

    Parameters
    ----------
    n : int
        Number of nodes, :math:`n \\ge \\max(2, 2m - 1)`.
    m : int
        Edges per new node, m ≥ 1.
    seed : int or numpy.random.Generator, optional
        Source of randomness.

    Returns
    -------
    networkx.Graph
        Undirected, nodes ``0..n-1``; ``G.graph["rho"] = m``, construction order
        ``0..n-1`` with seed size s.

    Raises
    ------
    InputError
        n or m is not an integer in range, or seed is not an int or Generator.

    Notes
    -----
    ρ = m for every valid n: :math:`K_s` is m-robust and each new node has m
    earlier neighbours (lower bound); for n > s the last node has degree m, and for
    :math:`\\rho \\ge 2` ρ is at most the minimum degree, while a tree (m = 1)
    is not 2-robust (upper bound). The default networkx seed, a star, is *not*
    m-robust.
    """
    m = integer("m", m, low=1)
    size = max(2, 2 * m - 1)
    n = integer("n", n, low=size)
    G = nx.barabasi_albert_graph(n, m, seed=_rng(seed), initial_graph=nx.complete_graph(size))
    return _annotate(G, rho=m, order=list(range(n)), seed_size=size)


def directed_growth(n: int, k: int, *, seed: Seed = None) -> nx.DiGraph:
    """Directed growth from the complete digraph :math:`K_{2k-1}`; ρ = k.

    Nodes ``0..2k-2`` form a complete digraph; each new node
    ``v = 2k-1, ..., n-1`` receives from k distinct earlier nodes chosen
    uniformly at random (edges :math:`u \\to v`, u < v).

    Parameters
    ----------
    n : int
        Number of nodes, :math:`n \\ge \\max(2, 2k - 1)`.
    k : int
        In-neighbours per new node, k ≥ 1.
    seed : int or numpy.random.Generator, optional
        Source of randomness.

    Returns
    -------
    networkx.DiGraph
        ``G.graph["rho"] = k``, construction order ``0..n-1`` with seed size 2k − 1.

    Raises
    ------
    InputError
        n or k is not an integer in range, or seed is not an int or Generator.

    Notes
    -----
    ρ = k for every valid n: the construction gives ρ ≥ k; the last node v has
    in-degree k and no out-edges, so the pair ({v}, V \\ {v}) has
    max(e(S1), e(S2)) = max(k, 0) = k.
    """
    k = integer("k", k, low=1)
    n = integer("n", n, low=max(2, 2 * k - 1))
    rng = _rng(seed)
    G = nx.complete_graph(2 * k - 1, create_using=nx.DiGraph)
    for v in range(2 * k - 1, n):
        G.add_edges_from((int(u), v) for u in rng.choice(v, size=k, replace=False))
    return _annotate(G, rho=k, order=list(range(n)), seed_size=2 * k - 1)


def circulant(n: int, k: int, *, directed: bool = False) -> nx.Graph:
    """Circulant graph on nodes ``0..n-1`` where i receives from i − 1, ..., i − k (mod n).

    Undirected (``directed=False``): ``networkx.circulant_graph(n, range(1, k + 1))``,
    the ring lattice where i is adjacent to :math:`i \\pm 1, \\dots, i \\pm k`:

    .. math::
        \\rho = k \\text{ if } n \\ge 2k + 2, \\qquad
        \\rho = \\lceil n/2 \\rceil \\text{ if } n \\le 2k + 1 \\text{ (then } G = K_n).

    Directed: edges :math:`(i - s) \\bmod n \\to i`, s = 1..k:

    .. math::
        \\rho = \\lceil k/2 \\rceil \\text{ (k odd)}, \\qquad
        \\rho = k/2 + (n \\bmod 2) \\text{ (k even)}, \\qquad \\text{for all } n \\ge k + 1.

    Parameters
    ----------
    n : int
        Number of nodes, n ≥ 2.
    k : int
        Offsets 1..k, :math:`1 \\le k \\le n - 1` (k = n − 1 gives the complete graph).
    directed : bool, default False
        Directed circulant instead of the undirected ring lattice.

    Returns
    -------
    networkx.Graph or networkx.DiGraph
        With ``G.graph["rho"]``. A construction order (``0..n-1``) is stored
        when one exists with a complete seed: G complete (seed size n), or
        undirected with k ≤ 2 (seed {0, ..., k}, a clique of size k + 1 ≥ 2k − 1;
        node i > k has in-neighbours i − 1, ..., i − k before it).

    Raises
    ------
    InputError
        n or k is not an integer in range.

    Notes
    -----
    Both formulas were verified by exhaustive search for all n ≤ 18 (undirected:
    k ≤ 6; directed: k ≤ 8). The parity dependence of the directed case is
    real: for k = 2 the directed circulant is 1-robust for even n and 2-robust for
    odd n. At n = k + 1 the directed formula gives :math:`\\lceil n/2 \\rceil`, the
    value of the complete digraph.
    """
    n = integer("n", n, low=2)
    k = integer("k", k, low=1)
    directed = flag("directed", directed)
    if k > n - 1:
        raise InputError(f"k must be an integer with 1 <= k <= n - 1 = {n - 1}; got k={k}")
    complete = k >= n // 2 if not directed else k == n - 1
    order = list(range(n))
    if directed:
        G: nx.Graph = nx.DiGraph()
        G.add_nodes_from(order)
        G.add_edges_from(((i - s) % n, i) for i in order for s in range(1, k + 1))
        rho = (k + 1) // 2 if k % 2 else k // 2 + n % 2
    else:
        G = nx.circulant_graph(n, range(1, k + 1))
        rho = k if n >= 2 * k + 2 else math.ceil(n / 2)
    if complete:
        return _annotate(G, rho=rho, order=order, seed_size=n)
    if not directed and k <= 2:
        return _annotate(G, rho=rho, order=order, seed_size=k + 1)
    return _annotate(G, rho=rho)


def two_cliques(m: int, b: int, *, seed: Seed = None) -> nx.Graph:
    """Two copies of :math:`K_m` joined by b disjoint perfect matchings; ρ = b.

    Clique A is ``0..m-1``, clique B is ``m..2m-1``. With a random permutation π
    of ``0..m-1`` and b distinct random shifts :math:`t_1, \\dots, t_b`, matching
    l joins i to :math:`m + \\pi((i + t_l) \\bmod m)`.

    Parameters
    ----------
    m : int
        Clique size, m ≥ 1.
    b : int
        Number of matchings, :math:`0 \\le b \\le m` (b = m gives :math:`K_{2m}`).
    seed : int or numpy.random.Generator, optional
        Source of randomness.

    Returns
    -------
    networkx.Graph
        ``G.graph["rho"] = b``. A construction order ``0..2m-1`` is stored when
        :math:`1 \\le b` and :math:`m \\ge 2b - 1` (seed: the first 2b − 1 nodes
        of A) or b = m (G complete, seed size 2m).

    Raises
    ------
    InputError
        m or b is not an integer in range, or seed is not an int or Generator.

    Notes
    -----
    ρ = b for all :math:`0 \\le b \\le m`, although the minimum degree is
    m − 1 + b. Upper bound: in the pair (A, B) every node has exactly b
    neighbours outside its set. Lower bound (for any b-regular bipartite join):
    a set inside one clique has a node with at least b outside neighbours. If
    both sets of a pair met both cliques with e(S1), e(S2) ≤ b − 1, write
    :math:`P_k = S_k \\cap A`, :math:`Q_k = S_k \\cap B`; a node of :math:`P_2`
    has :math:`|A \\setminus P_2| \\ge |P_1|` outside neighbours in A, so at least
    :math:`|P_1| + 1` matched neighbours in :math:`Q_2`, hence
    :math:`|B \\setminus Q_1| \\ge |P_1| + 1`; then a node of :math:`Q_1` needs
    :math:`|B \\setminus Q_1| + 1 \\ge |P_1| + 2` matched neighbours in
    :math:`P_1`, impossible. Brute force confirms it for m ≤ 8.
    """
    m = integer("m", m, low=1)
    b = integer("b", b, low=0)
    if b > m:
        raise InputError(f"b must be an integer with 0 <= b <= m = {m}; got b={b}")
    rng = _rng(seed)
    G = nx.Graph()
    G.add_nodes_from(range(2 * m))
    for X in (range(m), range(m, 2 * m)):
        G.add_edges_from((i, j) for i in X for j in X if i < j)
    perm = rng.permutation(m)
    for t in rng.choice(m, size=b, replace=False):
        G.add_edges_from((i, m + int(perm[(i + t) % m])) for i in range(m))
    order = list(range(2 * m))
    if b == m:
        return _annotate(G, rho=b, order=order, seed_size=2 * m)
    if b >= 1 and m >= 2 * b - 1:
        return _annotate(G, rho=b, order=order, seed_size=2 * b - 1)
    return _annotate(G, rho=b)


def _annotate(G: Any, *, rho: int, order: list[int] | None = None,
              seed_size: int | None = None) -> Any:
    G.graph["rho"] = rho
    if order is not None:
        G.graph["construction_order"] = order
        G.graph["seed_size"] = seed_size
    return G


def _rng(seed: Any) -> np.random.Generator:
    if isinstance(seed, np.random.Generator):
        return seed
    if seed is None:
        return np.random.default_rng()
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise InputError(
            f"seed must be None, a nonnegative int or a numpy.random.Generator; got {seed!r}"
        )
    return np.random.default_rng(int(seed))
