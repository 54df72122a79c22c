"""The fast path's exact vertices, solved when first read.

The certification reads the exact homogeneous vertices (w, y) only where its float
filters cannot decide (equal correctly rounded floats, undecided (row, vertex) pairs);
the floats themselves are proven correctly rounded without them
(:mod:`._vertex_floats`). :class:`LazyVertices` holds, per vertex, the k rows it is
solved from and solves a vertex the first time it is read — exactly as the eager solve
(:func:`.fastpath._solve_rows` of the same rows: the same integers, not reduced by their
gcd), so every reader sees what it saw before. What it keeps until then is small: the
exact rows (a, b) of the defining halfspaces S, their data points and the data points
(not the scan's table of valid halfspaces)."""

from __future__ import annotations

import threading
from collections.abc import Iterator, Sequence
from typing import Any

import numpy as np


class RowsOf:
    """The part of the valid halfspaces H that :func:`.fastpath._solve_rows` reads,
    for the rows S alone (renumbered 0, 1, … in S's order): ``exact``, ``through``,
    ``Yi``."""

    def __init__(self, a: list[tuple[int, ...]], b: list[int], through: np.ndarray,
                 Yi: list[tuple[int, ...]]) -> None:
        self.a, self.b = list(a), list(b)
        self.through = np.ascontiguousarray(through, dtype=np.int64)
        self.Yi = Yi

    def exact(self, i: int) -> tuple[tuple[int, ...], int]:
        return self.a[i], self.b[i]


class LazyVertices(Sequence):
    """A sequence of homogeneous vertices (w, y) (tuples of Python ints), vertex i the
    point where the rows ``basis[i]`` (positions in ``rows``, a :class:`RowsOf`) meet,
    solved on first read (``known``: those already solved, by index). Indexing with an
    integer gives a tuple (all unsolved vertices are then solved at once: a reader of
    one usually reads them all); with an integer array, an object array (m, k + 1) of
    those rows (only they are solved) — so it also serves where the rows were an object
    array. Thread-safe: the solves run under a lock, and a vertex, once stored, never
    changes. Pickles as a plain list."""

    def __init__(self, rows: RowsOf | None, basis: np.ndarray, k: int,
                 known: dict[int, tuple[int, ...]] | None = None) -> None:
        self._basis = np.asarray(basis, dtype=np.int64).reshape(-1, k)
        self._k = k
        self._known: dict[int, tuple[int, ...]] = dict(known or {})
        # the rows are kept only while a vertex is left to solve
        self._rows = rows if len(self._known) < len(self._basis) else None
        self._lock = threading.Lock()

    def __len__(self) -> int:
        return len(self._basis)

    def _solve(self, ids: list[int]) -> None:
        from .fastpath import _solve_rows

        with self._lock:
            todo = [i for i in dict.fromkeys(ids) if i not in self._known]
            if not todo:
                return
            X = _solve_rows(self._rows, self._basis[todo], self._k)
            for i, row in zip(todo, X.tolist(), strict=True):
                self._known[i] = tuple(row)
            if len(self._known) == len(self._basis):
                self._rows = None  # all solved: the rows are no longer needed

    def select(self, ids: np.ndarray) -> LazyVertices:
        """The vertices ``ids`` (in that order) as a new sequence, sharing what is
        solved."""
        ids = np.asarray(ids, dtype=np.int64)
        known = {j: self._known[i] for j, i in enumerate(ids.tolist()) if i in self._known}
        return LazyVertices(self._rows, self._basis[ids], self._k, known)

    def __getitem__(self, i: Any) -> Any:
        if isinstance(i, (int, np.integer)):
            i = int(i)
            if i < 0:
                i += len(self)
            if not 0 <= i < len(self):
                raise IndexError(i)
            if i not in self._known:
                self._solve(list(range(len(self))))
            return self._known[i]
        if isinstance(i, slice):
            return self.tolist()[i]
        ids = np.arange(len(self))[np.asarray(i)].ravel().tolist()
        self._solve(ids)
        out = np.empty((len(ids), self._k + 1), dtype=object)
        if ids:
            out[:] = [self._known[j] for j in ids]
        return out

    def tolist(self) -> list[tuple[int, ...]]:
        self._solve(list(range(len(self))))
        return [self._known[i] for i in range(len(self))]

    def __iter__(self) -> Iterator[tuple[int, ...]]:
        return iter(self.tolist())

    def __eq__(self, other: object) -> bool:
        if isinstance(other, (LazyVertices, list, tuple)):
            return self.tolist() == list(other)
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"LazyVertices({len(self)} vertices, {len(self._known)} solved)"

    def __reduce__(self) -> tuple[Any, ...]:
        return list, (self.tolist(),)
