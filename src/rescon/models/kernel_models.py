"""Optimisation models that turn a polytope (a safe kernel) into one canonical point.

The polytope is given in float form as

.. math::  K = \\{x \\in \\mathbb R^d : x = o + B^\\top t,\\ A x \\le b\\},

with ``origin`` :math:`o \\in \\mathbb R^d`, ``basis`` :math:`B \\in \\mathbb R^{k\\times d}`
(orthonormal rows, :math:`k` = affine dimension, :math:`0 \\le k \\le d`), ``A``
:math:`\\in \\mathbb R^{m\\times d}`, ``b`` :math:`\\in \\mathbb R^m`. Every model works in
the hull coordinates :math:`t \\in \\mathbb R^k`:

.. math::  G t \\le h, \\qquad G_i = \\frac{A_i B^\\top}{\\|A_i B^\\top\\|},\\quad
           h_i = \\frac{b_i - A_i o}{\\|A_i B^\\top\\|}

(rows scaled to unit normals). A row whose hull part :math:`A_i B^\\top` vanishes (up to
rounding, :math:`\\|A_i B^\\top\\| \\le 10^{-12}\\|A_i\\|`) describes the hull itself,
:math:`0 \\le b_i - A_i o`, which the caller guarantees; it is skipped.

Two models:

* :func:`project` — the QP :math:`\\min_t \\tfrac12\\|t - B(y - o)\\|^2` s.t. :math:`Gt \\le h`:
  the unique point of :math:`K` closest to a target :math:`y` (``project_batch`` for many);
* :func:`chebyshev` — the LP :math:`\\max_{t,\\rho} \\rho` s.t. :math:`Gt + \\rho \\le h,\\
  \\rho \\ge 0`: the largest ball inside :math:`K` within its affine hull.

Backends come from :mod:`rescon.models.backends` (never a silent fallback). Matrix
backends (``clarabel``, ``proxsuite``, ``highs``) take the standard form
:math:`\\min \\tfrac12 z^\\top P z + q^\\top z` s.t. :math:`Gz \\le h`; the symbolic backends
(``cvxpy``, ``casadi``) write each model with their own modelling language and take the
underlying solver as ``solver=`` or as ``backend="name:solver"`` (e.g. ``"casadi:osqp"``);
:func:`qp_backends` / :func:`lp_backends` list every usable spelling.
"""

from __future__ import annotations

import contextlib
import functools
import io
import math
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np

from ..errors import InputError, SolverError, SolverNotFound
from .backends import available_backends, require_backend, silent_highs, silent_highs_inside

__all__ = ["check_backend", "chebyshev", "lp_backends", "project", "project_batch", "qp_backends"]

#: Tolerance asked of every solver (absolute / relative gap and feasibility).
TOL = 1e-9
#: Gap tolerance of the interior-point solver (Clarabel): its error is ~√gap when a
#: constraint is weakly active (target on a facet, or projecting onto a vertex along
#: a facet): 1e-9 leaves errors of 2e-5, 1e-13 of 2e-7; 1e-14 ends 'AlmostSolved'.
IPM_TOL = 1e-13
#: proxsuite's iteration limit (see ``_proxsuite_setup``)
PROXSUITE_MAX_ITER = 1_000
#: A row with ``‖A_i Bᵀ‖ ≤ _HULL_NORMAL ‖A_i‖`` is normal to the hull (see module doc).
_HULL_NORMAL = 1e-12
#: Orthonormality the ``basis`` rows must have: ``max |B Bᵀ − I| ≤ _ORTHONORMAL``.
_ORTHONORMAL = 1e-8

#: CVXPY solvers with known tight-tolerance settings → (capabilities, options).
_CVXPY_SOLVERS: dict[str, tuple[frozenset[str], dict]] = {
    "CLARABEL": (
        frozenset({"LP", "QP"}),
        {"tol_gap_abs": IPM_TOL, "tol_gap_rel": IPM_TOL, "tol_feas": IPM_TOL},
    ),
    # OSQP (ADMM) hits its iteration limit on some LPs at 1e-9: QP only
    "OSQP": (
        frozenset({"QP"}),
        {"eps_abs": TOL, "eps_rel": TOL, "polishing": True, "max_iter": 200_000},
    ),
    "HIGHS": (
        frozenset({"LP", "QP"}),
        {"primal_feasibility_tolerance": TOL, "dual_feasibility_tolerance": TOL,
         "qp_regularization_value": 0.0},
    ),
    "SCS": (frozenset({"LP", "QP"}), {"eps_abs": TOL, "eps_rel": TOL, "max_iters": 200_000}),
    "SCIPY": (frozenset({"LP"}), {}),
}
#: CasADi conic plugins, in order of preference → (capabilities, options).
_CASADI_PLUGINS: dict[str, tuple[frozenset[str], dict]] = {
    "qpoases": (frozenset({"LP", "QP"}), {"printLevel": "none"}),
    # no polishing: CasADi's OSQP then prints on C-level stdout; QP only as for CVXPY
    "osqp": (
        frozenset({"QP"}),
        {"osqp": {"eps_abs": TOL, "eps_rel": TOL, "polish": False, "verbose": False,
                  "max_iter": 200_000}},
    ),
}
#: "backend:solver" pairs that exist but are not offered → why.
_REFUSED = {
    "casadi:highs": "CasADi's bundled HiGHS and highspy cannot share a process (segfault "
    "or ImportError, depending on which loads first); use backend='highs'",
    "casadi:proxqp": "CasADi's interface exposes neither proxqp's duality-gap check (errors "
    "~1e-5) nor its infeasibility tolerance (spurious PRIMAL_INFEASIBLE on feasible "
    "problems); use backend='proxsuite'",
    "cvxpy:PROXQP": "CVXPY's interface exposes neither proxqp's duality-gap check (errors "
    "~1e-5) nor its infeasibility tolerance (spurious 'infeasible'); use "
    "backend='proxsuite'",
}


class _Hull(NamedTuple):
    """A validated polytope reduced to hull coordinates: ``K = {o + Bᵀt : G t ≤ h}``."""

    origin: np.ndarray  # (d,)
    basis: np.ndarray  # (k, d)
    G: np.ndarray  # (m', k), unit rows
    h: np.ndarray  # (m',)

    @property
    def k(self) -> int:
        return self.basis.shape[0]

    def lift(self, t: np.ndarray) -> np.ndarray:
        """x = o + Bᵀ t."""
        return self.origin + self.basis.T @ t


class _Standard(NamedTuple):
    """min ½ zᵀPz + qᵀz  s.t.  G z ≤ h  (P symmetric PSD, dense)."""

    P: np.ndarray
    q: np.ndarray
    G: np.ndarray
    h: np.ndarray


# --------------------------------------------------------------------------- #
# public API
# --------------------------------------------------------------------------- #


def project(A, b, origin, basis, target, *, backend="clarabel", solver=None) -> np.ndarray:
    """The point of ``K`` closest to ``target`` (Euclidean projection).

    Solves the strictly convex QP

    .. math::  \\min_{t\\in\\mathbb R^k} \\tfrac12 \\|t - B(y - o)\\|^2
               \\quad\\text{s.t.}\\quad G t \\le h

    and returns :math:`x^* = o + B^\\top t^*`. Since :math:`B` has orthonormal rows,
    :math:`\\|x - y\\|^2 = \\|t - B(y-o)\\|^2 + \\|(I - B^\\top B)(y - o)\\|^2`, so
    :math:`x^*` is the unique minimiser of :math:`\\|x - y\\|` over ``K``.

    Parameters
    ----------
    A : array_like, shape (m, d)
    b : array_like, shape (m,)
        Inequalities ``A x ≤ b`` of ``K``.
    origin : array_like, shape (d,)
        A point of the affine hull of ``K``.
    basis : array_like, shape (k, d)
        Orthonormal rows spanning the hull directions (``k = 0``: ``K = {origin}``).
    target : array_like, shape (d,)
        The point ``y`` to project.
    backend : str
        A name from :func:`qp_backends`: ``"clarabel"``, ``"proxsuite"``, ``"highs"``,
        ``"cvxpy"``/``"cvxpy:SOLVER"``, ``"casadi"``/``"casadi:plugin"``.
    solver : str, optional
        The solver behind a symbolic backend: a CVXPY solver name (default
        ``"CLARABEL"``; also HIGHS, SCS, OSQP for QPs, SCIPY for LPs) or a CasADi
        conic plugin (``"qpoases"``, the default, or ``"osqp"`` for QPs).
        ``_REFUSED`` says why ``cvxpy:PROXQP``, ``casadi:proxqp`` and ``casadi:highs``
        are not offered.
        Not accepted by the matrix backends.

    Returns
    -------
    numpy.ndarray, shape (d,)

    Raises
    ------
    InputError
        Malformed or non-finite input, or a ``solver=`` the backend does not take.
    SolverNotFound
        Unknown or missing backend / solver / plugin (names the available ones).
    SolverError
        The solver did not report an optimal solution (e.g. ``K`` empty); the message
        carries the solver's status.

    Notes
    -----
    One QP in ``k ≤ d`` variables with ``m`` constraints; ``k = 0`` calls no solver.

    Examples
    --------
    >>> A = [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]  # the square [-1, 1]²
    >>> x = project(A, [1, 1, 1, 1], [0, 0], np.eye(2), [3.0, 0.5])
    >>> np.round(x, 6).tolist()
    [1.0, 0.5]
    """
    name, solver = _resolve(backend, solver, "QP")
    hull = _validate(A, b, origin, basis)
    y = _vector(target, "target", hull.origin.size)
    if hull.k == 0:
        return hull.origin.copy()
    # the minimiser of ½‖u − c/s‖² over G u ≤ h/s is t*/s
    s, scaled = _unit_scale(hull)
    t = _SOLVE_QP[name](scaled, _scaled_target(hull, y, s), solver)
    return hull.lift(s * _checked(name, scaled, t))


def chebyshev(A, b, origin, basis, *, backend="highs", solver=None) -> tuple[np.ndarray, float]:
    """Centre and radius of the largest ball inside ``K`` within its affine hull.

    Solves the LP (rows of ``G`` are unit vectors)

    .. math::  \\max_{t, \\rho} \\rho \\quad\\text{s.t.}\\quad G t + \\rho \\mathbf 1 \\le h,
               \\quad \\rho \\ge 0,

    and returns :math:`(o + B^\\top t^*, \\rho^*)`: the ball of radius :math:`\\rho^*`
    around the centre, intersected with the hull, lies in ``K``.

    Parameters are those of :func:`project` (without ``target``); ``backend`` is a name
    from :func:`lp_backends`.

    Returns
    -------
    centre : numpy.ndarray, shape (d,)
    radius : float
        Unique; ``0.0`` when ``k = 0`` (centre = ``origin``, no solver called).

    Raises
    ------
    InputError, SolverNotFound, SolverError
        As for :func:`project`; an unbounded ``K`` gives a SolverError.

    Notes
    -----
    The maximiser need not be unique (a 2×1 rectangle has a segment of centres); each
    backend returns one of them, so only the radius is backend-independent. Use
    :func:`project` when a canonical point is needed.

    Examples
    --------
    >>> A = [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]
    >>> c, r = chebyshev(A, [1, 1, 1, 1], [0, 0], np.eye(2))
    >>> np.round(c, 6).tolist(), round(r, 6)
    ([0.0, 0.0], 1.0)
    """
    name, solver = _resolve(backend, solver, "LP")
    hull = _validate(A, b, origin, basis)
    if hull.k == 0:
        return hull.origin.copy(), 0.0
    s, scaled = _unit_scale(hull)  # max ρ over G u + ρ ≤ h/s is ρ*/s, at t*/s
    t, rho = _SOLVE_LP[name](scaled, solver)
    return hull.lift(s * _checked(name, scaled, t, float(rho))), float(s * rho)


def project_batch(problems: Sequence[tuple], *, backend="proxsuite", solver=None,
                  on_failure: str = "raise") -> np.ndarray:
    """:func:`project` for many polytopes at once.

    Parameters
    ----------
    problems : sequence of (A, b, origin, basis, target)
        Arguments of :func:`project`; all must share ``d``, while ``m`` and ``k`` may vary.
    backend, solver
        As for :func:`project`. A backend with the ``"batch"`` capability (proxsuite)
        solves all QPs in one parallel call (``proxqp.dense.solve_in_parallel`` over a
        ``BatchQP`` of QPs of their own sizes); any other backend solves them in a loop.
    on_failure : {"raise", "nan"}
        What a problem the solver does not solve gives: a SolverError naming its index
        (default), or a row of NaN (the caller then decides that problem otherwise).

    Returns
    -------
    numpy.ndarray, shape (len(problems), d)
        Row ``i`` is ``project(*problems[i])``.

    Raises
    ------
    InputError
        A malformed problem (the message names its index) or different ``d``.
    SolverNotFound, SolverError
        As for :func:`project`; a failure names the problem's index.
    """
    if on_failure not in ("raise", "nan"):
        raise InputError(f"on_failure must be 'raise' or 'nan', got {on_failure!r}")
    name, solver = _resolve(backend, solver, "QP")
    hulls, targets = _validate_batch(problems)
    out = np.zeros((len(hulls), hulls[0].origin.size if hulls else 0))
    for i, hull in enumerate(hulls):
        out[i] = hull.origin
    # each problem in its unit frame (:func:`project`); a target beyond it fails alone
    scales, scaled, cs, todo = {}, {}, {}, []
    for i, hull in enumerate(hulls):
        if hull.k > 0:
            scales[i], scaled[i] = _unit_scale(hull)
            cs[i] = _indexed(i, on_failure, _scaled_target, hull, targets[i], scales[i])
            if cs[i] is None:
                out[i] = np.nan
            else:
                todo.append(i)
    if name in _BATCH_QP:
        ts = _BATCH_QP[name]([scaled[i] for i in todo], [cs[i] for i in todo], todo,
                             on_failure)
    else:
        ts = [_indexed(i, on_failure, _SOLVE_QP[name], scaled[i], cs[i], solver)
              for i in todo]
    for i, t in zip(todo, ts):
        if t is not None:
            t = _indexed(i, on_failure, _checked, name, scaled[i], t)
        out[i] = np.nan if t is None else hulls[i].lift(scales[i] * t)
    return out


def qp_backends() -> list[str]:
    """Every usable ``backend=`` spelling for :func:`project`, e.g. ``"casadi:osqp"``."""
    return _variants("QP")


def lp_backends() -> list[str]:
    """Every usable ``backend=`` spelling for :func:`chebyshev`."""
    return _variants("LP")


# --------------------------------------------------------------------------- #
# validation and reduction to hull coordinates
# --------------------------------------------------------------------------- #


def _array(x, name: str, ndim: int, expected: str) -> np.ndarray:
    """``x`` as a finite float array of ``ndim`` dimensions, else InputError."""
    try:
        arr = np.asarray(x, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{name} must be a finite {expected} float array; got {x!r:.60}") from exc
    if arr.ndim != ndim:
        raise InputError(f"{name} must be a finite {expected} array; got shape {arr.shape}")
    bad = int(np.count_nonzero(~np.isfinite(arr)))
    if bad:
        raise InputError(f"{name} must be a finite {expected} array; got {bad} NaN/inf entries")
    return arr


def _vector(x, name: str, d: int) -> np.ndarray:
    arr = _array(x, name, 1, f"({d},)")
    if arr.shape != (d,):
        raise InputError(f"{name} must be a finite ({d},) array; got shape {arr.shape}")
    return arr


def _validate(A, b, origin, basis) -> _Hull:
    """Check shapes, finiteness and orthonormality; reduce to hull coordinates."""
    o = _array(origin, "origin", 1, "(d,)")
    d = o.size
    if d == 0:
        raise InputError("origin must be a finite (d,) array with d >= 1; got shape (0,)")
    A = _array(A, "A", 2, f"(m, {d})")
    B = _array(basis, "basis", 2, f"(k, {d})")
    if A.shape[1] != d:
        raise InputError(f"A must be a finite (m, {d}) array; got shape {A.shape}")
    b = _vector(b, "b", A.shape[0])
    if B.shape[1] != d or B.shape[0] > d:
        raise InputError(f"basis must be a finite (k, {d}) array, k <= {d}; got shape {B.shape}")
    err = float(np.max(np.abs(B @ B.T - np.eye(B.shape[0])), initial=0.0))
    if err > _ORTHONORMAL:
        raise InputError(f"basis rows must be orthonormal; got max |B Bᵀ − I| = {err:.3g}")
    return _reduce(A, b, o, B)


def _reduce(A: np.ndarray, b: np.ndarray, o: np.ndarray, B: np.ndarray) -> _Hull:
    """G = A Bᵀ, h = b − A o, rows normal to the hull dropped, the rest unit-scaled."""
    At = A @ B.T
    norm = np.linalg.norm(At, axis=1)
    keep = norm > _HULL_NORMAL * np.linalg.norm(A, axis=1)
    G = At[keep] / norm[keep, None]
    h = (b - A @ o)[keep] / norm[keep]
    return _Hull(o, B, G, h)


def _unit_scale(hull: _Hull) -> tuple[float, _Hull]:
    """(s, the hull with h / s): every backend sees the polytope at unit size, s the
    power of two with max |h| ∈ [s, 2s) (the largest facet distance from the origin,
    a point of K); dividing by it is exact, so the scaled model is the same polytope."""
    top = float(np.abs(hull.h).max()) if hull.h.size else 0.0
    if not (top > 0 and np.isfinite(top)):
        return 1.0, hull
    s = float(np.ldexp(1.0, np.frexp(top)[1] - 1))
    return s, _Hull(hull.origin, hull.basis, hull.G, hull.h / s)


def _scaled_target(hull: _Hull, y: np.ndarray, s: float) -> np.ndarray:
    """c / s, c = B (y − o) the target in hull coordinates, in the unit frame of
    :func:`_unit_scale` (s a power of two), computed as B (y/4 − o/4) · (4/s) so that
    nothing overflows on the way; SolverError
    when c / s itself passes the float range (a target some 10^308 polytope sizes away:
    no float QP resolves the polytope there)."""
    with np.errstate(over="ignore", invalid="ignore"):
        c = (hull.basis @ (y / 4 - hull.origin / 4)) * (4 / s)
    if not np.isfinite(c).all():
        raise SolverError("the target lies beyond the float range in the polytope's unit "
                          f"frame (the polytope is ~{s:.3g} across): no float QP resolves "
                          "it; rescon.kernel_point decides such projections exactly")
    return c


#: a backend's answer may violate G t ≤ h (unit rows, unit frame) by at most this much of
#: the frame's size (max(1, |h|, |t|); the solvers are asked for 1e-9): beyond, it is a
#: wrong answer reported as optimal (cvxpy's OSQP put the projection of (1e10, 5e9) on
#: the square [−1, 1]² at (−4.48, −2.24); V29) and a SolverError
FEASIBILITY = 1e-6


def _checked(backend: str, hull: _Hull, t: np.ndarray, rho: float = 0.0) -> np.ndarray:
    """t, once it is finite and G t + ρ ≤ h up to :data:`FEASIBILITY` (ρ ≥ 0 up to it
    too); else SolverError naming the backend."""
    t = np.asarray(t, dtype=np.float64)
    scale = max(float(np.abs(hull.h).max(initial=0.0)), float(np.abs(t).max(initial=0.0)),
                1.0)  # the unit frame (h ≡ 0: a cone's apex, s = 1)
    with np.errstate(all="ignore"):
        excess = max(float((hull.G @ t + rho - hull.h).max(initial=-math.inf)), -rho)
    if not (np.isfinite(t).all() and math.isfinite(rho) and excess <= FEASIBILITY * scale):
        raise SolverError(f"{backend}: reported optimal, but its point is "
                          + ("not finite" if not np.isfinite(t).all() else
                             f"outside the polytope (by {excess:.3g}, {excess / scale:.2g} of "
                             "its frame)"))
    return t


def _validate_batch(problems) -> tuple[list[_Hull], list[np.ndarray]]:
    hulls, targets = [], []
    for i, prob in enumerate(problems):
        try:
            if len(prob) != 5:
                raise InputError(f"expected (A, b, origin, basis, target); got {len(prob)} items")
            hull = _validate(*prob[:4])
            targets.append(_vector(prob[4], "target", hull.origin.size))
        except (InputError, TypeError) as exc:
            raise InputError(f"problems[{i}]: {exc}") from exc
        if hulls and hull.origin.size != hulls[0].origin.size:
            raise InputError(
                f"problems[{i}]: all problems must share d = {hulls[0].origin.size}; "
                f"got d = {hull.origin.size}"
            )
        hulls.append(hull)
    return hulls, targets


# --------------------------------------------------------------------------- #
# backend resolution
# --------------------------------------------------------------------------- #


def check_backend(backend: str, capability: str) -> None:
    """InputError / SolverNotFound unless ``backend`` ("name" or "name:solver") is usable
    for ``capability`` ("QP" or "LP"): what :func:`project` / :func:`chebyshev` would
    raise, without data."""
    _resolve(backend, None, capability)


def _resolve(backend: str, solver: str | None, capability: str) -> tuple[str, str | None]:
    """(backend name, solver) from ``backend`` ("name" or "name:solver") and ``solver``."""
    if not isinstance(backend, str) or not isinstance(solver, (str, type(None))):
        raise InputError(f"backend and solver must be strings; got {backend!r}, {solver!r}")
    return _resolve_cached(backend, solver, capability)


@functools.lru_cache(maxsize=64)
def _resolve_cached(backend: str, solver: str | None, capability: str) -> tuple[str, str | None]:
    """:func:`_resolve` after the type checks, cached: looking a backend up in the
    registry costs ~0.3 ms (``find_spec`` of every backend), more than a small QP."""
    name, _, inline = backend.partition(":")
    if inline and solver is not None:
        raise InputError(f"give the solver once: backend={backend!r} and solver={solver!r}")
    solver = inline or solver
    require_backend(name, capability)
    if name == "cvxpy":
        solver = "CLARABEL" if solver is None else solver.upper()
        return name, _pick(name, solver, _cvxpy_solvers(capability), capability)
    if name == "casadi":
        return name, _pick(name, solver, _casadi_plugins(capability), capability)
    if solver is not None:
        raise InputError(f"backend {name!r} takes no solver=; got {solver!r}")
    return name, None


def _cvxpy_solvers(capability: str) -> list[str]:
    """Installed CVXPY solvers that have ``capability`` and known tolerance settings."""
    import cvxpy as cp

    installed = set(cp.installed_solvers())
    return [s for s, (caps, _) in _CVXPY_SOLVERS.items() if capability in caps and s in installed]


def _casadi_plugins(capability: str) -> list[str]:
    """CasADi conic plugins with ``capability`` that can be loaded.

    ``casadi.has_conic`` is asked first because CasADi may abort the process when a
    missing plugin is instantiated.
    """
    import casadi

    return [p for p, (caps, _) in _CASADI_PLUGINS.items()
            if capability in caps and casadi.has_conic(p)]


def _pick(name: str, solver: str | None, ok: list[str], capability: str) -> str:
    """``solver`` (default: the first of ``ok``) if it is in ``ok``, else SolverNotFound."""
    if solver is None and ok:
        return ok[0]
    why = _REFUSED.get(f"{name}:{solver}", f"not available for {capability}")
    if solver not in ok:
        raise SolverNotFound(f"{name} solver {solver!r}: {why}; available: {ok}")
    return solver


def _variants(capability: str) -> list[str]:
    out = []
    for name in available_backends(capability):
        if name == "cvxpy":
            out += [f"cvxpy:{s}" for s in _cvxpy_solvers(capability)]
        elif name == "casadi":
            out += [f"casadi:{p}" for p in _casadi_plugins(capability)]
        else:
            out.append(name)
    return out


def _indexed(i: int, on_failure: str, fn, *args):
    """``fn(*args)``; a SolverError is raised naming the batch index ``i``, or gives
    None with ``on_failure="nan"``."""
    try:
        return fn(*args)
    except SolverNotFound:
        raise
    except SolverError as exc:
        if on_failure == "nan":
            return None
        raise SolverError(f"problems[{i}]: {exc}") from exc


def _fail(backend: str, status) -> SolverError:
    return SolverError(f"{backend}: solver status {str(status)!r} is not optimal")


# --------------------------------------------------------------------------- #
# standard forms for the matrix backends
# --------------------------------------------------------------------------- #


def _qp_form(hull: _Hull, c: np.ndarray) -> _Standard:
    """min ½ tᵀt − cᵀt  s.t.  G t ≤ h."""
    return _Standard(np.eye(hull.k), -c, hull.G, hull.h)


def _lp_form(hull: _Hull) -> _Standard:
    """z = (t, ρ): min −ρ  s.t.  [G 1; 0 −1] z ≤ [h; 0]."""
    k, m = hull.k, hull.h.size
    G = np.zeros((m + 1, k + 1))
    G[:m, :k] = hull.G
    G[:m, k] = 1.0
    G[m, k] = -1.0
    q = np.zeros(k + 1)
    q[k] = -1.0
    return _Standard(np.zeros((k + 1, k + 1)), q, G, np.append(hull.h, 0.0))


def _dense_csc(M: np.ndarray):
    """A small dense matrix as CSC with its nonzeros, built directly (the generic
    conversions cost more than clarabel's solve on kernel-sized problems)."""
    import scipy.sparse as sps

    rows, cols = np.nonzero(M.T)  # column-major order: (column, row) pairs
    indptr = np.searchsorted(rows, np.arange(M.shape[1] + 1))
    return sps.csc_matrix((M.T[rows, cols], cols, indptr), shape=M.shape)


def _clarabel_settings():
    import clarabel

    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = IPM_TOL
    return settings


def _clarabel(s: _Standard, settings=None) -> np.ndarray:
    """Clarabel's native API: P upper triangle and G as CSC, G z + slack = h, slack ≥ 0."""
    import clarabel

    cones = [clarabel.NonnegativeConeT(s.h.size)] if s.h.size else []
    sol = clarabel.DefaultSolver(_dense_csc(np.triu(s.P)), s.q, _dense_csc(s.G), s.h, cones,
                                 settings or _clarabel_settings()).solve()
    if str(sol.status) != "Solved":
        raise _fail("clarabel", sol.status)
    return np.array(sol.x)


def _clarabel_batch(hulls: list[_Hull], cs: list[np.ndarray], index: list[int],
                    on_failure: str) -> list:
    """The QPs one after another, sharing one settings object (clarabel has no
    parallel batch; this only saves the per-problem set-up)."""
    settings = _clarabel_settings()
    return [_indexed(i, on_failure, _clarabel, _qp_form(hull, c), settings)
            for hull, c, i in zip(hulls, cs, index, strict=True)]


def _proxsuite_setup(qp, s: _Standard) -> None:
    """Settings and data of a proxqp dense QP: min ½ zᵀPz + qᵀz, G z ≤ h (no l)."""
    qp.settings.eps_abs = qp.settings.eps_duality_gap_abs = TOL
    qp.settings.eps_rel = qp.settings.eps_duality_gap_rel = 0.0
    qp.settings.check_duality_gap = True  # small residuals alone leave errors ~1e-5
    # the default 1e-4 certifies infeasibility of some feasible QPs
    qp.settings.eps_primal_inf = qp.settings.eps_dual_inf = 1e-12
    # bounded work: kernel QPs converge within ~30 iterations (1000 stress cases: max
    # 27); proxsuite's default 10 000 outer × 1 500 inner let a thin kernel run for
    # minutes before MAX_ITER_REACHED (a SolverError, as now, but at once)
    qp.settings.max_iter = PROXSUITE_MAX_ITER
    qp.settings.verbose = False
    if s.h.size:
        qp.init(s.P, s.q, None, None, s.G, None, s.h)
    else:
        qp.init(s.P, s.q, None, None, None, None, None)


def _proxsuite_result(qp) -> np.ndarray:
    import proxsuite

    status = qp.results.info.status
    if status != proxsuite.proxqp.PROXQP_SOLVED:
        raise _fail("proxsuite", status)
    return np.array(qp.results.x)


def _proxsuite(s: _Standard) -> np.ndarray:
    import proxsuite

    qp = proxsuite.proxqp.dense.QP(s.q.size, 0, s.h.size)
    _proxsuite_setup(qp, s)
    qp.solve()
    return _proxsuite_result(qp)


def _proxsuite_batch(hulls: list[_Hull], cs: list[np.ndarray], index: list[int],
                     on_failure: str) -> list:
    """All QPs in one ``BatchQP`` (each with its own n, n_in), solved in parallel."""
    import proxsuite

    dense = proxsuite.proxqp.dense
    batch = dense.BatchQP(len(hulls))
    for hull, c in zip(hulls, cs):
        _proxsuite_setup(batch.init_qp_in_place(hull.k, 0, hull.h.size), _qp_form(hull, c))
    dense.solve_in_parallel(batch)
    return [_indexed(i, on_failure, _proxsuite_result, batch.get(j))
            for j, i in enumerate(index)]


def _highs(s: _Standard) -> np.ndarray:
    """highspy: columns z free, rows −∞ ≤ G z ≤ h, Hessian P (lower triangle, CSC)."""
    import highspy
    import scipy.sparse as sps

    n, m = s.q.size, s.h.size
    h = silent_highs()
    for option, value in (("primal_feasibility_tolerance", TOL),
                          ("dual_feasibility_tolerance", TOL), ("qp_regularization_value", 0.0)):
        h.setOptionValue(option, value)
    h.addVars(n, np.full(n, -highspy.kHighsInf), np.full(n, highspy.kHighsInf))
    h.changeColsCost(n, np.arange(n, dtype=np.int32), s.q)
    if m:
        G = sps.csr_matrix(s.G)
        h.addRows(m, np.full(m, -highspy.kHighsInf), s.h, G.nnz,
                  G.indptr[:-1].astype(np.int32), G.indices.astype(np.int32), G.data)
    if np.any(s.P):
        P = sps.tril(sps.csc_matrix(s.P), format="csc")
        hess = highspy.HighsHessian()
        hess.dim_ = n
        hess.format_ = highspy.HessianFormat.kTriangular
        hess.start_, hess.index_, hess.value_ = P.indptr, P.indices, P.data
        h.passHessian(hess)
    h.run()
    status = h.getModelStatus()
    if status != highspy.HighsModelStatus.kOptimal:
        raise _fail("highs", h.modelStatusToString(status))
    return np.array(h.getSolution().col_value)


_MATRIX = {"clarabel": _clarabel, "proxsuite": _proxsuite, "highs": _highs}


# --------------------------------------------------------------------------- #
# symbolic models
# --------------------------------------------------------------------------- #


@contextlib.contextmanager
def _c_stdout_to_stderr():
    """stdout (file descriptor 1 and sys.stdout) pointed at stderr: solvers print
    errors whatever their verbosity (OSQP "ERROR in validate_data", SCS "could not determine
    problem status"), which would precede a ``--json`` object on stdout."""
    import os
    import sys

    sys.stdout.flush()
    saved = os.dup(1)
    try:
        os.dup2(2, 1)
        with contextlib.redirect_stdout(sys.stderr):  # solvers printing through Python
            yield
    finally:
        sys.stdout.flush()
        _flush_c_stdio()
        os.dup2(saved, 1)
        os.close(saved)


def _flush_c_stdio() -> None:
    """fflush(NULL): printf's buffer (full buffering off a terminal) is written
    while fd 1 still points at stderr."""
    import ctypes

    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError, TypeError):  # no C library handle (Windows)
        pass


def _cvxpy_solve(problem, solver: str) -> None:
    import cvxpy as cp

    quiet = silent_highs_inside() if solver == "HIGHS" else contextlib.nullcontext()
    try:
        with quiet, _c_stdout_to_stderr():
            problem.solve(solver=solver, **_CVXPY_SOLVERS[solver][1])
    except (cp.error.SolverError, ValueError) as exc:
        # ValueError: CVXPY's HiGHS interface cannot unpack a solution of status UNKNOWN
        raise SolverError(f"cvxpy:{solver}: {exc}") from exc
    if problem.status != cp.OPTIMAL:
        raise _fail(f"cvxpy:{solver}", problem.status)


def _cvxpy_qp(hull: _Hull, c: np.ndarray, solver: str) -> np.ndarray:
    """CVXPY: minimize ½‖t − c‖² subject to G t ≤ h."""
    import cvxpy as cp

    t = cp.Variable(hull.k)
    cons = [hull.G @ t <= hull.h] if hull.h.size else []
    _cvxpy_solve(cp.Problem(cp.Minimize(0.5 * cp.sum_squares(t - c)), cons), solver)
    return np.asarray(t.value)


def _cvxpy_lp(hull: _Hull, solver: str) -> tuple[np.ndarray, float]:
    """CVXPY: maximize ρ subject to G t + ρ ≤ h, ρ ≥ 0."""
    import cvxpy as cp

    t, rho = cp.Variable(hull.k), cp.Variable()
    cons = [hull.G @ t + rho <= hull.h, rho >= 0] if hull.h.size else [rho >= 0]
    _cvxpy_solve(cp.Problem(cp.Maximize(rho), cons), solver)
    return np.asarray(t.value), float(rho.value)


def _casadi_solve(opti, plugin: str):
    """Solve an ``Opti('conic')`` model with ``plugin``; SolverError unless it succeeds.

    Plugins print through CasADi's Python ``sys.stdout`` whatever their options say
    (qpOASES its licence banner on every solve); that is discarded so that stdout
    stays clean for ``--json`` output.
    """
    try:
        with contextlib.redirect_stdout(io.StringIO()), _c_stdout_to_stderr():
            opti.solver(plugin, {"print_time": False, "error_on_fail": False,
                                 **_CASADI_PLUGINS[plugin][1]})
            return opti.solve()
    except RuntimeError as exc:
        raise _fail(f"casadi:{plugin}", opti.stats().get("return_status", exc)) from exc


def _casadi_qp(hull: _Hull, c: np.ndarray, plugin: str) -> np.ndarray:
    """CasADi Opti: minimize ½‖t − c‖² subject to G t ≤ h."""
    import casadi

    opti = casadi.Opti("conic")
    t = opti.variable(hull.k)
    opti.minimize(0.5 * casadi.sumsqr(t - c))
    if hull.h.size:
        opti.subject_to(casadi.mtimes(casadi.DM(hull.G), t) <= hull.h)
    sol = _casadi_solve(opti, plugin)
    return np.atleast_1d(np.asarray(sol.value(t), dtype=float)).ravel()


def _casadi_lp(hull: _Hull, plugin: str) -> tuple[np.ndarray, float]:
    """CasADi Opti: maximize ρ subject to G t + ρ ≤ h, ρ ≥ 0."""
    import casadi

    opti = casadi.Opti("conic")
    t, rho = opti.variable(hull.k), opti.variable()
    opti.minimize(-rho)
    if hull.h.size:
        opti.subject_to(casadi.mtimes(casadi.DM(hull.G), t) + rho <= hull.h)
    opti.subject_to(rho >= 0)
    sol = _casadi_solve(opti, plugin)
    return np.atleast_1d(np.asarray(sol.value(t), dtype=float)).ravel(), float(sol.value(rho))


# --------------------------------------------------------------------------- #
# dispatch: backend name → (hull, c, solver) -> t  /  (hull, solver) -> (t, ρ)
# --------------------------------------------------------------------------- #


def _matrix_qp(name: str):
    return lambda hull, c, solver: _MATRIX[name](_qp_form(hull, c))


def _matrix_lp(name: str):
    def solve(hull: _Hull, solver) -> tuple[np.ndarray, float]:
        z = _MATRIX[name](_lp_form(hull))
        return z[:-1], z[-1]

    return solve


_SOLVE_QP = {
    "clarabel": _matrix_qp("clarabel"),
    "proxsuite": _matrix_qp("proxsuite"),
    "highs": _matrix_qp("highs"),
    "cvxpy": _cvxpy_qp,
    "casadi": _casadi_qp,
}
_SOLVE_LP = {
    "clarabel": _matrix_lp("clarabel"),
    "highs": _matrix_lp("highs"),
    "cvxpy": _cvxpy_lp,
    "casadi": _casadi_lp,
}
_BATCH_QP = {"proxsuite": _proxsuite_batch, "clarabel": _clarabel_batch}
