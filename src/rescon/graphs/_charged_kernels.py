"""Numba kernel recording the charged-set proof of (r, s)-robustness (n ≤ 64).

A pair (S1, S2) of cost c = |reach_r(S1)| + |reach_r(S2)| whose sets both keep an
r-closed member splits as S_k = U_k ∪ Q_k: Q_k = reach_r(S_k) (the charged nodes,
|Q1| + |Q2| = c) and U_k ≠ ∅ the rest, whose members i have
|N(i) \\ U_k| < t_k(i) = r + |N(i) ∩ Q_k| in-neighbours outside U_k. So no pair costs
less than s iff, for every *configuration* (Q1, Q2) of disjoint sets with
|Q1| + |Q2| ≤ s − 1, no two disjoint nonempty sets U1, U2 avoiding Q1 ∪ Q2 are closed
for the thresholds t1, t2: an r-robustness decision with per-node, per-side thresholds,
searched as ``_kernels.decide_step`` searches r-robustness, with its primitives (which
take per-node thresholds), plus two leaves: maximal pairs of least cost, and the capped
core (``capped_member``: what the other set may take from a member's candidates is
capped by its need; ER(30, 0.5), r = 8, s = 3: 15–39× fewer tokens with one member,
and with pairs, ``_branch`` and ``charged.charged_order`` 41.1M → 0.40M and
30.8M → 0.10M)
(certificates/FORMAT.md, ``cost_search`` with a ``charged_tree``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._kernels import (
    U1,
    ZERO,
    capped_core,
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
    ≥ t[i] in-neighbours outside S). The candidates are those of the *needy* members
    i (with need |N(i) \\ S| − t[i] + 1 > 0): N(i) ∩ P \\ S. The one sending to the
    most needy members, ties: the most in-neighbours outside S (hard to close: its S
    branch fails sooner), then a candidate of the member whose candidates exceed its
    need by the least (ties: the largest need). On ER(30, 0.5), r = ρ = 8, s = 3 with
    the capped leaf: 2.3× fewer tokens than the tightest member's candidate that
    takes an in-neighbour from the most nodes of Q (``branch_node``'s rule, its ties
    the other way), which the tree used before the capped leaf."""
    best, tight, needy, cand = np.int64(1 << 40), ZERO, ZERO, ZERO
    m = S
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        need = popcount(inmask[i] & ~S) - t[i] + 1
        if need > 0:
            c = inmask[i] & P & ~S
            needy |= U1 << np.uint64(i)
            cand |= c
            key = (popcount(c) - need) * 64 - need
            if key < best:
                best, tight = key, c
    u, best = -1, np.int64(-1)
    while cand:
        j = low_index(cand)
        bj = U1 << np.uint64(j)
        cand &= ~bj
        v = (popcount(outmask[j] & needy) * 128 + popcount(inmask[j] & ~S) * 2
             + (1 if tight & bj else 0))
        if v > best:
            best, u = v, j
    return u


@njit(cache=True, nogil=True)
def capped_member(S: np.uint64, P: np.uint64, Q: np.uint64, inmask: np.ndarray,
                  t1: np.ndarray, t2: np.ndarray) -> np.int64:
    """i·n + j for members i ≤ j of S whose :func:`capped_core` of Q is empty, with
    (c, sl) = (N(m) ∩ P \\ S, |c| − need_m) for m = i, j and
    need_m = |N(m) \\ S| − t1[m] + 1 > 0: the *capped* leaf −5 − (i·n + j)
    (certificates/FORMAT.md); a single member (i = j, the first by index) first, then
    the first pair; -1 when there is none.

    Proof: a pair's U1 ⊇ S is closed in V \\ X, so U1 ⊆ P, and m ∈ U1 keeps
    ≤ t1[m] − 1 in-neighbours outside U1: ≥ need_m of them lie in U1 \\ S ⊆ P \\ S,
    i.e. in c. U2 avoids U1, so |U2 ∩ c| ≤ |c| − need_m = sl; and U2 ⊆ Q is closed:
    each j ∈ U2 has ≥ d_j − t2[j] + 1 in-neighbours in U2, of which at most
    min(sl, |N(j) ∩ U2 ∩ c|) in c. So U2 lies in the capped core (peeling never
    removes a member of U2), and none exists when it is empty; none exists either when
    sl < 0 (m cannot be closed in U1; the checker takes that as an empty core too).
    (ER(30, 0.5), r = 8,
    s = 3: pairs, tried where no single member does, save ~35 % of the tokens.)"""
    n = inmask.shape[0]
    idx = np.empty(64, dtype=np.int64)
    cs = np.empty(64, dtype=np.uint64)
    sls = np.empty(64, dtype=np.int64)
    qs = np.empty(64, dtype=np.uint64)
    k = 0
    m = S
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        need = popcount(inmask[i] & ~S) - t1[i] + 1
        if need > 0:
            c = inmask[i] & P & ~S
            idx[k], cs[k], sls[k] = i, c, popcount(c) - need
            if sls[k] < 0:
                return i * n + i  # no U1 (never met below a -2 leaf: there S ⊆ P)
            qs[k] = capped_core(Q, c, sls[k], c, sls[k], inmask, t2)
            if qs[k] == ZERO:
                return i * n + i
            k += 1
    for a in range(k):
        for b in range(a + 1, k):
            # the pair's core lies in both single ones: peel from their intersection
            if capped_core(qs[a] & qs[b], cs[a], sls[a], cs[b], sls[b], inmask, t2) == ZERO:
                return idx[a] * n + idx[b]
    return -1


@njit(cache=True, nogil=True)
def _subtree(S0: np.uint64, B: np.uint64, R: np.uint64, P0: np.uint64, Q0: np.uint64,
             inmask: np.ndarray, outmask: np.ndarray, t1: np.ndarray, t2: np.ndarray,
             tokens: np.ndarray, ntok: int) -> int:
    """Record the decision subtree of one root and side, from S = S0, X = B (P0, Q0 the
    cores of V \\ X for t1 and of V \\ S0 \\ B for t2; R: the earlier roots and the
    charged nodes of S's side); the new token count, OVERFLOW when ``tokens`` is full
    or WITNESS when the state is a violating pair.

    Leaves: -1 when Q = ∅, -2 when S ⊄ P, -3 when the sizes cannot fit (``leaf_code``),
    -4 when S is ``crowded`` for R, −5 − (i·n + j) when the capped core of Q for the
    members i ≤ j of S is empty (``capped_member``); otherwise a candidate u of the members with
    ≥ t1 outside in-neighbours (``_branch``): u into S first, then into X."""
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
        if leaf == 0:
            ij = capped_member(S, P, Q, inmask, t1, t2)
            if ij >= 0:
                leaf = -5 - ij
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
