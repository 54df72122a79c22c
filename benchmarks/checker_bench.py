"""Certificates checked at the speed they are made (issue 13 §4): safe kernels and
robustness proofs.

    python -m benchmarks.checker_bench [--out benchmarks/results] [--repeat 3]
                                       [--before REV] [--search-before REV] [--timeout 300]
                                       [--only kernels|robustness]

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

Robustness (``search`` trees, n ≤ 30; benchmarks/families.py instances, r = ρ unless
the table says otherwise): ``rescon.is_r_robust(G, r, method="search")``'s certificate
(its proof: a search tree, or a construction whose seed is one; ``tokens`` counts
them) with ``holds`` True, and ``is_r_robust(G, r + 1)`` deciding whether r = ρ; then

* ``after``: today's checker (median of ``--repeat`` runs, as above);
* ``before``: the checker of ``--search-before`` (the last revision whose replay peeled
  every core from scratch), with its work limit, once;
* ``before, no limit``: the same replay with its work limit lifted, once (its time is
  reported when it says ``valid``).

Rows of ``rescon.robustness(G)`` certificates name what is still unchecked (e.g. the
s* proofs ``dp`` / ``cost_search`` beyond n = 20).

The load average (1 min) is recorded before and after each case: the machine is shared.
Writes ``checker.csv`` (one row per case; the columns of the other part left empty)
and ``checker.md``. ``--only`` re-measures one part and keeps the other part's rows of
the existing ``checker.csv``.
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

from .families import make_instance, variant_label
from .kernel_clouds import make_cloud

ROOT = Path(__file__).resolve().parent.parent
CHECKER_FILES = ("__init__.py", "check.py", "kernels.py", "redundancy.py")
BEFORE = "df4ddbe"  # the last revision before the adjacency and the normal fan
SEARCH_BEFORE = "6572996"  # the last revision before the incremental search replay
#: (family, d, n, F); F = ⌊n/10⌋, and F = 1 on the circle (a kernel with n vertices)
CASES = [("gaussian", 2, 100, 10), ("gaussian", 2, 1000, 100), ("sphere", 2, 1000, 100),
         ("sphere", 2, 1000, 1), ("gaussian", 3, 20, 2), ("gaussian", 3, 30, 3),
         ("gaussian", 3, 100, 10), ("sphere", 3, 100, 10)]
#: (family, variant, n, instance, r): is_r_robust(G, r) certificates
SEARCH_CASES = [("er_directed", {"p": 0.8}, 20, 1, 9), ("er_directed", {"p": 0.5}, 30, 1, 8),
                ("geometric", {"radius": 0.5}, 30, 1, 7), ("er", {"p": 0.8}, 25, 1, 11),
                ("er_directed", {"p": 0.8}, 25, 0, 11), ("er_directed", {"p": 0.8}, 30, 0, 11),
                ("er_directed", {"p": 0.8}, 30, 0, 12), ("er_directed", {"p": 0.7}, 30, 0, 11),
                ("er_directed", {"p": 0.85}, 26, 1, 12)]
#: (family, variant, n, instance): rescon.robustness(G, time_limit=ROBUSTNESS_LIMIT_S)
ROBUSTNESS_CASES = [("er", {"p": 0.5}, 20, 0), ("er_directed", {"p": 0.5}, 30, 1),
                    ("er_directed", {"p": 0.8}, 25, 0)]
ROBUSTNESS_LIMIT_S = 60.0
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


def _tokens(proof: dict | None) -> int:
    """Tokens of the search trees in a proof (nested in constructions and implications)."""
    if not isinstance(proof, dict):
        return 0
    own = len(proof["tree"]) if proof.get("method") == "search" and proof.get("tree") else 0
    return own + sum(_tokens(proof.get(k)) for k in ("proof", "seed_proof"))


def _methods(proof: dict | None) -> str:
    """``construction(search)`` etc.: the proof's methods, outermost first."""
    if not isinstance(proof, dict):
        return "–"
    inner = proof.get("seed_proof") or proof.get("proof")
    if proof.get("method") == "search" and proof.get("tree") is None:
        return "search (tree not recorded)"
    return proof["method"] + (f"({_methods(inner)})" if isinstance(inner, dict) else "")


def _nolimit_run(checker: Path, cert: Path, timeout: float) -> tuple[str, float]:
    """(verdict, seconds) of ``checker``'s main on ``cert`` with MAX_SEARCH_WORK lifted."""
    code = ("import importlib.util, sys; spec = importlib.util.spec_from_file_location("
            f"'old_check', {str(checker)!r}); m = importlib.util.module_from_spec(spec); "
            "sys.modules['old_check'] = m; spec.loader.exec_module(m); "
            "m.MAX_SEARCH_WORK = 10 ** 15; "
            f"sys.exit(m.main([{str(cert)!r}]))")
    t0 = time.perf_counter()
    try:
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             timeout=timeout)
    except subprocess.TimeoutExpired:
        return "timeout", time.perf_counter() - t0
    verdict = {0: "valid", 1: "invalid", 3: "unchecked"}.get(res.returncode, "error")
    if "Traceback" in res.stderr:
        verdict = "error"
    return verdict, time.perf_counter() - t0


def _search_row(case: str, kind: str, cert: dict, build: float, proof: str, rho: str,
                tmpdir: Path, checkers: tuple[Path, Path], repeat: int, timeout: float,
                load0: float) -> dict:
    """One robustness row: today's checker, the old one with and without its limit."""
    new, old = checkers
    path = tmpdir / "search.json"
    path.write_text(json.dumps(cert))
    verdict, sec = _median(new, path, repeat, timeout)
    before_verdict, before_sec = _run(old, path, timeout)
    tokens = sum(_tokens(cert.get(k)) for k in ("proof", "lower", "lower_s"))
    free_verdict, free_sec = ("–", None)
    if before_verdict == "unchecked" and tokens:
        free_verdict, free_sec = _nolimit_run(old, path, timeout)
    trusted = rescon.check_certificate(cert).trusted if verdict == "unchecked" else ()
    row = {"case": case, "kind": kind, "rho": rho, "proof": proof, "tokens": tokens,
           "build_s": round(build, 3), "after_verdict": verdict,
           "after_s": round(sec, 3), "unchecked_parts": "; ".join(trusted),
           "before_verdict": before_verdict, "before_s": round(before_sec, 3),
           "before_nolimit_verdict": free_verdict,
           "before_nolimit_s": round(free_sec, 3) if free_sec is not None else None,
           "met": verdict == "valid" and sec <= TARGET_S,
           "load_before": round(load0, 2), "load_after": round(os.getloadavg()[0], 2)}
    print(row, file=sys.stderr)
    return row


def bench_search(repeat: int, before: str, timeout: float) -> list[dict]:
    """Rows for SEARCH_CASES (is_r_robust) and ROBUSTNESS_CASES (robustness)."""
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmpdir = Path(tmp)
        old = _old_checker(before, tmpdir)
        checkers = (ROOT / "certificates" / "check.py", old)
        for name, variant, n, i, r in SEARCH_CASES:
            load0 = os.getloadavg()[0]
            G = make_instance(name, variant, n, i).G
            t0 = time.perf_counter()
            out = rescon.is_r_robust(G, r, method="search")
            build = time.perf_counter() - t0
            if out.holds is not True:
                raise RuntimeError(f"{name} n={n} i={i} is not {r}-robust: the case list is "
                                   "wrong")
            above = rescon.is_r_robust(G, r + 1, method="search").holds
            rho = str(r) if above is False else f"> {r}"
            case = f"{name} {variant_label(variant)} n={n} i={i} r={r}"
            rows.append(_search_row(case, "rs_robust", out.certificate, build,
                                    _methods(out.certificate["proof"]), rho, tmpdir,
                                    checkers, repeat, timeout, load0))
        for name, variant, n, i in ROBUSTNESS_CASES:
            load0 = os.getloadavg()[0]
            G = make_instance(name, variant, n, i).G
            t0 = time.perf_counter()
            rep = rescon.robustness(G, time_limit=ROBUSTNESS_LIMIT_S)
            build = time.perf_counter() - t0
            cert = rep.certificate
            proof = (f"lower: {_methods(cert['lower'])}, lower_s: "
                     f"{_methods(cert.get('lower_s'))}")
            s_star = rep.s_max if rep.exact else f"{rep.s_lower}..{rep.s_upper}"
            rho = f"{rep.r_lower}" if rep.r_lower == rep.r_upper else \
                f"{rep.r_lower}..{rep.r_upper}"
            case = f"{name} {variant_label(variant)} n={n} i={i} (s* = {s_star})"
            rows.append(_search_row(case, "robustness", cert, build, proof, rho, tmpdir,
                                    checkers, repeat, timeout, load0))
    return rows


def write(rows: list[dict], search_rows: list[dict], out: Path, seconds: float, before: str,
          search_before: str, only: str | None = None) -> None:
    out.mkdir(parents=True, exist_ok=True)
    fields = list(rows[0]) + [k for k in search_rows[0] if k not in rows[0]]
    with (out / "checker.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, restval="")
        w.writeheader()
        w.writerows(rows + search_rows)
    lines = [
        "# Certificate checking (issue 13 §4)", "", "## Safe kernels", "",
        (f"- `python -m benchmarks.checker_bench` in {seconds:.0f} s on {platform.machine()}, "
         f"Python {platform.python_version()}, {os.cpu_count()} cores shared with other jobs "
         "(load average before/after each case in the table)"
         + (f"; `--only {only}`: the other part's rows are those of the previous run."
            if only else ".")),
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
    lines += _search_lines(search_rows, search_before)
    (out / "checker.md").write_text("\n".join(lines) + "\n")


def _search_lines(rows: list[dict], before: str) -> list[str]:
    lines = [
        "", "## Robustness proofs (search trees, n ≤ 30)", "",
        ("- `rs_robust`: `rescon.is_r_robust(G, r, method=\"search\")` (holds; ρ: `r` when "
         "`is_r_robust(G, r + 1)` is refuted); `robustness`: `rescon.robustness(G, "
         f"time_limit={ROBUSTNESS_LIMIT_S:g})`. `tokens`: the search-tree tokens in the "
         "certificate; `build s`: rescon's answer and certificate, in-process."),
        ("- Wall time of `python certificates/check.py CERT` (fresh process). `after`: "
         "today's checker (incremental replay, limit "
         "2.5·10^7 steps), median of the repeats; `before`: the checker of revision "
         f"{before} (every core peeled from scratch, limit 1.2·10^7 mask operations), "
         "once; `before, no limit`: that replay with its limit lifted, once (run when "
         "`before` is unchecked). `unchecked parts`: what today's checker did not verify. "
         "A `before` = `invalid` on a robustness row: its `cost_search` proof carries a "
         "tree (certificates/cost_tree.py), a key that older checker does not know."),
        f"- Target: `valid` in ≤ {TARGET_S:g} s.", "",
        "| case | kind | ρ | proof | tokens | build s | after | after s | unchecked parts "
        "| before | before s | before, no limit | no limit s | met | load |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        free = r["before_nolimit_s"] if r["before_nolimit_s"] is not None else "–"
        lines.append(
            f"| {r['case']} | {r['kind']} | {r['rho']} | {r['proof']} | {r['tokens']} | "
            f"{r['build_s']} | {r['after_verdict']} | {r['after_s']} | "
            f"{r['unchecked_parts'] or '–'} | {r['before_verdict']} | {r['before_s']} | "
            f"{r['before_nolimit_verdict']} | {free} | {'met' if r['met'] else 'NOT met'} | "
            f"{r['load_before']}/{r['load_after']} |")
    return lines


KERNEL_KINDS = ("safe_kernel", "kernel_point")


def _kept(path: Path, kernels: bool) -> list[dict]:
    """The rows of one part (kernels, or robustness) of an existing checker.csv, typed
    as :func:`write` expects (booleans, None for empty cells)."""
    with path.open(newline="") as fh:
        rows = [row for row in csv.DictReader(fh) if (row["kind"] in KERNEL_KINDS) == kernels]
    typed = {"True": True, "False": False, "": None}
    return [{k: typed.get(v, v) for k, v in row.items()} for row in rows]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--before", default=BEFORE, help="git revision of the 'before' checker")
    ap.add_argument("--search-before", default=SEARCH_BEFORE,
                    help="git revision of the 'before' checker for robustness proofs")
    ap.add_argument("--timeout", type=float, default=300.0)
    ap.add_argument("--only", choices=("kernels", "robustness"),
                    help="re-measure this part only, keep the other's rows of checker.csv")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    if args.only == "robustness":
        rows = _kept(args.out / "checker.csv", kernels=True)
    else:
        rows = bench(args.repeat, args.before, args.timeout)
    if args.only == "kernels":
        search_rows = _kept(args.out / "checker.csv", kernels=False)
    else:
        search_rows = bench_search(args.repeat, args.search_before, args.timeout)
    write(rows, search_rows, args.out, time.perf_counter() - t0, args.before,
          args.search_before, args.only)
    # kernels: every target met; robustness: no correct certificate called invalid
    bad = [r for r in search_rows if r["after_verdict"] not in ("valid", "unchecked")]
    return 0 if all(r["met"] for r in rows) and not bad else 1


if __name__ == "__main__":
    raise SystemExit(main())
