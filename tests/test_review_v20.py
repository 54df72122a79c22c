"""V20 hostile review: graphs with named nodes end to end (read_graph's edge lists with
names, robustness with witnesses and certificates, the CLI's JSON, scenarios naming
agents) and RMDO's divergence hint.

Bugs found are strict xfails (they pass once fixed); everything else guards what was
checked and found correct. Brute force: every pair of disjoint nonempty sets (3^n
assignments, n <= 8)."""

from __future__ import annotations

import copy
import itertools
import json
import random
import re
import subprocess
import sys
import warnings
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon import InputError, Scenario, rmdo
from rescon.cli import main
from rescon.errors import GraphFormatError
from rescon.graphs.robustness import is_rs_robust, robustness
from rescon.io import read_graph

pytestmark = pytest.mark.filterwarnings("ignore::rescon.consensus.scenario.ScenarioWarning")

ROOT = Path(__file__).resolve().parent.parent
CHECKER = ROOT / "certificates" / "check.py"

ROBUSTNESS_KEYS = {"n", "r_max", "s_max", "exact", "witness", "method", "seconds"}
R_KEYS = {"r", "r_robust", "s_max", "witness"}
RS_KEYS = {"r", "s", "holds", "witness"}


def _write(tmp_path: Path, name: str, text: str, encoding: str = "utf-8") -> Path:
    p = tmp_path / name
    p.write_bytes(text.encode(encoding))
    return p


def _cli(argv, capsys) -> tuple[int, str, str]:
    try:
        code = main([str(a) for a in argv])
    except SystemExit as exc:
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err


def _assert_one_line_error(code, out, err) -> None:
    assert code == 2, (code, out, err)
    assert "Traceback" not in err + out
    lines = err.strip("\n").splitlines()
    assert len(lines) == 1 and lines[0].startswith("rescon: error:"), err


# --------------------------------------------------------------------------- brute force


def _in_sets(G: nx.DiGraph) -> dict:
    return {v: set(G.predecessors(v)) - {v} for v in G}


def _pair_cost(inn: dict, r: int, S1: set, S2: set) -> int | None:
    """|reach_r(S1)| + |reach_r(S2)| when neither set is fully reachable (a pair that
    violates (r, s) for every s above it), else None (the pair violates nothing)."""
    X1 = sum(len(inn[v] - S1) >= r for v in S1)
    X2 = sum(len(inn[v] - S2) >= r for v in S2)
    if X1 == len(S1) or X2 == len(S2):
        return None
    return X1 + X2


def _pairs(nodes):
    for a in itertools.product((0, 1, 2), repeat=len(nodes)):
        S1 = {v for v, k in zip(nodes, a) if k == 1}
        S2 = {v for v, k in zip(nodes, a) if k == 2}
        if S1 and S2:
            yield S1, S2


def _brute_s_star(G: nx.DiGraph, r: int) -> int:
    """s*(r) = min over violating-capable pairs of their cost (n when there is none;
    0 when G is not r-robust)."""
    inn = _in_sets(G)
    costs = [c for S1, S2 in _pairs(list(G)) if (c := _pair_cost(inn, r, S1, S2)) is not None]
    return min(costs, default=G.number_of_nodes())


def _brute_rho(G: nx.DiGraph) -> tuple[int, int]:
    rho = 0
    for r in range(1, G.number_of_nodes() + 1):
        if _brute_s_star(G, r) >= 1:
            rho = r
        else:
            break
    return rho, _brute_s_star(G, rho)


def _violates(G: nx.DiGraph, pair, r: int, s: int) -> bool:
    S1, S2 = set(pair[0]), set(pair[1])
    if not S1 or not S2 or S1 & S2 or not (S1 | S2) <= set(G):
        return False
    c = _pair_cost(_in_sets(G), r, S1, S2)
    return c is not None and c < s


NAMES = ["alice", "bob", "carol", "dave", "eve", "zoë", "東京", "٣x", "O'Brien", "a-b",
         "🙂", "x" * 300]


def _random_digraph(rng: random.Random, n: int) -> nx.DiGraph:
    p = rng.choice([0.3, 0.5, 0.7, 0.9])
    G = nx.gnp_random_graph(n, p, seed=rng.randrange(10**6), directed=True)
    return G


# --------------------------------------------------------------------------- reader: names


def test_named_labels_are_kept_verbatim_and_sorted(tmp_path, capsys):
    text = "alice bob\nzoë 東京\n٣x 🙂\nO'Brien a-b\n"
    G = read_graph(_write(tmp_path, "g.edgelist", text))
    assert capsys.readouterr() == ("", "")  # library code never prints
    tokens = text.split()
    assert list(G.nodes()) == sorted(set(tokens))
    assert set(G.edges()) == {("alice", "bob"), ("zoë", "東京"), ("٣x", "🙂"),
                              ("O'Brien", "a-b")}


@pytest.mark.parametrize("token", ["1_000", "nan", "inf", "-inf", "NaN", "True", "0x10",
                                   "1e", "e3", ".", "+", "-", "1.2.3", "²", "3.5x", "1/2"])
def test_number_like_tokens_that_are_not_decimal_numbers_are_names(tmp_path, token):
    G = read_graph(_write(tmp_path, "g.edgelist", f"{token} 2\n2 a\n"))
    assert set(G.nodes()) == {token, "2", "a"} and G.has_edge(token, "2")


@pytest.mark.parametrize("token", ["3.5", "1e3", ".5", "-2.", "+1E-3", "1E+3", "007.0"])
def test_decimal_labels_are_refused_with_file_and_line(tmp_path, token, capsys):
    p = _write(tmp_path, "g.edgelist", f"a b\n# c\n\nb {token}\n")
    with pytest.raises(GraphFormatError, match=rf"g\.edgelist:4: node label '{re.escape(token)}' "
                                               r"is a number but not an integer"):
        read_graph(p)
    _assert_one_line_error(*_cli(["robustness", p], capsys))


@pytest.mark.parametrize("named", [False, True])
def test_layout_variants_read_as_the_same_graph(tmp_path, named):
    """BOM, CRLF, lone CR, tabs, indentation, trailing blanks, inline and full-line
    comments and blank lines do not change the graph."""
    a, b, c, d = ("alice", "bob", "zoë", "dave") if named else ("1", "2", "3", "40")
    plain = f"{a} {b}\n{b} {c}\n{c} {a}\n{d}\n"
    variants = [
        "\ufeff" + plain,
        plain.replace("\n", "\r\n"),
        plain.replace("\n", "\r"),
        plain.replace(" ", "\t"),
        f"  # header\n\n {a}  {b}  # first\n\t{b} {c}\t\n\n{c} {a}   \n{d}#lone\n",
    ]
    want = read_graph(_write(tmp_path, "plain.edgelist", plain))
    assert want.number_of_nodes() == 4 and want.number_of_edges() == 3
    for k, text in enumerate(variants):
        G = read_graph(_write(tmp_path, f"v{k}.edgelist", text))
        assert list(G.nodes()) == list(want.nodes()), k
        assert set(G.edges()) == set(want.edges()), k


def test_self_loops_duplicates_isolated_and_target_only_nodes(tmp_path):
    G = read_graph(_write(tmp_path, "g.edgelist",
                          "a a\na b\na b\nb a\nc\nd b\nonly_target_of_d_is_b\n"))
    assert list(G.nodes()) == ["a", "b", "c", "d", "only_target_of_d_is_b"]
    assert set(G.edges()) == {("a", "b"), ("b", "a"), ("d", "b")}
    H = read_graph(_write(tmp_path, "t.edgelist", "x y\n"))
    assert list(H.nodes()) == ["x", "y"] and H.in_degree("y") == 1 and H.out_degree("y") == 0


def test_weights_column_is_a_one_line_error_naming_the_line(tmp_path, capsys):
    p = _write(tmp_path, "w.edgelist", "alice bob\nbob carol 0.5\n")
    with pytest.raises(GraphFormatError, match=r"w\.edgelist:2: .*got 3 fields"):
        read_graph(p)
    _assert_one_line_error(*_cli(["robustness", p], capsys))


def test_one_node_graph_reads_and_robustness_refuses_it_in_one_line(tmp_path, capsys):
    p = _write(tmp_path, "one.edgelist", "alice\nalice alice\n")
    G = read_graph(p)
    assert list(G.nodes()) == ["alice"] and G.number_of_edges() == 0
    with pytest.raises(InputError, match="at least 2 nodes"):
        robustness(G)
    _assert_one_line_error(*_cli(["robustness", p, "--json"], capsys))


def test_long_labels_and_long_integers_below_the_limit(tmp_path, capsys):
    big = "9" * 3000
    G = read_graph(_write(tmp_path, "g.edgelist", f"{big} 1\n1 {big}\n"))
    assert set(G.nodes()) == {int(big), 1}
    long = "n" * 100_000
    H = read_graph(_write(tmp_path, "h.edgelist", f"{long} b\nb c\n"))
    assert set(H.nodes()) == {long, "b", "c"}
    code, out, err = _cli(["robustness", tmp_path / "h.edgelist", "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    w = data["witness"]
    assert data["r_max"] == 1 and _violates(H, (w["S1"], w["S2"]), 2, 1)


def test_not_utf8_is_a_one_line_error(tmp_path, capsys):
    p = _write(tmp_path, "latin.edgelist", "zoë bob\n", encoding="latin-1")
    with pytest.raises(GraphFormatError, match="not a UTF-8 text file"):
        read_graph(p)
    _assert_one_line_error(*_cli(["robustness", p], capsys))


# --------------------------------------------------------------------------- reader: bugs


@pytest.mark.parametrize("a,b", [("1", "01"), ("+1", "1"), ("-0", "0"), ("٣", "3"),
                                 ("１", "1"), ("007", "7")])
def test_two_spellings_of_one_integer_are_not_silently_merged(tmp_path, a, b):
    """Every token is an 'integer', so labels become ints and the two spellings one
    node: the edge a -> b vanishes (a self-loop), the graph has 2 nodes instead of 3.
    GraphML (io._read_networkx) and CSV headers (not distinct: an error) already refuse
    to merge; the edge list should either keep the labels as strings or say so."""
    p = _write(tmp_path, "g.edgelist", f"{a} {b}\n{b} 2\n2 {a}\n")
    try:
        G = read_graph(p)
    except GraphFormatError:
        return  # a clear refusal is a fix too
    assert G.number_of_nodes() == 3 and G.number_of_edges() == 3


def test_graphml_and_csv_do_not_merge_two_spellings(tmp_path):
    """The other readers' behaviour the edge list should match (passes today)."""
    G = nx.DiGraph([("1", "01"), ("01", "2"), ("2", "1")])
    nx.write_graphml(G, tmp_path / "g.graphml")
    H = read_graph(tmp_path / "g.graphml")
    assert H.number_of_nodes() == 3 and H.number_of_edges() == 3
    try:  # a refusal, or two nodes
        C = read_graph(_write(tmp_path, "g.csv", "1,01\n0,1\n1,0\n"))
    except GraphFormatError as exc:
        assert "header labels are not distinct" in str(exc)
    else:
        assert C.number_of_nodes() == 2 and C.number_of_edges() == 2


def _huge() -> str:
    limit = sys.get_int_max_str_digits()
    if not limit:
        pytest.skip("the interpreter has no int-string digit limit")
    return "9" * (limit + 700)


def _huge_graph_file(tmp_path: Path, fmt: str) -> Path:
    big = _huge()
    if fmt == "edgelist":
        return _write(tmp_path, "big.edgelist", f"{big} 1\n1 2\n2 {big}\n")
    if fmt == "csv":
        return _write(tmp_path, "big.csv", f"{big},1\n0,1\n1,0\n")
    G = nx.DiGraph([(big, "1"), ("1", "2"), ("2", big)])
    nx.write_graphml(G, tmp_path / "big.graphml")
    return tmp_path / "big.graphml"


@pytest.mark.parametrize("fmt", ["edgelist", "csv", "graphml"])
def test_integer_label_beyond_the_digit_limit_is_read_or_refused_in_one_line(tmp_path, fmt):
    p = _huge_graph_file(tmp_path, fmt)
    try:
        G = read_graph(p)
    except GraphFormatError:
        return
    assert G.number_of_nodes() == 3


def test_cli_integer_label_beyond_the_digit_limit(tmp_path, capsys):
    p = _huge_graph_file(tmp_path, "edgelist")
    code, out, err = _cli(["robustness", p, "--json"], capsys)
    if code != 0:
        _assert_one_line_error(code, out, err)


# --------------------------------------------------------------------------- robustness


def test_int_and_string_labels_give_the_same_rho_and_s_star_as_brute_force():
    """Random digraphs n = 2..8 and the same graphs relabelled with shuffled names
    (Unicode, a 300-character one): ρ and s*(ρ) equal the brute force's, and every
    witness is a pair of the user's labels violating (ρ + 1)-robustness (s_witness:
    violating (ρ, s* + 1))."""
    rng = random.Random(20)
    for _ in range(30):
        n = rng.randint(2, 8)
        G = _random_digraph(rng, n)
        names = rng.sample(NAMES, n)
        H = nx.relabel_nodes(G, dict(zip(G.nodes(), names)))
        want = _brute_rho(G)
        for graph in (G, H):
            rep = robustness(graph)
            assert rep.exact and (rep.r_max, rep.s_max) == want, (list(G.edges()), names)
            if rep.witness is not None:
                assert _violates(graph, rep.witness, rep.r_max + 1, 1)
            if rep.s_witness is not None:
                assert _violates(graph, rep.s_witness, rep.r_max, rep.s_max + 1)
            assert rescon.check_certificate(rep.certificate).verdict == "valid"


def test_rs_queries_on_named_graphs_name_the_violating_pair():
    rng = random.Random(7)
    for _ in range(25):
        n = rng.randint(3, 7)
        G = _random_digraph(rng, n)
        H = nx.relabel_nodes(G, dict(zip(G.nodes(), rng.sample(NAMES, n))))
        r, s = rng.randint(1, 3), rng.randint(1, n)
        holds = _brute_s_star(G, r) >= s
        res = is_rs_robust(H, r, s)
        assert res.holds is holds
        if not holds:
            assert _violates(H, res.witness, r, s), res.witness
        assert rescon.check_certificate(res.certificate).verdict == "valid"


def test_int_file_and_named_file_of_one_graph_agree(tmp_path, capsys):
    """The same random graph written with ints and with names (whose sorted order is
    another node order): the CLI gives the same ρ and s*, witnesses in each file's labels."""
    rng = random.Random(3)
    for k in range(6):
        n = rng.randint(4, 8)
        G = _random_digraph(rng, n)
        names = {v: f"{NAMES[(v * 5) % len(NAMES)][:8]}_{v}" for v in G}
        lines = [str(7 * v - 20) for v in G] + [f"{7 * u - 20} {7 * v - 20}"
                                                for u, v in G.edges()]  # negative ints too
        named = [names[v] for v in G] + [f"{names[u]} {names[v]}" for u, v in G.edges()]
        outs = []
        for tag, text in (("i", lines), ("s", named)):
            p = _write(tmp_path, f"{tag}{k}.edgelist", "\n".join(text) + "\n")
            code, out, err = _cli(["robustness", p, "--json"], capsys)
            assert code == 0, err
            outs.append(json.loads(out))
        a, b = outs
        assert set(a) == set(b) == ROBUSTNESS_KEYS
        assert (a["r_max"], a["s_max"]) == (b["r_max"], b["s_max"]) == _brute_rho(G)
        if b["witness"] is not None:
            assert set(b["witness"]["S1"] + b["witness"]["S2"]) <= set(names.values())
            inv = {s: v for v, s in names.items()}
            back = ([inv[x] for x in b["witness"]["S1"]], [inv[x] for x in b["witness"]["S2"]])
            assert _violates(G, back, b["r_max"] + 1, 1)
        if a["witness"] is not None:
            back = ([(x + 20) // 7 for x in a["witness"]["S1"]],
                    [(x + 20) // 7 for x in a["witness"]["S2"]])
            assert all(isinstance(x, int) for x in back[0] + back[1])
            assert _violates(G, back, a["r_max"] + 1, 1)


@pytest.fixture(scope="module")
def named_graph() -> nx.DiGraph:
    G = nx.DiGraph()
    for i, u in enumerate(NAMES[3:11]):
        for j, v in enumerate(NAMES[3:11]):
            if u != v and (i + j) % 3:
                G.add_edge(u, v)
    return G


def test_named_certificate_names_nodes_and_maps_the_witness(named_graph):
    rep = robustness(named_graph)
    cert = rep.certificate
    nodes = cert["graph"]["nodes"]
    assert sorted(nodes) == sorted(named_graph.nodes()) and cert["graph"]["n"] == len(nodes)
    # edges are index pairs over `nodes`, exactly the graph's edges
    assert {(nodes[u], nodes[v]) for u, v in cert["graph"]["edges"]} == set(named_graph.edges())
    up = cert["upper_r"]
    pair = {frozenset(nodes[i] for i in up["S1"]), frozenset(nodes[i] for i in up["S2"])}
    assert pair == set(rep.witness)
    assert _violates(named_graph, rep.witness, rep.r_max + 1, 1)
    json.dumps(cert, ensure_ascii=True)  # plain JSON


def _standalone(cert: dict, tmp_path: Path) -> tuple[int, str]:
    """certificates/check.py run in an isolated interpreter from another directory."""
    p = tmp_path / "cert.json"
    p.write_text(json.dumps(cert), encoding="utf-8")
    done = subprocess.run([sys.executable, "-I", str(CHECKER), str(p)], capture_output=True,
                          text=True, timeout=60, cwd=tmp_path)
    return done.returncode, done.stdout + done.stderr


def test_named_certificate_valid_for_both_checkers_and_tampering_is_caught(named_graph,
                                                                           tmp_path):
    rep = robustness(named_graph)
    cert = rep.certificate
    assert rescon.check_certificate(cert).verdict == "valid"
    assert _standalone(cert, tmp_path)[0] == 0

    def tampered(edit):
        c = copy.deepcopy(cert)
        edit(c)
        return c

    bad = {
        "r_max + 1": lambda c: c.__setitem__("r_max", c["r_max"] + 1),
        "s_max + 1": lambda c: c.__setitem__("s_max", c["s_max"] + 1),
        "witness moved": lambda c: c["upper_r"].__setitem__(
            "S1", sorted(set(range(c["graph"]["n"])) - set(c["upper_r"]["S2"]))[:1]),
        "nodes short": lambda c: c["graph"].__setitem__("nodes", c["graph"]["nodes"][:-1]),
        "node a float": lambda c: c["graph"]["nodes"].__setitem__(0, 1.5),
        "node a bool": lambda c: c["graph"]["nodes"].__setitem__(0, True),
    }
    for what, edit in bad.items():
        c = tampered(edit)
        assert rescon.check_certificate(c).verdict == "invalid", what
        assert _standalone(c, tmp_path)[0] == 1, what
    # labels are informational: renaming them (Unicode, ints) keeps it valid
    renamed = tampered(lambda c: c["graph"].__setitem__(
        "nodes", [f"ñ{k}" if k % 2 else k for k in range(c["graph"]["n"])]))
    assert rescon.check_certificate(renamed).verdict == "valid"
    assert _standalone(renamed, tmp_path)[0] == 0


def test_cli_named_graph_json_keys_witness_and_certificate(tmp_path, capsys, named_graph):
    p = _write(tmp_path, "g.edgelist", "".join(f"{u} {v}\n" for u, v in named_graph.edges()))
    cert = tmp_path / "c.json"
    code, out, err = _cli(["robustness", p, "--json", "--certificate", cert], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert set(data) == ROBUSTNESS_KEYS and data["exact"]
    rho = data["r_max"]
    w = data["witness"]
    assert set(w) == {"S1", "S2"} and w["S1"] == sorted(w["S1"])
    assert _violates(named_graph, (w["S1"], w["S2"]), rho + 1, 1)
    assert _cli(["check", cert], capsys)[0] == 0
    data = json.loads(_cli(["robustness", p, "--json", "--r", rho + 1], capsys)[1])
    assert set(data) == R_KEYS and data["r_robust"] is False and data["s_max"] == 0
    assert _violates(named_graph, (data["witness"]["S1"], data["witness"]["S2"]), rho + 1, 1)
    s_max = robustness(named_graph).s_max
    data = json.loads(_cli(["robustness", p, "--json", "--r", rho, "--s", s_max + 1], capsys)[1])
    assert set(data) == RS_KEYS and data["holds"] is False
    assert _violates(named_graph, (data["witness"]["S1"], data["witness"]["S2"]), rho,
                     s_max + 1)
    code, out, err = _cli(["robustness", p], capsys)  # text: the labels, quoted
    assert code == 0 and f"S1 = {w['S1']!r}, S2 = {w['S2']!r}" in out, out


def test_node_link_json_with_int_1_and_string_1_are_two_nodes(tmp_path, capsys):
    data = {"directed": True, "nodes": [{"id": 1}, {"id": "1"}, {"id": "a"}],
            "links": [{"source": 1, "target": "1"}, {"source": "1", "target": "a"},
                      {"source": "a", "target": 1}, {"source": 1, "target": "a"}]}
    p = _write(tmp_path, "g.json", json.dumps(data))
    G = read_graph(p)
    assert G.number_of_nodes() == 3 and G.number_of_edges() == 4
    out = json.loads(_cli(["robustness", p, "--json"], capsys)[1])
    assert (out["r_max"], out["s_max"]) == _brute_rho(G)
    w = out["witness"]
    assert _violates(G, (w["S1"], w["S2"]), out["r_max"] + 1, 1)  # 1 and "1" kept apart


# --------------------------------------------------------------------------- scenarios


def _named_scenario(tmp_path: Path, names, *, key_of=lambda v: json.dumps(v)) -> Path:
    (tmp_path / "g.edgelist").write_text(
        "".join(f"{u} {v}\n" for u, v in itertools.permutations(names, 2)), encoding="utf-8")
    init = "".join(f"{key_of(v)} = [{k}.0, {k % 2}.0]\n" for k, v in enumerate(names))
    text = ("[scenario]\nF = 1\nsteps = 12\ncheck_robustness = false\n"
            "[graph]\nedgelist = \"g.edgelist\"\n"
            f"[initial]\n{init}"
            f"[adversaries.{key_of(names[-1])}]\nkind = \"constant\"\nvalue = [40.0, 40.0]\n")
    p = tmp_path / "s.toml"
    p.write_text(text, encoding="utf-8")
    return p


def test_simulate_names_agents_adversaries_and_outputs(tmp_path, capsys):
    names = ["alice", "bob", "carol", "dave", "zoë", "東京", "eve"]
    p = _named_scenario(tmp_path, names)
    sc = Scenario.from_toml(p)
    assert list(sc.nodes) == sorted(names) and list(sc.adversaries) == ["eve"]
    code, out, err = _cli(["simulate", p, "--json", "--out", tmp_path / "out", "-q"], capsys)
    assert code == 0, err
    assert set(json.loads(out)) == {"steps", "N", "d", "F", "algorithm", "policy",
                                    "final_diameter", "max_validity",
                                    "assumptions_violated", "seconds", "out"}  # README
    traj = json.loads((tmp_path / "out" / "trajectory.json").read_text(encoding="utf-8"))
    assert traj["nodes"] == sorted(names) and "eve" not in traj["benign"]
    assert len(traj["benign"]) == len(names) - 1
    row = traj["nodes"].index("eve")
    assert all(step[row] == [40.0, 40.0] for step in traj["states"])
    x0 = dict(zip(traj["nodes"], traj["states"][0]))
    assert x0["zoë"] == [4.0, 0.0] and x0["東京"] == [5.0, 1.0]
    csv_text = (tmp_path / "out" / "trajectory.csv").read_text(encoding="utf-8")
    assert "\n0,0.0,東京,1," in csv_text and "\n0,0.0,eve,0," in csv_text


def test_rmdo_with_named_agents():
    names = ["alice", "bob", "carol", "dave"]
    G = nx.relabel_nodes(nx.complete_graph(4), dict(enumerate(names))).to_directed()
    sc = Scenario(graph=G, x0=[[0.0], [1.0], [2.0], [3.0]], F=0, steps=100,
                  check_robustness=False)
    tr = rmdo(sc, {v: "(x1 - 1)^2" for v in names})
    assert tuple(tr.nodes) == tuple(names)
    assert tr.metrics["distance_to_optimum"][-1] < 0.05


def test_toml_keys_name_a_digit_node_of_a_named_graph(tmp_path):
    """Labels are strings when any label is a name, so the node written `1` in the file
    is the string '1'; scenario._label turns the TOML key "1" into int 1 ('x0 has states
    for [1], which are not nodes of the graph'). Same for [adversaries.1] and [costs]."""
    names = ["alice", "bob", "carol", "dave", "zoë", "1"]
    sc = Scenario.from_toml(_named_scenario(tmp_path, names))
    assert "1" in sc.adversaries and len(sc.nodes) == 6


# --------------------------------------------------------------------------- RMDO hint


def _domain_cost(bound: float, centre: float = 1.0):
    """(x1 - centre)^2 defined for x1 <= bound only (a cost failing for a reason of its
    own)."""

    def f(x):
        if float(np.asarray(x, float)[0]) > bound:
            raise ValueError(f"outside the cost's domain x1 <= {bound}")
        return float((np.asarray(x, float)[0] - centre) ** 2)

    def g(x):
        if float(np.asarray(x, float)[0]) > bound:
            raise ValueError(f"outside the cost's domain x1 <= {bound}")
        return np.array([2 * (float(np.asarray(x, float)[0]) - centre)])

    return f, g


def _run_error(x0, costs, **kw) -> str:
    sc = Scenario(graph=nx.complete_graph(4), x0=x0, F=0, steps=kw.pop("steps", 50),
                  check_robustness=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(InputError) as err:
            rmdo(sc, costs, **kw)
    return str(err.value)


def test_a_domain_error_near_a_nonzero_start_keeps_its_reason_and_has_no_hint():
    """Iterates moving steadily from x0 ∈ [0, 0.3] towards 1 (β = 0.1) leave the cost's
    domain at ~0.54: the error names the point and the cost's own reason, no hint."""
    msg = _run_error([[0.3], [0.0], [0.0], [0.0]], {v: _domain_cost(0.5) for v in range(4)},
                     step_size=0.1, optimum=[0.4])
    assert "ValueError: outside the cost's domain x1 <= 0.5" in msg
    assert "diverged" not in msg and "step_size" not in msg


def test_huge_legitimate_states_overflowing_at_the_start_have_no_hint():
    """States at the scenario's limit 1e150: a cost overflowing there (1e10 x1^2) is an
    error at the start point, not a divergence."""
    msg = _run_error([[1e150], [-1e150], [0.0], [1.0]], {v: "1e10*x1^2" for v in range(4)},
                     optimum=[0.0], steps=5)
    assert "diverged" not in msg and ("1e+150" in msg or "1e150" in msg), msg


def test_states_beyond_the_scenario_limit_are_refused():
    with pytest.raises(InputError, match="1e150|1e\\+150"):
        Scenario(graph=nx.complete_graph(4), x0=[[1e300], [0.0], [0.0], [0.0]], F=0,
                 steps=5, check_robustness=False)


@pytest.mark.parametrize("x0", [[[0.0]] * 4, [[0.0], [1.0], [2.0], [3.0]]], ids=["zero", "0-3"])
def test_a_run_that_really_diverges_says_so(x0):
    """1e10 (x1 - 1)^2 under the paper's steps (β_0 = 1) runs away to ~1e300 from zero
    states too (a real divergence: the hint is right, and must stay once the zero start
    is handled)."""
    msg = _run_error(x0, {v: "1e10*(x1 - 1)^2" for v in range(4)}, optimum=[1.0], steps=60)
    assert "the iterates diverged" in msg and "try a smaller step_size" in msg


@pytest.mark.parametrize("x0", [[[0.0]] * 4, [[1e-300], [0.0], [0.0], [0.0]]],
                         ids=["zero", "1e-300"])
def test_no_divergence_hint_for_a_steady_run_from_zero_states(x0):
    """Same steady run as the nonzero-start test above (0 -> 0.59 with β = 0.1, the
    cost's domain ends at 0.5), from all-zero states: the message says 'the iterates
    diverged (max |x| = 0.59, 0 at the start) ... try a smaller step_size'. The scale
    max(start, tiny) makes any nonzero point 'diverged'."""
    msg = _run_error(x0, {v: _domain_cost(0.5) for v in range(4)}, step_size=0.1,
                     optimum=[0.4])
    assert "ValueError: outside the cost's domain" in msg
    assert "diverged" not in msg


_MIXED_EDGES = [(1, "a"), ("a", 1), ("a", "b"), ("b", 1), (1, "b"), ("b", "a"), (2, 1),
                (1, 2), ("a", 2), ("b", 2)]


def test_scenario_with_mixed_int_and_string_labels_warns_instead_of_crashing():
    """README: [graph] edges = [[u, v], ...] with integer or string labels. The graph is
    3-robust, not the (d+1)F+1 = 4 the theorems need: the warning's witness is sorted
    with sorted() (TypeError: '<' not supported between 'str' and 'int'); the CLI
    (`rescon simulate` of such a TOML) ends in a traceback."""
    sc = Scenario(graph=nx.DiGraph(_MIXED_EDGES), x0=np.zeros((4, 2)), F=1, steps=3)
    problems = sc.warn()
    assert any("witness" in p for p in problems), problems


def test_scenario_with_mixed_labels_runs_when_robustness_is_not_checked():
    sc = Scenario(graph=nx.DiGraph(_MIXED_EDGES), x0=np.arange(8.0).reshape(4, 2), F=1,
                  steps=3, check_robustness=False)
    tr = rescon.simulate(sc)
    assert list(tr.nodes) == [1, "a", "b", 2] and tr.states.shape == (4, 4, 2)


def test_to_dict_round_trip_of_a_named_graph_with_a_digit_name():
    names = ["alice", "bob", "carol", "1"]
    sc = Scenario(graph=nx.complete_graph(names).to_directed(), x0=np.zeros((4, 1)), F=0,
                  steps=3, check_robustness=False)
    back = Scenario.from_dict(sc.to_dict())
    assert list(back.nodes) == names


@pytest.mark.parametrize("workers", [0, pytest.param(1, marks=pytest.mark.slow)])
def test_sweep_of_a_named_graph_file(tmp_path, capsys, named_graph, workers):
    """A robustness grid over a named edge list (--workers 0, and 1 on a LocalCluster):
    ρ, s* as the brute force, the in-cell certificate valid."""
    pd = pytest.importorskip("pandas")
    if workers:
        pytest.importorskip("distributed")
    (tmp_path / "g.edgelist").write_text(
        "".join(f"{u} {v}\n" for u, v in named_graph.edges()), encoding="utf-8")
    (tmp_path / "grid.toml").write_text(
        '[run]\nkind = "robustness"\n[base.graph]\nedgelist = "g.edgelist"\n'
        '[axes]\n"robustness.method" = ["auto", "dp"]\n', encoding="utf-8")
    code, out, err = _cli(["sweep", tmp_path / "grid.toml", "--out", tmp_path / "sw",
                           "--workers", workers, "--json", "-q"], capsys)
    assert code == 0, err
    assert json.loads(out)["ok"] == 2
    df = pd.read_parquet(tmp_path / "sw" / "results.parquet")
    want = _brute_rho(named_graph)
    assert [(int(a), int(b)) for a, b in zip(df["rho"], df["s_star"])] == [want, want]
    assert set(df["certificate_verdict"]) == {"valid"}


def test_int_and_string_labels_agree_up_to_n12_with_the_exhaustive_dp():
    """n = 9..12 (beyond the brute force here): the int graph by the subset DP, the named
    copy by auto and by the search; witnesses of the named copy violate in its labels."""
    rng = random.Random(12)
    for _ in range(8):
        n = rng.randint(9, 12)
        G = _random_digraph(rng, n)
        H = nx.relabel_nodes(G, dict(zip(G.nodes(), rng.sample(NAMES, n))))
        want = robustness(G, method="dp")
        for rep in (robustness(H), robustness(H, method="search")):
            assert (rep.r_max, rep.s_max) == (want.r_max, want.s_max), list(G.edges())
            if rep.witness is not None:
                assert _violates(H, rep.witness, rep.r_max + 1, 1)
            if rep.s_witness is not None:
                assert _violates(H, rep.s_witness, rep.r_max, rep.s_max + 1)


def test_no_divergence_hint_for_a_steady_run_towards_a_far_minimiser():
    """x ← 0.8 x + 2·10^6 (β = 0.1, f = (x1 − 10^7)^2): 2e6, 3.6e6, 4.9e6, then 5.9e6
    leaves the cost's domain x1 ≤ 5e6. The iterates approach X* monotonically; the
    message still says they diverged and to take a smaller step (the scale compares the
    point with the initial states only, not with where the costs send them)."""
    msg = _run_error([[1.0], [0.0], [0.0], [0.5]], {v: _domain_cost(5e6, 1e7) for v in range(4)},
                     step_size=0.1, optimum=[4e6])
    assert "ValueError: outside the cost's domain" in msg
    assert "diverged" not in msg


def test_cli_rmdo_with_named_costs_and_adversary(tmp_path, capsys):
    names = ["alice", "bob", "carol", "dave", "zoë", "東京", "eve"]
    p = _named_scenario(tmp_path, names)
    costs = "".join(f'{json.dumps(v)} = "(x1 - 1)^2 + {k + 1}*(x2 + 1)^2"\n'
                    for k, v in enumerate(names[:-1]))
    p.write_text(p.read_text(encoding="utf-8").replace("steps = 12", "steps = 60")
                 + "[costs]\n" + costs, encoding="utf-8")
    code, out, err = _cli(["rmdo", p, "--json", "-q", "--out", tmp_path / "o"], capsys)
    assert code == 0, err
    data = json.loads(out)
    assert data["optimum"]["point"] == [1.0, -1.0] and data["final_distance_to_optimum"] < 0.1
    traj = json.loads((tmp_path / "o" / "trajectory.json").read_text(encoding="utf-8"))
    assert traj["benign"] == sorted(names[:-1])


def test_an_error_while_computing_x_star_has_no_hint_and_keeps_its_reason():
    """No optimum given: Nelder–Mead from the benign mean (0) steps past the cost's
    domain while computing X*: the error says so, with the cost's reason, no hint."""
    msg = _run_error([[0.0]] * 4, {v: _domain_cost(0.5) for v in range(4)}, step_size=0.1)
    assert "while computing X*" in msg and "ValueError: outside the cost's domain" in msg
    assert "diverged" not in msg


def test_dos_links_name_agents_and_an_unknown_name_is_one_line(tmp_path, capsys):
    names = ["alice", "bob", "carol", "dave", "zoë", "eve"]
    p = _named_scenario(tmp_path, names)
    dos = ('[[dos]]\nname = "D1"\nlinks = [["alice", "bob"], ["zoë", "carol"]]\n'
           '[dos.schedule]\nkind = "periodic"\nperiod = 4.0\nduration = 1.5\n')
    p.write_text(p.read_text(encoding="utf-8") + dos, encoding="utf-8")
    code, out, err = _cli(["simulate", p, "--json", "-q", "--out", tmp_path / "o"], capsys)
    assert code == 0, err
    traj = json.loads((tmp_path / "o" / "trajectory.json").read_text(encoding="utf-8"))
    assert traj["metrics"]["blocked_links"][:4] == [2.0, 2.0, 2.0, 0.0]
    p.write_text(p.read_text(encoding="utf-8").replace('"carol"]]', '"mallory"]]'),
                 encoding="utf-8")
    code, out, err = _cli(["simulate", p, "--json", "-q"], capsys)
    _assert_one_line_error(code, out, err)
    assert "mallory" in err


def test_cli_simulate_on_a_csv_graph_with_int_and_name_header(tmp_path, capsys):
    """The CSV reader turns integer header cells into ints and keeps the others as strings
    (the edge list makes every label a string then), so the labels mix types; the
    K4's robustness warning then sorts the witness with sorted(). Expected: exit 0, the
    warning on stderr."""
    (tmp_path / "g.csv").write_text("1,a,b,2\n0,1,1,1\n1,0,1,1\n1,1,0,1\n1,1,1,0\n")
    (tmp_path / "s.toml").write_text(
        '[scenario]\nF = 1\nsteps = 5\n[graph]\nedgelist = "g.csv"\n[initial]\n'
        '1 = [0.0, 0.0]\na = [1.0, 0.0]\nb = [0.0, 1.0]\n2 = [1.0, 1.0]\n')
    code, out, err = _cli(["simulate", tmp_path / "s.toml", "--json", "-q"], capsys)
    assert code == 0 and "witness" in err, err


def test_a_byte_order_mark_inside_the_file_is_not_part_of_a_label(tmp_path):
    """`cat a.edgelist b.edgelist` of two BOM-marked files: utf-8-sig strips only the
    first BOM, the second stays in '\\ufeff3', so node 3 is doubled and every label
    becomes a string ('\\ufeff3' is not an integer). Either strip it or say so."""
    p = tmp_path / "g.edgelist"
    p.write_bytes(b"\xef\xbb\xbf1 2\n2 3\n" + b"\xef\xbb\xbf3 1\n")
    try:
        G = read_graph(p)
    except GraphFormatError:
        return
    assert list(G.nodes()) == [1, 2, 3] and set(G.edges()) == {(1, 2), (2, 3), (3, 1)}


def test_error_line_numbers_count_newlines_only(tmp_path):
    """A page-break line (a lone form feed, GNU style) before a bad line 3: the message
    says line 4 (splitlines also breaks at \\x0c, \\x1c-\\x1e, \\x85, \\u2028-9; after
    the universal-newline decoding only '\\n' ends a line)."""
    p = _write(tmp_path, "g.edgelist", "a b\n\x0c\nc d e\n")
    with pytest.raises(GraphFormatError, match=r"g\.edgelist:3: .*got 3 fields"):
        read_graph(p)


def test_undirected_named_file_through_the_cli(tmp_path, capsys):
    p = _write(tmp_path, "p.edgelist", "alice bob\nbob zoë\nzoë alice\nzoë dave\n")
    code, out, err = _cli(["robustness", p, "--undirected", "--json"], capsys)
    assert code == 0, err
    data = json.loads(out)
    U = nx.Graph([("alice", "bob"), ("bob", "zoë"), ("zoë", "alice"), ("zoë", "dave")])
    assert (data["r_max"], data["s_max"]) == _brute_rho(U.to_directed())
    w = data["witness"]
    assert _violates(U.to_directed(), (w["S1"], w["S2"]), data["r_max"] + 1, 1)


def test_zero_padded_labels_can_be_given_states_and_attacks_in_toml(tmp_path):
    """Agents numbered 001..006 in the graph file and the same keys in [initial] and
    [adversaries]: whatever type the reader gives such labels (int 1 before, the string
    '001' once two spellings of a number are kept apart), the TOML keys must name the
    same nodes (scenario._label reads "001" as int 1)."""
    names = [f"{k:03d}" for k in range(1, 7)]
    p = _named_scenario(tmp_path, names, key_of=lambda v: v)
    sc = Scenario.from_toml(p)
    assert len(sc.nodes) == 6 and len(sc.adversaries) == 1
    G = read_graph(tmp_path / "g.edgelist")
    assert list(sc.adversaries) == [list(G.nodes())[-1]]
