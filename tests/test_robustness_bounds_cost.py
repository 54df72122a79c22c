"""The bounds phase of ``rescon.robustness`` on large dense graphs (V33 noticed: a
0.05-s limit took 2 s on ER(800, 0.5); measured 6–56 s at load ~4): the out-neighbour
lists were rebuilt for every r the bounds tried (O(|E|) Python each, ~r_upper times)
and the MILP built its model after the deadline had passed. Checked here against
independent computations."""

from __future__ import annotations

import random
import sys

import networkx as nx
import pytest

import rescon
from rescon.graphs import bounds as bd
from rescon.graphs import milp
from rescon.graphs.indexed import index_graph


def _calls(name: str, fn):
    """fn()'s result and how many Python frames of a function called ``name`` it ran."""
    count = 0

    def profile(frame, event, arg):
        nonlocal count
        if event == "call" and frame.f_code.co_name == name:
            count += 1

    sys.setprofile(profile)
    try:
        out = fn()
    finally:
        sys.setprofile(None)
    return out, count


def test_out_lists_built_once_per_graph_in_the_bounds():
    """Fixed (was a bug: the lower bound's scan from r_upper down rebuilt the lists at
    every r — 60+ times here, 213 times on ER(800, 0.5))."""
    G = nx.gnp_random_graph(160, 0.5, seed=3, directed=True)
    rep, built = _calls("_out_lists", lambda: rescon.robustness(G, time_limit=0.05))
    assert rep.r_upper is not None and rep.r_upper >= 20
    assert built <= 2  # this graph (and possibly a searched seed's subgraph)


def test_out_lists_are_the_reverse_of_in_neighbours():
    rng = random.Random(1)
    for seed in range(20):
        G = nx.gnp_random_graph(rng.randint(2, 30), rng.random(), seed=seed, directed=True)
        ig = index_graph(G)
        out = bd._out_lists(ig)
        assert sorted((u, v) for u in range(ig.n) for v in out[u]) == sorted(
            (u, v) for v in range(ig.n) for u in ig.in_nbrs[v])
        assert bd._out_lists(index_graph(G)) is out  # an equal graph: the same lists


def _source_sccs(G: nx.DiGraph) -> list[frozenset]:
    C = nx.condensation(G)
    members = C.graph["mapping"]
    comps: dict[int, set] = {}
    for v, c in members.items():
        comps.setdefault(c, set()).add(v)
    return [frozenset(comps[c]) for c in C.nodes if C.in_degree(c) == 0]


@pytest.mark.parametrize("seed", range(10))
def test_source_components_witness_against_networkx(seed):
    rng = random.Random(seed)
    n = rng.randint(2, 40)
    G = nx.gnp_random_graph(n, rng.choice([0.02, 0.05, 0.1, 0.3]), seed=seed, directed=True)
    ig = index_graph(G)  # nodes 0..n-1 in order: indices are the labels
    sources = _source_sccs(G)
    pair = bd.source_components_witness(ig)
    if len(sources) < 2:
        assert pair is None
        return
    assert pair is not None
    assert pair.S1 in sources and pair.S2 in sources and pair.S1 != pair.S2


def test_edges_sorted_as_before():
    G = nx.gnp_random_graph(60, 0.2, seed=7, directed=True)
    G.add_edge(5, 5)  # self-loops are ignored
    ig = index_graph(G)
    assert ig.edges() == sorted([u, v] for v, s in enumerate(ig.in_nbrs) for u in s)
    assert all(type(x) is int for e in ig.edges() for x in e)


def test_milp_past_its_deadline_builds_no_model(monkeypatch):
    """Fixed (was a bug: with no time left the MILP still built its model, ~1 s on a
    dense n = 800 graph, before HiGHS stopped at once)."""
    ig = index_graph(nx.complete_graph(6, create_using=nx.DiGraph))

    def refuse(*args, **kwargs):
        raise AssertionError("a model was built")

    monkeypatch.setattr(milp.RobustnessMilp, "__init__", refuse)
    out = milp.milp_min_cost(ig, 2, upper=1, decision_only=True, time_limit=0.0)
    assert out.status == "time_limit" and out.pair is None
