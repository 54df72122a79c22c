"""Review V25 (hostile): experiment sweeps, their Dask execution and ``rescon paper``.

Attacked, as a hostile user reaches them: grid files at the edges (an empty grid, one
point, duplicate points, 10^5 points, unknown keys, wrong types — a list where a name
goes, a non-string axis key —, booleans for integers, NaN/inf, seeds at the int64
edge, unicode paths, malformed TOML bytes), output directories (a file, a path under a
file, a path that cannot be created, a leftover ``results.parquet`` directory, a
``grid.json`` of another grid or of garbage, a corrupt part file), ``--scheduler``
addresses (malformed, not a string, empty, something that answers HTTP), both a
scheduler and a worker count, a LocalCluster of 1 worker (``--json`` purity, rows equal
to the serial run), 2 workers with one killed mid-sweep (nanny restarts it), the only
worker of a scheduler killed mid-sweep (no nanny), reruns into an existing output (full
and partial resume give the fresh table, dtypes included), the table's dtypes and
Parquet schema for all-ok vs mixed outcomes, a KilledWorker row on resume, dask missing
(``sys.modules[name] = None`` as tests/test_review_v14.py does) for ``sweep`` and for
``rescon paper`` (``--json``, twice in a row, into a directory that cannot be made).

Every Dask service here is on loopback and started by the test (LocalCluster, or
``dask scheduler`` / ``dask worker`` processes killed in a ``finally``).
"""

from __future__ import annotations

import http.server
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

import rescon
from rescon import InputError
from rescon.cli import main
from rescon.errors import MissingDependency
from rescon.sweep import run as run_mod
from rescon.sweep.cell import failed_row
from rescon.sweep.grid import read_grid

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent

#: the paper's example, 5 steps (a cell takes well under a second)
BASE = {"scenario": {"paper_example": True, "steps": 5, "check_robustness": False}}
GRID2 = {"base": BASE, "axes": {"scenario.policy": ["hold", "zero"]}}

GRID2_TOML = """\
[base.scenario]
paper_example = true
steps = 5
check_robustness = false
[axes]
"scenario.policy" = ["hold", "zero"]
"""


def _same_rows(a: pd.DataFrame, b: pd.DataFrame) -> None:
    cols = [c for c in a.columns if c != "seconds"]
    assert list(a.columns) == list(b.columns)
    pd.testing.assert_frame_equal(a[cols].reset_index(drop=True),
                                  b[cols].reset_index(drop=True))


def _one_line_error(capsys) -> str:
    """stderr of a failed CLI call: one line, no traceback; stdout empty."""
    cap = capsys.readouterr()
    assert cap.out == ""
    assert "Traceback" not in cap.err
    assert cap.err.count("\n") == 1 and cap.err.startswith("rescon: error: ")
    return cap.err


@pytest.fixture(scope="module")
def serial2() -> pd.DataFrame:
    return rescon.sweep(GRID2, workers=0)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


# ======================================== bugs (strict xfails at first; all fixed)


# Fixed (was a bug: [run] kind = [...] (a list) is tested with `kind not in KINDS` on a
# dict: TypeError unhashable, a traceback)
def test_run_kind_that_is_not_a_name_is_a_one_line_error(tmp_path, capsys):
    grid = tmp_path / "g.toml"
    grid.write_text('[run]\nkind = ["consensus"]\n' + GRID2_TOML, encoding="utf-8")
    try:
        code = main(["sweep", str(grid), "--workers", "0", "--out", str(tmp_path / "o")])
    except TypeError:
        code = "traceback"
    assert code == 2
    assert "kind" in _one_line_error(capsys)


# Fixed (was a bug: a non-string axis key in a dict grid reaches key.partition:
# AttributeError instead of the documented InputError)
def test_non_string_axis_key_is_an_input_error():
    with pytest.raises(InputError):
        read_grid({"base": BASE, "axes": {1: [1, 2]}})


# Fixed (was a bug: a corrupt parts/cell-*.parquet (or a stray cell-abc.parquet) makes the
# rerun die in _finished with a pyarrow ArrowInvalid / ValueError traceback (exit 1))
@pytest.mark.parametrize("damage", ["truncated", "bad_name"])
def test_corrupt_part_file_on_rerun_is_not_a_traceback(tmp_path, capsys, damage):
    grid = tmp_path / "g.toml"
    grid.write_text(GRID2_TOML, encoding="utf-8")
    out = tmp_path / "o"
    assert main(["sweep", str(grid), "--workers", "0", "--out", str(out), "-q"]) == 0
    capsys.readouterr()
    if damage == "truncated":
        (out / "parts" / "cell-000001.parquet").write_bytes(b"garbage")
    else:
        (out / "parts" / "cell-abc.parquet").write_bytes(b"")
    try:
        code = main(["sweep", str(grid), "--workers", "0", "--out", str(out), "--json"])
    except Exception as exc:  # noqa: BLE001 (what escapes is the bug)
        code = f"traceback: {type(exc).__name__}"
    if code == 0:  # recomputing the damaged cell is a fine answer too
        assert json.loads(capsys.readouterr().out)["ok"] == 2
    else:
        assert code == 2
        _one_line_error(capsys)


# Fixed (was a bug: scenario.seed = 2**63 - 1 (TOML's largest integer) with 2 repetitions:
# the grid is accepted and the cells run, then _write_part's pa.Table.from_pylist raises
# OverflowError on seed 2**63 — with out=None the same grid succeeds)
def test_seed_at_the_int64_edge_is_stored_or_refused_before_any_work(tmp_path):
    grid = {"base": {"scenario": {**BASE["scenario"], "seed": 2**63 - 1}},
            "axes": {"scenario.policy": ["hold"]}, "run": {"repetitions": 2}}
    assert list(rescon.sweep(grid, workers=0)["seed"]) == [2**63 - 1, 2**63]
    out = tmp_path / "o"
    try:
        table = rescon.sweep(grid, workers=0, out=out)
    except InputError as exc:  # refused up front: no cell ran, named seed
        assert "seed" in str(exc)
        assert not list((out / "parts").glob("*.parquet"))
    else:
        assert list(table["seed"]) == [2**63 - 1, 2**63]


# Fixed (was a bug: _frame fixes numeric dtypes only: `error` is object (Parquet null) when
# every cell is ok and str (large_string) when one failed, so two results.parquet do not
# concatenate)
def test_table_dtypes_and_schema_do_not_depend_on_outcomes(tmp_path):
    import pyarrow as pa
    import pyarrow.parquet as pq

    all_ok = rescon.sweep({"base": BASE, "axes": {"scenario.policy": ["hold"]}},
                          workers=0, out=tmp_path / "ok")
    mixed = rescon.sweep({"base": BASE, "axes": {"scenario.policy": ["hold", "nope"]}},
                         workers=0, out=tmp_path / "mixed")
    assert list(mixed["status"]) == ["ok", "failed"]
    assert all_ok.dtypes.to_dict() == mixed.dtypes.to_dict()
    pa.concat_tables([pq.read_table(tmp_path / "ok" / "results.parquet"),
                      pq.read_table(tmp_path / "mixed" / "results.parquet")])


# Fixed (was a bug: a KilledWorker row (the worker died, the cell never finished) is written
# as a part like a real result, so every rerun skips it: a transient cluster failure becomes
# permanent)
def test_a_killed_worker_row_is_recomputed_on_rerun(tmp_path, monkeypatch):
    from types import SimpleNamespace

    from distributed import KilledWorker

    real = run_mod._execute
    died = KilledWorker("run_cell-0", SimpleNamespace(address="tcp://127.0.0.1:1"), 3)

    def dying(cells, scheduler, workers):  # the first cell's worker died (3 times)
        for c in cells:
            if c["cell"] == 0:
                yield {"cell": 0, **failed_row(c, died)}
            else:
                yield from real([c], scheduler, workers)

    monkeypatch.setattr(run_mod, "_execute", dying)
    first = rescon.sweep(GRID2, workers=0, out=tmp_path / "o")
    assert first["status"].tolist() == ["failed", "ok"]
    assert first["error"][0].startswith("KilledWorker")
    monkeypatch.setattr(run_mod, "_execute", real)
    again = rescon.sweep(GRID2, workers=0, out=tmp_path / "o")
    assert again["status"].tolist() == ["ok", "ok"]


_DEAD_WORKER = """\
import sys
import rescon._dask
rescon._dask.WORKER_SECONDS = 3  # the documented guard's wait, shortened for the test
from rescon.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.mark.slow
# Fixed (was a bug: the only worker of a scheduler dies mid-sweep (no nanny): _execute waits
# in as_completed forever — no failed rows, no error (graphs/distributed.py's _Workers guard
# is not used here))
def test_sweep_whose_last_worker_dies_ends(tmp_path):
    dask = shutil.which("dask", path=str(BIN))
    assert dask is not None
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    grid = tmp_path / "g.toml"  # 6 cells of ~1 s
    grid.write_text(GRID2_TOML.replace("steps = 5", "steps = 60")
                    + "[run]\nrepetitions = 3\n", encoding="utf-8")
    out = tmp_path / "o"
    procs = []
    try:
        procs.append(subprocess.Popen(
            [dask, "scheduler", "--host", "127.0.0.1", "--port", str(port),
             "--no-dashboard"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        worker = subprocess.Popen(
            [dask, "worker", address, "--no-nanny", "--nthreads", "1", "--no-dashboard",
             "--local-directory", str(tmp_path / "w")],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, cwd=ROOT)
        procs.append(worker)
        sweep = subprocess.Popen(
            [sys.executable, "-c", _DEAD_WORKER, "sweep", str(grid), "--scheduler",
             address, "--out", str(out), "--json"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=ROOT)
        procs.append(sweep)
        deadline = time.monotonic() + 90
        while not list((out / "parts").glob("cell-*.parquet")):
            assert sweep.poll() is None and time.monotonic() < deadline
            time.sleep(0.2)
        worker.kill()
        try:
            stdout, stderr = sweep.communicate(timeout=40)
        except subprocess.TimeoutExpired:
            pytest.fail("the sweep still waits 40 s after its last worker died")
        assert "Traceback" not in stderr
        if sweep.returncode == 0:  # every row, the lost ones as failed rows
            assert json.loads(stdout)["cells"] == 6
        else:
            assert sweep.returncode == 2 and stderr.count("\n") == 1
    finally:
        for p in reversed(procs):
            if p.poll() is None:
                p.kill()
            p.communicate() if p.stdout else p.wait()


# Fixed (was a bug: no bound on a grid's size: [run] repetitions = 1000000000 (a typo) is
# accepted; Grid.cells' itertools.product materialises range(10**9) (8 GB of pointers)
# before any check — under a 3 GB limit 'the input is out of range (MemoryError: (no
# message))' naming nothing, without one the machine swaps or OOM-kills)
def test_a_grid_of_a_billion_cells_is_refused_when_read(tmp_path):
    grid = tmp_path / "g.toml"
    grid.write_text(GRID2_TOML + "[run]\nrepetitions = 1000000000\n", encoding="utf-8")
    code = ("import resource, sys\n"
            "resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))\n"
            "from rescon.cli import main\nsys.exit(main(sys.argv[1:]))")
    try:
        p = subprocess.run([sys.executable, "-c", code, "sweep", str(grid), "--workers",
                            "0", "--out", str(tmp_path / "o")],
                           capture_output=True, text=True, timeout=30)
    except subprocess.TimeoutExpired:
        pytest.fail("still building cells after 30 s")
    assert p.returncode == 2
    assert "repetitions" in p.stderr or "cells" in p.stderr


_SILENT = """\
import socket, sys
srv = socket.socket()
srv.bind(("127.0.0.1", 0))
srv.listen(5)  # accepts (the kernel's backlog) and never says a word
from rescon.cli import main
sys.exit(main(["sweep", sys.argv[1], "--scheduler",
               f"tcp://127.0.0.1:{srv.getsockname()[1]}", "--out", sys.argv[2]]))
"""


@pytest.mark.slow
# Fixed (was a bug: a --scheduler address where a TCP peer accepts but never answers (a
# tarpit, python -m http.server waiting for a line): Client(address,
# timeout=CONNECT_SECONDS) blocks in its handshake forever — no 'cannot connect' after 5 s)
def test_a_scheduler_that_accepts_and_stays_silent_times_out(tmp_path):
    grid = tmp_path / "g.toml"
    grid.write_text(GRID2_TOML, encoding="utf-8")
    t0 = time.monotonic()
    try:
        p = subprocess.run([sys.executable, "-c", _SILENT, str(grid), str(tmp_path / "o")],
                           capture_output=True, text=True, timeout=20)
    except subprocess.TimeoutExpired:
        pytest.fail("rescon sweep still connecting after 20 s")
    assert p.returncode == 2 and "cannot connect" in p.stderr
    assert time.monotonic() - t0 < 15


# =================================================================== attacks that held


@pytest.mark.parametrize("grid, match", [
    ({"base": BASE, "run": {"repetitions": True}}, "repetitions"),
    ({"base": BASE, "run": {"epsilon": True}}, "epsilon"),
    ({"base": BASE, "run": {"epsilon": float("nan")}}, "epsilon"),
    ({"base": BASE, "axes": {"scenario.steps": [5, float("inf")]}}, "plain data"),
    ({"base": BASE, "axes": {"scenario.alpha": [float("nan")]}}, "plain data"),
    ({"base": BASE, "axes": {"scenario.policy": []}}, "non-empty list"),
    ({"base": BASE, "axes": {"scenario.policy": "hold"}}, "non-empty list"),
    ({"base": BASE, "axes": {"scenario.polcy": ["hold"]}}, "unknown keys"),
    ({"base": BASE, "run": {"repetitons": 2}}, "unknown keys"),
    ({"base": {**BASE, "extra": {}}}, "unknown tables"),
    ({"base": BASE, "axis": {}}, "unknown keys"),
    ({"base": BASE, "run": {"kind": "kernels"}}, "kind must be one of"),
    ([1, 2], "TOML file name or a dict"),
])
def test_bad_grids_are_input_errors(grid, match):
    with pytest.raises(InputError, match=match):
        rescon.sweep(grid, workers=0)


@pytest.mark.parametrize("scheduler, match", [
    ("", "must be an address"), (5, "must be an address"),
    ("not an address", "cannot connect"), ("tcp://127.0.0.1:notaport", "cannot connect"),
])
def test_malformed_scheduler_addresses_are_refused_at_once(scheduler, match):
    t0 = time.monotonic()
    with pytest.raises(InputError, match=match):
        rescon.sweep(GRID2, scheduler=scheduler)
    assert time.monotonic() - t0 < 5


def test_scheduler_and_workers_together_or_bad_counts_are_refused(capsys):
    for kw in ({"scheduler": "tcp://127.0.0.1:1", "workers": 0}, {"workers": True},
               {"workers": -1}, {"workers": 2.0}):
        with pytest.raises(InputError, match="workers"):
            rescon.sweep(GRID2, **kw)


class _Answers(http.server.BaseHTTPRequestHandler):
    """Whatever comes, an HTTP 400 at once (a web server at the address)."""

    def handle(self) -> None:
        self.request.recv(1000)
        self.request.sendall(b"HTTP/1.0 400 Bad Request\r\n\r\n")


def test_a_scheduler_address_where_http_answers_fails_fast(tmp_path):
    server = http.server.HTTPServer(("127.0.0.1", 0), _Answers)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        t0 = time.monotonic()
        with pytest.raises(InputError, match="cannot connect"):
            rescon.sweep(GRID2, scheduler=f"tcp://127.0.0.1:{server.server_port}",
                         out=tmp_path / "o")
        assert time.monotonic() - t0 < 5
    finally:
        server.shutdown()
        server.server_close()


def test_without_distributed_serial_sweeps_run_and_clusters_say_install(monkeypatch,
                                                                       serial2):
    monkeypatch.setitem(sys.modules, "dask", None)
    monkeypatch.setitem(sys.modules, "distributed", None)
    _same_rows(rescon.sweep(GRID2, workers=0), serial2)
    with pytest.raises(MissingDependency, match=r"rescon\[dask\]"):
        rescon.sweep(GRID2, workers=1)


def test_output_paths_that_cannot_be_used_are_one_line_errors(tmp_path, capsys):
    grid = tmp_path / "g.toml"
    grid.write_text(GRID2_TOML, encoding="utf-8")
    blocked = tmp_path / "results_dir"
    (blocked / "results.parquet").mkdir(parents=True)
    for out in (str(grid), str(grid / "sub"), "/proc/rescon-v25-cannot-exist", str(blocked)):
        assert main(["sweep", str(grid), "--workers", "0", "--out", out, "--json"]) == 2
        _one_line_error(capsys)
    assert not Path("/proc/rescon-v25-cannot-exist").exists()


def test_grid_files_at_the_edges(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_bytes(b"\xff\xfe[base]\n")
    for path in (tmp_path, tmp_path / "missing.toml", bad):
        assert main(["sweep", str(path), "--workers", "0",
                     "--out", str(tmp_path / "o")]) == 2
        _one_line_error(capsys)
    odd = tmp_path / "ünï cødé ☃ dir" / "grïd ☃.toml"
    odd.parent.mkdir()
    odd.write_text(GRID2_TOML, encoding="utf-8")
    out = odd.parent / "out ü"
    assert main(["sweep", str(odd), "--workers", "0", "--out", str(out), "--json"]) == 0
    got = json.loads(capsys.readouterr().out)
    assert got["cells"] == 2 and Path(got["out"]) == out / "results.parquet"
    assert (out / "results.parquet").is_file()


def test_another_grid_or_garbage_grid_json_is_refused(tmp_path):
    out = tmp_path / "o"
    rescon.sweep(GRID2, workers=0, out=out)
    other = {"base": BASE, "axes": {"scenario.policy": ["zero", "hold"]}}
    with pytest.raises(InputError, match="another grid"):
        rescon.sweep(other, workers=0, out=out)
    for text in ("[1, 2]\n", "not json\n", ""):
        (out / "grid.json").write_text(text, encoding="utf-8")
        with pytest.raises(InputError, match="another grid"):
            rescon.sweep(GRID2, workers=0, out=out)


def test_rerun_full_and_partial_resume_give_the_fresh_table(tmp_path):
    grid = {"base": BASE, "axes": {"scenario.policy": ["hold", "nope"],
                                   "scenario.F": [2, "x"], "scenario.alpha": [0.5, 1]}}
    out = tmp_path / "o"
    fresh = rescon.sweep(grid, workers=0, out=out)
    assert len(fresh) == 8 and set(fresh["status"]) == {"ok", "failed"}
    again = rescon.sweep(grid, workers=0, out=out)  # every cell resumed
    pd.testing.assert_frame_equal(fresh, again)  # seconds too: read back, not rerun
    (out / "parts" / "cell-000003.parquet").unlink()
    partial = rescon.sweep(grid, workers=0, out=out)
    _same_rows(fresh, partial)
    assert (fresh.dtypes == partial.dtypes).all()
    pd.testing.assert_frame_equal(pd.read_parquet(out / "results.parquet")[["status"]],
                                  fresh[["status"]])


def test_empty_grid_one_point_and_duplicate_points(tmp_path):
    empty = rescon.sweep({}, workers=0)  # one cell: the default scenario
    assert len(empty) == 1 and list(empty.columns)[:2] == ["repetition", "seed"]
    dup = rescon.sweep({"base": BASE, "axes": {"scenario.policy": ["hold", "hold"]}},
                       workers=0, out=tmp_path / "dup")
    assert len(dup) == 2 and list(dup["status"]) == ["ok", "ok"]
    assert dup["final_diameter"][0] == dup["final_diameter"][1]
    assert len(list((tmp_path / "dup" / "parts").glob("*.parquet"))) == 2


def test_a_grid_of_ten_thousand_points_is_read_and_numbered_quickly():
    t0 = time.monotonic()
    g = read_grid({"base": BASE, "axes": {"scenario.steps": list(range(1, 100_001))}})
    cells = g.cells()
    assert time.monotonic() - t0 < 5
    assert [c["cell"] for c in cells] == list(range(100_000))
    assert cells[-1]["spec"]["scenario"]["steps"] == 100_000


def test_json_of_a_serial_sweep_in_a_fresh_process_is_clean(tmp_path):
    grid = tmp_path / "g.toml"
    grid.write_text(GRID2_TOML, encoding="utf-8")
    p = subprocess.run([str(BIN / "rescon"), "sweep", str(grid), "--workers", "0",
                        "--out", str(tmp_path / "o"), "--json"],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0 and "Traceback" not in p.stderr
    got = json.loads(p.stdout)
    assert set(got) == {"cells", "ok", "failed", "out", "seconds"}
    assert (got["cells"], got["ok"], got["failed"]) == (2, 2, 0)


@pytest.mark.slow
def test_one_worker_local_cluster_json_is_pure_and_rows_equal_serial(tmp_path, serial2):
    grid = tmp_path / "g.toml"
    grid.write_text(GRID2_TOML, encoding="utf-8")
    p = subprocess.run([str(BIN / "rescon"), "sweep", str(grid), "--workers", "1",
                        "--out", str(tmp_path / "o"), "--json"],
                       capture_output=True, text=True, timeout=180, cwd=tmp_path)
    assert p.returncode == 0 and "Traceback" not in p.stderr
    assert len(p.stdout.splitlines()) == 1
    assert json.loads(p.stdout)["ok"] == 2
    _same_rows(pd.read_parquet(tmp_path / "o" / "results.parquet"), serial2)


@pytest.mark.slow
def test_a_worker_killed_mid_sweep_on_two_workers_loses_no_row(tmp_path, cluster):
    """The conftest LocalCluster (2 workers, nannies): one worker is SIGKILLed while
    the sweep runs; the nanny restarts it and every row comes back."""
    from distributed import Client

    grid = {"base": {"scenario": {**BASE["scenario"], "steps": 40}},
            "axes": {"scenario.policy": ["hold", "zero"]}, "run": {"repetitions": 3}}
    out = tmp_path / "o"
    result: dict = {}

    def run() -> None:
        try:
            result["table"] = rescon.sweep(grid, scheduler=cluster, out=out)
        except Exception as exc:  # noqa: BLE001
            result["error"] = exc

    with Client(cluster) as c:
        pids = c.run(os.getpid)
    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 60
    while not list((out / "parts").glob("cell-*.parquet")) if (out / "parts").exists() \
            else True:
        assert time.monotonic() < deadline and thread.is_alive()
        time.sleep(0.1)
    os.kill(next(iter(pids.values())), signal.SIGKILL)
    thread.join(timeout=120)
    assert not thread.is_alive(), "the sweep hangs after a worker was killed"
    assert "error" not in result, result.get("error")
    table = result["table"]
    assert len(table) == 6 and table["status"].notna().all()
    assert len(list((out / "parts").glob("cell-*.parquet"))) == 6


# ----------------------------------------------------------------------- rescon paper


def test_paper_into_a_directory_that_cannot_be_made_is_one_line(tmp_path, capsys):
    afile = tmp_path / "a_file"
    afile.write_text("x", encoding="utf-8")
    for out in ("/proc/rescon-v25-paper", str(afile), str(afile / "sub")):
        t0 = time.monotonic()
        assert main(["paper", "--out", out, "--json"]) == 2
        assert time.monotonic() - t0 < 5  # refused before any work
        _one_line_error(capsys)


_NO_DASK = ("import sys; sys.modules['dask'] = None; sys.modules['distributed'] = None\n"
            "from rescon.cli import main; sys.exit(main(sys.argv[1:]))")


@pytest.mark.slow
def test_paper_twice_without_dask_json_is_one_object_and_the_same(tmp_path):
    out = tmp_path / "paper ü"
    runs = []
    for _ in range(2):
        p = subprocess.run([sys.executable, "-c", _NO_DASK, "paper", "--out", str(out),
                            "--json"], capture_output=True, text=True, timeout=300)
        assert p.returncode == 0 and "Traceback" not in p.stderr, p.stderr[-2000:]
        assert len(p.stdout.splitlines()) == 1
        runs.append(json.loads(p.stdout))
    a, b = runs
    assert [c["verdict"] for c in a["claims"]] == [c["verdict"] for c in b["claims"]]
    assert a["claims"][0]["verdict"] == "does not hold"
    assert [c["verdict"] for c in a["certificates"]] == \
        [c["verdict"] for c in b["certificates"]]
    assert json.loads((out / "summary.json").read_text(encoding="utf-8"))["claims"] == \
        b["claims"]
