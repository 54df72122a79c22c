"""Review R1 (hostile inputs for today's robustness work): the s*(r) branch and bounds
— each engine on its own, in root parts, below caps and above proven floors — against
the subset DP and LeBlanc's enumeration on structured digraph families (isolated
nodes, sources, sinks, complete graphs minus a few arcs, two cliques joined by a few
arcs, undirected graphs), every r from 1 to n; and the recorded s* trees: a tree the
checker accepts, tampered or not, never claims more than the true s*(r)."""

from __future__ import annotations

import networkx as nx
import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from benchmarks.baselines import leblanc_max_s
from rescon.graphs import _kernels as K
from rescon.graphs import bounds as bd
from rescon.graphs import search as se
from rescon.graphs.indexed import index_graph

FAMILIES = ("er", "isolated", "sources", "sinks", "complete_minus", "two_cliques", "undirected")


@st.composite
def family_graphs(draw, max_n: int = 10):
    """A graph of one of FAMILIES, n ≤ max_n, density 0.05–0.98."""
    n = draw(st.integers(2, max_n))
    family = draw(st.sampled_from(FAMILIES))
    p = draw(st.sampled_from([0.05, 0.2, 0.5, 0.8, 0.95, 0.98]))
    seed = draw(st.integers(0, 10**6))
    if family == "undirected":
        return nx.gnp_random_graph(n, p, seed=seed)
    if family == "complete_minus":
        G = nx.complete_graph(n, create_using=nx.DiGraph)
        arcs = draw(st.lists(st.sampled_from(sorted(G.edges)), max_size=6, unique=True))
        G.remove_edges_from(arcs)
        return G
    if family == "two_cliques":
        a = draw(st.integers(1, n - 1))
        G = nx.DiGraph()
        G.add_nodes_from(range(n))
        for block in (range(a), range(a, n)):
            G.add_edges_from((u, v) for u in block for v in block if u != v)
        bridges = draw(st.lists(st.tuples(st.integers(0, a - 1), st.integers(a, n - 1),
                                          st.booleans()), max_size=4))
        G.add_edges_from((v, u) if back else (u, v) for u, v, back in bridges)
        return G
    G = nx.gnp_random_graph(n, p, seed=seed, directed=True)
    picked = draw(st.lists(st.integers(0, n - 1), min_size=1, max_size=max(1, n // 3)))
    for v in picked:
        if family in ("isolated", "sources"):
            G.remove_edges_from(list(G.in_edges(v)))
        if family in ("isolated", "sinks"):
            G.remove_edges_from(list(G.out_edges(v)))
    return G


def _engine(ig, r, upper, engine, *, roots=(0, None), lower=0, slice_nodes=7):
    """One s* kernel alone, in slices of ``slice_nodes`` states, to the end: (best, S1
    mask, S2 mask)."""
    _, inmask, outmask, order = se._kernel_inputs(ig)
    mmask, mout = K.non_in_masks(inmask)
    run = se._CostRun(K, ig.n, (roots[0], ig.n if roots[1] is None else roots[1]), upper)
    while run.state[K.CS_STATUS] == K.RUNNING:
        args = (r, lower, run.stack, run.depth, run.state, run.ubuf, slice_nodes, run.progress)
        if engine == "sized":
            K.min_cost_sized_step(inmask, mmask, mout, order, *args,
                                  np.zeros(1, dtype=np.int32), False)
        else:
            K.min_cost_step(inmask, outmask, order, *args)
    return int(run.state[K.CS_BEST]), int(run.ubuf[K.CB_W1]), int(run.ubuf[K.CB_W2])


def _pair(m1: int, m2: int, n: int) -> bd.Pair:
    return bd.Pair(frozenset(i for i in range(n) if m1 >> i & 1),
                   frozenset(i for i in range(n) if m2 >> i & 1))


@settings(max_examples=40, deadline=None)
@given(family_graphs(), st.data())
def test_each_s_star_engine_alone_is_exact_on_structured_families(G, data):
    """For every r: each engine alone (in tiny slices) gives the DP's s*(r) with a pair of
    that cost; the two root parts of a random cut give it as their minimum; below a cap
    at, under or over s*(r) it gives min(cap, s*(r)); above a proven floor, s*(r)."""
    ig = index_graph(G)
    n = ig.n
    inmask = np.array(ig.in_masks(), dtype=np.uint64)
    cut = data.draw(st.integers(0, n))
    for r in range(1, n + 1):
        dp = int(K.min_pair_cost(inmask, r)[0])
        assert dp == leblanc_max_s(G, r)
        for engine in ("sized", "charged"):
            best, w1, w2 = _engine(ig, r, n, engine)
            assert best == dp, (engine, r)
            if best < n:
                assert bd.pair_cost(ig, _pair(w1, w2, n), r) == best
            parts = [_engine(ig, r, n, engine, roots=span)[0] for span in ((0, cut), (cut, n))]
            assert min(parts) == dp, (engine, r, cut)
            for cap in {max(dp - 1, 0), dp, min(dp + 1, n)}:
                assert _engine(ig, r, cap, engine)[0] == min(cap, dp), (engine, r, cap)
            if 0 < dp < n:
                floor = data.draw(st.integers(0, dp))
                assert _engine(ig, r, n, engine, lower=floor)[0] == dp, (engine, r, floor)


@settings(max_examples=40, deadline=None)
@given(family_graphs(max_n=9), st.data())
def test_public_s_star_agrees_with_enumeration_on_structured_families(G, data):
    """rescon.max_s, is_rs_robust and robustness (forced search and auto) against
    LeBlanc's enumeration; every certificate checks (never invalid)."""
    n = G.number_of_nodes()
    r = data.draw(st.integers(0, n + 1))
    truth = leblanc_max_s(G, r)
    method = data.draw(st.sampled_from(["search", "auto"]))
    assert rescon.max_s(G, r, method=method) == truth
    s = data.draw(st.integers(1, n))
    check = rescon.is_rs_robust(G, r, s, method=method)
    assert check.holds == (truth >= s)
    assert rescon.check_certificate(check.certificate).verdict != "invalid"
    rep = rescon.robustness(G, method=method)
    rho = rep.r_max
    assert rep.s_max == (leblanc_max_s(G, rho) if rho > 0 else n)
    assert rescon.check_certificate(rep.certificate).verdict != "invalid"


# --------------------------------------------------------------------------- #
# the checker's replay of s* trees (certificates/cost_tree.py) on large graphs
# --------------------------------------------------------------------------- #


def test_a_large_cost_tree_is_charged_by_the_width_of_its_sets(monkeypatch):
    """n = 2048: under root 0 and sizes (1, 1), node 0 is reachable in every completion,
    so a chain of branches (u into S1: leaf, into S2: leaf, into R: the next branch) has
    only valid leaves. Each leaf's bound does n operations on n-bit sets, but a state
    was charged n: for n = 12 000 the replay ran 65 s (load 7) to its limit, minutes for
    the n ≈ 10^5 that the graph limit accepts. Charged n·⌈n / 1024⌉, it stops after at
    most max_work / (n·⌈n / 1024⌉) states."""
    from certificates import cost_tree

    n, max_work = 2048, 200_000
    inmask = [1 << ((i - 1) % n) for i in range(n)]  # the directed n-cycle
    tree = [t for u in range(1, n) for t in (u, -1, -1)] + [-1]
    leaves = []
    exact = cost_tree.bound
    monkeypatch.setattr(cost_tree, "bound", lambda *a: leaves.append(a) or exact(*a))
    assert cost_tree.replay(inmask, 1, 1, list(range(n)), tree, "proof", max_work) is False
    states = max_work // (n * 2)
    assert states // 2 <= len(leaves) <= states
