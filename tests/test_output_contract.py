"""The output contract (issue 10 §6): stdout carries results only.

HiGHS prints its banner once per process, so every check runs a fresh interpreter.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap

import networkx as nx
import numpy as np
import pytest

from rescon.consensus.adversaries import Behaviour
from rescon.errors import InputError

pytestmark = pytest.mark.filterwarnings("ignore::rescon.consensus.scenario.ScenarioWarning")

#: one API call per place a HiGHS model is built (each in its own process)
API_CALLS = {
    "margin LP (empty kernel)":
        "rescon.safe_kernel(np.random.default_rng(0).normal(size=(6, 2)), 3)",
    "robustness MILP":
        "rescon.robustness(nx.gnp_random_graph(12, 0.5, seed=1, directed=True),"
        " method='milp')",
    "Tverberg MILP":
        "rescon.tverberg_partition(np.random.default_rng(1).normal(size=(7, 2)), 3)",
    "kernel QP on highs":
        "rescon.safe_kernel([[0, 0], [1, 0], [1, 1], [0, 1], [0.3, 0.6]], 1)"
        ".point('project', backend='highs')",
    "kernel QP on cvxpy:HIGHS (CVXPY builds its own Highs)":
        "rescon.safe_kernel([[0, 0], [1, 0], [1, 1], [0, 1], [0.3, 0.6]], 1)"
        ".point('project', backend='cvxpy:HIGHS')",
}


def _python(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], check=False,
                          capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("call", list(API_CALLS))
def test_api_writes_nothing_to_stdout(call):
    proc = _python(f"import numpy as np, networkx as nx, rescon\n{API_CALLS[call]}\n")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "", proc.stdout


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "rescon.cli", *args], check=False,
                          capture_output=True, text=True, timeout=300)


def _one_json_object(proc: subprocess.CompletedProcess) -> dict:
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert len(lines) == 1, proc.stdout
    data = json.loads(lines[0])
    assert isinstance(data, dict)
    return data


def test_cli_kernel_json_is_one_object(tmp_path):
    pts = tmp_path / "p.csv"
    pts.write_text("0,0\n1,0\n0,1\n1,1\n2,3\n-1,2\n")
    assert _one_json_object(_cli("kernel", str(pts), "--F", "3", "--json"))["empty"] is True


def test_cli_robustness_milp_json_is_one_object(tmp_path):
    import networkx as nx

    G = nx.gnp_random_graph(12, 0.5, seed=1, directed=True)
    g = tmp_path / "g.edgelist"
    g.write_text("".join(f"{u} {v}\n" for u, v in G.edges()))
    data = _one_json_object(_cli("robustness", str(g), "--method", "milp", "--json"))
    assert data["exact"] is True and data["method"] == "milp"


# --------------------------------------------------------------------------- #
# the engine checks what a behaviour returns
# --------------------------------------------------------------------------- #


class _Shaped(Behaviour):
    """Returns one array of a given shape whatever the receivers."""

    def __init__(self, shape):
        self.shape = shape

    def messages(self, sender, receivers, view):
        return np.full(self.shape, 5.0)

    def to_dict(self):
        return {}


@pytest.mark.parametrize("shape", [(1, 2), (2,), (3, 2, 1)])
def test_engine_refuses_a_message_of_the_wrong_shape(shape):
    from rescon.consensus.engine import simulate
    from rescon.consensus.scenario import Scenario
    from rescon.graphs.generators import circulant

    G = nx.relabel_nodes(circulant(8, 4), {v: f"a{v}" for v in range(8)})
    x0 = np.random.default_rng(0).uniform(0, 1, size=(8, 2))
    sc = Scenario(graph=G, x0=x0, F=1, adversaries={"a3": _Shaped(shape)}, steps=3,
                  check_robustness=False)
    with pytest.raises(InputError, match=r"adversary 'a3'.*shape"):
        simulate(sc)


# --------------------------------------------------------------------------- #
# time-limited robustness: r_max never poses as rho, method says what ran
# --------------------------------------------------------------------------- #


def _undecided(monkeypatch):
    """Every exact decision of r-robustness stops at the time limit."""
    import rescon.graphs.robustness as rb

    monkeypatch.setattr(rb, "_decide_r", lambda *a, **kw: rb._Decision(None, method="search"))


def test_unsettled_rho_is_not_reported_as_r_max(monkeypatch):
    import rescon

    G = nx.gnp_random_graph(30, 0.5, directed=True, seed=3)
    _undecided(monkeypatch)
    rep = rescon.robustness(G, time_limit=5)
    assert not rep.exact and rep.r_lower < rep.r_upper
    assert rep.r_max is None and rep.s_max is None
    assert rep.method == "search"


def test_cli_unsettled_rho_json(monkeypatch, tmp_path, capsys):
    from rescon.cli import main

    g = tmp_path / "er.edgelist"
    G = nx.gnp_random_graph(30, 0.5, directed=True, seed=3)
    g.write_text("".join(f"{u} {v}\n" for u, v in G.edges()))
    _undecided(monkeypatch)
    assert main(["robustness", str(g), "--time-limit", "5", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["exact"] is False and data["r_max"] is None and data["s_max"] is None
    assert data["r_lower"] < data["r_upper"] and data["method"] == "search"


def test_method_names_the_s_star_search_that_timed_out():
    import rescon
    from rescon.graphs.generators import circulant

    rep = rescon.robustness(circulant(64, 6).to_directed(), time_limit=0.3)
    assert rep.s_max is None and rep.s_lower < rep.s_upper  # s* cut by the time limit
    assert rep.r_lower == rep.r_upper == rep.r_max == 6  # rho proven: r_max is rho
    assert rep.method != "bounds", rep.method


# --------------------------------------------------------------------------- #
# bad input: exit 2, one line on stderr, no traceback
# --------------------------------------------------------------------------- #


def _run(argv, capsys):
    from rescon.cli import main

    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def _clean_error(code, out, err, *words):
    assert code == 2, (code, out, err)
    assert out == "" and "Traceback" not in err
    assert len(err.strip("\n").splitlines()) == 1 and err.startswith("rescon: error:"), err
    for w in words:
        assert w in err, err


@pytest.fixture
def square(tmp_path):
    p = tmp_path / "square.csv"
    p.write_text("0,0\n1,0\n1,1\n0,1\n")
    return p


def test_cli_plot_unsupported_format(capsys, square, tmp_path):
    _clean_error(*_run(["kernel", square, "--F", 1, "--plot", tmp_path / "k.xyz"], capsys),
                 "--plot", ".png")
    _clean_error(*_run(["kernel", square, "--F", 1, "--plot", tmp_path / "k"], capsys),
                 "--plot")


def test_cli_overflow_is_a_clean_error(capsys, square, monkeypatch):
    import rescon.geometry.kernel as gk

    def overflow(X, F):
        raise OverflowError("int too large to convert to float")

    monkeypatch.setattr(gk, "safe_kernel", overflow)
    _clean_error(*_run(["kernel", square, "--F", 1], capsys), "out of range")


def test_cli_multi_line_error_message_is_one_line(capsys, square, monkeypatch):
    import rescon.geometry.kernel as gk

    def bad(X, F):
        raise InputError("first line\nsecond line")

    monkeypatch.setattr(gk, "safe_kernel", bad)
    _clean_error(*_run(["kernel", square, "--F", 1], capsys), "first line second line")


# --------------------------------------------------------------------------- #
# one rule for output paths
# --------------------------------------------------------------------------- #


def test_output_paths_create_missing_parents(capsys, square, tmp_path):
    cert = tmp_path / "a" / "b" / "k.json"
    png = tmp_path / "c" / "d" / "k.png"
    code, _out, err = _run(["kernel", square, "--F", 1, "--certificate", cert, "--plot", png,
                           "--json"], capsys)
    assert code == 0, err
    assert cert.is_file() and png.is_file()
    g = tmp_path / "g.edgelist"
    g.write_text("".join(f"{u} {v}\n" for u in range(4) for v in range(4) if u != v))
    cert2 = tmp_path / "e" / "f" / "r.json"
    assert _run(["robustness", g, "--certificate", cert2], capsys)[0] == 0
    assert cert2.is_file()


def test_output_paths_of_the_wrong_kind_are_refused(capsys, square, tmp_path):
    _clean_error(*_run(["kernel", square, "--F", 1, "--certificate", tmp_path], capsys),
                 "--certificate", "is a directory")
    (tmp_path / "d.png").mkdir()
    _clean_error(*_run(["kernel", square, "--F", 1, "--plot", tmp_path / "d.png"], capsys),
                 "--plot", "is a directory")
    blocker = tmp_path / "file"
    blocker.write_text("")
    _clean_error(*_run(["kernel", square, "--F", 1, "--certificate", blocker / "k.json"],
                       capsys), "--certificate")


def test_write_json_and_to_csv_follow_the_output_rule(tmp_path):
    import rescon
    from rescon.io import write_json

    target = tmp_path / "new" / "dir" / "x.json"
    write_json({"a": 1}, target)
    assert json.loads(target.read_text()) == {"a": 1}
    with pytest.raises(InputError, match="is a directory"):
        write_json({"a": 1}, tmp_path)
    tr = rescon.simulate(rescon.Scenario.from_toml(_scenario_file(tmp_path)))
    csv_path = tr.to_csv(tmp_path / "more" / "t.csv")
    assert csv_path.read_text().startswith("k,t,node,benign,x1,x2")
    with pytest.raises(InputError, match="is a directory"):
        tr.to_csv(tmp_path)


# --------------------------------------------------------------------------- #
# without matplotlib (pip install -e . only)
# --------------------------------------------------------------------------- #


@pytest.fixture
def no_matplotlib(monkeypatch):
    import importlib.util

    real = importlib.util.find_spec

    def find_spec(name, *args, **kw):
        return None if name.split(".")[0] == "matplotlib" else real(name, *args, **kw)

    monkeypatch.setattr(importlib.util, "find_spec", find_spec)


def test_plot_without_matplotlib_says_what_to_install(no_matplotlib, capsys, square, tmp_path):
    import rescon

    _clean_error(*_run(["kernel", square, "--F", 1, "--plot", tmp_path / "k.png"], capsys),
                 "install rescon[plot]")
    K = rescon.safe_kernel([[0, 0], [1, 0], [1, 1], [0, 1]], 1)
    with pytest.raises(rescon.errors.MissingDependency, match=r"install rescon\[plot\]"):
        K.plot()
    assert not (tmp_path / "k.png").exists()
    _clean_error(*_run(["simulate", _scenario_file(tmp_path), "--out", tmp_path / "o",
                        "--plot"], capsys), "install rescon[plot]")
    tr = rescon.simulate(rescon.Scenario.from_toml(_scenario_file(tmp_path)))
    with pytest.raises(rescon.errors.MissingDependency, match=r"install rescon\[plot\]"):
        tr.plot(tmp_path / "t.png")


# --------------------------------------------------------------------------- #
# scenario files: every malformed value is one clean error
# --------------------------------------------------------------------------- #

_RING = "".join(f"{u} {(u + k) % 12}\n" for u in range(12) for k in (1, 2, 3, -1, -2, -3))
_STATES = "".join(f"{i} = [{i}.0, {i % 3}.5]\n" for i in range(12))


def _scenario_file(tmp_path, *, scenario="F = 1\nsteps = 3", initial=_STATES, extra=""):
    (tmp_path / "ring.edgelist").write_text(_RING)
    p = tmp_path / "s.toml"
    p.write_text(f"[scenario]\n{scenario}\n[graph]\nedgelist = \"ring.edgelist\"\n"
                 f"[initial]\n{initial}\n{extra}")
    return p


def test_scenario_file_template_is_valid(tmp_path):
    from rescon.consensus.scenario import Scenario

    sc = Scenario.from_toml(_scenario_file(tmp_path, extra=(
        '[[dos]]\nlinks = [[1, 2], [2, 3]]\n[dos.schedule]\nkind = "periodic"\n'
        "period = 2.0\nduration = 0.5\n")))
    assert (len(sc.nodes), sc.d, sc.steps, sc.dos[0].links) == (12, 2, 3,
                                                               frozenset({(1, 2), (2, 3)}))


_DOS = '[dos.schedule]\nkind = "periodic"\nperiod = 2.0\nduration = 0.5\n'
_BAD_SCENARIOS = {
    "steps": ({"scenario": "F = 1\nsteps = 10000000000000"}, ["steps", "PiB"]),
    "links all": ({"extra": f'[[dos]]\nlinks = "all"\n{_DOS}'}, ["links"]),
    "links flat": ({"extra": f"[[dos]]\nlinks = [1, 2]\n{_DOS}"}, ["links"]),
    "links triple": ({"extra": f"[[dos]]\nlinks = [[1, 2, 3]]\n{_DOS}"}, ["links"]),
    "file 5": ({"initial": "file = 5"}, ["file"]),
    "state a": ({"initial": _STATES.replace("0 = [0.0, 0.5]", '0 = "a"')}, ["[initial] 0"]),
    "state bool": ({"initial": _STATES.replace("0 = [0.0, 0.5]", "0 = [true, 1.0]")},
                   ["[initial] 0"]),
    "state huge": ({"initial": _STATES.replace("0 = [0.0, 0.5]", "0 = [1e308, 1.0]")},
                   ["1e+150"]),
    "file and states": ({"initial": 'file = "x.csv"\n0 = [1.0, 2.0]'}, ["file", "not both"]),
    "adversary kind": ({"extra": '[adversaries.0]\nkind = "nope"\n'}, ["adversaries.0"]),
    "T bool": ({"scenario": "F = 1\nsteps = 3\nT = true"}, ["T"]),
    "alpha text": ({"scenario": 'F = 1\nsteps = 3\nalpha = "x"'}, ["alpha"]),
    "paper yes": ({"scenario": 'paper_example = "yes"'}, ["paper_example"]),
    "check yes": ({"scenario": 'F = 1\nsteps = 3\ncheck_robustness = "no"'},
                  ["check_robustness"]),
}


@pytest.mark.parametrize("case", list(_BAD_SCENARIOS))
def test_bad_scenario_files(case, tmp_path, capsys):
    from rescon.consensus.scenario import Scenario

    kw, words = _BAD_SCENARIOS[case]
    path = _scenario_file(tmp_path, **kw)
    with pytest.raises(InputError) as exc:
        Scenario.from_toml(path)
    assert "\n" not in str(exc.value)
    for w in words:
        assert w in str(exc.value), str(exc.value)
    _clean_error(*_run(["simulate", path, "--json"], capsys), *words)


@pytest.mark.parametrize("text, words", [
    ("scenario = 5\n", ["[scenario]", "table"]),
    ("[scenario]\npaper_example = true\nsteps = 3\n[graph]\nedges = [[1, 2]]\n", ["[graph]"]),
    ("[scenario]\nF = 1\n[graph]\nedges = [[1, 2]]\nundirected = \"no\"\n[initial]\n",
     ["undirected"]),
    ("[scenario]\nF = 1\n[graph]\nedges = [[1.5, 2]]\n[initial]\n", ["edges"]),
    ("[scenario]\nF = 1\n[graph]\nedgelist = 3\n[initial]\n", ["edgelist"]),
    ("initial = 3\n[scenario]\nF = 1\n[graph]\nedges = [[1, 2]]\n", ["[initial]", "table"]),
    ("dos = 5\n[scenario]\nF = 1\n[graph]\nedges = [[1, 2]]\n[initial]\n", ["dos"]),
    ("adversaries = 5\n[scenario]\nF = 1\n[graph]\nedges = [[1, 2]]\n[initial]\n",
     ["[adversaries]"]),
])
def test_bad_scenario_tables(text, words, tmp_path, capsys):
    from rescon.consensus.scenario import Scenario

    path = tmp_path / "s.toml"
    path.write_text(text)
    with pytest.raises(InputError) as exc:
        Scenario.from_toml(path)
    for w in words:
        assert w in str(exc.value), str(exc.value)
    _clean_error(*_run(["simulate", path], capsys), *words)


def test_scenario_api_validates_states_and_numbers():
    from rescon.consensus.scenario import Scenario
    from rescon.graphs.generators import circulant

    G = circulant(12, 3)
    x0 = {v: [float(v), 1.0] for v in G}
    with pytest.raises(InputError, match=r"x0\[3\]"):
        Scenario(graph=G, x0={**x0, 3: ["a", 1.0]}, F=1)
    with pytest.raises(InputError, match=r"x0"):
        Scenario(graph=G, x0=[[1e308, 0.0]] * 12, F=1)
    with pytest.raises(InputError, match="alpha"):
        Scenario(graph=G, x0=x0, F=1, alpha="x")
    with pytest.raises(InputError, match="T"):
        Scenario(graph=G, x0=x0, F=1, T=True)
    with pytest.raises(InputError, match="steps.*PiB"):
        Scenario(graph=G, x0=x0, F=1, steps=10**13)
    with pytest.raises(InputError, match="adversaries"):
        Scenario(graph=G, x0=x0, F=1, adversaries={0: "constant"})
    big = Scenario(graph=G, x0=[[1e150 * (-1) ** v, v] for v in range(12)], F=1, steps=3,
                   residual="none", check_robustness=False)
    import rescon

    assert np.isfinite(rescon.simulate(big).final_diameter)  # the largest states still run
