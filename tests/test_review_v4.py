"""Review V4 (hostile): the s*(r) search split on Dask and the dense-robustness changes.

Each test is a failure found by fuzzing (or a guard for one), small and deterministic,
on a cluster this module starts on loopback and closes."""

from __future__ import annotations

import subprocess
import sys
import threading
import time
from pathlib import Path

import networkx as nx
import pytest

import rescon
from benchmarks.baselines import leblanc_max_s
from rescon import _dask
from rescon.errors import SolverError
from rescon.graphs import distributed, search
from rescon.graphs.facts import clear_cache

DASK = Path(sys.executable).with_name("dask")


@pytest.fixture
def tiny_parts(monkeypatch):
    """Searches go to the cluster after 20 states, in tasks of 50."""
    monkeypatch.setattr(search, "_SLICE", 20)
    monkeypatch.setattr(distributed, "LOCAL_NODES", 20)
    monkeypatch.setattr(distributed, "TASK_NODES", 50)
    monkeypatch.setattr(distributed, "COST_TASK_NODES", 50)


@pytest.fixture
def lone_worker():
    """A scheduler (in this process, no worker of its own) and one worker process
    without a nanny (nothing restarts it): (address, the worker's Popen)."""
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=0, host="127.0.0.1", protocol="tcp",
                      dashboard_address=None) as local:
        address = local.scheduler_address
        worker = subprocess.Popen(
            [str(DASK), "worker", address, "--no-nanny", "--nthreads", "1", "--host",
             "127.0.0.1", "--no-dashboard"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:
            with Client(address) as client:
                client.wait_for_workers(1, timeout=60)
            yield address, worker
        finally:
            worker.kill()
            worker.wait()


@pytest.mark.slow
@pytest.mark.parametrize("finish", ["finish_cost_on_cluster", "finish_on_cluster"])
def test_the_last_worker_killed_mid_search_is_a_solver_error_not_a_hang(
        lone_worker, tiny_parts, monkeypatch, finish):
    """The only worker of a scheduler dies (kill -9) when the search goes to the
    cluster: its tasks can never run. _dask.client refuses a scheduler where no worker
    joins within WORKER_SECONDS because "its tasks would wait forever"; mid-search the
    same wait had no end: max_s (no time limit) polled forever (seen: > 150 s, killed).
    Expected: a one-line SolverError once no worker has been seen for WORKER_SECONDS."""
    address, worker = lone_worker
    original = getattr(distributed, finish)

    def kill_then_finish(*args, **kwargs):
        worker.kill()
        worker.wait()
        monkeypatch.setattr(_dask, "WORKER_SECONDS", 2)  # connected: now shorten the wait
        return original(*args, **kwargs)

    monkeypatch.setattr(distributed, finish, kill_then_finish)
    G = nx.gnp_random_graph(16, 0.8, seed=3, directed=True)  # s*(3) = 11, 5-robust
    outcome: list[BaseException | int] = []

    def run() -> None:
        try:
            clear_cache()
            if finish == "finish_cost_on_cluster":
                outcome.append(rescon.max_s(G, 3, method="search", scheduler=address))
            else:
                outcome.append(rescon.is_r_robust(G, 5, method="search",
                                                  scheduler=address).holds)
        except BaseException as exc:  # noqa: BLE001 (what the caller would see)
            outcome.append(exc)

    thread = threading.Thread(target=run, daemon=True)
    t0 = time.perf_counter()
    thread.start()
    thread.join(30)
    assert not thread.is_alive(), f"{finish}: still waiting for a worker after 30 s"
    assert time.perf_counter() - t0 < 30
    (got,) = outcome
    assert isinstance(got, SolverError), got
    assert "\n" not in str(got)


@pytest.mark.slow
def test_a_worker_killed_mid_search_and_restarted_by_its_nanny_keeps_the_answer(
        tiny_parts, monkeypatch):
    """Guard (held): the worker process of a LocalCluster killed (SIGKILL) as the s*
    search goes to the cluster; its nanny restarts it, the lost tasks run again, and
    the split s*(3) is still brute force's (11)."""
    import os
    import signal

    from distributed import Client, LocalCluster

    G = nx.gnp_random_graph(16, 0.8, seed=3, directed=True)
    original = distributed.finish_cost_on_cluster
    killed: list[int] = []
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as local, Client(local) as client:
        (pid,) = client.run(os.getpid).values()

        def kill_then_finish(*args, **kwargs):
            if not killed:
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)
            return original(*args, **kwargs)

        monkeypatch.setattr(distributed, "finish_cost_on_cluster", kill_then_finish)
        clear_cache()
        got = rescon.max_s(G, 3, method="search", scheduler=local.scheduler_address)
    assert killed and got == leblanc_max_s(G, 3) == 11
