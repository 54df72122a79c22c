"""R5: sweeps and their Dask execution, beyond V25's cases (tests/test_review_v25.py).

Each test failed before its fix: a sweep waiting forever on a cluster without workers
or on a silent scheduler, a corrupt part file's traceback, unhashable or non-string
grid keys, integers beyond int64 found only when a part is written, outcome-dependent
column types, cluster failures stored as results, unbounded grids. Dask services here
are in-process or on loopback, started and stopped by the tests."""

from __future__ import annotations

import socket
import threading
import time
from pathlib import Path

import pandas as pd
import pytest

import rescon
from rescon import InputError
from rescon.errors import SolverError
from rescon.sweep import run as run_mod
from rescon.sweep.grid import MAX_CELLS, read_grid

BASE = {"scenario": {"paper_example": True, "steps": 5, "check_robustness": False}}
GRID2 = {"base": BASE, "axes": {"scenario.policy": ["hold", "zero"]}}


def _within(seconds: float, call):
    """``call()``'s result or exception, failing the test if it takes longer (a hang)."""
    got: list = []

    def run() -> None:
        try:
            got.append(call())
        except BaseException as exc:  # noqa: BLE001 (returned to the test)
            got.append(exc)

    thread = threading.Thread(target=run, daemon=True)
    thread.start()
    thread.join(seconds)
    assert not thread.is_alive(), f"still running after {seconds} s"
    return got[0]


# ------------------------------------------------------------ 1. a cluster without worker


@pytest.mark.slow
def test_a_sweep_on_a_cluster_that_loses_its_workers_ends_with_a_solver_error(
        tmp_path, monkeypatch):
    """The tasks were submitted to a cluster with no worker (its last one died): the
    sweep gives up after WORKER_SECONDS, as the split robustness search does."""
    from distributed import Client, LocalCluster

    from rescon import _dask

    cluster = LocalCluster(n_workers=0, processes=False, dashboard_address=None)
    try:
        monkeypatch.setattr(run_mod, "client", lambda scheduler, workers: Client(cluster))
        monkeypatch.setattr(_dask, "WORKER_SECONDS", 1)
        t0 = time.monotonic()
        got = _within(30, lambda: rescon.sweep(GRID2, scheduler="x", out=tmp_path / "o"))
        assert isinstance(got, SolverError) and "no worker" in str(got), got
        assert "\n" not in str(got) and time.monotonic() - t0 < 10
    finally:
        cluster.close()


# ------------------------------------------------------------ 2. a silent scheduler


@pytest.mark.slow
def test_a_silent_scheduler_is_refused_within_the_connect_deadline(monkeypatch):
    from rescon import _dask

    monkeypatch.setattr(_dask, "CONNECT_SECONDS", 1)
    with socket.socket() as srv:
        srv.bind(("127.0.0.1", 0))
        srv.listen(5)  # accepts, never answers
        address = f"tcp://127.0.0.1:{srv.getsockname()[1]}"
        t0 = time.monotonic()
        got = _within(20, lambda: rescon.sweep(GRID2, scheduler=address))
    assert isinstance(got, InputError) and "cannot connect" in str(got), got
    assert "\n" not in str(got) and time.monotonic() - t0 < 6


# ------------------------------------------------------------ 3. damaged part files


def test_damaged_parts_are_recomputed_and_stray_names_ignored(tmp_path):
    out = tmp_path / "o"
    fresh = rescon.sweep(GRID2, workers=0, out=out)
    parts = out / "parts"
    (parts / "cell-000000.parquet").write_bytes(b"")  # empty
    (parts / "cell-000001.parquet").write_bytes(b"PAR1 not parquet")
    for stray in ("cell-1.parquet", "cell-0000001.parquet", "cell-00000x.parquet"):
        (parts / stray).write_bytes(b"junk")
    again = rescon.sweep(GRID2, workers=0, out=out)
    assert list(again["status"]) == ["ok", "ok"]
    cols = [c for c in fresh.columns if c != "seconds"]
    pd.testing.assert_frame_equal(fresh[cols], again[cols])
    resumed = rescon.sweep(GRID2, workers=0, out=out)  # the rewritten parts are read
    pd.testing.assert_frame_equal(again, resumed)


# ------------------------------------------------------------ 4. / 9. grid keys


@pytest.mark.parametrize("kind", [["consensus"], {"a": 1}, 5, None])
def test_a_kind_that_is_not_a_name_is_an_input_error(kind):
    with pytest.raises(InputError, match="kind must be one of"):
        read_grid({"base": BASE, "run": {"kind": kind}})


@pytest.mark.parametrize("key", [1, None, ("scenario", "steps"), 2.5])
def test_axis_keys_that_are_not_strings_are_input_errors(key):
    with pytest.raises(InputError, match="axis"):
        read_grid({"base": BASE, "axes": {key: [1, 2]}})


# ------------------------------------------------------------ 5. integers beyond int64


@pytest.mark.parametrize("grid, name", [
    ({"base": BASE, "axes": {"scenario.seed": [0, 2**63]}}, "seed"),
    ({"base": {"scenario": {**BASE["scenario"], "seed": -2**63 - 1}}}, "seed"),
    ({"base": {"scenario": {**BASE["scenario"], "seed": 2**63 - 2}},
      "run": {"repetitions": 3}}, "seed"),
    ({"base": BASE, "axes": {"scenario.steps": [5, 2**64]}}, "scenario.steps"),
])
def test_integers_beyond_int64_are_refused_before_anything_is_written(tmp_path, grid,
                                                                      name):
    out = tmp_path / "o"
    with pytest.raises(InputError, match=name):
        rescon.sweep(grid, workers=0, out=out)
    assert not out.exists()


def test_integers_beyond_int64_without_out_still_run():
    grid = {"base": BASE, "axes": {"scenario.seed": [2**63]}}
    assert list(rescon.sweep(grid, workers=0)["seed"]) == [2**63]


# ------------------------------------------------------------ 6. fixed column types


def test_string_columns_and_parquet_schema_are_fixed_for_every_kind(tmp_path):
    import pyarrow.parquet as pq

    kernel = {"base": {"points": {"generator": "gaussian", "n": 6, "d": 2},
                       "kernel": {"F": 1}}, "run": {"kind": "kernel"}}
    tables = {
        "ok": rescon.sweep({"base": BASE}, workers=0, out=tmp_path / "ok"),
        "failed": rescon.sweep({"base": {"scenario": {**BASE["scenario"], "F": "x"}}},
                               workers=0, out=tmp_path / "failed"),
        "kernel": rescon.sweep(kernel, workers=0, out=tmp_path / "kernel"),
    }
    assert list(tables["failed"]["status"]) == ["failed"]
    for name in ("status", "error", "method", "certificate_verdict", "rescon_version"):
        assert {str(t[name].dtype) for t in tables.values()} == {"string"}, name
    schemas = [pq.read_schema(tmp_path / k / "results.parquet") for k in tables]
    assert all(s.equals(schemas[0], check_metadata=False) for s in schemas)
    for k, t in tables.items():  # what is read back is what was returned
        pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / k / "results.parquet"), t)


# ------------------------------------------------------------ 7. cluster failures


@pytest.mark.parametrize("error", ["KilledWorker: gone", "FutureCancelledError: lost",
                                   "CancelledError: x", "CommClosedError: in <TCP>"])
def test_rows_lost_to_the_cluster_are_neither_stored_nor_resumed(tmp_path, monkeypatch,
                                                                error):
    import pyarrow as pa
    import pyarrow.parquet as pq

    real = run_mod._execute

    def lost(cells, scheduler, workers):
        for row in real(cells, scheduler, workers):
            yield {**row, "status": "failed", "error": error} if row["cell"] == 1 else row

    monkeypatch.setattr(run_mod, "_execute", lost)
    out = tmp_path / "o"
    first = rescon.sweep(GRID2, workers=0, out=out)
    assert list(first["status"]) == ["ok", "failed"]
    assert not (out / "parts" / "cell-000001.parquet").exists()
    # a part such a row left behind (an older rescon stored them) is not a result either
    row = first.iloc[1].to_dict()
    pq.write_table(pa.Table.from_pylist([{k: None if pd.isna(v) else v
                                          for k, v in row.items()}]),
                   out / "parts" / "cell-000001.parquet")
    monkeypatch.setattr(run_mod, "_execute", real)
    assert list(rescon.sweep(GRID2, workers=0, out=out)["status"]) == ["ok", "ok"]


def test_a_cell_that_fails_by_itself_is_stored_and_resumed(tmp_path, monkeypatch):
    grid = {"base": BASE, "axes": {"scenario.policy": ["hold", "nope"]}}
    first = rescon.sweep(grid, workers=0, out=tmp_path / "o")
    assert list(first["status"]) == ["ok", "failed"]
    monkeypatch.setattr(run_mod, "run_cell", lambda cell: pytest.fail("recomputed"))
    pd.testing.assert_frame_equal(rescon.sweep(grid, workers=0, out=tmp_path / "o"), first)


# ------------------------------------------------------------ 8. grid size


def test_grids_beyond_the_cell_budget_are_refused_when_read(tmp_path):
    big = {"base": BASE, "axes": {"scenario.steps": list(range(1, 1001)),
                                  "scenario.F": list(range(MAX_CELLS // 1000 + 1))}}
    t0 = time.monotonic()
    with pytest.raises(InputError, match=r"scenario\.steps.*scenario\.F"):
        read_grid(big)
    with pytest.raises(InputError, match="repetitions"):
        read_grid({"base": BASE, "run": {"repetitions": MAX_CELLS + 1}})
    assert time.monotonic() - t0 < 5
    assert len(read_grid({"base": BASE, "run": {"repetitions": 3}}).cells()) == 3
    out = tmp_path / "o"
    with pytest.raises(InputError, match="cells"):
        rescon.sweep({**big, "axes": {**big["axes"]}}, workers=0, out=out)
    assert not Path(out).exists()


@pytest.mark.parametrize("address", ["tcp://127.0.0.1:notaport", "not an address",
                                     "tcp://hostonly", "tls://127.0.0.1:x1"])
def test_malformed_tcp_addresses_are_refused_before_any_client(address, monkeypatch):
    """A tcp / tls address without a host and a numeric port is refused before a Client
    is made: a Client failing in its constructor is closed by its finaliser, which can
    wait 10 s for its event loop in whatever thread the garbage collector runs it — in
    CI a later attempt's thread, which then missed its 7-s deadline (the 'notaport'
    refusal took 7 s instead of 0.2)."""
    import distributed

    made = []
    monkeypatch.setattr(distributed, "Client", lambda *a, **k: made.append(a))
    with pytest.raises(InputError, match="cannot connect"):
        rescon.sweep({"base": {"scenario": {"paper_example": True, "steps": 2}}},
                     scheduler=address)
    assert made == []
