"""Latency benchmark (BENCHMARKS.md §6, issue 12 §5): what a user waits for.

    python -m benchmarks.latency_bench [--quick] [--out benchmarks/results]

Every number is the wall time of a fresh process, as a user starts it:
``import rescon``; each small command-line call warm (numba caches already on disk:
one untimed run first, then the median of three); each small call cold (a fresh, empty
``NUMBA_CACHE_DIR``, so whatever it compiles is compiled — the first run after
install); ``rescon paper`` cold (skipped by ``--quick``). Each call's answer is checked
(its ``--json`` output) before its time is recorded, and the 1-minute load average is
recorded next to it: on a shared machine the wall times grow with the load.

Writes ``latency.csv`` and ``latency.md``.
"""

from __future__ import annotations

import csv
import json
import os
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import NamedTuple

from benchmarks.consensus_bench import bench_main

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
#: BENCHMARKS.md §6 targets, seconds of wall time
IMPORT_TARGET, WARM_TARGET, COLD_TARGET, PAPER_TARGET = 0.5, 1.0, 10.0, 60.0
#: a 10-node digraph (edge u v: v receives u): the circulant C_10(1, 2, 3), 3-robust
TEN_NODES = "".join(f"{u} {(u + k) % 10}\n" for u in range(10) for k in (1, 2, 3, 7, 8, 9))


def _check_robustness(r_max: int) -> Callable[[dict], bool]:
    return lambda out: out["exact"] and out["r_max"] == r_max


def _calls(tmp: Path) -> list[tuple[str, list[str], Callable[[dict], bool]]]:
    """(name, rescon arguments, check of the JSON answer) for each small call."""
    ten = tmp / "ten.edgelist"
    ten.write_text(TEN_NODES)
    return [
        ("robustness, paper graph (12 nodes)",
         ["robustness", str(EX / "graphs" / "paper_example.edgelist")], _check_robustness(5)),
        ("robustness, 10-node circulant", ["robustness", str(ten)], _check_robustness(3)),
        ("kernel, 12 points, F = 2",
         ["kernel", str(EX / "points" / "attack_12.csv"), "--F", "2"],
         lambda out: not out["empty"] and out["dim"] == 2 and out["point"] is not None),
        ("simulate, paper example (200 steps)",
         ["simulate", str(EX / "scenarios" / "paper.toml")],
         lambda out: out["final_diameter"] < 1e-9 and out["max_validity"] == 0.0),
        ("rmdo, paper example (200 steps)",
         ["rmdo", str(EX / "scenarios" / "paper_rmdo.toml")],
         lambda out: out["final_diameter"] < 0.1 and out["final_distance_to_optimum"] < 2),
    ]


class Timing(NamedTuple):
    """One process: wall s, CPU s (user + system, all its threads) and the 1-minute load
    average at its start. CPU time barely moves with the load, wall time does."""

    wall: float
    cpu: float
    load: float


def _cpu_of_children() -> float:
    use = resource.getrusage(resource.RUSAGE_CHILDREN)
    return use.ru_utime + use.ru_stime


def _run(args: list[str], env: dict[str, str] | None = None, timeout: float = 900
         ) -> tuple[Timing, subprocess.CompletedProcess]:
    """The timing of a fresh process running ``args``, and the finished process."""
    load, cpu = os.getloadavg()[0], _cpu_of_children()
    t0 = time.perf_counter()
    proc = subprocess.run(args, capture_output=True, text=True, env=env, timeout=timeout,
                          cwd=ROOT)
    return Timing(time.perf_counter() - t0, _cpu_of_children() - cpu, load), proc


def _rescon(args: list[str], env: dict[str, str] | None = None,
            check: Callable[[dict], bool] | None = None) -> Timing:
    """A ``rescon ... --json --quiet`` call, its answer checked."""
    timing, proc = _run([sys.executable, "-m", "rescon", *args, "--json", "--quiet"], env)
    if proc.returncode != 0:
        raise RuntimeError(f"rescon {' '.join(args)}: exit {proc.returncode}: {proc.stderr}")
    out = json.loads(proc.stdout)
    if check is not None and not check(out):
        raise RuntimeError(f"rescon {' '.join(args)}: wrong answer {proc.stdout[:300]}")
    return timing


def _cold_env(tmp: Path) -> dict[str, str]:
    """The environment of a cold start: a fresh, empty numba cache directory."""
    return {**os.environ, "NUMBA_CACHE_DIR": tempfile.mkdtemp(prefix="numba-", dir=tmp)}


def _row(case: str, mode: str, timings: list[Timing], target: float) -> dict:
    """The median wall and CPU time of ``timings`` (and the highest load) vs target."""
    wall = statistics.median(t.wall for t in timings)
    return {"case": case, "mode": mode, "seconds": round(wall, 3),
            "cpu_seconds": round(statistics.median(t.cpu for t in timings), 3),
            "load1": round(max(t.load for t in timings), 2), "target_s": target,
            "met": wall <= target}


def _import() -> Timing:
    timing, proc = _run([sys.executable, "-c", "import rescon, sys; "
                         "print('numba' in sys.modules, 'networkx' in sys.modules)"])
    if proc.returncode != 0 or proc.stdout.split() != ["False", "False"]:
        raise RuntimeError(f"import rescon: {proc.stdout} {proc.stderr}")
    return timing


def _check_call(cert: Path) -> Timing:
    """``rescon check`` of a certificate; the verdict must be valid."""
    timing, proc = _run([sys.executable, "-m", "rescon", "check", str(cert), "--json"])
    if proc.returncode != 0 or json.loads(proc.stdout)["verdict"] != "valid":
        raise RuntimeError(f"rescon check: {proc.stdout} {proc.stderr}")
    return timing


def run(quick: bool) -> list[dict]:
    rows = [_row("import rescon", "warm, median of 5", [_import() for _ in range(5)],
                 IMPORT_TARGET)]
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        version = [_run([sys.executable, "-m", "rescon", "--version"])[0] for _ in range(3)]
        rows.append(_row("rescon --version", "warm, median of 3", version, WARM_TARGET))
        for name, args, check in _calls(tmp):
            _rescon(args, check=check)  # warm the caches (numba, bytecode)
            rows.append(_row(name, "warm, median of 3",
                             [_rescon(args, check=check) for _ in range(3)], WARM_TARGET))
        cert = tmp / "paper.cert.json"
        _rescon(["robustness", str(EX / "graphs" / "paper_example.edgelist"), "--certificate",
                 str(cert)], check=_check_robustness(5))
        rows.append(_row("check, the paper graph's certificate", "warm, median of 3",
                         [_check_call(cert) for _ in range(3)], WARM_TARGET))
        for name, args, check in _calls(tmp):
            rows.append(_row(name, "cold (empty numba cache)",
                             [_rescon(args, env=_cold_env(tmp), check=check)], COLD_TARGET))
        if not quick:
            paper = _rescon(["paper", "--out", str(tmp / "paper")], env=_cold_env(tmp),
                            check=lambda s: bool(s["claims"]))
            rows.append(_row("rescon paper", "cold (empty numba cache)", [paper], PAPER_TARGET))
    return rows


def write(rows: list[dict], out: Path, seconds: float) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with (out / "latency.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = ["# Latency benchmark (BENCHMARKS.md §6)", "",
             (f"- `python -m benchmarks.latency_bench` in {seconds:.0f} s on "
              f"{platform.machine()} ({os.cpu_count()} CPUs), Python "
              f"{platform.python_version()}; every time is the wall time of a fresh "
              "process, its --json answer checked first."),
             ("- load1 = the 1-minute load average when the call started (the largest of "
              "the repeats): on a shared machine wall times grow with it."),
             "- cold = a fresh, empty NUMBA_CACHE_DIR (everything the call uses is compiled).",
             ("- cpu s = user + system time of the process (all its threads): what the call "
              "costs whatever the load; met compares the wall time with the target."),
             "", "| call | mode | wall s | cpu s | load1 | target s | met |",
             "|---|---|---|---|---|---|---|"]
    lines += [f"| {r['case']} | {r['mode']} | {r['seconds']:.2f} | {r['cpu_seconds']:.2f} | "
              f"{r['load1']:.2f} | {r['target_s']:g} | {'met' if r['met'] else 'NOT met'} |"
              for r in rows]
    (out / "latency.md").write_text("\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    return bench_main("latency", __doc__, run, write, argv)


if __name__ == "__main__":
    raise SystemExit(main())
