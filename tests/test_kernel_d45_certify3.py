"""The d = 4-5 fast path's modular point keys (issue 13 §3): joggled proposals are
solved once per point (:func:`fastpath._one_per_point`), the keys are the vertices
modulo the prime, a key shared by distinct points loses a vertex that the closure
refuses, and the kernels stay bit-identical to the exact clipping."""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest

import rescon
from rescon.geometry import _certify_nb, fastpath
from rescon.geometry import kernel as km
from rescon.geometry.exact import solve_exact
from tests.test_kernel_d45 import _halfspaces, _primitive_verts
from tests.test_kernel_d45_certify import _reference_vertex
from tests.test_kernel_d45_certify2 import _cell24, _lattice, _ternary
from tests.test_kernels_d45_fast import _cloud, _public

P = _certify_nb.KEY_PRIME


def _key_of(rows: list[list[int]]) -> list[int] | None:
    """y = A⁻¹ b modulo P for the rows (−b, a), exactly (Fractions), or None when
    det A ≡ 0 (mod P)."""
    A = [[Fraction(v) for v in r[1:]] for r in rows]
    det = 1
    M = [row[:] for row in A]  # det by elimination over Q
    for c in range(len(M)):
        p = next((i for i in range(c, len(M)) if M[i][c] != 0), None)
        if p is None:
            return None
        if p != c:
            M[c], M[p] = M[p], M[c]
            det = -det
        det *= M[c][c]
        for i in range(c + 1, len(M)):
            f = M[i][c] / M[c][c]
            M[i] = [x - f * y for x, y in zip(M[i], M[c], strict=True)]
    if int(det) % P == 0:
        return None
    y = solve_exact(A, [Fraction(-r[0]) for r in rows])
    return [v.numerator * pow(v.denominator, -1, P) % P for v in y]


@pytest.mark.parametrize("k", [2, 3, 4, 5])
def test_point_keys_are_the_vertices_modulo_the_prime(k):
    rng = np.random.default_rng(k)
    rows = [[int(v) for v in rng.integers(-2**62, 2**62, size=k + 1)] for _ in range(12)]
    rows += [[v * 3 for v in rows[0]]]  # dependent on row 0
    rows += [[7] + [P if j == 0 else 0 for j in range(k)]]  # a_0 = P: zero mod P only
    rows += [[5] + [int(j == i) for j in range(k)] for i in range(1, k)]  # the other axes
    sets = [list(rng.choice(12, size=k, replace=False)) for _ in range(40)]
    sets += [[0, 12, *range(1, k - 1)]]  # dependent rows: no point
    sets += [[13, *range(14, 13 + k)]]  # det A = P ≠ 0, but ≡ 0 (mod P): no key
    E = np.array([[v % P for v in r] for r in rows], dtype=np.int64)
    at = np.array(sets, dtype=np.int64)
    keys = np.full((len(sets), k), -1, dtype=np.int64)
    ok = _certify_nb.point_keys(E, at, keys)
    for i, T in enumerate(sets):
        want = _key_of([rows[h] for h in T])
        assert ok[i] == (want is not None)
        if want is not None:
            assert keys[i].tolist() == want
    assert not ok[-1] and not ok[-2] and ok[:-2].all()


def _joggled(monkeypatch, X, F):
    """certified_kernel on joggled proposals only, with the proposals it was given and
    the ones it solved recorded."""
    H, hull, _, unit = _halfspaces(X, F)
    first = np.flatnonzero(H.outside == F)
    seen = {}
    one = fastpath._one_per_point

    def spy(H_, Ts, k):
        seen["proposed"], seen["solved"] = Ts, one(H_, Ts, k)
        return seen["solved"]

    monkeypatch.setattr(fastpath, "QHULL_OPTIONS", ("QJ",))
    monkeypatch.setattr(fastpath, "_one_per_point", spy)
    return fastpath.certified_kernel(H, hull.dim, unit, first), seen, H


@pytest.mark.parametrize("X,F", [
    (_cell24(), 3), (_lattice(4, 8), 2), (_ternary(14, 5, 1), 1),
    (np.random.default_rng(3).normal(size=(16, 4)), 2),
])
def test_joggled_pieces_are_solved_once_per_point(X, F, monkeypatch):
    P_, seen, H = _joggled(monkeypatch, X, F)
    assert P_ is not None
    Ts, solved = seen["proposed"], seen["solved"].tolist()
    points = [_reference_vertex(H, T) for T in Ts]
    # the solved proposals are the first of each point (those with dependent rows too)
    firsts = sorted({v: p for p, v in reversed(list(enumerate(points)))}.values())
    assert set(firsts) <= set(solved)
    assert len({points[p] for p in solved if points[p] is not None}) == len(P_.verts)
    assert set(_primitive_verts(P_)) == {v for v in points if v is not None}
    if any(t.bit_count() > P_.k for t in P_.tight):  # non-simple: pieces were merged
        assert len(solved) < len(Ts)
    # the solved ones' exact vertices (primitive, w > 0) are the null spaces
    assert fastpath._solve_all(H, [Ts[p] for p in solved], P_.k) == [points[p] for p in solved]


@pytest.mark.parametrize("X,F", [(_cell24(), 3), (_ternary(14, 5, 1), 1)])
def test_a_key_shared_by_distinct_points_loses_a_vertex_the_closure_refuses(X, F,
                                                                           monkeypatch):
    def one_key(E, at, keys):  # every proposal the same key: one proposal solved
        keys[:] = 0
        return np.ones(len(at), dtype=np.bool_)

    monkeypatch.setattr(_certify_nb, "point_keys", one_key)
    P_, seen, _ = _joggled(monkeypatch, X, F)
    assert len(seen["solved"]) == 1 < len(seen["proposed"])
    assert P_ is None


def _public_both(X, F, monkeypatch) -> tuple[tuple, tuple, list]:
    made = []
    certify = km.certified_kernel
    with monkeypatch.context() as m:
        m.setattr(km, "certified_kernel", lambda *a: made.append(certify(*a)) or made[-1])
        fast = _public(rescon.safe_kernel(X, F))
    with monkeypatch.context() as m:
        m.setattr(km, "certified_kernel", lambda *a: None)
        slow = _public(rescon.safe_kernel(X, F))
    return fast, slow, made


HOSTILE = [
    ("gaussian", 4, 16, 2), ("cube", 4, 16, 1), ("sphere", 4, 16, 3), ("gaussian", 5, 11, 1),
    ("tiny", 4, 14, 2), ("huge", 4, 14, 2), ("converged", 4, 14, 1), ("duplicated", 4, 18, 2),
    ("integers", 4, 18, 2), ("flat", 4, 14, 2), ("gaussian", 4, 5, 0), ("gaussian", 5, 6, 0),
]


@pytest.mark.parametrize("kind,d,n,F", HOSTILE)
@pytest.mark.parametrize("options", [(None, "QJ"), ("QJ",)])
def test_kernels_are_bit_identical_to_exact_clipping(kind, d, n, F, options, monkeypatch):
    """Merged and joggled-only proposals (one solve per point) on hostile clouds:
    magnitudes 1e-300 and 1e300, converged states, duplicates, integer data, flat
    kernels and n = d + 1."""
    monkeypatch.setattr(fastpath, "QHULL_OPTIONS", options)
    fast, slow, _ = _public_both(_cloud(kind, d, n, 7), F, monkeypatch)
    assert fast == slow


@pytest.mark.parametrize("X,F", [
    (_cell24(), 3), (_cell24() * 2.0**-1000, 3), (_lattice(4, 8), 2),
])
def test_very_non_simple_joggled_kernels_are_bit_identical(X, F, monkeypatch):
    monkeypatch.setattr(fastpath, "QHULL_OPTIONS", ("QJ",))
    fast, slow, made = _public_both(X, F, monkeypatch)
    assert fast == slow
    assert made and made[0] is not None


def test_mixed_magnitudes_joggled_are_bit_identical(monkeypatch):
    rng = np.random.default_rng(8)
    X = rng.normal(size=(14, 4)) * 10.0 ** rng.integers(-300, 300, size=(14, 1))
    monkeypatch.setattr(fastpath, "QHULL_OPTIONS", ("QJ",))
    fast, slow, _ = _public_both(X, 1, monkeypatch)
    assert fast == slow


def test_every_proposal_of_a_row_set_reused_gets_one_key():
    """Proposals listing the same rows in another order, or another basis of the same
    point, share its key; a proposal of another point does not."""
    H, hull, _, _ = _halfspaces(_cell24(), 3)
    k = hull.dim
    by_point: dict = {}
    for T in itertools.combinations(range(len(H)), k):
        v = _reference_vertex(H, list(T))
        if v is not None:
            by_point.setdefault(v, []).append(list(T))
        if len(by_point) > 12 and sum(len(ts) > 1 for ts in by_point.values()) > 3:
            break
    Ts = [T for ts in by_point.values() for T in ts] + [list(reversed(T)) for T in
                                                         next(iter(by_point.values()))]
    solved = fastpath._one_per_point(H, Ts, k).tolist()
    assert len(solved) == len(by_point)
    assert {_reference_vertex(H, Ts[p]) for p in solved} == set(by_point)
