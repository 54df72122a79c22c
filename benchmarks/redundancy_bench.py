"""r-redundancy verification time (issue 11 §3): :func:`rescon.check_redundancy` for
N = 12 and N = 20 costs over x ∈ R³, r = 2, on redundant and on non-redundant families.

    python -m benchmarks.redundancy_bench [--out benchmarks/results] [--repeat 3]

Families (integer data, seed 0; c a common centre):

* ``quadratic-common``: (a_iᵀ(x − c))² + w_i (x1 − c1)², some of rank 1 — redundant
  exactly when every N − 2 of them still pin down c;
* ``quadratic-shifted``: ‖x − c_i‖² with c_i = c except for a few agents — not redundant;
* ``mixed-common``: w_i‖x − c‖² + |a_iᵀ(x − c)| + ‖x − c‖₁ (kinks at c) — redundant;
* ``mixed-shifted``: ‖x − c_i‖² + |a_iᵀ(x − c_i)| with centres c_i = c + a small
  integer shift, different for every agent — not redundant;
* ``numerical``: Huber + ‖x − c‖₂ + a shifted quadratic (not piecewise quadratic, and
  the 2-norm is off its kink): the numerical path (CVXPY/Clarabel supports).

Each verdict is checked before it is timed: exact ones by the standalone checker
(``valid``), numerical ones must say ``unchecked``. The time is the median of
``--repeat`` runs after one warm-up, the machine's load average noted (times grow with
it). Writes ``redundancy.csv`` and ``redundancy.md``.
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import statistics
import time
from pathlib import Path

import numpy as np

import rescon

D = 3
TARGET = {12: 1.0, 20: 5.0}


def _vec(a: np.ndarray, c: np.ndarray) -> str:
    """aᵀ(x − c) as an expression."""
    return " + ".join(f"({int(u)})*(x{j + 1} - ({int(v)}))" for j, (u, v) in enumerate(zip(a, c)))


def family(name: str, N: int) -> list[str]:
    rng = np.random.default_rng(0)
    c = rng.integers(-3, 4, size=D)
    out = []
    for i in range(N):
        a = rng.integers(-2, 3, size=D)
        a[i % D] = a[i % D] or 1
        shift = rng.integers(-1, 2, size=D)
        ci = c + (shift if (i < 3 and name == "quadratic-shifted") or name == "mixed-shifted"
                  else 0)
        sq = " + ".join(f"(x{j + 1} - ({int(v)}))^2" for j, v in enumerate(ci))
        if name == "quadratic-common":
            out.append(f"({_vec(a, c)})^2"
                       + (f" + {1 + i % 3}*(x1 - ({int(c[0])}))^2" if i % 2 else ""))
        elif name == "quadratic-shifted":
            out.append(sq)
        elif name == "mixed-shifted":
            out.append(f"{sq} + abs({_vec(a, ci)})")
        elif name == "mixed-common":
            out.append(f"{1 + i % 3}*({sq}) + abs({_vec(a, ci)}) + "
                       + " + ".join(f"abs(x{j + 1} - ({int(v)}))" for j, v in enumerate(ci)))
        else:
            out.append(f"huber(x1 - ({int(c[0])}), 1) + sqrt({sq}) + "
                       f"(x2 - ({int(c[1]) + i % 2}))^2")
    return out


def run(name: str, N: int, repeat: int) -> dict:
    costs = family(name, N)
    rep = rescon.check_redundancy(costs, 2, d=D)
    verdict = rescon.check_certificate(rep.certificate).verdict
    assert verdict == ("valid" if rep.exact else "unchecked"), (name, N, verdict)
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        rescon.check_redundancy(costs, 2, d=D)
        times.append(time.perf_counter() - t0)
    return {"family": name, "N": N, "r": 2, "holds": rep.holds, "exact": rep.exact, "gap": rep.gap,
            "seconds": statistics.median(times), "target": TARGET[N]}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=Path("benchmarks/results"))
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    load0 = os.getloadavg()[0]
    rows = [run(name, N, args.repeat) for N in (12, 20)
            for name in ("quadratic-common", "quadratic-shifted", "mixed-common",
                         "mixed-shifted", "numerical")]
    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "redundancy.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    machine = f"{platform.processor() or platform.machine()}, Python {platform.python_version()}"
    load = f"{load0:.1f}–{os.getloadavg()[0]:.1f}"  # the 2 cores are shared: times scale
    lines = ["# r-redundancy verification (rescon.check_redundancy, d = 3, r = 2)", "",
             (f"{machine}; load {load} (1-min average, start–end); median of {args.repeat} "
              "warm runs; C(N, 2) subsets + the whole set "
              "+ each agent alone. exact: certificate verified valid by certificates/check.py; "
              "numerical: unchecked."), "",
             "| family | N | holds | exact | gap | seconds | target |",
             "|---|---|---|---|---|---|---|"]
    lines += [f"| {r['family']} | {r['N']} | {r['holds']} | {r['exact']} | {r['gap']:.3g} | "
              f"{r['seconds']:.3f} | ≤ {r['target']:g} s |" for r in rows]
    (args.out / "redundancy.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
