"""s*(ρ) on dense digraphs (issue 13 §2): the hard-threshold cores that bound the
charged-set branch and bound, and the tabu walks that find its upper bound, against
brute force and the subset DP."""

from __future__ import annotations

import itertools

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from benchmarks.baselines import leblanc_max_s
from rescon.graphs import bounds as bd
from rescon.graphs.indexed import index_graph
from rescon.graphs.robustness import _descended_upper, _dp_min_cost
from rescon.graphs.search import min_cost_pair
from tests.test_robustness_exact import digraphs


def _brute_core_hard(inmask, U, free, hard, r, slack):
    """Union of every A ⊆ U whose members i have |N(i) ∩ hard| < r and
    |N(i) \\ (A ∪ free)| < r + slack (by the definition, over all subsets)."""
    members = [i for i in range(len(inmask)) if (U >> i) & 1]
    union = 0
    for k in range(1, len(members) + 1):
        for sub in itertools.combinations(members, k):
            A = sum(1 << i for i in sub)
            if all((inmask[i] & hard).bit_count() < r
                   and (inmask[i] & ~(A | free)).bit_count() < r + slack for i in sub):
                union |= A
    return union


@settings(max_examples=60, deadline=None)
@given(digraphs(max_n=8), st.data())
def test_core_hard_is_the_largest_set_of_its_definition(G, data):
    from rescon.graphs._kernels import core_hard

    ig = index_graph(G)
    n = ig.n
    inmask = ig.in_masks()
    labels = data.draw(st.lists(st.integers(0, 2), min_size=n, max_size=n))  # U / free / hard
    U = sum(1 << i for i in range(n) if labels[i] == 0)
    free = sum(1 << i for i in range(n) if labels[i] == 1)
    hard = sum(1 << i for i in range(n) if labels[i] == 2)
    r = data.draw(st.integers(1, 3))
    slack = data.draw(st.integers(0, 2))
    got = core_hard(np.uint64(U), np.uint64(free), np.uint64(hard),
                    np.array(inmask, dtype=np.uint64), r, slack)
    assert int(got) == _brute_core_hard(inmask, U, free, hard, r, slack)


@settings(max_examples=40, deadline=None)
@given(digraphs(max_n=9))
def test_cost_search_with_hard_cores_matches_enumeration_on_dense_graphs(G):
    """Dense digraphs (every missing arc of the drawn graph added with the drawn
    ones): the charged-set search still gives LeBlanc's s*(r) for every r."""
    D = nx.complete_graph(G.number_of_nodes(), create_using=nx.DiGraph)
    D.remove_edges_from(list(G.edges)[: len(G.edges) // 3])
    ig = index_graph(D)
    for r in range(1, (ig.n + 1) // 2 + 2):
        out = min_cost_pair(ig, r, ig.n)
        assert out.status == "done"
        assert out.best == leblanc_max_s(D, r)


@settings(max_examples=30, deadline=None)
@given(digraphs(max_n=9), st.integers(1, 4))
def test_tabu_pairs_are_valid_and_improving(G, r):
    ig = index_graph(G)
    pairs = bd.tabu_pairs(ig, r, draws=3)
    costs = [bd.pair_cost(ig, p, r) for p in pairs]
    assert all(c is not None for c in costs)
    assert costs == sorted(costs, reverse=True) and len(set(costs)) == len(costs)
    for p in pairs:
        assert p.S1 and p.S2 and not p.S1 & p.S2
    if costs:
        assert costs[-1] >= leblanc_max_s(G, r)  # an upper bound on s*(r)
        below = costs[0]
        assert all(bd.pair_cost(ig, p, r) < below
                   for p in bd.tabu_pairs(ig, r, below=below, draws=3))


def test_tabu_pairs_need_a_stop():
    ig = index_graph(nx.complete_graph(4, create_using=nx.DiGraph))
    with pytest.raises(ValueError):
        bd.tabu_pairs(ig, 1)


def test_tabu_walks_reach_the_dense_optimum_where_descent_stops():
    """ER(25, 0.8), seed 25000 (BENCHMARKS §1), ρ = 11: the DP gives s*(11) = 2;
    descents from random bisections stop at 5 or more, tabu walks reach 2."""
    G = nx.gnp_random_graph(25, 0.8, directed=True, seed=25000)
    ig = index_graph(G)
    assert min(bd.pair_cost(ig, p, 11) for p in bd.descended_pairs(ig, 11)) > 2
    pairs = bd.tabu_pairs(ig, 11, floor=2, draws=10)
    assert bd.pair_cost(ig, pairs[-1], 11) == 2
    upper, pair = _descended_upper(ig, 11, 25, None, None, lower=1)
    assert upper == 2 and bd.pair_cost(ig, pair, 11) == 2


@pytest.mark.slow
@pytest.mark.parametrize("seed", [25000, 25001])
def test_dense_er25_search_agrees_with_the_dp(seed):
    """The charged-set search below cap 3 and the subset DP agree on s*(ρ) = 2."""
    G = nx.gnp_random_graph(25, 0.8, directed=True, seed=seed)
    ig = index_graph(G)
    dp, _ = _dp_min_cost(ig, 11)
    out = min_cost_pair(ig, 11, 3, lower=1)
    assert out.status == "done" and out.best == dp == 2


def test_a_stopped_deepening_keeps_the_bound_its_finished_rounds_proved(monkeypatch):
    """s* search stopped by the time limit after proving 'no pair below 2': the report's
    s_lower is 2 with a cost_search proof, not the bounds' 1 (ER(30, 0.8) at 60 s)."""
    from rescon.graphs import robustness as rb
    from rescon.graphs.search import CostOutcome

    ig = index_graph(nx.gnp_random_graph(12, 0.8, directed=True, seed=1))
    rounds = iter([CostOutcome("done", 2, None, 10, ()), CostOutcome("stopped", 3, None, 5, ())])
    monkeypatch.setattr(rb, "min_cost_pair", lambda *a, **k: next(rounds))
    out = rb._deepening_search(ig, 3, 1, 6, None)
    assert out.status == "stopped" and out.floor == 2 and out.nodes == 15
    ss = rb._cost_search_result(ig, 3, out, 1, 6, {"method": "degree"}, None)
    assert ss.value is None and (ss.lower, ss.upper) == (2, 6)
    assert ss.proof["method"] == "cost_search"
