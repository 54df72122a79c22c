"""`rescon paper`: the paper's example end to end, its outputs and its claim verdicts."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest
from rescon_certificates.check import check, load

from rescon import cli
from rescon.paper import _Reproduction

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "certificates" / "examples"

#: what the run must find (SPEC §5, and the exact checks that settle it)
EXPECTED = {
    "graph_7_robust": "does not hold",  # rho(G) = 5; no 12-node graph is 7-robust
    "assumption2": "holds",
    "f_local": "holds",
    "assumption3": "holds",
    "alg1_consensus": "holds",
    "alg1_validity": "holds",
    "zero_fill_fails": "holds",
    # every 8 of the 10 costs share argmin {0} (certified): SPEC §5's "not F-redundant"
    # is refuted by the exact check
    "costs_F_redundant": "holds",
    "costs_2F_redundant": "does not hold",
    "alg2_consensus": "holds",
    "alg2_optimum": "does not hold",  # 0.8 from X* = {0} at t = 100 s
}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """One run of the command line, with --json, into a fresh directory."""
    out = tmp_path_factory.mktemp("paper") / "out"
    proc = subprocess.run([sys.executable, "-m", "rescon.cli", "paper", "--out", str(out),
                           "--json"], capture_output=True, text=True, check=False, cwd=ROOT)
    return out, proc


@pytest.mark.slow
def test_cli_exits_0_and_prints_one_json_object(run):
    out, proc = run
    assert proc.returncode == 0, proc.stderr
    printed = json.loads(proc.stdout)  # one object, nothing else on stdout
    assert isinstance(printed, dict)
    assert printed == json.loads((out / "summary.json").read_text())


@pytest.mark.slow
def test_outputs_exist(run):
    out, _ = run
    summary = json.loads((out / "summary.json").read_text())
    assert len(summary["figures"]) >= 4
    for name in summary["figures"]:
        assert (out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    report = (out / "report.md").read_text()
    for name in summary["figures"]:
        assert f"]({name})" in report  # embedded


@pytest.mark.slow
def test_every_certificate_checks_as_recorded(run):
    out, _ = run
    summary = json.loads((out / "summary.json").read_text())
    listed = {c["file"]: c for c in summary["certificates"]}
    assert set(listed) == {p.name for p in out.glob("*.cert.json")}
    assert len(listed) >= 5
    for name, entry in listed.items():
        verdict = check(load(str(out / name))).verdict  # the standalone checker again
        assert verdict != "invalid", name
        assert verdict == entry["verdict"], name


@pytest.mark.slow
def test_claim_verdicts(run):
    out, _ = run
    summary = json.loads((out / "summary.json").read_text())
    verdicts = {c["id"]: c["verdict"] for c in summary["claims"]}
    assert verdicts == EXPECTED
    report = (out / "report.md").read_text()
    for c in summary["claims"]:
        assert f"| **{c['verdict']}** |" in report
    assert summary["graph"]["rho"] == 5 and summary["graph"]["s_star"] == 1
    assert summary["optimum"]["exact"] and summary["optimum"]["point"] == ["0", "0"]


@pytest.mark.slow
def test_measured_numbers_are_recorded(run):
    out, _ = run
    s = json.loads((out / "summary.json").read_text())
    a2 = s["algorithm2"]
    assert a2["final_distance_to_optimum"] > 1e-3 * a2["initial_distance_to_optimum"]
    assert a2["long_run"]["final_distance_to_optimum"] < a2["final_distance_to_optimum"]
    assert a2["final_cost_at_mean"] > a2["F_star"] == pytest.approx(1.38)
    hold, zero = s["algorithm1"]["hold_centroid"], s["algorithm1"]["zero_centroid"]
    assert hold["policy"] == "hold" and zero["policy"] == "zero"
    assert max(abs(v) for v in zero["final_benign_mean"]) < 1e-3
    assert min(hold["final_benign_mean"]) > 1.0


@pytest.mark.parametrize(("source", "verdict"), [
    ("k21_2_robust_milp_unchecked.json", "unchecked"),
    ("c4_robustness.json", "valid"),
])
def test_certificate_verdicts_recorded_as_the_checker_gives_them(tmp_path, source, verdict):
    rep = _Reproduction(tmp_path, progress=False)
    entry = rep.certificate("x", json.loads((EXAMPLES / source).read_text()), "example")
    assert entry["verdict"] == verdict and (tmp_path / "x.cert.json").exists()


def test_tampered_certificate_recorded_invalid(tmp_path):
    cert = json.loads((EXAMPLES / "c4_robustness.json").read_text())
    cert["r_max"] = cert["r_max"] + 1
    entry = _Reproduction(tmp_path, progress=False).certificate("t", cert, "tampered")
    assert entry["verdict"] == "invalid"


def test_out_that_is_a_file_is_refused(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert cli.main(["paper", "--out", str(f)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("rescon: error: out:") and "not a directory" in err
    assert len(err.splitlines()) == 1


def test_redundancy_without_a_solver_is_not_decided(tmp_path, monkeypatch):
    """Without cvxpy (core install + [plot]) the r = 2F check needs a solver it lacks:
    the claim is "not decided" with the install hint, the other parts still run."""
    from rescon import paper
    from rescon.errors import SolverNotFound

    real = paper.check_redundancy

    def no_cvxpy(costs, r, **kw):
        if r == 4:
            raise SolverNotFound("backend 'cvxpy' is not installed (pip install cvxpy)")
        return real(costs, r, **kw)

    monkeypatch.setattr(paper, "check_redundancy", no_cvxpy)
    run = _Reproduction(tmp_path, progress=False)
    run.redundancy()
    verdicts = {c.id: (c.verdict, c.evidence) for c in run.claims}
    assert verdicts["costs_F_redundant"][0] == "holds"
    assert verdicts["costs_2F_redundant"][0] == "not decided"
    assert "rescon[solvers]" in verdicts["costs_2F_redundant"][1]
    assert run.summary["redundancy"]["r4"]["holds"] is None
    assert run.summary["optimum"]["exact"] and not (tmp_path / "redundancy_r4.cert.json").exists()
