"""``rescon rmdo`` and RMDO files (issue 11 §5): the examples through the command line,
the outputs, and every bad-input path (one line on stderr, exit 2)."""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import rescon
from rescon.errors import InputError
from rescon.optim.files import read_costs, read_rmdo
from tests.test_cli import run

ROOT = Path(__file__).parent.parent
EXAMPLES = ROOT / "examples" / "scenarios"
SIMULATE_KEYS = {"steps", "N", "d", "F", "algorithm", "policy", "final_diameter",
                 "max_validity", "assumptions_violated", "seconds"}
RMDO_KEYS = SIMULATE_KEYS | {"final_cost", "optimum", "final_distance_to_optimum",
                             "final_gap", "step_size"}

#: K5, d = 2, no adversary: a small, fast scenario the cost tables are added to
BASE = """\
[scenario]
F = 0
steps = 40
check_robustness = false
[graph]
edges = [[0, 1], [1, 2], [2, 3], [3, 4], [4, 0], [0, 2], [1, 3], [2, 4], [3, 0], [4, 1]]
undirected = true
[initial]
0 = [0.0, 0.0]
1 = [4.0, 0.0]
2 = [0.0, 4.0]
3 = [4.0, 4.0]
4 = [2.0, 1.0]
"""
QUAD = "".join(f'{i} = "(x1 - 1)^2 + {i + 1}*(x2 - 2)^2"\n' for i in range(5))


def run_json(argv, capsys) -> dict:
    code, out, err = run(list(argv) + ["--json"], capsys)
    assert code == 0, err
    lines = out.strip().splitlines()
    assert len(lines) == 1, out  # exactly one JSON object on stdout
    data = json.loads(lines[0], parse_constant=lambda c: pytest.fail(f"non-JSON {c}"))
    assert isinstance(data, dict)
    return data


def assert_error(argv, capsys, *needles) -> str:
    code, out, err = run(argv, capsys)
    assert code == 2, (code, out, err)
    assert out == "" and "Traceback" not in err
    lines = err.strip("\n").splitlines()
    assert len(lines) == 1 and lines[0].startswith("rescon: error:"), err
    for n in needles:
        assert n in lines[0], (n, lines[0])
    return lines[0]


def write(tmp_path: Path, text: str, name: str = "s.toml") -> Path:
    p = tmp_path / name
    p.write_text(textwrap.dedent(text), encoding="utf-8")
    return p


# ---------------------------------------------------------------- examples


@pytest.mark.slow
def test_example_rmdo_quadratic(capsys):
    """Redundant quadratics (common minimiser (2, -1)) under a two-faced adversary and
    DoS: the benign agents reach X* (exact)."""
    out = run_json(["rmdo", EXAMPLES / "rmdo_quadratic.toml"], capsys)
    assert set(out) == RMDO_KEYS
    opt = out["optimum"]
    assert opt["exact"] is True and opt["point"] == [2.0, -1.0] and opt["value"] == 0
    assert opt["dimension"] == 0
    assert out["final_distance_to_optimum"] < 0.02
    assert 0 <= out["final_gap"] < 1e-2 and out["final_cost"] < 1e-2
    assert out["N"] == 20 and out["step_size"] == "harmonic(5, 1)"


def test_example_paper_rmdo(capsys, tmp_path):
    out = run_json(["rmdo", EXAMPLES / "paper_rmdo.toml", "--out", tmp_path / "o", "--plot"],
                   capsys)
    assert set(out) == RMDO_KEYS | {"out"}
    assert (out["N"], out["d"], out["F"], out["steps"]) == (12, 2, 2, 200)
    assert out["optimum"]["exact"] is False  # nonsmooth costs: X* found numerically
    assert np.isfinite([out["final_cost"], out["final_distance_to_optimum"],
                        out["final_gap"]]).all()
    for name in ("trajectory.json", "trajectory.csv", "trajectory.png"):
        assert (tmp_path / "o" / name).stat().st_size > 0
    traj = json.loads((tmp_path / "o" / "trajectory.json").read_text())
    assert {"cost", "cost_at_mean", "distance_to_optimum"} <= set(traj["metrics"])
    assert traj["metrics"]["cost_at_mean"][-1] == pytest.approx(out["final_cost"])


def test_paper_file_same_as_python(tmp_path):
    """paper = true is rescon.optim.paper_costs on Scenario.paper_example; f7 = "x2"."""
    f = read_rmdo(EXAMPLES / "paper_rmdo.toml")
    ref = rescon.optim.paper_costs()
    assert sorted(f.costs) == sorted(ref)
    Z = np.random.default_rng(0).normal(size=(7, 2))
    for i, o in f.costs.items():
        np.testing.assert_array_equal(o.value(Z), ref[i].value(Z))
    p = write(tmp_path, '[scenario]\npaper_example = true\n[costs]\npaper = true\nf7 = "x2"\n')
    f7 = read_rmdo(p).costs[7]
    assert f7.value([[0.0, 0.2]]).tolist() == pytest.approx([0.09])


def test_human_output_and_warnings(capsys, tmp_path):
    p = write(tmp_path, BASE + "[costs]\n" + QUAD + '[step_size]\nkind = "sqrt_decay"\nc = 0.1\n')
    code, out, err = run(["rmdo", p], capsys)
    assert code == 0, err
    assert "sqrt_decay(0.1)" in out and "X* (exact (quadratic))" in out
    assert "rescon: warning: Assumption 5" in err  # not square-summable


# ---------------------------------------------------------------- files


@pytest.mark.parametrize(("table", "expect"), [
    ("", "harmonic(5, 1)"),
    ('[step_size]\nkind = "paper"\n', "harmonic(5, 1)"),
    ('[step_size]\nkind = "harmonic"\na = 2\nb = 3\n', "harmonic(2, 3)"),
    ('[step_size]\nkind = "sqrt_decay"\nc = 0.5\n', "sqrt_decay(0.5)"),
    ('[step_size]\nkind = "constant"\nvalue = 0.01\n', "constant(0.01)"),
])
def test_step_size_table(tmp_path, table, expect):
    f = read_rmdo(write(tmp_path, BASE + "[costs]\n" + QUAD + table))
    assert repr(f.step_size) == expect


def test_same_expression_is_one_oracle(tmp_path):
    costs = "".join(f'{i} = "abs(x1) + x2^2"\n' for i in range(5))
    f = read_rmdo(write(tmp_path, BASE + "[costs]\n" + costs))
    assert len({id(o) for o in f.costs.values()}) == 1


@pytest.mark.slow  # X* by Nelder-Mead on Python callables: ~5 s
def test_module_costs(capsys, tmp_path):
    """module = "pkg.mod:function", imported from the file's directory; mixed with
    per-agent expressions."""
    (tmp_path / "rmdo_user_costs_ok.py").write_text(textwrap.dedent("""\
        import numpy as np

        def build():
            f = lambda x: float(np.sum((x - 1.0) ** 2))
            g = lambda x: 2.0 * (x - 1.0)
            return {1: (f, g), 2: "(x1 - 1)^2 + (x2 - 1)^2", 3: (f, g), 4: (f, g)}
        """))
    p = write(tmp_path, BASE + '[costs]\nmodule = "rmdo_user_costs_ok:build"\n'
              '0 = "(x1 - 1)^2 + (x2 - 1)^2"\n')
    out = run_json(["rmdo", p], capsys)
    assert out["optimum"]["exact"] is False and out["final_distance_to_optimum"] < 0.05


def test_costs_file_for_redundancy(tmp_path):
    costs, d = read_costs(write(tmp_path, '[costs]\n1 = "x1^2"\n2 = "abs(x3)"\n'))
    assert d == 3 and sorted(costs) == [1, 2] and costs[1].d == 3
    costs, d = read_costs(write(tmp_path, 'd = 4\n[costs]\nalgorithm = "rmdo"\na = "x1^2"\n'))
    assert (d, list(costs), costs["a"].d) == (4, ["a"], 4)
    costs, d = read_costs(EXAMPLES / "paper_rmdo.toml")
    assert d == 2 and sorted(costs) == [1, 3, 4, 5, 6, 7, 8, 9, 10, 11]
    costs, d = read_costs(EXAMPLES / "rmdo_quadratic.toml")
    assert d == 2 and sorted(costs) == list(range(1, 20))  # agent 0 is the adversary
    for text, needle in (('d = 0\n[costs]\n1 = "x1^2"\n', "d must be"),
                         ('d = 2\n', "needs a [costs] table"),
                         ('d = 1\n[costs]\n1 = "x2^2"\n', "x2 is used but d = 1"),
                         ('[costs]\n1 = "x1^2 +"\n', "position 6"),
                         ('D = 2\n[costs]\n1 = "x1^2"\n', "unknown keys ['D']"),
                         ('[costs]\nalgorithm = "alg1"\n1 = "x1^2"\n', "algorithm must be")):
        with pytest.raises(InputError, match=r".*" + needle.replace("[", r"\[")):
            read_costs(write(tmp_path, text))


# ---------------------------------------------------------------- bad input


def test_simulate_refuses_rmdo_file(capsys):
    msg = assert_error(["simulate", EXAMPLES / "paper_rmdo.toml"], capsys, "rescon rmdo")
    assert "[costs]" in msg


def test_rmdo_needs_costs(capsys):
    assert_error(["rmdo", EXAMPLES / "paper.toml"], capsys, "needs a [costs] table")


BAD = {
    "unparsable": ('0 = "(x1 - 1)^2 + * x2"\n', ["agent 0", "position 13"]),
    "nonconvex": ('0 = "x1 * x2"\n', ["agent 0", "neither convex nor concave"]),
    "nonconvex_call": ('0 = "-abs(x1)"\n', ["agent 0", "x1"]),
    "dimension": ('0 = "x3^2"\n', ["agent 0", "x3 is used but d = 2"]),
    "not_a_string": ("0 = 3\n", ["agent 0", "int"]),
    "unknown_node": ('7 = "x1^2"\n', ["[7]", "not nodes of the graph"]),
    "typo_reserved": ('modul = "x:y"\n', ["['modul']", "not nodes", "reserved"]),
    "paper_mixed": ('paper = true\n0 = "x1^2"\n', ["paper = true", "unknown keys"]),
    "paper_not_true": ("paper = false\n", ["needs paper = true"]),
    "f7_without_paper": ('f7 = "x2"\n', ["needs paper = true"]),
    "f7_bad": ('paper = true\nf7 = "x3"\n', ["f7 must be"]),
    "module_syntax": ('module = "nocolon"\n', ["pkg.mod:function"]),
    "module_missing": ('module = "rmdo_no_such_module_zz:f"\n', ["cannot be imported",
                                                               "ModuleNotFoundError"]),
}


@pytest.mark.parametrize("name", sorted(BAD))
def test_bad_costs(capsys, tmp_path, name):
    table, needles = BAD[name]
    full = table if name.startswith(("paper", "f7", "module", "unknown", "typo")) else (
        table + QUAD.split("\n", 1)[1])
    p = write(tmp_path, BASE + "[costs]\n" + full)
    assert_error(["rmdo", p], capsys, str(p), *needles)


def test_agent_without_cost(capsys, tmp_path):
    p = write(tmp_path, BASE + "[costs]\n" + QUAD.split("\n", 1)[1])
    assert_error(["rmdo", p], capsys, "no cost for benign agent(s) [0]")


def test_costs_not_a_table(capsys, tmp_path):
    p = write(tmp_path, 'costs = "x1^2"\n' + BASE)
    assert_error(["rmdo", p], capsys, "[costs] must be a table")


@pytest.mark.parametrize(("table", "needle"), [
    ('kind = "cubic"\n', "kind must be one of paper, harmonic, sqrt_decay, constant"),
    ('kind = "harmonic"\na = 5\n', "needs a, b; missing b"),
    ('kind = "harmonic"\na = -1\nb = 1\n', "a must be"),
    ('kind = "constant"\nvalue = 0\n', "step_size must be"),
    ('kind = "constant"\nvalue = "big"\n', "step_size must be"),
    ('kind = "sqrt_decay"\nc = 1\nvalue = 2\n', "unknown keys ['value']"),
])
def test_bad_step_size(capsys, tmp_path, table, needle):
    p = write(tmp_path, BASE + "[costs]\n" + QUAD + "[step_size]\n" + table)
    assert_error(["rmdo", p], capsys, f"{p} [step_size]", needle)


@pytest.mark.parametrize(("body", "needles"), [
    ("x = 1\n", ["has no function 'build'"]),
    ("def build():\n    raise RuntimeError('boom')\n", ["build() failed", "RuntimeError: boom"]),
    ("def build():\n    return [1, 2]\n", ["must return a mapping", "list"]),
    ("raise ImportError('needs foo')\n", ["cannot be imported", "needs foo"]),
    ("def build():\n    return {i: 'x1^2' for i in (0, 1, 2, 3, 4, 9)}\n",
     ["[9]", "not nodes of the graph"]),
])
def test_bad_module(capsys, tmp_path, body, needles):
    name = f"rmdo_user_bad_{abs(hash(body))}"
    (tmp_path / f"{name}.py").write_text(body)
    p = write(tmp_path, BASE + f'[costs]\nmodule = "{name}:build"\n')
    assert_error(["rmdo", p], capsys, *needles)


def test_module_and_file_give_the_same_agent(capsys, tmp_path):
    (tmp_path / "rmdo_user_dup.py").write_text("def build():\n    return {0: 'x1^2'}\n")
    p = write(tmp_path, BASE + '[costs]\nmodule = "rmdo_user_dup:build"\n' + QUAD)
    assert_error(["rmdo", p], capsys, "agent 0 has a cost in the file and one from module")


def test_nan_oracle_names_agent_step_point(capsys, tmp_path):
    """An oracle returning NaN mid-run: one line naming the agent, step and point;
    nothing written."""
    (tmp_path / "rmdo_user_nan.py").write_text(textwrap.dedent("""\
        import math

        def build():
            f = lambda x: float(x[0] ** 2)
            g = lambda x: [math.nan if x[0] < 1.5 else 2 * x[0], 0.0]
            return {i: (f, g) for i in range(5)}
        """))
    p = write(tmp_path, BASE + '[costs]\nmodule = "rmdo_user_nan:build"\n')
    msg = assert_error(["rmdo", p, "--out", tmp_path / "o"], capsys, "subgradient",
                       "agent", "at step", "point")
    assert "nan" in msg.lower()
    assert not (tmp_path / "o" / "trajectory.json").exists()


def test_plot_needs_out_and_bad_out(capsys, tmp_path):
    assert_error(["rmdo", EXAMPLES / "paper_rmdo.toml", "--plot"], capsys, "--plot needs --out")
    f = tmp_path / "file"
    f.write_text("x")
    assert_error(["rmdo", EXAMPLES / "paper_rmdo.toml", "--out", f], capsys, "--out",
                 "not a directory")
    assert_error(["rmdo", tmp_path / "missing.toml"], capsys, "no such RMDO file")


def test_subprocess_bad_expression(tmp_path):
    p = write(tmp_path, BASE + '[costs]\n0 = "max(x1,"\n' + QUAD.split("\n", 1)[1])
    res = subprocess.run([sys.executable, "-m", "rescon.cli", "rmdo", str(p), "--json"],
                         capture_output=True, text=True, timeout=120, check=False)
    assert res.returncode == 2 and res.stdout == "" and "Traceback" not in res.stderr
    assert res.stderr.count("\n") == 1 and "position" in res.stderr


# ---------------------------------------------------------------- rescon redundancy

REDUNDANCY_KEYS = {"holds", "exact", "r", "N", "gap", "unbounded", "witness", "seconds",
                   "unbounded_agents", "tolerance"}


def test_redundancy_violation_with_certificate(capsys, tmp_path):
    p = write(tmp_path, 'd = 2\n[costs]\n1 = "(x1 - 1)^2 + x2^2"\n2 = "x1^2 + x2^2"\n'
              '3 = "(x1 + 1)^2 + x2^2"\n')
    cert = tmp_path / "c" / "cert.json"
    out = run_json(["redundancy", p, "--r", 1, "--certificate", cert], capsys)
    assert set(out) == REDUNDANCY_KEYS
    assert (out["holds"], out["exact"], out["r"], out["N"]) == (False, True, 1, 3)
    assert out["gap"] > 0 and out["tolerance"] is None
    assert len(out["witness"]["subsets"]) == 2
    code, _, err = run(["check", cert], capsys)
    assert code == 0, err


def test_redundancy_examples(capsys, tmp_path):
    out = run_json(["redundancy", EXAMPLES / "rmdo_quadratic.toml", "--r", 2], capsys)
    assert (out["holds"], out["exact"], out["N"], out["gap"]) == (True, True, 19, 0.0)
    code, out, err = run(["redundancy", EXAMPLES / "paper_rmdo.toml", "--r", 2], capsys)
    assert code == 0, err
    assert "N = 10 costs in d = 2" in out and "agents [6]" in out


def test_redundancy_infinite_gap_is_null(capsys, tmp_path):
    """A subset with no minimiser (max(x1, x2) alone) against a bounded whole set: the
    gap is infinite, written as null (the output stays strict JSON)."""
    p = write(tmp_path, '[costs]\n1 = "max(x1, x2)"\n2 = "x1^2 + x2^2"\n')
    out = run_json(["redundancy", p, "--r", 1], capsys)
    assert out["holds"] is False and out["gap"] is None
    assert out["unbounded"] == [[1]] and out["unbounded_agents"] == [1]


def test_redundancy_bad_input(capsys, tmp_path):
    p = write(tmp_path, '[costs]\n1 = "x1^2"\n2 = "x1^2"\n')
    assert_error(["redundancy", p, "--r", 2], capsys, "r must be", "N = 2")
    assert_error(["redundancy", write(tmp_path, "d = 1\n", "e.toml"), "--r", 0], capsys,
                 "needs a [costs] table")
    assert_error(["redundancy", write(tmp_path, '[costs]\n1 = "x1^"\n', "x.toml"), "--r", 0],
                 capsys, "agent 1", "position 3")
    assert_error(["redundancy", p, "--r", 0, "--certificate", tmp_path], capsys,
                 "--certificate", "is a directory")
    code, out, err = run(["redundancy", p], capsys)  # --r is required
    assert code == 2 and "--r" in err and out == ""


@pytest.mark.parametrize("argv", [
    ["rmdo", EXAMPLES / "paper_rmdo.toml", "--json"],
    ["redundancy", EXAMPLES / "paper_rmdo.toml", "--r", "2", "--json"],
])
def test_subprocess_stdout_is_one_json_object(argv):
    """In a fresh process (solver banners are written at the C level, past capsys):
    stdout is exactly one JSON object."""
    res = subprocess.run([sys.executable, "-m", "rescon.cli", *map(str, argv)],
                         capture_output=True, text=True, timeout=300, check=False)
    assert res.returncode == 0, res.stderr
    lines = res.stdout.splitlines()
    assert len(lines) == 1 and isinstance(json.loads(lines[0]), dict), res.stdout


def test_unbounded_costs_null_optimum(capsys, tmp_path):
    """Σ f_i unbounded below (affine costs): X* empty, reported as nulls (F* = -inf is
    not JSON), the run still goes ahead; the text output says why."""
    costs = "".join(f'{i} = "x1 + {i}*x2"\n' for i in range(5))
    p = write(tmp_path, BASE + "[costs]\n" + costs + '[step_size]\nkind = "constant"\n'
              "value = 0.01\n")
    out = run_json(["rmdo", p], capsys)
    opt = out["optimum"]
    assert opt["exact"] is True and opt["point"] is None and opt["value"] is None
    assert "unbounded" in opt["reason"]
    assert out["final_distance_to_optimum"] is None and out["final_gap"] is None
    code, text, _ = run(["rmdo", p], capsys)
    assert code == 0 and "X* not known" in text and "unbounded" in text
