"""A small experiment sweep: ``examples/sweeps/small.toml`` through :func:`rescon.sweep`.

Shows: a TOML grid (the paper's example under three blocked-link policies × two
centres × 2 repetitions = 12 cells) run serially (``workers=0``, no Dask needed) or on
a local Dask cluster (``--workers N``) or an existing one (``--scheduler ADDRESS``);
one row per cell in ``OUT/results.parquet`` (resumable: rerunning skips finished
cells). Prints the table's main columns and one JSON line. Any grid works, e.g.
``examples/sweeps/robustness.toml`` (ρ and s* of generated graphs, certificates checked).

Run::

    python examples/sweep_small.py [GRID.toml] [--out DIR] [--workers N | --scheduler ADDR] [--fast]

``--fast`` (or ``RESCON_EXAMPLES_FAST=1``) is accepted for uniformity; the grid is
already small (30 steps per cell).
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import rescon

DEFAULT = Path(__file__).resolve().parent / "sweeps" / "small.toml"
#: columns never printed (the rest is printed when some row has a value)
HIDDEN = {"repetition", "error", "rescon_version", "seconds"}


def main() -> None:
    """Run the grid, print the rows and a one-line JSON summary."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("grid", nargs="?", default=str(DEFAULT), help="TOML grid")
    ap.add_argument("--out", default="out/sweep_small", help="output directory")
    ap.add_argument("--workers", type=int, default=None,
                    help="Dask local workers (default: 0 = serial, in this process)")
    ap.add_argument("--scheduler", default=None, help="address of a running Dask scheduler")
    ap.add_argument("--fast", action="store_true",
                    default=bool(os.environ.get("RESCON_EXAMPLES_FAST")))
    args = ap.parse_args()
    workers = 0 if args.workers is None and args.scheduler is None else args.workers
    df = rescon.sweep(args.grid, workers=workers, scheduler=args.scheduler, out=args.out,
                      progress=False)
    shown = [c for c in df.columns if c not in HIDDEN and df[c].notna().any()]
    print(df[shown].to_string(index=False))
    summary = {"cells": len(df), "ok": int((df["status"] == "ok").sum()),
               "results": str(Path(args.out) / "results.parquet")}
    if df["final_diameter"].notna().any():
        summary["max_final_diameter"] = float(df["final_diameter"].max())
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
