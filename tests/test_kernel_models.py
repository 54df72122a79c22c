"""rescon.models.kernel_models: projection QP and Chebyshev LP on every backend.

Each backend is checked against brute-force oracles that share no code with the
module: the projection by enumerating active sets (subsets of ≤ k constraints made
tight), the Chebyshev radius by enumerating the vertices of {(t, ρ)}. The polytopes
are built in hull coordinates and lifted to R^d with an off-hull part added to every
row, plus pairs of rows normal to the hull (the equalities of a lower-dimensional K).
"""

from __future__ import annotations

import doctest
import functools
import itertools

import numpy as np
import pytest

from rescon.errors import InputError, SolverError, SolverNotFound
from rescon.models import kernel_models as km
from rescon.models.kernel_models import (
    chebyshev,
    lp_backends,
    project,
    project_batch,
    qp_backends,
)

QP_BACKENDS = qp_backends()
LP_BACKENDS = lp_backends()
SHAPES = [(1, 1), (2, 2), (2, 1), (3, 3), (3, 1), (3, 2), (4, 4), (4, 2)]  # (d, k), k > 0
SQUARE = (
    np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]),
    np.ones(4),
    np.zeros(2),
    np.eye(2),
)


# --------------------------------------------------------------------------- #
# random polytopes and brute-force oracles
# --------------------------------------------------------------------------- #


def hull_polytope(rng, k, n_random):
    """G t ≤ h in R^k: a box |t_i| ≤ 1.5 and random cuts at distance 0.1..1 from 0."""
    U = rng.normal(size=(n_random, k))
    U /= np.linalg.norm(U, axis=1, keepdims=True)
    G = np.vstack([np.eye(k), -np.eye(k), U])
    h = np.concatenate([np.full(2 * k, 1.5), rng.uniform(0.1, 1.0, n_random)])
    return G, h


def lift(rng, G, h, d):
    """(A, b, origin, basis) in R^d with hull part G, h (rows rescaled, off-hull noise)."""
    k = G.shape[1]
    Q, _ = np.linalg.qr(rng.normal(size=(d, d)))
    B, N = Q[:, :k].T, Q[:, k:].T  # hull directions, normals to the hull
    o = rng.normal(size=d)
    scale = rng.uniform(0.5, 3.0, size=(len(h), 1))
    A = scale * (G @ B + rng.normal(size=(len(h), d - k)) @ N)
    b = scale[:, 0] * h + A @ o
    if d > k:  # the hull's own equalities n·x = n·o as two rows each
        A = np.vstack([A, N, -N])
        b = np.concatenate([b, N @ o, -N @ o])
    return A, b, o, B


def faces(m, size):
    """All index sets S ⊆ {0..m-1} with |S| = size, as an (n, size) array."""
    return np.array(list(itertools.combinations(range(m), size)), dtype=int).reshape(-1, size)


def brute_project(G, h, c):
    """argmin ½‖t − c‖² over G t ≤ h: the nearest feasible point among c and the
    projections of c onto every face {G_S t = h_S}, |S| ≤ k, G_S of full row rank."""
    k = G.shape[1]
    candidates = [c[None, :]]
    for size in range(1, k + 1):
        S = faces(len(h), size)
        S = S[np.linalg.matrix_rank(G[S]) == size]
        GS = G[S]  # (n, size, k)
        lam = np.linalg.solve(GS @ GS.transpose(0, 2, 1), (GS @ c - h[S])[..., None])
        candidates.append(c - (GS.transpose(0, 2, 1) @ lam)[..., 0])
    T = np.vstack(candidates)
    T = T[np.all(T @ G.T <= h + 1e-9, axis=1)]
    return T[np.argmin(np.linalg.norm(T - c, axis=1))]


def brute_radius(G, h):
    """max ρ over G t + ρ‖G_i‖ ≤ h, ρ ≥ 0: the best vertex of the (t, ρ) polyhedron."""
    k = G.shape[1]
    M = np.vstack([np.column_stack([G, np.linalg.norm(G, axis=1)]), -np.eye(k + 1)[-1:]])
    r = np.append(h, 0.0)
    S = faces(len(r), k + 1)
    S = S[np.abs(np.linalg.det(M[S])) > 1e-12]
    Z = np.linalg.solve(M[S], r[S][..., None])[..., 0]
    return Z[np.all(Z @ M.T <= r + 1e-9, axis=1), -1].max()


def make_case(seed, d, k, outside):
    """A random lifted polytope, a target (inside or outside, plus an off-hull part),
    the oracle's projection and Chebyshev radius."""
    rng = np.random.default_rng(seed)
    G, h = hull_polytope(rng, k, n_random=int(rng.integers(2, 5)))
    A, b, o, B = lift(rng, G, h, d)
    u = rng.normal(size=k)
    t_target = (3.0 if outside else 0.05) * u / np.linalg.norm(u)
    off = rng.normal(size=d)
    y = o + B.T @ t_target + off - B.T @ (B @ off)
    x_ref = o + B.T @ brute_project(G, h, t_target)
    return (A, b, o, B), y, x_ref, brute_radius(G, h)


CASES = [make_case(10 * i + out, d, k, out) for i, (d, k) in enumerate(SHAPES) for out in (0, 1)]


# --------------------------------------------------------------------------- #
# every backend against the oracles
# --------------------------------------------------------------------------- #


def test_oracle_sanity():
    """Targets inside are their own projection; targets outside are not."""
    for (A, b, o, B), y, x_ref, _ in CASES:
        inside = np.all(A @ (o + B.T @ (B @ (y - o))) <= b + 1e-12)
        assert np.allclose(x_ref, o + B.T @ (B @ (y - o))) == inside


@pytest.mark.parametrize("backend", QP_BACKENDS)
def test_project_matches_oracle(backend):
    for (A, b, o, B), y, x_ref, _ in CASES:
        x = project(A, b, o, B, y, backend=backend)
        assert x.shape == (len(o),)
        np.testing.assert_allclose(x, x_ref, atol=1e-6, err_msg=f"d={len(o)}, k={len(B)}")


@pytest.mark.parametrize("backend", LP_BACKENDS)
def test_chebyshev_matches_oracle(backend):
    for (A, b, o, B), _, _, r_ref in CASES:
        centre, radius = chebyshev(A, b, o, B, backend=backend)
        assert abs(radius - r_ref) <= 1e-6
        t = B @ (centre - o)
        np.testing.assert_allclose(centre, o + B.T @ t, atol=1e-9)  # in the hull
        AB = A @ B.T
        keep = np.linalg.norm(AB, axis=1) > 1e-9
        slack = (b - A @ centre)[keep] / np.linalg.norm(AB[keep], axis=1)
        assert slack.min() >= r_ref - 1e-6  # the ball of radius r_ref fits


@functools.cache
def stress_cases():
    """Many small polytopes (d = 2, 3; k = 2; m = 6..11) with targets outside. Rare
    failures show up only here: spurious infeasibility (proxqp, 1 QP in 2000 with its
    default eps_primal_inf), interior-point errors ~√gap at weakly active constraints."""
    rng = np.random.default_rng(2024)
    out = []
    for i in range(1000):
        G, h = hull_polytope(rng, 2, n_random=int(rng.integers(2, 8)))
        A, b, o, B = lift(rng, G, h, 2 + i % 2)
        t_target = rng.normal(size=2) * 2
        y = o + B.T @ t_target
        out.append(((A, b, o, B), y, o + B.T @ brute_project(G, h, t_target),
                    brute_radius(G, h)))
    return out


def n_stress(backend):
    """1000 cases for the fast matrix backends (< 1 ms per solve), else 100."""
    return 100 if ":" in backend else 1000


@pytest.mark.parametrize("backend", QP_BACKENDS)
def test_project_stress(backend):
    for (A, b, o, B), y, x_ref, _ in stress_cases()[: n_stress(backend)]:
        np.testing.assert_allclose(project(A, b, o, B, y, backend=backend), x_ref, atol=1e-6)


@pytest.mark.parametrize("backend", LP_BACKENDS)
def test_chebyshev_stress(backend):
    for (A, b, o, B), _, _, r_ref in stress_cases()[: n_stress(backend)]:
        assert chebyshev(A, b, o, B, backend=backend)[1] == pytest.approx(r_ref, abs=1e-6)


@pytest.mark.parametrize("d", [2, 3])
def test_batch_stress(d):
    cases = [case for case in stress_cases() if len(case[1]) == d]
    X = project_batch([(*p, y) for p, y, _, _ in cases], backend="proxsuite")
    np.testing.assert_allclose(X, [x for _, _, x, _ in cases], atol=1e-6)


@pytest.mark.parametrize("backend", QP_BACKENDS)
def test_project_degenerate(backend):
    """Weakly active constraints (zero multipliers): targets on a facet, at a vertex,
    or projecting onto a vertex along a facet; interior-point errors are ~√gap here.
    The square [-1, 1]² with the redundant cut x + y ≤ 2 through its corner."""
    A = np.vstack([SQUARE[0], [1.0, 1.0]])
    b = np.append(SQUARE[1], 2.0)
    for y in ([2.0, 1.0], [1.0, 1.0], [1.0, 0.5], [2.0, -1.0], [0.5, 1.0], [3.0, 3.0]):
        x = project(A, b, [0.0, 0.0], np.eye(2), y, backend=backend)
        np.testing.assert_allclose(x, np.clip(y, -1, 1), atol=1e-6, err_msg=f"target {y}")


@pytest.mark.parametrize("backend", QP_BACKENDS)
def test_infeasible_qp_raises(backend):
    A, b = np.array([[1.0], [-1.0]]), np.array([-1.0, -1.0])  # x ≤ −1 and x ≥ 1
    with pytest.raises(SolverError, match="status"):
        project(A, b, [0.0], [[1.0]], [0.0], backend=backend)


@pytest.mark.parametrize("backend", LP_BACKENDS)
def test_infeasible_lp_raises(backend):
    A, b = np.array([[1.0], [-1.0]]), np.array([-1.0, -1.0])
    with pytest.raises(SolverError, match="status"):
        chebyshev(A, b, [0.0], [[1.0]], backend=backend)


@pytest.mark.parametrize("backend", QP_BACKENDS)
def test_project_without_constraints_is_the_hull_projection(backend):
    B = np.array([[0.6, 0.8, 0.0]])
    x = project(np.zeros((0, 3)), np.zeros(0), [1.0, 0, 0], B, [2.0, 1.0, 5.0], backend=backend)
    np.testing.assert_allclose(x, [1.0, 0, 0] + B[0] * (B[0] @ [1.0, 1.0, 5.0]), atol=1e-6)


# --------------------------------------------------------------------------- #
# degenerate K, batches
# --------------------------------------------------------------------------- #


def test_point_kernel_needs_no_solver():
    A = np.array([[1.0, 1.0], [-1.0, -1.0]])
    o = np.array([0.3, -0.2])
    x = project(A, A @ o, o, np.zeros((0, 2)), [5.0, 5.0])
    centre, radius = chebyshev(A, A @ o, o, np.zeros((0, 2)))
    np.testing.assert_array_equal(x, o)
    np.testing.assert_array_equal(centre, o)
    assert radius == 0.0


def batch_problems(n, d=2, seed=7):
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        k = [d, 1, 0][i % 3]
        G, h = hull_polytope(rng, k, n_random=int(rng.integers(1, 6)))
        A, b, o, B = lift(rng, G, h, d)
        out.append((A, b, o, B, o + rng.normal(size=d)))
    return out


@pytest.mark.parametrize("backend", ["proxsuite", "clarabel", "casadi"])
def test_batch_equals_loop(backend):
    if backend not in {s.partition(":")[0] for s in QP_BACKENDS}:
        pytest.skip(f"{backend} not installed")
    problems = batch_problems(30)
    X = project_batch(problems, backend=backend)
    loop = np.array([project(*p, backend=backend) for p in problems])
    assert X.shape == (30, 2)
    np.testing.assert_allclose(X, loop, atol=1e-7)


def test_batch_failure_names_the_problem():
    problems = batch_problems(3)
    problems[1] = (np.array([[1.0, 0], [-1.0, 0]]), np.array([-1.0, -1.0]),
                   np.zeros(2), np.eye(2), np.zeros(2))
    for backend in ("proxsuite", "clarabel"):
        with pytest.raises(SolverError, match=r"problems\[1\]"):
            project_batch(problems, backend=backend)


def test_empty_batch():
    assert project_batch([]).shape == (0, 0)


# --------------------------------------------------------------------------- #
# errors
# --------------------------------------------------------------------------- #


def test_unknown_backend_lists_available():
    with pytest.raises(SolverNotFound, match="unknown backend 'gurobi'.*clarabel"):
        project(*SQUARE, [0.0, 0.0], backend="gurobi")


def test_backend_without_capability():
    with pytest.raises(SolverNotFound, match="cannot solve LP"):
        chebyshev(*SQUARE, backend="proxsuite")


def test_casadi_missing_plugin_is_named():
    pytest.importorskip("casadi")
    with pytest.raises(SolverNotFound, match="'clarabel': not available for QP; available: .*osqp"):
        project(*SQUARE, [0.0, 0.0], backend="casadi", solver="clarabel")
    with pytest.raises(SolverNotFound, match="'highs': CasADi's bundled HiGHS and highspy"):
        project(*SQUARE, [0.0, 0.0], backend="casadi:highs")
    with pytest.raises(SolverNotFound, match="'proxqp': CasADi's interface exposes neither"):
        project(*SQUARE, [0.0, 0.0], backend="casadi:proxqp")
    with pytest.raises(SolverNotFound, match="'osqp': not available for LP; available: .*qpoases"):
        chebyshev(*SQUARE, backend="casadi:osqp")


def test_cvxpy_unusable_solver_is_named():
    pytest.importorskip("cvxpy")
    with pytest.raises(SolverNotFound, match="'GLOP': not available for QP; available: .*CLARABEL"):
        project(*SQUARE, [0.0, 0.0], backend="cvxpy", solver="GLOP")
    with pytest.raises(SolverNotFound, match="'PROXQP': CVXPY's interface exposes neither"):
        project(*SQUARE, [0.0, 0.0], backend="cvxpy:proxqp")


def test_solver_option_checks():
    with pytest.raises(InputError, match="takes no solver"):
        project(*SQUARE, [0.0, 0.0], backend="clarabel", solver="x")
    with pytest.raises(InputError, match="give the solver once"):
        project(*SQUARE, [0.0, 0.0], backend="cvxpy:OSQP", solver="SCS")


A, b, o, B = SQUARE
BAD = [
    ((A[:, :1], b, o, B, o), r"A must be a finite \(m, 2\) array; got shape \(4, 1\)"),
    ((A, b[:3], o, B, o), r"b must be a finite \(4,\) array; got shape \(3,\)"),
    ((A, b, o, 2 * B, o), "basis rows must be orthonormal"),
    ((A, b, o, np.eye(3)[:, :2], o), r"basis must be a finite \(k, 2\) array"),
    ((A, b, o, B, [0.0, 0.0, 0.0]), r"target must be a finite \(2,\) array"),
    ((np.where(A == 1, np.nan, A), b, o, B, o), "A must be .* got 2 NaN/inf entries"),
    ((A, b, [np.inf, 0.0], B, o), "origin must be .* got 1 NaN/inf entries"),
    ((A, b, np.zeros((1, 2)), B, o), r"origin must be a finite \(d,\) array"),
    ((A, b, o, B, "xy"), "target must be a finite"),
]


@pytest.mark.parametrize("args, message", BAD)
def test_bad_input(args, message):
    with pytest.raises(InputError, match=message) as info:
        project(*args)
    assert isinstance(info.value, ValueError)
    assert "\n" not in str(info.value)


def test_bad_batch_input_names_the_problem():
    problems = [(A, b, o, B, o), (A, b[:3], o, B, o)]
    with pytest.raises(InputError, match=r"problems\[1\]: b must be"):
        project_batch(problems)
    with pytest.raises(InputError, match=r"problems\[1\]: all problems must share d = 2"):
        project_batch([(A, b, o, B, o), (A[:, :1], b, [0.0], [[1.0]], [0.0])])
    with pytest.raises(InputError, match=r"problems\[0\]: expected \(A, b, origin"):
        project_batch([(A, b)])


# --------------------------------------------------------------------------- #
# listing, docs, stdout
# --------------------------------------------------------------------------- #


def test_listings_cover_the_registry():
    assert {"clarabel", "proxsuite"} <= set(QP_BACKENDS)
    assert {"highs", "clarabel"} <= set(LP_BACKENDS)
    assert "casadi:highs" not in QP_BACKENDS
    assert all(project(*SQUARE, [2.0, 0.0], backend=s)[0] == pytest.approx(1.0)
               for s in QP_BACKENDS[:3])


@pytest.mark.parametrize("backend", [s for s in QP_BACKENDS if s.startswith("casadi:")])
def test_casadi_keeps_stdout_clean(backend, capfd):
    """qpOASES prints a banner, OSQP with polishing "Polishing not needed"."""
    for target in ([2.0, 0.0], [0.5, 0.0]):  # an active set, and none
        project(*SQUARE, target, backend=backend)
    assert capfd.readouterr().out == ""


def test_docstring_examples():
    result = doctest.testmod(km, optionflags=doctest.ELLIPSIS)
    assert result.attempted > 0 and result.failed == 0


def test_project_batch_reports_failures_as_nan_on_request():
    """An infeasible problem: a SolverError naming it, or a NaN row with on_failure="nan"."""
    from rescon.errors import SolverError
    from rescon.models.kernel_models import project_batch

    good = (np.array([[1.0, 0], [-1, 0], [0, 1], [0, -1]]), np.ones(4), np.zeros(2), np.eye(2),
            np.array([3.0, 0.0]))
    bad = (np.array([[1.0, 0], [-1, 0]]), np.array([-1.0, -1.0]), np.zeros(2), np.eye(2),
           np.zeros(2))
    for backend in ("clarabel", "proxsuite"):
        with pytest.raises(SolverError, match=r"problems\[1\]"):
            project_batch([good, bad], backend=backend)
        out = project_batch([good, bad], backend=backend, on_failure="nan")
        assert np.allclose(out[0], [1.0, 0.0], atol=1e-7) and np.isnan(out[1]).all()
    with pytest.raises(ValueError, match="on_failure"):
        project_batch([good], on_failure="skip")
