"""Hostile review of issue 12 as a new user meets it: sweeps of every kind on graph
files and generated graphs, CLI contracts, figures of odd trajectories."""

from __future__ import annotations

from pathlib import Path

import rescon

ROOT = Path(__file__).resolve().parents[1]
PAPER_GRAPH = ROOT / "examples" / "graphs" / "paper_example.edgelist"


def test_robustness_cells_of_a_graph_file_run_every_repetition():
    """A robustness grid over the user's own graph file (no generator): each repetition
    gets a seed, which a file graph does not take, and must not fail on it."""
    table = rescon.sweep({"base": {"graph": {"edgelist": str(PAPER_GRAPH)}},
                          "run": {"kind": "robustness", "repetitions": 2}}, workers=0)
    assert list(table["status"]) == ["ok", "ok"], list(table["error"])
    assert list(table["rho"]) == [5, 5] and list(table["s_star"]) == [1, 1]
    assert list(table["certificate_verdict"]) == ["valid", "valid"]
