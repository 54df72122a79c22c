"""numba kernel: classify every point against every hyperplane through k points.

For a k-subset {p_0, ..., p_{k-1}} of points in R^k and a point q, the orientation

    s(q) = det[p_1 − p_0; ...; p_{k−1} − p_0; q − p_0] = Σ_j (q − p_0)_j · C_j

(C_j the cofactors of the last row) is > 0, = 0 or < 0 as q lies on the positive
side of, on, or on the negative side of the hyperplane through the subset. With
``c_err > 0`` the float value is trusted only when |s| exceeds the rounding-error
bound c_err · Σ_j |q − p_0|_j · |C|_j + floor (|C|_j: the same cofactors of the
absolute values, a permanent; floor: the underflow term of
:func:`rescon._rounding.underflow_floor`); otherwise — and whenever s or the bound is
inf or NaN, as no comparison with them holds — the point is counted as *uncertain*
and decided later in exact integer arithmetic. With ``c_err = 0`` the caller guarantees that
float arithmetic is exact (small integers), and s = 0 means "on the hyperplane".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .._rounding import UNIT_ROUNDOFF


@njit(cache=True)
def _cofactors(Y, idx, k, perms, psigns, C, Cabs, D, cols):
    """Cofactors of the last row of [p_1 − p_0; ...; p_{k−1} − p_0; ·] and their
    absolute-value permanents, into C and Cabs (length k); D ((k−1, k)) and cols
    (k − 1) are scratch. Closed forms for k = 2, 3."""
    p0 = idx[0]
    for i in range(k - 1):
        for j in range(k):
            D[i, j] = Y[idx[i + 1], j] - Y[p0, j]
    if k == 2:
        C[0] = -D[0, 1]
        C[1] = D[0, 0]
        Cabs[0] = abs(D[0, 1])
        Cabs[1] = abs(D[0, 0])
        return
    if k == 3:
        a0, a1, a2 = D[0, 0], D[0, 1], D[0, 2]
        b0, b1, b2 = D[1, 0], D[1, 1], D[1, 2]
        C[0] = a1 * b2 - a2 * b1
        C[1] = a2 * b0 - a0 * b2
        C[2] = a0 * b1 - a1 * b0
        Cabs[0] = abs(a1 * b2) + abs(a2 * b1)
        Cabs[1] = abs(a2 * b0) + abs(a0 * b2)
        Cabs[2] = abs(a0 * b1) + abs(a1 * b0)
        return
    for j in range(k):
        c = 0
        for t in range(k):
            if t != j:
                cols[c] = t
                c += 1
        det = 0.0
        per = 0.0
        for p in range(perms.shape[0]):
            prod = 1.0
            aprod = 1.0
            for i in range(k - 1):
                v = D[i, cols[perms[p, i]]]
                prod *= v
                aprod *= abs(v)
            det += psigns[p] * prod
            per += aprod
        sign = 1.0 if (k - 1 + j) % 2 == 0 else -1.0
        C[j] = sign * det
        Cabs[j] = per


#: below this many subsets the scan runs on one thread (thread start-up dominates;
#: measured: 5000 saves ~10 % at d = 3, n = 50, 2000 costs ~20 % at d = 2, n = 100)
PARALLEL_MIN_SUBSETS = 5_000


def classify(Y, W, subsets, perms, psigns, c_err, F, floor=0.0):
    """:func:`classify_subsets`, on one thread for small inputs."""
    count, k = subsets.shape
    if count >= PARALLEL_MIN_SUBSETS:
        return classify_subsets(Y, W, subsets, perms, psigns, c_err, F, floor)
    out = (np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64),
           np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.bool_),
           np.empty((count, k)), np.empty((count, k)))
    M = float(np.abs(Y).max()) if Y.size else 0.0
    _classify_range(Y, W, subsets, perms, psigns, c_err, F, floor, M, 0, count, *out)
    return out


@njit(cache=True)
def k_subsets(n, k, count):
    """The first ``count`` k-subsets of range(n) in lexicographic order, (count, k)."""
    subsets = np.empty((count, k), dtype=np.int32)
    idx = np.arange(k)
    for t in range(count):
        for i in range(k):
            subsets[t, i] = idx[i]
        i = k - 1
        while i >= 0 and idx[i] == n - k + i:
            i -= 1
        if i < 0:
            break
        idx[i] += 1
        for j in range(i + 1, k):
            idx[j] = idx[j - 1] + 1
    return subsets


@njit(cache=True, nogil=True, inline="always")
def _side(s, bound, c_err):
    """+1 / −1: surely on that side; 0: on the hyperplane (exact mode, c_err = 0);
    2: undecided (within the rounding bound)."""
    if s > bound:
        return 1
    if s < -bound:
        return -1
    return 0 if c_err == 0.0 else 2


@njit(cache=True, nogil=True, inline="always")
def _tally(side, w, np_, nm, nu):
    """Add weight w to the count of ``side`` (see _side)."""
    if side == 1:
        return np_ + w, nm, nu
    if side == -1:
        return np_, nm + w, nu
    if side == 2:
        return np_, nm, nu + w
    return np_, nm, nu


@njit(cache=True, nogil=True, inline="always")
def _scan3(Y, W, i0, i1, i2, C, Cabs, coarse, c_err, floor, F):
    """The point scan of _classify_range for k = 3 with scalars (the hot loop; the
    counts are accumulated without branches on the side, which is unpredictable)."""
    c0, c1, c2 = C[0], C[1], C[2]
    a0, a1, a2 = Cabs[0], Cabs[1], Cabs[2]
    x0, x1, x2 = Y[i0, 0], Y[i0, 1], Y[i0, 2]
    np_, nm, nu = 0, 0, 0
    for q in range(Y.shape[0]):
        if q == i0 or q == i1 or q == i2:
            continue
        d0 = Y[q, 0] - x0
        d1 = Y[q, 1] - x1
        d2 = Y[q, 2] - x2
        s = d0 * c0 + d1 * c1 + d2 * c2
        bound = coarse
        if c_err != 0.0 and abs(s) <= coarse:
            bound = c_err * (abs(d0) * a0 + abs(d1) * a1 + abs(d2) * a2) + floor
        pos = s > bound
        neg = s < -bound
        w = W[q]
        np_ += w * pos
        nm += w * neg
        if c_err != 0.0:
            nu += w * (not (pos or neg))
        if np_ > F and nm > F:
            break
    return np_, nm, nu


@njit(cache=True, nogil=True)
def _classify_range(Y, W, subsets, perms, psigns, c_err, F, floor, M, t0, t1,
                    plus, minus, unc, degenerate, cof, cof_abs):
    """classify_subsets for rows t0 ≤ t < t1 (written into the output arrays)."""
    n, k = Y.shape
    C = np.empty(k)
    Cabs = np.empty(k)
    D = np.empty((max(k - 1, 1), k))
    cols = np.empty(max(k - 1, 1), dtype=np.int64)
    for t in range(t0, t1):
        idx = subsets[t]
        if k == 1:
            C[0] = 1.0
            Cabs[0] = 1.0
        else:
            _cofactors(Y, idx, k, perms, psigns, C, Cabs, D, cols)
        zero = True
        coarse = 0.0
        for j in range(k):
            cof[t, j] = C[j]
            cof_abs[t, j] = Cabs[j]
            coarse += Cabs[j]
            if C[j] != 0.0:
                zero = False
        coarse = coarse * c_err * 2.0 * M + floor
        if zero and c_err == 0.0:
            degenerate[t] = True
            continue
        p0 = idx[0]
        if k == 3:
            np_, nm, nu = _scan3(Y, W, idx[0], idx[1], idx[2], C, Cabs, coarse, c_err, floor,
                                 F)
            plus[t] = np_
            minus[t] = nm
            unc[t] = nu
            continue
        np_, nm, nu = 0, 0, 0
        for q in range(n):
            is_member = False
            for i in range(k):
                if idx[i] == q:
                    is_member = True
            if is_member:
                continue
            s = 0.0
            for j in range(k):
                s += (Y[q, j] - Y[p0, j]) * C[j]
            if abs(s) <= coarse:
                bound = 0.0
                for j in range(k):
                    bound += abs(Y[q, j] - Y[p0, j]) * Cabs[j]
                bound = bound * c_err + floor
            else:
                bound = coarse
            np_, nm, nu = _tally(_side(s, bound, c_err), W[q], np_, nm, nu)
            if np_ > F and nm > F:
                break
        plus[t] = np_
        minus[t] = nm
        unc[t] = nu


@njit(cache=True, parallel=True)
def classify_subsets(Y, W, subsets, perms, psigns, c_err, F, floor=0.0):
    """For every k-subset (rows of ``subsets``): the weighted numbers of points surely
    on the + side, surely on the − side and uncertain, its cofactors C and their
    permanents |C|, and whether C is surely zero (degenerate subset; only decided
    when c_err = 0).

    A point is first tested against the subset's coarse bound c_err · 2M · Σ|C|_j
    (M = max |coordinate|, so |q − p_0|_j ≤ 2M), and only near the hyperplane against
    the precise one (both plus ``floor``, 0 when c_err = 0). The scan of a subset stops
    once both sides surely hold more than F points (it can then bound no valid
    halfspace), so counts above F are not exact."""
    n, k = Y.shape
    count = subsets.shape[0]
    plus = np.zeros(count, dtype=np.int64)
    minus = np.zeros(count, dtype=np.int64)
    unc = np.zeros(count, dtype=np.int64)
    degenerate = np.zeros(count, dtype=np.bool_)
    cof = np.empty((count, k))
    cof_abs = np.empty((count, k))
    M = 0.0
    for q in range(n):
        for j in range(k):
            M = max(M, abs(Y[q, j]))
    chunks = 64
    for c in prange(chunks):
        _classify_range(Y, W, subsets, perms, psigns, c_err, F, floor, M, count * c // chunks,
                        count * (c + 1) // chunks, plus, minus, unc, degenerate, cof,
                        cof_abs)
    return plus, minus, unc, degenerate, cof, cof_abs


#: angle error bound of atan2 on a correctly rounded difference vector (radians):
#: the difference has relative error ≤ ε per component (≤ √2 ε in direction), atan2
#: a few ulps of π; 64 ε is a wide margin.
ANGLE_ERR = 64.0 * UNIT_ROUNDOFF * np.pi


@njit(cache=True, parallel=True)
def sweep_pairs_2d(Y, W, subsets):
    """Side counts of the lines through every pair (rows of ``subsets``, i < j) of
    distinct points in the plane by an angular sweep around each point, O(n² log n).

    For the directed line i → j, + is the left side (the sign of the cofactor
    normal (−Δy, Δx)). A point whose angle around i is within 2·ANGLE_ERR of the
    line's two directions is counted as uncertain (decided exactly later); the others
    are certainly on their side, since each float angle is within ANGLE_ERR of the
    true one."""
    n = Y.shape[0]
    count = subsets.shape[0]
    plus = np.zeros(count, dtype=np.int64)
    minus = np.zeros(count, dtype=np.int64)
    unc = np.zeros(count, dtype=np.int64)
    cof = np.empty((count, 2))
    cof_abs = np.empty((count, 2))
    # row offset of the pairs (i, ·): pairs are in lexicographic order
    start = np.zeros(n + 1, dtype=np.int64)
    for i in range(n):
        start[i + 1] = start[i] + (n - 1 - i)
    two_pi = 2.0 * np.pi
    tol = 2.0 * ANGLE_ERR
    for i in prange(n - 1):
        m = n - 1
        ang = np.empty(m)
        wts = np.empty(m, dtype=np.int64)
        others = np.empty(m, dtype=np.int64)
        c = 0
        for q in range(n):
            if q != i:
                ang[c] = np.arctan2(Y[q, 1] - Y[i, 1], Y[q, 0] - Y[i, 0])
                wts[c] = W[q]
                others[c] = q
                c += 1
        order = np.argsort(ang)
        a2 = np.empty(2 * m)
        cw = np.zeros(2 * m + 1, dtype=np.int64)
        for t in range(m):
            a2[t] = ang[order[t]]
            a2[t + m] = ang[order[t]] + two_pi
        for t in range(2 * m):
            cw[t + 1] = cw[t] + wts[order[t % m]]
        for t in range(m):
            j = others[t]
            if j <= i:
                continue
            th = ang[t]
            # window sums over (lo, hi] of the doubled, sorted angles
            a = np.searchsorted(a2, th + tol, side="right")
            b = np.searchsorted(a2, th + np.pi - tol, side="left")
            cc = np.searchsorted(a2, th + np.pi + tol, side="right")
            e = np.searchsorted(a2, th + two_pi - tol, side="left")
            left = cw[b] - cw[a] if b > a else 0
            right = cw[e] - cw[cc] if e > cc else 0
            total = cw[m]
            row = start[i] + (j - i - 1)
            plus[row] = left
            minus[row] = right
            # everything else but j itself is uncertain
            unc[row] = total - left - right - W[j]
            dx = Y[j, 0] - Y[i, 0]
            dy = Y[j, 1] - Y[i, 1]
            cof[row, 0] = -dy
            cof[row, 1] = dx
            cof_abs[row, 0] = abs(dy)
            cof_abs[row, 1] = abs(dx)
    degenerate = np.zeros(count, dtype=np.bool_)
    return plus, minus, unc, degenerate, cof, cof_abs


@njit(cache=True, nogil=True)
def _row_max_range(A, b, V, h0, h1, out):
    k = A.shape[1]
    for h in range(h0, h1):
        best = -np.inf
        for v in range(V.shape[0]):
            s = 0.0
            for j in range(k):
                s += A[h, j] * V[v, j]
            best = max(best, s)
        out[h] = best - b[h]


@njit(cache=True, parallel=True)
def _row_max_parallel(A, b, V, out):
    m = A.shape[0]
    chunks = 64
    for c in prange(chunks):
        _row_max_range(A, b, V, m * c // chunks, m * (c + 1) // chunks, out)


def row_max(A, b, V):
    """max_v (A_h · v) − b_h for every row h, without the (rows × vertices) matrix
    (threads only for large inputs)."""
    out = np.empty(A.shape[0])
    if A.shape[0] * V.shape[0] >= 200_000:
        _row_max_parallel(A, b, V, out)
    else:
        _row_max_range(A, b, V, 0, A.shape[0], out)
    return out
