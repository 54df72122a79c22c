"""Benchmark runner: ``python -m benchmarks.run robustness [options]``.

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
import os
import platform
import statistics
import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

import networkx as nx

from . import baselines as B
from .families import FAMILIES, STRUCTURED, Instance, instances, known_s_star, variant_label

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

    def run(G: nx.Graph, time_limit: float | None = None) -> Answer:
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
                a, t = _timed(_guard(lambda: cand_fn(inst.G, cfg.time_limit)), cfg.repeats)
                answers[cand], secs[cand] = a, t
                for b in cfg.baselines:
                    if (b == "leblanc" and n > cfg.leblanc_max_n) or (
                        b == "milp" and n > cfg.milp_max_n
                    ):
                        continue
                    fn = BASELINES[b]
                    a, t = _timed(_guard(lambda fn=fn: fn(inst.G, cfg.time_limit)),
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
    md_path.write_text(md)
    print(f"wrote {csv_path} and {md_path}; {n_err} instance(s) with errors", file=log)
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
                import highspy
                v = highspy.Highs().version()
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
        f"- Generated {_dt.datetime.now(_dt.timezone.utc).strftime('%Y-%m-%d %H:%M UTC')} by "
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
        for (fam, par, n), insts in cells.items():
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
    return p


def main(argv: Sequence[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    args = _parser().parse_args(argv)
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
