"""Safe-kernel certificates checked at the speed they are made (issue 13 §4).

    python -m benchmarks.checker_bench [--out benchmarks/results] [--repeat 3]
                                       [--before REV] [--timeout 300]

For gaussian and sphere clouds (benchmarks/kernel_clouds.py, fixed seeds) in d = 2
(n = 100, 1000) and d = 3 (n = 20, 30, 100), with F = ⌊n/10⌋ (every kernel nonempty;
and F = 1 for n = 1000 points on the circle: a kernel with 1000 vertices),
the standalone checker's wall time (``python certificates/check.py CERT``, a fresh
process: start-up and JSON parsing included, median of ``--repeat`` runs) on

* ``after``: the certificate rescon writes now (with ``adjacency``), checked by
  today's checker — its verdict must be ``valid`` before its time is reported;
* ``old form``: the same certificate without ``adjacency``, today's checker (old
  certificates: vertex enumeration within its work limit, else ``unchecked``);
* ``before``: the old form checked by the checker of git revision ``--before`` (the
  one before issue 13 §4), run once with a ``--timeout``.

Each cloud also gives a ``kernel_point`` row (``rescon.kernel_point``'s certificate,
now with the ``kernel`` proof; old form: the ``halfspaces`` proof).

The load average (1 min) is recorded before and after each case: the machine is shared.
Writes ``checker.csv`` and ``checker.md``.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import rescon

from .kernel_clouds import make_cloud

ROOT = Path(__file__).resolve().parent.parent
CHECKER_FILES = ("__init__.py", "check.py", "kernels.py", "redundancy.py")
BEFORE = "df4ddbe"  # the last revision before the adjacency and the normal fan
#: (family, d, n, F); F = ⌊n/10⌋, and F = 1 on the circle (a kernel with n vertices)
CASES = [("gaussian", 2, 100, 10), ("gaussian", 2, 1000, 100), ("sphere", 2, 1000, 100),
         ("sphere", 2, 1000, 1), ("gaussian", 3, 20, 2), ("gaussian", 3, 30, 3),
         ("gaussian", 3, 100, 10), ("sphere", 3, 100, 10)]
TARGET_S = 5.0


def _run(checker: Path, cert: Path, timeout: float) -> tuple[str, float]:
    """(verdict, wall seconds) of ``python checker cert`` ("timeout" past ``timeout``)."""
    t0 = time.perf_counter()
    try:
        res = subprocess.run([sys.executable, str(checker), str(cert)], capture_output=True,
                             text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - t0
    sec = time.perf_counter() - t0
    verdict = {0: "valid", 1: "invalid", 2: "unreadable", 3: "unchecked"}.get(res.returncode,
                                                                             "error")
    return verdict, sec


def _median(checker: Path, cert: Path, repeat: int, timeout: float) -> tuple[str, float]:
    runs = [_run(checker, cert, timeout) for _ in range(repeat)]
    return runs[0][0], statistics.median(s for _, s in runs)


def _old_checker(rev: str, where: Path) -> Path:
    """The checker files of git revision ``rev`` in ``where``; the path of its check.py."""
    for name in CHECKER_FILES:
        text = subprocess.run(["git", "show", f"{rev}:certificates/{name}"], cwd=ROOT,
                              capture_output=True, text=True, check=True).stdout
        (where / name).write_text(text)
    return where / "check.py"


def bench(repeat: int, before: str, timeout: float) -> list[dict]:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmpdir = Path(tmp)
        old = _old_checker(before, tmpdir)
        new = ROOT / "certificates" / "check.py"
        for family, d, n, F in CASES:
            load0 = os.getloadavg()[0]
            X = make_cloud(family, d, n, F).X
            t0 = time.perf_counter()
            K = rescon.safe_kernel(X, F)
            cert = K.certificate
            build = time.perf_counter() - t0
            full, short = tmpdir / "new.json", tmpdir / "old.json"
            full.write_text(json.dumps(cert))
            short.write_text(json.dumps({k: v for k, v in cert.items() if k != "adjacency"}))
            case = f"{family} d={d} n={n} F={F}"
            rows.append(_row(case, "safe_kernel", cert, build, (new, old), (full, short),
                             repeat, timeout, load0))
            t0 = time.perf_counter()
            _, point = rescon.kernel_point(X, F)
            build = time.perf_counter() - t0
            full.write_text(json.dumps(point))
            short.write_text(json.dumps({**point, "proof": {"method": "halfspaces"}}))
            rows.append(_row(case, "kernel_point", cert, build, (new, old), (full, short),
                             repeat, timeout, os.getloadavg()[0]))
    return rows


def _row(case: str, kind: str, cert: dict, build: float, checkers: tuple[Path, Path],
         files: tuple[Path, Path], repeat: int, timeout: float, load0: float) -> dict:
    """One table row: today's checker on today's certificate (``files[0]``) and on the
    old form (``files[1]``), the old checker on the old form."""
    (new, old), (full, short) = checkers, files
    verdict, sec = _median(new, full, repeat, timeout)
    old_verdict, old_sec = _median(new, short, repeat, timeout)
    before_verdict, before_sec = _run(old, short, timeout)
    row = {"case": case, "kind": kind, "vertices": len(cert["vertices"]),
           "facets": len(cert["facets"]), "build_s": round(build, 3),
           "after_verdict": verdict, "after_s": round(sec, 3) if verdict == "valid" else None,
           "old_form_verdict": old_verdict, "old_form_s": round(old_sec, 3),
           "before_verdict": before_verdict, "before_s": round(before_sec, 3),
           "met": verdict == "valid" and sec <= TARGET_S,
           "load_before": round(load0, 2), "load_after": round(os.getloadavg()[0], 2)}
    print(row, file=sys.stderr)
    return row


def write(rows: list[dict], out: Path, seconds: float, before: str) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with (out / "checker.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = [
        "# Safe-kernel certificate checking (issue 13 §4)", "",
        (f"- `python -m benchmarks.checker_bench` in {seconds:.0f} s on {platform.machine()}, "
         f"Python {platform.python_version()}, {os.cpu_count()} cores shared with other jobs "
         "(load average before/after each case in the table)."),
        ("- Wall time of `python certificates/check.py CERT` (fresh process, median of the "
         "repeats). `after`: today's certificate (safe_kernel: with `adjacency`; "
         "kernel_point: `kernel` proof) and checker, verdict checked to be `valid` before "
         "its time is reported; `old form`: without `adjacency` / with the `halfspaces` "
         f"proof, today's checker; `before`: the old form, checker of revision {before}. "
         "`build s`: rescon's kernel (or point) and certificate, in-process (the first row "
         "includes imports)."),
        f"- Target: `valid` in ≤ {TARGET_S:g} s.", "",
        "| case | kind | #V | #facets | build s | after | after s | old form | old form s "
        "| before | before s | met | load |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['kind']} | {r['vertices']} | {r['facets']} | {r['build_s']} | "
            f"{r['after_verdict']} | {r['after_s'] if r['after_s'] is not None else '–'} | "
            f"{r['old_form_verdict']} | {r['old_form_s']} | {r['before_verdict']} | "
            f"{r['before_s']} | {'met' if r['met'] else 'NOT met'} | "
            f"{r['load_before']}/{r['load_after']} |")
    (out / "checker.md").write_text("\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--before", default=BEFORE, help="git revision of the 'before' checker")
    ap.add_argument("--timeout", type=float, default=300.0)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = bench(args.repeat, args.before, args.timeout)
    write(rows, args.out, time.perf_counter() - t0, args.before)
    return 0 if all(r["met"] for r in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
