"""The candidate scan for k ≥ 4 (issue 13 §3): cofactors from the minors shared by a
run of subsets, every point's orientation at once, complete counts. Checked against
exact integer arithmetic (brute force), the numpy twin, the single-thread scan, the
budget, and whole kernels against the exact clipping on hostile inputs."""

from __future__ import annotations

from fractions import Fraction
from math import comb, factorial

import numpy as np
import pytest

import rescon
from rescon._rounding import UNIT_ROUNDOFF, underflow_floor
from rescon.geometry import _candidates, _scan_np, halfspaces
from rescon.geometry import kernel as km


def _points(kind: str, k: int, m: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng([seed, k, m])
    Y = rng.normal(size=(m, k))
    if kind == "ties":  # many points exactly on candidate hyperplanes
        Y = np.round(Y * 2) / 2
    elif kind == "tiny":  # the underflow term decides
        Y = Y * 1e-300
    elif kind == "huge":
        Y = Y * 1e300
    elif kind == "repeated":  # a repeated point and a repeated coordinate
        Y[:, 0] = Y[:, 1]
        Y[1] = Y[0]
    elif kind == "nearsame":  # converged: all within a few ulps of 1
        Y = 1.0 + 2.0**-50 * np.round(Y * 4)
    return Y


def _integers(Y: np.ndarray) -> list[tuple[int, ...]]:
    """Y's exact binary values times one power of two: integers."""
    fr = [[Fraction(float(v)) for v in row] for row in Y]
    unit = max(v.denominator for row in fr for v in row)
    return [tuple(int(v * unit) for v in row) for row in fr]


def _exact_counts(Yi, W, subset) -> tuple[int, int, bool]:
    """Exact weighted + and − counts of the hyperplane through ``subset`` (brute force:
    a Bareiss determinant per point), and whether the subset is affinely dependent."""
    k = len(Yi[0])
    normal = halfspaces.exact_normal(Yi, subset)
    if not any(normal):
        return 0, 0, True
    p0 = Yi[subset[0]]
    plus = minus = 0
    for q, y in enumerate(Yi):
        if q in subset:
            continue
        rows = [[Yi[i][j] - p0[j] for j in range(k)] for i in subset[1:]]
        s = halfspaces._int_det(rows + [[y[j] - p0[j] for j in range(k)]])
        plus += int(W[q]) * (s > 0)
        minus += int(W[q]) * (s < 0)
    return plus, minus, False


def _scan_args(Y: np.ndarray, exact: bool) -> tuple[float, float]:
    k = Y.shape[1]
    if exact:
        return 0.0, 0.0
    return (4.0 * (3 * k + factorial(k) + 4) * UNIT_ROUNDOFF,
            underflow_floor(k, float(np.abs(Y).max())))


CASES = [(k, kind, seed) for k in (4, 5, 6)
         for kind in ("normal", "ties", "tiny", "huge", "repeated", "nearsame")
         for seed in (0, 1)]


@pytest.mark.parametrize("k,kind,seed", CASES)
def test_scan_counts_bracket_the_exact_counts(k, kind, seed):
    """Every point surely on a side is on it, exactly; plus + uncertain bounds the
    exact count from above (counts are complete for k ≥ 4: no early stop); with exact
    floats (small integers) the counts are the exact ones and degenerate subsets are
    flagged exactly."""
    m = k + 4
    Y = _points(kind, k, m, seed)
    W = np.random.default_rng(seed).integers(1, 3, size=m)
    Yi = _integers(Y)
    subsets = _scan_np.k_subsets(m, k)
    exact = kind == "ties" and np.abs(Y).max() < 8
    c_err, floor = _scan_args(Y, exact)
    plus, minus, unc, degenerate = _candidates.classify(Y, W.astype(np.int64), subsets, c_err,
                                                        m, floor)
    for t, subset in enumerate(subsets.tolist()):
        p, n_, dep = _exact_counts(Yi, W, subset)
        if exact:
            assert degenerate[t] == dep
            if not dep:
                assert (plus[t], minus[t], unc[t]) == (p, n_, 0)
        elif not degenerate[t]:
            assert plus[t] <= p <= plus[t] + unc[t]
            assert minus[t] <= n_ <= minus[t] + unc[t]


@pytest.mark.parametrize("k", [4, 5, 6])
def test_cofactors_within_their_bound_of_the_exact_ones(k):
    """The float cofactors (expanded along the last row over the prefix's minors)
    are within c_err/4 · their permanents of the exact cofactors."""
    Y = _points("normal", k, k + 5, 7)
    Yi = _integers(Y)
    unit = Fraction(Yi[0][0]) / Fraction(float(Y[0, 0])) if Y[0, 0] else None
    assert unit is not None
    subsets = _scan_np.k_subsets(len(Y), k)
    c_err = _scan_args(Y, False)[0]
    cof, cof_abs = _candidates.cofactors(Y, subsets)
    for t, subset in enumerate(subsets.tolist()):
        exact = halfspaces.exact_normal(Yi, subset)  # = C · unit^(k−1)
        for j in range(k):
            err = abs(Fraction(float(cof[t, j])) - Fraction(exact[j]) / unit ** (k - 1))
            assert err <= Fraction(c_err / 4) * Fraction(float(cof_abs[t, j]))


def _full_sides(counts, F):
    """The scan's counts with every subset surely holding more than F points on both
    sides written as the numba scan may leave it after its octant prune
    (``_candidates._prefix_octants``): F + 1 on each side, none uncertain."""
    plus, minus, unc, degenerate = (np.array(c) for c in counts)
    full = (plus > F) & (minus > F)
    plus[full], minus[full], unc[full] = F + 1, F + 1, 0
    return plus, minus, unc, degenerate


@pytest.mark.parametrize("k,m,kind", [(4, 25, "normal"), (4, 22, "ties"), (5, 16, "normal"),
                                      (5, 15, "repeated"), (6, 12, "tiny")])
def test_parallel_scan_equals_the_numpy_twin_exactly(k, m, kind):
    """Above PARALLEL_MIN_SUBSETS the scan runs in CLASSIFY_CHUNKS ranges on threads (each range
    builds its own prefix minors); for k ≥ 4 its counts and flags are identical to the
    numpy twin's — and to one thread's; so are the cofactors of any subsets, as the
    scan computes them."""
    Y = _points(kind, k, m, 3)
    W = np.random.default_rng(m).integers(1, 4, size=m)
    subsets = _scan_np.k_subsets(m, k)
    c_err, floor = _scan_args(Y, kind == "ties")
    threads = _full_sides(_candidates.classify(Y, W.astype(np.int64), subsets,
                                               c_err, 2, floor, 2), 2)
    twin = _full_sides(_scan_np.classify(Y, W, subsets, c_err, 2, floor), 2)
    one = _full_sides(_candidates.classify(Y, W.astype(np.int64),
                                           subsets[:_candidates.PARALLEL_MIN_SUBSETS - 1],
                                           c_err, 2, floor), 2)
    for a, b, c in zip(threads, twin, one, strict=True):
        assert np.array_equal(a, b)
        assert np.array_equal(a[:len(c)], c)
    some = subsets[np.random.default_rng(k).permutation(len(subsets))[:500]]
    for a, b in zip(_candidates.cofactors(Y, some), _scan_np.cofactors(Y, some), strict=True):
        assert np.array_equal(a, b)


def test_budget_counts_the_prefix_minors():
    """The k 2^k minors per prefix are in the estimate: 25 points in R^20 (C(25, 19)
    prefixes of 2^20 minors) are refused before any table is built; the benchmark
    sizes cost a few tests per subset."""
    exact_only, work, nbytes = halfspaces._scan_plan(50, 4, False)
    assert not exact_only and work == comb(50, 4) * (46 + 12) + comb(50, 3) * 4 * 16
    assert halfspaces._scan_plan(25, 20, False)[1] > 4e9
    with pytest.raises(rescon.errors.InputError, match="steps"):
        rescon.safe_kernel(np.random.default_rng(0).normal(size=(25, 20)), 0)


def _hostile(kind: str, d: int, n: int) -> np.ndarray:
    rng = np.random.default_rng([d, n])
    Z = rng.normal(size=(n, d))
    return {
        "simplex": lambda: Z[: d + 1],  # n = d + 1
        "nearsame": lambda: 1.0 + 1e-15 * np.round(4 * Z),
        "mixed": lambda: Z * 10.0 ** rng.integers(-300, 300, size=(n, 1)),
        "smallint": lambda: np.round(2 * Z),
        "coplanar": lambda: np.vstack([np.column_stack([Z[: n // 2, :-1], np.zeros(n // 2)]),
                                       Z[n // 2:]]),
    }[kind]()


@pytest.mark.parametrize("kind,d,n,F", [
    ("simplex", 4, 5, 0), ("simplex", 5, 6, 0), ("nearsame", 4, 16, 2),
    ("nearsame", 5, 12, 1), ("mixed", 4, 12, 1), ("smallint", 4, 18, 2),
    ("smallint", 5, 13, 1), ("coplanar", 4, 18, 2), ("gaussian", 6, 9, 1),
])
def test_kernels_equal_the_exact_clipping(kind, d, n, F, monkeypatch):
    X = (np.random.default_rng(n).normal(size=(n, d)) if kind == "gaussian"
         else _hostile(kind, d, n))
    fast = rescon.safe_kernel(X, F)
    monkeypatch.setattr(km, "certified_kernel", lambda *a: None)
    slow = rescon.safe_kernel(X, F)
    assert fast.dim == slow.dim
    assert fast.exact_vertices == slow.exact_vertices
    assert fast._exact.constraints == slow._exact.constraints
    assert fast.certificate == slow.certificate


@pytest.mark.parametrize("block", [1, 7, 4096])
@pytest.mark.parametrize(("k", "m"), [(2, 12), (3, 11), (4, 9), (5, 8)])
@pytest.mark.parametrize("kind", ["normal", "ties", "repeated", "tiny"])
def test_exact_side_counts_in_integers_equal_the_brute_force(kind, k, m, block,
                                                              monkeypatch):
    """The integer path of ``halfspaces._exact_side_counts`` (every point at once per
    block of subsets, object arrays) against one Bareiss determinant per point: the
    counts and dependence flags of every subset, in blocks of any size."""
    monkeypatch.setattr(halfspaces, "EXACT_BLOCK", block * m)
    Y = _points(kind, k, m, 7)
    Yi = _integers(Y)
    W = np.random.default_rng(m).integers(1, 4, size=m)
    subsets = _scan_np.k_subsets(m, k)
    plus, minus, dep = halfspaces._exact_side_counts(Y, Yi, W, subsets, m, False)
    want = [_exact_counts(Yi, W, s) for s in subsets.tolist()]
    assert [list(t) for t in zip(plus.tolist(), minus.tolist(), dep.tolist())] == [
        list(t) for t in want]
