"""Tests for rescon.graphs.attacks: F-local / F-total models and Assumption 2."""

from __future__ import annotations

from pathlib import Path

import networkx as nx
import numpy as np
import pytest

from rescon.errors import InputError
from rescon.graphs.attacks import check_assumption2, check_attack_model
from rescon.io import read_graph

PAPER = Path(__file__).parent.parent / "examples" / "graphs" / "paper_example.edgelist"
IN_NBRS = {1: [2, 3, 5, 7, 9, 10, 11, 12], 3: [1, 2, 4, 5, 6, 7, 11], 4: [2, 3, 5, 8, 9, 10, 12],
           5: [1, 3, 4, 6, 7, 11, 12], 6: [2, 3, 5, 7, 9, 10, 11], 7: [1, 2, 3, 5, 8, 9, 10, 11],
           8: [2, 3, 5, 7, 9, 11, 12], 9: [1, 3, 5, 7, 8, 10, 12], 10: [1, 3, 5, 7, 9, 11, 12],
           11: [1, 3, 4, 5, 8, 9, 12]}


@pytest.fixture(scope="module")
def paper() -> nx.DiGraph:
    return read_graph(PAPER)


def test_paper_example_is_2_local(paper):
    r = check_attack_model(paper, [2, 12], 2)
    assert r.holds and r.violations == () and (r.model, r.F) == ("local", 2)


def test_paper_example_is_not_1_local(paper):
    r = check_attack_model(paper, {12, 2}, 1)
    expected = tuple((i, (2, 12)) for i in sorted(IN_NBRS) if {2, 12} <= set(IN_NBRS[i]))
    assert not r.holds and r.violations == expected
    assert [v for v, _ in r.violations] == [1, 4, 8]


def test_total_model(paper):
    assert check_attack_model(paper, [2, 12], 2, model="total").holds
    r = check_attack_model(paper, [12, 2, 2], 1, model="total")
    assert not r.holds and r.violations == ((None, (2, 12)),)


def test_local_model_ignores_adversaries_own_in_neighbours():
    G = nx.DiGraph([(0, 1), (2, 1), (0, 3), (2, 3)])
    assert check_attack_model(G, [0, 2, 3], 1).violations == ((1, (0, 2)),)
    assert check_attack_model(G, [], 0).holds


def test_paper_example_assumption2(paper):
    r = check_assumption2(paper, d=2, F=2, adversaries=[2, 12])
    assert r.holds and r.required == 7
    r = check_assumption2(paper, d=3, F=2, adversaries=[2, 12])
    assert r.required == 9
    assert r.violations == tuple((i, len(IN_NBRS[i])) for i in sorted(IN_NBRS))


def test_assumption2_counts_undirected_edges_both_ways_and_ignores_self_loops():
    G = nx.star_graph(3)
    G.add_edge(1, 1)
    r = check_assumption2(G, d=0, F=1)
    assert r.required == 2 and r.violations == ((1, 1), (2, 1), (3, 1))
    assert check_assumption2(G, d=0, F=1, adversaries=[1, 2, 3]).holds
    assert check_assumption2(G, d=5, F=0).holds


@pytest.mark.parametrize(
    ("call", "pattern"),
    [
        (lambda G: check_attack_model(G, [7], 1), r"adversaries contains 7, which is not a node"),
        (lambda G: check_attack_model(G, [[1]], 1), r"adversaries contains \[1\], which is not"),
        (lambda G: check_attack_model(G, 1, 1), r"adversaries must be an iterable .* got int"),
        (lambda G: check_attack_model(G, "12", 1), r"adversaries must be an iterable .* got str"),
        (lambda G: check_attack_model(G, [1], True), r"F must be a nonnegative integer; got True"),
        (lambda G: check_attack_model(G, [1], -1), r"F must be a nonnegative integer; got -1"),
        (lambda G: check_attack_model(G, [1], 1.0), r"F must be a nonnegative integer; got 1.0"),
        (lambda G: check_attack_model(G, [1], 1, model="global"),
         r"model must be one of \('local', 'total'\); got 'global'"),
        (lambda G: check_assumption2(G, -1, 1), r"d must be a nonnegative integer; got -1"),
        (lambda G: check_assumption2(G, 2, False), r"F must be a nonnegative integer; got False"),
        (lambda G: check_assumption2(G, 2, 1, adversaries=[0]), r"adversaries contains 0"),
        (lambda G: check_attack_model(nx.DiGraph(), [], 1), r"G must have at least 1 nodes"),
        (lambda G: check_assumption2({1: [2]}, 2, 1), r"G must be a networkx Graph .* got dict"),
    ],
)
def test_input_errors(call, pattern):
    G = nx.DiGraph([(1, 2), (2, 3)])
    with pytest.raises(InputError, match=pattern):
        call(G)


def test_numpy_integers_accepted():
    G = nx.complete_graph(4)
    assert check_attack_model(G, [np.int64(0)], np.int64(1)).holds
    assert check_assumption2(G, np.int32(1), np.int64(1)).holds
