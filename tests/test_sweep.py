"""rescon.sweep and the plain-data scenario it rests on (issue 12 §2).

Services are started here, on loopback: a LocalCluster of 2 worker processes, and a
scheduler + worker started as separate processes with Dask's own `dask scheduler` /
`dask worker` commands on a free port (killed in the fixture's finaliser)."""

from __future__ import annotations

import pickle
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import rescon
from rescon import InputError, Scenario
from rescon.cli import main
from rescon.sweep import cell as cell_mod
from rescon.sweep import run as run_mod
from rescon.sweep.cell import steps_to_consensus
from rescon.sweep.grid import read_grid

ROOT = Path(__file__).resolve().parents[1]
SMALL = ROOT / "examples" / "sweeps" / "small.toml"

#: 8 cells: 2 policies × 2 centres × 2 repetitions of the paper's example, 15 steps
GRID8 = {"base": {"scenario": {"paper_example": True, "steps": 15,
                               "check_robustness": False}},
         "axes": {"scenario.policy": ["hold", "zero"], "scenario.centre": ["mean", "box"]},
         "run": {"repetitions": 2}}


def _same_rows(a: pd.DataFrame, b: pd.DataFrame) -> None:
    """Every column but the wall time equal, row for row."""
    cols = [c for c in a.columns if c != "seconds"]
    assert list(a.columns) == list(b.columns)
    pd.testing.assert_frame_equal(a[cols].reset_index(drop=True),
                                  b[cols].reset_index(drop=True))


@pytest.fixture(scope="module")
def serial8() -> pd.DataFrame:
    return rescon.sweep(GRID8, workers=0)


# ---------------------------------------------------------------- plain-data scenarios


def _custom() -> Scenario:
    """Nodes in a non-sorted order, per-agent α, a DoS attack, residual none."""
    data = {"scenario": {"F": 1, "steps": 5, "alpha": {"c": 0.4, "a": 0.6},
                         "residual": "none", "check_robustness": False},
            "graph": {"nodes": ["c", "a", "b", "d"],
                      "edges": [[u, v] for u in "abcd" for v in "abcd" if u != v]},
            "initial": {"a": [0.0, 1.0], "b": [2.0, 0.0], "c": [1.0, 1.0], "d": [3.0, 3.0]},
            "adversaries": {"d": {"kind": "constant", "value": [9.0, 9.0]}},
            "dos": [{"name": "D", "links": [["a", "b"]],
                     "schedule": {"kind": "periodic", "period": 2.0, "duration": 1.0}}]}
    return Scenario.from_dict(data)


@pytest.mark.parametrize("make", [lambda: Scenario.paper_example(steps=10), _custom])
def test_scenario_dict_round_trip_and_pickle(make):
    s = make()
    d = s.to_dict()
    again = Scenario.from_dict(d)
    assert again.to_dict() == d
    assert again.nodes == s.nodes
    np.testing.assert_array_equal(again.x0, s.x0)
    np.testing.assert_array_equal(again.alpha, s.alpha)
    back = pickle.loads(pickle.dumps(s))  # the residual used to be a lambda
    assert back.to_dict() == d
    a, b = rescon.simulate(again, progress=False), rescon.simulate(back, progress=False)
    np.testing.assert_array_equal(a.states, b.states)


def test_alpha_table_keys_are_node_labels():
    """A TOML [scenario] alpha table has string keys; they name nodes as [initial] keys
    do (they used to be ignored, every agent getting 0.5)."""
    s = _custom()
    assert dict(zip(s.nodes, s.alpha.tolist())) == {"c": 0.4, "a": 0.6, "b": 0.5, "d": 0.5}
    paper = Scenario.from_dict({"scenario": {"paper_example": True, "alpha": {"3": 0.4}}})
    assert paper.alpha[paper.nodes.index(3)] == 0.4


def test_to_dict_refuses_what_is_not_data():
    s = Scenario.paper_example(steps=3, residual=lambda t: 0.0)
    with pytest.raises(InputError, match="residual"):
        s.to_dict()


def test_from_toml_is_from_dict(tmp_path):
    text = (ROOT / "examples" / "scenarios" / "paper.toml").read_text()
    p = tmp_path / "s.toml"
    p.write_text(text)
    import tomllib

    assert Scenario.from_toml(p).to_dict() == Scenario.from_dict(
        tomllib.loads(text), base=tmp_path).to_dict()


def test_results_pickle():
    import networkx as nx

    tr = rescon.simulate(Scenario.paper_example(steps=5, check_robustness=False),
                         progress=False)
    tr2 = pickle.loads(pickle.dumps(tr))
    np.testing.assert_array_equal(tr2.metrics["diameter"], tr.metrics["diameter"])
    rep = rescon.robustness(nx.complete_graph(5).to_directed())
    assert pickle.loads(pickle.dumps(rep)).r_max == rep.r_max == 3
    X = np.array([[0.0, 0], [1, 0], [0, 1], [1, 1], [0.5, 0.5]])
    k = rescon.safe_kernel(X, 1)
    k2 = pickle.loads(pickle.dumps(k))
    np.testing.assert_array_equal(k2.vertices, k.vertices)


def test_steps_to_consensus_definition():
    d = np.array([4.0, 2.0, 5e-6, 4e-6, 0.0])  # ε · diameter(t_0) = 4e-6 at ε = 1e-6
    assert steps_to_consensus(d, 1e-6) == 3
    assert steps_to_consensus(d, 1e-3) == 2
    assert steps_to_consensus(np.array([0.0, 0.0]), 1e-6) == 0
    assert steps_to_consensus(np.array([1.0, np.nan, 0.5]), 1e-6) is None


# ---------------------------------------------------------------- grids and cells


@pytest.mark.parametrize("grid, match", [
    ({"base": {}, "axes": {}, "runs": {}}, "unknown keys"),
    ({"axes": {"scenario.policy": []}}, "non-empty list"),
    ({"axes": {"policy": ["hold"]}}, "dotted key"),
    ({"axes": {"nosuch.x": [1]}}, "dotted key"),
    ({"base": {"scenarios": {}}}, "unknown tables"),
    ({"run": {"repetitions": 0}}, "repetitions"),
    ({"run": {"seeds": 3}}, "unknown keys"),
    ({"axes": {"scenario.polcy": ["hold"]}}, r"unknown keys \['polcy'\] in scenario"),
    ({"base": {"graph": {"generator": "circulant", "degree": 3}}}, "unknown keys"),
    ({"axes": {"graph.generator": ["circulant", "nosuch"]}},
     r"unknown generators \['nosuch'\] \(available: ba_robust, directed_growth"),
    ({"run": {"kind": "robustnes"}}, "kind must be one of consensus, robustness, kernel"),
    ({"run": {"kind": "robustness"}, "base": {"scenario": {}}}, "unknown tables"),
    ({"run": {"kind": "robustness"}, "axes": {"scenario.F": [1]}}, "dotted key"),
    ({"run": {"kind": "kernel"}, "axes": {"kernel.f": [1]}}, r"unknown keys \['f'\]"),
    ({"run": {"kind": "kernel"}, "axes": {"points.generator": ["cube"]}},
     "available: gaussian, uniform, sphere"),
])
def test_bad_grid_is_one_line_input_error(grid, match):
    with pytest.raises(InputError, match=match) as exc:
        read_grid(grid)
    assert "\n" not in str(exc.value)


def test_failing_cell_is_recorded_and_others_run():
    grid = {"base": GRID8["base"], "axes": {"scenario.F": [2, 50]}}
    t = rescon.sweep(grid, workers=0)
    assert list(t["status"]) == ["ok", "failed"]
    assert pd.isna(t["error"][0])
    assert t["error"][1].startswith("InputError: ") and "F = 50" in t["error"][1]
    assert pd.isna(t["final_diameter"][1]) and t["final_diameter"][0] >= 0


def test_rmdo_cell_with_expression_costs():
    base = {"scenario": {"F": 1, "steps": 30, "check_robustness": False},
            "graph": {"edges": [[u, v] for u in range(5) for v in range(5) if u != v]},
            "initial": {str(v): [float(v), -float(v)] for v in range(5)},
            "adversaries": {"4": {"kind": "constant", "value": [50.0, 50.0]}},
            "costs": {str(v): "(x1 - 1)^2 + (x2 + 2)^2" for v in range(4)}}
    t = rescon.sweep({"base": base, "axes": {"scenario.policy": ["hold", "drop"]}},
                     workers=0)
    assert list(t["status"]) == ["ok", "ok"], list(t["error"])
    assert (t["final_gap"] >= 0).all() and (t["final_gap"] < 1).all()
    assert (t["rescon_version"] == rescon.__version__).all()


def test_seed_is_base_seed_plus_repetition():
    g = read_grid({"base": {"scenario": {"seed": 10}}, "axes": {"scenario.seed": [0, 100]},
                   "run": {"repetitions": 2}})
    assert [c["seed"] for c in g.cells()] == [0, 1, 100, 101]
    assert read_grid({"run": {"repetitions": 3}}).cells()[2]["seed"] == 2


# ---------------------------------------------------------------- output directory


def test_resume_skips_finished_cells(tmp_path, monkeypatch, serial8):
    out = tmp_path / "run"
    first = rescon.sweep(GRID8, workers=0, out=out)
    _same_rows(first, serial8)
    stored = pd.read_parquet(out / "results.parquet")
    _same_rows(stored, serial8)
    # an interrupted sweep: two cells' parts and the consolidated table are missing
    for k in (1, 6):
        (out / "parts" / f"cell-{k:06d}.parquet").unlink()
    (out / "results.parquet").unlink()
    ran = []
    real = cell_mod.run_cell
    monkeypatch.setattr(run_mod, "run_cell", lambda c: ran.append(c["cell"]) or real(c))
    again = rescon.sweep(GRID8, workers=0, out=out)
    assert sorted(ran) == [1, 6]
    _same_rows(again, serial8)
    _same_rows(pd.read_parquet(out / "results.parquet"), serial8)
    assert (out / "summary.png").stat().st_size > 0


def test_axes_of_mixed_or_nested_values_are_json_columns(tmp_path):
    grid = {"base": GRID8["base"],
            "axes": {"scenario.residual": ["none", 0.5],
                     "scenario.alpha": [{"3": 0.4, "1": 0.6}]}}
    t = rescon.sweep(grid, workers=0, out=tmp_path / "mixed")
    assert list(t["scenario.residual"]) == ['"none"', "0.5"]
    assert t["scenario.alpha"][0] == '{"1": 0.6, "3": 0.4}'
    assert (t["status"] == "ok").all(), list(t["error"])
    _same_rows(pd.read_parquet(tmp_path / "mixed" / "results.parquet"), t)


def test_changed_grid_is_refused(tmp_path):
    out = tmp_path / "run"
    small = {"base": GRID8["base"], "axes": {"scenario.policy": ["hold"]}}
    rescon.sweep(small, workers=0, out=out)
    changed = {"base": GRID8["base"], "axes": {"scenario.policy": ["hold", "zero"]}}
    with pytest.raises(InputError, match="another grid"):
        rescon.sweep(changed, workers=0, out=out)
    assert len(pd.read_parquet(out / "results.parquet")) == 1


def test_out_that_is_a_file_is_refused(tmp_path):
    f = tmp_path / "file"
    f.write_text("x")
    with pytest.raises(InputError):
        rescon.sweep(GRID8, workers=0, out=f)


def test_cli_small_example(tmp_path, capsys):
    out = tmp_path / "small"
    assert main(["sweep", str(SMALL), "--workers", "0", "--out", str(out), "--json"]) == 0
    import json

    res = json.loads(capsys.readouterr().out)
    assert res["cells"] == 12 and res["ok"] == 12 and res["failed"] == 0
    t = pd.read_parquet(out / "results.parquet")
    assert set(t["scenario.policy"]) == {"hold", "zero", "drop"}
    hold = t[t["scenario.policy"] == "hold"]
    assert hold["steps_to_consensus"].notna().all()
    bad = tmp_path / "bad.toml"
    bad.write_text('[axes]\n"scenario.policy" = []\n')
    assert main(["sweep", str(bad), "--workers", "0", "--out", str(tmp_path / "b")]) == 2
    assert "non-empty list" in capsys.readouterr().err


# ---------------------------------------------------------------- real Dask clusters


@pytest.mark.slow
def test_local_cluster_two_workers_gives_the_serial_rows(serial8, tmp_path):
    _same_rows(rescon.sweep(GRID8, workers=2, out=tmp_path / "lc"), serial8)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture
def dask_cluster(tmp_path):
    """`dask scheduler` and `dask worker` as separate processes on 127.0.0.1."""
    dask = shutil.which("dask", path=str(Path(sys.executable).parent))
    if dask is None:
        pytest.fail("the `dask` command of dask[distributed] is not installed")
    address = f"tcp://127.0.0.1:{_free_port()}"
    procs = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port",
                               address.rsplit(":", 1)[1], "--no-dashboard"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        procs.append(subprocess.Popen(
            [dask, "worker", address, "--nworkers", "1", "--nthreads", "1",
             "--no-dashboard", "--local-directory", str(tmp_path / "worker")],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT))
        from distributed import Client

        deadline = time.monotonic() + 60
        while True:
            try:
                with Client(address, timeout=5) as c:
                    c.wait_for_workers(1, timeout=60)
                break
            except OSError:
                if time.monotonic() > deadline:
                    raise
                time.sleep(0.5)
        yield address
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(timeout=5)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


@pytest.mark.slow
def test_separate_scheduler_and_worker_give_the_serial_rows(serial8, dask_cluster):
    _same_rows(rescon.sweep(GRID8, scheduler=dask_cluster), serial8)


@pytest.mark.slow
def test_unreachable_scheduler_is_a_clear_error_within_seconds():
    t0 = time.monotonic()
    with pytest.raises(InputError, match="cannot connect"):
        rescon.sweep(GRID8, scheduler=f"tcp://127.0.0.1:{_free_port()}")
    assert time.monotonic() - t0 < 20


# ---------------------------------------------------------- generated graphs and states

#: a scenario on a generated graph with seeded uniform initial states
GENERATED = {"scenario": {"F": 1, "steps": 20, "check_robustness": False, "seed": 5},
             "graph": {"generator": "ba_robust", "n": 12, "m": 4},
             "initial": {"random": {"low": [0.0, -1.0], "high": [10.0, 1.0]}},
             "adversaries": {"0": {"kind": "constant", "value": [50.0, 50.0]}}}


def _with(table: str, **changes) -> dict:
    return {**GENERATED, table: {**GENERATED[table], **changes}}


def test_generated_graph_and_random_states_follow_the_seed():
    from rescon.graphs.generators import ba_robust

    s = Scenario.from_dict(GENERATED)
    G = ba_robust(12, 4, seed=np.random.default_rng([5, 1]))
    assert set(s.graph.edges) == set(G.to_directed().edges)
    assert s.x0.shape == (12, 2)
    assert (s.x0 >= [0.0, -1.0]).all() and (s.x0 <= [10.0, 1.0]).all()
    again = Scenario.from_dict(GENERATED)
    assert again.to_dict() == s.to_dict()
    other = Scenario.from_dict(_with("scenario", seed=6))
    assert set(other.graph.edges) != set(s.graph.edges)
    assert not np.array_equal(other.x0, s.x0)
    pinned = Scenario.from_dict(_with("graph", seed=5) | {"scenario": {
        **GENERATED["scenario"], "seed": 6}})
    assert set(pinned.graph.edges) == set(s.graph.edges)  # graph.seed wins
    assert Scenario.from_dict(s.to_dict()).to_dict() == s.to_dict()
    assert rescon.simulate(s, progress=False).final_diameter < 1.0


@pytest.mark.parametrize("generator, n, extra, rho", [
    ("circulant", 12, {"k": 3}, 3), ("two_cliques", 10, {"b": 2}, 2),
    ("directed_growth", 9, {"k": 2}, 2), ("complete", 6, {}, 3),
    ("erdos_renyi", 8, {"p": 1.0, "directed": True}, 4),
    ("random_geometric", 8, {"radius": 2.0, "dim": 3}, 4),
])
def test_every_generator_builds_its_graph(generator, n, extra, rho):
    s = Scenario.from_dict({**GENERATED, "graph": {"generator": generator, "n": n, **extra}})
    assert s.graph.number_of_nodes() == n
    assert rescon.robustness(s.graph, progress=False).r_max == rho


@pytest.mark.parametrize("graph, match", [
    ({"generator": "barabasi"}, r"\[graph\]: generator must be one of ba_robust, "
                                "directed_growth, circulant, two_cliques, erdos_renyi"),
    ({"generator": "circulant", "n": 10}, "generator 'circulant' needs k"),
    ({"generator": "circulant", "n": 10, "k": 2, "m": 2},
     r"\['m'\] are not parameters of generator 'circulant' \(it takes n, k, directed\)"),
    ({"generator": "erdos_renyi", "n": 10, "p": 1.5}, "p must be a probability"),
    ({"generator": "two_cliques", "n": 9, "b": 2}, "n must be even"),
    ({"generator": "ba_robust", "n": 3, "m": 3}, "ba_robust: n must be an integer >= 5"),
    ({"generator": "circulant", "n": 10, "k": 2, "directed": "yes"}, "directed must be true"),
    ({"generator": "circulant", "n": 10, "circulant": 2}, "circulant must be a table"),
    ({"generator": "complete", "n": 5, "undirected": True}, "not parameters"),
])
def test_bad_generator_is_one_line_error_naming_the_key(graph, match):
    with pytest.raises(InputError, match=match) as exc:
        Scenario.from_dict({**GENERATED, "graph": graph})
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("random, match", [
    ({"low": 0.0}, "needs low and high"),
    ({"low": [0.0, 0.0], "high": [1.0, 1.0, 1.0]}, "same length d"),
    ({"low": 1.0, "high": 0.0}, "finite low <= high"),
    ({"low": 0.0, "high": 1.0, "d": 0}, "d must be an integer >= 1"),
    ({"low": 0.0, "high": 1.0, "size": 3}, r"unknown keys \['size'\]"),
])
def test_bad_random_states_are_one_line_errors(random, match):
    with pytest.raises(InputError, match=match) as exc:
        Scenario.from_dict({**GENERATED, "initial": {"random": random}})
    assert "\n" not in str(exc.value)


# -------------------------------------------------- generator, robustness and kernel grids

#: consensus cells over graph generators (each with its own parameters) and sizes
GEN = {"base": {"scenario": {"F": 1, "steps": 20, "check_robustness": False},
                "graph": {"generator": "ba_robust", "n": 12, "ba_robust": {"m": 4},
                          "circulant": {"k": 4}, "erdos_renyi": {"p": 0.8}},
                "initial": {"random": {"low": 0.0, "high": 10.0, "d": 2}},
                "adversaries": {"0": {"kind": "constant", "value": [50.0, 50.0]}}},
       "axes": {"graph.generator": ["ba_robust", "circulant", "erdos_renyi"],
                "graph.n": [10, 14]},
       "run": {"epsilon": 0.01}}
#: robustness cells: no graph twice (a rho cached by an earlier cell in the same process
#: makes the method "bounds"), the search forced (the auto race's winner is timing)
ROB = {"run": {"kind": "robustness"},
       "base": {"graph": {"generator": "ba_robust", "n": 12, "ba_robust": {"m": 3},
                          "circulant": {"k": 3}, "erdos_renyi": {"p": 0.5, "directed": True},
                          "seed": 7},
                "robustness": {"method": "search"}},
       "axes": {"graph.generator": ["ba_robust", "circulant", "erdos_renyi"],
                "graph.n": [9, 13]}}
#: kernel cells over the three clouds, sizes, dimensions and F (F = 13 >= n fails)
KER = {"run": {"kind": "kernel"},
       "base": {"points": {"generator": "gaussian", "n": 12, "d": 2}, "kernel": {"F": 1}},
       "axes": {"points.generator": ["gaussian", "sphere", "uniform"],
                "points.n": [8, 13], "points.d": [2, 3], "kernel.F": [1, 2, 13]}}
ROB_COLUMNS = ("rho", "s_star", "exact", "method", "certificate_valid", "certificate_verdict")
KER_COLUMNS = ("dim", "is_empty", "n_vertices", "certificate_valid", "certificate_verdict")
CON_COLUMNS = ("final_diameter", "max_validity", "steps_to_consensus", "blocked_links")


@pytest.fixture(scope="module")
def kinds_out(tmp_path_factory) -> Path:
    return tmp_path_factory.mktemp("kinds")


@pytest.fixture(scope="module")
def serial_kinds(kinds_out) -> dict[str, pd.DataFrame]:
    return {name: rescon.sweep(g, workers=0, out=kinds_out / name)
            for name, g in (("gen", GEN), ("rob", ROB), ("ker", KER))}


def test_generator_axes_give_consensus_rows(serial_kinds):
    t = serial_kinds["gen"]
    assert len(t) == 6 and (t["status"] == "ok").all(), list(t["error"])
    assert list(t["graph.n"]) == [10, 14] * 3
    assert t[list(CON_COLUMNS)].notna().all().all()
    assert t[[*ROB_COLUMNS, "dim", "is_empty", "n_vertices"]].isna().all().all()


def test_robustness_rows_are_exact_and_certified(serial_kinds):
    from rescon.graphs.named import generate

    t = serial_kinds["rob"]
    assert (t["status"] == "ok").all(), list(t["error"])
    assert t["exact"].all() and t["certificate_valid"].all()
    assert (t["certificate_verdict"] == "valid").all()
    for _, row in t.iterrows():
        G = generate({**ROB["base"]["graph"], "generator": row["graph.generator"],
                      "n": int(row["graph.n"])}, 0)
        if "rho" in G.graph:  # the structured generators know their rho
            assert row["rho"] == G.graph["rho"]
        assert row["rho"] == rescon.robustness(G, progress=False).r_max
    assert t[list(CON_COLUMNS)].isna().all().all()


def test_kernel_rows_and_a_failing_cell(serial_kinds):
    t = serial_kinds["ker"]
    bad = t["kernel.F"] == 13
    assert (t["status"][~bad] == "ok").all(), list(t["error"][~bad])
    assert (t["status"][bad] == "failed").all()
    assert t["error"][bad].str.startswith("InputError: F").all()
    ok = t[~bad]
    assert (ok["is_empty"] == (ok["dim"] == -1)).all()
    assert (ok["is_empty"] == (ok["n_vertices"] == 0)).all()
    helly = ok["points.n"] >= (ok["points.d"] + 1) * ok["kernel.F"] + 1
    assert not ok["is_empty"][helly].any()  # Helly: non-empty from (d+1)F+1 points on
    assert (ok["certificate_verdict"] == "valid").all()
    assert t[list(ROB_COLUMNS[:4])].isna().all().all()


def test_every_kind_writes_its_summary_plot(serial_kinds, kinds_out):
    for name in serial_kinds:
        assert (kinds_out / name / "summary.png").stat().st_size > 10_000


def test_robustness_example_grid():
    t = rescon.sweep(ROOT / "examples" / "sweeps" / "robustness.toml", workers=0)
    assert len(t) == 24 and (t["status"] == "ok").all(), list(t["error"])
    assert t["exact"].all() and (t["certificate_verdict"] == "valid").all()


def test_generated_example_grid():
    t = rescon.sweep(ROOT / "examples" / "sweeps" / "generated.toml", workers=0)
    assert len(t) == 18 and (t["status"] == "ok").all(), list(t["error"])
    assert (t["max_validity"] == 0).all()  # no residual: the benign hull is kept
    assert set(t["graph.generator"]) == {"ba_robust", "circulant", "random_geometric"}


def test_cli_simulates_a_scenario_file_with_a_generated_graph(tmp_path, capsys):
    import json

    p = tmp_path / "gen.toml"
    p.write_text('[scenario]\nF = 1\nsteps = 10\nseed = 4\n\n[graph]\n'
                 'generator = "circulant"\nn = 10\n\n[graph.circulant]\nk = 3\n\n'
                 '[initial.random]\nlow = [0.0, 0.0]\nhigh = [10.0, 10.0]\n')
    assert main(["simulate", str(p), "--json", "--quiet"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["N"] == 10 and res["d"] == 2 and res["final_diameter"] < 1


@pytest.mark.slow
def test_every_kind_on_two_workers_gives_the_serial_rows(serial_kinds, cluster):
    for name, g in (("gen", GEN), ("rob", ROB), ("ker", KER)):
        _same_rows(rescon.sweep(g, scheduler=cluster), serial_kinds[name])


# ---------------------------------------------------------------- progress and bad input


def test_progress_bar_on_stderr_only_when_asked(capsys):
    grid = {"base": GRID8["base"], "axes": {"scenario.policy": ["hold", "zero"]}}
    rescon.sweep(grid, workers=0, progress=True)
    out, err = capsys.readouterr()
    # the bar is drawn at 0/2 and at most every 0.1 s after (tqdm's mininterval), then
    # cleared: cells faster than that (the paper's example since the exact planar
    # fallback) never show 2/2
    assert out == "" and "sweep" in err and "/2 [" in err and "cell" in err
    rescon.sweep(grid, workers=0, progress=False)
    assert capsys.readouterr() == ("", "")


def test_cli_bad_inputs_are_one_line(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["sweep", str(SMALL), "--workers", "0", "--out", str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert "out" in err and "not a directory" in err and "\n" not in err
    bad = tmp_path / "bad.toml"
    bad.write_text('[axes]\n"graph.generator" = ["ba"]\n')
    assert main(["sweep", str(bad), "--workers", "0", "--out", str(tmp_path / "b")]) == 2
    err = capsys.readouterr().err.strip()
    assert "unknown generators ['ba']" in err and "\n" not in err


def test_dotted_axis_keys_reach_nested_tables():
    """As TOML reads a.b.c = v: "graph.circulant.k" sets [graph.circulant] k."""
    g = read_grid({"base": {"graph": {"generator": "circulant", "n": 10,
                                      "circulant": {"k": 4, "directed": True}},
                            "initial": {"random": {"low": 0.0, "high": 1.0}}},
                   "axes": {"graph.circulant.k": [2, 3], "initial.random.d": [3]}})
    specs = [c["spec"] for c in g.cells()]
    assert [s["graph"]["circulant"] for s in specs] == [{"k": 2, "directed": True},
                                                        {"k": 3, "directed": True}]
    assert specs[0]["initial"]["random"] == {"low": 0.0, "high": 1.0, "d": 3}


def test_without_matplotlib_the_rows_are_written_and_no_summary(tmp_path, monkeypatch):
    """summary.png goes through rescon.plot.pyplot; a missing matplotlib skips only it."""
    import rescon.plot as plot_mod
    from rescon.errors import MissingDependency

    def missing() -> None:
        raise MissingDependency("matplotlib is not installed")

    monkeypatch.setattr(plot_mod, "_require_matplotlib", missing)
    grid = {**GRID8, "axes": {"scenario.policy": ["hold"]}}
    rows = rescon.sweep(grid, workers=0, out=tmp_path / "out", progress=False)
    assert len(rows) == 2 and (tmp_path / "out" / "results.parquet").exists()
    assert not (tmp_path / "out" / "summary.png").exists()
