"""The split searches' tree room (graphs/distributed.py, "the tree's room"): each part
records at most the tokens it is granted and stops there, the grants and the joined
tokens never pass the cap together. So the split search keeps the serial tree exactly
when the serial search keeps it (then with the serial state count), and its parts write
at most ``MAX_TREE_TOKENS`` tokens in all, as the serial search does — before, every part
in flight was given the whole remaining room and recorded (without the forced-candidate
rule) until the joined tree overflowed.

The parts run here in this process, finishing in an order drawn at random (as tasks do
on a cluster), and on a LocalCluster of 2 worker processes on loopback."""

from __future__ import annotations

import itertools
import random

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from benchmarks.baselines import leblanc_rho
from rescon.graphs import bounds as bd
from rescon.graphs import distributed, search
from rescon.graphs import robustness as rob
from rescon.graphs.charged import charged_tree, uniform_excluded, uniform_tree
from rescon.graphs.facts import clear_cache, facts_for
from rescon.graphs.indexed import index_graph
from rescon.graphs.search import CostPartRun, cost_tree, decide_r_robust, whole_cost_part
from tests.test_robustness_exact import digraphs


class _Future:
    """A task of :class:`_InProcess`: it runs when its result is asked for."""

    def __init__(self, fn, args) -> None:
        self.fn, self.args = fn, args

    def result(self):
        return self.fn(*self.args)


class _InProcess:
    """Stands for the Dask client and cluster: tasks run in this process."""

    def client(self):
        return self

    def submit(self, fn, *args, pure: bool):
        return _Future(fn, args)

    def cancel(self, futures) -> None:
        pass

    def nthreads(self) -> dict[str, int]:
        return {"a": 1, "b": 1}


def _count_shipped(mp) -> dict[str, int]:
    """Counts, from now on, the tokens every part ships to its tree (the states it
    expanded recording) and the parts that ship none (None) while the tree records."""
    seen = {"tokens": 0, "none": 0}
    add = distributed._Tree.add

    def spy(self, pid, tokens, children):
        if tokens is not None:
            seen["tokens"] += tokens.shape[0]
        elif self.record:
            seen["none"] += 1
        add(self, pid, tokens, children)

    mp.setattr(distributed._Tree, "add", spy)
    return seen


@pytest.fixture
def shipped(monkeypatch):
    return _count_shipped(monkeypatch)


def _caps(monkeypatch, cap: int, task: int, grant: int) -> None:
    monkeypatch.setattr(search, "MAX_TREE_TOKENS", cap)
    monkeypatch.setattr(distributed, "MAX_TREE_TOKENS", cap)
    monkeypatch.setattr(search, "_SLICE", 20)
    monkeypatch.setattr(distributed, "LOCAL_NODES", 20)
    monkeypatch.setattr(distributed, "TASK_NODES", task)
    monkeypatch.setattr(distributed, "COST_TASK_NODES", task)
    monkeypatch.setattr(distributed, "MIN_GRANT", grant)


def _in_process(monkeypatch, rng: random.Random):
    """Tasks finish one at a time, drawn at random among those submitted."""
    monkeypatch.setattr(distributed._Workers, "finished",
                        lambda self, running: {rng.choice(list(running))})


def _split_decision(ig, r: int):
    token = distributed._ACTIVE.set(_InProcess())
    try:
        return decide_r_robust(ig, r)
    finally:
        distributed._ACTIVE.reset(token)


def _dense_digraphs(max_n: int):
    return st.builds(lambda n, p, seed: nx.gnp_random_graph(n, p, seed=seed, directed=True),
                     st.integers(8, max_n), st.sampled_from([0.5, 0.7, 0.8, 0.9]),
                     st.integers(0, 10**6))


@settings(max_examples=80, deadline=None)
@given(st.one_of(digraphs(max_n=12), _dense_digraphs(18)), st.integers(1, 400),
       st.integers(1, 60), st.integers(1, 50), st.randoms(use_true_random=False))
def test_split_decision_keeps_the_serial_tree_and_records_no_more(G, cap, task, grant, rng):
    """Every r: the serial answer; the serial tree (None iff the serial search dropped
    it) and, when kept, the serial state count; the parts ship at most ``cap`` tokens
    in all, and no part given room drops its own."""
    ig = index_graph(G)
    with pytest.MonkeyPatch.context() as mp:
        _caps(mp, cap, task, grant)
        _in_process(mp, rng)
        shipped = _count_shipped(mp)
        for r in range(1, (ig.n + 1) // 2 + 2):
            serial = decide_r_robust(ig, r)
            split = _split_decision(ig, r)
            assert split.status == serial.status
            if serial.status == "robust":
                assert split.tree == serial.tree
                if serial.tree is not None:
                    assert split.nodes == serial.nodes
            else:
                assert split.witness is not None
            assert shipped["tokens"] <= cap and shipped["none"] == 0
            shipped["tokens"] = 0


def _s_star(ig, r: int) -> int:
    """s*(r) by the serial search (n: no pair)."""
    return search.min_cost_pair(ig, r, ig.n).best


def _split_sized(ig, r: int, s: int, cluster):
    """The sized search below cap s split on ``cluster``, alone (no charged engine):
    (its tree or None, its states)."""
    inputs = search._kernel_inputs(ig)
    run = CostPartRun(inputs, "sized", r, -1, whole_cost_part(ig.n), s,
                      search.MAX_TREE_TOKENS)
    run.advance(distributed.LOCAL_NODES)
    if run.finished:
        return run.tree(), run.nodes
    out = distributed.finish_cost_on_cluster(cluster, [run], {"sized": 1.0}, s, None)
    assert (out.status, out.best, out.engine) == ("done", s, "sized")
    return out.tree, out.nodes


def _serial_sized(ig, r: int, s: int):
    run = search.SizedRun(ig, r, s, max_tokens=search.MAX_TREE_TOKENS)
    while run.advance(1000) == run.K.RUNNING:
        pass
    return run.tree(), run.nodes


@settings(max_examples=60, deadline=None)
@given(_dense_digraphs(13), st.integers(1, 60), st.integers(1, 50),
       st.randoms(use_true_random=False), st.data())
def test_split_sized_search_keeps_the_serial_tree_and_records_no_more(G, task, grant, rng,
                                                                      data):
    """The sized s* search below cap s*(r) (the incumbent never falls, so every part
    prunes as the serial search): the serial tree, None iff the serial search dropped it,
    with the serial state count when kept; the parts ship at most the cap in tokens."""
    ig = index_graph(G)
    r = data.draw(st.integers(1, (ig.n + 1) // 2))
    s = _s_star(ig, r)
    full, _ = _serial_sized(ig, r, s)
    cap = data.draw(st.integers(max(1, len(full) - 3), len(full) + 3) | st.integers(1, 400))
    with pytest.MonkeyPatch.context() as mp:
        _caps(mp, cap, task, grant)
        _in_process(mp, rng)
        shipped = _count_shipped(mp)
        serial, serial_nodes = _serial_sized(ig, r, s)
        assert (serial is not None) == (len(full) < cap)
        split, nodes = _split_sized(ig, r, s, _InProcess())
    assert split == serial and shipped["tokens"] <= cap and shipped["none"] == 0
    if serial is not None:
        assert nodes == serial_nodes


def test_split_sized_search_keeps_a_tree_one_token_below_the_cap():
    """A tree of cap − 1 tokens is kept, as by the serial search: each part used to be
    given one token less than the free room, and a part filling it dropped the tree
    (in 31 of these 120 runs)."""
    for seed in range(10):
        ig = index_graph(nx.gnp_random_graph(12, 0.8, seed=seed, directed=True))
        for r in range(2, 6):
            s = _s_star(ig, r)
            full = cost_tree(ig, r, s)
            for task in (7, 30, 200):
                with pytest.MonkeyPatch.context() as mp:
                    _caps(mp, len(full) + 1, task, 5)
                    _in_process(mp, random.Random(seed))
                    assert _split_sized(ig, r, s, _InProcess())[0] == full


def test_a_grant_waits_only_while_running_parts_hold_room(monkeypatch):
    """:meth:`distributed._Tree.grant`: an equal share of the free room, at least
    MIN_GRANT; a smaller share waits while another part holds room, else takes what is
    free; 0 once the tree is dropped; the room comes back when the part returns."""
    monkeypatch.setattr(distributed, "MAX_TREE_TOKENS", 1000)
    monkeypatch.setattr(distributed, "MIN_GRANT", 100)
    tree = distributed._Tree(True)
    assert tree.grant(1, 4, 10_000) == 250 and tree.grant(2, 3, 10_000) == 250
    assert tree.grant(3, 2, 120) == 120 and tree.room() == 380
    assert tree.grant(4, 10, 10_000) == 100  # 380 // 10 < MIN_GRANT
    assert tree.grant(5, 10, 10_000) == 100 and tree.grant(6, 10, 10_000) == 100
    assert tree.grant(7, 1, 10_000) is None  # 80 free < MIN_GRANT, parts hold room
    for pid in (1, 2, 3, 4, 5, 6):
        tree.add(pid, _tokens(1), [])
    assert tree.room() == 994 and tree.grant(7, 1, 10_000) == 994
    tree.add(7, _tokens(994), [])  # the cap reached: dropped
    assert not tree.record and tree.grant(8, 1, 10_000) == 0 and tree.assemble() is None


def _tokens(k: int) -> np.ndarray:
    return np.zeros(k, dtype=np.int32)


# ---------------------------------------------------------------- on a Dask cluster


@pytest.mark.slow
@pytest.mark.parametrize(("n", "p", "seed", "r"), [(22, 0.7, 0, 8), (24, 0.8, 1, 9)])
def test_split_on_the_cluster_keeps_the_serial_tree_and_records_no_more(cluster, monkeypatch,
                                                                       shipped, n, p, seed,
                                                                       r):
    """Dense digraphs, caps below, at and above the serial tree's size: the serial
    answer and tree (kept iff the serial search keeps it; then the serial states); the
    parts ship at most the cap in tokens."""
    ig = index_graph(nx.gnp_random_graph(n, p, seed=seed, directed=True))
    full = decide_r_robust(ig, r)
    assert full.status == "robust" and len(full.tree) > 20_000
    for cap in (len(full.tree) // 3, len(full.tree), len(full.tree) + 1):
        _caps(monkeypatch, cap, 2000, 500)
        serial = decide_r_robust(ig, r)
        shipped["tokens"] = 0
        with distributed.searches_on(scheduler=cluster):
            split = decide_r_robust(ig, r)
        assert (split.status, split.tree) == ("robust", serial.tree)
        assert (serial.tree is not None) == (cap > len(full.tree))
        if serial.tree is not None:
            assert split.nodes == serial.nodes
        assert shipped["tokens"] <= cap and shipped["none"] == 0


@pytest.mark.slow
def test_split_sized_search_on_the_cluster_keeps_a_tree_one_below_the_cap(cluster,
                                                                          monkeypatch):
    """The sized s* search split on the cluster keeps a tree of cap − 1 tokens, as the
    serial search does (a part was given one token less than the free room, so the
    split dropped it), and drops one of cap tokens."""
    ig = index_graph(nx.gnp_random_graph(20, 0.8, seed=2, directed=True))
    r = 8
    s = _s_star(ig, r)
    full = cost_tree(ig, r, s)
    assert full is not None and len(full) > 4000
    for cap in (len(full) + 1, len(full)):
        _caps(monkeypatch, cap, 300, 100)
        with distributed.searches_on(scheduler=cluster):
            split, _ = _split_sized(ig, r, s, distributed.active())
        assert split == (full if cap > len(full) else None)


# ---------------------------------------------------------------- the uniform attempt


def _all_pairs(n: int):
    """Every pair of disjoint nonempty node sets of range(n), each unordered pair once
    per order."""
    for labels in itertools.product(range(3), repeat=n):
        S1 = frozenset(i for i in range(n) if labels[i] == 1)
        S2 = frozenset(i for i in range(n) if labels[i] == 2)
        if S1 and S2:
            yield bd.Pair(S1, S2)


@settings(max_examples=40, deadline=None)
@given(digraphs(max_n=6), st.integers(1, 4), st.integers(2, 6))
def test_a_pair_excluding_the_uniform_tree_means_it_has_none(G, r, s):
    """charged.uniform_excluded against the uniform tree itself, pair by pair (every
    pair of disjoint sets of a small digraph): a pair that excludes it means no tree."""
    ig = index_graph(G)
    excluding = [p for p in _all_pairs(ig.n) if uniform_excluded(ig, r, s, [p])]
    assert not excluding or uniform_tree(ig, r, s) is None


@settings(max_examples=40, deadline=None)
@given(digraphs(max_n=9))
def test_at_rho_the_refuting_pair_excludes_the_uniform_tree_of_every_s_from_3(G):
    ig = index_graph(G)
    rho = leblanc_rho(G)
    if rho < 1:
        return
    refuted = decide_r_robust(ig, rho + 1)
    assert refuted.status == "not_robust"
    pair = bd.Pair(*refuted.witness)
    for s in range(2, 7):
        assert uniform_excluded(ig, rho, s, [pair]) == (s >= 3)
        assert s == 2 or uniform_tree(ig, rho, s) is None


def test_the_charged_proof_skips_an_excluded_uniform_tree(monkeypatch):
    """robustness._charged with the pair that refuted (ρ + 1)-robustness among the facts
    records the configurations' tree without trying the uniform one (it was tried first,
    always, though it cannot exist)."""
    G = nx.gnp_random_graph(14, 0.5, seed=3, directed=True)
    ig = index_graph(G)
    clear_cache()
    rho = leblanc_rho(G)
    s = search.min_cost_pair(ig, rho, ig.n).best
    assert s >= 3
    facts_for(ig).add_pair(bd.Pair(*decide_r_robust(ig, rho + 1).witness))
    tried = []
    monkeypatch.setattr(rob, "uniform_tree", lambda *a, **k: tried.append(a))
    try:
        assert rob._charged(ig, rho, s, None) == (charged_tree(ig, rho, s), {})
    finally:
        clear_cache()
    assert tried == [] and charged_tree(ig, rho, s) is not None
