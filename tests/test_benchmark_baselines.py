"""The benchmark baselines (benchmarks/baselines.py) are right, and the harness
refuses to report times for wrong answers.

* LeBlanc exhaustive (numba) == Usevitch–Panagou MILP (HiGHS) == a plain-Python
  brute force on small random graphs (n <= 8), for rho and s*(r), r = 0..rho+1;
* closed forms: K_n (rho = ceil(n/2), s* = n), undirected cycles (rho = 1), the
  closed forms claimed by benchmarks/families.py;
* the runner exits non-zero and writes an error row when a candidate disagrees.
"""

from __future__ import annotations

import csv
import itertools
import math
import random
import sys
from pathlib import Path

import networkx as nx
import pytest

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks import baselines as B  # noqa: E402
from benchmarks import families as F  # noqa: E402
from benchmarks import run as R  # noqa: E402

# --------------------------------------------------------------------------- oracle


def _in_sets(G: nx.Graph) -> list[set[int]]:
    """In-neighbour sets, written independently of the baselines' helper."""
    idx = {v: i for i, v in enumerate(G.nodes)}
    ins: list[set[int]] = [set() for _ in G.nodes]
    for u, v in G.edges():
        if u != v:
            ins[idx[v]].add(idx[u])
            if not G.is_directed():
                ins[idx[u]].add(idx[v])
    return ins


def _pairs(n: int):
    """All unordered pairs of disjoint nonempty subsets (label 0: none, 1: S1, 2: S2)."""
    for lab in itertools.product((0, 1, 2), repeat=n):
        S1 = frozenset(i for i in range(n) if lab[i] == 1)
        S2 = frozenset(i for i in range(n) if lab[i] == 2)
        if S1 and S2 and min(S1) < min(S2):
            yield S1, S2


def brute_rho(G: nx.Graph) -> int:
    ins = _in_sets(G)
    n = len(ins)

    def e(S):
        return max(len(ins[i] - S) for i in S)

    return min(max(e(S1), e(S2)) for S1, S2 in _pairs(n))


def brute_max_s(G: nx.Graph, r: int) -> int:
    """Largest s <= n such that every pair satisfies one of the (r, s) conditions."""
    ins = _in_sets(G)
    n = len(ins)

    def X(S):
        return {i for i in S if len(ins[i] - S) >= r}

    best = n
    for S1, S2 in _pairs(n):
        x1, x2 = X(S1), X(S2)
        if len(x1) == len(S1) or len(x2) == len(S2):
            continue
        best = min(best, len(x1) + len(x2))
    return best


def _random_graphs():
    rng = random.Random(20240611)
    out = []
    for k in range(14):
        n = rng.randint(3, 8)
        p = rng.choice([0.3, 0.5, 0.7, 0.9])
        G = nx.gnp_random_graph(n, p, seed=rng.randrange(10**6), directed=k % 2 == 1)
        out.append(G)
    # a self-loop must be ignored
    G = nx.gnp_random_graph(7, 0.6, seed=5, directed=True)
    G.add_edge(3, 3)
    out.append(G)
    return out


RANDOM = _random_graphs()


# --------------------------------------------------------------------------- agreement


def test_pair_enumeration_visits_every_unordered_pair_once():
    for n in range(2, 11):
        assert B._count_pairs(n) == B.n_pairs(n) == (3**n - 2 ** (n + 1) + 1) // 2
    assert sum(1 for _ in _pairs(6)) == B.n_pairs(6)


@pytest.mark.parametrize("G", RANDOM, ids=lambda G: f"{'di' if G.is_directed() else 'un'}"
                         f"{G.number_of_nodes()}m{G.number_of_edges()}")
def test_baselines_agree_with_brute_force(G):
    rho = brute_rho(G)
    assert B.leblanc_rho(G) == rho
    m = B.milp_rho(G, time_limit=60)
    assert m.status == "optimal" and m.value == rho
    n = G.number_of_nodes()
    assert B.leblanc_max_s(G, 0) == n
    for r in range(1, rho + 2):
        s = brute_max_s(G, r)
        assert B.leblanc_max_s(G, r) == s, r
        ms = B.milp_max_s(G, r, time_limit=60)
        assert ms.value == s, (r, ms)
        assert ms.status == ("infeasible" if s == n else "optimal")
    assert B.leblanc_max_s(G, rho + 1) == 0  # not (rho+1)-robust


def test_leblanc_witness_pair_attains_rho():
    G = nx.gnp_random_graph(8, 0.5, seed=3, directed=True)
    rho, S1, S2 = B.leblanc_rho_pair(G)
    ins = _in_sets(G)
    assert S1 and S2 and not (S1 & S2)
    assert max(max(len(ins[i] - S) for i in S) for S in (S1, S2)) == rho


# --------------------------------------------------------------------------- closed forms


@pytest.mark.parametrize("n", range(2, 10))
def test_complete_graph(n):
    G = nx.complete_graph(n)
    rho = math.ceil(n / 2)
    assert B.leblanc_rho(G) == rho
    assert B.leblanc_max_s(G, rho) == n
    assert B.milp_rho(G).value == rho
    res = B.milp_max_s(G, rho)
    assert res.value == n and res.status == "infeasible"


@pytest.mark.parametrize("n", range(4, 11))
def test_undirected_cycle_is_1_robust(n):
    G = nx.cycle_graph(n)
    assert B.leblanc_rho(G) == 1
    assert B.milp_rho(G).value == 1


def test_edge_direction_convention():
    # 0 -> i for all i: every i receives from 0; one source component: rho = 1
    out_star = nx.DiGraph([(0, i) for i in range(1, 6)])
    assert B.leblanc_rho(out_star) == B.milp_rho(out_star).value == 1
    # i -> 0: node 0 receives from all, the others from nobody: several sources, rho = 0
    in_star = nx.DiGraph([(i, 0) for i in range(1, 6)])
    assert B.leblanc_rho(in_star) == B.milp_rho(in_star).value == 0
    assert B.leblanc_max_s(in_star, 1) == 0


def test_family_closed_forms_hold_on_small_sizes():
    checked = 0
    for inst in F.instances(sizes=(7, 10, 13), k=1):
        if inst.known_rho is not None:
            assert B.leblanc_rho(inst.G) == inst.known_rho, (inst.name, inst.params)
            checked += 1
        ks = F.known_s_star(inst)
        if ks is not None:
            assert B.leblanc_max_s(inst.G, B.leblanc_rho(inst.G)) == ks
    assert checked >= 20


def test_families_are_seeded_and_reproducible():
    a = [nx.to_edgelist(i.G) for i in F.instances(["er_directed", "k_in", "ba"], (12,), 2)]
    b = [nx.to_edgelist(i.G) for i in F.instances(["er_directed", "k_in", "ba"], (12,), 2)]
    assert [sorted(x) for x in a] == [sorted(x) for x in b]
    inst = F.make_instance("k_in", {"k": 3}, 12, 4)
    assert inst.params["seed"] == 12004
    assert all(d == 3 for _, d in inst.G.in_degree())


# --------------------------------------------------------------------------- errors and statuses


def test_milp_time_limit_status():
    G = nx.gnp_random_graph(40, 0.8, seed=1)
    res = B.milp_rho(G, time_limit=0.02)
    assert res.status == "time_limit" and res.value is None


def test_input_errors():
    with pytest.raises(ValueError, match="at least 2 nodes"):
        B.leblanc_rho(nx.empty_graph(1))
    with pytest.raises(ValueError, match="max_n"):
        B.leblanc_rho(nx.empty_graph(30))
    with pytest.raises(ValueError, match="r must be an integer >= 1"):
        B.milp_max_s(nx.complete_graph(4), 0)
    with pytest.raises(TypeError, match="networkx"):
        B.leblanc_rho([[0, 1]])


# --------------------------------------------------------------------------- harness


def _run(tmp_path, *extra):
    return R.main(["robustness", "--sizes", "7", "--families", "complete,er,two_cliques",
                   "--instances", "1", "--time-limit", "30", "--out", str(tmp_path), *extra])


def test_harness_runs_and_writes_results(tmp_path):
    assert _run(tmp_path, "--candidate", "leblanc", "--name", "t") == 0
    rows = list(csv.DictReader((tmp_path / "t.csv").read_text().splitlines()))
    assert {r["method"] for r in rows} == {"leblanc(candidate)", "leblanc", "milp"}
    assert all(r["status"] in ("exact", "optimal") for r in rows)
    md = (tmp_path / "t.md").read_text()
    assert "All answers agree" in md and "MILP/cand" in md


def test_harness_flags_a_wrong_candidate(tmp_path, monkeypatch):
    def wrong():
        def wrong(G, time_limit=None):
            return R.Answer(B.leblanc_rho(G) + 1, None, "exact")

        return wrong, "deliberately wrong"

    monkeypatch.setitem(R.CANDIDATES, "wrong", wrong)
    assert _run(tmp_path, "--candidate", "wrong", "--name", "w") == 1
    rows = list(csv.DictReader((tmp_path / "w.csv").read_text().splitlines()))
    errs = [r for r in rows if r["method"] == "check"]
    assert errs and all(r["status"] == "error" and "rho mismatch" in r["detail"] for r in errs)
    assert "Errors" in (tmp_path / "w.md").read_text()


def test_harness_fails_clearly_when_candidate_is_missing(tmp_path, monkeypatch, capsys):
    def missing():
        raise R.CandidateUnavailable("rescon.robustness does not exist (yet)")

    monkeypatch.setitem(R.CANDIDATES, "rescon", missing)
    assert _run(tmp_path) == 2
    assert "rescon.robustness does not exist" in capsys.readouterr().err
    assert not (tmp_path / "robustness.csv").exists()
