"""The Chebyshev centre of kernels too thin for their unit frame (V34): a full-dimensional
Ψ whose unit-frame LP fails (float-collinear points, columns at 1e-200 and 1e200) is
solved again in its principal frame (``points._principal_chebyshev``).

Oracles: the certificate checker (the point is in Ψ) and the exact inscribed radius
min over facets of (β − a·x) / ‖a‖ at the point, against the unit-frame LP's point where
that one succeeds (the principal frame must find a ball as large, up to rounding)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import rescon
from rescon.geometry import points


def _radius(K, x) -> float:
    """The exact slack of x in each facet over ‖a‖, the smallest (floats of exact slacks)."""
    out = math.inf
    for a, beta in K._exact.facets:
        top = max(map(abs, a))
        slack = float((beta - sum(ai * xi for ai, xi in zip(a, x))) / top)
        out = min(out, slack / math.hypot(*(float(t / top) for t in a)))
    return out


def _thin_cloud(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    d = int(rng.integers(2, 4))
    u = rng.normal(size=d)
    u /= np.linalg.norm(u)
    n = d + 1 + int(rng.integers(0, 4))
    X = np.outer(rng.uniform(-1, 1, size=n), u)
    X += 10.0 ** rng.uniform(-17, -6) * rng.normal(size=(n, d))
    return X * 10.0 ** rng.uniform(-200, 200)


@pytest.mark.parametrize("seed", range(40))
def test_thin_kernels_get_a_certified_chebyshev_point(seed):
    """Thin full-dimensional kernels (widths 1e-17..1e-6 of their extent, at 1e-200..1e200):
    a point with a valid certificate (about 40 % of these failed before the fallback)."""
    X = _thin_cloud(seed)
    K = rescon.safe_kernel(X, 0)
    assert K.dim == X.shape[1]
    x, cert = rescon.kernel_point(X, 0, method="chebyshev")
    assert rescon.check_certificate(cert).verdict == "valid"
    assert K.contains(x, tol=1e-12)


@pytest.mark.parametrize("seed", range(12))
def test_principal_frame_finds_as_large_a_ball(seed):
    """Where the unit-frame LP succeeds (kernels 1e-3..1 thick), the principal frame's
    point has an inscribed radius within 1e-6 of it (the LPs solve the same problem)."""
    rng = np.random.default_rng(1000 + seed)
    d = int(rng.integers(2, 4))
    X = rng.normal(size=(d + 3, d)) * 10.0 ** rng.uniform(-3, 0, size=d)
    K = rescon.safe_kernel(X, 0)
    o, _ = points._frame(K)
    unit = points._chebyshev(K, "auto")
    principal = points._principal_chebyshev(K, o)
    assert principal is not None and K._exact.contains(principal)
    assert _radius(K, principal) >= (1 - 1e-6) * _radius(K, unit)


def test_explicit_backends_keep_their_own_answer_or_error():
    """The principal frame is "auto"'s: a named backend still reports its own failure."""
    X = [[0.0, 0.0], [1e-200, 0.0], [0.0, 1e200]]
    with pytest.raises(rescon.errors.SolverError):
        rescon.kernel_point(X, 0, method="chebyshev", backend="clarabel")
    x, cert = rescon.kernel_point(X, 0, method="chebyshev")
    assert rescon.check_certificate(cert).verdict == "valid"
    assert 0 < x[0] < 1e-200 and 0 < x[1]
