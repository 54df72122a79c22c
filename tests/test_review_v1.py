"""Review V1: hostile checks of the charged-tree s* certificates and the dense-robustness
changes (compiled tabu walks, the sized search in the ρ race, the forced charged path),
all against brute force on small digraphs. Each is a regression guard for an attack
that held in the review's long fuzzing runs."""

from __future__ import annotations

import random
import time

import networkx as nx
import numpy as np
import pytest

import rescon
from benchmarks.baselines import leblanc_max_s, leblanc_rho
from rescon.graphs import bounds as bd
from rescon.graphs import robustness as rb
from rescon.graphs._kernels import pair_walk
from rescon.graphs.charged import charged_order, charged_tree
from rescon.graphs.facts import clear_cache
from rescon.graphs.indexed import index_graph
from rescon.graphs.search import SearchOutcome, SizedRun, cost_tree
from tests.test_checker import C, digraph, in_masks, is_robust, rand_edges, rho_and_s

pytestmark = pytest.mark.usefixtures("fresh_facts")


_graph = digraph


def _cert(n, edges, r, s, order, tree, key="charged_tree"):
    return {"rescon_certificate": 1, "kind": "rs_robust",
            "graph": {"n": n, "nodes": list(range(n)), "edges": [list(e) for e in edges]},
            "r": r, "s": s, "proof": {"method": "cost_search", "order": order, key: list(tree)}}


def _end(tree, k):
    """End (exclusive) of the subtree whose token is tree[k] (a branch has two children)."""
    need = 1
    while need:
        need += 1 if tree[k] >= 0 else -1
        k += 1
    return k


def _surgeries(tree):
    """Every branch cut to each leaf kind, every branch with its children swapped, and
    each of the first 6 leaves turned into each other kind (the capped one on node 0:
    -5)."""
    for k in [k for k, t in enumerate(tree) if t < 0][:6]:
        yield from (tree[:k] + [leaf] + tree[k + 1:] for leaf in (-1, -2, -3, -4, -5)
                    if leaf != tree[k])
    for k, t in enumerate(tree):
        if t < 0:
            continue
        end, mid = _end(tree, k), _end(tree, k + 1)
        for leaf in (-1, -2, -3, -4):
            yield tree[:k] + [leaf] + tree[end:]
        yield tree[:k + 1] + tree[mid:end] + tree[k + 1:mid] + tree[end:]


@pytest.mark.parametrize("seed, n, p", [(3, 7, 0.75), (13, 7, 0.75), (19, 6, 0.6)])
def test_surgery_on_charged_trees_never_proves_a_false_claim(seed, n, p):
    """Cut subtrees and swapped children of the trees below s*(r), claimed for s*(r) and
    s*(r) + 1 and on the graph minus an arc: whatever the checker accepts is true."""
    edges = rand_edges(random.Random(seed), n, p)
    ig = index_graph(_graph(n, edges))
    order = charged_order(ig).tolist()
    rho, _ = rho_and_s(n, in_masks(n, edges))
    fewer = edges[1:]
    accepted = rejected = 0
    for r in range(1, rho + 1):
        s_star = max(s for s in range(1, n + 1) if is_robust(n, in_masks(n, edges), r, s))
        tree = list(charged_tree(ig, r, s_star))
        for bad in _surgeries(tree):
            for graph, s in ((edges, s_star), (edges, min(s_star + 1, n)), (fewer, s_star)):
                if C.check(_cert(n, graph, r, s, order, bad)).verdict == "valid":
                    assert is_robust(n, in_masks(n, graph), r, s)
                    accepted += 1
                else:
                    rejected += 1
    assert rejected > accepted


@pytest.mark.parametrize("n, steps, r, s", [(64, [1, 2], 2, 2), (63, [1, 2], 1, 2),
                                            (64, [1, 5, 9], 3, 1)])
def test_charged_trees_at_the_64_node_limit_are_replayed(n, steps, r, s):
    """The kernel's uint64 sets at n = 63, 64 (all bits used): the recorded tree is valid,
    the same tree for r + 1 is not (circulants are not (r + 1, s)-robust here)."""
    G = nx.circulant_graph(n, steps).to_directed()
    ig = index_graph(G)
    tree = charged_tree(ig, r, s)
    assert tree is not None
    edges, order = ig.edges(), charged_order(ig).tolist()
    assert C.check(_cert(n, edges, r, s, order, tree)).verdict == "valid"
    assert C.check(_cert(n, edges, r + 1, s, order, tree)).verdict == "invalid"


@pytest.mark.parametrize("seed", range(6))
def test_sized_tree_survives_a_growing_token_buffer(seed):
    """SizedRun resumed one state at a time from a 1-token buffer (NEED_ROOM on every
    token) records the tree cost_tree records in one go, and the checker accepts it."""
    rng = random.Random(seed)
    n = rng.randint(7, 11)
    G = nx.gnp_random_graph(n, rng.choice([0.6, 0.8, 0.9]), directed=True, seed=seed)
    ig = index_graph(G)
    r = max(1, leblanc_rho(G))
    s = min(2, leblanc_max_s(G, r)) or 1
    run = SizedRun(ig, r, s)
    run.tokens = np.empty(1, dtype=np.int32)
    while not run.finished:
        run.advance(1)
    assert (run.pair() is None) == (leblanc_max_s(G, r) >= s)
    if run.pair() is None:
        assert run.tree() == cost_tree(ig, r, s)
        cert = _cert(n, ig.edges(), r, s, run.order.tolist(), run.tree(), key="tree")
        assert C.check(cert).verdict == "valid"


def test_tabu_walk_costs_are_exact_pair_costs():
    """pair_walk's reported cost is bd.pair_cost of the pair it leaves in ``lab`` (or > n:
    none), never below the brute-force s*(r); tabu_pairs improves strictly."""
    rng = random.Random(5)
    for seed in range(25):
        n = rng.randint(4, 11)
        G = nx.gnp_random_graph(n, rng.choice([0.4, 0.7, 0.9]), directed=True, seed=seed)
        ig = index_graph(G)
        out = bd._out_lists(ig)
        outptr = np.cumsum([0] + [len(o) for o in out], dtype=np.int64)
        outidx = np.array([w for o in out for w in o], dtype=np.int64)
        deg = np.array(ig.in_degrees, dtype=np.int64)
        for r in range(n + 1):
            truth = leblanc_max_s(G, r)
            lab = np.array([rng.randrange(3) for _ in range(n)], dtype=np.int8)
            cost = int(pair_walk(deg, outptr, outidx, r, lab, 50, 3, 0, seed))
            if cost <= n:
                pair = bd.Pair(frozenset(np.flatnonzero(lab == 1).tolist()),
                               frozenset(np.flatnonzero(lab == 2).tolist()))
                assert bd.pair_cost(ig, pair, r) == cost >= min(truth, n)
            costs = [bd.pair_cost(ig, p, r) for p in bd.tabu_pairs(ig, r, draws=20, seed=seed)]
            assert all(c is not None for c in costs)
            assert costs == sorted(set(costs), reverse=True)


def _forced(monkeypatch, charged):
    """No DP, every proof made replayable; with ``charged``, no sized tree either."""
    monkeypatch.setattr(rb, "DP_AUTO_NODES", 0)
    monkeypatch.setattr(rb, "MAX_ENUM_N", 0)
    if charged:
        monkeypatch.setattr(rb, "cost_tree", lambda *a, **k: None)


@pytest.mark.parametrize("charged", [False, True])
def test_forced_replayable_paths_match_brute_force(monkeypatch, charged):
    """robustness, max_s and is_rs_robust through the s* race and the replayed trees
    (sized or charged) agree with brute force; their certificates are valid."""
    _forced(monkeypatch, charged)
    rng = random.Random(17)
    kinds = set()
    for _ in range(6):
        n = rng.randint(5, 9)
        G = _graph(n, rand_edges(rng, n, rng.choice([0.5, 0.7, 0.9]), rng.random() < 0.3))
        rho = leblanc_rho(G)
        rep = rescon.robustness(G, method=rng.choice(["auto", "search"]))
        assert (rep.r_max, rep.s_max) == (rho, leblanc_max_s(G, rho))
        assert rescon.check_certificate(rep.certificate).verdict == "valid"
        kinds.update(k for k in ("tree", "charged_tree") if k in (rep.certificate["lower_s"] or {}))
        for r in (1, rho, rho + 1):
            clear_cache()
            assert rescon.max_s(G, r) == leblanc_max_s(G, r)
            s = rng.randint(1, n)
            check = rescon.is_rs_robust(G, r, s)
            assert check.holds == (leblanc_max_s(G, r) >= s)
            assert rescon.check_certificate(check.certificate).verdict == "valid"
    assert ("charged_tree" if charged else "tree") in kinds


def test_sized_search_decides_the_race(monkeypatch):
    """The decision search yields every turn to the sized search (cap 1) until it
    finishes: ρ and s* still match brute force, and the sized tree is a valid proof."""
    _forced(monkeypatch, False)
    real = rb.decide_r_robust

    def yielding(ig, r, *, deadline=None, on_progress=None, should_stop=None, **kw):
        if should_stop is None:
            return real(ig, r, deadline=deadline, on_progress=on_progress, **kw)
        while not should_stop():
            time.sleep(0)
        return SearchOutcome("stopped", r, (), None, None, 0, 0.0)

    decided = []
    monkeypatch.setattr(rb, "decide_r_robust", yielding)
    monkeypatch.setattr(rb, "_walked_witness", lambda *a, **k: None)
    monkeypatch.setattr(rb, "_searched_seed_construction", lambda *a, **k: None)
    monkeypatch.setattr(rb, "_sized_decision",
                        lambda *a, real=rb._sized_decision: decided.append(1) or real(*a))
    rng = random.Random(29)
    for _ in range(10):
        n = rng.randint(5, 11)
        G = _graph(n, rand_edges(rng, n, rng.choice([0.6, 0.8, 0.95])))
        rho = leblanc_rho(G)
        rep = rescon.robustness(G)
        assert (rep.r_max, rep.s_max) == (rho, leblanc_max_s(G, rho))
        assert rescon.check_certificate(rep.certificate).verdict == "valid"
    assert decided
