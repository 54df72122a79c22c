"""Safe kernels in d = 4-5 (issue 13 §3): the fast path's vertices as they are solved
(``fastpath._solve_rows``, not reduced by their gcd) and the merging of equal points
on their correctly rounded floats (``fastpath._distinct_points``), against Fraction
brute forces and the exact clipping."""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest

from rescon.geometry import fastpath
from tests.test_kernel_d45 import _both_paths, _halfspaces, _primitive_verts
from tests.test_kernel_d45_around2 import _cloud
from tests.test_kernel_d45_review7 import _same_polytope
from tests.test_kernel_d45_solve import HOSTILE, _brute, _row_sets


def _point(row) -> tuple[Fraction, ...]:
    return tuple(Fraction(y, row[0]) for y in row[1:])


def _floats(W: np.ndarray, unit: int = 1) -> np.ndarray:
    return (W[:, 1:] / (W[:, :1] * unit)).astype(np.float64)


def _check_distinct(rows: list[tuple[int, ...]], unit: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """_distinct_points against grouping the exact points (Fractions), numbered in
    order of first appearance."""
    W = np.empty((len(rows), len(rows[0])), dtype=object)
    W[:] = rows
    of_row, firsts = fastpath._distinct_points(W, _floats(W, unit))
    number: dict[tuple[Fraction, ...], int] = {}
    want = [number.setdefault(_point(r), len(number)) for r in rows]
    assert of_row.tolist() == want
    assert firsts.tolist() == [want.index(j) for j in range(len(number))]
    return of_row, firsts


def test_distinct_points_merges_multiples_and_splits_float_twins():
    """Positive multiples of one point are one point; points closer than the floats
    resolve (1 and 1 + 10⁻⁴⁰ round alike) stay apart, whichever comes first."""
    big = 10**40
    rows = [(1, 1, 0, 0, 0), (3, 3, 0, 0, 0), (big, big + 1, 0, 0, 0),
            (2 * big, 2 * big + 2, 0, 0, 0), (7, 0, 7, 0, -7), (big, big - 1, 0, 0, 0),
            (5, 5, 0, 0, 0), (1, 0, 1, 0, -1)]
    assert len({_floats(np.array([r], dtype=object)).tobytes() for r in rows[:4]}) == 1
    of_row, _ = _check_distinct(rows)
    assert of_row.tolist() == [0, 0, 1, 1, 2, 3, 0, 2]
    _check_distinct(rows[::-1])


@pytest.mark.parametrize("seed", range(6))
def test_distinct_points_random_multiples_and_twins(seed):
    """Random points, each repeated at random positive multiples, some with twins
    that differ below the float resolution (and signed zeros: y = 0 · w)."""
    rng = np.random.default_rng(seed)
    base = []
    for _ in range(12):
        w = int(rng.integers(1, 10**6)) * 10**30
        y = [int(v) for v in rng.integers(-10**6, 10**6, size=4)]
        base.append((w, *(v * 10**30 for v in y)))
        if rng.random() < 0.5:
            base.append((w, y[0] * 10**30 + 1, *(v * 10**30 for v in y[1:])))
        if rng.random() < 0.3:
            base.append((w, 0, 0, 0, 0))
    rows = [tuple(int(m) * v for v in base[int(i)])
            for i, m in zip(rng.integers(len(base), size=60), rng.integers(1, 50, size=60),
                            strict=True)]
    _check_distinct(rows, unit=int(rng.choice([1, 2**40])))


@pytest.mark.parametrize("kind,d,n,F", HOSTILE)
def test_solve_rows_are_positive_multiples_of_the_point(kind, d, n, F):
    """Each row of _solve_rows spans the null space of E_T with w > 0 (a positive
    multiple of the primitive brute-force point), or has w = 0 where the rows do not
    meet in one point; _solve_all is its primitive form."""
    H, hull, _, _ = _halfspaces(_cloud(kind, d, n, F), F)
    Ts = _row_sets(H, hull.dim, 25, seed=n)
    X = fastpath._solve_rows(H, Ts, hull.dim)
    for row, T in zip(X.tolist(), Ts, strict=True):
        want = _brute(H, T)
        if want is None:
            assert row[0] == 0
            continue
        assert row[0] > 0 and row[0] % want[0] == 0
        m = row[0] // want[0]
        assert list(row) == [m * v for v in want]
    assert fastpath._solve_all(H, Ts, hull.dim) == [_brute(H, T) for T in Ts]


@pytest.mark.parametrize("kind,d,n,F", [("gaussian", 4, 20, 1), ("integer", 4, 14, 2),
                                        ("huge", 4, 14, 1), ("converged", 4, 20, 2),
                                        ("gaussian", 5, 12, 1)])
def test_repeated_proposals_are_one_vertex(kind, d, n, F):
    """Every proposal listed twice, the second time with its rows reversed (the same
    point, solved through other pairs of rows: another multiple): the polytope is the
    honest one, and the exact clipping's."""
    _, slow, H, unit, first = _both_paths(_cloud(kind, d, n, F), F)
    _, facets = fastpath._propose(H, first)
    honest = fastpath._certify(H, d, unit, first, facets)
    assert honest is not None
    twice = fastpath._certify(H, d, unit, first, facets + [f[::-1] for f in facets])
    assert twice is not None and _same_polytope(twice, honest)
    assert set(_primitive_verts(twice)) == set(slow.verts)


@pytest.mark.parametrize("p", [2, 3, 2_147_483_647])
def test_nonsingular_modulo_a_prime_is_the_determinants_residue(p):
    """_certify_nb.nonsingular against the exact determinant modulo p (and _det_mod,
    its numpy reference), on random integer matrices with repeated and combined rows
    (singular over ℚ) and entries that are multiples of p."""
    from rescon.geometry._certify_nb import nonsingular
    from rescon.geometry.halfspaces import _int_det

    rng = np.random.default_rng(p)
    for k in (3, 4, 5):
        rows = [[int(v) for v in rng.integers(-5, 6, size=k)] for _ in range(12)]
        rows += [[3 * a + b for a, b in zip(rows[0], rows[1], strict=True)], rows[2][:],
                 [p * int(v) for v in rng.integers(-3, 4, size=k)]]
        at = np.array([rng.choice(len(rows), size=k, replace=False) for _ in range(300)]
                      + [[len(rows) - 3, 0, 1, *range(3, k)][:k],
                         [len(rows) - 2, 2, *range(4, k + 2)][:k]], dtype=np.int64)
        A = np.array([[v % p for v in r] for r in rows], dtype=np.int64)
        got = nonsingular(A, at, p).tolist()
        want = [_int_det([rows[i] for i in T]) % p != 0 for T in at.tolist()]
        assert got == want == (fastpath._det_mod(A[at], p) != 0).tolist()
        assert not all(want) and any(want)


def _tight_through_brute(through, basis, h, v) -> bool:
    """The rule of _certify_nb.tight_through, on Python sets."""
    rows = [set(through[g]) for g in basis[v]]
    k = len(rows)
    for r in range(1, k + 1):
        for G in itertools.combinations(range(k), r):
            common = set.intersection(*(rows[a] for a in G))
            if len(common) == k - r + 1 and common <= set(through[h]):
                return True
    return False


def test_tight_through_needs_enough_common_points():
    """k = 3: rows 0, 1 share only point 0 (one point does not fix their line), so a
    row through point 0 and two others is not proven tight at their vertex with row 2;
    rows 0, 3 share points 0, 1 (their line), and a row through 0, 1 is; the three
    rows 0, 4, 5 meet at point 0 (their vertex), and a row through it is."""
    from rescon.geometry._certify_nb import tight_through

    through = np.array([[0, 1, 2], [0, 3, 4], [5, 6, 7], [0, 1, 8], [0, 9, 10],
                        [0, 11, 12], [0, 13, 14], [1, 0, 15], [1, 2, 16]], dtype=np.int64)
    basis = np.array([[0, 1, 2], [0, 3, 2], [0, 4, 5]], dtype=np.int64)
    hs = np.array([6, 6, 7, 8, 6, 8], dtype=np.int64)
    vs = np.array([0, 1, 1, 1, 2, 2], dtype=np.int64)
    got = tight_through(through, basis, hs, vs).tolist()
    assert got == [False, False, True, False, True, False]
    assert got == [_tight_through_brute(through.tolist(), basis.tolist(), h, v)
                   for h, v in zip(hs.tolist(), vs.tolist(), strict=True)]


@pytest.mark.parametrize("kind,d,n,F", [("gaussian", 4, 14, 1), ("integer", 4, 14, 2),
                                        ("lattice", 4, 30, 2), ("cell24", 4, 28, 4),
                                        ("huge", 4, 14, 1), ("gaussian", 5, 10, 1),
                                        ("integer", 5, 10, 1), ("gaussian", 3, 12, 2)])
def test_tight_through_is_sound(kind, d, n, F):
    """Pairs (row, vertex) proven tight by the rows' data points have exact slack 0 —
    on the vertices of random bases and the rows sharing points with them (many proven,
    the others checked too: the brute-force rule agrees on every pair)."""
    from rescon.geometry._certify_nb import tight_through

    H, hull, _, _ = _halfspaces(_cloud(kind, d, n, F), F)
    k = hull.dim
    Ts = [T for T in _row_sets(H, k, 40, seed=n) if len(set(T)) == k]
    X = fastpath._solve_rows(H, Ts, k)
    keep = [i for i, w in enumerate(X[:, 0].tolist()) if w != 0]
    basis = np.array([Ts[i] for i in keep], dtype=np.int64)
    through = np.ascontiguousarray(H.through, dtype=np.int64)
    rng = np.random.default_rng(n)
    hs, vs = [], []
    for v in range(len(keep)):
        pts = set(through[basis[v]].ravel().tolist())
        near = [h for h in range(len(H)) if len(pts & set(through[h].tolist())) >= k - 1]
        hs += near + rng.integers(len(H), size=5).tolist()
        vs += [v] * (len(near) + 5)
    hs_a, vs_a = np.array(hs, dtype=np.int64), np.array(vs, dtype=np.int64)
    got = tight_through(through, basis, hs_a, vs_a)
    assert got.sum() > len(keep)
    want = [_tight_through_brute(through.tolist(), basis.tolist(), h, v)
            for h, v in zip(hs, vs, strict=True)]
    assert got.tolist() == want
    W = X[keep]
    H.exact_all(sorted(set(hs)))
    for h, v in zip(hs_a[got].tolist(), vs_a[got].tolist(), strict=True):
        a, b = H.exact(h)
        assert sum(ai * yi for ai, yi in zip(a, W[v, 1:].tolist(), strict=True)) == b * W[v, 0]
