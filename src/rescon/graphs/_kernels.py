"""Numba kernels on uint64 bitmasks (n ≤ 64) for the exact robustness searches.

A set of nodes is a ``uint64`` whose bit i stands for node i; ``inmask[i]`` is the
set of in-neighbours of i. All kernels are resumable: their whole state lives in
arrays owned by the Python driver, so a search can run in slices, report progress
and stop at a time limit without losing what it proved.
"""

from __future__ import annotations

import numpy as np
from numba import njit

U1 = np.uint64(1)
ZERO = np.uint64(0)

# status codes of the decision search (state[ST_STATUS])
RUNNING, SAT, UNSAT, NEED_ROOM = 0, 1, 2, 3
# indices into the int64 state array
ST_SP, ST_ROOT, ST_NTOK, ST_STATUS, ST_NODES = 0, 1, 2, 3, 4
STATE_LEN = 5
# indices into the uint64 buffer: current B, witness S1, witness S2
UB_B, UB_W1, UB_W2 = 0, 1, 2
UBUF_LEN = 3


@njit(cache=True, inline="always")
def popcount(x: np.uint64) -> np.int64:
    """Number of set bits of a uint64 (SWAR)."""
    x = x - ((x >> np.uint64(1)) & np.uint64(0x5555555555555555))
    x = (x & np.uint64(0x3333333333333333)) + ((x >> np.uint64(2)) & np.uint64(0x3333333333333333))
    x = (x + (x >> np.uint64(4))) & np.uint64(0x0F0F0F0F0F0F0F0F)
    return np.int64((x * np.uint64(0x0101010101010101)) >> np.uint64(56))


@njit(cache=True, inline="always")
def lowest_bit_index(x: np.uint64) -> np.int64:
    """Index of the lowest set bit of a nonzero uint64."""
    return popcount((x & (~x + U1)) - U1)


@njit(cache=True)
def core(U: np.uint64, inmask: np.ndarray, n: int, r: int) -> np.uint64:
    """Largest r-closed subset of U: peel every i ∈ U with |N(i) \\ U| ≥ r.

    Closed sets (no member has r in-neighbours outside) are closed under union,
    so the fixpoint is the unique largest closed subset of U.
    """
    changed = True
    while changed:
        changed = False
        for i in range(n):
            b = U1 << np.uint64(i)
            if U & b and popcount(inmask[i] & ~U) >= r:
                U &= ~b
                changed = True
    return U


@njit(cache=True)
def max_outside(S: np.uint64, inmask: np.ndarray, n: int) -> np.int64:
    """e(S) = max over i ∈ S of |N(i) \\ S| (0 for the empty set)."""
    best = 0
    for i in range(n):
        if S & (U1 << np.uint64(i)):
            c = popcount(inmask[i] & ~S)
            if c > best:
                best = c
    return best


@njit(cache=True)
def decide_step(
    inmask: np.ndarray,
    order: np.ndarray,
    r: int,
    stack_S: np.ndarray,
    stack_X: np.ndarray,
    stack_depth: np.ndarray,
    state: np.ndarray,
    ubuf: np.ndarray,
    tokens: np.ndarray,
    record: bool,
    max_nodes: int,
    progress: np.ndarray,
) -> None:
    """Advance the branch-and-bound for "is there a pair of disjoint closed sets?".

    G is **not** r-robust iff there are disjoint nonempty S1, S2, both r-closed.
    Root k fixes order[k] ∈ S1 as the first node of S1 ∪ S2 (B = order[:k] is
    outside both). A state (S, X) asks for a closed S1 ⊇ S avoiding X; S2 is
    implicit: it must lie in core(V \\ S \\ B). Leaves (certificates/FORMAT.md):
    -1 when core(V \\ S \\ B) = ∅, -2 when S ⊄ core(V \\ X). Otherwise a member i
    of S with ≥ r outside in-neighbours needs one more of them inside: branch on
    u ∈ N(i) ∩ core(V \\ X) \\ S (include first, then exclude). A state without
    such a member is closed and, with S2 = core(V \\ S \\ B) ≠ ∅, a witness.

    Runs until ``max_nodes`` states were expanded, the token buffer is full
    (status NEED_ROOM), or the search ends (SAT / UNSAT).
    """
    n = inmask.shape[0]
    full = (U1 << np.uint64(n)) - U1 if n < 64 else ~ZERO
    sp = state[ST_SP]
    root = state[ST_ROOT]
    ntok = state[ST_NTOK]
    done = 0
    while done < max_nodes:
        if record and ntok >= tokens.shape[0]:
            state[ST_STATUS] = NEED_ROOM
            break
        if sp == 0:
            if root >= n:
                state[ST_STATUS] = UNSAT
                break
            B = ZERO
            for j in range(root):
                B |= U1 << np.uint64(order[j])
            ubuf[UB_B] = B
            stack_S[0] = U1 << np.uint64(order[root])
            stack_X[0] = B
            stack_depth[0] = 0
            sp = 1
            root += 1
        sp -= 1
        S = stack_S[sp]
        X = stack_X[sp]
        depth = stack_depth[sp]
        B = ubuf[UB_B]
        done += 1
        Q = core(full & ~S & ~B, inmask, n, r)
        if Q == ZERO:
            if record:
                tokens[ntok] = -1
            ntok += 1
            progress[0] += 0.5 ** depth / n
            continue
        P = core(full & ~X, inmask, n, r)
        if S & ~P:
            if record:
                tokens[ntok] = -2
            ntok += 1
            progress[0] += 0.5 ** depth / n
            continue
        best_slack = n + 1
        best_cand = ZERO
        for i in range(n):
            if S & (U1 << np.uint64(i)):
                out = popcount(inmask[i] & ~S)
                if out >= r:
                    cand = inmask[i] & P & ~S
                    slack = popcount(cand) - (out - r + 1)
                    if slack < best_slack:
                        best_slack = slack
                        best_cand = cand
        if best_cand == ZERO:
            ubuf[UB_W1] = S
            ubuf[UB_W2] = Q
            state[ST_STATUS] = SAT
            break
        u = lowest_bit_index(best_cand)
        if record:
            tokens[ntok] = u
        ntok += 1
        bu = U1 << np.uint64(u)
        stack_S[sp] = S
        stack_X[sp] = X | bu
        stack_depth[sp] = depth + 1
        stack_S[sp + 1] = S | bu
        stack_X[sp + 1] = X
        stack_depth[sp + 1] = depth + 1
        sp += 2
    state[ST_SP] = sp
    state[ST_ROOT] = root
    state[ST_NTOK] = ntok
    state[ST_NODES] += done
