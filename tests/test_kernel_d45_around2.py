"""Safe kernels in d = 4-5 (issue 13 §3), around the certification: the scan's octant
prune (``_candidates._prefix_octants``) against exact integer counts of every subset
and against the unpruned numpy twin, and the d ≥ 5 qhull option chain of
``fastpath._propose`` — whole kernels bit-identical to the exact clipping on the
benchmark families and on hostile data."""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest

import rescon
from rescon.geometry import _candidates, _scan_np, fastpath, halfspaces
from rescon.geometry import kernel as km
from tests.test_kernel_d45_scan import _integers, _scan_args


def _points(kind: str, k: int, m: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng([seed, k, m, 6])
    Y = rng.normal(size=(m, k))
    if kind == "coplanar":  # most points on one hyperplane (x_k = 0), prefixes inside it
        Y[: m - 3, -1] = 0.0
    elif kind == "repeated":  # repeated points, some of them in every prefix
        Y[3] = Y[0]
        Y[5] = Y[1]
        Y[m - 1] = Y[m - 2]
    elif kind == "integers":  # exact float arithmetic (c_err = 0), ties on hyperplanes
        Y = np.round(Y * 2)
    elif kind == "tiny":
        Y = Y * 1e-300
    elif kind == "subnormal":
        Y = Y * 1e-310
    elif kind == "huge":
        Y = Y * 1e300
    elif kind == "nearsame":  # converged: within a few ulps of 1
        Y = 1.0 + 2.0**-50 * np.round(Y * 4)
    elif kind == "adversary":  # one point at 1e300 among O(1) ones
        Y[m // 2] = 1e300 * np.sign(Y[m // 2])
    return Y


def _exact_sides(Yi, W, subset) -> tuple[int, int, bool]:
    """Weighted numbers of points strictly on the + and − side of the hyperplane
    through ``subset`` (brute force: the exact cofactor normal, one integer dot product
    per point), and whether the subset is affinely dependent."""
    normal = halfspaces.exact_normal(Yi, subset)
    if not any(normal):
        return 0, 0, True
    p0 = Yi[subset[0]]
    plus = minus = 0
    for q, y in enumerate(Yi):
        if q in subset:
            continue
        s = sum(c * (a - b) for c, a, b in zip(normal, y, p0, strict=True))
        plus += int(W[q]) * (s > 0)
        minus += int(W[q]) * (s < 0)
    return plus, minus, False


KINDS = ("normal", "coplanar", "repeated", "integers", "tiny", "subnormal", "huge",
         "nearsame", "adversary")
#: (k, m): every prefix p_0 < … < p_{k−2} ≤ m − 1 − PRUNE_MIN_RUN is pruned by octants
SIZES = [(4, 14), (5, 13)]


@pytest.mark.parametrize("F", [1, 3])
@pytest.mark.parametrize("k,m", SIZES)
@pytest.mark.parametrize("kind", KINDS)
def test_pruned_scan_counts_are_exact_lower_bounds_of_every_subset(kind, k, m, F):
    """All C(m, k) subsets against exact integer counts: each count is a lower bound
    of its side's; a subset reported with more than F on both sides has them exactly;
    any other is bracketed by its count and count + uncertain, and equals the
    unpruned numpy twin's; degenerate flags agree with the twin's. On the data in
    general position the prune fires (counts differ from the twin's)."""
    assert m - 1 - _candidates.PRUNE_MIN_RUN >= k - 2  # some prefixes are pruned
    Y = _points(kind, k, m, F)
    W = np.random.default_rng([m, F]).integers(1, 3, size=m)
    Yi = _integers(Y)
    subsets = _scan_np.k_subsets(m, k)
    c_err, floor = _scan_args(Y, kind == "integers")
    got = _candidates.classify(Y, W.astype(np.int64), subsets, c_err, F, floor, 2)
    one = _candidates.classify(Y, W.astype(np.int64), subsets, c_err, F, floor, 1)
    twin = _scan_np.classify(Y, W, subsets, c_err, F, floor)
    for a, b in zip(got, one, strict=True):  # threads and one thread: the same
        assert np.array_equal(a, b)
    plus, minus, unc, degenerate = got
    assert np.array_equal(degenerate, twin[3])
    pruned = 0
    for t, subset in enumerate(subsets.tolist()):
        p, n_, dependent = _exact_sides(Yi, W, subset)
        if c_err == 0.0:
            assert degenerate[t] == dependent
        if degenerate[t] or dependent:
            continue
        assert plus[t] <= p and minus[t] <= n_
        if plus[t] > F and minus[t] > F:
            assert p > F and n_ > F
            pruned += (plus[t], minus[t], unc[t]) != (twin[0][t], twin[1][t], twin[2][t])
        else:
            assert plus[t] <= p <= plus[t] + unc[t]
            assert minus[t] <= n_ <= minus[t] + unc[t]
            assert (plus[t], minus[t], unc[t]) == (twin[0][t], twin[1][t], twin[2][t])
    if kind in ("normal", "integers"):  # tiny, huge: underflow, overflow hide all
        assert pruned > 0


def test_octants_are_sure_or_none():
    """The open octant of a point known within e: counterclockwise from the positive x
    axis; a point within e of an axis or of a diagonal, or NaN, has none (8)."""
    octant = _candidates._octant.py_func
    cases = {(2.0, 1.0): 0, (1.0, 2.0): 1, (-1.0, 2.0): 2, (-2.0, 1.0): 3, (-2.0, -1.0): 4,
             (-1.0, -2.0): 5, (1.0, -2.0): 6, (2.0, -1.0): 7}
    for (x, y), o in cases.items():
        assert octant(x, y, 0.0) == o
        assert octant(x, y, 0.2) == o
        assert octant(x, y, 0.6) == 8  # within 2e of the diagonal: |x| − |y| = ±1
    assert octant(1.0, 1.0, 0.0) == 8  # on a diagonal
    assert octant(0.0, 1.0, 0.0) == 8  # on an axis
    assert octant(1.0, 0.5, 0.5) == 8  # y within e of 0
    assert octant(float("nan"), 1.0, 0.0) == 8
    assert octant(1e308, 1e300, 1e307) == 8  # 2e overflows: nothing is sure


def _rows(H) -> list:
    return sorted(H.exact(h) for h in range(len(H)))


@pytest.mark.parametrize("kind", ["normal", "coplanar", "repeated", "integers", "nearsame",
                                  "adversary"])
@pytest.mark.parametrize("k,m,F", [(4, 20, 1), (4, 20, 3), (5, 18, 1), (5, 18, 2)])
def test_valid_halfspaces_equal_the_unpruned_twins(kind, k, m, F, monkeypatch):
    """The valid halfspaces (exact primitive rows, their subsets and signs) from the
    pruned numba scan are those of the numpy twin, which counts every point."""
    Y = _points(kind, k, m, 11)
    P = km.exact_points(Y)
    rows = [tuple(r) for r in P.ints]
    uniq = list(dict.fromkeys(rows))
    W = np.array([rows.count(r) for r in uniq])
    Yf, unit, exact_view = km.float_view(uniq, P.scale)
    assert halfspaces.candidate_cost(len(uniq), k) > halfspaces.SMALL_SCAN  # numba
    pruned = halfspaces.valid_halfspaces(Yf, uniq, W, F, exact_view)
    monkeypatch.setattr(halfspaces, "SMALL_SCAN", 10**12)
    twin = halfspaces.valid_halfspaces(Yf, uniq, W, F, exact_view)
    assert np.array_equal(pruned.through, twin.through)
    assert np.array_equal(pruned.sign, twin.sign)
    assert np.array_equal(pruned.outside, twin.outside)
    assert _rows(pruned) == _rows(twin)


def _cell24() -> np.ndarray:
    pts = sorted({tuple(s * (t == i) + u * (t == j) for t in range(4))
                  for i, j in itertools.combinations(range(4), 2)
                  for s in (1, -1) for u in (1, -1)})
    return np.array(pts, dtype=float)


def _cloud(kind: str, d: int, n: int, F: int) -> np.ndarray:
    """Benchmark families (benchmarks/kernel_clouds.py) and hostile data."""
    from benchmarks.kernel_clouds import make_cloud

    if kind in ("gaussian", "cube", "sphere", "attack", "converged", "grid", "duplicates",
                "flat", "above_helly"):
        return make_cloud(kind, d, n, F).X
    Z = np.random.default_rng([d, n, F]).normal(size=(n, d))
    return {
        "tiny": lambda: Z * 1e-300,
        "huge": lambda: Z * 1e300,
        "subnormal": lambda: Z * 1e-310,
        "nearsame": lambda: 1.0 + 2.0**-50 * np.round(4 * Z),
        "integer": lambda: np.round(3 * Z),
        "adversary": lambda: np.vstack([Z[:-1], 1e300 * np.ones((1, d))]),
        "simplex": lambda: Z[: d + 1],
        "cell24": lambda: np.vstack([_cell24() * 3.0 + 1.0, np.ones((n - 24, 4))]),
        "lattice": lambda: np.array(list(itertools.product((0, 1, 2), repeat=d))[:n],
                                    dtype=float),
    }[kind]()


def _same_as_clipping(X: np.ndarray, F: int, monkeypatch) -> rescon.SafeKernel:
    fast = rescon.safe_kernel(X, F)
    with monkeypatch.context() as mp:
        mp.setattr(km, "certified_kernel", lambda *a: None)
        slow = rescon.safe_kernel(X, F)
    assert_identical(fast, slow)
    return fast


def assert_identical(K: rescon.SafeKernel, L: rescon.SafeKernel) -> None:
    """Every output of the two kernels identical (floats bit for bit)."""
    assert K.dim == L.dim and K.is_empty == L.is_empty
    for name in ("vertices", "A", "b", "Aeq", "beq", "affine_basis"):
        assert getattr(K, name).tobytes() == getattr(L, name).tobytes(), name
    assert K.exact_vertices == L.exact_vertices
    assert K._exact.constraints == L._exact.constraints
    assert K._exact.facets == L._exact.facets
    assert K.certificate == L.certificate


KERNELS = [("gaussian", 4, 20, 2), ("cube", 4, 20, 3), ("sphere", 4, 20, 1),
           ("attack", 4, 20, 2), ("converged", 4, 20, 2), ("grid", 4, 20, 2),
           ("duplicates", 4, 21, 2), ("flat", 4, 20, 2), ("above_helly", 4, 19, 4),
           ("tiny", 4, 20, 2), ("huge", 4, 20, 2), ("subnormal", 4, 20, 2),
           ("nearsame", 4, 20, 2), ("integer", 4, 20, 3),
           pytest.param("adversary", 4, 20, 2, marks=pytest.mark.slow),  # ~12 s clipping
           ("simplex", 4, 5, 0), ("cell24", 4, 28, 4), ("lattice", 4, 27, 4),
           ("gaussian", 5, 14, 1), ("sphere", 5, 14, 1), ("integer", 5, 14, 1),
           ("nearsame", 5, 13, 1), ("adversary", 5, 14, 1)]


@pytest.mark.parametrize("kind,d,n,F", KERNELS)
def test_kernels_identical_to_the_exact_clipping(kind, d, n, F, monkeypatch):
    """Every output — floats bit for bit, exact vertices and rows, certificate — equals
    the exact clipping's (fast path off): benchmark families, extreme magnitudes,
    subnormal and converged points, integers, flat and empty kernels, n = d + 1, an
    adversary at 1e300, the 24-cell's and the lattice's non-simple vertices."""
    _same_as_clipping(_cloud(kind, d, n, F), F, monkeypatch)


@pytest.mark.slow
@pytest.mark.parametrize("kind,F", [("gaussian", 3), ("cube", 1), ("sphere", 2)])
def test_d5_kernels_with_the_first_qhull_option_identical_to_the_clipping(kind, F,
                                                                          monkeypatch):
    """d = 5, n = 20 benchmark clouds: the merged proposal comes from the first option
    of the d ≥ 5 chain and is certified; the kernel equals the exact clipping's."""
    used = _recorded_options(monkeypatch)
    _same_as_clipping(_cloud(kind, 5, 20, F), F, monkeypatch)
    assert used[0] == fastpath.MERGED_OPTIONS_5D[0]


def _recorded_options(monkeypatch, fail: tuple = ()) -> list:
    """Records the options of every qhull halfspace intersection; those in ``fail``
    raise QhullError."""
    import scipy.spatial as sp

    real, used = sp.HalfspaceIntersection, []

    def record(*args, qhull_options=None, **kw):
        used.append(qhull_options)
        if qhull_options in fail:
            raise sp.QhullError("refused by the test")
        return real(*args, qhull_options=qhull_options, **kw)

    monkeypatch.setattr(sp, "HalfspaceIntersection", record)
    return used


def test_d5_merged_proposal_falls_back_to_qhull_default_in_the_same_attempt(monkeypatch):
    """When the first option of the chain fails, the same proposal round retries with
    qhull's default before any joggled input; the certified kernel is unchanged."""
    X, F = _cloud("gaussian", 5, 14, 1), 1
    fail = (fastpath.MERGED_OPTIONS_5D[0],)
    used = _recorded_options(monkeypatch, fail)
    K = _same_as_clipping(X, F, monkeypatch)
    assert used[:2] == [fail[0], None]
    assert "QJ" not in used
    assert K.dim == 5


def test_d4_merged_proposal_is_qhull_default_without_the_outer_plane_pass(monkeypatch):
    """In d = 4 the merged proposal is qhull's default with "Q5" alone (the chain of
    options is d ≥ 5); the kernel is the clipping's."""
    used = _recorded_options(monkeypatch)
    _same_as_clipping(_cloud("gaussian", 4, 20, 2), 2, monkeypatch)
    assert used and used[0] == "Q5" == fastpath.MERGED_OPTIONS_4D[0]
    assert None not in used


@pytest.mark.parametrize(("kind", "n", "F"), [("gaussian", 20, 2), ("cube", 30, 3),
                                               ("sphere", 30, 1), ("sphere", 50, 5)])
def test_d4_q5_proposal_is_the_default_one_bit_for_bit(monkeypatch, kind, n, F):
    """qhull with "Q5" returns the default's dual facets and intersections, bit for bit,
    on the halfspaces the fast path gives it (the rows of its first round)."""
    import scipy.spatial as sp

    real, seen = sp.HalfspaceIntersection, []

    def record(halfspaces, interior, qhull_options=None, **kw):
        seen.append((halfspaces.copy(), interior.copy()))
        return real(halfspaces, interior, qhull_options=qhull_options, **kw)

    monkeypatch.setattr(sp, "HalfspaceIntersection", record)
    rescon.safe_kernel(_cloud(kind, 4, n, F), F)
    assert seen
    for rows, interior in seen:
        a, b = real(rows, interior), real(rows, interior, qhull_options="Q5")
        assert a.dual_facets == b.dual_facets
        assert a.intersections.tobytes() == b.intersections.tobytes()


@pytest.mark.parametrize("seed", range(8))
def test_lex_order_with_many_runs_of_ties_is_the_exact_order(seed):
    """Points whose floats tie in runs (in the first and later columns, several runs
    side by side, equal points) come in the exact lexicographic order."""
    rng = np.random.default_rng(seed)
    tiny = Fraction(1, 2**80)
    base = [Fraction(int(v)) for v in rng.integers(0, 4, size=3)]
    pts = [tuple(base[int(rng.integers(0, 3))] + int(rng.integers(0, 3)) * tiny
                 for _ in range(3)) for _ in range(60)]
    V = np.array([[float(v) for v in p] for p in pts])
    got = km._lex_order(V, lambda i: pts[i])
    assert [pts[i] for i in got] == sorted(pts)
    assert sorted(got) == list(range(len(pts)))


def test_centre_moves_only_data_far_from_the_origin_against_its_spread():
    """Data near the origin (against its spread) is clipped where it is; states
    converged far from it are moved to their median (their float offsets would keep no
    precision), unless a difference is no longer a float times the scale."""
    near = [(3, -4), (5, 2), (-1, 7)]
    assert km._centre(near) == [0, 0]
    far = [(v + 2**40, w + 2**40) for v, w in near]
    assert km._centre(far) == [3 + 2**40, 2 + 2**40]
    assert km._centre([(v * 2**70, w * 2**70) for v, w in far]) == [
        (3 + 2**40) * 2**70, (2 + 2**40) * 2**70]
    wide = [(2**40 + 1, 2**40), (2**40 + 2**60 + 1, 2**40 + 1), (2**40, 2**40 + 2)]
    assert km._centre(wide) == [0, 0]  # spread 2^60: the origin is near enough
    odd = [(2**80, 2**80), (2**80 + 2**55 + 1, 2**80 + 1), (2**80 + 3, 2**80 + 2**55 + 1)]
    assert km._centre(odd) == [0, 0]  # 2^55 − 2 from the median: odd part ≥ 2^53
