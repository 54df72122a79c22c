"""The s*(r) search split on Dask (issue 13 §2): s*(r) on dense digraphs n = 40-60,
serially in this process against the same search finished on a LocalCluster of 1 and of
2 worker processes.

    python -m benchmarks.robustness_dask_sstar [--instances N:P:SEED:R ...] [--repeats K]
                                               [--out benchmarks/results]
    python -m benchmarks.robustness_dask_sstar --scan N:P:SEED:R ... [--limit SECONDS]

The instances are gnp_random_graph(n, p, seed, directed=True) with an r ≤ ρ at which the
serial s* search took 10-120 s in a scan (``--scan``, recorded in ``SCAN``). What is timed
is the exact s* search the public API runs after its bounds (robustness._deepening_search:
rounds of search.min_cost_pair below growing caps, the sized and the charged-set branch
and bounds taking turns), from lower = 1 (G is r-robust) to the cheapest pair the bounds
find (bd.s_candidates, then the descents and tabu walks of robustness._descended_upper;
computed once per instance, the same for every run). The public API would add the
bounds' time, and a MILP racing on the second core.

Each cluster is a ``distributed.LocalCluster`` (one thread per worker) started and warmed
(both engines run a part of a search of the same graph on every worker) before the clock
starts; the runs are interleaved (serial, 1 worker, 2 workers, repeated) so that the
machine's load, shared with other jobs, hits all three alike; the median is reported,
with the load average before each run. Before any time is reported, every run's answer
is checked: the same s*(r), a pair of exactly that cost (bd.pair_cost), and the
``rs_robust`` certificate (r, s*) of every run checked with ``rescon.check_certificate``
(the split runs carry the sized tree assembled from their parts when it fits in
MAX_TREE_TOKENS; a serial run's proof has no tree: the API records it afterwards within
2 s, or leaves it unchecked): never "invalid".

Writes ``robustness_dask_sstar.md`` and ``robustness_dask_sstar.csv``.
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import statistics
import time
from pathlib import Path

import networkx as nx

import rescon
from rescon.graphs import bounds as bd
from rescon.graphs import distributed
from rescon.graphs.indexed import index_graph
from rescon.graphs.robustness import _deepening_search, _descended_upper
from rescon.graphs.search import _kernel_inputs, min_cost_pair, whole_cost_part

from .robustness_dask_bench import _cpu, _graph

INSTANCES = ("40:0.8:40001:16", "50:0.9:50000:22", "60:0.9:60000:28")

#: the scan that chose the instances (--scan, 130 s per search; ρ from rescon.robustness):
#: (n, p, seed, r, s*(r) or the bounds when stopped, search states, seconds)
SCAN = (
    (40, 0.8, 40001, 16, "s* = 8", 38_017_290, 11.68),
    (50, 0.8, 50000, 20, "stopped: 4 ≤ s* ≤ 8", 499_006_181, 130.0),
    (50, 0.8, 50001, 20, "stopped: 5 ≤ s* ≤ 8", 455_343_212, 130.0),
    (50, 0.9, 50000, 23, "s* = 3", 28_777_158, 6.83),
    (50, 0.9, 50000, 22, "s* = 13", 129_016_663, 31.03),
    (60, 0.9, 60000, 28, "s* = 3", 146_354_235, 37.64),
)
SCAN_NOTE = ("load 3.2-4.7 from other jobs; ρ = 17, 20, 21, 23, 28 for ER(40, 0.8) seed "
             "40001, ER(50, 0.8) seeds 50000 and 50001, ER(50, 0.9) seed 50000, ER(60, 0.9) "
             "seed 60000. At ρ, ER(50, 0.8) seed 50001 (r = 21) has s* = 1, which the "
             "bounds' probes now find as the upper bound: no search is left. Before the "
             "maximality prune (commit 2ec7722) ER(60, 0.8) seed 60000, r = 24 and 25, "
             "did not finish within 130 s (not re-scanned); so the n = 50 and 60 "
             "instances have p = 0.9")


def _upper(ig, r: int) -> int:
    """The cheapest pair the API's bounds find (candidates, descents, tabu walks)."""
    upper, pair = ig.n, None
    for cand in bd.s_candidates(ig, r):
        cost = bd.pair_cost(ig, cand, r)
        if cost is not None and cost < upper:
            upper, pair = cost, cand
    return _descended_upper(ig, r, upper, pair, None, 1)[0]


def _certificate(G: nx.DiGraph, r: int, out) -> dict:
    """The ``rs_robust`` certificate (r, s*) of an s* search's outcome."""
    proof = {"method": "cost_search", "order": list(out.order), "info": {"nodes": out.nodes}}
    if out.tree is not None:
        proof["tree"] = list(out.tree)
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": index_graph(G).graph_json(),
            "r": r, "s": out.best, "proof": proof}


def _timed(ig, r: int, upper: int, cluster, client):
    """(outcome, wall seconds, load before, CPU seconds by process) of one s* search,
    serial when ``cluster`` is None."""
    load = os.getloadavg()[0]
    cpu0 = _cpu(client)
    t0 = time.perf_counter()
    with distributed.searches_on(scheduler=None if cluster is None else
                                 cluster.scheduler_address):
        out = _deepening_search(ig, r, 1, upper, None)
    wall = time.perf_counter() - t0
    cpu1 = _cpu(client)
    return out, wall, load, {k: cpu1[k] - cpu0[k] for k in cpu0}


def _checked(ig, r: int, out, label: str, truth: int | None) -> int:
    """s*(r) of a finished search, its pair's cost checked (AssertionError otherwise)."""
    if out.status != "done":
        raise AssertionError(f"{label}: the search did not finish ({out.status})")
    if out.pair is not None and bd.pair_cost(ig, bd.Pair(*out.pair), r) != out.best:
        raise AssertionError(f"{label}: the pair does not cost {out.best}")
    if truth is not None and out.best != truth:
        raise AssertionError(f"{label}: s* = {out.best}, the serial search says {truth}")
    return out.best


def _cluster(workers: int, ig, r: int):
    """(a started LocalCluster of ``workers`` processes, a client on it, its start-up
    seconds); warmed: every worker has run a part of both engines on ig."""
    from distributed import Client, LocalCluster

    t0 = time.perf_counter()
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    started = time.perf_counter() - t0
    client = Client(cluster)
    masks = _kernel_inputs(ig)[1:]
    for engine in ("sized", "charged"):
        client.run(distributed.run_cost_part, masks, engine, r, 1, whole_cost_part(ig.n),
                   ig.n, 0, 1000)
    return cluster, client, started


def bench(spec: str, repeats: int) -> dict:
    name, G, r = _graph(spec)
    ig = index_graph(G)
    min_cost_pair(ig, r, 2)  # numba kernels compiled / loaded here too
    upper = _upper(ig, r)
    clusters = {w: _cluster(w, ig, r) for w in (1, 2)}
    runs: dict[str, list[tuple[float, float, dict]]] = {"serial": [], "1 worker": [],
                                                         "2 workers": []}
    outs: dict[str, list] = {k: [] for k in runs}
    try:
        for _ in range(repeats):
            serial, t, load, cpu = _timed(ig, r, upper, None, None)
            truth = _checked(ig, r, serial, f"{name}, r = {r}, serial", None)
            runs["serial"].append((t, load, cpu))
            outs["serial"].append(serial)
            for w, (cluster, client, _) in clusters.items():
                key = f"{w} worker{'s' if w > 1 else ''}"
                split, t, load, cpu = _timed(ig, r, upper, cluster, client)
                _checked(ig, r, split, f"{name}, r = {r}, {key}", truth)
                runs[key].append((t, load, cpu))
                outs[key].append(split)
    finally:
        for cluster, client, _ in clusters.values():
            client.close()
            cluster.close()
    verdicts = {k: sorted({rescon.check_certificate(_certificate(G, r, o)).verdict
                           for o in v}) for k, v in outs.items()}
    if any("invalid" in v for v in verdicts.values()):
        raise AssertionError(f"{name}: certificate verdicts {verdicts}")
    med = {k: statistics.median(t for t, _, _ in v) for k, v in runs.items()}
    cpu_serial = statistics.median(c["driver"] for _, _, c in runs["serial"])
    work = {k: statistics.median(sum(x for p, x in c.items() if p != "driver")
                                 for _, _, c in runs[k]) for k in ("1 worker", "2 workers")}
    busiest = statistics.median(max(x for p, x in c.items() if p != "driver")
                                for _, _, c in runs["2 workers"])
    driver = statistics.median(c["driver"] for _, _, c in runs["2 workers"])
    return {"instance": name, "n": ig.n, "r": r, "s_star": truth, "upper": upper,
            "states_serial": int(statistics.median(o.nodes for o in outs["serial"])),
            "states_w2": int(statistics.median(o.nodes for o in outs["2 workers"])),
            "cert_serial": "/".join(verdicts["serial"]),
            "cert_split": "/".join(sorted(set(verdicts["1 worker"] + verdicts["2 workers"]))),
            "serial_s": med["serial"], "w1_s": med["1 worker"], "w2_s": med["2 workers"],
            "w2_vs_w1": med["1 worker"] / med["2 workers"],
            "w2_vs_serial": med["serial"] / med["2 workers"],
            "cpu_serial_s": cpu_serial, "cpu_w1_s": work["1 worker"],
            "cpu_w2_s": work["2 workers"], "cpu_w2_busiest_s": busiest,
            "cpu_w2_driver_s": driver, "cpu_balance": cpu_serial / busiest,
            "start_w1_s": clusters[1][2], "start_w2_s": clusters[2][2],
            "loads": "; ".join(f"{k}: " + ", ".join(f"{ld:.1f}" for _, ld, _ in v)
                               for k, v in runs.items()),
            "times": "; ".join(f"{k}: " + ", ".join(f"{t:.1f}" for t, _, _ in v)
                               for k, v in runs.items())}


def scan(specs: list[str], limit: float) -> None:
    """Time the serial s* search on each instance (stopped after ``limit`` seconds) and
    print one line each, with the load average before it."""
    for spec in specs:
        name, G, r = _graph(spec)
        ig = index_graph(G)
        min_cost_pair(ig, r, 2)
        upper = _upper(ig, r)
        load = os.getloadavg()[0]
        t0 = time.perf_counter()
        out = _deepening_search(ig, r, 1, upper, t0 + limit)
        seconds = time.perf_counter() - t0
        found = (f"s* = {out.best}" if out.status == "done" else
                 f"stopped: {out.floor} ≤ s* ≤ {out.best}")
        print(f"({ig.n}, {spec.split(':')[1]}, {spec.split(':')[2]}, {r}, {found!r}, "
              f"{out.nodes}, {seconds:.2f}),  # upper {upper}, load {load:.1f}", flush=True)


def _write(rows: list[dict], out: Path, argv: str, seconds: float) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with (out / "robustness_dask_sstar.csv").open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    load = " / ".join(f"{x:.2f}" for x in os.getloadavg())
    lines = [
        "# The s*(r) search split on Dask (benchmarks/robustness_dask_sstar.py)",
        "",
        f"`{argv}` in {seconds:.0f} s. Machine: {platform.machine()}, {os.cpu_count()} CPUs, "
        f"Python {platform.python_version()}, shared with other jobs; load average at the "
        f"end {load}.",
        "",
        "The exact s*(r) search (rounds of the sized and the charged-set branch and bounds "
        "below growing caps, from lower = 1 to the bounds' cheapest pair) on dense digraphs, "
        "serially in this process and finished on a warm LocalCluster of 1 and of 2 worker "
        "processes (each engine's search split into parts, the incumbent shared as parts are "
        "submitted: `rescon.graphs.distributed`). Every run's s*(r) is the serial one and its "
        "pair costs exactly s* (checked before any time is reported); the number of states "
        "differs (parts prune with the incumbent they were given). Certificate: the verdict "
        "of `rescon.check_certificate` on the (r, s*) certificate of the runs' proofs "
        "(split: the sized tree assembled from the parts, recorded when it fits in 4 million "
        "tokens and the sized engine answered; serial: no tree). Times: median of the "
        "interleaved repeats, in seconds; on a machine shared with other jobs a wall time "
        "measures the share of the 2 cores a run got (load before each run, below).",
        "",
        "| instance | r | s* | states serial | states 2 w | serial | 1 worker | 2 workers "
        "| 2 w vs 1 w | 2 w vs serial | certificate serial / split |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- |",
    ]
    for row in rows:
        lines.append(f"| {row['instance']} | {row['r']} | {row['s_star']} | "
                     f"{row['states_serial']:,} | {row['states_w2']:,} | "
                     f"{row['serial_s']:.1f} | {row['w1_s']:.1f} | {row['w2_s']:.1f} | "
                     f"{row['w2_vs_w1']:.2f}x | {row['w2_vs_serial']:.2f}x | "
                     f"{row['cert_serial']} / {row['cert_split']} |")
    lines += ["", "CPU seconds (median over the repeats): the serial search; the workers' sum "
              "(the work, task overhead included); with 2 workers, the busiest worker and this "
              "process (the driver: its local start, splitting, assembling). Serial / busiest "
              "is the speed-up the split reaches when each worker has a core of its own.", "",
              "| instance | r | serial | 1 worker | 2 workers (sum) | busiest of 2 | driver "
              "| serial / busiest |",
              "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    lines += [f"| {row['instance']} | {row['r']} | {row['cpu_serial_s']:.1f} | "
              f"{row['cpu_w1_s']:.1f} | {row['cpu_w2_s']:.1f} | {row['cpu_w2_busiest_s']:.1f} | "
              f"{row['cpu_w2_driver_s']:.1f} | {row['cpu_balance']:.2f}x |" for row in rows]
    lines += ["", "Each run (seconds) and the 1-minute load average before it:", ""]
    for row in rows:
        lines.append(f"- {row['instance']}, r = {row['r']} (upper bound {row['upper']}): "
                     f"{row['times']} (load {row['loads']}); cluster start-up "
                     f"{row['start_w1_s']:.1f} s (1 worker), {row['start_w2_s']:.1f} s "
                     "(2 workers), not in the times.")
    lines += ["", "## Instances tried (the scan that chose them)", "",
              f"The serial s* search alone, `--scan` ({SCAN_NOTE}):", "",
              "| n | p | seed | r | outcome | states | seconds |",
              "| ---: | ---: | ---: | ---: | --- | ---: | ---: |"]
    lines += [f"| {n} | {p} | {seed} | {r} | {status} | {states:,} | {t:.2f} |"
              for n, p, seed, r, status, states, t in SCAN]
    (out / "robustness_dask_sstar.md").write_text("\n".join(lines) + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--instances", nargs="+", default=list(INSTANCES), metavar="N:P:SEED:R")
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--scan", nargs="+", metavar="N:P:SEED:R")
    ap.add_argument("--limit", type=float, default=130.0, help="seconds per scanned search")
    ap.add_argument("--out", default="benchmarks/results")
    args = ap.parse_args()
    if args.scan:
        scan(args.scan, args.limit)
        return
    t0 = time.perf_counter()
    argv = "python -m benchmarks.robustness_dask_sstar " + " ".join(
        ["--instances", *args.instances, "--repeats", str(args.repeats)])
    rows = []
    for spec in args.instances:  # the files are rewritten after each instance
        rows.append(bench(spec, args.repeats))
        _write(rows, Path(args.out), argv, time.perf_counter() - t0)


if __name__ == "__main__":
    main()
