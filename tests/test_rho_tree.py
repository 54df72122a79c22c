"""Replayable ρ proofs on dense graphs (issue 13 §4): when the r-robustness proof
would be a ``search`` without its tree (beyond MAX_TREE_TOKENS) or a ``milp`` (on trust
beyond n = 20), the sized search's tree below s = 1 (search.cost_tree) is attached
instead, and the checker replays it."""

from __future__ import annotations

import json

import networkx as nx
import pytest

import rescon
from rescon.errors import RESCONError
from rescon.graphs import bounds as bd
from rescon.graphs.indexed import index_graph
from rescon.graphs.robustness import _Decision, _replayable

pytestmark = pytest.mark.usefixtures("fresh_facts")


def _cut_branch(proof):
    """A copy of ``proof`` whose first branch token is cut to a leaf."""
    bad = json.loads(json.dumps(proof))
    tree = bad["tree"]
    tree[next(k for k, t in enumerate(tree) if t >= 0)] = -1
    return bad


@pytest.mark.slow
def test_dense_er30_robustness_certificate_is_fully_checked():
    """ER(30, 0.8), seed 30000: ρ = 12 by the decision search, whose tree exceeds
    MAX_TREE_TOKENS; the ρ proof is the s = 1 cost tree, so nothing is on trust; a
    tampered ρ tree is rejected."""
    G = nx.gnp_random_graph(30, 0.8, directed=True, seed=30000)
    rep = rescon.robustness(G, time_limit=60)
    assert rep.exact and (rep.r_max, rep.s_max) == (12, 5)
    lower = rep.certificate["lower"]
    assert lower["method"] == "cost_search" and lower["tree"] and rep.lower_proof == "cost_search"
    check = rescon.check_certificate(rep.certificate)
    assert check.verdict == "valid" and check.trusted == () and check.unchecked == ()
    bad = {**rep.certificate, "lower": _cut_branch(lower)}
    assert rescon.check_certificate(bad).verdict == "invalid"


def test_milp_proof_of_r_robustness_is_replaced_by_a_replayed_tree():
    """ER(30, 0.8), seed 30001: the MILP's proof of ρ = 12 would be taken on trust
    (n > 20); the attached s = 1 tree is replayed."""
    G = nx.gnp_random_graph(30, 0.8, directed=True, seed=30001)
    res = rescon.is_r_robust(G, 12, method="milp")
    assert res.holds and res.proof_method == "cost_search" and res.method == "milp"
    assert res.certificate["proof"]["info"]["decided_by"] == "milp"
    assert rescon.check_certificate(res.certificate).verdict == "valid"


def test_replayable_swaps_only_unreplayed_proofs_and_never_the_answer():
    """ER(22, 0.8), seed 22000, r = ρ: a ``milp`` or tree-less ``search`` proof becomes
    the s = 1 tree, which the checker replays (a tampered one is rejected); a recorded
    search tree and a refutation are kept; a wrong claim of (ρ + 1)-robustness is an
    internal error, not a proof."""
    G = nx.gnp_random_graph(22, 0.8, directed=True, seed=22000)
    ig = index_graph(G)
    rho = rescon.robustness(G, method="dp").r_max  # the subset DP, exact
    cert = {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(),
            "r": rho, "s": 1}
    for proof in ({"method": "milp", "solver": "highs"},
                  {"method": "search", "order": list(range(22)), "tree": None}):
        dec = _replayable(ig, rho, _Decision(True, proof=proof, method="milp"), None)
        assert dec.holds and dec.method == "milp" and dec.proof["method"] == "cost_search"
        assert rescon.check_certificate({**cert, "proof": dec.proof}).verdict == "valid"
        bad = {**cert, "proof": _cut_branch(dec.proof)}
        assert rescon.check_certificate(bad).verdict == "invalid"
    recorded = _Decision(True, proof={"method": "search", "order": [0], "tree": [-1]})
    refuted = _Decision(False, pair=bd.upper_witness(ig)[1], method="milp")
    for dec in (recorded, refuted):
        assert _replayable(ig, rho, dec, None) is dec
    with pytest.raises(RESCONError, match="internal error"):
        _replayable(ig, rho + 1, _Decision(True, proof={"method": "milp"}), None)


def test_recorded_search_trees_are_kept():
    """A sparse graph whose decision-search tree is recorded keeps that proof."""
    G = nx.gnp_random_graph(30, 0.3, directed=True, seed=30001)
    res = rescon.is_r_robust(G, 4)
    assert res.proof_method == "search" and res.certificate["proof"]["tree"]
    assert rescon.check_certificate(res.certificate).verdict == "valid"
