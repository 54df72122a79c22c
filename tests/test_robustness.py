"""Tests for the public robustness API (rescon.robustness, is_r_robust, is_rs_robust,
max_s) against brute-force oracles written here (tests/conftest.py), and for the
certificates it produces (rescon.check_certificate, the independent checker).

Convention (SPEC §1): DiGraph edge (u, v) means v receives u. For S ⊆ V,
reach_r(S) = {i ∈ S : |N_in(i) \\ S| ≥ r}; rho = min over disjoint nonempty pairs of
max(e(S1), e(S2)) with e(S) = max_{i∈S} |N_in(i) \\ S|; s*(r) = min over pairs with
reach_r(S1) ≠ S1 and reach_r(S2) ≠ S2 of |reach_r(S1)| + |reach_r(S2)| (n if none,
0 when r > rho).
"""

from __future__ import annotations

import copy
import json
import math
import time

import networkx as nx
import numpy as np
import pytest
from conftest import (
    cert_graph_matches,
    fast_oracle,
    in_masks,
    oracle,
    pair_violates,
)
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import rescon
from rescon.graphs.facts import clear_cache
from rescon.graphs.generators import ba_robust, circulant, directed_growth, two_cliques

METHODS = ("auto", "search", "milp", "dp")


def half(n: int) -> int:
    return math.ceil(n / 2)


# --------------------------------------------------------------------------- #
# shared assertions
# --------------------------------------------------------------------------- #


TRUSTED_METHODS = {"milp", "dp", "cost_search", "search", "enumeration", "spectral"}


def check_valid(cert: dict, G: nx.Graph, *, fully_checked: bool = False,
                roundtrip: bool = True):
    """The certificate is JSON-ready, about G, and the checker accepts it (also after a
    JSON round trip). With ``fully_checked`` nothing may be accepted on trust."""
    assert cert is not None
    assert cert_graph_matches(cert, G), "the certificate's graph is not G"
    text = json.dumps(cert, allow_nan=False)
    res = rescon.check_certificate(cert)
    # a proof the checker cannot replay (n > 20) makes it "unchecked", never "valid"
    assert res.verdict == "valid" or set(res.trusted) <= TRUSTED_METHODS, res
    assert res.verdict != "invalid", res.reason
    if roundtrip:
        again = rescon.check_certificate(json.loads(text))
        assert again.verdict == res.verdict, again.reason
    if fully_checked:
        assert res.trusted == (), f"accepted on trust: {res.trusted}"
    n = cert["graph"]["n"]
    if n <= 20:  # dp is re-verified by enumeration up to n = 20: only milp is ever trusted
        assert set(res.trusted) <= {"milp"}, res.trusted
    return res


def check_report(G: nx.Graph, rep, rho: int, s_star: int, method: str) -> None:
    """An exact RobustnessReport agrees with the oracle and carries a valid certificate."""
    n = G.number_of_nodes()
    assert rep.n == n
    assert rep.exact is True
    assert (rep.r_max, rep.s_max) == (rho, s_star), f"method={method}"
    assert rep.r_lower == rep.r_upper == rho
    assert rep.seconds >= 0 and isinstance(rep.method, str)
    cert = rep.certificate
    assert cert["kind"] == "robustness" and cert["exact"] is True
    assert (cert["r_max"], cert["s_max"]) == (rho, s_star)
    assert rep.lower_proof == cert["lower"]["method"]
    # dp proofs are re-verified by the checker's own enumeration up to n = 20
    check_valid(cert, G, fully_checked=method == "dp" and n <= 20)
    # witness: labels of G showing "not (r_max + 1)-robust"; None only at ceil(n/2)
    if rep.witness is None:
        assert rho == half(n)
    else:
        S1, S2 = rep.witness
        assert isinstance(S1, frozenset) and isinstance(S2, frozenset)
        assert pair_violates(G, S1, S2, rho + 1, 1), rep.witness
    # s_witness: not (r_max, s_max + 1)-robust; None iff s_max = n
    if s_star == n:
        assert rep.s_witness is None
    else:
        S1, S2 = rep.s_witness
        assert pair_violates(G, S1, S2, rho, s_star + 1), rep.s_witness


def check_rs(G: nx.Graph, res, r: int, s: int, expected: bool) -> None:
    """An is_rs_robust answer agrees with the oracle, with witness/certificate."""
    assert (res.r, res.s) == (r, s)
    assert res.holds is expected, f"(r, s) = ({r}, {s})"
    cert = res.certificate
    check_valid(cert, G)
    assert (cert["r"], cert["s"]) == (r, s)
    if expected:
        assert cert["kind"] == "rs_robust"
        assert res.witness is None
        assert res.proof_method == cert["proof"]["method"]
    else:
        assert cert["kind"] == "not_rs_robust"
        S1, S2 = res.witness
        assert pair_violates(G, S1, S2, r, s), res.witness


def full_check(G: nx.Graph, *, methods=METHODS, grid_methods=("auto",)) -> None:
    """Everything the API answers about a small graph, against the brute-force oracle."""
    o = oracle(G)
    n = o.n
    for m in methods:
        clear_cache()  # each method computes, none reads another's cached facts
        rep = rescon.robustness(G, method=m)
        check_report(G, rep, o.rho, o.s_star_of(o.rho), m)
    for m in grid_methods:
        clear_cache()
        for r in range(0, half(n) + 2):
            assert rescon.max_s(G, r, method=m) == o.s_star_of(r), (m, r)
            res1 = rescon.is_r_robust(G, r, method=m)
            check_rs(G, res1, r, 1, r <= o.rho)
            for s in range(1, n + 1):
                check_rs(G, rescon.is_rs_robust(G, r, s, method=m), r, s, o.holds(r, s))


# --------------------------------------------------------------------------- #
# the oracles check themselves
# --------------------------------------------------------------------------- #


def test_oracle_known_values():
    # K_n: ceil(n/2)-robust, (r, s)-robust for all s
    for n in range(2, 8):
        o = oracle(nx.complete_graph(n))
        assert o.rho == half(n)
        assert all(o.s_star_of(r) == n for r in range(0, half(n) + 1))
        assert o.s_star_of(half(n) + 1) == 0
    # directed cycle: 1-robust, s*(1) = 2 (each set needs one inside arc)
    o = oracle(nx.cycle_graph(6, create_using=nx.DiGraph))
    assert (o.rho, o.s_star_of(1)) == (1, 2)
    # empty graph: 0-robust, s*(0) = n
    o = oracle(nx.empty_graph(5))
    assert (o.rho, o.s_star_of(0), o.s_star_of(1)) == (0, 5, 0)
    # out-star (centre -> leaves) is 1-robust, in-star (leaves -> centre) is not
    out_star = nx.DiGraph([(0, i) for i in range(1, 5)])
    assert oracle(out_star).rho == 1
    assert oracle(out_star.reverse()).rho == 0


def test_fast_oracle_matches_enumeration():
    rng = np.random.default_rng(7)
    for k in range(40):
        n = int(rng.integers(2, 8))
        G = nx.gnp_random_graph(n, float(rng.uniform(0.1, 0.9)), directed=bool(k % 3), seed=k)
        o = oracle(G)
        rho, ss = fast_oracle(G)
        assert rho == o.rho and ss == o.s_star


# --------------------------------------------------------------------------- #
# small graph families, n <= 8: everything against the oracle
# --------------------------------------------------------------------------- #


def _relabel(G: nx.Graph, how: str) -> nx.Graph:
    if how == "str":
        return nx.relabel_nodes(G, {v: f"agent-{v}" for v in G}, copy=True)
    if how == "tuple":
        return nx.relabel_nodes(G, {v: (v, "x") for v in G}, copy=True)
    if how == "mixed":
        return nx.relabel_nodes(G, {v: (v if v % 2 else f"n{v}") for v in G}, copy=True)
    raise AssertionError(how)


def _two_components(a: nx.Graph, b: nx.Graph) -> nx.Graph:
    return nx.disjoint_union(a, b)


def _families() -> list[tuple[str, nx.Graph]]:
    F: list[tuple[str, nx.Graph]] = []
    for n in (2, 3, 4, 5, 6, 7, 8):
        F.append((f"K{n}", nx.complete_graph(n)))
        F.append((f"empty{n}", nx.empty_graph(n)))
    for n in (3, 5, 6, 8):
        F.append((f"Kdi{n}", nx.complete_graph(n, create_using=nx.DiGraph)))
    for n in (3, 4, 5, 7, 8):
        F.append((f"C{n}", nx.cycle_graph(n)))
        F.append((f"Cdi{n}", nx.cycle_graph(n, create_using=nx.DiGraph)))
    for n in (2, 3, 5, 8):
        F.append((f"P{n}", nx.path_graph(n)))
        F.append((f"Pdi{n}", nx.path_graph(n, create_using=nx.DiGraph)))
    for k in (2, 4, 7):
        F.append((f"star{k + 1}", nx.star_graph(k)))
        out_star = nx.DiGraph([(0, i) for i in range(1, k + 1)])
        F.append((f"outstar{k + 1}", out_star))
        F.append((f"instar{k + 1}", out_star.reverse()))
    for n in (4, 5, 6, 8):
        F.append((f"wheel{n}", nx.wheel_graph(n)))
    F.append(("2xK3", _two_components(nx.complete_graph(3), nx.complete_graph(3))))
    F.append(("K3+K4", _two_components(nx.complete_graph(3), nx.complete_graph(4))))
    F.append(("K5+isolated", _two_components(nx.complete_graph(5), nx.empty_graph(1))))
    F.append(("C4di+C4di", _two_components(nx.cycle_graph(4, nx.DiGraph),
                                           nx.cycle_graph(4, nx.DiGraph))))
    for m, b in ((2, 1), (3, 1), (3, 2), (4, 0), (4, 2), (4, 3)):
        F.append((f"two_cliques{m},{b}", two_cliques(m, b, seed=m * 10 + b)))
    for n, k in ((7, 2), (8, 3), (8, 2)):
        F.append((f"circ{n},{k}", circulant(n, k)))
        F.append((f"dcirc{n},{k}", circulant(n, k, directed=True)))
    for seed in range(12):
        n = 3 + seed % 6
        F.append((f"gnp{n}-{seed}", nx.gnp_random_graph(n, 0.2 + 0.06 * seed, directed=True,
                                                        seed=seed)))
    # non-integer labels
    F.append(("wheel6-str", _relabel(nx.wheel_graph(6), "str")))
    F.append(("gnp7-tuple", _relabel(nx.gnp_random_graph(7, 0.5, directed=True, seed=3), "tuple")))
    F.append(("Cdi6-mixed", _relabel(nx.cycle_graph(6, nx.DiGraph), "mixed")))
    F.append(("2xK3-str", _relabel(_two_components(nx.complete_graph(3), nx.complete_graph(3)),
                                   "str")))
    return F


FAMILIES = _families()


@pytest.mark.parametrize("G", [g for _, g in FAMILIES], ids=[i for i, _ in FAMILIES])
def test_family_against_oracle(G):
    full_check(G)


@pytest.mark.parametrize("name", ["C5", "wheel6-str", "gnp7-tuple", "two_cliques4,2", "dcirc8,3",
                                  "Pdi5", "K3+K4", "outstar5"])
def test_family_grid_every_method(name):
    """is_rs_robust and max_s over the whole (r, s) grid with every forced method."""
    G = dict(FAMILIES)[name]
    full_check(G, methods=(), grid_methods=METHODS)


def test_self_loops_and_multigraph_ignored():
    base = nx.gnp_random_graph(6, 0.45, directed=True, seed=11)
    o = oracle(base)
    loops = base.copy()
    loops.add_edges_from((v, v) for v in loops)
    multi = nx.MultiDiGraph(base)
    multi.add_edges_from(list(base.edges()))  # every edge twice
    multi.add_edges_from((v, v) for v in list(base)[:3])
    for H in (loops, multi):
        rep = rescon.robustness(H)
        assert (rep.r_max, rep.s_max) == (o.rho, o.s_star_of(o.rho))
        cert = rep.certificate
        assert len(cert["graph"]["edges"]) == base.number_of_edges()
        assert all(u != v for u, v in cert["graph"]["edges"])
        check_valid(cert, H)
    # undirected multigraph with loops: same as the simple graph
    und = nx.MultiGraph(nx.cycle_graph(6))
    und.add_edges_from([(0, 1), (2, 2), (3, 4)])
    assert rescon.robustness(und).r_max == rescon.robustness(nx.cycle_graph(6)).r_max == 1
    assert rescon.robustness(und).s_max == oracle(nx.cycle_graph(6)).s_star_of(1)


def test_direction_convention():
    """Edge (u, v): v receives u. An out-star is 1-robust, an in-star is not."""
    out_star = nx.DiGraph([("c", leaf) for leaf in "abcd" if leaf != "c"] + [("c", "e")])
    in_star = out_star.reverse()
    assert rescon.robustness(out_star).r_max == 1
    rep = rescon.robustness(in_star)
    assert rep.r_max == 0
    S1, S2 = rep.witness
    assert pair_violates(in_star, S1, S2, 1, 1)
    assert (S1 | S2) <= set("abde")  # two leaves: each has no in-neighbour
    assert rescon.is_r_robust(out_star, 1).holds is True
    assert rescon.is_r_robust(in_star, 1).holds is False


def test_undirected_option_on_digraph():
    D = nx.path_graph(6, create_using=nx.DiGraph)
    assert rescon.robustness(D).r_max == 1
    rep = rescon.robustness(D, undirected=True)
    o = oracle(nx.path_graph(6))
    assert (rep.r_max, rep.s_max) == (o.rho, o.s_star_of(o.rho))
    check_valid(rep.certificate, nx.path_graph(6))


def test_reports_are_frozen_and_input_untouched():
    import dataclasses

    G = two_cliques(4, 2, seed=1)
    before = (list(G.nodes(data=True)), sorted(G.edges()), dict(G.graph))
    rep = rescon.robustness(G)
    res = rescon.is_rs_robust(G, 1, 2)
    assert (list(G.nodes(data=True)), sorted(G.edges()), dict(G.graph)) == before
    with pytest.raises(dataclasses.FrozenInstanceError):
        rep.r_max = 7
    with pytest.raises(dataclasses.FrozenInstanceError):
        res.holds = False
    again = rescon.robustness(G)
    assert (again.r_max, again.s_max, again.exact) == (rep.r_max, rep.s_max, rep.exact)


def test_progress_bar_option(capsys):
    G = circulant(10, 3, directed=True)
    rep = rescon.robustness(G, progress=True)
    assert (rep.r_max, rep.exact) == (2, True)
    rep = rescon.robustness(G, progress=False)
    assert rep.r_max == 2
    capsys.readouterr()


def test_two_node_graphs():
    K2 = nx.complete_graph(2)
    rep = rescon.robustness(K2)
    assert (rep.r_max, rep.s_max, rep.witness) == (1, 2, None)
    check_valid(rep.certificate, K2, fully_checked=True)
    one_way = nx.DiGraph([(0, 1)])  # 0 -> 1 only: one source component
    rep = rescon.robustness(one_way)
    assert (rep.r_max, rep.s_max) == (1, 2)
    E2 = nx.empty_graph(2)
    rep = rescon.robustness(E2)
    assert (rep.r_max, rep.s_max) == (0, 2)
    assert rep.witness is not None and pair_violates(E2, *rep.witness, 1, 1)
    assert rep.certificate["lower"] == {"method": "trivial"}
    check_valid(rep.certificate, E2, fully_checked=True)


# --------------------------------------------------------------------------- #
# hypothesis: arbitrary small digraphs
# --------------------------------------------------------------------------- #

LABELINGS = ("int", "shuffled-int", "str", "tuple")


@st.composite
def graphs(draw, min_n: int = 2, max_n: int = 7):
    """Arbitrary graphs: directed / undirected / multi, with self-loops, sparse or
    dense, with integer, shuffled-integer, string or tuple node labels."""
    n = draw(st.integers(min_n, max_n))
    kind = draw(st.sampled_from(("di", "di", "multidi", "undirected", "multi")))
    mode = draw(st.sampled_from(("sparse", "dense")))
    pairs = draw(st.lists(st.tuples(st.integers(0, n - 1), st.integers(0, n - 1)),
                          max_size=2 * n * n))
    if mode == "dense":
        pairs = sorted({(u, v) for u in range(n) for v in range(n)} - set(pairs))
    labeling = draw(st.sampled_from(LABELINGS))
    if labeling == "int":
        label = list(range(n))
    elif labeling == "shuffled-int":
        label = draw(st.permutations([7 * i + 3 for i in range(n)]))
    elif labeling == "str":
        label = [f"v{i}" for i in range(n)]
    else:
        label = [(i, "t") for i in range(n)]
    cls = {"di": nx.DiGraph, "multidi": nx.MultiDiGraph, "undirected": nx.Graph,
           "multi": nx.MultiGraph}[kind]
    G = cls()
    G.add_nodes_from(draw(st.permutations(label)))  # node order differs from index order
    G.add_edges_from((label[u], label[v]) for u, v in pairs)
    if kind.startswith("multi") and pairs:
        G.add_edges_from((label[u], label[v]) for u, v in pairs[: len(pairs) // 2])
    return G


HYP = settings(max_examples=150, deadline=None,
               suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@HYP
@given(graphs())
def test_random_graphs_against_oracle(G):
    full_check(G)


@HYP
@given(graphs(), st.data())
def test_random_graphs_forced_methods(G, data):
    o = oracle(G)
    n = o.n
    method = data.draw(st.sampled_from(("search", "milp", "dp")))
    r = data.draw(st.integers(0, half(n) + 1))
    s = data.draw(st.integers(1, n))
    clear_cache()  # the forced method computes the answer itself
    check_rs(G, rescon.is_rs_robust(G, r, s, method=method), r, s, o.holds(r, s))
    assert rescon.max_s(G, r, method=method) == o.s_star_of(r)


@HYP
@given(graphs(min_n=2, max_n=6), st.data())
def test_checker_never_accepts_a_false_claim(G, data):
    """Soundness: put the certificate of G on another graph H with the same n; if the
    checker accepts it, the claim must be true for H (per the oracle)."""
    n = G.number_of_nodes()
    H = data.draw(graphs(min_n=n, max_n=n))
    nodes, masks = in_masks(H)
    edges = sorted([j, i] for i, mk in enumerate(masks) for j in range(n) if mk >> j & 1)
    graph_json = {"n": n, "edges": edges}
    oh = oracle(H)
    rep = rescon.robustness(G)
    cert = copy.deepcopy(rep.certificate)
    cert["graph"] = graph_json
    if rescon.check_certificate(cert).valid:
        assert (oh.rho, oh.s_star_of(oh.rho)) == (rep.r_max, rep.s_max)
    r = data.draw(st.integers(0, half(n) + 1))
    s = data.draw(st.integers(1, n))
    res = rescon.is_rs_robust(G, r, s)
    cert = copy.deepcopy(res.certificate)
    cert["graph"] = graph_json
    if rescon.check_certificate(cert).valid:
        assert oh.holds(r, s) is res.holds


# --------------------------------------------------------------------------- #
# tampered certificates
# --------------------------------------------------------------------------- #


def _checker_ok(cert) -> bool:
    return rescon.check_certificate(cert).valid


def test_tamper_flip_witness_node():
    """Move each node into / out of S1 of a witness: the checker's verdict must be
    exactly the oracle's (violating pair or not), and some flips must break it."""
    G = nx.gnp_random_graph(8, 0.45, directed=True, seed=5)
    o = oracle(G)
    res = rescon.is_r_robust(G, o.rho + 1)
    assert res.holds is False
    base = res.certificate
    assert _checker_ok(base)
    broke = 0
    for v in range(8):
        cert = copy.deepcopy(base)
        S1, S2 = set(cert["witness"]["S1"]), set(cert["witness"]["S2"])
        if v in S1:
            S1.discard(v)
        else:
            S1.add(v)
            S2.discard(v)
        cert["witness"] = {"S1": sorted(S1), "S2": sorted(S2)}
        m1 = sum(1 << i for i in S1)
        m2 = sum(1 << i for i in S2)
        expected = o.violates(m1, m2, o.rho + 1, 1)
        assert _checker_ok(cert) is expected, (v, S1, S2)
        broke += not expected
    assert broke > 0
    # same in a robustness certificate's upper_r and upper_s
    rep = rescon.robustness(G)
    for key in ("upper_r", "upper_s"):
        if rep.certificate[key] is None or rep.certificate[key]["method"] != "witness":
            continue
        r, s = (o.rho + 1, 1) if key == "upper_r" else (o.rho, rep.s_max + 1)
        for v in range(8):
            cert = copy.deepcopy(rep.certificate)
            S1, S2 = set(cert[key]["S1"]), set(cert[key]["S2"])
            if v in S1:
                S1.discard(v)
            else:
                S1.add(v)
                S2.discard(v)
            cert[key].update(S1=sorted(S1), S2=sorted(S2))
            expected = o.violates(sum(1 << i for i in S1), sum(1 << i for i in S2), r, s)
            assert _checker_ok(cert) is expected, (key, v)
    # overlapping / empty sets are never accepted
    cert = copy.deepcopy(base)
    cert["witness"]["S2"] = cert["witness"]["S2"] + cert["witness"]["S1"][:1]
    assert not _checker_ok(cert)
    cert = copy.deepcopy(base)
    cert["witness"]["S1"] = []
    assert not _checker_ok(cert)


@pytest.mark.parametrize("G", [nx.wheel_graph(7),
                               nx.gnp_random_graph(8, 0.5, directed=True, seed=2),
                               circulant(8, 3, directed=True), nx.complete_graph(6),
                               nx.cycle_graph(7, create_using=nx.DiGraph)],
                         ids=["wheel7", "gnp8", "dcirc8,3", "K6", "Cdi7"])
def test_tamper_r_max_and_s_max(G):
    rep = rescon.robustness(G)
    n = G.number_of_nodes()
    assert _checker_ok(rep.certificate)
    for dr in (-1, 1):
        cert = copy.deepcopy(rep.certificate)
        cert["r_max"] += dr
        if cert["r_max"] >= 0:
            assert not _checker_ok(cert), dr
    for ds in (-1, 1):
        cert = copy.deepcopy(rep.certificate)
        cert["s_max"] += ds
        if 1 <= cert["s_max"] <= n:
            assert not _checker_ok(cert), ds
    cert = copy.deepcopy(rep.certificate)
    cert["exact"] = "true"
    assert not _checker_ok(cert)


def test_tamper_construction_seed():
    G = directed_growth(30, 3, seed=4)
    rep = rescon.robustness(G)
    assert rep.r_max == 3 and rep.lower_proof == "construction"
    lower = rep.certificate["lower"]
    assert lower["seed_size"] >= 5
    assert _checker_ok(rep.certificate)
    dropped = copy.deepcopy(rep.certificate)
    del dropped["lower"]["seed_proof"]
    assert not _checker_ok(dropped)
    trivial_seed = copy.deepcopy(rep.certificate)
    trivial_seed["lower"]["seed_proof"] = {"method": "trivial"}
    assert not _checker_ok(trivial_seed)
    tiny = copy.deepcopy(rep.certificate)
    tiny["lower"]["seed_size"] = 1
    tiny["lower"]["seed_proof"] = {"method": "trivial"}
    assert not _checker_ok(tiny)
    swapped = copy.deepcopy(rep.certificate)
    order = swapped["lower"]["order"]
    order[-1], order[0] = order[0], order[-1]  # the last node (in-degree 3) into the seed
    assert not _checker_ok(swapped)


def test_tamper_search_tree():
    G = circulant(10, 3, directed=True)  # rho = 2, proven by the search
    assert fast_oracle(G)[0] == 2
    rep = rescon.robustness(G)
    assert rep.r_max == 2 and rep.certificate["lower"]["method"] == "search"
    base = {"rescon_certificate": 1, "kind": "rs_robust", "graph": rep.certificate["graph"],
            "r": 2, "s": 1, "proof": rep.certificate["lower"]}
    assert _checker_ok(base)
    tree = base["proof"]["tree"]
    order = base["proof"]["order"]
    assert len(tree) >= 10

    def with_tree(t):
        cert = copy.deepcopy(base)
        cert["proof"]["tree"] = t
        return cert

    assert not _checker_ok(with_tree(tree[:-1]))  # ends early
    assert not _checker_ok(with_tree(tree + [-1]))  # unused token
    assert not _checker_ok(with_tree([order[0]] + tree[1:]))  # branch on a node in S
    assert not _checker_ok(with_tree([10] + tree[1:]))  # out of range
    assert not _checker_ok(with_tree([-4] + tree[1:]))
    assert not _checker_ok(with_tree([True] + tree[1:]))
    assert not _checker_ok(with_tree([float(t) for t in tree]))
    bad_order = copy.deepcopy(base)
    bad_order["proof"]["order"] = order[:-1] + [order[0]]
    assert not _checker_ok(bad_order)
    # the same tree may never prove a false claim (G is not 3-robust)
    assert not _checker_ok(dict(copy.deepcopy(base), r=3))
    # any single-token corruption that the checker still accepts is harmless only
    # because the claim (2-robust) is true; claiming 3 must fail for every corruption
    for pos in range(0, len(tree), max(1, len(tree) // 15)):
        for tok in (-1, -2, -3):
            t = list(tree)
            t[pos] = tok
            assert not _checker_ok(dict(with_tree(t), r=3))


def test_tamper_graph_edges():
    # complete proof: remove one edge
    rep = rescon.robustness(nx.complete_graph(6))
    cert = copy.deepcopy(rep.certificate)
    assert cert["lower"]["method"] in ("complete", "degree")
    cert["graph"]["edges"].remove([0, 1])
    assert not _checker_ok(cert)
    # degree / complete proof of (4, 7)-robustness of K7: remove an in-edge of node 0
    G = nx.complete_graph(7)
    res = rescon.is_rs_robust(G, 4, 7)
    assert res.holds is True
    cert = copy.deepcopy(res.certificate)
    cert["graph"]["edges"] = [e for e in cert["graph"]["edges"] if e != [1, 0]]
    assert not _checker_ok(cert)
    # search proof: delete edges until the graph is no longer 2-robust
    G = circulant(10, 3, directed=True)
    rep = rescon.robustness(G)
    base = {"rescon_certificate": 1, "kind": "rs_robust", "graph": rep.certificate["graph"],
            "r": 2, "s": 1, "proof": rep.certificate["lower"]}
    assert _checker_ok(base)
    cert = copy.deepcopy(base)
    H = G.copy()
    for i in range(10):
        H.remove_edge((i - 1) % 10, i)
        cert["graph"]["edges"].remove([(i - 1) % 10, i])
        if fast_oracle(H)[0] < 2:
            break
    assert fast_oracle(H)[0] < 2
    assert not _checker_ok(cert)
    # robustness certificate: remove each directed edge of the certificate graph in
    # turn; whenever (rho, s*) of the new graph differs from the claim, it is rejected
    for G in (nx.wheel_graph(7), nx.gnp_random_graph(7, 0.6, directed=True, seed=8)):
        rep = rescon.robustness(G)
        changed = 0
        for e in rep.certificate["graph"]["edges"]:
            cert = copy.deepcopy(rep.certificate)
            cert["graph"]["edges"].remove(e)
            H = nx.DiGraph(cert["graph"]["edges"])
            H.add_nodes_from(range(cert["graph"]["n"]))
            o = oracle(H)
            if (o.rho, o.s_star_of(o.rho)) != (rep.r_max, rep.s_max):
                changed += 1
                assert not _checker_ok(cert), e
        assert changed > 0


def test_tamper_misc():
    rep = rescon.robustness(nx.cycle_graph(6, create_using=nx.DiGraph))
    for key in ("lower", "upper_r", "graph", "r_max"):
        cert = copy.deepcopy(rep.certificate)
        del cert[key]
        assert not _checker_ok(cert), key
    cert = copy.deepcopy(rep.certificate)
    cert["extra"] = 1
    assert not _checker_ok(cert)
    cert = copy.deepcopy(rep.certificate)
    cert["r_max"] = True
    assert not _checker_ok(cert)
    cert = copy.deepcopy(rep.certificate)
    cert["upper_r"] = {"method": "half"}  # rho = 1 < ceil(6/2)
    assert not _checker_ok(cert)
    cert = copy.deepcopy(rep.certificate)
    cert["lower"] = {"method": "milp", "solver": "highs"}  # small n: re-verified, not trusted
    res = rescon.check_certificate(cert)
    assert res.valid and res.trusted == ()
    cert["r_max"] = 2
    assert not _checker_ok(cert)  # upper_r witness does not violate 3


# --------------------------------------------------------------------------- #
# closed forms at larger n
# --------------------------------------------------------------------------- #


def _lower_untrusted(rep, G) -> None:
    """The r_max proof alone (as an rs_robust certificate) needs no trusted method."""
    cert = {"rescon_certificate": 1, "kind": "rs_robust", "graph": rep.certificate["graph"],
            "r": rep.r_lower, "s": 1, "proof": rep.certificate["lower"]}
    res = rescon.check_certificate(cert)
    assert res.valid and res.trusted == (), (res.reason, res.trusted)


@pytest.mark.parametrize("n", [10, 11, 17, 30, 45, 60])
def test_complete_graphs(n):
    for G in (nx.complete_graph(n), nx.complete_graph(n, create_using=nx.DiGraph)):
        rep = rescon.robustness(G)
        assert (rep.r_max, rep.s_max, rep.exact, rep.witness) == (half(n), n, True, None)
        assert rep.lower_proof in ("complete", "degree")
        res = check_valid(rep.certificate, G, fully_checked=True)
        assert res.valid
        assert rescon.is_r_robust(G, half(n)).holds is True
        assert rescon.is_r_robust(G, half(n) + 1).holds is False
        assert rescon.max_s(G, half(n)) == n


@pytest.mark.parametrize("n,m", [(200, 1), (300, 2), (500, 3), (1000, 4), (1000, 6)])
def test_ba_robust(n, m):
    G = ba_robust(n, m, seed=n + m)
    rep = rescon.robustness(G, time_limit=10)
    assert rep.r_lower == rep.r_upper == m
    if rep.exact:
        assert rep.r_max == m
    assert rep.lower_proof in ("construction", "degree", "complete")
    check_valid(rep.certificate, G)
    _lower_untrusted(rep, G)
    assert pair_violates(G, *rep.witness, m + 1, 1)


@pytest.mark.parametrize("n,k", [(300, 1), (400, 2), (600, 3), (1000, 5)])
def test_directed_growth(n, k):
    G = directed_growth(n, k, seed=k)
    rep = rescon.robustness(G, time_limit=10)
    assert rep.r_lower == rep.r_upper == k
    assert rep.lower_proof in ("construction", "degree", "complete")
    check_valid(rep.certificate, G)
    _lower_untrusted(rep, G)
    assert pair_violates(G, *rep.witness, k + 1, 1)


@pytest.mark.parametrize("n,k", [(10, 2), (12, 3), (14, 4), (16, 3), (20, 3), (30, 4),
                                 (40, 5), (64, 6), (100, 3), (200, 4)])
def test_undirected_circulant(n, k):
    """rho = k for n >= 2k + 2. s* may stay unsettled under the time limit: then the
    report must still be exact about rho (r_lower == r_upper == k) with exact=False."""
    G = circulant(n, k)
    rep = rescon.robustness(G, time_limit=0.5)
    assert rep.r_lower == rep.r_upper == k
    check_valid(rep.certificate, G)
    _lower_untrusted(rep, G)
    if rep.exact:
        assert rep.r_max == k
        if n <= 16:
            rho, ss = fast_oracle(G, rs=[k])
            assert rho == k and rep.s_max == ss[k]
    else:
        assert rep.s_max is None and rep.certificate["exact"] is False
        _check_s_bounds(rep, G, k)


def _check_s_bounds(rep, G, r):
    """rho settled, s* not: proven bounds s_lower <= s*(r) <= s_upper, in the report and
    in the certificate, the cheapest pair found as s_witness."""
    n = G.number_of_nodes()
    c = rep.certificate
    assert 1 <= rep.s_lower <= rep.s_upper <= n
    assert (c["s_lower"], c["s_upper"]) == (rep.s_lower, rep.s_upper)
    if rep.s_upper < n:
        assert pair_violates(G, *rep.s_witness, r, rep.s_upper + 1)
    else:
        assert rep.s_witness is None
    assert (c["lower_s"] is None) == (rep.s_lower == 1)


def test_s_bounds_when_only_s_star_times_out():
    """circulant(64, 6): rho = 6 by construction, s*(6) not settled in 0.3 s."""
    G = circulant(64, 6)
    rep = rescon.robustness(G, time_limit=0.3)
    assert rep.r_lower == rep.r_upper == 6 and not rep.exact
    _check_s_bounds(rep, G, 6)
    res = check_valid(rep.certificate, G)
    assert "<= s*(6) <=" in res.reason
    jsonschema = pytest.importorskip("jsonschema")
    from pathlib import Path

    schema = json.loads((Path(__file__).parent.parent / "certificates" / "schema"
                         / "certificate.schema.json").read_text())
    validator = jsonschema.Draft202012Validator(schema)
    validator.validate(rep.certificate)
    partial = {k: v for k, v in rep.certificate.items() if k != "upper_s"}
    assert not validator.is_valid(partial)
    cert = rep.certificate
    # s_upper one below what the witness pair shows: rejected
    bad = copy.deepcopy(cert)
    bad["s_upper"] -= 1
    assert not _checker_ok(bad)
    # s_lower above what its proof proves
    bad = copy.deepcopy(cert)
    bad["s_lower"] = bad["s_upper"]
    assert not _checker_ok(bad)
    bad = copy.deepcopy(cert)
    bad["s_lower"], bad["s_upper"] = bad["s_upper"], bad["s_lower"]
    assert not _checker_ok(bad)
    # all four keys or none
    for key in ("s_lower", "s_upper", "lower_s", "upper_s"):
        bad = copy.deepcopy(cert)
        del bad[key]
        assert not _checker_ok(bad)
    # s bounds need rho settled
    bad = copy.deepcopy(cert)
    bad["r_lower"] -= 1
    bad["lower"] = {"method": "implied", "r": 6, "s": 1, "proof": cert["lower"]}
    assert not _checker_ok(bad)
    trimmed = {k: v for k, v in cert.items() if k not in ("s_lower", "s_upper", "lower_s",
                                                             "upper_s")}
    assert _checker_ok(trimmed)


def _dcirc_rho(n, k):
    return (k + 1) // 2 if k % 2 else k // 2 + n % 2


@pytest.mark.parametrize("n,k", [(9, 2), (10, 2), (10, 3), (11, 4), (12, 4), (13, 6), (15, 4),
                                 (16, 4), (16, 5), (17, 5), (20, 6), (31, 2), (31, 3), (35, 4),
                                 (40, 2), (40, 4), (39, 5), (40, 6)])
def test_directed_circulant(n, k):
    G = circulant(n, k, directed=True)
    rho = _dcirc_rho(n, k)
    rep = rescon.robustness(G, time_limit=0.5)
    assert rep.r_lower <= rho <= rep.r_upper
    assert rep.r_lower == rep.r_upper == rho, "rho not settled within the time limit"
    check_valid(rep.certificate, G)
    if rep.lower_proof in ("construction", "degree", "complete", "search"):
        _lower_untrusted(rep, G)
    if rep.exact and n <= 16:
        r2, ss = fast_oracle(G, rs=[rho])
        assert r2 == rho and rep.s_max == ss[rho]


@pytest.mark.parametrize("m,b", [(3, 1), (5, 2), (6, 0), (8, 3), (10, 4), (6, 6), (12, 7),
                                 (15, 3), (20, 5)])
def test_two_cliques(m, b):
    G = two_cliques(m, b, seed=m * b + 1)
    rep = rescon.robustness(G, time_limit=5)
    assert rep.r_lower == rep.r_upper == b
    check_valid(rep.certificate, G)
    if rep.lower_proof in ("construction", "degree", "complete"):
        _lower_untrusted(rep, G)
    if 2 * m <= 16 and rep.exact:
        rho, ss = fast_oracle(G, rs=[b])
        assert rho == b and rep.s_max == ss[b]


def test_paper_example_graph():
    from pathlib import Path

    from rescon.io import read_graph

    G = read_graph(Path(__file__).parent.parent / "examples" / "graphs" / "paper_example.edgelist")
    rho, ss = fast_oracle(G, rs=[5, 6])
    assert rho == 5
    rep = rescon.robustness(G)
    assert (rep.r_max, rep.s_max) == (5, ss[5])
    check_valid(rep.certificate, G, fully_checked=True)
    assert pair_violates(G, *rep.witness, 6, 1)
    assert rescon.is_r_robust(G, 7).holds is False  # the paper's claim does not hold


# --------------------------------------------------------------------------- #
# time limit
# --------------------------------------------------------------------------- #


def test_time_limit_dense_random_digraph():
    G = nx.gnp_random_graph(40, 0.5, directed=True, seed=1)
    rescon.robustness(nx.cycle_graph(5))  # warm the numba cache outside the timing
    clear_cache()  # cold: facts other tests proved about G would shorten the search
    t0 = time.perf_counter()
    rep = rescon.robustness(G, time_limit=1.0)
    elapsed = time.perf_counter() - t0
    assert elapsed < 3.5, elapsed
    assert rep.r_lower <= rep.r_upper
    # a big search tree: ~3 s to replay. Valid when the limit stopped the search (ρ in
    # [2, 10] here); where the search settled ρ (a faster machine, or facts cached) its
    # proof at n = 40 > 20 is accepted on trust: "unchecked", never "invalid"
    res = check_valid(rep.certificate, G, roundtrip=False)
    assert res.valid or (rep.r_lower == rep.r_upper and res.trusted == ("search",)), res
    if rep.exact:
        assert rep.r_lower == rep.r_upper == rep.r_max
        assert rep.certificate["exact"] is True
    else:
        assert rep.certificate["exact"] is False
        assert (rep.certificate["r_lower"], rep.certificate["r_upper"]) == (rep.r_lower,
                                                                             rep.r_upper)
        assert rep.r_max == (rep.r_lower if rep.r_lower == rep.r_upper else None)
        assert "r_max" not in rep.certificate and "s_max" not in rep.certificate
    # witness (if any) shows "not (r_upper + 1)-robust"
    if rep.witness is not None:
        assert pair_violates(G, *rep.witness, rep.r_upper + 1, 1)
    else:
        assert rep.r_upper == half(40)
    # the bounds are true: min in-degree >= rho for rho >= 2
    assert rep.r_upper <= min(d for _, d in G.in_degree())


def test_time_limit_decision_and_max_s():
    G = nx.gnp_random_graph(40, 0.5, directed=True, seed=1)
    for r in (2, 11, 25):
        res = rescon.is_r_robust(G, r, time_limit=0.5)
        if res.holds is None:
            assert res.certificate is None and res.witness is None
        else:
            check_valid(res.certificate, G)
            if res.holds is False:
                assert pair_violates(G, *res.witness, r, 1)
    assert rescon.is_r_robust(G, 2, time_limit=0.5).holds is True  # min in-degree bound
    assert rescon.is_r_robust(G, 21, time_limit=0.5).holds is False  # > ceil(n/2)
    assert rescon.max_s(G, 21, time_limit=0.5) == 0


def test_time_limit_is_honoured_for_tiny_limits():
    G = nx.gnp_random_graph(50, 0.5, directed=True, seed=1)
    rescon.robustness(nx.cycle_graph(5))
    t0 = time.perf_counter()
    rep = rescon.robustness(G, time_limit=0.05)
    elapsed = time.perf_counter() - t0
    assert rep.r_lower <= rep.r_upper
    assert elapsed < 1.5, f"time_limit=0.05 but robustness() took {elapsed:.2f} s"


# --------------------------------------------------------------------------- #
# bad input
# --------------------------------------------------------------------------- #

G5 = nx.cycle_graph(5)


def test_input_error_is_value_error():
    assert issubclass(rescon.InputError, ValueError)


@pytest.mark.parametrize("G", [nx.Graph(), nx.DiGraph(), nx.empty_graph(1),
                               nx.DiGraph([(0, 0)])], ids=["empty", "empty-di", "one", "loop"])
def test_too_few_nodes(G):
    for call in (lambda: rescon.robustness(G), lambda: rescon.is_r_robust(G, 1),
                 lambda: rescon.is_rs_robust(G, 1, 1), lambda: rescon.max_s(G, 1)):
        with pytest.raises(rescon.InputError, match=r"\bG\b.*nodes"):
            call()


@pytest.mark.parametrize("bad", [[(0, 1), (1, 0)], np.ones((3, 3)), None, "graph", {0: [1]}],
                         ids=["edges", "array", "None", "str", "dict"])
def test_not_a_networkx_graph(bad):
    for call in (lambda: rescon.robustness(bad), lambda: rescon.is_r_robust(bad, 1),
                 lambda: rescon.is_rs_robust(bad, 1, 1), lambda: rescon.max_s(bad, 1)):
        with pytest.raises(rescon.InputError, match=r"\bG\b.*networkx"):
            call()


@pytest.mark.parametrize("r", [-1, -5, 1.5, 2.0, "2", True, False, None, np.float64(1.0)])
def test_bad_r(r):
    with pytest.raises(rescon.InputError, match=r"^r must"):
        rescon.is_r_robust(G5, r)
    with pytest.raises(rescon.InputError, match=r"^r must"):
        rescon.is_rs_robust(G5, r, 1)
    with pytest.raises(rescon.InputError, match=r"^r must"):
        rescon.max_s(G5, r)


def test_numpy_integer_r_accepted():
    assert rescon.is_r_robust(G5, np.int64(1)).holds is True
    assert rescon.is_rs_robust(G5, np.int32(1), np.int64(2)).holds is True
    assert rescon.max_s(G5, np.int64(1)) == oracle(G5).s_star_of(1)


@pytest.mark.parametrize("s", [0, -1, 6, 100, 1.0, "1", True, None])
def test_bad_s(s):
    with pytest.raises(rescon.InputError, match=r"^s must"):
        rescon.is_rs_robust(G5, 1, s)


@pytest.mark.parametrize("method", ["foo", "AUTO", "", None, "exhaustive"])
def test_unknown_method(method):
    for call in (lambda: rescon.robustness(G5, method=method),
                 lambda: rescon.is_r_robust(G5, 1, method=method),
                 lambda: rescon.is_rs_robust(G5, 1, 1, method=method),
                 lambda: rescon.max_s(G5, 1, method=method)):
        with pytest.raises(rescon.InputError, match=r"^method"):
            call()


@pytest.mark.parametrize("tl", [0, 0.0, -1, -0.5, float("nan"), float("inf"), -float("inf"),
                                True, "1"])
def test_bad_time_limit(tl):
    for call in (lambda: rescon.robustness(G5, time_limit=tl),
                 lambda: rescon.is_r_robust(G5, 1, time_limit=tl),
                 lambda: rescon.is_rs_robust(G5, 1, 1, time_limit=tl),
                 lambda: rescon.max_s(G5, 1, time_limit=tl)):
        with pytest.raises(rescon.InputError, match=r"^time_limit"):
            call()


def test_large_r_is_not_an_error():
    for r in (3, 4, 10, 10**6):
        res = rescon.is_r_robust(G5, r)
        assert res.holds is False
        check_valid(res.certificate, G5)
        assert rescon.max_s(G5, r) == 0


def test_dp_size_limit_is_input_error():
    """method='dp' is exponential in memory; a large graph must be refused cleanly
    (when an exact step is needed at all)."""
    G = nx.gnp_random_graph(40, 0.3, directed=True, seed=3)
    try:
        rep = rescon.robustness(G, method="dp", time_limit=2)
    except rescon.InputError as exc:
        assert "dp" in str(exc)
    else:
        check_valid(rep.certificate, G)


# --------------------------------------------------------------------------- #
# exact decisions at n = 12..16: dp, search and milp agree with each other and
# with an independent vectorised oracle; the exact engines are checked directly too
# --------------------------------------------------------------------------- #

# (n, p, seed) of gnp_random_graph(n, p, directed=True, seed=seed); chosen so that the
# bounds alone do not settle rho and s* (an exact method has to run)
REGRESSION = [(14, 0.45, 1), (16, 0.35, 2), (16, 0.3, 3), (12, 0.3, 11), (16, 0.4, 18),
              (13, 0.55, 21), (13, 0.4, 24), (14, 0.35, 25), (12, 0.5, 27), (16, 0.3, 29),
              (12, 0.35, 30), (12, 0.3, 34), (12, 0.4, 35), (12, 0.5, 37), (13, 0.45, 38),
              (14, 0.55, 40), (14, 0.5, 43), (15, 0.3, 44), (12, 0.4, 48), (13, 0.6, 51)]


@pytest.mark.parametrize("k", range(len(REGRESSION)),
                         ids=[f"n{n}-s{s}" for n, _, s in REGRESSION])
def test_regression_methods_agree(k):
    n, p, seed = REGRESSION[k]
    G = nx.gnp_random_graph(n, p, directed=True, seed=seed)
    rho, ss = fast_oracle(G, rs=None)
    got = {}
    for m in ("dp", "search", "milp", "auto"):
        clear_cache()  # each method computes, none reads another's cached facts
        rep = rescon.robustness(G, method=m)
        check_report(G, rep, rho, ss[rho], m)
        got[m] = (rep.r_max, rep.s_max)
    assert len(set(got.values())) == 1, got
    # the decision around rho and the s*(r) values, every method
    for m in ("dp", "search", "milp"):
        clear_cache()
        assert rescon.is_r_robust(G, rho, method=m).holds is True
        res = rescon.is_r_robust(G, rho + 1, method=m)
        assert res.holds is False and pair_violates(G, *res.witness, rho + 1, 1)
        if m == "dp" or k % 2 == 0:  # robustness() above already computed s*(rho)
            assert rescon.max_s(G, rho, method=m) == ss[rho]
        if rho >= 2 and (m == "dp" or k % 4 == 0):  # the MILP for s*(rho - 1) is slower
            assert rescon.max_s(G, rho - 1, method=m) == ss[rho - 1]


@pytest.mark.parametrize("n,p,seed", REGRESSION[::2], ids=[f"n{n}-s{s}" for n, _, s in
                                                          REGRESSION[::2]])
def test_regression_exact_engines(n, p, seed):
    """The engines behind the methods, without the bounds in front of them."""
    from rescon.graphs.indexed import index_graph
    from rescon.graphs.milp import milp_min_cost
    from rescon.graphs.search import decide_r_robust

    G = nx.gnp_random_graph(n, p, directed=True, seed=seed)
    rho, ss = fast_oracle(G)
    ig = index_graph(G)
    graph_json = ig.graph_json()
    for r in range(1, rho + 2):
        out = decide_r_robust(ig, r)
        assert out.status == ("robust" if r <= rho else "not_robust"), r
        if r <= rho:
            cert = {"rescon_certificate": 1, "kind": "rs_robust", "graph": graph_json,
                    "r": r, "s": 1, "proof": {"method": "search", "order": list(out.order),
                                              "tree": list(out.tree)}}
            res = rescon.check_certificate(cert)
            assert res.valid and res.trusted == (), res.reason
        else:
            S1, S2 = out.witness
            assert pair_violates(G, S1, S2, r, 1)
        dec = milp_min_cost(ig, r, upper=1, decision_only=True)
        assert (dec.status == "infeasible") == (r <= rho), (r, dec.status)
        if r > rho:
            assert pair_violates(G, *dec.pair, r, 1)
    for r in range(1, rho + 1):
        full = milp_min_cost(ig, r, upper=n + 1)
        if ss[r] == n:
            assert full.status == "infeasible"
        else:
            assert full.status == "optimal" and full.cost == ss[r], (r, full, ss[r])
            assert pair_violates(G, *full.pair, r, ss[r] + 1)


def test_search_method_beyond_64_nodes():
    G = nx.gnp_random_graph(66, 0.1, directed=True, seed=2)
    try:
        rep = rescon.robustness(G, method="search", time_limit=5)
    except rescon.InputError as exc:
        assert "search" in str(exc) and "64" in str(exc)
    else:  # or a correct, certified answer
        check_valid(rep.certificate, G)
