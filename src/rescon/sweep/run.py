"""``rescon.sweep``: run a grid's cells as Dask tasks and stream the rows to Parquet.

Output directory (``out``): ``grid.json`` (the grid's canonical SHA-256 and the grid),
``parts/cell-NNNNNN.parquet`` (one file per finished cell, written as it finishes),
``results.parquet`` (every finished row, consolidated at the end) and, with matplotlib,
``summary.png``. A rerun in the same directory skips the finished cells; a different
grid there is refused. A row lost to the cluster (:data:`LOST`: the worker running the
cell died, the task was cancelled) is in the table but not stored as finished, so a
rerun computes it; a part file that cannot be read is computed again too.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

from .._dask import Workers, check_workers, client
from .._progress import progress_bar
from ..errors import InputError, MissingDependency
from .cell import METRICS, failed_row, run_cell
from .grid import Grid, read_grid

__all__ = ["LOST", "sweep"]

#: the errors of a row lost to the cluster, not to its cell (run_cell never raises: a
#: cell's own exception is its row): the cell is computed again on a rerun
LOST = ("KilledWorker", "CancelledError", "FutureCancelledError", "CommClosedError")
#: a Parquet integer column holds 64-bit integers
_INT64 = (-(2**63), 2**63 - 1)
_PART = re.compile(r"cell-(\d{6})\.parquet")


def sweep(grid: str | Path | Mapping[str, Any], *, scheduler: str | None = None,
          workers: int | None = None, out: str | Path | None = None,
          progress: bool | None = None) -> Any:
    """Run every cell of ``grid`` (TOML file or dict; format: :mod:`rescon.sweep.grid`)
    and return a pandas DataFrame, one row per cell in grid order: one column per
    axis, ``repetition``, ``seed``, ``status`` ("ok" / "failed"), ``error``,
    ``final_diameter``, ``max_validity`` (max over time and benign agents of the
    distance to conv(benign x0)), ``steps_to_consensus`` (first k with diameter(t_k) ≤
    ε·diameter(t_0), ε = [run] epsilon, default 1e-6; null if never),
    ``blocked_links`` (Σ over steps of the links under DoS), ``final_gap`` (RMDO: the
    optimality gap at the last step), then the columns of robustness and kernel cells
    (``[run] kind``; :mod:`rescon.sweep.cell`: ``rho``, ``s_star``, ``exact``,
    ``method``, ``certificate_valid``, ``certificate_verdict``, ``dim``, ``is_empty``,
    ``n_vertices``; null in the rows of another kind), ``seconds`` (wall time of the
    cell), ``rescon_version``.

    scheduler : address of a running Dask scheduler ("tcp://host:8786"); default an
        embedded ``distributed.LocalCluster`` of ``workers`` processes (default: the
        machine's CPU count), one thread each. ``workers=0``: serially in this process.
    out : directory for ``results.parquet`` (resumable); None: nothing written.
    progress : a bar on stderr (default: when stderr is a terminal).

    Raises InputError for a bad grid (:func:`rescon.sweep.grid.read_grid`) and, with
    ``out``, for a seed or integer axis value beyond int64 (before anything is written);
    SolverError when the cluster has had no worker for ``rescon._dask.WORKER_SECONDS``
    (its tasks cannot run; the finished cells stay in ``out`` for a rerun).
    """
    g = read_grid(grid)
    workers = check_workers(scheduler, workers)
    pd = _pandas()
    cells = g.cells()
    as_text = {k for k, values in g.axes.items() if len({type(v) for v in values}) > 1}
    if out is not None:
        _storable(cells, as_text)
    folder = _prepare(out, g) if out is not None else None
    done = _finished(folder) if folder is not None else {}
    todo = [c for c in cells if c["cell"] not in done]
    for row in _bar(_execute(todo, scheduler, workers), len(cells), len(done), progress):
        cell = row.pop("cell")
        done[cell] = {k: _encode(v, k in as_text) for k, v in row.items()}
        if folder is not None and not _lost(done[cell]):
            _write_part(folder, cell, done[cell])
    table = _frame(pd, g, [done[c["cell"]] for c in cells])
    if folder is not None:
        _write(table, folder / "results.parquet")
        _plot(table, g.axes, g.kind, folder)
    return table


def _pandas() -> Any:
    try:
        import pandas as pd
        import pyarrow  # noqa: F401 (the Parquet engine)
    except ImportError:
        raise MissingDependency("rescon sweep needs pandas and pyarrow: install "
                                "rescon[dask]") from None
    return pd


def _execute(cells: list[dict[str, Any]], scheduler: str | None,
             workers: int | None) -> Iterator[dict[str, Any]]:
    """The rows of ``cells`` (each with its "cell" index) as they finish."""
    if not cells:
        return
    if workers == 0:
        for c in cells:
            yield {"cell": c["cell"], **run_cell(c)}
        return
    with client(scheduler, workers) as connected:
        futures = connected.map(run_cell, cells, pure=False)
        index = {f.key: c for f, c in zip(futures, cells, strict=True)}
        watch = Workers(connected)  # no worker for WORKER_SECONDS: SolverError
        for fut in watch.as_completed(futures):
            cell = index[fut.key]
            try:
                row = fut.result()
            except Exception as exc:  # noqa: BLE001 (the workers running it died: KilledWorker)
                row = failed_row(cell, exc)
            yield {"cell": cell["cell"], **row}
            fut.release()


def _prepare(out: str | Path, g: Grid) -> Path:
    """``out`` as a directory holding this grid: created with grid.json when new; a
    directory of another grid (or a file) is refused."""
    from ..io import output_path

    folder = output_path(out, "out", directory=True)
    stamp = folder / "grid.json"
    record = {"sha256": g.digest, "base": g.base, "axes": g.axes,
              "run": {"repetitions": g.repetitions, "epsilon": g.epsilon}}
    if stamp.exists():
        try:
            old = json.loads(stamp.read_text(encoding="utf-8")).get("sha256")
        except (ValueError, AttributeError):
            old = None
        if old != g.digest:
            raise InputError(f"out {folder}: holds the results of another grid (sha256 "
                             f"{str(old)[:12]}…, this grid {g.digest[:12]}…); use another "
                             "directory")
    else:
        stamp.write_text(json.dumps(record, sort_keys=True) + "\n", encoding="utf-8")
    (folder / "parts").mkdir(exist_ok=True)
    return folder


def _storable(cells: list[dict[str, Any]], as_text: set[str]) -> None:
    """Refuse, before any cell runs, a seed or an integer axis value that the table's
    64-bit integer columns cannot hold (a seed 2⁶³ − 1 + repetition, say)."""
    low, high = _INT64
    for c in cells:
        for name, value in (("seed", c["seed"]), *c["params"].items()):
            if (isinstance(value, int) and not isinstance(value, bool)
                    and name not in as_text and not low <= value <= high):
                raise InputError(f"{name} = {value} (cell {c['cell']}, repetition "
                                 f"{c['repetition']}) does not fit the table's 64-bit "
                                 f"integer column [{low}, {high}]")


def _lost(row: Mapping[str, Any]) -> bool:
    """The row of a cell lost to the cluster (:data:`LOST`), not a result."""
    return row.get("status") == "failed" and str(row.get("error")).split(":")[0] in LOST


def _finished(folder: Path) -> dict[int, dict[str, Any]]:
    """The rows already written in ``folder``, by cell index: the parts named
    cell-NNNNNN.parquet that can be read, hold one row and are not :func:`_lost` (the
    others are computed again and their part overwritten)."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    out = {}
    for part in sorted((folder / "parts").glob("cell-*.parquet")):
        match = _PART.fullmatch(part.name)
        if match is None:
            continue
        try:
            rows = pq.read_table(part).to_pylist()
        except (pa.ArrowException, OSError):
            continue
        if len(rows) == 1 and not _lost(rows[0]):
            out[int(match.group(1))] = rows[0]
    return out


def _write_part(folder: Path, cell: int, row: dict[str, Any]) -> None:
    """One finished row as parts/cell-NNNNNN.parquet (written under a temporary name,
    then renamed: an interrupted write leaves no half file behind)."""
    import pyarrow as pa

    _replace(pa.Table.from_pylist([row], schema=_schema(pa, row)),
             folder / "parts" / f"cell-{cell:06d}.parquet")


def _write(table: Any, path: Path) -> None:
    """The table as Parquet with the fixed types of :data:`_DTYPES` (all-null columns
    included: the schema does not depend on the outcomes), written under a temporary
    name and then renamed: an interrupted rerun leaves the previous table, and a reader
    never sees a half-written one."""
    import pyarrow as pa

    schema = _schema(pa, table)
    _replace(pa.Table.from_pandas(table, schema=schema, preserve_index=False), path)


def _replace(arrow_table: Any, path: Path) -> None:
    """Write ``arrow_table`` to path.tmp, then rename it to ``path`` (atomic on POSIX)."""
    import pyarrow.parquet as pq

    tmp = path.with_suffix(".tmp")
    pq.write_table(arrow_table, tmp)
    tmp.replace(path)


def _schema(pa: Any, columns: Any) -> Any:
    """The Arrow schema of a table with ``columns`` (a row or a DataFrame): the types of
    :data:`_DTYPES` for the result columns, the inferred type (of the grid's values)
    for the axes and the seed."""
    fixed = {name: pa.type_for_alias(_ARROW[dtype]) for names, dtype in _DTYPES
             for name in names}
    if isinstance(columns, Mapping):
        inferred = pa.Table.from_pylist([{k: v for k, v in columns.items()
                                          if k not in fixed}]).schema
    else:
        inferred = pa.Schema.from_pandas(columns.drop(columns=list(fixed)),
                                         preserve_index=False)
    types = {f.name: f.type for f in inferred}
    return pa.schema([(name, fixed.get(name) or types[name]) for name in columns])


def _encode(value: Any, as_text: bool = False) -> Any:
    """An axis value as a column entry (a Parquet column has one type): lists and
    tables, and every value of an axis mixing types, as JSON text."""
    if as_text or isinstance(value, (list, dict)):
        return json.dumps(value, sort_keys=True)
    return value


def _frame(pd: Any, g: Grid, rows: list[dict[str, Any]]) -> Any:
    """The rows as a DataFrame with fixed columns and dtypes (nullable integers)."""
    columns = [*g.axes, "repetition", "seed", *METRICS]
    table = pd.DataFrame(rows, columns=columns)
    for names, dtype in _DTYPES:
        for name in names:
            table[name] = table[name].astype(dtype)
    return table


#: column dtypes (nullable integers, booleans and strings: null where a kind or a
#: failed cell does not fill them), the same whatever the cells' outcomes
_DTYPES = ((("steps_to_consensus", "blocked_links", "repetition", "rho", "s_star", "dim",
             "n_vertices"), "Int64"),
           (("final_diameter", "max_validity", "final_gap", "seconds"), "float64"),
           (("exact", "certificate_valid", "is_empty"), "boolean"),
           (("status", "error", "method", "certificate_verdict", "rescon_version"),
            "string"))
#: the Arrow type of each dtype of :data:`_DTYPES` (pandas' own mapping)
_ARROW = {"Int64": "int64", "float64": "double", "boolean": "bool", "string": "large_string"}


def _bar(rows: Iterator[dict[str, Any]], total: int, done: int,
         progress: bool | None) -> Iterator[dict[str, Any]]:
    """``rows`` passed through, with a bar on stderr (:mod:`rescon._progress`: None =
    when stderr is a terminal) counting finished cells, resumed ones included."""
    bar = progress_bar(progress, total, "sweep", unit="cell", initial=done)
    if bar is None:
        yield from rows
        return
    with bar:
        for row in rows:
            bar.update(1)
            yield row


def _panels(table: Any, kind: str) -> tuple[tuple[str, Any], tuple[str, Any]]:
    """The two rows of summary.png for ``kind``: (label, 0/1 per row) whose mean per
    axis value is a rate, and (label, numbers per row, null for failed cells) whose
    mean is plotted."""
    ok = table["status"] == "ok"
    seconds = ("mean seconds (cells ok)", table["seconds"].where(ok))
    if kind == "robustness":
        good = ok & table["exact"].fillna(False) & table["certificate_valid"].fillna(False)
        return ("exact, certificate valid", good), seconds
    if kind == "kernel":
        return ("kernel non-empty", ok & ~table["is_empty"].fillna(True)), seconds
    return (("success rate (ε-consensus)", ok & table["steps_to_consensus"].notna()),
            ("mean steps to ε-consensus", table["steps_to_consensus"]))


def _plot(table: Any, axes: Mapping[str, list[Any]], kind: str, folder: Path) -> None:
    """summary.png: per axis, a rate (consensus: status ok and ε-consensus reached;
    robustness: exact with a valid certificate; kernel: non-empty) and a mean
    (consensus: steps to ε-consensus; robustness, kernel: seconds) against the axis
    values, averaged over the other axes and repetitions (when matplotlib is there)."""
    from ..plot import new_figure

    keys = list(axes) or ["repetition"]
    try:  # its own Agg canvas: the caller's matplotlib backend is left alone
        fig = new_figure(folder / "summary.png", figsize=(4 * len(keys), 6))
    except MissingDependency:
        return  # the table is the result; the plot is optional

    (rate_label, hits), (mean_label, values) = _panels(table, kind)
    values = values.astype("float64")
    ax = fig.subplots(2, len(keys), squeeze=False)
    for j, key in enumerate(keys):
        labels = [str(v) for v in table[key]]
        order = list(dict.fromkeys(labels))
        rows = [[x == v for x in labels] for v in order]
        ticks = range(len(order))  # positions, not categories: a NaN mean keeps its tick
        means = [values[r].mean() for r in rows]
        ax[0, j].bar(ticks, [hits[r].mean() for r in rows])
        ax[0, j].set(ylim=(0, 1), ylabel=rate_label, title=key, xticks=ticks,
                     xticklabels=order)
        ax[1, j].plot(ticks, means, "o-")
        ax[1, j].set(xlabel=key, ylabel=mean_label, xticks=ticks, xticklabels=order,
                     xlim=(-0.5, len(order) - 0.5))
        ax[1, j].set_ylim(bottom=0)  # seconds and steps are never negative
        if all(math.isnan(m) for m in means):
            ax[1, j].text(0.5, 0.5, "no value", ha="center",
                          transform=ax[1, j].transAxes)
        if sum(map(len, order)) > 24:  # long labels side by side would overlap
            for a in ax[:, j]:
                a.tick_params(axis="x", labelrotation=35)
    fig.tight_layout()
    fig.savefig(folder / "summary.png", dpi=120)
