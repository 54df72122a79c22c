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
from numba import njit


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
def classify_subsets(Y, W, k, perms, psigns, c_err, count, F):
    """For the first ``count`` k-subsets of range(len(Y)) in lexicographic order:
    the weighted numbers of points surely on the + side, surely on the − side and
    uncertain, the subset, its cofactors C and their permanents |C|, and whether C is
    surely zero (degenerate subset; only decided when c_err = 0).

    The scan of a subset stops once both sides surely hold more than F points (it
    can then bound no valid halfspace), so counts above F are not exact."""
    n = Y.shape[0]
    plus = np.zeros(count, dtype=np.int64)
    minus = np.zeros(count, dtype=np.int64)
    unc = np.zeros(count, dtype=np.int64)
    degenerate = np.zeros(count, dtype=np.bool_)
    subsets = np.empty((count, k), dtype=np.int32)
    cof = np.empty((count, k))
    cof_abs = np.empty((count, k))
    idx = np.arange(k)
    C = np.empty(k)
    Cabs = np.empty(k)
    member = np.zeros(n, dtype=np.bool_)
    for t in range(count):
        for i in range(k):
            subsets[t, i] = idx[i]
            member[idx[i]] = True
        if k == 1:
            C[0] = 1.0
            Cabs[0] = 1.0
        else:
            _cofactors(Y, idx, k, perms, psigns, C, Cabs)
        zero = True
        for j in range(k):
            if C[j] != 0.0:
                zero = False
        if zero and c_err == 0.0:
            degenerate[t] = True
        else:
            p0 = idx[0]
            for q in range(n):
                if member[q]:
                    continue
                s = 0.0
                bound = 0.0
                for j in range(k):
                    diff = Y[q, j] - Y[p0, j]
                    s += diff * C[j]
                    bound += abs(diff) * Cabs[j]
                bound *= c_err
                if s > bound:
                    plus[t] += W[q]
                    if plus[t] > F and minus[t] > F:
                        break
                elif s < -bound:
                    minus[t] += W[q]
                    if plus[t] > F and minus[t] > F:
                        break
                elif c_err != 0.0:
                    unc[t] += W[q]
        for j in range(k):
            cof[t, j] = C[j]
            cof_abs[t, j] = Cabs[j]
        for i in range(k):
            member[idx[i]] = False
        # next combination
        i = k - 1
        while i >= 0 and idx[i] == n - k + i:
            i -= 1
        if i < 0:
            break
        idx[i] += 1
        for j in range(i + 1, k):
            idx[j] = idx[j - 1] + 1
    return plus, minus, unc, degenerate, subsets, cof, cof_abs
