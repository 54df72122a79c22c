"""Benchmark runner: ``python -m benchmarks.run robustness|kernels [options]``.

``kernels`` (BENCHMARKS.md §2): rescon.safe_kernel, the kernel point and the emptiness
certificate against the subset LP and the subset-hull qhull baselines on the point
clouds of ``benchmarks/kernel_clouds.py``; results ``<out>/kernels_<name>.{csv,md}``.
See the "Safe kernels" section of ``benchmarks/README.md``.

``robustness`` (BENCHMARKS.md §1):

For every instance of the selected graph families (``benchmarks/families.py``) the
runner times the candidate (``rescon.robustness`` by default) and, in the same
process, the published baselines that are feasible at that size
(``benchmarks/baselines.py``: LeBlanc exhaustive search, Usevitch–Panagou MILP).
It **checks that rho and s*(rho) agree** (between all methods and with closed forms)
before a time is used; any disagreement is recorded as an ``error`` row and makes
the run exit with status 1. Results: ``<out>/robustness.csv`` (one row per instance
and method) and ``<out>/robustness.md`` (medians and speed-up ratios).

See ``benchmarks/README.md`` for what is measured and how ratios are computed.
"""

from __future__ import annotations

import argparse
import csv
import datetime as _dt
import math
import os
import platform
import statistics
import sys
import time
import traceback
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import networkx as nx
import numpy as np

from . import baselines as B
from . import kernel_baselines as KB
from .families import FAMILIES, STRUCTURED, Instance, instances, known_s_star, variant_label
from .kernel_clouds import CLOUD_FAMILIES, Cloud, make_cloud
from .kernel_clouds import DEFAULT_SIZES as KC_DEFAULT_SIZES
from .kernel_clouds import clouds as kernel_clouds_iter

REPO = Path(__file__).resolve().parent.parent
DEFAULT_OUT = REPO / "benchmarks" / "results"

CSV_FIELDS = [
    "family", "params", "n", "instance", "seed", "method", "rho", "s_max", "seconds",
    "status", "detail",
]


# --------------------------------------------------------------------------- named sets


@dataclass(frozen=True)
class BenchSet:
    """A named test set: families (optionally restricted variants), sizes, settings."""

    name: str
    families: tuple[str, ...]
    sizes: tuple[int, ...]
    instances: int
    time_limit: float
    baselines: tuple[str, ...] = ("leblanc", "milp")
    variants: dict[str, list[dict[str, Any]]] = field(default_factory=dict)
    stem: str = "robustness"
    description: str = ""


SETS: dict[str, BenchSet] = {
    "core": BenchSet(
        "core", tuple(FAMILIES), (10, 15, 20, 25, 30), 10, 600.0,
        description="BENCHMARKS.md §1 grid against both baselines (LeBlanc to n = 20)",
    ),
    "milp": BenchSet(
        "milp", tuple(FAMILIES), (40, 50, 75, 100, 200), 10, 600.0, baselines=("milp",),
        stem="robustness_milp",
        description="BENCHMARKS.md §1 large grid against the MILP only (600 s limit)",
    ),
    "large": BenchSet(
        "large", STRUCTURED, (100, 200, 500, 1000), 3, 600.0, baselines=(),
        stem="robustness_large",
        description="structured families to n = 1000, checked against closed forms only",
    ),
    "quick": BenchSet(
        "quick",
        ("er", "er_directed", "k_in", "circulant_directed", "complete", "ba", "two_cliques",
         "random_regular"),
        (10, 16), 2, 30.0,
        variants={
            "er": [{"p": 0.5}], "er_directed": [{"p": 0.8}], "k_in": [{"k": 3}],
            "circulant_directed": [{"k": 4}], "ba": [{"m": 3}], "two_cliques": [{"b": 2}],
            "random_regular": [{"d": 4}],
        },
        stem="robustness_quick",
        description="CI smoke test (under a minute): n <= 16, 2 instances, 8 families",
    ),
}


# --------------------------------------------------------------------------- candidates


class CandidateUnavailable(RuntimeError):
    """The requested candidate cannot be run (e.g. rescon.robustness is missing)."""


@dataclass(frozen=True)
class Answer:
    rho: int | None
    s_max: int | None
    status: str  # 'exact', 'not_exact', 'optimal', 'time_limit', 'error:...'
    detail: str = ""


def _rescon_candidate() -> tuple[Callable[[nx.Graph], Answer], str]:
    """Adapter for ``rescon.robustness(G)`` (report with r_max, s_max, exact).

    The checkout's ``src/`` goes first on sys.path so the working tree is measured,
    not some installed copy.
    """
    src = REPO / "src"
    if src.is_dir() and str(src) not in sys.path:
        sys.path.insert(0, str(src))
    try:
        import rescon
    except Exception as exc:  # noqa: BLE001 - report any import failure clearly
        raise CandidateUnavailable(f"cannot import rescon: {type(exc).__name__}: {exc}") from exc
    fn = getattr(rescon, "robustness", None)
    if fn is None:
        raise CandidateUnavailable(
            "rescon.robustness does not exist (yet) in "
            f"{getattr(rescon, '__file__', None) or list(getattr(rescon, '__path__', []))}; "
            "use --candidate leblanc to exercise the harness"
        )

    try:  # rescon caches proven facts per graph; a repeat must not time a cache hit
        from rescon.graphs.facts import clear_cache as forget
    except ImportError:
        forget = None

    def run(G: nx.Graph, time_limit: float | None = None) -> Answer:
        if forget is not None:
            forget()
        rep = fn(G, time_limit=time_limit)
        missing = [a for a in ("r_max", "s_max", "exact") if not hasattr(rep, a)]
        if missing:
            raise TypeError(f"rescon.robustness report lacks attributes {missing}: {rep!r}")
        rho = None if rep.r_max is None else int(rep.r_max)
        s = None if rep.s_max is None else int(rep.s_max)
        return Answer(rho, s, "exact" if rep.exact else "not_exact")

    where = getattr(rescon, "__file__", None) or str(list(getattr(rescon, "__path__", [])))
    return run, f"rescon.robustness ({where}, version {getattr(rescon, '__version__', '?')})"


def _leblanc_candidate() -> tuple[Callable[[nx.Graph], Answer], str]:
    """LeBlanc as the candidate: to exercise the harness (ratios vs LeBlanc ≈ 1)."""

    def run(G: nx.Graph, time_limit: float | None = None) -> Answer:
        rho = B.leblanc_rho(G)
        s = B.leblanc_max_s(G, rho) if rho >= 1 else G.number_of_nodes()
        return Answer(rho, s, "exact")

    return run, "benchmarks.baselines LeBlanc exhaustive search (harness test)"


CANDIDATES: dict[str, Callable[[], tuple[Callable[[nx.Graph], Answer], str]]] = {
    "rescon": _rescon_candidate,
    "leblanc": _leblanc_candidate,
}


# --------------------------------------------------------------------------- baselines


def _run_leblanc(G: nx.Graph, time_limit: float) -> Answer:
    rho = B.leblanc_rho(G)
    s = B.leblanc_max_s(G, rho) if rho >= 1 else G.number_of_nodes()
    return Answer(rho, s, "optimal")


def _run_milp(G: nx.Graph, time_limit: float) -> Answer:
    """rho MILP, then the s*(rho) MILP with what is left of the per-instance budget."""
    t0 = time.perf_counter()
    r = B.milp_rho(G, time_limit=time_limit)
    if r.status != "optimal":
        return Answer(None, None, r.status, "rho MILP")
    rho = r.value
    assert rho is not None
    if rho == 0:
        return Answer(0, G.number_of_nodes(), "optimal", "s*(0) = n by definition")
    left = max(time_limit - (time.perf_counter() - t0), 1.0)
    s = B.milp_max_s(G, rho, time_limit=left)
    if s.status in ("optimal", "infeasible"):
        return Answer(rho, s.value, "optimal", "s MILP infeasible: s* = n" if s.status ==
                      "infeasible" else "")
    return Answer(rho, None, s.status, "s*(rho) MILP")


BASELINES: dict[str, Callable[[nx.Graph, float], Answer]] = {
    "leblanc": _run_leblanc,
    "milp": _run_milp,
}


# --------------------------------------------------------------------------- timing


def _timed(fn: Callable[[], Answer], repeats: int, budget: float = 1.0) -> tuple[Answer, float]:
    """Run fn; if it took < ``budget`` s, run it again up to ``repeats`` times in total.

    Returns the first answer (all repeats must agree) and the median wall time.
    """
    times = []
    t0 = time.perf_counter()
    first = fn()
    times.append(time.perf_counter() - t0)
    while len(times) < repeats and sum(times) < budget:
        t0 = time.perf_counter()
        again = fn()
        times.append(time.perf_counter() - t0)
        if (again.rho, again.s_max) != (first.rho, first.s_max):
            return Answer(first.rho, first.s_max, "error:nondeterministic",
                          f"repeat gave rho={again.rho}, s={again.s_max}"), statistics.median(times)
    return first, statistics.median(times)


def _guard(fn: Callable[[], Answer]) -> Callable[[], Answer]:
    def wrapped() -> Answer:
        try:
            return fn()
        except Exception as exc:  # noqa: BLE001 - every failure becomes an error row
            tb = traceback.format_exc(limit=3).strip().splitlines()[-1]
            return Answer(None, None, f"error:{type(exc).__name__}", f"{exc} [{tb}]")
    return wrapped


# --------------------------------------------------------------------------- run


@dataclass
class Config:
    set: BenchSet
    candidate: str
    families: tuple[str, ...]
    sizes: tuple[int, ...]
    instances: int
    time_limit: float
    baselines: tuple[str, ...]
    leblanc_max_n: int
    milp_max_n: int
    repeats: int
    out: Path
    stem: str
    argv: list[str]


def _check(inst: Instance, answers: dict[str, Answer], cand: str) -> list[str]:
    """Disagreements between methods and closed forms (rho, and s*(rho) when rho >= 1)."""
    errs: list[str] = []
    # a time-limited answer (not_exact: r_max is only a lower bound) is a time-out,
    # not an answer to compare
    rhos = {m: a.rho for m, a in answers.items() if a.rho is not None and a.status != "not_exact"}
    if inst.known_rho is not None:
        rhos["closed_form"] = inst.known_rho
    if len(set(rhos.values())) > 1:
        errs.append("rho mismatch: " + ", ".join(f"{m}={v}" for m, v in rhos.items()))
    ss = {m: a.s_max for m, a in answers.items()
          if a.rho is not None and a.s_max is not None and a.status != "not_exact"}
    ks = known_s_star(inst)
    if ks is not None:
        ss["closed_form"] = ks
    if len(set(rhos.values())) == 1 and next(iter(rhos.values())) >= 1:
        if len(set(ss.values())) > 1:
            errs.append("s*(rho) mismatch: " + ", ".join(f"{m}={v}" for m, v in ss.items()))
        c = answers.get(cand)
        others = [m for m in ss if m != cand]
        if c is not None and c.status == "exact" and c.s_max is None and others:
            errs.append(f"{cand} gave no s_max while {others} computed s*(rho)")
    for m, a in answers.items():
        if a.status.startswith("error"):
            errs.append(f"{m} failed: {a.status} {a.detail}".strip())
    return errs


def _row(inst: Instance, method: str, a: Answer | None, seconds: float | None,
         status: str | None = None, detail: str | None = None) -> dict[str, Any]:
    p = inst.params
    return {
        "family": inst.name,
        "params": variant_label(p),
        "n": p["n"],
        "instance": p["instance"],
        "seed": p["seed"],
        "method": method,
        "rho": "" if a is None or a.rho is None else a.rho,
        "s_max": "" if a is None or a.s_max is None else a.s_max,
        "seconds": "" if seconds is None else f"{seconds:.6f}",
        "status": status if status is not None else (a.status if a else ""),
        "detail": detail if detail is not None else (a.detail if a else ""),
    }


def _warmup(cand_fn: Callable[..., Answer], insts: list[Instance], log: Any,
            time_limit: float) -> None:
    """Compile numba kernels (baselines and candidate) before anything is timed.

    The candidate is run once on two tiny graphs and on the first instance of each
    family at the smallest size in the run (so size-dependent code paths are
    compiled too), each within the run's time limit. Failures here are not fatal:
    they show up as error rows later.
    """
    t0 = time.perf_counter()
    B.leblanc_warmup()
    B.milp_rho(nx.complete_graph(4), time_limit=10)
    B.milp_max_s(nx.cycle_graph(5), 1, time_limit=10)
    seen: set[str] = set()
    small = [nx.complete_graph(5), nx.gnp_random_graph(9, 0.5, seed=1, directed=True)]
    for inst in sorted(insts, key=lambda x: x.params["n"]):
        if inst.name not in seen:
            seen.add(inst.name)
            small.append(inst.G)
    for G in small:
        _guard(lambda G=G: cand_fn(G, time_limit))()
    print(f"warm-up {time.perf_counter() - t0:.1f} s", file=log, flush=True)


def run_robustness(cfg: Config, log: Any = sys.stderr) -> int:
    cand_fn, cand_desc = CANDIDATES[cfg.candidate]()  # raises CandidateUnavailable
    cand = cfg.candidate if cfg.candidate == "rescon" else f"{cfg.candidate}(candidate)"
    insts = list(instances(cfg.families, cfg.sizes, cfg.instances, cfg.set.variants or None))
    if not insts:
        print("error: the selection contains no instance", file=sys.stderr)
        return 2
    cfg.out.mkdir(parents=True, exist_ok=True)
    csv_path = cfg.out / f"{cfg.stem}.csv"
    md_path = cfg.out / f"{cfg.stem}.md"
    _warmup(cand_fn, insts, log, cfg.time_limit)

    rows: list[dict[str, Any]] = []
    n_err = 0
    interrupted = False
    started = time.perf_counter()
    with open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=CSV_FIELDS)
        w.writeheader()
        try:
            for k, inst in enumerate(insts, 1):
                n = inst.params["n"]
                answers: dict[str, Answer] = {}
                secs: dict[str, float] = {}
                a, t = _timed(_guard(lambda G=inst.G: cand_fn(G, cfg.time_limit)),
                              cfg.repeats)
                answers[cand], secs[cand] = a, t
                for b in cfg.baselines:
                    if (b == "leblanc" and n > cfg.leblanc_max_n) or (
                        b == "milp" and n > cfg.milp_max_n
                    ):
                        continue
                    fn = BASELINES[b]
                    a, t = _timed(_guard(lambda fn=fn, G=inst.G: fn(G, cfg.time_limit)),
                                  1 if b == "milp" else cfg.repeats)
                    answers[b], secs[b] = a, t
                new = [_row(inst, m, answers[m], secs[m]) for m in answers]
                errs = _check(inst, answers, cand)
                if errs:
                    n_err += 1
                    new.append(_row(inst, "check", None, None, "error", "; ".join(errs)))
                rows.extend(new)
                w.writerows(new)
                fh.flush()
                msg = " ".join(
                    f"{m}={a.rho}/{a.s_max}:{secs[m]:.3g}s"
                    + ("" if a.status in ("exact", "optimal") else f"[{a.status}]")
                    for m, a in answers.items()
                )
                print(f"[{k}/{len(insts)}] {inst.name}({variant_label(inst.params)}) n={n} "
                      f"i={inst.params['instance']} {msg}" + (" ERROR: " + "; ".join(errs)
                                                              if errs else ""),
                      file=log, flush=True)
        except KeyboardInterrupt:
            interrupted = True
            print("interrupted: writing the partial summary", file=log, flush=True)
    md = summarise(rows, cfg, cand, cand_desc, time.perf_counter() - started, interrupted)
    return _finish(md, md_path, csv_path, n_err, "instance(s)", interrupted, log)


def _finish(md: str, md_path, csv_path, n_err: int, unit: str, interrupted: bool,
            log) -> int:
    """Write the summary; exit code 130 if interrupted, 1 with errors, else 0."""
    md_path.write_text(md)
    print(f"wrote {csv_path} and {md_path}; {n_err} {unit} with errors", file=log)
    if interrupted:
        return 130
    return 1 if n_err else 0


# --------------------------------------------------------------------------- summary


def _fmt_t(x: float | None, lower: bool = False) -> str:
    if x is None:
        return "–"
    s = f"{x:.3g}" if x >= 1e-3 else f"{x:.2g}"
    return ("≥ " if lower else "") + s


def _fmt_r(x: float | None, lower: bool = False) -> str:
    if x is None:
        return "–"
    s = f"{x:.3g}×" if x < 1000 else f"{x:.0f}×"
    return ("≥ " if lower else "") + s


def _median(xs: Sequence[float]) -> float | None:
    return statistics.median(xs) if xs else None


def _versions() -> str:
    out = [f"Python {platform.python_version()}"]
    for mod in ("numpy", "numba", "networkx", "highspy", "scipy"):
        try:
            m = __import__(mod)
            v = getattr(m, "__version__", None)
            if v is None and mod == "highspy":
                from rescon.models.backends import silent_highs

                v = silent_highs().version()
            out.append(f"{mod} {v}")
        except Exception:  # noqa: BLE001
            out.append(f"{mod} ?")
    return ", ".join(out)


def _machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    load = ""
    if hasattr(os, "getloadavg"):
        load = ", load average at end {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())
    return f"{platform.system()} {platform.release()}, {cpu}, {os.cpu_count()} logical CPUs{load}"


def summarise(rows: list[dict[str, Any]], cfg: Config, cand: str, cand_desc: str,
              wall: float, interrupted: bool = False) -> str:
    """Markdown report: per (family, params, n) medians and ratios, targets, errors."""
    # group rows by instance
    by_inst: dict[tuple, dict[str, dict[str, Any]]] = {}
    errors: list[dict[str, Any]] = []
    for r in rows:
        key = (r["family"], r["params"], int(r["n"]), int(r["instance"]))
        by_inst.setdefault(key, {})[r["method"]] = r
        if r["method"] == "check":
            errors.append(r)
    cells: dict[tuple, list[dict[str, dict[str, Any]]]] = {}
    for key, ms in by_inst.items():
        cells.setdefault(key[:3], []).append(ms)

    def base_time(r: dict[str, Any]) -> tuple[float | None, bool]:
        """Baseline time, or the time limit as a lower bound for a time-out."""
        if r["status"] == "time_limit":
            return cfg.time_limit, True
        if r["status"] == "optimal" and r["seconds"] != "":
            return float(r["seconds"]), False
        return None, False

    lines = []
    title = f"# Robustness benchmark — set `{cfg.set.name}`"
    lines += [title, ""]
    if interrupted:
        lines += ["**INTERRUPTED: partial results.**", ""]
    n_inst = len(by_inst)
    status = ("**All answers agree** (candidate, baselines and closed forms)." if not errors else
              f"**{len(errors)} instance(s) with disagreements or failures — see Errors.**")
    lines += [
        f"- Generated {_dt.datetime.now(_dt.UTC).strftime('%Y-%m-%d %H:%M UTC')} by "
        f"`python -m benchmarks.run {' '.join(cfg.argv)}` in {wall:.0f} s.",
        f"- Candidate `{cand}`: {cand_desc}.",
        f"- Baselines: {', '.join(cfg.baselines) or 'none'} "
        f"(LeBlanc for n ≤ {cfg.leblanc_max_n}, "
        f"MILP for n ≤ {cfg.milp_max_n}, MILP time limit {cfg.time_limit:g} s per instance).",
        f"- Machine: {_machine()}.",
        f"- {_versions()}.",
        f"- {n_inst} instances; {status}",
        "",
        "Times are wall-clock seconds (median over instances; each instance's time is the",
        f"median of up to {cfg.repeats} repeats when one run takes < 1 s; numba kernels are",
        "compiled before timing). A time covers rho and s*(rho) together. Ratio = baseline",
        "time / candidate time on the same instance, median over the instances of the cell;",
        "instances with errors are left out of ratios. A MILP time-out counts as",
        f"{cfg.time_limit:g} s, a **lower bound** on its time, so medians and ratios that",
        "include a time-out are lower bounds (marked ≥).",
        "",
    ]

    # targets
    def collect(pred: Callable[[int], bool], base: str) -> tuple[list[float], bool]:
        ratios, lower = [], False
        for (_fam, _par, n), insts in cells.items():
            if not pred(n):
                continue
            for ms in insts:
                if "check" in ms or cand not in ms or base not in ms:
                    continue
                bt, lb = base_time(ms[base])
                ct = ms[cand]["seconds"]
                if bt is None or ct == "":
                    continue
                ratios.append(bt / max(float(ct), 1e-9))
                lower |= lb
        return ratios, lower

    tgt = []
    r_milp, lb = collect(lambda n: 25 <= n <= 40, "milp")
    if r_milp:
        med = statistics.median(r_milp)
        tgt.append(f"| median MILP/candidate ratio, n = 25–40 | ≥ 20× | {_fmt_r(med, lb)} "
                   f"({len(r_milp)} instances) | {'met' if med >= 20 else 'NOT met'} |")
    small = [(ms[cand], n) for (f, p, n), insts in cells.items() if n <= 30 for ms in insts
             if cand in ms and ms[cand]["seconds"] != ""]
    if small:
        worst = max(float(r["seconds"]) for r, _ in small)
        exact = sum(1 for r, _ in small if r["status"] == "exact")
        tgt.append(f"| exact rho and s*(rho) for n ≤ 30 in ≤ 10 s | ≤ 10 s, exact | max "
                   f"{_fmt_t(worst)} s, {exact}/{len(small)} exact | "
                   f"{'met' if worst <= 10 and exact == len(small) else 'NOT met'} |")
    if tgt:
        lines += ["## Targets (BENCHMARKS.md §1)", "",
                  "| target | goal | measured | |", "|---|---|---|---|", *tgt, ""]

    # table
    has_lb = any("leblanc" in ms for v in cells.values() for ms in v)
    has_milp = any("milp" in ms for v in cells.values() for ms in v)
    head = ["family", "params", "n", "inst", f"{cand} s"]
    if has_lb:
        head += ["LeBlanc s", "LeBlanc/cand"]
    if has_milp:
        head += ["MILP s", "MILP/cand", "MILP time-outs"]
    head += ["errors"]
    lines += ["## Per (family, params, n)", "", "| " + " | ".join(head) + " |",
              "|" + "---|" * len(head)]
    for (fam, par, n) in sorted(cells, key=lambda k: (list(FAMILIES).index(k[0])
                                                      if k[0] in FAMILIES else 99, k[1], k[2])):
        insts = cells[(fam, par, n)]
        ok = [ms for ms in insts if "check" not in ms]
        ct = [float(ms[cand]["seconds"]) for ms in insts
              if cand in ms and ms[cand]["seconds"] != ""]
        cells_out = [fam, par or "–", str(n), str(len(insts)), _fmt_t(_median(ct))]
        for base, enabled in (("leblanc", has_lb), ("milp", has_milp)):
            if not enabled:
                continue
            bts, rat, lower, touts, ran = [], [], False, 0, 0
            for ms in insts:
                if base not in ms:
                    continue
                ran += 1
                bt, lb_ = base_time(ms[base])
                touts += ms[base]["status"] == "time_limit"
                if bt is None:
                    continue
                bts.append(bt)
                lower |= lb_
                if ms in ok and cand in ms and ms[cand]["seconds"] != "":
                    rat.append(bt / max(float(ms[cand]["seconds"]), 1e-9))
            if not ran:
                cells_out += ["–", "–"] + (["–"] if base == "milp" else [])
                continue
            cells_out += [_fmt_t(_median(bts), lower), _fmt_r(_median(rat), lower)]
            if base == "milp":
                cells_out.append(f"{touts}/{ran}")
        cells_out.append(str(len(insts) - len(ok)))
        lines.append("| " + " | ".join(cells_out) + " |")
    lines.append("")

    if errors:
        lines += ["## Errors", "", "| family | params | n | instance | seed | detail |",
                  "|---|---|---|---|---|---|"]
        for r in errors:
            d = str(r["detail"]).replace("|", "\\|")
            lines.append(f"| {r['family']} | {r['params']} | {r['n']} | {r['instance']} | "
                         f"{r['seed']} | {d} |")
        lines.append("")
    return "\n".join(lines)


# =========================================================================== kernels (§2)
#
# ``python -m benchmarks.run kernels``: rescon.safe_kernel (polytope), K.point("project")
# (point + certificate, timed separately), the emptiness certificate (the safe_kernel
# call that returns a ``kernel_empty`` certificate), and the subset LP / subset-hull
# qhull baselines (benchmarks/kernel_baselines.py) on the point clouds of
# benchmarks/kernel_clouds.py. Answers are compared before any time is reported and
# every certificate is verified by rescon.check_certificate (not timed).

KERNEL_CSV_FIELDS = [
    "family", "d", "n", "F", "seed", "method", "empty", "dim", "vertices", "seconds",
    "status", "cert", "detail",
]

#: the instances behind the reference times quoted in BENCHMARKS.md §2
#: (subset LP 7.6 s at n = 25, F = 4, d = 2; qhull 4.9 s at n = 20, F = 6)
KERNEL_REFERENCE: tuple[tuple[str, int, int, int, str, float], ...] = (
    ("gaussian", 2, 25, 4, "lp", 7.6),
    ("gaussian", 2, 20, 6, "qhull", 4.9),
)

KERNEL_BASELINES = ("lp", "qhull")


@dataclass(frozen=True)
class KernelSet:
    """A named set of clouds and baseline settings for ``benchmarks.run kernels``."""

    name: str
    families: tuple[str, ...]
    sizes: dict[int, tuple[int, ...]]
    f_values: tuple[int, ...] | None = None  # None: kernel_clouds.f_values
    baselines: tuple[str, ...] = KERNEL_BASELINES
    max_subsets: int = KB.MAX_SUBSETS
    time_limit: float = 600.0
    reference: bool = True  # add the reference instances (baselines forced on them)
    cert_timeout: float = 60.0  # seconds per rescon.check_certificate call
    description: str = ""


KERNEL_SETS: dict[str, KernelSet] = {
    "core": KernelSet(
        "core", tuple(CLOUD_FAMILIES), dict(KC_DEFAULT_SIZES),
        description="BENCHMARKS.md §2 grid: all families, d = 2 (n to 1000), d = 3 (n to 100), "
                    "a few d = 4, 5; baselines up to 2·10^5 subsets, 600 s limit",
    ),
    "reduced": KernelSet(
        "reduced", tuple(CLOUD_FAMILIES), dict(KC_DEFAULT_SIZES), max_subsets=5_000,
        cert_timeout=10.0,
        description="REDUCED RUN: the full §2 cloud grid for rescon, but the baselines only "
                    "where C(n,F) ≤ 5000 subsets (plus the two reference instances) and "
                    "10 s per certificate check; the full run is `--set core`",
    ),
    "quick": KernelSet(
        "quick", tuple(CLOUD_FAMILIES), {2: (10, 20, 50), 3: (10,)}, max_subsets=2_000,
        time_limit=60.0, reference=False, cert_timeout=30.0,
        description="CI smoke test (< 3 min): all families, d = 2 (n ≤ 50), d = 3 (n = 10), "
                    "baselines where C(n,F) ≤ 2000",
    ),
}


@dataclass
class KernelConfig:
    set: KernelSet
    families: tuple[str, ...]
    sizes: dict[int, tuple[int, ...]]
    f_values: tuple[int, ...] | None
    baselines: tuple[str, ...]
    max_subsets: int
    time_limit: float
    reference: bool
    repeats: int
    out: Path
    stem: str
    argv: list[str]
    cert_timeout: float = 60.0


@dataclass
class KernelRecord:
    """Everything measured on one cloud."""

    cloud: Cloud
    forced: bool = False  # a reference instance: baselines run whatever max_subsets says
    empty: bool | None = None
    dim: int | None = None
    n_vertices: int | None = None
    t_poly: float | None = None
    t_point: float | None = None
    kcert: str = ""
    kcert_reason: str = ""
    pcert: str = ""
    pcert_reason: str = ""
    base: dict[str, tuple[str, float | None, str]] = field(default_factory=dict)
    hausdorff: float | None = None
    errors: list[str] = field(default_factory=list)  # rescon failures, unresolved disagreements
    # baseline failures (solver trouble) and disagreements settled against the baseline
    # by rescon's exactly verified certificate: listed, left out of that baseline's ratios
    base_issues: dict[str, str] = field(default_factory=dict)


class _Nondeterministic(RuntimeError):
    pass


def _time_call(fn: Callable[[], Any], repeats: int, same: Callable[[Any, Any], bool] | None,
               budget: float = 1.0) -> tuple[Any, float]:
    """Run fn; repeat while the total stays < budget, up to ``repeats`` runs; median."""
    times: list[float] = []
    first: Any = None
    while True:
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
        if len(times) == 1:
            first = out
        elif same is not None and not same(first, out):
            raise _Nondeterministic("a repeated call gave a different answer")
        if len(times) >= repeats or sum(times) >= budget:
            return first, statistics.median(times)


def _check_in_worker(cert: dict) -> tuple[str, str, tuple[str, ...]]:
    import rescon

    r = rescon.check_certificate(cert)
    return str(r.verdict), str(r.reason), tuple(r.trusted)


class _CertChecker:
    """rescon.check_certificate with a wall-clock limit: the check runs in a forked
    worker process (the runner waits for it, so nothing is timed meanwhile); a check
    that takes longer than ``timeout`` s is abandoned (worker killed and restarted) and
    reported as ``timeout``. ``timeout`` ≤ 0: in-process, no limit."""

    def __init__(self, timeout: float):
        self.timeout = timeout
        self._pool: Any = None

    def start(self) -> None:
        if self.timeout > 0 and self._pool is None:
            import multiprocessing

            self._pool = multiprocessing.get_context("fork").Pool(1)

    def close(self) -> None:
        if self._pool is not None:
            self._pool.terminate()
            self._pool.join()
            self._pool = None

    def __call__(self, cert: dict) -> tuple[str, str]:
        """valid / trusted / too_large (checker work limit) / timeout / INVALID / error;
        the checker's "unchecked" verdict is too_large when its vertex enumeration was
        beyond the limit, else trusted (the halfspace membership beyond its limit)."""
        import multiprocessing

        try:
            if self.timeout > 0:
                self.start()
                verdict, reason, trusted = self._pool.apply_async(
                    _check_in_worker, (cert,)).get(self.timeout)
            else:
                verdict, reason, trusted = _check_in_worker(cert)
        except multiprocessing.TimeoutError:
            self.close()
            return "timeout", f"checker still running after {self.timeout:g} s: not verified"
        except Exception as exc:  # noqa: BLE001
            return "error", f"{type(exc).__name__}: {exc}"
        if verdict == "unchecked":
            return ("too_large" if "vertex enumeration" in trusted else "trusted"), reason
        return ("valid" if verdict == "valid" else "INVALID"), reason


def _same_kernel(a: Any, b: Any) -> bool:
    return a.dim == b.dim and a.exact_vertices == b.exact_vertices


def _same_point(a: Any, b: Any) -> bool:
    return bool(np.array_equal(a[0], b[0])) and a[1].get("x") == b[1].get("x")


def _rescon_kernel_api() -> tuple[Any, str]:
    src = REPO / "src"
    if src.is_dir() and str(src) not in sys.path:
        sys.path.insert(0, str(src))
    try:
        import rescon
    except Exception as exc:  # noqa: BLE001
        raise CandidateUnavailable(f"cannot import rescon: {type(exc).__name__}: {exc}") from exc
    missing = [a for a in ("safe_kernel", "check_certificate") if not hasattr(rescon, a)]
    if missing:
        raise CandidateUnavailable(f"rescon lacks {missing}")
    where = getattr(rescon, "__file__", None) or str(list(getattr(rescon, "__path__", [])))
    return rescon, f"rescon.safe_kernel + SafeKernel.point('project') ({where}, version " \
                   f"{getattr(rescon, '__version__', '?')})"


def _kernel_clouds(cfg: KernelConfig) -> list[tuple[Cloud, bool]]:
    out = [(c, False) for c in kernel_clouds_iter(cfg.families, cfg.sizes, cfg.f_values)]
    if cfg.reference:
        have = {(c.family, c.d, c.n, c.F): i for i, (c, _) in enumerate(out)}
        for fam, d, n, F, _, _ in KERNEL_REFERENCE:
            key = (fam, d, n, F)
            if key in have:
                out[have[key]] = (out[have[key]][0], True)
            else:
                out.append((make_cloud(fam, d, n, F), True))
    return out


def _kernel_warmup(rescon: Any, todo: list[tuple[Cloud, bool]], log: Any) -> None:
    """Compile numba (rescon's kernels) and load HiGHS / qhull before any timing: a
    small cloud per dimension, the first cloud of each (family, d) at its smallest
    n, and one cloud per dimension at its largest n (small inputs skip numba, so only
    large ones load its compiled kernels: gaussian(2, 1000, 1), the first n = 1000
    cloud, had been timed with numba's load, 1–4 s). Failures here are not fatal (they
    show up as error rows later)."""
    t0 = time.perf_counter()
    warm: list[tuple[np.ndarray, int]] = []
    for d in sorted({c.d for c, _ in todo}):
        warm.append((make_cloud("gaussian", d, 2 * d + 4, 1).X, 1))
        warm.append((make_cloud("above_helly", d, 2 * d + 4, (2 * d + 3) // (d + 1) + 1).X,
                     (2 * d + 3) // (d + 1) + 1))
    seen: set[tuple[str, int]] = set()
    for c, _ in sorted(todo, key=lambda t: (t[0].n, t[0].F)):
        if (c.family, c.d) not in seen and c.n <= 100:
            seen.add((c.family, c.d))
            warm.append((c.X, c.F))
    largest: dict[int, Cloud] = {}
    for c, _ in todo:
        if c.d not in largest or c.n > largest[c.d].n:
            largest[c.d] = c
    warm += [(c.X, c.F) for c in largest.values() if c.n > 100]
    for X, F in warm:
        try:
            K = rescon.safe_kernel(X, F)
            if not K.is_empty:
                K.point("project")
        except Exception as exc:  # noqa: BLE001 - reported again, as an error row, later
            print(f"warm-up: {type(exc).__name__}: {exc}", file=log, flush=True)
    X = make_cloud("gaussian", 2, 6, 1).X
    KB.subset_lp(X, 1)
    KB.subset_hull_qhull(X, 1)
    print(f"warm-up {time.perf_counter() - t0:.1f} s ({len(warm)} clouds)", file=log, flush=True)


def _kernel_one(rescon: Any, cloud: Cloud, forced: bool, cfg: KernelConfig,
                checker: Callable[[dict], tuple[str, str]]) -> KernelRecord:
    rec = KernelRecord(cloud, forced)
    X, F, n, d = cloud.X, cloud.F, cloud.n, cloud.d
    try:
        K, rec.t_poly = _time_call(lambda: rescon.safe_kernel(X, F), cfg.repeats, _same_kernel)
    except Exception as exc:  # noqa: BLE001
        tb = traceback.format_exc(limit=3).strip().splitlines()[-1]
        rec.errors.append(f"rescon.safe_kernel failed: {type(exc).__name__}: {exc} [{tb}]")
        return rec
    rec.empty, rec.dim, rec.n_vertices = K.is_empty, K.dim, len(K.vertices)
    rec.kcert, rec.kcert_reason = checker(K.certificate)
    want = "kernel_empty" if K.is_empty else "safe_kernel"
    if K.certificate.get("kind") != want:
        rec.errors.append(f"certificate kind {K.certificate.get('kind')!r}, expected {want!r}")
    if rec.kcert in ("INVALID", "error"):
        rec.errors.append(f"{want} certificate rejected by the checker: {rec.kcert_reason}")
    if cloud.expect_empty is not None and cloud.expect_empty != K.is_empty:
        rec.errors.append(f"kernel {'empty' if K.is_empty else 'nonempty'} but the construction "
                          f"forces it {'empty' if cloud.expect_empty else 'nonempty'} "
                          f"(F = {F}, Helly bound {(n - 1) // (d + 1)})")
    if not K.is_empty:
        try:
            (x, pc), rec.t_point = _time_call(lambda: K.point("project"), cfg.repeats,
                                              _same_point)
            rec.pcert, rec.pcert_reason = checker(pc)
            if rec.pcert in ("INVALID", "error"):
                rec.errors.append(f"kernel_point certificate rejected: {rec.pcert_reason}")
            if not K.contains(x, tol=1e-9):
                rec.errors.append(f"K.point('project') = {x.tolist()} not in K (tol 1e-9)")
        except Exception as exc:  # noqa: BLE001
            tb = traceback.format_exc(limit=3).strip().splitlines()[-1]
            rec.errors.append(f"K.point('project') failed: {type(exc).__name__}: {exc} [{tb}]")
    C = math.comb(n, F)
    for b in cfg.baselines:
        cap = max(cfg.max_subsets, C) if forced else cfg.max_subsets
        if C > cap:
            rec.base[b] = ("skipped", None, f"C({n},{F}) = {C} > {cap} subsets")
            continue
        try:
            if b == "lp":
                r, t = _time_call(lambda cap=cap: KB.subset_lp(X, F, max_subsets=cap,
                                                               time_limit=cfg.time_limit),
                                  cfg.repeats, lambda a, b_: a.status == b_.status)
                err = KB.compare_lp(K, r)
                detail = (f"{r.n_vars} variables; " + (f"x = {r.x.tolist()}" if r.x is not None
                                                         else r.detail)).strip()
            else:
                r, t = _time_call(lambda cap=cap: KB.subset_hull_qhull(
                                      X, F, max_subsets=cap, time_limit=cfg.time_limit),
                                  cfg.repeats, lambda a, b_: a.status == b_.status)
                err, rec.hausdorff = KB.compare_qhull(K, r)
                detail = f"{r.n_halfspaces} halfspaces" + (
                    f", Hausdorff {rec.hausdorff:.3g}" if rec.hausdorff is not None else "") + (
                    f"; {r.detail}" if r.detail else "")
        except Exception as exc:  # noqa: BLE001
            tb = traceback.format_exc(limit=3).strip().splitlines()[-1]
            rec.base[b] = (f"error:{type(exc).__name__}", None, f"{exc} [{tb}]")
            rec.base_issues[b] = f"{b} raised {type(exc).__name__}: {exc}"
            continue
        rec.base[b] = (r.status, t, detail)
        name = "subset LP" if b == "lp" else "qhull"
        if err:
            if rec.kcert == "valid":
                # rescon's answer is proved by a certificate the independent checker
                # verified in exact arithmetic: the float baseline is wrong here
                note = ""
                if b == "lp" and r.x is not None and d == 2:
                    dep = KB.tukey_depth_2d_exact(X, r.x)
                    note = (f" [exact Tukey depth of the LP point: {dep}, "
                            f"{'≥' if dep >= F + 1 else '<'} F+1 = {F + 1}]")
                rec.base_issues[b] = (f"{name} WRONG (rescon's {want} certificate verified "
                                      f"exactly): {err}{note}")
            else:
                rec.errors.append(f"{name} disagrees with rescon (rescon certificate "
                                  f"{rec.kcert or 'missing'}): {err}")
        elif r.status.startswith("error"):
            rec.base_issues[b] = f"{name} failed: {r.status} {r.detail}".strip()
    return rec


def _kernel_rows(rec: KernelRecord) -> list[dict[str, Any]]:
    c = rec.cloud
    common = {"family": c.family, "d": c.d, "n": c.n, "F": c.F, "seed": c.seed}
    rows = []
    if rec.t_poly is not None:
        rows.append({**common, "method": "rescon_empty" if rec.empty else "rescon_polytope",
                     "empty": int(bool(rec.empty)), "dim": rec.dim, "vertices": rec.n_vertices,
                     "seconds": f"{rec.t_poly:.6f}", "status": "ok", "cert": rec.kcert,
                     "detail": rec.kcert_reason if rec.kcert != "valid" else ""})
    if rec.t_point is not None:
        rows.append({**common, "method": "rescon_point", "empty": 0, "dim": rec.dim,
                     "vertices": rec.n_vertices, "seconds": f"{rec.t_point:.6f}",
                     "status": "ok", "cert": rec.pcert,
                     "detail": rec.pcert_reason if rec.pcert != "valid" else ""})
    for b, (st, t, detail) in rec.base.items():
        rows.append({**common, "method": "subset_lp" if b == "lp" else "qhull", "empty": "",
                     "dim": "", "vertices": "", "seconds": "" if t is None else f"{t:.6f}",
                     "status": st, "cert": "", "detail": detail})
    if rec.errors:
        rows.append({**common, "method": "check", "empty": "", "dim": "", "vertices": "",
                     "seconds": "", "status": "error", "cert": "",
                     "detail": "; ".join(rec.errors)})
    for issue in rec.base_issues.values():
        rows.append({**common, "method": "check", "empty": "", "dim": "", "vertices": "",
                     "seconds": "", "cert": "", "detail": issue,
                     "status": "baseline_wrong" if "WRONG" in issue else "baseline_failed"})
    return rows


def run_kernels(cfg: KernelConfig, log: Any = sys.stderr) -> int:
    rescon, desc = _rescon_kernel_api()  # raises CandidateUnavailable
    todo = _kernel_clouds(cfg)
    if not todo:
        print("error: the selection contains no cloud", file=sys.stderr)
        return 2
    cfg.out.mkdir(parents=True, exist_ok=True)
    csv_path = cfg.out / f"{cfg.stem}.csv"
    md_path = cfg.out / f"{cfg.stem}.md"
    checker = _CertChecker(cfg.cert_timeout)
    checker.start()  # fork the worker before numba starts its threads
    _kernel_warmup(rescon, todo, log)
    recs: list[KernelRecord] = []
    interrupted = False
    started = time.perf_counter()
    with open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=KERNEL_CSV_FIELDS)
        w.writeheader()
        try:
            for k, (cloud, forced) in enumerate(todo, 1):
                rec = _kernel_one(rescon, cloud, forced, cfg, checker)
                recs.append(rec)
                w.writerows(_kernel_rows(rec))
                fh.flush()
                parts = []
                if rec.t_poly is not None:
                    parts.append(("empty" if rec.empty else f"dim {rec.dim}, {rec.n_vertices} v")
                                 + f" {rec.t_poly * 1e3:.3g} ms")
                if rec.t_point is not None:
                    parts.append(f"point {rec.t_point * 1e3:.3g} ms")
                parts.append(f"cert {rec.kcert}" + (f"/{rec.pcert}" if rec.pcert else ""))
                for b, (st, t, _) in rec.base.items():
                    if st != "skipped":
                        parts.append(f"{b} {st} {t:.3g} s" if t is not None else f"{b} {st}")
                print(f"[{k}/{len(todo)}] {cloud.label} " + ", ".join(parts)
                      + (" ERROR: " + "; ".join(rec.errors) if rec.errors else "")
                      + "".join(f" BASELINE: {v}" for v in rec.base_issues.values()),
                      file=log, flush=True)
        except KeyboardInterrupt:
            interrupted = True
            print("interrupted: writing the partial summary", file=log, flush=True)
        finally:
            checker.close()
    md = summarise_kernels(recs, cfg, desc, time.perf_counter() - started, interrupted)
    n_err = sum(1 for r in recs if r.errors)
    return _finish(md, md_path, csv_path, n_err, "cloud(s)", interrupted, log)


# --------------------------------------------------------------------------- kernels summary


def _ms(x: float | None, lower: bool = False) -> str:
    if x is None:
        return "–"
    x *= 1e3
    s = f"{x:.3g}" if x < 1000 else f"{x:.0f}"
    return ("≥ " if lower else "") + s


def _base_time(rec: KernelRecord, b: str, limit: float) -> tuple[float | None, bool]:
    st, t, _ = rec.base.get(b, ("", None, ""))
    if st == "time_limit":
        return limit, True
    if t is None or st in ("skipped", "n/a") or st.startswith("error"):
        return None, False  # no answer: no time to report
    return t, False


def _cand_time(rec: KernelRecord, b: str) -> float | None:
    """The rescon time a baseline is compared with: the polytope for qhull; the polytope
    plus the point (or the emptiness proof) for the subset LP, which returns a point."""
    if rec.t_poly is None:
        return None
    if b == "lp":
        return rec.t_poly + (rec.t_point or 0.0)
    return rec.t_poly


def _agg(recs: list[KernelRecord], limit: float) -> list[str]:
    """Cells for one row of the per-size / per-family tables."""
    ok = [r for r in recs if not r.errors]
    tp = [r.t_poly for r in recs if r.t_poly is not None and not r.empty]
    te = [r.t_poly for r in recs if r.t_poly is not None and r.empty]
    tq = [r.t_point for r in recs if r.t_point is not None]
    cells = [str(len(recs)), str(sum(1 for r in recs if r.empty)),
             _ms(_median(tp)), _ms(max(tp) if tp else None),
             _ms(_median(tq)), _ms(max(tq) if tq else None),
             _ms(max(te) if te else None)]
    for b in KERNEL_BASELINES:
        ts, rat, lower, ran = [], [], False, 0
        extra = 0
        for r in recs:
            st = r.base.get(b, ("", None, ""))[0]
            if b == "qhull" and st == "n/a":
                extra += 1
            bt, lb = _base_time(r, b, limit)
            if bt is None:
                continue
            ran += 1
            ts.append(bt)
            lower |= lb
            ct = _cand_time(r, b)
            if r in ok and b not in r.base_issues and ct:
                rat.append(bt / max(ct, 1e-9))
        cells += [str(ran), _fmt_t(_median(ts), lower), _fmt_r(_median(rat), lower)]
        if b == "qhull":
            cells.append(str(extra))
    cells.append(str(len(recs) - len(ok)))
    cells.append(str(sum(len(r.base_issues) for r in recs)))
    return cells


_AGG_HEAD = ["clouds", "empty", "polytope med ms", "polytope max ms", "point med ms",
             "point max ms", "empty-cert max ms", "LP runs", "LP med s", "LP/rescon",
             "qhull runs", "qhull med s", "qhull/rescon", "qhull n/a", "errors",
             "baseline issues"]


def _target(recs: list[KernelRecord], goal: float, what: str, label: str,
            get: Callable[[KernelRecord], float | None]) -> str | None:
    vals = [(get(r), r) for r in recs]
    vals = [(t, r) for t, r in vals if t is not None]
    if not vals:
        return f"| {label} | {what} ≤ {_ms(goal)} ms | no instance in this run | – |"
    ts = [t for t, _ in vals]
    worst, wr = max(vals, key=lambda v: v[0])
    over = sum(1 for t in ts if t > goal)
    med = statistics.median(ts)
    verdict = "met" if over == 0 else (
        f"**NOT met** ({over}/{len(ts)} over" + ("; median met)" if med <= goal else ")"))
    return (f"| {label} | {what} ≤ {_ms(goal)} ms | median {_ms(med)} ms, max {_ms(worst)} ms "
            f"({wr.cloud.label}), {len(ts)} clouds | {verdict} |")


def summarise_kernels(recs: list[KernelRecord], cfg: KernelConfig, desc: str, wall: float,
                      interrupted: bool = False) -> str:
    lim = cfg.time_limit
    lines = [f"# Safe-kernel benchmark — set `{cfg.set.name}`", ""]
    if interrupted:
        lines += ["**INTERRUPTED: partial results.**", ""]
    errors = [r for r in recs if r.errors]
    n_empty = sum(1 for r in recs if r.empty)

    def cert_counts(attr: str) -> str:
        cnt: dict[str, int] = {}
        for r in recs:
            v = getattr(r, attr)
            if v:
                cnt[v] = cnt.get(v, 0) + 1
        order = ["valid", "trusted", "too_large", "timeout", "INVALID", "error"]
        return ", ".join(f"{k} {cnt[k]}" for k in order if k in cnt) or "none"

    n_wrong = sum(1 for r in recs for v in r.base_issues.values() if "WRONG" in v)
    n_bfail = sum(1 for r in recs for v in r.base_issues.values() if "WRONG" not in v)
    status = ("**No rescon error**: rescon agrees with every baseline answer that was not "
              "refuted by an exactly verified certificate, with Helly / construction "
              "expectations, and no certificate was rejected." if not errors else
              f"**{len(errors)} cloud(s) with rescon failures or unresolved disagreements — "
              "see Errors.**")
    status += (f" Baselines: {n_wrong} answer(s) refuted by rescon's verified certificates, "
               f"{n_bfail} solver failure(s) (see the baseline section).")
    lines += [
        f"- Generated {_dt.datetime.now(_dt.UTC).strftime('%Y-%m-%d %H:%M UTC')} by "
        f"`python -m benchmarks.run {' '.join(cfg.argv)}` in {wall:.0f} s.",
        f"- Set `{cfg.set.name}`: {cfg.set.description}.",
        f"- Candidate: {desc}.",
        f"- Baselines: {', '.join(cfg.baselines) or 'none'} (subset LP = `subset_lp`, qhull = "
        f"`subset_hull_qhull` in benchmarks/kernel_baselines.py), run where C(n,F) ≤ "
        f"{cfg.max_subsets}" + (" and on the reference instances" if cfg.reference else "")
        + f"; time limit {lim:g} s per call.",
        f"- Machine: {_machine()}.",
        f"- {_versions()}.",
        f"- {len(recs)} clouds ({n_empty} with an empty kernel); {status}",
        f"- Certificates (rescon.check_certificate, not timed): kernel/emptiness "
        f"{cert_counts('kcert')}; point {cert_counts('pcert')}. `trusted` = not fully "
        f"checked (halfspace membership beyond the checker's limit), `too_large` = beyond "
        f"the checker's work limit, "
        f"`timeout` = the checker ran longer than {cfg.cert_timeout:g} s (both: not "
        f"verified, not counted as failures).",
        "",
        "Times are wall-clock (`time.perf_counter`), median of up to "
        f"{cfg.repeats} repeats while one cloud's calls stay under 1 s, after a numba "
        "warm-up. *polytope* = `rescon.safe_kernel(X, F)` on nonempty kernels; *point* = "
        "`K.point('project')` (exact point + `kernel_point` certificate, timed separately); "
        "*empty-cert* = `safe_kernel` on clouds whose kernel is empty (it returns the "
        "`kernel_empty` certificate). Ratios (> 1: rescon faster) are medians over clouds of "
        "baseline time / rescon time, where rescon time = polytope + point for the subset LP "
        "(which also returns a point) and polytope for qhull (which returns the vertices); "
        "clouds with errors are left out. A baseline time-out counts as the limit (≥).",
        "",
    ]

    def sel(pred: Callable[[KernelRecord], bool]) -> list[KernelRecord]:
        return [r for r in recs if pred(r)]

    def poly(r: KernelRecord) -> float | None:
        return r.t_poly if r.t_poly is not None and not r.empty else None

    def pt(r: KernelRecord) -> float | None:
        return r.t_point

    def emp(r: KernelRecord) -> float | None:
        return r.t_poly if r.t_poly is not None and r.empty else None
    tg = [
        _target(sel(lambda r: r.cloud.d == 2 and r.cloud.n <= 100), 0.020, "polytope",
                "d = 2, n ≤ 100: exact polytope", poly),
        _target(sel(lambda r: r.cloud.d == 2 and r.cloud.n <= 100), 0.005, "point + cert",
                "d = 2, n ≤ 100: point + certificate", pt),
        _target(sel(lambda r: r.cloud.d == 2 and r.cloud.n == 1000), 1.0, "polytope",
                "d = 2, n = 1000: exact polytope", poly),
        _target(sel(lambda r: r.cloud.d == 3 and r.cloud.n == 50), 0.050, "polytope",
                "d = 3, n = 50: exact polytope", poly),
        _target(sel(lambda r: r.cloud.d == 3 and r.cloud.n == 100), 0.150, "polytope",
                "d = 3, n = 100: exact polytope", poly),
        _target(sel(lambda r: True), 0.020, "emptiness cert", "emptiness certificate (all)",
                emp),
    ]
    for d in sorted({r.cloud.d for r in recs}):
        tg.append(_target(sel(lambda r, d=d: r.cloud.d == d), 0.020, "emptiness cert",
                          f"… of which d = {d}", emp))
    lines += ["## Targets (BENCHMARKS.md §2)", "",
              "Verdict `met` only when **every** cloud of the group is within the target.", "",
              "| target | goal | measured | verdict |", "|---|---|---|---|",
              *[t for t in tg if t], ""]

    if cfg.reference:
        lines += ["## Reference instances (BENCHMARKS.md §2 quotes)", "",
                  "| instance | baseline | quoted | measured here | rescon (poly + point) | "
                  "ratio | agree |", "|---|---|---|---|---|---|---|"]
        for fam, d, n, F, b, quoted in KERNEL_REFERENCE:
            r = next((x for x in recs if (x.cloud.family, x.cloud.d, x.cloud.n, x.cloud.F)
                      == (fam, d, n, F)), None)
            if r is None or b not in cfg.baselines:
                continue
            bt, lb = _base_time(r, b, lim)
            ct = _cand_time(r, b)
            st = r.base.get(b, ("–", None, ""))[0]
            ratio = _fmt_r(bt / max(ct, 1e-9), lb) if bt is not None and ct else "–"
            lines.append(f"| {r.cloud.label} | {'subset LP' if b == 'lp' else 'qhull'} | "
                         f"{quoted:g} s | {_fmt_t(bt, lb)} s ({st}) | {_ms(ct)} ms | {ratio} | "
                         f"{'no' if r.errors else 'yes'} |")
        lines.append("")

    by_size: dict[tuple[int, int], list[KernelRecord]] = {}
    by_fam: dict[tuple[str, int, int], list[KernelRecord]] = {}
    for r in recs:
        by_size.setdefault((r.cloud.d, r.cloud.n), []).append(r)
        by_fam.setdefault((r.cloud.family, r.cloud.d, r.cloud.n), []).append(r)
    lines += ["## By size (all families and F)", "",
              "| d | n | " + " | ".join(_AGG_HEAD) + " |", "|" + "---|" * (2 + len(_AGG_HEAD))]
    for (d, n) in sorted(by_size):
        lines.append(f"| {d} | {n} | " + " | ".join(_agg(by_size[(d, n)], lim)) + " |")
    lines += ["", "## By family and size (all F)", "",
              "| family | d | n | F | " + " | ".join(_AGG_HEAD) + " |",
              "|" + "---|" * (4 + len(_AGG_HEAD))]
    fam_order = list(CLOUD_FAMILIES)
    for key in sorted(by_fam, key=lambda k: (fam_order.index(k[0]) if k[0] in fam_order
                                             else 99, k[1], k[2])):
        rs = by_fam[key]
        Fs = ",".join(str(r.cloud.F) for r in rs)
        lines.append(f"| {key[0]} | {key[1]} | {key[2]} | {Fs} | " + " | ".join(_agg(rs, lim))
                     + " |")
    lines.append("")
    hd = [r.hausdorff for r in recs if r.hausdorff is not None]
    if hd:
        lines += [f"qhull vs rescon vertices: {len(hd)} full-dimensional kernels compared, "
                  f"largest Hausdorff distance {max(hd):.3g} (tolerance 1e-6).", ""]
    if errors:
        lines += ["## Errors (rescon failures or unresolved disagreements)", "",
                  "Reproduce: `benchmarks.kernel_clouds.make_cloud(family, d, n, F)`.", "",
                  "| cloud | seed | detail |", "|---|---|---|"]
        for r in errors:
            dtl = "; ".join(r.errors).replace("|", "\\|")
            lines.append(f"| {r.cloud.label} | {r.cloud.seed} | {dtl} |")
        lines.append("")
    issues = [r for r in recs if r.base_issues]
    if issues:
        lines += ["## Baseline failures and baseline answers refuted by rescon's certificates",
                  "",
                  "Not counted as rescon errors and left out of that baseline's ratios. "
                  "*WRONG*: the baseline disagrees with rescon and rescon's certificate was "
                  "verified by the independent exact checker (for a subset-LP point in d = 2 "
                  "the exact Tukey depth of that point is given too). *failed*: the solver "
                  "gave no answer (HiGHS numerical trouble, qhull precision error).", "",
                  "| cloud | seed | baseline | detail |", "|---|---|---|---|"]
        for r in issues:
            for b, v in r.base_issues.items():
                lines.append(f"| {r.cloud.label} | {r.cloud.seed} | {b} | "
                             + v.replace("|", "\\|") + " |")
        lines.append("")
    big = [r for r in recs if {"too_large", "timeout"} & {r.kcert, r.pcert}]
    if big:
        cnt: dict[tuple[int, int, str], int] = {}
        for r in big:
            for kind, st in (("kernel", r.kcert), ("point", r.pcert)):
                if st in ("too_large", "timeout"):
                    key = (r.cloud.d, r.cloud.n, f"{kind} {st}")
                    cnt[key] = cnt.get(key, 0) + 1
        lines += ["## Certificates not verified (checker work limit or time-out)", "",
                  "; ".join(f"d = {d}, n = {n}: {k} {what}"
                            for (d, n, what), k in sorted(cnt.items())) + ".", ""]
    return "\n".join(lines)


# --------------------------------------------------------------------------- CLI


def _split(values: Iterable[str] | None) -> list[str]:
    out: list[str] = []
    for v in values or []:
        out += [x for x in v.split(",") if x]
    return out


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m benchmarks.run",
                                description="rescon benchmarks (see benchmarks/README.md)")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("robustness", help="rho and s*(rho) against LeBlanc and the MILP")
    r.add_argument("--set", choices=sorted(SETS), default="core",
                   help="named test set (default core = BENCHMARKS.md §1 grid)")
    r.add_argument("--quick", action="store_true", help="alias for --set quick (CI smoke, ~1 min)")
    r.add_argument("--sizes", nargs="+", help="node counts, e.g. --sizes 10 15 or 10,15")
    r.add_argument("--families", nargs="+", help=f"families among {', '.join(FAMILIES)}")
    r.add_argument("--instances", type=int, help="instances per (family, params, n)")
    r.add_argument("--time-limit", type=float, help="MILP time limit per instance, seconds")
    r.add_argument("--candidate", choices=sorted(CANDIDATES), default="rescon",
                   help="what is benchmarked (leblanc: to test the harness)")
    r.add_argument("--baselines", nargs="+", help="subset of leblanc,milp; 'none' for none")
    r.add_argument("--leblanc-max-n", type=int, default=20)
    r.add_argument("--milp-max-n", type=int, default=200)
    r.add_argument("--repeats", type=int, default=3,
                   help="repeats of sub-second runs (median is kept); default 3")
    r.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output directory")
    r.add_argument("--name", help="output file stem (default depends on the set: "
                   + ", ".join(f"{s.name}→{s.stem}" for s in SETS.values()) + ")")

    k = sub.add_parser("kernels", help="safe kernels against the subset LP and qhull")
    k.add_argument("--set", choices=sorted(KERNEL_SETS), default="core",
                   help="named set (default core = BENCHMARKS.md §2 grid; reduced: same "
                        "clouds, small baselines only; quick: CI smoke)")
    k.add_argument("--quick", action="store_true", help="alias for --set quick (< 3 min)")
    k.add_argument("--families", nargs="+",
                   help=f"cloud families among {', '.join(CLOUD_FAMILIES)}")
    k.add_argument("--dims", nargs="+", help="dimensions d, e.g. --dims 2 3")
    k.add_argument("--sizes", nargs="+", help="point counts n (for every d selected)")
    k.add_argument("--F", nargs="+", dest="F",
                   help="F values instead of {1, n/10, h, h+1..h+3} (those < n are used)")
    k.add_argument("--baselines", nargs="+", help="subset of lp,qhull; 'none' for none")
    k.add_argument("--max-subsets", type=int,
                   help="run a baseline only when C(n,F) is at most this (set default)")
    k.add_argument("--time-limit", type=float, help="baseline time limit per call, seconds")
    k.add_argument("--no-reference", action="store_true",
                   help="do not add the reference instances (gaussian d=2 n=25 F=4, n=20 F=6)")
    k.add_argument("--cert-timeout", type=float,
                   help="seconds allowed to rescon.check_certificate per certificate (in a "
                        "worker process; beyond: 'timeout', not verified); 0: no limit; "
                        "default: core 60, reduced 10, quick 30")
    k.add_argument("--repeats", type=int, default=5,
                   help="repeats while a cloud's calls take < 1 s (median is kept); default 5")
    k.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output directory")
    k.add_argument("--name", help="results go to kernels_<name>.{csv,md} (default: the set name)")
    return p


def _kernels_main(args: argparse.Namespace, argv: list[str]) -> int:
    kset = KERNEL_SETS["quick" if args.quick else args.set]
    try:
        fams = tuple(_split(args.families)) or kset.families
        bad = [f for f in fams if f not in CLOUD_FAMILIES]
        if bad:
            raise ValueError(f"--families: unknown {bad}; known: {', '.join(CLOUD_FAMILIES)}")
        dims = tuple(int(x) for x in _split(args.dims)) or tuple(kset.sizes)
        if any(d < 1 for d in dims):
            raise ValueError(f"--dims: every d must be >= 1; got {list(dims)}")
        ns = tuple(int(x) for x in _split(args.sizes))
        if any(n < 2 for n in ns):
            raise ValueError(f"--sizes: every n must be >= 2; got {list(ns)}")
        sizes = {d: ns or kset.sizes.get(d) or KC_DEFAULT_SIZES.get(d, (10,)) for d in dims}
        Fs = tuple(int(x) for x in _split(args.F)) or kset.f_values
        if Fs is not None and any(F < 1 for F in Fs):
            raise ValueError(f"--F: every F must be >= 1; got {list(Fs)}")
        bl = tuple(_split(args.baselines)) if args.baselines else kset.baselines
        bl = () if bl == ("none",) else bl
        if any(b not in KERNEL_BASELINES for b in bl):
            raise ValueError(f"--baselines: expected a subset of {list(KERNEL_BASELINES)}; "
                             f"got {list(bl)}")
        cap = args.max_subsets if args.max_subsets is not None else kset.max_subsets
        if cap < 1:
            raise ValueError(f"--max-subsets must be >= 1; got {cap}")
        tl = args.time_limit if args.time_limit is not None else kset.time_limit
        if not tl > 0:
            raise ValueError(f"--time-limit must be > 0; got {tl}")
        name = args.name or kset.name
        if not name or "/" in name:
            raise ValueError(f"--name must be a plain file-name part; got {name!r}")
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    cfg = KernelConfig(set=kset, families=fams, sizes=sizes, f_values=Fs, baselines=bl,
                       max_subsets=cap, time_limit=tl,
                       reference=kset.reference and not args.no_reference and bool(bl),
                       repeats=max(1, args.repeats), out=args.out, stem=f"kernels_{name}",
                       argv=argv, cert_timeout=(kset.cert_timeout if args.cert_timeout is None
                                                else args.cert_timeout))
    try:
        return run_kernels(cfg)
    except CandidateUnavailable as exc:
        print(f"error: rescon unavailable: {exc}", file=sys.stderr)
        return 2


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    args = _parser().parse_args(argv)
    if args.command == "kernels":
        return _kernels_main(args, argv)
    bset = SETS["quick" if args.quick else args.set]
    try:
        fams = tuple(_split(args.families)) or bset.families
        bad = [f for f in fams if f not in FAMILIES]
        if bad:
            raise ValueError(f"--families: unknown {bad}; known: {', '.join(FAMILIES)}")
        sizes = tuple(int(x) for x in _split(args.sizes)) or bset.sizes
        if any(n < 2 for n in sizes):
            raise ValueError(f"--sizes: every n must be >= 2; got {list(sizes)}")
        bl = tuple(_split(args.baselines)) if args.baselines else bset.baselines
        bl = () if bl == ("none",) else bl
        if any(b not in BASELINES for b in bl):
            raise ValueError(f"--baselines: expected a subset of {list(BASELINES)}; got {list(bl)}")
        k = args.instances if args.instances is not None else bset.instances
        if k < 1:
            raise ValueError(f"--instances must be >= 1; got {k}")
        tl = args.time_limit if args.time_limit is not None else bset.time_limit
        if not tl > 0:
            raise ValueError(f"--time-limit must be > 0; got {tl}")
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.leblanc_max_n > B.LEBLANC_MAX_N:
        print(f"error: --leblanc-max-n must be <= {B.LEBLANC_MAX_N}", file=sys.stderr)
        return 2
    cfg = Config(set=bset, candidate=args.candidate, families=fams, sizes=sizes, instances=k,
                 time_limit=tl, baselines=bl, leblanc_max_n=args.leblanc_max_n,
                 milp_max_n=args.milp_max_n, repeats=max(1, args.repeats), out=args.out,
                 stem=args.name or bset.stem, argv=argv)
    try:
        return run_robustness(cfg)
    except CandidateUnavailable as exc:
        print(f"error: candidate '{args.candidate}' unavailable: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
