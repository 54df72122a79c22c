"""rescon command line: thin subcommands over the Python API.

Every subcommand takes ``--json`` (one JSON object on stdout) and ``--quiet`` (no
progress bars; warnings, e.g. the assumptions a scenario violates, still go to stderr).
Progress bars appear only when stderr is a terminal. Bad input exits 2
with one line on stderr, never a traceback; ``rescon check`` exits 0 (valid),
1 (invalid, reason on stderr), 2 (unreadable) or 3 (not fully checked: the parts taken
on trust or beyond the checker's limits are named).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from ._labels import sorted_labels
from .errors import InputError, RESCONError, TimeLimitReached

__all__ = ["main"]




def _pair_json(pair: Any) -> dict[str, list[Any]] | None:
    if pair is None:
        return None
    S1, S2 = pair
    return {"S1": sorted_labels(S1), "S2": sorted_labels(S2)}


def _output(path: str | None, what: str, *, directory: bool = False,
            input_file: str | None = None) -> Path | None:
    """An output path checked (and its directories created) before any work is done;
    never the command's ``input_file`` (``--certificate G.txt`` for the graph G.txt
    would overwrite the graph)."""
    from .io import output_path

    if path is None:
        return None
    out = output_path(path, what, directory=directory)
    if input_file is not None and _same_file(out, input_file):
        raise InputError(f"{what}: {out} is the input file; give the output another name")
    return out


def _same_file(a: Path, b: str) -> bool:
    """Whether ``a`` and ``b`` name one existing file (links followed)."""
    try:
        return Path(a).samefile(b)
    except (OSError, ValueError):  # either missing (the input's error comes later)
        return False


def _write_certificate(cert: dict[str, Any] | None, target: Path | None) -> None:
    if target is None:
        return
    if cert is None:
        print(f"rescon: no certificate written to {target}: the time limit stopped the "
              "search before an answer", file=sys.stderr)
        return
    # compact: a search-tree proof can hold millions of tokens
    text = json.dumps(cert, separators=(",", ":")) + "\n"
    try:  # checked writable before the work (_output); this catches what changed since
        target.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise RESCONError(f"--certificate: cannot write {target} "
                          f"({exc.strerror or exc})") from None


def _progress(args: argparse.Namespace) -> bool | None:
    """The library's ``progress``: False under ``--quiet``, else None (a bar only when
    stderr is a terminal; see :mod:`rescon._progress`)."""
    return False if args.quiet else None


def _emit(result: dict[str, Any], as_json: bool, lines: list[str]) -> None:
    try:
        print(json.dumps(result) if as_json else "\n".join(lines), flush=True)
    except BrokenPipeError:
        raise _StdoutClosed from None





def _cmd_robustness(args: argparse.Namespace) -> int:
    from .graphs.distributed import searches_for
    from .graphs.robustness import is_rs_robust, robustness
    from .io import read_graph

    if args.s is not None and args.r is None:
        raise RESCONError("--s needs --r")
    cert_path = _output(args.certificate, "--certificate", input_file=args.graph)
    G = read_graph(args.graph, undirected=args.undirected)
    kw = {"time_limit": args.time_limit, "method": args.method,
          "scheduler": args.scheduler, "workers": args.workers}
    if args.r is None:
        rep = robustness(G, progress=_progress(args), **kw)
        _write_certificate(rep.certificate, cert_path)
        out = {"n": rep.n, "r_max": rep.r_max, "s_max": rep.s_max, "exact": rep.exact,
               "witness": _pair_json(rep.witness), "method": rep.method,
               "seconds": round(rep.seconds, 6)}
        if not rep.exact:
            out.update(r_lower=rep.r_lower, r_upper=rep.r_upper)
            if rep.s_lower is not None:
                out.update(s_lower=rep.s_lower, s_upper=rep.s_upper,
                           s_witness=_pair_json(rep.s_witness))
        lines = [f"n = {rep.n}"]
        if rep.exact:
            lines.append(f"rho(G) = {rep.r_max} (proof: {rep.lower_proof}); "
                         f"s*({rep.r_max}) = {rep.s_max}")
        elif rep.r_lower == rep.r_upper:
            lines.append(f"rho(G) = {rep.r_max} (proof: {rep.lower_proof}); time limit "
                         f"reached: {rep.s_lower} <= s*({rep.r_max}) <= {rep.s_upper}")
        else:
            lines.append(f"time limit reached: {rep.r_lower} <= rho(G) <= {rep.r_upper}")
        if rep.witness is not None:
            lines.append(f"witness that G is not {rep.r_upper + 1}-robust: "
                         f"S1 = {sorted_labels(rep.witness[0])}, "
                         f"S2 = {sorted_labels(rep.witness[1])}")
        lines.append(f"method: {rep.method}, {rep.seconds:.3f} s")
        _emit(out, args.json, lines)
        return 0
    if args.s is None:
        with searches_for(G, args.scheduler, args.workers):  # one cluster for both queries
            res, s_max = _r_robust_and_s_star(G, args)
        _write_certificate(res.certificate, cert_path)
        out = {"r": args.r, "r_robust": res.holds, "s_max": s_max,
               "witness": _pair_json(res.witness)}
        verdict = {True: "is", False: "is NOT", None: "undecided (time limit):"}[res.holds]
        shown = "not settled (time limit)" if s_max is None else s_max
        lines = [f"G {verdict} {args.r}-robust; s*({args.r}) = {shown}"]
    else:
        res = is_rs_robust(G, args.r, args.s, **kw)
        _write_certificate(res.certificate, cert_path)
        out = {"r": args.r, "s": args.s, "holds": res.holds, "witness": _pair_json(res.witness)}
        verdict = {True: "is", False: "is NOT", None: "undecided (time limit):"}[res.holds]
        lines = [f"G {verdict} ({args.r}, {args.s})-robust"]
    if res.witness is not None:
        lines.append(f"witness: S1 = {sorted_labels(res.witness[0])}, "
                     f"S2 = {sorted_labels(res.witness[1])}")
    _emit(out, args.json, lines)
    return 0


def _r_robust_and_s_star(G: Any, args: argparse.Namespace) -> tuple[Any, int | None]:
    """``rescon robustness --r R``: is G R-robust, and s*(R) when it is (0 when it is
    not, None when the time limit ends first), within one time limit (on the cluster of
    the caller's ``searches_for`` block, if any)."""
    from .graphs.robustness import is_rs_robust, max_s

    res = is_rs_robust(G, args.r, 1, time_limit=args.time_limit, method=args.method)
    s_max: int | None = 0 if res.holds is False else None
    left = None if args.time_limit is None else args.time_limit - res.seconds
    if res.holds and (left is None or left > 0):
        try:
            s_max = max_s(G, args.r, method=args.method, time_limit=left)
        except TimeLimitReached:
            s_max = None
    return res, s_max


def _cmd_kernel(args: argparse.Namespace) -> int:
    from .geometry.kernel import safe_kernel
    from .io import read_points
    from .plot import figure_path

    plot = None if args.plot is None else figure_path(args.plot, "--plot")
    cert_path = _output(args.certificate, "--certificate", input_file=args.points)
    X = read_points(args.points)
    if plot is not None and X.shape[1] not in (2, 3):
        raise RESCONError(f"--plot draws d = 2 or 3 only; the points have d = {X.shape[1]}")
    K = safe_kernel(X, args.F)
    point = None if K.is_empty else K.point("project")[0]
    _write_certificate(K.certificate, cert_path)
    if plot is not None:
        _draw(lambda: K.plot(point=point, path=plot), plot)
    out = {"n": int(X.shape[0]), "d": int(X.shape[1]), "F": K.F, "empty": K.is_empty,
           "dim": K.dim, "vertices": K.vertices.tolist(), "A": K.A.tolist(),
           "b": K.b.tolist(), "point": None if point is None else point.tolist(),
           "seconds": round(K.seconds, 6)}
    if K.is_empty:
        lines = [(f"n = {X.shape[0]}, d = {X.shape[1]}, F = {K.F}: the safe kernel is EMPTY "
                  "(Farkas certificate)")]
    else:
        lines = [(f"n = {X.shape[0]}, d = {X.shape[1]}, F = {K.F}: safe kernel of dimension "
                  f"{K.dim} with {len(K.vertices)} vertices, {len(K.b)} facets"),
                 f"point (closest to the mean of the points): {point.tolist()}"]
    lines.append(f"{K.seconds:.4f} s")
    _emit(out, args.json, lines)
    return 0


def _draw(draw: Callable[[], Any], path: Path) -> None:
    """``draw()`` (a figure to ``path``); a ValueError raised while drawing (matplotlib
    refusing what it was given) becomes a one-line error naming the file, not a
    traceback."""
    try:
        draw()
    except RESCONError:
        raise
    except ValueError as exc:
        raise RESCONError(f"--plot: cannot draw {path}: {exc}") from exc
    except OSError as exc:  # checked writable before the work; changed since
        raise RESCONError(f"--plot: cannot write {path} ({exc.strerror or exc})") from None


def _run_outputs(args: argparse.Namespace) -> tuple[Path | None, Path | None]:
    """--out DIR, its trajectory.json and trajectory.csv and, with --plot,
    DIR/trajectory.png: each checked (:func:`rescon.io.output_path`) before any work."""
    from .plot import figure_path

    if args.plot and not args.out:
        raise RESCONError("--plot needs --out DIR (where the figure is written)")
    out_dir = _output(args.out, "--out", directory=True)
    if out_dir is not None:
        for name in ("trajectory.json", "trajectory.csv"):
            _output(str(out_dir / name), "--out")
    return out_dir, figure_path(out_dir / "trajectory.png", "--plot") if args.plot else None


def _warned(run: Callable[[], Any]) -> Any:
    """``run()``, its ScenarioWarnings (the assumptions it violates) on stderr."""
    import warnings

    from .consensus.scenario import ScenarioWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ScenarioWarning)
        result = run()
    for w in caught:
        if issubclass(w.category, ScenarioWarning):
            print(f"rescon: warning: {w.message}", file=sys.stderr)
    return result


def _run_summary(args: argparse.Namespace, sc: Any, traj: Any, out_dir: Path | None,
                 plot: Path | None) -> tuple[dict[str, Any], list[str]]:
    """The JSON keys and text lines shared by simulate and rmdo; writes DIR's files."""
    m = traj.metrics
    diameter = float(m["diameter"][-1]) if "diameter" in m else None
    validity = float(m["validity"].max()) if "validity" in m else None
    out = {"steps": sc.steps, "N": len(sc.nodes), "d": sc.d, "F": sc.F,
           "algorithm": sc.algorithm, "policy": sc.policy,
           "final_diameter": diameter, "max_validity": validity,
           "assumptions_violated": traj.info["assumptions_violated"],
           "seconds": round(traj.seconds, 6)}
    if out_dir is not None:
        try:  # checked writable before the run (_run_outputs)
            (out_dir / "trajectory.json").write_text(json.dumps(traj.to_json()) + "\n",
                                                     encoding="utf-8")
            traj.to_csv(out_dir / "trajectory.csv")
        except OSError as exc:
            raise RESCONError(f"--out: cannot write into {out_dir} "
                              f"({exc.strerror or exc})") from None
        if plot is not None:
            _draw(lambda: traj.plot(plot), plot)
        out["out"] = str(out_dir)
    lines = [(f"{sc.algorithm} with policy {sc.policy}: N = {len(sc.nodes)}, d = {sc.d}, "
              f"F = {sc.F}, {sc.steps} steps in {traj.seconds:.2f} s"),
             (f"final benign diameter {_maybe(diameter)}, largest distance to the "
              f"initial benign hull {_maybe(validity)}")]
    if args.out:
        lines.append(f"written to {args.out}")
    return out, lines


def _maybe(x: float | None) -> str:
    """A metric for the text summary: 3 significant digits, or "not monitored"."""
    return "not monitored" if x is None else f"{x:.3e}"


def _metrics(args: argparse.Namespace) -> list[str] | None:
    """``--metrics a,b`` as a list of monitor names (None: every monitor)."""
    if args.metrics is None:
        return None
    names = [name.strip() for name in args.metrics.split(",") if name.strip()]
    if not names:
        raise InputError(f"--metrics names no monitor ({args.metrics!r}); give some of "
                         "spread, diameter, validity, or omit it for every one")
    return names


def _cmd_simulate(args: argparse.Namespace) -> int:
    from .consensus.engine import simulate
    from .consensus.scenario import Scenario

    out_dir, plot = _run_outputs(args)
    sc = Scenario.from_toml(args.scenario)
    traj = _warned(lambda: simulate(sc, metrics=_metrics(args), progress=_progress(args)))
    out, lines = _run_summary(args, sc, traj, out_dir, plot)
    _emit(out, args.json, lines)
    return 0


def _cmd_rmdo(args: argparse.Namespace) -> int:
    """simulate's keys plus ``final_cost`` (F = Σ_{i∈B} f_i at the final benign mean),
    ``optimum`` (how X* was found: ``point`` or null, ``exact``, ``value`` F* or null,
    ``method``, ``dimension`` or ``reason``), ``final_distance_to_optimum`` (max_i
    dist(x_i, X*)) and ``final_gap`` (max_i F(x_i) − F*), null when X* is not known,
    and ``step_size``."""
    from .optim.files import read_rmdo
    from .optim.rmdo import rmdo

    out_dir, plot = _run_outputs(args)
    f = read_rmdo(args.scenario)
    traj = _warned(lambda: rmdo(f.scenario, f.costs, step_size=f.step_size,
                                metrics=_metrics(args), progress=_progress(args)))
    out, lines = _run_summary(args, f.scenario, traj, out_dir, plot)
    m, opt = traj.metrics, dict(traj.info["optimum"])
    opt.setdefault("point", None)
    opt["value"] = _finite_or_none(opt.get("value"))
    known = "distance_to_optimum" in m
    out.update(final_cost=_finite_or_none(float(m["cost_at_mean"][-1])), optimum=opt,
               final_distance_to_optimum=float(m["distance_to_optimum"][-1]) if known else None,
               final_gap=float(m["optimality_gap"][-1]) if known else None,
               step_size=traj.info["step_size"])
    lines.insert(1, f"step size {out['step_size']}; final global cost at the benign mean "
                    f"{m['cost_at_mean'][-1]:.6g}")
    if known:
        lines.insert(2, f"X* ({opt['method']}): F* = {opt['value']:.6g}; final distance to "
                        f"X* {out['final_distance_to_optimum']:.3e}, optimality gap "
                        f"{out['final_gap']:.3e}")
    else:
        lines.insert(2, f"X* not known ({opt['method']}): {opt.get('reason', '')}")
    _emit(out, args.json, lines)
    return 0


def _finite_or_none(x: Any) -> Any:
    """A float for JSON: ±inf and NaN (not JSON) become null."""
    return x if x is None or math.isfinite(x) else None


def _json_safe(x: Any) -> Any:
    """``x`` with every non-finite float (anywhere in lists, tuples, dicts) as null."""
    if isinstance(x, dict):
        return {k: _json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_json_safe(v) for v in x]
    return _finite_or_none(x) if isinstance(x, float) else x


def _cmd_redundancy(args: argparse.Namespace) -> int:
    """JSON keys ``holds, exact, r, N, gap, unbounded, witness, seconds`` (+
    ``unbounded_agents``, ``tolerance``); ``gap`` is null when infinite (one argmin
    empty, the other not), non-finite support values in ``witness`` too."""
    import time

    from .optim.files import read_costs
    from .optim.redundancy import check_redundancy

    cert_path = _output(args.certificate, "--certificate", input_file=args.costs)
    t0 = time.perf_counter()
    costs, d = read_costs(args.costs)
    rep = check_redundancy(costs, args.r, d=d)
    seconds = time.perf_counter() - t0
    _write_certificate(rep.certificate, cert_path)
    out = {"holds": rep.holds, "exact": rep.exact, "r": args.r, "N": len(costs),
           "gap": _finite_or_none(rep.gap),
           "unbounded": [sorted_labels(S) for S in rep.unbounded],
           "witness": _json_safe(rep.witness), "seconds": round(seconds, 6),
           "unbounded_agents": sorted_labels(rep.unbounded_agents),
           "tolerance": rep.tolerance}
    how = "exact" if rep.exact else f"numerical, tolerance {rep.tolerance:.1e}"
    lines = [(f"N = {len(costs)} costs in d = {d} {'ARE' if rep.holds else 'are NOT'} "
              f"{args.r}-redundant ({how}); largest argmin gap {rep.gap:.3e}")]
    if rep.witness is not None:
        S1, S2 = rep.witness["subsets"]
        lines.append(f"witness: argmin over {sorted_labels(S1)} differs from argmin over "
                     f"{sorted_labels(S2)} ({rep.witness.get('reason', '')})")
    if rep.unbounded_agents:
        lines.append(f"unbounded below alone: agents {sorted_labels(rep.unbounded_agents)}")
    lines.append(f"{seconds:.3f} s")
    _emit(out, args.json, lines)
    return 0


def _cmd_paper(args: argparse.Namespace) -> int:
    """Exit 0 when the reproduction ran: claims that do not hold are findings, not
    failures. ``--json``: the object of ``DIR/summary.json``."""
    from .paper import reproduce_paper

    rep = reproduce_paper(args.out, progress=_progress(args))
    lines = [f"{c.verdict:>13}  {c.claim}" for c in rep.claims]
    verdicts = [c["verdict"] for c in rep.certificates]
    lines.append(f"certificates: {len(verdicts)} written, "
                 + ", ".join(f"{verdicts.count(v)} {v}" for v in sorted(set(verdicts))))
    lines.append(f"written to {rep.out}: report.md, summary.json, {len(rep.figures)} figures "
                 f"({rep.seconds:.1f} s)")
    _emit(rep.summary, args.json, lines)
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    """Run a grid; exit 0 when every cell ran (failed cells are rows, not errors).
    ``--json``: cells, ok, failed, out, seconds."""
    import time

    from .sweep import sweep

    t0 = time.perf_counter()
    table = sweep(args.grid, scheduler=args.scheduler, workers=args.workers, out=args.out,
                  progress=_progress(args))
    ok = int((table["status"] == "ok").sum())
    out = {"cells": len(table), "ok": ok, "failed": len(table) - ok,
           "out": str(Path(args.out) / "results.parquet"),
           "seconds": round(time.perf_counter() - t0, 3)}
    _emit(out, args.json, [f"{out['cells']} cells: {ok} ok, {out['failed']} failed; "
                           f"rows in {out['out']} ({out['seconds']:.1f} s)"])
    return 0


def _cmd_check(args: argparse.Namespace) -> int:
    """Exit 0 valid, 1 invalid, 2 unreadable, 3 unchecked (the standalone checker's codes);
    ``--json``: one object with ``verdict``, ``valid``, ``readable``, ``reason``,
    ``trusted`` and ``unchecked`` (the parts not verified)."""
    from rescon_certificates.check import EXIT_CODES, check, load
    from rescon_certificates.check import main as check_main

    if not args.json:
        return check_main([args.certificate])
    try:
        cert = load(args.certificate)
    except (ValueError, OSError, RecursionError) as exc:  # what the checker calls unreadable
        print(f"unreadable: {args.certificate}: {exc}", file=sys.stderr)
        print(json.dumps({"verdict": "unreadable", "valid": False, "readable": False,
                          "reason": str(exc), "trusted": [], "unchecked": []}))
        return 2
    res = check(cert)
    if res.verdict == "invalid":
        print(f"invalid: {res.reason}", file=sys.stderr)
    print(json.dumps({"verdict": res.verdict, "valid": res.valid, "readable": True,
                      "reason": res.reason, "trusted": list(res.trusted),
                      "unchecked": list(res.unchecked)}))
    return EXIT_CODES[res.verdict]


def _nonneg_int(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a nonnegative integer, got {text!r}") from None
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a nonnegative integer, got {value}")
    return value


def _positive_float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not value > 0:
        raise argparse.ArgumentTypeError(f"expected a positive number of seconds, got {text}")
    return value


def _robustness_method(text: str) -> str:
    """A name of :data:`rescon.graphs.robustness.METHODS` (imported only when given)."""
    from .graphs.robustness import METHODS

    if text not in METHODS:
        raise argparse.ArgumentTypeError(f"expected one of {', '.join(METHODS)}; got {text!r}")
    return text


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors and exit status 2."""

    def error(self, message: str) -> None:  # type: ignore[override]
        self.exit(2, f"rescon: error: {message}\n")


def _version() -> str:
    from . import __version__

    return __version__


def _parser() -> argparse.ArgumentParser:
    p = _Parser(prog="rescon", description=__doc__.splitlines()[0])
    p.add_argument("--version", action="version", version=f"rescon {_version()}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    rob = sub.add_parser("robustness", help="rho(G), s*(r), (r,s)-robustness with certificates")
    rob.add_argument("graph", help="edge list (u v: u->v), .graphml, .gml, .json, .csv")
    rob.add_argument("--r", type=_nonneg_int, help="check r-robustness (and s*(r))")
    rob.add_argument("--s", type=_nonneg_int, help="with --r: check (r,s)-robustness")
    rob.add_argument("--undirected", action="store_true", help="treat edges as undirected")
    rob.add_argument("--time-limit", type=_positive_float, metavar="SEC",
                     help="stop and report proven bounds after SEC seconds")
    rob.add_argument("--method", default="auto", type=_robustness_method,
                     help="exact method when the bounds do not meet: auto (default), "
                          "search, milp or dp")
    rob.add_argument("--scheduler", metavar="ADDRESS",
                     help="finish long exact searches on this Dask scheduler, e.g. "
                          "tcp://host:8786 (split into subtrees; same answer and certificate)")
    rob.add_argument("--workers", type=int, metavar="N",
                     help="finish long exact searches on a local Dask cluster of N worker "
                          "processes (default: serial)")
    rob.add_argument("--certificate", metavar="FILE", help="write the certificate (JSON)")
    rob.add_argument("--json", action="store_true", help="one JSON object on stdout")
    rob.set_defaults(func=_cmd_robustness)

    ker = sub.add_parser("kernel", help="the safe kernel of a point set (exact polytope)")
    ker.add_argument("points", help="text (n rows of d numbers, comma- or "
                     "whitespace-separated, optional header) or .npy")
    ker.add_argument("--F", type=_nonneg_int, required=True, help="points that may be removed")
    ker.add_argument("--plot", metavar="PNG", help="draw points, kernel and point (d = 2, 3)")
    ker.add_argument("--certificate", metavar="FILE", help="write the certificate (JSON)")
    ker.add_argument("--json", action="store_true", help="one JSON object on stdout")
    ker.set_defaults(func=_cmd_kernel)

    sim = sub.add_parser("simulate", help="run Algorithm 1 (or a baseline) on a scenario")
    sim.add_argument("scenario", help="scenario TOML file")
    sim.add_argument("--out", metavar="DIR", help="write trajectory.json/.csv (and .png)")
    sim.add_argument("--plot", action="store_true", help="with --out: draw the trajectory")
    sim.add_argument("--metrics", metavar="NAMES",
                     help="monitors to run, comma-separated from spread, diameter, validity "
                          "(default: all; unmonitored values are null)")
    sim.add_argument("--json", action="store_true", help="one JSON object on stdout")
    sim.set_defaults(func=_cmd_simulate)

    opt = sub.add_parser("rmdo", help="run Algorithm 2 (RMDO) on a scenario with [costs]")
    opt.add_argument("scenario", help="scenario TOML file with [costs] (and [step_size])")
    opt.add_argument("--out", metavar="DIR", help="write trajectory.json/.csv (and .png)")
    opt.add_argument("--plot", action="store_true", help="with --out: draw the trajectory")
    opt.add_argument("--metrics", metavar="NAMES",
                     help="monitors to run, comma-separated from spread, diameter, validity "
                          "(default: all; unmonitored values are null)")
    opt.add_argument("--json", action="store_true", help="one JSON object on stdout")
    opt.set_defaults(func=_cmd_rmdo)

    red = sub.add_parser("redundancy", help="are the costs r-redundant? (exact when possible)")
    red.add_argument("costs", help="TOML with [costs] (and d), or an RMDO scenario file")
    red.add_argument("--r", type=_nonneg_int, required=True, help="agents that may be left out")
    red.add_argument("--certificate", metavar="FILE", help="write the certificate (JSON)")
    red.add_argument("--json", action="store_true", help="one JSON object on stdout")
    red.set_defaults(func=_cmd_redundancy)

    pap = sub.add_parser("paper", help="reproduce the paper's example and check its claims")
    pap.add_argument("--out", metavar="DIR", default="out/paper",
                     help="figures, certificates, summary.json, report.md (default out/paper)")
    pap.add_argument("--json", action="store_true", help="one JSON object on stdout (summary)")
    pap.set_defaults(func=_cmd_paper)

    swp = sub.add_parser("sweep", help="run a grid of scenarios as Dask tasks (Parquet rows)")
    swp.add_argument("grid", help="grid TOML: [base], [axes], [run]")
    swp.add_argument("--scheduler", metavar="ADDRESS",
                     help="a running Dask scheduler, e.g. tcp://host:8786 (default: a "
                          "local cluster)")
    swp.add_argument("--workers", type=int, metavar="N",
                     help="local worker processes (default: the CPU count; 0: serial)")
    swp.add_argument("--out", metavar="DIR", default="out/sweep",
                     help="results.parquet, resumable (default out/sweep)")
    swp.add_argument("--json", action="store_true",
                     help="one JSON object: cells, ok, failed, out, seconds")
    swp.set_defaults(func=_cmd_sweep)

    chk = sub.add_parser("check", help="verify a certificate with the standalone checker")
    chk.add_argument("certificate", help="certificate JSON file")
    chk.add_argument("--json", action="store_true",
                     help="one JSON object: valid, readable, reason, trusted")
    chk.set_defaults(func=_cmd_check)
    for command in sub.choices.values():
        command.add_argument("--quiet", "-q", action="store_true",
                             help="no progress bars (warnings still go to stderr)")
    return p


def _one_line(text: str) -> str:
    """An error message on one line (the stderr contract)."""
    return " ".join(text.split()) or "(no message)"


class _StdoutClosed(Exception):
    """stdout was closed under us (``rescon ... | head``): not an error to report."""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``rescon`` console script; returns the exit status."""
    args = _parser().parse_args(argv)
    func: Callable[[argparse.Namespace], int] = args.func
    try:
        return func(args)
    except _StdoutClosed:  # like a program killed by SIGPIPE, silently
        import os

        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError):
            pass
        return 141
    except (RESCONError, OSError) as exc:
        print(f"rescon: error: {_one_line(str(exc))}", file=sys.stderr)
        return 2
    except (OverflowError, MemoryError) as exc:  # an input beyond what can be represented
        print(f"rescon: error: the input is out of range ({type(exc).__name__}: "
              f"{_one_line(str(exc))})", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("rescon: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
