"""Safe kernels and kernel points at every finite magnitude (issue 10 §3).

Ψ(2^j X, F) = 2^j Ψ(X, F) exactly, so scaling the data by a power of two must scale
every exact answer (vertices, kernel points) by the same power — wherever the scaled
floats are exact — and every certificate must still check. Clouds mixing magnitudes
(1e-300 … 1e300, subnormals) must give exact answers, never an OverflowError.
"""

from __future__ import annotations

import math
import sys
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from rescon_certificates.kernels import _rat

import rescon
from rescon.errors import EmptyKernel


def _not_invalid(cert) -> None:
    res = rescon.check_certificate(cert)
    verdict = getattr(res, "verdict", "valid" if res.valid else "invalid")
    assert verdict != "invalid", res.reason


def _scaled(X: np.ndarray, j: int) -> np.ndarray | None:
    """2^j X when every entry scales exactly (else None)."""
    Y = np.ldexp(X, j)
    return Y if np.all(np.isfinite(Y)) and np.array_equal(np.ldexp(Y, -j), X) else None


def _point(X, F):
    """The exact projection point as Fractions, or None when Ψ is empty."""
    try:
        x, cert = rescon.kernel_point(X, F)
    except EmptyKernel:
        return None
    _not_invalid(cert)
    xq = tuple(_rat(v, "x") for v in cert["x"])  # Fraction(str) stops at 4300 digits
    assert x.tolist() == [float(v) for v in xq]
    return xq


# --------------------------------------------------------------------------- #
# the reported cases
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("X", [
    [[0, 0], [1, 0], [0, 1], [1, 1], [5e-324, 0.5]],
    [[.3, .1], [1.2, -.7], [.5, 2], [-1.1, .4], [1e300, 1e300]],
    [[1e-300, 2.0], [0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]],
    [[1e-300, 1e300], [-1e300, 5e-324], [3.0, -7.0], [1e-310, 1e-310], [2.0, 2.0]],
    [[-0.0, 3e-311], [-0.0, -0.0], [-0.0, -8.5e+307]],  # collinear: 3e-311 vs 0 in 1-D
    [[0.0, 0.0], [-1e-310, 0.0], [-1.0, 0.0], [0.0, 0.0]],  # Ψ 1e-310 long, target far
])
def test_points_spanning_the_exponent_range_give_exact_checked_answers(X):
    K = rescon.safe_kernel(X, 1)
    assert not K.is_empty
    _not_invalid(K.certificate)
    assert np.all(np.isfinite(K.vertices)) and np.isfinite(K.A).all()
    x = _point(X, 1)
    assert K._exact.contains(x)


def test_square_at_1e200_is_its_centre():
    """The README's square scaled by 1e200: Ψ is the point (5e199, 5e199) (it was a
    segment, and contains() said True at depth-1 points)."""
    X = np.array([[0, 0], [1, 0], [1, 1], [0, 1]]) * 1e200
    K = rescon.safe_kernel(X, 1)
    assert K.dim == 0
    assert K.exact_vertices == ((Fraction(1e200) / 2, Fraction(1e200) / 2),)
    assert not K.contains([0.0, 0.0]) and not K.contains([1e200, 5e199])
    assert not K.contains([0.0, 0.0], tol=1.0)
    _not_invalid(K.certificate)


@pytest.mark.parametrize("scale,d", [(400, 3), (600, 2), (-900, 3), (1000, 3)])
def test_zero_dimensional_kernel_scales_exactly(scale, d):
    """5 points in R³ (4 in R²), F = 1: Ψ is one point; at 2^400 it was the bounding
    box and the kernel point lay outside Ψ."""
    rng = np.random.default_rng(3)
    X = rng.standard_normal((d + 2, d))
    Y = _scaled(X, scale)
    assert Y is not None
    K0, K1 = rescon.safe_kernel(X, 1), rescon.safe_kernel(Y, 1)
    s = Fraction(2) ** scale
    assert K1.dim == K0.dim
    assert set(K1.exact_vertices) == {tuple(v * s for v in x) for x in K0.exact_vertices}
    _not_invalid(K1.certificate)
    assert _point(Y, 1) == tuple(v * s for v in _point(X, 1))


def test_gaussian_cloud_at_2_600():
    """200 Gaussian points × 2^600, F = 20: it was the bounding box (depth-0 vertices)."""
    X = np.random.default_rng(0).standard_normal((200, 2))
    K0, K1 = rescon.safe_kernel(X, 20), rescon.safe_kernel(np.ldexp(X, 600), 20)
    s = Fraction(2) ** 600
    assert set(K1.exact_vertices) == {tuple(v * s for v in x) for x in K0.exact_vertices}
    assert np.array_equal(K1.vertices, np.ldexp(K0.vertices, 600))


def test_contains_at_huge_magnitude():
    """contains(x, tol) from the float rows: a point of depth 0 far outside is out, the
    exact vertex is in with a tolerance."""
    X = np.ldexp(np.random.default_rng(5).standard_normal((9, 2)), 1000)
    K = rescon.safe_kernel(X, 2)
    assert not K.contains(X[np.argmax(X[:, 0])], tol=0.0)
    assert K.contains(K.vertices[0], tol=1e-9 * np.abs(K.vertices).max())


@pytest.mark.parametrize("j", [600, -1000, 1000])
def test_float_guides_are_solved_at_unit_size(j):
    """The LP/QP guides see Ψ in a power-of-two frame: the Chebyshev centre of 2^j X
    is 2^j times that of X (HiGHS read b ~ 1e180 as infinite: "Unbounded"), and an
    explicit backend projects as "auto" does."""
    X = np.random.default_rng(1).standard_normal((30, 3))
    Y = _scaled(X, j)
    x0, _ = rescon.kernel_point(X, 3, method="chebyshev")
    x1, cert = rescon.kernel_point(Y, 3, method="chebyshev")
    _not_invalid(cert)
    assert np.array_equal(x1, np.ldexp(x0, j))
    for backend in ("highs", "clarabel"):
        x2, _ = rescon.kernel_point(Y, 3, backend=backend)
        assert np.array_equal(x2, np.ldexp(rescon.kernel_point(X, 3)[0], j))


@pytest.mark.parametrize("X,F,j", [
    ([[6e12, -2e12, 11e12], [-11, -4, -13], [11, 0, 20], [3, 4, -9], [-9, -4, 7],
      [-8, -19, 6], [7, -8, 3], [8, 9, -13], [0, -7, 7], [0, -10, 0]], 2, -73),
    ([[-2, 2, 8, 7], [1, 2, 10, 5], [4, -8, 1, 3], [1, -7, -13, 5], [5, 1, -6, -3],
      [0, 6, 1, -6], [-3, -8, 14, -5], [11, 3, 14, -7], [6, -6, -6, -5], [-9, -6, -1, 13],
      [-3, -11, 5, 11], [-19, 4, -10, -13], [5, 11, 14, 1], [-2, 2, 5, 7]], 2, 602),
])
def test_float_outputs_do_not_depend_on_the_path(X, F, j):
    """Integer data take exact-float paths, 2^j X the normalised ones; the vertices
    (lexicographic) and facet rows (by direction) come out in one order either way, so
    the float outputs and the Chebyshev point (not unique: the LP's choice) scale by
    2^j exactly too."""
    X = np.array(X, dtype=np.float64)
    K0, K1 = rescon.safe_kernel(X, F), rescon.safe_kernel(np.ldexp(X, j), F)
    assert np.array_equal(np.ldexp(K0.vertices, j), K1.vertices)
    assert np.array_equal(K0.A, K1.A) and np.array_equal(np.ldexp(K0.b, j), K1.b)
    x0, x1 = K0.point("chebyshev")[0], K1.point("chebyshev")[0]
    assert np.array_equal(np.ldexp(x0, j), x1)


def _parse(s: str) -> Fraction:
    """Fraction(s) without Python's default limit on str → int."""
    old = sys.get_int_max_str_digits()
    sys.set_int_max_str_digits(0)
    try:
        return Fraction(s)
    finally:
        sys.set_int_max_str_digits(old)


def test_fraction_str_at_any_size():
    from rescon.geometry.exact import fraction_str

    for x in (Fraction(0), Fraction(-7, 3), Fraction(3**40000, 7**9000),
              Fraction(-(10**20000)), Fraction(10**9000 - 1, 2**50000)):
        assert _parse(fraction_str(x)) == x


@pytest.mark.slow
def test_kernel_point_with_more_than_4300_digits():
    """Points spanning the exponent range in R⁴: the exact kernel point has numbers of
    more than 4300 decimal digits (Python's default limit on int → str: it raised
    ValueError), written out in full."""
    X = [[-0.0, -7.5e+299, 1.7e+308, 1e-150], [-0.75, 7.5e-301, 3e+19, 1e+20],
         [3e+299, -3e+149, 1.7e+308, 0.0], [-7.5e+299, -3e-311, -0.0, -0.0],
         [-0.0, 1e+300, 7.5e+149, 1e-20], [0.0, 2.25, -7.5e+299, -0.0],
         [0.5, -1e+20, 5e-21, -0.0], [1.275e+308, 1e+300, -0.5, 5e+299]]
    x, cert = rescon.kernel_point(X, 1)
    assert max(len(v) for v in cert["x"]) > 4300
    xq = [_parse(v) for v in cert["x"]]
    assert x.tolist() == [float(v) for v in xq]
    assert rescon.safe_kernel(X, 1)._exact.contains(tuple(xq))


def test_near_the_largest_floats():
    """Points up to 1.8e308: every point method answers (the guides' frame, sums and
    squared distances do not overflow) with certificates that check."""
    M = 1.7976931348623157e308
    X = [[M, 7.539858393500878e+307], [-M, -1.0664471603681233e+307],
         [-M, 3.203156529627997e+307], [-M, 9.001509230066127e+307],
         [M, 5.225055269170945e+307], [-M, -1.5407846165241795e+308],
         [-M, -1.7660707030873052e+308]]
    K = rescon.safe_kernel(X, 1)
    _not_invalid(K.certificate)
    for method in ("project", "chebyshev", "vertex-mean"):
        x, cert = K.point(method)
        _not_invalid(cert)
        assert np.isfinite(x).all()


def test_facet_beyond_the_float_range_is_an_input_error():
    """A facet farther than 1.8e308 from the origin has no float row (A, b): a clear
    InputError naming X (was OverflowError)."""
    X = [[-2.272956801015845e+307, -1.710713625959321e+308, -1.5775076933864834e+308],
         [-9.046334991928531e+307, -1.6587419007340286e+308, -1.191681222943448e+308],
         [-1.5696120464382734e+308, -1.2903053238039122e+308, -1.4426235833087205e+308],
         [-2.701117294305795e+307, 1.1723228828124586e+308, 1.0196944313068759e+308],
         [1.0738971835495317e+307, -1.5742804080770382e+308, 1.6103484333392725e+308],
         [-1.5601797632008004e+308, -1.7525193314787036e+308, 8.939936037146471e+307],
         [4.522609685852205e+307, 9.26896478035055e+307, -8.09681361301021e+307],
         [1.4126998329289943e+308, 1.3365735683933705e+308, -1.6389939781711726e+308],
         [1.641828548899451e+308, 9.671762013930054e+307, 1.2712555719317322e+308],
         [-7.53386258035707e+306, 1.0605146072666493e+308, 1.479140203799131e+308]]
    with pytest.raises(rescon.errors.InputError, match="^X: a facet of the safe kernel"):
        rescon.safe_kernel(X, 1)


def test_flat_kernel_whose_hull_is_beyond_the_float_range():
    """Collinear points on x + y = 3·2^1023 (every coordinate finite): the line's
    distance from the origin exceeds 1.8e308, so (Aeq, beq) cannot be floats —
    InputError (beq was inf, silently)."""
    X = [[math.ldexp(a, 1023), math.ldexp(3 - a, 1023)] for a in (1.75, 1.5, 1.25, 1.625)]
    with pytest.raises(rescon.errors.InputError, match="^X: the affine hull"):
        rescon.safe_kernel(X, 1)


# --------------------------------------------------------------------------- #
# properties
# --------------------------------------------------------------------------- #

_SETTINGS = settings(max_examples=25, deadline=None,
                     suppress_health_check=[HealthCheck.too_slow])


@st.composite
def _clouds(draw, dims=(2, 3)):
    d = draw(st.sampled_from(dims))
    F = draw(st.integers(1, 2))
    n = draw(st.integers((d + 1) * F - 1, (d + 1) * F + 4))
    seed = draw(st.integers(0, 2**32 - 1))
    X = np.random.default_rng(seed).standard_normal((n, d))
    if draw(st.booleans()):  # integer data (exact float arithmetic paths)
        X = np.round(X * 8)
    return X, F


@_SETTINGS
@given(_clouds(), st.integers(-1070, 1000))
def test_scaling_by_a_power_of_two_scales_everything(cloud, j):
    X, F = cloud
    Y = _scaled(X, j)
    if Y is None:  # 2^j X not representable exactly: nothing to compare
        return
    K0, K1 = rescon.safe_kernel(X, F), rescon.safe_kernel(Y, F)
    assert K1.is_empty == K0.is_empty and K1.dim == K0.dim
    s = Fraction(2) ** j
    assert set(K1.exact_vertices) == {tuple(v * s for v in x) for x in K0.exact_vertices}
    _not_invalid(K1.certificate)
    p0, p1 = _point(X, F), _point(Y, F)
    assert p1 == (None if p0 is None else tuple(v * s for v in p0))


@pytest.mark.parametrize("seed,j", [(0, 700), (1, -1000), (2, 345)])
def test_scaling_in_four_dimensions(seed, j):
    X = np.random.default_rng(seed).standard_normal((6, 4))
    Y = _scaled(X, j)
    K0, K1 = rescon.safe_kernel(X, 1), rescon.safe_kernel(Y, 1)
    s = Fraction(2) ** j
    assert set(K1.exact_vertices) == {tuple(v * s for v in x) for x in K0.exact_vertices}
    _not_invalid(K1.certificate)
    assert _point(Y, 1) == tuple(v * s for v in _point(X, 1))


@_SETTINGS
@given(_clouds(), st.integers(-1000, 1000), st.integers(-60, 60))
def test_translation_by_a_representable_vector(cloud, j, t):
    """X + c with c = 2^j·(1, …): when the translated floats are exact, Ψ moves by c."""
    X, F = cloud
    c = np.ldexp(np.ones(X.shape[1]), j)
    Xs = _scaled(X, t)
    if Xs is None:
        return
    Y = Xs + c
    if any(Fraction(y) != Fraction(x) + Fraction(v)  # rounded: a different point set
           for yr, xr in zip(Y.tolist(), Xs.tolist()) for y, x, v in zip(yr, xr, c.tolist())):
        return
    K0, K1 = rescon.safe_kernel(Xs, F), rescon.safe_kernel(Y, F)
    cq = tuple(Fraction(v) for v in c)
    assert set(K1.exact_vertices) == {tuple(v + w for v, w in zip(x, cq))
                                      for x in K0.exact_vertices}
    _not_invalid(K1.certificate)


@st.composite
def _mixed(draw):
    d = draw(st.sampled_from((2, 3)))
    F = 1
    n = draw(st.integers(d + 1, d + 4))
    mags = st.sampled_from([5e-324, 1e-310, 1e-300, 1e-150, 1e-20, 1.0, 3.0, 1e20, 1e150,
                            1e300, 1.7e308])
    X = np.array([[draw(st.sampled_from([-1.0, 1.0])) * draw(mags)
                   * draw(st.sampled_from([0.0, 1.0, 0.5, 0.75, 0.3]))
                   for _ in range(d)] for _ in range(n)])
    return X, F


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(_mixed())
def test_clouds_mixing_magnitudes(cloud):
    """Subnormals next to 1e300: exact answers, certificates that check, no overflow.
    Ψ is compared with the subsets' hulls it must lie in (each vertex has depth ≥ F+1
    by the certificate) and the kernel point with Ψ."""
    X, F = cloud
    K = rescon.safe_kernel(X, F)
    _not_invalid(K.certificate)
    x = _point(X, F)
    assert (x is None) == K.is_empty
    if x is not None:
        assert K._exact.contains(x)
        assert np.isfinite(K.vertices).all()
