"""The charged-set s* engine in its own root order (search.charged_search_order,
descending in-degree) against the subset DP, engine by engine: min_cost_pair answers
with whichever engine finishes first, so each is run alone to completion here."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest

from rescon.graphs import _kernels as K
from rescon.graphs import search as se
from rescon.graphs.indexed import index_graph


def _engine_alone(ig, r: int, engine: str, order: np.ndarray) -> tuple[int, object]:
    """(least cost found below n, pair) by ``engine`` alone, roots in ``order``."""
    _, inmask, outmask, _ = se._kernel_inputs(ig)
    run = se.CostPartRun((K, inmask, outmask, order), engine, r, -1, se.whole_cost_part(ig.n),
                         ig.n)
    while run.advance(10_000) == K.RUNNING:
        pass
    return run.best, run.pair()


def _graphs():
    rng = np.random.default_rng(13)
    for k in range(60):
        n = int(rng.integers(4, 11))
        p = (0.3, 0.5, 0.7, 0.85)[k % 4]
        yield nx.gnp_random_graph(n, p, seed=int(rng.integers(1 << 30)), directed=True)
    # adversarial: in-degrees all tied (the order falls back to the index), and two
    # cliques joined by a matching (a cheap pair whose first node is late in either order)
    yield nx.circulant_graph(9, [1, 2, 4]).to_directed()
    two = nx.disjoint_union(nx.complete_graph(5), nx.complete_graph(5)).to_directed()
    two.add_edges_from((i, i + 5) for i in range(5))
    yield two


@pytest.mark.parametrize("G", list(_graphs()))
def test_charged_engine_in_its_order_matches_dp(G):
    ig = index_graph(G)
    inmask = np.array(ig.in_masks(), dtype=np.uint64)
    for r in range(1, (ig.n + 1) // 2 + 1):
        truth = int(K.min_pair_cost(inmask, r)[0])
        for order in (se.charged_search_order(ig), se.search_order(ig)):
            best, pair = _engine_alone(ig, r, "charged", order)
            assert best == truth, (r, order)
            if best < ig.n:
                S1, S2 = pair
                assert S1 and S2 and not S1 & S2


def test_charged_search_order_is_descending_in_degree():
    G = nx.DiGraph([(0, 1), (2, 1), (3, 1), (0, 2), (3, 2), (1, 3)])
    ig = index_graph(G)
    deg = ig.in_degrees
    order = se.charged_search_order(ig).tolist()
    assert sorted(order) == list(range(ig.n))
    assert all(deg[order[k]] >= deg[order[k + 1]] for k in range(ig.n - 1))


def _orders_used(monkeypatch, ig, **kw) -> dict[str, list[int]]:
    seen: dict[str, list[int]] = {}

    class Spy(se.CostPartRun):
        def __init__(self, inputs, engine, *args, **kwargs):
            seen[engine] = inputs[3].tolist()
            super().__init__(inputs, engine, *args, **kwargs)

    monkeypatch.setattr(se, "CostPartRun", Spy)
    se.min_cost_pair(ig, 2, ig.n, **kw)
    return seen


def test_engines_orders(monkeypatch):
    """The charged engine takes its own order on a whole search, the sized one's on a
    part (a root range must mean the same pairs to both engines)."""
    G = nx.DiGraph([(0, 1), (2, 1), (3, 1), (0, 2), (3, 2), (1, 3), (1, 0), (4, 0), (0, 4)])
    ig = index_graph(G)
    asc, desc = se.search_order(ig).tolist(), se.charged_search_order(ig).tolist()
    assert asc != desc
    assert _orders_used(monkeypatch, ig) == {"sized": asc, "charged": desc}
    assert _orders_used(monkeypatch, ig, roots=range(0, 3)) == {"sized": asc, "charged": asc}


def test_roots_parts_use_one_order():
    """The least of the parts' answers over a split into root ranges is s*(r), whichever
    engine is favoured. (On graphs this small the sized engine answers in its first
    slice, so this would not notice the charged engine taking another order on parts:
    test_engines_orders and test_review_v11's prefix test guard that.)"""
    for seed in range(8):
        G = nx.gnp_random_graph(9, 0.6, seed=seed, directed=True)
        ig = index_graph(G)
        inmask = np.array(ig.in_masks(), dtype=np.uint64)
        for r in (2, 3):
            truth = int(K.min_pair_cost(inmask, r)[0])
            parts = [range(0, 3), range(3, 6), range(6, 9)]
            for favour in ("sized", "charged"):
                got = min(se.min_cost_pair(ig, r, ig.n, roots=p, favour=favour).best
                          for p in parts)
                assert got == truth


def test_cluster_engines_keep_their_own_orders():
    """distributed._Engine sends each engine's parts with that engine's masks and order
    (its parts' root positions and frames are in its order; before the charged engine
    had its own order, all parts went with the sized run's)."""
    from rescon.graphs import distributed

    G = nx.gnp_random_graph(12, 0.5, seed=4, directed=True)
    ig = index_graph(G)
    inputs = se._kernel_inputs(ig)
    runs = [se.CostPartRun(inputs, "sized", 2, 0, se.whole_cost_part(ig.n), ig.n),
            se.CostPartRun((*inputs[:3], se.charged_search_order(ig)), "charged", 2, 0,
                           se.whole_cost_part(ig.n), ig.n)]
    for run in runs:
        run.advance(5)
        eng = distributed._Engine(run)
        assert eng.masks[2].tolist() == run.order.tolist()
