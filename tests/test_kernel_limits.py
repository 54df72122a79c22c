"""Issue 10 §3/§5: float rows that describe the kernel, bounded tables, input limits,
QP backends on thin kernels, certificates that list only facets."""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import rescon
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
