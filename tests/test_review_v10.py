"""Hostile review of the checker's one-pass capped peel (certificates/check.py
``_Replay.capped``: Q \\ S peeled from the stack's closed superset, F_m = D − E_m in
packed fields, ``capped_wide``, the row-sum store ``sums``). Checked against a
brute-force capped core on closed supersets at the packed-width boundaries (n = 15, 16,
31, 32; thresholds above n, need ≤ 0, t ≤ 0, empty candidate sets), against the
checker before the change (50bba3b, read from git) on charged trees and tampered ones,
against brute-force robustness (n ≤ 9), with tiny row-sum stores and a small work
limit; the store's memory charge covers its keys."""

from __future__ import annotations

import importlib.util
import random
import subprocess
import sys
from pathlib import Path

import pytest

import rescon
from rescon.graphs.charged import charged_order, charged_tree, uniform_tree
from rescon.graphs.indexed import index_graph
from tests.test_checker import C, digraph, in_masks, is_robust, rand_edges
from tests.test_robustness_certs3 import _core

pytestmark = pytest.mark.usefixtures("fresh_facts")

ROOT = Path(__file__).resolve().parents[1]


def _capped_brute(inm, t1, t2, i, j, S, P, Q):
    """The capped core of FORMAT.md's −5 − (i·n + j) leaf, node by node on bitmasks, for
    the exact Q = core_t2(V \\ S \\ B) (0 when a slack is negative)."""
    caps = []
    for m in (i, j):
        c = inm[m] & P & ~S
        sl = c.bit_count() - ((inm[m] & ~S).bit_count() - t1[m] + 1)
        if sl < 0:
            return 0
        caps.append((c, sl))
    U = Q & ~S
    while True:
        drop = 0
        for v in range(len(inm)):
            if U >> v & 1:
                ins, need = inm[v] & U, inm[v].bit_count() - t2[v] + 1
                if any((ins & ~c).bit_count() + min(sl, (ins & c).bit_count()) < need
                       for c, sl in caps):
                    drop |= 1 << v
        if not drop:
            return U
        U &= ~drop


def _thresholds(rng, n, inm, mode):
    if mode == 0:
        return [rng.randint(1, 3) for _ in range(n)]
    if mode == 1:
        return [rng.randint(1, n + 4) for _ in range(n)]
    if mode == 2:  # at and beyond n: s2.most = n, the packed room 2^(w-1) - n smallest
        return [rng.choice([1, n, n + 1, 10 * n]) for _ in range(n)]
    if mode == 3:  # need_v = d_v - t_v + 1 around 0
        return [inm[v].bit_count() + rng.randint(-1, 2) for v in range(n)]
    return [rng.choice([0, 1, 2, n]) for _ in range(n)]  # t <= 0: never in a closed set


@pytest.mark.parametrize("seed", range(6))
def test_capped_on_any_closed_superset_is_the_brute_force_capped_core(seed):
    """capped(i, j, S, P, Q', D') for a closed Q' (core of V minus a part of S ∪ B, minus
    a random set, or the exact core) equals the brute-force capped core of
    core(Q' \\ S), for n at the packed-width edges (2^(w−1) = n + 1 or 2n), graphs
    empty to complete and thresholds from 0 to 10·n; both packed paths, the boundary
    sl = 2^(w−1) − most, ``capped_wide`` and ``capped_slow`` are all taken."""
    rng = random.Random(seed)
    taken = {"boundary": 0, "wide": 0, "cases": 0}
    wide = C._Replay.capped_wide

    def counting_wide(self, *a):
        taken["wide"] += 1
        return wide(self, *a)

    C._Replay.capped_wide = counting_wide
    try:
        for _ in range(25):
            n = rng.choice([2, 3, 7, 8, 15, 16, 17, 31, 32])
            p = rng.choice([0.0, 0.2, 0.6, 0.9, 1.0])
            edges = [(u, v) for u in range(n) for v in range(n) if u != v and rng.random() < p]
            inm = in_masks(n, edges)
            rp = C._Replay(C._graph({"n": n, "edges": [list(e) for e in edges]}), 1, "t")
            rp.capped_tables()
            mode = rng.randrange(5)
            t1, t2 = (_thresholds(rng, n, inm, mode) for _ in range(2))
            s1, s2 = rp.threshold_side(t1), rp.threshold_side(t2)
            gone2 = sum(1 << v for v in range(n) if t2[v] <= 0)
            room = (1 << (rp.w - 1)) - s2.most
            for _ in range(8):
                lab = [rng.choice((0, 0, 1, 1, 2, 3)) for _ in range(n)]
                lab[rng.randrange(n)] = 1
                S = sum(1 << v for v in range(n) if lab[v] == 1)
                X = sum(1 << v for v in range(n) if lab[v] >= 2)
                B = sum(1 << v for v in range(n) if lab[v] == 3)
                P = rp.shrink(rp.full, s1.D, s1.gone | rp.pack(X), s1)[0]
                T = rng.choice([S | B, (S & rng.getrandbits(n)) | B,
                                rng.getrandbits(n) & rng.getrandbits(n)])
                Qs, QD = rp.shrink(rp.full, s2.D, s2.gone | rp.pack(T), s2)
                assert rp.unpack(Qs) == _core(((1 << n) - 1) & ~T & ~gone2, inm, t2)
                Q = _core(rp.unpack(Qs) & ~S, inm, t2)
                members = [v for v in range(n) if S >> v & 1]
                for i in members:
                    for j in (j for j in members if j >= i):
                        want = _capped_brute(inm, t1, t2, i, j, S, rp.unpack(P), Q)
                        got = rp.capped(i, j, rp.pack(S), P, Qs, QD, s1, s2)
                        assert rp.unpack(got) == want, (n, edges, t1, t2, S, X, B, T, i, j)
                        taken["cases"] += 1
                        for m in (i, j):
                            cm = rp.pin[m] & P & ~rp.pack(S)
                            sl = min(cm.bit_count() - (rp.pin[m] & ~rp.pack(S)).bit_count()
                                     + t1[m] - 1, (cm & Qs).bit_count())
                            taken["boundary"] += sl == room
    finally:
        C._Replay.capped_wide = wide
    assert taken["cases"] > 200 and taken["boundary"] > 0 and taken["wide"] > 0, taken


def _cert(ig, r, s, tree, order=None, uniform=False):
    order = charged_order(ig).tolist() if order is None else order
    proof = {"method": "cost_search", "order": order, "charged_tree": list(tree)}
    if uniform:
        proof["uniform"] = True
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(), "r": r,
            "s": s, "proof": proof}


def _tampered(rng, tree, n):
    """Trees with a capped leaf's members changed (swapped, random i ≤ j, another leaf
    kind), another leaf or a branch turned into a capped leaf, two tokens swapped, one
    deleted."""
    out = []
    capped = [k for k, t in enumerate(tree) if t <= -5]
    leaves = [k for k, t in enumerate(tree) if -4 <= t < 0]
    branches = [k for k, t in enumerate(tree) if t >= 0]

    def put(k, t):
        out.append(tree[:k] + [t] + tree[k + 1:])

    def any_capped():
        a = rng.randrange(n)
        return -5 - (a * n + rng.randrange(a, n))

    for k in rng.sample(capped, min(3, len(capped))):
        i, j = divmod(-5 - tree[k], n)
        if i < j:
            put(k, -5 - (j * n + i))
        for _ in range(5):
            put(k, any_capped())
        for t in (-1, -2, -3, -4):
            put(k, t)
    for k in rng.sample(leaves, min(3, len(leaves))) + rng.sample(branches, min(2, len(branches))):
        put(k, any_capped())
    if len(tree) > 1:
        k = rng.randrange(len(tree) - 1)
        out.append(tree[:k] + [tree[k + 1], tree[k]] + tree[k + 2:])
        k = rng.randrange(len(tree))
        out.append(tree[:k] + tree[k + 1:])
    return out


def _graphs(seed, count, n_hi):
    """Random digraphs n = 5..n_hi (directed or undirected, p = 0.2..0.9) with their
    (ρ, s*) from rescon and a charged tree (and a uniform one when there is one) for
    each s = 2..min(s*, 4), with the claims' tampered variants: (ig, inm, certs)."""
    rng = random.Random(seed)
    for _ in range(count):
        n = rng.randint(5, n_hi)
        ig = index_graph(digraph(n, rand_edges(rng, n, rng.uniform(0.2, 0.9),
                                               undirected=rng.random() < 0.4)))
        inm = in_masks(n, ig.edges())
        rep = rescon.robustness(digraph(n, ig.edges()))
        r, s_star = rep.r_max, rep.s_max
        if r < 1:
            continue
        certs = []
        for s in range(2, min(s_star, 4) + 1):
            tree = charged_tree(ig, r, s, max_tokens=100_000)
            if tree is None:
                continue
            tree = list(tree)
            certs += [_cert(ig, r, s, tree), _cert(ig, r, s + 1, tree),
                      _cert(ig, r + 1, s, tree), _cert(ig, r, s, tree, uniform=True)]
            order = charged_order(ig).tolist()
            a, b = rng.sample(range(n), 2)
            order[a], order[b] = order[b], order[a]
            certs.append(_cert(ig, r, s, tree, order))
            certs += [_cert(ig, r, s, bad) for bad in _tampered(rng, tree, n)]
            ut = uniform_tree(ig, r, s, max_tokens=100_000)
            if ut is not None:
                certs += [_cert(ig, r, s, list(ut), uniform=True),
                          _cert(ig, r, s + 1, list(ut), uniform=True)]
                certs += [_cert(ig, r, s, bad, uniform=True) for bad in _tampered(rng, list(ut), n)]
        yield n, inm, certs


@pytest.mark.parametrize("seed", range(3))
def test_a_valid_charged_tree_claim_is_true_by_brute_force(seed):
    """n = 5..9: every charged-tree certificate the checker calls valid (recorded,
    tampered, or claiming s + 1, r + 1, another order) states a true (r, s)-robustness."""
    valid = invalid = 0
    for n, inm, certs in _graphs(500 + seed, 6, 9):
        for cert in certs:
            res = C.check(cert)
            assert res.verdict != "unchecked", res.reason
            if res.verdict == "valid":
                assert is_robust(n, inm, cert["r"], cert["s"]), cert
                valid += 1
            else:
                invalid += 1
    assert valid > 3 and invalid > 30


@pytest.mark.parametrize("limit", [0, 1, 3])
def test_a_tiny_row_sum_store_changes_no_verdict_or_reason(monkeypatch, limit):
    """The store emptied on (almost) every insertion, in the middle of every replay:
    the same verdict and reason as with the default store, on recorded and tampered
    charged trees."""
    seen = set()
    for _n, _inm, certs in _graphs(700 + limit, 4, 10):
        for cert in certs:
            monkeypatch.setattr(C, "ROW_SUMS", 1 << 16)
            want = C.check(cert)
            monkeypatch.setattr(C, "ROW_SUMS", limit)
            got = C.check(cert)
            assert (got.verdict, got.reason) == (want.verdict, want.reason)
            seen.add(got.verdict)
    assert seen == {"valid", "invalid"}


@pytest.mark.slow
def test_the_work_limit_fails_closed_on_capped_leaves(monkeypatch):
    """n = 22 (beyond the checker's own enumeration), s* ≥ 2, a charged tree with
    capped leaves: valid under the default limit; under limits cutting its replay
    anywhere (from before the tables to one step short), "unchecked", never valid; a
    tree with its last capped leaf made wrong is invalid or, when the replay stops
    before it, unchecked."""
    rng = random.Random(7)
    n = 22
    while True:
        ig = index_graph(digraph(n, rand_edges(rng, n, rng.uniform(0.4, 0.8))))
        rep = rescon.robustness(digraph(n, ig.edges()))
        if rep.r_max >= 1 and rep.s_max >= 2:
            break
    r, s = rep.r_max, min(rep.s_max, 3)
    tree = list(charged_tree(ig, r, s))
    assert any(t <= -5 for t in tree)
    spent = []
    run = C._Replay.run

    def recording_run(self, *a):
        out = run(self, *a)
        spent.append(self.work)
        return out

    monkeypatch.setattr(C._Replay, "run", recording_run)
    assert C.check(_cert(ig, r, s, tree)).verdict == "valid"
    work = spent[-1]
    k = max(k for k, t in enumerate(tree) if t <= -5)
    bad = tree[:k] + [-1 if tree[k] != -1 else -2] + tree[k + 1:]
    assert C.check(_cert(ig, r, s, bad)).verdict == "invalid"
    for limit in (1, work // 100, work // 3, work // 2, work - 1):
        monkeypatch.setattr(C, "MAX_SEARCH_WORK", limit)
        assert C.check(_cert(ig, r, s, tree)).verdict == "unchecked", limit
        assert C.check(_cert(ig, r, s, bad)).verdict in ("unchecked", "invalid"), limit


def test_the_row_sum_store_charges_its_keys_too():
    """_Replay's memory bound (one step per 64 bits kept): a stored row sum keeps its
    key q, a packed set as wide as the sum; the steps charged for new entries cover the
    bits of both (n = 200: 28 steps per entry charged for about 56 held)."""
    rng = random.Random(5)
    n = 200
    edges = [[u, v] for u in range(n) for v in range(n) if u != v and rng.random() < 0.5]
    rp = C._Replay(C._graph({"n": n, "edges": edges}), 1, "t")
    rp.capped_tables()
    members = [rp.pack(1 << u) for u in range(n) if rp.g.inmask[0] >> u & 1]
    charged = held = 0
    for k in range(60):
        q = members[k] | members[k + 1]
        before = rp.work
        E = rp.row_sum(0, q)
        charged += rp.work - before
        held += q.bit_length() + E.bit_length()
    assert len(rp.sums) == 60
    assert 64 * charged >= held


def _old_checker(tmp_path):
    """certificates/ at 50bba3b (before the one-pass capped peel), loaded by path."""
    for name in ("check", "cost_tree", "kernels", "redundancy"):
        try:
            text = subprocess.run(["git", "show", f"50bba3b:certificates/{name}.py"], cwd=ROOT,
                                  capture_output=True, text=True, check=True).stdout
        except (OSError, subprocess.CalledProcessError):
            pytest.skip("commit 50bba3b is not in this checkout")
        (tmp_path / f"{name}.py").write_text(text)
    spec = importlib.util.spec_from_file_location("_review_v10_check_old", tmp_path / "check.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.slow
def test_the_checker_before_the_one_pass_peel_gives_the_same_verdicts(tmp_path):
    """Old (50bba3b) and new checker: the same verdict and reason on recorded, tampered
    and false-claim charged-tree certificates, n = 5..12, directed and undirected."""
    old = _old_checker(tmp_path)
    compared = 0
    for _n, _inm, certs in _graphs(900, 25, 12):
        for cert in certs:
            a, b = old.check(cert), C.check(cert)
            assert (b.verdict, b.reason) == (a.verdict, a.reason)
            compared += 1
    assert compared > 300


def test_the_row_sum_store_keys_do_not_collide_by_construction():
    """2000 packed subsets of N(0) that differ only in which node of each pair of
    fields (p, p + 61) they hold: their store keys have (nearly) distinct hashes, so a
    look-up costs O(1) probes, not O(|sums|) (measured with the int keys: 5000 such
    sets, all one hash, 3.0 CPU-s per 10^6 steps charged against 0.12 for others)."""
    n = 130
    edges = [[u, 0] for u in range(1, n)] + [[u, u % (n - 1) + 1] for u in range(1, n)]
    rp = C._Replay(C._graph({"n": n, "edges": edges}), 1, "t")
    rp.capped_tables()
    pairs = [(rp.node[p], rp.node[p + 61]) for p in range(61)
             if 0 not in (rp.node[p], rp.node[p + 61])][:14]
    assert len(pairs) == 14
    rng = random.Random(3)
    for bits in rng.sample(range(1 << len(pairs)), 2000):
        mask = sum(1 << (a if bits >> k & 1 else b) for k, (a, b) in enumerate(pairs))
        rp.row_sum(0, rp.pack(mask))
    assert len(rp.sums) == 2000
    assert len({hash(k) for k in rp.sums}) > 1900
