"""Proven robustness facts about one graph, the implications between them, and a
bounded per-process cache of them keyed by the graph itself.

Implication (generalising LeBlanc et al. 2013, Lemmas on (r, s)-robustness): for
r ≤ r' and 1 ≤ s ≤ min(n, s' + r' − r),

    (r', s')-robust  ⇒  (r, s)-robust.

Proof. Let (S1, S2) violate (r, s): with X_i = reach_r(S_i), X_i ≠ S_i and
|X1| + |X2| ≤ s − 1. Remove from each S_i up to k = r' − r members of X_i (Y_i,
|Y_i| = min(k, |X_i|)) and call the rest T_i. T_i ⊇ S_i \\ X_i is nonempty. A member
of S_i \\ X_i has < r in-neighbours outside S_i, hence ≤ r − 1 + |Y_i| < r' outside
T_i, so reach_r'(T_i) ⊆ X_i \\ Y_i ≠ T_i, and |X1 \\ Y1| + |X2 \\ Y2| ≤ s − 1 − |Y1| −
|Y2|. If neither X_i was exhausted, this is ≤ s − 1 − 2k; otherwise one X_i became
empty and the other lost min(k, |X_j|) members, so the sum is ≤ max(0, s − 1 − k).
Either way it is ≤ s − 1 − k ≤ s' − 1 when s ≤ s' + k, so (T1, T2) violates (r', s').
Special cases: r' = r (monotone in s), s' = 1 (``(r + s − 1)-robust ⇒ (r, s)``),
r = r' − 1 (``(r', s') ⇒ (r' − 1, s' + 1)``). Hence s*(r) ≥ s*(r') + r' − r.

Refutation: a pair violating (r, s) violates every (r'', s'') with r'' ≥ r, s'' ≥ s
(reach_r'' ⊆ reach_r, so the sets stay not fully reachable and the count only drops).

Facts are stored per :class:`IndexedGraph` (its node labels, their types and its
in-neighbour sets: an exact fingerprint; any edit of the graph gives another key),
in a least-recently-used cache of ``CACHE_SIZE`` graphs.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Hashable
from dataclasses import dataclass, field
from typing import Any

from . import bounds as bd
from .indexed import IndexedGraph

__all__ = ["Facts", "facts_for", "implied_s", "implied_proof", "clear_cache", "CACHE_SIZE"]

CACHE_SIZE = 32
MAX_PAIRS = 64
Proof = dict[str, Any]


def implied_s(n: int, r: int, r2: int, s2: int) -> int:
    """The largest s with (r2, s2)-robust ⇒ (r, s)-robust (module docstring); 0 if r > r2."""
    if r > r2:
        return 0
    return min(n, s2 + r2 - r)


def implied_proof(r: int, s: int, r2: int, s2: int, proof: Proof) -> Proof:
    """``proof`` of (r2, s2)-robustness as a proof of (r, s) (wrapped unless equal; an
    implied proof is unwrapped first: the implication is transitive, since
    s ≤ s2 + r2 − r ≤ s3 + r3 − r2 + r2 − r)."""
    if proof.get("method") == "implied":
        r2, s2, proof = proof["r"], proof["s"], proof["proof"]
    if (r, s) == (r2, s2):
        return proof
    return {"method": "implied", "r": r2, "s": s2, "proof": proof}


@dataclass
class Facts:
    """What is proven about one graph: for each r the largest s proven with its proof,
    the violating pairs met so far, and finished s*(r) values."""

    ig: IndexedGraph
    proofs: dict[int, tuple[int, Proof]] = field(default_factory=dict)
    pairs: list[bd.Pair] = field(default_factory=list)
    s_exact: dict[int, int] = field(default_factory=dict)

    def add_proof(self, r: int, s: int, proof: Proof) -> None:
        """Record that ``proof`` proves (r, s)-robustness."""
        if r >= 1 and s > self.proofs.get(r, (0, None))[0]:
            self.proofs[r] = (s, proof)

    def add_pair(self, pair: bd.Pair | None) -> None:
        """Record a pair of disjoint nonempty sets (each violates (r, s) for every
        r > its value; the first ``MAX_PAIRS`` distinct pairs are kept)."""
        if pair is not None and pair not in self.pairs and len(self.pairs) < MAX_PAIRS:
            self.pairs.append(pair)

    def lower(self, r: int) -> tuple[int, Proof] | None:
        """(s, proof of (r, s)-robustness) with the largest s implied by the facts."""
        best: tuple[int, Proof] | None = None
        for r2, (s2, proof) in self.proofs.items():
            s = implied_s(self.ig.n, r, r2, s2)
            if s >= 1 and (best is None or s > best[0]):
                best = (s, implied_proof(r, s, r2, s2, proof))
        return best

    def upper(self, r: int) -> tuple[int, bd.Pair] | None:
        """(c, pair): the cheapest known pair at threshold r; it violates (r, c + 1)."""
        best: tuple[int, bd.Pair] | None = None
        for pair in self.pairs:
            cost = bd.pair_cost(self.ig, pair, r)
            if cost is not None and (best is None or cost < best[0]):
                best = (cost, pair)
        return best


def _key(ig: IndexedGraph) -> tuple[Hashable, ...]:
    """Exact fingerprint: labels with their types (1, 1.0 and True differ) and edges."""
    return tuple((type(v), v) for v in ig.nodes), ig.in_nbrs


_CACHE: OrderedDict[tuple[Hashable, ...], Facts] = OrderedDict()
_LOCK = threading.Lock()


def facts_for(ig: IndexedGraph) -> Facts:
    """The cached facts of ``ig`` (created empty on first use; LRU, ``CACHE_SIZE`` graphs)."""
    key = _key(ig)
    with _LOCK:
        facts = _CACHE.get(key)
        if facts is None:
            facts = _CACHE[key] = Facts(ig)
            while len(_CACHE) > CACHE_SIZE:
                _CACHE.popitem(last=False)
        else:
            _CACHE.move_to_end(key)
        return facts


def clear_cache() -> None:
    """Forget every cached fact (e.g. to time a cold call)."""
    with _LOCK:
        _CACHE.clear()
