"""Tests for rescon.geometry.tverberg.tverberg_partition.

Every partition found is re-verified here in exact arithmetic, independently of the
module (disjoint nonempty groups, weights > 0 summing to 1, Σ w x = y over Q), and
so is its ``kernel_point`` certificate, after a JSON round trip, both here and by the
standalone checker (rescon.check_certificate). Non-existence, a MILP claim, is
compared with a brute-force oracle (every partition, an LP each, via scipy).
"""

from __future__ import annotations

import doctest
import itertools
import json
from fractions import Fraction

import numpy as np
import pytest
from scipy.optimize import linprog

import rescon
from rescon.errors import InputError, SolverError, TimeLimitReached
from rescon.geometry import tverberg as tv
from rescon.geometry.tverberg import tverberg_partition


def tverberg_n(d: int, q: int) -> int:
    """Tverberg's number: any (d+1)(q−1)+1 points in R^d have a partition into q."""
    return (d + 1) * (q - 1) + 1


def exact_combination(X, group, weights) -> tuple[Fraction, ...]:
    return tuple(sum((Fraction(w) * Fraction(float(X[i][k])) for i, w in zip(group, weights)),
                     Fraction(0)) for k in range(len(X[0])))


def assert_partition(X, res, q: int) -> None:
    """res is an exact Tverberg partition of X into q groups with a valid certificate."""
    X = np.asarray(X, dtype=float)
    assert res.exists
    assert len(res.groups) == len(res.weights) == q
    flat = [i for g in res.groups for i in g]
    assert len(flat) == len(set(flat)) and all(0 <= i < len(X) for i in flat)
    for g, ws in zip(res.groups, res.weights):
        assert g and len(g) == len(ws) and list(g) == sorted(g)
        assert all(isinstance(w, Fraction) and w > 0 for w in ws) and sum(ws) == 1
        assert exact_combination(X, g, ws) == res.point_exact
    assert res.point.tolist() == [float(v) for v in res.point_exact]
    assert_certificate(X, res.certificate, q)


def assert_certificate(X, cert, q: int) -> None:
    """The kernel_point certificate, read back from JSON, proves x ∈ Ψ(X, q − 1)."""
    cert = json.loads(json.dumps(cert, allow_nan=False))
    assert set(cert) == {"rescon_certificate", "kind", "points", "F", "x", "proof"}
    assert cert["rescon_certificate"] == 1 and cert["kind"] == "kernel_point"
    assert cert["points"] == np.asarray(X, dtype=float).tolist()  # exact binary values
    assert cert["F"] == q - 1 and cert["proof"]["method"] == "tverberg"
    assert set(cert["proof"]) == {"method", "parts"}
    x = tuple(Fraction(s) for s in cert["x"])
    parts = cert["proof"]["parts"]
    assert len(parts) == cert["F"] + 1
    seen: set[int] = set()
    for part in parts:
        assert set(part) == {"indices", "weights"}
        idx, ws = part["indices"], [Fraction(s) for s in part["weights"]]
        assert idx and seen.isdisjoint(idx) and len(set(idx)) == len(idx) == len(ws)
        seen.update(idx)
        assert all(w >= 0 for w in ws) and sum(ws) == 1
        assert exact_combination(cert["points"], idx, ws) == x
    result = rescon.check_certificate(cert)  # the standalone checker agrees
    assert result.valid and not result.trusted, result.reason


def brute_force_exists(X, q: int) -> bool:
    """Does some partition of all points into q nonempty groups have a common point?
    (Covering all points loses nothing.) One feasibility LP per partition."""
    X = np.asarray(X, dtype=float)
    n, d = X.shape
    for labels in itertools.product(range(q), repeat=n):
        if labels[0] != 0 or set(labels) != set(range(q)):
            continue
        # unknowns: λ_i ≥ 0 (one per point) and y; Σ_{g(i)=p} λ_i (x_i, 1) = (y, 1)
        A = np.zeros((q * (d + 1), n + d))
        b = np.zeros(q * (d + 1))
        for p in range(q):
            for i in range(n):
                if labels[i] == p:
                    A[p * (d + 1): p * (d + 1) + d, i] = X[i]
                    A[p * (d + 1) + d, i] = 1.0
            A[p * (d + 1): p * (d + 1) + d, n:] = -np.eye(d)
            b[p * (d + 1) + d] = 1.0
        res = linprog(np.zeros(n + d), A_eq=A, b_eq=b,
                      bounds=[(0, None)] * n + [(None, None)] * d)
        if res.status == 0:
            return True
    return False


# --------------------------------------------------------------------------- #
# known configurations
# --------------------------------------------------------------------------- #


def test_square_diagonals():
    X = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
    res = tverberg_partition(X, 2)
    assert_partition(X, res, 2)
    assert res.groups == ((0, 2), (1, 3))
    assert res.weights == ((Fraction(1, 2),) * 2,) * 2
    assert res.point_exact == (1, 1)


def test_seven_points_in_the_plane_three_parts():
    rng = np.random.default_rng(7)
    for X in (rng.standard_normal((7, 2)),
              np.c_[np.cos(2 * np.pi * np.arange(7) / 7), np.sin(2 * np.pi * np.arange(7) / 7)]):
        assert_partition(X, tverberg_partition(X, 3), 3)


def test_checker_rejects_a_tampered_certificate():
    X = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]]
    cert = tverberg_partition(X, 2).certificate
    cert["proof"]["parts"][1]["weights"] = ["1/3", "2/3"]
    assert not rescon.check_certificate(cert).valid
    cert = tverberg_partition(X, 2).certificate
    cert["F"] = 2  # three parts needed
    assert not rescon.check_certificate(cert).valid


def test_three_collinear_points():
    X = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]]
    res = tverberg_partition(X, 2)
    assert_partition(X, res, 2)
    assert res.groups == ((0, 2), (1,)) and res.point_exact == (1, 1)


def test_duplicates():
    X = [[1.0, 2.0], [5.0, 5.0], [1.0, 2.0], [1.0, 2.0]]
    res = tverberg_partition(X, 3)
    assert_partition(X, res, 3)
    assert res.point_exact == (1, 2)
    assert tverberg_partition([[0.5, 0.5], [0.5, 0.5]], 2).exists


def test_line_median():
    X = [[3.0], [0.0], [4.0], [1.0], [2.0]]
    res = tverberg_partition(X, 3)
    assert_partition(X, res, 3)
    assert res.point_exact == (2,)


def test_space():
    rng = np.random.default_rng(3)
    for q in (2, 3):
        X = rng.standard_normal((tverberg_n(3, q), 3))
        assert_partition(X, tverberg_partition(X, q), q)


def test_one_part_is_a_single_point():
    X = np.array([[0.25, -1.0], [3.0, 4.0]])
    res = tverberg_partition(X, 1)
    assert_partition(X, res, 1)
    assert res.groups == ((0,),) and res.point_exact == (Fraction(1, 4), -1)
    assert res.certificate["F"] == 0


def test_integer_input_and_inexact_decimals():
    X = np.array([[0, 0], [10, 0], [0, 10], [3, 3]])
    res = tverberg_partition(X, 2)
    assert_partition(X, res, 2)
    assert res.groups == ((0, 1, 2), (3,)) and res.point_exact == (3, 3)
    Y = [[0.1, 0.2], [0.7, 0.1], [0.3, 0.9], [0.3, 0.3]]  # not dyadic: exact binary values
    assert_partition(Y, tverberg_partition(Y, 2), 2)


def test_result_is_read_only():
    res = tverberg_partition([[0.0], [1.0], [2.0]], 2)
    with pytest.raises(ValueError):
        res.point[0] = 1.0
    with pytest.raises(AttributeError):
        res.exists = False


# --------------------------------------------------------------------------- #
# random sets: Tverberg's bound always gives a partition; Carathéodory-sized groups
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("d,q", [(1, 2), (1, 4), (2, 2), (2, 3), (2, 4), (3, 2), (3, 3)])
@pytest.mark.parametrize("extra", [0, 2])
def test_random_sets_at_tverberg_bound(d, q, extra):
    rng = np.random.default_rng(100 * d + 10 * q + extra)
    X = rng.uniform(-5, 5, size=(tverberg_n(d, q) + extra, d))
    res = tverberg_partition(X, q)
    assert_partition(X, res, q)
    assert all(len(g) <= d + 1 for g in res.groups)  # basic solutions


@pytest.mark.parametrize("seed", range(3))
def test_exact_simplex_fallback(monkeypatch, seed):
    """With the fast support path disabled, the exact simplex rebuilds every answer."""
    monkeypatch.setattr(tv, "_from_support", lambda *args: None)
    rng = np.random.default_rng(seed)
    X = rng.integers(-3, 4, size=(7, 2)).astype(float)  # many degeneracies
    assert_partition(X, tverberg_partition(X, 3), 3)


def test_non_unique_point_needs_the_simplex():
    """Four collinear points in the plane, groups {0, 2} and {1, 3}: the hulls overlap
    in a segment, so the supports do not fix y; the exact simplex settles it."""
    X = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]]
    P = [tuple(map(Fraction, row)) for row in X]
    groups, lam = [[0, 2], [1, 3]], np.array([[0.5, 0.0], [0.0, 0.5], [0.5, 0.0], [0.0, 0.5]])
    assert tv._from_support(P, groups, lam) is None
    exact = tv._from_simplex(P, groups, lam)
    assert exact is not None and all(w and set(w) <= set(g) for w, g in zip(exact, groups))
    y = {exact_combination(X, list(w), list(w.values())) for w in exact}
    assert len(y) == 1 and all(sum(w.values()) == 1 for w in exact)


def test_phase_one():
    one, zero = Fraction(1), Fraction(0)
    # x0 + x1 = 1, x0 − x1 = 0  →  (1/2, 1/2)
    assert tv._phase_one([[one, one], [one, -one]], [one, zero], [1, 0]) == [one / 2] * 2
    # x0 + x1 = 1, x0 + x1 = 2: infeasible; x0 − x1 = 1, x1 ≥ 0 ... −x0 = 1: infeasible
    assert tv._phase_one([[one, one], [one, one]], [one, 2 * one], [0, 1]) is None
    assert tv._phase_one([[-one]], [one], [0]) is None


# --------------------------------------------------------------------------- #
# no partition: a MILP claim, compared with the brute-force oracle
# --------------------------------------------------------------------------- #


def test_triangle_has_no_radon_partition():
    res = tverberg_partition([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], 2)
    assert not res.exists
    assert res.groups == () and res.weights == () and res.point_exact == ()
    assert res.point.shape == (0,) and res.certificate == {}


def test_distinct_points_cannot_each_be_a_group():
    assert not tverberg_partition([[0.0, 0.0], [1.0, 0.0]], 2).exists
    assert not tverberg_partition(np.eye(4), 2).exists  # affinely independent in R^4


@pytest.mark.parametrize("seed", range(6))
def test_existence_matches_brute_force(seed):
    rng = np.random.default_rng(seed)
    n, q = (5, 2) if seed % 2 else (6, 3)
    X = rng.integers(0, 4, size=(n, 2)).astype(float)  # below Tverberg's bound
    res = tverberg_partition(X, q)
    assert res.exists == brute_force_exists(X, q)
    if res.exists:
        assert_partition(X, res, q)


def test_near_degenerate_points_are_refused():
    """0.5 + 2^-40 puts the third point off the line through the others by far less
    than HiGHS's tolerance: the MILP's groups have no exact common point."""
    X = [[0.0, 0.0], [1.0, 1.0], [0.5, 0.5 + 2.0**-40]]
    with pytest.raises(SolverError, match="no exact common point"):
        tverberg_partition(X, 2)


def test_infeasible_claim_against_tverberg_is_an_error(monkeypatch):
    monkeypatch.setattr(tv, "_milp", lambda *args: None)
    with pytest.raises(SolverError, match="contradicting Tverberg"):
        tverberg_partition(np.random.default_rng(0).standard_normal((4, 2)), 2)


# --------------------------------------------------------------------------- #
# input validation and time limit
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("X,match", [
    ([1.0, 2.0], r"\(n, d\) array"),
    (np.zeros((2, 2, 2)), r"\(n, d\) array"),
    (np.zeros((0, 2)), r"\(n, d\) array"),
    (np.zeros((3, 0)), r"\(n, d\) array"),
    ([["a", "b"]], r"\(n, d\) array"),
    (np.ones((2, 2), dtype=bool), r"\(n, d\) array"),
    (np.ones((2, 2), dtype=complex), "must be real"),
    ([[0.0, np.nan], [np.inf, 1.0]], "must be finite.* 1 NaN and 1 infinite"),
    ([[2**60 + 1, 0], [0, 1]], "2\\^53"),
])
def test_bad_points(X, match):
    with pytest.raises(InputError, match=match):
        tverberg_partition(X, 1)


@pytest.mark.parametrize("parts", [0, 4, -1, 2.0, True, "2", None])
def test_bad_parts(parts):
    with pytest.raises(InputError, match=r"parts must be an integer in \[1, 3\]"):
        tverberg_partition(np.zeros((3, 2)), parts)


@pytest.mark.parametrize("limit", [0, -1.0, float("nan"), float("inf"), "1", True])
def test_bad_time_limit(limit):
    with pytest.raises(InputError,
                       match="time_limit must be a (real number|finite number of seconds > 0)"):
        tverberg_partition(np.zeros((3, 2)), 2, time_limit=limit)


def test_unknown_keyword():
    with pytest.raises(TypeError):
        tverberg_partition(np.zeros((3, 2)), 2, method="milp")


def test_numpy_integer_parts():
    X = np.zeros((3, 1))
    assert_partition(X, tverberg_partition(X, np.int64(3)), 3)


def test_time_limit():
    X = np.random.default_rng(1).standard_normal((64, 2))
    with pytest.raises(TimeLimitReached, match="time limit of 0.01 s"):
        tverberg_partition(X, 22, time_limit=0.01)


def test_docstring_examples():
    result = doctest.testmod(tv, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0
