"""Safe kernels in d = 4-5 (issue 13 §3): the work around the certification — the
facet test, the float rows, the candidate scan, the row maxima and the proposal —
checked against brute force in exact arithmetic and against the exact clipping."""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest

from rescon.geometry import kernel as km
from rescon.geometry.exact import affine_hull, exact_points, nullspace_exact


def _cell24(centres: int = 0) -> np.ndarray:
    """The 24-cell's vertices (±e_i ± e_j; 6 rows tight at each) and ``centres``
    copies of its centre."""
    pts = sorted({tuple(s * (t == i) + u * (t == j) for t in range(4))
                  for i, j in itertools.combinations(range(4), 2)
                  for s in (1, -1) for u in (1, -1)})
    return np.vstack([np.array(pts, dtype=float), np.zeros((centres, 4))])


def _flat_data(seed: int, d: int, n: int) -> np.ndarray:
    """Small integer points whose kernel (for the F of FLAT) is flat in aff X."""
    rng = np.random.default_rng(seed)
    rng.integers(d + 3, 14)
    return rng.integers(-2, 3, size=(n, d)).astype(float)


def _gaussian(d: int, n: int, seed: int = 0) -> np.ndarray:
    return np.random.default_rng([seed, d, n]).normal(size=(n, d))


#: (name, X, F): simple and very non-simple vertices, kernels flat in aff X (dim 1-3)
POLYTOPES = [
    ("gaussian4", _gaussian(4, 18), 2),
    ("gaussian5", _gaussian(5, 12), 1),
    ("cell24", _cell24(4), 4),
    ("lattice", np.array(list(itertools.product((0, 1, 2), repeat=4)), dtype=float), 5),
    ("flat-dim3", _flat_data(77, 4, 7), 1),
    ("flat-dim2", _flat_data(207, 4, 7), 1),
    ("flat-dim1", _flat_data(69, 4, 7), 1),
    ("flat-aff-X", np.column_stack([np.round(3 * _gaussian(3, 20)),
                                    np.zeros(20)]), 2),
]


def _exact_rank(points: list[tuple[Fraction, ...]]) -> int:
    """Affine dimension of exact points (brute force: a Fraction null space)."""
    diffs = [[x - y for x, y in zip(p, points[0], strict=True)] for p in points[1:]]
    return len(points[0]) - len(nullspace_exact(diffs)) if diffs else 0


@pytest.mark.parametrize("fast", [True, False])
@pytest.mark.parametrize("name,X,F", POLYTOPES, ids=[p[0] for p in POLYTOPES])
def test_relative_facets_are_the_faces_of_dimension_dim_minus_one(name, X, F, fast,
                                                                   monkeypatch):
    """The combinatorial facet test (maximal faces by their exact vertex sets) keeps
    exactly the rows whose tight vertices span a (dim − 1)-flat (exact ranks), on the
    fast path's polytope and on the exact clipping's."""
    if not fast:
        monkeypatch.setattr(km, "certified_kernel", lambda *a: None)
    P = exact_points(X)
    hull = affine_hull(P)
    poly = km._clip(P, hull, F)
    verts = poly.fraction_vertices()
    dim = _exact_rank(verts)
    incidence = poly.incidence()
    sizes = {h: len(m) for h, m in incidence.items()}
    want = [h for h, m in sorted(incidence.items())
            if len(m) < len(verts) and _exact_rank([verts[v] for v in m]) == dim - 1]
    assert want
    assert km._relative_facets(poly, incidence, sizes, dim) == want


def _exact_matrix_rank(rows: list[list[int]]) -> int:
    if not rows:
        return 0
    return len(rows[0]) - len(nullspace_exact([[Fraction(v) for v in r] for r in rows]))


@pytest.mark.parametrize("seed", range(40))
def test_rank_mod_p_bounds_the_exact_rank_and_equals_it_off_multiples_of_p(seed):
    """The rank modulo p never exceeds the exact rank; it equals it when no minor is a
    multiple of p — and a matrix whose full minors are all multiples of p has a
    smaller rank modulo p than over the integers."""
    from rescon.geometry.polytope import PRIME, _rank_mod

    rng = np.random.default_rng(seed)
    m, k = int(rng.integers(1, 7)), int(rng.integers(1, 6))
    B = rng.integers(-3, 4, size=(m, k)).tolist()
    rows = [[v * 2**int(rng.integers(0, 400)) + int(rng.integers(0, 2)) * PRIME * 3**200
             for v in r] for r in B]
    assert _rank_mod(rows, PRIME) <= _exact_matrix_rank(rows)
    assert _rank_mod(B, PRIME) == _exact_matrix_rank(B)
    scaled = [[PRIME * v for v in B[0]], *B[1:]]  # its first row ≡ 0 modulo p
    assert _rank_mod(scaled, PRIME) == _exact_matrix_rank(B[1:])
    assert _exact_matrix_rank(scaled) == _exact_matrix_rank(B)


def test_dim_gets_the_exact_rank_when_it_drops_only_modulo_p():
    """Vertices whose floats cannot certify their rank (offset 2^60: the differences
    round away) and whose only full minor is p: the rank modulo p is 1, the
    dimension is 2 (exact elimination decides); without the factor p the rank
    modulo p already proves 2."""
    from rescon.geometry.polytope import PRIME, ExactPolytope

    M = 2**60
    for step, want in ((PRIME, 2), (PRIME + 1, 2), (0, 1)):
        P = ExactPolytope(2)
        P.verts = [(1, M, M), (1, M + step, M), (1, M - 512, M + (step != 0))]
        P.tight = [0, 0, 0]
        assert P.dim() == want


@pytest.mark.parametrize("seed", range(6))
def test_selection_partitions_at_the_median_with_ties(seed):
    from rescon.geometry._candidates import _select

    rng = np.random.default_rng(seed)
    key = np.round(rng.normal(size=200) * (1 + 3 * (seed % 2)))  # many ties
    order = rng.permutation(200)
    lo, hi = int(rng.integers(0, 50)), int(rng.integers(150, 201))
    mid = int(rng.integers(lo, hi))
    before = order.copy()
    _select(key, order, lo, hi, mid)
    assert sorted(order[lo:hi].tolist()) == sorted(before[lo:hi].tolist())
    assert np.array_equal(order[:lo], before[:lo]) and np.array_equal(order[hi:], before[hi:])
    assert key[order[mid]] == np.sort(key[before[lo:hi]])[mid - lo]
    assert key[order[lo:mid]].max(initial=-np.inf) <= key[order[mid]]
    assert key[order[mid:hi]].min() >= key[order[mid]]


@pytest.mark.parametrize("n,k,leaf", [(1, 4, 32), (33, 5, 32), (3000, 4, 32), (500, 5, 8)])
def test_ball_chunks_are_small_and_cover_their_points_with_repeats(n, k, leaf):
    from rescon.geometry._candidates import ball_chunks

    V = np.round(np.random.default_rng(n).normal(size=(n, k)), 1)  # repeated coordinates
    V[: n // 3] = V[0]  # a third of the points equal
    order, starts, centres, radii = ball_chunks(V, leaf)
    assert sorted(order.tolist()) == list(range(n))
    assert np.all(np.diff(starts) >= 1) and np.all(np.diff(starts) <= leaf)
    for c in range(len(starts) - 1):
        P = V[order[starts[c]:starts[c + 1]]]
        assert np.linalg.norm(P - centres[c], axis=1).max() <= radii[c] * (1 + 1e-12)


def _hostile(kind: str, d: int, n: int) -> np.ndarray:
    Z = _gaussian(d, n, 5)
    return {
        "tiny": lambda: Z * 1e-300,
        "huge": lambda: Z * 1e300,
        "mixed": lambda: Z * 10.0 ** np.random.default_rng(n).integers(-300, 300, size=(n, 1)),
        "converged": lambda: 1.0 + 1e-15 * np.round(4 * Z),
        "duplicated": lambda: np.vstack([Z[: n - 4], Z[:4]]),
        "integer": lambda: np.round(3 * Z),
        "flat": lambda: np.column_stack([np.round(3 * Z[:, :-1]), np.zeros(n)]),
        "simplex": lambda: Z[: d + 1],
        "cell24": lambda: _cell24(4) * 3.0 + 1.0,
    }[kind]()


HOSTILE = [("tiny", 4, 20, 2), ("huge", 4, 20, 2), ("mixed", 4, 18, 1), ("converged", 4, 20, 2),
           ("duplicated", 4, 22, 2), ("integer", 4, 20, 2), ("flat", 4, 24, 2),
           ("simplex", 4, 5, 0), ("cell24", 4, 28, 4), ("tiny", 5, 12, 1),
           ("converged", 5, 12, 1), ("integer", 5, 13, 1)]


@pytest.mark.parametrize("kind,d,n,F", HOSTILE, ids=[f"{h[0]}-{h[1]}" for h in HOSTILE])
def test_kernels_identical_to_the_exact_clipping_on_hostile_data(kind, d, n, F, monkeypatch):
    """Every output — floats bit for bit, exact vertices and rows, certificate — equals
    the exact clipping's (fast path off) at extreme magnitudes, converged and repeated
    points, integers, flat data, n = d + 1 and the 24-cell's non-simple vertices."""

    from tests.test_kernel_d45_around2 import _same_as_clipping

    _same_as_clipping(_hostile(kind, d, n), F, monkeypatch)


@pytest.mark.parametrize("seed", range(3))
def test_near_pairs_with_rows_near_many_points_equal_brute_force(seed):
    """Rows with more near points than the counting pass keeps (NEAR_KEPT) are scanned
    again; every pair is found, in the order of the rows (brute force: every slack)."""
    from rescon.geometry._candidates import NEAR_KEPT, near_pairs

    rng = np.random.default_rng(seed)
    k, nv = 4, 900
    V = rng.uniform(-1.0, 1.0, size=(nv, k))
    V[: 3 * NEAR_KEPT, 0] = 2.0  # on the hyperplane x_0 = 2 of row 0
    V[NEAR_KEPT // 2: NEAR_KEPT, 1] = 3.0  # a few on x_1 = 3 (row 1) too
    A = rng.normal(size=(40, k))
    A[0], A[1] = [1, 0, 0, 0], [0, 1, 0, 0]
    b = (A @ V.T).max(axis=1) + rng.uniform(0.0, 2.0, 40)
    b[:2] = [2.0, 3.0]
    b[2::5] = (A[2::5] @ V.T).max(axis=1)  # rows touching their highest point
    A_abs, b_abs = np.abs(A) * 1.01, np.abs(b) * 1.01
    c_err, c = 1e-12, 32 * 2.0**-53
    M = np.abs(V).max()
    coarse = c_err * (A_abs.sum(axis=1) * M + b_abs) + c * (np.abs(A).sum(axis=1) * M + np.abs(b))
    S = A @ V.T - b[:, None]
    bound = c_err * (A_abs @ np.abs(V).T + b_abs[:, None]) + c * (
        np.abs(A) @ np.abs(V).T + np.abs(b)[:, None])
    assert not (S > np.minimum(bound, coarse[:, None])).any()
    want_r, want_v = np.nonzero((np.abs(S) <= coarse[:, None]) & ~(np.abs(S) > bound))
    got_r, got_v = near_pairs(A, b, A_abs, b_abs, V, coarse, c_err, c, 0.0)
    assert np.bincount(want_r)[0] == 3 * NEAR_KEPT
    assert got_r.tolist() == want_r.tolist()  # by row
    assert sorted(zip(got_r.tolist(), got_v.tolist())) == list(zip(want_r.tolist(),
                                                                    want_v.tolist()))
