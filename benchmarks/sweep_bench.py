"""Sweep benchmark (issue 12 §2): a 64-cell grid run serially in this process against
the same grid on 2 local Dask worker processes, and the per-task overhead of Dask.

    python -m benchmarks.sweep_bench [--steps K] [--out benchmarks/results]

The grid: the paper's example (SPEC §5), K steps (default 60), policy hold / zero ×
centre mean / box × 16 repetitions = 64 cells. The 2-worker cluster is a
``distributed.LocalCluster`` started and warmed (every worker has run a cell) before the
clock starts; the wall time of a run with a cold cluster (start-up included) is
reported too. Before any time is reported, the rows of both runs are checked equal in
every column but ``seconds``.

Per-task overhead: 64 cells of 0 steps (nothing but the scenario build and the row) on
the warm cluster: overhead = wall · workers / cells − (serial wall / cells), i.e. what
each task costs beyond its own work when the workers are kept busy.

Writes ``sweep.md``.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import pandas as pd

from rescon.sweep import sweep

WORKERS = 2


def grid(steps: int, repetitions: int = 16) -> dict:
    """4 axis points × ``repetitions``: 64 cells by default."""
    return {"base": {"scenario": {"paper_example": True, "steps": steps,
                                  "check_robustness": False}},
            "axes": {"scenario.policy": ["hold", "zero"],
                     "scenario.centre": ["mean", "box"]},
            "run": {"repetitions": repetitions}}


def _same(a: pd.DataFrame, b: pd.DataFrame) -> None:
    cols = [c for c in a.columns if c != "seconds"]
    pd.testing.assert_frame_equal(a[cols], b[cols])
    if (a["status"] != "ok").any():
        raise AssertionError(f"failed cells: {list(a['error'].dropna())[:3]}")


def _timed(g: dict, **kw) -> tuple[pd.DataFrame, float]:
    t0 = time.perf_counter()
    table = sweep(g, progress=False, **kw)
    return table, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=60)
    ap.add_argument("--out", default="benchmarks/results")
    args = ap.parse_args()
    from distributed import Client, LocalCluster

    g, trivial = grid(args.steps), grid(0)
    sweep(grid(args.steps, 1), workers=0, progress=False)  # numba caches of this process
    serial, t_serial = _timed(g, workers=0)
    serial0, t_serial0 = _timed(trivial, workers=0)
    cold, t_cold = _timed(g, workers=WORKERS)
    with LocalCluster(n_workers=WORKERS, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        address = cluster.scheduler_address
        client.wait_for_workers(WORKERS)
        sweep(grid(args.steps, 2), scheduler=address, progress=False)  # warm every worker
        warm, t_warm = _timed(g, scheduler=address)
        warm0, t_warm0 = _timed(trivial, scheduler=address)
    for other in (cold, warm):
        _same(serial, other)
    _same(serial0, warm0)
    n = len(serial)
    overhead = t_warm0 * WORKERS / n - t_serial0 / n
    load = os.getloadavg()
    lines = [
        "# Sweep benchmark (benchmarks/sweep_bench.py)",
        "",
        f"{n}-cell grid: the paper's example, {args.steps} steps, policy hold/zero × centre "
        "mean/box × 16 repetitions. Rows of every run checked equal (all columns but "
        "`seconds`) before timing is reported.",
        "",
        f"Machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
        f"Python {platform.python_version()}; load average at the end "
        f"{load[0]:.2f} / {load[1]:.2f} / {load[2]:.2f} (the machine is shared).",
        "",
        "| run | wall (s) | speed-up vs serial |",
        "| --- | ---: | ---: |",
        f"| serial (workers=0, this process) | {t_serial:.2f} | 1.00 |",
        f"| LocalCluster, {WORKERS} workers, warm | {t_warm:.2f} | {t_serial / t_warm:.2f} |",
        f"| LocalCluster, {WORKERS} workers, cold (start-up included) | {t_cold:.2f} | "
        f"{t_serial / t_cold:.2f} |",
        "",
        f"Mean cell time (serial): {t_serial / n * 1e3:.1f} ms. Per-task overhead on the "
        f"warm cluster ({n} cells of 0 steps; serial {t_serial0 / n * 1e3:.1f} ms/cell, "
        f"cluster {t_warm0:.2f} s wall): {overhead * 1e3:.1f} ms per task.",
        "",
    ]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "sweep.md").write_text("\n".join(lines), encoding="utf-8")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
