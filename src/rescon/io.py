"""Read graphs and point sets from files; write results as JSON.

Graph convention (SPEC §1): a directed edge ``(u, v)`` means **v receives u's
state** (u is an in-neighbour of v). Every reader returns a simple graph:
self-loops are dropped without error (robustness ignores them) and parallel
edges of multigraph files collapse to one edge.

Every error is a single line that names the file, and the line where one
applies (``path:line: message``).
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import errno
import json
import math
import os
import re
import sys
import tempfile
from collections.abc import Callable, Hashable, Iterable, Iterator
from fractions import Fraction
from pathlib import Path
from typing import Any, TextIO
from xml.etree.ElementTree import ParseError

import networkx as nx
import numpy as np

from ._validate import flag
from .errors import GraphFormatError, InputError

__all__ = ["input_file", "output_path", "read_graph", "read_points", "to_jsonable",
           "write_json"]

#: an integer label as Python writes it (ASCII digits, no "+", no leading zeros, not
#: "-0"): only these become ints, so two spellings of one number ("1", "01") stay two nodes
_INT = re.compile(r"0|-?[1-9][0-9]*")
_DECIMAL = re.compile(r"[+-]?([0-9]+\.?[0-9]*|\.[0-9]+)([eE][+-]?[0-9]+)?")
_INTEGER_SPELLING = re.compile(r"[+-]?[0-9]+")


# --------------------------------------------------------------------------- graphs


def read_graph(path: str | os.PathLike[str], *, undirected: bool = False) -> nx.Graph:
    """Read a graph file into a simple networkx graph.

    The format is chosen by the file suffix:

    ``.graphml`` / ``.gml``
        Read with networkx. GML nodes are named by their ``label`` attributes
        when all are distinct strings, else by their ids. Node names that are
        all integers (written as Python writes them) become ``int``. An
        undirected file counts each edge both ways.
    ``.json``
        networkx node-link data: ``{"directed": bool, "nodes": [{"id": ...}, ...],
        "links": [{"source": u, "target": v}, ...]}``; the edge list may also be
        under ``"edges"``. Node ids are integers or strings; a missing
        ``"directed"`` means directed (as for edge lists).
    ``.csv``
        Adjacency matrix :math:`A`: :math:`a_{ij} \\ne 0` is the edge
        :math:`i \\to j`. Entries are nonnegative finite numbers (0/1 usually).
        An optional first row holds the node labels; it is recognised when it
        contains a non-number, or when the file has one more row than columns
        and the first row holds distinct integers. Its labels are ints or
        strings by the edge list's rule. Without it the nodes are ``0..n-1``.
        The matrix must be square.
    anything else
        Edge list: ``u v`` per line is the edge :math:`u \\to v`; a line with a
        single label declares a (possibly isolated) node. Labels are integers
        when every label in the file is an integer written as Python writes
        one (``0``, ``-3``, ``42``), else strings as spelled (any token without
        whitespace: ``a b``, ``1 a`` and ``1 01`` all give string labels, so two
        spellings of one number stay two nodes); a label that is a number but not
        an integer (``3.5``, ``1e3``) is an error. ``#`` starts a comment; blank
        lines and a byte-order mark starting a line are ignored. Nodes are sorted
        by label.

    Lines starting with ``#`` are comments in ``.csv`` files too.

    Parameters
    ----------
    path : str or os.PathLike
        The graph file.
    undirected : bool, default False
        Return an undirected :class:`networkx.Graph`; edges of a directed file
        are symmetrised (:math:`u \\to v` becomes :math:`\\{u, v\\}`).

    Returns
    -------
    networkx.DiGraph or networkx.Graph
        A :class:`~networkx.DiGraph` (an undirected file gives both directions of
        every edge), or a :class:`~networkx.Graph` when ``undirected`` is true.
        Self-loops are dropped without error; parallel edges collapse to one.
        Node and graph attributes of GraphML, GML and JSON files are kept; edge
        attributes are not.

    Raises
    ------
    InputError
        ``path`` does not name an existing file.
    GraphFormatError
        The file cannot be parsed, or the graph has no nodes. The message names
        the file, and the line where one applies.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> p = pathlib.Path(tempfile.mkdtemp()) / "g.edgelist"
    >>> _ = p.write_text("# a path 1 -> 2 -> 3 and node 4\\n1 2\\n2 3\\n4\\n")
    >>> G = read_graph(p)
    >>> sorted(G.edges()), sorted(G.nodes())
    ([(1, 2), (2, 3)], [1, 2, 3, 4])
    """
    undirected = flag("undirected", undirected)
    p = input_file(path, "graph file")
    reader = _GRAPH_READERS.get(p.suffix.lower(), _read_edge_list)
    G = reader(p)
    if G.number_of_nodes() == 0:
        raise GraphFormatError(f"{p}: the graph has no nodes")
    out: nx.Graph = nx.Graph() if undirected else nx.DiGraph()
    out.graph.update(G.graph)
    out.add_nodes_from(G.nodes(data=True))
    both_ways = not undirected and not G.is_directed()
    for u, v in G.edges():
        if u != v:
            out.add_edge(u, v)
            if both_ways:
                out.add_edge(v, u)
    return out


def _check_label(p: Path, lineno: int, token: str) -> None:
    """A label that reads as a number but not as an integer is refused (a weight or a
    coordinate in the wrong place, more likely than a node named '3.5')."""
    if _INTEGER_SPELLING.fullmatch(token) or not _DECIMAL.fullmatch(token):
        return
    raise GraphFormatError(f"{p}:{lineno}: node label {token!r} is a number but not an "
                           "integer (labels are integers or names)")


def _read_edge_list(p: Path) -> nx.DiGraph:
    rows: list[list[str]] = []
    for lineno, line in _data_lines(p, inline_comments=True):
        tokens = line.split()
        if len(tokens) > 2:
            raise GraphFormatError(
                f"{p}:{lineno}: expected 'u v' (edge u -> v) or a single node 'u'; "
                f"got {len(tokens)} fields"
            )
        for t in tokens:
            _check_label(p, lineno, t)
        rows.append(tokens)
    ints = _as_ints(p, [t for tokens in rows for t in tokens])
    label: Callable[[str], Hashable] = str if ints is None else ints.__getitem__
    G = nx.DiGraph()
    for tokens in rows:
        if len(tokens) == 1:
            G.add_node(label(tokens[0]))
        else:
            G.add_edge(label(tokens[0]), label(tokens[1]))
    H = nx.DiGraph()
    H.add_nodes_from(sorted(G.nodes()))
    H.add_edges_from(G.edges())
    return H



def _read_adjacency_csv(p: Path) -> nx.DiGraph:
    rows = _csv_rows(p)
    if not rows:
        raise GraphFormatError(f"{p}: the graph has no nodes")
    labels: list[Hashable] | None = None
    first_line, first = rows[0]
    width = len(first)
    if any(_number(c) is None for c in first) or (
        len(rows) == width + 1 and all(_INTEGER_SPELLING.fullmatch(c) for c in first)
    ):
        if not all(first):
            raise GraphFormatError(f"{p}:{first_line}: header has an empty node label")
        ints = _as_ints(p, first)
        labels = list(first) if ints is None else [ints[c] for c in first]
        if len(set(labels)) != len(labels):
            raise GraphFormatError(f"{p}:{first_line}: header labels are not distinct")
        rows = rows[1:]
    matrix = [_number_row(p, lineno, cells, width, first_line, GraphFormatError)
              for lineno, cells in rows]
    if len(matrix) != width:
        raise GraphFormatError(
            f"{p}: adjacency matrix must be square; got {len(matrix)} rows and {width} columns"
        )
    for (lineno, _), values in zip(rows, matrix):
        for j, a in enumerate(values):
            if not (math.isfinite(a) and a >= 0):
                raise GraphFormatError(
                    f"{p}:{lineno}: column {j + 1}: entry {a} is not a nonnegative finite "
                    "number (expected 0/1 or a nonnegative weight)"
                )
    nodes: list[Hashable] = labels if labels is not None else list(range(width))
    G = nx.DiGraph()
    G.add_nodes_from(nodes)
    G.add_edges_from(
        (nodes[i], nodes[j]) for i, values in enumerate(matrix) for j, a in enumerate(values) if a
    )
    return G


def _as_ints(p: Path, labels: list[str]) -> dict[str, int] | None:
    """Each label's int when every label is an integer as Python writes it (:data:`_INT`),
    else None: the labels stay strings, spelled as given. An integer longer than
    Python's int–string limit (``sys.get_int_max_str_digits()``) is refused."""
    if not all(_INT.fullmatch(t) for t in labels):
        return None
    try:
        return {t: int(t) for t in labels}
    except ValueError:  # only the digit limit: the spelling is checked above
        digits = max(len(t.lstrip("-")) for t in labels)
        raise GraphFormatError(
            f"{p}: a node label is an integer of {digits} digits, beyond Python's limit of "
            f"{sys.get_int_max_str_digits()} (sys.set_int_max_str_digits raises it)") from None


def _read_node_link(p: Path) -> nx.Graph:
    data = _load_json(p)
    if not isinstance(data, dict) or "nodes" not in data:
        raise GraphFormatError(
            f"{p}: expected a node-link JSON object with 'nodes' and 'links' (or 'edges')"
        )
    if ("links" in data) == ("edges" in data):
        raise GraphFormatError(f"{p}: node-link JSON needs exactly one of 'links' or 'edges'")
    links = data["links"] if "links" in data else data["edges"]
    directed = data.get("directed", True)
    if not isinstance(directed, bool) or not isinstance(data["nodes"], list) or not isinstance(
        links, list
    ):
        raise GraphFormatError(
            f"{p}: 'directed' must be a boolean and 'nodes', 'links' must be lists"
        )
    G: nx.Graph = nx.DiGraph() if directed else nx.Graph()
    graph_attrs = data.get("graph", {})
    if isinstance(graph_attrs, dict):
        G.graph.update(graph_attrs)
    for k, node in enumerate(data["nodes"]):
        if not isinstance(node, dict) or not _is_label(node.get("id")):
            raise GraphFormatError(
                f"{p}: nodes[{k}] must be an object with an integer or string 'id'"
            )
        if node["id"] in G:
            raise GraphFormatError(f"{p}: nodes[{k}]: duplicate node id {node['id']!r}")
        G.add_node(node["id"], **{a: v for a, v in node.items() if a != "id"})
    for k, link in enumerate(links):
        if not isinstance(link, dict) or "source" not in link or "target" not in link:
            raise GraphFormatError(f"{p}: links[{k}] must be an object with 'source' and 'target'")
        for end in (link["source"], link["target"]):
            if not _is_label(end) or end not in G:
                raise GraphFormatError(f"{p}: links[{k}] refers to unknown node {end!r}")
        G.add_edge(link["source"], link["target"])
    return G


def _is_label(x: Any) -> bool:
    return isinstance(x, (int, str)) and not isinstance(x, bool)


def _load_json(p: Path) -> Any:
    text = _read_text(p, GraphFormatError)
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise GraphFormatError(f"{p}:{exc.lineno}: invalid JSON: {exc.msg}") from exc


def _read_networkx(p: Path, read: Callable[[Path], nx.Graph]) -> nx.Graph:
    try:
        G = read(p)
    except ParseError as exc:
        raise GraphFormatError(f"{p}:{exc.position[0]}: invalid XML: {exc}") from exc
    except (nx.NetworkXError, ValueError, KeyError, TypeError) as exc:
        raise GraphFormatError(f"{p}: cannot read as {p.suffix[1:]}: {exc}") from exc
    labels = list(G.nodes())
    ints = _as_ints(p, labels) if all(isinstance(v, str) for v in labels) else None
    return G if ints is None else nx.relabel_nodes(G, ints)


def _read_gml_file(p: Path) -> nx.Graph:
    G = nx.read_gml(p, label=None)
    names = [G.nodes[v].get("label") for v in G]
    if all(isinstance(s, str) for s in names) and len(set(names)) == len(names):
        G = nx.relabel_nodes(G, dict(zip(G.nodes(), names)))
    return G


_GRAPH_READERS: dict[str, Callable[[Path], nx.Graph]] = {
    ".graphml": lambda p: _read_networkx(p, nx.read_graphml),
    ".gml": lambda p: _read_networkx(p, _read_gml_file),
    ".json": _read_node_link,
    ".csv": _read_adjacency_csv,
}


# --------------------------------------------------------------------------- points


def read_points(path: str | os.PathLike[str]) -> np.ndarray:
    """Read a point set :math:`X \\in \\mathbb{R}^{n \\times d}` (one point per row).

    Parameters
    ----------
    path : str or os.PathLike
        ``.npy``: a 2-D numeric array (no pickles). Anything else: text with n
        rows of d numbers — comma-separated (CSV) if any data line has a comma,
        else separated by spaces or tabs (``numpy.savetxt``'s and MATLAB's default);
        an optional header row (recognised by having no number cell, ignored; a
        first row mixing numbers and other cells is an error), ``#`` comment lines
        and blank lines ignored.

    Returns
    -------
    numpy.ndarray
        Float array of shape ``(n, d)``, n ≥ 1, d ≥ 1, all entries finite.

    Raises
    ------
    InputError
        Missing file, ragged rows, non-numeric cells, NaN or infinite entries,
        no points, or an ``.npy`` array that is not 2-D. CSV messages name the
        file and line.
    """
    p = input_file(path, "points file")
    if p.suffix.lower() == ".npy":
        return _read_npy_points(p)
    rows = _point_rows(p)
    if not rows:
        raise InputError(f"{p}: no points (expected n >= 1 rows of d numbers)")
    first_line, width = rows[0][0], len(rows[0][1])
    if all(_number(c) is None for c in rows[0][1]):  # a header; a mixed row is a bad point
        rows = rows[1:]
        if not rows:
            raise InputError(f"{p}: no points after the header row")
    values = [_number_row(p, lineno, cells, width, first_line, InputError)
              for lineno, cells in rows]
    for (lineno, _), row in zip(rows, values):
        bad = [j + 1 for j, x in enumerate(row) if not math.isfinite(x)]
        if bad:
            raise InputError(f"{p}:{lineno}: column {bad[0]}: coordinates must be finite numbers")
    return np.array(values, dtype=float)


def _read_npy_points(p: Path) -> np.ndarray:
    try:
        arr = np.load(p, allow_pickle=False)
    except (OSError, ValueError, EOFError) as exc:
        raise InputError(f"{p}: not a readable .npy array: {exc}") from exc
    if arr.ndim != 2 or arr.shape[0] < 1 or arr.shape[1] < 1 or arr.dtype.kind not in "biuf":
        raise InputError(
            f"{p}: points must be a numeric (n, d) array with n, d >= 1; "
            f"got shape {arr.shape}, dtype {arr.dtype}"
        )
    X = arr.astype(float)
    bad = ~np.isfinite(X)
    if bad.any():
        i, j = np.argwhere(bad)[0]
        raise InputError(
            f"{p}: points must be finite; got {int(bad.sum())} NaN/inf entries, "
            f"first at row {i}, column {j}"
        )
    return X


# --------------------------------------------------------------------------- text helpers


def input_file(path: Any, what: str, *, missing: str = "{what} not found: {path}") -> Path:
    """``path`` as a Path naming an existing file, by one rule for every input (graph,
    points, scenario, costs, RMDO and sweep files).

    Parameters
    ----------
    path : str or os.PathLike
    what : what the file is, for the message (e.g. ``"graph file"``).
    missing : the message when nothing is at ``path`` (``{what}``, ``{path}`` filled in).

    Raises
    ------
    InputError
        ``path`` is not a str or os.PathLike, is a directory, or names nothing (one line).
    """
    if not isinstance(path, (str, os.PathLike)):
        raise InputError(f"{what}: path must be a str or os.PathLike; got {type(path).__name__}")
    p = Path(path)
    if not p.is_file():
        if p.is_dir():
            raise InputError(f"{what} is a directory: {p}")
        raise InputError(missing.format(what=what, path=p))
    return p


def _read_text(p: Path, error: type[InputError]) -> str:
    try:
        return p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise error(f"{p}: not a UTF-8 text file ({exc.reason} at byte {exc.start})") from exc


def _data_lines(p: Path, *, inline_comments: bool = False,
                error: type[InputError] = GraphFormatError) -> Iterator[tuple[int, str]]:
    # after universal-newline decoding only "\n" ends a line (str.splitlines would also
    # break at form feeds, U+0085, U+2028 …, and the line numbers would disagree with
    # editors); a byte-order mark starting a line (files saved with one, concatenated)
    # is not part of its first field
    for lineno, raw in enumerate(_read_text(p, error).split("\n"), start=1):
        raw = raw.removeprefix("\ufeff")
        line = raw.split("#", 1)[0] if inline_comments else raw
        line = line.strip()
        if line and not line.startswith("#"):
            yield lineno, line


def _csv_rows(p: Path, error: type[InputError] = GraphFormatError) -> list[tuple[int, list[str]]]:
    return _csv_cells(_data_lines(p, error=error))


def _csv_cells(lines: Iterable[tuple[int, str]]) -> list[tuple[int, list[str]]]:
    return [(lineno, [c.strip() for c in next(csv.reader([line]))]) for lineno, line in lines]


def _point_rows(p: Path) -> list[tuple[int, list[str]]]:
    """A points file's data rows: CSV cells if any line has a comma, else the
    whitespace-separated fields of each line."""
    lines = list(_data_lines(p, error=InputError))
    if any("," in line for _, line in lines):
        return _csv_cells(lines)
    return [(lineno, line.split()) for lineno, line in lines]


def _number(cell: str) -> float | None:
    try:
        return float(cell)
    except ValueError:
        return None


def _number_row(p: Path, lineno: int, cells: list[str], width: int, first_line: int,
                error: type[InputError]) -> list[float]:
    if len(cells) != width:
        raise error(
            f"{p}:{lineno}: row has {len(cells)} entries; "
            f"expected {width} (as in line {first_line})"
        )
    row = []
    for j, cell in enumerate(cells):
        x = _number(cell)
        if x is None:
            raise error(f"{p}:{lineno}: column {j + 1}: {cell!r} is not a number")
        row.append(x)
    return row


# --------------------------------------------------------------------------- output paths


def output_path(path: Any, what: str, *, directory: bool = False) -> Path:
    """Where an output goes, by one rule for every output (``--plot``,
    ``--certificate``, ``--out``, ``write_json``, figures): missing parent
    directories are created; a file path that is an existing directory, a directory
    path that is an existing file, a symbolic link to nothing, and a place that
    cannot be written now are refused — before any work is done. Writability is
    tried, not guessed from permission bits (``os.access`` says yes to root on file
    systems that refuse it, such as /sys): an existing file is opened for appending
    (nothing written); for a new file, and a directory, a probe file of a unique name
    is created in the directory and removed. A refused path leaves no directory it
    created behind.

    Parameters
    ----------
    path : str or os.PathLike
    what : the argument's name, for the message (e.g. ``"--certificate"``).
    directory : the output is a directory (created, with its parents).

    Raises
    ------
    InputError
        ``path`` is not a path, has the wrong kind, a directory on it cannot be
        created, or it cannot be written (one line naming ``what``).
    """
    if not isinstance(path, (str, os.PathLike)) or not os.fspath(path):
        raise InputError(f"{what} must be a non-empty path; got {path!r}")
    p = Path(path)
    if p.is_symlink() and not p.exists():
        raise InputError(f"{what}: {p} is a symbolic link to nothing ({os.readlink(p)})")
    if directory and p.exists() and not p.is_dir():
        raise InputError(f"{what}: {p} exists and is not a directory")
    if not directory and p.is_dir():
        raise InputError(f"{what}: {p} is a directory, not a file name")
    folder = p if directory else p.parent
    created = _missing_ancestors(folder)
    try:
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise InputError(f"{what}: cannot create the directory for {p} "
                             f"({exc.strerror or exc})") from None
        try:
            _try_writing(p, directory)
        except OSError as exc:
            raise InputError(f"{what}: cannot write {p} ({exc.strerror or exc})") from None
    except InputError:
        for d in created:  # deepest first: a refusal leaves nothing behind (V39)
            with contextlib.suppress(OSError):
                d.rmdir()
        raise
    return p


def _missing_ancestors(folder: Path) -> list[Path]:
    """``folder`` and its ancestors that do not exist yet, deepest first."""
    out = []
    while not folder.exists() and folder != folder.parent:
        out.append(folder)
        folder = folder.parent
    return out


def _try_writing(p: Path, directory: bool) -> None:
    """OSError unless ``p`` (a directory: a file in it) can be written now; leaves
    everything as it was. Special files (/dev/null, FIFOs) by their permission bits only:
    opening a FIFO for writing would wait for a reader. A new file is not created: its
    directory gets a probe file of its own (a unique name, created and removed — creating
    ``p`` itself and removing it could delete a file another run wrote meanwhile, V39)
    and the name's length is checked against the directory's limit."""
    if directory or not p.exists():
        fd, probe = tempfile.mkstemp(prefix=".rescon-write-probe-",
                                     dir=p if directory else p.parent)
        os.close(fd)
        os.unlink(probe)
        if not directory and len(os.fsencode(p.name)) > _name_max(p.parent):
            raise OSError(errno.ENAMETOOLONG, os.strerror(errno.ENAMETOOLONG))
    elif p.is_file():
        with p.open("a"):
            pass
    elif not os.access(p, os.W_OK):
        raise PermissionError(errno.EACCES, os.strerror(errno.EACCES))


def _name_max(folder: Path) -> int:
    """The longest file name (bytes) ``folder``'s file system takes (255 where unknown)."""
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


# --------------------------------------------------------------------------- JSON output


def to_jsonable(obj: Any) -> Any:
    """Convert ``obj`` recursively into plain JSON types.

    Conversions: numpy scalars → Python scalars; numpy arrays, tuples → lists;
    sets, frozensets → sorted lists (mixed types: by type name first); dataclass
    instances → dicts of their fields; :class:`fractions.Fraction` → exact
    strings such as ``"3/4"``; paths → strings; mapping keys → strings;
    non-finite floats → ``None`` (JSON has no NaN or infinity).

    Raises
    ------
    InputError
        ``obj`` contains a value with no JSON form (e.g. complex, bytes).

    Examples
    --------
    >>> from fractions import Fraction
    >>> to_jsonable({"S": {3, 1}, "x": np.float64(0.5), "q": Fraction(3, 4)})
    {'S': [1, 3], 'x': 0.5, 'q': '3/4'}
    """
    if obj is None or isinstance(obj, (bool, int, str)):
        return obj
    if isinstance(obj, float):
        return float(obj) if math.isfinite(obj) else None
    if isinstance(obj, np.generic):
        return to_jsonable(obj.item())
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, Fraction):
        return str(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return {f.name: to_jsonable(getattr(obj, f.name)) for f in dataclasses.fields(obj)}
    if isinstance(obj, dict):
        return {k if isinstance(k, str) else str(to_jsonable(k)): to_jsonable(v)
                for k, v in obj.items()}
    if isinstance(obj, (set, frozenset)):
        items = [to_jsonable(x) for x in obj]
        try:
            return sorted(items)
        except TypeError:
            return sorted(items, key=lambda x: (type(x).__name__, json.dumps(x, sort_keys=True)))
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(x) for x in obj]
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    raise InputError(f"obj contains a {type(obj).__name__} value, which has no JSON form")


def write_json(obj: Any, path_or_stream: str | os.PathLike[str] | TextIO) -> None:
    """Write ``to_jsonable(obj)`` as indented JSON (UTF-8, trailing newline).

    Parameters
    ----------
    obj : Any
        Anything :func:`to_jsonable` accepts.
    path_or_stream : str, os.PathLike or text stream
        A file path (overwritten; missing parent directories are created, as for
        every output: :func:`output_path`) or an object with a ``write(str)`` method.

    Raises
    ------
    InputError
        ``obj`` has no JSON form, or ``path_or_stream`` is neither a path nor a
        writable stream.
    """
    text = json.dumps(to_jsonable(obj), indent=2) + "\n"
    if isinstance(path_or_stream, (str, os.PathLike)):
        output_path(path_or_stream, "path_or_stream").write_text(text, encoding="utf-8")
    elif callable(getattr(path_or_stream, "write", None)):
        path_or_stream.write(text)
    else:
        raise InputError(
            "path_or_stream must be a path or a writable text stream; "
            f"got {type(path_or_stream).__name__}"
        )
