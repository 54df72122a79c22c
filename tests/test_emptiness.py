"""Fast emptiness certificates from directional halfspaces."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from rescon.geometry.emptiness import empty_certificate


def _above_helly(rng, n, d, spread=0.02):
    E = np.eye(d + 1) - 1.0 / (d + 1)
    q, _ = np.linalg.qr(E[:, :d])
    V = E @ q
    return V[np.arange(n) % (d + 1)] + spread * rng.standard_normal((n, d))


@pytest.mark.parametrize("d,n", [(2, 300), (3, 60), (4, 25), (2, 12)])
def test_certificates_of_clearly_empty_kernels_check(d, n):
    X = _above_helly(np.random.default_rng(d * n), n, d)
    F = n // (d + 1)
    found = empty_certificate(X, F)
    assert found is not None, "d+1 separated clusters: a few directions prove Ψ = ∅"
    cert, halfspaces = found
    assert len(halfspaces) <= d + 1
    assert rescon.check_certificate(cert).valid
    K = rescon.safe_kernel(X, F)
    assert K.is_empty and rescon.check_certificate(K.certificate).valid


def test_integer_ties_are_exact():
    """Small-integer data: tied values are real ties (not skipped as uncertain)."""
    X = np.array([[0, 0], [0, 0], [6, 0], [6, 0], [0, 6], [0, 6]], dtype=float)
    cert, _ = empty_certificate(X, 2)
    assert rescon.check_certificate(cert).valid


def test_tampered_certificates_are_rejected():
    X = _above_helly(np.random.default_rng(1), 90, 2)
    cert, _ = empty_certificate(X, 30)
    for mutate in (lambda c: c["multipliers"].__setitem__(0, "0"),
                   lambda c: c["halfspaces"][0].__setitem__("b", "-1000"),
                   lambda c: c.__setitem__("F", 29)):
        bad = copy.deepcopy(cert)
        mutate(bad)
        assert not rescon.check_certificate(bad).valid


def test_nonempty_kernels_are_left_to_the_full_algorithm():
    """No certificate can exist for a nonempty kernel: the quick path returns None and
    the full algorithm answers (here with the kernel's vertices)."""
    rng = np.random.default_rng(3)
    assert empty_certificate(rng.normal(size=(30, 2)), 9) is None  # n > (d+1)F: Helly
    nonempty = 0
    for _ in range(20):
        X = rng.normal(size=(30, 2))
        K = rescon.safe_kernel(X, 10)  # n ≤ (d+1)F: the quick path is tried first
        if not K.is_empty:
            nonempty += 1
            assert empty_certificate(X, 10) is None
    assert nonempty > 0


@settings(max_examples=60, deadline=None)
@given(st.integers(2, 3), st.integers(5, 24), st.integers(0, 10**6), st.booleans())
def test_a_quick_certificate_agrees_with_the_full_algorithm(d, n, seed, integer):
    """Whenever the directions prove Ψ = ∅, the candidate-hyperplane algorithm (run on
    the data as given, bypassing both quick paths) finds it empty too."""
    from rescon.geometry import kernel as km

    rng = np.random.default_rng(seed)
    X = rng.integers(0, 4, size=(n, d)).astype(float) if integer else rng.normal(size=(n, d))
    F = max(1, n // (d + 1))
    found = empty_certificate(X, F)
    if found is None:
        return
    assert rescon.check_certificate(found[0]).valid
    originals = km.empty_certificate, km.empty_from_halfspaces
    try:  # the double-description clipping alone
        km.empty_certificate = km.empty_from_halfspaces = lambda *a: None
        assert rescon.safe_kernel(X, F).is_empty
    finally:
        km.empty_certificate, km.empty_from_halfspaces = originals


@pytest.mark.parametrize("d,n,F", [(4, 20, 6), (4, 16, 4), (5, 10, 2)])
def test_farkas_from_the_valid_halfspaces(d, n, F, monkeypatch):
    """With the directional path off, an LP over the valid halfspaces proposes the
    Farkas support before any clipping (d ≥ 4); its certificate checks, and the
    clipping agrees that Ψ is empty."""
    from rescon.geometry import kernel as km

    X = np.random.default_rng(d * 100 + n).normal(size=(n, d))
    monkeypatch.setattr(km, "empty_certificate", lambda *a: None)
    K = rescon.safe_kernel(X, F)
    assert K.is_empty and rescon.check_certificate(K.certificate).valid
    monkeypatch.setattr(km, "empty_from_halfspaces", lambda *a: None)
    assert rescon.safe_kernel(X, F).is_empty
