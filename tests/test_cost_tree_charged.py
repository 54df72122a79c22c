"""The charged tree of a ``cost_search`` proof (certificates/FORMAT.md): one decision
tree per configuration of charged nodes, recorded by rescon.graphs.charged and
replayed by the checker; checked against brute force on small digraphs (sparse to
complete), with tampered trees and claims rejected."""

from __future__ import annotations

import random

import networkx as nx
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from rescon.graphs import robustness as rb
from rescon.graphs.charged import (
    charged_order,
    charged_tree,
    configurations,
    count_configurations,
)
from rescon.graphs.indexed import index_graph
from tests.test_checker import C, _validator, digraph, in_masks, is_robust, rand_edges, rho_and_s
from tests.test_rho_tree import _cut_branch

pytestmark = pytest.mark.usefixtures("fresh_facts")


def _graph(n, edges):
    return index_graph(digraph(n, edges))


def _proof(ig, tree):
    return {"method": "cost_search", "order": charged_order(ig).tolist(),
            "charged_tree": list(tree)}


def _cert(ig, r, s, proof):
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(),
            "r": r, "s": s, "proof": proof}


def _verdict(ig, r, s, proof):
    return C.check(_cert(ig, r, s, proof)).verdict


def _cut(proof):
    """``proof`` with its first branch token cut to a leaf."""
    return {**proof, "charged_tree": _cut_branch({"tree": proof["charged_tree"]})["tree"]}


@pytest.mark.parametrize("seed, n, p, undirected",
                         [(1, 7, 0.5, False), (2, 8, 0.7, False), (3, 8, 0.9, False),
                          (4, 8, 1.0, False), (5, 8, 0.5, True), (6, 7, 0.8, True)])
def test_charged_trees_prove_exactly_the_brute_force_s_star(seed, n, p, undirected):
    """For every r ≤ ρ (brute force): the charged tree below each s ≤ s*(r) is valid; below
    s*(r) + 1 none is recorded (a cheaper pair exists), and the tree below s*(r) claimed
    for s*(r) + 1, or with its first branch cut to a leaf, is invalid."""
    _agree_with_brute_force(seed, n, p, undirected)


@pytest.mark.slow
@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(3, 8), p=st.floats(0.3, 1.0),
       undirected=st.booleans())
def test_charged_trees_prove_exactly_the_brute_force_s_star_random(seed, n, p, undirected):
    """The same on random digraphs, sparse to complete."""
    _agree_with_brute_force(seed, n, p, undirected)


def _agree_with_brute_force(seed, n, p, undirected):
    edges = rand_edges(random.Random(seed), n, p, undirected)
    ig = _graph(n, edges)
    inm = in_masks(n, ig.edges())
    rho, _ = rho_and_s(n, inm)
    for r in range(1, rho + 1):
        s_star = 1
        while s_star < n and is_robust(n, inm, r, s_star + 1):
            s_star += 1
        for s in range(1, s_star + 1):
            proof = _proof(ig, charged_tree(ig, r, s))
            assert _verdict(ig, r, s, proof) == "valid"
        if any(t >= 0 for t in proof["charged_tree"]):
            assert _verdict(ig, r, s_star, _cut(proof)) == "invalid"
        if s_star < n:
            assert _verdict(ig, r, s_star + 1, proof) == "invalid"
            with pytest.raises(ValueError, match="cheaper than s"):
                charged_tree(ig, r, s_star + 1)


def test_configurations_are_counted_and_distinct_up_to_swapping():
    """(Q1, Q2) pairs of disjoint sets, |Q1| + |Q2| ≤ c, each swapped pair once."""
    for n, c in ((5, 0), (5, 1), (6, 2), (7, 3)):
        seen = list(configurations(n, c))
        assert len(seen) == count_configurations(n, c)
        keys = {(frozenset(a), frozenset(b)) for a, b in seen}
        assert len(keys) == len(seen)
        assert not any((b, a) in keys for a, b in keys if a != b)
        assert all(not set(a) & set(b) and len(a) + len(b) <= c for a, b in seen)
        n_pairs = sum(1 for k in range(c + 1) for _ in _splits(n, k))
        assert (n_pairs + 1) // 2 == len(seen)


def _splits(n, k):
    """Every ordered (Q1, Q2) of disjoint sets with |Q1| + |Q2| = k (brute force)."""
    for a in range(1 << n):
        for b in range(1 << n):
            if not a & b and (a | b).bit_count() == k:
                yield a, b


def test_tampered_charged_trees_are_invalid():
    """Each field: unknown tokens, -4 in a ``search`` tree, both trees, a token more or
    less, and a wrong r are all rejected."""
    ig, r, s = next((ig, *rho_and_s(8, in_masks(8, ig.edges())))
                    for ig in (_graph(8, rand_edges(random.Random(seed), 8, 0.7))
                               for seed in range(100))
                    if rho_and_s(8, in_masks(8, ig.edges()))[1] >= 2)
    proof = _proof(ig, charged_tree(ig, r, s))
    assert _verdict(ig, r, s, proof) == "valid"
    _validator().validate(_cert(ig, r, s, proof))  # the JSON schema knows the field
    tree = proof["charged_tree"]
    for bad in ([-5] + tree[1:], tree + [-1], tree[:-1], [0.0] + tree[1:]):
        assert _verdict(ig, r, s, {**proof, "charged_tree": bad}) == "invalid"
    assert _verdict(ig, r, s, {**proof, "tree": [-1]}) == "invalid"
    assert _verdict(ig, r + 1, 1, proof) == "invalid"
    search = {"method": "search", "order": proof["order"], "tree": [-4] * 8}
    assert "not a token" in C.check(_cert(ig, r, 1, search)).reason


def test_crowded_leaves_are_checked():
    """Recorded trees use -4 leaves (valid: an earlier root j has more than d_j − t_j
    in-neighbours in S); one at root 0's first leaf (no earlier root) is rejected."""
    for seed in range(40):
        ig = _graph(8, rand_edges(random.Random(seed), 8, 0.6))
        r, s = rho_and_s(8, in_masks(8, ig.edges()))
        tree = list(charged_tree(ig, r, s)) if r else []
        if -4 in tree:
            break
    else:
        pytest.fail("no recorded tree with a -4 leaf")
    proof = _proof(ig, tree)
    assert _verdict(ig, r, s, proof) == "valid"
    first_leaf = next(k for k, t in enumerate(tree) if t < 0)
    bad = tree[:first_leaf] + [-4] + tree[first_leaf + 1:]
    res = C.check(_cert(ig, r, s, {**proof, "charged_tree": bad}))
    assert res.verdict == "invalid" and "no earlier root" in res.reason


def test_sized_tree_failure_falls_back_to_the_charged_tree(monkeypatch):
    """_replayed: when the sized tree is not recorded, a trusted s* proof (s ≥ 2)
    becomes the charged tree; for s = 1 nothing changes."""
    ig = index_graph(nx.gnp_random_graph(10, 0.6, directed=True, seed=3))
    r, s = rho_and_s(10, in_masks(10, ig.edges()))
    assert s >= 2
    monkeypatch.setattr(rb, "cost_tree", lambda *a, **k: None)
    milp = {"method": "milp", "solver": "highs"}
    proof = rb._replayed(ig, r, s, milp, None)
    assert proof["charged_tree"] and proof["info"]["decided_by"] == "milp"
    assert _verdict(ig, r, s, proof) == "valid"
    assert rb._replayed(ig, r, 1, milp, None) is milp


@pytest.mark.slow
def test_er30_s_star_certificate_is_fully_checked():
    """ER(30, 0.3) directed, seed 30001 (benchmark robustness_n30): ρ = 4, s* = 2, settled
    by the charged-set engine; its sized tree is beyond 4M tokens, the charged tree has
    ~16k: the whole certificate is valid, a cut one invalid."""
    G = nx.gnp_random_graph(30, 0.3, directed=True, seed=30001)
    rep = rescon.robustness(G)
    assert (rep.r_max, rep.s_max) == (4, 2)
    lower_s = rep.certificate["lower_s"]
    assert lower_s["method"] == "cost_search" and len(lower_s["charged_tree"]) < 100_000
    check = rescon.check_certificate(rep.certificate)
    assert check.verdict == "valid" and check.trusted == ()
    bad = {**rep.certificate, "lower_s": _cut(lower_s)}
    assert rescon.check_certificate(bad).verdict == "invalid"


def test_no_charged_tree_beyond_its_limits():
    """None, never a partial tree: too many configurations, a token budget the first
    configuration shows to be too small, a passed deadline, r < 1."""
    ig = index_graph(nx.gnp_random_graph(20, 0.5, directed=True, seed=2))
    assert count_configurations(20, 5) > 20_000 and charged_tree(ig, 1, 6) is None
    assert charged_tree(ig, 0, 2) is None
    full = charged_tree(ig, 1, 2)
    assert full is not None and charged_tree(ig, 1, 2, max_tokens=len(full) // 4) is None
    assert charged_tree(ig, 1, 2, deadline=0.0) is None
