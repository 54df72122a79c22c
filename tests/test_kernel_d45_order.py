"""Issue 13 §3 (session 12, K15): the facets' order decided on integers where floats tie,
and the scan's k-subset table kept between kernels — each against the path it replaces."""

from __future__ import annotations

from fractions import Fraction
from types import SimpleNamespace

import numpy as np
import pytest

import rescon
import rescon.geometry.halfspaces as hm
import rescon.geometry.kernel as km
from benchmarks.kernel_clouds import make_cloud
from rescon.geometry._candidates import k_subsets


def _tied_rows(seed: int, d: int = 4, n: int = 120) -> list[tuple[int, ...]]:
    """Integer rows whose directions a / max|a_j| tie in floats: entries ±top (exact ±1,
    in every column), entries a ulp below top (2^80 − 1 over 2^80: float 1.0, not 1),
    equal directions at different scales, and plain ones."""
    rng = np.random.default_rng(seed)
    top = 2**80
    rows = []
    for _ in range(n):
        kind = int(rng.integers(0, 4))
        a = [int(v) * 2**78 for v in rng.integers(-3, 4, size=d)]
        j = int(rng.integers(0, d))
        if kind == 0:  # an exact ±1 entry
            a[j] = top * int(rng.choice([-1, 1]))
        elif kind == 1:  # rounds to ±1.0 but is not ±1
            a[j] = (top - int(rng.integers(1, 3))) * int(rng.choice([-1, 1]))
            a[(j + 1) % d] = top
        elif kind == 2:  # an equal direction at another scale
            a = [v * int(rng.integers(2, 5)) for v in rows[-1]] if rows else a
        if not any(a):
            a[0] = top
        rows.append(tuple(a))
    return rows


@pytest.mark.parametrize("seed", range(6))
def test_facet_order_on_integers_is_the_exact_order(seed):
    """_facet_order (ties of equal floats decided as a_i·t_0 = a_0·t_i) returns what the
    Fraction path returns (:func:`.kernel._lex_order` without ``equal``), which is the
    exact lexicographic order of the directions (stable for equal ones)."""
    d = 4
    rows = _tied_rows(seed, d)
    poly = SimpleNamespace(a=rows)
    hull = SimpleNamespace(coords=tuple(range(d)))
    ids = list(range(len(rows)))
    got, D, tops = km._facet_order(poly, hull, ids, d)
    exact = [tuple(Fraction(v, max(map(abs, a))) for v in a) for a in rows]
    D0 = np.array([[float(v) for v in x] for x in exact])
    assert np.array_equal(D0, np.array([[v / max(map(abs, a)) for v in a] for a in rows]))
    assert got == km._lex_order(D0, exact.__getitem__)  # the path it replaces
    assert got == sorted(ids, key=exact.__getitem__)
    assert np.array_equal(D, D0[got])
    assert tops == [max(map(abs, rows[i])) for i in got]


def test_subset_table_is_kept_and_read_only_by_its_readers(monkeypatch):
    """The scan's k-subset table is built once per (m, k) and left unchanged by the
    kernels that read it (each kernel is the one computed on a fresh table); tables
    beyond SUBSET_CACHE_ROWS are not kept, and at most 4 are."""
    monkeypatch.setattr(hm, "_SUBSET_TABLES", {})
    X = make_cloud("sphere", 4, 30, 3).X
    first = rescon.safe_kernel(X, 3)
    table = hm._SUBSET_TABLES[(30, 4)]
    kept = table.copy()
    assert np.array_equal(table, k_subsets(30, 4, len(table)))
    again = rescon.safe_kernel(X, 3)
    assert hm._SUBSET_TABLES[(30, 4)] is table and np.array_equal(table, kept)
    assert again.certificate == first.certificate
    assert again.exact_vertices == first.exact_vertices
    for m in range(31, 36):
        hm._all_subsets(m, 4, len(k_subsets(m, 4, 10**6)))
    assert len(hm._SUBSET_TABLES) == 4 and (30, 4) not in hm._SUBSET_TABLES
    monkeypatch.setattr(hm, "SUBSET_CACHE_ROWS", 10)
    hm._all_subsets(12, 3, 220)
    assert (12, 3) not in hm._SUBSET_TABLES


@pytest.mark.parametrize("seed", range(4))
def test_margin_lp_row_selection_is_the_stable_sort_prefix(seed):
    """_lp._smallest (a partition, then a stable sort of the entries up to the m-th
    value) is np.argsort(v, kind="stable")[:m], ties by index, with NaN, ±inf and ±0."""
    from rescon.geometry._lp import _smallest

    rng = np.random.default_rng(seed)
    for t in range(400):
        n, m = int(rng.integers(0, 200)), int(rng.integers(1, 60))
        v = (rng.integers(-4, 4, size=n).astype(float) if t % 2 else rng.normal(size=n))
        for special in (np.nan, np.inf, -np.inf, -0.0, 0.0):
            if n and rng.random() < 0.3:
                v[rng.integers(0, n, size=max(1, n // 5))] = special
        assert np.array_equal(_smallest(v, m), np.argsort(v, kind="stable")[:m])
