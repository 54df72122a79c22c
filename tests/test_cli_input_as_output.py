"""``--certificate`` naming the command's own input file (V39 noticed:
``rescon robustness G.txt --certificate G.txt`` replaced the graph by the certificate):
refused before any work, exit 2 with one line, the input untouched — also through a
symbolic link; another name is written as before."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from rescon.cli import main

ROOT = Path(__file__).resolve().parents[1]
INPUTS = {
    "robustness": (ROOT / "examples" / "graphs" / "paper_example.edgelist", []),
    "kernel": (ROOT / "examples" / "points" / "attack_12.csv", ["--F", "2"]),
    "redundancy": (ROOT / "examples" / "scenarios" / "paper_rmdo.toml", ["--r", "1"]),
}


def _run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


@pytest.mark.parametrize("command", sorted(INPUTS))
@pytest.mark.parametrize("via_link", [False, True])
def test_certificate_over_the_input_is_refused(command, via_link, tmp_path, capsys):
    source, extra = INPUTS[command]
    given = tmp_path / source.name
    shutil.copy(source, given)
    before = given.read_bytes()
    target = given
    if via_link:
        target = tmp_path / "cert.json"
        target.symlink_to(given)
    code, out, err = _run([command, given, *extra, "--certificate", target], capsys)
    assert code == 2 and out == ""
    assert err.startswith("rescon: error: --certificate:") and "is the input file" in err
    assert len(err.strip().splitlines()) == 1
    assert given.read_bytes() == before


def test_another_name_is_written(tmp_path, capsys):
    source, _ = INPUTS["robustness"]
    given = tmp_path / source.name
    shutil.copy(source, given)
    cert = tmp_path / "cert.json"
    code, _, _ = _run(["robustness", given, "--certificate", cert], capsys)
    assert code == 0 and cert.read_text().startswith("{")
