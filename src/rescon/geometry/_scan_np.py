"""numpy twins of the numba candidate scan, for small inputs: nothing to compile.

:func:`classify` returns what :func:`rescon.geometry._candidates.classify` returns — the
same float orientations s(q) = Σ_j (q − p_0)_j · C_j evaluated in the same order, the
same coarse and precise rounding bounds, hence the same decisions — vectorised over
all (subset, point) pairs instead of looped. For k ≤ 3 the numba scan stops a subset
once both sides hold more than F points, and for k ≥ 4 it may skip a subset whose both
sides its prefix's octants show to hold more than F (reporting F + 1 each), so its
counts above F are lower bounds; here every count is complete, which changes no
comparison with F (a count above F stays above F). :mod:`.halfspaces` takes this path
when the scan is small enough that numba's start-up (import, type registries,
compiling on a cold cache) would dominate.
"""

from __future__ import annotations

import itertools
from math import comb

import numpy as np

__all__ = ["HUGE", "PIVOT_ERR", "TINY", "classify", "cofactors", "in_range", "k_subsets",
           "sets_in_range", "side_signs"]

#: nonzero |coordinates| must lie in [TINY, HUGE] for the expansion predicates of
#: :mod:`._expansions` to be exact: then products of up to four differences neither
#: underflow nor overflow
TINY, HUGE = 2.0**-120, 2.0**120
#: relative error bound of :func:`side_signs`' orientations (k ≤ 3), 16u = 2^-49: twice
#: the proven 8u (see there), and a power of two, so the bound itself is exact
PIVOT_ERR = 2.0**-49


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


def _cofactors(D: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For every subset, the cofactors C of the last row of [D; ·] (D: (T, k−1, k),
    rows p_i − p_0) and their absolute-value permanents |C|, (T, k) each: closed forms
    for k ≤ 3, else each minor expanded along its last row over the minors of the rows
    above it (by column bitmask), every operation in the order of the numba scan
    (:func:`._candidates._prefix_minors`, :func:`._candidates._last_row_cofactors`)."""
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
    minors = {0: (np.ones(T), np.ones(T))}
    for r in range(k - 2):
        for cols in itertools.combinations(range(k), r + 1):
            minors[sum(1 << c for c in cols)] = _expand_last(D[:, r], r, cols, minors)
    C, Cabs = np.empty((T, k)), np.empty((T, k))
    for j in range(k):
        det, Cabs[:, j] = _expand_last(D[:, k - 2], k - 2, [c for c in range(k) if c != j],
                                       minors)
        C[:, j] = det if (k - 1 + j) % 2 == 0 else -det
    return C, Cabs


def _expand_last(row: np.ndarray, r: int, cols, minors: dict
                 ) -> tuple[np.ndarray, np.ndarray]:
    """det and permanent of |·| of the minors on rows 0..r and the columns ``cols``
    (increasing), along row r (``row``: (T, k)) over ``minors`` (by column bitmask) of
    the rows above — :func:`._candidates._expand_last`, term by term in its order."""
    mask = sum(1 << c for c in cols)
    det, per = np.zeros(len(row)), np.zeros(len(row))
    for t, c in enumerate(cols):
        sub_det, sub_per = minors[mask ^ (1 << c)]
        term = row[:, c] * sub_det
        det = det + term if (r + t) % 2 == 0 else det - term
        per = per + np.abs(row[:, c]) * sub_per
    return det, per


def classify(Y: np.ndarray, W: np.ndarray, subsets: np.ndarray, c_err: float, F: int,
             floor: float = 0.0, pairs: bool = False) -> tuple[np.ndarray, ...]:
    """(plus, minus, unc, degenerate) for every k-subset, as
    :func:`rescon.geometry._candidates.classify` defines them; with ``pairs``, also
    the (count, n) signs (int8: +1, −1, 0 undecided or a member) behind them.

    A point q off the subset is surely on the + side when s(q) > bound, on the − side
    when s(q) < −bound, else uncertain (c_err > 0) or on the hyperplane (c_err = 0,
    exact floats); bound = c_err · 2M · Σ_j |C|_j + floor (M = max |coordinate|)
    unless |s(q)| is within it, then c_err · Σ_j |q − p_0|_j |C|_j + floor. NaN or
    inf never passes a comparison, so it is uncertain too."""
    n, k = Y.shape
    count = len(subsets)
    M = float(np.abs(Y).max()) if Y.size else 0.0
    P0 = Y[subsets[:, 0]]
    cof, cof_abs = cofactors(Y, subsets)
    coarse = np.zeros(count)
    for j in range(k):
        coarse = coarse + cof_abs[:, j]
    coarse = coarse * c_err * 2.0 * M + floor
    degenerate = np.all(cof == 0.0, axis=1) & (c_err == 0.0)
    s = np.zeros((count, n))
    precise = np.zeros((count, n))
    for j in range(k):  # coordinate j of q − p_0, (count, n), contiguous
        Q = Y[:, j] - P0[:, j, None]
        s += Q * cof[:, j, None]
        np.abs(Q, out=Q)
        precise += Q * cof_abs[:, j, None]
    precise *= c_err
    precise += floor
    near = np.abs(s) <= coarse[:, None]
    bound = np.where(near, precise, coarse[:, None])
    off = np.ones((count, n), dtype=np.bool_)
    off[np.arange(count)[:, None], subsets] = False
    off[degenerate] = False
    pos, neg = off & (s > bound), off & (s < -bound)
    w = W.astype(np.int64)
    plus, minus = pos @ w, neg @ w
    unc = (off & ~pos & ~neg) @ w if c_err != 0.0 else np.zeros(count, dtype=np.int64)
    if pairs:
        return plus, minus, unc, degenerate, pos.view(np.int8) - neg.view(np.int8)
    return plus, minus, unc, degenerate


def cofactors(Y: np.ndarray, subsets: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cofactors C and their permanents |C| of the subsets (rows), as
    :func:`rescon.geometry._candidates.cofactors` computes them."""
    return _cofactors(Y[subsets[:, 1:]] - Y[subsets[:, :1]])


def _det_per(R) -> tuple[np.ndarray, np.ndarray]:
    """det and permanent of |·| of k × k matrices given by rows of columns, R[r][c] an
    array over the matrices, k ∈ {2, 3}: for k = 3 the cofactors c of the first two
    rows (a₁b₂ − a₂b₁, …) and det = (c₀r₀ + c₁r₁) + c₂r₂ with the third row r, so every
    monomial passes through ≤ 5 roundings (product, difference, product, two sums);
    for k = 2, a₀c₁ − a₁c₀ (2 roundings)."""
    if len(R) == 2:
        p, q = R[0][0] * R[1][1], R[0][1] * R[1][0]
        return p - q, np.abs(p) + np.abs(q)
    a, b, r = R
    det = per = None
    for j, (u, v) in enumerate(((1, 2), (2, 0), (0, 1))):
        p, q = a[u] * b[v], a[v] * b[u]
        t, tp = (p - q) * r[j], (np.abs(p) + np.abs(q)) * np.abs(r[j])
        det, per = (t, tp) if det is None else (det + t, per + tp)
    return det, per


def side_signs(Y: np.ndarray, subsets: np.ndarray, start: np.ndarray | None = None
               ) -> np.ndarray:
    """Signs (T, m) of s(q) = C·(q − p_0) for every subset (p_0..p_{k−1}) = Y[subsets[t]]
    and point q = Y[i] (C the cofactor normal, :func:`cofactors`), k = Y.shape[1] ∈ {2, 3}:
    +1 or −1 where the float filter below proves the sign, 0 where it cannot (always
    for the subset's own points, and for every point of a dependent subset).

    Requires :func:`in_range` (Y): then no product of ≤ 3 differences underflows or
    overflows (nonzero differences lie in [2^-172, 2^121]); otherwise every point is
    reported undecided (0). Intermediate values too: the entries are floats of
    magnitude ≥ 2^-120 or 0, so a nonzero computed difference of two of them is ≥ 2^-172
    (a multiple of their ulp), a 2×2 term fl(p − q)·r ≥ 2^-344 and a 3×3 monomial
    ≥ 2^-516 — all normal, so every rounding is relative (|δ| ≤ u) as the bound uses.

    Pivots. With x_0..x_k = (p_0, …, p_{k−1}, q), s(q) = det[x_j − x_0]_{j≥1} = D_0,
    and D_i = det[x_j − x_i]_{j≠i, increasing} = (−1)^i D_0 (subtract row i of the
    (k+1) × (k+1) matrix [x_j, 1] from the others and expand along the column of ones:
    the determinant is (−1)^(i+k) D_i for every i). The filter tries every pivot i and
    keeps the first decision: for a cluster with one far point, the pivot in the
    cluster has well-conditioned differences where p_0 = the far point cancels ~1e8-fold.

    Bound. Each difference is rounded once (|δ| ≤ u = 2^-53) and every monomial of
    :func:`_det_per` passes through at most 5 more roundings, so the computed det is
    Σ_t m_t Π(1 + δ) over ≤ k + 5 ≤ 8 factors: |fl(det) − det| ≤ γ_8 Σ_t |m_t|, with
    m_t the monomials of the exact differences; the computed permanent P satisfies
    Σ_t |m_t| ≤ P / (1 − u)^8 (the same factors, at most 8 of them). Hence
    |fl(det) − det| ≤ 8u(1 + 20u) P < 16u · P = PIVOT_ERR · P, and |fl(det)| >
    PIVOT_ERR · P proves sign(det) = sign(fl(det)). A NaN or inf never passes.

    ``start``: (T, m) int8 signs already proven (e.g. by :func:`classify`); its nonzero
    entries are returned as they are and not evaluated again."""
    T, k = subsets.shape
    m = len(Y)
    sign = np.zeros((T, m), dtype=np.int8) if start is None else start.astype(np.int8)
    if not in_range(Y) or not T:
        return sign
    flat = sign.reshape(-1)
    todo = np.flatnonzero(flat == 0)
    t, q = np.divmod(todo, m)
    # coordinate c of point j of every pair (subset t, point q) still open: X[j][c]
    X = [[Y[subsets[t, j], c] for c in range(k)] for j in range(k)]
    X.append([Y[q, c] for c in range(k)])
    for i in range(k + 1):  # each pivot on the pairs still undecided
        R = [[X[j][c] - X[i][c] for c in range(k)] for j in range(k + 1) if j != i]
        det, per = _det_per(R)
        bound = PIVOT_ERR * per
        s = 1 if i % 2 == 0 else -1
        pos, neg = det > bound, det < -bound
        flat[todo[pos]] = s
        flat[todo[neg]] = -s
        left = ~(pos | neg)
        todo = todo[left]
        if not len(todo):
            break
        X = [[x[left] for x in row] for row in X]
    return sign
