"""The safe kernel Ψ(X, F) of a CSV point cloud, with its plot.

Shows: :func:`rescon.io.read_points` (CSV with or without header, .npy),
:func:`rescon.safe_kernel` (Ψ(X, F) = ⋂ {conv(S) : S ⊆ X, |S| = n − F}, exactly),
a canonical kernel point (:meth:`rescon.SafeKernel.point`), the certificate checked
by :func:`rescon.check_certificate`, and :meth:`rescon.SafeKernel.plot` (d = 2, 3).

Run::

    python examples/kernel_of_csv.py [POINTS.csv] --F 2 [--plot PNG] [--fast]

POINTS.csv defaults to ``examples/points/attack_12.csv``. ``--fast`` (or
``RESCON_EXAMPLES_FAST=1``) is accepted for uniformity; small clouds are fast anyway.
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import rescon
from rescon.io import read_points

DEFAULT = Path(__file__).resolve().parent / "points" / "attack_12.csv"


def main() -> None:
    """Compute Ψ(X, F), check its certificate, optionally plot, print one JSON line."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("points", nargs="?", default=str(DEFAULT), help="CSV or .npy file")
    ap.add_argument("--F", type=int, default=2, help="number of points that may be removed")
    ap.add_argument("--plot", default=None, help="write the plot to this PNG file")
    ap.add_argument("--fast", action="store_true",
                    default=bool(os.environ.get("RESCON_EXAMPLES_FAST")))
    args = ap.parse_args()
    X = read_points(args.points)
    K = rescon.safe_kernel(X, args.F)
    check = rescon.check_certificate(K.certificate)
    point = None if K.is_empty else K.point()[0]
    if args.plot is not None and X.shape[1] in (2, 3):
        K.plot(point=point, path=args.plot)
    print(f"{args.points}: n = {X.shape[0]}, d = {X.shape[1]}, F = {args.F}: "
          f"dim Psi = {K.dim}, {len(K.vertices)} vertices, certificate {check.verdict}")
    print(json.dumps({
        "n": int(X.shape[0]), "d": int(X.shape[1]), "F": args.F, "empty": K.is_empty,
        "dim": int(K.dim), "vertices": K.vertices.tolist(),
        "point": None if point is None else point.tolist(),
        "verdict": check.verdict, "plot": args.plot,
    }))


if __name__ == "__main__":
    main()
