"""Hostile review of issue 12 as a new user meets it: sweeps of every kind on graph
files and generated graphs, CLI contracts, figures of odd trajectories."""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

import pytest

import rescon
from rescon import InputError

ROOT = Path(__file__).resolve().parents[1]
PAPER_GRAPH = ROOT / "examples" / "graphs" / "paper_example.edgelist"


def test_robustness_cells_of_a_graph_file_run_every_repetition():
    """A robustness grid over the user's own graph file (no generator): each repetition
    gets a seed, which a file graph does not take, and must not fail on it."""
    table = rescon.sweep({"base": {"graph": {"edgelist": str(PAPER_GRAPH)}},
                          "run": {"kind": "robustness", "repetitions": 2}}, workers=0)
    assert list(table["status"]) == ["ok", "ok"], list(table["error"])
    assert list(table["rho"]) == [5, 5] and list(table["s_star"]) == [1, 1]
    assert list(table["certificate_verdict"]) == ["valid", "valid"]


def test_a_server_that_is_not_a_dask_scheduler_is_a_clear_error():
    """An address where something else answers (here: an HTTP-like reply, whose first
    bytes Dask reads as a frame length of ~3 EiB) is "cannot connect", not a
    MemoryError."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen()

    def answer() -> None:
        conn, _ = srv.accept()
        with conn:
            conn.sendall(b"HTTP/1.1 400 Bad Request\r\n\r\n" * 4)
            time.sleep(1)

    threading.Thread(target=answer, daemon=True).start()
    grid = {"base": {"points": {"generator": "gaussian", "n": 5, "d": 2},
                     "kernel": {"F": 1}}, "run": {"kind": "kernel"}}
    t0 = time.monotonic()
    try:
        with pytest.raises(InputError, match="cannot connect"):
            rescon.sweep(grid, scheduler=f"tcp://127.0.0.1:{srv.getsockname()[1]}")
    finally:
        srv.close()
    assert time.monotonic() - t0 < 20


@pytest.mark.parametrize("graph", [
    {"generator": "complete", "n": 100_000},
    {"generator": "erdos_renyi", "n": 1_000_000, "p": 1e-5},  # draws every pair
    {"generator": "two_cliques", "n": 20_000, "b": 1},
    {"generator": "random_geometric", "n": 200_000, "radius": 0.9},
])
def test_huge_generated_graphs_are_refused_before_they_are_built(graph):
    """A size a grid axis can reach by a typo must not fill the shared machine's memory
    (K_100000 took 36 s to die of MemoryError under a 4 GB limit)."""
    from rescon.graphs.named import generate

    t0 = time.monotonic()
    with pytest.raises(InputError, match=f"generator '{graph['generator']}' with n = "):
        generate(graph, 0)
    assert time.monotonic() - t0 < 1


def test_generated_graphs_of_ordinary_size_are_built():
    from rescon.graphs.named import generate

    assert generate({"generator": "complete", "n": 800}, 0).number_of_nodes() == 800
    G = generate({"generator": "erdos_renyi", "n": 2000, "p": 0.001}, 0)
    assert G.number_of_nodes() == 2000


def test_random_states_and_clouds_beyond_the_memory_budget_are_refused():
    """12 random states in dimension 3e7 (2.7 GiB) or a 1e8-point cloud in R³ are
    refused with the estimate, not drawn into memory first."""
    from rescon.consensus.scenario import _random_states
    from rescon.sweep.clouds import cloud

    with pytest.raises(InputError, match="12 states in dimension 30000000"):
        _random_states({"low": 0, "high": 1, "d": 30_000_000}, 12, 0, "random")
    with pytest.raises(InputError, match="100000000 points in dimension 3"):
        cloud({"generator": "gaussian", "n": 100_000_000, "d": 3})


def _summary_figure(monkeypatch, tmp_path, grid):
    """The summary figure a sweep of ``grid`` draws (caught as it is made: it is drawn
    on its own canvas, outside pyplot)."""
    import rescon.plot

    figures, made = [], rescon.plot.new_figure

    def caught(*args, **kwargs):
        figures.append(made(*args, **kwargs))
        return figures[-1]

    monkeypatch.setattr(rescon.plot, "new_figure", caught)
    rescon.sweep(grid, workers=0, out=tmp_path / "out")
    assert len(figures) == 1
    return figures[0]


def test_summary_of_failed_cells_names_every_axis_value_and_says_why_it_is_empty(
        monkeypatch, tmp_path):
    """Every cell failed (F ≥ n): the mean panel still lists every axis value, its y
    axis does not run below 0 (seconds, steps), and it says there is no value."""
    grid = {"base": {"points": {"generator": "gaussian", "n": 5, "d": 2},
                     "kernel": {"F": 9}},
            "axes": {"points.n": [5, 6, 7]}, "run": {"kind": "kernel"}}
    fig = _summary_figure(monkeypatch, tmp_path, grid)
    rate, mean = fig.axes
    for ax in (rate, mean):
        assert [t.get_text() for t in ax.get_xticklabels()] == ["5", "6", "7"]
    assert mean.get_ylim()[0] >= 0
    assert any("no value" in t.get_text() for t in mean.texts)


def test_rerun_with_the_axes_in_another_order_is_refused_not_mixed(tmp_path):
    """Cells are numbered in axis order: swapping two axes renumbers them, so resuming
    would skip cells that never ran and run others twice; it is another grid."""
    base = {"graph": {"generator": "circulant", "n": 7}}
    first = {"base": base, "axes": {"graph.n": [7, 9], "graph.circulant.k": [1, 2]},
             "run": {"kind": "robustness"}}
    swapped = {**first, "axes": {"graph.circulant.k": [1, 2], "graph.n": [7, 9]}}
    rescon.sweep(first, workers=0, out=tmp_path)
    with pytest.raises(InputError, match="another grid"):
        rescon.sweep(swapped, workers=0, out=tmp_path)


@pytest.mark.parametrize("command", ["simulate", "rmdo"])
@pytest.mark.parametrize("names", [",", "", " , "])
def test_cli_metrics_naming_no_monitor_is_refused(command, names, capsys):
    """``--metrics ,`` (or an empty string) names no monitor: a one-line error, not a
    run whose every metric is silently null."""
    from rescon.cli import main

    scenario = ROOT / "examples" / "scenarios" / (
        "paper.toml" if command == "simulate" else "rmdo_quadratic.toml")
    assert main([command, str(scenario), "--metrics", names, "--json", "-q"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "--metrics" in err


def test_an_adversary_without_receivers_is_recorded_as_sending_nothing():
    """Its row of ``states`` is what it sent: NaN, not its initial state held forever
    (which the figure drew as an adversary line at x_0 that nobody ever received)."""
    import networkx as nx
    import numpy as np

    from rescon.consensus.adversaries import Constant, TwoFaced, TwoFacedTable

    G = nx.complete_graph(8).to_directed()
    G.remove_edges_from([(0, j) for j in range(1, 8)])  # node 0 talks to nobody
    x0 = [[i, i % 3] for i in range(8)]
    for adv in (Constant([5.0, 5.0]), TwoFaced(TwoFacedTable(cycle=[[9, 9], [-9, 0]]))):
        sc = rescon.Scenario(graph=G, x0=x0, F=1, steps=3, adversaries={0: adv},
                             check_robustness=False)
        tr = rescon.simulate(sc, progress=False)
        assert np.isnan(tr.states[:, 0]).all()
        assert np.isnan(tr.sent).all()
        assert tr.to_json()["states"][1][0] == [None, None]


def _visible_ticks(fig, ylabel: str) -> list[float]:
    """The major y ticks of the panel ``ylabel`` inside its limits, after drawing."""
    fig.canvas.draw()
    ax = next(a for a in fig.axes if a.get_ylabel() == ylabel)
    lo, hi = ax.get_ylim()
    return [y for y in ax.yaxis.get_majorticklocs() if lo <= y <= hi]


@pytest.mark.parametrize("cost", ["x1 - 100", "x1 + 500", "0.01 * abs(x1) + 0.01 * abs(x2)"])
def test_cost_panel_of_negative_or_small_costs_has_ticks(cost):
    """Costs in [−800, −740] (unbounded below) or in [0, 0.07] (F* = 0): the global cost
    panel was a symlog axis with no tick inside its range — no number on it."""
    import matplotlib
    import networkx as nx

    matplotlib.use("Agg")
    sc = rescon.Scenario(graph=nx.complete_graph(8).to_directed(),
                         x0=[[i, i % 3] for i in range(8)], F=1, steps=20,
                         check_robustness=False)
    fig = rescon.rmdo(sc, {i: cost for i in sc.benign}, progress=False).plot()
    assert len(_visible_ticks(fig, "global cost")) >= 2


def test_diameter_of_a_zero_step_run_is_drawn():
    """steps = 0: the diameter at t = 0 is one point; a plain line of one point draws
    nothing, so the panel was empty."""
    import matplotlib
    import networkx as nx

    matplotlib.use("Agg")
    sc = rescon.Scenario(graph=nx.complete_graph(6).to_directed(),
                         x0=[[i, i % 3] for i in range(6)], F=1, steps=0,
                         check_robustness=False)
    fig = rescon.simulate(sc, progress=False).plot()
    ax = next(a for a in fig.axes if a.get_ylabel() == "diameter (benign)")
    line = ax.get_lines()[0]
    assert len(line.get_xdata()) == 1 and line.get_marker() not in (None, "None", "")


def test_kernel_plot_takes_a_file_name_as_trajectory_plot_does(tmp_path):
    """``K.plot("kernel.png")`` (the README's ``plot(path)``) wrote nothing and crashed
    with "'str' object has no attribute 'scatter'": the first parameter was ``ax``."""
    import matplotlib

    matplotlib.use("Agg")
    K = rescon.safe_kernel([[0, 0], [4, 0], [4, 4], [0, 4], [1, 3]], 1)
    for target in (str(tmp_path / "k.png"), tmp_path / "k2.png"):
        K.plot(target)
        assert Path(target).stat().st_size > 1000


@pytest.mark.parametrize("grid", [
    {"axes": {"graph.circulant.kk": [1, 2]}},  # a misspelt parameter of another generator
    {"axes": {"graph.circulant.k.x": [1, 2]}},
    {"base": {"graph": {"generator": "ba_robust", "n": 8, "m": 2,
                        "circulant": {"kk": 3}}}},
])
def test_misspelt_generator_parameters_are_refused_when_the_grid_is_read(grid):
    """A sub-table key of a generator that is not its parameter was accepted and, while
    another generator ran, silently ignored: an axis that changed nothing."""
    from rescon.sweep.grid import read_grid

    full = {"base": {"graph": {"generator": "ba_robust", "n": 8, "m": 2}},
            "run": {"kind": "robustness"}, **grid}
    with pytest.raises(InputError, match="circulant takes n, k, directed"):
        read_grid(full)


@pytest.mark.slow
def test_a_cell_that_kills_its_worker_is_a_failed_row_not_a_crash(tmp_path):
    """User code (an RMDO ``module`` cost, an out-of-memory kill) can end the worker
    process: Dask then raises KilledWorker from the future, which stopped the whole
    sweep with a traceback instead of recording the cell."""
    import dask

    (tmp_path / "killer.py").write_text("import os\n\n\ndef build():\n    os._exit(1)\n")
    (tmp_path / "grid.toml").write_text(
        '[base.scenario]\nF = 1\nsteps = 3\ncheck_robustness = false\n'
        '[base.graph]\ngenerator = "complete"\nn = 6\n'
        '[base.initial.random]\nlow = 0.0\nhigh = 1.0\nd = 2\n'
        '[base.costs]\nmodule = "killer:build"\n')
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        table = rescon.sweep(tmp_path / "grid.toml", workers=1, out=tmp_path / "out")
    assert list(table["status"]) == ["failed"]
    assert table["error"][0].startswith("KilledWorker")


@pytest.mark.slow
def test_a_scheduler_without_workers_is_a_clear_error_not_a_hang(tmp_path, monkeypatch):
    """`dask scheduler` running but no `dask worker`: the sweep waited forever."""
    import shutil
    import subprocess
    import sys

    from rescon import _dask

    monkeypatch.setattr(_dask, "WORKER_SECONDS", 2)
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    dask = shutil.which("dask", path=str(Path(sys.executable).parent))
    proc = subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", str(port),
                             "--no-dashboard"], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    grid = {"base": {"points": {"generator": "gaussian", "n": 5, "d": 2},
                     "kernel": {"F": 1}}, "run": {"kind": "kernel"}}
    try:
        deadline = time.monotonic() + 30
        while True:  # until the scheduler listens
            try:
                socket.create_connection(("127.0.0.1", port), timeout=1).close()
                break
            except OSError:
                assert time.monotonic() < deadline
                time.sleep(0.3)
        t0 = time.monotonic()
        with pytest.raises(InputError, match="no worker joined"):
            rescon.sweep(grid, scheduler=f"tcp://127.0.0.1:{port}")
        assert time.monotonic() - t0 < 20
    finally:
        proc.terminate()
        proc.wait(timeout=10)
