"""Kernel points for many small point sets in R³: exact halfspaces, a float QP, a
certificate relative to the answer.

For each set Y (m points in R³) and F, the valid halfspaces of Ψ(Y, F) — planes through
three points with at most F points strictly outside — are enumerated in numba, every
side taken from a float orientation only when its rounding-error bound decides it
(the filter of :mod:`._candidates`); a set where an undecided side or a possibly
degenerate triple could change the list is declined, and so is a set not surely
affinely full-dimensional (its kernel needs in-flat constraints); the caller computes
those exactly (:mod:`.kernel`). Copies of a point are merged (they lie on every plane
through it). The set is first scaled by a power of two (exact) so that its largest
|coordinate| lies in [1/2, 1): no product below overflows, and a set with a nonzero
|coordinate| below TINY after scaling (products could underflow) is declined.

The point of Ψ nearest mean(Y) is then found in floats — a hint: a dual active-set
method in numba (Goldfarb–Idnani), and for the sets where it stalls or its hint fails
the certificate, the QP solver (clarabel, one batch call). The hint only proposes the
active set S (halfspaces tight at it, at most three independent ones; if that fails,
every S of at most three among the NEAR_CANDIDATES halfspaces nearest it); the answer
is certified by :func:`_certify`, with rigorous rounding bounds throughout:

* x* is the exact solution of the 3 × 3 system M* x = r*: the planes of S,
  n_s · (x − p_s) = 0, anchored at a data point p_s of each, and, for |S| < 3, the
  conditions t · (x − m) = 0 for t spanning S's orthogonal complement (x* − m ∈
  span N_S); the float x is refined in anchored coordinates, δ = fl(M⁻¹ ρ) from its
  residuals ρ, and ‖x − x*‖₂ ≤ ‖δ‖₂ + ‖M*⁻¹‖₂ ‖ρ* − M* δ‖₂, with ‖M*⁻¹‖₂ bounded from
  a float inverse X by ‖X‖_F / (1 − ‖I − X M*‖_F). Every residual is anchored at a data point of its
  plane (or at the exactly summed mean), so the bound scales with the distances near
  the answer and the answer's own magnitude, not with the set's spread: a far point
  cannot loosen it;
* the multipliers (m* − x* = N*_Sᵀ λ) are certified positive on inequality
  halfspaces (free on planes valid on both sides), every other halfspace strictly
  satisfied at x* (signs decided with the bound above, or exactly when x* is a data
  point); three independent two-sided planes with m ≥ 4F + 1 pin Ψ = {x*} (Ψ is
  nonempty), so no other check is needed;
* the point is accepted if its bound is at most ACCEPT_REL of its magnitude; anything
  undecided, singular or non-finite is declined (the exact path computes it).

Before all this, a converged cluster — m − F points in a box a few ulps wide — is
answered by one of its points (:func:`._small2d.cluster_box`: Ψ lies in that box), and
five points with F = 1 by their Radon point from exactly rounded determinants
(:func:`_radon5`), however flat they are.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._rounding import MIN_NORMAL, MIN_SUBNORMAL
from .._rounding import UNIT_ROUNDOFF as EPS
from ._expansions import TINY, det3, mean_two, normal3, orient3
from ._small2d import ACCEPT_REL, cluster_box

#: rounding-error factor of the 3 × 3 orientation (as in _candidates for k = 3)
C_ERR = 4.0 * (3 * 3 + math.factorial(3) + 4) * EPS
#: a halfspace is proposed as active when its slack at the float hint is below this
#: (in units of the set's spread; the hint is solved to GI_TOL); a hint only
ACTIVE_TOL = 1e-7
#: a proposed normal joins S if its component off the span of those already in S is
#: at least this (unit normals); a hint only — the determinant bound decides
INDEPENDENT_TOL = 1e-12
OK, DECLINED = 0, 1
#: at a degenerate answer, at most this many other choices of S are tried
MAX_CHOICES = 500
#: when the hint's proposal fails, every S of at most three among this many
#: halfspaces nearest the hint is tried
NEAR_CANDIDATES = 8
#: the dual active-set method: its step limit and its feasibility tolerance (local units)
GI_MAX_STEPS = 200
GI_TOL = 1e-13
#: the QP backend of the fallback (a core dependency; an interior-point method)
BACKEND = "clarabel"


def _planes(B, H):
    """Per set and halfspace: the signed float cross product c (B, H, 3), the bound on
    |c − c_exact| per component, the three point indices, whether both sides of the
    plane are valid, and the sign (c = sign·(p_j − p_i) × (p_k − p_i))."""
    return (np.empty((B, H, 3)), np.empty((B, H, 3)), np.empty((B, H, 3), dtype=np.int64),
            np.zeros((B, H), dtype=np.bool_), np.zeros((B, H), dtype=np.int64))


@njit(cache=True, nogil=True)
def _store(planes, b, h, sign, c, i, j, k, both):
    """Halfspace h of set b into ``planes``: sign·c, c the cross product of
    (p_j − p_i, p_k − p_i) with each component its exact value rounded (normal3:
    within 3u of it, plus the smallest normal against underflow)."""
    cn, cne, tri, eq, sgn = planes
    sgn[b, h] = 1 if sign > 0 else -1
    for t in range(3):
        cn[b, h, t] = sign * c[t]
        cne[b, h, t] = 3.0 * EPS * abs(c[t]) + MIN_NORMAL
    tri[b, h, 0], tri[b, h, 1], tri[b, h, 2] = i, j, k
    eq[b, h] = both


@njit(cache=True, nogil=True)
def _in_scaled_range(Y):
    """Every coordinate finite, |·| < 1 and every nonzero one ≥ TINY (the set scaled by
    a power of two): then no product of up to four differences over- or underflows."""
    for v in Y.ravel():
        a = abs(v)
        if not a < 1.0 or (a != 0.0 and a < TINY):
            return False
    return True


@njit(cache=True, nogil=True)
def halfspaces_3d(Ys, F, normals, offsets, count, status, origin, scale, planes):
    """For each set b: its valid halfspaces n·(x − o) ≤ c, in coordinates centred at
    o = mean(Ys[b]) and scaled by s = max |Ys[b] − o| (so c is in units of s; n unit),
    into normals[b, :count[b]], offsets[b, :count[b]]; o and s into origin[b],
    scale[b]; status OK or DECLINED. For the certificate, ``planes`` (see _planes)
    receives each halfspace as the float cross product c of its three points (signed
    so that c · (x − p_i) ≤ 0 is the halfspace) with a bound on |c − c_exact| per
    component, the three point indices, and whether the plane is valid on both sides."""
    B, m, _ = Ys.shape
    rep = np.empty(m, dtype=np.int64)
    for b in range(B):
        Y = Ys[b]
        status[b] = DECLINED
        count[b] = 0
        if not _in_scaled_range(Y):
            continue
        o0, o1, o2 = Y[:, 0].mean(), Y[:, 1].mean(), Y[:, 2].mean()
        s = 0.0
        for q in range(m):
            s = max(s, abs(Y[q, 0] - o0), abs(Y[q, 1] - o1), abs(Y[q, 2] - o2))
        origin[b, 0], origin[b, 1], origin[b, 2] = o0, o1, o2
        scale[b] = s
        if s == 0.0:
            continue  # one point: the exact path
        for q in range(m):
            rep[q] = q
            for r in range(q):
                if Y[r, 0] == Y[q, 0] and Y[r, 1] == Y[q, 1] and Y[r, 2] == Y[q, 2]:
                    rep[q] = r
                    break
        full = False  # some point off some plane: affinely full-dimensional
        nh = 0
        c = np.empty(3)
        for i in range(m):
            if rep[i] != i:
                continue
            for j in range(i + 1, m):
                if rep[j] != j:
                    continue
                for k in range(j + 1, m):
                    if rep[k] != k:
                        continue
                    a0 = Y[j, 0] - Y[i, 0]
                    a1 = Y[j, 1] - Y[i, 1]
                    a2 = Y[j, 2] - Y[i, 2]
                    b0 = Y[k, 0] - Y[i, 0]
                    b1 = Y[k, 1] - Y[i, 1]
                    b2 = Y[k, 2] - Y[i, 2]
                    c0 = a1 * b2 - a2 * b1
                    c1 = a2 * b0 - a0 * b2
                    c2 = a0 * b1 - a1 * b0
                    e0 = abs(a1 * b2) + abs(a2 * b1)
                    e1 = abs(a2 * b0) + abs(a0 * b2)
                    e2 = abs(a0 * b1) + abs(a1 * b0)
                    sure = max(abs(c0) - 8.0 * EPS * e0, abs(c1) - 8.0 * EPS * e1,
                               abs(c2) - 8.0 * EPS * e2) > 0.0
                    if not sure:  # (the exact normal: zero for a collinear triple,
                        normal3(Y, i, j, k, c)  # which bounds no facet)
                        if c[0] == 0.0 and c[1] == 0.0 and c[2] == 0.0:
                            continue
                    plus = 0
                    minus = 0
                    for q in range(m):
                        r = rep[q]
                        if r == i or r == j or r == k:
                            continue
                        d0 = Y[q, 0] - Y[i, 0]
                        d1 = Y[q, 1] - Y[i, 1]
                        d2 = Y[q, 2] - Y[i, 2]
                        v = d0 * c0 + d1 * c1 + d2 * c2
                        bound = C_ERR * (abs(d0) * e0 + abs(d1) * e1 + abs(d2) * e2)
                        side = 1 if v > bound else (-1 if v < -bound else
                                                    orient3(Y, i, j, k, q))
                        if side > 0:
                            plus += 1
                        elif side < 0:
                            minus += 1
                        if plus > F and minus > F:
                            break
                    full = full or plus + minus > 0
                    if plus > F and minus > F:
                        continue
                    normal3(Y, i, j, k, c)  # each component rounded from its exact value
                    norm = math.sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2])
                    n0, n1, n2 = c[0] / norm, c[1] / norm, c[2] / norm
                    off = (n0 * (Y[i, 0] - o0) + n1 * (Y[i, 1] - o1) + n2 * (Y[i, 2] - o2)) / s
                    both = plus <= F and minus <= F
                    for sign, outside in ((1.0, plus), (-1.0, minus)):
                        if outside <= F:
                            normals[b, nh, 0] = sign * n0
                            normals[b, nh, 1] = sign * n1
                            normals[b, nh, 2] = sign * n2
                            offsets[b, nh] = sign * off
                            _store(planes, b, nh, sign, c, i, j, k, both)
                            nh += 1
        if full:  # (flat sets need in-plane constraints: the exact path)
            count[b] = nh
            status[b] = OK


@njit(cache=True, nogil=True)
def _nearest_to_origin(N, c, h, y):
    """Goldfarb–Idnani dual active-set method for min ½‖y‖² s.t. N[:h] y ≤ c[:h]
    (y ∈ R³; 1983, with the Hessian the identity): start at the unconstrained minimum
    0, add the most violated constraint, step along its normal projected onto the null
    space of the active ones, and drop an active constraint whose multiplier would turn
    negative. Writes y; returns False if it has not converged in GI_MAX_STEPS (the
    caller then uses the QP solver). Its answer is checked by _polish either way."""
    act = np.empty(3, dtype=np.int64)
    lam = np.empty(3)
    r = np.empty(3)
    z = np.empty(3)
    na = 0
    y[:] = 0.0
    steps = 0
    while steps < GI_MAX_STEPS:
        steps += 1
        p = -1
        worst = -GI_TOL
        for i in range(h):
            sl = c[i] - (N[i, 0] * y[0] + N[i, 1] * y[1] + N[i, 2] * y[2])
            if sl < worst:
                worst = sl
                p = i
        if p < 0:
            return True
        lam_p = 0.0
        while steps < GI_MAX_STEPS:
            steps += 1
            # n⁺ = −N[p] (constraints as −N y ≥ −c); r: n⁺ = Σ_A (−N[a]) r_a + z
            G = np.empty((na, na))
            rhs = np.empty(na)
            for u in range(na):
                rhs[u] = N[act[u]] @ N[p]
                for v in range(na):
                    G[u, v] = N[act[u]] @ N[act[v]]
            rr = rhs.copy()
            if na and not _solve(G, rr):
                return False  # dependent active normals: the QP solver proposes
            for k in range(3):
                z[k] = -N[p, k]
                for u in range(na):
                    z[k] += N[act[u], k] * rr[u]
            for u in range(na):
                r[u] = rr[u]
            t1 = np.inf
            drop = -1
            for u in range(na):
                if r[u] > 0.0 and lam[u] / r[u] < t1:
                    t1 = lam[u] / r[u]
                    drop = u
            zz = z @ z
            t2 = np.inf
            if zz > GI_TOL * GI_TOL:
                sl = c[p] - N[p] @ y
                t2 = -sl / zz
            t = min(t1, t2)
            if t == np.inf:
                return False  # infeasible (or degenerate): the QP solver decides
            if t2 < np.inf:
                for k in range(3):
                    y[k] += t * z[k]
            for u in range(na):
                lam[u] -= t * r[u]
            lam_p += t
            if t == t2:
                act[na] = p
                lam[na] = lam_p
                na += 1
                break
            for u in range(drop, na - 1):
                act[u] = act[u + 1]
                lam[u] = lam[u + 1]
            na -= 1
    return False


@njit(cache=True, nogil=True)
def nearest_points(normals, offsets, count, status, out, solved):
    """_nearest_to_origin for every set with status OK."""
    for b in range(normals.shape[0]):
        solved[b] = False
        if status[b] == OK and count[b] > 0:
            solved[b] = _nearest_to_origin(normals[b], offsets[b], count[b], out[b])


def project_small_3d(Ys: np.ndarray, F: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For each set Ys[b] ((B, m, 3)): the point of Ψ(Ys[b], F) nearest its mean, a
    bound on its distance to the exact point (2-norm), and whether it was certified
    (False: compute that set exactly)."""
    Ys = np.ascontiguousarray(Ys, dtype=np.float64)
    out = np.zeros((len(Ys), 3))
    err = np.full(len(Ys), np.inf)
    if Ys.shape[1] >= 4 * F + 1:  # (Ψ ≠ ∅) converged clusters: any of their points
        cluster_boxes(Ys, F, out, err)
    found = err <= ACCEPT_REL * np.abs(out).max(axis=1)
    if Ys.shape[1] == 5 and F == 1 and not found.all():  # one Radon point, directly
        rest = np.flatnonzero(~found)
        Zs, exps = _scaled(Ys[rest])
        pts, bounds = np.zeros((len(rest), 3)), np.full(len(rest), np.inf)
        radon5_all(Zs, pts, bounds)
        out[rest], err[rest] = _unscaled(pts, bounds, exps)
        found = err <= ACCEPT_REL * np.abs(out).max(axis=1)
    rest = np.flatnonzero(~found)
    if len(rest):
        out[rest], err[rest], found[rest] = _project(Ys[rest], F)
    return out, err, found


def _unscaled(pts: np.ndarray, err: np.ndarray, exps: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray]:
    """The points and their 2-norm bounds of the sets scaled by :func:`_scaled`, times
    2^e again. Where a coordinate or the bound falls below the normal range, the
    scaling may round (to the subnormal grid, or to 0): each coordinate by at most half
    the smallest subnormal, the bound down by as much, so 2 of the smallest subnormal
    are added to the bound where it did (V41: a set of ±2^-1074 got the point 0 with
    the bound 0, its exact point ~2e-327 away). It did not where scaling back by 2^-e
    gives the scaled values again (a product by a power of two that does not round is
    exact), e.g. a point 0 with the bound 0 — a converged cluster moved next to the
    origin (``engine._batch_points_moved``) — which the unconditional term declined."""
    out, bound = np.ldexp(pts, exps[:, None]), np.ldexp(err, exps)
    with np.errstate(invalid="ignore", over="ignore"):
        rounded = ((np.ldexp(out, -exps[:, None]) != pts) & ~np.isnan(pts)).any(axis=1) \
            | ((np.ldexp(bound, -exps) != err) & ~np.isnan(err))
    bound[rounded] = (bound[rounded] + 2.0 * MIN_SUBNORMAL) * (1.0 + 2.0**-50)
    return out, bound


def _scaled(Ys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each set times 2^−e, e its largest |coordinate|'s exponent (0 for a set with a
    non-finite one, which the numba passes then decline): (scaled sets, e). A set in
    which the scaling rounds — a coordinate below 2^(e−1075) underflows, e.g. 1e-30
    beside 1e300 — is returned as NaN, so the numba passes decline it too (its point
    would have lost that coordinate with the bound 0, V43)."""
    with np.errstate(invalid="ignore", over="ignore"):
        big = np.abs(Ys).max(axis=(1, 2)) if Ys.shape[1] else np.zeros(len(Ys))
    exps = np.where(np.isfinite(big), np.frexp(np.where(np.isfinite(big), big, 1.0))[1], 0)
    Zs = np.ldexp(Ys, -exps[:, None, None])
    with np.errstate(invalid="ignore", over="ignore"):
        rounded = ((np.ldexp(Zs, exps[:, None, None]) != Ys) & np.isfinite(Ys)).any(axis=(1, 2))
    Zs[rounded] = np.nan
    return Zs, exps


@njit(cache=True, nogil=True)
def radon5_all(Zs, out, err):
    """_radon5 for every (scaled) set of five points; err stays inf where declined."""
    for b in range(Zs.shape[0]):
        if _in_scaled_range(Zs[b]):
            e = _radon5(Zs[b], out[b])
            if e >= 0.0:
                err[b] = e


@njit(cache=True, nogil=True)
def _radon5(Y, x):
    """Ψ(Y, 1) for five points in general position (every orientation below nonzero):
    the data point strictly inside the tetrahedron of the others, or the crossing of
    the segment p_i p_j with the triangle p_k p_l p_r it pierces (the plane klr and
    the planes ijk, ijl are valid on both sides, and meet only there; the crossing
    lies in every hull of four). x = p_i + t (p_j − p_i), t = D_i / (D_i − D_j) with
    D_q = det3(k, l, r, q) exactly rounded and of opposite signs (no cancellation): t
    within 8 ulps, so ‖x − x*‖₂ ≤ √3 (14u |t| ‖p_j − p_i‖_∞ + 2u ‖x‖_∞). Writes x,
    returns that bound; −1 if an orientation is zero."""
    for i in range(5):
        o = _others(i, -1)
        inside = True
        for f in range(4):  # face without o[f], against the vertex o[f]
            a, b, c = o[(f + 1) % 4], o[(f + 2) % 4], o[(f + 3) % 4]
            s_i = orient3(Y, a, b, c, i)
            s_v = orient3(Y, a, b, c, o[f])
            if s_i == 0 or s_v == 0:
                return -1.0
            inside = inside and s_i == s_v
        if inside:
            x[:] = Y[i]
            return 0.0
    for i in range(5):
        for j in range(i + 1, 5):
            k, m, r = _others(i, j)[:3]
            s1 = orient3(Y, i, j, k, m)
            s2 = orient3(Y, i, j, m, r)
            s3 = orient3(Y, i, j, r, k)
            if s1 == 0 or s2 == 0 or s3 == 0:
                return -1.0
            if not (s1 == s2 == s3):
                continue
            di, dj = det3(Y, k, m, r, i), det3(Y, k, m, r, j)
            if not di * dj < 0.0:
                continue
            t = di / (di - dj)
            e = 0.0
            for c in range(3):
                u = Y[j, c] - Y[i, c]
                x[c] = Y[i, c] + t * u
                e = max(e, 14.0 * EPS * abs(t * u) + 2.0 * EPS * abs(x[c]))
            return (e + MIN_NORMAL) * math.sqrt(3.0) * (1.0 + 4.0 * EPS)
    return -1.0


@njit(cache=True, nogil=True)
def _others(i, j):
    """The indices of range(5) other than i and j (j = −1: other than i)."""
    o = np.empty(4, dtype=np.int64)
    n = 0
    for q in range(5):
        if q != i and q != j:
            o[n] = q
            n += 1
    return o


@njit(cache=True, nogil=True)
def cluster_boxes(Ys, F, out, err):
    """cluster_box for every set; err in the 2-norm (√3 times the max norm)."""
    for b in range(Ys.shape[0]):
        err[b] = cluster_box(Ys[b], F, out[b]) * math.sqrt(3.0) * (1.0 + 4.0 * EPS)


def _project(Ys: np.ndarray, F: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """project_small_3d by the certified KKT route (module docstring)."""
    B, m, _ = Ys.shape
    Zs, exps = _scaled(Ys)  # exact (else NaN); max |coordinate| in [1/2, 1)
    H = m * (m - 1) * (m - 2) // 3
    normals = np.empty((B, H, 3))
    offsets = np.empty((B, H))
    count = np.zeros(B, dtype=np.int64)
    status = np.empty(B, dtype=np.int64)
    origin = np.zeros((B, 3))  # (left 0 for declined sets)
    scale = np.zeros(B)
    planes = _planes(B, H)
    halfspaces_3d(Zs, F, normals, offsets, count, status, origin, scale, planes)
    out = np.zeros((B, 3))
    err = np.full(B, np.inf)
    local = np.zeros((B, 3))
    solved = np.zeros(B, dtype=bool)
    certify_all(Zs, F, planes, count, status, local, scale, solved, out, err)  # pinned
    nearest_points(normals, offsets, count, np.where(np.isfinite(err), DECLINED, status),
                   local, solved)
    certify_all(Zs, F, planes, count, status, origin + scale[:, None] * local, scale, solved,
                out, err)
    retry = np.flatnonzero((status == OK) & (count > 0) & ~np.isfinite(err))
    if len(retry):  # the active-set method stalled or its hint failed: the QP proposes
        hints = by_qp(normals, offsets, count, retry)
        have = np.isfinite(hints).all(axis=1)
        certify_all(Zs[retry], F, tuple(a[retry] for a in planes), count[retry],
                    status[retry], origin[retry] + scale[retry, None] * hints, scale[retry],
                    have, out[retry], err[retry])
    out, err = _unscaled(out, err, exps)
    return out, err, np.isfinite(err) & (err <= ACCEPT_REL * np.abs(out).max(axis=1))


def by_qp(normals, offsets, count, sets) -> np.ndarray:
    """Hints (local coordinates; NaN where the solver failed) for the given sets, from
    the QP solver in one batch call."""
    from ..models.kernel_models import project_batch

    problems = [(normals[b, :count[b]], offsets[b, :count[b]], np.zeros(3), np.eye(3),
                 np.zeros(3)) for b in sets]
    return np.array(project_batch(problems, backend=BACKEND, on_failure="nan"),
                    dtype=np.float64).reshape(len(sets), 3)


@njit(cache=True, nogil=True)
def certify_all(Zs, F, planes, count, status, hints, scale, have, out, err):
    """_certify for every set with status OK not yet certified (have: whether its hint
    is set)."""
    cn, cne, tri, eq, sgn = planes
    for b in range(Zs.shape[0]):
        if status[b] == OK and count[b] > 0 and not np.isfinite(err[b]):
            nh = count[b]
            e = _certify(Zs[b], F, (cn[b, :nh], cne[b, :nh], tri[b, :nh], eq[b, :nh],
                                    sgn[b, :nh]), hints[b], have[b], scale[b], out[b])
            if e >= 0.0:
                err[b] = e


@njit(cache=True, nogil=True)
def _solve(M, r):
    """Solve M y = r (n × n, n ≤ 3) in place of r by Gaussian elimination with partial
    pivoting; False if a pivot is zero or not finite (the caller declines)."""
    n = len(r)
    A = M.copy()
    for c in range(n):
        p = c
        for q in range(c + 1, n):
            if abs(A[q, c]) > abs(A[p, c]):
                p = q
        if not (abs(A[p, c]) > 0.0 and np.isfinite(A[p, c])):
            return False
        for k in range(n):
            A[c, k], A[p, k] = A[p, k], A[c, k]
        r[c], r[p] = r[p], r[c]
        for q in range(c + 1, n):
            f = A[q, c] / A[c, c]
            for k in range(c, n):
                A[q, k] -= f * A[c, k]
            r[q] -= f * r[c]
    for c in range(n - 1, -1, -1):
        for k in range(c + 1, n):
            r[c] -= A[c, k] * r[k]
        r[c] /= A[c, c]
    return np.isfinite(r).all()


@njit(cache=True, nogil=True)
def _unit_row(v, ve, row, rowe):
    """row = v / τ with τ = fl(‖v‖₂) (a fixed number: the exact row is v*/τ); rowe
    bounds |v*/τ − row| given |v* − v| ≤ ve. False if τ is not a safe normal number."""
    tau = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    if not (2.0**-500 < tau < 2.0**500):
        return False
    for k in range(3):
        row[k] = v[k] / tau
        rowe[k] = ve[k] / tau * (1.0 + 2.0 * EPS) + 2.0 * EPS * abs(row[k])
    return True


@njit(cache=True, nogil=True)
def _cross(u, ue, v, ve, w, we):
    """w = fl(u × v) and we ≥ |u* × v* − w| given |u* − u| ≤ ue, |v* − v| ≤ ve:
    u*_a v*_b − u_a v_b = (u*_a − u_a) v*_b + u_a (v*_b − v_b), plus 3u of rounding."""
    for k in range(3):
        a, b = (k + 1) % 3, (k + 2) % 3
        w[k] = u[a] * v[b] - u[b] * v[a]
        we[k] = (ue[a] * (abs(v[b]) + ve[b]) + abs(u[a]) * ve[b]
                 + ue[b] * (abs(v[a]) + ve[a]) + abs(u[b]) * ve[a]
                 + 3.0 * EPS * (abs(u[a] * v[b]) + abs(u[b] * v[a])))


@njit(cache=True, nogil=True)
def _residual(row, rowe, x, a, alo, ae):
    """fl(row · fl(fl(x − a) − alo)) and a bound on its distance to row* · (x − a*),
    given |row* − row| ≤ rowe and |a* − (a + alo)| ≤ ae (alo: the low part of a
    two-double anchor, else 0): (row* − row)·(x − a*) + row·((x − a*) − d) + the dot
    product's rounding (γ₃ < 4u), d within u(|d₁| + |d|) of x − a − alo."""
    val = 0.0
    bnd = 0.0
    for k in range(3):
        d1 = x[k] - a[k]
        d = d1 - alo[k]
        val += row[k] * d
        rnd = EPS * (abs(d1) + abs(d))
        bnd += (rowe[k] * (abs(d) + rnd + ae[k]) + abs(row[k]) * (rnd + ae[k])
                + 4.0 * EPS * abs(row[k] * d))
    return val, bnd * (1.0 + 8.0 * EPS) + 4.0 * MIN_NORMAL


@njit(cache=True, nogil=True)
def _inverse_bound(M, Me):
    """κ ≥ ‖M*⁻¹‖₂ for every 3 × 3 M* with |M* − M| ≤ Me, from a float inverse X:
    with R = I − X M* and ‖R‖_F ≤ θ < 1, M*⁻¹ = (I − R)⁻¹ X, so
    ‖M*⁻¹‖₂ ≤ ‖X‖_F / (1 − θ); |R| ≤ |I − fl(XM)| + its rounding + |X| Me. inf if
    θ ≥ 1/2 or M is singular in floats."""
    X = np.empty((3, 3))
    col = np.empty(3)
    for c in range(3):
        col[:] = 0.0
        col[c] = 1.0
        if not _solve(M, col):
            return np.inf
        X[:, c] = col
    theta2 = 0.0
    x2 = 0.0
    for i in range(3):
        for j in range(3):
            v = 1.0 if i == j else 0.0
            bnd = 0.0
            for k in range(3):
                v -= X[i, k] * M[k, j]
                bnd += 5.0 * EPS * abs(X[i, k] * M[k, j]) + abs(X[i, k]) * Me[k, j]
            theta2 += (abs(v) + bnd) ** 2
            x2 += X[i, j] ** 2
    theta = math.sqrt(theta2) * (1.0 + 4.0 * EPS)
    if not theta < 0.5:
        return np.inf
    return math.sqrt(x2) * (1.0 + 4.0 * EPS) / (1.0 - theta) * (1.0 + 4.0 * EPS)


@njit(cache=True, nogil=True)
def _pinning_planes(cn, eq, sel):
    """Up to three two-sided planes, each the one farthest from the span of the normals
    already chosen (the best-conditioned choice, greedily), into sel; returns how many
    are independent (3: they pin Ψ ≠ ∅ to their meeting point)."""
    basis = np.zeros((3, 3))
    ns = 0
    while ns < 3:
        best = -1
        far = INDEPENDENT_TOL
        for h in range(len(cn)):
            if not eq[h]:
                continue
            w = cn[h] / math.sqrt(cn[h] @ cn[h])
            for r in range(ns):
                w = w - (w @ basis[r]) * basis[r]
            nw = math.sqrt(w @ w)
            if nw > far:
                far = nw
                best = h
                basis[ns] = w / nw
        if best < 0:
            return ns
        sel[ns] = best
        ns += 1
    return ns


@njit(cache=True, nogil=True)
def _slacks(Y, cn, tri, hint):
    """|distance| of the hint to each halfspace's plane (floats; a hint only)."""
    nh = len(cn)
    dist = np.empty(nh)
    for h in range(nh):
        i = tri[h, 0]
        v = 0.0
        for k in range(3):
            v += cn[h, k] * (hint[k] - Y[i, k])
        dist[h] = abs(v) / math.sqrt(cn[h, 0] ** 2 + cn[h, 1] ** 2 + cn[h, 2] ** 2)
    return dist


@njit(cache=True, nogil=True)
def _propose(cn, eq, dist, s, sel):
    """The active set S proposed by the hint (its slacks dist): halfspaces within
    ACTIVE_TOL·s of tight, two-sided planes first, then by slack, each kept if its
    normal is independent of those kept (INDEPENDENT_TOL); into sel, returns
    |S| ≤ 3. A proposal only."""
    order = np.argsort(dist)
    basis = np.zeros((3, 3))
    ns = 0
    for two_sided in (True, False):
        for h in order:
            if dist[h] > ACTIVE_TOL * s or ns == 3:
                break
            if eq[h] != two_sided:
                continue
            w = cn[h] / math.sqrt(cn[h, 0] ** 2 + cn[h, 1] ** 2 + cn[h, 2] ** 2)
            for r in range(ns):
                w = w - (w @ basis[r]) * basis[r]
            nw = math.sqrt(w @ w)
            if nw > INDEPENDENT_TOL:
                basis[ns] = w / nw
                sel[ns] = h
                ns += 1
    return ns


@njit(cache=True, nogil=True)
def _nearest_of(Y, idx, x):
    """The point among Y[idx] nearest x (max norm): the anchor of a plane's residual."""
    best = idx[0]
    bd = np.inf
    for q in idx:
        d = max(abs(x[0] - Y[q, 0]), abs(x[1] - Y[q, 1]), abs(x[2] - Y[q, 2]))
        if d < bd:
            bd = d
            best = q
    return best


@njit(cache=True, nogil=True)
def _system(Y, cn, cne, tri, sel, ns, hint, mean, mlo, merr, M, Me, A, Alo, Ae):
    """The rows of M* x = r* (module docstring) as unit rows M (errors Me) with their
    anchors A + Alo (errors Ae): the planes of S anchored at their data point nearest
    the hint, then tangents n₁ × n₂ (|S| = 2) or n × e_a for the two axes a other than
    n's largest component (|S| = 1), anchored at the two-double mean (mean + mlo).
    False if a row is unsafe."""
    for r in range(ns):
        h = sel[r]
        if not _unit_row(cn[h], cne[h], M[r], Me[r]):
            return False
        A[r] = Y[_nearest_of(Y, tri[h], hint)]
        Alo[r] = 0.0
        Ae[r] = 0.0
    t = np.empty(3)
    te = np.empty(3)
    if ns == 2:
        _cross(M[0], Me[0], M[1], Me[1], t, te)
        if not _unit_row(t, te, M[2], Me[2]):
            return False
    elif ns == 1:
        big = np.argmax(np.abs(M[0]))
        r = 1
        for axis in range(3):
            if axis != big:
                e = np.zeros(3)
                e[axis] = 1.0
                _cross(M[0], Me[0], e, np.zeros(3), t, te)
                if not _unit_row(t, te, M[r], Me[r]):
                    return False
                r += 1
    for r in range(ns, 3):
        A[r] = mean
        Alo[r] = mlo
        Ae[r] = merr
    return True


@njit(cache=True, nogil=True)
def _solution(M, A, x):
    """x ≈ the solution of M (x − A_r) = 0 row by row: solved in coordinates centred at
    A[0] and refined twice from the anchored residuals. False if M is singular."""
    r = np.empty(3)
    for i in range(3):
        r[i] = M[i] @ (A[i] - A[0])
    if not _solve(M, r):
        return False
    x[:] = A[0] + r
    for _ in range(2):
        for i in range(3):
            r[i] = M[i] @ (x - A[i])
        if not _solve(M, r):
            return False
        x -= r
    return True


@njit(cache=True, nogil=True)
def _error_bound(M, Me, A, Alo, Ae, x, kappa):
    """β ≥ ‖x − x*‖₂, x* = the exact solution of M* x = r*: with ρ the anchored float
    residuals (each within e_i of ρ*_i = M*_i x − r*_i) and δ = fl(M⁻¹ρ),
    x − x* − δ = M*⁻¹(ρ* − M*δ), so β = ‖δ‖₂ + κ ‖ρ* − M*δ‖₂: κ multiplies only
    rounding-sized terms, and β stays near the true error even for large κ."""
    rho = np.empty(3)
    e = np.empty(3)
    for r in range(3):
        rho[r], e[r] = _residual(M[r], Me[r], x, A[r], Alo[r], Ae[r])
    delta = rho.copy()
    if not _solve(M, delta):
        return np.inf
    w2 = 0.0
    for r in range(3):
        res = -rho[r]
        bnd = EPS * abs(rho[r]) + e[r]
        for k in range(3):
            res += M[r, k] * delta[k]
            bnd += Me[r, k] * abs(delta[k]) + 4.0 * EPS * abs(M[r, k] * delta[k])
        w2 += (abs(res) + bnd) ** 2
    return (math.sqrt(delta @ delta) * (1.0 + 4.0 * EPS)
            + kappa * math.sqrt(w2) * (1.0 + 8.0 * EPS))


@njit(cache=True, nogil=True)
def _multipliers_positive(M, Me, ns, two_sided, x, beta, kappa, mean, mlo, merr):
    """m* − x* = Σ_r λ_r M*_r (tangent rows: λ = 0): λ from Mᵀ μ = fl(m − x), with
    ‖λ − μ‖₂ ≤ κ ‖M*ᵀμ − (m* − x*)‖₂ bounded by the float residual, the row errors,
    the mean's error and β. True if μ_r exceeds that on every one-sided row."""
    g1 = mean - x
    g = g1 + mlo  # m* − x within u(|g₁| + |g|) + merr
    mu = g.copy()
    if not _solve(M.T.copy(), mu):
        return False
    w2 = 0.0
    for k in range(3):
        res = -g[k]
        bnd = EPS * (abs(g1[k]) + abs(g[k])) + merr[k]
        for i in range(3):
            res += M[i, k] * mu[i]
            bnd += Me[i, k] * abs(mu[i]) + 4.0 * EPS * abs(M[i, k] * mu[i])
        w2 += (abs(res) + bnd) ** 2
    spread = kappa * (math.sqrt(w2) + beta) * (1.0 + 16.0 * EPS)
    for r in range(ns):
        if not two_sided[r] and not mu[r] > spread:
            return False
    return True


@njit(cache=True, nogil=True)
def _others_satisfied(Y, cn, cne, tri, sgn, sel, ns, x, beta, point):
    """Every halfspace not on a plane of S strictly satisfied at x* (‖x − x*‖₂ ≤ β):
    from the float residual at its point nearest x and its bound, or, when x* is the
    data point Y[point], exactly (≤ 0: a plane through it is satisfied). A plane
    through two data points p, q that two planes of S share contains their line, hence
    x*: satisfied exactly."""
    lines = _shared_lines(tri, sel, ns)
    for h in range(len(cn)):
        on_s = False
        for r in range(ns):
            g = sel[r]
            on_s = on_s or (tri[h, 0] == tri[g, 0] and tri[h, 1] == tri[g, 1]
                            and tri[h, 2] == tri[g, 2])
        for r in range(len(lines)):
            on_s = on_s or (_has(tri[h], lines[r, 0]) and _has(tri[h], lines[r, 1]))
        if on_s:
            continue
        if point >= 0:
            if sgn[h] * orient3(Y, tri[h, 0], tri[h, 1], tri[h, 2], point) > 0:
                return False
            continue
        a = Y[_nearest_of(Y, tri[h], x)]
        val, bnd = _residual(cn[h], cne[h], x, a, np.zeros(3), np.zeros(3))
        norm = math.sqrt(cn[h] @ cn[h]) + math.sqrt(cne[h] @ cne[h])
        if not val + bnd + norm * beta * (1.0 + 4.0 * EPS) < 0.0:
            return False
    return True


@njit(cache=True, nogil=True)
def _certify(Y, F, planes, hint, have_hint, s, x):
    """The certified projection of mean(Y) onto Ψ(Y, F) (module docstring): from three
    independent two-sided planes when they pin Ψ to a point (no hint needed), else from
    the active set the hint proposes. Writes x, returns β ≥ ‖x − x*‖₂, or −1
    (declined)."""
    cn, _, tri, eq, _ = planes
    mean = np.empty(3)
    mlo = np.empty(3)
    merr = np.empty(3)
    mean_two(Y, mean, mlo, merr)
    sel = np.empty(3, dtype=np.int64)
    ns = _pinning_planes(cn, eq, sel) if len(Y) >= 4 * F + 1 else 0
    if ns == 3:
        beta = _certify_choice(Y, F, planes, sel, ns, hint, mean, mlo, merr, x)
        if beta >= 0.0:
            return beta
    if not have_hint:
        return -1.0
    dist = _slacks(Y, cn, tri, hint)
    ns = _propose(cn, eq, dist, s, sel)
    beta = _certify_choice(Y, F, planes, sel, ns, hint, mean, mlo, merr, x)
    if beta >= 0.0:
        return beta
    # the hint's proposal failed (an inaccurate hint on an ill-conditioned set): every
    # choice of at most three among the NEAR_CANDIDATES halfspaces nearest it
    near = np.argsort(dist)[:NEAR_CANDIDATES]
    for size in range(1, 4):
        for combo in _combinations(len(near), size):
            for r in range(size):
                sel[r] = near[combo[r]]
            beta = _certify_choice(Y, F, planes, sel, size, hint, mean, mlo, merr, x)
            if beta >= 0.0:
                return beta
    return -1.0


@njit(cache=True, nogil=True)
def _certify_choice(Y, F, planes, sel, ns, hint, mean, mlo, merr, x):
    """_certify for the active set S = sel[:ns]: writes x, returns β or −1."""
    cn, cne, tri, eq, sgn = planes
    two_sided = np.zeros(3, dtype=np.bool_)
    for r in range(ns):
        two_sided[r] = eq[sel[r]]
    if ns == 0:
        x[:] = mean
        gap = np.abs(mlo) + merr  # (x = the high part)
        beta = math.sqrt(gap @ gap) * (1.0 + 4.0 * EPS)
        return beta if _others_satisfied(Y, cn, cne, tri, sgn, sel, 0, x, beta, -1) else -1.0
    M = np.empty((3, 3))
    Me = np.empty((3, 3))
    A = np.empty((3, 3))
    Ae = np.empty((3, 3))
    Alo = np.empty((3, 3))
    if not _system(Y, cn, cne, tri, sel, ns, hint, mean, mlo, merr, M, Me, A, Alo, Ae):
        return -1.0
    kappa = _inverse_bound(M, Me)
    if not kappa < np.inf:
        return -1.0
    point = _common_point(tri, sel, ns)
    if point >= 0:  # three independent planes through a data point meet only there
        x[:] = Y[point]
        beta = 0.0
    else:
        if not _solution(M, A, x):
            return -1.0
        beta = _error_bound(M, Me, A, Alo, Ae, x, kappa)
    if not np.isfinite(beta):
        return -1.0
    if ns == 3 and two_sided.all() and len(Y) >= 4 * F + 1:
        return beta  # Ψ ≠ ∅ lies on three independent planes: Ψ = {x*}
    if not (_multipliers_positive(M, Me, ns, two_sided, x, beta, kappa, mean, mlo, merr)
            or _other_choice(Y, planes, sel, ns, point, x, beta, mean, mlo, merr)):
        return -1.0
    return beta if _others_satisfied(Y, cn, cne, tri, sgn, sel, ns, x, beta, point) else -1.0


@njit(cache=True, nogil=True)
def _other_choice(Y, planes, sel, ns, point, x, beta, mean, mlo, merr):
    """At a degenerate x* — the data point Y[point], or on the line pq of two data
    points two planes of S share — every plane through that point (line) contains x*,
    and the normal cone is spanned by some choice of them: try the choices (at most
    MAX_CHOICES) in place of S's planes through it, keeping x and β (x* is the same
    point). On success sel holds the choice whose multipliers are certified."""
    cn, cne, tri, eq, _ = planes
    lines = _shared_lines(tri, sel, ns)
    if point < 0 and not len(lines):
        return False
    p = point if point >= 0 else lines[0, 0]
    q = point if point >= 0 else lines[0, 1]
    keep = np.empty(3, dtype=np.int64)
    nk = 0
    for r in range(ns):
        if not (_has(tri[sel[r]], p) and _has(tri[sel[r]], q)):
            keep[nk] = sel[r]
            nk += 1
    members = np.array([h for h in range(len(cn)) if _has(tri[h], p) and _has(tri[h], q)])
    k = ns - nk
    M = np.empty((3, 3))
    Me = np.empty((3, 3))
    A = np.empty((3, 3))
    Alo = np.empty((3, 3))
    Ae = np.empty((3, 3))
    trial = keep.copy()
    two_sided = np.zeros(3, dtype=np.bool_)
    tried = 0
    for combo in _combinations(len(members), k):
        tried += 1
        if tried > MAX_CHOICES:
            return False
        for r in range(k):
            trial[nk + r] = members[combo[r]]
        for r in range(ns):
            two_sided[r] = eq[trial[r]]
        if not _system(Y, cn, cne, tri, trial, ns, x, mean, mlo, merr, M, Me, A, Alo, Ae):
            continue
        kappa = _inverse_bound(M, Me)
        if kappa < np.inf and _multipliers_positive(M, Me, ns, two_sided, x, beta, kappa,
                                                     mean, mlo, merr):
            sel[:ns] = trial[:ns]
            return True
    return False


@njit(cache=True, nogil=True)
def _combinations(n, k):
    """All k-subsets (k ≤ 3) of range(n), as rows of an array."""
    out = []
    if k == 1:
        for a in range(n):
            out.append((a, 0, 0))
    elif k == 2:
        for a in range(n):
            for b in range(a + 1, n):
                out.append((a, b, 0))
    elif k == 3:
        for a in range(n):
            for b in range(a + 1, n):
                for c in range(b + 1, n):
                    out.append((a, b, c))
    return out


@njit(cache=True, nogil=True)
def _has(t, p):
    return t[0] == p or t[1] == p or t[2] == p


@njit(cache=True, nogil=True)
def _shared_lines(tri, sel, ns):
    """The pairs of data points shared by two planes of S (rows of a (k, 2) array):
    two independent planes through p and q meet in the line pq, so x* lies on it."""
    lines = np.empty((3, 2), dtype=np.int64)
    k = 0
    for r1 in range(ns):
        for r2 in range(r1 + 1, ns):
            shared = 0
            pair = np.empty(2, dtype=np.int64)
            for p in tri[sel[r1]]:
                if _has(tri[sel[r2]], p) and shared < 2:
                    pair[shared] = p
                    shared += 1
            if shared == 2:
                lines[k] = pair
                k += 1
    return lines[:k]


@njit(cache=True, nogil=True)
def _common_point(tri, sel, ns):
    """A data point on all three planes of S (|S| = 3), else −1."""
    if ns < 3:
        return -1
    for p in tri[sel[0]]:
        if (p == tri[sel[1], 0] or p == tri[sel[1], 1] or p == tri[sel[1], 2]) and \
                (p == tri[sel[2], 0] or p == tri[sel[2], 1] or p == tri[sel[2], 2]):
            return p
    return -1
