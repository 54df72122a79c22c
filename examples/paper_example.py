"""The paper's numerical example (SPEC §5) end to end through the public API.

Shows: :func:`rescon.reproduce_paper` writes figures, certificates, ``summary.json``
and ``report.md``, and checks the paper's claims one by one; this script prints the
table "claim — verdict" and the verdict of every certificate, then one JSON line.

Run::

    python examples/paper_example.py [--out DIR] [--fast]

``--fast`` (or ``RESCON_EXAMPLES_FAST=1``) is accepted for uniformity with the other
examples; the reproduction is already short (about 10 s on 2 cores, warm caches).
"""

from __future__ import annotations

import argparse
import json
import os

import rescon


def main() -> None:
    """Reproduce the paper, print each claim's verdict and a one-line JSON summary."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/paper", help="output directory")
    ap.add_argument("--fast", action="store_true",
                    default=bool(os.environ.get("RESCON_EXAMPLES_FAST")))
    args = ap.parse_args()
    report = rescon.reproduce_paper(args.out, progress=False)
    for c in report.claims:
        print(f"{c.verdict:>14} | {c.id}: {c.claim}")
    for cert in report.certificates:
        print(f"certificate {cert['file']}: {cert['verdict']}")
    print(json.dumps({
        "out": str(report.out),
        "claims": {c.id: c.verdict for c in report.claims},
        "certificates": {c["file"]: c["verdict"] for c in report.certificates},
        "figures": list(report.figures),
        "seconds": round(report.seconds, 2),
    }))


if __name__ == "__main__":
    main()
