"""Forced candidates (issue 13 §2, dense n = 40–50): a member of S1 whose candidates are
exactly the in-neighbours it still needs takes them all at once, in the decision search
without a recorded tree and in the charged-set search — the lemma by enumeration, the
kernels' single forced child, and both searches against the subset DP and LeBlanc's
enumeration on small random digraphs, dense ones included."""

from __future__ import annotations

import random

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from benchmarks.baselines import leblanc_max_s
from rescon.graphs import _kernels as K
from rescon.graphs import bounds as bd
from rescon.graphs import search as se
from rescon.graphs.indexed import index_graph

DENSITIES = [0.2, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95]


@st.composite
def random_digraphs(draw, max_n: int = 9):
    """Random digraphs of every density (dense ones: p ≥ 0.7), 3 ≤ n ≤ max_n."""
    n = draw(st.integers(3, max_n))
    p = draw(st.sampled_from(DENSITIES))
    return nx.gnp_random_graph(n, p, directed=True, seed=draw(st.integers(0, 10**6)))


def _supersets(S: int, allowed: int):
    """Every S1 with S ⊆ S1 ⊆ S ∪ allowed (bitmasks)."""
    rest = [i for i in range(allowed.bit_length()) if allowed >> i & 1]
    for k in range(1 << len(rest)):
        yield S | sum(1 << u for j, u in enumerate(rest) if k >> j & 1)


def _closed(inmask, S1: int, r: int) -> bool:
    return all((inmask[i] & ~S1).bit_count() < r for i in range(len(inmask)) if S1 >> i & 1)


@settings(max_examples=150, deadline=None)
@given(random_digraphs(), st.data())
def test_a_member_without_slack_needs_all_its_candidates(G, data):
    """The forcing lemma, by enumeration over every S1 ⊇ S avoiding X: when the tightest
    member i of M ⊆ S has slack 0 (``tightest_member`` over the candidates V \\ X \\ S,
    as the charged-set search asks), every S1 in which i has < r outside in-neighbours
    holds all of them; over the candidates P \\ S (P = core(V \\ X), as the decision
    search asks), every closed S1 does."""
    ig = index_graph(G)
    n, masks = ig.n, ig.in_masks()
    inmask = np.array(masks, dtype=np.uint64)
    full = (1 << n) - 1
    labels = data.draw(st.lists(st.integers(0, 2), min_size=n, max_size=n))
    S = sum(1 << i for i, t in enumerate(labels) if t == 1)
    X = sum(1 << i for i, t in enumerate(labels) if t == 2)
    M = S & data.draw(st.integers(0, full))
    r = data.draw(st.integers(1, n))
    slack, cand = K.tightest_member(np.uint64(M), np.uint64(S), np.uint64(full & ~X),
                                    inmask, r, n)
    if slack == 0:
        i = next(i for i in range(n) if M >> i & 1 and int(inmask[i]) & ~S & ~X == int(cand)
                 and (masks[i] & ~S).bit_count() - r + 1 == int(cand).bit_count())
        for S1 in _supersets(S, full & ~S & ~X):
            if (masks[i] & ~S1).bit_count() < r:
                assert S1 & int(cand) == int(cand)
    P = int(K.core(np.uint64(full & ~X), inmask, r))
    if S and S & ~P == 0:
        slack, cand = K.tightest_member(np.uint64(S), np.uint64(S), np.uint64(P), inmask, r, n)
        if slack == 0:
            for S1 in _supersets(S, full & ~S & ~X):
                if _closed(masks, S1, r):
                    assert S1 & int(cand) == int(cand)


def _decision_step(inputs, r, root, record):
    """One decide_step from the root state of ``root`` (S = {order[root]}, X = B): the
    run after it."""
    _, inmask, outmask, order = inputs
    n = inmask.shape[0]
    run = se.PartRun(inputs, r, se.whole_part(n, range(root, root + 1)), 64 if record else 0)
    K.decide_step(inmask, outmask, order, r, run.stack, run.depth, run.state, run.ubuf,
                  run.buffer, record, 1, run.progress)
    return run


def _charged_step(inputs, r, root):
    """One min_cost_step from the state S = M = {order[root]}, X = B, C = ∅ (no cap):
    the run after it."""
    _, inmask, outmask, order = inputs
    n = inmask.shape[0]
    run = se._CostRun(K, n, (root + 1, n), n)
    B = K.prefix_mask(order, root)
    S = np.uint64(1) << np.uint64(order[root])
    run.stack[0, K.CK_S], run.stack[0, K.CK_X], run.stack[0, K.CK_M] = S, B, S
    run.ubuf[K.CB_B], run.state[K.CS_SP] = B, 1
    K.min_cost_step(inmask, outmask, order, r, 0, run.stack, run.depth, run.state, run.ubuf,
                    1, run.progress)
    return run


def _slack_zero_root(engine: str):
    """(inputs, r, root, S, cand): a seeded G(12, 0.5) whose root state S = {order[root]},
    X = B is expanded (no leaf, no prune) and has a member of slack 0 — for the decision
    search over the candidates P \\ S; for the charged-set search, with that member
    marked closed, over V \\ X \\ S."""
    for seed in range(1000):
        ig = index_graph(nx.gnp_random_graph(12, 0.5, directed=True, seed=seed))
        inputs = se._kernel_inputs(ig)
        _, inmask, _, order = inputs
        full = np.uint64((1 << ig.n) - 1)
        for r, root in ((r, root) for r in range(2, 6) for root in range(3)):
            B = np.uint64(K.prefix_mask(order, root))
            S = np.uint64(1) << np.uint64(order[root])
            allowed = np.uint64(K.core(full & ~B, inmask, r) if engine == "decide"
                                else full & ~B)
            if S & ~allowed:
                continue
            slack, cand = K.tightest_member(S, S, allowed, inmask, r, ig.n)
            if engine == "decide":  # expanded with and without a tree (the capped prune)
                expanded = all(_decision_step(inputs, r, root, rec).state[K.ST_SP] > 0
                               for rec in (True, False))
            else:
                expanded = _charged_step(inputs, r, root).state[K.CS_SP] > 0
            if slack == 0 and expanded:
                return inputs, r, root, S, np.uint64(cand)
    raise AssertionError("no expanded root state with a member of slack 0")


@pytest.mark.parametrize("record", [False, True])
def test_decision_step_forces_a_member_without_slack(record):
    """One decide_step from a root state whose member has slack 0: without a recorded
    tree one child, S + the candidates, at the root's depth; with a tree the two
    children of the recorded branching on one candidate (include, exclude)."""
    inputs, r, root, S, cand = _slack_zero_root("decide")
    run = _decision_step(inputs, r, root, record)
    sp = int(run.state[K.ST_SP])
    if record:
        added = run.stack[1, K.SK_S] & ~S
        assert sp == 2 and added & cand == added and bin(int(added)).count("1") == 1
    else:
        assert sp == 1 and run.stack[0, K.SK_S] == S | cand and run.depth[0] == 0


def test_charged_step_forces_a_marked_member_without_slack():
    """min_cost_step from a state (S, X = B, C = ∅, M = S) whose member has slack 0 over
    V \\ X \\ S: one child, S + the candidates, at the same depth (not two)."""
    inputs, r, root, S, cand = _slack_zero_root("charged")
    run = _charged_step(inputs, r, root)
    assert run.state[K.CS_SP] == 1
    assert run.stack[0, K.CK_S] == S | cand and run.depth[0] == 0


def _charged(ig, r, upper, roots=None):
    """The charged-set search alone, in slices of 7 states, to the end: (best, S1, S2)."""
    _, inmask, outmask, order = se._kernel_inputs(ig)
    run = se._CostRun(K, ig.n, (0, ig.n) if roots is None else roots, upper)
    while run.state[K.CS_STATUS] == K.RUNNING:
        K.min_cost_step(inmask, outmask, order, r, 0, run.stack, run.depth, run.state,
                        run.ubuf, 7, run.progress)
    return int(run.state[K.CS_BEST]), int(run.ubuf[K.CB_W1]), int(run.ubuf[K.CB_W2])


def _set(mask: int, n: int) -> frozenset[int]:
    return frozenset(i for i in range(n) if mask >> i & 1)


def _agrees_with_the_dp(ig, cut: int) -> None:
    """For every r up to ⌈n/2⌉ + 1: the decision search without a tree (whole, and as two
    root parts) decides r-robustness as the DP does, its witness violating it; the
    charged-set search gives the DP's s*(r) with a pair of that cost, also as the least
    over two root parts."""
    n = ig.n
    inmask = np.array(ig.in_masks(), dtype=np.uint64)
    for r in range(1, (n + 1) // 2 + 2):
        dp = int(K.min_pair_cost(inmask, r)[0])
        out = se.decide_r_robust(ig, r, record=False)
        assert (out.status == "robust") == (dp >= 1), r
        if out.witness is not None:
            assert bd.violates(ig, bd.Pair(*out.witness), r, 1)
        parts = [se.decide_r_robust(ig, r, record=False, roots=span).status
                 for span in (range(0, cut), range(cut, n))]
        assert (parts == ["robust", "robust"]) == (dp >= 1), (r, cut)
        best, w1, w2 = _charged(ig, r, n)
        assert best == dp, r
        if best < n:
            assert bd.pair_cost(ig, bd.Pair(_set(w1, n), _set(w2, n)), r) == best
        assert min(_charged(ig, r, n, span)[0] for span in ((0, cut), (cut, n))) == dp


@settings(max_examples=80, deadline=None)
@given(random_digraphs(max_n=12), st.data())
def test_forcing_searches_agree_with_the_dp(G, data):
    ig = index_graph(G)
    _agrees_with_the_dp(ig, data.draw(st.integers(0, ig.n)))


def test_forcing_searches_agree_with_leblanc_on_dense_digraphs():
    """40 digraphs, n = 10–13, p ≥ 0.7, every r up to ⌈n/2⌉ + 1: the charged-set search's
    s*(r) is LeBlanc's, and the decision search without a tree says robust exactly when
    s*(r) ≥ 1."""
    rng = random.Random(20261202 + 3)
    for k in range(40):
        n, p = rng.randint(10, 13), rng.choice([0.7, 0.8, 0.9])
        G = nx.gnp_random_graph(n, p, directed=True, seed=rng.randrange(10**6))
        ig = index_graph(G)
        for r in range(1, (n + 1) // 2 + 2):
            truth = leblanc_max_s(G, r)
            assert _charged(ig, r, n)[0] == truth, (k, r)
            assert (se.decide_r_robust(ig, r, record=False).status == "robust") == (truth >= 1)


@pytest.mark.slow
def test_forcing_searches_agree_with_the_dp_on_1500_digraphs():
    """1500 seeded digraphs, n = 5–13, p = 0.2–0.95, a random root cut each."""
    rng = random.Random(3)
    for _ in range(1500):
        n = rng.randint(5, 13)
        ig = index_graph(nx.gnp_random_graph(n, rng.choice(DENSITIES), directed=True,
                                             seed=rng.randrange(10**6)))
        _agrees_with_the_dp(ig, rng.randint(0, n))


# digraphs on which both ρ and s*(ρ) ≥ 2 come from the searches (not the bounds)
SEARCHED = [(15, 0.7, 0), (16, 0.6, 19), (15, 0.7, 20), (15, 0.7, 27), (16, 0.85, 11),
            (16, 0.85, 8)]


@pytest.mark.parametrize("n, p, seed", SEARCHED)
def test_searches_agree_with_the_milp_through_the_api(n, p, seed):
    """robustness(method="search") — ρ by the decision search, s*(ρ) by the deepening
    s* searches, whose charged-set engine forces — against the MILP; the certificate
    checks."""
    from rescon import check_certificate, robustness

    G = nx.gnp_random_graph(n, p, directed=True, seed=seed)
    by_search, by_milp = robustness(G, method="search"), robustness(G, method="milp")
    assert by_search.method == "search+search" and by_search.s_max >= 2
    assert (by_search.r_max, by_search.s_max) == (by_milp.r_max, by_milp.s_max)
    assert check_certificate(by_search.certificate).valid
