"""Canonical points of a safe kernel, exact, with ``kernel_point`` certificates.

* ``"project"``: the unique point of Ψ closest to a target (default: the mean of X),
  argmin ‖x − m‖² over Ψ. A backend (:mod:`rescon.models.kernel_models`) solves the QP
  in floats; its active facets then fix the exact answer: x = m − Eᵀν − A_Sᵀμ with
  E x = f (aff Ψ) and A_S x = b_S, solved in rationals and accepted only if μ ≥ 0 and
  x ∈ Ψ exactly (KKT). If the guess fails, active sets are enumerated exactly.
  The answer is therefore the same for every backend.
* ``"chebyshev"``: the centre of the largest ball in Ψ within aff Ψ (LP, floats: Clarabel
  for "auto", HiGHS where it fails; a full-dimensional Ψ too thin for its unit frame in
  its principal frame), moved exactly onto aff Ψ and certified inside.
* ``"vertex-mean"``: the exact mean of Ψ's vertices.
"""

from __future__ import annotations

import itertools
import math
import operator
from fractions import Fraction
from typing import TYPE_CHECKING, Any

import numpy as np

from .._validate import check_point
from ..errors import EmptyKernel, InputError, SolverError
from .exact import exact_sum, fraction_str, solve_exact

if TYPE_CHECKING:
    from .kernel import SafeKernel

__all__ = ["METHODS", "check_choice", "kernel_point_of", "point_certificate"]

METHODS = ("project", "chebyshev", "vertex-mean")
MAX_ACTIVE_SETS = 200_000

Vec = tuple[Fraction, ...]


def _dot(a, x) -> Fraction:
    return sum((ai * xi for ai, xi in zip(a, x, strict=True)), Fraction(0))


#: the safe_kernel fields a "kernel" proof of a kernel point carries
KERNEL_PROOF_KEYS = ("dim", "vertices", "equalities", "facets", "adjacency")


def point_certificate(K: SafeKernel, x: Vec) -> dict[str, Any]:
    """A ``kernel_point`` certificate: for a full-dimensional kernel in d = 2–4 the
    kernel itself ("kernel" proof: the checker verifies Ψ = P by the vertex adjacency
    and the normal fan, then x ∈ P), else the checker's own enumeration of the
    hyperplanes through data points ("halfspaces"; in d ≥ 5 the adjacency check of
    the kernel's often non-simple vertices is beyond the checker's limits sooner)."""
    d = K.points.shape[1]
    proof: dict[str, Any] = {"method": "halfspaces"}
    if K.dim == d and d in (2, 3, 4):
        kc = K.certificate
        proof = {"method": "kernel", **{k: kc[k] for k in KERNEL_PROOF_KEYS}}
    return {"rescon_certificate": 1, "kind": "kernel_point", "points": K.points.tolist(),
            "F": K.F, "x": [fraction_str(v) for v in x], "proof": proof}


def check_choice(method: str, backend: str) -> None:
    """InputError for an unknown method, SolverNotFound / InputError for a backend the
    method cannot use (``"auto"``; ``"exact"`` for "project" and "vertex-mean"; else a
    name of :func:`~rescon.models.qp_backends`, of :func:`~rescon.models.lp_backends`
    for "chebyshev") — decided before any data is looked at: a kernel of one point,
    or an empty one, calls no solver."""
    if method not in METHODS:
        raise InputError(f"method must be one of {', '.join(METHODS)}; got {method!r}")
    if backend == "auto" or (backend == "exact" and method != "chebyshev"):
        return
    if backend == "exact":
        raise InputError("backend='exact' is for method='project' (exact KKT); the "
                         "Chebyshev centre is an LP: 'auto' or a name of lp_backends()")
    from ..models.kernel_models import check_backend

    check_backend(backend, "LP" if method == "chebyshev" else "QP")


def kernel_point_of(K: SafeKernel, *, method: str, backend: str, target: Any
                    ) -> tuple[np.ndarray, dict[str, Any]]:
    x = exact_point(K, method=method, backend=backend, target=target)
    return np.array([float(v) for v in x]), point_certificate(K, x)


def exact_point(K: SafeKernel, *, method: str, backend: str = "auto", target: Any = None
                ) -> Vec:
    """The exact point :func:`kernel_point_of` returns rounded, without its certificate
    (the engine reads only the point: building a d = 2–4 kernel's certificate took a
    fifth of each exactly computed kernel point of a run)."""
    check_choice(method, backend)
    if K.is_empty:
        raise EmptyKernel(f"the safe kernel is empty (n = {len(K.points)}, "
                          f"F = {K.F}): no point to return; see the kernel's certificate")
    if method == "vertex-mean":
        if target is not None:
            raise InputError("target is only used by method='project'")
        return _vertex_mean(K)
    if method == "project":
        return _project(K, _target(K, target), backend)
    if target is not None:
        raise InputError("target is only used by method='project'")
    return _chebyshev(K, backend)


def _vertex_mean(K: SafeKernel) -> Vec:
    V = K.exact_vertices
    return tuple(exact_sum(col) / len(V) for col in zip(*V, strict=True))


def _target(K: SafeKernel, target: Any) -> Vec:
    d = K.points.shape[1]
    if target is None:
        n = len(K.points)
        cols = zip(*K.points.tolist(), strict=True)
        return tuple(sum(map(Fraction, col), Fraction(0)) / n for col in cols)
    return tuple(Fraction(float(v)) for v in check_point(target, d, "target"))


#: up to this many vertices, "auto" guides a projection in dimension ≤ 2 geometrically
GEOMETRIC_GUIDE_VERTICES = 64
#: facets within this fraction of the kernel's size from a guide count as near it
#: (at most MAX_NEAR of them; their subsets are tried first)
NEAR_SLACK = 1e-6
MAX_NEAR = 10


#: the float guides see the target at most 2^FAR_TARGET kernel sizes away (squared
#: distances stay finite)
FAR_TARGET = 400
#: a QP backend's guide sees the target at most 2^QP_REACH kernel sizes away: the
#: solvers lose a unit polytope beside a target ≳ 2^24 away (1e20 in one value of X
#: moves the mean 2^66 kernel sizes away), while the direction fixes the active set
QP_REACH = 12


def _frame(K: SafeKernel, m: np.ndarray | None = None) -> tuple[np.ndarray, int]:
    """o, e: the mean of Ψ's float vertices and an exponent with 2^e about Ψ's extent
    (or 2^-FAR_TARGET times the distance to the target m, if larger). The float guides
    work in y = (x − o) / 2^e (:func:`_to_frame`), where Ψ has unit size whatever its
    magnitude (HiGHS reads |b| ≥ 1e20 as infinite; absolute tolerances swamp a
    kernel at 1e-300; nothing overflows near the largest floats) — and, 2^e a power
    of two, on the same numbers for X and 2^j X. The mean and the extent are taken of
    the vertices times 2^−s (s: the exponent of their largest |coordinate|), so
    neither underflows: of a kernel a few subnormals wide both were 0 (V40: the
    Chebyshev LP then saw it 2^-1074 wide, and its centre was refused)."""
    V = K.vertices
    top = float(np.abs(V).max())
    s = math.frexp(top)[1] if 0 < top < math.inf else 0
    Vs = np.ldexp(V, -s)
    os = (Vs / len(Vs)).sum(axis=0)
    o = np.ldexp(os, s)
    ext = float(np.abs(Vs / 4 - os / 4).max())
    e = math.frexp(ext)[1] + 2 + s if ext > 0 else None
    if m is not None:
        far = math.ldexp(float(np.abs(m / 4 - o / 4).max()), -FAR_TARGET)
        if far > 0:
            e = max(e, math.frexp(far)[1] + 2) if e is not None else math.frexp(far)[1] + 2
    return o, (e if e is not None else 0)


def _to_frame(x: np.ndarray, c: np.ndarray, e: int) -> np.ndarray:
    """(x − c) / 2^e for a point x, each entry rounded once from its exact value
    (no overflow in between, no bits lost to subnormal differences)."""
    return np.array([_float((Fraction(float(a)) - Fraction(float(b))) / Fraction(2) ** e)
                     for a, b in zip(x, c, strict=True)])


def _from_frame(y: np.ndarray, o: np.ndarray, e: int) -> Vec:
    """o + 2^e y, exactly: rounded to floats, the centre of a kernel a few subnormals
    wide fell on the subnormal grid, outside it (V40). A non-finite y is a
    SolverError."""
    if not np.isfinite(y).all():
        raise SolverError("the backend returned a non-finite Chebyshev centre")
    scale = Fraction(2) ** e
    return tuple(Fraction(float(a)) + Fraction(float(b)) * scale
                 for a, b in zip(o, y, strict=True))


def _framed(K: SafeKernel, o: np.ndarray, e: int):
    """A, b, origin, basis and vertices of Ψ in the frame y = (x − o) / 2^e: the rows
    A y ≤ (b − A o) / 2^e, from :func:`_offsets` (the origin is the first vertex)."""
    D, c, t = _offsets(K, o)
    V = np.ldexp(D, -t - e)
    return K.A, np.ldexp(c, -t - e), V[0], K.affine_basis, V


def _offsets(K: SafeKernel, o: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """(v − o)·2^t for the exact vertices v and (b − A o)·2^t for the rows, each
    rounded once from its exact value, with max |v − o|·2^t ∈ [1/2, 2) (no overflow,
    no subnormal); kept in K's cache (o is K's vertex mean). From the floats of v and
    b, a kernel 1 wide at 1e15 was off by ~ulp(1e15) = 1/8, one of subnormal states
    by its own size, and the guides ranked the wrong active sets (the exact search
    then exceeded MAX_ACTIVE_SETS). A facet of a full-dimensional Ψ is a·x ≤ β with
    A's row a / ‖a‖, so its offset is (β − a·o) / ‖a‖; a facet relative to a flat Ψ
    is tight at a vertex, so its offset is the largest A·(v − o)."""
    key = ("frame", o.tobytes())
    if key not in K._cache:
        ex = K._exact
        of = [Fraction(float(v)) for v in o]
        diffs = [[v - w for v, w in zip(x, of, strict=True)] for x in ex.vertices]
        top = max((abs(q) for row in diffs for q in row), default=Fraction(0))
        t = top.denominator.bit_length() - top.numerator.bit_length() if top else 0
        unit = Fraction(2) ** t
        D = np.array([[float(q * unit) for q in row] for row in diffs]).reshape(
            len(diffs), len(of))
        if ex.kernel_eqs or not len(K.A):
            c = (K.A @ D.T).max(axis=1) if len(K.A) else np.zeros(0)
        else:
            c = np.array([_float((beta - sum(map(operator.mul, a, of))) * unit / m)
                          / math.hypot(*(float(v / m) for v in a))
                          for a, beta in ex.facets for m in [max(map(abs, a))]])
        K._cache[key] = (D, c, t)
    return K._cache[key]


def _float(q: Fraction) -> float:
    """q rounded to a float, ±inf beyond the float range (a guide's offset)."""
    try:
        return float(q)
    except OverflowError:
        return math.inf if q > 0 else -math.inf


def _geometric_guide(A, b, origin, B, V, dim: int, m: np.ndarray) -> np.ndarray:
    """Nearest point of conv(V) to m for a kernel of dimension 1 or 2 (unit frame,
    :func:`_frame`), in floats: m itself (moved onto aff Ψ) if inside, else the
    nearest point of the segments between vertices (every edge is one of them)."""
    y = origin + B.T @ (B @ (m - origin))
    if dim == 2 and np.all(A @ y - b <= 1e-12):
        return y
    i, j = np.triu_indices(len(V), 1)
    P, Q = V[i], V[j]
    D = Q - P
    dd = np.einsum("ij,ij->i", D, D)
    t = np.clip(np.einsum("ij,ij->i", m - P, D) / np.where(dd > 0, dd, 1.0), 0.0, 1.0)
    C = P + t[:, None] * D
    return C[np.argmin(np.linalg.norm(C - m, axis=1))]


def _vertex_guide(V: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Nearest point of conv(V) to m in floats (unit frame, :func:`_frame`), as
    min ‖Vᵀλ − m‖ over λ ≥ 0 with Σλ = 1 weighted in (Lawson–Hanson NNLS, scipy): a
    kernel 1e-7 wide a million sizes away from m, where the QP solvers stop short of
    optimal, still gives the face it lands on."""
    from scipy.optimize import nnls

    w = max(1.0, float(np.abs(m).max()))
    lam, _ = nnls(np.vstack([V.T, np.full(len(V), w)]), np.r_[m, w])
    total = lam.sum()
    return (V.T @ lam) / total if total > 0 else V.mean(axis=0)


def _guides(dim: int, framed, m: np.ndarray, backend: str):
    """Float points near the projection of m, best first, all in the unit frame
    (:func:`_frame`; ``framed``: Ψ there, :func:`_framed`). An explicit backend guides
    first (its failure is the user's answer); "auto" tries the geometric guide (dim ≤ 2)
    or Clarabel. The vertex guide follows either way, so a backend's inaccurate answer
    (thin kernels, far targets) never leaves the exact search to enumerate every
    active set (4–6 s for a thin 3-D kernel where "auto" took 0.06 s)."""
    from ..models.kernel_models import project

    A, b, origin, B, V = framed
    if backend not in ("auto", "exact"):
        yield project(A, b, origin, B, _within_reach(m, V), backend=backend)
    elif backend == "auto" and dim <= 2 and len(V) <= GEOMETRIC_GUIDE_VERTICES:
        yield _geometric_guide(A, b, origin, B, V, dim, m)
    else:
        try:
            guess = project(A, b, origin, B, _within_reach(m, V), backend="clarabel")
        except SolverError:  # a hint only: the next guide and the exact search decide
            pass
        else:
            yield guess
    try:
        guess = _vertex_guide(V, m)
    except (RuntimeError, ValueError):  # scipy's NNLS at its iteration limit: no hint
        return
    yield guess


def _within_reach(m: np.ndarray, V: np.ndarray) -> np.ndarray:
    """The target m seen from the frame's centre (0, the vertex mean) at most
    2^QP_REACH · max|V| away, on the same ray: m · min(1, 2^QP_REACH max|V| / max|m|).
    A guide only ranks active sets; the exact KKT test decides."""
    reach = math.ldexp(float(np.abs(V).max()), QP_REACH)
    far = float(np.abs(m).max())
    return m * (reach / far) if far > reach > 0 else m


def _near_active_sets(A: np.ndarray, b: np.ndarray, V: np.ndarray, dim: int,
                      guess: np.ndarray) -> list[tuple[int, ...]]:
    """Subsets of ≤ dim facets near the guide, most plausible first: the dim + 1 nearest
    and every facet about as near (at a degenerate vertex more than dim are tight up
    to rounding, in any order). Unit frame (:func:`_frame`): A, b the facet rows, V
    the vertices."""
    slack = b - A @ guess  # unit rows: distances
    reach = NEAR_SLACK * float(np.ptp(V, axis=0).max())
    order = np.argsort(slack, kind="stable")
    ranked = slack[order]
    close = int(np.searchsorted(ranked, ranked[min(dim, len(ranked) - 1)] + reach,
                                side="right"))
    near = sorted(order[: min(max(dim + 1, close), MAX_NEAR)].tolist())
    tight = slack <= reach  # a hint only: the KKT check decides

    def plausibility(S: tuple[int, ...]) -> tuple[int, int]:
        return (sum(not tight[i] for i in S) + sum(tight[i] for i in near if i not in S),
                len(S))

    sets = [S for size in range(dim + 1) for S in itertools.combinations(near, size)]
    return sorted(sets, key=plausibility)


def _project(K: SafeKernel, m: Vec, backend: str) -> Vec:
    """Exact projection: the target if it lies in Ψ ("auto", "exact"), then active sets
    near each float guide, then all of them."""
    ex = K._exact
    if K.dim == 0:
        return ex.vertices[0]
    facets = list(ex.facets)
    mf = np.array([float(v) for v in m])
    o, e = _frame(K, mf)
    framed = _framed(K, o, e)

    def near_sets():
        for guess in _guides(K.dim, framed, _to_frame(mf, o, e), backend):
            if len(facets) and np.isfinite(guess).all():
                yield from _near_active_sets(framed[0], framed[1], framed[4], K.dim, guess)

    tried = set()
    # S = (): the target itself when it lies in Ψ (always for F = 0: the mean is in
    # conv X), before any float guide — unless an explicit backend is to guide
    first = [()] if backend in ("auto", "exact") else []
    for S in itertools.chain(first, near_sets(), _active_sets(len(facets), K.dim)):
        if S in tried or len(S) > K.dim:
            continue
        tried.add(S)
        x = _kkt(ex.kernel_eqs, facets, S, m)
        if x is not None:
            return x
    raise SolverError("no exact KKT point found for the projection (internal error)")


def _active_sets(m: int, dim: int):
    count = 0
    for size in range(dim + 1):
        for S in itertools.combinations(range(m), size):
            count += 1
            if count > MAX_ACTIVE_SETS:
                raise SolverError(f"the exact projection needs more than {MAX_ACTIVE_SETS} "
                                  f"active sets ({m} facets, dim {dim})")
            yield S


def _kkt(eqs, facets, S, m: Vec) -> Vec | None:
    """The KKT point for active set S, if it is optimal: x = m − Σ_rows c_r g_r with
    g_r the equality rows and the facet normals in S, G x = h; μ ≥ 0 on S, x ∈ Ψ."""
    rows = [a for a, _ in eqs] + [facets[i][0] for i in S]
    rhs = [b for _, b in eqs] + [facets[i][1] for i in S]
    if rows:
        gram = [[_dot(g, h) for h in rows] for g in rows]
        c = solve_exact(gram, [_dot(g, m) - r for g, r in zip(rows, rhs, strict=True)])
        if c is None:
            return None
        x = tuple(mi - sum(cr * g[j] for cr, g in zip(c, rows, strict=True))
                  for j, mi in enumerate(m))
        if any(cr < 0 for cr in c[len(eqs):]):
            return None
    else:
        x = m
    if all(_dot(a, x) <= b for a, b in facets):
        return x
    return None


#: the LP backends of method "chebyshev" with backend "auto", the second where the first
#: fails: Clarabel's interior point (relative gap 1e-13) keeps kernels down to ~1e-13 of
#: their extent thick, where HiGHS' absolute tolerances (1e-9 in the unit frame)
#: returned a vertex of a hexagon 2 long and 2^-30 thick (radius 0 instead of 2^-31;
#: V29); Clarabel in turn ends "AlmostSolved" on some thin kernels (6e-10 of their
#: extent, V30) where HiGHS finds a point
CHEBYSHEV_AUTO = ("clarabel", "highs")


#: a unit-frame ball this small (the frame's unit is about Ψ's extent) is near the
#: solvers' tolerances: "auto" then also asks the principal frame
THIN = 2.0**-20


def _chebyshev(K: SafeKernel, backend: str) -> Vec:
    """The Chebyshev centre from a backend's LP in Ψ's unit frame (:func:`_frame`),
    moved onto aff Ψ and certified inside (pulled towards the vertex mean if rounding
    left it on the boundary).  With ``backend="auto"``, a full-dimensional Ψ the unit
    frame may not resolve — its LP failed, its centre needed the pull, or its ball is
    under THIN of the frame (thinner there than the solvers' tolerances, or narrower
    than the float range allows beside its extent) — is solved again in its principal
    frame (:func:`_principal_chebyshev`), and the point with the larger inscribed ball
    (:func:`_inscribed`) is kept."""
    from ..models.kernel_models import chebyshev

    ex = K._exact
    if K.dim == 0:
        return ex.vertices[0]
    o, e = _frame(K)
    framed = _framed(K, o, e)[:4]
    x, unsure = None, True
    try:
        if backend == "auto":  # Clarabel, else HiGHS (its point is certified below either way)
            try:
                centre, radius = chebyshev(*framed, backend=CHEBYSHEV_AUTO[0])
            except SolverError:
                centre, radius = chebyshev(*framed, backend=CHEBYSHEV_AUTO[1])
        else:
            centre, radius = chebyshev(*framed, backend=backend)
        c0 = _onto_hull(ex.kernel_eqs, _from_frame(centre, o, e))
        x = _inside(K, c0)
        unsure = x is not c0 or not radius >= THIN
    except SolverError:
        if backend != "auto" or K.dim < len(o):
            raise
    if unsure and backend == "auto" and K.dim == len(o):
        y = _principal_chebyshev(K, o)
        if y is not None and (x is None or _inscribed(K, y) > _inscribed(K, x)):
            x = y
    if x is None:
        raise SolverError("the Chebyshev centre returned by the backend is not in the kernel")
    return x


def _inscribed(K: SafeKernel, x: Vec) -> float:
    """The radius of the largest ball around x in a full-dimensional Ψ: the smallest
    (β − a·x)/‖a‖ over its facets (exact slacks, rounded; the norms in floats)."""
    out = math.inf
    for a, beta in K._exact.facets:
        top = max(map(abs, a))
        slack = _float((beta - _dot(a, x)) / top)
        out = min(out, slack / math.hypot(*(float(t / top) for t in a)))
    return out


def _inside(K: SafeKernel, x: Vec) -> Vec | None:
    """x if it is in Ψ, else the first point of Ψ on the way from x to the vertex mean
    (a centre on the boundary up to rounding), else None."""
    if K._exact.contains(x):
        return x
    vm = _vertex_mean(K)
    for t in (Fraction(1, 10**12), Fraction(1, 10**6), Fraction(1, 1000), Fraction(1, 2)):
        y = tuple((1 - t) * a + t * b for a, b in zip(x, vm, strict=True))
        if K._exact.contains(y):
            return y
    return None


def _principal_chebyshev(K: SafeKernel, o: np.ndarray) -> Vec | None:
    """A Chebyshev centre of a full-dimensional Ψ from the margin LP (HiGHS) in its
    principal frame x = o + Σ_j z_j s_j u_j: u_j the principal axes of Ψ's float vertices
    (exact as floats, orthonormal up to rounding), s_j Ψ's exact extent max |u_j·(v − o)|
    along u_j, so Ψ fills about [−1, 1]^d in z however thin or anisotropic it is in x.
    A facet a·x ≤ β and a ball of radius r = s ρ (s = min s_j) in x read

        Σ_j (s_j a·u_j) z_j + s‖a‖ ρ ≤ β − a·o,

    each row computed exactly from the exact facet and divided by its largest entry
    λ = max_j |s_j a·u_j| before rounding (s‖a‖/λ ≤ √d·(1 + rounding): some |a·u_j| ≥
    ‖a‖/√d).  The point o + Σ z_j s_j u_j is formed exactly and certified as in
    :func:`_chebyshev`; None if the LP has no optimum or no point is certified."""
    from ._lp import max_margin

    ex = K._exact
    D, _, _ = _offsets(K, o)
    axes = np.linalg.svd(D, full_matrices=False)[2]
    of = [Fraction(float(v)) for v in o]
    U = [[Fraction(float(t)) for t in u] for u in axes]
    diffs = [[v - w for v, w in zip(x, of, strict=True)] for x in ex.vertices]
    ext = [max(abs(_dot(u, df)) for df in diffs) for u in U]
    if not all(ext):
        return None
    s = min(ext)
    rows, rhs, w = [], [], []
    for a, beta in ex.facets:
        g = [sj * _dot(a, u) for sj, u in zip(ext, U, strict=True)]
        lam = max(map(abs, g))
        top = max(map(abs, a))
        if not lam:
            return None
        rows.append([float(t / lam) for t in g])
        rhs.append(_float((beta - _dot(a, of)) / lam))
        w.append(float(s * top / lam) * math.hypot(*(float(t / top) for t in a)))
    d = len(of)
    with np.errstate(divide="ignore"):  # w = 0 (a ball negligible beside λ): slack / 0 = ±inf
        found = max_margin(np.array(rows), np.array(rhs), np.array(w), np.full(d, -2.0),
                           np.full(d, 2.0))
    if found is None or not found.t > 0:
        return None
    z = [Fraction(float(t)) for t in found.x]
    x = tuple(oi + sum(zj * sj * u[i] for zj, sj, u in zip(z, ext, U, strict=True))
              for i, oi in enumerate(of))
    return _inside(K, x)


def _onto_hull(eqs, x: Vec) -> Vec:
    """Orthogonal projection of x onto {y : a·y = b for (a, b) in eqs}, exactly."""
    if not eqs:
        return x
    rows = [a for a, _ in eqs]
    gram = [[_dot(g, h) for h in rows] for g in rows]
    c = solve_exact(gram, [_dot(a, x) - b for a, b in eqs])
    assert c is not None
    return tuple(xi - sum(cr * g[j] for cr, g in zip(c, rows, strict=True))
                 for j, xi in enumerate(x))
