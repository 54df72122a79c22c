"""Polynomial-time bounds on ρ(G) and s*(r), each with its proof object.

Upper bounds are witness pairs (S1, S2): max(e(S1), e(S2)) = m shows G is not
(m+1)-robust, where e(S) = max_{i∈S} |N(i) \\ S|. Lower bounds are proofs in the
format of certificates/FORMAT.md:

* ``degree``: min in-degree ≥ ⌊n/2⌋ + r − 1 ⇒ (r, s)-robust for every s;
* ``complete``: K_n is (r, s)-robust for every s when n ≥ 2r − 1;
* ``construction``: an ordering from a certified seed in which every later node has
  ≥ r + s − 1 in-neighbours among the earlier ones (adding such a node preserves
  (r, s)-robustness);
* ``implied``: (r', s')-robust ⇒ (r, s)-robust when r' ≥ r and s' ≥ s, or when
  r' ≥ r + s − 1 (for s' ≥ 1);
* ``spectral`` (undirected): ρ ≥ ⌈λ2/2⌉, with a rational c < λ2 checked exactly.
"""

from __future__ import annotations

import random
import time
from collections.abc import Iterable
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import networkx as nx
import numpy as np

from .indexed import IndexedGraph

__all__ = [
    "Pair",
    "pair_value",
    "pair_cost",
    "descend_pair",
    "descended_pairs",
    "tabu_pairs",
    "probed_pairs",
    "compiled_walk",
    "violates",
    "upper_witness",
    "source_components_witness",
    "degree_r",
    "is_complete",
    "construction_proof",
    "best_construction",
    "greedy_cliques",
    "greedy_order",
    "s_candidates",
    "closure_order",
    "is_undirected",
    "spectral_r",
]

Proof = dict[str, Any]


@dataclass(frozen=True)
class Pair:
    """A pair of disjoint nonempty node-index sets."""

    S1: frozenset[int]
    S2: frozenset[int]

    def to_json(self) -> dict[str, list[int]]:
        return {"S1": sorted(self.S1), "S2": sorted(self.S2)}


def _outside(ig: IndexedGraph, S: frozenset[int]) -> list[int]:
    return [len(ig.in_nbrs[i] - S) for i in S]


def pair_value(ig: IndexedGraph, pair: Pair) -> int:
    """max(e(S1), e(S2)): the pair shows G is not (value + 1)-robust."""
    return max(max(_outside(ig, pair.S1)), max(_outside(ig, pair.S2)))


def pair_cost(ig: IndexedGraph, pair: Pair, r: int) -> int | None:
    """|reach_r(S1)| + |reach_r(S2)| when neither set is fully r-reachable, else None.

    A pair with cost c violates (r, s) for every s > c, so s*(r) ≤ c.
    """
    total = 0
    for S in (pair.S1, pair.S2):
        reach = sum(1 for c in _outside(ig, S) if c >= r)
        if reach == len(S):
            return None
        total += reach
    return total


def violates(ig: IndexedGraph, pair: Pair, r: int, s: int) -> bool:
    """True when the pair violates (r, s)-robustness."""
    cost = pair_cost(ig, pair, r)
    return cost is not None and cost < s


def source_components_witness(ig: IndexedGraph) -> Pair | None:
    """Two source strongly connected components, if G has them (then ρ = 0).

    G is 1-robust iff it has exactly one source SCC: a source SCC has no in-edge
    from outside, so two of them form a pair of closed sets.
    """
    D = nx.DiGraph()
    D.add_nodes_from(range(ig.n))
    D.add_edges_from((u, v) for v, s in enumerate(ig.in_nbrs) for u in s)
    C = nx.condensation(D)
    sources = [c for c in C.nodes if C.in_degree(c) == 0]
    if len(sources) < 2:
        return None
    members = C.graph["mapping"]
    comp: dict[int, set[int]] = {}
    for v, c in members.items():
        comp.setdefault(c, set()).add(v)
    return Pair(frozenset(comp[sources[0]]), frozenset(comp[sources[1]]))


@lru_cache(maxsize=8)
def _out_lists(ig: IndexedGraph) -> list[list[int]]:
    """Out-neighbour lists (``out[u]``: the nodes u sends to), built once per graph —
    O(|E|) Python, 0.2 s at n = 800, p = 0.5, which the bounds ask for once per r
    (V33: a 0.05-s limit took seconds). Shared between callers: read only."""
    out: list[list[int]] = [[] for _ in range(ig.n)]
    for v, s in enumerate(ig.in_nbrs):
        for u in s:
            out[u].append(v)
    return out


def greedy_order(ig: IndexedGraph, start: int) -> list[int]:
    """All nodes, from ``start``, each step absorbing the outside node with the most
    in-neighbours already absorbed (ties: lowest index). Its prefixes are compact
    sets (good witness candidates) and it is the natural construction order."""
    n = ig.n
    out = _out_lists(ig)
    absorbed = np.zeros(n, dtype=bool)
    cnt = np.zeros(n, dtype=np.int64)
    order = []
    u = start
    for _ in range(n):
        absorbed[u] = True
        order.append(u)
        cnt[out[u]] += 1
        if len(order) < n:
            u = int(np.where(absorbed, -1, cnt).argmax())
    return order


def _prefix_stats(ig: IndexedGraph, order: list[int], r: int | None):
    """For each proper prefix S of ``order``: (size, e(S), e(V \\ S), cost_r) where
    cost_r = |reach_r(S)| + |reach_r(V \\ S)| if both keep a closed member, else -1."""
    n = ig.n
    deg = np.array(ig.in_degrees, dtype=np.int64)
    out = _out_lists(ig)
    in_S = np.zeros(n, dtype=bool)
    cnt = np.zeros(n, dtype=np.int64)  # |N(j) ∩ S|
    for size, u in enumerate(order[:-1], start=1):
        in_S[u] = True
        cnt[out[u]] += 1
        inside_out = (deg - cnt)[in_S]  # |N(i) \ S| for i in S
        comp_out = cnt[~in_S]  # |N(j) ∩ S| = |N(j) \ (V \ S)| for j outside
        cost = -1
        if r is not None:
            c1 = int((inside_out >= r).sum())
            c2 = int((comp_out >= r).sum())
            if c1 < size and c2 < n - size:
                cost = c1 + c2
        yield size, int(inside_out.max()), int(comp_out.max()), cost


def _growth_pairs(ig: IndexedGraph, starts: Iterable[int]) -> Iterable[tuple[int, Pair]]:
    """Best bipartition (S, V \\ S) along the greedy order of each start."""
    full = frozenset(range(ig.n))
    for v in starts:
        order = greedy_order(ig, v)
        value, size = min((max(e1, e2), size) for size, e1, e2, _ in _prefix_stats(ig, order, None))
        S = frozenset(order[:size])
        yield value, Pair(S, full - S)


def s_candidates(ig: IndexedGraph, r: int, *, starts: int | None = None) -> list[Pair]:
    """Pairs whose sets both keep an r-closed member, cheapest first (s*(r) ≤ cost):
    bipartitions along greedy orders, and each low-degree node v with one
    in-neighbour against the rest (v stays closed when d_v ≤ r)."""
    n = ig.n
    if starts is None:
        starts = 12 if n <= 200 else 4
    full = frozenset(range(n))
    deg = ig.in_degrees
    found: dict[Pair, int] = {}
    by_degree = sorted(range(n), key=lambda i: (deg[i], i))
    for v in by_degree[:starts]:
        order = greedy_order(ig, v)
        best = min(((cost, size) for size, _, _, cost in _prefix_stats(ig, order, r) if cost >= 0),
                   default=None)
        if best is not None:
            S = frozenset(order[: best[1]])
            found[Pair(S, full - S)] = best[0]
        for u in sorted(ig.in_nbrs[v])[:4]:
            S = frozenset((v, u))
            pair = Pair(S, full - S)
            cost = pair_cost(ig, pair, r)
            if cost is not None:
                found[pair] = cost
    return sorted(found, key=lambda p: (found[p], len(p.S1)))


def _mask_cost(inmask: list[int], S: int, r: int) -> int | None:
    """|reach_r(S)| for a bitmask S, or None when S is empty or fully r-reachable."""
    reach = size = 0
    rest = S
    while rest:
        low = rest & -rest
        rest ^= low
        size += 1
        reach += (inmask[low.bit_length() - 1] & ~S).bit_count() >= r
    return reach if reach < size else None


def _masks_cost(inmask: list[int], A: int, B: int, r: int) -> int | None:
    """The pair cost (as :func:`pair_cost`) of bitmasks A, B (None if not a valid pair)."""
    a = _mask_cost(inmask, A, r)
    b = None if a is None else _mask_cost(inmask, B, r)
    return None if b is None else a + b


def descend_pair(ig: IndexedGraph, r: int, A: int, B: int) -> tuple[int, int, int] | None:
    """Steepest descent on the pair cost from bitmasks (A, B): each step moves one node
    into A, into B or out of both, taking the cheapest strictly improving move.
    Returns (cost, A, B) at a local minimum, or None when (A, B) is not a valid pair."""
    return _descend(ig.in_masks(), r, A, B)


def _descend(inmask: list[int], r: int, A: int, B: int) -> tuple[int, int, int] | None:
    """:func:`descend_pair` on in-neighbour bitmasks."""
    cur = _masks_cost(inmask, A, B, r)
    if cur is None:
        return None
    while True:
        best = (cur, A, B)
        for v in range(len(inmask)):
            bit = 1 << v
            a0, b0 = A & ~bit, B & ~bit
            for a, b in ((a0 | bit, b0), (a0, b0 | bit), (a0, b0)):
                c = _masks_cost(inmask, a, b, r)
                if c is not None and c < best[0]:
                    best = (c, a, b)
        if best[0] == cur:
            return cur, A, B
        cur, A, B = best


def descended_pairs(ig: IndexedGraph, r: int, *, starts: int = 40, seed: int = 0,
                    deadline: float | None = None) -> list[Pair]:
    """Local minima of the pair cost (:func:`descend_pair`) from ``starts`` random
    bisections that are valid pairs (seeded, so reproducible; at most 50·``starts``
    draws), stopping at ``deadline`` (perf_counter); every returned pair's cost bounds
    s*(r) from above."""
    rng = random.Random(seed)
    full = (1 << ig.n) - 1
    inmask = ig.in_masks()
    found: list[Pair] = []
    for _ in range(50 * starts):
        if len(found) == starts or (deadline is not None and time.perf_counter() > deadline):
            break
        A = rng.getrandbits(ig.n) & full
        out = _descend(inmask, r, A, full ^ A)
        if out is not None:
            found.append(Pair(_set(out[1]), _set(out[2])))
    return found


TABU_MOVES = 300  # moves per tabu walk
TABU_TENURE = 7  # a moved node stays put for this many moves (plus 0-2 at random)
TABU_PATIENCE = 16  # draws in a row without a cheaper pair end the search


def tabu_pairs(ig: IndexedGraph, r: int, *, floor: int = 0, below: int | None = None,
               seed: int = 0, deadline: float | None = None,
               draws: int | None = None) -> list[Pair]:
    """Pairs found by tabu walks (``_kernels.pair_walk``, compiled), each from a random
    bisection: a walk moves one node at a time into S1, into S2 or out of both, down
    the members' total excess of outside in-neighbours, and keeps the cheapest valid
    pair it visits. Unlike plain descent on the cost it crosses the cost's plateaus
    (on ER(25, 0.8) it reaches the cost-2 optimum where descent stops at 4; on
    ER(40, 0.8), r = 17, the cost-5 optimum where descents stop at 10).
    Returns each improvement on the best cost so far (from ``below``, a known upper
    bound; default n + 1), cheapest last. Stops at ``deadline``, after ``draws``
    walks (one of the two must be given; seeded, so reproducible when only ``draws``
    is), on reaching cost ``floor`` (a proven lower bound, or 0: a pair of cost 0
    refutes r-robustness) or after ``TABU_PATIENCE`` walks in a row without a cheaper
    pair. Every returned pair's cost bounds s*(r) from above. Past ``deadline`` from the
    start: none, and nothing compiled (a cold compile takes ~1 s)."""
    if deadline is None and draws is None:
        raise ValueError("tabu_pairs needs a deadline or a number of draws")
    if deadline is not None and time.perf_counter() >= deadline:
        return []
    pair_walk = compiled_walk()
    rng = random.Random(seed)
    out = _out_lists(ig)
    outptr = np.cumsum([0] + [len(o) for o in out], dtype=np.int64)
    outidx = np.array([w for o in out for w in o], dtype=np.int64)
    deg = np.array(ig.in_degrees, dtype=np.int64)
    found: list[Pair] = []
    best, done, stale = ig.n + 1 if below is None else below, 0, 0
    while best > floor and stale < TABU_PATIENCE and (draws is None or done < draws) and (
            deadline is None or time.perf_counter() < deadline):
        lab = np.array([1 + rng.getrandbits(1) for _ in range(ig.n)], dtype=np.int8)
        cost = int(pair_walk(deg, outptr, outidx, r, lab, TABU_MOVES, TABU_TENURE, floor,
                             rng.getrandbits(31)))
        done += 1
        stale += 1
        if cost < best:
            best, stale = cost, 0
            found.append(Pair(frozenset(np.flatnonzero(lab == 1).tolist()),
                              frozenset(np.flatnonzero(lab == 2).tolist())))
    return found


PROBE_STATES = 2_000_000  # states per size combination probed (probed_pairs)


def probed_pairs(ig: IndexedGraph, r: int, *, floor: int, below: int,
                 deadline: float) -> list[Pair]:
    """Pairs found by the exact sized search (``_kernels.min_cost_sized_step``, no tree)
    run on the near-bisections alone: at root 0 (order[0] ∈ S1, nothing excluded) with
    |S1| + |S2| = n, then n − 1, the most even sizes first, each for at most
    ``PROBE_STATES`` states, below the best cost so far (from ``below``) and until cost
    ``floor`` (a proven lower bound) or ``deadline``. On dense graphs the cheapest pairs
    are near-bisections, which the full search meets only after every less even size
    (ER(50, 0.8), seed 50001, r = 21: the cost-1 pair at sizes (24, 26) after 1.9M
    states here, 114M in the full search; the tabu walks stop at cost 2). Heuristic:
    each returned pair's cost (checked) bounds s*(r) from above; cheapest last. n ≤ 64."""
    from . import _kernels as K
    from .search import _CostRun, _kernel_inputs

    n = ig.n
    _, inmask, _, order = _kernel_inputs(ig)
    mmask, mout = K.non_in_masks(inmask)
    sizes = [(a, total - a) for total in (n, n - 1) for a in sorted(
        range(1, total), key=lambda a: (abs(2 * a - total), -a))]
    found: list[Pair] = []
    best = below
    for s1, s2 in sizes:
        if best <= floor or time.perf_counter() > deadline:
            break
        run = _CostRun(K, n, (1, n), best)
        state = run.state
        state[K.CS_ROOT], state[K.CS_S1], state[K.CS_S2], state[K.CS_ALONE] = 1, s1, s2, 1
        run.stack[0, 0], state[K.CS_SP] = np.uint64(1) << np.uint64(order[0]), 1
        while (state[K.CS_STATUS] == K.RUNNING and state[K.CS_NODES] < PROBE_STATES
               and time.perf_counter() < deadline):
            K.min_cost_sized_step(inmask, mmask, mout, order, r, floor, run.stack, run.depth,
                                  state, run.ubuf, 20_000, run.progress, _NO_TOKENS, False)
        if state[K.CS_BEST] < best:
            pair = Pair(_set(int(run.ubuf[K.CB_W1])), _set(int(run.ubuf[K.CB_W2])))
            cost = pair_cost(ig, pair, r)
            if cost is None or cost != state[K.CS_BEST]:
                raise RuntimeError(f"internal error: the sized search's pair costs {cost}, "
                                   f"not {state[K.CS_BEST]}")
            best = cost
            found.append(pair)
    return found


_NO_TOKENS = np.empty(1, dtype=np.int32)


@lru_cache(maxsize=1)
def compiled_walk() -> Any:
    """``_kernels.pair_walk``, compiled (or loaded from numba's cache) by one walk on a
    2-node graph: a caller that gives the walks a time budget calls this before its clock
    starts, so the first walk of a process does not spend the budget compiling (a cold
    process: ~3 s, over the 1 s the ρ race's witness walks get)."""
    from ._kernels import pair_walk  # numba: imported on first use

    one = np.ones(2, dtype=np.int64)
    pair_walk(one, np.arange(3, dtype=np.int64), np.array([1, 0], dtype=np.int64), 1,
              np.array([1, 2], dtype=np.int8), 1, 1, 0, 0)
    return pair_walk


def _set(mask: int) -> frozenset[int]:
    return frozenset(i for i in range(mask.bit_length()) if (mask >> i) & 1)


def upper_witness(ig: IndexedGraph, *, starts: int | None = None) -> tuple[int, Pair]:
    """The best witness pair found by cheap heuristics: (value, pair), ρ ≤ value.

    Candidates: two source SCCs (value 0); the minimum in-degree node against the
    rest; greedy growths from the lowest-degree nodes (``starts`` of them; default
    24, or 6 when n > 200: each growth costs O(n²)).
    """
    n = ig.n
    if starts is None:
        starts = 24 if n <= 200 else 6
    src = source_components_witness(ig)
    if src is not None:
        return 0, src
    deg = ig.in_degrees
    v = min(range(n), key=lambda i: (deg[i], i))
    best_pair = Pair(frozenset([v]), frozenset(range(n)) - {v})
    best = pair_value(ig, best_pair)
    by_degree = sorted(range(n), key=lambda i: (deg[i], i))
    for value, pair in _growth_pairs(ig, by_degree[:starts]):
        if value < best:
            best, best_pair = value, pair
    return best, best_pair


def degree_r(ig: IndexedGraph) -> int:
    """Largest r that the degree bound proves: min in-degree − ⌊n/2⌋ + 1 (may be ≤ 0)."""
    return min(ig.in_degrees) - ig.n // 2 + 1


def is_complete(ig: IndexedGraph) -> bool:
    return all(len(s) == ig.n - 1 for s in ig.in_nbrs)


def greedy_cliques(ig: IndexedGraph, *, limit: int = 32) -> list[list[int]]:
    """Cliques of the mutual graph (u → v and v → u), grown greedily from up to
    ``limit`` high-degree nodes; largest first. Seeds for construction proofs."""
    n = ig.n
    masks = ig.in_masks()
    out_masks = [0] * n
    for v, s in enumerate(ig.in_nbrs):
        for u in s:
            out_masks[u] |= 1 << v
    mutual = [masks[i] & out_masks[i] for i in range(n)]
    starts = sorted(range(n), key=lambda i: -mutual[i].bit_count())[:limit]
    seen = set()
    cliques = []
    for v in starts:
        clique = [v]
        cand = mutual[v]
        while cand:
            best_u, best_c = -1, -1
            c = cand
            while c:
                low = c & -c
                u = low.bit_length() - 1
                c ^= low
                k = (mutual[u] & cand).bit_count()
                if k > best_c:
                    best_u, best_c = u, k
            clique.append(best_u)
            cand &= mutual[best_u]
        key = frozenset(clique)
        if key not in seen:
            seen.add(key)
            cliques.append(sorted(clique))
    cliques.sort(key=len, reverse=True)
    return cliques


def closure_order(ig: IndexedGraph, seed: list[int], threshold: int, *,
                  out: list[list[int]] | None = None) -> list[int] | None:
    """Order extending ``seed`` in which every later node has ≥ threshold in-neighbours
    among the earlier ones, or None if some node can never be added. The closure is
    unique (adding nodes only raises counts), so greedy is exact; an order for
    ``threshold`` is one for every lower threshold. O(|E|) (``out``: the out-neighbour
    lists, when the caller has them)."""
    n = ig.n
    if out is None:
        out = _out_lists(ig)
    placed = [False] * n
    count = [0] * n
    order = list(seed)
    for v in seed:
        placed[v] = True
    for v in seed:
        for w in out[v]:
            count[w] += 1
    ready = [w for w in range(n) if not placed[w] and count[w] >= threshold]
    queued = set(ready)
    while ready:
        v = ready.pop()
        placed[v] = True
        order.append(v)
        for w in out[v]:
            count[w] += 1
            if not placed[w] and w not in queued and count[w] >= threshold:
                ready.append(w)
                queued.add(w)
    return order if len(order) == n else None


def construction_proof(
    ig: IndexedGraph, r: int, s: int, *, seeds: list[list[int]] | None = None
) -> Proof | None:
    """A ``construction`` proof of (r, s)-robustness from a complete seed, or None.

    Tries each clique of size ≥ 2r − 1 (K_m with m ≥ 2r − 1 is (r, s)-robust for
    every s) and closes it under "≥ r + s − 1 in-neighbours among earlier nodes".
    """
    if seeds is None:
        seeds = greedy_cliques(ig)
    return _construction(ig, r, s, seeds, _out_lists(ig))


def best_construction(
    ig: IndexedGraph, r: int, high: int, *, seeds: list[list[int]],
    deadline: float | None = None,
) -> tuple[int, Proof] | None:
    """(s, :func:`construction_proof` of (r, s)-robustness) for the largest s ≤ ``high``
    (s ≥ 2) it proves, or None.

    Bisection over s: a seed's closure under r + s − 1 is complete for s only if it is
    for every smaller s (closure_order), so "some seed closes" is monotone in s, and
    the answer and its proof (the first seed that closes at that s) are those of trying
    every s from ``high`` down; O(log(high) · |seeds| · |E|). When ``deadline`` passes
    between two probes, the best s proven so far (a true lower bound, not always the
    largest)."""
    out = _out_lists(ig)
    best: tuple[int, Proof] | None = None
    lo, hi = 2, high  # the largest s lies in [lo − 1, hi] (lo − 1: none, or best's)
    while lo <= hi:
        if deadline is not None and time.perf_counter() > deadline:
            break
        mid = (lo + hi) // 2
        proof = _construction(ig, r, mid, seeds, out)
        if proof is None:
            hi = mid - 1
        else:
            best, lo = (mid, proof), mid + 1
    return best


def _construction(ig: IndexedGraph, r: int, s: int, seeds: list[list[int]],
                  out: list[list[int]]) -> Proof | None:
    """:func:`construction_proof` with the seeds and out-neighbour lists given."""
    for clique in seeds:
        if len(clique) < 2 * r - 1:
            break
        order = closure_order(ig, clique, r + s - 1, out=out)
        if order is not None:
            return {
                "method": "construction",
                "order": order,
                "seed_size": len(clique),
                "seed_proof": {"method": "complete"},
            }
    return None


SPECTRAL_MAX_NODES = 200  # the checker verifies the bound by exact elimination, O(n³)


def is_undirected(ig: IndexedGraph) -> bool:
    """True when every edge has its reverse (the in-neighbour relation is symmetric)."""
    return all(v in ig.in_nbrs[u] for v, s in enumerate(ig.in_nbrs) for u in s)


@lru_cache(maxsize=8)
def spectral_r(ig: IndexedGraph) -> tuple[int, Proof | None]:
    """ρ ≥ ⌈λ2/2⌉ for an undirected graph, with a ``spectral`` proof.

    For |S| ≤ n/2 the edge boundary is ≥ λ2 |S| (n − |S|)/n ≥ λ2 |S|/2, so some member
    of S has ≥ λ2/2 neighbours outside; the smaller set of any pair has ≤ n/2 nodes.
    The proof gives a rational c with 2(r − 1) ≤ c < λ2 (half-way into the gap, so
    float error cannot matter); the checker verifies λ2 > c exactly by showing
    L − c·I + (c/n + 1)·J is positive definite. Returns (0, None) when the bound
    gives nothing, the graph is directed, or n > ``SPECTRAL_MAX_NODES``.
    """
    from fractions import Fraction

    n = ig.n
    if n > SPECTRAL_MAX_NODES or not is_undirected(ig):
        return 0, None
    L = np.zeros((n, n))
    for v, s in enumerate(ig.in_nbrs):
        L[v, v] = len(s)
        for u in s:
            L[v, u] = -1.0
    lam2 = float(np.linalg.eigvalsh(L)[1])
    r = int(np.ceil(lam2 / 2 - 1e-9))
    while r >= 1:
        floor_c = 2 * (r - 1)
        gap = lam2 - floor_c
        if gap > 2e-3:
            c = Fraction(floor_c) + Fraction(int(gap / 2 * 1000), 1000)
            return r, {"method": "spectral", "c": str(c)}
        r -= 1
    return 0, None
