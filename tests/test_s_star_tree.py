"""Replayable s* proofs (issue 13 §4): when the proof of (ρ, s*)-robustness would be
taken on trust by the checker (``dp`` or ``milp`` beyond its enumeration, n > 20, or a
``cost_search`` without its tree), the sized search's tree below s* (search.cost_tree)
is attached instead, and the checker replays it."""

from __future__ import annotations

import networkx as nx
import pytest

import rescon
from rescon.errors import RESCONError
from rescon.graphs.facts import clear_cache
from rescon.graphs.indexed import index_graph
from rescon.graphs.robustness import _replayed
from tests.test_rho_tree import _cut_branch


@pytest.fixture(autouse=True)
def _fresh_facts():
    """Each test decides its graphs afresh (facts.py caches proofs across calls)."""
    clear_cache()


def _cert(ig, r, s, proof):
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(),
            "r": r, "s": s, "proof": proof}


def test_dp_s_star_on_21_nodes_is_replayed():
    """ER(21, 0.9), seed 4: auto settles s*(ρ) by the subset DP (n ≤ 22), whose proof
    the checker takes on trust beyond n = 20; the s* tree (1.7k tokens) is attached,
    so the whole certificate is checked, and a tampered tree is rejected."""
    G = nx.gnp_random_graph(21, 0.9, directed=True, seed=4)
    rep = rescon.robustness(G)
    assert rep.exact and "dp" in rep.method
    lower_s = rep.certificate["lower_s"]
    assert lower_s["method"] == "cost_search" and lower_s["info"]["decided_by"] == "dp"
    check = rescon.check_certificate(rep.certificate)
    assert check.verdict == "valid" and check.trusted == () and check.unchecked == ()
    bad = {**rep.certificate, "lower_s": _cut_branch(lower_s)}
    assert rescon.check_certificate(bad).verdict == "invalid"
    # the answer is the DP's: the s* proof is replaced, never the value
    clear_cache()
    assert (rescon.robustness(G, method="dp").s_max, rep.s_max) == (rep.s_max, rep.s_max)


def test_milp_s_star_proof_on_24_nodes_becomes_a_replayed_tree():
    """ER(24, 0.8), seed 24: ρ = 10, s*(10) = 3 (subset DP). A ``milp`` proof of
    (10, 3)-robustness (on trust, n > 20) becomes the tree below s = 3, which the checker
    replays (a tampered one is rejected); a claim of (10, 4) is an internal error."""
    G = nx.gnp_random_graph(24, 0.8, directed=True, seed=24)
    ig = index_graph(G)
    milp = {"method": "milp", "solver": "highs", "info": {"seconds": 1.0}}
    before = rescon.check_certificate(_cert(ig, 10, 3, milp))
    assert before.verdict != "valid" and before.trusted == ("milp",)
    proof = _replayed(ig, 10, 3, milp, None)
    assert proof["method"] == "cost_search" and proof["info"]["decided_by"] == "milp"
    check = rescon.check_certificate(_cert(ig, 10, 3, proof))
    assert check.verdict == "valid" and check.trusted == ()
    assert rescon.check_certificate(_cert(ig, 10, 3, _cut_branch(proof))).verdict == "invalid"
    assert rescon.check_certificate(_cert(ig, 10, 4, proof)).verdict == "invalid"
    with pytest.raises(RESCONError, match=r"internal error: \(10, 4\)"):
        _replayed(ig, 10, 4, milp, None)


def test_checked_proofs_are_kept():
    """Proofs the checker already checks stay as they are: a ``dp`` proof on n ≤ 20
    (re-verified by enumeration), a recorded tree, a construction; and beyond the
    search's node limit nothing is attempted."""
    small = index_graph(nx.gnp_random_graph(20, 0.9, directed=True, seed=4))
    dp = {"method": "dp"}
    assert _replayed(small, 1, 1, dp, None) is dp
    tree = {"method": "cost_search", "order": [0], "tree": [-1]}
    assert _replayed(small, 1, 1, tree, None) is tree
    con = {"method": "construction", "order": list(range(20))}
    assert _replayed(small, 1, 1, con, None) is con
    big = index_graph(nx.complete_graph(70))
    milp = {"method": "milp", "solver": "highs"}
    assert _replayed(big, 35, 1, milp, None) is milp
