"""Tests of the standalone certificate checker (certificates/check.py) on its own.

Genuine certificates are built here from a brute-force oracle (all disjoint pairs,
n <= 7), from graphs grown by adding nodes, from complete graphs and from a small
branch-and-bound that writes ``search`` trees; tampered certificates must be rejected.
Nothing here imports rescon: the checker is tested against independent code.
"""

from __future__ import annotations

import copy
import importlib.util
import json
import random
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

ROOT = Path(__file__).resolve().parents[1]
CERT_DIR = ROOT / "certificates"
CHECK_PY = CERT_DIR / "check.py"
SCHEMA = CERT_DIR / "schema" / "certificate.schema.json"
EXAMPLES = sorted((CERT_DIR / "examples").glob("*.json"))


def _load_checker():
    """The checker file of this repository (not whatever copy may be installed)."""
    name = "_rescon_certificates_check_under_test"
    spec = importlib.util.spec_from_file_location(name, CHECK_PY)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


C = _load_checker()
check = C.check


# --------------------------------------------------------------------------- #
# brute-force oracle (independent of the checker)
# --------------------------------------------------------------------------- #


def popcount(x: int) -> int:
    return x.bit_count()


def bits(mask: int) -> list[int]:
    return [i for i in range(mask.bit_length()) if mask >> i & 1]


def to_mask(nodes) -> int:
    return sum(1 << i for i in nodes)


def in_masks(n: int, edges) -> list[int]:
    inm = [0] * n
    for u, v in edges:
        inm[v] |= 1 << u
    return inm


def reach_mask(inm: list[int], S: int, r: int) -> int:
    return sum(1 << i for i in bits(S) if popcount(inm[i] & ~S) >= r)


def violates(inm, r, s, S1, S2) -> bool:
    """Definition of FORMAT.md, for disjoint nonempty S1, S2."""
    R1, R2 = reach_mask(inm, S1, r), reach_mask(inm, S2, r)
    return R1 != S1 and R2 != S2 and popcount(R1) + popcount(R2) < s


def all_violations(n, inm, r, s):
    """Every violating unordered pair (S1 < S2 as masks)."""
    full = (1 << n) - 1
    rc = [reach_mask(inm, S, r) for S in range(full + 1)]
    out = []
    for S1 in range(1, full + 1):
        if rc[S1] == S1:
            continue
        comp = full & ~S1
        S2 = comp
        while S2:
            if S2 > S1 and rc[S2] != S2 and popcount(rc[S1]) + popcount(rc[S2]) < s:
                out.append((S1, S2))
            S2 = (S2 - 1) & comp
    return out


def first_violation(n, inm, r, s):
    full = (1 << n) - 1
    rc = [reach_mask(inm, S, r) for S in range(full + 1)]
    for S1 in range(1, full + 1):
        if rc[S1] == S1:
            continue
        comp = full & ~S1
        S2 = comp
        while S2:
            if rc[S2] != S2 and popcount(rc[S1]) + popcount(rc[S2]) < s:
                return S1, S2
            S2 = (S2 - 1) & comp
    return None


def is_robust(n, inm, r, s) -> bool:
    return first_violation(n, inm, r, s) is None


def rho_and_s(n, inm):
    """(r_max, s_max) by brute force, n >= 2."""
    r = 0
    while is_robust(n, inm, r + 1, 1):
        r += 1
    s = 1
    while s < n and is_robust(n, inm, r, s + 1):
        s += 1
    return r, s


def rand_edges(rng: random.Random, n: int, p: float, undirected: bool = False):
    edges = set()
    for u in range(n):
        for v in range(n):
            if u != v and rng.random() < p:
                edges.add((u, v))
                if undirected:
                    edges.add((v, u))
    return sorted(edges)


def complete_edges(n):
    return [(u, v) for u in range(n) for v in range(n) if u != v]


# --------------------------------------------------------------------------- #
# certificate builders
# --------------------------------------------------------------------------- #


def digraph(n: int, edges):
    """The networkx digraph on nodes 0..n-1 with ``edges``."""
    import networkx as nx

    G = nx.DiGraph()
    G.add_nodes_from(range(n))
    G.add_edges_from(edges)
    return G


def graph_json(n, edges):
    return {"n": n, "edges": [[u, v] for u, v in edges]}


def rs_cert(n, edges, r, s, proof):
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": graph_json(n, edges),
            "r": r, "s": s, "proof": proof}


def not_cert(n, edges, r, s, S1, S2):
    return {"rescon_certificate": 1, "kind": "not_rs_robust", "graph": graph_json(n, edges),
            "r": r, "s": s, "witness": {"S1": bits(S1), "S2": bits(S2)}}


def robustness_cert(n, edges):
    inm = in_masks(n, edges)
    r, s = rho_and_s(n, inm)
    lower = {"method": "trivial"} if r == 0 else {"method": "enumeration"}
    if r == (n + 1) // 2:
        upper_r = {"method": "half"}
    else:
        S1, S2 = first_violation(n, inm, r + 1, 1)
        upper_r = {"method": "witness", "S1": bits(S1), "S2": bits(S2)}
    if s == n:
        upper_s = None
    else:
        S1, S2 = first_violation(n, inm, r, s + 1)
        upper_s = {"method": "witness", "S1": bits(S1), "S2": bits(S2)}
    return {"rescon_certificate": 1, "kind": "robustness", "graph": graph_json(n, edges),
            "exact": True, "r_max": r, "s_max": s, "lower": lower, "lower_s": lower,
            "upper_r": upper_r,
            "upper_s": upper_s}


def grow(rng, seed_n, total_n, r, s):
    """K_seed_n plus nodes with exactly r + s - 1 in-neighbours among earlier nodes
    (and random out-edges back to them), randomly relabelled.

    Returns (edges, order, tight) with order[j] = label of the j-th node added and
    tight = labels of the added nodes."""
    k = r + s - 1
    assert seed_n >= max(1, k)
    edges = set(complete_edges(seed_n))
    for v in range(seed_n, total_n):
        for u in rng.sample(range(v), k):
            edges.add((u, v))
        for u in range(v):
            if rng.random() < 0.3:
                edges.add((v, u))
    perm = list(range(total_n))
    rng.shuffle(perm)
    edges = sorted((perm[u], perm[v]) for u, v in edges)
    return edges, perm, perm[seed_n:]


def construction_cert(n, edges, r, s, order, m, seed_proof=None):
    return rs_cert(n, edges, r, s, {"method": "construction", "order": order, "seed_size": m,
                                    "seed_proof": seed_proof or {"method": "complete"}})


# --------------------------------------------------------------------------- #
# search-tree generator (branch and bound of FORMAT.md, method "search")
# --------------------------------------------------------------------------- #


def peel(inm, U, r):
    changed = True
    while changed:
        changed = False
        for i in bits(U):
            if popcount(inm[i] & ~U) >= r:
                U &= ~(1 << i)
                changed = True
    return U


def search_tree(n, inm, r, order):
    """(tokens, states) proving r-robustness, or None if the search finds a violating
    pair.  states[t] = (S, X, B) at token t."""
    full = (1 << n) - 1
    tokens, states = [], []
    for k in range(n):
        B = to_mask(order[:k])
        stack = [(1 << order[k], B)]
        while stack:
            S, X = stack.pop()
            states.append((S, X, B))
            if peel(inm, full & ~S & ~B, r) == 0:
                tokens.append(-1)
                continue
            if S & ~peel(inm, full & ~X, r):
                tokens.append(-2)
                continue
            violators = [i for i in bits(S) if popcount(inm[i] & ~S) >= r]
            if not violators:
                return None  # S is closed and a closed S2 fits in V \ S \ B
            i = violators[0]
            u = bits(inm[i] & ~S & ~X)[0]  # exists: S lies in the closed core(V \ X)
            tokens.append(u)
            stack.append((S, X | 1 << u))
            stack.append((S | 1 << u, X))
    return tokens, states


def search_cert(n, edges, r, order, tokens):
    return rs_cert(n, edges, r, 1, {"method": "search", "order": list(order), "tree": tokens})


# --------------------------------------------------------------------------- #
# reference implementation of the enumeration of the brief (per-mask lists + SOS min)
# --------------------------------------------------------------------------- #


def sos_reference_robust(n, inm, r, s) -> bool:
    full = (1 << n) - 1
    INF = 10**9
    c = [0] * (full + 1)
    f = [False] * (full + 1)
    for S in range(full + 1):
        R = reach_mask(inm, S, r)
        c[S] = popcount(R)
        f[S] = R != S
    h = [c[S] if f[S] else INF for S in range(full + 1)]
    for j in range(n):
        b = 1 << j
        for U in range(full + 1):
            if U & b and h[U ^ b] < h[U]:
                h[U] = h[U ^ b]
    best = min((c[S] + h[full & ~S] for S in range(1, full + 1) if f[S]), default=INF)
    return best >= s


# --------------------------------------------------------------------------- #
# the mathematical claims the checker relies on, by brute force
# --------------------------------------------------------------------------- #


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_claim_adding_node_keeps_rs_robustness(data):
    n = data.draw(st.integers(1, 6))
    p = data.draw(st.floats(0.3, 1.0))
    rng = random.Random(data.draw(st.integers(0, 2**32)))
    edges = rand_edges(rng, n, p)
    inm = in_masks(n, edges)
    r = data.draw(st.integers(0, 3))
    s = data.draw(st.integers(1, n + 1))
    if r + s - 1 > n or not is_robust(n, inm, r, s):
        return
    ins = rng.sample(range(n), data.draw(st.integers(r + s - 1, n)))
    outs = [u for u in range(n) if rng.random() < 0.5]
    edges2 = edges + [(u, n) for u in ins] + [(n, u) for u in outs]
    assert is_robust(n + 1, in_masks(n + 1, edges2), r, s)


@pytest.mark.parametrize("n", range(1, 9))
def test_claim_complete_graph(n):
    inm = in_masks(n, complete_edges(n))
    for r in range(n + 2):
        for s in range(1, n + 1):
            if n >= 2 * r - 1:
                assert is_robust(n, inm, r, s)
        if n >= 2 and n < 2 * r - 1:
            assert not is_robust(n, inm, r, 1)


@settings(max_examples=200, deadline=None)
@given(st.data())
def test_claim_min_degree(data):
    n = data.draw(st.integers(1, 7))
    rng = random.Random(data.draw(st.integers(0, 2**32)))
    edges = rand_edges(rng, n, data.draw(st.floats(0.5, 1.0)))
    inm = in_masks(n, edges)
    dmin = min(popcount(m) for m in inm)
    r = dmin - n // 2 + 1  # largest r the degree bound covers
    if r < 0:
        return
    for s in range(1, n + 1):
        assert is_robust(n, inm, r, s)


# --------------------------------------------------------------------------- #
# enumeration agrees with the oracle
# --------------------------------------------------------------------------- #


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.data())
def test_enumeration_agrees_with_oracle(data):
    n = data.draw(st.integers(1, 7))
    rng = random.Random(data.draw(st.integers(0, 2**32)))
    edges = rand_edges(rng, n, data.draw(st.floats(0.0, 1.0)),
                       undirected=data.draw(st.booleans()))
    r = data.draw(st.integers(0, 4))
    s = data.draw(st.integers(1, n))
    expect = is_robust(n, in_masks(n, edges), r, s)
    for method in ("enumeration", "dp"):
        res = check(rs_cert(n, edges, r, s, {"method": method}))
        assert res.valid == expect, res.reason
        assert res.trusted == ()
        if not expect:
            assert f"not ({r}, {s})-robust" in res.reason


def test_enumeration_agrees_with_sos_reference():
    rng = random.Random(7)
    for _ in range(12):
        n = rng.randint(8, 10)
        edges = rand_edges(rng, n, rng.uniform(0.3, 0.9), undirected=rng.random() < 0.5)
        inm = in_masks(n, edges)
        for r, s in ((1, 1), (2, 1), (2, 3), (3, 2), (3, 5)):
            res = check(rs_cert(n, edges, r, s, {"method": "enumeration"}))
            assert res.valid == sos_reference_robust(n, inm, r, s), (n, edges, r, s)


def test_enumeration_reports_a_genuine_witness():
    rng = random.Random(3)
    for _ in range(30):
        n = rng.randint(5, 12)
        edges = rand_edges(rng, n, 0.5)
        res = check(rs_cert(n, edges, 2, 2, {"method": "enumeration"}))
        if res.valid:
            continue
        text = res.reason.split("S1 = ")[1]
        s1 = json.loads("[" + text.split("}")[0].strip("{") + "]")
        s2 = json.loads("[" + text.split("S2 = {")[1].split("}")[0] + "]")
        assert check(not_cert(n, edges, 2, 2, to_mask(s1), to_mask(s2))).valid


def test_enumeration_speed_and_limits():
    rng = random.Random(11)
    t0 = time.perf_counter()
    for n in (16, 20):
        edges = rand_edges(rng, n, 0.7)
        for r, s in ((3, 1), (4, 6)):
            check(rs_cert(n, edges, r, s, {"method": "enumeration"}))
    assert time.perf_counter() - t0 < 10
    big = rand_edges(rng, 21, 0.9)
    res = check(rs_cert(21, big, 2, 1, {"method": "enumeration"}))
    assert res.verdict == "unchecked" and res.trusted == ("enumeration",)
    assert "too large to enumerate (n = 21 > 20)" in res.unchecked[0]
    res = check(rs_cert(21, big, 2, 1, {"method": "dp"}))
    assert res.verdict == "unchecked" and res.trusted == ("dp",) and not res
    res = check(rs_cert(21, big, 2, 1, {"method": "dp", "info": {"seconds": 1.5}}))
    assert res.verdict == "unchecked" and res.trusted == ("dp",)


def test_enumeration_of_k20():
    n = 20
    cert = rs_cert(n, complete_edges(n), 10, n, {"method": "enumeration"})
    assert check(cert).valid
    cert["r"] = 11
    assert not check(cert).valid


# --------------------------------------------------------------------------- #
# not_rs_robust witnesses
# --------------------------------------------------------------------------- #


@settings(max_examples=150, deadline=None)
@given(st.data())
def test_witnesses_from_oracle_and_flipped_nodes(data):
    n = data.draw(st.integers(2, 7))
    rng = random.Random(data.draw(st.integers(0, 2**32)))
    edges = rand_edges(rng, n, data.draw(st.floats(0.1, 0.9)))
    inm = in_masks(n, edges)
    r = data.draw(st.integers(1, 4))
    s = data.draw(st.integers(1, n))
    hit = first_violation(n, inm, r, s)
    if hit is None:
        return
    S1, S2 = hit
    assert check(not_cert(n, edges, r, s, S1, S2)).valid
    assert check(not_cert(n, edges, r, s, S2, S1)).valid
    # flip one node of one set: the checker must agree with the definition
    which = data.draw(st.sampled_from(["S1", "S2"]))
    v = data.draw(st.integers(0, n - 1))
    T1, T2 = (S1 ^ (1 << v), S2) if which == "S1" else (S1, S2 ^ (1 << v))
    res = check(not_cert(n, edges, r, s, T1, T2))
    expect = bool(T1) and bool(T2) and not T1 & T2 and violates(inm, r, s, T1, T2)
    assert res.valid == expect, res.reason
    if T1 & T2:
        assert "intersect at node" in res.reason


def test_witness_rejections():
    n = 4
    c4 = [(0, 1), (1, 0), (1, 2), (2, 1), (2, 3), (3, 2), (3, 0), (0, 3)]
    good = not_cert(n, c4, 2, 1, to_mask([0, 1]), to_mask([2, 3]))
    assert check(good).valid
    bad = copy.deepcopy(good)
    bad["r"] = 1
    assert not check(bad).valid
    bad = copy.deepcopy(good)
    bad["witness"]["S2"] = [1, 2]
    res = check(bad)
    assert not res.valid and "S1 and S2 intersect at node 1" in res.reason
    bad = copy.deepcopy(good)
    bad["witness"]["S2"] = [0]  # node 0 has 2 in-neighbours outside: fully reachable
    bad["witness"]["S1"] = [2]
    assert "fully 2-reachable" in check(bad).reason
    bad = copy.deepcopy(good)
    bad["witness"]["S2"] = []
    assert "empty" in check(bad).reason
    bad = copy.deepcopy(good)
    bad["witness"]["S2"] = [2, 3, 3]
    assert "twice" in check(bad).reason


# --------------------------------------------------------------------------- #
# rs_robust: trivial / degree / complete / construction
# --------------------------------------------------------------------------- #


def test_trivial_degree_complete():
    assert check(rs_cert(3, [], 0, 3, {"method": "trivial"})).valid
    assert check(rs_cert(1, [], 5, 1, {"method": "trivial"})).valid
    assert not check(rs_cert(3, [], 1, 1, {"method": "trivial"})).valid
    k5 = complete_edges(5)
    assert check(rs_cert(5, k5, 3, 5, {"method": "complete"})).valid
    assert check(rs_cert(5, k5, 3, 5, {"method": "degree"})).valid  # 4 >= 2 + 3 - 1
    res = check(rs_cert(5, k5, 4, 1, {"method": "complete"}))
    assert not res.valid and "2r - 1" in res.reason
    res = check(rs_cert(5, k5[1:], 2, 1, {"method": "complete"}))
    assert not res.valid and "edge [0, 1] is missing" in res.reason
    res = check(rs_cert(5, k5[1:], 3, 1, {"method": "degree"}))
    assert not res.valid and "node 1 has in-degree 3" in res.reason


def test_complete_graphs_all_r_s():
    for n in range(1, 9):
        for r in range(n + 2):
            for s in range(1, n + 1):
                res = check(rs_cert(n, complete_edges(n), r, s, {"method": "complete"}))
                assert res.valid == (n >= 2 * r - 1)
                if 2 <= n <= 7:  # (K_1 is vacuously robust: method "trivial")
                    assert res.valid == is_robust(n, in_masks(n, complete_edges(n)), r, s)


def test_construction_certificates_and_tampering():
    rng = random.Random(5)
    for _trial in range(40):
        r = rng.randint(1, 3)
        s = rng.randint(1, 3)
        m = max(2 * r - 1, r + s - 1, 1) + rng.randint(0, 1)
        n = m + rng.randint(1, 4)
        edges, order, _ = grow(rng, m, n, r, s)
        cert = construction_cert(n, edges, r, s, order, m)
        res = check(cert)
        assert res.valid, res.reason
        if n <= 7:
            assert is_robust(n, in_masks(n, edges), r, s)
        # seed proved differently: enumeration, or a nested construction
        assert check(construction_cert(n, edges, r, s, order, m, {"method": "enumeration"})).valid
        nested = {"method": "construction", "order": list(range(m)), "seed_size": m,
                  "seed_proof": {"method": "complete"}}
        assert check(construction_cert(n, edges, r, s, order, m, nested)).valid
        # drop an in-edge of an added node from an earlier node: that step fails
        k = rng.randrange(m, n)
        v = order[k]
        earlier = set(order[:k])
        u = next(u for u, w in edges if w == v and u in earlier)
        bad_edges = [e for e in edges if e != (u, v)]
        res = check(construction_cert(n, bad_edges, r, s, order, m))
        assert not res.valid
        assert f"node order[{k}]={v} has {r + s - 2} in-neighbours among earlier nodes, " \
               f"needs {r + s - 1}" in res.reason
        # change r (or s) upwards: the steps no longer have enough in-neighbours
        bad = copy.deepcopy(cert)
        bad["r"] = r + 1
        assert not check(bad).valid
        if s < n:
            bad = copy.deepcopy(cert)
            bad["s"] = s + 1
            assert not check(bad).valid
        # order not a permutation, seed size out of range
        bad = copy.deepcopy(cert)
        bad["proof"]["order"][0] = bad["proof"]["order"][1]
        assert "not a permutation" in check(bad).reason
        bad = copy.deepcopy(cert)
        bad["proof"]["seed_size"] = 0
        assert "out of range" in check(bad).reason


def test_construction_seed_is_reindexed():
    # 0 <- 1 <- 2 path plus node 3 with in-edges from 0,1: seed order [2, 0, 1]
    # re-indexes node 2 -> 0, 0 -> 1, 1 -> 2; the seed proof is checked on that graph.
    edges = complete_edges(3) + [(0, 3), (1, 3)]
    order = [2, 0, 1, 3]
    cert = construction_cert(4, edges, 1, 2, order, 3, {"method": "enumeration"})
    assert check(cert).valid
    # seed proof with a wrong assumption about the seed: not complete after dropping
    edges2 = [e for e in edges if e != (2, 0)]
    res = check(construction_cert(4, edges2, 1, 2, order, 3))
    assert not res.valid and "seed_proof" in res.reason and "edge [0, 1] is missing" in res.reason


def test_seed_proof_with_s_above_seed_size():
    # seed of 1 node is (r, s)-robust for every s; n = 3, s = 3 needs r + s - 1 = 3
    edges = [(0, 1), (0, 2), (1, 2)]
    cert = construction_cert(3, edges, 0, 3, [0, 1, 2], 1, {"method": "trivial"})
    res = check(cert)
    assert not res.valid  # node 1 has only 1 earlier in-neighbour, needs 2
    cert = construction_cert(3, edges, 0, 2, [0, 1, 2], 1, {"method": "trivial"})
    assert check(cert).valid


# --------------------------------------------------------------------------- #
# rs_robust: search trees
# --------------------------------------------------------------------------- #


def test_search_trees_on_random_graphs():
    rng = random.Random(2024)
    accepted = rejected = 0
    for _trial in range(150):
        n = rng.randint(2, 8)
        edges = rand_edges(rng, n, rng.uniform(0.3, 1.0), undirected=rng.random() < 0.5)
        inm = in_masks(n, edges)
        r = rng.randint(1, 4)
        order = list(range(n))
        rng.shuffle(order)
        out = search_tree(n, inm, r, order)
        robust = is_robust(n, inm, r, 1) if n <= 7 else None
        if out is None:
            assert robust in (False, None)
            assert not check(rs_cert(n, edges, r, 1, {"method": "enumeration"})).valid
            continue
        if robust is not None:
            assert robust
        tokens, states = out
        cert = search_cert(n, edges, r, order, tokens)
        res = check(cert)
        assert res.valid, res.reason
        accepted += 1
        # corruptions that are invalid by construction
        for pos, t in enumerate(tokens):
            if t == -2:  # the generator tried -1 first, so -1 is unjustified here
                bad = copy.deepcopy(cert)
                bad["proof"]["tree"][pos] = -1
                res = check(bad)
                assert not res.valid and f"leaf -1 at token {pos} is not justified" in res.reason
                rejected += 1
                break
        for pos, t in enumerate(tokens):
            if t >= 0:
                S = states[pos][0]
                bad = copy.deepcopy(cert)
                bad["proof"]["tree"][pos] = bits(S)[0]
                res = check(bad)
                assert not res.valid and f"at token {pos} on node {bits(S)[0]}" in res.reason
                rejected += 1
                break
        bad = copy.deepcopy(cert)
        bad["proof"]["tree"].pop()
        assert "ends early" in check(bad).reason
        bad = copy.deepcopy(cert)
        bad["proof"]["tree"].append(-1)
        assert "unused tokens" in check(bad).reason
        # the tree proves r-robustness, nothing stronger
        bad = copy.deepcopy(cert)
        bad["s"] = 2 if n >= 2 else 1
        assert not check(bad).valid
    assert accepted > 20 and rejected > 20


def test_search_tree_changed_r_is_rejected():
    rng = random.Random(99)
    hits = 0
    for _ in range(200):
        n = rng.randint(3, 7)
        edges = rand_edges(rng, n, rng.uniform(0.4, 1.0), undirected=True)
        inm = in_masks(n, edges)
        r, _ = rho_and_s(n, inm)
        if r == 0:
            continue
        out = search_tree(n, inm, r, list(range(n)))
        assert out is not None
        cert = search_cert(n, edges, r, list(range(n)), out[0])
        assert check(cert).valid
        bad = copy.deepcopy(cert)
        bad["r"] = r + 1  # G is not (r+1)-robust, so no tree can prove it
        assert not check(bad).valid
        hits += 1
    assert hits > 50


def test_search_tree_bad_tokens():
    k3 = complete_edges(3)
    tokens, _ = search_tree(3, in_masks(3, k3), 2, [0, 1, 2])
    cert = search_cert(3, k3, 2, [0, 1, 2], tokens)
    assert check(cert).valid and len(tokens) > 3
    for tok in (-4, 3, True, 1.0, "x", None):
        bad = copy.deepcopy(cert)
        bad["proof"]["tree"][1] = tok
        res = check(bad)
        assert not res.valid and "tree[1]" in res.reason


def test_deep_search_tree_replay_is_iterative():
    # Directed cycle, r = 1: the only closed sets are {} and V, so every -1 leaf is
    # justified; branching on 1, 2, ..., n-1 along the first child makes a preorder
    # subtree deeper than Python's recursion limit.
    n = 1200
    edges = [(i, (i + 1) % n) for i in range(n)]
    tree = list(range(1, n)) + [-1] + [-1] * (n - 1) + [-1] * (n - 1)
    t0 = time.perf_counter()
    res = check(search_cert(n, edges, 1, list(range(n)), tree))
    assert res.valid, res.reason
    assert time.perf_counter() - t0 < 10
    bad = list(tree)
    bad[500] = 0  # node 0 is already in S
    res = check(search_cert(n, edges, 1, list(range(n)), bad))
    assert not res.valid and "at token 500 on node 0, which is already in S" in res.reason


# --------------------------------------------------------------------------- #
# robustness kind
# --------------------------------------------------------------------------- #


def test_robustness_certificates_and_tampering():
    rng = random.Random(17)
    seen_half = seen_zero = 0
    for _ in range(120):
        n = rng.randint(2, 7)
        edges = rand_edges(rng, n, rng.uniform(0.1, 1.0), undirected=rng.random() < 0.5)
        cert = robustness_cert(n, edges)
        res = check(cert)
        assert res.valid, res.reason
        r, s = cert["r_max"], cert["s_max"]
        seen_half += cert["upper_r"]["method"] == "half"
        seen_zero += r == 0
        bad = copy.deepcopy(cert)
        bad["r_max"] = r + 1
        assert not check(bad).valid
        if s > 1:
            bad = copy.deepcopy(cert)
            bad["s_max"] = s - 1
            assert not check(bad).valid
        if s < n:
            bad = copy.deepcopy(cert)
            bad["upper_s"] = None
            assert "upper_s is null" in check(bad).reason
        else:
            bad = copy.deepcopy(cert)
            bad["upper_s"] = {"method": "witness", "S1": [0], "S2": [1]}
            assert "must be null" in check(bad).reason
        if r == 0:
            bad = copy.deepcopy(cert)
            bad["lower"] = bad["lower_s"] = {"method": "enumeration"}
            assert "trivial" in check(bad).reason
        # the bounds variant
        bounds = {k: cert[k] for k in ("rescon_certificate", "kind", "graph", "upper_r")}
        bounds.update(exact=False, r_lower=r, r_upper=r, lower={"method": "enumeration"})
        assert check(bounds).valid
        if r > 0:
            b2 = copy.deepcopy(bounds)
            b2["r_lower"] = r - 1
            assert check(b2).valid
            b2["r_lower"] = r + 1
            assert "r_lower" in check(b2).reason
        b3 = copy.deepcopy(bounds)
        b3["s_max"] = 1
        assert "unknown key 's_max'" in check(b3).reason
    assert seen_half and seen_zero


def test_robustness_half_and_lower_on_trust():
    n = 5
    cert = {"rescon_certificate": 1, "kind": "robustness",
            "graph": graph_json(n, complete_edges(n)),
            "exact": True, "r_max": 3, "s_max": 5, "lower": {"method": "milp", "solver": "highs"},
            "lower_s": {"method": "milp", "solver": "highs"},
            "upper_r": {"method": "half"}, "upper_s": None}
    res = check(cert)
    assert res.valid and res.trusted == ()  # n <= 20: milp is re-verified by enumeration
    cert["lower"] = cert["lower_s"] = {"method": "complete"}
    res = check(cert)
    assert res.valid and res.trusted == ()
    bad = copy.deepcopy(cert)
    bad["r_max"] = 2
    bad["upper_r"] = {"method": "half"}
    assert "half" in check(bad).reason
    bad = copy.deepcopy(cert)
    bad["upper_s"] = {"method": "half"}
    bad["s_max"] = 4
    assert not check(bad).valid
    one = {"rescon_certificate": 1, "kind": "robustness", "graph": {"n": 1, "edges": []},
           "exact": True, "r_max": 1, "s_max": 1, "lower": {"method": "trivial"}, "lower_s": None,
           "upper_r": {"method": "half"}, "upper_s": None}
    assert "n >= 2" in check(one).reason


# --------------------------------------------------------------------------- #
# not_sarymsakov
# --------------------------------------------------------------------------- #


def sarymsakov_violation(n, support):
    rows = [0] * n
    for i, j in support:
        rows[i] |= 1 << j
    full = (1 << n) - 1
    for V1 in range(1, full + 1):
        comp = full & ~V1
        V2 = comp
        while V2:
            I1 = I2 = 0
            for i in bits(V1):
                I1 |= rows[i]
            for i in bits(V2):
                I2 |= rows[i]
            if not I1 & I2 and popcount(I1 | I2) <= popcount(V1 | V2):
                return V1, V2
            V2 = (V2 - 1) & comp
    return None


def test_not_sarymsakov():
    rng = random.Random(8)
    found = 0
    for _ in range(100):
        n = rng.randint(1, 5)
        support = sorted({(i, j) for i in range(n) for j in range(n) if rng.random() < 0.4}
                         | {(i, rng.randrange(n)) for i in range(n)})
        hit = sarymsakov_violation(n, support)
        if hit is None:
            continue
        V1, V2 = hit
        cert = {"rescon_certificate": 1, "kind": "not_sarymsakov", "n": n,
                "support": [list(e) for e in support],
                "witness": {"V1": bits(V1), "V2": bits(V2)}}
        assert check(cert).valid
        found += 1
        # every other pair: checker agrees with the definition
        for W1 in range(1, 1 << n):
            for W2 in range(1, 1 << n):
                if W1 & W2:
                    continue
                c2 = copy.deepcopy(cert)
                c2["witness"] = {"V1": bits(W1), "V2": bits(W2)}
                rows = [to_mask(j for i2, j in support if i2 == i) for i in range(n)]
                I1 = to_mask({j for i in bits(W1) for j in bits(rows[i])})
                I2 = to_mask({j for i in bits(W2) for j in bits(rows[i])})
                expect = not I1 & I2 and popcount(I1 | I2) <= popcount(W1 | W2)
                assert check(c2).valid == expect
        bad = copy.deepcopy(cert)
        bad["support"] = [e for e in bad["support"] if e[0] != 0]
        assert "row 0 has no entry" in check(bad).reason
        bad = copy.deepcopy(cert)
        bad["support"].append(bad["support"][0])
        assert "duplicate" in check(bad).reason
    assert found > 10


# --------------------------------------------------------------------------- #
# strict validation
# --------------------------------------------------------------------------- #


def _base():
    return rs_cert(3, complete_edges(3), 2, 3, {"method": "complete"})


def _set(path, value):
    def f(c):
        d = c
        for k in path[:-1]:
            d = d[k]
        d[path[-1]] = value
    return f


def _delete(path):
    def f(c):
        d = c
        for k in path[:-1]:
            d = d[k]
        del d[path[-1]]
    return f


TAMPER = {
    "unknown top key": (_set(["extra"], 1), "unknown key 'extra'"),
    "unknown graph key": (_set(["graph", "weights"], []), "unknown key 'weights'"),
    "unknown proof key": (_set(["proof", "order"], [0, 1, 2]), "unknown key 'order'"),
    "missing graph": (_delete(["graph"]), "missing key 'graph'"),
    "missing n": (_delete(["graph", "n"]), "missing key 'n'"),
    "bool r": (_set(["r"], True), "r must be an integer"),
    "float r": (_set(["r"], 2.0), "r must be an integer"),
    "bool n": (_set(["graph", "n"], True), "graph.n must be an integer"),
    "bool in edge": (_set(["graph", "edges", 0], [False, 1]), "must be an integer"),
    "string s": (_set(["s"], "3"), "s must be an integer"),
    "negative r": (_set(["r"], -1), "out of range"),
    "s zero": (_set(["s"], 0), "out of range"),
    "s above n": (_set(["s"], 4), "out of range"),
    "edge index out of range": (_set(["graph", "edges", 0], [0, 3]), "out of range"),
    "negative edge index": (_set(["graph", "edges", 0], [-1, 1]), "out of range"),
    "duplicate edge": (_set(["graph", "edges", 1], [0, 1]), "duplicate edge"),
    "self-loop": (_set(["graph", "edges", 0], [1, 1]), "self-loop"),
    "edge triple": (_set(["graph", "edges", 0], [0, 1, 2]), "pair"),
    "edges not array": (_set(["graph", "edges"], {}), "must be an array"),
    "nodes wrong length": (_set(["graph", "nodes"], ["a", "b"]), "labels"),
    "nodes bool label": (_set(["graph", "nodes"], ["a", True, 3]), "string or an integer"),
    "version 2": (_set(["rescon_certificate"], 2), "unsupported"),
    "version true": (_set(["rescon_certificate"], True), "unsupported"),
    "unknown kind": (_set(["kind"], "rs_robustness"), "unknown kind"),
    "unknown method": (_set(["proof", "method"], "magic"), "unknown proof method 'magic'"),
    "proof not object": (_set(["proof"], "complete"), "must be a JSON object"),
    "milp without solver": (_set(["proof"], {"method": "milp"}), "missing key 'solver'"),
    "milp bad info": (_set(["proof"], {"method": "milp", "solver": "highs", "info": 3}),
                      "info must be a JSON object"),
    "dp unknown key": (_set(["proof"], {"method": "dp", "objective": 1}), "unknown key"),
}


@pytest.mark.parametrize("name", sorted(TAMPER))
def test_strict_validation(name):
    assert check(_base()).valid
    f, needle = TAMPER[name]
    cert = _base()
    f(cert)
    res = check(cert)
    assert not res.valid
    assert needle in res.reason, res.reason


def test_labels_and_non_dict():
    cert = _base()
    cert["graph"]["nodes"] = ["a", 7, "a"]
    assert check(cert).valid
    for x in (None, [], "x", 3):
        res = check(x)
        assert not res.valid and "JSON object" in res.reason
    # a milp proof on a small graph is re-verified by enumeration: a false claim fails
    res = check({"rescon_certificate": 1, "kind": "rs_robust", "graph": {"n": 3, "edges": []},
                 "r": 1, "s": 1, "proof": {"method": "milp", "solver": "highs",
                                          "info": {"anything": [1, 2]}}})
    assert not res.valid and "enumeration" in res.reason and not bool(res)
    res = check({"rescon_certificate": 1, "kind": "rs_robust",
                 "graph": {"n": 3, "edges": complete_edges(3)},
                 "r": 1, "s": 1, "proof": {"method": "milp", "solver": "highs",
                                          "info": {"anything": [1, 2]}}})
    assert res.valid and res.trusted == () and bool(res)


def test_trusted_nested_dp_and_milp():
    n = 22
    edges = complete_edges(n)
    seed = {"method": "construction", "order": list(range(21)), "seed_size": 3,
            "seed_proof": {"method": "complete"}}
    # nested: order of the top level puts a 21-node dp-proved seed first
    cert = rs_cert(n, edges, 2, 1, {"method": "construction", "order": list(range(n)),
                                    "seed_size": 21, "seed_proof": {"method": "dp"}})
    res = check(cert)
    assert res.verdict == "unchecked" and res.trusted == ("dp",)
    assert res.unchecked == (("proof.seed_proof: 'dp' proof of (2, 1)-robustness not checked: "
                              "accepted on trust (n = 21 > 20, beyond the checker's own "
                              "enumeration)"),)
    cert["proof"]["seed_proof"] = {"method": "milp", "solver": "highs"}
    assert check(cert).trusted == ("milp",)
    cert["proof"]["seed_proof"] = seed
    res = check(cert)
    assert res.valid and res.trusted == ()


# --------------------------------------------------------------------------- #
# three verdicts: what the checker did not verify is never "valid"
# --------------------------------------------------------------------------- #


def ring_lattice_edges(n, k):
    """Each node receives from the k nearest nodes on each side: in-degree 2k."""
    return [((i + j) % n, i) for i in range(n) for j in range(-k, k + 1) if j]


def test_check_result_verdicts():
    res = check(_base())
    assert res.verdict == "valid" and res.valid and res.unchecked == () and bool(res)
    res = check(dict(_base(), r=3))
    assert res.verdict == "invalid" and not res and res.unchecked == ()
    res = check(rs_cert(22, complete_edges(22), 11, 22, {"method": "milp", "solver": "highs"}))
    assert res.verdict == "unchecked" and not res.valid and not res
    assert res.trusted == ("milp",) and res.reason.startswith("not fully checked: ")
    assert res.unchecked == (("proof: 'milp' proof of (11, 22)-robustness not checked: accepted "
                              "on trust (n = 22 > 20, beyond the checker's own enumeration)"),)
    with pytest.raises(ValueError):
        C.CheckResult(True, "x", ("milp",), ("proof",))
    assert set(C.EXIT_CODES) == set(C.VERDICTS) and C.EXIT_CODES["unchecked"] == 3


def test_forged_milp_claim_is_refuted_by_linear_time_witnesses():
    """rho = 15 claimed for a 30-node ring lattice of in-degree 6 with a milp proof:
    ({min in-degree node}, the rest) violates (r, s) for every r >= 7."""
    n = 30
    edges = ring_lattice_edges(n, 3)
    milp = {"method": "milp", "solver": "highs"}
    forged = {"rescon_certificate": 1, "kind": "robustness", "graph": graph_json(n, edges),
              "exact": True, "r_max": 15, "s_max": n, "lower": milp, "lower_s": milp,
              "upper_r": {"method": "half"}, "upper_s": None}
    res = check(forged)
    assert res.verdict == "invalid", res
    assert "S1 = {0}" in res.reason and "linear-time witness" in res.reason
    for r, s in ((7, 1), (3, 1)):  # r > min in-degree: refuted; else not refuted cheaply
        res = check(rs_cert(n, edges, r, s, milp))
        assert res.verdict == ("invalid" if r > 6 else "unchecked"), (r, s, res)
    # r > ceil(n/2): the balanced split refutes it even on K_n (every method)
    for method in (milp, {"method": "dp"}, {"method": "cost_search", "order": list(range(n))},
                   {"method": "search", "order": list(range(n)), "tree": None},
                   {"method": "enumeration"}):
        res = check(rs_cert(n, complete_edges(n), 16, 1, method))
        assert res.verdict == "invalid" and "S1 = {0, 1, 2" in res.reason, (method, res)
        res = check(rs_cert(n, complete_edges(n), 15, 1, method))
        assert res.verdict == "unchecked" and len(res.unchecked) == 1, (method, res)
    # two nodes without in-neighbours: ({0}, {1}) violates (1, s) for every s (while
    # ({0}, the rest) does not: every other node hears node 0)
    edges = [e for e in complete_edges(n) if e[1] not in (0, 1)]
    res = check(rs_cert(n, edges, 1, 1, milp))
    assert res.verdict == "invalid" and "S1 = {0}, S2 = {1}" in res.reason, res


def test_spectral_and_enumeration_beyond_limits_are_unchecked():
    n = C.MAX_SPECTRAL_N + 1
    res = check(rs_cert(n, complete_edges(n), 2, 1, {"method": "spectral", "c": "2"}))
    assert res.verdict == "unchecked" and "spectral" in res.unchecked[0], res
    res = check(rs_cert(n, complete_edges(n), 2, 1, {"method": "spectral", "c": "x"}))
    assert res.verdict == "invalid"  # still parsed first
    res = check({"rescon_certificate": 1, "kind": "rs_robust",
                 "graph": {"n": C.MAX_N + 1, "edges": []}, "r": 1, "s": 1,
                 "proof": {"method": "trivial"}})
    assert res.verdict == "unchecked" and res.trusted == ("size limit",), res


def test_sarymsakov_trusted_methods_are_unchecked_unless_refuted():
    n = 14
    cycle = [[i, (i + 1) % n] for i in range(n)] + [[i, i] for i in range(n)]
    for method in ("min_cut", "enumeration"):
        c = {"rescon_certificate": 1, "kind": "sarymsakov", "method": method, "n": n,
             "support": cycle}
        res = check(c)
        assert res.verdict == "unchecked" and res.trusted == (method,), res
        # rows 0 and 1 with one entry each, in different columns: V1 = {0}, V2 = {1}
        c["support"] = [e for e in cycle if e[0] not in (0, 1) or e[1] == e[0]]
        res = check(c)
        assert res.verdict == "invalid" and "V1 = {0}, V2 = {1}" in res.reason, res


def test_number_overflowing_a_double_is_unreadable_like_infinity(tmp_path):
    """1e400 and Infinity get the same verdict: unreadable (exit 2)."""
    for i, text in enumerate(("1e400", "-1e400", "Infinity", "-Infinity", "1E+999")):
        f = tmp_path / f"big{i}.json"
        f.write_text('{"rescon_certificate": 1, "kind": "kernel_point", "points": [[' + text
                     + ']], "F": 0, "x": [0], "proof": {"method": "halfspaces"}}')
        assert C.main([str(f)]) == 2, text
    # a dict holding an infinite float (no file) is invalid, as before
    res = check({"rescon_certificate": 1, "kind": "kernel_point", "points": [[float("inf")]],
                 "F": 0, "x": [0], "proof": {"method": "halfspaces"}})
    assert res.verdict == "invalid" and "not a finite number" in res.reason


def test_json_numbers_at_the_edges_of_the_double_and_integer_ranges(tmp_path, capsys):
    """V24's reads, at their edges: a nonzero number underflowing to zero is unreadable
    (1e-400 would claim 0); zeros in any spelling and the smallest subnormal are read
    exactly (5e-324 = 2^-1074: the claim x = 5e-324 ∈ Ψ([-1, 0, 1], 1) = {0} is
    refuted, not unreadable); JSON integers of 4301–9865 digits are read (chunks; the
    kernel {0} of ±10^9000 is valid), longer ones make the certificate unchecked
    (beyond the 32 768-bit limit), never unreadable, in no time."""
    def run(points, x):
        f = tmp_path / "c.json"
        f.write_text('{"rescon_certificate": 1, "kind": "kernel_point", "points": ' + points
                     + ', "F": 1, "x": [' + x + '], "proof": {"method": "halfspaces"}}')
        return C.main([str(f)])

    line = "[[-1], [0], [1]]"
    for text in ("1e-400", "-1e-400", "0.5e-330", "1E-999"):
        assert run(line, text) == 2, text
    for text in ("0.0", "-0.0", "0e-999", "0.000E+5"):
        assert run(line, text) == 0, text
    assert run(line, "5e-324") == 1
    big = "1" + "0" * 9000
    assert run(f"[[-{big}], [0], [{big}]]", "0") == 0
    huge = "9" * 10 ** 6
    assert run(f"[[-{huge}], [0], [{huge}]]", "0") == 3
    assert run(line, huge) == 3


def test_deeply_nested_proof_is_rejected_not_crashing():
    proof = {"method": "trivial"}
    for _ in range(3000):
        proof = {"method": "construction", "order": [0, 1], "seed_size": 2, "seed_proof": proof}
    res = check(rs_cert(2, [(0, 1), (1, 0)], 1, 1, proof))
    assert not res.valid


# --------------------------------------------------------------------------- #
# examples, schema, command line
# --------------------------------------------------------------------------- #


def _validator():
    jsonschema = pytest.importorskip("jsonschema")
    schema = json.loads(SCHEMA.read_text())
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


def test_examples_exist_and_are_valid():
    assert len(EXAMPLES) >= 5
    v = _validator()
    kinds = set()
    for path in EXAMPLES:
        cert = json.loads(path.read_text())
        v.validate(cert)
        res = check(cert)
        expect = "unchecked" if path.stem.endswith("_unchecked") else "valid"
        assert res.verdict == expect, (path.name, res.reason)
        kinds.add(cert["kind"])
    assert kinds == set(C.KINDS)


def test_generated_certificates_match_schema():
    v = _validator()
    rng = random.Random(1)
    certs = [_base(), robustness_cert(4, complete_edges(4))]
    for _ in range(20):
        n = rng.randint(2, 6)
        edges = rand_edges(rng, n, 0.6)
        certs.append(robustness_cert(n, edges))
        out = search_tree(n, in_masks(n, edges), 1, list(range(n)))
        if out:
            certs.append(search_cert(n, edges, 1, list(range(n)), out[0]))
    edges, order, _ = grow(rng, 3, 7, 2, 1)
    certs.append(construction_cert(7, edges, 2, 1, order, 3))
    for c in certs:
        v.validate(c)
    bad = _base()
    bad["extra"] = 1
    assert not v.is_valid(bad)
    bad = _base()
    bad["proof"]["method"] = "magic"
    assert not v.is_valid(bad)


def _run(*args):
    return subprocess.run([sys.executable, str(CHECK_PY), *map(str, args)],
                          capture_output=True, text=True, timeout=60, check=False)


def test_cli_exit_codes(tmp_path):
    good = tmp_path / "good.json"
    good.write_text(json.dumps(_base()))
    p = _run(good)
    assert p.returncode == 0 and p.stdout.strip() == "valid", p.stderr

    trusted = tmp_path / "milp.json"
    c = rs_cert(21, complete_edges(21), 2, 1, {"method": "milp", "solver": "highs"})
    trusted.write_text(json.dumps(c))
    p = _run(trusted)
    assert p.returncode == 3 and p.stderr == ""
    assert p.stdout.splitlines() == [
        "unchecked", ("not checked: proof: 'milp' proof of (2, 1)-robustness not checked: "
                      "accepted on trust (n = 21 > 20, beyond the checker's own enumeration)")]

    bad = tmp_path / "bad.json"
    c = _base()
    c["r"] = 3
    bad.write_text(json.dumps(c))
    p = _run(bad)
    assert p.returncode == 1 and p.stderr.startswith("invalid: ") and p.stdout == ""

    p = _run(tmp_path / "missing.json")
    assert p.returncode == 2 and p.stderr.startswith("unreadable: ")
    for name, text in (("garbage.json", "{not json"), ("array.json", "[1, 2]"),
                       ("dup.json", '{"kind": 1, "kind": 2}'), ("nan.json", '{"r": NaN}')):
        f = tmp_path / name
        f.write_text(text)
        p = _run(f)
        assert p.returncode == 2 and p.stderr.startswith("unreadable: "), (name, p.stderr)
    p = _run()
    assert p.returncode == 2

    for path in EXAMPLES:
        assert _run(path).returncode == (3 if path.stem.endswith("_unchecked") else 0)


def test_main_in_process(tmp_path, capsys):
    good = tmp_path / "good.json"
    good.write_text(json.dumps(_base()))
    assert C.main([str(good)]) == 0
    assert capsys.readouterr().out == "valid\n"
    assert C.main([str(tmp_path / "nope.json")]) == 2


def test_package_init_exports():
    text = (CERT_DIR / "__init__.py").read_text()
    assert "from .check import" in text
    spec = importlib.util.spec_from_file_location(
        "_rescon_certificates_pkg_under_test", CERT_DIR / "__init__.py",
        submodule_search_locations=[str(CERT_DIR)])
    pkg = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = pkg
    spec.loader.exec_module(pkg)
    assert pkg.check(_base()).valid
    assert pkg.CheckResult is sys.modules[spec.name + ".check"].CheckResult


def _timed_check(cert):
    t0 = time.perf_counter()
    res = check(json.loads(json.dumps(cert)))
    return res, time.perf_counter() - t0


def test_search_tree_replay_is_bounded_on_a_long_peeling_chain():
    """A 5 KB certificate: a directed cycle where node i hears only node i + 1, so
    peeling V \\ S removes one node per pass, with one leaf per root. Replaying it took
    O(n^3) mask operations (11 s at n = 400, minutes at n = 1000)."""
    n = 1000
    edges = [[(i + 1) % n, i] for i in range(n)]
    cert = rs_cert(n, edges, 1, 1, {"method": "search", "order": list(range(n)),
                                    "tree": [-1] * n})
    res, seconds = _timed_check(cert)
    assert res.verdict in ("valid", "unchecked"), res
    assert seconds < 10, seconds
    # a smaller chain is replayed in full, and a wrong leaf there is still refuted
    n = 300
    edges = [[(i + 1) % n, i] for i in range(n)]
    good = rs_cert(n, edges, 1, 1, {"method": "search", "order": list(range(n)),
                                    "tree": [-1] * n})
    res, seconds = _timed_check(good)
    assert res.verdict == "valid" and seconds < 5, (res, seconds)
    bad = rs_cert(n, edges, 1, 1, {"method": "search", "order": list(range(n)),
                                   "tree": [-2] * n})
    assert check(bad).verdict == "invalid"


def test_spectral_check_at_its_size_limit_is_bounded():
    """An undirected ring lattice on MAX_SPECTRAL_N nodes: the exact LDL^T in Fractions
    took 26 s; integer (Bareiss) elimination on the upper triangle answers in seconds.
    A c beyond lambda2 is still refuted."""
    def ring(n, k):
        edges = [[i, (i + j) % n] for i in range(n) for j in range(1, k + 1)]
        return edges + [[v, u] for u, v in edges]

    n = C.MAX_SPECTRAL_N
    proof = {"method": "spectral", "c": "7/3"}
    res, seconds = _timed_check(rs_cert(n, ring(n, 30), 1, 1, proof))
    assert res.verdict in ("valid", "unchecked") and seconds < 10, (res, seconds)
    # lambda2 of the ring lattice (60, 3) is 2 sum_j (1 - cos(2 pi j / 60)) < 1: c = 5 fails
    res = check(rs_cert(60, ring(60, 3), 2, 1, {"method": "spectral", "c": "5"}))
    assert res.verdict == "invalid" and "lambda2" in res.reason, res


def test_large_sparse_graph_answers_in_bounded_time():
    """A 6.8 MB certificate: a 200 000-node undirected ring with a trusted proof. Node
    sets are n-bit masks, so reading its edges and the witness pairs cost n (n + m) / 64
    word operations (63 s); beyond the graph work limit it is unchecked at once."""
    n = 200_000
    edges = [[i, (i + 1) % n] for i in range(n)] + [[(i + 1) % n, i] for i in range(n)]
    cert = rs_cert(n, edges, 1, 1, {"method": "milp", "solver": "highs"})
    res, seconds = _timed_check(cert)
    assert res.verdict == "unchecked" and res.trusted == ("size limit",), res
    assert seconds < 10, seconds
    # the same ring on 20 000 nodes is read and its trusted proof named
    n = 20_000
    edges = [[i, (i + 1) % n] for i in range(n)] + [[(i + 1) % n, i] for i in range(n)]
    res = check(rs_cert(n, edges, 1, 1, {"method": "milp", "solver": "highs"}))
    assert res.verdict == "unchecked" and res.trusted == ("milp",), res


@pytest.mark.parametrize("label", [1.5, True, None, [1], {"a": 1}])
def test_redundancy_agent_labels_are_strings_or_integers(label):
    """FORMAT.md: agents are N distinct labels, JSON strings or integers; anything else
    is invalid (V24's note: they were not type-checked), strings and integers keep the
    genuine verdict."""
    import json
    from pathlib import Path

    path = Path(__file__).parents[1] / "certificates/examples/redundancy_shifted_violation.json"
    cert = json.loads(path.read_text())
    genuine = check(cert).verdict
    assert genuine == "valid"
    for fine in ("agent x", 7):
        cert["agents"][0] = fine
        assert check(cert).verdict == genuine
    cert["agents"][0] = label
    res = check(cert)
    assert res.verdict == "invalid" and "agents[0]" in res.reason, res
