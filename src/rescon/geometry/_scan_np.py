"""numpy twins of the numba candidate scan, for small inputs: nothing to compile.

:func:`classify` returns what :func:`rescon.geometry._candidates.classify` returns — the
same float orientations s(q) = Σ_j (q − p_0)_j · C_j evaluated in the same order, the
same coarse and precise rounding bounds, hence the same decisions — vectorised over
all (subset, point) pairs instead of looped. The numba scan stops a subset once both
sides hold more than F points, so its counts above F are lower bounds; here every
count is complete, which changes no comparison with F (a count above F stays above
F). :mod:`.halfspaces` takes this path when the scan is small enough that numba's
start-up (import, type registries, compiling on a cold cache) would dominate.
"""

from __future__ import annotations

import itertools
from math import comb

import numpy as np

__all__ = ["HUGE", "TINY", "classify", "in_range", "k_subsets", "sets_in_range"]

#: nonzero |coordinates| must lie in [TINY, HUGE] for the expansion predicates of
#: :mod:`._expansions` to be exact: then products of up to four differences neither
#: underflow nor overflow
TINY, HUGE = 2.0**-120, 2.0**120


def in_range(Y: np.ndarray) -> bool:
    """Every nonzero |coordinate| in [TINY, HUGE] (:func:`._expansions.in_range`)."""
    a = np.abs(Y)
    return bool(np.all((a == 0.0) | ((a >= TINY) & (a <= HUGE))))


def sets_in_range(Ys: np.ndarray) -> np.ndarray:
    """:func:`in_range` for each set Ys[b] of a stack (B, m, d), as a boolean (B,)."""
    a = np.abs(Ys)
    return np.all((a == 0.0) | ((a >= TINY) & (a <= HUGE)), axis=(1, 2))


def k_subsets(n: int, k: int) -> np.ndarray:
    """All k-subsets of range(n) in lexicographic order, (C(n, k), k) int32."""
    out = np.fromiter(itertools.chain.from_iterable(itertools.combinations(range(n), k)),
                      dtype=np.int32, count=comb(n, k) * k)
    return out.reshape(-1, k)


def _cofactors(D: np.ndarray, perms: np.ndarray, psigns: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray]:
    """For every subset, the cofactors C of the last row of [D; ·] (D: (T, k−1, k),
    rows p_i − p_0) and their absolute-value permanents |C|, (T, k) each: closed forms
    for k ≤ 3, else the (k−1)!-term expansion with the signs ``psigns`` of ``perms``,
    each product formed left to right as in the numba scan."""
    T, _, k = D.shape
    if k == 1:
        return np.ones((T, 1)), np.ones((T, 1))
    if k == 2:
        C = np.column_stack([-D[:, 0, 1], D[:, 0, 0]])
        return C, np.abs(C)
    if k == 3:
        a0, a1, a2 = D[:, 0, 0], D[:, 0, 1], D[:, 0, 2]
        b0, b1, b2 = D[:, 1, 0], D[:, 1, 1], D[:, 1, 2]
        C = np.column_stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])
        Cabs = np.column_stack([np.abs(a1 * b2) + np.abs(a2 * b1),
                                np.abs(a2 * b0) + np.abs(a0 * b2),
                                np.abs(a0 * b1) + np.abs(a1 * b0)])
        return C, Cabs
    if k in (4, 5):
        return _cofactors45(D)
    C, Cabs = np.empty((T, k)), np.empty((T, k))
    for j in range(k):
        cols = [t for t in range(k) if t != j]
        det, per = np.zeros(T), np.zeros(T)
        for p in range(perms.shape[0]):
            prod, aprod = np.ones(T), np.ones(T)
            for i in range(k - 1):
                v = D[:, i, cols[perms[p, i]]]
                prod = prod * v
                aprod = aprod * np.abs(v)
            det = det + psigns[p] * prod
            per = per + aprod
        C[:, j] = (1.0 if (k - 1 + j) % 2 == 0 else -1.0) * det
        Cabs[:, j] = per
    return C, Cabs


def _minor2(D: np.ndarray, r: int, a: int, b: int) -> tuple[np.ndarray, np.ndarray]:
    """det and permanent of |·| of rows r, r + 1 and columns a, b (as the numba scan)."""
    x, y = D[:, r, a] * D[:, r + 1, b], D[:, r, b] * D[:, r + 1, a]
    return x - y, np.abs(x) + np.abs(y)


def _cofactors45(D: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The closed forms of the numba scan for k = 4, 5 (:func:`._candidates._cofactors4`,
    :func:`._candidates._cofactors5`), every operation in the same order: k = 4 expands
    each 3 × 3 minor along row 0 over the 2 × 2 minors of rows 1, 2; k = 5 each 4 × 4
    minor along rows 0, 1 over the 2 × 2 minors of rows 0, 1 and 2, 3."""
    T, _, k = D.shape
    C, Cabs = np.empty((T, k)), np.empty((T, k))
    pairs = list(itertools.combinations(range(k), 2))
    top = {ab: _minor2(D, 0, *ab) for ab in pairs} if k == 5 else {}
    low = {ab: _minor2(D, 1 if k == 4 else 2, *ab) for ab in pairs}
    for j in range(k):
        cols = [t for t in range(k) if t != j]
        det, per = np.zeros(T), np.zeros(T)
        if k == 4:
            sign = 1.0
            for i in cols:
                m, p = low[tuple(t for t in cols if t != i)]
                det = det + sign * D[:, 0, i] * m
                per = per + np.abs(D[:, 0, i]) * p
                sign = -sign
        else:
            for u, v in itertools.combinations(range(4), 2):
                w0, w1 = (t for t in range(4) if t not in (u, v))
                term = top[cols[u], cols[v]][0] * low[cols[w0], cols[w1]][0]
                det = det + (term if (1 + u + v) % 2 == 0 else -term)
                per = per + top[cols[u], cols[v]][1] * low[cols[w0], cols[w1]][1]
        C[:, j] = det if (k - 1 + j) % 2 == 0 else -det
        Cabs[:, j] = per
    return C, Cabs


def classify(Y: np.ndarray, W: np.ndarray, subsets: np.ndarray, perms: np.ndarray,
             psigns: np.ndarray, c_err: float, F: int, floor: float = 0.0
             ) -> tuple[np.ndarray, ...]:
    """(plus, minus, unc, degenerate, cof, cof_abs) for every k-subset, as
    :func:`rescon.geometry._candidates.classify_subsets` defines them.

    A point q off the subset is surely on the + side when s(q) > bound, on the − side
    when s(q) < −bound, else uncertain (c_err > 0) or on the hyperplane (c_err = 0,
    exact floats); bound = c_err · 2M · Σ_j |C|_j + floor (M = max |coordinate|)
    unless |s(q)| is within it, then c_err · Σ_j |q − p_0|_j |C|_j + floor. NaN or
    inf never passes a comparison, so it is uncertain too."""
    n, k = Y.shape
    count = len(subsets)
    M = float(np.abs(Y).max()) if Y.size else 0.0
    P0 = Y[subsets[:, 0]]
    cof, cof_abs = _cofactors(Y[subsets[:, 1:]] - P0[:, None, :], perms, psigns)
    coarse = np.zeros(count)
    for j in range(k):
        coarse = coarse + cof_abs[:, j]
    coarse = coarse * c_err * 2.0 * M + floor
    degenerate = np.all(cof == 0.0, axis=1) & (c_err == 0.0)
    Q = Y[None, :, :] - P0[:, None, :]  # (count, n, k): q − p_0
    s = np.zeros((count, n))
    precise = np.zeros((count, n))
    for j in range(k):
        s = s + Q[:, :, j] * cof[:, None, j]
        precise = precise + np.abs(Q[:, :, j]) * cof_abs[:, None, j]
    precise = precise * c_err + floor
    near = np.abs(s) <= coarse[:, None]
    bound = np.where(near, precise, coarse[:, None])
    off = np.ones((count, n), dtype=np.bool_)
    off[np.arange(count)[:, None], subsets] = False
    off[degenerate] = False
    pos, neg = off & (s > bound), off & (s < -bound)
    w = W.astype(np.int64)
    plus, minus = pos @ w, neg @ w
    unc = (off & ~pos & ~neg) @ w if c_err != 0.0 else np.zeros(count, dtype=np.int64)
    return plus, minus, unc, degenerate, cof, cof_abs
