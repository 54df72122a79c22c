"""Public robustness API: ρ(G), s*(r), r- and (r, s)-robustness, with certificates.

For S ⊆ V, reach_r(S) = {i ∈ S : |N(i) \\ S| ≥ r}. G is (r, s)-robust when every pair
of disjoint nonempty S1, S2 has reach_r(S1) = S1, reach_r(S2) = S2 or
|reach_r(S1)| + |reach_r(S2)| ≥ s; r-robust = (r, 1)-robust. ρ(G) = max r such
that G is r-robust, s*(r) = max s such that G is (r, s)-robust (0 when G is not
r-robust).

Strategy: polynomial bounds first (witness pairs above, among them two disjoint
r-closed sets found by the tabu walks of bounds.tabu_pairs; degree, complete and
construction proofs below); only when they do not meet, an exact method: for ρ, the
bitmask branch and bound (n ≤ 64, its search tree is the certificate) taking turns
on one core with the s* sized search below s = 1 (its tree is the certificate; it
wins on dense graphs), raced against the improved MILP on the other (when no search
leaves a replayable proof, the sized search's tree below s = 1 proves r-robustness,
if it is small); for s*, the
subset DP (n ≤ 22), else the two s* branch and bounds of search.min_cost_pair
(charged-set, sized) raced against the MILP (n ≤ 64), else the MILP; an s* proof the
checker would take on trust gets the sized search's tree below s* instead, if it is
small, else the smaller charged tree (one decision tree per set of charged nodes, or
per type of charges: the uniform one; _replayed).

Before any search, every fact already proven about the same graph in this process
(facts.py: a bounded cache keyed by node labels and edges) is used through the
implication (r', s')-robust ⇒ (r, s)-robust for r ≤ r', s ≤ s' + r' − r (so
s*(r) ≥ s*(ρ) + ρ − r), and every known violating pair refutes (r'', s'') above it;
under a forced method, only the proofs the checker verifies or that method's own
(facts.trusted_methods).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from rescon_certificates.check import MAX_ENUM_N

from .._progress import progress_bar
from .._validate import integer, positive
from ..errors import InputError, RESCONError, SolverError, TimeLimitReached
from . import bounds as bd
from .charged import charged_order, charged_tree, uniform_excluded, uniform_tree
from .distributed import searches_for
from .facts import Facts, facts_for, implied_proof
from .indexed import IndexedGraph, index_graph
from .milp import MilpOutcome, RobustnessMilp, milp_min_cost
from .search import (
    FAVOURED_SHARE,
    MAX_SEARCH_NODES,
    CostOutcome,
    SearchOutcome,
    SizedRun,
    cost_tree,
    decide_r_robust,
    min_cost_pair,
    search_order,
)

__all__ = [
    "RobustnessReport",
    "RobustnessCheck",
    "robustness",
    "is_r_robust",
    "is_rs_robust",
    "max_s",
    "METHODS",
]

METHODS = ("auto", "search", "milp", "dp")
DP_MAX_NODES = 26
DP_AUTO_NODES = 22
Proof = dict[str, Any]
LabelPair = tuple[frozenset[Hashable], frozenset[Hashable]]


@dataclass(frozen=True)
class RobustnessReport:
    """ρ(G) and s*(ρ) with their proofs.

    Attributes
    ----------
    n : number of nodes.
    r_max : ρ(G) when it was proven (``r_lower == r_upper``); None when the time limit
        stopped before ρ was settled (then ``r_lower ≤ ρ ≤ r_upper``).
    s_max : s*(r_max), or None when the time limit stopped before it was settled.
    witness : (S1, S2) in node labels showing G is not (r_upper + 1)-robust, or None
        when r_upper = ⌈n/2⌉ (no n-node graph is more robust).
    s_witness : (S1, S2) showing G is not (r_max, s_max + 1)-robust, None if s_max = n;
        when only s* hit the time limit, the cheapest pair found (not (r_max, s_upper + 1)).
    lower_proof : how r_max was proven ("trivial", "degree", "complete",
        "construction", "spectral", "implied", "search", "milp", "dp", or
        "cost_search": the replayable tree below s = 1 attached to a search or MILP
        decision whose own proof the checker cannot replay).
    certificate : JSON-ready ``robustness`` certificate (certificates/FORMAT.md).
    exact : False only when ``time_limit`` cut the search; then ρ ∈ [r_lower, r_upper],
        and when ρ was settled but s*(ρ) was not, s*(ρ) ∈ [s_lower, s_upper].
    method : the exact methods that ran, whether or not they finished ("bounds" when
        the bounds met; e.g. "search+milp": ρ by the search, s* by the MILP).
    seconds : wall time.
    s_lower, s_upper : proven bounds on s*(r_max) (both equal s_max when exact; None
        when ρ itself was not settled).
    """

    n: int
    r_max: int | None
    s_max: int | None
    witness: LabelPair | None
    s_witness: LabelPair | None
    lower_proof: str
    certificate: dict[str, Any] = field(repr=False)
    exact: bool
    r_lower: int
    r_upper: int
    method: str
    seconds: float
    s_lower: int | None = None
    s_upper: int | None = None


@dataclass(frozen=True)
class RobustnessCheck:
    """Answer to "is G (r, s)-robust?": ``holds`` with a ``witness`` pair (labels) when
    it does not, the proof method when it does, and the certificate either way.
    ``holds`` is None only when the time limit stopped the search."""

    r: int
    s: int
    holds: bool | None
    witness: LabelPair | None
    proof_method: str | None
    certificate: dict[str, Any] | None = field(repr=False)
    method: str
    seconds: float


# --------------------------------------------------------------------------- #
# input validation
# --------------------------------------------------------------------------- #


def _check_options(method: str, time_limit: float | None) -> float | None:
    if method not in METHODS:
        raise InputError(f"method must be one of {METHODS}; got {method!r}")
    if time_limit is None:
        return None
    return time.perf_counter() + positive("time_limit", time_limit, what="number of seconds")


def _remaining(deadline: float | None) -> float | None:
    return None if deadline is None else max(deadline - time.perf_counter(), 0.0)


# --------------------------------------------------------------------------- #
# deciding r-robustness
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class _Decision:
    holds: bool | None
    proof: Proof | None = None
    pair: bd.Pair | None = None
    method: str = "bounds"
    replay_tried: bool = False  # the sized tree below s = 1 was tried already (_race)


def _check_method_size(method: str, n: int) -> None:
    if method == "search" and n > MAX_SEARCH_NODES:
        raise InputError(f"method 'search' handles n ≤ {MAX_SEARCH_NODES}; got n = {n} "
                         "(use method='auto' or 'milp')")
    if method == "dp" and n > DP_MAX_NODES:
        raise InputError(f"method 'dp' handles n ≤ {DP_MAX_NODES}; got n = {n} "
                         "(use method='auto' or 'milp')")


def _half_pair(ig: IndexedGraph) -> bd.Pair:
    half = frozenset(range(ig.n // 2))
    return bd.Pair(half, frozenset(range(ig.n)) - half)


def _cheap_proof(ig: IndexedGraph, r: int, s: int, seeds: list[list[int]]) -> Proof | None:
    """A proof of (r, s)-robustness from the bounds, if one gives it: trivial, degree,
    complete, construction from a clique, spectral (undirected: ⌈λ2/2⌉ ≥ r + s − 1)."""
    if r <= 0:
        return {"method": "trivial"}
    if bd.degree_r(ig) >= r:
        return {"method": "degree"}
    if bd.is_complete(ig):
        return {"method": "complete"} if ig.n >= 2 * r - 1 else None
    proof = bd.construction_proof(ig, r, s, seeds=seeds)
    if proof is None:
        r_spec, spec = bd.spectral_r(ig)
        if spec is not None and r_spec >= r + s - 1:
            proof = spec if s == 1 else {"method": "implied", "r": r_spec, "s": 1, "proof": spec}
    return proof


SEED_SIZES = (2, 3, 4)  # seed sizes tried, in units of r (capped at the search's limit)
SEED_SEARCH_SECONDS = 1.0


def _searched_seed_construction(ig: IndexedGraph, r: int, deadline: float | None) -> Proof | None:
    """A construction whose seed (a prefix of a greedy order from the highest-degree
    node) is proven r-robust by a short search: e.g. circulants, whose seeds are
    path powers rather than cliques. Only proper seeds (m < n): a seed of all n nodes
    would be the race's own decision search, with a second's budget (ER(40, 0.8):
    1 s lost per decided r)."""
    start = max(range(ig.n), key=lambda i: (ig.in_degrees[i], -i))
    order = bd.greedy_order(ig, start)
    for m in sorted({min(k * r, MAX_SEARCH_NODES, ig.n) for k in SEED_SIZES}):
        closure = bd.closure_order(ig, order[:m], r)
        if closure is None or not 2 <= m < ig.n:
            continue
        stop = time.perf_counter() + SEED_SEARCH_SECONDS
        out = decide_r_robust(ig.induced(order[:m]), r,
                              deadline=stop if deadline is None else min(stop, deadline))
        if out.status == "robust" and out.tree is not None:
            return {"method": "construction", "order": closure, "seed_size": m,
                    "seed_proof": {"method": "search", "order": list(out.order),
                                   "tree": list(out.tree)}}
    return None


def _decide_r(
    ig: IndexedGraph,
    r: int,
    method: str,
    deadline: float | None,
    seeds: list[list[int]],
    known_pair: tuple[int, bd.Pair] | None = None,
    on_progress: Callable[[float, int], None] | None = None,
) -> _Decision:
    """Is ig r-robust? The cached facts first (an implied proof, or a known pair of
    cost 0 at threshold r), then :func:`_decide_r_fresh`; the answer is cached."""
    if r > (ig.n + 1) // 2:
        return _Decision(False, pair=_half_pair(ig))
    facts = facts_for(ig)
    known = facts.lower(r, method)
    if known is not None:
        return _Decision(True, proof=implied_proof(r, 1, r, known[0], known[1]))
    refuted = facts.upper(r)
    if refuted is not None and refuted[0] == 0:
        return _Decision(False, pair=refuted[1])
    dec = _replayable(ig, r, _decide_r_fresh(ig, r, method, deadline, seeds, known_pair,
                                             on_progress), deadline)
    _remember(facts, r, 1, dec)
    return dec


def _replayable(ig: IndexedGraph, r: int, dec: _Decision, deadline: float | None) -> _Decision:
    """``dec`` with its proof of r-robustness made replayable where that is cheap
    (:func:`_replayed`, s = 1); a refutation is kept. The answer never changes."""
    if not dec.holds or dec.proof is None or dec.replay_tried:
        return dec
    proof = _replayed(ig, r, 1, dec.proof, deadline)
    return dec if proof is dec.proof else replace(dec, proof=proof)


def _replayed(ig: IndexedGraph, r: int, s: int, proof: Proof, deadline: float | None) -> Proof:
    """``proof`` of (r, s)-robustness, or one the checker replays where that is cheap: a
    ``milp`` proof, a ``search`` or ``cost_search`` proof without its tree (beyond
    MAX_TREE_TOKENS, or the charged-set engine settled s*), or a ``dp`` proof beyond the
    checker's own enumeration (n > MAX_ENUM_N) becomes the sized search's tree below s
    (search.cost_tree: every pair whose sets both keep an r-closed member costs ≥ s,
    i.e. (r, s)-robustness), if it is recorded within ``TREE_SECONDS`` (dense graphs:
    4.9k tokens below s = 1 on ER(30, 0.8), where the decision tree has > 4M), else, for
    s ≥ 2, the charged tree (charged.charged_tree: one decision tree per set of charged
    nodes; ER(30, 0.5) with s = 2: 13–138 k tokens, where the sized tree has > 30M) or,
    when it is smaller, the uniform charged tree (charged.uniform_tree: one decision tree
    per type of charges), recorded within ``TREE_SECONDS``, resp. ``CHARGED_SECONDS``; the
    deciding method stays in ``info.decided_by``. Otherwise ``proof`` itself."""
    method = proof["method"]
    if (ig.n > MAX_SEARCH_NODES
            or not (method == "milp" or method == "dp" and ig.n > MAX_ENUM_N
                    or method in ("search", "cost_search") and proof.get("tree") is None
                    and proof.get("charged_tree") is None)):
        return proof
    key, tree, extra = "tree", _recorded(cost_tree, ig, r, s, deadline, TREE_SECONDS), {}
    if tree is None and s >= 2:
        key, (tree, extra) = "charged_tree", _charged(ig, r, s, deadline)
    if tree is None:
        return proof
    order = charged_order(ig) if key == "charged_tree" else search_order(ig)
    return {"method": "cost_search", "order": order.tolist(), key: list(tree),
            **extra, "info": {**proof.get("info", {}), "decided_by": method}}


def _charged(ig: IndexedGraph, r: int, s: int, deadline: float | None
             ) -> tuple[tuple[int, ...] | None, dict[str, bool]]:
    """(the charged tree of (r, s)-robustness, the proof's extra keys): the smaller of
    the two kinds recorded within ``CHARGED_SECONDS`` (the configurations' tree only
    below the uniform one's size; ``{"uniform": True}`` for the uniform one), or
    (None, {}). The uniform tree is not tried where a violating pair met so far shows
    that it does not exist (charged.uniform_excluded: at r = ρ for every s ≥ 3)."""
    stop = time.perf_counter() + CHARGED_SECONDS
    stop = stop if deadline is None else min(stop, deadline)
    uniform = None if uniform_excluded(ig, r, s, facts_for(ig).pairs) else _recorded(
        uniform_tree, ig, r, s, stop, CHARGED_SECONDS)
    limit = {} if uniform is None else {"max_tokens": max(1, len(uniform) - 1)}
    tree = _recorded(charged_tree, ig, r, s, stop, CHARGED_SECONDS, **limit)
    if tree is not None or uniform is None:
        return tree, {}
    return uniform, {"uniform": True}


def _recorded(record: Callable[..., tuple[int, ...] | None], ig: IndexedGraph, r: int, s: int,
              deadline: float | None, seconds: float, **limits: int) -> tuple[int, ...] | None:
    """The tree ``record`` (search.cost_tree, charged.charged_tree or uniform_tree)
    proving (r, s)-robustness within ``seconds`` (``limits``: its token limit), or None."""
    stop = time.perf_counter() + seconds
    try:
        return record(ig, r, s, deadline=stop if deadline is None else min(stop, deadline),
                      **limits)
    except ValueError as exc:
        raise RESCONError(f"internal error: ({r}, {s})-robustness was proven, "
                          f"but {exc}") from exc


def _remember(facts: Facts, r: int, s: int, dec: _Decision) -> None:
    """Cache a decision of (r, s)-robustness (nothing when the time limit cut it)."""
    if dec.holds and dec.proof is not None:
        facts.add_proof(r, s, dec.proof)
    elif dec.holds is False:
        facts.add_pair(dec.pair)


def _decide_r_fresh(
    ig: IndexedGraph,
    r: int,
    method: str,
    deadline: float | None,
    seeds: list[list[int]],
    known_pair: tuple[int, bd.Pair] | None,
    on_progress: Callable[[float, int], None] | None,
) -> _Decision:
    """Is ig r-robust (r ≤ ⌈n/2⌉)? Bounds first (proofs, the known pair, the walks'
    witness, a construction from a searched seed), then the exact ``method``."""
    _check_method_size(method, ig.n)
    proof = _cheap_proof(ig, r, 1, seeds)
    if proof is not None:
        return _Decision(True, proof=proof)
    value, pair = known_pair if known_pair is not None else bd.upper_witness(ig)
    if value < r:
        return _Decision(False, pair=pair)
    walked = _walked_witness(ig, r, deadline)
    if walked is not None:
        return _Decision(False, pair=walked)
    proof = _searched_seed_construction(ig, r, deadline)
    if proof is not None:
        return _Decision(True, proof=proof)
    if method == "auto" and ig.n > MAX_SEARCH_NODES:
        method = "milp"
    if method == "auto":
        return _race(ig, r, deadline, on_progress)
    if method == "search":
        return _search_decision(decide_r_robust(ig, r, deadline=deadline, on_progress=on_progress))
    if method == "dp":
        cost, pair = _dp_min_cost(ig, r)
        if cost >= 1:
            return _Decision(True, proof={"method": "dp"}, method="dp")
        assert pair is not None
        return _Decision(False, pair=pair, method="dp")
    return _milp_decision(ig, r, milp_min_cost(ig, r, upper=1, decision_only=True,
                                               time_limit=_remaining(deadline),
                                               on_progress=on_progress))


WITNESS_SECONDS = 1.0  # budget of the tabu walks for two disjoint r-closed sets


def _walked_witness(ig: IndexedGraph, r: int, deadline: float | None) -> bd.Pair | None:
    """Two disjoint r-closed sets (a pair of cost 0 at threshold r: not r-robust) found
    by the tabu walks (bounds.tabu_pairs) within ``WITNESS_SECONDS``, or None. Dense
    graphs are where the exact decision finds its witness slowly: ER(50, 0.8), seed
    50000, r = 21: the walks find one in 0.1 s, the MILP took 41 s, the decision
    search more than 60 s. The budget starts once the walk is compiled; past the
    ``deadline`` nothing is compiled or walked (a cold compile takes ~1 s)."""
    if deadline is not None and time.perf_counter() >= deadline:
        return None
    bd.compiled_walk()
    stop = time.perf_counter() + WITNESS_SECONDS
    found = bd.tabu_pairs(ig, r, floor=0, deadline=stop if deadline is None else
                          min(stop, deadline))
    if found and bd.pair_cost(ig, found[-1], r) == 0:
        return found[-1]
    return None


def _search_decision(out: SearchOutcome) -> _Decision:
    if out.status == "stopped":
        return _Decision(None, method="search")
    if out.status == "not_robust":
        assert out.witness is not None
        return _Decision(False, pair=bd.Pair(*out.witness), method="search")
    tree = list(out.tree) if out.tree is not None else None
    return _Decision(True, proof={"method": "search", "order": list(out.order), "tree": tree,
                                  "info": {"nodes": out.nodes}}, method="search")


def _milp_decision(ig: IndexedGraph, r: int, out: MilpOutcome) -> _Decision:
    if out.status == "infeasible":
        return _Decision(True, proof={"method": "milp", "solver": "highs",
                                      "info": {"seconds": round(out.seconds, 3)}}, method="milp")
    if out.pair is None:
        return _Decision(None, method="milp")
    pair = bd.Pair(*out.pair)
    if not (pair.S1 and pair.S2 and bd.violates(ig, pair, r, 1)):
        raise SolverError("the robustness MILP returned a pair that does not violate "
                          f"{r}-robustness")
    return _Decision(False, pair=pair, method="milp")


def _race(ig: IndexedGraph, r: int, deadline: float | None,
          on_progress: Callable[[float, int], None] | None) -> _Decision:
    """The decision search, the sized search below cap 1 (search.SizedRun) and the MILP
    race; the first answer wins, the others are cancelled.

    The two searches take turns on one core (``_turns``, ``_sized_share``), the MILP
    has the other. The decision search wins on sparse and mid-density graphs, the
    sized search on dense ones (ER(50, 0.8), seed 50000, r = 20: 0.4 s, where the MILP
    took 54 s and the decision search more than 60 s); both trees are checkable
    certificates. The MILP (its proof is accepted on trust) is the fallback where
    neither search gets far.
    """
    milp = RobustnessMilp(ig, r, upper=1, decision_only=True, time_limit=_remaining(deadline))
    sized = SizedRun(ig, r, 1, lower=0)
    try:
        out = decide_r_robust(ig, r, deadline=deadline, on_progress=on_progress,
                              should_stop=_turns(sized, _rival(milp), _sized_share(ig)))
    except BaseException:
        milp.cancel()
        raise
    if out.status != "stopped":
        milp.cancel()
        return _resumed(ig, r, _search_decision(out), sized, deadline)
    if sized.finished:
        milp.cancel()
        return _sized_decision(ig, r, sized)
    if deadline is not None and time.perf_counter() > deadline:
        milp.cancel()
        return _Decision(None, method="search+milp")
    return _resumed(ig, r, _milp_decision(ig, r, milp.outcome()), sized, deadline)


def _resumed(ig: IndexedGraph, r: int, dec: _Decision, sized: SizedRun,
             deadline: float | None) -> _Decision:
    """``dec`` from the decision search or the MILP, its proof of r-robustness made
    replayable by the race's own sized search below s = 1 where that is cheap: the run is
    resumed for up to ``TREE_SECONDS`` (its tree is the one search.cost_tree would
    record from scratch), and its tree, if it fits, becomes the proof, as in
    :func:`_replayed` (which is not tried again: a tree that overflowed in the race, or
    did not end within the budget resumed, would not from scratch either)."""
    if not dec.holds or dec.proof is None or dec.proof.get("tree") is not None:
        return dec
    if sized.recording and not sized.finished:
        stop = time.perf_counter() + TREE_SECONDS
        sized.run_for((stop if deadline is None else min(stop, deadline)) - time.perf_counter())
    tree = sized.tree() if sized.finished else None
    if tree is None:
        return replace(dec, replay_tried=True)
    if sized.pair() is not None:
        raise RESCONError(f"internal error: {r}-robustness was proven, but the sized search "
                          "found two disjoint closed sets")
    proof = {"method": "cost_search", "order": sized.order.tolist(), "tree": list(tree),
             "info": {**dec.proof.get("info", {}), "decided_by": dec.proof["method"]}}
    return replace(dec, proof=proof, replay_tried=True)


DENSE = 0.65  # arc density from which the sized searches are favoured


def _dense(ig: IndexedGraph) -> bool:
    """Arc density ≥ ``DENSE``: where the sized searches win (ER(40–50, 0.8): ρ decided in
    0.1–10 s, where the decision search takes over 60 s; s* rounds), and below it the
    decision search and the charged-set search (ER(40, 0.5): ρ in 6 s, where the sized
    search takes over 60 s; ER(50, 0.3): the s* round below cap 2)."""
    return sum(ig.in_degrees) >= DENSE * ig.n * (ig.n - 1)


def _sized_share(ig: IndexedGraph) -> float:
    """The sized search's share of the core it takes turns on with the decision search:
    ``FAVOURED_SHARE`` on dense graphs (:func:`_dense`), else the rest. A wrong guess
    costs at most 4× the winner's own time."""
    return FAVOURED_SHARE if _dense(ig) else 1 - FAVOURED_SHARE


def _turns(sized: SizedRun, rival: Callable[[], bool], share: float) -> Callable[[], bool]:
    """``should_stop`` for a decision search that shares its core with ``sized``: at each
    poll (between the decision search's slices) the sized search runs until it has had
    its ``share`` of the time; True once it has finished or ``rival`` (the MILP's
    ``should_stop``) says stop."""
    spent = [0.0, 0.0]  # decision search, sized search
    mark = [time.perf_counter()]

    def should_stop() -> bool:
        now = time.perf_counter()
        spent[0] += now - mark[0]
        owed = spent[0] * share / (1 - share) - spent[1]
        if owed > 0:
            sized.run_for(owed)
            spent[1] += time.perf_counter() - now
        mark[0] = time.perf_counter()
        return sized.finished or rival()

    return should_stop


def _sized_decision(ig: IndexedGraph, r: int, sized: SizedRun) -> _Decision:
    """r-robustness from the finished sized search below cap 1: a pair of cost 0 (two
    disjoint r-closed sets) refutes it; none proves it, the recorded tree is the proof
    (certificates/FORMAT.md, ``cost_search`` with s = 1)."""
    found = sized.pair()
    if found is not None:
        pair = bd.Pair(*found)
        if not bd.violates(ig, pair, r, 1):
            raise RESCONError(f"internal error: the sized search's pair does not violate "
                              f"{r}-robustness")
        return _Decision(False, pair=pair, method="search")
    proof: Proof = {"method": "cost_search", "order": sized.order.tolist(),
                    "info": {"nodes": sized.nodes}}
    tree = sized.tree()
    if tree is not None:
        proof["tree"] = list(tree)
    return _Decision(True, proof=proof, method="search")


RACE_DELAY_SECONDS = 1.0


def _rival(milp: RobustnessMilp) -> Callable[[], bool]:
    """``should_stop`` for a search racing ``milp``: the MILP starts only once the search
    has run ``RACE_DELAY_SECONDS`` (most searches end sooner, and on a shared machine
    the MILP's core slows them: max_s(ER(25, 0.5), 3) 1.0 s alone, 1.7-2.0 s raced
    from the start); from then on the search stops when the MILP has finished."""
    start_at = time.perf_counter() + RACE_DELAY_SECONDS

    def should_stop() -> bool:
        if not milp.started():
            if time.perf_counter() < start_at:
                return False
            milp.start()
        return not milp.running()

    return should_stop


def _dp_min_cost(ig: IndexedGraph, r: int) -> tuple[int, bd.Pair | None]:
    """Exact min pair cost by the subset DP (O(n·2^n) time, ~10·2^n bytes; it cannot
    be interrupted, so ``auto`` uses it only where it takes well under a second)."""
    _check_method_size("dp", ig.n)
    from ._kernels import min_pair_cost  # numba: imported on first use

    inmask = np.array(ig.in_masks(), dtype=np.uint64)
    best, w1, w2 = min_pair_cost(inmask, r)
    if w1 == 0:
        return int(best), None
    to_set = lambda m: frozenset(i for i in range(ig.n) if (int(m) >> i) & 1)  # noqa: E731
    return int(best), bd.Pair(to_set(w1), to_set(w2))


# --------------------------------------------------------------------------- #
# s*(r)
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class _SStar:
    value: int | None  # None: not settled before the deadline
    lower: int
    upper: int
    proof: Proof | None  # proves (r, lower)-robust
    pair: bd.Pair | None  # violates (r, upper + 1), None when upper = n
    method: str


def _s_star(
    ig: IndexedGraph,
    r: int,
    method: str,
    deadline: float | None,
    seeds: list[list[int]],
    r_proof: Proof,
    candidates: list[bd.Pair],
    *,
    cap: int | None = None,
    on_progress: Callable[[float, int], None] | None = None,
) -> _SStar:
    """s*(r) for an r-robust graph (r ≥ 1), ``r_proof`` proving (r, 1)-robustness; with
    ``cap``, min(s*(r), cap) (enough to decide (r, cap)-robustness). The result's proof
    and pair are added to the cached facts."""
    facts = facts_for(ig)
    ss = _s_star_fresh(ig, r, method, deadline, seeds, r_proof, candidates + facts.pairs,
                       facts.lower(r, method), cap, on_progress)
    if ss.value is not None and ss.proof is not None:
        ss = replace(ss, proof=_replayed(ig, r, ss.lower, ss.proof, deadline))
    if ss.proof is not None:
        facts.add_proof(r, ss.lower, ss.proof)
    facts.add_pair(ss.pair)
    return ss


def _s_star_fresh(
    ig: IndexedGraph,
    r: int,
    method: str,
    deadline: float | None,
    seeds: list[list[int]],
    r_proof: Proof,
    candidates: list[bd.Pair],
    known: tuple[int, Proof] | None,
    cap: int | None,
    on_progress: Callable[[float, int], None] | None,
) -> _SStar:
    """:func:`_s_star` given the facts: ``known`` = (s, proof of (r, s)-robustness)."""
    n = ig.n
    all_s = _cheap_proof(ig, r, n, seeds)
    if all_s is not None:
        return _SStar(n, n, n, all_s, None, "bounds")
    # upper: the cheapest candidate pair whose sets both keep a closed member
    upper, pair = n, None
    for cand in candidates + bd.s_candidates(ig, r):
        cost = bd.pair_cost(ig, cand, r)
        if cost is not None and cost < upper:
            upper, pair = cost, cand
    # lower: the r-robustness proof itself (s = 1), a construction with r + s − 1,
    # or what the facts imply
    lower, proof = 1, r_proof
    con = bd.best_construction(ig, r, upper, seeds=seeds, deadline=deadline)
    if con is not None:
        lower, proof = con
    if known is not None and known[0] > lower:
        lower, proof = min(known[0], upper), implied_proof(r, min(known[0], upper), r, *known)
    if lower < upper and (cap is None or cap > lower):
        upper, pair = _descended_upper(ig, r, upper, pair, deadline, lower)
    if cap is not None and cap < upper:
        if lower >= cap:
            return _SStar(cap, cap, cap, implied_proof(r, cap, r, lower, proof), None, "bounds")
        upper, pair = cap, None
    if lower >= upper:
        return _SStar(upper, upper, upper, proof, pair, "bounds")
    _check_method_size(method, n)
    if method == "auto":
        if n <= DP_AUTO_NODES and (deadline is None or _remaining(deadline) > 1.0):
            method = "dp"
        elif n <= MAX_SEARCH_NODES:
            return _race_s(ig, r, lower, upper, proof, pair, deadline, on_progress)
        else:
            method = "milp"
    if method == "dp":
        cost, dp_pair = _dp_min_cost(ig, r)
        if dp_pair is None:
            return _SStar(n, n, n, {"method": "dp"}, None, "dp")
        return _SStar(cost, cost, cost, {"method": "dp"}, dp_pair, "dp")
    if method == "search":
        found = _deepening_search(ig, r, lower, upper, deadline, on_progress=on_progress)
        return _cost_search_result(ig, r, found, lower, upper, proof, pair)
    milp = _milp_s(ig, r, lower, upper, deadline, on_progress)
    return _milp_s_result(ig, r, milp.outcome(), lower, upper, proof, pair)


DESCENT_SECONDS = 0.25  # budget of the local search for cheap pairs (bounds.descended_pairs)
TABU_SECONDS = 0.5  # budget of the tabu walks (bounds.tabu_pairs), beyond the DP's sizes
PROBE_SECONDS = 1.0  # budget of the near-bisection probes (bounds.probed_pairs), dense graphs


def _descended_upper(ig: IndexedGraph, r: int, upper: int, pair: bd.Pair | None,
                     deadline: float | None, lower: int = 0) -> tuple[int, bd.Pair | None]:
    """The cheapest of (upper, pair) and the local-search pairs: a tight upper bound
    makes every exact s* search prune from its first node, and one equal to ``lower``
    (proven) leaves no search at all. Beyond the DP's sizes, tabu walks follow the
    descents (on ER(25, 0.8) they find the optimum, cost 2, where descents stop at 4,
    sparing the search that would find it: ~7 s), and on dense graphs the sized search
    probes the near-bisections (bounds.probed_pairs; ER(50, 0.8), seed 50001: s* = 1 in
    0.3 s, where walks stop at 2 and the deepening search took 40 s)."""
    now = time.perf_counter()
    stop, tabu_stop = now + DESCENT_SECONDS, now + DESCENT_SECONDS + TABU_SECONDS
    if deadline is not None:
        stop, tabu_stop = min(stop, deadline), min(tabu_stop, deadline)
    for cand in bd.descended_pairs(ig, r, deadline=stop):
        cost = bd.pair_cost(ig, cand, r)
        if cost is not None and cost < upper:
            upper, pair = cost, cand
    if ig.n > DP_AUTO_NODES and lower < upper:
        for cand in bd.tabu_pairs(ig, r, floor=lower, below=upper, deadline=tabu_stop):
            upper, pair = bd.pair_cost(ig, cand, r), cand
    if DP_AUTO_NODES < ig.n <= MAX_SEARCH_NODES and lower < upper and _dense(ig):
        probe_stop = time.perf_counter() + PROBE_SECONDS
        for cand in bd.probed_pairs(ig, r, floor=lower, below=upper, deadline=probe_stop
                                    if deadline is None else min(probe_stop, deadline)):
            upper, pair = bd.pair_cost(ig, cand, r), cand
    return upper, pair


def _milp_s(ig: IndexedGraph, r: int, lower: int, upper: int, deadline: float | None,
            on_progress: Callable[[float, int], None] | None = None) -> RobustnessMilp:
    return RobustnessMilp(ig, r, lower=lower, upper=upper, time_limit=_remaining(deadline),
                          on_progress=on_progress)


def _milp_s_result(ig: IndexedGraph, r: int, out: MilpOutcome, lower: int, upper: int,
                   proof: Proof, pair: bd.Pair | None) -> _SStar:
    """s*(r) from the MILP: infeasible below ``upper`` → s* = upper; optimal → its pair."""
    milp_proof = {"method": "milp", "solver": "highs", "info": {"seconds": round(out.seconds, 3)}}
    if out.status == "infeasible":
        return _SStar(upper, upper, upper, milp_proof, pair, "milp")
    if out.pair is None:
        return _SStar(None, lower, upper, proof, pair, "milp")
    found = bd.Pair(*out.pair)
    cost = bd.pair_cost(ig, found, r)
    if cost is None or cost >= upper:
        raise SolverError("the robustness MILP returned a pair that is not cheaper than "
                          f"the incumbent (cost {cost}, incumbent {upper})")
    if out.status == "optimal":
        return _SStar(cost, cost, cost, milp_proof, found, "milp")
    return _SStar(None, lower, cost, proof, found, "milp")


def _cost_search_result(ig: IndexedGraph, r: int, out: CostOutcome, lower: int, upper: int,
                        proof: Proof, pair: bd.Pair | None) -> _SStar:
    """s*(r) from the s* branch and bounds (see search.min_cost_pair); its proof gets
    the sized search's tree recorded by the search (on a Dask cluster), else in
    :func:`_s_star` (:func:`_replayed`)."""
    if out.pair is not None:
        found = bd.Pair(*out.pair)
        cost = bd.pair_cost(ig, found, r)
        if cost is None or cost > out.best:
            raise RESCONError(f"internal error: the s* search returned a pair of cost {cost} "
                              f"for a claimed {out.best}")
        upper, pair = cost, found
    search_proof: Proof = {"method": "cost_search", "order": list(out.order),
                           "info": {"nodes": out.nodes}}
    if out.tree is not None:  # recorded on a Dask cluster (search.min_cost_pair)
        search_proof["tree"] = list(out.tree)
    if out.status == "stopped":
        if out.floor > lower:  # finished deepening rounds proved more than the bounds
            lower, proof = out.floor, search_proof
        return _SStar(None, lower, upper, proof, pair, "search")
    return _SStar(upper, upper, upper, search_proof, pair, "search")


TREE_SECONDS = 2.0  # budget for recording a replayable proof tree (search.cost_tree)
CHARGED_SECONDS = 4.0  # budget for both charged trees (charged.py; ~0.5 s for 2.7M tokens)


DEEPEN_CHEAP_SECONDS = 0.1


def _deepening_search(ig: IndexedGraph, r: int, lower: int, upper: int,
                      deadline: float | None, *, should_stop: Callable[[], bool] | None = None,
                      on_progress: Callable[[float, int], None] | None = None) -> CostOutcome:
    """The s* branch and bounds below growing caps (at most ``upper``): a search
    below a small cap prunes hard, and one that finds no pair proves s*(r) ≥ cap, so the
    search below a weak heuristic ``upper`` runs only when nothing cheaper exists. The
    step from lower to cap doubles while rounds are cheap (< ``DEEPEN_CHEAP_SECONDS``)
    and falls back to 1 after an expensive one: the search cost grows steeply with the
    cap, and a pair of cost = lower ends a search early. Each round favours the engine
    that finished the last one, the first round the one that wins on graphs of its
    density (:func:`_dense`; see search.min_cost_pair). Exact: the last search is
    exact below its cap, and every earlier one proved that nothing is cheaper than its
    cap. A recorded tree (search.min_cost_pair on a Dask cluster) proves the last
    round's answer, or the floor when that round stopped or ended at a pair of cost
    ``lower`` (then the previous round's tree, below cap = lower, is the proof)."""
    step, nodes, favour = 1, 0, "sized" if _dense(ig) else "charged"
    floor_tree = None  # the tree of the last round that proved s*(r) ≥ lower
    while True:
        cap = min(lower + step, upper)
        t0 = time.perf_counter()
        out = min_cost_pair(ig, r, cap, lower=lower, deadline=deadline, should_stop=should_stop,
                            on_progress=on_progress, favour=favour)
        favour = out.engine
        nodes += out.nodes
        if out.status == "stopped" or out.pair is not None or cap == upper:
            best = out.best if out.pair is not None else upper
            tree = out.tree
            if tree is None and (out.status == "stopped" or best == lower):
                tree = floor_tree
            return replace(out, nodes=nodes, best=best, floor=lower, tree=tree)
        cheap = time.perf_counter() - t0 < DEEPEN_CHEAP_SECONDS
        lower, step, floor_tree = cap, 2 * step if cheap else 1, out.tree


def _race_s(ig: IndexedGraph, r: int, lower: int, upper: int, proof: Proof,
            pair: bd.Pair | None, deadline: float | None,
            on_progress: Callable[[float, int], None] | None = None) -> _SStar:
    """The s*(r) branch and bound (deepening) and the MILP race, one core each."""
    milp = _milp_s(ig, r, lower, upper, deadline)
    try:
        out = _deepening_search(ig, r, lower, upper, deadline,
                                should_stop=_rival(milp), on_progress=on_progress)
    except BaseException:
        milp.cancel()
        raise
    if out.status != "stopped" or (deadline is not None and time.perf_counter() > deadline):
        milp.cancel()
        return _cost_search_result(ig, r, out, lower, upper, proof, pair)
    return _milp_s_result(ig, r, milp.outcome(), lower, upper, proof, pair)


# --------------------------------------------------------------------------- #
# public API
# --------------------------------------------------------------------------- #


def _labels(ig: IndexedGraph, pair: bd.Pair | None) -> LabelPair | None:
    if pair is None:
        return None
    return frozenset(ig.nodes[i] for i in pair.S1), frozenset(ig.nodes[i] for i in pair.S2)


def _head(kind: str, ig: IndexedGraph) -> dict[str, Any]:
    return {"rescon_certificate": 1, "kind": kind, "graph": ig.graph_json()}


def _upper_json(pair: bd.Pair | None) -> dict[str, Any]:
    if pair is None:
        return {"method": "half"}
    return {"method": "witness", **pair.to_json()}


def robustness(
    G: Any,
    *,
    method: str = "auto",
    time_limit: float | None = None,
    undirected: bool | None = None,
    progress: bool | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
) -> RobustnessReport:
    """ρ(G) and s*(ρ(G)), exactly, with a certificate.

    Parameters
    ----------
    G : networkx.Graph or DiGraph; edge (u, v) means v receives u's state.
    method : "auto" (bounds, then the search raced against the MILP for n ≤ 64, the
        MILP beyond; s* by the DP for n ≤ 22, else the s* searches raced
        against the MILP), or force "search" (n ≤ 64), "milp" or "dp" (n ≤ 26).
    time_limit : seconds; when reached, returns proven bounds with ``exact=False``.
    undirected : treat the edges of a DiGraph as undirected.
    progress : show a progress bar (default: when stderr is a terminal).
    scheduler, workers : finish the exact searches (decision and s*) that outlast a
        fraction of a second on Dask, split into independent subtrees
        (graphs/distributed.py; same answers; the decision's certificate is the serial
        one, s* proofs carry the sized tree assembled from the parts when it fits):
        the scheduler at this address, or an embedded LocalCluster of ``workers``
        processes (0: serial). n ≤ 64.

    Returns
    -------
    RobustnessReport

    Notes
    -----
    Deciding r-robustness is coNP-complete; the bounds settle most structured
    graphs in O(n·|E|) and the exact methods are exponential in the worst case.

    Examples
    --------
    >>> import networkx as nx, rescon
    >>> rep = rescon.robustness(nx.complete_graph(6))
    >>> rep.r_max, rep.s_max, rep.lower_proof
    (3, 6, 'degree')
    >>> rep = rescon.robustness(nx.cycle_graph(8))
    >>> rep.r_max, rep.lower_proof, sorted(map(sorted, rep.witness))
    (1, 'construction', [[0, 1], [2, 3, 4, 5, 6, 7]])
    >>> rescon.check_certificate(rep.certificate).valid
    True
    """
    with searches_for(G, scheduler, workers):
        return _robustness(G, method, time_limit, undirected, progress)


def _robustness(G: Any, method: str, time_limit: float | None, undirected: bool | None,
                progress: bool | None) -> RobustnessReport:
    """:func:`robustness` (its searches where the caller put them)."""
    t0 = time.perf_counter()
    deadline = _check_options(method, time_limit)
    ig = index_graph(G, undirected=undirected)
    _check_method_size(method, ig.n)
    n = ig.n
    half = (n + 1) // 2
    # no graph is more than ⌈n/2⌉-robust: when the degree bound (or K_n) reaches it,
    # nothing else is needed
    if _cheap_proof(ig, half, n, []) is not None:
        seeds: list[list[int]] = []
        up_value, up_pair = half, _half_pair(ig)
    else:
        seeds = bd.greedy_cliques(ig)
        up_value, up_pair = bd.upper_witness(ig)
    facts = facts_for(ig)
    for known_pair in facts.pairs:
        if bd.pair_value(ig, known_pair) < up_value:
            up_value, up_pair = bd.pair_value(ig, known_pair), known_pair
    r_upper, r_upper_pair = (half, None) if up_value >= half else (up_value, up_pair)
    # lower bound: the best cheap or cached proof at or below r_upper
    r_lower, lower = 0, {"method": "trivial"}
    for r in range(r_upper, 0, -1):
        known = facts.lower(r, method)
        proof = _cheap_proof(ig, r, 1, seeds)
        if proof is None and known is not None:
            proof = implied_proof(r, 1, r, *known)
        if proof is not None:
            r_lower, lower = r, proof
            facts.add_proof(r, 1, proof)
            break
    used = "bounds"
    bar = _Phases(progress, n)
    engine = "MILP" if method == "milp" or (method == "auto" and n > MAX_SEARCH_NODES) else method
    candidates = [up_pair]
    while r_lower < r_upper:
        bar.phase(f"ρ {'search' if engine == 'auto' else engine} (r={r_upper})")
        dec = _decide_r(ig, r_upper, method, deadline, seeds,
                        known_pair=(up_value, up_pair), on_progress=bar.update)
        used = dec.method
        if dec.holds is None:
            break
        if dec.holds:
            assert dec.proof is not None
            r_lower, lower = r_upper, dec.proof
        else:
            assert dec.pair is not None
            candidates.append(dec.pair)
            r_upper_pair = dec.pair
            r_upper = bd.pair_value(ig, dec.pair)
            up_value, up_pair = r_upper, dec.pair
    facts.add_pair(r_upper_pair)
    exact = r_lower == r_upper
    if not exact:
        bar.close()
        cert = {**_head("robustness", ig), "exact": False, "r_lower": r_lower,
                "r_upper": r_upper, "lower": lower, "upper_r": _upper_json(r_upper_pair)}
        return RobustnessReport(n, None, None, _labels(ig, r_upper_pair), None,
                                lower["method"], cert, False, r_lower, r_upper, used,
                                time.perf_counter() - t0)
    rho = r_lower
    if rho == 0:
        ss = _SStar(n, n, n, {"method": "trivial"}, None, "bounds")
    else:
        bar.phase(f"s* {'search' if engine == 'auto' else engine} (r={rho})")
        ss = _s_star(ig, rho, method, deadline, seeds, lower, candidates,
                     on_progress=bar.update)
    bar.close()
    if ss.method != "bounds":
        used = ss.method if used == "bounds" else f"{used}+{ss.method}"
    if ss.value is None:
        cert = {**_head("robustness", ig), "exact": False, "r_lower": rho, "r_upper": rho,
                "lower": lower, "upper_r": _upper_json(r_upper_pair),
                "s_lower": ss.lower, "s_upper": ss.upper,
                "lower_s": None if ss.lower == 1 else ss.proof,
                "upper_s": None if ss.upper == n else _upper_json(ss.pair)}
        return RobustnessReport(n, rho, None, _labels(ig, r_upper_pair), _labels(ig, ss.pair),
                                lower["method"], cert, False, rho, rho, used,
                                time.perf_counter() - t0, s_lower=ss.lower, s_upper=ss.upper)
    cert = {**_head("robustness", ig), "exact": True, "r_max": rho, "s_max": ss.value,
            "lower": lower, "lower_s": None if ss.value == 1 else ss.proof,
            "upper_r": _upper_json(r_upper_pair),
            "upper_s": None if ss.value == n else _upper_json(ss.pair)}
    return RobustnessReport(n, rho, ss.value, _labels(ig, r_upper_pair), _labels(ig, ss.pair),
                            lower["method"], cert, True, rho, rho, used,
                            time.perf_counter() - t0, s_lower=ss.value, s_upper=ss.value)


def is_rs_robust(
    G: Any,
    r: int,
    s: int,
    *,
    method: str = "auto",
    time_limit: float | None = None,
    undirected: bool | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
) -> RobustnessCheck:
    """Is G (r, s)-robust? With a witness pair when not, a proof when it is.

    Parameters
    ----------
    r : int ≥ 0.  s : int, 1 ≤ s ≤ n.
    scheduler, workers : the exact searches on Dask, as in :func:`robustness`.

    Raises
    ------
    InputError
        For r < 0, s < 1, s > n, non-integer r or s, fewer than 2 nodes.
    """
    with searches_for(G, scheduler, workers):
        return _is_rs_robust(G, r, s, method, time_limit, undirected)


def _is_rs_robust(G: Any, r: int, s: int, method: str, time_limit: float | None,
                  undirected: bool | None) -> RobustnessCheck:
    """:func:`is_rs_robust` (its searches where the caller put them)."""
    t0 = time.perf_counter()
    deadline = _check_options(method, time_limit)
    ig = index_graph(G, undirected=undirected)
    _check_method_size(method, ig.n)
    r = integer("r", r, low=0)
    s = integer("s", s, low=1, high=ig.n)
    seeds = bd.greedy_cliques(ig)
    dec = _decide_r(ig, r, method, deadline, seeds)
    if dec.holds and s > 1:
        if r == 0:
            dec = _Decision(True, proof={"method": "trivial"})
        else:
            assert dec.proof is not None
            dec = _decide_rs(ig, r, s, method, deadline, seeds, dec.proof)
    return _check_result(ig, r, s, dec, time.perf_counter() - t0)


IMPLIED_SEARCH_SECONDS = 1.0  # budget for proving (r + s − 1)-robustness first


def _decide_rs(ig: IndexedGraph, r: int, s: int, method: str, deadline: float | None,
               seeds: list[list[int]], r_proof: Proof) -> _Decision:
    """(r, s)-robust, for r-robust ig (r ≥ 1, s ≥ 2)? In this order: the cached facts
    (implications, known pairs), (r + s − 1)-robustness (⇒ (r, s), facts.py; decided
    within ``IMPLIED_SEARCH_SECONDS``; not with the DP, which settles min(s*(r), s)
    in one uninterruptible pass anyway), then the exact min(s*(r), s)."""
    facts = facts_for(ig)
    known = facts.lower(r, method)
    if known is not None and known[0] >= s:
        return _Decision(True, proof=implied_proof(r, s, r, *known))
    refuted = facts.upper(r)
    if refuted is not None and refuted[0] < s:
        return _Decision(False, pair=refuted[1])
    if r + s - 1 <= (ig.n + 1) // 2 and method != "dp":
        stop = time.perf_counter() + IMPLIED_SEARCH_SECONDS
        strong = _decide_r(ig, r + s - 1, method, stop if deadline is None else
                           min(stop, deadline), seeds)
        if strong.holds:
            assert strong.proof is not None
            return _Decision(True, proof=implied_proof(r, s, r + s - 1, 1, strong.proof),
                             method=strong.method)
    ss = _s_star(ig, r, method, deadline, seeds, r_proof, [bd.upper_witness(ig)[1]], cap=s)
    if ss.lower >= s:
        assert ss.proof is not None
        return _Decision(True, proof=implied_proof(r, s, r, ss.lower, ss.proof),
                         method=ss.method)
    if ss.value is None and ss.upper >= s:
        return _Decision(None, method=ss.method)
    return _Decision(False, pair=ss.pair, method=ss.method)


def _check_result(ig: IndexedGraph, r: int, s: int, dec: _Decision,
                  seconds: float) -> RobustnessCheck:
    if dec.holds is None:
        return RobustnessCheck(r, s, None, None, None, None, dec.method, seconds)
    if dec.holds:
        assert dec.proof is not None
        cert = {**_head("rs_robust", ig), "r": r, "s": s, "proof": dec.proof}
        return RobustnessCheck(r, s, True, None, dec.proof["method"], cert, dec.method, seconds)
    assert dec.pair is not None
    cert = {**_head("not_rs_robust", ig), "r": r, "s": s, "witness": dec.pair.to_json()}
    return RobustnessCheck(r, s, False, _labels(ig, dec.pair), None, cert, dec.method, seconds)


def is_r_robust(
    G: Any,
    r: int,
    *,
    method: str = "auto",
    time_limit: float | None = None,
    undirected: bool | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
) -> RobustnessCheck:
    """Is G r-robust (= (r, 1)-robust)? See :func:`is_rs_robust`."""
    return is_rs_robust(G, r, 1, method=method, time_limit=time_limit, undirected=undirected,
                        scheduler=scheduler, workers=workers)


def max_s(
    G: Any,
    r: int,
    *,
    method: str = "auto",
    time_limit: float | None = None,
    undirected: bool | None = None,
    scheduler: str | None = None,
    workers: int | None = None,
) -> int:
    """s*(r) = max s such that G is (r, s)-robust; 0 when G is not r-robust.
    ``scheduler``, ``workers``: the exact searches on Dask, as in :func:`robustness`.

    Raises
    ------
    InputError
        Bad r, method or time limit.
    TimeLimitReached
        The time limit stopped the search before s*(r) was settled (the message
        gives the proven bounds).
    """
    with searches_for(G, scheduler, workers):
        return _max_s(G, r, method, time_limit, undirected)


def _max_s(G: Any, r: int, method: str, time_limit: float | None,
           undirected: bool | None) -> int:
    """:func:`max_s` (its searches where the caller put them)."""
    deadline = _check_options(method, time_limit)
    ig = index_graph(G, undirected=undirected)
    _check_method_size(method, ig.n)
    r = integer("r", r, low=0)
    if r == 0:
        return ig.n
    seeds = bd.greedy_cliques(ig)
    dec = _decide_r(ig, r, method, deadline, seeds)
    if dec.holds is None:
        raise TimeLimitReached(f"time limit reached before deciding whether G is {r}-robust")
    if not dec.holds:
        return 0
    assert dec.proof is not None
    ss = _s_star_of_robust(ig, r, method, deadline, seeds, dec.proof)
    if ss.value is None:
        raise TimeLimitReached(f"time limit reached: {ss.lower} ≤ s*({r}) ≤ {ss.upper}")
    return ss.value


def _s_star_of_robust(ig: IndexedGraph, r: int, method: str, deadline: float | None,
                      seeds: list[list[int]], r_proof: Proof) -> _SStar:
    """s*(r) of a graph proven r-robust by ``r_proof`` (r ≥ 1), seeding the upper
    bound with the best witness heuristic."""
    _, up_pair = bd.upper_witness(ig)
    return _s_star(ig, r, method, deadline, seeds, r_proof, [up_pair])


class _Phases:
    """One progress bar (stderr; see rescon._progress) over the phases of
    :func:`robustness`: its description names the phase (bounds → ρ search (r = …) →
    s* search (r = …)), its count the refuted share of the current search space in ‰,
    and its postfix the search nodes explored so far in that phase."""

    def __init__(self, enabled: bool | None, n: int) -> None:
        self.n = n
        self.bar = progress_bar(enabled, 1000, f"robustness (n={n}): bounds", unit="‰")

    def phase(self, name: str) -> None:
        """Start phase ``name`` (the count restarts at 0)."""
        if self.bar is not None:
            self.bar.set_description_str(f"robustness (n={self.n}): {name}", refresh=False)
            self.bar.n = 0
            self.bar.set_postfix_str("", refresh=True)

    def update(self, fraction: float, nodes: int) -> None:
        """The current search has refuted ``fraction`` of its space in ``nodes`` nodes."""
        if self.bar is not None:
            self.bar.n = min(int(fraction * 1000), 1000)
            self.bar.set_postfix_str(f"{nodes:,} nodes", refresh=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
