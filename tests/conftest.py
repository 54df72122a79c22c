"""Shared fixtures and a brute-force robustness oracle (SPEC §1).

Convention: a DiGraph edge (u, v) means v receives u (u is an in-neighbour of v);
undirected edges count both ways; self-loops are ignored; parallel edges count once.

The oracle enumerates every pair of disjoint nonempty node sets literally (bitmasks),
so it is only for small graphs (n <= 8: 3^8 = 6561 ordered pairs).
"""

from __future__ import annotations

import math
from collections.abc import Hashable
from dataclasses import dataclass
from fractions import Fraction

import networkx as nx
import pytest


@dataclass(frozen=True)
class Oracle:
    """Brute-force facts about a graph: labels, in-neighbour bitmasks, rho, s*(r)."""

    nodes: tuple[Hashable, ...]
    inmask: tuple[int, ...]
    rho: int
    s_star: dict[int, int]  # r -> s*(r) for r in 0..ceil(n/2)+2 (0 when not r-robust)

    @property
    def n(self) -> int:
        return len(self.nodes)

    def index(self, labels) -> int:
        pos = {v: i for i, v in enumerate(self.nodes)}
        mask = 0
        for v in labels:
            mask |= 1 << pos[v]
        return mask

    def e(self, S: int) -> int:
        """e(S) = max_{i in S} |N(i) \\ S| (S a nonempty bitmask)."""
        return max(bin(self.inmask[i] & ~S).count("1") for i in range(self.n) if S >> i & 1)

    def reach(self, S: int, r: int) -> int:
        out = 0
        for i in range(self.n):
            if S >> i & 1 and bin(self.inmask[i] & ~S).count("1") >= r:
                out |= 1 << i
        return out

    def violates(self, S1: int, S2: int, r: int, s: int) -> bool:
        """(S1, S2) disjoint nonempty and violating (r, s)-robustness."""
        if not S1 or not S2 or S1 & S2:
            return False
        R1, R2 = self.reach(S1, r), self.reach(S2, r)
        return R1 != S1 and R2 != S2 and bin(R1).count("1") + bin(R2).count("1") < s

    def holds(self, r: int, s: int) -> bool:
        """Is the graph (r, s)-robust?"""
        return s <= self.s_star_of(r)

    def s_star_of(self, r: int) -> int:
        if r in self.s_star:
            return self.s_star[r]
        return 0 if r > self.rho else _s_star(self.inmask, r)


def in_masks(G: nx.Graph) -> tuple[tuple[Hashable, ...], tuple[int, ...]]:
    """Node labels (in G's order) and in-neighbour bitmasks, read straight from G."""
    nodes = tuple(G.nodes())
    pos = {v: i for i, v in enumerate(nodes)}
    masks = [0] * len(nodes)
    for u, v in G.edges():  # multigraphs: repeated edges OR into the same bit
        if u == v:
            continue
        masks[pos[v]] |= 1 << pos[u]
        if not G.is_directed():
            masks[pos[u]] |= 1 << pos[v]
    return nodes, tuple(masks)


def _pairs(n: int):
    """All ordered pairs (S1, S2) of disjoint nonempty bitmasks over n nodes."""
    full = (1 << n) - 1
    for S1 in range(1, full + 1):
        rest = full & ~S1
        S2 = rest
        while S2:
            yield S1, S2
            S2 = (S2 - 1) & rest


def _popcount(x: int) -> int:
    return bin(x).count("1")


def _rho(inmask: tuple[int, ...]) -> int:
    n = len(inmask)
    full = (1 << n) - 1
    e = [0] * (full + 1)
    for S in range(1, full + 1):
        e[S] = max(_popcount(inmask[i] & ~S) for i in range(n) if S >> i & 1)
    return min(max(e[S1], e[S2]) for S1, S2 in _pairs(n))


def _s_star(inmask: tuple[int, ...], r: int) -> int:
    """min |reach_r(S1)| + |reach_r(S2)| over pairs where neither set is fully
    r-reachable; n when there is no such pair. (Callers handle r > rho -> 0.)"""
    n = len(inmask)
    full = (1 << n) - 1
    cost = [0] * (full + 1)
    notfull = [False] * (full + 1)
    for S in range(1, full + 1):
        c = sum(1 for i in range(n) if S >> i & 1 and _popcount(inmask[i] & ~S) >= r)
        cost[S] = c
        notfull[S] = c < _popcount(S)
    best = n
    for S1, S2 in _pairs(n):
        if notfull[S1] and notfull[S2]:
            best = min(best, cost[S1] + cost[S2])
    return best


def oracle(G: nx.Graph) -> Oracle:
    """Brute-force rho(G) and s*(r) for r = 0..ceil(n/2)+2."""
    nodes, masks = in_masks(G)
    n = len(nodes)
    assert 2 <= n <= 9, "the oracle is exponential: small graphs only"
    rho = _rho(masks)
    s_star = {r: (0 if r > rho else _s_star(masks, r)) for r in range(math.ceil(n / 2) + 3)}
    return Oracle(nodes, masks, rho, s_star)


@pytest.fixture
def fresh_facts():
    """Decide each test's graphs afresh (graphs/facts.py caches proofs across calls)."""
    from rescon.graphs.facts import clear_cache

    clear_cache()


@pytest.fixture(scope="session")
def brute():
    """The brute-force oracle as a fixture: ``brute(G) -> Oracle``."""
    return oracle


# --------------------------------------------------------------------------- #
# a second, vectorised oracle for 9 <= n <= 16 (subset-minimum transforms)
# --------------------------------------------------------------------------- #


def _subset_min(values):
    """h[U] = min over subsets S of U of values[S] (in place on a copy)."""
    import numpy as np

    h = values.copy()
    n = int(h.shape[0]).bit_length() - 1
    for b in range(n):
        view = h.reshape(-1, 2, 1 << b)
        np.minimum(view[:, 1, :], view[:, 0, :], out=view[:, 1, :])
    return h


def fast_oracle(G: nx.Graph, rs=None) -> tuple[int, dict[int, int]]:
    """(rho, {r: s*(r)}) by the O(n 2^n) subset transforms, independent of rescon.

    rho = min over nonempty proper S1 of max(e(S1), min_{nonempty S2 ⊆ V\\S1} e(S2));
    s*(r) = min over open S1 (some member r-closed) of c(S1) + min_{open S2 ⊆ V\\S1} c(S2),
    c(S) = |reach_r(S)|; n when no two disjoint open sets exist; 0 when r > rho.
    """
    import numpy as np

    nodes, masks = in_masks(G)
    n = len(nodes)
    assert 2 <= n <= 18
    N = 1 << n
    full = N - 1
    S = np.arange(N, dtype=np.int64)
    pop = np.zeros(N, dtype=np.int64)
    for b in range(n):
        pop += (S >> b) & 1
    member = [((S >> i) & 1).astype(bool) for i in range(n)]
    outside = [pop[masks[i] & ~S & full] for i in range(n)]  # |N(i) \ S|
    big = 10 * n
    e = np.zeros(N, dtype=np.int64)
    for i in range(n):
        e = np.maximum(e, np.where(member[i], outside[i], 0))
    e_ne = np.where(S == 0, big, e)
    best = _subset_min(e_ne)
    S1 = S[1:full]
    rho = int(np.min(np.maximum(e[S1], best[full & ~S1])))
    if rs is None:
        rs = range(0, (n + 1) // 2 + 3)
    out = {}
    for r in rs:
        if r > rho:
            out[r] = 0
            continue
        c = np.zeros(N, dtype=np.int64)
        for i in range(n):
            c += member[i] & (outside[i] >= r)
        open_ = c < pop  # false for S = 0
        c_open = np.where(open_, c, big)
        h = _subset_min(c_open)
        tot = np.where(open_, c + h[full & ~S], big)
        m = int(tot.min())
        out[r] = n if m >= big else m
    return rho, out


# --------------------------------------------------------------------------- #
# checks straight from the graph, any n (no enumeration)
# --------------------------------------------------------------------------- #


def label_masks(G: nx.Graph, S1, S2) -> tuple[tuple[int, ...], int, int]:
    """In-neighbour bitmasks of G and the bitmasks of two label sets."""
    nodes, masks = in_masks(G)
    pos = {v: i for i, v in enumerate(nodes)}
    m1 = m2 = 0
    for v in S1:
        m1 |= 1 << pos[v]
    for v in S2:
        m2 |= 1 << pos[v]
    return masks, m1, m2


def _reach(masks, S: int, r: int) -> int:
    out = 0
    for i, mk in enumerate(masks):
        if S >> i & 1 and _popcount(mk & ~S) >= r:
            out |= 1 << i
    return out


def pair_violates(G: nx.Graph, S1, S2, r: int, s: int) -> bool:
    """Do the label sets S1, S2 form a disjoint nonempty pair violating (r, s)?"""
    S1, S2 = set(S1), set(S2)
    if not S1 or not S2 or S1 & S2 or not (S1 | S2) <= set(G.nodes()):
        return False
    masks, m1, m2 = label_masks(G, S1, S2)
    R1, R2 = _reach(masks, m1, r), _reach(masks, m2, r)
    return R1 != m1 and R2 != m2 and _popcount(R1) + _popcount(R2) < s


def cert_graph_matches(cert: dict, G: nx.Graph) -> bool:
    """The certificate's ``graph`` is G: same n, and (through ``nodes``, the labels)
    exactly G's edge set, self-loops dropped, undirected edges both ways."""
    g = cert["graph"]
    nodes, masks = in_masks(G)
    if g["n"] != len(nodes) or len(g.get("nodes", [])) != len(nodes):
        return False

    def js(v):
        return v if isinstance(v, (int, str)) and not isinstance(v, bool) else str(v)

    labels = [js(v) for v in nodes]
    if sorted(map(repr, labels)) != sorted(map(repr, g["nodes"])):
        return False
    idx = {repr(lab): k for k, lab in enumerate(g["nodes"])}
    expected = set()
    for i, mk in enumerate(masks):
        for j in range(len(nodes)):
            if mk >> j & 1:  # j -> i
                expected.add((idx[repr(labels[j])], idx[repr(labels[i])]))
    got = {tuple(e) for e in g["edges"]}
    return got == expected and len(got) == len(g["edges"])


def solve_exact(M, rhs):
    """The solution of M λ = rhs (Fractions, Gauss–Jordan) for M of full column rank;
    None if inconsistent or the columns are dependent. Independent of rescon: the
    review tests' brute-force oracles (hull membership, Tukey depth) use it."""
    rows, cols = len(M), len(M[0])
    # Fractions throughout: an int pivot row (the 1s of a convex combination) divided
    # by itself gave floats, and the answer was rounded or overflowed
    A = [[Fraction(v) for v in M[i]] + [Fraction(rhs[i])] for i in range(rows)]
    for c in range(cols):
        p = next((i for i in range(c, rows) if A[i][c]), None)
        if p is None:
            return None
        A[c], A[p] = A[p], A[c]
        A[c] = [x / A[c][c] for x in A[c]]
        for i in range(rows):
            if i != c and A[i][c]:
                f = A[i][c]
                A[i] = [x - f * y for x, y in zip(A[i], A[c])]
    if any(A[i][cols] for i in range(cols, rows)):
        return None
    return [A[i][cols] for i in range(cols)]


@pytest.fixture(scope="module")
def cluster():
    """The scheduler address of a LocalCluster of 2 worker processes on loopback,
    shared by the tests of one module."""
    from distributed import LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as local:
        yield local.scheduler_address
