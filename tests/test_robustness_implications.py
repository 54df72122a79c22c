"""Implications between (r, s)-robustness facts, the per-process fact cache, the
deepening s* search, and the phased progress bar (issue 12 §5, issue 13 §2)."""

from __future__ import annotations

import copy
import itertools
import random

import networkx as nx
import pytest

import rescon
from rescon.graphs import bounds as bd
from rescon.graphs import facts as fx
from rescon.graphs.indexed import index_graph


def brute_s_star(G: nx.Graph, r: int) -> int:
    """s*(r) by enumerating every pair (0 when G is not r-robust)."""
    ig = index_graph(G)
    n, best = ig.n, ig.n
    for lab in itertools.product((0, 1, 2), repeat=n):
        S1 = frozenset(i for i in range(n) if lab[i] == 1)
        S2 = frozenset(i for i in range(n) if lab[i] == 2)
        if S1 and S2 and min(S1) < min(S2):
            cost = bd.pair_cost(ig, bd.Pair(S1, S2), r)
            if cost is not None:
                best = min(best, cost)
    return best


def small_graphs(count: int, seed: int) -> list[nx.Graph]:
    rng = random.Random(seed)
    out = []
    for k in range(count):
        n = rng.randint(3, 8)
        G = nx.gnp_random_graph(n, rng.uniform(0.3, 0.95), directed=rng.random() < 0.6,
                                seed=seed * 1000 + k)
        out.append(G)
    return out


def assert_valid(cert: dict) -> None:
    res = rescon.check_certificate(cert)
    assert res.valid, res.reason


@pytest.fixture(autouse=True)
def _fresh_cache():
    fx.clear_cache()
    yield
    fx.clear_cache()


def test_implication_rule_against_brute_force():
    """s*(r) ≥ min(n, s*(r') + r' − r) whenever r ≤ r' and G is r'-robust (often more
    than monotonicity alone, s*(r) ≥ s*(r'), gives)."""
    stronger = 0
    for G in small_graphs(40, 1):
        n = G.number_of_nodes()
        ss = {r: brute_s_star(G, r) for r in range(1, n + 1)}
        for r, r2 in itertools.combinations_with_replacement(sorted(ss), 2):
            if ss[r2] >= 1:
                implied = fx.implied_s(n, r, r2, ss[r2])
                assert ss[r] >= implied, (G.edges(), r, r2, ss)
                stronger += implied > ss[r2]
    assert stronger > 0


def test_checker_accepts_exactly_the_sound_implications():
    """An ``implied`` proof wrapping a true (r', s') enumeration proof is valid iff
    r ≤ r' and s ≤ s' + r' − r; every accepted claim is true by brute force."""
    for G in small_graphs(6, 2):
        ig = index_graph(G)
        n = ig.n
        ss = {r: brute_s_star(G, r) for r in range(1, n)}
        for r, r2 in itertools.product(ss, ss):
            s2 = ss[r2]
            if s2 < 1:
                continue
            for s in range(1, n + 1):
                cert = {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(),
                        "r": r, "s": s, "proof": {"method": "implied", "r": r2, "s": s2,
                                                  "proof": {"method": "enumeration"}}}
                res = rescon.check_certificate(cert)
                sound = r <= r2 and s <= s2 + r2 - r
                assert res.valid == sound, (G.edges(), r, s, r2, s2, res.reason)
                if res.valid:
                    assert ss[r] >= s


@pytest.mark.parametrize("warm", [False, True])
def test_every_rs_answer_matches_brute_force(warm):
    """All (r, s) on small graphs: is_rs_robust and max_s equal brute force, cold or
    after robustness(G) filled the cache; certificates are fully checked; some answers
    come from implications."""
    methods = set()
    for G in small_graphs(14, 3 + warm):
        n = G.number_of_nodes()
        fx.clear_cache()
        if warm:
            rescon.robustness(G)
        for r in range(1, (n + 1) // 2 + 2):
            truth = brute_s_star(G, r)
            assert rescon.max_s(G, r) == truth
            for s in range(1, n + 1):
                res = rescon.is_rs_robust(G, r, s)
                assert res.holds == (truth >= s), (G.edges(), r, s, truth)
                assert_valid(res.certificate)
                methods.add(res.proof_method)
    assert "implied" in methods


def test_quick_start_rs_query_uses_rho_without_searching():
    """The README quick start: ρ = 6 proven by robustness(G) implies (3, 2) and (3, 4)
    with no further search; the certificate embeds the ρ proof and is fully checked."""
    G = nx.gnp_random_graph(25, 0.5, directed=True, seed=7)
    rep = rescon.robustness(G)
    assert (rep.r_max, rep.s_max) == (6, 1)
    for s in (2, 4):
        res = rescon.is_rs_robust(G, 3, s)
        assert res.holds and res.method == "bounds" and res.proof_method == "implied"
        proof = res.certificate["proof"]
        assert (proof["r"], proof["s"]) == (6, 1)
        assert_valid(res.certificate)


def test_cold_rs_query_proves_the_stronger_r_robustness_first():
    """Without a cached ρ, (3, 2) follows from a proof of 4-robustness (checkable), not
    from a trusted s* search."""
    G = nx.gnp_random_graph(25, 0.5, directed=True, seed=7)
    res = rescon.is_rs_robust(G, 3, 2)
    assert res.holds and res.proof_method == "implied"
    assert res.certificate["proof"]["r"] == 4
    assert_valid(res.certificate)


def test_max_s_result_is_cached_and_reused():
    G = nx.gnp_random_graph(16, 0.6, directed=True, seed=5)
    s3 = rescon.max_s(G, 3)
    assert s3 == rescon.max_s(G, 3, method="dp")
    for s, holds in ((s3, True), (min(s3 + 1, 16), s3 >= 16)):
        res = rescon.is_rs_robust(G, 3, s)
        assert res.holds == holds and res.method == "bounds"
        assert_valid(res.certificate)


def test_tampered_implied_certificates_are_rejected():
    G = nx.gnp_random_graph(25, 0.5, directed=True, seed=7)
    rescon.robustness(G)
    cert = rescon.is_rs_robust(G, 3, 4).certificate
    assert_valid(cert)
    too_far = copy.deepcopy(cert)
    too_far["s"] = 5  # 6-robust implies (3, s) only for s ≤ 1 + 6 − 3 = 4
    assert not rescon.check_certificate(too_far).valid
    weaker = copy.deepcopy(cert)
    weaker["proof"]["r"] = 5  # the embedded proof is of 6-robustness
    assert not rescon.check_certificate(weaker).valid
    below = copy.deepcopy(cert)
    below["r"] = 7  # an implication never raises r
    assert not rescon.check_certificate(below).valid
    edge = copy.deepcopy(cert)
    edge["graph"]["edges"] = edge["graph"]["edges"][5:]
    assert not rescon.check_certificate(edge).valid


def test_mutated_graph_never_reuses_stale_facts():
    G = nx.complete_graph(7)
    assert rescon.robustness(G).r_max == 4
    assert rescon.is_rs_robust(G, 3, 2).holds
    for u in range(1, 7):  # node 0 keeps one neighbour: ρ drops to 1
        if u != 1:
            G.remove_edge(0, u)
    assert rescon.is_rs_robust(G, 3, 2).holds is False
    assert rescon.is_r_robust(G, 2).holds is False
    assert rescon.max_s(G, 1) == brute_s_star(G, 1)
    assert rescon.robustness(G).r_max == 1
    H = nx.relabel_nodes(nx.complete_graph(7), {0: "a"})  # same edges, other labels
    res = rescon.is_rs_robust(H, 3, 2)
    assert res.holds and res.certificate["graph"]["nodes"][0] == "a"
    assert_valid(res.certificate)


def test_cache_keys_tell_labels_of_different_types_apart():
    G = nx.Graph([(1, 2), (2, 3), (3, 1)])
    H = nx.Graph([(1.0, 2), (2, 3), (3, 1.0)])
    assert fx.facts_for(index_graph(G)) is not fx.facts_for(index_graph(H))


def test_cache_is_bounded():
    for k in range(fx.CACHE_SIZE + 5):
        rescon.is_r_robust(nx.path_graph(k + 3), 1)
    assert len(fx._CACHE) == fx.CACHE_SIZE


def test_deepening_search_equals_dp():
    """The s* search (deepening caps after a local-search upper bound) is exact."""
    for seed in range(6):
        G = nx.gnp_random_graph(14, 0.4 + 0.08 * seed, directed=True, seed=seed)
        for r in (1, 2, 3):
            fx.clear_cache()
            fast = rescon.max_s(G, r, method="search")
            fx.clear_cache()
            assert fast == rescon.max_s(G, r, method="dp")


def test_descend_pair_never_worsens_and_stays_valid():
    G = nx.gnp_random_graph(20, 0.5, directed=True, seed=3)
    ig = index_graph(G)
    for pair in bd.descended_pairs(ig, 3, starts=10):
        assert bd.pair_cost(ig, pair, 3) is not None and pair.S1 and pair.S2
        assert not pair.S1 & pair.S2
    full = (1 << ig.n) - 1
    start = bd.descend_pair(ig, 3, 0b1011, full ^ 0b1011)
    if start is not None:
        assert start[0] <= bd.pair_cost(ig, bd.Pair(frozenset({0, 1, 3}),
                                                    frozenset(range(4, 20)) | {2}), 3)


def test_progress_names_every_phase_on_stderr_only(capfd):
    G = nx.gnp_random_graph(28, 0.3, directed=True, seed=1)  # ρ and s* both searched
    rep = rescon.robustness(G, progress=True)
    assert rep.method == "search+search"
    out, err = capfd.readouterr()
    assert out == ""
    assert "bounds" in err and "ρ search (r=" in err and "s* search (r=" in err
    assert " nodes" in err
    fx.clear_cache()
    rescon.robustness(G, progress=False)
    out, err = capfd.readouterr()
    assert out == "" and err == ""


class _FakeMilp:
    def __init__(self) -> None:
        self.t0, self.alive = 0.0, False

    def started(self) -> bool:
        return self.t0 > 0.0

    def start(self) -> None:
        self.t0, self.alive = 1.0, True

    def running(self) -> bool:
        return self.alive


def test_race_starts_the_milp_only_after_the_delay(monkeypatch):
    import time

    from rescon.graphs import robustness as rb

    monkeypatch.setattr(rb, "RACE_DELAY_SECONDS", 0.05)
    milp = _FakeMilp()
    stop = rb._rival(milp)
    assert stop() is False and not milp.started()  # short searches never meet the MILP
    time.sleep(0.06)
    assert stop() is False and milp.started()
    milp.alive = False  # the MILP answered: the search stops
    assert stop() is True


def test_milp_progress_names_the_phase_and_counts_nodes(capfd):
    """Beyond the search's reach (n > 64 takes the MILP) the bar is not stuck at a bare
    0: the phase is named and HiGHS's branch-and-bound nodes are counted."""
    G = nx.gnp_random_graph(70, 0.2, directed=True, seed=1)  # ρ's MILP runs ≫ 2 s
    rep = rescon.robustness(G, progress=True, time_limit=2)
    assert not rep.exact and rep.method == "milp"
    out, err = capfd.readouterr()
    assert out == ""
    assert "ρ MILP (r=" in err and " nodes" in err
