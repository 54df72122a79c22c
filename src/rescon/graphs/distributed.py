"""The exact searches — the decision "is G r-robust?" and s*(r) — split into independent
subtrees on Dask.

The search (:func:`rescon.graphs.search.decide_r_robust`) is a depth-first
branch and bound whose whole state is a stack of pending frames and the next root.
Its tree T, written in preorder, is the certificate (certificates/FORMAT.md, method
``search``). Split and compose:

**Claim.** Let a run of the kernel over a part P (frames f_1 … f_k, top first, then the
roots a … b − 1) expand some states, writing tokens t, and stop with pending frames
g_1 … g_m (top first) and roots a' … b − 1. Then

    T(P) = t + T(g_1) + … + T(g_m) + T(roots a' … b − 1),

where T(g) is the tree of a run from the stack [g] alone; the status of P is SAT iff
some run on the right finds a pair, and every pair such a run finds is a witness.

*Proof.* The kernel pops the top frame, and either closes it (a leaf token) or writes
its branch token and pushes its two children; what it does with a frame depends on
the frame alone (S, X, P, Q, the pending peelings and the depth), never on the frames
below it, and a new root starts only on an empty stack. By induction on the size of
g_1's subtree, a run from [g_1, g_2, …] writes all of T(g_1) before it pops g_2, and
leaves g_2, … untouched meanwhile; the same holds for g_2, …, g_m and then the roots.
So the continued serial run writes exactly the right-hand side, and the search space
(pairs whose first node is order[k] placed in S1, refined by the branch decisions)
is partitioned among the frames and the roots: a pair exists in P iff it exists in
one of them, and a pair found from a frame is closed, disjoint and nonempty by the
same leaf test as in the serial run. Each part also counts its own states and its
own refuted share 2^−depth / n, so their sums are the serial counts. ∎

Hence a part run on a worker for at most ``TASK_NODES`` states returns its tokens and,
when not finished, its rest split into parts again (:func:`search.split_part`); the
driver assembles T by the claim, part by part in preorder: the same tree as the
serial search, checkable as one certificate. Work stays balanced however unbalanced
the subtrees are (the first roots hold most of the work): a part never runs longer
than one task before its rest is shared out again.

**The tree's room.** The serial search keeps its tree while it has fewer than
``MAX_TREE_TOKENS`` tokens; past that it drops it and goes on with the rules only a
search recording no tree may use (``_kernels.decide_step``'s forced candidates and
``crowded`` prune; ``min_cost_sized_step``'s ``sized_crowded``). Here each part records
at most the tokens it is granted (:meth:`_Tree.grant`) and stops there, its rest shared
out as after a task; the grants held by running parts and the tokens joined never
exceed the cap together. So (i) no part drops its tokens, every token of the tree is
joined until the joined ones reach the cap, and the tree is dropped then, i.e. exactly
when the serial search drops its own: the same tree whenever the serial tree fits, and
then the same states (every part records, as the serial search does throughout);
(ii) one token is written per state expanded while recording, so the parts expand at
most ``MAX_TREE_TOKENS`` states without those rules, as the serial search does. (Only
where the parts record differs: the serial search records a prefix of the tree. When
each part was given the whole remaining room, every part in flight recorded until the
joined tree overflowed: +3–4 % states on the Dask bench instances, +50 % on a
10⁷-state ER(40, 0.5) search.)

**The s*(r) search** (:func:`search.min_cost_pair`: the sized and the charged-set
branch and bounds over the same roots, sharing the incumbent ``best``, the cheapest
pair's cost found so far, at first the cap ``upper``) splits engine by engine in the
same way (:func:`search.split_cost_part`), with two differences: a state's subtree
depends on its frame and on the context a part carries (:class:`search.CostPart`: the
root's B; the sized search's size combination (s1, s2), whose stack empties before the
next one starts), and on the incumbent, which only prunes.

**Claim (s*).** Let the parts of an engine's search run, each below an incumbent of
its own (the best known when it was submitted; it falls as the part finds pairs), and
let b be the least of ``upper`` and the costs of the pairs they find. Then
b = min(upper, s*) over the searched roots, the serial search's answer; and for the
sized search, unless a part ended early at a pair of cost ≤ ``lower``, the tokens
assembled as in the claim above form a tree the checker accepts below cap s = b
(certificates/FORMAT.md, ``cost_search``).

*Proof.* By the argument above, the pairs are partitioned among the frames, the rest of
the root (its later size combinations) and the later roots, each searched by exactly one
part, in the kernel's (and the checker's) order. A state is pruned only when its lower
bound reaches the part's incumbent at that moment, the cost of a found pair or
``upper``, hence ≥ b, or when no maximal pair lies below it (``_kernels.crowded``,
only where no tree is recorded; some cheapest pair is maximal). A cheapest maximal
pair p is therefore found, or pruned below an incumbent ≤ cost(p): either way
b ≤ min(upper, cost(p)); and b ≥ min(upper, s*), being ``upper`` or a pair's cost.
Each leaf of a sized tree is a state whose bound reached its
incumbent (≥ b), or a complete labelling whose bound is its pair's cost (≥ s* ≥ b); the
checker's bound is at least the kernel's (which stops counting once it reaches the
incumbent), so every leaf passes at cap b, and the subtrees, each complete, cover the
roots and size combinations in order. ∎

The states differ from the serial search's (pruning depends on when a part learns of
the incumbent); the answer does not. A part runs for at most ``COST_TASK_NODES``
states; as many run as the cluster has threads, and a free thread takes the next part
of the engine furthest below its due share of the task seconds (search.min_cost_pair's
turns), with the incumbent as it is then. The first engine to finish answers; the
sized engine's tree is the ``cost_search`` certificate when it fits ``MAX_TREE_TOKENS``.

The cluster is the one sweeps use (rescon._dask): an embedded LocalCluster of
``workers`` processes or a running scheduler's address, opened only when a search
outlasts ``LOCAL_NODES`` states in this process, inside :func:`searches_on`.
"""

from __future__ import annotations

import itertools
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from typing import Any

import networkx as nx
import numpy as np

from .. import _dask
from .._dask import Workers as _Workers
from ..errors import InputError, SolverError
from .search import (
    MAX_SEARCH_NODES,
    MAX_TREE_TOKENS,
    CostOutcome,
    CostPart,
    CostPartRun,
    PartRun,
    SearchOutcome,
    SearchPart,
    split_cost_part,
    split_part,
)

__all__ = ["COST_TASK_NODES", "LOCAL_NODES", "TASK_NODES", "active", "finish_cost_on_cluster",
           "finish_on_cluster", "searches_for", "searches_on"]

#: states a search expands in this process before it goes to the cluster (~0.1 s)
LOCAL_NODES = 500_000
#: states one task expands before it returns the rest of its part (~0.3–0.5 s)
TASK_NODES = 2_000_000
#: states one s* task expands before it returns the rest of its part (~0.3 s: ER(40, 0.8))
COST_TASK_NODES = 2_000_000
#: frames of a stopped part that become parts of their own (the bottom, shallowest ones)
SPLIT_SINGLES = 4
#: the least tree room a part is granted while running parts hold some (:meth:`_Tree.grant`)
MIN_GRANT = 1 << 16


class _Cluster:
    """A Dask client for the searches of one :func:`searches_on` block, opened on first
    use (a search that ends locally never starts a cluster) and closed with the block.

    The client is made in a daemon thread (an embedded LocalCluster takes 1–2 s to
    start on 2 cores), so a search with a deadline stops waiting for it at the deadline
    (:meth:`ready`); a block that ends while the start is still under way leaves it to
    that thread, which closes what it made as soon as it has it."""

    def __init__(self, scheduler: str | None, workers: int | None) -> None:
        self.scheduler, self.workers = scheduler, workers
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None
        self._made: dict[str, Any] = {}  # "context", or "error"; or "abandoned"
        self._client: Any = None

    def ready(self, deadline: float | None = None) -> bool:
        """Is the client made? Waits for it until ``deadline`` (perf_counter; none is
        started past it); the error that stopped it from being made is raised here."""
        if self._client is not None:
            return True
        if self._thread is None:
            if deadline is not None and time.perf_counter() >= deadline:
                return False
            self._thread = threading.Thread(target=self._make, name="rescon-cluster",
                                            daemon=True)
            self._thread.start()
        self._thread.join(None if deadline is None else max(deadline - time.perf_counter(), 0))
        with self._lock:
            if "error" in self._made:
                raise self._made["error"]
            context = self._made.get("context")
        if context is None:
            return False
        self._client = context.__enter__()  # in the caller's context (contextvars)
        return True

    def client(self) -> Any:
        """The client (made now if need be)."""
        self.ready()
        return self._client

    def _make(self) -> None:
        try:
            made = {"context": _dask.client(self.scheduler, self.workers)}
        except BaseException as exc:  # noqa: BLE001 (raised in the caller's thread)
            made = {"error": exc}
        with self._lock:
            if "abandoned" not in self._made:
                self._made = made
                return
        if "context" in made:
            made["context"].close()

    def close(self) -> None:
        with self._lock:
            made, self._made = self._made, {"abandoned": True}
        context, entered, self._client = made.get("context"), self._client is not None, None
        if context is not None and entered:
            context.__exit__(None, None, None)
        elif context is not None:
            context.close()


_ACTIVE: ContextVar[_Cluster | None] = ContextVar("rescon_search_cluster", default=None)


def active() -> _Cluster | None:
    """The cluster of the enclosing :func:`searches_on` block, if any."""
    return _ACTIVE.get()


@contextmanager
def searches_on(scheduler: str | None = None, workers: int | None = None) -> Iterator[None]:
    """Within the block, exact searches (decision and s*) that outlast ``LOCAL_NODES``
    states finish on Dask: the scheduler at address ``scheduler``, or an embedded
    LocalCluster of ``workers`` processes. Neither given, or ``workers=0``: nothing
    changes (serial).

    Raises InputError for both given or a bad count, MissingDependency without dask
    (checked on entry, not when a search first needs the cluster)."""
    workers = _dask.check_workers(scheduler, workers)
    if scheduler is None and not workers:
        yield
        return
    _dask.require()  # now, not mid-search
    cluster = _Cluster(scheduler, workers)
    if scheduler is not None:
        cluster.client()  # a bad address is refused on entry
    token = _ACTIVE.set(cluster)
    try:
        yield
    finally:
        _ACTIVE.reset(token)
        cluster.close()


def searches_for(G: Any, scheduler: str | None, workers: int | None) -> Any:
    """:func:`searches_on` for the searches on graph ``G``, refused (InputError) when G
    has more nodes than the bitmask search takes: nothing else splits."""
    if (scheduler is not None or workers) and isinstance(G, nx.Graph) and (
            G.number_of_nodes() > MAX_SEARCH_NODES):
        raise InputError(f"scheduler/workers: only the exact search (n ≤ {MAX_SEARCH_NODES}) "
                         f"runs on a cluster; got n = {G.number_of_nodes()}")
    return searches_on(scheduler, workers)


@dataclass(frozen=True)
class PartResult:
    """What a task returns: the kernel status, the part's tokens (None when not
    recorded), its states and refuted share, the witness after SAT, and the rest of
    the part (None when it finished)."""

    status: int
    tokens: np.ndarray | None
    nodes: int
    progress: float
    witness: tuple[frozenset[int], frozenset[int]] | None
    rest: SearchPart | None


def run_part(masks: tuple[np.ndarray, np.ndarray, np.ndarray], r: int, part: SearchPart,
             room: int, max_nodes: int) -> PartResult:
    """Run the decision kernel over ``part`` for at most ``max_nodes`` states, recording
    at most ``room`` tokens (0: none) and stopping when they are written (on a worker:
    numba and the compiled kernels load there on first use)."""
    from . import _kernels as K

    run = PartRun((K, *masks), r, part, room, keep=True)
    status = run.advance(max_nodes)
    return PartResult(status, run.tokens(), run.nodes, float(run.progress[0]),
                      run.witness() if status == K.SAT else None,
                      run.rest() if status in (K.RUNNING, K.NEED_ROOM) else None)


class _Tree:
    """The tree of a split search, assembled by the claim: each part's tokens, then
    its children's trees in order. Dropped (``record`` False) when it reaches
    MAX_TREE_TOKENS tokens, as the serial search drops its own (a full buffer drops the
    tree). ``granted``: the room held by running parts (module docstring, the tree's
    room)."""

    def __init__(self, record: bool) -> None:
        self.record = record
        self.tokens: dict[int, np.ndarray] = {}
        self.children: dict[int, list[int]] = {}
        self.granted: dict[int, int] = {}
        self.size = 0

    def add(self, pid: int, tokens: np.ndarray | None, children: list[int]) -> None:
        """Part ``pid`` has run: its tokens (None: not recorded) and its children's ids;
        the room it held comes back."""
        self.children[pid] = children
        self.granted.pop(pid, None)
        if not self.record:
            return
        if tokens is None or self.size + tokens.shape[0] >= MAX_TREE_TOKENS:
            self.record, self.tokens, self.granted = False, {}, {}
            return
        self.tokens[pid] = tokens
        self.size += tokens.shape[0]

    def room(self) -> int:
        """Tokens neither joined nor granted, below the cap (0: the tree is dropped;
        then no task ships tokens)."""
        return MAX_TREE_TOKENS - self.size - sum(self.granted.values()) if self.record else 0

    def grant(self, pid: int, waiting: int, cap: int) -> int | None:
        """The tokens part ``pid`` may record, one of ``waiting`` parts that want room
        now, in a task of at most ``cap`` states (a state writes at most one token): an
        equal share of the free room, but at least ``MIN_GRANT`` (fewer tasks), or all
        that is free when less; None while that is less than ``MIN_GRANT`` (and ``cap``)
        and running parts hold room, which they give back when they return. 0 once
        dropped. Never 0 while recording: with no room held, ``size`` < the cap."""
        if not self.record:
            return 0
        free = self.room()
        room = min(cap, max(free // waiting, min(free, MIN_GRANT)))
        if room < min(cap, MIN_GRANT) and self.granted:
            return None
        self.granted[pid] = room
        return room

    def assemble(self) -> tuple[int, ...] | None:
        """Preorder concatenation from part 0 (None when dropped)."""
        if not self.record:
            return None
        out: list[int] = []
        todo = [0]
        while todo:
            pid = todo.pop()
            out.extend(self.tokens[pid].tolist())
            todo.extend(reversed(self.children[pid]))
        return tuple(out)


def _result(fut: Any) -> PartResult:
    """A task's result; its failure (a worker died, a lost connection) in one line."""
    try:
        return fut.result()
    except Exception as exc:  # noqa: BLE001 (whatever the cluster raised)
        first = str(exc).splitlines()[0] if str(exc) else ""
        raise SolverError(f"a search task failed on the Dask cluster "
                          f"({type(exc).__name__}: {first})") from exc


def finish_on_cluster(
    cluster: _Cluster,
    run: PartRun,
    *,
    deadline: float | None = None,
    on_progress: Callable[[float, int], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> SearchOutcome:
    """Finish the decision search ``run`` (started in this process, not finished) on the
    cluster; the outcome is the serial search's, tree included (module docstring);
    after "not_robust" the witness is the first one a task found."""

    K = run.K
    order = tuple(run.order.tolist())
    r = run.r
    if deadline is not None and not cluster.ready(deadline):
        return SearchOutcome("stopped", r, order, None, None, run.nodes, float(run.progress[0]))
    client = cluster.client()
    workers = _Workers(client)
    masks = (run.inmask, run.outmask, run.order)
    tree = _Tree(run.record)
    nodes, progress = run.nodes, float(run.progress[0])
    running: dict[Any, int] = {}
    waiting: list[tuple[int, SearchPart]] = []  # parts waiting for tree room, in order

    ids = itertools.count(1)

    def share(pid: int, tokens: np.ndarray | None, rest: SearchPart | None) -> None:
        parts = [] if rest is None else split_part(rest, SPLIT_SINGLES)
        children = [next(ids) for _ in parts]
        tree.add(pid, tokens, children)
        waiting.extend(zip(children, parts, strict=True))
        while waiting:
            room = tree.grant(waiting[0][0], len(waiting), TASK_NODES)
            if room is None:  # a running part holds room (so ``running`` is not empty)
                return
            cid, part = waiting.pop(0)
            running[client.submit(run_part, masks, r, part, room, TASK_NODES,
                                  pure=False)] = cid

    try:
        share(0, run.tokens(), run.rest())
        while running:
            done = workers.finished(running)
            for fut in done:
                pid = running.pop(fut)
                res = _result(fut)
                nodes += res.nodes
                progress += res.progress
                if res.status == K.SAT:
                    return SearchOutcome("not_robust", r, order, res.witness, None, nodes, 1.0)
                share(pid, res.tokens, res.rest)
            if on_progress is not None:
                on_progress(progress, nodes)
            if (deadline is not None and time.perf_counter() > deadline) or (
                should_stop is not None and should_stop()
            ):
                return SearchOutcome("stopped", r, order, None, None, nodes, progress)
    finally:
        client.cancel(list(running))
    return SearchOutcome("robust", r, order, None, tree.assemble(), nodes, 1.0)


# --------------------------------------------------------------------------- #
# the s*(r) search
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class CostPartResult:
    """What an s* task returns: the incumbent after the part, the pair of that cost when
    the part found it (None: it found nothing cheaper than it was given), the sized
    tree's tokens (None when not recorded), states, refuted share and seconds, and the
    rest of the part (None when it finished)."""

    best: int
    pair: tuple[frozenset[int], frozenset[int]] | None
    tokens: np.ndarray | None
    nodes: int
    progress: float
    seconds: float
    rest: CostPart | None


def run_cost_part(masks: tuple[np.ndarray, np.ndarray, np.ndarray], engine: str, r: int,
                  lower: int, part: CostPart, best: int, room: int,
                  max_nodes: int) -> CostPartResult:
    """Run the s* ``engine`` over ``part`` below the incumbent ``best`` for at most
    ``max_nodes`` states, recording at most ``room`` tokens (0: none) and stopping when
    they are written (on a worker)."""
    from . import _kernels as K

    run = CostPartRun((K, *masks), engine, r, lower, part, best, room, keep=True)
    status = run.advance(max_nodes)
    return CostPartResult(run.best, run.pair(), run.recorded(), run.nodes, run.progress,
                          run.seconds,
                          run.rest() if status in (K.RUNNING, K.NEED_ROOM) else None)


class _Engine:
    """One s* engine's parts on the cluster: those waiting (a stack, the next in preorder
    on top), how many run, its tree (the sized engine's, recorded while it fits), its
    task seconds (its turns) and counts."""

    def __init__(self, run: CostPartRun) -> None:
        self.name, self.n = run.engine, run.inmask.shape[0]
        self.masks = (run.inmask, run.outmask, run.order)  # the engines' orders differ
        self.tree = _Tree(run.recording)
        self.waiting: list[tuple[int, CostPart]] = []
        self.running = 0
        self.seconds, self.nodes, self.progress = run.seconds, run.nodes, run.progress
        self._ids = itertools.count(1)
        self.share(0, run.recorded(), run.rest())

    def share(self, pid: int, tokens: np.ndarray | None, rest: CostPart | None) -> None:
        """Part ``pid`` has run: its tokens into the tree, its rest's parts to wait."""
        parts = [] if rest is None else split_cost_part(rest, SPLIT_SINGLES, self.n)
        children = [next(self._ids) for _ in parts]
        self.tree.add(pid, tokens, children)
        self.waiting.extend(reversed(list(zip(children, parts, strict=True))))

    def next_part(self, slots: int) -> tuple[int, CostPart, int] | None:
        """The next waiting part, its id and its tree room, ``slots`` parts able to start
        now; None when it must wait for room (:meth:`_Tree.grant`)."""
        pid, part = self.waiting[-1]
        room = self.tree.grant(pid, min(slots, len(self.waiting)), COST_TASK_NODES)
        if room is None:
            return None
        self.waiting.pop()
        self.running += 1
        return pid, part, room

    def take(self, res: CostPartResult) -> None:
        self.running -= 1
        self.nodes += res.nodes
        self.progress += res.progress
        self.seconds += res.seconds

    @property
    def finished(self) -> bool:
        return not self.waiting and not self.running


def _next_part(engines: list[_Engine], due: dict[str, float],
               slots: int) -> tuple[_Engine, tuple[int, CostPart, int]] | None:
    """The part to start next: of the engine furthest below its ``due`` share of the task
    seconds among those with a part that may start now (None: none has)."""
    for eng in sorted((e for e in engines if e.waiting), key=lambda e: e.seconds / due[e.name]):
        taken = eng.next_part(slots)
        if taken is not None:
            return eng, taken
    return None


def finish_cost_on_cluster(
    cluster: _Cluster,
    runs: list[CostPartRun],
    due: dict[str, float],
    best: int,
    pair: tuple[frozenset[int], frozenset[int]] | None,
    *,
    deadline: float | None = None,
    on_progress: Callable[[float, int], None] | None = None,
    should_stop: Callable[[], bool] | None = None,
) -> CostOutcome:
    """Finish the s* search of ``runs`` (both engines, started in this process below the
    incumbent ``best`` of ``pair``, neither finished) on the cluster: each engine's rest
    split into parts (module docstring), as many running as the cluster has threads;
    a free thread takes the next part of the engine furthest below its ``due`` share of
    the task seconds, with the incumbent as it is then. The first engine whose parts
    have all finished answers, as in search.min_cost_pair; so does a pair of cost
    ``lower``. Its ``best`` is the serial search's; the sized engine's tree, assembled
    from its parts, proves it."""

    first = runs[0]
    lower = first.lower
    order = tuple(first.order.tolist())
    if deadline is not None and not cluster.ready(deadline):
        return CostOutcome("stopped", best, pair, sum(run.nodes for run in runs), order)
    client = cluster.client()
    workers = _Workers(client)
    slots = max(sum(client.nthreads().values()), 1)
    engines = [_Engine(run) for run in runs]
    running: dict[Any, tuple[_Engine, int]] = {}
    found_by = ""  # the engine that found the incumbent (it answers when that is lower)

    def counts() -> tuple[float, int]:
        return max(e.progress for e in engines), sum(e.nodes for e in engines)

    try:
        while best > lower and not any(e.finished for e in engines):
            while len(running) < slots:
                taken = _next_part(engines, due, slots - len(running))
                if taken is None:
                    break
                eng, (pid, part, room) = taken
                running[client.submit(run_cost_part, eng.masks, eng.name, first.r, lower, part,
                                      best, room, COST_TASK_NODES, pure=False)] = (eng, pid)
            done = workers.finished(running)
            for fut in done:
                eng, pid = running.pop(fut)
                res = _result(fut)
                eng.take(res)
                if res.best < best:
                    best, pair, found_by = res.best, res.pair, eng.name
                eng.share(pid, res.tokens, res.rest)
            if on_progress is not None:
                on_progress(*counts())
            if (deadline is not None and time.perf_counter() > deadline) or (
                should_stop is not None and should_stop()
            ):
                return CostOutcome("stopped", best, pair, counts()[1], order)
    finally:
        client.cancel(list(running))
    winner = next((e for e in engines if e.finished), None)
    tree = winner.tree.assemble() if winner is not None and best > lower else None
    return CostOutcome("done", best, pair, counts()[1], order,
                       engine=found_by if winner is None else winner.name,
                       tree=None if winner is None or winner.name != "sized" else tree)
