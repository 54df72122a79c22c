"""Safe kernels of data whose columns are in different units (issue 13, reviewer V17).

Ψ(XD) = Ψ(X)D for an invertible diagonal D, and :func:`rescon.geometry.kernel._clip_rows`
clips the pivot rows with their columns shifted to one magnitude
(:func:`rescon.geometry.kernel._column_shifts`) and maps the exact answer back
(:func:`rescon.geometry.kernel._unshifted`). Checked here: the kernel of XD is that of X
mapped by D exactly (D a power of two per column), equals the answer of the rows
clipped as given (any D), keeps the fast path, certifies, and an empty kernel's Farkas
multipliers survive the map; data whose columns are of like size is untouched.
"""

from __future__ import annotations

import contextlib
import math
from fractions import Fraction

import numpy as np
import pytest

import rescon
from rescon.geometry import kernel as km
from tests.test_kernel_d45_around2 import _cloud, assert_identical
from tests.test_review_v17 import _fast_path_certifies, _hostile

POW2 = [np.array([16, 0, -16, 8]), np.array([600, 0, -600, 300]),
        np.array([-20, 40, 0, -600])]


def _factors(exps: np.ndarray, d: int) -> np.ndarray:
    return 2.0 ** np.resize(exps, d)


@contextlib.contextmanager
def _as_is(monkeypatch):
    """A context in which the rows are clipped as given (the rescale disabled)."""
    with monkeypatch.context() as m:
        m.setattr(km, "COLUMN_SPREAD_MAX_BITS", math.inf)
        yield


def _direction_set(rows, factors=None) -> set:
    """Ambient rows a·x ≤ b (Fractions) as a set of (a, b) / max|a_j|; with ``factors``
    (powers of two, exact) the rows of the image set {x D}: (a D⁻¹)·x' ≤ b."""
    out = set()
    for a, b in rows:
        if factors is not None:
            a = [Fraction(v) / Fraction(f) for v, f in zip(a, factors, strict=True)]
        top = max(abs(Fraction(v)) for v in a)
        out.add((tuple(Fraction(v) / top for v in a), Fraction(b) / top))
    return out


def _certified(cert: dict) -> None:
    """The checker accepts the certificate: valid, or — for data at 2^±600, whose
    hyperplanes are ~2000-bit numbers — unchecked beyond its work limit (never
    invalid)."""
    r = rescon.check_certificate(cert)
    assert r.verdict == "valid" or (r.verdict == "unchecked" and "needs work" in str(r)), r




CLOUDS = [("gaussian", 2, 12, 2), ("sphere", 2, 15, 3), ("gaussian", 3, 16, 2),
          ("cube", 3, 20, 3), ("gaussian", 4, 20, 2), ("integer", 4, 20, 3),
          ("nearsame", 4, 20, 2), ("cell24", 4, 28, 4), ("flat", 4, 20, 2),
          ("gaussian", 5, 14, 1), ("sphere", 5, 14, 1)]


@pytest.mark.parametrize("exps", POW2, ids=["16", "600", "mixed"])
@pytest.mark.parametrize("kind,d,n,F", CLOUDS)
def test_the_kernel_of_xd_is_the_kernel_of_x_mapped_by_d(kind, d, n, F, exps):
    """D = diag(2^{e_j}): Ψ(XD) = Ψ(X)D exactly — vertices, dim, the facets' set — and
    the certificate of Ψ(XD) passes the checker."""
    X = _cloud(kind, d, n, F)
    f = _factors(exps, d)
    K, L = rescon.safe_kernel(X, F), rescon.safe_kernel(X * f, F)
    assert L.dim == K.dim and L.is_empty == K.is_empty
    scaled = sorted(tuple(v * Fraction(c) for v, c in zip(x, f, strict=True))
                    for x in K.exact_vertices)
    assert sorted(L.exact_vertices) == scaled
    assert _direction_set(L._exact.facets) == _direction_set(K._exact.facets, f)
    assert _direction_set(L._exact.constraints) == _direction_set(K._exact.constraints, f)
    _certified(L.certificate)


UNITS = [np.array([1e6, 1.0, 1e-6, 1e3, 1e-3]), np.array([1e-9, 1e9, 1.0, 1e4, 1e12])]


@pytest.mark.parametrize("units", UNITS, ids=["1e6", "1e-9"])
@pytest.mark.parametrize("kind,d,n,F", [
    ("gaussian", 2, 12, 2), ("gaussian", 3, 16, 2),
    pytest.param("gaussian", 4, 20, 2, marks=pytest.mark.slow),  # ~5 s: the rows as given
    pytest.param("cube", 4, 20, 3, marks=pytest.mark.slow),  # are clipped exactly
    pytest.param("gaussian", 5, 14, 1, marks=pytest.mark.slow)])
def test_mixed_units_equal_the_rows_clipped_as_given(kind, d, n, F, units, monkeypatch):
    """Units 1e6 / 1 / 1e-6 / …  (not powers of two: XD is rounded, so compared with
    the rows clipped as given — the exact answer for the same float data): every
    output identical, and the certificate valid."""
    Y = _cloud(kind, d, n, F) * units[:d]
    K = rescon.safe_kernel(Y, F)
    with _as_is(monkeypatch):
        L = rescon.safe_kernel(Y, F)
    assert_identical(K, L)
    _certified(K.certificate)


@pytest.mark.slow  # the rows as given are clipped exactly: 2–20 s each
@pytest.mark.parametrize("name", ["int_grid_4", "sphere_int_4", "threshold_n15_4"])
@pytest.mark.parametrize("exps", POW2[:2], ids=["16", "600"])
def test_hostile_clouds_in_mixed_units(name, exps, monkeypatch):
    """The d45 hostile clouds with columns scaled by 2^e: the same as the rows clipped as
    given, and certified. (mixed_columns_4 is such a cloud already:
    tests/test_review_v17.)"""
    X, F = _hostile(name)
    Y = X * _factors(exps, X.shape[1])
    K = rescon.safe_kernel(Y, F)
    with _as_is(monkeypatch):
        L = rescon.safe_kernel(Y, F)
    assert_identical(K, L)
    _certified(K.certificate)


@pytest.mark.parametrize("units", [2.0 ** np.array([16, 0, -16, 8, 4]),
                                   2.0 ** np.array([600, 0, -600, 300, -30]),
                                   np.array([1e6, 1.0, 1e-6, 1e3, 1e-3])],
                         ids=["2^16", "2^600", "1e6"])
@pytest.mark.parametrize("kind,d,n,F", [("gaussian", 4, 50, 9), ("sphere", 4, 30, 4),
                                        ("gaussian", 5, 20, 2)])
def test_the_fast_path_certifies_mixed_units(kind, d, n, F, units, monkeypatch):
    """The fast path certifies the kernel in mixed units (it did not before the
    columns were shifted: the exact clipping ran — 5.3 CPU-s for gaussian d = 4,
    n = 50, F = 9), as it does for the cloud as it is."""
    X = _cloud(kind, d, n, F)
    with monkeypatch.context() as m:
        assert _fast_path_certifies(X, F, m)
    with monkeypatch.context() as m:
        assert _fast_path_certifies(X * units[:d], F, m)


def test_the_fast_path_was_refused_without_the_shifts(monkeypatch):
    """The bug: with the rescale disabled, mixed units lose the fast path."""
    X = _cloud("gaussian", 4, 50, 9) * np.array([1e6, 1.0, 1e-6, 1e3])
    with monkeypatch.context() as m:
        m.setattr(km, "COLUMN_SPREAD_MAX_BITS", math.inf)
        assert not _fast_path_certifies(X, 9, m)


def _spied_polytope(monkeypatch, X, F):
    """safe_kernel(X, F) without the quick float emptiness test, the polytope that
    :func:`rescon.geometry.kernel._clip` returned and the column shifts it used."""
    seen, shifts = [], []
    real, real_shifts = km._clip, km._column_shifts

    def spy(*args):
        seen.append(real(*args))
        return seen[-1]

    with monkeypatch.context() as m:
        m.setattr(km, "empty_certificate", lambda *a: None)
        m.setattr(km, "_clip", spy)
        m.setattr(km, "_column_shifts", lambda rows: shifts.append(real_shifts(rows))
                  or shifts[-1])
        K = rescon.safe_kernel(X, F)
    return K, seen[0], shifts[0]


def _empty_cloud(d: int, F: int, units: np.ndarray) -> np.ndarray:
    """F points near each vertex of a simplex, n = (d+1)F: dropping one cluster leaves
    the points near the opposite facet, and the facets meet nowhere — Ψ = ∅."""
    S = np.vstack([np.zeros(d), np.eye(d)])
    noise = 0.05 * np.random.default_rng([d, F]).normal(size=((d + 1) * F, d))
    return (np.repeat(S, F, axis=0) + noise) * units[:d]


@pytest.mark.parametrize("units", [2.0 ** np.array([40, 0, -40, 20, 8]),
                                   2.0 ** np.array([600, 0, -600, 300, -30]),
                                   np.array([1e6, 1.0, 1e-6, 1e3, 1e-3])],
                         ids=["2^40", "2^600", "1e6"])
@pytest.mark.parametrize("d,F", [(2, 3), (3, 3), (4, 3), (4, 2), (5, 1)])
def test_an_empty_kernel_in_mixed_units_keeps_a_valid_farkas_certificate(d, F, units,
                                                                        monkeypatch):
    """Ψ = ∅ in mixed units: the Farkas multipliers mapped back still satisfy λ ≥ 0,
    Σ λ_i a_i = 0, Σ λ_i b_i < 0 on the mapped (primitive) rows, and the emptiness
    certificate passes the checker — the quick float test disabled so that the exact
    path (the LP's Farkas in d ≥ 4, the clipping's below) is the one certified."""
    K, poly, shifts = _spied_polytope(monkeypatch, _empty_cloud(d, F, units), F)
    assert K.is_empty and any(shifts)
    far = poly.farkas
    assert far is not None and all(lam >= 0 for lam in far.multipliers)
    for j in range(poly.k):
        assert sum(lam * poly.a[i][j] for i, lam in zip(far.ids, far.multipliers)) == 0
    assert sum(lam * poly.b[i] for i, lam in zip(far.ids, far.multipliers)) < 0
    for i in far.ids:  # rows stay primitive
        assert math.gcd(*poly.a[i], poly.b[i]) == 1
    cert = K.certificate
    assert cert["kind"] == "kernel_empty"
    _certified(cert)


@pytest.mark.parametrize("d,F", [(3, 3), (4, 2)])
def test_a_tampered_farkas_multiplier_is_rejected(d, F, monkeypatch):
    """The checker rejects the empty kernel's certificate with a multiplier doubled
    (so the test above can fail)."""
    X = _empty_cloud(d, F, np.array([1e6, 1.0, 1e-6, 1e3, 1e-3]))
    K, _, _ = _spied_polytope(monkeypatch, X, F)
    assert K.is_empty
    cert = dict(K.certificate)
    lam = Fraction(cert["multipliers"][0])
    cert["multipliers"] = [str(2 * lam), *cert["multipliers"][1:]]
    assert lam > 0 and rescon.check_certificate(cert).verdict == "invalid"


@pytest.mark.parametrize("kind,d,n,F", CLOUDS + [("converged", 4, 20, 2), ("grid", 4, 20, 2),
                                                 ("flat", 4, 20, 2), ("tiny", 4, 20, 2),
                                                 ("huge", 4, 20, 2)])
def test_ordinary_clouds_are_untouched(kind, d, n, F, monkeypatch):
    """Columns of like size: no shift, and every output bit-identical to the rows
    clipped as given."""
    X = _cloud(kind, d, n, F)
    shifts = []
    real = km._column_shifts
    with monkeypatch.context() as m:
        m.setattr(km, "_column_shifts", lambda rows: shifts.append(real(rows)) or shifts[-1])
        K = rescon.safe_kernel(X, F)
    assert all(not any(e) for e in shifts)
    with _as_is(monkeypatch):
        L = rescon.safe_kernel(X, F)
    assert_identical(K, L)


def test_column_shifts():
    """e_j brings every column to the longest's bit length, beyond the threshold only."""
    assert km._column_shifts([(1, 300), (-2, 5)]) == [0, 0]
    assert km._column_shifts([(1, 1 << 20), (-2, 5), (0, 0)]) == [19, 0]
    assert km._column_shifts([(3, -(1 << 40), 0), (1, 7, 1 << 9)]) == [39, 0, 31]
