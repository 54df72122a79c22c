"""The exact engines on their own: the r-decision branch and bound, the s*(r)
charged-set branch and bound, the DP and the search/MILP races, against the
independent LeBlanc enumeration of benchmarks/baselines.py."""

from __future__ import annotations

import json
from pathlib import Path

import jsonschema
import networkx as nx
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from benchmarks.baselines import leblanc_max_s, leblanc_rho
from rescon.graphs import bounds as bd
from rescon.graphs.facts import clear_cache
from rescon.graphs.indexed import index_graph
from rescon.graphs.search import decide_r_robust, min_cost_pair
from tests.test_robustness import check_valid

SCHEMA = json.loads(
    (Path(__file__).parents[1] / "certificates" / "schema" / "certificate.schema.json").read_text()
)


@st.composite
def digraphs(draw, max_n: int = 9):
    n = draw(st.integers(2, max_n))
    pairs = [(u, v) for u in range(n) for v in range(n) if u != v]
    edges = draw(st.lists(st.sampled_from(pairs), unique=True, max_size=len(pairs)))
    G = nx.DiGraph()
    G.add_nodes_from(range(n))
    G.add_edges_from(edges)
    return G


@settings(max_examples=80, deadline=None)
@given(digraphs())
def test_decision_search_matches_enumeration(G):
    ig = index_graph(G)
    rho = leblanc_rho(G)
    for r in range(1, (ig.n + 1) // 2 + 1):
        out = decide_r_robust(ig, r)
        assert (out.status == "robust") == (r <= rho)
        if out.status == "not_robust":
            pair = bd.Pair(*out.witness)
            assert pair.S1 and pair.S2 and not pair.S1 & pair.S2
            assert bd.violates(ig, pair, r, 1)


@settings(max_examples=80, deadline=None)
@given(digraphs())
def test_cost_search_matches_enumeration(G):
    ig = index_graph(G)
    for r in range(1, (ig.n + 1) // 2 + 2):
        expected = leblanc_max_s(G, r)  # 0 when G is not r-robust
        out = min_cost_pair(ig, r, ig.n)
        assert out.status == "done"
        assert out.best == expected
        if out.pair is not None:
            cost = bd.pair_cost(ig, bd.Pair(*out.pair), r)
            assert cost is not None and cost <= out.best


@pytest.mark.parametrize("seed", range(6))
def test_auto_race_agrees_with_dp_beyond_the_dp_threshold(seed):
    """n = 23..25: auto takes the search/MILP race for s*, dp is forced; same answer."""
    G = nx.gnp_random_graph(23 + seed % 3, 0.25, directed=True, seed=seed)
    auto = rescon.robustness(G)
    clear_cache()  # the DP computes, not reads the race's cached answer
    dp = rescon.robustness(G, method="dp")
    assert (auto.r_max, auto.s_max) == (dp.r_max, dp.s_max)
    check_valid(auto.certificate, G)  # which engine wins the race (tree or milp) may vary


@pytest.mark.parametrize("n, p, seed", [pytest.param(30, 0.5, 30000, marks=pytest.mark.slow),
                                         (25, 0.5, 25000), (22, 0.3, 7)])
def test_produced_certificates_match_the_schema(n, p, seed):
    G = nx.gnp_random_graph(n, p, directed=True, seed=seed)
    rep = rescon.robustness(G)
    jsonschema.validate(rep.certificate, SCHEMA)
    for r in (1, rep.r_max, rep.r_max + 1):
        res = rescon.is_rs_robust(G, r, 2)
        jsonschema.validate(res.certificate, SCHEMA)


def test_search_tree_certificate_is_replayed_not_trusted():
    G = nx.gnp_random_graph(25, 0.5, directed=True, seed=25000)  # ρ = 7, no clique seed
    res = rescon.is_r_robust(G, 7, method="search")
    assert res.holds and res.proof_method in ("search", "construction")
    check = rescon.check_certificate(res.certificate)
    assert check.valid and check.trusted == ()
    tampered = json.loads(json.dumps(res.certificate))
    proof = tampered["proof"]
    tree = proof["tree"] if proof["method"] == "search" else proof["seed_proof"]["tree"]
    leaf = next(k for k, t in enumerate(tree) if t < 0)
    tree[leaf] = -2 if tree[leaf] != -2 else -1
    assert not rescon.check_certificate(tampered).valid


@pytest.mark.slow
def test_race_uses_the_milp_on_dense_graphs_and_says_so():
    """ER(40, 0.8): the MILP proves 17-robustness long before the search; the proof is
    labelled milp and the checker reports it as accepted on trust."""
    G = nx.gnp_random_graph(40, 0.8, directed=True, seed=40000)
    res = rescon.is_r_robust(G, 17, time_limit=60)
    assert res.holds
    if res.proof_method == "milp":
        assert rescon.check_certificate(res.certificate).trusted == ("milp",)


def test_spectral_bound_is_sound_and_checked_exactly():
    """ρ ≥ ⌈λ2/2⌉ on undirected graphs: the bound holds against the exact ρ, the
    checker verifies λ2 > c in exact arithmetic and rejects an inflated c."""
    from rescon.graphs.bounds import spectral_r

    for seed in range(4):
        G = nx.random_regular_graph(4 + 2 * (seed % 2), 14, seed=seed)
        ig = index_graph(G)
        r, proof = spectral_r(ig)
        assert r <= leblanc_rho(G)
        if proof is None:
            continue
        cert = {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(),
                "r": r, "s": 1, "proof": proof}
        jsonschema.validate(cert, SCHEMA)
        assert rescon.check_certificate(cert).valid
        lam2 = sorted(nx.laplacian_spectrum(G))[1]
        bad = json.loads(json.dumps(cert))
        bad["proof"]["c"] = str(int(lam2) + 1)  # above λ2: not positive definite
        bad["r"] = max(r, (int(lam2) + 2) // 2)
        assert not rescon.check_certificate(bad).valid
    directed = nx.gnp_random_graph(12, 0.9, directed=True, seed=1)
    assert spectral_r(index_graph(directed)) == (0, None)


@settings(max_examples=60, deadline=None)
@given(digraphs(), st.data())
def test_root_split_parts_compose_to_the_whole_search(G, data):
    """Both searches split by roots: the parts' trees concatenate to the whole tree, a
    part is "robust" iff no witness starts in its roots, and s*(r) is the parts' least."""
    ig = index_graph(G)
    n = ig.n
    cut = data.draw(st.integers(0, n))
    parts = [range(0, cut), range(cut, n)]
    for r in range(1, (n + 1) // 2 + 2):
        whole = decide_r_robust(ig, r)
        outs = [decide_r_robust(ig, r, roots=p) for p in parts]
        if whole.status == "robust":
            assert all(o.status == "robust" for o in outs)
            assert sum((o.tree for o in outs), ()) == whole.tree
        else:
            assert any(o.status == "not_robust" for o in outs)
        cost = min_cost_pair(ig, r, n)
        assert min(min_cost_pair(ig, r, n, roots=p).best for p in parts) == cost.best


def test_root_range_must_lie_in_the_search_order():
    ig = index_graph(nx.complete_graph(4, create_using=nx.DiGraph))
    with pytest.raises(ValueError, match="consecutive range"):
        decide_r_robust(ig, 1, roots=range(2, 6))
    with pytest.raises(ValueError, match="consecutive range"):
        min_cost_pair(ig, 1, 4, roots=range(0, 4, 2))
