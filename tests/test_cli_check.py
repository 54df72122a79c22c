"""`rescon check CERT.json`: the four exit codes of DESIGN.md and the JSON report.

0 valid (every part verified), 1 invalid (reason on stderr), 2 unreadable, 3 not fully
checked (a part taken on trust or beyond the checker's limits, named on stdout).
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np

import rescon
from rescon.cli import main


def _complete(n: int) -> dict:
    return {"n": n, "edges": [[u, v] for u in range(n) for v in range(n) if u != v]}


def _rs(n: int, r: int, proof: dict) -> dict:
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": _complete(n), "r": r, "s": 1,
            "proof": proof}


def _run(capsys, *args) -> tuple[int, str, str]:
    code = main(["check", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out, err


def test_exit_codes_and_json(tmp_path, capsys):
    milp = {"method": "milp", "solver": "highs"}
    cases = {
        "valid": (_rs(5, 3, {"method": "complete"}), 0),
        "invalid": (_rs(5, 4, {"method": "complete"}), 1),
        "unchecked": (_rs(21, 2, milp), 3),
    }
    for verdict, (cert, code) in cases.items():
        path = tmp_path / f"{verdict}.json"
        path.write_text(json.dumps(cert))
        got, out, err = _run(capsys, path)
        assert got == code, (verdict, out, err)
        if verdict == "invalid":
            assert err.startswith("invalid: ") and out == ""
        else:
            assert out.splitlines()[0] == verdict and err == ""
        if verdict == "unchecked":
            assert out.splitlines()[1].startswith("not checked: proof: 'milp' proof")
        got, out, err = _run(capsys, path, "--json")
        report = json.loads(out)
        assert got == code and report["verdict"] == verdict
        assert report["valid"] == (verdict == "valid") and report["readable"] is True
        assert bool(report["unchecked"]) == (verdict == "unchecked")
    for name, text in (("inf.json", '{"rescon_certificate": 1e400}'),
                       ("infinity.json", '{"rescon_certificate": Infinity}'),
                       ("junk.json", "not json")):
        path = tmp_path / name
        path.write_text(text)
        got, out, err = _run(capsys, path)
        assert got == 2 and err.startswith("unreadable: "), (name, err)
        got, out, err = _run(capsys, path, "--json")
        assert got == 2 and json.loads(out)["verdict"] == "unreadable"
        # bad input: one line on stderr under --json too (DESIGN.md, command line)
        assert err.startswith("unreadable: ") and err.count("\n") == 1, (name, err)


def test_correct_kernel_too_large_to_enumerate_is_not_invalid(tmp_path, capsys):
    """rescon's own certificate for a d = 3, n = 50 kernel was called "invalid: too large
    to check"; it is a correct certificate, so now: exit 3 naming the parts. (With the
    vertex adjacency rescon now writes, it is valid; the old form, without it, is not.)"""
    X = np.random.default_rng(0).normal(size=(50, 3))
    cert = rescon.safe_kernel(X, 4).certificate
    assert rescon.check_certificate(cert).verdict == "valid"
    del cert["adjacency"]
    res = rescon.check_certificate(cert)
    assert res.verdict == "unchecked" and "vertex enumeration" in res.trusted, res
    path = tmp_path / "kernel.json"
    path.write_text(json.dumps(cert))
    proc = subprocess.run([sys.executable, "-m", "rescon.cli", "check", str(path)],
                          capture_output=True, text=True, timeout=120, check=False)
    assert proc.returncode == 3 and proc.stderr == "", proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0] == "unchecked" and any("enumerating" in ln for ln in lines[1:]), lines
