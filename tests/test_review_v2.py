"""Review V2 of the d = 4-5 safe-kernel fast path: failures found by fuzzing safe_kernel
against the exact clipping (the fast path switched off), and the attacks that held."""

from __future__ import annotations

import concurrent.futures
import gc
import itertools
from fractions import Fraction

import numpy as np
import pytest

import rescon
from rescon.geometry import fastpath
from rescon.geometry import kernel as km
from rescon.geometry.exact import float_view, solve_exact
from rescon.geometry.halfspaces import valid_halfspaces

#: a collinear triple (rows 0, 1, 2 of the d = 4 cloud; 0, 1, 2 of the d = 5 one) in
#: coordinates too large for exact float orientations: the float scan leaves every point
#: of an affinely dependent subset undecided, and with F ≥ that count it passed as "sure"
DEGENERATE = [
    (np.array([[1476, -2156, 516, -835], [17, 1128, -299, 831], [-1442, 4412, -1114, 2497],
               [-1605, 1526, -27, 449], [2762, 1512, -1995, 10], [1824, -1534, 2049, 963]],
              dtype=float), 2),
    (np.array([[697565811523.0, 793062429521.0, 1029678217053.0, 939546592337.0, 602975389969.0],
               [76576528871.0, 190428594171.0, 1015648457710.0, 543836510904.0, 142037470447.0],
               [-544412753781.0, -412205241179.0, 1001618698367.0, 148126429471.0,
                -318900449075.0],
               [856067122097.0, 1024398219945.0, 627105880081.0, 161108289404.0, 424038546139.0],
               [1068429923905.0, 840076717167.0, 1030204008623.0, 89625149635.0, 672497636319.0],
               [331046177680.0, 472399421124.0, 886802054933.0, 841105842907.0, 41854813714.0],
               [839342414309.0, 212505908990.0, 850525921651.0, 637982672376.0, 873130960236.0]]),
     6),
]


def _clipped(X, F):
    """safe_kernel with the fast path switched off (benchmarks/kernel_d45_bench.py)."""
    saved = km.certified_kernel
    km.certified_kernel = lambda *a: None
    try:
        return rescon.safe_kernel(X, F)
    finally:
        km.certified_kernel = saved


def _cell24() -> np.ndarray:
    """The 24 vertices of the 24-cell, permutations of (±1, ±1, 0, 0): many points on
    each hyperplane through four of them."""
    pts = set()
    for i, j in itertools.combinations(range(4), 2):
        for s, t in itertools.product((-1, 1), repeat=2):
            v = [0, 0, 0, 0]
            v[i], v[j] = s, t
            pts.add(tuple(v))
    return np.array(sorted(pts), dtype=float)


@pytest.mark.parametrize("case", range(len(DEGENERATE)))
def test_an_affinely_dependent_subset_is_dropped_not_divided_by_zero(case):
    # was: ZeroDivisionError in halfspaces._primitive (the zero normal of the subset)
    X, F = DEGENERATE[case]
    K = rescon.safe_kernel(X, F)
    assert K.is_empty
    assert rescon.check_certificate(K.certificate).verdict == "valid"


def test_the_fast_path_states_each_facet_once():
    # a converged 24-cell (inexact floats: no exact dedup of equal rows): the fast path
    # listed 257 facet rows, the same 96 hyperplanes that the exact clipping lists once
    X = 1.0 + 1e-13 * _cell24()
    K = rescon.safe_kernel(X, 4)
    rows = {(tuple(a), b) for a, b in zip(K.A.tolist(), K.b.tolist(), strict=True)}
    assert len(K.A) == len(rows) == 96
    assert len(K.certificate["facets"]) == 96
    assert rescon.check_certificate(K.certificate).verdict != "invalid"


@pytest.mark.slow
def test_the_fast_path_facets_are_the_clippings():
    X = 1.0 + 1e-13 * _cell24()
    fast, slow = rescon.safe_kernel(X, 4), _clipped(X, 4)
    assert sorted(fast.exact_vertices) == sorted(slow.exact_vertices)
    assert np.array_equal(fast.A, slow.A) and np.array_equal(fast.b, slow.b)
    assert fast.certificate["facets"] == slow.certificate["facets"]


def test_a_basis_whose_determinant_is_the_prime_is_solved_by_the_fallback():
    # rows y1 = 0, y2 = 0, y3 = 0 and y1 + y2 + y3 + p y4 = 2p (p = fastpath.PRIME)
    # through data points: det A = ±p ≡ 0 (mod p) although the rows are independent
    p = fastpath.PRIME
    pts = [(0, 1, 0, 0), (0, 0, 1, 0), (0, 1, 1, 0), (0, 2, 1, 1), (1, 0, 0, 0), (1, 0, 1, 1),
           (2, 0, 1, 0), (1, 1, 0, 0), (2, 1, 0, 1), (2 * p, 0, 0, 0), (0, 2 * p, 0, 0),
           (0, 0, 2 * p, 0), (0, 0, 0, 2)]
    Yf, unit, exact_view = float_view(pts, 1)
    H = valid_halfspaces(Yf, pts, np.ones(len(pts), dtype=np.int64), 0, exact_view)

    def row(normal):
        return next(h for h in range(len(H)) if any(H.exact(h)[0]) and all(
            a * c == b * e for (a, e), (b, c) in itertools.product(
                zip(H.exact(h)[0], normal), repeat=2)))

    T = [row(v) for v in [(1, 0, 0, 0), (0, 1, 0, 0), (0, 0, 1, 0), (1, 1, 1, p)]]
    A = np.array([[v % p for v in H.exact(h)[0]] for h in T], dtype=np.int64)[None]
    assert fastpath._det_mod(A, p).tolist() == [0]
    (w, *y), = fastpath._solve_all(H, [T], 4)
    want = solve_exact([[Fraction(v) for v in H.exact(h)[0]] for h in T],
                       [Fraction(H.exact(h)[1]) for h in T])
    assert [Fraction(v, w * unit) for v in y] == list(want) == [0, 0, 0, 2]


def test_a_tiny_prime_sends_most_bases_to_the_fallback_with_the_same_kernel(monkeypatch):
    X = np.random.default_rng(7).integers(-2, 3, size=(18, 4)).astype(float) / 4
    slow = _clipped(X, 2)
    monkeypatch.setattr(fastpath, "PRIME", 2)
    certified = []
    real = km.certified_kernel
    monkeypatch.setattr(km, "certified_kernel", lambda *a: certified.append(real(*a))
                        or certified[-1])
    fast = rescon.safe_kernel(X, 2)
    assert certified and certified[0] is not None
    assert sorted(fast.exact_vertices) == sorted(slow.exact_vertices)
    assert rescon.check_certificate(fast.certificate).verdict != "invalid"


@pytest.mark.parametrize("was_on", [True, False])
def test_the_collector_is_restored_after_an_interrupt_inside_the_fast_path(was_on,
                                                                           monkeypatch):
    def interrupted(*a, **k):
        raise KeyboardInterrupt

    X = np.random.default_rng(3).normal(size=(22, 4))
    monkeypatch.setattr(fastpath, "_closed", interrupted)
    before = gc.isenabled()
    (gc.enable if was_on else gc.disable)()
    try:
        with pytest.raises(KeyboardInterrupt):
            rescon.safe_kernel(X, 2)
        assert gc.isenabled() == was_on
    finally:
        (gc.enable if before else gc.disable)()


def test_the_collector_is_restored_after_two_threads():
    Xs = [np.random.default_rng(s).normal(size=(22, 4)) for s in range(4)]
    assert gc.isenabled()
    with concurrent.futures.ThreadPoolExecutor(2) as pool:
        together = list(pool.map(lambda X: rescon.safe_kernel(X, 2), Xs))
    assert gc.isenabled()
    for X, K in zip(Xs, together, strict=True):
        assert sorted(K.exact_vertices) == sorted(rescon.safe_kernel(X, 2).exact_vertices)
