"""V37: a hostile review of the public contract (DESIGN.md "Contract" sections, README).

Attacked: every CLI subcommand as a user types it — ``--json`` is one JSON object with
the documented keys and JSON-only values (no NaN / Infinity tokens), nothing else on
fd 1; exit codes and one-line errors for missing files, directories, empty files,
BOM / CRLF / tabs / trailing commas, non-UTF-8 bytes, 1e400 / nan / inf / -0 as text,
bad --F / --r / --s / --time-limit / --workers, unwritable --certificate, --out that is
a file; label rules of edge lists; ``rescon check`` on unreadable input. The Python API:
frozen results, JSON-ready certificates (``allow_nan=False``) the checker accepts,
kernel points identical on every registered backend with nothing on fd 1, and bad
arguments raising rescon's one-line InputError (not a numpy / builtins error from deep
inside). The README's console blocks that tests/test_readme.py does not run.

Bugs found are ``xfail(strict=True)`` tests named after what should hold.
"""

from __future__ import annotations

import dataclasses
import json
import os
import re
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon.cli import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
PAPER_GRAPH = EXAMPLES / "graphs" / "paper_example.edgelist"
RMDO_TOML = EXAMPLES / "scenarios" / "rmdo_quadratic.toml"
RING_TOML = EXAMPLES / "scenarios" / "ring_attack.toml"
SQUARE = "0,0\n4,0\n4,4\n0,4\n1,3\n"  # README §2: Ψ(X, 1) is the segment [1,3]-[2,2]


def _no_constant(token: str) -> None:
    raise AssertionError(f"{token} is not JSON")


def run(argv, capfd) -> tuple[int, str, str]:
    """The CLI in-process; stdout and stderr at the file-descriptor level."""
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse
        code = exc.code
    out, err = capfd.readouterr()
    return code, out, err


def one_object(code: int, out: str, err: str) -> dict:
    """Exit 0 and exactly one JSON object (strict JSON: no NaN / Infinity) on stdout."""
    assert code == 0, err
    lines = out.splitlines()
    assert len(lines) == 1, out
    data = json.loads(lines[0], parse_constant=_no_constant)
    assert isinstance(data, dict)
    return data


def clean_error(code: int, out: str, err: str, status: int = 2) -> str:
    """Exit ``status``, nothing on stdout, one line on stderr, no traceback."""
    assert code == status, (code, out, err)
    assert out == "", out
    assert "Traceback" not in err, err
    assert len(err.strip("\n").splitlines()) == 1, err
    return err


def _python(code: str, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                          text=True, timeout=timeout, check=False, cwd=ROOT)


# --------------------------------------------------------------------------- CLI: kernel


def test_kernel_reads_bom_crlf_header_tabs_and_minus_zero_as_the_plain_file(tmp_path, capfd):
    plain = tmp_path / "plain.csv"
    plain.write_text(SQUARE)
    ref = one_object(*run(["kernel", plain, "--F", 1, "--json"], capfd))
    variants = {
        "bom_crlf_header.csv": b"\xef\xbb\xbfx,y\r\n" + SQUARE.replace("\n", "\r\n").encode(),
        "tabs.txt": SQUARE.replace(",", "\t").encode(),
        "minus_zero.csv": SQUARE.replace("0,0", "-0,-0.0", 1).encode(),
    }
    for name, content in variants.items():
        p = tmp_path / name
        p.write_bytes(content)
        data = one_object(*run(["kernel", p, "--F", 1, "--json"], capfd))
        for key in ("n", "d", "F", "empty", "dim", "vertices", "point"):
            assert data[key] == ref[key], (name, key)
    assert ref["vertices"] == [[1.0, 3.0], [2.0, 2.0]] and ref["point"] == [1.8, 2.2]
    assert set(ref) == {"n", "d", "F", "empty", "dim", "vertices", "A", "b", "point", "seconds"}


@pytest.mark.parametrize("content", [
    b"0,0\n1e400,0\n4,4\n0,4\n", b"0,0\nnan,0\n4,4\n0,4\n", b"0,0\n-inf,0\n4,4\n0,4\n",
    b"0,0,\n4,0,\n4,4,\n", b"0,0\n4\n4,4\n", b"0 1\n\xff\xfe 1\n", b"",
], ids=["1e400", "nan", "-inf", "trailing-comma", "ragged", "not-utf8", "empty"])
def test_kernel_bad_point_files_are_one_line_errors(tmp_path, capfd, content):
    p = tmp_path / "pts.csv"
    p.write_bytes(content)
    err = clean_error(*run(["kernel", p, "--F", 1, "--json"], capfd))
    assert "pts.csv" in err


@pytest.mark.parametrize("F", ["-1", "1.5", "1e400", "5", "x"])
def test_kernel_bad_F_is_a_one_line_error(tmp_path, capfd, F):
    p = tmp_path / "pts.csv"
    p.write_text(SQUARE)
    clean_error(*run(["kernel", p, "--F", F, "--json"], capfd))


def test_kernel_empty_and_one_point_json(tmp_path, capfd):
    tri = tmp_path / "tri.csv"
    tri.write_text("0,0\n1,0\n0,1\n")
    data = one_object(*run(["kernel", tri, "--F", 1, "--json"], capfd))
    assert (data["empty"], data["dim"], data["point"], data["vertices"]) == (True, -1, None, [])
    one = tmp_path / "one.csv"
    one.write_text("5\n")
    data = one_object(*run(["kernel", one, "--F", 0, "--json"], capfd))
    assert (data["dim"], data["vertices"], data["point"]) == (0, [[5.0]], [5.0])


# --------------------------------------------------------------------------- CLI: robustness


@pytest.mark.parametrize("args", [
    ["--r", "1e400"], ["--workers", "-1"], ["--workers", "abc"], ["--scheduler", ""],
    ["--workers", "1", "--scheduler", "tcp://127.0.0.1:1"], ["--bogus"],
    ["--certificate", "{dir}"],
], ids=["r-1e400", "workers-neg", "workers-text", "scheduler-empty", "both", "unknown",
        "certificate-dir"])
def test_robustness_bad_flags_are_one_line_errors(tmp_path, capfd, args):
    g = tmp_path / "g.txt"
    g.write_text("0 1\n1 0\n")
    args = [a.replace("{dir}", str(tmp_path)) for a in args]
    clean_error(*run(["robustness", g, *args, "--json"], capfd))


@pytest.mark.parametrize("label, integer", [
    ("+1", False), ("-0", False), ("1_000", False), ("\u0661", False), ("01", False),
    ("-3", True),
])
def test_edge_list_labels_are_integers_only_as_python_writes_them(tmp_path, capfd, label,
                                                                   integer):
    """README: labels are integers when every label is written as Python writes an
    integer, else names spelled as given (so ``+1`` and ``1`` are two nodes)."""
    g = tmp_path / "g.txt"
    g.write_text(f"{label} 2\n1 3\n2 3\n", encoding="utf-8")
    data = one_object(*run(["robustness", g, "--json"], capfd))
    assert data["n"] == 4  # "+1" and "1" are two nodes
    labels = data["witness"]["S1"] + data["witness"]["S2"]
    assert all(isinstance(v, int) is integer for v in labels), labels


def test_huge_r_and_r_zero_certificates_are_valid(tmp_path, capfd):
    g = tmp_path / "g.txt"
    g.write_text("0 1\n1 0\n")
    for r, robust in ((10**26, False), (0, True)):
        cert = tmp_path / f"c{r}.json"
        data = one_object(*run(["robustness", g, "--r", r, "--certificate", cert, "--json"],
                               capfd))
        assert (data["r"], data["r_robust"]) == (r, robust)
        assert run(["check", cert], capfd)[:2] == (0, "valid\n")


def test_single_node_and_self_loop_only_graphs_are_one_line_errors(tmp_path, capfd):
    for text in ("0\n", "0 0\n"):
        g = tmp_path / "g.txt"
        g.write_text(text)
        clean_error(*run(["robustness", g, "--json"], capfd))


def test_readme_robustness_console_block_runs_as_shown():
    """Fixed (was a bug: the README's block said 'proof: construction', 'method: bounds'
    — from before seeds of all n nodes were left to the search itself). README "Command
    line": the first console block, run in a fresh process."""
    text = (ROOT / "README.md").read_text()
    block = re.search(r"```console\n\$ rescon robustness examples/graphs/paper_example"
                      r"\.edgelist\n(.*?)```", text, re.S)
    assert block is not None
    expected = block.group(1).splitlines()
    proc = subprocess.run([sys.executable, "-m", "rescon", "robustness",
                           "examples/graphs/paper_example.edgelist"], cwd=ROOT,
                          capture_output=True, text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    got = proc.stdout.splitlines()
    assert got[:3] == expected[:3]
    assert got[3].split(",")[0] == expected[3].split(",")[0]


def test_readme_kernel_console_block_runs_as_shown(tmp_path, capfd):
    text = (ROOT / "README.md").read_text()
    block = re.search(r"```console\n\$ rescon kernel (\S+) --F 2 .*?\n(.*?)\$ rescon check",
                      text, re.S)
    assert block is not None
    expected = block.group(2).splitlines()
    cert = tmp_path / "k.json"
    code, out, _ = run(["kernel", ROOT / block.group(1), "--F", 2, "--certificate", cert],
                       capfd)
    assert code == 0 and out.splitlines()[:2] == expected[:2]
    assert run(["check", cert], capfd)[:2] == (0, "valid\n")


# --------------------------------------------------------------------------- CLI: check


@pytest.mark.parametrize("what", ["missing", "directory", "array", "not-utf8"])
def test_check_unreadable_inputs_exit_2_and_json_says_so(tmp_path, capfd, what):
    p = {"missing": tmp_path / "nope.json", "directory": tmp_path}.get(what, tmp_path / "c.json")
    if what == "array":
        p.write_text("[]")
    elif what == "not-utf8":
        p.write_bytes(b"\xff\xfe{}")
    err = clean_error(*run(["check", p], capfd))
    assert err.startswith("unreadable:")
    code, out, err = run(["check", p, "--json"], capfd)
    assert code == 2 and "Traceback" not in err
    data = json.loads(out, parse_constant=_no_constant)
    assert (data["verdict"], data["valid"], data["readable"]) == ("unreadable", False, False)


# --------------------------------------------------------------------------- CLI: runs


def test_rmdo_json_with_one_monitor_has_every_documented_key(capfd):
    data = one_object(*run(["rmdo", RMDO_TOML, "--json", "--metrics", "spread", "-q"], capfd))
    assert {"steps", "N", "d", "F", "algorithm", "policy", "final_diameter", "max_validity",
            "assumptions_violated", "seconds"} <= set(data)
    assert {"final_cost", "optimum", "final_distance_to_optimum", "final_gap",
            "step_size"} <= set(data)
    assert data["final_diameter"] is None and data["max_validity"] is None
    assert data["optimum"]["point"] == [2.0, -1.0] and data["optimum"]["exact"] is True
    assert isinstance(data["final_gap"], float) and data["final_gap"] >= 0


def test_redundancy_json_keys_types_and_r_at_least_N(tmp_path, capfd):
    c = tmp_path / "c.toml"
    c.write_text('[costs]\r\n0 = "(x1-1)^2 + x2^2"\r\n1 = "(x1-1)^2 + 2*x2^2"\r\n'
                 '2 = "abs(x1-1) + abs(x2)"\r\n')
    data = one_object(*run(["redundancy", c, "--r", 1, "--json"], capfd))
    assert set(data) == {"holds", "exact", "r", "N", "gap", "unbounded", "witness", "seconds",
                         "unbounded_agents", "tolerance"}
    assert (data["holds"], data["exact"], data["N"], data["gap"]) == (True, True, 3, 0.0)
    clean_error(*run(["redundancy", c, "--r", 3, "--json"], capfd))


def test_simulate_out_that_is_a_file_is_refused_before_running(tmp_path, capfd):
    f = tmp_path / "taken"
    f.write_text("x")
    err = clean_error(*run(["simulate", RING_TOML, "--out", f, "--json"], capfd))
    assert "--out" in err and f.read_text() == "x"


def test_unwritable_certificate_is_refused_before_any_work(tmp_path, capfd, monkeypatch):
    """Fixed (was a bug: an unwritable --certificate was found only after the computation,
    as a bare '[Errno 13] ...' not naming the option)."""
    target = Path("/sys/rescon_v37_certificate.json")
    if not Path("/sys").is_dir() or os.access("/sys", os.W_OK) and _writable(target):
        pytest.skip("needs an unwritable location (/sys on Linux)")
    import rescon.graphs.robustness as rob

    ran = []

    def fake(*args, **kwargs):
        ran.append(True)
        raise rescon.RESCONError("the search ran")

    monkeypatch.setattr(rob, "robustness", fake)
    g = tmp_path / "g.txt"
    g.write_text("0 1\n1 0\n")
    err = clean_error(*run(["robustness", g, "--certificate", target], capfd))
    assert not ran and "--certificate" in err


def _writable(p: Path) -> bool:
    try:
        p.write_text("")
    except OSError:
        return False
    p.unlink()
    return True


# --------------------------------------------------------------------------- API


def test_results_are_frozen_and_certificates_json_ready_and_valid():
    G = nx.complete_graph(5).to_directed()
    results = [rescon.robustness(G), rescon.is_r_robust(G, 2), rescon.is_rs_robust(G, 2, 2),
               rescon.safe_kernel([[0, 0], [1, 0], [0, 1], [1, 1]], 1),
               rescon.safe_kernel([[0, 0], [1, 0], [0, 1]], 1),
               rescon.check_redundancy({0: "x1^2", 1: "(x1-1)^2", 2: "x1^2"}, 1),
               rescon.tverberg_partition([[0, 0], [4, 0], [0, 4], [4, 4], [2, 2]], 2)]
    for res in results:
        first = dataclasses.fields(res)[0].name
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(res, first, None)
        json.dumps(res.certificate, allow_nan=False)
        assert rescon.check_certificate(res.certificate).verdict == "valid", type(res)


def test_kernel_certificates_at_extreme_magnitudes_are_json_and_valid():
    for X in ([[1e308, 0], [-1e308, 0], [0, 1e308], [0, -1e308], [1e307, 1e307]],
              [[5e-324, 0], [0, 5e-324], [0, 0], [5e-324, 5e-324], [1e-320, 2e-320]]):
        for F in (0, 1):
            K = rescon.safe_kernel(X, F)
            x, cert = rescon.kernel_point(X, F)
            for c in (K.certificate, cert):
                json.dumps(c, allow_nan=False)
                assert rescon.check_certificate(c).verdict == "valid"


@pytest.mark.slow
def test_kernel_point_is_the_same_on_every_backend_and_silent_on_fd1():
    """DESIGN: "project" makes trajectories independent of the solver; no library call
    writes to stdout (CasADi's qpOASES banner goes to stderr)."""
    proc = _python("""
        import json, numpy as np, rescon
        X = np.random.default_rng(3).normal(size=(10, 3))
        pts = {}
        for b in ["auto", "highs", "clarabel", "proxsuite", "cvxpy", "casadi"]:
            x, c = rescon.kernel_point(X, 2, backend=b)
            assert rescon.check_certificate(c).verdict == "valid", b
            pts[b] = x.tolist()
        import sys
        sys.stderr.write("RESULT " + json.dumps(pts) + "\\n")
    """)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout == ""
    pts = json.loads(proc.stderr.split("RESULT ")[-1])
    assert all(np.array_equal(p, pts["auto"]) for p in pts.values()), pts


@pytest.mark.slow
def test_numerical_redundancy_and_cvxpy_rmdo_are_silent_on_fd1():
    proc = _python("""
        import warnings; warnings.simplefilter("ignore")
        import numpy as np, cvxpy as cp, rescon
        costs = {i: f"abs(x1 - {i}) + (x2 - {i % 2})^2 + huber(x1 + x2, 0.5)" for i in range(6)}
        assert rescon.check_redundancy(costs, 1).exact is False
        x = cp.Variable(2)
        c = {i: rescon.cost(cp.sum_squares(x - np.array([i, 0.0])) + cp.norm1(x), x=x)
             for i in range(5)}
        rescon.check_redundancy(c, 1)
        sc = rescon.Scenario.paper_example(steps=3)
        rescon.rmdo(sc, {i: rescon.cost(cp.sum_squares(x - np.array([1.0, 2.0])), x=x)
                         for i in sc.benign})
    """)
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout == ""


def test_trajectory_to_json_is_strict_json_with_unknown_optimum_and_one_monitor():
    sc = rescon.Scenario.paper_example(steps=4)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        runs = [rescon.simulate(sc, metrics=["spread"]),
                rescon.rmdo(sc, {i: "x1 + abs(x2)" for i in sc.benign})]  # unbounded: no X*
    for t in runs:
        s = json.dumps(t.to_json(), allow_nan=False)
        json.loads(s, parse_constant=_no_constant)
        with pytest.raises(dataclasses.FrozenInstanceError):
            t.states = None


G5 = nx.complete_graph(5).to_directed()
SQ = [[0, 0], [4, 0], [4, 4], [0, 4], [1, 3]]
BAD_CALLS = {
    "robustness time_limit=True": lambda: rescon.robustness(G5, time_limit=True),
    "robustness time_limit='5'": lambda: rescon.robustness(G5, time_limit="5"),
    "robustness workers=1.5": lambda: rescon.robustness(G5, workers=1.5),
    "is_r_robust r=True": lambda: rescon.is_r_robust(G5, True),
    "is_rs_robust s=0": lambda: rescon.is_rs_robust(G5, 2, 0),
    "robustness of a list": lambda: rescon.robustness([(0, 1), (1, 0)]),
    "safe_kernel F=1.0": lambda: rescon.safe_kernel(SQ, 1.0),
    "safe_kernel bool points": lambda: rescon.safe_kernel([[True, False], [False, True]], 0),
    "safe_kernel complex points": lambda: rescon.safe_kernel([[1j, 0], [1, 1]], 0),
    "safe_kernel ragged": lambda: rescon.safe_kernel([[0, 0], [1]], 0),
    "safe_kernel d=0": lambda: rescon.safe_kernel(np.zeros((3, 0)), 0),
    "contains wrong d": lambda: rescon.safe_kernel(SQ, 1).contains([1, 2, 3]),
    "contains tol<0": lambda: rescon.safe_kernel(SQ, 1).contains([1.5, 2.5], tol=-1),
    "point method": lambda: rescon.safe_kernel(SQ, 1).point("foo"),
    "kernel_points on_empty": lambda: rescon.kernel_points([SQ], 1, on_empty="foo"),
    "tverberg parts=0": lambda: rescon.tverberg_partition(SQ, 0),
    "tverberg time_limit=0": lambda: rescon.tverberg_partition(SQ, 2, time_limit=0),
    "check_subgradient samples=0": lambda: rescon.check_subgradient(
        rescon.cost("x1^2"), [[0.0]], samples=0),
    "paper_costs f7=None": lambda: rescon.optim.paper_costs(f7=None),
    "cost huber M=0": lambda: rescon.cost("huber(x1, 0)"),
    "cost unicode": lambda: rescon.cost("x\u2081^2"),
    "rmdo step_size=True": lambda: rescon.rmdo(rescon.Scenario.paper_example(steps=1),
                                               rescon.optim.paper_costs(), step_size=True),
    "rmdo beta_k nan": lambda: rescon.rmdo(rescon.Scenario.paper_example(steps=1),
                                           rescon.optim.paper_costs(),
                                           step_size=lambda k: float("nan")),
    "rmdo scenario None": lambda: rescon.rmdo(None, {}),
    "Scenario residual inf": lambda: rescon.simulate(
        rescon.Scenario.paper_example(steps=1, residual=lambda t: float("inf"))),
    "check_redundancy r=True": lambda: rescon.check_redundancy({0: "x1^2", 1: "x1^2"}, True),
}


@pytest.mark.parametrize("call", list(BAD_CALLS))
def test_bad_api_arguments_raise_one_line_input_errors(call):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(rescon.InputError) as exc:
            BAD_CALLS[call]()
    assert "\n" not in str(exc.value)


def test_scenario_files_naming_a_directory_are_input_errors(tmp_path):
    (tmp_path / "sub").mkdir()
    base = "[scenario]\nF = 0\nsteps = 2\n"
    cases = {"graph": base + '[graph]\nedgelist = "sub"\n[initial]\n0 = [0.0]\n',
             "initial": base + '[graph]\nedges = [[0, 1], [1, 0]]\n[initial]\nfile = "sub"\n'}
    for name, text in cases.items():
        p = tmp_path / f"{name}.toml"
        p.write_text(text)
        with pytest.raises(rescon.InputError, match="is a directory"):
            rescon.Scenario.from_toml(p)


# --------------------------------------------------------------------------- API: bugs


def test_from_toml_of_a_directory_is_an_input_error(tmp_path):
    """Fixed (was a bug: IsADirectoryError, read_toml caught FileNotFoundError only)."""
    with pytest.raises(rescon.InputError):
        rescon.Scenario.from_toml(tmp_path)


def test_from_toml_of_a_non_path_is_an_input_error():
    """Fixed (was a bug: a builtins TypeError from Path(None))."""
    with pytest.raises(rescon.InputError):
        rescon.Scenario.from_toml(None)


def test_scenario_file_with_a_bom_reads_like_without(tmp_path):
    """Fixed (was a bug: a BOM-prefixed scenario file was 'malformed TOML'; read_toml now
    reads utf-8-sig like rescon.io)."""
    text = '[scenario]\nF = 0\nsteps = 2\n[graph]\nedges = [[0, 1], [1, 0]]\n' \
           '[initial]\n0 = [0.0]\n1 = [1.0]\n'
    plain, bom = tmp_path / "plain.toml", tmp_path / "bom.toml"
    plain.write_text(text)
    bom.write_bytes(b"\xef\xbb\xbf" + text.encode())
    assert rescon.Scenario.from_toml(bom).to_dict() == rescon.Scenario.from_toml(plain).to_dict()


def test_simulate_of_a_non_scenario_is_an_input_error():
    """Fixed (was a bug: AttributeError from ConsensusMonitor; rmdo checked, simulate not)."""
    with pytest.raises(rescon.InputError):
        rescon.simulate({"scenario": {"paper_example": True}})


def test_progress_takes_true_false_or_none_only():
    """Fixed (was a bug: progress='no' was read by its truth value, a bar forced)."""
    with pytest.raises(rescon.InputError):
        rescon.simulate(rescon.Scenario.paper_example(steps=1), progress="no")


def test_check_subgradient_negative_seed_is_an_input_error():
    """Fixed (was a bug: numpy's 'expected non-negative integer' ValueError)."""
    with pytest.raises(rescon.InputError):
        rescon.check_subgradient(rescon.cost("x1^2"), [[1.0]], seed=-1)


def test_cost_with_a_5000_digit_constant_is_a_clean_error(tmp_path, capfd):
    """Fixed (was a bug: formatting 10^5000 in its own error hit Python's int-string
    limit, a traceback and exit 1)."""
    with pytest.raises(rescon.InputError):
        rescon.cost("1e5000*x1")
    c = tmp_path / "c.toml"
    c.write_text('[costs]\n0 = "1e5000*x1^2"\n1 = "x1^2"\n')
    clean_error(*run(["redundancy", c, "--r", 1, "--json"], capfd))


@pytest.mark.slow
def test_cost_with_a_huge_exponent_is_refused_quickly():
    """Fixed (was a bug: '1e1000000000' built 10**1e9 exactly, no answer in 10 s)."""
    proc = _python("""
        import rescon
        try:
            rescon.cost("1e1000000000*x1")
        except rescon.InputError:
            print("refused")
    """, timeout=10)
    assert proc.stdout == "refused\n"


@pytest.mark.parametrize("value", ["no", 0, 1])
def test_undirected_takes_true_or_false_only(value):
    """Fixed (was a bug: undirected='no' was read by its truth value, a directed 3-cycle
    answered as undirected: rho 2 instead of 1)."""
    D = nx.DiGraph([(0, 1), (1, 2), (2, 0)])
    assert rescon.robustness(D).r_max == 1 and rescon.robustness(D, undirected=True).r_max == 2
    for call in (lambda: rescon.robustness(D, undirected=value),
                 lambda: rescon.is_r_robust(D, 2, undirected=value),
                 lambda: rescon.max_s(D, 1, undirected=value)):
        with pytest.raises(rescon.InputError, match="undirected"):
            call()
