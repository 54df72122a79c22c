"""Hostile review (V11) of the charged s* engine's own root order
(search.charged_search_order) and of the lower bound k on S2's charges carried from
parent to child (_kernels.min_cost_step, stack column CK_K).

The carried k is only sound if the peeled core core_hard(V \\ S \\ B, ∅, S ∪ B, r, k)
only shrinks from a state to its children: B must be the same (one root) and S may only
grow. Every way a state meets a stack row written elsewhere is tried: any root order
(random permutations, so B is any prefix), roots split into ranges, a search cut into
parts (CostPart frames, run alone, in any order, split again mid-root), the parts of the
charged engine alone on a Dask LocalCluster, and searches stopped by their budget. The
truth is a pure-Python enumeration of every pair of disjoint sets (n ≤ 9) or the subset
DP (_kernels.min_pair_cost)."""

from __future__ import annotations

import random

import networkx as nx
import numpy as np
import pytest

import rescon
from certificates import check as check_certificate
from rescon.graphs import _kernels as K
from rescon.graphs import distributed
from rescon.graphs import search as se
from rescon.graphs.facts import clear_cache
from rescon.graphs.indexed import index_graph
from rescon.graphs.robustness import _deepening_search

# ----------------------------------------------------------------------- oracles


def _brute_s_star(in_masks: list[int], n: int, r: int) -> int:
    """min |reach_r(S1)| + |reach_r(S2)| over disjoint nonempty S1, S2 that both keep a
    member with < r in-neighbours outside its set; n when there is none (every pair)."""
    cost, open_ = [0] * (1 << n), [False] * (1 << n)
    for S in range(1, 1 << n):
        reached = [i for i in range(n) if S >> i & 1 and bin(in_masks[i] & ~S).count("1") >= r]
        cost[S] = len(reached)
        open_[S] = len(reached) < bin(S).count("1")
    best = n
    full = (1 << n) - 1
    for S1 in range(1, 1 << n):
        if not open_[S1] or cost[S1] >= best:
            continue
        rest = full & ~S1
        S2 = rest
        while S2:
            if S2 > S1 and open_[S2]:  # each unordered pair once
                best = min(best, cost[S1] + cost[S2])
            S2 = (S2 - 1) & rest
    return best


def _in_masks(G) -> tuple[list[int], int]:
    ig = index_graph(G)
    return list(ig.in_masks()), ig.n


def _dp(ig, r: int) -> int:
    return int(K.min_pair_cost(np.array(ig.in_masks(), dtype=np.uint64), r)[0])


def _families(seed: int, count: int, nmin: int, nmax: int):
    """Random digraphs and graphs, and adversarial ones: tied in-degrees (circulants,
    regular graphs), cliques joined by a matching, stars, complete, empty, isolated
    nodes, self-loops in the input."""
    rng = np.random.default_rng(seed)
    for k in range(count):
        n = int(rng.integers(nmin, nmax + 1))
        p = float(rng.uniform(0.2, 0.95))
        s = int(rng.integers(1 << 30))
        kind = k % 9
        if kind in (0, 1):
            G = nx.gnp_random_graph(n, p, seed=s, directed=True)
        elif kind == 2:
            G = nx.gnp_random_graph(n, p, seed=s)
        elif kind == 3:
            offs = sorted({int(x) for x in rng.integers(1, n, size=int(rng.integers(1, n)))})
            G = nx.DiGraph([(i, (i + o) % n) for i in range(n) for o in offs])
        elif kind == 4:
            a = int(rng.integers(2, n // 2 + 2))
            b = max(2, n - a)
            G = nx.disjoint_union(nx.complete_graph(a), nx.complete_graph(b)).to_directed()
            G.add_edges_from((i, a + i) for i in range(min(a, b)) if rng.random() < 0.8)
        elif kind == 5:
            G = [nx.star_graph(n - 1), nx.complete_graph(n).to_directed(),
                 nx.empty_graph(n, create_using=nx.DiGraph)][k // 9 % 3]
        elif kind == 6:
            G = nx.gnp_random_graph(n, p, seed=s, directed=True)
            G.add_nodes_from(range(n, n + 2))
        elif kind == 7:
            G = nx.gnp_random_graph(n, p, seed=s, directed=True)
            G.add_edges_from((i, i) for i in range(n) if rng.random() < 0.5)
        else:
            d = int(rng.integers(1, n))
            G = nx.random_regular_graph(d - (n * d) % 2, n, seed=s)
        yield G


def _engine(ig, r: int, engine: str, order: np.ndarray, part=None, best=None,
            slice_=10_000) -> se.CostPartRun:
    _, inmask, outmask, _ = se._kernel_inputs(ig)
    run = se.CostPartRun((K, inmask, outmask, np.asarray(order, dtype=np.int64)), engine, r,
                         -1, se.whole_cost_part(ig.n) if part is None else part,
                         ig.n if best is None else best)
    while run.advance(slice_) == K.RUNNING:
        pass
    return run


# ----------------------------------------------------------------------- brute force


@pytest.mark.parametrize("seed", range(4))
def test_s_star_and_rho_against_every_pair(seed):
    """n = 4-9: s*(r) by min_cost_pair (both engines racing), by each engine alone in
    its order and in a random order, and the DP, all equal to the enumeration of every
    pair; ρ and s*(ρ) of rescon.robustness(method="search") too, with a certificate
    the stdlib checker finds valid."""
    rng = np.random.default_rng(100 + seed)
    for G in _families(seed, 27, 4, 9):
        ig = index_graph(G)
        masks, n = list(ig.in_masks()), ig.n
        truth = {r: _brute_s_star(masks, n, r) for r in range(0, (n + 1) // 2 + 2)}
        for r in range(1, (n + 1) // 2 + 2):
            assert _dp(ig, r) == truth[r]
            assert se.min_cost_pair(ig, r, n).best == truth[r], r
            for order in (se.charged_search_order(ig), rng.permutation(n)):
                assert _engine(ig, r, "charged", order).best == truth[r], (r, order)
        rho = max(r for r in truth if truth[r] >= 1 or r == 0)
        clear_cache()
        rep = rescon.robustness(G, method="search")
        assert (rep.r_max, rep.s_max) == (rho, truth[rho]), (rho, truth)
        assert check_certificate(rep.certificate).valid


# ----------------------------------------------------------------------- root orders


@pytest.mark.parametrize("seed", range(3))
def test_each_engine_in_any_root_order_is_the_dp(seed):
    """n = 8-14, random root orders (B any prefix): each engine alone equals the DP, and
    so does a partition of the roots into random ranges (min over the parts)."""
    rng = np.random.default_rng(200 + seed)
    for G in _families(10 + seed, 18, 8, 14):
        ig = index_graph(G)
        n = ig.n
        for r in range(1, (n + 1) // 2 + 1):
            truth = _dp(ig, r)
            order = rng.permutation(n)
            for engine in se.COST_ENGINES:
                assert _engine(ig, r, engine, order).best == truth, (engine, r)
            cuts = sorted({0, n, *(int(c) for c in rng.integers(0, n + 1, size=3))})
            parts = [range(a, b) for a, b in zip(cuts, cuts[1:], strict=False)]
            for favour in se.COST_ENGINES:
                got = min(se.min_cost_pair(ig, r, n, roots=p, favour=favour).best
                          for p in parts)
                assert got == truth, (favour, r, parts)


def _brute_by_first(in_masks: list[int], n: int, r: int, order) -> list[int]:
    """For each position j: the least cost over the pairs of :func:`_brute_s_star`
    whose first node in ``order`` is order[j] (n when there is none)."""
    pos = {int(v): j for j, v in enumerate(order)}
    cost, open_ = [0] * (1 << n), [False] * (1 << n)
    for S in range(1, 1 << n):
        reached = sum(1 for i in range(n)
                      if S >> i & 1 and bin(in_masks[i] & ~S).count("1") >= r)
        cost[S], open_[S] = reached, reached < bin(S).count("1")
    best = [n] * n
    full = (1 << n) - 1
    for S1 in range(1, 1 << n):
        if not open_[S1]:
            continue
        rest = full & ~S1
        S2 = rest
        while S2:
            if S2 > S1 and open_[S2]:
                both = S1 | S2
                j = min(pos[i] for i in range(n) if both >> i & 1)
                best[j] = min(best[j], cost[S1] + cost[S2])
            S2 = (S2 - 1) & rest
    return best


def _only(monkeypatch, engine: str) -> None:
    """min_cost_pair's other engine never advances: ``engine`` answers."""

    class Only(se.CostPartRun):
        def advance(self, max_nodes: int) -> int:
            if self.engine != engine:
                self.seconds += 1e-3
                return K.RUNNING
            return super().advance(max_nodes)

    monkeypatch.setattr(se, "CostPartRun", Only)


@pytest.mark.parametrize("engine", se.COST_ENGINES)
@pytest.mark.parametrize("seed", range(3))
def test_roots_parts_are_exact_on_prefixes_and_bounded_below_elsewhere(seed, engine,
                                                                        monkeypatch):
    """n = 6-9, against every pair: min_cost_pair(..., roots=range(0, b)) is the least
    cost over the pairs whose first node in search_order is at a position < b (a
    pair's saturation, which the engines search instead, only adds nodes, so its first
    node stays in the prefix), and roots=range(a, b) the cost of a pair whose first
    node is at a position in [a, b), so at least the least of those — whichever engine
    answers (each made to answer alone). A min over a partition equal to s* cannot tell
    the engines' orders apart (optimal pairs are many, and on small graphs the sized
    engine answers in its first slice: it held with the charged engine in its own order
    on a part); these do."""
    _only(monkeypatch, engine)
    rng = np.random.default_rng(400 + seed)
    for G in _families(50 + seed, 18, 6, 9):
        ig = index_graph(G)
        n = ig.n
        order = se.search_order(ig)
        for r in range(1, (n + 1) // 2 + 1):
            by_first = _brute_by_first(list(ig.in_masks()), n, r, order)
            ranges = [range(0, int(rng.integers(1, n + 1)))]
            a = int(rng.integers(1, n))
            ranges.append(range(a, int(rng.integers(a + 1, n + 1))))
            for roots in ranges:
                want = min(by_first[roots.start:roots.stop])
                got = se.min_cost_pair(ig, r, n, roots=roots)
                assert got.engine == engine
                if roots.start == 0:
                    assert got.best == want, (r, roots)
                assert got.best >= want, (r, roots)
                if got.pair is not None:
                    S1, S2 = got.pair
                    first = min(int(np.flatnonzero(order == i)[0]) for i in S1 | S2)
                    assert first in roots


def test_a_roots_part_need_not_bound_its_own_pairs():
    """The docstring of min_cost_pair said a part's ``best`` "bounds only the pairs
    whose first node lies in its roots"; it is not an upper bound on them: the engines
    search maximal pairs only, and a pair's saturation may start in an earlier root.
    Only the least over a partition of range(n) is s*(r)."""
    G = next(iter(_families(51, 1, 6, 9)))
    ig = index_graph(G)
    n, order = ig.n, se.search_order(ig)
    seen = False
    for r in range(1, (n + 1) // 2 + 1):
        by_first = _brute_by_first(list(ig.in_masks()), n, r, order)
        for a in range(1, n):
            got = se.min_cost_pair(ig, r, n, roots=range(a, n)).best
            seen |= got > min(by_first[a:])
    assert seen


# ----------------------------------------------------------------------- cut and resumed


def _cut_and_resumed(ig, r: int, order, rng: random.Random) -> int:
    """The charged engine in ``order``, cut after a random number of states, its rest
    split into parts (split_cost_part), each part run alone in a random order and cut
    again (a part started in the middle of a root, from frames carrying CK_K); the
    least incumbent."""
    best = ig.n
    waiting = [se.whole_cost_part(ig.n)]
    while waiting:
        part = waiting.pop(rng.randrange(len(waiting)))
        _, inmask, outmask, _ = se._kernel_inputs(ig)
        run = se.CostPartRun((K, inmask, outmask, np.asarray(order, dtype=np.int64)),
                             "charged", r, -1, part, best)
        status = run.advance(rng.randint(1, 40))
        best = min(best, run.best)
        if status == K.RUNNING:
            waiting += se.split_cost_part(run.rest(), rng.randint(0, 3), ig.n)
    return best


@pytest.mark.parametrize("seed", range(3))
def test_charged_parts_cut_mid_root_and_resumed_give_the_dp(seed):
    rng = random.Random(300 + seed)
    for G in _families(20 + seed, 18, 7, 11):
        ig = index_graph(G)
        for r in range(1, (ig.n + 1) // 2 + 1):
            truth = _dp(ig, r)
            for order in (se.charged_search_order(ig), se.search_order(ig)):
                assert _cut_and_resumed(ig, r, order, rng) == truth, r


def test_a_frame_without_its_bound_resumes_to_the_same_answer():
    """A saved frame whose CK_K column is 0 (the weakest bound, e.g. a part written
    before the column existed) still gives s*: the carried k is only a hint."""
    rng = random.Random(5)
    for seed in range(6):
        G = nx.gnp_random_graph(11, 0.55, seed=seed, directed=True)
        ig = index_graph(G)
        order = se.charged_search_order(ig)
        for r in (2, 3):
            truth = _dp(ig, r)
            run = _engine(ig, r, "charged", order, slice_=1)
            _, inmask, outmask, _ = se._kernel_inputs(ig)
            first = se.CostPartRun((K, inmask, outmask, order), "charged", r, -1,
                                   se.whole_cost_part(ig.n), ig.n)
            if first.advance(rng.randint(2, 30)) != K.RUNNING:
                continue
            rest = first.rest()
            assert rest.frames.shape[1] == K.COST_STACK_WIDTH
            frames = rest.frames.copy()
            frames[:, K.CK_K] = 0
            zeroed = se.CostPart(frames, rest.depths, rest.root, rest.end)
            assert min(first.best, _engine(ig, r, "charged", order, zeroed,
                                           first.best).best) == truth == run.best


# ----------------------------------------------------------------------- stopped searches


@pytest.mark.parametrize("seed", range(2))
def test_stopped_searches_give_true_bounds(seed):
    """Cut after 1, 2, 4, ... states: the incumbent of either engine and of min_cost_pair
    is an upper bound on s*(r) and its pair costs it; the deepening search stopped by
    should_stop has floor ≤ s*(r) ≤ best."""
    from rescon.graphs import bounds as bd

    for G in _families(30 + seed, 12, 10, 16):
        ig = index_graph(G)
        n = ig.n
        for r in range(1, (n + 1) // 2 + 1):
            truth = _dp(ig, r)
            for engine, order in (("charged", se.charged_search_order(ig)),
                                  ("sized", se.search_order(ig))):
                _, inmask, outmask, _ = se._kernel_inputs(ig)
                run = se.CostPartRun((K, inmask, outmask, order), engine, r, -1,
                                     se.whole_cost_part(n), n)
                steps = 1
                while run.advance(steps) == K.RUNNING:
                    assert run.best >= truth
                    if run.pair() is not None:  # a charged node may be unreached
                        cost = bd.pair_cost(ig, bd.Pair(*run.pair()), r)
                        assert cost is not None and truth <= cost <= run.best
                    steps *= 2
                assert run.best == truth
            for calls in (1, 2, 5):
                left = [calls]

                def stop(left=left) -> bool:
                    left[0] -= 1
                    return left[0] < 0

                out = _deepening_search(ig, r, 0, n, None, should_stop=stop)
                assert out.floor <= truth <= out.best, (calls, out)


@pytest.mark.slow
def test_time_limited_robustness_bounds_hold():
    """rescon.robustness with tiny time limits on n = 18-22: r_lower ≤ ρ ≤ r_upper and,
    when ρ is settled, s_lower ≤ s*(ρ) ≤ s_upper (truth: the DP)."""
    for G in _families(40, 9, 18, 22):
        ig = index_graph(G)
        n = ig.n
        s = {r: _dp(ig, r) for r in range(0, (n + 1) // 2 + 1)}
        rho = max(r for r in s if s[r] >= 1 or r == 0)
        for limit in (0.001, 0.05, 0.3):
            clear_cache()
            rep = rescon.robustness(G, method="search", time_limit=limit)
            assert rep.r_lower <= rho <= rep.r_upper
            if rep.r_max is not None:
                assert rep.r_max == rho
                assert rep.s_lower <= s[rho] <= rep.s_upper, (limit, rep)
            assert check_certificate(rep.certificate).verdict != "invalid"


# ----------------------------------------------------------------------- Dask


@pytest.fixture
def tiny_parts(monkeypatch):
    monkeypatch.setattr(se, "_SLICE", 20)
    monkeypatch.setattr(distributed, "LOCAL_NODES", 20)
    monkeypatch.setattr(distributed, "COST_TASK_NODES", 60)


@pytest.mark.slow
def test_charged_engine_alone_on_the_cluster_in_its_order(cluster, tiny_parts):
    """The charged engine's parts alone on 2 workers (finish_cost_on_cluster with only
    the charged run, started in its own order and stopped in a later root, so the
    parts' B is a prefix of that order): the DP's s*, as serial."""
    from rescon.graphs import bounds as bd

    sent, most = 0, 0
    with distributed.searches_on(scheduler=cluster):
        pool = distributed.active()
        for seed, (n, p) in enumerate([(12, 0.4), (13, 0.6), (14, 0.8), (12, 0.3)]):
            G = nx.gnp_random_graph(n, p, seed=seed, directed=True)
            ig = index_graph(G)
            inputs = se._kernel_inputs(ig)
            for r in range(1, (n + 1) // 2 + 1):
                truth = _dp(ig, r)
                order = se.charged_search_order(ig)
                run = se.CostPartRun((*inputs[:3], order), "charged", r, -1,
                                     se.whole_cost_part(n), n)
                status = run.advance(7 + seed)
                while status == K.RUNNING and run.run.state[K.CS_ROOT] < r + 2:
                    status = run.advance(5)  # into a later root: its B is a prefix
                if status != K.RUNNING:
                    continue
                # the rest alone, serially and on the cluster, below n (not below the
                # local incumbent, which would hide a part searched in the wrong order)
                serial = _engine(ig, r, "charged", order, part=run.rest(), best=n).best
                assert min(run.best, serial) == truth
                out = distributed.finish_cost_on_cluster(pool, [run], {"charged": 1.0}, n,
                                                         None)
                assert (out.status, out.best) == ("done", serial), (seed, r)
                if out.pair is not None:
                    assert bd.pair_cost(ig, bd.Pair(*out.pair), r) <= serial
                sent, most = sent + 1, max(most, out.nodes)
    assert sent >= 10 and most > 600  # > 10 tasks of 60 states
