"""The d = 4-5 speed-ups of the safe kernel keep every answer bit-identical (issue 13
§3): the chunked float filters against brute force, the float-then-exact orders
against exact sorting, the simple-vertex facet rule against exact ranks, the lazily
built exact vertices, and whole kernels against the exact clipping path (the fast
path switched off) on the benchmark families and hostile inputs."""

from __future__ import annotations

import pickle
from fractions import Fraction

import numpy as np
import pytest

import rescon
from rescon.geometry import kernel as km
from rescon.geometry._candidates import ball_chunks, near_pairs, row_top
from rescon.geometry.exact import nullspace_exact

EPS = 2.0**-53


def _cloud(kind: str, d: int, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng([seed, d, n])
    Z = rng.normal(size=(n, d))
    return {
        "gaussian": lambda: Z,
        "cube": lambda: rng.uniform(-1, 1, size=(n, d)),
        "sphere": lambda: Z / np.linalg.norm(Z, axis=1)[:, None],
        "tiny": lambda: Z * 1e-300,
        "huge": lambda: Z * 1e300,
        "converged": lambda: np.vstack([0.3 + 1e-9 * Z[: n - 2], 5.0 * Z[n - 2:]]),
        "duplicated": lambda: np.vstack([Z[: n // 2], Z[: n - n // 2]]),
        "integers": lambda: np.round(8 * Z),
        "flat": lambda: np.column_stack([Z[:, :-1], np.full(n, 0.75)]),
    }[kind]()


def _public(K) -> tuple:
    """Everything a caller can read from a kernel, floats as bytes."""
    return (K.dim, K.exact_vertices, K._exact.constraints, K._exact.facets,
            K._exact.kernel_eqs, K.vertices.tobytes(), K.A.tobytes(), K.b.tobytes(),
            K.Aeq.tobytes(), K.beq.tobytes(), K.affine_basis.tobytes(),
            None if K.affine_origin is None else K.affine_origin.tobytes(),
            K.certificate["adjacency"], K.certificate["facets"])


@pytest.mark.parametrize("kind,d,n,F", [
    ("gaussian", 4, 18, 2), ("cube", 4, 16, 1), ("sphere", 4, 18, 3), ("gaussian", 5, 12, 1),
    ("tiny", 4, 16, 2), ("huge", 4, 16, 2), ("converged", 4, 16, 1),
    ("duplicated", 4, 18, 2), ("integers", 4, 18, 2), ("flat", 4, 16, 2),
])
def test_fast_path_answers_are_bit_identical_to_exact_clipping(kind, d, n, F, monkeypatch):
    X = _cloud(kind, d, n, 5)
    fast = rescon.safe_kernel(X, F)
    monkeypatch.setattr(km, "certified_kernel", lambda *a: None)
    slow = rescon.safe_kernel(X, F)
    assert _public(fast) == _public(slow)


def _brute_pairs(A, b, A_abs, b_abs, V, coarse, c_err, c, floor):
    """The reference: every (row, point) slack in floats, the same tests."""
    S = A @ V.T - b[:, None]
    if (S > coarse[:, None]).any():
        return None
    bound = c_err * (A_abs @ np.abs(V).T + b_abs[:, None]) + c * (
        np.abs(A) @ np.abs(V).T + np.abs(b)[:, None]) + floor
    if ((np.abs(S) <= coarse[:, None]) & (S > bound)).any():
        return None
    r, v = np.nonzero((np.abs(S) <= coarse[:, None]) & ~(np.abs(S) > bound))
    return set(zip(r.tolist(), v.tolist(), strict=True))


@pytest.mark.parametrize("seed", range(6))
def test_near_pairs_equal_brute_force(seed):
    """Points placed on some rows (exactly up to rounding) are found near; chunks of
    points far from a row are skipped without losing a pair; a violated row is None."""
    rng = np.random.default_rng(seed)
    k, m, nv = 4, 60, 700
    V = rng.normal(size=(nv, k)) * 10.0 ** rng.integers(-2, 2)
    A = rng.normal(size=(m, k))
    best = (A @ V.T).max(axis=1)
    b = best + rng.uniform(0.0, 3.0, m)  # every row holds
    b[::3] = best[::3]  # a third of the rows touch their highest point
    A_abs = np.abs(A) * 1.01
    b_abs = np.abs(b) * 1.01
    c_err, c = 1e-12, 16 * EPS
    coarse = c_err * (A_abs.sum(axis=1) * np.abs(V).max() + b_abs) + c * (
        np.abs(A).sum(axis=1) * np.abs(V).max() + np.abs(b))
    got = near_pairs(A, b, A_abs, b_abs, V, coarse, c_err, c, 0.0)
    want = _brute_pairs(A, b, A_abs, b_abs, V, coarse, c_err, c, 0.0)
    assert want is not None and len(want) >= m // 3
    assert got is not None
    assert set(zip(got[0].tolist(), got[1].tolist(), strict=True)) == want
    b[7] = best[7] - 1e-6 * np.abs(V).max()  # row 7 now cuts off a point
    assert near_pairs(A, b, A_abs, b_abs, V, coarse, c_err, c, 0.0) is None


@pytest.mark.parametrize("seed", range(4))
def test_row_top_bounds_the_maximum_and_is_it_where_nonnegative(seed):
    rng = np.random.default_rng(seed)
    V = rng.normal(size=(900, 5))
    A = rng.normal(size=(300, 5))
    best = (A @ V.T).max(axis=1)
    b = best + rng.normal(size=300)  # about half the rows are violated somewhere
    top = row_top(A, b, V, 0.0)
    want = best - b
    scale = np.abs(A) @ np.abs(V).max(axis=0) + np.abs(b)
    assert np.all(top >= want - 1e-14 * scale)
    reach = want >= 0
    assert reach.sum() > 50
    assert np.allclose(top[reach], want[reach], rtol=0, atol=1e-14 * scale.max())


def test_ball_chunks_cover_every_point_within_their_radius():
    V = np.random.default_rng(1).normal(size=(1000, 4))
    order, starts, centres, radii = ball_chunks(V, leaf=16)
    assert sorted(order.tolist()) == list(range(1000))
    assert np.all(np.diff(starts) <= 16)
    for c in range(len(starts) - 1):
        P = V[order[starts[c]:starts[c + 1]]]
        assert np.linalg.norm(P - centres[c], axis=1).max() <= radii[c] * (1 + 1e-12)


def test_lex_order_is_the_exact_lexicographic_order():
    """Points whose first floats tie (Fractions closer than an ulp) are ordered
    exactly; the others by their floats."""
    rng = np.random.default_rng(3)
    tiny = Fraction(1, 2**70)
    pts = []
    for _ in range(300):
        base = Fraction(int(rng.integers(0, 4)), 4)
        pts.append((base + int(rng.integers(-3, 4)) * tiny,
                    Fraction(int(rng.integers(-50, 50)), 7), Fraction(int(rng.integers(0, 3)))))
    V = np.array([[float(v) for v in p] for p in pts])
    got = km._lex_order(V, lambda i: pts[i])
    assert [pts[i] for i in got] == sorted(pts)


def test_facets_at_simple_vertices_are_the_exact_rank_ones():
    """The simple-vertex rule of _relative_facets keeps exactly the constraints whose
    tight vertices span a (dim − 1)-face (exact ranks of the Fraction differences)."""
    X = _cloud("gaussian", 4, 18, 2)
    K = rescon.safe_kernel(X, 2)
    V = K.exact_vertices
    want = set()
    for a, beta in K._exact.constraints:
        on = [v for v in V if sum(x * y for x, y in zip(a, v, strict=True)) == beta]
        diffs = [[x - y for x, y in zip(v, on[0], strict=True)] for v in on[1:]]
        rank = len(a) - len(nullspace_exact(diffs)) if diffs else 0
        if rank == K.dim - 1:
            want.add((a, beta))
    assert set(K._exact.facets) == want
    assert len(want) == len(K.A)


def test_exact_vertices_are_built_once_on_first_read_and_pickle():
    X = _cloud("sphere", 4, 16, 2)
    K = rescon.safe_kernel(X, 2)
    assert isinstance(K.__dict__["_exact_vertices_value"], km._Deferred)
    again = pickle.loads(pickle.dumps(K))  # builds them first
    V = K.exact_vertices
    assert type(V) is tuple and all(type(v) is Fraction for x in V for v in x)
    assert K._exact.vertices is V
    assert again.exact_vertices == V
    assert np.array_equal(K.vertices, np.array([[float(v) for v in x] for x in V]))
    assert K.certificate["vertices"] == [[km.fraction_str(v) for v in x] for x in V]
    assert "exact_vertices" not in repr(K)


@pytest.mark.parametrize("d,n,F", [(2, 12, 2), (3, 14, 2), (4, 14, 2), (5, 10, 1)])
def test_exact_rows_at_once_equal_one_by_one(d, n, F):
    """Halfspaces.exact_all (cross products of object arrays) caches the same primitive
    rows as Halfspaces.exact (a Bareiss elimination per row), at mixed magnitudes."""
    from rescon.geometry.exact import affine_hull, exact_points, float_view
    from rescon.geometry.halfspaces import valid_halfspaces

    rng = np.random.default_rng(d)
    X = rng.normal(size=(n, d)) * 10.0 ** rng.integers(-3, 3, size=(n, d))
    P = exact_points(X)
    hull = affine_hull(P)
    rows = [tuple(r[c] for c in hull.coords) for r in P.ints]
    Yf, unit, exact_view = float_view(rows, P.scale)
    one, many = (valid_halfspaces(Yf, rows, np.ones(n, dtype=np.int64), F, exact_view)
                 for _ in range(2))
    many.exact_all(range(len(many)))
    assert len(one) > 10
    assert [many._cache[h] for h in range(len(many))] == [one.exact(h) for h in range(len(one))]
