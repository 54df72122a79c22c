"""R10: robustness time limits and cached proofs (fixes for the V33 review).

* s*'s construction lower bound is found by bisection over s (bounds.best_construction),
  the same answer and proof as trying every s from the upper bound down, and it stops
  at the deadline; the tabu walks compile nothing past their deadline;
* a numpy complex time limit is an InputError;
* a cached proof that the checker would take on trust (an earlier MILP call's) does not
  answer a later call that forces another method;
* ``workers=N`` calls return close to their time limit (slow).
"""

from __future__ import annotations

import threading
import time

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon.graphs import bounds as bd
from rescon.graphs import generators as gen
from rescon.graphs.facts import Facts, clear_cache, trusted_methods
from rescon.graphs.indexed import index_graph
from tests.test_review_v33 import _k_in

# --------------------------------------------------------------------------- #
# item 1: s*'s construction bound by bisection, deadlines
# --------------------------------------------------------------------------- #


def _top_down(ig, r, high, seeds):
    for s in range(high, 1, -1):
        proof = bd.construction_proof(ig, r, s, seeds=seeds)
        if proof is not None:
            return s, proof
    return None


def _construction_graphs():
    out = [gen.circulant(30, 6), gen.circulant(40, 8, directed=True), nx.complete_graph(9),
           nx.cycle_graph(12), nx.path_graph(5)]
    for seed in range(8):
        out.append(nx.gnp_random_graph(20 + 5 * seed, 0.5, seed=seed))
        out.append(nx.gnp_random_graph(20 + 5 * seed, 0.6, seed=50 + seed, directed=True))
    return out


@pytest.mark.parametrize("G", _construction_graphs())
def test_best_construction_is_the_top_down_answer_and_proof(G):
    ig = index_graph(G)
    seeds = bd.greedy_cliques(ig)
    for r in (1, 2, 3, 5):
        for high in (1, 2, 3, ig.n // 2, ig.n):
            assert bd.best_construction(ig, r, high, seeds=seeds) == _top_down(ig, r, high, seeds)


def test_best_construction_stops_at_its_deadline():
    ig = index_graph(gen.circulant(30, 6))
    seeds = bd.greedy_cliques(ig)
    assert bd.best_construction(ig, 2, 30, seeds=seeds) is not None
    assert bd.best_construction(ig, 2, 30, seeds=seeds, deadline=time.perf_counter()) is None


def test_tabu_walks_compile_nothing_past_their_deadline(monkeypatch):
    ig = index_graph(nx.cycle_graph(6))

    def no_compile():
        raise AssertionError("compiled past the deadline")

    monkeypatch.setattr(bd, "compiled_walk", no_compile)
    assert bd.tabu_pairs(ig, 1, deadline=time.perf_counter() - 1) == []


def _sparse_400():
    G = nx.gnp_random_graph(400, 0.04, seed=1)  # ρ ≥ 2 proven fast; s*(2) ∈ [1, 349]
    rescon.robustness(nx.cycle_graph(5), time_limit=0.1)  # warm imports
    clear_cache()
    return G


def test_is_rs_robust_and_max_s_honour_a_short_time_limit_on_400_nodes():
    """The work a 0.05-s limit allows, in CPU seconds of this process (wall time grows
    with the machine's load: 1.55 s in a clean-clone CI run at load 4, 0.2-0.4 s
    alone); the bug took 2.3-4 CPU-s."""
    G = _sparse_400()
    t0 = time.process_time()
    c = rescon.is_rs_robust(G, 2, 3, time_limit=0.05)
    assert c.holds in (None, True)
    assert time.process_time() - t0 < 1.0
    clear_cache()
    t0 = time.process_time()
    with pytest.raises(rescon.TimeLimitReached, match=r"≤ s\*\(2\) ≤"):
        rescon.max_s(G, 2, time_limit=0.05)
    assert time.process_time() - t0 < 1.0


# --------------------------------------------------------------------------- #
# item 2: complex time limits
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("tl", [np.complex128(1 + 5j), np.complex64(2), np.clongdouble(3),
                                np.complex128(float("nan"))])
def test_numpy_complex_time_limits_are_input_errors(tl):
    G = nx.cycle_graph(6)
    for call in (lambda: rescon.robustness(G, time_limit=tl),
                 lambda: rescon.max_s(G, 1, time_limit=tl),
                 lambda: rescon.is_rs_robust(G, 1, 2, time_limit=tl)):
        with pytest.raises(rescon.InputError, match="^time_limit must be"):
            call()


@pytest.mark.parametrize("tl", [np.float32(5), np.int64(5), np.uint8(5), 5, 5.0])
def test_numpy_real_time_limits_are_accepted(tl):
    rep = rescon.robustness(nx.cycle_graph(6), time_limit=tl)
    assert (rep.r_max, rep.exact) == (1, True)


def test_an_integer_time_limit_beyond_the_float_range_is_an_input_error():
    with pytest.raises(rescon.InputError, match="time_limit"):
        rescon.robustness(nx.cycle_graph(6), time_limit=10**400)


# --------------------------------------------------------------------------- #
# item 3: cached trusted proofs and forced methods
# --------------------------------------------------------------------------- #


def test_trusted_methods_of_nested_proofs():
    milp = {"method": "milp", "solver": "highs"}
    assert trusted_methods(milp, 21) == {"milp"}
    assert trusted_methods(milp, 20) == set()  # the checker enumerates n ≤ 20
    assert trusted_methods({"method": "implied", "r": 3, "s": 1, "proof": milp}, 30) == {"milp"}
    assert trusted_methods({"method": "search", "order": [], "tree": None}, 30) == {"search"}
    assert trusted_methods({"method": "cost_search", "order": [], "tree": [1]}, 30) == set()
    assert trusted_methods({"method": "cost_search", "order": [], "charged_tree": [1]},
                           30) == set()
    seed = {"method": "construction", "order": [], "seed_size": 25,
            "seed_proof": {"method": "dp"}}
    assert trusted_methods(seed, 40) == {"dp"}
    assert trusted_methods({**seed, "seed_size": 12}, 40) == set()
    for p in ({"method": "degree"}, {"method": "trivial"}, {"method": "spectral"}):
        assert trusted_methods(p, 100) == set()


def test_facts_offer_a_trusted_proof_only_to_auto_and_its_own_method():
    ig = index_graph(gen.circulant(24, 6))
    facts = Facts(ig)
    milp = {"method": "milp", "solver": "highs"}
    facts.add_proof(3, 2, milp)
    assert facts.lower(2) == (3, {"method": "implied", "r": 3, "s": 2, "proof": milp})
    assert facts.lower(3, "milp") == (2, milp)
    assert facts.lower(3, "search") is None and facts.lower(3, "dp") is None
    tree = {"method": "cost_search", "order": list(range(24)), "tree": [0]}
    facts.add_proof(3, 2, tree)  # same s, checkable: replaces the trusted one
    assert facts.lower(3, "search") == (2, tree) and facts.lower(3) == (2, tree)
    facts.add_proof(3, 2, milp)  # ... and is not replaced by it again
    assert facts.lower(3, "milp") == (2, tree)


def test_forced_search_after_a_trusted_milp_proof_gives_a_tree():
    G = _k_in(22, 3, 0)  # ρ = 2, proven by the MILP with a proof kept on trust
    clear_cache()
    first = rescon.is_r_robust(G, 2, method="milp")
    assert first.holds and first.proof_method == "milp"
    assert rescon.check_certificate(first.certificate).verdict == "unchecked"
    again = rescon.is_r_robust(G, 2, method="search")
    assert again.holds and again.method == "search"
    assert rescon.check_certificate(again.certificate).verdict == "valid"
    assert rescon.is_r_robust(G, 2, method="milp").proof_method != "milp"  # the tree, cached
    rep = rescon.robustness(G, method="search")
    assert rep.r_max == 2 and rep.exact
    assert rescon.check_certificate(rep.certificate).verdict == "valid"
    assert rescon.is_rs_robust(G, 2, rep.s_max, method="search").holds is True


# --------------------------------------------------------------------------- #
# item 4: workers=N within the time limit, nothing left behind (slow)
# --------------------------------------------------------------------------- #


def _running() -> set[tuple[str, int]]:
    """This process's threads and child processes (multiprocessing's resource tracker,
    started once per process, excepted)."""
    import psutil

    procs = {("process", p.pid) for p in psutil.Process().children(recursive=True)
             if "resource_tracker" not in " ".join(p.cmdline())}
    return {(t.name, t.ident or 0) for t in threading.enumerate()} | procs


def _left(before: set[tuple[str, int]], seconds: float = 15.0) -> set[tuple[str, int]]:
    """What runs now and did not before, once it has had ``seconds`` to end (distributed's
    process-wide offload thread, started once, excepted)."""
    stop = time.perf_counter() + seconds
    while True:
        new = {x for x in _running() - before if not x[0].startswith("Dask-Offload")}
        if not new or time.perf_counter() > stop:
            return new
        time.sleep(0.2)


@pytest.mark.slow
@pytest.mark.parametrize("limit", [1.6, 4.0])
def test_workers_time_limit_is_honoured_and_nothing_is_left(limit):
    """1.6 s: the cluster start is still under way at the limit (it is left to its
    thread, which closes what it made); 4 s: the s* search's parts are running on it."""
    pytest.importorskip("distributed")
    G = gen.circulant(63, 3, directed=True)
    rescon.robustness(nx.cycle_graph(5), time_limit=0.1)  # warm imports
    clear_cache()
    before = _running()
    t0 = time.perf_counter()
    rep = rescon.robustness(G, time_limit=limit, workers=1)
    wall = time.perf_counter() - t0
    assert rep.r_max == 2 and not rep.exact and 1 <= rep.s_lower <= rep.s_upper <= 4
    assert wall < limit + 1.0
    assert _left(before) == set()


@pytest.mark.slow
def test_an_embedded_cluster_closes_fast_with_a_task_running():
    pytest.importorskip("distributed")
    from rescon import _dask

    before = _running()
    with _dask.client(None, 1) as client:
        client.submit(time.sleep, 30, pure=False)
        time.sleep(1.0)
        t0 = time.perf_counter()
    assert time.perf_counter() - t0 < 2.0  # distributed's own close: 4 s
    assert _left(before) == set()
