"""Robustness certificates of the n ≤ 30 benchmark, re-verified (issue 13 §4).

    python -m benchmarks.robustness_certs [--out benchmarks/results] [--timeout 120]

For the instances of ``robustness_n30`` (ER and directed ER, p = 0.3 / 0.5 / 0.8,
n = 25 and 30, 4 each; benchmarks/families.py), ``rescon.robustness(G)``'s certificate
is checked by the standalone checker in a fresh process (``python certificates/check.py
CERT``: start-up and JSON parsing included). Each row gives ρ, s*(ρ), the time to make
the certificate, the proof of (ρ, s*) (``lower_s``: its method and the tree it carries),
the checker's verdict and wall time, and the 1-minute load average before and after
(the machine is shared). Writes ``robustness_n30_certificates.csv`` and ``.md``.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import sys
import tempfile
import time
from pathlib import Path

import rescon

from .checker_bench import _run
from .families import instances, variant_label

ROOT = Path(__file__).resolve().parent.parent
TARGET_S = 5.0
FIELDS = ("family", "params", "n", "instance", "rho", "s_max", "make_s", "lower_s",
          "tokens", "verdict", "check_s", "load_before", "load_after")


def _lower_s(cert: dict) -> tuple[str, int]:
    """(``method`` or ``method:tree kind``, tokens) of the certificate's s* proof."""
    proof = cert.get("lower_s")
    if not isinstance(proof, dict):
        return "–", 0
    for key in ("tree", "charged_tree"):
        if proof.get(key):
            return f"{proof['method']}:{key}", len(proof[key])
    return proof["method"], 0


def bench(timeout: float) -> list[dict]:
    rows = []
    checker = ROOT / "certificates" / "check.py"
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "cert.json"
        for inst in instances(("er_directed", "er"), (25, 30), 4):
            load0 = os.getloadavg()[0]
            t0 = time.perf_counter()
            rep = rescon.robustness(inst.G)
            make = time.perf_counter() - t0
            path.write_text(json.dumps(rep.certificate))
            verdict, sec = _run(checker, path, timeout)
            method, tokens = _lower_s(rep.certificate)
            row = {"family": inst.name, "params": variant_label(inst.params),
                   "n": inst.params["n"], "instance": inst.params["instance"],
                   "rho": rep.r_max, "s_max": rep.s_max, "make_s": round(make, 3),
                   "lower_s": method, "tokens": tokens, "verdict": verdict,
                   "check_s": round(sec, 3), "load_before": round(load0, 2),
                   "load_after": round(os.getloadavg()[0], 2)}
            print(row, file=sys.stderr, flush=True)
            rows.append(row)
    return rows


def write(rows: list[dict], out: Path, seconds: float) -> None:
    out.mkdir(parents=True, exist_ok=True)
    stem = out / "robustness_n30_certificates"
    with open(f"{stem}.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=FIELDS)
        w.writeheader()
        w.writerows(rows)
    valid = sum(r["verdict"] == "valid" for r in rows)
    fast = sum(r["verdict"] == "valid" and r["check_s"] <= TARGET_S for r in rows)
    lines = [
        "# Robustness certificates of `robustness_n30`, re-verified",
        "",
        f"- Generated {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())} by "
        f"`python -m benchmarks.robustness_certs` in {seconds:.0f} s; load average at end "
        f"{' '.join(f'{x:.2f}' for x in os.getloadavg())} (2 logical CPUs, shared).",
        "- Checker: `python certificates/check.py CERT` in a fresh process (start-up and "
        "JSON parsing included), once per certificate.",
        f"- **{valid} of {len(rows)} valid**; {fast} of them checked in ≤ {TARGET_S:g} s.",
        "",
        "| family | params | n | i | ρ | s* | make s | s* proof | tokens | verdict | "
        "check s | load |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r['family']} | {r['params']} | {r['n']} | {r['instance']} | "
                     f"{r['rho']} | {r['s_max']} | {r['make_s']} | {r['lower_s']} | "
                     f"{r['tokens']} | {r['verdict']} | {r['check_s']} | "
                     f"{r['load_before']}–{r['load_after']} |")
    Path(f"{stem}.md").write_text("\n".join(lines) + "\n")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results")
    ap.add_argument("--timeout", type=float, default=120.0)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = bench(args.timeout)
    write(rows, args.out, time.perf_counter() - t0)
    return 0


if __name__ == "__main__":
    sys.exit(main())
