"""Exact decision "is G r-robust?" by branch and bound over closed sets (n ≤ 64).

G is not r-robust iff V contains two disjoint nonempty *r-closed* sets (sets none
of whose members has r in-neighbours outside). Closed sets are closed under union,
so for a fixed S1 the only candidate S2 worth trying is core_r(V \\ S1), found by
peeling in O(|E|). The search enumerates S1 only, with three prunings — S2 must
fit in core(V \\ S1 \\ B), S1 must fit in core(V \\ X), and a member with too many
outside in-neighbours forces a branch — and the symmetry break "the first node of
S1 ∪ S2 in the search order is in S1". The tree it explores is recorded token by
token and is itself the certificate of robustness (certificates/FORMAT.md,
method ``search``), replayed by the checker in polynomial time per leaf.

Complexity: exponential in the worst case (the problem is coNP-complete); the tree
is tiny on graphs whose robustness is decided by small or large sets.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .indexed import IndexedGraph

__all__ = [
    "FAVOURED_SHARE",
    "MAX_SEARCH_NODES",
    "MAX_TREE_TOKENS",
    "COST_ENGINES",
    "CostOutcome",
    "CostPart",
    "CostPartRun",
    "SearchOutcome",
    "SizedRun",
    "charged_search_order",
    "cost_tree",
    "decide_r_robust",
    "min_cost_pair",
    "search_order",
    "split_cost_part",
    "whole_cost_part",
]

MAX_SEARCH_NODES = 64
FAVOURED_SHARE = 0.75  # of the wall time, for min_cost_pair's favoured engine
MAX_TREE_TOKENS = 4_000_000
_SLICE = 20_000


@dataclass(frozen=True)
class SearchOutcome:
    """Result of one decision search.

    ``status`` is "robust" (no violating pair; ``tree`` proves it unless it grew
    past ``MAX_TREE_TOKENS``), "not_robust" (``witness`` = (S1, S2) index sets), or
    "stopped" (deadline reached; ``progress`` ∈ [0, 1) is the share of the search
    space refuted so far).
    """

    status: str
    r: int
    order: tuple[int, ...]
    witness: tuple[frozenset[int], frozenset[int]] | None
    tree: tuple[int, ...] | None
    nodes: int
    progress: float


def search_order(ig: IndexedGraph) -> np.ndarray:
    """Roots in ascending in-degree (ties by index): small-degree nodes are the
    likeliest members of closed sets, so witnesses surface from the first roots."""
    deg = np.array(ig.in_degrees)
    return np.lexsort((np.arange(ig.n), deg)).astype(np.int64)


def charged_search_order(ig: IndexedGraph) -> np.ndarray:
    """The root order of the charged-set s* search (``_kernels.min_cost_step``):
    descending in-degree, ties by index (as charged.charged_order). The first roots,
    hard to close, end their subtrees soonest, and the later ones find their easy nodes
    in B. ER(40, 0.5), seed 40000, r = ρ = 11, charged engine alone: below cap 2
    8.6M → 3.6M states, below cap 3 77M → 43M states (75 → 46 CPU-s)."""
    deg = np.array(ig.in_degrees)
    return np.lexsort((np.arange(ig.n), -deg)).astype(np.int64)


def _kernel_inputs(ig: IndexedGraph):
    """(kernels module, in-masks, out-masks, root order) for a search on ig (n ≤ 64).
    numba is imported here, on first use, not with rescon."""
    from . import _kernels

    if ig.n > MAX_SEARCH_NODES:
        raise ValueError(f"the bitmask search handles n ≤ {MAX_SEARCH_NODES}; got n = {ig.n}")
    return _kernels, _mask_array(ig), _out_mask_array(ig), search_order(ig)


def _root_range(roots: range | None, n: int) -> tuple[int, int]:
    """(first root, one past the last) of a search over ``roots`` ⊆ range(n)."""
    if roots is None:
        return 0, n
    if roots.step != 1 or not 0 <= roots.start <= roots.stop <= n:
        raise ValueError(f"roots must be a consecutive range within range({n}); got {roots}")
    return roots.start, roots.stop


def _mask_array(ig: IndexedGraph) -> np.ndarray:
    return np.array(ig.in_masks(), dtype=np.uint64)


def _out_mask_array(ig: IndexedGraph) -> np.ndarray:
    """outmask[u] = the nodes that receive from u."""
    out = np.zeros(ig.n, dtype=np.uint64)
    for v, nbrs in enumerate(ig.in_nbrs):
        for u in nbrs:
            out[u] |= np.uint64(1) << np.uint64(v)
    return out


def _grown(buffer: np.ndarray, room: int) -> np.ndarray | None:
    """A full token buffer doubled (capped at ``room``, its old tokens kept), or None
    when it already holds ``room`` tokens: the caller then drops the tree, or stops (a
    part on a cluster that keeps its tree: graphs/distributed.py, the tree's room)."""
    size = buffer.shape[0]
    if size >= room:
        return None
    grown = np.empty(min(2 * size, room), dtype=np.int32)
    grown[:size] = buffer
    return grown


def _bits(mask: int) -> frozenset[int]:
    return frozenset(i for i in range(int(mask).bit_length()) if (int(mask) >> i) & 1)


@dataclass(frozen=True)
class SearchPart:
    """An independent piece of the decision search: the subtrees of ``frames`` (rows of
    the kernel's stack, bottom first, ``depths`` their depths in the search tree),
    the top one first, then the subtrees of the roots ``root``, ..., ``end`` − 1.

    The kernel only ever pops the top frame and pushes its children, and a frame's
    subtree depends on the frame alone; so a run from any stack explores, in preorder,
    the top frame's subtree, then the next one's, ..., then the roots' — and its tree
    is the concatenation of the trees of the runs from each frame alone and from the
    roots alone (:func:`split_part`).
    """

    frames: np.ndarray
    depths: np.ndarray
    root: int
    end: int


def whole_part(n: int, roots: range | None = None) -> SearchPart:
    """The part of the search over ``roots`` (default all n): no pending frame."""
    from ._kernels import STACK_WIDTH

    first, end = _root_range(roots, n)
    return SearchPart(np.zeros((0, STACK_WIDTH), dtype=np.uint64), np.zeros(0, dtype=np.int64),
                      first, end)


def split_part(part: SearchPart, singles: int) -> list[SearchPart]:
    """``part`` as consecutive parts whose trees, concatenated in list order, are its
    tree: the top frames above the ``singles`` bottom ones together, each of those alone
    (the bottom frames are the shallowest: they hold most of the work), then the roots.
    Empty parts are left out."""
    parts = [SearchPart(part.frames[a:b], part.depths[a:b], part.end, part.end)
             for a, b in _frame_pieces(part.frames.shape[0], singles)]
    if part.root < part.end:
        parts.append(SearchPart(part.frames[:0], part.depths[:0], part.root, part.end))
    return parts


def _frame_pieces(k: int, singles: int) -> list[tuple[int, int]]:
    """Slices of a stack of k frames (bottom first), in preorder: the frames above the
    ``singles`` bottom ones together (the top of the stack runs first), then each of the
    bottom ones alone, the upper first. Empty slices are left out."""
    cut = min(singles, k)
    pieces = [(cut, k)] + [(i, i + 1) for i in range(cut - 1, -1, -1)]
    return [(a, b) for a, b in pieces if b > a]


class PartRun:
    """A resumable run of ``_kernels.decide_step`` over one :class:`SearchPart`: the
    stack, state, witness and token arrays it advances, slice by slice. The tree is
    recorded while it has fewer than ``room`` tokens (0: not recorded); with ``keep``,
    a run whose ``room`` tokens are written stops there (status NEED_ROOM, its
    :meth:`rest` still to search) instead of dropping its tree."""

    def __init__(self, inputs: tuple, r: int, part: SearchPart, room: int,
                 keep: bool = False) -> None:
        self.K, self.inmask, self.outmask, self.order = inputs
        self.r, self.room, self.record, self.keep = r, room, room > 0, keep
        K, n = self.K, self.inmask.shape[0]
        k = part.frames.shape[0]
        self.stack = np.zeros((2 * n + 2 + k, K.STACK_WIDTH), dtype=np.uint64)
        self.stack[:k] = part.frames
        self.depth = np.zeros(2 * n + 2 + k, dtype=np.int64)
        self.depth[:k] = part.depths
        self.state = np.zeros(K.STATE_LEN, dtype=np.int64)
        self.state[K.ST_SP], self.state[K.ST_ROOT], self.state[K.ST_END] = k, part.root, part.end
        self.ubuf = np.zeros(K.UBUF_LEN, dtype=np.uint64)
        self.progress = np.zeros(1, dtype=np.float64)
        self.buffer = np.empty(min(1 << 12, room) if room > 0 else 1, dtype=np.int32)

    def advance(self, max_nodes: int) -> int:
        """Expand up to ``max_nodes`` more states; the kernel's status (RUNNING: not
        finished). A full token buffer doubles, up to ``room``; a full buffer of that
        size drops the tree (``record`` becomes False), or with ``keep`` stops the run
        (NEED_ROOM)."""
        K = self.K
        while True:
            self.state[K.ST_STATUS] = K.RUNNING
            K.decide_step(self.inmask, self.outmask, self.order, self.r, self.stack,
                          self.depth, self.state, self.ubuf, self.buffer, self.record,
                          max_nodes, self.progress)
            if self.state[K.ST_STATUS] != K.NEED_ROOM:
                return int(self.state[K.ST_STATUS])
            grown = _grown(self.buffer, self.room)
            if grown is None and self.keep:
                return K.NEED_ROOM
            if grown is None:
                self.record, grown = False, np.empty(1, dtype=np.int32)
            self.buffer = grown

    @property
    def nodes(self) -> int:
        return int(self.state[self.K.ST_NODES])

    def tokens(self) -> np.ndarray | None:
        """The tree tokens written so far (None when the tree was dropped)."""
        return self.buffer[: self.state[self.K.ST_NTOK]].copy() if self.record else None

    def witness(self) -> tuple[frozenset[int], frozenset[int]]:
        """(S1, S2) after status SAT."""
        return _bits(self.ubuf[self.K.UB_W1]), _bits(self.ubuf[self.K.UB_W2])

    def rest(self) -> SearchPart:
        """What is left of the part: the pending frames and roots."""
        sp = int(self.state[self.K.ST_SP])
        return SearchPart(self.stack[:sp].copy(), self.depth[:sp].copy(),
                          int(self.state[self.K.ST_ROOT]), int(self.state[self.K.ST_END]))


def decide_r_robust(
    ig: IndexedGraph,
    r: int,
    *,
    record: bool = True,
    deadline: float | None = None,
    on_progress: Callable[[float, int], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
    roots: range | None = None,
) -> SearchOutcome:
    """Decide whether ``ig`` is r-robust, exactly.

    Parameters
    ----------
    ig : IndexedGraph with n ≤ 64 nodes.
    r : int ≥ 1.
    record : keep the search tree as a certificate (dropped if it exceeds
        ``MAX_TREE_TOKENS`` tokens; the answer stays exact).
    deadline : ``time.perf_counter()`` value after which the search stops.
    on_progress : called with the refuted share of the search space and the number
        of search nodes so far.
    should_stop : polled between slices; True abandons the search ("stopped"),
        e.g. when a racing MILP has answered.
    roots : search only the subtrees of these roots (positions in the search order;
        default all n). The subtrees are independent: the trees of a split of
        range(n) into consecutive parts, concatenated in root order, are the tree of
        the whole search, and "robust" from every part means robust.

    Inside ``distributed.searches_on(...)``, a search still running after
    ``distributed.LOCAL_NODES`` nodes is finished on the Dask cluster
    (:func:`rescon.graphs.distributed.finish_on_cluster`): same answer, same tree.
    """
    from . import distributed

    inputs = _kernel_inputs(ig)
    K, order = inputs[0], tuple(inputs[3].tolist())
    run = PartRun(inputs, r, whole_part(ig.n, roots), MAX_TREE_TOKENS if record else 0)
    cluster = distributed.active()
    while True:
        status = run.advance(_SLICE)
        if on_progress is not None:
            on_progress(float(run.progress[0]), run.nodes)
        if status != K.RUNNING:
            break
        if (deadline is not None and time.perf_counter() > deadline) or (
            should_stop is not None and should_stop()
        ):
            return SearchOutcome("stopped", r, order, None, None, run.nodes,
                                 float(run.progress[0]))
        if cluster is not None and run.nodes >= distributed.LOCAL_NODES:
            return distributed.finish_on_cluster(cluster, run, deadline=deadline,
                                                 on_progress=on_progress,
                                                 should_stop=should_stop)
    if status == K.SAT:
        return SearchOutcome("not_robust", r, order, run.witness(), None, run.nodes, 1.0)
    tokens = run.tokens()
    tree = None if tokens is None else tuple(tokens.tolist())
    return SearchOutcome("robust", r, order, None, tree, run.nodes, 1.0)


@dataclass(frozen=True)
class CostOutcome:
    """Result of the s*(r) branch and bound: ``status`` "done" (``best`` = s*(r)
    when < ``upper``, with ``pair`` the cheapest pair; otherwise s*(r) = ``upper``)
    or "stopped" (``best`` is still an upper bound). ``floor``: every pair is proven to
    cost at least this much (rounds of a deepening search that finished; 0 if none).
    ``engine``: the search that finished ("sized" or "charged"; "" when stopped).
    ``tree``: a recorded sized tree (certificates/FORMAT.md, ``cost_search``) proving
    that every pair costs at least ``best`` ("done") or ``floor`` ("stopped"); recorded
    only for searches run inside ``distributed.searches_on``, else None."""

    status: str
    best: int
    pair: tuple[frozenset[int], frozenset[int]] | None
    nodes: int
    order: tuple[int, ...]
    floor: int = 0
    engine: str = ""
    tree: tuple[int, ...] | None = None


class _CostRun:
    """The arrays one resumable s* kernel advances (stack with room for ``frames``
    pending frames, depths, state, witness buffer, refuted share)."""

    def __init__(self, K, n: int, roots: tuple[int, int], upper: int, frames: int = 0) -> None:
        self.stack = np.zeros((3 * n + 3 + frames, K.COST_STACK_WIDTH), dtype=np.uint64)
        self.depth = np.zeros(3 * n + 3 + frames, dtype=np.int64)
        self.state = np.zeros(K.COST_STATE_LEN, dtype=np.int64)
        self.state[K.CS_ROOT], self.state[K.CS_END] = roots
        self.state[K.CS_BEST] = upper
        self.ubuf = np.zeros(3, dtype=np.uint64)
        self.progress = np.zeros(1, dtype=np.float64)


COST_ENGINES = ("sized", "charged")


@dataclass(frozen=True)
class CostPart:
    """An independent piece of one s* engine's search: the subtrees of ``frames`` (rows of
    the kernel's stack, bottom first, ``depths`` their depths), pending states of the root
    order[root − 1] (the sized search's: of its size combination (s1, s2)); then, unless
    ``alone``, the rest of that root (the sized search's size combinations after
    (s1, s2)) and the roots ``root``, ..., ``end`` − 1. s1 = 0: no root started. The
    subtrees compose as the decision search's do (proof: graphs/distributed.py)."""

    frames: np.ndarray
    depths: np.ndarray
    root: int
    end: int
    s1: int = 0
    s2: int = 0
    alone: bool = False


def whole_cost_part(n: int, roots: range | None = None) -> CostPart:
    """The part of an s* search over ``roots`` (default all n): no pending frame."""
    from ._kernels import COST_STACK_WIDTH

    first, end = _root_range(roots, n)
    return CostPart(np.zeros((0, COST_STACK_WIDTH), dtype=np.uint64),
                    np.zeros(0, dtype=np.int64), first, end)


def split_cost_part(part: CostPart, singles: int, n: int) -> list[CostPart]:
    """``part`` as consecutive parts whose trees, concatenated in list order, are its
    tree (as :func:`split_part`): the top frames above the ``singles`` bottom ones
    together, each of those alone, then the rest of the root (the sized search's size
    combinations after (s1, s2), if any), then the next roots. Empty parts are left out."""
    parts = [CostPart(part.frames[a:b], part.depths[a:b], part.root, part.root, part.s1,
                      part.s2, alone=True)
             for a, b in _frame_pieces(part.frames.shape[0], singles)]
    if part.alone:
        return parts
    none = (part.frames[:0], part.depths[:0])
    if part.s1 > 0 and part.s1 + 2 <= n - part.root + 1:  # a size combination is left
        parts.append(CostPart(*none, part.root, part.root, part.s1, part.s2))
    if part.root < part.end:
        parts.append(CostPart(*none, part.root, part.end))
    return parts


class CostPartRun:
    """A resumable run of one s* engine over a :class:`CostPart`: ``engine`` "sized"
    (``_kernels.min_cost_sized_step``) or "charged" (``_kernels.min_cost_step``), below
    the incumbent ``best`` (a pair's cost, or a cap), ending at the first pair of cost
    ≤ ``lower``. The sized search's tree is recorded while it has fewer than
    ``max_tokens`` tokens (``recording`` turns False beyond, the search goes on; 0: not
    recorded), or with ``keep`` the run stops there (NEED_ROOM), as :class:`PartRun`."""

    def __init__(self, inputs: tuple, engine: str, r: int, lower: int, part: CostPart,
                 best: int, max_tokens: int = 0, keep: bool = False) -> None:
        if engine not in COST_ENGINES:
            raise ValueError(f"engine must be one of {COST_ENGINES}; got {engine!r}")
        self.K, self.inmask, self.outmask, self.order = inputs
        K, n, k = self.K, self.inmask.shape[0], part.frames.shape[0]
        self.engine, self.r, self.lower, self.upper = engine, r, lower, best
        if engine == "sized":
            self.mmask, self.mout = K.non_in_masks(self.inmask)
        self.run = run = _CostRun(K, n, (part.root, part.root if part.alone else part.end),
                                  best, k)
        run.stack[:k], run.depth[:k] = part.frames, part.depths
        state = run.state
        state[K.CS_SP], state[K.CS_S1], state[K.CS_S2] = k, part.s1, part.s2
        state[K.CS_ALONE] = part.alone
        if part.root > 0:  # the started root's B (a root not yet started sets its own)
            run.ubuf[K.CB_B] = K.prefix_mask(self.order, part.root - 1)
        self.max_tokens = max_tokens if engine == "sized" else 0
        self.recording, self.keep = self.max_tokens > 0, keep
        self.tokens = np.empty(min(1 << 12, self.max_tokens) if self.recording else 1,
                               dtype=np.int32)
        self.seconds = 0.0  # wall time in advance(), for turns between engines

    def advance(self, max_nodes: int) -> int:
        """Expand up to ``max_nodes`` more states; the kernel's status (RUNNING: not
        finished). A full token buffer doubles, up to ``max_tokens``; beyond, the tree
        is dropped, or with ``keep`` the run stops (NEED_ROOM)."""
        K, run = self.K, self.run
        t0 = time.perf_counter()
        try:
            while True:
                run.state[K.CS_STATUS] = K.RUNNING
                args = (self.r, self.lower, run.stack, run.depth, run.state, run.ubuf,
                        max_nodes, run.progress)
                if self.engine == "charged":
                    K.min_cost_step(self.inmask, self.outmask, self.order, *args)
                else:
                    K.min_cost_sized_step(self.inmask, self.mmask, self.mout, self.order,
                                          *args, self.tokens, self.recording)
                status = int(run.state[K.CS_STATUS])
                if status != K.NEED_ROOM:
                    return status
                grown = _grown(self.tokens, self.max_tokens)
                if grown is None and self.keep:
                    return status
                if grown is None:
                    self.recording, grown = False, np.empty(1, dtype=np.int32)
                self.tokens = grown
        finally:
            self.seconds += time.perf_counter() - t0

    def run_for(self, seconds: float) -> None:
        """Advance slice by slice for about ``seconds`` (or until finished)."""
        stop = time.perf_counter() + seconds
        while not self.finished and time.perf_counter() < stop:
            self.advance(_SLICE)

    @property
    def finished(self) -> bool:
        return int(self.run.state[self.K.CS_STATUS]) not in (self.K.RUNNING, self.K.NEED_ROOM)

    @property
    def best(self) -> int:
        """The incumbent: the cheapest pair's cost found so far, or the one it was given."""
        return int(self.run.state[self.K.CS_BEST])

    @best.setter
    def best(self, value: int) -> None:
        self.run.state[self.K.CS_BEST] = value

    @property
    def nodes(self) -> int:
        return int(self.run.state[self.K.CS_NODES])

    @property
    def progress(self) -> float:
        """The share of the part's search space refuted so far."""
        return float(self.run.progress[0])

    def pair(self) -> tuple[frozenset[int], frozenset[int]] | None:
        """The last pair this run found (cost at most ``best`` right after it found it:
        the charged engine may count a charged node the pair in fact leaves unreached;
        callers recompute the cost), None while it found none cheaper than the incumbent
        it started with."""
        if self.best >= self.upper:
            return None
        return _bits(self.run.ubuf[self.K.CB_W1]), _bits(self.run.ubuf[self.K.CB_W2])

    def recorded(self) -> np.ndarray | None:
        """The tokens recorded so far (None when not recorded or dropped)."""
        if not self.recording:
            return None
        return self.tokens[: self.run.state[self.K.CS_NTOK]].copy()

    def tree(self) -> tuple[int, ...] | None:
        """:meth:`recorded` as a tuple."""
        tokens = self.recorded()
        return None if tokens is None else tuple(tokens.tolist())

    def rest(self) -> CostPart:
        """What is left of the part: its pending frames, the rest of its root, its roots."""
        K, state = self.K, self.run.state
        sp = int(state[K.CS_SP])
        return CostPart(self.run.stack[:sp].copy(), self.run.depth[:sp].copy(),
                        int(state[K.CS_ROOT]), int(state[K.CS_END]), int(state[K.CS_S1]),
                        int(state[K.CS_S2]), bool(state[K.CS_ALONE]))


def _dues(favour: str | None) -> dict[str, float]:
    """Each engine's due share of the time: equal, or ``FAVOURED_SHARE`` for ``favour``."""
    if favour is None:
        return dict.fromkeys(COST_ENGINES, 0.5)
    if favour not in COST_ENGINES:
        raise ValueError(f"favour must be one of {sorted(COST_ENGINES)} or None; got "
                         f"{favour!r}")
    return {e: FAVOURED_SHARE if e == favour else 1 - FAVOURED_SHARE for e in COST_ENGINES}


def min_cost_pair(
    ig: IndexedGraph,
    r: int,
    upper: int,
    *,
    lower: int = 0,
    deadline: float | None = None,
    should_stop: Callable[[], bool] | None = None,
    on_progress: Callable[[float, int], None] | None = None,
    roots: range | None = None,
    favour: str | None = None,
) -> CostOutcome:
    """s*(r) = min |reach_r(S1)| + |reach_r(S2)| over pairs whose sets both keep an
    r-closed member, searched below ``upper`` (a known pair's cost, or n); the search
    ends early when it finds a pair of cost ``lower`` (a proven lower bound).

    Two exact branch and bounds share the incumbent and take turns in slices; the
    first to finish answers: over S1 with charged members (``_kernels.min_cost_step``,
    "charged": fast on sparse graphs, small sets) and two-sided with both sizes fixed
    (``_kernels.min_cost_sized_step``, "sized": fast on dense graphs, near-bisections).
    Each takes the next slice while its share of the wall time is below its due: equal
    shares, or ``FAVOURED_SHARE`` for the ``favour``-ed engine (the last round's winner
    in a deepening search: the faster engine stays the faster on the same graph, and
    the other still has a quarter of the time, so a wrong guess costs at most 4×).
    n ≤ 64. ``on_progress`` and ``roots`` as in :func:`decide_r_robust` (a part's
    ``best`` is at least the least cost of the pairs whose first node lies in its
    roots — its pair is one — but not always at most: the engines search maximal
    pairs only, whose first node may come earlier; it is that least cost for roots =
    range(0, b), and s*(r) is the least over a partition of range(n)). The sized
    engine takes its roots in ``search_order``, the charged one in
    :func:`charged_search_order` (each engine covers every pair in its
    own order, so either one finishing answers) — but both in ``search_order`` when
    ``roots`` is given, so that a part means the same pairs to both.

    Inside ``distributed.searches_on(...)``, a search still running after
    ``distributed.LOCAL_NODES`` states is finished on the Dask cluster, split into
    parts (:func:`rescon.graphs.distributed.finish_cost_on_cluster`; same ``best``), and
    the sized search records its tree (``CostOutcome.tree``).
    """
    from . import distributed

    inputs = _kernel_inputs(ig)
    K, order = inputs[0], tuple(inputs[3].tolist())
    due = _dues(favour)
    part = whole_cost_part(ig.n, roots)
    cluster = distributed.active()
    room = MAX_TREE_TOKENS if cluster is not None else 0
    runs = [CostPartRun(inputs, "sized", r, lower, part, upper, room),
            CostPartRun(inputs if roots is not None else (*inputs[:3], charged_search_order(ig)),
                        "charged", r, lower, part, upper)]
    best, pair = upper, None
    while True:
        run = min(runs, key=lambda c: c.seconds / due[c.engine])
        run.best = best
        status = run.advance(_SLICE)
        if run.best < best:
            best, pair = run.best, run.pair()
        if on_progress is not None:
            on_progress(max(c.progress for c in runs), sum(c.nodes for c in runs))
        if status != K.RUNNING:
            break
        if (deadline is not None and time.perf_counter() > deadline) or (
            should_stop is not None and should_stop()
        ):
            return CostOutcome("stopped", best, pair, sum(c.nodes for c in runs), order)
        if (cluster is not None and best > lower
                and sum(c.nodes for c in runs) >= distributed.LOCAL_NODES):
            return distributed.finish_cost_on_cluster(
                cluster, runs, due, best, pair, deadline=deadline, on_progress=on_progress,
                should_stop=should_stop)
    tree = run.tree() if best > lower else None  # else it ended early: a partial tree
    return CostOutcome("done", best, pair, sum(c.nodes for c in runs), order,
                       engine=run.engine, tree=tree)


class SizedRun(CostPartRun):
    """A resumable run of the sized search (``_kernels.min_cost_sized_step``) over all
    roots below cap ``s``: does some pair whose sets both keep an r-closed member cost
    less than s? It ends at the first pair of cost ≤ ``lower`` (a proven lower bound;
    -1: it never ends early). Its tree is recorded while it has at most ``max_tokens``
    tokens (``recording`` turns False beyond, the search goes on). With s = 1 it decides
    r-robustness (a pair of cost 0 is two disjoint r-closed sets), and on dense graphs
    in a fraction of the decision search's time: ER(50, 0.8), r = 20: 0.5M states,
    0.4 s, where the decision search had not finished after 60 s (150M states)."""

    def __init__(self, ig: IndexedGraph, r: int, s: int, *, lower: int = -1,
                 max_tokens: int = MAX_TREE_TOKENS) -> None:
        super().__init__(_kernel_inputs(ig), "sized", r, lower, whole_cost_part(ig.n), s,
                         max_tokens)
        self.s = s


def cost_tree(ig: IndexedGraph, r: int, s: int, *, deadline: float | None = None,
              max_tokens: int = MAX_TREE_TOKENS) -> tuple[int, ...] | None:
    """The recorded tree of the sized search (``_kernels.min_cost_sized_step``) below
    cap s: the certificate that every pair whose sets both keep an r-closed member
    costs ≥ s (certificates/FORMAT.md, ``cost_search``). None when it needs more than
    ``max_tokens`` tokens or passes ``deadline``; ValueError when it meets a pair
    cheaper than s (then s is no lower bound)."""
    run = SizedRun(ig, r, s, max_tokens=max_tokens)
    while True:
        status = run.advance(_SLICE)
        if run.best < s:
            raise ValueError(f"a pair costs {run.best} < s = {s}")
        if not run.recording:
            return None
        if status != run.K.RUNNING:
            return run.tree()
        if deadline is not None and time.perf_counter() > deadline:
            return None
