"""Hostile review V16: the pivoted float orientation filter of the small path
(``_scan_np.side_signs``, cf7fec2), the pair signs ``classify(pairs=True)`` hands it
(e169240), and the correctly rounded exact normals (``halfspaces._rounded_cofactors``,
``_quotients``, 9833036) — every sign, count and float against an independent oracle
written here: the (k + 1) × (k + 1) homogeneous determinant in Fractions (Laplace),
a brute-force list of valid halfspaces, and float(Fraction) for the normals; the public
results (``safe_kernel``, ``rescon kernel``) against the integer-only and the numba
paths, on hostile clouds (scales 2^±119/500/1000, subnormals, mixed magnitudes, range
edges, 1-ulp perturbations of flat sets, converged clouds, grids, duplicates)."""

from __future__ import annotations

import json
import random
from fractions import Fraction
from math import factorial

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rescon._rounding import MIN_NORMAL, UNIT_ROUNDOFF, underflow_floor
from rescon.geometry import _scan_np, halfspaces
from rescon.geometry.exact import exact_points, float_view
from rescon.geometry.kernel import safe_kernel

# --------------------------------------------------------------------------- oracle


def _det(M):
    """Determinant by Laplace expansion along the first row (exact for Fractions)."""
    if len(M) == 1:
        return M[0][0]
    return sum((-1) ** j * M[0][j] * _det([r[:j] + r[j + 1:] for r in M[1:]])
               for j in range(len(M)) if M[0][j])


def orient(Y: np.ndarray, pts) -> int:
    """sign s(q) = C·(q − p_0) for pts = (p_0, …, p_{k−1}, q) rows of the float array Y:
    (−1)^k det [x_j, 1], the homogeneous (k + 1) × (k + 1) matrix, in Fractions."""
    k = Y.shape[1]
    d = _det([[Fraction(v) for v in Y[i].tolist()] + [Fraction(1)] for i in pts])
    return ((d > 0) - (d < 0)) * (-1) ** k


def normal(Y: np.ndarray, sub) -> list[Fraction]:
    """The cofactor normal C of the float points Y[sub] in Fractions: C_j = s(p_0 + e_j)
    (s is affine in q with linear part C), by the homogeneous determinant."""
    k = Y.shape[1]
    P = [[Fraction(v) for v in Y[i].tolist()] for i in sub]
    out = []
    for j in range(k):
        q = [v + (c == j) for c, v in enumerate(P[0])]
        out.append(_det([p + [Fraction(1)] for p in (*P, q)]) * (-1) ** k)
    return out


# --------------------------------------------------------------------------- clouds

SCALES = (-1000, -500, -119, 0, 60, 119, 500, 1000)


def hostile(kind: str, k: int, m: int, seed: int) -> np.ndarray:
    """A hostile cloud of m points in R^k (float64, contiguous, maybe with repeats)."""
    rng = np.random.default_rng([seed, k, m, sum(map(ord, kind))])
    if kind.startswith("scale"):
        Y = rng.standard_normal((m, k)) * 2.0 ** int(kind[5:])
    elif kind == "subnormal":
        Y = rng.integers(-5, 6, (m, k)) * 2.0**-1074
    elif kind == "mixed_points":  # whole points at 2^-110 .. 2^110
        Y = rng.standard_normal((m, k)) * 2.0 ** rng.integers(-110, 110, (m, 1))
    elif kind == "mixed_coords":  # every coordinate its own magnitude
        Y = rng.standard_normal((m, k)) * 2.0 ** rng.integers(-110, 110, (m, k))
    elif kind == "edges":  # the in_range edges 2^±120 and 0
        Y = rng.choice([0.0, 2.0**-120, -(2.0**-120), 2.0**120, -(2.0**120),
                        2.0**120 * (1 - 2.0**-53), 2.0**-120 * (1 + 2.0**-52)], (m, k))
    elif kind == "flat":  # on a line / plane, products inexact
        x = rng.standard_normal((m, k - 1))
        last = x @ (rng.standard_normal(k - 1) / 3) + 0.1
        Y = np.column_stack([x, last])
    elif kind == "flat_ulp":  # the same, some coordinates nudged by one ulp
        Y = hostile("flat", k, m, seed)
        nudge = rng.integers(-1, 2, (m, k))
        Y = np.where(nudge > 0, np.nextafter(Y, np.inf),
                     np.where(nudge < 0, np.nextafter(Y, -np.inf), Y))
    elif kind == "exact_flat":  # exactly on a line / plane (40-bit mantissas: the
        # last coordinate is exact) while products of differences are not
        x = rng.integers(0, 2**40, (m, k - 1)) * 2.0**-40
        last = x @ np.array([3.0, -2.0][: k - 1]) + 0.25
        Y = np.column_stack([x, last])
    elif kind == "converged":  # 1e-15 across around 1e6
        Y = rng.uniform(-1, 1, k) * 1e6 + 1e-9 * rng.uniform(-1, 1, (m, k))
    elif kind == "tight":  # 1e-15 across around 1
        Y = rng.uniform(-1, 1, k) + 1e-15 * rng.uniform(-1, 1, (m, k))
    elif kind == "far_pivot":  # a 1e-7 cluster and far points (cancellation about them)
        Y = 0.5 + 1e-7 * rng.standard_normal((m, k))
        Y[: max(1, m // 4)] += 1e5 * rng.standard_normal((max(1, m // 4), k))
    elif kind == "grid":
        Y = rng.integers(-3, 4, (m, k)).astype(float)
    elif kind == "duplicates":
        base = rng.standard_normal((max(2, m // 3), k))
        Y = base[rng.integers(0, len(base), m)]
    else:
        raise ValueError(kind)
    return np.ascontiguousarray(Y, dtype=np.float64)


KINDS = [f"scale{e}" for e in SCALES] + [
    "subnormal", "mixed_points", "mixed_coords", "edges", "flat", "exact_flat", "flat_ulp",
    "converged",
    "tight", "far_pivot", "grid", "duplicates"]


def exact_view_of(X: np.ndarray):
    """(Yf, Yi, exact_view) of the distinct rows of X, as :func:`.kernel._clip_rows` makes
    them (the library's own exact_points and float_view)."""
    P = exact_points(np.unique(X, axis=0))
    rows = [tuple(r) for r in P.ints]
    Yf, _, ev = float_view(rows, P.scale)
    return Yf, rows, ev


# ------------------------------------------------------------------ side_signs itself


def _check_signs(Y, subsets, sg) -> int:
    """Every nonzero sign is the exact one and no member is decided; returns how many
    were decided."""
    decided = 0
    for t, sub in enumerate(subsets.tolist()):
        for q in np.flatnonzero(sg[t]).tolist():
            assert q not in sub, (sub, q)
            assert int(sg[t, q]) == orient(Y, (*sub, q)), (sub, q, Y.tolist())
            decided += 1
    return decided


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("kind", KINDS)
def test_side_signs_decide_only_exact_signs(kind, k):
    """On every hostile kind: each decided sign is the exact one (homogeneous det in
    Fractions), members and exact zeros stay 0, nothing is decided out of the
    expansions' range, and where the data are well conditioned nearly all is decided."""
    m = 9 if k == 2 else 8
    Y = hostile(kind, k, m, 16)
    subsets = _scan_np.k_subsets(m, k)
    with np.errstate(all="ignore"):
        sg = _scan_np.side_signs(Y, subsets)
    decided = _check_signs(Y, subsets, sg)
    if not _scan_np.in_range(Y):
        assert decided == 0
    if kind in ("scale0", "scale60", "mixed_points", "mixed_coords", "converged", "far_pivot"):
        assert decided >= 0.9 * len(subsets) * (m - k)
    if kind == "exact_flat":  # every orientation exactly 0, the products inexact
        assert not sg.any()


def test_side_signs_in_range_is_checked_and_edges_decide():
    """Range edges: coordinates ±2^±120 (inside) decide, ±2^121 / ±2^-121 (outside)
    decide nothing — the check is on the very array the filter evaluates."""
    for k in (2, 3):
        subsets = _scan_np.k_subsets(k + 3, k)
        Y = hostile("edges", k, k + 3, 1)
        assert _scan_np.in_range(Y)
        _check_signs(Y, subsets, _scan_np.side_signs(Y, subsets))
        for out in (2.0**121, 2.0**-121, 2.0**-1074, np.inf, np.nan):
            Z = np.random.default_rng(k).standard_normal((k + 3, k))
            Z[0, 0] = out
            with np.errstate(all="ignore"):
                assert not _scan_np.side_signs(Z, subsets).any()


#: four points at ~2^-360: the filter's products of three differences are subnormal
#: (~2^-1080), and evaluated anyway the pivots would prove the wrong sign (+1; exact −1)
UNDERFLOW = [[5.322449800010188e-109, 2.6612249000050942e-108, -3.3531433740064187e-108],
             [-3.193469880006113e-108, 0.0, -1.916081928003668e-108],
             [4.257959840008151e-109, 3.512816868006724e-108, 2.9805718880057055e-108],
             [-1.756408434003362e-108, 1.1709389560022414e-108, -1.2773879520024452e-108]]


def test_side_signs_range_guard_is_what_stops_a_subnormal_wrong_sign(monkeypatch):
    """Subnormal products lose relative accuracy, so a bound relative to the computed
    permanent is no proof: on UNDERFLOW the unguarded filter decides +1 where the exact
    sign is −1. The in_range guard (nonzero |coordinates| ≥ 2^-120, products ≥ 2^-568)
    rejects this input, so nothing is decided."""
    Y = np.array(UNDERFLOW)
    sub = np.array([[0, 1, 2]], dtype=np.int32)
    assert orient(Y, (0, 1, 2, 3)) == -1
    assert not _scan_np.in_range(Y)
    assert _scan_np.side_signs(Y, sub)[0, 3] == 0
    monkeypatch.setattr(_scan_np, "in_range", lambda Y: True)
    with np.errstate(all="ignore"):
        assert _scan_np.side_signs(Y, sub)[0, 3] == 1  # what the guard prevents


def test_side_signs_dependent_subsets_repeated_points_and_duplicates():
    """A subset with a repeated index, duplicate rows, a collinear triple in R^3: every
    det is exactly 0, so nothing is decided for them (and a point equal to a member is
    never decided either)."""
    rng = np.random.default_rng(3)
    for k in (2, 3):
        Y = rng.standard_normal((6, k))
        Y[1] = Y[0]  # duplicate rows
        Y[5] = Y[2] + (Y[3] - Y[2]) * 0.5  # on a segment (exactly, in binary)
        subsets = np.array([[0] * k, [0, 1] + [2] * (k - 2), [0, 0, 3][:k]], dtype=np.int32)
        sg = _scan_np.side_signs(Y, subsets)
        assert not sg.any()
        subs = _scan_np.k_subsets(6, k)
        sg = _scan_np.side_signs(Y, subs)
        _check_signs(Y, subs, sg)
        for t, sub in enumerate(subs.tolist()):
            if 0 in sub:
                assert sg[t, 1] == 0
            if 1 in sub:
                assert sg[t, 0] == 0
    Y = np.array([[0.1, 0.2, 0.3], [0.3, 0.6, 0.9], [0.2, 0.4, 0.6], [1.0, -1.0, 0.5]])
    subs = _scan_np.k_subsets(4, 3)
    _check_signs(Y, subs, _scan_np.side_signs(Y, subs))


def test_side_signs_start_is_kept_not_modified():
    """``start``: its nonzero entries come back unchanged (even ones the filter would
    call otherwise — it must not evaluate them), the zeros are evaluated, and the
    caller's array is not written."""
    Y = hostile("scale0", 3, 7, 2)
    subsets = _scan_np.k_subsets(7, 3)
    free = _scan_np.side_signs(Y, subsets)
    start = np.zeros_like(free)
    start[::2, 3] = 2
    start[1::2, 4] = -free[1::2, 4]  # deliberately wrong: must be kept as given
    before = start.copy()
    got = _scan_np.side_signs(Y, subsets, start)
    assert np.array_equal(start, before)
    keep = start != 0
    assert np.array_equal(got[keep], start[keep])
    assert np.array_equal(got[~keep], free[~keep])


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(k=st.sampled_from([2, 3]), seed=st.integers(0, 2**32 - 1),
       base=st.integers(-100, 100), spread=st.integers(-60, 40), ulps=st.integers(0, 3),
       far=st.booleans())
def test_side_signs_near_degenerate_hypothesis(k, seed, base, spread, ulps, far):
    """Points on a random affine (k − 1)-flat at 2^base, spread 2^spread along it, each
    coordinate nudged by up to ``ulps`` ulps (exact orientations tiny but mostly
    nonzero), optionally one far point: every decision exact."""
    rng = np.random.default_rng(seed)
    m = k + 3
    dirs = rng.standard_normal((k - 1, k)) * 2.0**spread
    Y = rng.standard_normal(k) * 2.0**base + rng.standard_normal((m, k - 1)) @ dirs
    for _ in range(ulps):
        step = rng.integers(-1, 2, (m, k))
        Y = np.where(step > 0, np.nextafter(Y, np.inf),
                     np.where(step < 0, np.nextafter(Y, -np.inf), Y))
    if far:
        Y[int(rng.integers(m))] += rng.standard_normal(k) * 2.0 ** (base + 40)
    Y = np.ascontiguousarray(Y)
    subsets = _scan_np.k_subsets(m, k)
    with np.errstate(all="ignore"):
        sg = _scan_np.side_signs(Y, subsets)
    _check_signs(Y, subsets, sg)


_SPECIAL = [0.0, -0.0, 1.0, -1.0, 0.5, 3.0, 2.0**-120, -(2.0**-120), 2.0**120, -(2.0**120),
            2.0**-121, 2.0**121, 5e-324, 2.0**-1022, 1e300, 1.0 + 2.0**-52, 1.0 - 2.0**-53]
_ANY_FLOAT = st.one_of(st.sampled_from(_SPECIAL), st.floats(allow_nan=True, allow_infinity=True),
                       st.floats(-(2.0**120), 2.0**120),
                       st.integers(-8, 8).map(lambda v: v * 2.0**-60 + 1.0))


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(k=st.sampled_from([2, 3]), data=st.data())
def test_side_signs_any_floats_hypothesis(k, data):
    """Arbitrary float64 points (special values, range edges, nan/inf, subnormals, values
    1 + j·2^-60 that collapse to neighbours): every sign decided is the exact one, and
    outside the expansions' range nothing is."""
    m = data.draw(st.integers(k + 1, k + 2))
    Y = np.array(data.draw(st.lists(st.lists(_ANY_FLOAT, min_size=k, max_size=k),
                                    min_size=m, max_size=m)), dtype=np.float64)
    subsets = _scan_np.k_subsets(m, k)
    with np.errstate(all="ignore"):
        sg = _scan_np.side_signs(Y, subsets)
    if not _scan_np.in_range(Y):
        assert not sg.any()
        return
    _check_signs(Y, subsets, sg)


# ------------------------------------------------------- classify's pair signs (start)


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("kind", KINDS)
def test_classify_pair_signs_are_exact(kind, k):
    """``classify(pairs=True)``'s signs (handed to the pivot filter as proven) with the
    c_err and underflow floor valid_halfspaces uses: each nonzero one exact, members 0;
    the counts are those of the signs."""
    m = 9 if k == 2 else 8
    Y = hostile(kind, k, m, 21)
    c_err = 4.0 * (3 * k + factorial(k) + 4) * UNIT_ROUNDOFF
    floor = underflow_floor(k, float(np.abs(Y).max()))
    subsets = _scan_np.k_subsets(m, k)
    W = np.arange(1, m + 1, dtype=np.int64)
    with np.errstate(all="ignore"):
        plus, minus, _, _, sg = _scan_np.classify(Y, W, subsets, c_err, m, floor, pairs=True)
    _check_signs(Y, subsets, sg)
    assert np.array_equal(plus, (sg == 1) @ W) and np.array_equal(minus, (sg == -1) @ W)


# ---------------------------------------------------------- exact side counts, pivots


def _brute_counts(Y, W, subsets):
    """(plus, minus, dependent) of every subset by the homogeneous determinant."""
    k = Y.shape[1]
    plus, minus, dep = [], [], []
    for sub in subsets.tolist():
        s = [0 if q in sub else orient(Y, (*sub, q)) for q in range(len(Y))]
        plus.append(sum(int(w) for w, v in zip(W, s, strict=True) if v > 0))
        minus.append(sum(int(w) for w, v in zip(W, s, strict=True) if v < 0))
        dep.append(not any(normal(Y, sub)) if k > 1 else False)
    return plus, minus, dep


@pytest.mark.parametrize("k", [2, 3])
@pytest.mark.parametrize("kind", ["scale-500", "scale119", "mixed_coords", "flat", "flat_ulp",
                                  "converged", "tight", "far_pivot", "grid",
                                  "subnormal", "edges"])  # duplicates: ≤ k distinct here
def test_exact_side_counts_with_pivots_against_brute_force(kind, k):
    """``_exact_side_counts(pivots=True)`` — with and without classify's pair signs as
    ``start`` — on the library's own exact view (distinct rows, weights 0, 1, 2^40):
    the counts and the dependence are those of the homogeneous determinant."""
    X = hostile(kind, k, 10 if k == 2 else 8, 5)
    Yf, Yi, ev = exact_view_of(X)
    m = len(Yi)
    assert m > k  # more distinct points than a subset
    W = np.array([0, 1, 2**40] * m, dtype=np.int64)[:m]
    subsets = _scan_np.k_subsets(m, k)
    want = _brute_counts(Yf, W, subsets) if ev else None
    c_err = 4.0 * (3 * k + factorial(k) + 4) * UNIT_ROUNDOFF
    with np.errstate(all="ignore"):
        *_, pairs = _scan_np.classify(Yf, W, subsets, c_err, m,
                                      underflow_floor(k, float(np.abs(Yf).max())), pairs=True)
    pivots = ev and _scan_np.in_range(Yf)  # as valid_halfspaces sets it
    for start in (None, pairs):
        got = halfspaces._exact_side_counts(Yf, Yi, W, subsets, int(W.sum()), False,
                                            pivots=pivots, start=start)
        if want is not None:
            assert [g.tolist() for g in got] == [list(w) for w in want]


# ------------------------------------------------------------- valid halfspaces, brute


def _canonical(a, b, unit) -> tuple[Fraction, ...]:
    """The row a·y ≤ b of units ``unit`` (y = unit · Yf) in Yf's units, scaled so
    that its first nonzero |a_j| is 1."""
    top = abs(next(Fraction(v) for v in a if v))
    return (*(Fraction(v) / top for v in a), Fraction(b) / unit / top)


def _brute_valid(Yf, W, F):
    """{(subset, sign): outside} of every independent k-subset with ≤ F weight strictly
    outside (sign +1: the + side is outside), and the set of its rows (canonical)."""
    k = Yf.shape[1]
    subsets = _scan_np.k_subsets(len(Yf), k)
    plus, minus, dep = _brute_counts(Yf, W, subsets)
    valid, rows = {}, set()
    for t, sub in enumerate(subsets.tolist()):
        if dep[t]:
            continue
        C = normal(Yf, sub)
        for sign, out in ((1, plus[t]), (-1, minus[t])):
            if out <= F:
                valid[(tuple(sub), sign)] = out
                a = [sign * c for c in C]
                b = sum(x * Fraction(v) for x, v in zip(a, Yf[sub[0]].tolist(), strict=True))
                rows.add(_canonical(a, b, 1))
    return valid, rows


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(k=st.sampled_from([2, 3]), kind=st.sampled_from(KINDS), seed=st.integers(0, 10**6),
       F=st.integers(1, 4))
def test_valid_halfspaces_small_path_against_brute_force(k, kind, seed, F):
    """The small path's valid halfspaces (pivot filter on) are exactly the brute-force
    ones: every row valid (its ``outside`` at most the exact count), and the same set
    of rows (rows of one plane deduplicated when exact); when the floats are not
    exact (c_err > 0) or k = 2, even the same (subset, sign) pairs."""
    X = hostile(kind, k, 9 if k == 2 else 7, seed)
    Yf, Yi, ev = exact_view_of(X)
    m = len(Yi)
    if m <= k or not ev:
        return
    W = np.random.default_rng(seed).integers(1, 3, m)
    hs = halfspaces.valid_halfspaces(Yf, Yi, W, F, ev)
    assert halfspaces.candidate_cost(m, k) <= halfspaces.SMALL_SCAN
    valid, rows = _brute_valid(Yf, W, F)
    got = {(tuple(t), int(s)): int(o) for t, s, o in
           zip(hs.through.tolist(), hs.sign.tolist(), hs.outside.tolist(), strict=True)}
    for key, out in got.items():  # ``outside``: the points surely outside, ≤ exact
        assert key in valid and out <= valid[key], (key, out, valid.get(key))
    unit = Fraction(Yi[0][0]) / Fraction(float(Yf[0, 0])) if Yf[0, 0] else Fraction(
        Yi[-1][-1]) / Fraction(float(Yf[-1, -1]))
    assert {_canonical(*hs.exact(h), unit) for h in range(len(hs))} == rows
    if hs.c_err != 0.0 or k == 2:
        assert set(got) == set(valid)


def _own_units(X: np.ndarray, k: int, F: int = 2, shift: int = 0) -> None:
    """valid_halfspaces(X, Yi, 1, F) with X in its own units, no float_view — Yi = X ·
    scale (exact_points), or with ``shift`` Yi = X / 2^shift (integers: a unit < 1) —
    against the brute force (see above)."""
    X = np.unique(X, axis=0)
    P = exact_points(X)
    Yi = [tuple(r) for r in P.ints]
    unit = Fraction(P.scale)
    if shift:
        Yi = [tuple(int(Fraction(v) / 2**shift) for v in r) for r in X.tolist()]
        unit = Fraction(1, 2**shift)
        assert all(y == unit * Fraction(v) for r, yr in zip(X.tolist(), Yi, strict=True)
                   for v, y in zip(r, yr, strict=True))  # Yi = Y · unit
    assert len(Yi) > k  # more distinct points than a subset
    W = np.ones(len(Yi), dtype=np.int64)
    with np.errstate(all="ignore"):
        hs = halfspaces.valid_halfspaces(X, Yi, W, F, True)
    valid, rows = _brute_valid(X, W, F)
    got = {(tuple(t), int(s)): int(o) for t, s, o in
           zip(hs.through.tolist(), hs.sign.tolist(), hs.outside.tolist(), strict=True)}
    for key, out in got.items():
        assert key in valid and out <= valid[key], (key, out, valid.get(key))
    assert {_canonical(*hs.exact(h), unit) for h in range(len(hs))} == rows
    if hs.c_err != 0.0 or k == 2:
        assert set(got) == set(valid)


@pytest.mark.parametrize(("kind", "k"), [(kind, k) for k in (2, 3) for kind in KINDS
                                         if kind != "subnormal"
                                         and (kind, k) != ("duplicates", 3)])  # ≤ k distinct
def test_valid_halfspaces_own_units_against_brute_force(kind, k):
    """``halfspaces.valid_halfspaces`` called directly with the data in their own units
    (Yf = X up to 2^±1000, no float_view rescaling; Yi = X · scale, exact_view): the
    same checks as above against the brute force (the pivot filter runs where X is in
    the expansions' range)."""
    _own_units(hostile(kind, k, 9 if k == 2 else 7, 3), k)


@pytest.mark.parametrize("k, e", [(2, -1000), (3, -400), (2, -1074), (3, -1074), (2, 1000),
                                  (3, 400)])
def test_valid_halfspaces_exact_floats_need_float_views_units(k, e):
    """A small-integer grid times 2^e handed to valid_halfspaces in its own units (Y = X
    exact, Yi = X · 2^-e: unit 2^-e, a power of two as its docstring asks): the rows
    must be the brute-force ones. Only direct calls get here (its one caller,
    kernel._clip_rows, passes float_view's Y with 2^-32 ≤ max |Y| < 2^32). It failed
    before exact_floats required that premise (k = 2, 2^-1000: 72 rows where 29 are
    valid; k = 3, 2^-400: none of 46): small integers over a unit of 2^1000 underflowed
    to 0, under 2^-1000 overflowed, and points counted as on the line."""
    G = hostile("grid", k, 9 if k == 2 else 7, 3)
    _own_units(G * 2.0**e, k, shift=max(e, 0))


# ---------------------------------------------------------------- the public results


def _summary(K) -> tuple:
    return (K.is_empty, K.dim, K.vertices.tobytes(), K.A.tobytes(), K.b.tobytes(),
            json.dumps(K.certificate, sort_keys=True))


class _Spy:
    """side_signs wrapped: counts the pairs it decided (the filter must have run)."""

    def __init__(self, real):
        self.real, self.decided = real, 0

    def __call__(self, Y, subsets, start=None):
        out = self.real(Y, subsets, start)
        self.decided += int(np.count_nonzero((out == 1) | (out == -1)))
        return out


def _paths(monkeypatch, X, F, numba: bool) -> list[tuple]:
    """safe_kernel(X, F) on the small path with the pivot filter, with the filter forced
    to decide nothing (every maybe-subset in integers, as test_halfspaces_pivots does),
    and — when ``numba`` — on the numba path (SMALL_SCAN = −1, as
    test_latency_contract does)."""
    out = [_summary(safe_kernel(X, F))]
    with monkeypatch.context() as mp:
        mp.setattr(_scan_np, "side_signs",
                   lambda Y, s, start=None: np.zeros((len(s), len(Y)), dtype=np.int8))
        out.append(_summary(safe_kernel(X, F)))
    if numba:
        with monkeypatch.context() as mp:
            mp.setattr(halfspaces, "SMALL_SCAN", -1)
            out.append(_summary(safe_kernel(X, F)))
    return out


PUBLIC = [("converged", 3, 20, 7), ("converged", 3, 16, 3), ("converged", 2, 30, 9),
          ("far_pivot", 3, 14, 2), ("far_pivot", 2, 25, 5), ("tight", 2, 24, 4),
          ("tight", 3, 12, 2), ("mixed_points", 3, 12, 2), ("mixed_coords", 2, 20, 3),
          ("flat_ulp", 3, 12, 2), ("flat_ulp", 2, 20, 4), ("scale-1000", 3, 12, 2),
          ("scale1000", 2, 20, 3), ("scale-500", 3, 12, 1), ("subnormal", 2, 20, 3),
          ("grid", 3, 14, 2), ("duplicates", 3, 15, 2), ("edges", 2, 18, 2)]


@pytest.mark.parametrize("kind, d, n, F", PUBLIC)
def test_safe_kernel_same_with_and_without_the_pivot_filter(monkeypatch, kind, d, n, F):
    """The public kernel (empty, dim, vertices, A, b, certificate) is bit-identical
    whether the pivot filter decides or the integers do."""
    X = hostile(kind, d, n, n + F)
    spy = _Spy(_scan_np.side_signs)
    monkeypatch.setattr(_scan_np, "side_signs", spy)
    a, b = _paths(monkeypatch, X, F, False)
    assert a == b


def test_the_public_comparison_reaches_the_filter(monkeypatch):
    """The comparison above is not vacuous: on the converged clouds the filter decides
    pairs inside safe_kernel."""
    spy = _Spy(_scan_np.side_signs)
    monkeypatch.setattr(_scan_np, "side_signs", spy)
    from benchmarks.kernel_clouds import make_cloud

    safe_kernel(make_cloud("converged", 3, 20, 7).X, 7)
    safe_kernel(hostile("converged", 3, 20, 27), 7)
    assert spy.decided > 0


@pytest.mark.slow
@settings(max_examples=60, deadline=None, suppress_health_check=[
    HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(kind=st.sampled_from(KINDS), d=st.sampled_from([2, 3]), seed=st.integers(0, 10**6),
       data=st.data())
def test_safe_kernel_three_paths_hypothesis(monkeypatch, kind, d, seed, data):
    """Random hostile clouds, d = 2 and 3, n ≤ 30 (≤ 20 in R^3: the small path): pivot
    filter, integers only and numba give the same kernel and certificate."""
    n = data.draw(st.integers(d + 2, 30 if d == 2 else 20))
    F = data.draw(st.integers(1, max(1, n // 3)))
    X = hostile(kind, d, n, seed)
    a, b, c = _paths(monkeypatch, X, F, True)
    assert a == b == c


def test_rescon_kernel_cli_same_with_and_without_the_pivot_filter(monkeypatch, tmp_path,
                                                                  capsys):
    """``rescon kernel`` on a converged cloud: the JSON (but the time) and the
    certificate file are the same with the pivot filter and with integers only."""
    from benchmarks.kernel_clouds import make_cloud
    from rescon.cli import main

    pts = tmp_path / "c.csv"
    pts.write_text("".join(",".join(map(repr, row)) + "\n"
                           for row in make_cloud("converged", 3, 20, 7).X.tolist()))
    outs = []
    for force in (False, True):
        with monkeypatch.context() as mp:
            if force:
                mp.setattr(_scan_np, "side_signs",
                           lambda Y, s, start=None: np.zeros((len(s), len(Y)), dtype=np.int8))
            cert = tmp_path / f"k{force}.json"
            assert main(["kernel", str(pts), "--F", "7", "--json", "--certificate",
                         str(cert)]) == 0
            data = json.loads(capsys.readouterr().out)
            data.pop("seconds")
            outs.append((data, cert.read_text()))
    assert outs[0] == outs[1]
    assert outs[0][0]["empty"] is True
    import rescon

    assert rescon.check_certificate(json.loads(outs[0][1])).valid


# ---------------------------------------------------------------- the rounded normals


@pytest.mark.parametrize(("k", "e"), [(k, e) for k in (3, 4)
                                      for e in (-600, -400, -119, 0, 119, 300, 400)
                                      if k == 3 or abs(e) <= 300])  # else beyond floats
@pytest.mark.parametrize("kind", ["tight", "converged", "flat_ulp", "far_pivot", "mixed_coords"])
def test_rounded_cofactors_are_float_of_the_exact_normal(kind, e, k):
    """``_rounded_cofactors`` = float(Fraction) of the cofactor normal of the float rows
    themselves (an oracle that never sees Yi or the unit), bit for bit, at scales where
    the normals are subnormal (2^-600 in R^3: ~2^-1200), tiny, huge (2^400: ~2^800) —
    or both raise OverflowError (2^600 in R^3 would; k = 3 reaches this only in the
    expansions' range, |Y| ≤ 2^120)."""
    X = np.unique(hostile(kind, k, 7, 9) * 2.0**e, axis=0)
    P = exact_points(X)
    rows = [tuple(r) for r in P.ints]
    Y = np.array([[v / P.scale for v in r] for r in rows])
    assert np.array_equal(Y, X)  # Y = Yi / unit exactly, unit = P.scale
    subsets = _scan_np.k_subsets(len(rows), k)
    try:
        want = np.array([[float(c) for c in normal(Y, s)] for s in subsets.tolist()])
    except OverflowError:
        with pytest.raises(OverflowError):
            halfspaces._rounded_cofactors(Y, rows, subsets)
        return
    got = halfspaces._rounded_cofactors(Y, rows, subsets)
    assert got.tobytes() == want.reshape(got.shape).tobytes()


def test_rounded_cofactors_overflow_raises_like_fraction():
    """A 3-D normal beyond the float range (data at 2^600, not reachable from the
    public path, which views |Y| ≤ 2^32): OverflowError, as float(Fraction) raises —
    never inf or a wrong finite value."""
    X = hostile("scale0", 3, 5, 1) * 2.0**600
    P = exact_points(X)
    Y = np.array([[v / P.scale for v in r] for r in P.ints])
    with pytest.raises(OverflowError):
        [float(c) for c in normal(Y, (0, 1, 2))]
    with pytest.raises(OverflowError):
        halfspaces._rounded_cofactors(Y, [tuple(r) for r in P.ints],
                                      np.array([[0, 1, 2]], dtype=np.int32))


def _quotient_cases(seed: int):
    r = random.Random(seed)
    for _ in range(400):
        e = r.choice([0, 1, 52, 500, 1021, 1022, 1023, 1074, 1075, 1076, 2000,
                      r.randrange(0, 3000)])
        t = max(0, e + r.randrange(-1100, 1030))
        c = r.choice([1 << t, (1 << t) - 1, (1 << t) + 1, r.getrandbits(t + 1) | 1,
                      ((1 << 53) - 1) << max(t - 53, 0),  # 53-bit odd part
                      ((1 << 54) + 1) << max(t - 54, 0),  # a tie of float(c) ± 1
                      (1 << max(t, 1)) - (1 << max(t - 54, 0))])  # rounds up a binade
        yield c * r.choice([1, -1]), e


def test_quotients_are_correctly_rounded():
    """``_quotients``(c, 1, 2^e) (float(c) scaled, int division below 2^-1022 or when
    float(c) overflows) and (c, 2^e, 1) against float(Fraction(c, 2^e)), around the
    subnormal edge (the double-rounding case: float(c) rounds c up to 2^(e − 1022)),
    the overflow edge and zero."""
    for c, e in _quotient_cases(16):
        for num, dnm in ((1, 1 << e), (1 << min(e, 60), 1)):
            try:
                want = float(Fraction(c * num, dnm))
            except OverflowError:
                with pytest.raises(OverflowError):
                    halfspaces._quotients([c], num, dnm)
                continue
            got = halfspaces._quotients([c, 0], num, dnm)
            assert got.tobytes() == np.array([want, 0.0]).tobytes(), (c, e, num)
    # double rounding below 2^-1022: c / 2^e = odd · 2^-1075 − 2^-e, just under a tie of
    # the subnormal grid; float(c) rounds the −1 away, and scaling that tie would round
    # it to even (up for odd ≡ 1 mod 4) where the correct rounding is down
    for e in (1100, 1500, 2000):
        for odd in (1, 3, 5, 7, (1 << 20) + 1, (1 << 51) - 1):
            for c in ((odd << (e - 1075)) - 1, (odd << (e - 1075)) + 1):
                want = float(Fraction(c, 1 << e))
                assert halfspaces._quotients([c, -c], 1, 1 << e).tobytes() == \
                    np.array([want, -want]).tobytes(), (e, odd)
    # the subnormal edge exactly: c / 2^e just below 2^-1022 rounds to 2^-1022
    e = 1100
    c = (1 << (e - 1022)) - 1
    assert halfspaces._quotients([c], 1, 1 << e)[0] == MIN_NORMAL == float(Fraction(c, 1 << e))
