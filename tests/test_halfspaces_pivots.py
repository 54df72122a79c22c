"""The pivoted orientation filter of the small path (``_scan_np.side_signs``) and the
vectorised exact normals (``halfspaces._rounded_cofactors``) against exact arithmetic:
every decision the filter makes is the exact sign, it is unsure where it must be
(coplanar points, members, out-of-range magnitudes, a forced tiny bound), and the
valid halfspaces are the same with and without it."""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest

from rescon.geometry import _scan_np, halfspaces
from rescon.geometry.exact import float_view


def _exact_sign(Y, sub, q) -> int:
    """sign det[p_1 − p_0, …, q − p_0] of the float points, in Fractions."""
    P = [[Fraction(v) for v in Y[i]] for i in (*sub, q)]
    R = [[a - b for a, b in zip(p, P[0], strict=True)] for p in P[1:]]
    if len(R) == 2:
        det = R[0][0] * R[1][1] - R[0][1] * R[1][0]
    else:
        (a, b, c), (d, e, f), (g, h, i) = R
        det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    return (det > 0) - (det < 0)


def _cloud(kind: str, k: int, m: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    if kind == "converged":  # the benchmark's converged family: a 1e-7 cluster + far points
        c = rng.uniform(-1, 1, k)
        out = m // 3
        Y = np.vstack([c + rng.uniform(-1e-7, 1e-7, (m - out, k)),
                       c + rng.uniform(1, 10, (out, 1)) * rng.standard_normal((out, k))])
    elif kind == "tight":  # ~1e-15 across, about a centre of order 1
        Y = rng.uniform(-1, 1, k) + 1e-15 * rng.uniform(-1, 1, (m, k))
    elif kind == "coplanar":  # on a hyperplane through small integers, and a few off it
        Y = rng.integers(-4, 5, (m, k)).astype(float)
        Y[: m - 2, -1] = Y[: m - 2, :-1].sum(axis=1) + 1.0
    elif kind == "duplicates":
        base = rng.standard_normal((m // 2, k))
        Y = base[rng.integers(0, len(base), m)]
    elif kind == "huge":
        Y = 1e300 * rng.uniform(-1, 1, (m, k))
    elif kind == "tiny":
        Y = 1e-300 * rng.uniform(-1, 1, (m, k))
    elif kind == "subnormal":
        Y = rng.integers(-3, 4, (m, k)) * 2.0**-1070
    else:
        Y = rng.standard_normal((m, k))
    return np.ascontiguousarray(Y, dtype=np.float64)


KINDS = ["converged", "tight", "coplanar", "duplicates", "huge", "tiny", "subnormal", "normal"]


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("kind", KINDS)
def test_side_signs_decide_only_exact_signs(kind, k):
    """Every nonzero sign is the exact one; members and exact zeros stay undecided;
    out of the expansions' range nothing is decided."""
    m = 9
    Y = _cloud(kind, k, m, 3 + k)
    subsets = _scan_np.k_subsets(m, k)
    sg = _scan_np.side_signs(Y, subsets)
    decided = 0
    for t, sub in enumerate(subsets.tolist()):
        for q in range(m):
            want = _exact_sign(Y, sub, q)
            got = int(sg[t, q])
            if q in sub or want == 0:
                assert got == 0
            elif got:
                decided += 1
                assert got == want, (sub, q)
    if not _scan_np.in_range(Y):
        assert decided == 0
    elif kind in ("converged", "tight", "normal"):
        assert decided >= 0.95 * len(subsets) * (m - k)  # the filter is worth running


def test_side_signs_pivot_decides_what_p0_cannot():
    """A far p_0 and three points of a 1e-7 cluster: the orientation about p_0 cancels
    ~1e8-fold (beyond the classify bound), about a cluster point it does not."""
    c = np.array([0.3, -0.7, 0.1])
    Y = np.vstack([c + [5.0, 1.0, -2.0],
                   c + np.array([[1e-7, 0, 0], [0, 1e-7, 0], [0, 0, 1e-7], [3e-8, 2e-8, 4e-8]])])
    sg = _scan_np.side_signs(Y, np.array([[0, 1, 2]]))
    assert sg[0, 3] == _exact_sign(Y, (0, 1, 2), 3) != 0
    assert sg[0, 4] == _exact_sign(Y, (0, 1, 2), 4) != 0


def test_side_signs_unsure_when_the_bound_is_forced_up(monkeypatch):
    """With the error bound forced to infinity no pair passes: all undecided."""
    monkeypatch.setattr(_scan_np, "PIVOT_ERR", np.inf)
    Y = _cloud("normal", 3, 7, 1)
    with np.errstate(invalid="ignore"):  # inf · 0 for the members
        assert not _scan_np.side_signs(Y, _scan_np.k_subsets(7, 3)).any()


def test_side_signs_unsure_on_a_nearly_coplanar_point():
    """Four points on the tilted plane z = 0.3x + 0.7y + 0.25, z rounded to floats: the
    exact orientation is nonzero (rounding residue ~1e-17) but below the 2^-49 bound
    of every pivot (the z differences are inexact) — undecided, never guessed."""
    xy = np.array([[0.1, 0.2], [0.9, 0.15], [0.35, 0.8], [0.45, 0.4]])
    Y = np.column_stack([xy, 0.3 * xy[:, 0] + 0.7 * xy[:, 1] + 0.25])
    assert _exact_sign(Y, (0, 1, 2), 3) != 0
    assert _scan_np.side_signs(Y, np.array([[0, 1, 2]]))[0, 3] == 0


def _integers(Y):
    rows = [tuple(Fraction(v) for v in y) for y in Y]
    den = 1
    for row in rows:
        for v in row:
            den = max(den, v.denominator)
    return [tuple(int(v * den) for v in row) for row in rows], den


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("kind", KINDS)
def test_exact_side_counts_same_with_pivots(kind, k, monkeypatch):
    """``_exact_side_counts`` with the pivot filter equals the integer path on every
    subset (counts and dependence); also when the filter is forced to be unsure."""
    m = 10
    Y = _cloud(kind, k, m, 11 * k)
    Y = np.unique(Y, axis=0)
    m = len(Y)
    Yi, den = _integers(Y)
    Yf, unit, exact_view = float_view(Yi, den)
    W = np.random.default_rng(m).integers(1, 4, size=m)
    subsets = _scan_np.k_subsets(m, k)
    want = halfspaces._exact_side_counts(Yf, Yi, W, subsets, m, False)
    got = halfspaces._exact_side_counts(Yf, Yi, W, subsets, m, False, pivots=exact_view)
    for a, b in zip(want, got, strict=True):
        assert a.tolist() == b.tolist()
    monkeypatch.setattr(_scan_np, "PIVOT_ERR", np.inf)
    with np.errstate(invalid="ignore"):
        unsure = halfspaces._exact_side_counts(Yf, Yi, W, subsets, m, False, pivots=True)
    for a, b in zip(want, unsure, strict=True):
        assert a.tolist() == b.tolist()


@pytest.mark.parametrize("family", ["converged", "attack", "gaussian", "grid", "duplicates"])
@pytest.mark.parametrize("k", [2, 3])
def test_valid_halfspaces_identical_without_pivots(family, k, monkeypatch):
    """The valid halfspaces of the small path (rows, counts, floats, order) are the
    same whether the pivot filter decides or every maybe-subset goes to integers."""
    from benchmarks.kernel_clouds import make_cloud

    cloud = make_cloud(family, k, 12 if k == 3 else 20, 4)
    Yi, den = _integers(np.unique(cloud.X, axis=0))
    Yf, _, exact_view = float_view(Yi, den)
    W = np.ones(len(Yi), dtype=np.int64)
    got = halfspaces.valid_halfspaces(Yf, Yi, W, 4, exact_view)
    monkeypatch.setattr(_scan_np, "side_signs", lambda Y, s, start: start)  # no more
    want = halfspaces.valid_halfspaces(Yf, Yi, W, 4, exact_view)
    for name in ("through", "sign", "af", "bf", "af_abs", "b_abs", "outside"):
        assert np.array_equal(getattr(got, name), getattr(want, name)), name
    assert got.c_err == want.c_err


def _rounded_reference(Y, Yi, subsets):
    """The former one-Fraction-per-component implementation."""
    k = Y.shape[1]
    i, j = np.unravel_index(np.abs(Y).argmax(), Y.shape)
    den = (Fraction(Yi[i][j]) / Fraction(float(Y[i, j]))) ** (k - 1)
    return np.array([[float(c / den) for c in halfspaces.exact_normal(Yi, sub)]
                     for sub in subsets.tolist()], dtype=np.float64).reshape(-1, k)


@pytest.mark.parametrize("k", [3, 4])
@pytest.mark.parametrize("kind", ["converged", "tight", "coplanar", "normal"])
@pytest.mark.parametrize("shift", [-60, 0, 40])
def test_rounded_cofactors_are_the_correctly_rounded_normals(kind, k, shift):
    """Vectorised (cross products of object arrays, int true division) equals the
    reference bit for bit, zero normals of dependent subsets included, at any unit."""
    Y = np.unique(_cloud(kind, k, 8, 5), axis=0)
    Yi, den = _integers(Y)
    Yi = [tuple(v << 80 for v in row) for row in Yi]  # unit = den · 2^(80 + shift)
    unit = den << (80 + shift) if shift >= -80 else None
    Yf = np.array([[v / unit for v in row] for row in Yi])
    subsets = _scan_np.k_subsets(len(Yi), k)
    got = halfspaces._rounded_cofactors(Yf, Yi, subsets)
    want = _rounded_reference(Yf, Yi, subsets)
    assert got.tobytes() == want.tobytes()
    assert list(itertools.chain(got.shape)) == [len(subsets), k]


@pytest.mark.parametrize("dnm", [1, 2**40, 2**1100, 2**2100, 3 * 2**40, 10**30],
                         ids=["1", "2^40", "2^1100", "2^2100", "3*2^40", "10^30"])
@pytest.mark.parametrize("num", [1, 3])
def test_quotients_are_correctly_rounded(num, dnm):
    """c · num / dnm as float(Fraction) for every c: halfway cases, results in the
    subnormal range and below it, c beyond the float range (the fallbacks)."""
    rng = np.random.default_rng(dnm % 1000 + num)
    ints = [0, 1, -1, 2**53 + 1, -(2**53 + 3), 2**54 + 2, 3 << 1100, -(1 << 1023) * 3,
            (1 << 1024) + 1, 2**60 - 1,
            # over 2^1100 a subnormal with spacing 2^26 in c: float(c) drops the last 1
            # and lands on a halfway point that ldexp would round to even (down)
            2**62 + 2**25 + 1, -(2**62 + 2**25 + 1)]
    ints += [int(v) << int(s) for v, s in zip(rng.integers(-2**62, 2**62, 40),
                                              rng.integers(0, 1200, 40), strict=True)]
    want = []
    for c in ints:
        try:
            want.append(float(Fraction(c * num, dnm)))
        except OverflowError:
            want.append(None)
    if None in want:
        with pytest.raises(OverflowError):
            halfspaces._quotients(ints, num, dnm)
        ok = [c for c, w in zip(ints, want, strict=True) if w is not None]
        want = [w for w in want if w is not None]
        ints = ok
    got = halfspaces._quotients(ints, num, dnm)
    assert got.tobytes() == np.array(want, dtype=np.float64).tobytes()
    # without the c beyond the float range (which send every c to the integers)
    fits = [i for i, c in enumerate(ints) if abs(c) < 2**1000]
    got = halfspaces._quotients([ints[i] for i in fits], num, dnm)
    assert got.tobytes() == np.array([want[i] for i in fits], dtype=np.float64).tobytes()


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("kind", KINDS)
def test_classify_pair_signs_are_exact_and_seed_the_pivots(kind, k):
    """``classify(..., pairs=True)``: its nonzero signs are the exact ones and make its
    counts; seeding the pivot filter with them gives the integer path's counts."""
    from math import factorial

    from rescon._rounding import UNIT_ROUNDOFF, underflow_floor

    Y = np.unique(_cloud(kind, k, 10, 5 * k), axis=0)
    m = len(Y)
    Yi, den = _integers(Y)
    Yf, _, exact_view = float_view(Yi, den)
    W = np.random.default_rng(m).integers(1, 4, size=m)
    subsets = _scan_np.k_subsets(m, k)
    c_err = 4.0 * (3 * k + factorial(k) + 4) * UNIT_ROUNDOFF
    floor = underflow_floor(k, float(np.abs(Yf).max()))
    plus, minus, unc, dege, sg = _scan_np.classify(Yf, W, subsets, c_err, 3, floor,
                                                   pairs=True)
    assert ((sg == 1) @ W).tolist() == plus.tolist()
    assert ((sg == -1) @ W).tolist() == minus.tolist()
    for t, sub in enumerate(subsets.tolist()):
        for q in np.flatnonzero(sg[t]).tolist():
            assert sg[t, q] == _exact_sign(Yf, sub, q)
    want = halfspaces._exact_side_counts(Yf, Yi, W, subsets, m, False)
    got = halfspaces._exact_side_counts(Yf, Yi, W, subsets, m, False, pivots=exact_view,
                                        start=sg)
    for a, b in zip(want, got, strict=True):
        assert a.tolist() == b.tolist()
