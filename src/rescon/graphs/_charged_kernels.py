"""Numba kernel recording the charged-set proof of (r, s)-robustness (n ≤ 64).

A pair (S1, S2) of cost c = |reach_r(S1)| + |reach_r(S2)| whose sets both keep an
r-closed member splits as S_k = U_k ∪ Q_k: Q_k = reach_r(S_k) (the charged nodes,
|Q1| + |Q2| = c) and U_k ≠ ∅ the rest, whose members i have
|N(i) \\ U_k| < t_k(i) = r + |N(i) ∩ Q_k| in-neighbours outside U_k. So no pair costs
less than s iff, for every *configuration* (Q1, Q2) of disjoint sets with
|Q1| + |Q2| ≤ s − 1, no two disjoint nonempty sets U1, U2 avoiding Q1 ∪ Q2 are closed
for the thresholds t1, t2: an r-robustness decision with per-node, per-side thresholds,
searched as ``_kernels.decide_step`` searches r-robustness, with its primitives (which
take per-node thresholds), plus one leaf for maximal pairs of least cost
(certificates/FORMAT.md, ``cost_search`` with a ``charged_tree``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._kernels import (
    U1,
    ZERO,
    core_after_removal,
    crowded,
    leaf_code,
    low_index,
    popcount,
)

OVERFLOW, WITNESS = -1, -2  # config_tree's results besides a token count


@njit(cache=True, nogil=True)
def _branch(S: np.uint64, P: np.uint64, Q: np.uint64, inmask: np.ndarray, outmask: np.ndarray,
            t: np.ndarray) -> np.int64:
    """The node to branch on at (S, P, Q), -1 when S is closed (no member i has
    ≥ t[i] in-neighbours outside S). The member i whose candidates N(i) ∩ P \\ S exceed
    its need (|N(i) \\ S| − t[i] + 1) by the least, ties: the largest need; among its
    candidates, the one that, put into S, takes an in-neighbour from the most nodes of
    Q (S2's room shrinks fastest), ties: the most in-neighbours. (The decision search's
    ``tightest_member`` and ``branch_node`` break both ties the other way; these give
    15–25 % fewer tokens on ER(30, 0.5) with s = 2.)"""
    best, cand = np.int64(1 << 40), ZERO
    m = S
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        need = popcount(inmask[i] & ~S) - t[i] + 1
        if need > 0:
            c = inmask[i] & P & ~S
            key = (popcount(c) - need) * 64 - need
            if key < best:
                best, cand = key, c
    u, best = -1, np.int64(-1)
    while cand:
        j = low_index(cand)
        cand &= ~(U1 << np.uint64(j))
        v = popcount(outmask[j] & Q) * 128 + popcount(inmask[j])
        if v > best:
            best, u = v, j
    return u


@njit(cache=True, nogil=True)
def _subtree(S0: np.uint64, B: np.uint64, R: np.uint64, P0: np.uint64, Q0: np.uint64,
             inmask: np.ndarray, outmask: np.ndarray, t1: np.ndarray, t2: np.ndarray,
             tokens: np.ndarray, ntok: int) -> int:
    """Record the decision subtree of one root and side, from S = S0, X = B (P0, Q0 the
    cores of V \\ X for t1 and of V \\ S0 \\ B for t2; R: the earlier roots and the
    charged nodes of S's side); the new token count, OVERFLOW when ``tokens`` is full
    or WITNESS when the state is a violating pair.

    Leaves: -1 when Q = ∅, -2 when S ⊄ P, -3 when the sizes cannot fit (``leaf_code``),
    -4 when S is ``crowded`` for R; otherwise the member of S with ≥ t1 outside
    in-neighbours gets one of its candidates N(i) ∩ P \\ S (``_branch``): u into S
    first, then into X."""
    n = inmask.shape[0]
    cap = 2 * n + 2
    stS = np.empty(cap, dtype=np.uint64)
    stX = np.empty(cap, dtype=np.uint64)
    stP = np.empty(cap, dtype=np.uint64)
    stQ = np.empty(cap, dtype=np.uint64)
    stS[0], stX[0], stP[0], stQ[0] = S0, B, P0, Q0
    sp = 1
    while sp:
        if ntok >= tokens.shape[0]:
            return OVERFLOW
        sp -= 1
        S, X, P, Q = stS[sp], stX[sp], stP[sp], stQ[sp]
        leaf = leaf_code(S, P, Q, inmask, t1, t2)
        if leaf == 0 and crowded(S, R, inmask, t1):
            leaf = -4
        if leaf != 0:
            tokens[ntok] = leaf
            ntok += 1
            continue
        u = _branch(S, P, Q, inmask, outmask, t1)
        if u < 0:
            return WITNESS
        tokens[ntok] = u
        ntok += 1
        bu = U1 << np.uint64(u)
        stS[sp], stX[sp], stQ[sp] = S, X | bu, Q  # second: u out of U1
        stP[sp] = core_after_removal(P & ~bu, bu, inmask, outmask, t1)
        stS[sp + 1], stX[sp + 1], stP[sp + 1] = S | bu, X, P  # first: u in U1
        stQ[sp + 1] = core_after_removal(Q & ~bu, bu & Q, inmask, outmask, t2)
        sp += 2
    return ntok


@njit(cache=True, nogil=True)
def config_tree(inmask: np.ndarray, outmask: np.ndarray, order: np.ndarray, t1: np.ndarray,
                t2: np.ndarray, sym: bool, q1: np.uint64, q2: np.uint64, tokens: np.ndarray,
                ntok: int) -> int:
    """Append to ``tokens`` (from ``ntok``) the tree of one configuration: its charged
    nodes q1, q2 (gone = Q1 ∪ Q2), thresholds t1, t2. For each root order[k] ∉ gone
    (the first node of U1 ∪ U2; B = gone ∪ order[:k] avoids both), the subtree with
    order[k] ∈ U1 and, unless ``sym`` (t1 = t2: the configuration (∅, ∅)), the one
    with order[k] ∈ U2 (the sides swapped). The ``crowded`` leaf checks the earlier
    roots and the charged nodes of the enumerated side (FORMAT.md: in a violating pair
    of least cost, grown maximal, Q_k = reach_r(S_k) still, so j ∈ Q_k has
    |N(j) ∩ U_k| ≤ d_j − t_k(j)). Returns the new count, OVERFLOW or WITNESS."""
    n = inmask.shape[0]
    gone = q1 | q2
    full = (U1 << np.uint64(n)) - U1 if n < 64 else ~ZERO
    C1 = core_after_removal(full & ~gone, gone, inmask, outmask, t1)
    C2 = C1 if sym else core_after_removal(full & ~gone, gone, inmask, outmask, t2)
    B = gone
    for k in range(n):
        b0 = U1 << np.uint64(order[k])
        if b0 & gone:
            continue
        ntok = _subtree(b0, B, (B & ~gone) | q1, C1,
                        core_after_removal(C2 & ~b0, b0 & C2, inmask, outmask, t2), inmask,
                        outmask, t1, t2, tokens, ntok)
        if ntok < 0:
            return ntok
        if not sym:
            ntok = _subtree(b0, B, (B & ~gone) | q2, C2,
                            core_after_removal(C1 & ~b0, b0 & C1, inmask, outmask, t1), inmask,
                            outmask, t2, t1, tokens, ntok)
            if ntok < 0:
                return ntok
        B |= b0
        C1 = core_after_removal(C1 & ~b0, b0 & C1, inmask, outmask, t1)
        C2 = C1 if sym else core_after_removal(C2 & ~b0, b0 & C2, inmask, outmask, t2)
    return ntok
