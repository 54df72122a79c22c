"""The s*(r) search split into parts (graphs/distributed.py, "the s*(r) search") against
the serial search and brute force (benchmarks.baselines.leblanc_max_s): parts run in any
order, each below the incumbent known when it starts, give the serial s*, and the sized
parts' tokens assembled in preorder are a tree the certificate checker accepts. On a
LocalCluster of 2 worker processes on loopback, started here, with budgets shrunk so
that small searches are cut into many parts: the same s* as the serial search, checked
certificates, a failed task as one SolverError, deadlines and bounds that hold."""

from __future__ import annotations

import random
import time

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from benchmarks.baselines import leblanc_max_s
from certificates import cost_tree
from rescon.errors import SolverError
from rescon.graphs import _kernels as K
from rescon.graphs import bounds as bd
from rescon.graphs import distributed, search
from rescon.graphs.facts import clear_cache
from rescon.graphs.indexed import index_graph
from rescon.graphs.robustness import _deepening_search
from rescon.graphs.search import (
    CostPart,
    CostPartRun,
    min_cost_pair,
    split_cost_part,
    whole_cost_part,
)
from tests.test_robustness_exact import digraphs


def _replays(ig, r: int, s: int, order, tree) -> bool:
    """The stdlib checker's replay of a sized tree below cap s (raises on a fault)."""
    return cost_tree.replay([int(m) for m in search._mask_array(ig)], r, s,
                            [int(i) for i in order], list(tree), "tree")


def _split_run(ig, r: int, engine: str, budgets, rng: random.Random, singles: int,
               record: bool = True):
    """One engine's search run as parts, the next part to run drawn at random (as tasks
    finish on a cluster in any order), each below the incumbent of that moment; the
    sized tokens assembled in preorder (distributed._Tree) when ``record`` (else the
    sized search prunes non-maximal pairs too). Returns (best, pair, tree)."""
    masks = search._kernel_inputs(ig)[1:]
    best, pair = ig.n, None
    tree = distributed._Tree(engine == "sized" and record)
    waiting = [(0, whole_cost_part(ig.n))]
    ids = iter(range(1, 10**9))
    while waiting and best > 0:
        pid, part = waiting.pop(rng.randrange(len(waiting)))
        res = distributed.run_cost_part(masks, engine, r, 0, part, best, tree.room(),
                                        next(budgets))
        if res.best < best:
            best, pair = res.best, res.pair
        parts = [] if res.rest is None else split_cost_part(res.rest, singles, ig.n)
        children = [next(ids) for _ in parts]
        tree.add(pid, res.tokens, children)
        waiting += list(zip(children, parts, strict=True))
    return best, pair, tree.assemble() if best > 0 else None


@settings(max_examples=60, deadline=None)
@given(digraphs(max_n=10), st.lists(st.integers(1, 30), min_size=1, max_size=6),
       st.integers(0, 3), st.randoms(use_true_random=False), st.booleans())
def test_cost_parts_in_any_order_give_the_serial_s_star(G, budgets, singles, rng, record):
    """The claim (s*) of graphs/distributed.py, both engines: s*(r) is brute force's, the
    pair costs s*, and the sized tree assembled from the parts replays below cap s*."""
    ig = index_graph(G)
    cycle = iter(budgets * 100_000)
    for r in range(1, (ig.n + 1) // 2 + 2):
        truth = leblanc_max_s(G, r)
        for engine in search.COST_ENGINES:
            best, pair, tree = _split_run(ig, r, engine, cycle, rng, singles, record)
            assert best == truth
            if pair is not None:
                assert bd.pair_cost(ig, bd.Pair(*pair), r) == best
            if engine == "sized" and record and best > 0:
                assert _replays(ig, r, best, search.search_order(ig), tree)


@pytest.mark.parametrize("seed", range(4))
def test_dense_cost_parts_give_the_serial_s_star(seed):
    """Dense digraphs (p = 0.8-0.95, n = 12-16), where the sized search wins."""
    rng = random.Random(seed)
    G = nx.gnp_random_graph(rng.randint(12, 16), rng.choice([0.8, 0.9, 0.95]), seed=seed,
                            directed=True)
    ig = index_graph(G)
    budgets = iter([rng.randint(20, 400) for _ in range(100)] * 100_000)
    for r in range(2, (ig.n + 1) // 2 + 1):
        truth = leblanc_max_s(G, r)
        best, _, tree = _split_run(ig, r, "sized", budgets, rng, 2)
        assert best == truth == min_cost_pair(ig, r, ig.n).best
        if best > 0:
            assert _replays(ig, r, best, search.search_order(ig), tree)


def test_split_cost_part_keeps_the_order_and_every_frame():
    """Top frames together, the bottom two alone (upper first), the rest of the root's
    size combinations, then the later roots."""
    ig = index_graph(nx.gnp_random_graph(14, 0.8, seed=3, directed=True))
    run = CostPartRun(search._kernel_inputs(ig), "sized", 5, 0, whole_cost_part(ig.n), ig.n)
    assert run.advance(100) == K.RUNNING
    rest = run.rest()
    k = rest.frames.shape[0]
    assert k >= 3 and rest.s1 >= 1 and not rest.alone
    parts = split_cost_part(rest, 2, ig.n)
    assert [p.frames.shape[0] for p in parts] == [k - 2, 1, 1, 0, 0]
    assert (parts[1].frames == rest.frames[1:2]).all()
    assert (parts[2].frames == rest.frames[:1]).all()
    assert [p.alone for p in parts] == [True, True, True, False, False]
    assert [(p.s1, p.s2) for p in parts[:4]] == [(rest.s1, rest.s2)] * 4
    assert [(p.root, p.end) for p in parts] == [(rest.root, rest.root)] * 4 + [
        (rest.root, ig.n)]
    assert parts[4].s1 == 0  # no root started
    # an alone part's rest splits into frames only
    alone = CostPartRun(search._kernel_inputs(ig), "sized", 5, 0, parts[0], ig.n)
    if alone.advance(3) == K.RUNNING:
        assert all(p.alone for p in split_cost_part(alone.rest(), 2, ig.n))


def test_split_part_makes_only_the_bottom_frames_parts_of_their_own():
    """The decision search's split (search.split_part) as documented: the frames above
    the ``singles`` bottom ones together. It made every frame below the top ``singles``
    a part of its own (9 frames, singles = 2: 8 parts instead of 3)."""
    ig = index_graph(nx.gnp_random_graph(50, 0.5, seed=50000, directed=True))
    run = search.PartRun(search._kernel_inputs(ig), 13, search.whole_part(ig.n), 0)
    steps = 100  # (G(22, 0.7), r = 8 ends too soon since the capped prune)
    while run.advance(steps) == K.RUNNING and run.rest().frames.shape[0] < 6:
        steps += 100
    rest = run.rest()
    k = rest.frames.shape[0]
    assert k >= 6
    parts = search.split_part(rest, 2)
    assert [p.frames.shape[0] for p in parts] == [k - 2, 1, 1, 0]
    assert (parts[1].frames == rest.frames[1:2]).all()
    assert (parts[2].frames == rest.frames[:1]).all()


# ---------------------------------------------------------------- on a Dask cluster


@pytest.fixture
def tiny_parts(monkeypatch):
    """Searches go to the cluster after 50 states, in tasks of 300."""
    monkeypatch.setattr(search, "_SLICE", 50)
    monkeypatch.setattr(distributed, "LOCAL_NODES", 50)
    monkeypatch.setattr(distributed, "COST_TASK_NODES", 300)


@pytest.mark.slow
def test_split_s_star_on_the_cluster_is_the_serial_s_star(cluster, tiny_parts):
    """Sparse to dense digraphs, n = 13-16, both engines favoured: s*(r) is brute force's,
    and every recorded tree replays below cap s*."""
    trees, most = 0, 0
    for seed, (n, p) in enumerate([(13, 0.5), (14, 0.7), (15, 0.8), (16, 0.9)]):
        G = nx.gnp_random_graph(n, p, seed=seed, directed=True)
        ig = index_graph(G)
        for r in range(1, (n + 1) // 2 + 1):
            truth = leblanc_max_s(G, r)
            for favour in search.COST_ENGINES:
                with distributed.searches_on(scheduler=cluster):
                    out = min_cost_pair(ig, r, n, favour=favour)
                assert (out.status, out.best) == ("done", truth)
                if out.pair is not None:
                    assert bd.pair_cost(ig, bd.Pair(*out.pair), r) == truth
                if out.tree is not None:
                    trees += 1
                    assert out.engine == "sized" and _replays(ig, r, truth, out.order, out.tree)
                most = max(most, out.nodes)
    assert trees >= 10 and most > 3000  # > 10 tasks of 300 states


@pytest.mark.slow
@pytest.mark.parametrize(("n", "p", "seed"), [(20, 0.8, 0), (20, 0.9, 3)])
def test_public_api_on_the_cluster_writes_a_checked_s_star_certificate(cluster, tiny_parts,
                                                                       n, p, seed,
                                                                       monkeypatch):
    """rescon.robustness with method "search" on the cluster (s*(ρ) = 4, 7): the
    serial ρ and s*(ρ), brute force's, and a certificate the checker verifies, whose s*
    proof is the sized tree assembled from the parts."""
    G = nx.gnp_random_graph(n, p, seed=seed, directed=True)
    clear_cache()
    serial = rescon.robustness(G, method="search")
    split_trees = []
    finish = distributed.finish_cost_on_cluster

    def spy(*args, **kwargs):
        out = finish(*args, **kwargs)
        split_trees.append(out.tree)
        return out

    monkeypatch.setattr(distributed, "finish_cost_on_cluster", spy)
    clear_cache()
    split = rescon.robustness(G, method="search", scheduler=cluster)
    assert (split.r_max, split.s_max, split.exact) == (serial.r_max, serial.s_max, True)
    assert split.s_max == leblanc_max_s(G, split.r_max) >= 2
    proof = split.certificate["lower_s"]
    assert proof["method"] == "cost_search" and list(proof["tree"]) in [
        list(t) for t in split_trees if t is not None]
    verdict = rescon.check_certificate(split.certificate)
    assert verdict.valid, verdict.reason
    clear_cache()
    assert rescon.max_s(G, split.r_max, method="search", scheduler=cluster) == split.s_max


def test_a_failed_s_star_task_is_a_one_line_solver_error(cluster):
    """A task that raises on its worker (here: a pending frame of the wrong width)."""
    ig = index_graph(nx.gnp_random_graph(16, 0.8, seed=0, directed=True))
    inputs = search._kernel_inputs(ig)
    runs = [CostPartRun(inputs, e, 4, 0, whole_cost_part(ig.n), ig.n)
            for e in search.COST_ENGINES]
    for run in runs:
        assert run.advance(30) == K.RUNNING
        run.rest = lambda: CostPart(np.zeros((1, K.COST_STACK_WIDTH - 1), dtype=np.uint64),
                                    np.zeros(1, dtype=np.int64), 1, 1, alone=True)
    with distributed.searches_on(scheduler=cluster), pytest.raises(SolverError) as info:
        distributed.finish_cost_on_cluster(distributed.active(), runs, search._dues(None),
                                           ig.n, None)
    assert "failed on the Dask cluster" in str(info.value) and "\n" not in str(info.value)


@pytest.mark.slow
def test_a_deadline_stops_the_split_s_star_search_with_bounds_on_the_truth(cluster):
    """ER(40, 0.8), r = 16: s* = 10 (the serial search: ~4 s, 26M states). Stopped after
    1 s on the cluster, the bounds hold s* = 10."""
    ig = index_graph(nx.gnp_random_graph(40, 0.8, seed=40000, directed=True))
    t0 = time.perf_counter()
    with distributed.searches_on(scheduler=cluster):
        out = _deepening_search(ig, 16, 1, 12, t0 + 1.0)
    assert time.perf_counter() - t0 < 5
    assert out.status == "stopped" and out.floor <= 10 <= out.best


@pytest.mark.slow
def test_a_time_limited_max_s_on_the_cluster_gives_bounds_on_the_truth(cluster):
    """The public API, 2 s for s*(16) = 10 on ER(40, 0.8) (13 s on the cluster): the
    proven bounds in the error hold the truth, and the limit is kept."""
    import re

    G = nx.gnp_random_graph(40, 0.8, seed=40000, directed=True)
    clear_cache()
    t0 = time.perf_counter()
    with pytest.raises(rescon.TimeLimitReached) as info:
        rescon.max_s(G, 16, time_limit=2.0, scheduler=cluster)
    assert time.perf_counter() - t0 < 5
    low, high = map(int, re.search(r"(\d+) ≤ s\*\(16\) ≤ (\d+)", str(info.value)).groups())
    assert low <= 10 <= high


def test_a_search_that_ends_locally_starts_no_cluster():
    ig = index_graph(nx.gnp_random_graph(12, 0.8, seed=1, directed=True))
    with distributed.searches_on(workers=2):
        out = min_cost_pair(ig, 3, ig.n)
        assert distributed.active()._client is None
    G = nx.gnp_random_graph(12, 0.8, seed=1, directed=True)
    assert out.best == leblanc_max_s(G, 3) and out.tree is not None
