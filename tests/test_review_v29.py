"""V29 hostile review: turning a safe kernel into one canonical point.

Attacked: ``rescon.kernel_point`` / ``kernel_points`` / ``SafeKernel.point`` with
``method`` = project / chebyshev / vertex-mean on ``auto`` and every backend of
``qp_backends()`` / ``lp_backends()``; ``rescon.models.kernel_models.project`` /
``project_batch`` / ``chebyshev`` directly; the Scenario option ``kernel_point``
("project", "project-exact", "vertex-mean") through ``rescon.simulate``; the CLI
``rescon kernel ... --json``; the ``kernel_point`` certificates and the independent
checker. Inputs: magnitudes 2^-1070 … 2^990 and 1e300, data offset far from the origin,
anisotropic columns, exactly flat kernels (points on a line / plane in R^3), single-point
kernels, targets on vertices / edges / far away, duplicate points, d = 1..5, batches with
empty kernels, converged states, NaN / inf / wrong shapes / bad F / unknown or missing
backends (``sys.modules[name] = None`` in a subprocess), solver stdout noise.

References are independent of rescon's projection code: the projection is the nearest
point over every simplex of the kernel's exact vertices (Carathéodory, Fractions); the
Chebyshev radius is read off a kernel whose inscribed ball is known in closed form, or
compared with scipy's linprog.

Bugs found (all fixed since, markers removed):

* the default Chebyshev point (HiGHS) of a hexagon 2 long and 2^-30 thick is one of its
  vertices (radius 0 instead of 2^-31): HiGHS' absolute tolerance 1e-9 in the unit frame
  swallows the ball, and nothing checks the radius the returned point has;
* ``project(..., backend="cvxpy:OSQP")`` returns a point far outside the polytope (the
  unit square, target 1e10 away) with status "optimal" — no backend answer is checked
  against ``G t <= h``;
* ``project`` divides the target by the polytope's scale s (``_target_t(...) / s``),
  which overflows for a tiny polytope and a moderate target: a RuntimeWarning, then
  SolverError from every backend — and NaN from ``casadi:qpoases``;
* a non-numeric ``target`` (``"ab"``, a complex number, a dict), or ``SafeKernel.contains``
  of one, raises a bare ValueError / TypeError instead of a one-line InputError;
* an unknown ``backend`` is accepted silently when no solver happens to be called
  (a single-point kernel, or a ``kernel_points`` batch whose kernels are all empty).
"""

from __future__ import annotations

import copy
import itertools
import json
import math
import subprocess
import sys
import warnings
from fractions import Fraction
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon.errors import EmptyKernel, InputError, SolverError, SolverNotFound
from rescon.models.kernel_models import chebyshev, lp_backends, project, qp_backends

PY = sys.executable
QP = qp_backends()
LP = lp_backends()
SQUARE_A = [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]


# --------------------------------------------------------------------------- #
# independent exact references
# --------------------------------------------------------------------------- #


def _dot(a, b) -> Fraction:
    return sum((x * y for x, y in zip(a, b, strict=True)), Fraction(0))


def _solve(M, r):
    """Gauss–Jordan in Fractions; None if singular."""
    n = len(M)
    M = [list(row) + [r[i]] for i, row in enumerate(M)]
    for c in range(n):
        p = next((i for i in range(c, n) if M[i][c] != 0), None)
        if p is None:
            return None
        M[c], M[p] = M[p], M[c]
        for i in range(n):
            if i != c and M[i][c] != 0:
                f = M[i][c] / M[c][c]
                M[i] = [a - f * b for a, b in zip(M[i], M[c], strict=True)]
    return [M[i][n] / M[i][i] for i in range(n)]


def exact_projection(V, m):
    """The point of conv(V) nearest to m: the best projection onto any simplex of ≤ d+1
    vertices that lands inside it (Carathéodory), all in Fractions."""
    V = [tuple(Fraction(x) for x in v) for v in V]
    m = tuple(Fraction(x) for x in m)
    d = len(m)
    best = None
    for r in range(1, min(len(V), d + 1) + 1):
        for S in itertools.combinations(V, r):
            p0 = S[0]
            D = [tuple(a - b for a, b in zip(s, p0, strict=True)) for s in S[1:]]
            if D:
                c = _solve([[_dot(u, w) for w in D] for u in D],
                           [_dot(u, tuple(a - b for a, b in zip(m, p0, strict=True)))
                            for u in D])
                if c is None or any(x < 0 for x in c) or sum(c) > 1:
                    continue
                x = tuple(p0[j] + sum(ci * u[j] for ci, u in zip(c, D, strict=True))
                          for j in range(d))
            else:
                x = p0
            dist = sum((a - b) ** 2 for a, b in zip(x, m, strict=True))
            if best is None or dist < best[0]:
                best = (dist, x)
    return best[1]


def exact_mean(X):
    X = np.asarray(X, dtype=float)
    return tuple(sum(map(Fraction, col), Fraction(0)) / len(X) for col in X.T.tolist())


def cert_point(cert):
    return tuple(Fraction(s) for s in cert["x"])


def in_kernel(K, x) -> bool:
    return K._exact.contains(tuple(Fraction(v) for v in x))


def inradius(K, x) -> float:
    """min over the exact facets a·y ≤ β of (β − a·x)/‖a‖ (numerator exact)."""
    return min(float(b - _dot(a, x)) / math.sqrt(sum(float(v) ** 2 for v in a))
               for a, b in K._exact.facets)


def _run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([PY, "-c", code], capture_output=True, text=True, timeout=120,
                          cwd=str(Path(__file__).resolve().parents[1]))


def _cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run([PY, "-m", "rescon", *map(str, args)], capture_output=True,
                          text=True, timeout=120)


# --------------------------------------------------------------------------- #
# attacks that held
# --------------------------------------------------------------------------- #


def _random_clouds():
    rng = np.random.default_rng(29)
    out = []
    for trial in range(10):
        d = 1 + trial % 3
        F = 1 + (trial // 3) % 2
        n = (d + 1) * F + 1 + int(rng.integers(0, 3))
        X = rng.normal(size=(n, d))
        kind = trial % 5
        if kind == 1:
            X = X * 1e-300
        elif kind == 2:
            X = 1e12 + X * 1e-3
        elif kind == 3:
            X = np.round(X * 2)  # duplicates, ties, degenerate positions
        elif kind == 4:
            X = X * 2.0**600
        out.append((X, F))
    return out


@pytest.mark.parametrize("case", range(10))
def test_project_is_the_exact_projection_on_every_backend(case):
    X, F = _random_clouds()[case]
    K = rescon.safe_kernel(X, F)
    if K.is_empty:
        pytest.skip("empty kernel")
    ref = exact_projection(K.exact_vertices, exact_mean(X))
    for backend in ["auto", *QP]:
        try:
            x, cert = rescon.kernel_point(X, F, backend=backend)
        except SolverError:  # a documented limit of explicit backends (thin kernels)
            assert backend != "auto"
            continue
        assert cert_point(cert) == ref, backend
        assert x.tolist() == [float(v) for v in ref]
        assert K._exact.contains(cert_point(cert))


@pytest.mark.parametrize("scale", [1.0, 2.0**-1000, 2.0**500, 2.0**990, 2.0**-1070])
def test_exactly_flat_kernels_in_space(scale):
    """Points exactly on a line and on a plane in R³ (integer data × a power of two)."""
    rng = np.random.default_rng(3)
    t = rng.integers(-8, 9, size=7).astype(float)
    line = (np.outer(t, [1, 2, 3]) + 16) * scale
    P = rng.integers(-8, 9, size=(9, 2)).astype(float)
    plane = (P @ np.array([[1.0, 0, 1], [0, 1, -2]])) * scale
    for X, F, dim in ((line, 1, 1), (plane, 2, 2)):
        K = rescon.safe_kernel(X, F)
        assert K.dim == dim
        ref = exact_projection(K.exact_vertices, exact_mean(X))
        for backend in ("auto", "clarabel", "highs"):
            x, cert = rescon.kernel_point(X, F, backend=backend)
            assert cert_point(cert) == ref
            assert np.isfinite(x).all()
        for method in ("chebyshev", "vertex-mean"):
            x, cert = rescon.kernel_point(X, F, method=method)
            assert K._exact.contains(cert_point(cert))
            assert rescon.check_certificate(cert).verdict == "valid"


def test_targets_on_vertices_edges_and_outside_give_the_exact_projection():
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(8):
        d = int(rng.integers(1, 4))
        X = rng.integers(-20, 21, size=(d + 4, d)).astype(float)
        K = rescon.safe_kernel(X, 1)
        if K.is_empty or K.dim < 1:
            continue
        V = K.exact_vertices
        for T in (V[0], tuple((a + b) / 2 for a, b in zip(V[0], V[1], strict=True)),
                  tuple(3 * a - 2 * b for a, b in zip(V[0], V[-1], strict=True))):
            Tf = [float(v) for v in T]
            if any(Fraction(v) != w for v, w in zip(Tf, T, strict=True)):
                continue
            ref = exact_projection(V, T)
            for backend in ("auto", "exact", "clarabel", "proxsuite", "highs"):
                if backend not in ("auto", "exact") and backend not in QP:
                    continue
                _, cert = rescon.kernel_point(X, 1, target=Tf, backend=backend)
                assert cert_point(cert) == ref
                checked += 1
    assert checked > 20


def test_single_point_and_duplicate_kernels():
    X = np.array([[1e12, -3.0, 5e-324]] * 5 + [[0.0, 0.0, 0.0]])
    K = rescon.safe_kernel(X, 1)
    assert K.dim == 0
    for method in ("project", "chebyshev", "vertex-mean"):
        x, cert = rescon.kernel_point(X, 1, method=method)
        assert x.tolist() == [1e12, -3.0, 5e-324]
        assert rescon.check_certificate(cert).verdict == "valid"


def test_chebyshev_radius_matches_linprog_on_full_dimensional_kernels():
    from scipy.optimize import linprog

    rng = np.random.default_rng(2)
    compared = 0
    for _ in range(12):
        d = int(rng.integers(2, 4))
        X = rng.integers(-50, 51, size=(d + 5, d)).astype(float)
        K = rescon.safe_kernel(X, 1)
        if K.is_empty or K.dim < d:
            continue
        A = np.array([[float(v) for v in a] for a, _ in K._exact.facets])
        b = np.array([float(v) for _, v in K._exact.facets])
        nr = np.linalg.norm(A, axis=1)
        res = linprog(np.r_[np.zeros(d), -1.0], A_ub=np.c_[A / nr[:, None], np.ones(len(b))],
                      b_ub=b / nr, bounds=[(None, None)] * d + [(0, None)], method="highs")
        assert res.status == 0
        for backend in ["auto", *LP]:
            _, cert = rescon.kernel_point(X, 1, method="chebyshev", backend=backend)
            r = inradius(K, cert_point(cert))
            assert r >= -res.fun * (1 - 1e-6), backend
            compared += 1
    assert compared > 10


def test_chebyshev_of_a_moderately_thin_hexagon_on_every_backend():
    h = 1e-3  # the ball's radius is h/2 (the two long edges y = 0, y = h)
    X = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [0, h], [1, h], [2, h], [3, h],
                  [1.5, h / 4]])
    K = rescon.safe_kernel(X, 1)
    for backend in ["auto", *LP]:
        _, cert = rescon.kernel_point(X, 1, method="chebyshev", backend=backend)
        assert inradius(K, cert_point(cert)) == pytest.approx(h / 2, rel=1e-6)


def test_d4_every_backend_gives_the_same_point():
    rng = np.random.default_rng(11)
    X = rng.normal(size=(8, 4)) * 1e-300
    K = rescon.safe_kernel(X, 1)
    assert K.dim == 4
    pts = {cert_point(rescon.kernel_point(X, 1, backend=b)[1]) for b in ["auto", *QP]}
    assert len(pts) == 1
    (p,) = pts
    assert K._exact.contains(p)
    _, cert = rescon.kernel_point(X, 1, method="chebyshev")
    assert rescon.check_certificate(cert).verdict == "valid"


def test_certificates_accepted_and_tampered_ones_rejected():
    X = [[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4], [1, 1, 1], [4, 4, 4], [2, 1, 3]]
    for Y in (X, [[0, 0], [4, 0], [4, 4], [0, 4], [1, 3]], [[0], [1], [2], [5]]):
        x, cert = rescon.kernel_point(Y, 1)
        assert rescon.check_certificate(cert).verdict == "valid"
        far = copy.deepcopy(cert)
        far["x"] = [str(Fraction(s) + 1000) for s in cert["x"]]
        assert rescon.check_certificate(far).verdict == "invalid"
        short = copy.deepcopy(cert)
        short["x"] = short["x"][:-1]
        assert rescon.check_certificate(short).verdict == "invalid"
        # a nudge by 1e-40: rejected exactly when the nudged point leaves Ψ
        K = rescon.safe_kernel(Y, 1)
        for eps in (Fraction(1, 10**40), -Fraction(1, 10**40)):
            t = copy.deepcopy(cert)
            t["x"][0] = str(Fraction(t["x"][0]) + eps)
            inside = K._exact.contains(cert_point(t))
            assert rescon.check_certificate(t).verdict == ("valid" if inside else "invalid")


def test_kernel_points_batch_with_empty_kernels():
    good = np.array([[0, 0], [4, 0], [4, 4], [0, 4], [1, 3.0]])
    square = np.array([[0, 0], [9, 0], [0, 9], [9, 9], [5, 5.0]])  # Ψ = {(5, 5)}
    tri = np.array([[0, 0], [1, 0], [0, 1.0]])
    out = rescon.kernel_points([tri, good, tri], 1, on_empty="nan")
    assert np.isnan(out[[0, 2]]).all()
    assert out[1].tolist() == [1.8, 2.2]
    with pytest.raises(EmptyKernel, match=r"batch\[2\]"):
        rescon.kernel_points([good, square, tri], 1)
    with pytest.raises(InputError, match=r"batch\[0\]"):
        rescon.kernel_points(good, 1)  # a single (n, d) set is not a batch
    with pytest.raises(InputError, match=r"batch\[1\]"):
        rescon.kernel_points([good, np.ones((5, 3))], 1)
    with pytest.raises(InputError, match="on_empty"):
        rescon.kernel_points([good], 1, on_empty="skip")
    big = np.random.default_rng(0).normal(size=(400, 7, 2))
    pts = rescon.kernel_points(big, 2)
    assert pts.shape == (400, 2) and np.isfinite(pts).all()


@pytest.mark.parametrize("bad, exc", [
    (dict(X=[[np.nan, 0], [1, 1], [2, 2]], F=0), InputError),
    (dict(F=-1), InputError), (dict(F=5), InputError), (dict(F=1.5), InputError),
    (dict(F=True), InputError), (dict(method="foo"), InputError),
    (dict(method=None), InputError), (dict(backend=None), InputError),
    (dict(backend="foo"), SolverNotFound), (dict(backend="cvxpy:PROXQP"), SolverNotFound),
    (dict(backend="casadi:highs"), SolverNotFound),
    (dict(method="chebyshev", backend="proxsuite"), SolverNotFound),
    (dict(backend="highs:x"), InputError), (dict(target=[1, np.inf]), InputError),
    (dict(target=[1, 2, 3]), InputError), (dict(method="vertex-mean", target=[0, 0]), InputError),
    (dict(X=[[0, 0], [1, 0], [0, 1]]), EmptyKernel),
])
def test_bad_input_is_a_one_line_error(bad, exc):
    kw = dict(X=[[0, 0], [4, 0], [4, 4], [0, 4], [1, 3]], F=1) | bad
    with pytest.raises(exc) as info:
        rescon.kernel_point(kw.pop("X"), kw.pop("F"), **kw)
    assert "\n" not in str(info.value)


def test_models_validation_and_failures_are_typed():
    with pytest.raises(InputError):
        project(SQUARE_A, [1, 1], [0, 0], np.eye(2), [0, 0])
    with pytest.raises(InputError):
        project(SQUARE_A, [1] * 4, [0, 0], [[1, 0], [1, 0]], [0, 0])
    with pytest.raises(InputError):
        project([[1, 0], [np.inf, 0]], [1, 1], [0, 0], np.eye(2), [1, 1])
    with pytest.raises(SolverError):
        project([[1, 0], [-1, 0]], [-1, -1], [0, 0], np.eye(2), [0, 0])  # K empty
    with pytest.raises(SolverError):
        chebyshev([[1.0, 0.0]], [1], [0, 0], np.eye(2))  # unbounded
    assert project(SQUARE_A, [1] * 4, [0, 0], np.zeros((0, 2)), [5, 0]).tolist() == [0, 0]


def test_missing_backend_in_a_fresh_process():
    code = """
import sys; sys.modules['proxsuite'] = None; sys.modules['cvxpy'] = None
import rescon
from rescon.errors import SolverNotFound
from rescon.models.kernel_models import qp_backends
X = [[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4], [1, 1, 1], [4, 4, 4], [2, 1, 3]]
assert 'proxsuite' not in qp_backends() and not any(b.startswith('cvxpy') for b in qp_backends())
print(rescon.kernel_point(X, 1)[1]['x'])
for be in ('proxsuite', 'cvxpy', 'cvxpy:OSQP'):
    try:
        rescon.kernel_point(X, 1, backend=be)
    except SolverNotFound as e:
        assert 'not installed' in str(e), e
    else:
        raise SystemExit('accepted ' + be)
"""
    r = _run(code)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "['11/7', '10/7', '12/7']"


def test_no_backend_writes_to_stdout_even_when_failing():
    code = """
import numpy as np, rescon
from rescon.models.kernel_models import qp_backends, lp_backends, project, chebyshev
from rescon.errors import RESCONError
X = np.random.default_rng(0).integers(-8, 9, size=(8, 3)) * np.array([2.0**-27, 2.0**27, 1])
A = [[1.0, 0], [-1, 0], [0, 1], [0, -1]]
calls = []
for be in qp_backends():
    calls += [lambda be=be: rescon.kernel_point(X, 1, backend=be),
              lambda be=be: project(A, [1] * 4, [0, 0], np.eye(2), [1e300, 1], backend=be),
              lambda be=be: project([[1, 0], [-1, 0]], [-1, -1], [0, 0], np.eye(2), [0, 0],
                                    backend=be)]
for be in lp_backends():
    calls += [lambda be=be: rescon.kernel_point(X, 1, method='chebyshev', backend=be),
              lambda be=be: chebyshev([[1, 0]], [1], [0, 0], np.eye(2), backend=be)]
for f in calls:
    try:
        f()
    except RESCONError:
        pass
"""
    r = _run(code)
    assert r.returncode == 0, r.stderr
    assert r.stdout == ""


def test_cli_kernel_json_and_bad_input(tmp_path):
    pts = tmp_path / "p.txt"
    pts.write_text("0 0 0\n4 0 0\n0 4 0\n0 0 4\n1 1 1\n4 4 4\n2 1 3\n")
    r = _cli("kernel", pts, "--F", 1, "--json")
    assert r.returncode == 0, r.stderr
    out = json.loads(r.stdout)  # exactly one object
    assert out["point"] == [11 / 7, 10 / 7, 12 / 7]
    empty = tmp_path / "e.txt"
    empty.write_text("0 0\n1 0\n0 1\n")
    r = _cli("kernel", empty, "--F", 1, "--json")
    assert r.returncode == 0 and json.loads(r.stdout)["point"] is None
    nan = tmp_path / "n.txt"
    nan.write_text("0 0\nnan 1\n2 2\n3 3\n")
    for args in ((nan, "--F", 1, "--json"), (pts, "--F", 9, "--json"),
                 (pts, "--F", 1, "--point")):
        r = _cli("kernel", *args)
        assert r.returncode == 2 and r.stdout == ""
        assert "Traceback" not in r.stderr and len(r.stderr.strip().splitlines()) <= 3


@pytest.mark.parametrize("method", ["project", "project-exact", "vertex-mean"])
def test_simulate_converged_states_stay_put(method):
    G = nx.complete_graph(8).to_directed()
    from rescon.consensus.adversaries import Constant

    for d in (1, 2, 3):
        for v in (3.0, 1e12, 5e-324, 1e150):
            x0 = np.full((8, d), v)
            sc = rescon.Scenario(graph=G, x0=x0, F=1, steps=4, kernel_point=method,
                                 residual="none", adversaries={0: Constant([1e150] * d)})
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                tr = rescon.simulate(sc)
            assert np.array_equal(tr.states[-1, tr.benign], x0[tr.benign])


def test_batch_project_agrees_with_project_exact_within_the_documented_bound():
    from rescon.consensus.engine import _kernel_points

    rng = np.random.default_rng(5)
    for d, n, F in ((2, 7, 2), (3, 9, 1)):
        P = 1e12 + rng.normal(size=(30, n, d)) * 1e-3
        a = _kernel_points(P, F, "project", {})
        b = _kernel_points(P, F, "project-exact", {})
        assert np.all(np.abs(a - b).max(axis=1) <= 2.0**-40 * np.abs(b).max(axis=1))


def test_scenario_rejects_unknown_kernel_point():
    G = nx.complete_graph(8).to_directed()
    for bad in ("chebyshev", None, ["project"], "Project"):
        with pytest.raises(InputError, match="kernel_point"):
            rescon.Scenario(graph=G, x0=np.zeros((8, 2)), F=1, kernel_point=bad)


# --------------------------------------------------------------------------- #
# bugs
# --------------------------------------------------------------------------- #


# Fixed (was a bug: the default Chebyshev point of a hexagon 2 long and 2^-30 thick is a vertex
# (radius 0, not 2^-31): HiGHS' 1e-9 tolerance in the unit frame, and the radius of the returned
# point is never checked)
def test_chebyshev_default_of_a_thin_hexagon_has_the_largest_ball():
    h = 2.0**-30  # far thicker than the documented 1e-16 sliver limit
    X = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [0, h], [1, h], [2, h], [3, h],
                  [1.5, h / 4]])
    K = rescon.safe_kernel(X, 1)
    assert K.dim == 2  # hexagon (1/2, h/2), (1, 0), (2, 0), (5/2, h/2), (2, h), (1, h)
    _, cert = rescon.kernel_point(X, 1, method="chebyshev")  # auto: Clarabel (was HiGHS)
    # the largest ball has radius h/2 (centre (3/2, h/2)); clarabel finds it
    assert inradius(K, cert_point(cert)) >= 0.99 * h / 2


@pytest.mark.skipif("cvxpy:OSQP" not in QP, reason="cvxpy's OSQP not installed")
# Fixed (was a bug: project(backend='cvxpy:OSQP') returns (-4.48, -2.24) for the square [-1, 1]²
# and target (1e10, 5e9): a point outside K with status optimal; backend answers are never
# checked)
def test_project_cvxpy_osqp_never_returns_a_point_outside_the_polytope():
    try:
        x = project(SQUARE_A, [1.0] * 4, [0, 0], np.eye(2), [1e10, 5e9], backend="cvxpy:OSQP")
    except SolverError:
        return  # a refusal is acceptable; a wrong point is not
    assert np.all(np.asarray(SQUARE_A) @ x <= 1 + 1e-6)
    assert np.allclose(x, [1, 1], atol=1e-6)


@pytest.mark.skipif("casadi:qpoases" not in QP, reason="casadi's qpoases not installed")
# Fixed (was a bug: project() divides the target by the polytope's scale (kernel_models.py,
# _target_t(hull, y) / s): it overflows to inf and casadi:qpoases returns NaN as the projection)
def test_project_qpoases_never_returns_nan():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            x = project(SQUARE_A, [1e-300] * 4, [0, 0], np.eye(2), [1e10, 5e9],
                        backend="casadi:qpoases")
        except SolverError:
            return
    assert np.isfinite(x).all()


# Fixed (was a bug: project() of a tiny box (1e-300) and target (1e10, 5e9): c / s
# overflowed (RuntimeWarning), then a SolverError from clarabel's status): the target is
# ~1e310 box sizes away, beyond what a float QP resolves — now a one-line SolverError
# saying so, no RuntimeWarning; rescon.kernel_point decides such projections exactly
def test_project_tiny_polytope_moderate_target():
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(SolverError, match="beyond the float range") as e:
            project(SQUARE_A, [1e-300] * 4, [0, 0], np.eye(2), [1e10, 5e9])
    assert "\n" not in str(e.value)
    X = [[-1e-300, -1e-300], [1e-300, -1e-300], [1e-300, 1e-300], [-1e-300, 1e-300]]
    x, _ = rescon.kernel_point(X, 0, target=[1e10, 5e9])
    assert x.tolist() == [1e-300, 1e-300]


@pytest.mark.parametrize("call", ["target-str", "target-complex", "target-dict",
                                  "contains-str"])
# Fixed (was a bug: a non-numeric target / point gives a bare ValueError or TypeError (points.py
# _target and SafeKernel.contains call np.asarray(..., dtype=float64) unguarded), not a one-line
# InputError)
def test_non_numeric_target_is_an_input_error(call):
    X = [[0, 0], [4, 0], [4, 4], [0, 4], [1, 3]]
    with pytest.raises(InputError):
        if call == "target-str":
            rescon.kernel_point(X, 1, target="ab")
        elif call == "target-complex":
            rescon.kernel_point(X, 1, target=[1 + 2j, 0])
        elif call == "target-dict":
            rescon.kernel_point(X, 1, target={"a": 1})
        else:
            rescon.safe_kernel(X, 1).contains("ab")


@pytest.mark.parametrize("call", ["point-kernel-project", "point-kernel-chebyshev",
                                  "all-empty-batch"])
# Fixed (was a bug: an unknown backend is only looked up when a solver is called: a single-point
# kernel (points.py _project / _chebyshev return early for K.dim == 0) or an all-empty batch
# accept backend='nope')
def test_unknown_backend_is_refused_whatever_the_data(call):
    with pytest.raises(SolverNotFound):
        if call == "point-kernel-project":
            rescon.kernel_point([[1.0, 1.0]] * 5, 1, backend="nope")
        elif call == "point-kernel-chebyshev":
            rescon.kernel_point([[1.0, 1.0]] * 5, 1, method="chebyshev", backend="nope")
        else:
            rescon.kernel_points([[[0, 0], [1, 0], [0, 1]]], 1, backend="nope", on_empty="nan")
