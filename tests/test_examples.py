"""Every script in examples/ runs with its fast settings and prints what it claims.

Each script runs as a subprocess (``--fast``, outputs in a tmp directory, cwd there);
its last stdout line is one JSON object whose content is checked here.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.spatial import ConvexHull

import rescon

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def run_example(name: str, *args: str, cwd: Path) -> dict[str, Any]:
    """Run ``examples/NAME --fast ARGS``; assert exit 0; return its last line's JSON."""
    proc = subprocess.run([sys.executable, str(EXAMPLES / name), "--fast", *args],
                          cwd=cwd, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.strip().splitlines()[-1])


@pytest.mark.slow
def test_paper_example(tmp_path: Path) -> None:
    out = tmp_path / "paper"
    res = run_example("paper_example.py", "--out", str(out), cwd=tmp_path)
    assert "does not hold" in res["claims"].values()  # the graph is not 7-robust
    assert res["certificates"] and "invalid" not in res["certificates"].values()
    assert all((out / f).is_file() for f in [*res["certificates"], *res["figures"]])
    assert (out / "summary.json").is_file() and (out / "report.md").is_file()


def test_graph_robustness_default_graph(tmp_path: Path) -> None:
    res = run_example("graph_robustness.py", "--out", str(tmp_path / "g"), cwd=tmp_path)
    assert (res["rho"], res["s_star"], res["exact"]) == (5, 1, True)  # SPEC §5: not 7-robust
    S1, S2 = map(set, res["witness"])
    assert S1 and S2 and not S1 & S2
    assert res["verdict"] == "valid"
    cert = json.loads(Path(res["certificate"]).read_text())
    assert rescon.check_certificate(cert).verdict == "valid"  # the file as written


def test_graph_robustness_own_file(tmp_path: Path) -> None:
    """A 6-cycle written by hand: every node has in-degree 2, ρ = 1 (two arcs)."""
    path = tmp_path / "cycle.edgelist"
    path.write_text("".join(f"{i} {(i + 1) % 6}\n{(i + 1) % 6} {i}\n" for i in range(6)))
    res = run_example("graph_robustness.py", str(path), "--out", str(tmp_path / "c"),
                      cwd=tmp_path)
    assert res["n"] == 6 and res["rho"] == 1 and res["verdict"] == "valid"


def test_kernel_of_csv(tmp_path: Path) -> None:
    png = tmp_path / "kernel.png"
    res = run_example("kernel_of_csv.py", str(EXAMPLES / "points" / "attack_12.csv"),
                      "--F", "2", "--plot", str(png), cwd=tmp_path)
    assert (res["n"], res["d"], res["F"], res["empty"], res["dim"]) == (12, 2, 2, False, 2)
    assert res["verdict"] == "valid"
    assert png.is_file() and png.stat().st_size > 1000
    hull = ConvexHull(np.array(res["vertices"]))  # the kernel point lies in Ψ
    assert np.all(hull.equations @ np.append(res["point"], 1.0) <= 1e-9)


def test_robot_network(tmp_path: Path) -> None:
    res = run_example("robot_network.py", "--out", str(tmp_path / "r"), cwd=tmp_path)
    assert len(res["adversaries"]) == 2 and len(res["dos_links"]) == 3
    assert res["final_diameter"] < 1.0  # initial positions span up to 10 × √2
    if not res["warnings"]:  # assumptions hold, no residual: states stay in the hull
        assert res["max_validity"] <= 1e-9
    assert Path(res["plot"]).is_file()


def test_rmdo_costs_agree(tmp_path: Path) -> None:
    res = run_example("rmdo_costs.py", cwd=tmp_path)
    ways = ["atoms", "casadi", "cvxpy", "callables"]
    for way in ways:
        assert res[way]["max_difference_to_atoms"] <= 1e-9
        assert np.allclose(res[way]["optimum"], res["x_star"], atol=1e-6)
    assert res["atoms"]["optimum_method"].startswith("exact")


def test_sweep_small_serial(tmp_path: Path) -> None:
    out = tmp_path / "sweep"
    res = run_example("sweep_small.py", "--out", str(out), cwd=tmp_path)
    assert res["cells"] == res["ok"] == 12
    assert Path(res["results"]).is_file()
    again = run_example("sweep_small.py", "--out", str(out), cwd=tmp_path)  # resumes
    assert again == res
