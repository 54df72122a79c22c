"""Dense digraphs n = 40-50 (issue 13 §2): the compiled tabu walks that find the ρ + 1
witness and the s* upper bound, and the sized search below cap 1 that decides
r-robustness in the race, against brute force (LeBlanc's enumeration) and the DP."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from benchmarks.baselines import leblanc_max_s
from rescon.graphs import bounds as bd
from rescon.graphs import robustness as rb
from rescon.graphs.indexed import index_graph
from rescon.graphs.search import SearchOutcome, SizedRun
from tests.test_robustness_dense import dense_digraphs


def _walk(ig, r, labels, moves, seed):
    """pair_walk from ``labels``: (returned cost, final labels)."""
    from rescon.graphs._kernels import pair_walk

    out = bd._out_lists(ig)
    outptr = np.cumsum([0] + [len(o) for o in out], dtype=np.int64)
    outidx = np.array([w for o in out for w in o], dtype=np.int64)
    lab = np.array(labels, dtype=np.int8)
    cost = pair_walk(np.array(ig.in_degrees, dtype=np.int64), outptr, outidx, r, lab, moves,
                     3, -1, seed)
    return int(cost), lab


@settings(max_examples=120, deadline=None)
@given(dense_digraphs(max_n=10), st.data())
def test_pair_walk_returns_a_valid_pair_of_the_cost_it_claims(G, data):
    """From any labelling the walk ends on the cheapest valid pair it met: its cost is
    the pair's true cost and never below s*(r) (brute force); n + 1 only when no valid
    pair was met, and then the labels are the start's."""
    ig = index_graph(G)
    n = ig.n
    r = data.draw(st.integers(1, (n + 1) // 2 + 1))
    labels = data.draw(st.lists(st.integers(0, 2), min_size=n, max_size=n))
    cost, lab = _walk(ig, r, labels, data.draw(st.integers(0, 40)), data.draw(st.integers(0, 99)))
    if cost == n + 1:
        assert lab.tolist() == labels
        return
    pair = bd.Pair(frozenset(np.flatnonzero(lab == 1).tolist()),
                   frozenset(np.flatnonzero(lab == 2).tolist()))
    assert bd.pair_cost(ig, pair, r) == cost
    assert cost >= leblanc_max_s(G, r)


def test_walks_find_the_dense_optimum_and_the_rho_plus_one_witness():
    """ER(40, 0.8), seed 40000 (BENCHMARKS §1): ρ = 17, s*(17) = 5 (the sized search).
    Descents stop at 10; the walks reach 5, and at r = 18 two disjoint 18-closed sets."""
    G = nx.gnp_random_graph(40, 0.8, directed=True, seed=40000)
    ig = index_graph(G)
    assert min(bd.pair_cost(ig, p, 17) for p in bd.descended_pairs(ig, 17)) >= 10
    assert bd.pair_cost(ig, bd.tabu_pairs(ig, 17, floor=5, draws=40)[-1], 17) == 5
    witness = rb._walked_witness(ig, 18, None)
    assert witness is not None and bd.violates(ig, witness, 18, 1)


@settings(max_examples=80, deadline=None)
@given(dense_digraphs(max_n=11))
def test_sized_run_below_one_decides_r_robustness(G):
    """SizedRun(s = 1) to the end: a pair of cost 0 exactly when G is not r-robust
    (brute force), else a tree the checker replays as the proof of r-robustness."""
    ig = index_graph(G)
    for r in range(1, (ig.n + 1) // 2 + 1):
        run = SizedRun(ig, r, 1, lower=0)
        run.run_for(60)
        assert run.finished
        dec = rb._sized_decision(ig, r, run)
        assert dec.holds == (leblanc_max_s(G, r) >= 1)
        if dec.holds:
            cert = {**rb._head("rs_robust", ig), "r": r, "s": 1, "proof": dec.proof}
            check = rescon.check_certificate(cert)
            assert check.valid and check.trusted == () and check.unchecked == ()
        else:
            assert bd.violates(ig, dec.pair, r, 1)


@pytest.mark.parametrize("seed", [3, 7])
def test_the_race_takes_the_sized_answer_when_the_decision_search_lags(monkeypatch, seed):
    """A decision search that never finishes on its own (it only polls should_stop):
    the race still answers, by the sized search's turns, as brute force says."""
    G = nx.gnp_random_graph(12, 0.75, directed=True, seed=seed)
    ig = index_graph(G)

    def lagging(ig, r, *, should_stop, **kw):
        while not should_stop():
            pass
        return SearchOutcome("stopped", r, (), None, None, 0, 0.0)

    monkeypatch.setattr(rb, "decide_r_robust", lagging)
    for r in range(1, (ig.n + 1) // 2 + 1):
        dec = rb._race(ig, r, None, None)
        assert dec.holds == (leblanc_max_s(G, r) >= 1)
        assert dec.method == "search"


def test_dense_is_the_arc_density_threshold():
    assert rb._dense(index_graph(nx.gnp_random_graph(40, 0.8, directed=True, seed=40000)))
    assert not rb._dense(index_graph(nx.gnp_random_graph(40, 0.5, directed=True, seed=40000)))
    assert rb._dense(index_graph(nx.complete_graph(5, create_using=nx.DiGraph)))
    assert not rb._dense(index_graph(nx.empty_graph(3, create_using=nx.DiGraph)))


@pytest.mark.parametrize("dense", [False, True])
def test_the_density_guess_changes_the_time_split_not_the_answer(monkeypatch, dense):
    """Either guess (sized or decision/charged search favoured): the race decides
    r-robustness and the deepening finds s*(r) as brute force does."""
    monkeypatch.setattr(rb, "_dense", lambda ig: dense)
    for seed in range(4):
        G = nx.gnp_random_graph(10, 0.7, directed=True, seed=seed)
        ig = index_graph(G)
        for r in range(1, (ig.n + 1) // 2 + 1):
            expected = leblanc_max_s(G, r)
            assert rb._race(ig, r, None, None).holds == (expected >= 1)
            if expected >= 1:
                out = rb._deepening_search(ig, r, 1, ig.n, None)
                assert out.status == "done" and out.best == expected


@pytest.mark.slow
def test_dense_er40_is_exact_within_the_minute():
    """ER(40, 0.8), seed 40000 (BENCHMARKS §1): (ρ, s*(ρ)) = (17, 5), exact, where the
    MILP race took 55 s; the ρ proof is the sized search's replayed tree, and no part
    of the certificate is refuted."""
    import time

    G = nx.gnp_random_graph(40, 0.8, directed=True, seed=40000)
    t0 = time.perf_counter()
    rep = rescon.robustness(G, time_limit=60)
    assert rep.exact and (rep.r_max, rep.s_max) == (17, 5)
    assert time.perf_counter() - t0 < 60
    assert rep.certificate["lower"]["method"] == "cost_search"
    assert rep.certificate["lower"]["tree"]
    check = rescon.check_certificate(rep.certificate)
    assert check.verdict != "invalid"
    assert all(not part.startswith("lower:") for part in check.unchecked)
    assert bd.pair_cost(index_graph(G), bd.Pair(*rep.s_witness), 17) == 5
