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

A cached proof answers a call that forces an exact method (``method`` other than
"auto") only when the checker can verify it, or when the parts it would take on trust
(:func:`trusted_methods`) are that method's own: a forced "search" gets a replayable
tree, not an earlier call's MILP proof.

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

from rescon_certificates.check import MAX_ENUM_N

from . import bounds as bd
from .indexed import IndexedGraph

__all__ = ["Facts", "facts_for", "implied_s", "implied_proof", "trusted_methods",
           "clear_cache", "CACHE_SIZE"]

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


# the proof methods each forced ``method`` produces (robustness.METHODS)
_OWN_METHODS = {"search": {"search", "cost_search"}, "milp": {"milp"}, "dp": {"dp"}}


def trusted_methods(proof: Proof, n: int) -> set[str]:
    """The methods of the parts of ``proof`` (on an n-node graph) that the checker
    takes on trust (certificates/check.py): ``milp``, ``dp``, and ``search`` or
    ``cost_search`` without a recorded tree, on more than ``MAX_ENUM_N`` nodes (up to
    that, the checker re-verifies them by enumeration), nested in ``implied`` proofs and
    ``construction`` seeds (on ``seed_size`` nodes) included. Not seen here: a recorded
    tree beyond the checker's replay limits."""
    method = proof.get("method")
    if method == "implied":
        return trusted_methods(proof["proof"], n)
    if method == "construction":
        return trusted_methods(proof["seed_proof"], proof["seed_size"])
    untreed = method in ("search", "cost_search") and proof.get("tree") is None \
        and proof.get("charged_tree") is None
    if n > MAX_ENUM_N and (method in ("milp", "dp") or untreed):
        return {method}
    return set()


def _usable(proof: Proof, n: int, method: str) -> bool:
    """May a cached ``proof`` answer a call with ``method``? Always under "auto"; under a
    forced method, when every part taken on trust is that method's own."""
    return method == "auto" or trusted_methods(proof, n) <= _OWN_METHODS.get(method, set())


@dataclass
class Facts:
    """What is proven about one graph: for each r the largest s proven with its proof,
    the violating pairs met so far, and finished s*(r) values."""

    ig: IndexedGraph
    proofs: dict[int, tuple[int, Proof]] = field(default_factory=dict)
    pairs: list[bd.Pair] = field(default_factory=list)
    s_exact: dict[int, int] = field(default_factory=dict)

    def add_proof(self, r: int, s: int, proof: Proof) -> None:
        """Record that ``proof`` proves (r, s)-robustness (kept when no proof of a larger s
        is known, or one of the same s that the checker cannot fully verify)."""
        if r < 1:
            return
        old = self.proofs.get(r)
        if old is None or s > old[0] or (s == old[0] and trusted_methods(old[1], self.ig.n)
                                         and not trusted_methods(proof, self.ig.n)):
            self.proofs[r] = (s, proof)

    def add_pair(self, pair: bd.Pair | None) -> None:
        """Record a pair of disjoint nonempty sets (each violates (r, s) for every
        r > its value; the first ``MAX_PAIRS`` distinct pairs are kept)."""
        if pair is not None and pair not in self.pairs and len(self.pairs) < MAX_PAIRS:
            self.pairs.append(pair)

    def lower(self, r: int, method: str = "auto") -> tuple[int, Proof] | None:
        """(s, proof of (r, s)-robustness) with the largest s implied by the facts whose
        proofs may answer a call with ``method`` (module docstring)."""
        best: tuple[int, Proof] | None = None
        for r2, (s2, proof) in self.proofs.items():
            s = implied_s(self.ig.n, r, r2, s2)
            if s >= 1 and (best is None or s > best[0]) and _usable(proof, self.ig.n, method):
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
