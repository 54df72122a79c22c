"""Tests for rescon.io: graph readers, point readers, JSON output."""

from __future__ import annotations

import io
import json
from dataclasses import dataclass
from fractions import Fraction
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

from rescon.errors import GraphFormatError, InputError
from rescon.io import read_graph, read_points, to_jsonable, write_json

DATA = Path(__file__).parent / "data"
EXAMPLES = Path(__file__).parent.parent / "examples" / "graphs"


def _write(tmp_path: Path, name: str, text: str) -> Path:
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


# ----------------------------------------------------------------------------- edge lists


def test_edge_list_reads_directed_sorted_simple_graph():
    G = read_graph(DATA / "small.edgelist")
    assert isinstance(G, nx.DiGraph)
    assert list(G.nodes()) == [1, 2, 3, 9, 10]
    assert sorted(G.edges()) == [(1, 2), (2, 3), (3, 1), (10, 1)]  # self-loop dropped


def test_undirected_symmetrises_a_directed_file():
    G = read_graph(DATA / "small.edgelist", undirected=True)
    assert type(G) is nx.Graph
    assert G.has_edge(2, 1) and G.has_edge(1, 10)
    assert G.number_of_edges() == 4


def test_edge_list_with_a_non_integer_label_reads_every_label_as_a_string(tmp_path):
    G = read_graph(DATA / "mixed_labels.edgelist")  # it was refused ('x' not an integer)
    assert list(G.nodes()) == ["1", "2", "x"]
    assert sorted(G.edges()) == [("1", "2"), ("2", "x")]
    named = read_graph(_write(tmp_path, "g.edgelist", "a b\nb c  # inline\nc a\nd\n"),
                       undirected=True)
    assert list(named.nodes()) == ["a", "b", "c", "d"] and named.number_of_edges() == 3


def test_an_edge_list_with_string_labels_runs_through_the_cli(tmp_path, capsys):
    from rescon.cli import main

    p = _write(tmp_path, "g.edgelist", "a b\nb c\nc a\nc d\nd a\nb d\n")
    assert main(["robustness", str(p), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["r_max"] == 1 and out["exact"]  # b and c have one in-neighbour each
    assert set(out["witness"]["S1"] + out["witness"]["S2"]) <= {"a", "b", "c", "d"}


def test_edge_list_three_fields_is_malformed(tmp_path):
    p = _write(tmp_path, "g.txt", "1 2\n1 2 0.5\n")
    with pytest.raises(GraphFormatError, match=r"g\.txt:2: expected 'u v'.*got 3 fields"):
        read_graph(p)


@pytest.mark.parametrize("text", ["", "# only a comment\n\n"])
def test_empty_graph_is_an_error(tmp_path, text):
    with pytest.raises(GraphFormatError, match=r"empty\.edgelist: the graph has no nodes"):
        read_graph(_write(tmp_path, "empty.edgelist", text))


def test_missing_file_names_the_path(tmp_path):
    missing = tmp_path / "nope.edgelist"
    with pytest.raises(InputError, match="graph file not found: .*nope.edgelist"):
        read_graph(missing)
    with pytest.raises(InputError, match="is a directory"):
        read_graph(tmp_path)
    with pytest.raises(InputError, match="path must be a str or os.PathLike; got int"):
        read_graph(3)  # type: ignore[arg-type]


def test_errors_are_one_line(tmp_path):
    p = _write(tmp_path, "g.csv", "0,1\n0\n")
    with pytest.raises(GraphFormatError) as info:
        read_graph(p)
    assert "\n" not in str(info.value)


# ----------------------------------------------------------------------------- CSV matrices


def test_csv_with_header_labels_and_weights():
    G = read_graph(DATA / "adjacency_header.csv")
    assert list(G.nodes()) == ["a", "b", "c"]
    assert sorted(G.edges()) == [("a", "b"), ("b", "c"), ("c", "a")]  # c -> c dropped


def test_csv_without_header_uses_indices(tmp_path):
    G = read_graph(_write(tmp_path, "m.csv", "0,1,1\n0,0,1\n1,0,0\n"))
    assert list(G.nodes()) == [0, 1, 2]
    assert sorted(G.edges()) == [(0, 1), (0, 2), (1, 2), (2, 0)]


def test_csv_numeric_header_when_one_extra_row(tmp_path):
    G = read_graph(_write(tmp_path, "m.csv", "1, 2\n0, 1\n1, 0\n"))
    assert sorted(G.edges()) == [(1, 2), (2, 1)]


def test_csv_ragged_row_names_line():
    pattern = r"adjacency_ragged\.csv:2: row has 2 entries; expected 3"
    with pytest.raises(GraphFormatError, match=pattern):
        read_graph(DATA / "adjacency_ragged.csv")


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        ("0,1\n1,x\n", r"m\.csv:2: column 2: 'x' is not a number"),
        ("0,1,0\n1,0,0\n", r"must be square; got 2 rows and 3 columns"),
        ("0,-1\n1,0\n", r"m\.csv:1: column 2: entry -1.0 is not a nonnegative finite"),
        ("0,nan\n1,0\n", r"m\.csv:1: column 2: entry nan is not a nonnegative finite"),
        ("a,a\n0,1\n1,0\n", r"m\.csv:1: header labels are not distinct"),
    ],
)
def test_csv_errors(tmp_path, text, pattern):
    with pytest.raises(GraphFormatError, match=pattern):
        read_graph(_write(tmp_path, "m.csv", text))


# ----------------------------------------------------------------------------- JSON node-link


def test_node_link_with_links_key():
    G = read_graph(DATA / "node_link_links.json")
    assert sorted(G.edges()) == [("a", "b"), ("b", "c")]
    assert G.nodes["c"]["role"] == "adversary"
    assert G.graph["name"] == "links"


def test_node_link_with_edges_key_undirected_counts_both_ways():
    G = read_graph(DATA / "node_link_edges.json")
    assert isinstance(G, nx.DiGraph)
    assert sorted(G.edges()) == [(0, 1), (1, 0), (1, 2), (2, 1)]


def test_node_link_round_trip_from_networkx(tmp_path):
    H = nx.gnp_random_graph(8, 0.4, seed=3, directed=True)
    p = tmp_path / "g.json"
    p.write_text(json.dumps(nx.node_link_data(H, edges="links")))
    assert sorted(read_graph(p).edges()) == sorted(H.edges())


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        (None, r"node_link_unknown\.json: links\[1\] refers to unknown node 7"),
        ('{"nodes": [], \n "links": [}', r"g\.json:2: invalid JSON"),
        ('{"nodes": [{"id": 0}]}', r"exactly one of 'links' or 'edges'"),
        ('[1, 2]', r"expected a node-link JSON object"),
        ('{"nodes": [{"id": [1]}], "links": []}', r"nodes\[0\] must be an object with an integer"),
        ('{"nodes": [{"id": 1}, {"id": 1}], "links": []}', r"nodes\[1\]: duplicate node id 1"),
    ],
)
def test_node_link_errors(tmp_path, text, pattern):
    p = DATA / "node_link_unknown.json" if text is None else _write(tmp_path, "g.json", text)
    with pytest.raises(GraphFormatError, match=pattern):
        read_graph(p)


# ----------------------------------------------------------------------------- GraphML / GML


def test_graphml_multigraph_collapses_and_ids_become_ints():
    G = read_graph(DATA / "multigraph.graphml")
    assert type(G) is nx.DiGraph
    assert sorted(G.edges()) == [(0, 1), (1, 2)]


def test_graphml_round_trip_keeps_graph_attributes(tmp_path):
    H = nx.gnp_random_graph(7, 0.5, seed=1)
    H.graph["rho"] = 2
    p = tmp_path / "h.graphml"
    nx.write_graphml(H, p)
    G = read_graph(p, undirected=True)
    assert nx.utils.graphs_equal(nx.Graph(G.edges()), nx.Graph(H.edges()))
    assert G.graph["rho"] == 2


def test_graphml_parse_error_names_file_and_line(tmp_path):
    p = _write(tmp_path, "bad.graphml", "<graphml>\n<graph>\n<node id='0'>\n</graphml>")
    with pytest.raises(GraphFormatError, match=r"bad\.graphml:4: invalid XML"):
        read_graph(p)


def test_gml_labels_become_nodes():
    G = read_graph(DATA / "undirected.gml")
    assert sorted(G.edges()) == [("x", "y"), ("y", "x"), ("y", "z"), ("z", "y")]


def test_gml_error_names_file(tmp_path):
    p = _write(tmp_path, "bad.gml", "graph [ node [ id 0 ] edge [ source 0 target 5 ] ]")
    with pytest.raises(GraphFormatError, match=r"bad\.gml: cannot read as gml: .*undefined target"):
        read_graph(p)


# ----------------------------------------------------------------------------- shipped examples


def test_example_files_parse():
    paper = read_graph(EXAMPLES / "paper_example.edgelist")
    assert sorted(paper.nodes()) == list(range(1, 13))
    assert sorted(paper.predecessors(1)) == [2, 3, 5, 7, 9, 10, 11, 12]
    assert sorted(paper.predecessors(2)) == [v for v in range(1, 13) if v != 2]
    ring = read_graph(EXAMPLES / "ring_lattice_20.edgelist")
    assert ring.number_of_edges() == 120 and all(ring.in_degree(v) == 6 for v in ring)
    cliques = read_graph(EXAMPLES / "two_cliques.graphml", undirected=True)
    assert cliques.number_of_nodes() == 12 and cliques.graph["rho"] == 2


# ----------------------------------------------------------------------------- points


def test_read_points_csv_with_header():
    X = read_points(DATA / "points_header.csv")
    assert X.shape == (4, 2) and X.dtype == float
    assert X[3].tolist() == [1.5, 2.5]


def test_read_points_npy(tmp_path):
    p = tmp_path / "x.npy"
    np.save(p, np.arange(6).reshape(3, 2))
    np.testing.assert_array_equal(read_points(p), np.arange(6.0).reshape(3, 2))


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        ("1,2\n3\n", r"p\.csv:2: row has 1 entries; expected 2 \(as in line 1\)"),
        ("1,2\n3,a\n", r"p\.csv:2: column 2: 'a' is not a number"),
        ("1,2\n3,nan\n", r"p\.csv:2: column 2: coordinates must be finite"),
        ("1,2\n-inf,0\n", r"p\.csv:2: column 1: coordinates must be finite"),
        ("", r"p\.csv: no points"),
        ("x,y\n", r"p\.csv: no points after the header row"),
        # a first row mixing numbers and other cells is a bad point, not a header
        # (it was dropped silently: "1+2j,2" gave n = 2)
        ("1+2j,2\n3,4\n5,6\n", r"p\.csv:1: column 1: '1\+2j' is not a number"),
        ("x,2\n3,4\n", r"p\.csv:1: column 1: 'x' is not a number"),
    ],
)
def test_read_points_csv_errors(tmp_path, text, pattern):
    with pytest.raises(InputError, match=pattern):
        read_points(_write(tmp_path, "p.csv", text))


def test_read_points_whitespace_separated(tmp_path):
    """numpy.savetxt's default output (spaces, %.18e) and tab-separated columns with
    a header read as the same points; a file with no comma used to be one CSV column
    whose first line passed for a header ("'3 4' is not a number")."""
    X = np.array([[1e308, -5e-324], [0.1, 2.0], [-3.0, 1e-300]])
    p = tmp_path / "x.txt"
    np.savetxt(p, X)
    np.testing.assert_array_equal(read_points(p), X)
    q = _write(tmp_path, "t.txt", "# comment\nx\ty\n1\t2\n 3   4 \n")
    np.testing.assert_array_equal(read_points(q), [[1.0, 2.0], [3.0, 4.0]])
    with pytest.raises(InputError, match=r"m\.txt:2: row has 2 entries; expected 1"):
        read_points(_write(tmp_path, "m.txt", "1 2\n3,4\n"))  # any comma: CSV throughout


@pytest.mark.parametrize(
    ("array", "pattern"),
    [
        (np.zeros(3), r"must be a numeric \(n, d\) array .*got shape \(3,\)"),
        (np.zeros((0, 2)), r"got shape \(0, 2\)"),
        (np.array([[0.0, np.nan], [1.0, 2.0]]), r"1 NaN/inf entries, first at row 0, column 1"),
        (np.array([["a", "b"]]), r"dtype <U1"),
    ],
)
def test_read_points_npy_errors(tmp_path, array, pattern):
    p = tmp_path / "x.npy"
    np.save(p, array)
    with pytest.raises(InputError, match=pattern):
        read_points(p)


def test_read_points_missing_file(tmp_path):
    with pytest.raises(InputError, match="points file not found"):
        read_points(tmp_path / "none.csv")


# ----------------------------------------------------------------------------- JSON output


@dataclass(frozen=True)
class _Result:
    holds: bool
    witness: tuple[frozenset[int], frozenset[int]]
    value: Fraction


def test_to_jsonable_converts_everything():
    obj = {
        "arr": np.arange(3),
        "scalars": [np.int64(4), np.float32(0.5), np.bool_(True)],
        "set": {3, 1, 2},
        "mixed": {"b", 1},
        "result": _Result(True, (frozenset({2, 0}), frozenset({1})), Fraction(2, 6)),
        "bad": [float("nan"), float("inf")],
        3: Path("a/b"),
    }
    out = to_jsonable(obj)
    assert out == {
        "arr": [0, 1, 2],
        "scalars": [4, 0.5, True],
        "set": [1, 2, 3],
        "mixed": [1, "b"],
        "result": {"holds": True, "witness": [[0, 2], [1]], "value": "1/3"},
        "bad": [None, None],
        "3": "a/b",
    }
    json.dumps(out, allow_nan=False)


def test_to_jsonable_rejects_unknown_types():
    with pytest.raises(InputError, match="obj contains a complex value"):
        to_jsonable({"z": 1j})


def test_write_json_to_path_and_stream(tmp_path):
    p = tmp_path / "out.json"
    write_json({"x": np.float64(1.5)}, p)
    assert json.loads(p.read_text()) == {"x": 1.5}
    assert p.read_text().endswith("\n")
    buf = io.StringIO()
    write_json([{1, 0}], buf)
    assert json.loads(buf.getvalue()) == [[0, 1]]
    with pytest.raises(InputError, match="path_or_stream must be a path or a writable .* got int"):
        write_json({}, 5)  # type: ignore[arg-type]
