"""The keyed pass of the closure at simple vertices (:func:`rescon.geometry._closure.
_simple_ends`) against the scan it replaces: identical verdicts and ends on the tight
sets of real kernels, on tampered ones (vertices dropped, copied, merged, rows removed
or added, fake vertices of k − 1 rows) and with the vertices of more than k rows left
to the scan (KEYED_ROWS = k) or all keyed."""

from __future__ import annotations

import random

import numpy as np
import pytest

from rescon.geometry import _closure
from tests.test_kernel_d45_closure import _kernel_closure, _pyramid


def _both(tight, normals, k, monkeypatch, keyed):
    """combinatorial_rays with the keyed pass (KEYED_ROWS = ``keyed``) and without it."""
    monkeypatch.setattr(_closure, "KEYED_ROWS", keyed)
    with_keys = _closure.combinatorial_rays(tight, normals, k)
    real = _closure._simple_ends
    monkeypatch.setattr(_closure, "_simple_ends", lambda *args: None)
    scanned = _closure.combinatorial_rays(tight, normals, k)
    monkeypatch.setattr(_closure, "_simple_ends", real)
    return with_keys, scanned


def _keyed_count(tight, normals, k, keyed) -> int:
    """How many vertices the keyed pass settles (so that a test shows it ran)."""
    from rescon.geometry.polytope import tight_pairs

    v_of, h_of = tight_pairs(tight)
    v_ptr = np.searchsorted(v_of, np.arange(len(tight) + 1)).astype(np.int64)
    by_row = np.argsort(h_of, kind="stable")
    h_ptr = np.searchsorted(h_of[by_row], np.arange(len(normals) + 1)).astype(np.int64)
    pre = np.zeros(len(tight), dtype=np.bool_)
    ends = np.zeros((len(tight), k), dtype=np.int64)
    _closure._simple_ends(v_ptr, h_of.astype(np.int64), h_ptr,
                          v_of[by_row].astype(np.int64), len(normals), k, keyed, pre, ends)
    return int(pre.sum())


def _tampered(tight: list[int], n_rows: int, rng: random.Random) -> list[int]:
    out = list(tight)
    for _ in range(rng.randint(1, 4)):
        move = rng.randrange(6)
        v = rng.randrange(len(out))
        if move == 0 and len(out) > 2:  # drop a vertex
            del out[v]
        elif move == 1:  # copy one
            out.append(out[v])
        elif move == 2:  # one row less
            bits = [h for h in range(n_rows) if out[v] >> h & 1]
            out[v] &= ~(1 << rng.choice(bits))
        elif move == 3:  # one row more
            out[v] |= 1 << rng.randrange(n_rows)
        elif move == 4:  # a vertex holding two others' rows
            out.append(out[v] | out[rng.randrange(len(out))])
        else:  # a fake vertex on k − 1 rows of another
            bits = [h for h in range(n_rows) if out[v] >> h & 1]
            out.append(sum(1 << h for h in bits[1:]))
    return out


@pytest.mark.parametrize("kind,d,n,F", [("sphere", 4, 30, 1), ("lattice", 4, 27, 4),
                                        ("cube", 5, 16, 1), ("gaussian", 5, 16, 1)])
def test_keyed_pass_equals_the_scan(kind, d, n, F, monkeypatch):
    tight, _, normals, k, _ = _kernel_closure(kind, d, n, F, monkeypatch)
    simple = [v for v, t in enumerate(tight) if t.bit_count() == k]
    assert _keyed_count(tight, normals, k, 12) >= len(simple) // 2
    rng = random.Random(f"{kind}{d}{n}{F}")
    cases = [tight] + [_tampered(tight, len(normals), rng) for _ in range(12)]
    for keyed in (k, 12):
        for case in cases:
            (ok1, ends1), (ok2, ends2) = _both(case, normals, k, monkeypatch, keyed)
            assert ok1.tolist() == ok2.tolist()
            assert ends1 == ends2
    # every real vertex passes, a dropped neighbour fails its simple neighbours
    ok, ends = _both(tight, normals, k, monkeypatch, 12)[0]
    assert ok.all()
    if simple:  # (the lattice's vertices are all non-simple)
        v = simple[len(simple) // 2]
        u = ends[v][0]
        ok, _ = _both(tight[:u] + tight[u + 1:], normals, k, monkeypatch, 12)[0]
        assert not ok[v - (v > u)]


def test_a_fake_vertex_of_k_minus_one_rows_is_an_owner(monkeypatch):
    """The pyramid's corner (1, 1) shares rows {0, 2} with the apex and with a fake
    vertex of those two rows only: two ends on one ray, refused by both."""
    tight, normals = _pyramid()
    for keyed in (3, 12):
        (ok1, _), (ok2, _) = _both([*tight, 0b00101], normals, 3, monkeypatch, keyed)
        assert ok1.tolist() == ok2.tolist() == [False, False, True, True, True, False]


def test_a_vertex_holding_a_simple_ones_rows_is_refused(monkeypatch):
    """A vertex u with T(u) ⊇ T(v) at a simple corner v (a copy with one row more): u
    holds every k − 1 of v's rows, so v has two ends on each ray — refused."""
    tight, normals = _pyramid()
    bad = [*tight, tight[1] | 0b01000]
    (ok1, _), (ok2, _) = _both(bad, normals, 3, monkeypatch, 12)
    assert not ok1[1] and ok1.tolist() == ok2.tolist()
    # u the only owner of each k − 1 of v's rows: only g ∉ T(u) refuses it
    (ok1, _), (ok2, _) = _both([0b0111, 0b1111], normals[:4], 3, monkeypatch, 12)
    assert not ok1[0] and ok1.tolist() == ok2.tolist()
