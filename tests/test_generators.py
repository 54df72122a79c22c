"""Tests for rescon.graphs.generators against a brute-force robustness oracle.

Oracle (SPEC §1): rho(G) = min over disjoint nonempty S1, S2 of
max(e(S1), e(S2)), e(S) = max_{i in S} |N_in(i) \\ S|. ``_rho_pairs`` enumerates
all pairs literally; ``_rho`` computes the same minimum with a subset-minimum
transform (for each S1 the best S2 ranges over the subsets of V \\ S1) and is
checked against ``_rho_pairs`` first.
"""

from __future__ import annotations

import importlib.util
import itertools
import math
import sys
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

from rescon.errors import InputError
from rescon.graphs.generators import ba_robust, circulant, directed_growth, two_cliques
from rescon.graphs.indexed import index_graph
from rescon.io import read_graph

EXAMPLES = Path(__file__).parent.parent / "examples" / "graphs"
CHECK_PY = Path(__file__).parent.parent / "certificates" / "check.py"


def _in_sets(G: nx.Graph) -> list[set[int]]:
    pos = {v: i for i, v in enumerate(G.nodes())}
    ins: list[set[int]] = [set() for _ in pos]
    for u, v in G.edges():
        if u != v:
            ins[pos[v]].add(pos[u])
            if not G.is_directed():
                ins[pos[u]].add(pos[v])
    return ins


def _rho_pairs(G: nx.Graph) -> int:
    ins = _in_sets(G)
    n = len(ins)
    best = n
    for labels in itertools.product((0, 1, 2), repeat=n):
        S1 = {i for i in range(n) if labels[i] == 1}
        S2 = {i for i in range(n) if labels[i] == 2}
        if S1 and S2:
            e1 = max(len(ins[i] - S1) for i in S1)
            e2 = max(len(ins[i] - S2) for i in S2)
            best = min(best, max(e1, e2))
    return best


def _rho(G: nx.Graph) -> int:
    ins = _in_sets(G)
    n = len(ins)
    full = (1 << n) - 1
    masks = np.arange(1 << n, dtype=np.int64)
    popcount = np.zeros(1 << n, dtype=np.int64)
    for b in range(n):
        popcount += (masks >> b) & 1
    e = np.zeros(1 << n, dtype=np.int64)
    for i, s in enumerate(ins):
        outside = popcount[sum(1 << j for j in s) & ~masks & full]
        e = np.maximum(e, np.where((masks >> i) & 1 == 1, outside, 0))
    best_sub = np.where(masks == 0, n + 1, e)  # min of e over nonempty subsets
    for b in range(n):
        view = best_sub.reshape(-1, 2, 1 << b)
        view[:, 1, :] = np.minimum(view[:, 1, :], view[:, 0, :])
    S1 = masks[1:full]
    return int(np.min(np.maximum(e[S1], best_sub[full & ~S1])))


def _check_construction(G: nx.Graph) -> None:
    """The stored order: complete seed of size >= 2 rho - 1, then >= rho earlier in-neighbours."""
    order, m, rho = G.graph["construction_order"], G.graph["seed_size"], G.graph["rho"]
    assert sorted(order) == sorted(G.nodes())
    assert 2 * rho - 1 <= m <= len(order)
    D = G if G.is_directed() else G.to_directed()
    seed = order[:m]
    assert all(D.has_edge(u, v) for u in seed for v in seed if u != v)
    for k in range(m, len(order)):
        earlier = set(order[:k])
        assert len(set(D.predecessors(order[k])) & earlier) >= rho


def test_oracle_matches_pair_enumeration():
    rng = np.random.default_rng(5)
    for t in range(40):
        n = int(rng.integers(2, 8))
        G = nx.gnp_random_graph(n, rng.uniform(0.2, 0.9), seed=int(rng.integers(1 << 30)),
                                directed=bool(t % 2))
        assert _rho(G) == _rho_pairs(G)
    for n in range(2, 9):
        assert _rho(nx.complete_graph(n)) == math.ceil(n / 2)
    assert _rho(nx.path_graph(6)) == 1
    assert _rho(nx.DiGraph([(0, 1), (2, 1)])) == 0  # two source components


@pytest.mark.parametrize("m", [1, 2, 3, 4])
def test_ba_robust(m):
    for n in range(max(2, 2 * m - 1), 13):
        G = ba_robust(n, m, seed=n)
        assert type(G) is nx.Graph and G.number_of_nodes() == n
        assert G.graph["rho"] == m == _rho(G)
        _check_construction(G)


@pytest.mark.parametrize("k", [1, 2, 3, 4])
def test_directed_growth(k):
    for n in range(max(2, 2 * k - 1), 13):
        G = directed_growth(n, k, seed=np.random.default_rng(n))
        assert G.is_directed()
        assert G.graph["rho"] == k == _rho(G)
        _check_construction(G)


@pytest.mark.parametrize("directed", [False, True])
def test_circulant_formulas_over_whole_range(directed):
    for n in range(2, 16):
        for k in range(1, n):
            G = circulant(n, k, directed=directed)
            assert G.graph["rho"] == _rho(G), (n, k)
            if "construction_order" in G.graph:
                _check_construction(G)


@pytest.mark.parametrize(("n", "k", "directed"), [(17, 5, False), (16, 6, True), (17, 6, True)])
def test_circulant_larger(n, k, directed):
    G = circulant(n, k, directed=directed)
    assert G.graph["rho"] == _rho(G)


def test_circulant_values():
    assert circulant(20, 3).graph["rho"] == 3
    assert circulant(7, 3).graph["rho"] == 4  # K_7
    assert [circulant(n, 2, directed=True).graph["rho"] for n in (8, 9)] == [1, 2]
    assert circulant(9, 3, directed=True).graph["rho"] == 2
    assert set(circulant(6, 2, directed=True).predecessors(0)) == {4, 5}


def test_two_cliques():
    for m in range(1, 7):
        for b in range(m + 1):
            G = two_cliques(m, b, seed=10 * m + b)
            assert G.graph["rho"] == b == _rho(G)
            degrees = {d for _, d in G.degree()}
            assert degrees == {m - 1 + b}
            if "construction_order" in G.graph:
                _check_construction(G)
            assert ("construction_order" in G.graph) == (b == m or (b >= 1 and m >= 2 * b - 1))


def test_seeds_reproduce():
    assert nx.utils.graphs_equal(ba_robust(30, 3, seed=4), ba_robust(30, 3, seed=4))
    assert nx.utils.graphs_equal(directed_growth(30, 3, seed=4), directed_growth(30, 3, seed=4))
    assert nx.utils.graphs_equal(two_cliques(8, 3, seed=4), two_cliques(8, 3, seed=4))


def test_large_instances_keep_certificates():
    G = directed_growth(500, 4, seed=1)
    assert G.number_of_edges() == 7 * 6 + 4 * (500 - 7)
    _check_construction(G)
    _check_construction(ba_robust(300, 5, seed=2))


@pytest.mark.skipif(not CHECK_PY.exists(), reason="certificates/check.py not present")
def test_construction_orders_pass_the_independent_checker(monkeypatch):
    spec = importlib.util.spec_from_file_location("_rescon_check_for_generators", CHECK_PY)
    checker = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, checker)  # dataclasses look the module up
    spec.loader.exec_module(checker)
    graphs = [ba_robust(200, 4, seed=1), directed_growth(300, 3, seed=2), circulant(40, 2),
              circulant(9, 8, directed=True), two_cliques(9, 4, seed=3), two_cliques(5, 5, seed=4)]
    for G in graphs:
        ig = index_graph(G)
        pos = {v: i for i, v in enumerate(ig.nodes)}
        cert = {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(),
                "r": G.graph["rho"], "s": 1,
                "proof": {"method": "construction",
                          "order": [pos[v] for v in G.graph["construction_order"]],
                          "seed_size": G.graph["seed_size"],
                          "seed_proof": {"method": "complete"}}}
        result = checker.check(cert)
        assert result.valid, result.reason


@pytest.mark.parametrize(
    ("call", "pattern"),
    [
        (lambda: ba_robust(4, 3), r"n must be an integer >= 5; got 4"),
        (lambda: ba_robust(10, 0), r"m must be an integer >= 1; got 0"),
        (lambda: ba_robust(10, True), r"m must be an integer >= 1; got True"),
        (lambda: ba_robust(10, 2, seed=-1), r"seed must be None, a nonnegative int"),
        (lambda: ba_robust(10, 2, seed="x"), r"seed must be None"),
        (lambda: directed_growth(1, 1), r"n must be an integer >= 2; got 1"),
        (lambda: directed_growth(10, 2.0), r"k must be an integer >= 1; got 2.0"),
        (lambda: circulant(5, 5), r"k must be an integer with 1 <= k <= n - 1 = 4; got k=5"),
        (lambda: circulant(1, 1), r"n must be an integer >= 2"),
        (lambda: two_cliques(3, 4), r"b must be an integer with 0 <= b <= m = 3; got b=4"),
        (lambda: two_cliques(0, 0), r"m must be an integer >= 1"),
        (lambda: two_cliques(3, -1), r"b must be a nonnegative integer"),
    ],
)
def test_argument_errors(call, pattern):
    with pytest.raises(InputError, match=pattern):
        call()


def test_paper_example_is_at_most_5_robust():
    G = read_graph(EXAMPLES / "paper_example.edgelist")
    assert _rho(G) == 5


def test_shipped_examples_match_generators():
    ring = read_graph(EXAMPLES / "ring_lattice_20.edgelist", undirected=True)
    assert nx.utils.edges_equal(sorted(ring.edges()), sorted(circulant(20, 3).edges()))
    cliques = read_graph(EXAMPLES / "two_cliques.graphml", undirected=True)
    assert _rho(cliques) == cliques.graph["rho"] == 2
