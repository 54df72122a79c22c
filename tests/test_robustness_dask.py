"""The exact decision search split into subtrees (graphs/distributed.py) against the
serial search: the parts' trees concatenate to exactly the serial tree, a witness from
any part is a witness, and the public API on a Dask cluster writes the serial
certificate. The cluster is a LocalCluster of 2 worker processes on loopback, started
here; the budgets are shrunk so that even small searches are cut into many parts."""

from __future__ import annotations

import socket
import sys

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from rescon.cli import main
from rescon.errors import InputError, MissingDependency
from rescon.graphs import _kernels as K
from rescon.graphs import bounds as bd
from rescon.graphs import distributed, search
from rescon.graphs.facts import clear_cache
from rescon.graphs.indexed import index_graph
from rescon.graphs.search import (
    PartRun,
    SearchPart,
    decide_r_robust,
    split_part,
    whole_part,
)
from tests.test_robustness_exact import digraphs


def _inputs(ig):
    return (K, search._mask_array(ig), search._out_mask_array(ig), search.search_order(ig))


def _split_run(inputs, r, part, budgets, singles):
    """Run ``part`` for the next budget, then its rest's parts recursively, in the order
    of :func:`split_part`; stop at the first part that finds a pair. Returns (tokens,
    nodes, witness or None)."""
    run = PartRun(inputs, r, part, search.MAX_TREE_TOKENS)
    status = run.advance(next(budgets))
    tokens, nodes = list(run.tokens()), run.nodes
    if status == K.SAT:
        return tokens, nodes, run.witness()
    if status == K.RUNNING:
        for sub in split_part(run.rest(), singles):
            sub_tokens, sub_nodes, witness = _split_run(inputs, r, sub, budgets, singles)
            tokens += sub_tokens
            nodes += sub_nodes
            if witness is not None:
                return tokens, nodes, witness
    return tokens, nodes, None


@settings(max_examples=60, deadline=None)
@given(digraphs(max_n=11), st.lists(st.integers(1, 40), min_size=1, max_size=8),
       st.integers(0, 3))
def test_split_parts_compose_to_the_serial_search(G, budgets, singles):
    """The claim of graphs/distributed.py, part by part in preorder: the tokens are the
    serial tree, the states the serial count, and the first pair found is the serial
    witness (a valid violating pair)."""
    ig = index_graph(G)
    inputs = _inputs(ig)
    cycle = iter(budgets * 10_000)
    for r in range(1, (ig.n + 1) // 2 + 2):
        whole = decide_r_robust(ig, r)
        tokens, nodes, witness = _split_run(inputs, r, whole_part(ig.n), cycle, singles)
        if whole.status == "robust":
            assert witness is None and tuple(tokens) == whole.tree and nodes == whole.nodes
        else:
            assert witness == whole.witness and nodes == whole.nodes
            assert bd.violates(ig, bd.Pair(*witness), r, 1)


def test_split_part_keeps_the_order_and_every_frame():
    ig = index_graph(nx.gnp_random_graph(14, 0.6, seed=3, directed=True))
    run = PartRun(_inputs(ig), 4, whole_part(ig.n), search.MAX_TREE_TOKENS)
    assert run.advance(15) == K.RUNNING
    rest = run.rest()
    k = rest.frames.shape[0]
    assert k >= 3
    parts = split_part(rest, 2)
    # top frames together, then the two bottom frames alone (upper first), then the roots
    assert [p.frames.shape[0] for p in parts] == [k - 2, 1, 1, 0]
    assert (parts[1].frames == rest.frames[1:2]).all()
    assert (parts[2].frames == rest.frames[:1]).all()
    assert [p.end for p in parts] == [ig.n] * 4
    assert [p.root for p in parts] == [ig.n, ig.n, ig.n, rest.root]


# ---------------------------------------------------------------- on a Dask cluster


@pytest.fixture
def tiny_parts(monkeypatch):
    """Searches go to the cluster after 50 states, in tasks of 500."""
    monkeypatch.setattr(search, "_SLICE", 50)
    monkeypatch.setattr(distributed, "LOCAL_NODES", 50)
    monkeypatch.setattr(distributed, "TASK_NODES", 500)


def test_split_search_on_the_cluster_is_the_serial_search(cluster, tiny_parts):
    seen, most = set(), 0
    for seed in (0, 2):
        ig = index_graph(nx.gnp_random_graph(22, 0.7, seed=seed, directed=True))
        for r in (6, 8):
            serial = decide_r_robust(ig, r)
            with distributed.searches_on(scheduler=cluster):
                split = decide_r_robust(ig, r)
            seen.add(split.status)
            assert (split.status, split.order) == (serial.status, serial.order)
            if serial.status == "robust":
                assert split.tree == serial.tree and split.nodes == serial.nodes
                most = max(most, split.nodes)
            else:
                assert bd.violates(ig, bd.Pair(*split.witness), r, 1)
    assert seen == {"robust", "not_robust"} and most > 20_000  # > 40 tasks of 500 states


def test_the_tree_is_dropped_past_the_cap_as_in_the_serial_search(cluster, tiny_parts,
                                                                 monkeypatch):
    ig = index_graph(nx.gnp_random_graph(22, 0.7, seed=0, directed=True))
    full = decide_r_robust(ig, 8)
    assert len(full.tree) > 5000
    for cap, kept in ((len(full.tree) + 1, True), (len(full.tree), False)):
        monkeypatch.setattr(search, "MAX_TREE_TOKENS", cap)
        monkeypatch.setattr(distributed, "MAX_TREE_TOKENS", cap)
        serial = decide_r_robust(ig, 8)
        with distributed.searches_on(scheduler=cluster):
            split = decide_r_robust(ig, 8)
        assert (serial.tree is not None) == kept and split.tree == serial.tree


@pytest.mark.parametrize(("n", "p", "seed"), [(18, 0.5, 4), (24, 0.5, 6)])
def test_public_api_on_the_cluster_writes_the_serial_certificate(cluster, tiny_parts, n, p,
                                                                 seed, monkeypatch):
    """ρ by a search (18 nodes) or by a construction whose seed a search proves (24)."""
    from rescon.graphs import robustness as rob

    monkeypatch.setattr(rob, "SEED_SEARCH_SECONDS", 60.0)  # not cut short by tiny tasks
    G = nx.gnp_random_graph(n, p, seed=seed, directed=True)
    clear_cache()
    serial = rescon.robustness(G, method="search")
    clear_cache()
    split = rescon.robustness(G, method="search", scheduler=cluster)
    assert (split.r_max, split.s_max, split.exact) == (serial.r_max, serial.s_max, True)
    assert split.certificate == serial.certificate
    assert '"tree": [' in str(split.certificate).replace("'", '"')
    verdict = rescon.check_certificate(split.certificate)
    assert verdict.valid, verdict.reason
    clear_cache()
    check = rescon.is_r_robust(G, serial.r_max + 1, method="search", scheduler=cluster)
    verdict = rescon.check_certificate(check.certificate)
    assert check.holds is False and verdict.valid, verdict.reason


@pytest.mark.slow
def test_workers_start_an_embedded_cluster_only_when_a_search_needs_it(tiny_parts,
                                                                        monkeypatch):
    """workers=1: the LocalCluster starts inside the call (a search outlasted 50 states)
    and the answer and certificate are the serial ones."""
    from rescon.graphs import robustness as rob

    monkeypatch.setattr(rob, "SEED_SEARCH_SECONDS", 60.0)
    G = nx.gnp_random_graph(24, 0.5, seed=6, directed=True)
    clear_cache()
    serial = rescon.is_r_robust(G, 5, method="search")
    started = []
    monkeypatch.setattr(distributed._Cluster, "client", _spy(distributed._Cluster.client,
                                                              started))
    clear_cache()
    split = rescon.is_r_robust(G, 5, method="search", workers=1)
    assert started and split.holds is serial.holds is True
    assert split.certificate == serial.certificate


def _spy(method, calls):
    def wrapped(self):
        calls.append(self.workers)
        return method(self)
    return wrapped


def test_a_time_limit_stops_the_split_search(cluster):
    ig = index_graph(nx.gnp_random_graph(50, 0.5, seed=50000, directed=True))
    import time

    t0 = time.perf_counter()
    with distributed.searches_on(scheduler=cluster):
        out = decide_r_robust(ig, 13, deadline=t0 + 1.5)  # ~40 s of work
    assert out.status == "stopped" and 0 < out.progress < 1
    assert time.perf_counter() - t0 < 6


def test_a_failed_task_is_a_one_line_solver_error(cluster):
    """A task that raises on its worker (here: a pending frame of the wrong width)."""
    from rescon.errors import SolverError

    ig = index_graph(nx.gnp_random_graph(22, 0.7, seed=0, directed=True))
    run = PartRun(_inputs(ig), 8, whole_part(ig.n), 0)
    assert run.advance(100) == K.RUNNING
    run.rest = lambda: SearchPart(np.zeros((1, K.STACK_WIDTH - 1), dtype=np.uint64),
                                  np.zeros(1, dtype=np.int64), ig.n, ig.n)
    with distributed.searches_on(scheduler=cluster), pytest.raises(SolverError) as info:
        distributed.finish_on_cluster(distributed.active(), run)
    assert "failed on the Dask cluster" in str(info.value) and "\n" not in str(info.value)


def test_a_search_that_ends_locally_starts_no_cluster():
    ig = index_graph(nx.gnp_random_graph(12, 0.5, seed=1, directed=True))
    with distributed.searches_on(workers=2):
        out = decide_r_robust(ig, 2)
        assert distributed.active()._client is None
    assert out.status in ("robust", "not_robust") and distributed.active() is None


# ---------------------------------------------------------------- bad input


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_bad_options_are_one_line_errors(capsys, tmp_path):
    G = nx.cycle_graph(8)
    with pytest.raises(InputError, match="either scheduler"):
        rescon.robustness(G, scheduler="tcp://127.0.0.1:1", workers=2)
    for bad in (-1, 1.5, True, "2"):
        with pytest.raises(InputError, match="workers must be a nonnegative integer"):
            rescon.max_s(G, 1, workers=bad)
    assert rescon.max_s(G, 1, workers=np.int64(0)) == rescon.max_s(G, 1)  # numpy ints too
    with pytest.raises(InputError, match="search \\(n ≤ 64\\) runs on a cluster; got n = 65"):
        rescon.is_r_robust(nx.cycle_graph(65), 1, workers=2)
    edges = tmp_path / "g.txt"
    edges.write_text("".join(f"{i} {(i + 1) % 65}\n" for i in range(65)))
    for args in (["--workers", "2", "--scheduler", "tcp://127.0.0.1:1"], ["--workers", "-1"],
                 ["--workers", "2"], ["--r", "1", "--workers", "2"]):
        assert main(["robustness", str(edges), *args]) == 2
        err = capsys.readouterr().err.strip()
        assert err.startswith("rescon: error:") and "\n" not in err


def test_unreachable_scheduler_is_refused_on_entry(capsys, tmp_path, monkeypatch):
    from rescon import _dask

    monkeypatch.setattr(_dask, "CONNECT_SECONDS", 1)
    edges = tmp_path / "g.txt"
    edges.write_text("0 1\n1 2\n2 0\n")
    address = f"tcp://127.0.0.1:{_free_port()}"
    assert main(["robustness", str(edges), "--scheduler", address]) == 2
    err = capsys.readouterr().err.strip()
    assert "cannot connect" in err and "\n" not in err


def test_missing_dask_is_a_one_line_error(monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed fails
    with pytest.raises(MissingDependency, match="rescon\\[dask\\]"):
        rescon.robustness(nx.cycle_graph(8), workers=2)
    edges = tmp_path / "g.txt"
    edges.write_text("0 1\n1 2\n2 0\n")
    assert main(["robustness", str(edges), "--workers", "2"]) == 2
    err = capsys.readouterr().err.strip()
    assert "rescon[dask]" in err and "\n" not in err
    assert main(["robustness", str(edges), "--workers", "0"]) == 0  # serial needs no dask


def test_cli_r_query_shares_one_cluster(monkeypatch, tmp_path, capsys):
    """`rescon robustness G --r R --workers N` asks two questions (R-robust? s*(R)?) on
    one cluster: it prepared one per question before."""
    made = []
    real = distributed._Cluster

    class Counted(real):
        def __init__(self, *args, **kwargs):
            made.append(args)
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(distributed, "_Cluster", Counted)
    clear_cache()
    edges = tmp_path / "g.txt"
    edges.write_text("".join(f"{i} {(i + k) % 9}\n" for i in range(9) for k in (1, 2, 3)))
    assert main(["robustness", str(edges), "--r", "2", "--workers", "1", "--json"]) == 0
    out = capsys.readouterr().out
    assert '"r_robust": true' in out and '"s_max"' in out
    assert len(made) == 1
