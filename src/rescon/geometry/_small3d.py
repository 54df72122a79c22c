"""Kernel points for many small point sets in R³: exact halfspaces, a tiny active-set QP.

For each set Y (m points in R³) and F, the valid halfspaces of Ψ(Y, F) — planes through
three points with at most F points strictly outside — are enumerated in numba, every
side taken from a float orientation only when its rounding-error bound decides it
(the filter of :mod:`._candidates`); a set where an undecided side or a possibly
degenerate triple could change the list is declined, and so is a set not surely
affinely full-dimensional (its kernel needs in-flat constraints); the caller computes
those exactly (:mod:`.kernel`). Copies of a point are merged (they lie on every plane
through it).

The point of Ψ nearest mean(Y) is then min ‖x − mean‖² over those halfspaces, in
coordinates centred at the mean and scaled to the set: by a dual active-set method in
numba (Goldfarb–Idnani), and for the sets where it stalls or its answer fails the
check below, by the QP solver (clarabel, one batch call); a QP the solver fails on is
declined. (proxsuite's batch was measured first: no faster on these 3-variable QPs,
and it runs to its iteration limit on the tiny kernels of converging states.) The
answer is polished: the halfspaces within ACTIVE_TOL of tight define an affine subspace, the mean is projected onto it by
least squares, and the result is accepted only if it satisfies every halfspace and the
multipliers are nonnegative, both up to POLISH_TOL of the set's scale; otherwise the
set is declined. So the combinatorics (which halfspaces exist) are exact and the point
is the float solution of the exact KKT system (≈1e-15 of the set's scale), checked
against POLISH_TOL.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_EPS = 2.0**-53
#: rounding-error factor of the 3 × 3 orientation (as in _candidates for k = 3)
C_ERR = 4.0 * (3 * 3 + math.factorial(3) + 4) * _EPS
#: a halfspace is treated as active at the QP answer when its slack is below this
#: (in units of the set's scale; the QP is solved to 1e-9)
ACTIVE_TOL = 1e-7
#: the polished point must satisfy every halfspace, and its multipliers be ≥ 0, to this
POLISH_TOL = 1e-11
OK, DECLINED = 0, 1
#: the dual active-set method: its step limit and its feasibility tolerance (local units)
GI_MAX_STEPS = 200
GI_TOL = 1e-13
#: the QP backend of the fallback (a core dependency; an interior-point method)
BACKEND = "clarabel"


@njit(cache=True, nogil=True)
def halfspaces_3d(Ys, F, normals, offsets, count, status, origin, scale):
    """For each set b: its valid halfspaces n·(x − o) ≤ c, in coordinates centred at
    o = mean(Ys[b]) and scaled by s = max |Ys[b] − o| (so c is in units of s; n unit),
    into normals[b, :count[b]], offsets[b, :count[b]]; o and s into origin[b],
    scale[b]; status OK or DECLINED."""
    B, m, _ = Ys.shape
    rep = np.empty(m, dtype=np.int64)
    for b in range(B):
        Y = Ys[b]
        status[b] = DECLINED
        count[b] = 0
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
        ok = True
        full = False  # some point surely off some plane: affinely full-dimensional
        nh = 0
        for i in range(m):
            if not ok:
                break
            if rep[i] != i:
                continue
            for j in range(i + 1, m):
                if not ok:
                    break
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
                    plus = 0
                    minus = 0
                    unc = 0
                    for q in range(m):
                        r = rep[q]
                        if r == i or r == j or r == k:
                            continue
                        d0 = Y[q, 0] - Y[i, 0]
                        d1 = Y[q, 1] - Y[i, 1]
                        d2 = Y[q, 2] - Y[i, 2]
                        v = d0 * c0 + d1 * c1 + d2 * c2
                        bound = C_ERR * (abs(d0) * e0 + abs(d1) * e1 + abs(d2) * e2)
                        if v > bound:
                            plus += 1
                        elif v < -bound:
                            minus += 1
                        else:
                            unc += 1
                        if plus > F and minus > F:
                            break
                    full = full or plus + minus > 0
                    if plus > F and minus > F:
                        continue
                    # a side that may be valid: it must be decided, and the triple
                    # surely affinely independent (else its normal is noise)
                    sure = max(abs(c0) - 4.0 * _EPS * e0, abs(c1) - 4.0 * _EPS * e1,
                               abs(c2) - 4.0 * _EPS * e2) > 0.0
                    if not sure or (plus <= F < plus + unc) or (minus <= F < minus + unc):
                        ok = False
                        break
                    norm = math.sqrt(c0 * c0 + c1 * c1 + c2 * c2)
                    n0, n1, n2 = c0 / norm, c1 / norm, c2 / norm
                    off = (n0 * (Y[i, 0] - o0) + n1 * (Y[i, 1] - o1) + n2 * (Y[i, 2] - o2)) / s
                    for sign, outside in ((1.0, plus), (-1.0, minus)):
                        if outside + unc <= F:
                            normals[b, nh, 0] = sign * n0
                            normals[b, nh, 1] = sign * n1
                            normals[b, nh, 2] = sign * n2
                            offsets[b, nh] = sign * off
                            nh += 1
        if ok and full:  # (flat sets need in-plane constraints: the exact path)
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
            rr = np.linalg.solve(G, rhs) if na else rhs
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


def project_small_3d(Ys: np.ndarray, F: int) -> tuple[np.ndarray, np.ndarray]:
    """For each set Ys[b] ((B, m, 3)): the point of Ψ(Ys[b], F) nearest its mean, and
    whether it was found (False: compute that set exactly)."""
    B, m, _ = Ys.shape
    Ys = np.ascontiguousarray(Ys, dtype=np.float64)
    H = m * (m - 1) * (m - 2) // 3
    normals = np.empty((B, H, 3))
    offsets = np.empty((B, H))
    count = np.zeros(B, dtype=np.int64)
    status = np.empty(B, dtype=np.int64)
    origin = np.empty((B, 3))
    scale = np.empty(B)
    halfspaces_3d(Ys, F, normals, offsets, count, status, origin, scale)
    local = np.zeros((B, 3))
    solved = np.zeros(B, dtype=bool)
    nearest_points(normals, offsets, count, status, local, solved)
    out = np.zeros((B, 3))
    found = np.zeros(B, dtype=bool)
    polished = {}
    for b in np.flatnonzero(solved):
        polished[b] = _polish(normals[b, :count[b]], offsets[b, :count[b]], local[b])
    retry = [b for b in np.flatnonzero((status == OK) & (count > 0)) if polished.get(b) is None]
    if retry:  # the active-set method stalled or its answer failed the check: the QP
        polished.update(by_qp(normals, offsets, count, retry))
    for b, y in polished.items():
        if y is not None:
            out[b] = origin[b] + scale[b] * y
            found[b] = True
    return out, found


def by_qp(normals, offsets, count, sets) -> dict:
    """The polished nearest points (local coordinates; None where the check fails) of
    the given sets, from the QP solver in one batch call."""
    from ..models.kernel_models import project_batch

    problems = [(normals[b, :count[b]], offsets[b, :count[b]], np.zeros(3), np.eye(3),
                 np.zeros(3)) for b in sets]
    out = {}
    for b, x in zip(sets, project_batch(problems, backend=BACKEND, on_failure="nan"),
                    strict=True):
        out[b] = None
        if np.isfinite(x).all():  # (NaN: the solver failed)
            out[b] = _polish(normals[b, :count[b]], offsets[b, :count[b]], x)
    return out


def _polish(N: np.ndarray, c: np.ndarray, x: np.ndarray) -> np.ndarray | None:
    """The projection of 0 (the mean, in local coordinates) onto {N_S y = c_S} (the
    least-norm solution), S the halfspaces nearly tight at the QP answer x, if it
    satisfies the KKT conditions of min ‖y‖² s.t. N y ≤ c up to POLISH_TOL — feasible,
    and −y = N_Sᵀλ for some λ ≥ 0 (nonnegative least squares); else None."""
    from scipy.optimize import nnls

    S = np.flatnonzero(c - N @ x <= ACTIVE_TOL)
    if not len(S):
        y = np.zeros(3)
        return y if np.all(N @ y <= c + POLISH_TOL) else None
    NS = N[S]
    y = np.linalg.lstsq(NS, c[S], rcond=None)[0]
    if np.any(N @ y > c + POLISH_TOL) or np.any(np.abs(NS @ y - c[S]) > POLISH_TOL):
        return None
    _, residual = nnls(NS.T, -y)
    return y if residual <= POLISH_TOL else None
