"""Hostile review of exact safe kernels and their points (issue 10 §1–§3).

Answers are compared with an independent oracle in Fractions: the Tukey depth of a
point in the plane, min over closed halfplanes through it of the points they hold,
evaluated at generic directions (the normal of each p − x turned by a symbolic ±ε),
so x ∈ Ψ(X, F) iff depth ≥ F + 1.
"""

from __future__ import annotations

import warnings
from fractions import Fraction

import numpy as np
import pytest

import rescon
from rescon.errors import SolverError
from rescon.models.kernel_models import qp_backends


def _depth2(X, x) -> int:
    """Exact Tukey depth (closed halfplanes) of x among the rows of X, d = 2."""
    x = [Fraction(v) for v in x]
    V = [(Fraction(float(p[0])) - x[0], Fraction(float(p[1])) - x[1]) for p in X]
    moved = [v for v in V if v != (0, 0)]
    best = len(V)
    for vi in moved:
        for sign in (1, -1):
            u = (-sign * vi[1], sign * vi[0])
            for turn in (1, -1):
                ahead = 0
                for vj in moved:
                    s = u[0] * vj[0] + u[1] * vj[1]
                    s = s if s else turn * (vi[0] * vj[0] + vi[1] * vj[1])
                    ahead += s > 0
                best = min(best, ahead + len(V) - len(moved))
    return best


def _far_target_cloud(d: int, far: float) -> np.ndarray:
    X = np.random.default_rng(5).standard_normal((7, d))
    X[0] = far
    return X


@pytest.mark.parametrize("backend", qp_backends())
@pytest.mark.parametrize("far", [1e20, 1e40, 1e300])
def test_explicit_backend_projects_towards_a_far_adversary(backend, far):
    """One value at 1e20..1e300 puts the default target (the mean) ~2^66+ kernel
    sizes away: every explicit QP backend raised SolverError (cvxpy:HIGHS a bare
    ValueError) where "auto" succeeds; the float guide now sees the target moved
    towards Ψ along the same direction, and the exact KKT search decides."""
    X = _far_target_cloud(3, far)
    x, cert = rescon.kernel_point(X, 1, backend=backend)
    assert np.array_equal(x, rescon.kernel_point(X, 1)[0])
    assert rescon.check_certificate(cert).valid


def test_explicit_backend_far_target_planar_oracle():
    X = _far_target_cloud(2, 1e40)
    for backend in ("highs", "proxsuite", "cvxpy:HIGHS"):
        if backend not in qp_backends():
            continue
        x, cert = rescon.kernel_point(X, 1, backend=backend)
        assert _depth2(X, [Fraction(v) for v in cert["x"]]) >= 2


def test_cvxpy_highs_unknown_status_is_a_solver_error():
    """CVXPY's HiGHS interface raises ValueError ("Cannot unpack invalid solution")
    when HiGHS ends with status UNKNOWN: that is a SolverError, not a traceback."""
    if "cvxpy:HIGHS" not in qp_backends():
        pytest.skip("cvxpy:HIGHS not installed")
    from rescon.models.kernel_models import project

    A = np.vstack([np.eye(3), -np.eye(3)])
    try:
        project(A, np.ones(6), np.zeros(3), np.eye(3), [1e300, -1e300, 1e300],
                backend="cvxpy:HIGHS")
    except SolverError:
        pass


def test_emptiness_step_near_the_largest_floats_warns_nothing():
    """The small-integer test of the emptiness step multiplied max|X| by a direction's
    1-norm: a RuntimeWarning (an exception under ``-W error``) at 1.7e308."""
    X = np.array([[1.7e308, 1.7e308], [0, 0], [1, 0], [0, 1], [-1.7e308, 2]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        K = rescon.safe_kernel(X, 2)
    assert K.is_empty
    assert rescon.check_certificate(K.certificate).valid


def test_farkas_search_at_a_degenerate_vertex_is_guided(monkeypatch):
    """7 points in R^5 spanning 5e-324..1.7e308, F = 2: Ψ is empty and the clipping
    proves it at a vertex with 14 tight rows of 1239-bit integers. Trying the C(14, 5)
    subsets in index order took 1991 exact nullspaces (12 s); a float NNLS order
    finds the multipliers among the first few."""
    from rescon.geometry import polytope

    X = np.array([
        [-1.7e308, 1.7e308, 1.7e308, -1.7e308, -1.7e308],
        [5e-324, -5e-324, 5e-324, -5e-324, -5e-324],
        [1.4329354626707616, 0.7792069850166151, 0.8713792260973728,
         1.2153939464516215, 0.7331652551567572],
        [-1.2500243511709286, -0.37364959880915405, 1.0182842115880062,
         -0.7538829964103553, 0.051864935612521784],
        [0.4124680042209678, 1.4561649558228973, 1.313318096968901,
         0.9128286964153371, -0.17215624236752008],
        [0.9290069448924019, 0.5420740821601429, -0.1479790187664939,
         1.3713910407205256, 0.5081032676371856],
        [-0.7426578474682369, 1.2794140055440122, -0.24214041336753075,
         0.6064618314522637, -1.5118072827459679]])
    calls = []
    real = polytope.nullspace_exact

    def counted(M):
        calls.append(1)
        return real(M)

    monkeypatch.setattr(polytope, "nullspace_exact", counted)
    K = rescon.safe_kernel(X, 2)
    assert K.is_empty
    assert rescon.check_certificate(K.certificate).valid
    assert len(calls) < 100


def test_projection_of_a_target_inside_tries_no_guide(monkeypatch):
    """F = 0: Ψ = conv X holds the mean, so the projection is the target itself. With
    values at ±1.7e308 and 5e-324 in R^5 the float guides marked many facets tight and
    the exact search tried up to 638 active sets per guide (7-11 s) before ()."""
    from rescon.geometry import points

    rng = np.random.default_rng(3)
    X = rng.standard_normal((8, 5))
    X[0] = [-1.7e308, -1.7e308, -1.7e308, -1.7e308, 1.7e308]
    X[1] = -5e-324
    calls = []
    real = points._kkt

    def counted(*args):
        calls.append(1)
        return real(*args)

    monkeypatch.setattr(points, "_kkt", counted)
    x, cert = rescon.kernel_point(X, 0)
    assert rescon.check_certificate(cert).valid
    assert [Fraction(v) for v in cert["x"]] == [sum(Fraction(float(p[j])) for p in X) / 8
                                               for j in range(5)]
    assert len(calls) == 1


@pytest.mark.parametrize("backend", ["cvxpy:OSQP", "cvxpy:SCS", "casadi:osqp"])
def test_c_solver_errors_stay_off_stdout(backend, capfd):
    """OSQP and SCS print their errors with C printf whatever their verbosity: on
    stdout they preceded a --json object (a far target, 1e200 beside a 1e-100 box)."""
    if backend not in qp_backends():
        pytest.skip(f"{backend} not installed")
    from rescon.models.kernel_models import project

    A = np.vstack([np.eye(3), -np.eye(3)])
    try:
        project(A, np.full(6, 1e-100), np.zeros(3), np.eye(3), [1e200, -1e200, 1e200],
                backend=backend)
    except SolverError:
        pass
    assert capfd.readouterr().out == ""
