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
def size_bound(S: np.uint64, Q: np.uint64, W: np.uint64, inmask: np.ndarray, n: int, r: int) -> bool:
    """True when a closed S1 ⊇ S and a nonempty closed S2 ⊆ Q cannot both fit,
    disjoint, in W = core(V \\ X) ∪ core(V \\ S \\ B).

    S1 holds S and, for each i ∈ S, ≥ |N(i) \\ S| − r + 1 more of i's in-neighbours:
    |S1| ≥ |S| + max_{i∈S} (|N(i) \\ S| − r + 1)⁺. A closed set holding j holds
    ≥ d_j − r + 1 of j's in-neighbours: |S2| ≥ min_{j∈Q} max(1, d_j − r + 2).
    """
    extra = 0
    need2 = n + 1
    for i in range(n):
        b = U1 << np.uint64(i)
        if S & b:
            m = popcount(inmask[i] & ~S) - r + 1
            if m > extra:
                extra = m
        if Q & b:
            m = popcount(inmask[i]) - r + 2
            if m < need2:
                need2 = m
    if need2 < 1:
        need2 = 1
    return popcount(S) + extra + need2 > popcount(W)


@njit(cache=True)
def fewest_in_neighbours(cand: np.uint64, inmask: np.ndarray, n: int) -> np.int64:
    """The node of ``cand`` with the fewest in-neighbours (the branching choice:
    such nodes are the cheapest to keep closed, so witnesses surface early)."""
    u = -1
    best = n + 1
    for j in range(n):
        if cand & (U1 << np.uint64(j)):
            v = popcount(inmask[j])
            if v < best:
                best = v
                u = j
    return u


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
    -1 when core(V \\ S \\ B) = ∅, -2 when S ⊄ core(V \\ X), -3 when the sizes
    cannot fit (``size_bound``). Otherwise a member i
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
        if size_bound(S, Q, P | Q, inmask, n, r):
            if record:
                tokens[ntok] = -3
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
        u = fewest_in_neighbours(best_cand, inmask, n)
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


@njit(cache=True)
def min_pair_cost(inmask: np.ndarray, r: int):
    """Exact s*(r) by the O(n·2^n) subset DP (n ≤ 26 or so).

    c(S) = |reach_r(S)|; a set is *open* when c(S) < |S| (some member closed).
    h(U) = min over open S ⊆ U of c(S) (subset-min transform). Then
    s*(r) = min over open S1 of c(S1) + h(V \\ S1), or n when no two disjoint open
    sets exist. Returns (s*, S1, S2) with S1 = S2 = 0 when s* = n from exhaustion.
    """
    n = inmask.shape[0]
    N = np.int64(1) << n
    big = np.int8(127)
    c = np.empty(N, dtype=np.int8)
    h = np.empty(N, dtype=np.int8)
    arg = np.empty(N, dtype=np.int64)
    c[0] = 0
    h[0] = big
    arg[0] = 0
    for S in range(1, N):
        su = np.uint64(S)
        cnt = 0
        for i in range(n):
            if su & (U1 << np.uint64(i)):
                if popcount(inmask[i] & ~su) >= r:
                    cnt += 1
        c[S] = cnt
        h[S] = big if cnt == popcount(su) else cnt
        arg[S] = S
    for b in range(n):
        bit = np.int64(1) << b
        for S in range(N):
            if S & bit:
                T = S ^ bit
                if h[T] < h[S]:
                    h[S] = h[T]
                    arg[S] = arg[T]
    full = N - 1
    best = np.int64(n)
    w1 = np.int64(0)
    w2 = np.int64(0)
    for S in range(1, N):
        if c[S] < popcount(np.uint64(S)):  # S is open
            rest = full ^ S
            if h[rest] != big:
                v = np.int64(c[S]) + np.int64(h[rest])
                if v < best:
                    best = v
                    w1 = S
                    w2 = arg[rest]
    return best, w1, w2
