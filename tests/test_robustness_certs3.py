"""Charged trees whose maximal-pair leaf (-4) also checks the charged nodes of the
enumerated side (certificates/FORMAT.md, ``cost_search``): in a violating pair of least
cost, grown maximal, every charged node stays r-reachable. Checked against brute force
on small digraphs (sparse to complete): an independent tree builder that takes every
leaf the rules allow still finds a violating state exactly when s > s*(r); recorded
trees replay valid; tampered trees are rejected."""

from __future__ import annotations

import random
from itertools import combinations

import networkx as nx
import pytest

from rescon.graphs.charged import charged_order, charged_tree, uniform_tree, uniform_types
from rescon.graphs.indexed import index_graph
from tests.test_checker import C, digraph, in_masks, is_robust, rand_edges, rho_and_s

pytestmark = pytest.mark.usefixtures("fresh_facts")

GRAPHS = [(seed, n, p) for seed, (n, p) in enumerate(
    [(5, 0.5), (6, 0.6), (6, 0.8), (7, 0.5), (7, 0.7), (7, 0.9), (6, 1.0), (7, 0.4)] * 4)]


def _core(U: int, inm: list[int], t: list[int]) -> int:
    """Largest subset of U whose members i have < t[i] in-neighbours outside it."""
    while True:
        drop = [i for i in range(len(inm)) if U >> i & 1 and (inm[i] & ~U).bit_count() >= t[i]]
        if not drop:
            return U
        for i in drop:
            U &= ~(1 << i)


def _crowded(S: int, nodes: list[int], inm: list[int], t: list[int]) -> bool:
    return any((inm[j] & S).bit_count() > inm[j].bit_count() - t[j] for j in nodes)


def _refuted(n, inm, order, t1, t2, q1, S, X, B, before) -> bool:
    """True when every completion of the state (S, X) under B ends in a leaf the rules
    allow (-1, -2, -4 with the earlier roots ``before`` and the charged nodes of ``q1``);
    False when a closed S ⊆ P meets a nonempty Q (a violating state)."""
    full = (1 << n) - 1
    Q = _core(full & ~S & ~B, inm, t2)
    P = _core(full & ~X, inm, t1)
    charged = [j for j in range(n) if q1 >> j & 1]
    if not Q or S & ~P or _crowded(S, before + charged, inm, t1):
        return True
    needy = [i for i in range(n) if S >> i & 1 and (inm[i] & ~S).bit_count() >= t1[i]]
    if not needy:
        return False
    u = (inm[needy[0]] & P & ~S).bit_length() - 1  # any candidate will do
    return (_refuted(n, inm, order, t1, t2, q1, S | 1 << u, X, B, before)
            and _refuted(n, inm, order, t1, t2, q1, S, X | 1 << u, B, before))


def _parts(n: int, inm: list[int], r: int, s: int, uniform: bool):
    """(Q1, Q2, t1, t2) of every part, both orders: the configurations
    |Q1| + |Q2| ≤ s − 1, or the uniform types with t_k(i) = r + min(c_k, d_i)."""
    if uniform:
        for c1, c2 in uniform_types(s):
            for a, b in ((c1, c2), (c2, c1)):
                yield 0, 0, [r + min(a, m.bit_count()) for m in inm], \
                    [r + min(b, m.bit_count()) for m in inm]
        return
    for size in range(s):
        for Q in combinations(range(n), size):
            for mask in range(1 << size):
                q1 = sum(1 << v for j, v in enumerate(Q) if mask >> j & 1)
                q2 = sum(1 << v for v in Q) & ~q1
                yield q1, q2, *([r + (m & q).bit_count() for m in inm] for q in (q1, q2))


def _leafy_trees_exist(n: int, inm: list[int], r: int, s: int, uniform: bool = False) -> bool:
    """Whether every part (:func:`_parts`) has a tree of the allowed leaves: independent
    of rescon and of the checker."""
    order = sorted(range(n), key=lambda v: (inm[v].bit_count(), v))
    for q1, q2, t1, t2 in _parts(n, inm, r, s, uniform):
        B, before = q1 | q2, []
        for v in order:
            if B >> v & 1:
                continue
            if not _refuted(n, inm, order, t1, t2, q1, 1 << v, B, B, before):
                return False
            B |= 1 << v
            before.append(v)
    return True


@pytest.mark.parametrize("seed, n, p", GRAPHS[:16])
def test_leaf_rules_refute_exactly_the_robust_claims(seed, n, p):
    """Brute force: with -4 also on the charged nodes, trees of allowed leaves exist
    for every s ≤ s*(r) and for no s = s*(r) + 1 (the rule never hides the violating
    pair of least cost)."""
    _rules_agree(seed, n, p)


@pytest.mark.slow
@pytest.mark.parametrize("seed, n, p", GRAPHS[16:])
def test_leaf_rules_refute_exactly_the_robust_claims_more(seed, n, p):
    """The same on more random digraphs, sparse to complete."""
    _rules_agree(seed, n, p)


def _rules_agree(seed, n, p):
    edges = rand_edges(random.Random(seed), n, p)
    inm = in_masks(n, edges)
    rho, _ = rho_and_s(n, inm)
    for r in range(1, rho + 1):
        s_star = 1
        while s_star < n and is_robust(n, inm, r, s_star + 1):
            s_star += 1
        assert _leafy_trees_exist(n, inm, r, s_star)
        if s_star < n:
            assert not _leafy_trees_exist(n, inm, r, s_star + 1)
            assert not _leafy_trees_exist(n, inm, r, s_star + 1, uniform=True)


def _cert(ig, r, s, charged, **extra):
    proof = {"method": "cost_search", "order": charged_order(ig).tolist(),
             "charged_tree": list(charged), **extra}
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(),
            "r": r, "s": s, "proof": proof}


def _recorded(seeds=range(30), n=8, top=4):
    """(ig, r, s, tree) for every r ≤ ρ and 2 ≤ s ≤ min(s*(r), top) of random digraphs,
    dense (p ≥ 0.7) included."""
    for seed in seeds:
        p = (0.4, 0.6, 0.7, 0.85, 1.0)[seed % 5]
        edges = rand_edges(random.Random(seed), n, p, undirected=seed % 7 == 0)
        ig = index_graph(digraph(n, edges))
        inm = in_masks(n, ig.edges())
        for r in range(1, rho_and_s(n, inm)[0] + 1):
            s = 2
            while s <= top and is_robust(n, inm, r, s):
                yield ig, r, s, charged_tree(ig, r, s)
                s += 1


def test_recorded_trees_replay_and_tampered_ones_do_not():
    """Every recorded tree is valid; each branch token turned into any leaf (-1..-4:
    the recorder took every leaf that held), the last token removed, or a token added
    is invalid."""
    count = 0
    for ig, r, s, tree in _recorded():
        tree = list(tree)
        assert C.check(_cert(ig, r, s, tree)).verdict == "valid"
        branches = [k for k, t in enumerate(tree) if t >= 0]
        for k in branches[:2] + branches[-1:]:
            for leaf in (-1, -2, -3, -4):
                bad = tree[:k] + [leaf] + tree[k + 1:]
                assert C.check(_cert(ig, r, s, bad)).verdict == "invalid"
        for bad in (tree[:-1], tree + [-1]):
            assert C.check(_cert(ig, r, s, bad)).verdict == "invalid"
        count += 1
    assert count >= 20


def test_charged_nodes_justify_crowded_leaves(monkeypatch):
    """Some recorded trees hold -4 leaves that only a charged node of the enumerated
    side justifies: a checker that ignores the charged nodes rejects them."""
    def blind(self, t, charged=0):
        return real(self, t)

    needing = [(ig, r, s, tree) for ig, r, s, tree in _recorded(seeds=range(60))
               if -4 in tree]  # rarer since the capped leaves (5 of 60 seeds)
    assert needing
    real = C._Replay.threshold_side
    monkeypatch.setattr(C._Replay, "threshold_side", blind)
    rejected = [res for res in (C.check(_cert(*x)) for x in needing)
                if res.verdict == "invalid"]
    assert rejected and all("charged node" in res.reason for res in rejected)


@pytest.mark.slow
def test_er30_p05_s_star_2_certificate_is_smaller():
    """ER(30, 0.5) directed, seed 30001 (benchmark robustness_n30, i = 1): ρ = 8,
    s* = 2 settled by the charged-set engine; its charged tree (3.48M tokens before
    these leaves and tie-breaks) has < 2.8M and is valid, a cut one invalid."""
    G = nx.gnp_random_graph(30, 0.5, directed=True, seed=30001)
    ig = index_graph(G)
    tree = list(charged_tree(ig, 8, 2))
    assert len(tree) < 2_800_000
    assert C.check(_cert(ig, 8, 2, tree)).verdict == "valid"
    k = next(k for k, t in enumerate(tree) if t >= 0)
    assert C.check(_cert(ig, 8, 2, tree[:k] + [-1] + tree[k + 1:])).verdict == "invalid"


def test_uniform_trees_replay_and_exist_only_for_robust_claims():
    """Brute force: a uniform tree is recorded only for s ≤ s*(r) and is valid (with
    ``uniform``; a branch cut to a leaf is invalid); where none exists (a type has a
    violating pair) the configurations' tree claimed as uniform is invalid; malformed
    ``uniform`` keys are invalid."""
    kinds = {"tree": 0, "none": 0}
    for seed in range(30):
        n, p = 7, (0.5, 0.7, 0.9)[seed % 3]
        ig = index_graph(digraph(n, rand_edges(random.Random(seed), n, p)))
        inm = in_masks(n, ig.edges())
        r, s_star = rho_and_s(n, inm)
        for s in range(2, min(s_star + 1, 5) + 1):
            tree = uniform_tree(ig, r, s)
            if s > s_star:
                assert tree is None
            elif tree is not None:
                kinds["tree"] += 1
                assert C.check(_cert(ig, r, s, tree, uniform=True)).verdict == "valid"
                k = next((k for k, t in enumerate(tree) if t >= 0), None)
                if k is not None:
                    bad = list(tree[:k]) + [-1] + list(tree[k + 1:])
                    assert C.check(_cert(ig, r, s, bad, uniform=True)).verdict == "invalid"
            else:
                kinds["none"] += 1
                last = ig, r, s, charged_tree(ig, r, s)
                assert C.check(_cert(*last)).verdict == "valid"
                assert C.check(_cert(*last, uniform=True)).verdict == "invalid"
    assert min(kinds.values()) >= 3
    for extra in ({"uniform": False}, {"uniform": 1}, {"uniform": True, "tree": [-1]}):
        assert C.check(_cert(*last, **extra)).verdict == "invalid"


def test_robustness_attaches_the_smaller_charged_tree(monkeypatch):
    """_replayed: without a sized tree, the uniform tree when it is the smaller (its
    proof carries ``uniform``), else the configurations' tree; both valid."""
    from rescon.graphs import robustness as rb

    monkeypatch.setattr(rb, "cost_tree", lambda *a, **k: None)
    seen = set()
    for seed in range(40):
        ig = index_graph(nx.gnp_random_graph(9, 0.6, directed=True, seed=seed))
        r, s = rho_and_s(9, in_masks(9, ig.edges()))
        if s < 2:
            continue
        proof = rb._replayed(ig, r, s, {"method": "milp", "solver": "highs"}, None)
        uniform, configs = uniform_tree(ig, r, s), charged_tree(ig, r, s)
        smaller = uniform is not None and len(uniform) < len(configs)
        assert proof.get("uniform", False) is smaller
        assert list(proof["charged_tree"]) == list(uniform if smaller else configs)
        res = C.check({"rescon_certificate": 1, "kind": "rs_robust",
                       "graph": ig.graph_json(), "r": r, "s": s, "proof": proof})
        assert res.verdict == "valid"
        seen.add(smaller)
    assert seen == {True, False}
