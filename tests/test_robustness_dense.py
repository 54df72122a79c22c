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


# --------------------------------------------------------------------------- #
# the two-sided search with fixed set sizes (min_cost_sized_step)
# --------------------------------------------------------------------------- #


def _sized_search(ig, r, upper, roots=None):
    """Run the sized kernel alone to the end: (best, S1 mask, S2 mask)."""
    from rescon.graphs import _kernels as K
    from rescon.graphs import search as se

    _, inmask, _, order = se._kernel_inputs(ig)
    mmask, mout = K.non_in_masks(inmask)
    run = se._CostRun(K, ig.n, (0, ig.n) if roots is None else (roots.start, roots.stop), upper)
    while run.state[K.CS_STATUS] == K.RUNNING:
        K.min_cost_sized_step(inmask, mmask, mout, order, r, 0, run.stack, run.depth,
                              run.state, run.ubuf, 10_000, run.progress,
                              np.empty(1, dtype=np.int32), False)
    return int(run.state[K.CS_BEST]), int(run.ubuf[K.CB_W1]), int(run.ubuf[K.CB_W2])


@st.composite
def dense_digraphs(draw, max_n: int = 14):
    """Digraphs of density 0.7-0.95 (and a few sparser), n ≤ max_n."""
    n = draw(st.integers(2, max_n))
    p = draw(st.sampled_from([0.3, 0.5, 0.7, 0.8, 0.9, 0.95]))
    return nx.gnp_random_graph(n, p, directed=True, seed=draw(st.integers(0, 10**6)))


def _pair_of(mask1, mask2, n):
    return bd.Pair(frozenset(i for i in range(n) if mask1 >> i & 1),
                   frozenset(i for i in range(n) if mask2 >> i & 1))


@settings(max_examples=120, deadline=None)
@given(dense_digraphs())
def test_sized_search_alone_matches_the_dp(G):
    """The sized kernel on its own (not raced) gives the DP's s*(r) for every r, and
    its pair costs what it claims."""
    from rescon.graphs._kernels import min_pair_cost

    ig = index_graph(G)
    inmask = np.array(ig.in_masks(), dtype=np.uint64)
    for r in range(1, (ig.n + 1) // 2 + 2):
        best, w1, w2 = _sized_search(ig, r, ig.n)
        assert best == int(min_pair_cost(inmask, r)[0])
        if best < ig.n:
            assert bd.pair_cost(ig, _pair_of(w1, w2, ig.n), r) == best


@settings(max_examples=60, deadline=None)
@given(dense_digraphs(max_n=10), st.data())
def test_sized_search_root_parts_compose(G, data):
    ig = index_graph(G)
    cut = data.draw(st.integers(0, ig.n))
    for r in range(1, (ig.n + 1) // 2 + 1):
        parts = [_sized_search(ig, r, ig.n, roots=p)[0]
                 for p in (range(0, cut), range(cut, ig.n))]
        assert min(parts) == leblanc_max_s(G, r)


def _completions(n, L1, L2, L0, s1, s2):
    """Every (S1, S2) with L1 ⊆ S1, L2 ⊆ S2, L0 ∩ (S1 ∪ S2) = ∅, |S_k| = s_k."""
    free = [i for i in range(n) if not (L1 | L2 | L0) >> i & 1]
    for labels in itertools.product((0, 1, 2), repeat=len(free)):
        S1 = L1 | sum(1 << u for u, t in zip(free, labels) if t == 1)
        S2 = L2 | sum(1 << u for u, t in zip(free, labels) if t == 2)
        if S1.bit_count() == s1 and S2.bit_count() == s2:
            yield S1, S2


@settings(max_examples=150, deadline=None)
@given(dense_digraphs(max_n=8), st.data())
def test_sized_lower_bound_never_exceeds_a_completion(G, data):
    """The bound of a partial labelling is at most the cost of every completion whose
    sets both keep a closed member (and n + 1 only when there is none); exact when
    nothing is left unlabelled."""
    from rescon.graphs._kernels import non_in_masks, sized_lower_bound

    ig = index_graph(G)
    n = ig.n
    inmask = np.array(ig.in_masks(), dtype=np.uint64)
    mmask, _ = non_in_masks(inmask)
    labels = data.draw(st.lists(st.integers(0, 3), min_size=n, max_size=n))  # 3: unlabelled
    L1, L2, L0 = (sum(1 << i for i in range(n) if labels[i] == t) for t in (1, 2, 0))
    s1 = data.draw(st.integers(1, n))
    s2 = data.draw(st.integers(1, n))
    r = data.draw(st.integers(1, 4))
    need = np.array([d - r + 1 for d in ig.in_degrees], dtype=np.int64)
    bound = sized_lower_bound(np.uint64(L1), np.uint64(L2), np.uint64(L0), s1, s2,
                              inmask, mmask, need, n + 2, n)
    costs = []
    for S1, S2 in _completions(n, L1, L2, L0, s1, s2):
        cost = bd.pair_cost(ig, _pair_of(S1, S2, n), r)
        if cost is not None:
            costs.append(cost)
    assert bound <= min(costs, default=n + 1)
    if labels.count(3) == 0 and costs:
        assert bound == costs[0]


@pytest.mark.slow
@pytest.mark.parametrize("seed", [1, 2, 3])
def test_sized_search_agrees_with_the_dp_on_dense_n22(seed):
    """ER(22, 0.85): the sized search alone and the subset DP give the same s*(ρ)."""
    G = nx.gnp_random_graph(22, 0.85, directed=True, seed=seed)
    import rescon

    ig = index_graph(G)
    r = rescon.robustness(G, method="dp").r_max
    dp, _ = _dp_min_cost(ig, r)
    assert _sized_search(ig, r, ig.n)[0] == dp


@pytest.mark.slow
def test_dense_er30_s_star_is_exact_within_seconds():
    """ER(30, 0.8), seed 30000 (BENCHMARKS §1), ρ = 12: the charged-set search alone left
    2 ≤ s* ≤ 6 after 60 s; with the sized search s*(12) = 5, exact, in seconds, and
    its pair costs 5."""
    import time

    import rescon

    G = nx.gnp_random_graph(30, 0.8, directed=True, seed=30000)
    t0 = time.perf_counter()
    rep = rescon.robustness(G, time_limit=60)
    assert rep.exact and (rep.r_max, rep.s_max) == (12, 5)
    assert time.perf_counter() - t0 < 30
    ig = index_graph(G)
    assert list(ig.nodes) == list(range(30))  # labels are the indices
    assert bd.pair_cost(ig, bd.Pair(*rep.s_witness), 12) == 5


@settings(max_examples=40, deadline=None)
@given(dense_digraphs(max_n=10))
def test_favoured_engine_changes_the_time_split_not_the_answer(G):
    ig = index_graph(G)
    for r in range(1, (ig.n + 1) // 2 + 1):
        expected = leblanc_max_s(G, r)
        for favour in (None, "sized", "charged"):
            out = min_cost_pair(ig, r, ig.n, favour=favour)
            assert out.best == expected and out.engine in ("sized", "charged")


def test_favour_names_an_engine():
    ig = index_graph(nx.complete_graph(4, create_using=nx.DiGraph))
    with pytest.raises(ValueError, match="favour must be one of"):
        min_cost_pair(ig, 1, 4, favour="milp")


# --------------------------------------------------------------------------- #
# recorded s* trees (search.cost_tree) and their replay (certificates/cost_tree.py)
# --------------------------------------------------------------------------- #


def _cost_cert(ig, r, s, tree, order):
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(), "r": r,
            "s": s, "proof": {"method": "cost_search", "order": list(order),
                              "tree": list(tree)}}


@settings(max_examples=60, deadline=None)
@given(dense_digraphs(max_n=9))
def test_recorded_cost_trees_replay_and_prove_exactly_s_star(G):
    """The tree below s*(r) replays valid; the same tree claimed for s*(r) + 1 is
    rejected (a pair of cost s*(r) exists); the search below s*(r) + 1 meets it."""
    import rescon
    from rescon.graphs.search import cost_tree, search_order

    ig = index_graph(G)
    order = search_order(ig).tolist()
    for r in range(1, (ig.n + 1) // 2 + 1):
        s = leblanc_max_s(G, r)
        if s == 0:
            continue
        tree = cost_tree(ig, r, s)
        assert rescon.check_certificate(_cost_cert(ig, r, s, tree, order)).valid
        if s < ig.n:
            assert not rescon.check_certificate(_cost_cert(ig, r, s + 1, tree, order)).valid
            with pytest.raises(ValueError, match="a pair costs"):
                cost_tree(ig, r, s + 1)


def test_tampered_cost_trees_are_rejected():
    """ER(24, 0.85): the recorded tree proves s*(ρ) = s with the checker's own bound;
    a branch cut to a leaf, a leaf made a branch, a missing or an extra token, or a
    different order is rejected."""
    import rescon
    from rescon.graphs.search import cost_tree, search_order

    G = nx.gnp_random_graph(24, 0.85, directed=True, seed=3)
    ig = index_graph(G)
    r = rescon.robustness(G, method="dp").r_max
    s, _ = _dp_min_cost(ig, r)
    order = search_order(ig).tolist()
    tree = list(cost_tree(ig, r, s))
    assert rescon.check_certificate(_cost_cert(ig, r, s, tree, order)).valid
    branch = next(k for k, t in enumerate(tree) if t >= 0)
    leaf = next(k for k, t in enumerate(tree) if t == -1)
    tampered = [
        tree[:branch] + [-1] + tree[branch + 1:],
        tree[:leaf] + [order[0]] + tree[leaf + 1:],  # order[0] is labelled in every state
        tree[:-1],
        tree + [-1],
    ]
    for bad in tampered:
        assert not rescon.check_certificate(_cost_cert(ig, r, s, bad, order)).valid
    swapped = order[1:] + order[:1]
    assert not rescon.check_certificate(_cost_cert(ig, r, s, tree, swapped)).valid


@pytest.mark.slow
def test_dense_er25_certificate_is_replayed_in_full():
    """ER(25, 0.8), seed 25000: s*(11) = 2 by the sized search; the certificate carries
    its tree and the checker verifies every part (nothing on trust); a tampered tree
    makes it invalid."""
    import json

    import rescon

    G = nx.gnp_random_graph(25, 0.8, directed=True, seed=25000)
    rep = rescon.robustness(G, time_limit=60)
    assert rep.exact and rep.s_max == 2
    proof = rep.certificate["lower_s"]
    assert proof["method"] == "cost_search" and proof["tree"]
    check = rescon.check_certificate(rep.certificate)
    assert check.valid and check.trusted == () and check.unchecked == ()
    bad = json.loads(json.dumps(rep.certificate))
    tree = bad["lower_s"]["tree"]
    tree[next(k for k, t in enumerate(tree) if t >= 0)] = -1  # a branch cut to a leaf
    assert not rescon.check_certificate(bad).valid
