"""numba kernel: classify every point against every hyperplane through k points.

For a k-subset {p_0, ..., p_{k-1}} of points in R^k and a point q, the orientation

    s(q) = det[p_1 − p_0; ...; p_{k−1} − p_0; q − p_0] = Σ_j (q − p_0)_j · C_j

(C_j the cofactors of the last row) is > 0, = 0 or < 0 as q lies on the positive
side of, on, or on the negative side of the hyperplane through the subset. With
``c_err > 0`` the float value is trusted only when |s| exceeds the rounding-error
bound c_err · Σ_j |q − p_0|_j · |C|_j (|C|_j: the same cofactors of the absolute
values, a permanent); otherwise the point is counted as *uncertain* and decided
later in exact integer arithmetic. With ``c_err = 0`` the caller guarantees that
float arithmetic is exact (small integers), and s = 0 means "on the hyperplane".
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange


@njit(cache=True)
def _cofactors(Y, idx, k, perms, psigns, C, Cabs):
    """Cofactors of the last row of [p_1 − p_0; ...; p_{k−1} − p_0; ·] and their
    absolute-value permanents, into C and Cabs (length k)."""
    D = np.empty((max(k - 1, 1), k))
    p0 = idx[0]
    for i in range(k - 1):
        for j in range(k):
            D[i, j] = Y[idx[i + 1], j] - Y[p0, j]
    cols = np.empty(max(k - 1, 1), dtype=np.int64)
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


@njit(cache=True, parallel=True)
def classify_subsets(Y, W, subsets, perms, psigns, c_err, F):
    """For every k-subset (rows of ``subsets``): the weighted numbers of points surely
    on the + side, surely on the − side and uncertain, its cofactors C and their
    permanents |C|, and whether C is surely zero (degenerate subset; only decided
    when c_err = 0).

    A point is first tested against the subset's coarse bound c_err · 2M · Σ|C|_j
    (M = max |coordinate|, so |q − p_0|_j ≤ 2M), and only near the hyperplane against
    the precise one. The scan of a subset stops once both sides surely hold more than
    F points (it can then bound no valid halfspace), so counts above F are not exact."""
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
    for t in prange(count):
        idx = subsets[t]
        C = np.empty(k)
        Cabs = np.empty(k)
        if k == 1:
            C[0] = 1.0
            Cabs[0] = 1.0
        else:
            _cofactors(Y, idx, k, perms, psigns, C, Cabs)
        zero = True
        coarse = 0.0
        for j in range(k):
            cof[t, j] = C[j]
            cof_abs[t, j] = Cabs[j]
            coarse += Cabs[j]
            if C[j] != 0.0:
                zero = False
        coarse *= c_err * 2.0 * M
        if zero and c_err == 0.0:
            degenerate[t] = True
            continue
        p0 = idx[0]
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
                bound *= c_err
            else:
                bound = coarse
            if s > bound:
                np_ += W[q]
                if np_ > F and nm > F:
                    break
            elif s < -bound:
                nm += W[q]
                if np_ > F and nm > F:
                    break
            elif c_err != 0.0:
                nu += W[q]
        plus[t] = np_
        minus[t] = nm
        unc[t] = nu
    return plus, minus, unc, degenerate, cof, cof_abs
