"""The checker's incremental replay of ``search`` trees (issue 13 §4).

The checker keeps P = core_r(V \\ X) and Q = core_r(V \\ S \\ B) along the tree, each
child's set re-peeled from its parent's with packed deficit counters
(``_Replay.shrink``). Here its verdicts are compared with a plain replay that
recomputes every core from scratch at every leaf (FORMAT.md, written out below):
on the trees rescon's branch and bound records for random digraphs, and on the same
trees tampered with. Its cores are compared with a from-scratch peel.
"""

from __future__ import annotations

import random
import time

import networkx as nx
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rescon.graphs.indexed import index_graph
from rescon.graphs.search import decide_r_robust
from tests.test_checker import C  # the checker file of this repository

# --------------------------------------------------------------------------- #
# the plain replay of FORMAT.md: every core from scratch
# --------------------------------------------------------------------------- #


def bits(mask: int) -> list[int]:
    return [i for i in range(mask.bit_length()) if mask >> i & 1]


def peel(inm: list[int], U: int, r: int) -> int:
    """core_r(U), pass by pass."""
    changed = True
    while changed:
        changed = False
        for i in bits(U):
            if (inm[i] & ~U).bit_count() >= r:
                U &= ~(1 << i)
                changed = True
    return U


def leaf_holds(n: int, inm: list[int], r: int, t: int, S: int, X: int, B: int) -> bool:
    full = (1 << n) - 1
    Q = peel(inm, full & ~S & ~B, r)
    P = peel(inm, full & ~X, r)
    if t == -1:
        return Q == 0
    if t == -2:
        return bool(S & ~P)
    need1 = S.bit_count() + max([0] + [(inm[i] & ~S).bit_count() - r + 1 for i in bits(S)])
    need2 = min([n + 1] + [max(1, inm[j].bit_count() - r + 2) for j in bits(Q)])
    return need1 + need2 > (P | Q).bit_count()


def plain_replay(n: int, inm: list[int], r: int, order: list[int], tree: list[int]) -> str:
    """'' if the tree proves r-robustness, else the phrase the checker's reason holds."""
    pos, B = 0, 0
    for k in range(n):
        stack = [(1 << order[k], B)]
        while stack:
            S, X = stack.pop()
            if pos >= len(tree):
                return "search tree ends early"
            t = tree[pos]
            if t >= 0:
                if (S | X) >> t & 1:
                    return f"branches at token {pos} on node {t}"
                stack.append((S, X | 1 << t))
                stack.append((S | 1 << t, X))
            elif not leaf_holds(n, inm, r, t, S, X, B):
                return f"leaf {t} at token {pos} is not justified"
            pos += 1
        B |= 1 << order[k]
    return "" if pos == len(tree) else "unused tokens"


# --------------------------------------------------------------------------- #
# certificates
# --------------------------------------------------------------------------- #


def random_digraph(rng: random.Random, n: int, p: float) -> nx.DiGraph:
    G = nx.DiGraph()
    G.add_nodes_from(range(n))
    G.add_edges_from((u, v) for u in range(n) for v in range(n) if u != v and rng.random() < p)
    return G


def in_masks(n: int, edges: list[list[int]]) -> list[int]:
    inm = [0] * n
    for u, v in edges:
        inm[v] |= 1 << u
    return inm


def search_cert(G: nx.DiGraph, r: int) -> dict | None:
    """An rs_robust certificate with rescon's search tree, or None if G is not r-robust."""
    ig = index_graph(G)
    out = decide_r_robust(ig, r)
    if out.status != "robust":
        return None
    edges = [[u, v] for v, nbrs in enumerate(ig.in_nbrs) for u in nbrs]
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": {"n": ig.n, "edges": edges},
            "r": r, "s": 1,
            "proof": {"method": "search", "order": list(out.order), "tree": list(out.tree)}}


def token_list_cert(rng: random.Random, G: nx.DiGraph, r: int) -> dict:
    """An rs_robust certificate whose "tree" is a random token list (no tree behind it)."""
    n = G.number_of_nodes()
    order = list(range(n))
    rng.shuffle(order)
    tree = [rng.choice([-1, -1, -2, -2, -3, *range(n)]) for _ in range(rng.randint(n, 6 * n))]
    return {"rescon_certificate": 1, "kind": "rs_robust",
            "graph": {"n": n, "edges": [list(e) for e in G.edges]}, "r": r, "s": 1,
            "proof": {"method": "search", "order": order, "tree": tree}}


def tampered(rng: random.Random, tree: list[int], n: int) -> list[int]:
    """The tree with one token changed, dropped, inserted or two swapped."""
    bad = list(tree)
    k = rng.randrange(len(bad))
    how = rng.randrange(4)
    if how == 0:
        bad[k] = rng.randint(-3, n - 1)
    elif how == 1:
        del bad[k]
    elif how == 2:
        bad.insert(k, rng.randint(-3, n - 1))
    else:
        j = rng.randrange(len(bad))
        bad[k], bad[j] = bad[j], bad[k]
    return bad


def agree(cert: dict) -> str:
    """Check ``cert`` with the checker and with the plain replay: same verdict, and an
    invalid tree is refuted at the same token for the same reason."""
    n, r = cert["graph"]["n"], cert["r"]
    proof = cert["proof"]
    expect = plain_replay(n, in_masks(n, cert["graph"]["edges"]), r, proof["order"],
                          proof["tree"])
    res = C.check(cert)
    if expect:
        assert res.verdict == "invalid" and expect in res.reason, (expect, res)
    else:
        assert res.verdict == "valid", res
    return expect


# --------------------------------------------------------------------------- #
# tests
# --------------------------------------------------------------------------- #


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(2, 12), p=st.floats(0.2, 0.95))
def test_replay_verdicts_equal_the_plain_replay(seed, n, p):
    """rescon's tree for the largest r it proves by search (a random token list when G
    is not even 1-robust), then tampered trees (tokens changed, dropped, inserted,
    swapped; other r): the checker accepts exactly what the from-scratch replay
    accepts."""
    rng = random.Random(seed)
    G = random_digraph(rng, n, p)
    cert = next((c for r in range((n + 1) // 2, 0, -1) if (c := search_cert(G, r))), None)
    if cert is None:
        cert = token_list_cert(rng, G, 1)
    else:
        assert agree(cert) == ""
    tree = cert["proof"]["tree"]
    for _ in range(12):
        agree({**cert, "proof": {**cert["proof"], "tree": tampered(rng, tree, n)}})
    for r2 in (cert["r"] + 1, cert["r"] - 1, 0, n + 2):
        agree({**cert, "r": r2})


@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 10), r=st.integers(0, 12))
def test_random_token_lists_get_the_plain_verdict(seed, n, r):
    """Token lists with no tree behind them (any r, including 0 and r > n)."""
    rng = random.Random(seed)
    G = random_digraph(rng, n, rng.uniform(0.2, 1.0))
    for _ in range(5):
        agree(token_list_cert(rng, G, r))


@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 16), r=st.integers(0, 18))
def test_shrink_is_the_core(seed, n, r):
    """_Replay.shrink(U, D, gone) = core_r(U \\ gone) for a closed U, node after node
    (with D carried along), down to the empty set."""
    rng = random.Random(seed)
    G = random_digraph(rng, n, rng.uniform(0.1, 1.0))
    inm = in_masks(n, [list(e) for e in G.edges])
    g = C.Graph(n, inm, G.number_of_edges())
    R = C._Replay(g, r, "proof")
    U = peel(inm, (1 << n) - 1, r)
    packed, D = R.shrink(R.full, R.side.D, R.side.gone, R.side)  # core_r(V) from V
    assert R.unpack(packed) == U
    while U:
        gone = 1 << rng.choice(bits(U) + bits(((1 << n) - 1) & ~U))
        # with a watched set: the core when it keeps the whole set, else a set between
        # the core and U \ gone that misses a watched node
        watch = rng.getrandbits(n)
        core = peel(inm, U & ~gone, r)
        seen = R.unpack(R.shrink(packed, D, R.pack(gone), R.side, R.pack(watch))[0])
        if watch & ~core:
            assert core & ~seen == 0 and seen & ~(U & ~gone) == 0 and watch & ~seen
        else:
            assert seen == core
        U = core
        packed, D = R.shrink(packed, D, R.pack(gone), R.side)
        assert R.unpack(packed) == U


def test_tokens_are_checked_in_one_pass():
    cert = search_cert(random_digraph(random.Random(3), 8, 0.9), 2)
    assert cert is not None and C.check(cert).valid
    for tok, k in ((True, 1), (1.0, 2), ("1", 0), (None, 3), (-4, 4), (8, 1)):
        tree = list(cert["proof"]["tree"])
        tree[k] = tok
        res = C.check({**cert, "proof": {**cert["proof"], "tree": tree}})
        assert res.verdict == "invalid" and f"tree[{k}] = {tok!r} is not a token" in res.reason


def _dense(n: int, p: float, seed: int) -> nx.DiGraph:
    return nx.gnp_random_graph(n, p, seed=seed, directed=True)


@pytest.mark.slow
def test_a_million_token_tree_for_n_25_is_replayed_within_the_limit():
    """ER(25, 0.8) directed (benchmark seed 25001), r = 11: rescon's tree has about a
    million tokens. The from-scratch replay needed ~8 s and stopped at its work limit
    (unchecked: n = 25 is beyond the checker's enumeration); now it is verified."""
    cert = search_cert(_dense(25, 0.8, 25001), 11)
    assert cert is not None and len(cert["proof"]["tree"]) > 900_000
    t0 = time.perf_counter()
    res = C.check(cert)
    seconds = time.perf_counter() - t0
    assert res.verdict == "valid", res  # n = 25 > 20: within the work limit
    assert seconds < 30, seconds
    # the last token (a leaf of the last root, whose S holds order[n - 1]) made a
    # branch on order[n - 1]: refuted after replaying the whole tree
    tree = list(cert["proof"]["tree"])
    last = cert["proof"]["order"][-1]
    tree[-1] = last
    res = C.check({**cert, "proof": {**cert["proof"], "tree": tree}})
    assert res.verdict == "invalid", res
    assert f"at token {len(tree) - 1} on node {last}, which is already in S" in res.reason


def test_over_the_limit_is_unchecked_beyond_enumeration(monkeypatch):
    """A valid tree whose replay needs more work than MAX_SEARCH_WORK: n > 20 is
    unchecked (never invalid), n ≤ 20 falls back to the enumeration."""
    cert = search_cert(_dense(22, 0.7, 7), 5)
    assert cert is not None and C.check(cert).valid
    monkeypatch.setattr(C, "MAX_SEARCH_WORK", len(cert["proof"]["tree"]) // 2)
    res = C.check(cert)
    assert res.verdict == "unchecked" and res.trusted == ("search",), res
    assert "work limit" in res.unchecked[0]
    small = search_cert(_dense(12, 0.8, 7), 3)
    assert small is not None
    monkeypatch.setattr(C, "MAX_SEARCH_WORK", 1)
    res = C.check(small)
    assert res.verdict == "valid" and "enumeration" in res.reason, res


def _check_with_peak(cert: dict):
    """(the checker's result, the peak of memory Python allocated while it ran)."""
    import tracemalloc

    tracemalloc.start()
    try:
        res = C.check(cert)
        return res, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def _leaf_list_cert(n: int, edges: list[list[int]]) -> dict:
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": {"n": n, "edges": edges},
            "r": 1, "s": 1,
            "proof": {"method": "search", "order": list(range(n)), "tree": [-1] * n}}


def test_a_large_graph_is_answered_within_the_work_limit():
    """n = 3000 without edges (the graph limit accepts it; its replay stops at its first
    leaf): the replay's set-up built a table of n + 1 packed sets of n fields, n² big-int
    additions outside the work count (~80 s; never ending for n = 10^4). The bound is a
    hang guard, not a speed target: ~1 s now, 40 s leaves room for a loaded machine."""
    t0 = time.perf_counter()
    res = C.check(_leaf_list_cert(3000, []))
    assert res.verdict == "invalid" and "leaf -1 at token 0" in res.reason, res
    assert time.perf_counter() - t0 < 40


def test_tables_beyond_the_work_limit_are_not_built(monkeypatch):
    """The set-up charge (n + |E| steps of ⌈n·w / 1024⌉) alone beyond MAX_SEARCH_WORK:
    unchecked without building the packed tables (for every node a set of up to n·w
    bits: n²·w bits, gigabytes for the n ≈ 10^5 the graph limit accepts)."""
    n = 2000  # every node sends to node 0, the last field: each table entry has n·w bits
    cert = _leaf_list_cert(n, [[v, 0] for v in range(1, n)] + [[0, v] for v in range(1, n)])
    monkeypatch.setattr(C, "MAX_SEARCH_WORK", 2 * n)
    res, peak = _check_with_peak(cert)
    assert res.verdict == "unchecked" and "work limit" in res.unchecked[0], res
    assert peak < 2_000_000, peak  # the tables: n · n·w bits ≈ 6 MB


def test_the_packed_table_is_charged_by_its_size(monkeypatch):
    """A star on n = 3000 nodes, every leaf sending to the hub (the last field): the
    table of out-neighbour fields holds n·w bits per node, n²·w bits in all (14 MB
    here; 800 MB for n = 20 000 within the default limit, when only n + |E| steps were
    charged). It counts one step per 64 bits: beyond the limit it is not built."""
    n = 3000
    edges = [[v, 0] for v in range(1, n)] + [[0, v] for v in range(1, n)]
    cert = _leaf_list_cert(n, edges)
    w = n.bit_length() + 1
    setup = (n + len(edges)) * -(-n * w // 1024)
    assert setup < 1_000_000 < setup + n * n * w // 64
    monkeypatch.setattr(C, "MAX_SEARCH_WORK", 1_000_000)
    res, peak = _check_with_peak(cert)
    assert res.verdict == "unchecked" and "work limit" in res.unchecked[0], res
    assert peak < 5_000_000, peak


def test_the_stack_is_charged_by_its_size(monkeypatch):
    """No edges and r = 1 (nothing is ever peeled): a tree that branches on nodes
    1..n-1 along its first children holds n stack entries, each with a fresh packed Q
    and its D (2·n·w bits per level, 12 MB for n = 2000; 375 MB for n = 10^4 within
    the default limit when only the tokens were charged). The stack counts one step
    per 64 bits of its largest size, 4(n + 1)·n·w bits, before the replay starts: here
    beyond the limit, so the tree is not replayed, and the graph (not 1-robust) is
    refuted by the linear-time witness pairs instead, in little memory."""
    n = 2000
    tree = list(range(1, n)) + [-1] * (2 * n)
    cert = {**_leaf_list_cert(n, []), "proof": {"method": "search", "order": list(range(n)),
                                                  "tree": tree}}
    monkeypatch.setattr(C, "MAX_SEARCH_WORK", 1_000_000)
    res, peak = _check_with_peak(cert)
    assert res.verdict == "invalid" and "witness pairs" in res.reason, res
    assert peak < 5_000_000, peak
