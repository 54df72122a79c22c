"""``--quiet`` on every subcommand: no progress bar on stderr, warnings still printed.

Bars are shown only when stderr is a terminal, so these tests make the captured stderr
claim to be one: without ``--quiet`` the long commands then draw a bar (the tests can
fail), with it they must not.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import pytest

from rescon import paper
from rescon.cli import _parser
from rescon.graphs.facts import clear_cache
from tests.test_cli import run

ROOT = Path(__file__).parent.parent
GRAPH = ROOT / "examples" / "graphs" / "paper_example.edgelist"
PAPER_TOML = ROOT / "examples" / "scenarios" / "paper.toml"
RMDO_TOML = ROOT / "examples" / "scenarios" / "rmdo_quadratic.toml"
POINTS = ROOT / "examples" / "points" / "attack_12.csv"
#: what a tqdm bar leaves on stderr: "desc:  40%|████      | 80/200 [...]"
BAR = re.compile(r"\d+%\|")

#: the commands whose library call draws a bar, each as fast as it goes
WITH_BARS = {
    "robustness": ["robustness", GRAPH],
    "simulate": ["simulate", PAPER_TOML],
    "rmdo": ["rmdo", RMDO_TOML],
}


@pytest.fixture
def terminal(capsys, monkeypatch):
    """``terminal(argv)``: the CLI run in-process, its captured stderr saying it is a
    terminal (patched in the test's call phase: pytest swaps the capture stream). Each
    run starts cold: robustness remembers what it proved about a graph in this process
    (graphs.facts), so a second run on it answers from those facts ("method": "bounds"
    where a cold run says "search")."""
    def call(argv):
        clear_cache()
        monkeypatch.setattr(sys.stderr, "isatty", lambda: True)
        return run(argv, capsys)
    return call


@pytest.mark.parametrize("name", sorted(WITH_BARS))
def test_bar_on_a_terminal_and_none_with_quiet(terminal, name):
    code, out, err = terminal([*WITH_BARS[name], "--json"])
    assert code == 0, err
    assert BAR.search(err), err  # the test would pass vacuously without a bar here
    answer = json.loads(out)
    for flag in ("--quiet", "-q"):
        code, out_q, err_q = terminal([*WITH_BARS[name], flag, "--json"])
        assert code == 0, err_q
        assert not BAR.search(err_q) and "\r" not in err_q, err_q
        quiet = json.loads(out_q)
        assert {**quiet, "seconds": 0} == {**answer, "seconds": 0}  # the same answer
    code, out_t, err_t = terminal([*WITH_BARS[name], "--quiet"])
    assert code == 0 and out_t and not BAR.search(err_t)


def test_quiet_keeps_warnings(terminal):
    """The paper's graph is not 7-robust: the warning is printed under --quiet too."""
    code, _, err = terminal(["simulate", PAPER_TOML, "--quiet"])
    assert code == 0
    assert "rescon: warning: the graph is not 7-robust" in err
    assert not BAR.search(err)


@pytest.mark.parametrize("argv", [["kernel", POINTS, "--F", "2"],
                                  ["redundancy", RMDO_TOML, "--r", "1"]],
                         ids=["kernel", "redundancy"])
def test_quiet_accepted_by_commands_without_bars(terminal, argv):
    code, out, err = terminal([*argv, "--quiet"])
    assert code == 0, err
    assert out and err == ""


def test_quiet_reaches_paper_and_sweep(terminal, monkeypatch, tmp_path):
    """``rescon paper`` and ``rescon sweep`` hand progress=False to the library."""
    seen = {}

    def spy(name):
        def call(*args, **kwargs):
            seen[name] = kwargs.get("progress", "missing")
            raise KeyboardInterrupt  # stop here: only the arguments matter
        return call

    import rescon.sweep

    monkeypatch.setattr(paper, "reproduce_paper", spy("paper"))
    monkeypatch.setattr(rescon.sweep, "sweep", spy("sweep"))
    grid = tmp_path / "grid.toml"
    grid.write_text("[base.scenario]\npaper_example = true\n")
    for argv in (["paper", "--out", tmp_path / "p"], ["sweep", grid, "--workers", "0"]):
        for flag, expected in (([], None), (["--quiet"], False)):
            code, _, _ = terminal([*argv, *flag])
            assert code == 130 and seen.pop(argv[0]) is expected


def test_every_subcommand_has_quiet():
    sub = next(a for a in _parser()._actions if a.dest == "command")
    for name, command in sub.choices.items():
        assert any("--quiet" in a.option_strings for a in command._actions), name
