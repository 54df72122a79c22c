"""Issue 10 §3/§5: float rows that describe the kernel, bounded tables, input limits,
QP backends on thin kernels, certificates that list only facets."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from fractions import Fraction

import numpy as np
import pytest

import rescon
from rescon.errors import EmptyKernel, InputError, SolverError
from rescon.geometry import halfspaces, points
from rescon.models.kernel_models import lp_backends, qp_backends

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


# --------------------------------------------------------------------------- #
# exponential tables: one budget (geometry/_budget.py), refused or skipped early
# --------------------------------------------------------------------------- #


def _run_limited(code: str, gib: float = 2.5, seconds: float = 120):
    """``code`` in a fresh interpreter whose address space is capped at ``gib`` GiB
    (what used to take 5–18 GB dies there with MemoryError)."""
    cap = int(gib * 2**30)
    pre = ("import resource\n"
           f"resource.setrlimit(resource.RLIMIT_AS, ({cap}, {cap}))\n"
           "import numpy as np, rescon\n")
    return subprocess.run([sys.executable, "-c", pre + textwrap.dedent(code)],
                          check=False, capture_output=True, text=True, timeout=seconds)


@pytest.mark.slow
def test_quick_emptiness_directions_skipped_in_high_dimension():
    # 3^16 directions took 10.5 GB; the full algorithm decides instead
    out = _run_limited("""
        K = rescon.safe_kernel(np.random.default_rng(0).normal(size=(2, 16)), 1)
        print(K.is_empty, K.certificate["kind"])
    """)
    assert out.returncode == 0, out.stderr[-500:]
    assert out.stdout.split() == ["True", "kernel_empty"]  # (the checker takes d ≤ 8)


@pytest.mark.slow
@pytest.mark.parametrize("n,d,F", [(13, 12, 0), (25, 20, 0), (21, 20, 0)])
def test_high_dimension_refused_by_the_budget(n, d, F):
    # (d−1)! permutations took 5.5 GB (13 in R^12) and 18 GB (25 in R^20)
    out = _run_limited(f"""
        import time
        from rescon.errors import InputError
        t = time.perf_counter()
        try:
            rescon.safe_kernel(np.random.default_rng(0).normal(size=({n}, {d})), {F})
        except InputError as exc:
            print("refused", round(time.perf_counter() - t, 1), exc)
    """)
    assert out.returncode == 0, out.stderr[-500:]
    assert out.stdout.startswith("refused"), out.stdout
    assert float(out.stdout.split()[1]) < 30 and "steps" in out.stdout


def test_bareiss_determinant_matches_fractions():
    rng = np.random.default_rng(4)
    for m in range(1, 8):
        for _ in range(5):
            M = rng.integers(-3, 4, size=(m, m)).tolist()
            if m > 2:
                M[1][0] = 0  # zero pivots: row swaps
                M[0][0] = 0
            assert halfspaces._int_det(M) == _fraction_det(M)


def _fraction_det(M) -> int:
    A = [[Fraction(v) for v in row] for row in M]
    det = Fraction(1)
    for c in range(len(A)):
        p = next((i for i in range(c, len(A)) if A[i][c]), None)
        if p is None:
            return 0
        if p != c:
            A[c], A[p] = A[p], A[c]
            det = -det
        det *= A[c][c]
        for i in range(c + 1, len(A)):
            f = A[i][c] / A[c][c]
            A[i] = [x - f * y for x, y in zip(A[i], A[c], strict=True)]
    return int(det)


@pytest.mark.parametrize("seed", [0, 1])
def test_exact_only_candidates_give_the_same_kernel(monkeypatch, seed):
    # the path taken where a (k−1)!-term expansion costs more (k ≥ 10), forced at k = 4
    X = np.random.default_rng(seed).normal(size=(14, 4))
    ref = rescon.safe_kernel(X, 1)
    monkeypatch.setattr(halfspaces, "PYTHON_STEP", 0)
    assert halfspaces._scan_plan(14, 4, False)[0]
    K = rescon.safe_kernel(X, 1)
    assert set(K.exact_vertices) == set(ref.exact_vertices)
    assert K.certificate == ref.certificate


def test_planar_estimate_is_the_sweeps():
    # 3000 distinct points in the plane: C(n,2)·(n−2) ≈ 1.3e10 tests refused them,
    # the angular sweep needs ~n² log n
    exact_only, work, nbytes = halfspaces._scan_plan(3000, 2, True)
    assert not exact_only and work < 1e9 and nbytes < 2**30
    assert halfspaces._scan_plan(3000, 2, False)[1] > 4e9  # the direct scan would not fit


# --------------------------------------------------------------------------- #
# certificates: only the rows the claim needs
# --------------------------------------------------------------------------- #

#: integer clouds whose kernels have degenerate vertices: 11 rows tight at a vertex for
#: 6 facets, and 19 for 12
DEGENERATE = [
    ([[1, 1, 1], [2, 1, 2], [1, 0, 0], [2, 1, 0], [2, 2, 0], [0, 2, 1], [1, 0, 0], [2, 2, 2],
      [1, 0, 0], [1, 2, 0], [1, 1, 1], [1, 2, 0], [2, 2, 2], [0, 1, 1], [0, 0, 2], [0, 2, 0]],
     2),
    ([[0, 1, 1, 0], [1, 1, 0, 0], [1, 1, 0, 1], [1, 1, 1, 1], [1, 0, 1, 1], [1, 0, 0, 1],
      [0, 1, 1, 0], [0, 1, 1, 1], [1, 1, 0, 0], [1, 0, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], 1),
]


@pytest.mark.parametrize("X,F", DEGENERATE)
def test_certificate_lists_only_the_facets(X, F):
    K = rescon.safe_kernel(X, F)
    cert = K.certificate
    assert K.dim == len(X[0])  # full-dimensional: the facets are all it needs
    assert len(cert["facets"]) == len(K.b)
    assert rescon.check_certificate(cert).valid


def test_flat_kernel_certificate_keeps_its_equalities():
    K = rescon.safe_kernel(FLAT, 1)
    rows = K.certificate["facets"]
    assert len(rows) == 4  # the segment's line (both sides) and its two ends
    assert rescon.check_certificate(K.certificate).valid


# --------------------------------------------------------------------------- #
# explicit QP backends on a thin 3-D kernel with a far target
# --------------------------------------------------------------------------- #


def _thin_kernel():
    """Ψ of a cloud 1e-12 thick along a tilted direction, its mean pulled 3e6 away by
    one far point: explicit backends' inaccurate answers used to leave the exact search
    enumerating active sets for seconds (minutes on larger kernels)."""
    rng = np.random.default_rng(3)
    X = rng.normal(size=(30, 3))
    X[:, 2] *= 1e-12
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    X = X @ Q.T + 10
    X[0] = 1e8
    return rescon.safe_kernel(X, 3)


@pytest.mark.parametrize("backend", qp_backends())
def test_thin_kernel_every_backend_exact_or_solver_error(monkeypatch, backend):
    K = _thin_kernel()
    ref = K.point("project")
    calls = []
    real = points._kkt
    monkeypatch.setattr(points, "_kkt", lambda *a: calls.append(1) or real(*a))
    try:
        x, cert = K.point("project", backend=backend)
    except SolverError as exc:
        assert backend in str(exc)
    else:
        assert np.array_equal(x, ref[0]) and cert == ref[1]
    assert len(calls) <= 2000  # the exact search was guided, not exhaustive


def test_planar_estimate_follows_the_method(monkeypatch):
    # integer points spread too wide for the sweep's exact separation are scanned
    # directly (O(n³)): the estimate must be that scan's, and refuse
    X = np.random.default_rng(6).integers(0, 10**7, size=(2100, 2)).astype(float)
    plans = []
    real = halfspaces._scan_plan
    monkeypatch.setattr(halfspaces, "_scan_plan", lambda *a: plans.append(a) or real(*a))
    with pytest.raises(InputError, match="2100 distinct points"):
        rescon.safe_kernel(X, 100)
    assert plans == [(2100, 2, False)]
