"""Issue 10 §3/§5: float rows that describe the kernel, bounded tables, input limits,
QP backends on thin kernels, certificates that list only facets."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import rescon
from rescon.errors import EmptyKernel, InputError
from rescon.models.kernel_models import lp_backends

FLAT = [[i, 0.1 * i] for i in range(6)]  # not exactly collinear in floats: a segment


def test_flat_kernel_float_rows_bound_the_kernel():
    K = rescon.safe_kernel(FLAT, 1)
    assert K.dim == 1
    # every row is along aff Ψ (a unit vector within it), so A x ≤ b on aff Ψ is Ψ
    along = np.linalg.norm(K.A @ K.affine_basis.T, axis=1)
    assert np.allclose(along, 1.0, atol=1e-12)
    assert not K.contains([-1000, -100], tol=1e-12)
    assert not K.contains([1000, 100], tol=1e-12)
    for v in K.vertices:
        assert K.contains(v, tol=1e-12)


@pytest.mark.parametrize("backend", lp_backends())
def test_flat_kernel_chebyshev_on_every_lp_backend(backend):
    K = rescon.safe_kernel(FLAT, 1)
    _, cert = K.point("chebyshev", backend=backend)
    assert K._exact.contains(tuple(Fraction(v) for v in cert["x"]))
    assert rescon.check_certificate(cert).valid


# --------------------------------------------------------------------------- #
# input: complex, integers a float cannot hold, batches
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("X,match", [
    ([[1 + 2j, 0], [1, 1], [0, 1]], "complex"),
    (np.array([[1, 0], [0, 1], [0, 0]], dtype=np.complex128), "complex"),
    ([[2**53 + 1, 0], [0, 1], [0, 0]], r"X\[0, 0\] = 9007199254740993"),
    (np.array([[0, 0], [1, 2**53 + 1], [0, 1]], dtype=np.int64), r"X\[1, 1\]"),
    (np.array([[0, 0], [1, 2**63 + 1], [0, 1]], dtype=np.uint64), r"X\[1, 1\]"),
    ([[0, 0], [1, 0], [0, Fraction(1, 3)]], r"X\[2, 1\] = 1/3"),
    ([[0, 0], [1, 0], [0, 10**400]], "float64 range"),
])
def test_inputs_a_float_cannot_hold_are_refused(X, match):
    with pytest.raises(InputError, match=match):
        rescon.safe_kernel(X, 0)


def test_integers_that_floats_hold_exactly_are_taken():
    X = [[2**60, 0], [0, 2**60], [0, 0], [-(2**53), 2**53], [2**53, 2**53]]
    K = rescon.safe_kernel(X, 0)
    assert K.dim == 2 and rescon.check_certificate(K.certificate).valid


def test_kernel_points_mixed_dimensions_is_an_input_error():
    with pytest.raises(InputError, match=r"batch\[1\] has dimension 3"):
        rescon.kernel_points([np.zeros((5, 2)), np.zeros((5, 3))], 1)


def test_kernel_points_names_a_malformed_item():
    with pytest.raises(InputError, match=r"batch\[1\] must be finite"):
        rescon.kernel_points([np.eye(3), [[0, np.nan], [1, 1], [2, 2]]], 0)


def test_kernel_points_empty_kernel_per_item():
    rng = np.random.default_rng(3)
    full, empty = rng.normal(size=(10, 2)), [[0, 0], [1, 0], [0, 1]]
    with pytest.raises(EmptyKernel, match=r"batch\[1\]"):
        rescon.kernel_points([full, empty, full], 1)
    out = rescon.kernel_points([full, empty, full], 1, on_empty="nan")
    assert out.shape == (3, 2)
    assert np.isnan(out[1]).all() and not np.isnan(out[[0, 2]]).any()
    assert np.array_equal(out[0], rescon.kernel_point(full, 1)[0])
    with pytest.raises(InputError, match="on_empty"):
        rescon.kernel_points([full], 1, on_empty="skip")
