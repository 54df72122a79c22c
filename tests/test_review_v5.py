"""Review V5 (hostile): this session's d = 4–5 safe-kernel changes — the scan's octant
prune (``_candidates._prefix_octants``), the modular keys of joggled proposals
(``_certify_nb``), the d ≥ 5 qhull option chain, the in-place lex order of tied
floats — on data chosen to break them: per-coordinate magnitudes 1e±150 and 1e±300,
collinear prefixes, points one ulp apart, subnormal integers, cross-polytope and
24-cell clouds. Every octant the float filter calls sure is checked against exact
rational arithmetic, every pruned subset against exact counts, and whole kernels
(floats bit for bit, exact vertices, certificates) against the exact clipping."""

from __future__ import annotations

import itertools
import pickle
import warnings
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from rescon.geometry import _candidates, _scan_np
from tests.test_kernel_d45_around2 import (
    _cell24,
    _exact_sides,
    _integers,
    _same_as_clipping,
    _scan_args,
)


def _hostile(kind: str, d: int, n: int, seed: int) -> np.ndarray:
    """Clouds the earlier tests do not cover."""
    rng = np.random.default_rng([seed, d, n, 55])
    Z = rng.normal(size=(n, d))
    if kind == "gaussian":
        return Z
    if kind == "aniso":  # one magnitude per coordinate, 1e-150..1e150
        return Z * np.array([1e150, 1e-150, 1.0, 1e100, 1e-100][:d])
    if kind == "aniso300":
        return Z * np.array([1e300, 1.0, 1e-300, 1.0, 1.0][:d])
    if kind == "collinear":  # half the points on one line through 0: collinear prefixes
        Z[: n // 2] = rng.normal(size=(n // 2, 1)) * Z[0]
        return Z
    if kind == "ulps":  # every coordinate 0.7 or its neighbour float
        return np.nextafter(np.full((n, d), 0.7), 2.0 * (rng.random((n, d)) < 0.5))
    if kind == "big_offset":  # converged at 1e15: integers a few units apart
        return 1e15 + np.round(2 * Z)
    if kind == "subnormal_int":  # small integers times the smallest subnormal
        return np.round(3 * Z) * 5e-324
    if kind == "cross":  # the cross-polytope's vertices, three times each
        return np.tile(np.vstack([np.eye(d), -np.eye(d)]), (3, 1))[:n] * 3.0
    if kind == "cell24":
        return np.vstack([_cell24(), np.tile([0.5, 0.25, 0.0, 0.0], (max(n - 24, 0), 1))])[:n]
    raise KeyError(kind)


KINDS = ("gaussian", "aniso", "aniso300", "collinear", "ulps", "big_offset", "subnormal_int",
         "cross")


def _det(rows: list[list[Fraction]]) -> Fraction:
    M = [list(r) for r in rows]
    out = Fraction(1)
    for c in range(len(M)):
        piv = next((r for r in range(c, len(M)) if M[r][c] != 0), None)
        if piv is None:
            return Fraction(0)
        if piv != c:
            M[c], M[piv] = M[piv], M[c]
            out = -out
        out *= M[c][c]
        for r in range(c + 1, len(M)):
            f = M[r][c] / M[c][c]
            M[r] = [x - f * y for x, y in zip(M[r], M[c], strict=True)]
    return out


def _exact_octant(x: Fraction, y: Fraction) -> int:
    """The open octant of (x, y), counterclockwise from the positive x axis; 8 on an
    axis or a diagonal."""
    if x == 0 or y == 0 or abs(x) == abs(y):
        return 8
    quadrant = {(True, True): 0, (False, True): 1, (False, False): 2, (True, False): 3}[
        (x > 0, y > 0)]
    wide = abs(x) > abs(y)
    return 2 * quadrant + (wide if quadrant % 2 else not wide)


def _check_octants(Y: np.ndarray, idx: np.ndarray, exact: bool) -> int:
    """Runs _prefix_octants for the prefix idx[:k − 1] and checks every point it puts
    in an octant against ω(e_a, q − p_0), ω(e_b, q − p_0) in rationals; the number of
    sure points."""
    m, k = Y.shape
    c_err, floor = _scan_args(Y, exact)
    R, mdet, mper = np.empty((k - 1, k)), np.empty(1 << k), np.empty(1 << k)
    C, Cabs, S, T = np.empty(k), np.empty(k), np.empty(m), np.empty(m)
    octant, weight = np.empty(m, dtype=np.int64), np.zeros(9, dtype=np.int64)
    _candidates._prefix_minors(Y, idx, k, R, mdet, mper)
    _candidates._prefix_octants(Y, np.ascontiguousarray(Y.T), idx, k, R, mdet, mper, c_err,
                                floor, float(np.abs(Y).max()), C, Cabs, S, T, octant,
                                weight, np.ones(m, dtype=np.int64))
    full = (1 << k) - 1
    a, b, top = 0, 1, -1.0  # the columns of the largest minor, as the filter picks them
    for i, j in itertools.combinations(range(k), 2):
        if abs(mdet[full ^ (1 << i) ^ (1 << j)]) > top:
            a, b, top = i, j, abs(mdet[full ^ (1 << i) ^ (1 << j)])
    Yf = [[Fraction(float(v)) for v in row] for row in Y]
    p0 = Yf[idx[0]]
    rows = [[x - y for x, y in zip(Yf[i], p0, strict=True)] for i in idx[1:k - 1]]
    unit = [[Fraction(int(j == c)) for j in range(k)] for c in (a, b)]
    sure = 0
    for q in np.flatnonzero(octant != 8).tolist():
        diff = [x - y for x, y in zip(Yf[q], p0, strict=True)]
        x, y = (_det([*rows, e, diff]) for e in unit)
        assert octant[q] == _exact_octant(x, y), (q, float(x), float(y))
        sure += 1
    assert weight.sum() == m
    return sure


@pytest.mark.parametrize("kind,k", [*itertools.product((*KINDS, "integers"), (4, 5)),
                                    ("cell24", 4)])
def test_every_sure_octant_is_the_exact_octant(kind, k):
    """Each point the float filter puts in an open octant of the prefix's plane lies
    there exactly (a wrong octant would prune a subset with ≤ F points on a side),
    for every 7th prefix of 12 hostile points (29th of the 24-cell); exact float
    arithmetic (c_err = 0) on the integer clouds."""
    exact = kind in ("integers", "cell24", "cross")
    Y = (np.round(3 * np.random.default_rng(k).normal(size=(12, k))) if kind == "integers"
         else _hostile(kind, k, 12 if kind != "cell24" else 24, 1))
    Y = np.ascontiguousarray(Y, dtype=np.float64)
    sure = sum(_check_octants(Y, np.array(p, dtype=np.int64), exact)
               for p in itertools.islice(itertools.combinations(range(len(Y)), k), 0, None,
                                         29 if kind == "cell24" else 7))
    if kind in ("integers", "collinear", "cell24"):
        assert sure > 0  # the filter decides something on these


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**20), kind=st.sampled_from(KINDS), k=st.sampled_from([4, 5]),
       F=st.integers(0, 3))
def test_pruned_subsets_have_more_than_F_points_on_both_sides(seed, kind, k, F):
    """Random hostile clouds (m = 14 − 15 points, weights 1–2): a subset the octant
    prune reports (F + 1 on both sides, differing from the numpy twin, which counts
    every point) has more than F points strictly on each side, counted exactly; every
    other subset's counts equal the twin's."""
    m = 15 if k == 4 else 14
    Y = np.ascontiguousarray(_hostile(kind, k, m, seed), dtype=np.float64)
    Y = Y[np.sort(np.unique(Y, axis=0, return_index=True)[1])]
    W = np.random.default_rng(seed).integers(1, 3, size=len(Y)).astype(np.int64)
    subsets = _scan_np.k_subsets(len(Y), k)
    c_err, floor = _scan_args(Y, False)
    got = _candidates.classify(Y, W, subsets, c_err, F, floor)
    twin = _scan_np.classify(Y, W, subsets, c_err, F, floor)
    assert np.array_equal(got[3], twin[3])
    Yi = _integers(Y)
    for t in np.flatnonzero((got[0] != twin[0]) | (got[1] != twin[1]) | (got[2] != twin[2])):
        assert (got[0][t], got[1][t], got[2][t]) == (F + 1, F + 1, 0)
        plus, minus, dependent = _exact_sides(Yi, W, subsets[t].tolist())
        assert not dependent and plus > F and minus > F


KERNELS = [("aniso", 4, 16, 0), pytest.param("aniso", 4, 16, 2, marks=pytest.mark.slow),
           ("collinear", 4, 16, 3),
           ("ulps", 4, 16, 2), ("ulps", 5, 15, 2), ("big_offset", 4, 16, 0),
           ("subnormal_int", 4, 16, 1), ("cross", 4, 16, 2), ("cross", 5, 15, 3),
           ("cell24", 4, 26, 4), ("cell24", 4, 24, 1),
           pytest.param("aniso", 5, 15, 1, marks=pytest.mark.slow),  # 2-20 s at load 2-7
           pytest.param("collinear", 5, 15, 1, marks=pytest.mark.slow),
           pytest.param("big_offset", 5, 15, 1, marks=pytest.mark.slow),
           pytest.param("aniso300", 4, 16, 1, marks=pytest.mark.slow)]


@pytest.mark.parametrize("kind,d,n,F", KERNELS)
def test_hostile_kernels_identical_to_the_exact_clipping(kind, d, n, F, monkeypatch):
    """Whole kernels — floats bit for bit, exact vertices and rows, certificate — equal
    the exact clipping's on the clouds above (the octant prune runs in both: its scan
    has ≥ 16 points in d = 4, 15 in d = 5); the certificate is never called invalid,
    and the kernel survives pickling unchanged."""
    K = _same_as_clipping(_hostile(kind, d, n, 7), F, monkeypatch)
    assert rescon.check_certificate(K.certificate).verdict != "invalid"
    back = pickle.loads(pickle.dumps(K))
    for name in ("vertices", "A", "b", "Aeq", "beq", "affine_basis"):
        assert getattr(back, name).tobytes() == getattr(K, name).tobytes(), name
    assert back.exact_vertices == K.exact_vertices
    assert back._exact.constraints == K._exact.constraints
    assert back.certificate == K.certificate


@pytest.mark.parametrize("kind,d,n,F", [pytest.param("aniso", 4, 16, 2, marks=pytest.mark.slow),
                                        ("collinear", 4, 16, 3),
                                        ("subnormal_int", 4, 16, 1), ("cross", 5, 15, 3)])
def test_joggled_hostile_kernels_identical_to_the_exact_clipping(kind, d, n, F,
                                                                 monkeypatch):
    """Joggled proposals only (one modular key per point, the rest dropped): the same
    kernels as the exact clipping."""
    from rescon.geometry import fastpath

    monkeypatch.setattr(fastpath, "QHULL_OPTIONS", ("QJ",))
    _same_as_clipping(_hostile(kind, d, n, 7), F, monkeypatch)


@pytest.mark.slow
@pytest.mark.parametrize("d,N", [(4, 10), (5, 8)])
def test_simulate_d45_identical_without_the_fast_path(d, N, monkeypatch):
    """simulate in d = 4–5 with the kernel algorithm (safe-kernel points of the
    converging states): trajectories and every monitor bit-identical with the fast
    path switched off."""
    import networkx as nx

    from rescon.consensus.adversaries import RandomInBox
    from rescon.consensus.engine import simulate
    from rescon.consensus.scenario import Scenario
    from rescon.geometry import kernel as km

    x0 = np.random.default_rng(d).normal(size=(N, d))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = Scenario(nx.complete_graph(N), x0, 1, adversaries={0: RandomInBox(3.0)},
                      steps=4 if d == 4 else 2, algorithm="kernel", seed=3, model="total",
                      check_robustness=False)
        fast = simulate(sc, progress=False)
        monkeypatch.setattr(km, "certified_kernel", lambda *a: None)
        slow = simulate(sc, progress=False)
    assert np.asarray(fast.states).tobytes() == np.asarray(slow.states).tobytes()
    assert fast.metrics.keys() == slow.metrics.keys()
    for name, values in fast.metrics.items():
        assert np.asarray(values).tobytes() == np.asarray(slow.metrics[name]).tobytes(), name
