"""Tests for the ``rescon`` command line (DESIGN.md, "Contract: command line").

Most tests call ``rescon.cli.main(argv)`` in-process (capturing stdout/stderr with
capsys); a few run ``python -m rescon.cli`` in a subprocess to see exactly what a user
sees (exit status, no traceback). Results are compared against the brute-force oracles
in tests/conftest.py.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import networkx as nx
import pytest
from conftest import fast_oracle, oracle, pair_violates

import rescon
from rescon.cli import main
from rescon.io import read_graph

ROOT = Path(__file__).parent.parent
PAPER = ROOT / "examples" / "graphs" / "paper_example.edgelist"

ROBUSTNESS_KEYS = {"n", "r_max", "s_max", "exact", "witness", "method", "seconds"}
R_KEYS = {"r", "r_robust", "s_max", "witness"}
RS_KEYS = {"r", "s", "holds", "witness"}


def run(argv, capsys) -> tuple[int, str, str]:
    """Run the CLI in-process: (exit status, stdout, stderr)."""
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse (--help, usage errors)
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def run_json(argv, capsys) -> dict:
    code, out, err = run(list(argv) + ["--json"], capsys)
    assert code == 0, err
    lines = out.strip().splitlines()
    assert len(lines) == 1, out  # one JSON object on stdout
    data = json.loads(lines[0])
    assert isinstance(data, dict)
    return data


def run_sub(args, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "rescon.cli", *map(str, args)],
                          capture_output=True, text=True, timeout=120, **kw)


def assert_clean_error(code, out, err, *, status=2):
    assert code == status, (code, out, err)
    assert "Traceback" not in err and "Traceback" not in out
    lines = err.strip("\n").splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("rescon: error:"), err


def write_edgelist(path: Path, G: nx.DiGraph) -> Path:
    lines = ["# test graph"] + [f"{v}" for v in G.nodes()] + [f"{u} {v}" for u, v in G.edges()]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def paper_graph():
    return read_graph(PAPER)


@pytest.fixture(scope="module")
def paper_oracle(paper_graph):
    return fast_oracle(paper_graph)


# --------------------------------------------------------------------------- #
# the paper's example graph
# --------------------------------------------------------------------------- #


def test_paper_example_robustness_json(capsys, paper_graph, paper_oracle):
    rho, ss = paper_oracle
    assert rho == 5  # the comment at the top of the file
    data = run_json(["robustness", PAPER], capsys)
    assert set(data) == ROBUSTNESS_KEYS
    assert data["n"] == 12
    assert data["r_max"] == 5
    assert data["s_max"] == ss[5]
    assert data["exact"] is True
    assert set(data["witness"]) == {"S1", "S2"}
    assert pair_violates(paper_graph, data["witness"]["S1"], data["witness"]["S2"], 6, 1)
    assert isinstance(data["method"], str) and data["method"]
    assert isinstance(data["seconds"], (int, float)) and data["seconds"] >= 0


def test_paper_example_r(capsys, paper_graph, paper_oracle):
    rho, ss = paper_oracle
    data = run_json(["robustness", PAPER, "--r", 5], capsys)
    assert set(data) == R_KEYS
    assert data == {"r": 5, "r_robust": True, "s_max": ss[5], "witness": None}
    data = run_json(["robustness", PAPER, "--r", 6], capsys)
    assert set(data) == R_KEYS
    assert (data["r"], data["r_robust"], data["s_max"]) == (6, False, 0)
    assert pair_violates(paper_graph, data["witness"]["S1"], data["witness"]["S2"], 6, 1)
    data = run_json(["robustness", PAPER, "--r", 0], capsys)
    assert (data["r_robust"], data["s_max"]) == (True, 12)


@pytest.mark.parametrize("s", [1, 2, 3, 12])
def test_paper_example_r_s(capsys, paper_graph, paper_oracle, s):
    rho, ss = paper_oracle
    data = run_json(["robustness", PAPER, "--r", 5, "--s", s], capsys)
    assert set(data) == RS_KEYS
    assert (data["r"], data["s"]) == (5, s)
    assert data["holds"] is (s <= ss[5])
    if data["holds"]:
        assert data["witness"] is None
    else:
        assert pair_violates(paper_graph, data["witness"]["S1"], data["witness"]["S2"], 5, s)


def test_paper_example_human_output(capsys):
    code, out, err = run(["robustness", PAPER], capsys)
    assert code == 0 and err == ""
    assert "rho(G) = 5" in out
    code, out, _ = run(["robustness", PAPER, "--r", 6], capsys)
    assert code == 0 and "NOT 6-robust" in out


@pytest.mark.parametrize("method", ["search", "milp", "dp"])
def test_methods_agree(capsys, method, paper_oracle):
    rho, ss = paper_oracle
    data = run_json(["robustness", PAPER, "--method", method], capsys)
    assert (data["r_max"], data["s_max"], data["exact"]) == (5, ss[5], True)


# --------------------------------------------------------------------------- #
# certificates: --certificate and `rescon check`
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("extra", [[], ["--r", "5"], ["--r", "6"], ["--r", "5", "--s", "2"],
                                   ["--r", "4", "--s", "3"]],
                         ids=["robustness", "r5", "r6", "r5s2", "r4s3"])
def test_certificate_written_and_checked(capsys, tmp_path, extra, paper_graph):
    cert_path = tmp_path / "cert.json"
    code, out, err = run(["robustness", PAPER, *extra, "--certificate", cert_path, "--json"],
                         capsys)
    assert code == 0, err
    cert = json.loads(cert_path.read_text())
    assert cert["rescon_certificate"] == 1
    assert cert["graph"]["n"] == 12
    assert rescon.check_certificate(cert).valid
    code, out, err = run(["check", cert_path], capsys)
    assert code == 0, err
    assert out.splitlines()[0] == "valid"


def test_check_tampered_and_unreadable(capsys, tmp_path):
    good = tmp_path / "good.json"
    code, _, err = run(["robustness", PAPER, "--certificate", good], capsys)
    assert code == 0, err
    cert = json.loads(good.read_text())
    # tampered: claim rho = 6
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(dict(cert, r_max=6)))
    code, out, err = run(["check", bad], capsys)
    assert code == 1
    assert err.strip(), "a reason on stderr"
    assert "Traceback" not in err
    # tampered: drop an edge of the certificate graph
    cert2 = json.loads(good.read_text())
    cert2["graph"]["edges"] = cert2["graph"]["edges"][1:]
    bad.write_text(json.dumps(cert2))
    code, _, err = run(["check", bad], capsys)
    H = nx.DiGraph([tuple(e) for e in cert2["graph"]["edges"]])
    H.add_nodes_from(range(12))
    rho, ss = fast_oracle(H)
    claim_true = (rho, ss[rho]) == (cert["r_max"], cert["s_max"])
    # a false claim must be rejected; a true one may still lack a valid proof
    assert code == 1 if not claim_true else code in (0, 1)
    assert "Traceback" not in err
    # unreadable: not JSON, not an object, missing, duplicate keys, NaN
    for name, text in [("nj.json", "not json {"), ("arr.json", "[1, 2]"),
                       ("dup.json", '{"kind": 1, "kind": 2}'),
                       ("nan.json", '{"rescon_certificate": NaN}')]:
        p = tmp_path / name
        p.write_text(text)
        code, out, err = run(["check", p], capsys)
        assert code == 2, (name, err)
        assert "Traceback" not in err and err.strip()
    code, _, err = run(["check", tmp_path / "missing.json"], capsys)
    assert code == 2 and "Traceback" not in err


def test_check_subprocess_exit_codes(tmp_path):
    cert_path = tmp_path / "c.json"
    proc = run_sub(["robustness", PAPER, "--json", "--certificate", cert_path])
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["r_max"] == 5
    assert run_sub(["check", cert_path]).returncode == 0
    cert = json.loads(cert_path.read_text())
    cert["upper_r"]["S1"] = cert["upper_r"]["S1"] + cert["upper_r"]["S2"][:1]  # overlap
    tampered = tmp_path / "t.json"
    tampered.write_text(json.dumps(cert))
    proc = run_sub(["check", tampered])
    assert proc.returncode == 1 and proc.stderr.strip() and "Traceback" not in proc.stderr
    junk = tmp_path / "junk.json"
    junk.write_text("this is not JSON")
    proc = run_sub(["check", junk])
    assert proc.returncode == 2 and "Traceback" not in proc.stderr


def test_check_has_json_option(capsys, tmp_path):
    cert_path = tmp_path / "c.json"
    run(["robustness", PAPER, "--certificate", cert_path], capsys)
    code, out, err = run(["check", cert_path, "--json"], capsys)
    assert code == 0, err
    assert isinstance(json.loads(out), dict)


# --------------------------------------------------------------------------- #
# input formats, direction convention, --undirected
# --------------------------------------------------------------------------- #

# A small digraph with string labels (u -> v: v receives u) whose answer depends on the
# direction: reversing it changes rho.
STR_EDGES = [("a", "b"), ("b", "c"), ("c", "a"), ("a", "d"), ("b", "d"), ("d", "e"),
             ("c", "e"), ("e", "f"), ("d", "f"), ("f", "a"), ("a", "g"), ("e", "g"), ("b", "h")]


def _digraph(edges, nodes=None) -> nx.DiGraph:
    G = nx.DiGraph()
    G.add_nodes_from(nodes or sorted({x for e in edges for x in e}))
    G.add_edges_from(edges)
    return G


def write_graphml(path, G):
    nx.write_graphml(G, path)
    return path


def write_gml(path, G):
    nx.write_gml(G, path, stringizer=str)
    return path


def write_node_link(path, G, key="links"):
    data = {"directed": G.is_directed(), "nodes": [{"id": v} for v in G.nodes()],
            key: [{"source": u, "target": v} for u, v in G.edges()]}
    path.write_text(json.dumps(data))
    return path


def write_csv(path, G, header=True):
    nodes = list(G.nodes())
    rows = []
    if header:
        rows.append(",".join(map(str, nodes)))
    for u in nodes:
        rows.append(",".join("1" if G.has_edge(u, v) else "0" for v in nodes))
    path.write_text("\n".join(rows) + "\n")
    return path


WRITERS = {
    "graphml": write_graphml,
    "gml": write_gml,
    "json": write_node_link,
    "csv": write_csv,
}


def _expect(G):
    o = oracle(G)
    return o.rho, o.s_star_of(o.rho)


@pytest.mark.parametrize("fmt", sorted(WRITERS))
@pytest.mark.parametrize("reverse", [False, True], ids=["forward", "reversed"])
def test_formats_string_labels(capsys, tmp_path, fmt, reverse):
    G = _digraph(STR_EDGES)
    if reverse:
        G = G.reverse(copy=True)
    path = WRITERS[fmt](tmp_path / f"g.{fmt}", G)
    rho, s = _expect(G)
    data = run_json(["robustness", path], capsys)
    assert (data["n"], data["r_max"], data["s_max"]) == (8, rho, s)
    if data["witness"] is not None:
        assert pair_violates(G, data["witness"]["S1"], data["witness"]["S2"], rho + 1, 1)
        assert set(data["witness"]["S1"]) <= set("abcdefgh")


def test_direction_matters_in_fixture():
    forward = _digraph(STR_EDGES)
    assert _expect(forward) == (1, 3)
    assert _expect(forward.reverse(copy=True)) == (0, 8)


@pytest.mark.parametrize("fmt", ["edgelist", "graphml", "gml", "json", "csv", "csv-noheader"])
def test_formats_out_star_vs_in_star(capsys, tmp_path, fmt):
    """u -> v means v receives u in every format: the out-star (centre 0 sends to 1..4)
    is 1-robust; the in-star (leaves send to the centre) is not."""
    out_star = _digraph([(0, i) for i in range(1, 5)], nodes=list(range(5)))
    in_star = out_star.reverse(copy=True)
    for G, rho in ((out_star, 1), (in_star, 0)):
        base = fmt.split("-")[0]
        path = tmp_path / f"star{rho}.{base}"
        if fmt == "edgelist":
            write_edgelist(path, G)
        elif fmt == "csv-noheader":
            write_csv(path, G, header=False)
        else:
            WRITERS[fmt](path, G)
        data = run_json(["robustness", path], capsys)
        assert data["r_max"] == rho, fmt
        assert data["s_max"] == _expect(G)[1]


def test_json_edges_key_and_undirected_file(capsys, tmp_path):
    G = _digraph(STR_EDGES)
    path = write_node_link(tmp_path / "g.json", G, key="edges")
    assert run_json(["robustness", path], capsys)["r_max"] == _expect(G)[0]
    U = nx.Graph(STR_EDGES)
    path = tmp_path / "u.json"
    path.write_text(json.dumps({"directed": False, "nodes": [{"id": v} for v in U],
                                "links": [{"source": a, "target": b} for a, b in U.edges()]}))
    data = run_json(["robustness", path], capsys)
    assert (data["r_max"], data["s_max"]) == _expect(U)
    path = write_graphml(tmp_path / "u.graphml", U)
    assert (run_json(["robustness", path], capsys)["r_max"]) == _expect(U)[0]


def test_undirected_flag(capsys, tmp_path):
    in_star = _digraph([(i, 0) for i in range(1, 5)], nodes=list(range(5)))
    path = write_edgelist(tmp_path / "instar.edgelist", in_star)
    assert run_json(["robustness", path], capsys)["r_max"] == 0
    data = run_json(["robustness", path, "--undirected"], capsys)
    assert (data["r_max"], data["s_max"]) == _expect(nx.star_graph(4))
    G = _digraph(STR_EDGES)
    path = write_graphml(tmp_path / "g.graphml", G)
    data = run_json(["robustness", path, "--undirected"], capsys)
    assert (data["r_max"], data["s_max"]) == _expect(G.to_undirected())
    data = run_json(["robustness", path, "--undirected", "--r", 1, "--s", 2], capsys)
    assert data["holds"] is oracle(G.to_undirected()).holds(1, 2)


def test_edgelist_comments_isolated_nodes_selfloops(capsys, tmp_path):
    path = tmp_path / "g.txt"
    path.write_text("# comment\n1 2  # inline\n2 3\n3 1\n\n3 3\n1 2\n9\n")
    G = nx.DiGraph([(1, 2), (2, 3), (3, 1)])
    G.add_node(9)
    data = run_json(["robustness", path], capsys)
    assert (data["n"], data["r_max"], data["s_max"]) == (4, 0, 4)
    assert pair_violates(G, data["witness"]["S1"], data["witness"]["S2"], 1, 1)
    assert 9 in data["witness"]["S1"] + data["witness"]["S2"]


def test_time_limit_reports_bounds(capsys, tmp_path):
    G = nx.gnp_random_graph(40, 0.5, directed=True, seed=1)
    path = write_edgelist(tmp_path / "dense.edgelist", G)
    cert_path = tmp_path / "c.json"
    data = run_json(["robustness", path, "--time-limit", "0.5", "--certificate", cert_path],
                    capsys)
    assert ROBUSTNESS_KEYS <= set(data)
    if data["exact"]:
        assert set(data) == ROBUSTNESS_KEYS
    elif data["r_lower"] < data["r_upper"]:
        assert set(data) == ROBUSTNESS_KEYS | {"r_lower", "r_upper"}
    else:
        assert set(data) == ROBUSTNESS_KEYS | {"r_lower", "r_upper", "s_lower", "s_upper",
                                               "s_witness"}
    cert = json.loads(cert_path.read_text())
    assert rescon.check_certificate(cert).valid


def test_time_limit_reports_s_bounds(capsys, tmp_path):
    """rho settled by construction, s* cut by the time limit: bounds on s* are printed."""
    from rescon.graphs.generators import circulant

    G = circulant(64, 6).to_directed()
    path = write_edgelist(tmp_path / "circ.edgelist", G)
    cert_path = tmp_path / "c.json"
    data = run_json(["robustness", path, "--time-limit", "0.3", "--certificate", cert_path],
                    capsys)
    assert set(data) == ROBUSTNESS_KEYS | {"r_lower", "r_upper", "s_lower", "s_upper",
                                           "s_witness"}
    assert (data["r_lower"], data["r_upper"], data["exact"]) == (6, 6, False)
    assert 1 <= data["s_lower"] <= data["s_upper"] < 64
    w = data["s_witness"]
    assert pair_violates(G, w["S1"], w["S2"], 6, data["s_upper"] + 1)
    assert rescon.check_certificate(json.loads(cert_path.read_text())).valid
    assert main(["robustness", str(path), "--time-limit", "0.3"]) == 0
    assert "<= s*(6) <=" in capsys.readouterr().out


# --------------------------------------------------------------------------- #
# bad input: exit 2, one line on stderr, no traceback
# --------------------------------------------------------------------------- #


def _bad_files(tmp_path: Path) -> dict[str, Path]:
    files = {
        "malformed.edgelist": "1 2\n1 2 3\n",
        "float.edgelist": "1 2\n2 3.5\n",
        "empty.edgelist": "",
        "comments.edgelist": "# nothing\n\n",
        "one.edgelist": "1\n",
        "selfloop_only.edgelist": "4 4\n",
        "ragged.csv": "0,1,0\n1,0\n0,1,0\n",
        "nonsquare.csv": "0,1,0\n1,0,1\n",
        "negative.csv": "0,-1\n1,0\n",
        "bad.json": "{not json",
        "nolinks.json": '{"nodes": [{"id": 1}]}',
        "unknown_node.json": '{"nodes": [{"id": 1}], "links": [{"source": 1, "target": 2}]}',
        "bad.graphml": "<graphml><graph",
        "bad.gml": "graph [ node [ id 0 ",
    }
    out = {}
    for name, text in files.items():
        p = tmp_path / name
        p.write_text(text)
        out[name] = p
    return out


@pytest.mark.parametrize("name", ["malformed.edgelist", "float.edgelist",
                                  "empty.edgelist", "comments.edgelist", "one.edgelist",
                                  "selfloop_only.edgelist", "ragged.csv", "nonsquare.csv",
                                  "negative.csv", "bad.json", "nolinks.json",
                                  "unknown_node.json", "bad.graphml", "bad.gml"])
def test_bad_graph_files(capsys, tmp_path, name):
    path = _bad_files(tmp_path)[name]
    code, out, err = run(["robustness", path, "--json"], capsys)
    assert_clean_error(code, out, err)
    assert out == ""


def test_bad_file_messages_name_file_and_line(capsys, tmp_path):
    files = _bad_files(tmp_path)
    code, out, err = run(["robustness", files["float.edgelist"]], capsys)
    assert_clean_error(code, out, err)
    assert "float.edgelist:2" in err and "'3.5' is a number but not an integer" in err
    code, out, err = run(["robustness", files["malformed.edgelist"]], capsys)
    assert "malformed.edgelist:2" in err


@pytest.mark.parametrize("args", [
    ["robustness", "{missing}"],
    ["robustness", "{dir}"],
    ["robustness", "{paper}", "--r", "-1"],
    ["robustness", "{paper}", "--r", "1.5"],
    ["robustness", "{paper}", "--r", "x"],
    ["robustness", "{paper}", "--s", "2"],
    ["robustness", "{paper}", "--r", "1", "--s", "13"],
    ["robustness", "{paper}", "--r", "1", "--s", "0"],
    ["robustness", "{paper}", "--r", "1", "--s", "-2"],
    ["robustness", "{paper}", "--time-limit", "0"],
    ["robustness", "{paper}", "--time-limit", "-1"],
    ["robustness", "{paper}", "--time-limit", "nan"],
    ["robustness", "{paper}", "--time-limit", "inf"],
    ["robustness", "{paper}", "--time-limit", "abc"],
    ["robustness", "{paper}", "--method", "foo"],
    ["robustness"],
    ["bogus"],
    [],
], ids=["missing", "directory", "r-neg", "r-float", "r-text", "s-without-r", "s-gt-n", "s-0",
        "s-neg", "tl-0", "tl-neg", "tl-nan", "tl-inf", "tl-text", "method", "no-graph",
        "unknown-cmd", "no-cmd"])
def test_bad_arguments(capsys, tmp_path, args):
    subs = {"{missing}": str(tmp_path / "nope.edgelist"), "{dir}": str(tmp_path),
            "{paper}": str(PAPER)}
    argv = [subs.get(a, a) for a in args]
    for tail in ([], ["--json"]) if args[:1] == ["robustness"] else ([],):
        code, out, err = run(argv + tail, capsys)
        assert_clean_error(code, out, err)
        assert out == ""


def test_bad_input_subprocess(tmp_path):
    """The real process: exit 2, one line on stderr, no traceback."""
    bad = tmp_path / "bad.edgelist"
    bad.write_text("1 2\n2 0.5\n")
    for args in (["robustness", bad, "--json"], ["robustness", tmp_path / "missing"],
                 ["robustness", PAPER, "--r", "1", "--s", "99"],
                 ["robustness", PAPER, "--time-limit", "0"]):
        proc = run_sub(args)
        assert_clean_error(proc.returncode, proc.stdout, proc.stderr)
        assert proc.stdout == ""


def test_help(capsys):
    code, out, err = run(["--help"], capsys)
    assert code == 0
    assert "robustness" in out and "check" in out
    code, out, err = run(["robustness", "--help"], capsys)
    assert code == 0
    for opt in ("--r", "--s", "--undirected", "--time-limit", "--certificate", "--json"):
        assert opt in out
    code, out, err = run(["check", "--help"], capsys)
    assert code == 0


def test_help_subprocess():
    for args in (["--help"], ["robustness", "--help"]):
        proc = run_sub(args)
        assert proc.returncode == 0, proc.stderr
        assert "usage" in proc.stdout.lower() and proc.stderr == ""



def test_version_and_python_m_rescon():
    import rescon

    proc = run_sub(["--version"])
    assert proc.returncode == 0 and proc.stdout.strip() == f"rescon {rescon.__version__}"
    proc = subprocess.run([sys.executable, "-m", "rescon", "--version"], capture_output=True,
                          text=True, timeout=120)
    assert proc.returncode == 0 and proc.stdout.strip() == f"rescon {rescon.__version__}"

# --------------------------------------------------------------------------- #
# time-limited answers with --r (deterministic: the API's undecided answers are
# simulated with monkeypatch, as a dense graph may or may not finish in time)
# --------------------------------------------------------------------------- #


def test_undecided_r_does_not_report_s_max_zero(capsys, monkeypatch):
    import rescon.graphs.robustness as rb

    def undecided(G, r, s, **kw):
        return rb.RobustnessCheck(r, s, None, None, None, None, "search", 0.0)

    monkeypatch.setattr(rb, "is_rs_robust", undecided)
    data = run_json(["robustness", PAPER, "--r", 5, "--time-limit", 1], capsys)
    assert data["r_robust"] is None
    assert data["s_max"] is None, data


def test_undecided_r_s_reports_null(capsys, monkeypatch):
    import rescon.graphs.robustness as rb

    def undecided(G, r, s, **kw):
        return rb.RobustnessCheck(r, s, None, None, None, None, "search", 0.0)

    monkeypatch.setattr(rb, "is_rs_robust", undecided)
    data = run_json(["robustness", PAPER, "--r", 5, "--s", 2, "--time-limit", 1], capsys)
    assert data == {"r": 5, "s": 2, "holds": None, "witness": None}


def test_r_proven_but_s_unsettled_is_not_an_error(capsys, monkeypatch):
    import rescon.graphs.robustness as rb

    def unsettled(G, r, **kw):  # max_s raises TimeLimitReached when the time limit stops it
        raise rescon.TimeLimitReached(f"time limit reached: 1 ≤ s*({r}) ≤ 4")

    monkeypatch.setattr(rb, "max_s", unsettled)
    code, out, err = run(["robustness", PAPER, "--r", 5, "--time-limit", 1, "--json"], capsys)
    assert code == 0, err
    assert json.loads(out)["r_robust"] is True
    assert json.loads(out)["s_max"] is None


def test_search_method_beyond_64_nodes_cli(capsys, tmp_path):
    G = nx.gnp_random_graph(66, 0.1, directed=True, seed=2)
    path = write_edgelist(tmp_path / "g66.edgelist", G)
    proc = run_sub(["robustness", path, "--method", "search", "--json"])
    assert "Traceback" not in proc.stderr
    assert proc.returncode in (0, 2)
    if proc.returncode == 2:
        assert_clean_error(proc.returncode, proc.stdout, proc.stderr)


# --------------------------------------------------------------------------- #
# rescon kernel
# --------------------------------------------------------------------------- #

KERNEL_KEYS = {"n", "d", "F", "empty", "dim", "vertices", "A", "b", "point", "seconds"}


def test_kernel_command(capsys, tmp_path):
    pts = tmp_path / "square.csv"
    pts.write_text("x,y\n0,0\n1,0\n1,1\n0,1\n")
    cert_path = tmp_path / "k.json"
    png = tmp_path / "k.png"
    data = run_json(["kernel", pts, "--F", "1", "--certificate", cert_path, "--plot", png],
                    capsys)
    assert set(data) == KERNEL_KEYS
    assert (data["n"], data["d"], data["F"], data["empty"], data["dim"]) == (4, 2, 1, False, 0)
    assert data["vertices"] == [[0.5, 0.5]] and data["point"] == [0.5, 0.5]
    assert rescon.check_certificate(json.loads(cert_path.read_text())).valid
    assert png.stat().st_size > 1000
    assert main(["check", str(cert_path)]) == 0


def test_kernel_command_empty_and_errors(capsys, tmp_path):
    pts = tmp_path / "tri.csv"
    pts.write_text("0,0\n1,0\n0,1\n")
    data = run_json(["kernel", pts, "--F", "1"], capsys)
    assert data["empty"] is True and data["dim"] == -1 and data["point"] is None
    bad = tmp_path / "bad.csv"
    bad.write_text("0,0\n1\n")
    for argv in (["kernel", str(bad), "--F", "0"], ["kernel", str(pts), "--F", "3"],
                 ["kernel", str(tmp_path / "missing.csv"), "--F", "0"]):
        capsys.readouterr()
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "Traceback" not in err
    with pytest.raises(SystemExit) as exc:
        main(["kernel", str(pts)])  # --F is required
    assert exc.value.code == 2


def test_method_help_names_every_method(capsys):
    """--method is checked lazily (the parser does not import graphs.robustness): its
    help and its error still name every method of the library."""
    from rescon.graphs.robustness import METHODS

    _, out, _ = run(["robustness", "--help"], capsys)
    code, _, err = run(["robustness", str(PAPER), "--method", "nope"], capsys)
    assert code == 2
    for m in METHODS:
        assert m in " ".join(out.split()) and m in err


SCENARIOS = ROOT / "examples" / "scenarios"


def test_simulate_metrics_choose_the_monitors(capsys):
    """--metrics runs only the named monitors; the others are null, not a crash."""
    data = run_json(["simulate", SCENARIOS / "paper.toml", "--metrics", "diameter"], capsys)
    assert data["final_diameter"] < 1e-9 and data["max_validity"] is None
    data = run_json(["rmdo", SCENARIOS / "paper_rmdo.toml", "--metrics", "validity"], capsys)
    assert data["final_diameter"] is None and data["max_validity"] >= 0
    code, out, err = run(["simulate", SCENARIOS / "paper.toml", "--metrics", "diamter"], capsys)
    assert_clean_error(code, out, err)
    assert "diamter" in err


def test_trajectory_without_a_monitor_says_so():
    traj = rescon.simulate(rescon.Scenario.paper_example(steps=3), metrics=["spread"])
    with pytest.raises(rescon.InputError, match="'validity' monitor did not run"):
        _ = traj.max_validity
    with pytest.raises(rescon.InputError, match="'diameter' monitor did not run"):
        _ = traj.final_diameter
    assert "final_diameter" not in repr(traj)
    traj.plot()  # the panels of the monitors that ran
