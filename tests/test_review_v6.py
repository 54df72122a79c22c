"""Review V6 (hostile): this session's charged / uniform certificate trees, the checker's
new -4 leaf and ``shrink``, the forced candidates of the searches, and the answers of
every method against brute force.

Each test is a failure found by fuzzing, or an independent guard: the adversarial tree
builder below takes *every* leaf the checker's own leaf tests accept, so a false claim
for which it completes a tree would be a false claim the checker accepts."""

from __future__ import annotations

import random

import networkx as nx
import pytest

import rescon
from benchmarks.baselines import leblanc_max_s, leblanc_rho
from tests.test_checker import C, in_masks, is_robust, rand_edges, rho_and_s

pytestmark = pytest.mark.usefixtures("fresh_facts")

# a 5-node digraph on which HiGHS 1.16's presolve reduces the s* MILP (r = 2,
# 0 ≤ cost ≤ 4) to empty with a point violating a row, and reports "Solve error"
PRESOLVE_TRAP = [(0, 2), (0, 3), (1, 0), (1, 2), (1, 3), (1, 4), (2, 0), (2, 1), (2, 3),
                 (2, 4), (3, 0), (3, 1), (3, 2), (4, 0), (4, 1), (4, 2), (4, 3)]


def _trap() -> nx.DiGraph:
    G = nx.DiGraph()
    G.add_nodes_from(range(5))
    G.add_edges_from(PRESOLVE_TRAP)
    return G


def test_milp_answers_where_highs_presolve_fails():
    """robustness / max_s / is_rs_robust with method="milp" on the trap digraph give
    LeBlanc's ρ = 2, s*(2) = 5 (they raised SolverError "HiGHS returned Solve error")."""
    G = _trap()
    assert (leblanc_rho(G), leblanc_max_s(G, 2)) == (2, 5)
    rep = rescon.robustness(G, method="milp")
    assert (rep.r_max, rep.s_max) == (2, 5)
    assert C.check(rep.certificate).verdict == "valid"
    assert rescon.max_s(G, 2, method="milp") == 5
    assert rescon.is_rs_robust(G, 2, 5, method="milp").holds is True


def _parts(rp, g, r: int, s: int, uniform: bool):
    """(gone, side1, side2) of every part of a charged tree, built with the checker's own
    ``threshold_side`` (FORMAT.md: the configurations, or the uniform types)."""
    if uniform:
        sides = {c: rp.threshold_side([r + min(c, d) for d in rp.deg]) if c else rp.side
                 for c in range(s)}
        for c2 in range((s - 1) // 2 + 1):
            yield 0, sides[s - 1 - c2], sides[c2]
        return
    for Q1, Q2 in C._configurations(g.n, s - 1):
        if not Q1:
            yield 0, rp.side, rp.side
            continue
        a, b = (rp.threshold_side([r + (mk & Q).bit_count() for mk in g.inmask], Q)
                if Q else rp.side for Q in (Q1, Q2))
        yield Q1 | Q2, a, b


def _greedy_tree(g, r: int, s: int, order: list[int], uniform: bool, rng) -> list[int] | None:
    """A charged tree taking, at every state, the first leaf (-1, -2, -4, -3) that the
    checker's own tests (``shrink``, ``crowded``, ``sizes``) justify, else branching on a
    random undecided node; None when a state with every node decided has no leaf (a
    violating pair: no tree of these rules exists along it)."""
    rp = C._Replay(g, r, "adversary")
    shrink, top, tokens = rp.shrink, rp.top, []
    for gone, a, b in _parts(rp, g, r, s, uniform):
        gone = rp.pack(gone)
        chain = {side: shrink(rp.full, side.D, side.gone | gone, side) for side in (a, b)}
        B, before = gone, []
        for v in order:
            S0 = 1 << top[v]
            if S0 & gone:
                continue
            for s1, s2 in ((a, b),) if a is b else ((a, b), (b, a)):
                stack = [(S0, B, *chain[s1], *shrink(*chain[s2], S0, s2))]
                while stack:
                    S, X, P, PD, Q, QD = stack.pop()
                    P, PD = shrink(P, PD, X, s1) if P & X else (P, PD)
                    Q, QD = shrink(Q, QD, S, s2) if Q & S else (Q, QD)
                    if not Q:
                        tokens.append(-1)
                    elif S & ~P:
                        tokens.append(-2)
                    elif rp.crowded(S, before, s1) is not None:
                        tokens.append(-4)
                    elif sum(rp.sizes(S, Q, s1, s2)) > (P | Q).bit_count():
                        tokens.append(-3)
                    else:
                        free = [u for u in range(g.n) if not (S | X) >> top[u] & 1]
                        if not free:
                            return None
                        u = rng.choice(free)
                        tokens.append(u)
                        stack += [(S, X | 1 << top[u], P, PD, Q, QD),
                                  (S | 1 << top[u], X, P, PD, Q, QD)]
            B |= S0
            before.append(v)
            chain = {side: shrink(*chain[side], S0, side) for side in chain}
    return tokens


def _claim(n, edges, r, s, order, tree, uniform):
    proof = {"method": "cost_search", "order": order, "charged_tree": tree,
             **({"uniform": True} if uniform else {})}
    return {"rescon_certificate": 1, "kind": "rs_robust",
            "graph": {"n": n, "edges": sorted(map(list, edges))}, "r": r, "s": s,
            "proof": proof}


def _adversary(seeds, nmax: int) -> dict[str, int]:
    """For random digraphs (sparse to complete, undirected ones too) and every r ≤ ρ + 1,
    s ≤ min(s*(r) + 1, 4) (brute force): the greedy tree exists exactly for the true
    claims (configurations; the uniform tree may not), is valid then, and for false
    claims it never exists — so no tree of checker-justified leaves proves them."""
    counts = {"true": 0, "false": 0}
    for seed in seeds:
        rng = random.Random(seed)
        n = rng.randint(2, nmax)
        edges = rand_edges(rng, n, rng.choice([0.3, 0.5, 0.7, 0.8, 0.9, 1.0]),
                           undirected=rng.random() < 0.3)
        inm = in_masks(n, edges)
        g = C.Graph(n, inm, len(edges))
        for r in range(1, rho_and_s(n, inm)[0] + 2):
            s_star = 0
            while s_star < n and is_robust(n, inm, r, s_star + 1):
                s_star += 1
            for s in range(1, min(s_star + 1, n, 4) + 1):
                for uniform in (False, True):
                    order = rng.sample(range(n), n)
                    tree = _greedy_tree(g, r, s, order, uniform, rng)
                    if s > s_star:
                        counts["false"] += 1
                        assert tree is None, (seed, r, s, uniform)
                    elif not uniform or tree is not None:
                        counts["true"] += 1
                        assert tree is not None, (seed, r, s)
                        res = C.check(_claim(n, edges, r, s, order, tree, uniform))
                        assert res.verdict == "valid", (seed, r, s, uniform, res.reason)
    return counts


def test_no_tree_of_checker_justified_leaves_proves_a_false_claim():
    counts = _adversary(range(40), 7)
    assert counts["true"] >= 100 and counts["false"] >= 50


@pytest.mark.slow
def test_no_tree_of_checker_justified_leaves_proves_a_false_claim_more():
    counts = _adversary(range(40, 240), 9)
    assert counts["true"] >= 500 and counts["false"] >= 250


def _part_trees(ig, r: int, s: int, uniform: bool) -> list[list[int]]:
    """The tree of each part of the charged (or uniform) tree, recorded one by one."""
    import numpy as np

    from rescon.graphs import charged as ch
    from rescon.graphs._charged_kernels import config_tree
    from rescon.graphs.search import _kernel_inputs

    _, inmask, outmask, _ = _kernel_inputs(ig)
    order = ch.charged_order(ig)
    masks, deg = ig.in_masks(), ig.in_degrees
    if uniform:
        parts = [((), (), [r + min(c1, d) for d in deg], [r + min(c2, d) for d in deg])
                 for c1, c2 in ch.uniform_types(s)]
    else:
        parts = [(Q1, Q2, *([r + (m & ch._mask(Q)).bit_count() for m in masks] for Q in (Q1, Q2)))
                 for Q1, Q2 in ch.configurations(ig.n, s - 1)]
    out = []
    for Q1, Q2, t1, t2 in parts:
        buf = np.empty(1 << 16, dtype=np.int32)
        k = config_tree(inmask, outmask, order, np.array(t1, dtype=np.int64),
                        np.array(t2, dtype=np.int64), not Q1 and t1 == t2,
                        np.uint64(ch._mask(Q1)), np.uint64(ch._mask(Q2)), buf, 0)
        assert k >= 0
        out.append(buf[:k].tolist())
    return out


def test_a_charged_tree_without_one_of_its_parts_is_invalid():
    """Charged and uniform trees (s = 2, 3) of random digraphs: the parts recorded one by
    one concatenate to the recorded tree, which is valid; without any one part (a
    configuration or a type dropped) it is invalid."""
    from rescon.graphs.charged import charged_order, charged_tree, uniform_tree
    from rescon.graphs.indexed import index_graph
    from tests.test_checker import digraph

    dropped = 0
    for seed in range(30):
        rng = random.Random(seed)
        n = rng.randint(3, 7)
        ig = index_graph(digraph(n, rand_edges(rng, n, rng.choice([0.5, 0.7, 0.9, 1.0]))))
        r, s_star = rho_and_s(n, in_masks(n, ig.edges()))
        for s in range(2, min(s_star, 3) + 1) if r else ():
            for uniform in (False, True):
                if uniform and uniform_tree(ig, r, s) is None:
                    continue
                parts = _part_trees(ig, r, s, uniform)
                whole = sum(parts, [])
                assert whole == list((uniform_tree if uniform else charged_tree)(ig, r, s))

                def verdict(tree, uniform=uniform, s=s, r=r, ig=ig):
                    proof = {"method": "cost_search", "order": charged_order(ig).tolist(),
                             "charged_tree": tree, **({"uniform": True} if uniform else {})}
                    return C.check({"rescon_certificate": 1, "kind": "rs_robust",
                                    "graph": ig.graph_json(), "r": r, "s": s,
                                    "proof": proof}).verdict

                assert verdict(whole) == "valid"
                for k in range(len(parts)):
                    assert verdict(sum(parts[:k] + parts[k + 1:], [])) == "invalid", (seed, s, k)
                    dropped += 1
    assert dropped >= 100
