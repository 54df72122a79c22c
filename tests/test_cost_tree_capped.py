"""The capped leaf of the charged tree (certificates/FORMAT.md, ``cost_search``): what
the second set may take from the candidates of one or two members of S is capped by
their need. Checked against brute force on small digraphs (every pair of a state lies
in the capped core, as the recorder's and the checker's packed and slow peels compute
it, which agree), tampered leaves rejected, trees recorded before the capped leaf still
valid, and the two ER(30, 0.5) s* = 3 proofs of ``robustness_n30`` valid (slow)."""

from __future__ import annotations

import json
import random
from itertools import product
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon.graphs._charged_kernels import capped_core, capped_member
from rescon.graphs.charged import charged_order, charged_tree
from rescon.graphs.indexed import index_graph
from tests.test_checker import C, digraph, in_masks, rand_edges, rho_and_s
from tests.test_robustness_certs3 import _core

pytestmark = pytest.mark.usefixtures("fresh_facts")

DATA = Path(__file__).parent / "data" / "charged_trees_before_capped.json"


def _closed(U: int, inm: list[int], t: list[int]) -> bool:
    return all((inm[i] & ~U).bit_count() < t[i] for i in range(len(inm)) if U >> i & 1)


def _states(rng: random.Random, n: int, count: int):
    """Random states (S, X, B): S nonempty, X ⊇ B, all disjoint."""
    for _ in range(count):
        lab = [rng.choice((0, 0, 1, 1, 2, 3)) for _ in range(n)]  # 1: S, 2: X \ B, 3: B
        lab[rng.randrange(n)] = 1
        S = sum(1 << v for v in range(n) if lab[v] == 1)
        B = sum(1 << v for v in range(n) if lab[v] == 3)
        yield S, B | sum(1 << v for v in range(n) if lab[v] == 2), B


def _packed_capped(rp, i, j, S, X, B, side1, side2):
    """The checker's capped core (packed and slow) of the state, unpacked."""
    P = rp.shrink(rp.full, side1.D, side1.gone | rp.pack(X), side1)[0]
    Q, QD = rp.shrink(rp.full, side2.D, side2.gone | rp.pack(S | B), side2)
    fast = rp.capped(i, j, rp.pack(S), P, Q, QD, side1, side2)
    return rp.unpack(fast), rp.unpack(P), rp.unpack(Q)


def _thresholds(rng: random.Random, n: int) -> list[int]:
    """r + charges per node (r = 1..3, 0..2 charges), one in eight above n."""
    r = rng.randint(1, 3)
    return [n + rng.randint(1, 3) if rng.random() < 0.125 else r + rng.randint(0, 2)
            for _ in range(n)]


@pytest.mark.parametrize("seed", range(12))
def test_every_pair_of_a_state_lies_in_its_capped_core(seed):
    """n = 6..8, random per-node thresholds (some above n): for random states and every
    i ≤ j in S with a need, each pair (U1 ⊇ S avoiding X, closed for t1; U2 ≠ ∅ avoiding
    U1 ∪ B, closed for t2) has U2 inside the capped core; the kernel's, the checker's
    packed and its slow peel give the same core; the kernel names a leaf exactly when a
    core (single members first) is empty."""
    rng = random.Random(seed)
    n = rng.randint(6, 8)
    edges = rand_edges(rng, n, rng.choice([0.5, 0.7, 0.9]))
    inm = in_masks(n, edges)
    t1, t2 = _thresholds(rng, n), _thresholds(rng, n)
    closed1 = [U for U in range(1, 1 << n) if _closed(U, inm, t1)]
    closed2 = [U for U in range(1, 1 << n) if _closed(U, inm, t2)]
    g = C._graph({"n": n, "edges": [list(e) for e in edges]})
    rp = C._Replay(g, 1, "t")
    rp.capped_tables()
    side1, side2 = rp.threshold_side(t1), rp.threshold_side(t2)
    inmask = np.array(inm, dtype=np.uint64)
    a1, a2 = np.array(t1, dtype=np.int64), np.array(t2, dtype=np.int64)
    full = (1 << n) - 1
    checked = empty = 0
    for S, X, B in _states(rng, n, 60):
        P, Q = _core(full & ~X, inm, t1), _core(full & ~S & ~B, inm, t2)
        pairs = [(U1, U2) for U1 in closed1 if U1 & S == S and not U1 & X
                 for U2 in closed2 if not U2 & (U1 | B)]
        needy = [i for i in range(n) if S >> i & 1 and (inm[i] & ~S).bit_count() >= t1[i]]
        cores = {}
        for i in needy:
            for j in needy:
                if i > j:
                    continue
                caps = []
                for m in (i, j):
                    c = inm[m] & P & ~S
                    caps += [c, c.bit_count() - ((inm[m] & ~S).bit_count() - t1[m] + 1)]
                core = int(capped_core(np.uint64(Q), np.uint64(caps[0]), caps[1],
                                       np.uint64(caps[2]), caps[3], inmask, a2))
                packed, P2, Q2 = _packed_capped(rp, i, j, S, X, B, side1, side2)
                assert (P2, Q2) == (P, Q)
                if min(caps[1], caps[3]) >= 0:
                    assert packed == core
                    slow = rp.capped_slow(
                        (rp.pack(caps[0]), min(caps[1], (caps[0] & Q).bit_count()),
                         rp.pack(caps[2]), min(caps[3], (caps[2] & Q).bit_count())),
                        rp.pack(Q), side2)
                    assert rp.unpack(slow) == core
                    assert all(U2 & ~core == 0 for _, U2 in pairs)
                else:
                    assert packed == 0 and not pairs  # i or j cannot be closed in U1
                cores[i, j] = core if min(caps[1], caps[3]) >= 0 else 0
                checked += 1
                empty += cores[i, j] == 0
        leaf = int(capped_member(np.uint64(S), np.uint64(P), np.uint64(Q), inmask, a1, a2))
        singles = [k for k in cores if k[0] == k[1] and cores[k] == 0]
        doubles = [k for k in cores if k[0] < k[1] and cores[k] == 0]
        want = singles[0] if singles else doubles[0] if doubles else None
        assert leaf == (-1 if want is None else want[0] * n + want[1])
    assert checked > 10


def test_the_packed_capped_core_handles_large_slack_and_thresholds():
    """n = 12..15 (fields of 5 bits, 2^(w−1) = 16 < sl + max t): the slow path is taken and
    agrees with the kernel's peel; thresholds up to n + 3 (a deficit field capped at n)."""
    taken = 0
    for seed in range(20):
        rng = random.Random(100 + seed)
        n = rng.randint(12, 15)
        edges = rand_edges(rng, n, 0.8)
        inm = in_masks(n, edges)
        t = [rng.randint(1, n + 3) for _ in range(n)]
        g = C._graph({"n": n, "edges": [list(e) for e in edges]})
        rp = C._Replay(g, 1, "t")
        rp.capped_tables()
        side = rp.threshold_side(t)
        inmask, arr = np.array(inm, dtype=np.uint64), np.array(t, dtype=np.int64)
        for S, X, B in _states(rng, n, 30):
            Q, QD = rp.shrink(rp.full, side.D, side.gone | rp.pack(S | B), side)
            for i, j in ((a, b) for a, b in product(range(n), repeat=2) if a <= b
                         and S >> a & S >> b & 1):
                P = rp.shrink(rp.full, side.D, side.gone | rp.pack(X), side)[0]
                got = rp.unpack(rp.capped(i, j, rp.pack(S), P, Q, QD, side, side))
                caps = []
                for m in (i, j):
                    c = inm[m] & rp.unpack(P) & ~S
                    caps += [c, c.bit_count() - ((inm[m] & ~S).bit_count() - t[m] + 1)]
                if min(caps[1], caps[3]) < 0:
                    assert got == 0
                    continue
                want = int(capped_core(np.uint64(rp.unpack(Q)), np.uint64(caps[0]), caps[1],
                                       np.uint64(caps[2]), caps[3], inmask, arr))
                assert got == want
                taken += min(caps[1], caps[3]) + side.most > 16
    assert taken > 0


def _cert(ig, r, s, tree, order=None):
    order = charged_order(ig).tolist() if order is None else order
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(), "r": r,
            "s": s, "proof": {"method": "cost_search", "order": order,
                              "charged_tree": list(tree)}}


def random_charged_trees(seeds):
    """(ig, n, r, s, tree) per seed whose random digraph (n = 6–8, p 0.5–0.9) has ρ ≥ 1:
    the charged tree recorded at r = ρ, s = min(s*, 3)."""
    for seed in seeds:
        rng = random.Random(seed)
        n = rng.randint(6, 8)
        ig = index_graph(digraph(n, rand_edges(rng, n, rng.choice([0.5, 0.7, 0.9]))))
        r, s_star = rho_and_s(n, in_masks(n, ig.edges()))
        if r:
            s = min(s_star, 3)
            yield ig, n, r, s, list(charged_tree(ig, r, s))


def test_tampered_capped_leaves_are_invalid():
    """Recorded trees with capped leaves: each such leaf with its members swapped
    (i > j), naming a node outside S or moved onto a branch is invalid; a branch turned
    into any capped leaf is invalid (the recorder took every capped leaf that held)."""
    tampered = 0
    for ig, n, r, s, tree in random_charged_trees(range(40)):
        assert C.check(_cert(ig, r, s, tree)).verdict == "valid"
        capped = [k for k, t in enumerate(tree) if t <= -5]
        for k in capped[:3]:
            i, j = divmod(-5 - tree[k], n)
            bads = [-5 - (v * n + v) for v in range(n)] + ([-5 - (j * n + i)] if i < j else [])
            for bad in bads:
                if bad != tree[k]:
                    res = C.check(_cert(ig, r, s, tree[:k] + [bad] + tree[k + 1:]))
                    if bad == -5 - (j * n + i) and i < j:
                        assert res.verdict == "invalid" and "not both in S" in res.reason
                    tampered += res.verdict == "invalid"
        for k in [k for k, t in enumerate(tree) if t >= 0][:2]:
            for i in range(n):
                for j in range(i, n):
                    bad = tree[:k] + [-5 - (i * n + j)] + tree[k + 1:]
                    assert C.check(_cert(ig, r, s, bad)).verdict == "invalid"
                    tampered += 1
        if capped:
            bad = tree[:-1] + [-5 - n * n]  # i = n: beyond the nodes
            assert C.check(_cert(ig, r, s, bad)).verdict == "invalid"
    assert tampered > 100


def test_trees_recorded_before_the_capped_leaf_are_still_valid():
    """Charged trees recorded by the previous kernel (search_order roots, no capped leaf,
    -4 leaves; r = 4, s = 2 twice, r = 1, s = 3) replay valid; cut, they do not."""
    for item in json.loads(DATA.read_text()):
        n, edges, r, s, order, tree = (item[k] for k in ("n", "edges", "r", "s", "order",
                                                         "tree"))
        ig = index_graph(digraph(n, [tuple(e) for e in edges]))
        assert C.check(_cert(ig, r, s, tree, order)).verdict == "valid"
        k = next((k for k, t in enumerate(tree) if t >= 0), None)
        bad = tree[:-1] if k is None else tree[:k] + [-1] + tree[k + 1:]
        assert C.check(_cert(ig, r, s, bad, order)).verdict == "invalid"


@pytest.mark.slow
@pytest.mark.parametrize("directed, seed, most", [(True, 30000, 450_000), (False, 30003, 120_000)])
def test_er30_s_star_3_certificates_are_fully_checked(directed, seed, most):
    """robustness_n30's er_directed p = 0.5 n = 30 i = 0 and er p = 0.5 n = 30 i = 3
    (ρ = 8, s* = 3; 901 configurations): unchecked before the capped leaf (30.8–41.1M
    tokens), now a charged tree of 0.10–0.40M tokens, valid."""
    G = nx.gnp_random_graph(30, 0.5, directed=directed, seed=seed)
    rep = rescon.robustness(G)
    assert (rep.r_max, rep.s_max) == (8, 3)
    lower_s = rep.certificate["lower_s"]
    assert len(lower_s["charged_tree"]) < most
    res = C.check(rep.certificate)
    assert res.verdict == "valid", res.reason


@pytest.mark.parametrize("seed", range(8))
def test_the_decision_search_without_a_tree_prunes_capped_states_soundly(seed):
    """decide_step without a recorded tree (where the capped prune runs): its answer for
    every r ≤ ρ + 1 is brute force's on random digraphs n = 7..10 (sparse to dense), and a
    witness it returns violates r-robustness."""
    from rescon.graphs import search

    rng = random.Random(1000 + seed)
    for _ in range(6):
        n = rng.randint(7, 10)
        edges = rand_edges(rng, n, rng.choice([0.4, 0.6, 0.75, 0.9]), undirected=rng.random() < 0.3)
        ig = index_graph(digraph(n, edges))
        inm = in_masks(n, ig.edges())
        rho = rho_and_s(n, inm)[0]
        for r in range(1, rho + 2):
            run = search.PartRun(search._kernel_inputs(ig), r, search.whole_part(n), 0)
            while (status := run.advance(1000)) == run.K.RUNNING:
                pass
            assert (status == run.K.UNSAT) == (r <= rho), (seed, n, r)
            if status == run.K.SAT:
                S1, S2 = run.witness()
                assert S1 and S2 and not S1 & S2
                for S in (S1, S2):
                    assert all((inm[i] & ~sum(1 << v for v in S)).bit_count() < r for i in S)


def test_the_capped_prune_shortens_dense_decisions():
    """G(40, 0.8) directed, seed 1, r = 15 (15-robust): about 100 s of decision search
    before the capped prune, now the 4M-token recorded part and little more."""
    from rescon.graphs.search import decide_r_robust

    ig = index_graph(nx.gnp_random_graph(40, 0.8, seed=1, directed=True))
    out = decide_r_robust(ig, 15)
    assert out.status == "robust" and out.nodes < 4_500_000


@pytest.mark.parametrize("seed", range(6))
def test_the_charged_engine_with_the_capped_prune_finds_the_brute_force_s_star(seed):
    """min_cost_step alone (its capped prune: ``_kernels.capped_charged``) gives s*(r),
    the largest s with (r, s)-robustness, for every r ≤ ρ of random digraphs n = 7..9."""
    from rescon.graphs import _kernels as K
    from rescon.graphs import search
    from tests.test_checker import is_robust

    rng = random.Random(2000 + seed)
    for _ in range(5):
        n = rng.randint(7, 9)
        edges = rand_edges(rng, n, rng.choice([0.4, 0.6, 0.75, 0.9]), undirected=rng.random() < 0.3)
        ig = index_graph(digraph(n, edges))
        inm = in_masks(n, ig.edges())
        _, inmask, outmask, order = search._kernel_inputs(ig)
        for r in range(1, rho_and_s(n, inm)[0] + 1):
            run = search._CostRun(K, n, (0, n), n)
            while run.state[K.CS_STATUS] == K.RUNNING:
                K.min_cost_step(inmask, outmask, order, r, 0, run.stack, run.depth, run.state,
                                run.ubuf, 1 << 16, run.progress)
            s_star = max(s for s in range(1, n + 1) if is_robust(n, inm, r, s))
            assert min(int(run.state[K.CS_BEST]), n) == s_star, (seed, n, r)
