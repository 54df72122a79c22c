"""Numba kernels on uint64 bitmasks (n ≤ 64) for the exact robustness searches.

A set of nodes is a ``uint64`` whose bit i stands for node i; ``inmask[i]`` is the
set of in-neighbours of i. All kernels are resumable: their whole state lives in
arrays owned by the Python driver, so a search can run in slices, report progress
and stop at a time limit without losing what it proved.

The decision search's primitives (``core_after_removal``, ``size_bound``,
``tightest_member``) take per-node thresholds t: a set is closed when each member i has
fewer than t[i] in-neighbours outside it. The decision search passes the integer r
(t ≡ r, compiled apart: no per-node loads in its hot loops); the charged-set search
(``_charged_kernels``) passes the array t(i) = r + |N(i) ∩ Q|, and every statement below
made for r holds with r replaced by t[i] at each node i.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numba.extending import overload

U1 = np.uint64(1)
ZERO = np.uint64(0)

# status codes of the decision search (state[ST_STATUS])
RUNNING, SAT, UNSAT, NEED_ROOM = 0, 1, 2, 3
# indices into the int64 state array
# (ST_END: one past the last root to search — n for the whole search, less for a part)
ST_SP, ST_ROOT, ST_NTOK, ST_STATUS, ST_NODES, ST_END = 0, 1, 2, 3, 4, 5
STATE_LEN = 6
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
def low_index(x: np.uint64) -> np.int64:
    """Index of the lowest set bit of a nonzero uint64."""
    return popcount((x & (~x + U1)) - U1)


def threshold(t: int | np.ndarray, i: int) -> int:
    """Node i's threshold: t[i] for per-node thresholds, t itself for one for all."""
    return t if np.ndim(t) == 0 else t[i]


@overload(threshold, inline="always")
def _threshold(t, i):
    """Compiled :func:`threshold`, chosen by t's type."""
    if isinstance(t, types.Integer):
        return lambda t, i: t
    return lambda t, i: t[i]


@njit(cache=True, nogil=True)
def core(U: np.uint64, inmask: np.ndarray, r: int) -> np.uint64:
    """Largest r-closed subset of U: peel every i ∈ U with |N(i) \\ U| ≥ r.

    Closed sets (no member has r in-neighbours outside) are closed under union,
    so the fixpoint is the unique largest closed subset of U.
    """
    changed = True
    while changed:
        changed = False
        m = U
        while m:
            i = low_index(m)
            b = U1 << np.uint64(i)
            m &= ~b
            if popcount(inmask[i] & ~U) >= r:
                U &= ~b
                changed = True
    return U


@njit(cache=True, nogil=True)
def core_after_removal(U: np.uint64, removed: np.uint64, inmask: np.ndarray,
                       outmask: np.ndarray, t: int | np.ndarray) -> np.uint64:
    """The largest A ⊆ U whose members i have < t[i] in-neighbours outside A, when U is
    such a set (closed for the thresholds t) minus ``removed``: only out-neighbours of
    removed nodes can have gained outside in-neighbours, so peel from a worklist. Such
    sets are closed under union, so the result is unique; with t ≡ r it is core(U)."""
    work = ZERO
    m = removed
    while m:
        u = low_index(m)
        m &= ~(U1 << np.uint64(u))
        work |= outmask[u]
    work &= U
    while work:
        i = low_index(work)
        b = U1 << np.uint64(i)
        work &= ~b
        if popcount(inmask[i] & ~U) >= threshold(t, i):
            U &= ~b
            work |= outmask[i] & U
    return U


@njit(cache=True, nogil=True)
def size_bound(S: np.uint64, Q: np.uint64, W: np.uint64, inmask: np.ndarray,
               t1: int | np.ndarray, t2: int | np.ndarray) -> bool:
    """True when a closed S1 ⊇ S (thresholds t1) and a nonempty closed S2 ⊆ Q
    (thresholds t2) cannot both fit, disjoint, in W = core(V \\ X) ∪ core(V \\ S \\ B).

    S1 holds S and, for each i ∈ S, ≥ |N(i) \\ S| − r + 1 more of i's in-neighbours:
    |S1| ≥ |S| + max_{i∈S} (|N(i) \\ S| − r + 1)⁺. A closed set holding j holds
    ≥ d_j − r + 1 of j's in-neighbours: |S2| ≥ min_{j∈Q} max(1, d_j − r + 2).
    (r: t1[i] for i ∈ S, t2[j] for j ∈ Q.)
    """
    extra = 0
    m = S
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        e = popcount(inmask[i] & ~S) - threshold(t1, i) + 1
        if e > extra:
            extra = e
    need2 = 1 << 30
    m = Q
    while m:
        j = low_index(m)
        m &= ~(U1 << np.uint64(j))
        e = popcount(inmask[j]) - threshold(t2, j) + 2
        if e < need2:
            need2 = e
    if need2 < 1:
        need2 = 1
    return popcount(S) + extra + need2 > popcount(W)


@njit(cache=True, nogil=True, inline="always")
def leaf_code(S: np.uint64, P: np.uint64, Q: np.uint64, inmask: np.ndarray,
              t1: int | np.ndarray, t2: int | np.ndarray) -> int:
    """The leaf token of a decision state (S, P, Q), 0 when it is none
    (certificates/FORMAT.md): -1 when Q = ∅ (no room for S2), -2 when S ⊄ P (no closed
    S1 ⊇ S), -3 when the sizes cannot fit (``size_bound``)."""
    if Q == ZERO:
        return -1
    if S & ~P:
        return -2
    if size_bound(S, Q, P | Q, inmask, t1, t2):
        return -3
    return 0


@njit(cache=True, nogil=True)
def crowded(S: np.uint64, R: np.uint64, inmask: np.ndarray, t: int | np.ndarray) -> bool:
    """True when a node j of R has more than d_j − t[j] in-neighbours in S, i.e. fewer
    than t[j] outside S ∪ {j}: j would be closed in S1 ∪ {j} for any S1 ⊇ S.

    Maximality (the prune of the searches that own no recorded leaf for it): adding such
    a j ∉ S1 ∪ S2 to S1 charges nothing (j's outside in-neighbours stay < t[j]) and can
    only uncharge members of S1 (they gain an inside in-neighbour); the members of S2
    keep theirs. So every pair, repeatedly saturated, becomes one whose cost (number of
    charged members) is no larger, whose sets keep their closed members, and where no
    node outside S1 ∪ S2 has more than d_j − t[j] in-neighbours in S1 or in S2
    (saturation ends: S1 ∪ S2 grows). Searching only such *maximal* pairs loses no
    minimum and no violating pair; a state with S ⊆ S1 and R known to avoid S1 ∪ S2
    (earlier roots, excluded nodes S2 cannot take) holds none when crowded."""
    m = R
    while m:
        j = low_index(m)
        m &= ~(U1 << np.uint64(j))
        if popcount(inmask[j] & S) > popcount(inmask[j]) - threshold(t, j):
            return True
    return False


@njit(cache=True, nogil=True)
def capped_core(Q: np.uint64, c1: np.uint64, sl1: int, c2: np.uint64, sl2: int,
                inmask: np.ndarray, t: int | np.ndarray) -> np.uint64:
    """The largest Q' ⊆ Q whose members j have, for (c, sl) = (c1, sl1) and (c2, sl2),
    |N(j) ∩ Q' \\ c| + min(sl, |N(j) ∩ Q' ∩ c|) ≥ d_j − t[j] + 1, by peeling (the left
    sides only grow with Q', so such sets are closed under union). Every closed set
    (thresholds t) inside Q with at most sl_k members in c_k (k = 1, 2) lies in it
    (``_charged_kernels.capped_member``, :func:`capped_single`)."""
    changed = True
    while changed and Q:
        changed = False
        m = Q
        while m:
            j = low_index(m)
            b = U1 << np.uint64(j)
            m &= ~b
            inside = inmask[j] & Q
            want = popcount(inmask[j]) - threshold(t, j) + 1
            x1 = min(popcount(inside & c1), sl1)
            x2 = min(popcount(inside & c2), sl2)
            if popcount(inside & ~c1) + x1 < want or popcount(inside & ~c2) + x2 < want:
                Q &= ~b
                changed = True
    return Q


@njit(cache=True, nogil=True)
def capped_single(S: np.uint64, P: np.uint64, Q: np.uint64, inmask: np.ndarray,
                  t: int | np.ndarray) -> bool:
    """True when some member i of S with need_i = |N(i) \\ S| − t[i] + 1 > 0 has
    sl_i = |c_i| − need_i < 0 or an empty :func:`capped_core` of Q for
    (c_i, sl_i), c_i = N(i) ∩ P \\ S: then no pair lies below the decision state
    (S, P, Q) (proof: ``_charged_kernels.capped_member``, the charged tree's capped
    leaf; thresholds t on both sides). The decision search prunes with it while it
    records no tree (ER(50, 0.5), r = 13: 1.1·10⁹ states, 3.7–4.1·10⁷ with it)."""
    m = S
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        need = popcount(inmask[i] & ~S) - threshold(t, i) + 1
        if need > 0:
            c = inmask[i] & P & ~S
            sl = popcount(c) - need
            if sl < 0 or capped_core(Q, c, sl, c, sl, inmask, t) == ZERO:
                return True
    return False


@njit(cache=True, nogil=True)
def branch_node(cand: np.uint64, Q: np.uint64, inmask: np.ndarray, outmask: np.ndarray) -> np.int64:
    """The candidate that, put into S1, takes an in-neighbour from the most nodes of
    Q (so S2's room shrinks fastest); ties: fewest in-neighbours."""
    u = -1
    best = np.int64(-(1 << 40))
    m = cand
    while m:
        j = low_index(m)
        m &= ~(U1 << np.uint64(j))
        v = popcount(outmask[j] & Q) * 128 - popcount(inmask[j])
        if v > best:
            best = v
            u = j
    return u


@njit(cache=True, nogil=True)
def prefix_mask(order: np.ndarray, k: int) -> np.uint64:
    """The set {order[0], ..., order[k-1]}."""
    B = ZERO
    for j in range(k):
        B |= U1 << np.uint64(order[j])
    return B


@njit(cache=True, nogil=True)
def tightest_member(members: np.uint64, S: np.uint64, allowed: np.uint64,
                    inmask: np.ndarray, t: int | np.ndarray, n: int):
    """Among ``members`` (⊆ S) i with ≥ t[i] in-neighbours outside S, the one whose
    candidates (in-neighbours in ``allowed`` \\ S) exceed its need
    (|N(i) \\ S| − t[i] + 1) by the least. Returns (slack, candidates); (n + 1, 0) when
    there is none."""
    best_slack = n + 1
    best_cand = ZERO
    m = members
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        outside = popcount(inmask[i] & ~S)
        ti = threshold(t, i)
        if outside >= ti:
            cand = inmask[i] & allowed & ~S
            slack = popcount(cand) - (outside - ti + 1)
            if slack < best_slack:
                best_slack = slack
                best_cand = cand
    return best_slack, best_cand


# rows of the search stack
SK_S, SK_X, SK_P, SK_Q, SK_DP, SK_DQ = 0, 1, 2, 3, 4, 5
STACK_WIDTH = 6


@njit(cache=True, nogil=True)
def decide_step(
    inmask: np.ndarray,
    outmask: np.ndarray,
    order: np.ndarray,
    r: int,
    stack: np.ndarray,
    stack_depth: np.ndarray,
    state: np.ndarray,
    ubuf: np.ndarray,
    tokens: np.ndarray,
    record: bool,
    max_nodes: int,
    progress: np.ndarray,
) -> None:
    """Advance the branch-and-bound for "are there two disjoint closed sets?".

    G is **not** r-robust iff there are disjoint nonempty S1, S2, both r-closed.
    Root k fixes order[k] ∈ S1 as the first node of S1 ∪ S2 (B = order[:k] is
    outside both). A state (S, X) asks for a closed S1 ⊇ S avoiding X; S2 is
    implicit: it must lie in Q = core(V \\ S \\ B), and S1 in P = core(V \\ X).
    Leaves (certificates/FORMAT.md): -1 when Q = ∅, -2 when S ⊄ P, -3 when the
    sizes cannot fit (``leaf_code``); without a recorded tree (the checker replays
    none of it) also when S is ``crowded`` for X \\ Q (nodes in neither set of any
    pair below: S2 ⊆ Q, and Q only shrinks; ER(40, 0.5), r = 11: 20M states, 15M
    with it) and when a member's capped core is empty (``capped_single``).
    Otherwise a member i of S with ≥ r outside
    in-neighbours needs one more of them inside: take the member with the least
    slack and branch on one of its candidates u ∈ N(i) ∩ P \\ S (``branch_node``),
    include first, then exclude. A state without such a member is closed and,
    with S2 = Q ≠ ∅, a witness. Without a recorded tree, a member of slack 0 takes
    all its candidates at once (one child, S + them, at the same depth), where the
    tree would branch on each and close every exclude child at once by leaf -2.
    Proof: every closed S1 ⊇ S avoiding X lies in P (the largest closed set avoiding
    X), so i's outside in-neighbours are ≥ |N(i) \\ S| − |N(i) ∩ (S1 \\ S)| with
    S1 \\ S ⊆ P \\ S; i needs |N(i) \\ S| − r + 1 of its candidates N(i) ∩ P \\ S in S1,
    and with slack 0 that is all of them (ER(40, 0.5), r = 11: 14.7M states, 9.6M
    with it, in 2.5× less time).

    P and Q are maintained incrementally: a child differs from its parent by the
    nodes it adds to S removed from Q (include) or one node removed from P (exclude).
    Runs until ``max_nodes`` states were expanded, the token buffer is full (status
    NEED_ROOM), or the search ends (SAT / UNSAT).
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
            if root >= state[ST_END]:
                state[ST_STATUS] = UNSAT
                break
            B = prefix_mask(order, root)
            ubuf[UB_B] = B
            S0 = U1 << np.uint64(order[root])
            stack[0, SK_S] = S0
            stack[0, SK_X] = B
            stack[0, SK_P] = core(full & ~B, inmask, r)
            stack[0, SK_Q] = core(full & ~B & ~S0, inmask, r)
            stack[0, SK_DP] = ZERO
            stack[0, SK_DQ] = ZERO
            stack_depth[0] = 0
            sp = 1
            root += 1
        sp -= 1
        S = stack[sp, SK_S]
        X = stack[sp, SK_X]
        P = stack[sp, SK_P]
        Q = stack[sp, SK_Q]
        if stack[sp, SK_DP]:
            P = core_after_removal(P & ~stack[sp, SK_DP], stack[sp, SK_DP], inmask, outmask, r)
        if stack[sp, SK_DQ]:
            Q = core_after_removal(Q & ~stack[sp, SK_DQ], stack[sp, SK_DQ], inmask, outmask, r)
        depth = stack_depth[sp]
        done += 1
        leaf = leaf_code(S, P, Q, inmask, r, r)
        if leaf == 0 and not record and crowded(S, X & ~Q, inmask, r):
            leaf = -4
        if leaf == 0 and not record and capped_single(S, P, Q, inmask, r):
            leaf = -5
        if leaf != 0:
            if record:
                tokens[ntok] = leaf
            ntok += 1
            progress[0] += 0.5 ** depth / n
            continue
        best_slack, best_cand = tightest_member(S, S, P, inmask, r, n)
        if best_cand == ZERO:
            ubuf[UB_W1] = S
            ubuf[UB_W2] = Q
            state[ST_STATUS] = SAT
            break
        if best_slack == 0 and not record:
            # forced: S + every candidate, at the same depth (it holds the whole share)
            stack[sp, SK_S] = S | best_cand
            stack[sp, SK_P] = P
            stack[sp, SK_Q] = Q
            stack[sp, SK_DP] = ZERO
            stack[sp, SK_DQ] = best_cand & Q
            sp += 1
            continue
        u = branch_node(best_cand, Q, inmask, outmask)
        if record:
            tokens[ntok] = u
        ntok += 1
        bu = U1 << np.uint64(u)
        # exclude child (expanded second): X + u, P loses u
        stack[sp, SK_S] = S
        stack[sp, SK_X] = X | bu
        stack[sp, SK_P] = P
        stack[sp, SK_Q] = Q
        stack[sp, SK_DP] = bu
        stack[sp, SK_DQ] = ZERO
        stack_depth[sp] = depth + 1
        # include child (expanded first): S + u, Q loses u
        stack[sp + 1, SK_S] = S | bu
        stack[sp + 1, SK_X] = X
        stack[sp + 1, SK_P] = P
        stack[sp + 1, SK_Q] = Q
        stack[sp + 1, SK_DP] = ZERO
        stack[sp + 1, SK_DQ] = bu & Q
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
    arg = np.empty(N, dtype=np.int32)
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
        arg[S] = np.int32(S)
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


@njit(cache=True, nogil=True)
def core_free(U: np.uint64, free: np.uint64, inmask: np.ndarray, r: int) -> np.uint64:
    """Largest subset A of U whose members have < r in-neighbours outside A ∪ free
    (the nodes of ``free`` count as inside and are never peeled)."""
    changed = True
    while changed:
        changed = False
        m = U
        while m:
            i = low_index(m)
            b = U1 << np.uint64(i)
            m &= ~b
            if popcount(inmask[i] & ~(U | free)) >= r:
                U &= ~b
                changed = True
    return U


@njit(cache=True, nogil=True)
def core_hard(U: np.uint64, free: np.uint64, hard: np.uint64, inmask: np.ndarray, r: int,
              slack: int) -> np.uint64:
    """Largest A ⊆ U whose members i have |N(i) ∩ hard| < r and
    |N(i) \\ (A ∪ free)| < r + slack (the nodes of ``free`` count as inside).

    Bound for the uncharged part A of a set S = A ∪ Q ∪ P with P ⊆ free, Q ⊆ U \\ A
    unknown, |Q| ≤ slack and ``hard`` ∩ S = ∅: a member i of A with fewer than r
    in-neighbours outside S has |N(i) ∩ hard| ≤ |N(i) \\ S| < r and
    |N(i) \\ (A ∪ free)| ≤ |N(i) \\ S| + |Q| < r + slack; such sets are closed under
    union, so the fixpoint of peeling holds every such A. With hard = ∅ this is
    :func:`core_free`; the hard part is what the slack may not excuse.
    """
    m = U
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        if popcount(inmask[i] & hard) >= r:
            U &= ~(U1 << np.uint64(i))
    return core_free(U, free, inmask, r + slack)


@njit(cache=True, nogil=True)
def cheapest_side(U: np.uint64, least: int, budget: int, inmask: np.ndarray, r: int,
                  out: np.ndarray) -> np.int64:
    """Fewest charged nodes Q2 ⊆ U (between ``least``, already proven necessary, and
    ``budget``) such that some nonempty A2 ⊆ U \\ Q2 has every member with < r
    in-neighbours outside A2 ∪ Q2; -1 if none.

    Then S2 = A2 ∪ Q2 has |reach_r(S2)| ≤ |Q2| and a closed member. Tries |Q2| = least,
    least + 1, ... by enumerating subsets of U; writes (A2, Q2) into ``out``.
    """
    if least == 0:
        A = core(U, inmask, r)
        if A != ZERO:
            out[0] = A
            out[1] = ZERO
            return 0
    members = np.empty(64, dtype=np.int64)
    k = 0
    m = U
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        members[k] = i
        k += 1
    idx = np.empty(64, dtype=np.int64)
    for size in range(max(least, 1), min(budget, k) + 1):
        for t in range(size):
            idx[t] = t
        while True:
            Q2 = ZERO
            for t in range(size):
                Q2 |= U1 << np.uint64(members[idx[t]])
            A = core_free(U & ~Q2, Q2, inmask, r)
            if A != ZERO:
                out[0] = A
                out[1] = Q2
                return size
            # next combination
            t = size - 1
            while t >= 0 and idx[t] == k - size + t:
                t -= 1
            if t < 0:
                break
            idx[t] += 1
            for v in range(t + 1, size):
                idx[v] = idx[v - 1] + 1
    return -1


@njit(cache=True, nogil=True)
def capped_charged(S: np.uint64, X: np.uint64, M: np.uint64, W: np.uint64,
                   inmask: np.ndarray, r: int, budget: int) -> bool:
    """True when no S2 below the charged-set search's state (S, X, M) fits: some member
    i of M (closed in S1) with need_i = |N(i) \\ S| − r + 1 > 0 has sl_i = |c_i| − need_i
    < 0 or an empty :func:`capped_core` of W for (c_i, sl_i) at threshold r + budget,
    c_i = N(i) \\ S \\ X. W ⊇ A2, the uncharged part of S2 (``core_hard`` below).

    Proof: i keeps ≤ r − 1 in-neighbours outside S1 ⊆ V \\ X, so ≥ need_i of c_i lie in
    S1 and S2 (disjoint) holds ≤ sl_i of them. A member j of A2 has ≥ d_j − r + 1
    in-neighbours in S2 = A2 ∪ Q2, |Q2| ≤ budget: |N(j) ∩ A2 \\ c_i| +
    min(sl_i, |N(j) ∩ A2 ∩ c_i|) + budget ≥ d_j − r + 1, the capped condition at
    threshold r + budget; A2 ≠ ∅ lies in the capped core."""
    m = M
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        need = popcount(inmask[i] & ~S) - r + 1
        if need > 0:
            c = inmask[i] & ~S & ~X
            sl = popcount(c) - need
            if sl < 0 or capped_core(W, c, sl, c, sl, inmask, r + budget) == ZERO:
                return True
    return False


# rows of the cost-search stack
CK_S, CK_X, CK_C, CK_M = 0, 1, 2, 3
# the charged-set search's hint: a lower bound on S2's charges, k, proven at the parent
CK_K = 4
COST_STACK_WIDTH = 5
# indices into the int64 state of the cost search
CS_SP, CS_ROOT, CS_STATUS, CS_NODES, CS_BEST, CS_END = 0, 1, 2, 3, 4, 5
# the sized search's current size combination (|S1|, |S2|; 0: no root started yet)
# and its number of recorded tokens
CS_S1, CS_S2, CS_NTOK = 6, 7, 8
# 1: the sized search ends when its stack empties (a part of pending frames alone, as
# the distributed s* search splits it off)
CS_ALONE = 9
COST_STATE_LEN = 10
# uint64 buffer: current B, best S1, best S2
CB_B, CB_W1, CB_W2 = 0, 1, 2


@njit(cache=True, nogil=True)
def min_cost_step(
    inmask: np.ndarray,
    outmask: np.ndarray,
    order: np.ndarray,
    r: int,
    lower: int,
    stack: np.ndarray,
    stack_depth: np.ndarray,
    state: np.ndarray,
    ubuf: np.ndarray,
    max_nodes: int,
    progress: np.ndarray,
) -> None:
    """Advance the branch and bound for s*(r) = min |reach_r(S1)| + |reach_r(S2)| over
    disjoint pairs whose sets both keep an r-closed member.

    A pair of cost ≤ c is: disjoint S_k = A_k ∪ Q_k with charged nodes Q_k (paid
    for, unconstrained), |Q1| + |Q2| ≤ c, and every member of A_k ≠ ∅ with < r
    in-neighbours outside S_k. S1 is enumerated from root order[k] (the first node of
    S1 ∪ S2; B = order[:k] is outside both), state (S, X, C, M): S ⊆ S1, X ∩ S1 = ∅,
    C ⊆ S charged, M ⊆ S must be closed. Unmarked members with r in-neighbours in X
    can no longer be closed: they are charged too (F). The budget b = best − 1 − |C| −
    |F| bounds the charges still to come (``best`` is the incumbent, state[CS_BEST]):

    * S2's uncharged part A2 has |N(i) \\ A2| ≤ r − 1 + |Q2| for its members, so it
      lies in core_{r+k}(V \\ S \\ B) for k = |Q2|: the least k making that core
      nonempty is a lower bound on |Q2|, and k > b prunes. The core only shrinks as S
      grows (B is fixed within a root), so a child starts the count at its parent's k
      (stack column CK_K), skipping the peels that emptied there (ER(40, 0.5), r = 11,
      below cap 2: same 3.6M states, ~7 % less CPU);
    * S1's uncharged part avoids X and has |N(i) \\ (A1 ∪ C ∪ F)| ≤ r − 1 + (b − k), so
      M ⊆ core at threshold r + b − k of V \\ X with C ∪ F counted inside;
    * in both cores, a node with r in-neighbours where its set cannot reach (S ∪ B for
      S2, X for S1) is peeled whatever the charges (``core_hard``): the charges only
      excuse in-neighbours that may still join the set;
    * only maximal pairs are searched (``crowded``: a pair and its saturation are found
      in their own roots, sides swapped if need be): a node of B, outside both sets,
      with more than d − r in-neighbours in S prunes (ER(40, 0.5), r = 11, below cap 2:
      root 1 took 90M states, 12M with this prune).

    An unmarked member of S with ≥ r outside in-neighbours is charged or marked
    closed (two branches); a member of M with ≥ r outside in-neighbours takes one of
    its in-neighbours (include / exclude), all of them at once when it has no slack:
    its candidates N(i) \\ S \\ X are exactly the |N(i) \\ S| − r + 1 it needs in S1 to
    stay closed (S1 avoids X), as in :func:`decide_step` (ER(40, 0.5), r = 11, below
    cap 2, every root but the first: 19.2M states, 12.3M with it). When nothing is
    left to fix, the best S2 outside S ∪ B is found by ``cheapest_side``; a cheaper pair
    becomes the incumbent.
    """
    n = inmask.shape[0]
    full = (U1 << np.uint64(n)) - U1 if n < 64 else ~ZERO
    sp = state[CS_SP]
    root = state[CS_ROOT]
    done = 0
    side = np.zeros(2, dtype=np.uint64)
    while done < max_nodes:
        if sp == 0:
            if root >= state[CS_END] or state[CS_BEST] <= lower:
                state[CS_STATUS] = UNSAT
                break
            B = prefix_mask(order, root)
            ubuf[CB_B] = B
            stack[0, CK_S] = U1 << np.uint64(order[root])
            stack[0, CK_X] = B
            stack[0, CK_C] = ZERO
            stack[0, CK_M] = ZERO
            stack[0, CK_K] = ZERO
            stack_depth[0] = 0
            sp = 1
            root += 1
        sp -= 1
        S = stack[sp, CK_S]
        X = stack[sp, CK_X]
        C = stack[sp, CK_C]
        M = stack[sp, CK_M]
        k = np.int64(stack[sp, CK_K])
        depth = stack_depth[sp]
        B = ubuf[CB_B]
        done += 1
        nc = popcount(C)
        # unmarked members that can no longer be closed must be charged
        F = ZERO
        m = S & ~C & ~M
        while m:
            i = low_index(m)
            m &= ~(U1 << np.uint64(i))
            if popcount(inmask[i] & X) >= r:
                F |= U1 << np.uint64(i)
        budget = state[CS_BEST] - 1 - nc - popcount(F)
        prune = budget < 0 or crowded(S, B, inmask, r)
        if not prune:
            # S2 needs ≥ k charges when core_{r+k−1}(V \ S \ B) is empty
            rest = full & ~S & ~B
            W = ZERO
            while k <= budget:
                W = core_hard(rest, ZERO, S | B, inmask, r, k)
                if W != ZERO:
                    break
                k += 1
            if k > budget:
                prune = True
            else:
                # uncharged members i of S1 have |N(i) \\ (A1 ∪ C ∪ F)| ≤ r − 1 + (charges
                # still to come on side 1) ≤ r − 1 + budget − k
                free = C | F
                if M & ~core_hard(full & ~X & ~free, free, X, inmask, r, budget - k):
                    prune = True
                else:
                    if k < budget:
                        W = core_hard(rest, ZERO, S | B, inmask, r, budget)
                    prune = capped_charged(S, X, M, W, inmask, r, budget)
        if prune:
            progress[0] += 0.5 ** depth / n
            continue
        # 1. an unmarked member with r outside in-neighbours: charge it, or mark it closed
        unmarked = S & ~C & ~M
        pick = -1
        m = unmarked
        while m:
            i = low_index(m)
            m &= ~(U1 << np.uint64(i))
            if popcount(inmask[i] & ~S) >= r:
                pick = i
                break
        if pick >= 0:
            bp = U1 << np.uint64(pick)
            stack[sp, CK_S] = S
            stack[sp, CK_X] = X
            stack[sp, CK_C] = C
            stack[sp, CK_M] = M | bp
            stack[sp, CK_K] = k
            stack_depth[sp] = depth + 1
            stack[sp + 1, CK_S] = S
            stack[sp + 1, CK_X] = X
            stack[sp + 1, CK_C] = C | bp
            stack[sp + 1, CK_M] = M
            stack[sp + 1, CK_K] = k
            stack_depth[sp + 1] = depth + 1
            sp += 2
            continue
        # 2. a closed-to-be member short of inside in-neighbours: take one more
        best_slack, best_cand = tightest_member(M, S, full & ~X, inmask, r, n)
        if best_slack < 0:
            progress[0] += 0.5 ** depth / n
            continue  # some member of M can no longer be closed
        if best_slack == 0:
            # forced: S + every candidate, at the same depth (it holds the whole share)
            stack[sp, CK_S] = S | best_cand
            stack[sp, CK_K] = k
            sp += 1
            continue
        if best_cand == ZERO and S & ~C == ZERO:
            # every member is charged: S1 still needs a closed member
            best_cand = full & ~S & ~X
            if best_cand == ZERO:
                progress[0] += 0.5 ** depth / n
                continue
        if best_cand != ZERO:
            u = branch_node(best_cand, full & ~S & ~B, inmask, outmask)
            bu = U1 << np.uint64(u)
            stack[sp, CK_S] = S
            stack[sp, CK_X] = X | bu
            stack[sp, CK_C] = C
            stack[sp, CK_M] = M
            stack[sp, CK_K] = k
            stack_depth[sp] = depth + 1
            stack[sp + 1, CK_S] = S | bu
            stack[sp + 1, CK_X] = X
            stack[sp + 1, CK_C] = C
            stack[sp + 1, CK_M] = M
            stack[sp + 1, CK_K] = k
            stack_depth[sp + 1] = depth + 1
            sp += 2
            continue
        # 3. S1 = S is settled at cost |C|: the cheapest S2 outside S ∪ B
        k2 = cheapest_side(full & ~S & ~B, k, state[CS_BEST] - 1 - nc, inmask, r, side)
        if k2 >= 0:
            state[CS_BEST] = nc + k2
            ubuf[CB_W1] = S
            ubuf[CB_W2] = side[0] | side[1]
        progress[0] += 0.5 ** depth / n
    state[CS_SP] = sp
    state[CS_ROOT] = root
    state[CS_NODES] += done


@njit(cache=True, nogil=True)
def non_in_masks(inmask: np.ndarray):
    """(mmask, mout): mmask[i] = M(i) = V \\ N(i) \\ {i}, the nodes that do not send
    to i; mout[u] = {i : u ∈ M(i)}."""
    n = inmask.shape[0]
    full = (U1 << np.uint64(n)) - U1 if n < 64 else ~ZERO
    mmask = np.zeros(n, dtype=np.uint64)
    mout = np.zeros(n, dtype=np.uint64)
    for i in range(n):
        mmask[i] = full & ~inmask[i] & ~(U1 << np.uint64(i))
        m = mmask[i]
        while m:
            u = low_index(m)
            m &= ~(U1 << np.uint64(u))
            mout[u] |= U1 << np.uint64(i)
    return mmask, mout


@njit(cache=True, nogil=True, inline="always")
def inside_cap(i: int, L: np.uint64, room: np.uint64, size: int, inmask: np.ndarray,
               mmask: np.ndarray) -> np.int64:
    """Upper bound on |N(i) ∩ S| for a set S with L ⊆ S ⊆ L ∪ room, |S| = size, i ∈ S
    (no self-loops): S's in-neighbours of i lie in L ∪ room, and S \\ {i} has
    size − 1 nodes of which those of M(i) ∩ L do not send to i."""
    return min(popcount(inmask[i] & (L | room)), size - 1 - popcount(mmask[i] & L))


@njit(cache=True, nogil=True)
def sized_lower_bound(L1: np.uint64, L2: np.uint64, L0: np.uint64, s1: int, s2: int,
                      inmask: np.ndarray, mmask: np.ndarray, need: np.ndarray, stop: int,
                      n: int) -> np.int64:
    """Lower bound on |reach_r(S1)| + |reach_r(S2)| over the completions of a partial
    labelling — L1 ⊆ S1, L2 ⊆ S2, L0 ⊆ R = V \\ (S1 ∪ S2), the rest A unlabelled —
    with |S1| = s1, |S2| = s2 and both sets keeping an r-closed member; n + 1 when
    there is no completion. Exact (the completion's cost) when A = ∅. Returns as soon
    as the bound reaches ``stop`` (the incumbent).

    A member i of S_k is uncharged iff |N(i) ∩ S_k| ≥ need[i] = d_i − r + 1 (fewer than
    r in-neighbours outside). ``inside_cap`` bounds |N(i) ∩ S_k| from above, so a
    labelled member whose cap is below need[i] is charged in every completion. An
    unlabelled node u can be uncharged in S_k only when its cap (with u ∈ S_k) reaches
    need[u] and S_k has room left. The unlabelled nodes fill the rooms c1, c2, c0
    (c1 + c2 + c0 = |A|) exactly; a node placed in S_k where it cannot be uncharged
    costs 1, in R nothing. The most nodes placed free is a bipartite b-matching of
    nodes to rooms whose size, by max-flow = min-cut, is
    min over room sets T of Σ_{b∈T} c_b + #{u : allowed(u) ⊄ T}; every allowed set
    holds R, so only T ∋ R matter. Charged labelled members plus the |A| − matching
    unlabelled ones that must be charged bound the cost. Each S_k needs a member that
    may stay uncharged (labelled or placeable), else there is no completion.
    """
    A = ~(L1 | L2 | L0) & ((U1 << np.uint64(n)) - U1 if n < 64 else ~ZERO)
    c1 = s1 - popcount(L1)
    c2 = s2 - popcount(L2)
    c0 = n - s1 - s2 - popcount(L0)
    if c1 < 0 or c2 < 0 or c0 < 0:
        return n + 1
    charged = 0
    open1 = False
    open2 = False
    m = L1
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        if inside_cap(i, L1, A, s1, inmask, mmask) >= need[i]:
            open1 = True
        else:
            charged += 1
    m = L2
    while m:
        i = low_index(m)
        m &= ~(U1 << np.uint64(i))
        if inside_cap(i, L2, A, s2, inmask, mmask) >= need[i]:
            open2 = True
        else:
            charged += 1
    if charged >= stop:
        return charged
    only1 = 0
    only2 = 0
    both = 0
    m = A
    while m:
        u = low_index(m)
        bu = U1 << np.uint64(u)
        m &= ~bu
        h1 = c1 > 0 and inside_cap(u, L1 | bu, A, s1, inmask, mmask) >= need[u]
        h2 = c2 > 0 and inside_cap(u, L2 | bu, A, s2, inmask, mmask) >= need[u]
        open1 |= h1
        open2 |= h2
        if h1 and h2:
            both += 1
        elif h1:
            only1 += 1
        elif h2:
            only2 += 1
    if not (open1 and open2):
        return n + 1
    na = popcount(A)
    matched = min(na, c0 + only1 + only2 + both, c0 + c1 + only2 + both,
                  c0 + c2 + only1 + both)
    return charged + na - matched


@njit(cache=True, nogil=True)
def sized_crowded(L1: np.uint64, L2: np.uint64, L0: np.uint64, s1: int, s2: int,
                  inmask: np.ndarray, mmask: np.ndarray, need: np.ndarray, n: int) -> bool:
    """True when every completion of the partial labelling (as in ``sized_lower_bound``)
    leaves a node of L0 with ≥ need[u] = d_u − r + 1 in-neighbours in S1 or in S2: u
    would be closed in that set plus u, so no completion is a maximal pair
    (``crowded``). S_k takes its c_k = s_k − |L_k| nodes still to come from the
    unlabelled A, of which only A ∩ M(u) do not send to u (u ∉ A): |N(u) ∩ S_k| ≥
    |N(u) ∩ L_k| + (c_k − |A ∩ M(u)|)⁺."""
    A = ~(L1 | L2 | L0) & ((U1 << np.uint64(n)) - U1 if n < 64 else ~ZERO)
    c1 = s1 - popcount(L1)
    c2 = s2 - popcount(L2)
    m = L0
    while m:
        u = low_index(m)
        m &= ~(U1 << np.uint64(u))
        away = popcount(A & mmask[u])
        if (popcount(inmask[u] & L1) + max(c1 - away, 0) >= need[u]
                or popcount(inmask[u] & L2) + max(c2 - away, 0) >= need[u]):
            return True
    return False


@njit(cache=True, nogil=True)
def sized_branch_node(A: np.uint64, L1: np.uint64, L2: np.uint64, mmask: np.ndarray,
                      mout: np.ndarray) -> np.int64:
    """The unlabelled node with the most non-arcs to or from the labelled members of
    S1 ∪ S2 (its label moves their caps soonest); ties: lowest index."""
    u = -1
    best = -1
    L = L1 | L2
    m = A
    while m:
        j = low_index(m)
        m &= ~(U1 << np.uint64(j))
        v = popcount(mout[j] & L) + popcount(mmask[j] & L)
        if v > best:
            best = v
            u = j
    return u


@njit(cache=True, nogil=True)
def next_sizes(state: np.ndarray, order: np.ndarray, n: int, ubuf: np.ndarray) -> bool:
    """Advance state to the next size combination (s1, s2) — s1, s2 ≥ 1,
    s1 + s2 ≤ n − |B| — of the current root, else of the next root (whose B goes to
    ubuf[CB_B]); False when the roots are exhausted."""
    while True:
        s1 = state[CS_S1]
        s2 = state[CS_S2] + 1
        room = n - state[CS_ROOT] + 1  # nodes outside B = order[:root]
        if s1 > 0 and s1 + s2 > room:
            s1 += 1
            s2 = 1
        if s1 > 0 and s1 + s2 <= room:
            state[CS_S1] = s1
            state[CS_S2] = s2
            return True
        if state[CS_ROOT] >= state[CS_END]:
            return False
        ubuf[CB_B] = prefix_mask(order, state[CS_ROOT])
        state[CS_ROOT] += 1
        state[CS_S1] = 1
        state[CS_S2] = 0


@njit(cache=True, nogil=True)
def min_cost_sized_step(
    inmask: np.ndarray,
    mmask: np.ndarray,
    mout: np.ndarray,
    order: np.ndarray,
    r: int,
    lower: int,
    stack: np.ndarray,
    stack_depth: np.ndarray,
    state: np.ndarray,
    ubuf: np.ndarray,
    max_nodes: int,
    progress: np.ndarray,
    tokens: np.ndarray,
    record: bool,
) -> None:
    """Advance the two-sided branch and bound for s*(r) with both set sizes fixed
    (the same problem, state layout and roots as :func:`min_cost_step`, whose
    incumbent state[CS_BEST] it shares).

    Root k puts order[k] in S1 and B = order[:k] in R (order[k] is the first node of
    S1 ∪ S2); then every size combination |S1| = s1, |S2| = s2 with
    s1 + s2 ≤ n − k is searched in turn. A state labels nodes S1 / S2 / R (rows
    L1, L2, L0 of ``stack``). Knowing the sizes, a member's inside in-neighbours are
    capped by its non-in-neighbours in its set (``inside_cap``), so on dense graphs,
    whose non-arcs are few, a label decides its neighbours' charges long before the
    sets are complete. A state whose ``sized_lower_bound`` reaches the incumbent is
    pruned; else the node of ``sized_branch_node`` is labelled S1, S2 or R (three
    children). A state without unlabelled nodes is a pair whose exact cost the bound
    gives; a cheaper one becomes the incumbent. Without a recorded tree (the checker
    replays none of it), only maximal pairs are searched: a ``sized_crowded`` state is
    pruned too (ER(50, 0.8), r = 20, below cap 3: 22M states, 18M with it).

    With ``record``, each expanded state appends a token (certificates/FORMAT.md,
    ``cost_search`` tree): its branch node, or -1 for a leaf; status NEED_ROOM when
    ``tokens`` is full.
    """
    n = inmask.shape[0]
    full = (U1 << np.uint64(n)) - U1 if n < 64 else ~ZERO
    need = np.empty(n, dtype=np.int64)
    for i in range(n):
        need[i] = popcount(inmask[i]) - r + 1
    sp = state[CS_SP]
    done = 0
    while done < max_nodes:
        if record and state[CS_NTOK] >= tokens.shape[0]:
            state[CS_STATUS] = NEED_ROOM
            break
        if sp == 0:
            if state[CS_BEST] <= lower or state[CS_ALONE] != 0 or not next_sizes(
                    state, order, n, ubuf):
                state[CS_STATUS] = UNSAT
                break
            stack[0, 0] = U1 << np.uint64(order[state[CS_ROOT] - 1])
            stack[0, 1] = ZERO
            stack[0, 2] = ubuf[CB_B]
            stack_depth[0] = 0
            sp = 1
        sp -= 1
        L1 = stack[sp, 0]
        L2 = stack[sp, 1]
        L0 = stack[sp, 2]
        depth = stack_depth[sp]
        done += 1
        s1 = state[CS_S1]
        s2 = state[CS_S2]
        bound = sized_lower_bound(L1, L2, L0, s1, s2, inmask, mmask, need, state[CS_BEST], n)
        if bound < state[CS_BEST] and not record and sized_crowded(L1, L2, L0, s1, s2,
                                                                   inmask, mmask, need, n):
            bound = n + 1
        A = full & ~(L1 | L2 | L0)
        if bound < state[CS_BEST] and A == ZERO:
            state[CS_BEST] = bound
            ubuf[CB_W1] = L1
            ubuf[CB_W2] = L2
        if bound >= state[CS_BEST] or A == ZERO:
            if record:
                tokens[state[CS_NTOK]] = -1
            state[CS_NTOK] += 1
            room = n - state[CS_ROOT] + 1
            progress[0] += 3.0 ** -depth / (n * (room * (room - 1) // 2))
            continue
        u = sized_branch_node(A, L1, L2, mmask, mout)
        if record:
            tokens[state[CS_NTOK]] = u
        state[CS_NTOK] += 1
        bu = U1 << np.uint64(u)
        stack[sp, 0] = L1
        stack[sp, 1] = L2
        stack[sp, 2] = L0 | bu
        stack[sp + 1, 0] = L1
        stack[sp + 1, 1] = L2 | bu
        stack[sp + 1, 2] = L0
        stack[sp + 2, 0] = L1 | bu
        stack[sp + 2, 1] = L2
        stack[sp + 2, 2] = L0
        for k in range(3):
            stack_depth[sp + k] = depth + 1
        sp += 3
    state[CS_SP] = sp
    state[CS_NODES] += done


@njit(cache=True, nogil=True, inline="always")
def walk_move_delta(u: int, b: int, lab: np.ndarray, cnt: np.ndarray, deg: np.ndarray,
                    outptr: np.ndarray, outidx: np.ndarray, r: int, unc: np.ndarray):
    """(change of the charged count, change of the excess, uncharged members of S1, of
    S2 after the move) when node u moves from its set lab[u] (0: neither, 1: S1, 2: S2)
    to b ≠ lab[u].

    cnt[k, j] = |N(j) ∩ S_k|; j ∈ S_k has o_j = d_j − cnt[k, j] outside in-neighbours,
    is charged iff o_j ≥ r, and has excess (o_j − r + 1)⁺ (how many more of them it
    would need inside to be uncharged). Moving u changes only u's own terms and, for
    each out-neighbour w of u, o_w + 1 in u's old set, o_w − 1 in the new one."""
    a = lab[u]
    u1 = unc[1]
    u2 = unc[2]
    delta = 0
    dex = 0
    if a != 0:
        o = deg[u] - cnt[a, u]
        dex -= max(o - r + 1, 0)
        if o >= r:
            delta -= 1
        elif a == 1:
            u1 -= 1
        else:
            u2 -= 1
    if b != 0:
        o = deg[u] - cnt[b, u]
        dex += max(o - r + 1, 0)
        if o >= r:
            delta += 1
        elif b == 1:
            u1 += 1
        else:
            u2 += 1
    for t in range(outptr[u], outptr[u + 1]):
        w = outidx[t]
        lw = lab[w]
        if lw == 0 or w == u:
            continue
        if lw == a:
            o = deg[w] - cnt[a, w]
            if o >= r - 1:
                dex += 1
            if o == r - 1:
                delta += 1
                if a == 1:
                    u1 -= 1
                else:
                    u2 -= 1
        elif lw == b:
            o = deg[w] - cnt[b, w]
            if o >= r:
                dex -= 1
            if o == r:
                delta -= 1
                if b == 1:
                    u1 += 1
                else:
                    u2 += 1
    return delta, dex, u1, u2


@njit(cache=True, nogil=True)
def pair_walk(deg: np.ndarray, outptr: np.ndarray, outidx: np.ndarray, r: int,
              lab: np.ndarray, moves: int, tenure: int, floor: int, seed: int) -> np.int64:
    """Tabu walk on labellings lab[u] ∈ {0 (neither), 1 (S1), 2 (S2)} for a cheap pair:
    one whose sets both keep an uncharged (r-closed) member, of small cost
    |reach_r(S1)| + |reach_r(S2)|. The walk descends the total excess
    Σ_{i ∈ S1 ∪ S2} (o_i − r + 1)⁺ (``walk_move_delta``) plus (n + 1) per set without an
    uncharged member, not the cost itself: the cost is flat over wide plateaus (a move
    rarely frees a node at once), the excess tells how close each member is (ER(40, 0.8),
    r = 17: walks reach the optimum, cost 5, in half the draws; on the cost they stop at
    8-10). Each step takes the best move of one node to another label (ties at
    random); a node moved in the last ``tenure`` (+ 0-2) steps stays put unless the move
    gives a valid pair cheaper than the walk's best. Stops after ``moves`` steps or at
    cost ``floor``. ``lab`` ends as the cheapest valid labelling visited; returns its
    cost (n + 1 if none was valid). deg: in-degrees; outidx[outptr[u]:outptr[u + 1]]:
    the nodes that receive from u (any n). Heuristic (any valid pair's cost bounds s*(r)
    from above, one of cost 0 refutes r-robustness); seeded, so reproducible."""
    np.random.seed(seed)
    n = deg.shape[0]
    cnt = np.zeros((3, n), dtype=np.int64)  # row 0 (nodes in neither set) is unused
    for u in range(n):
        for t in range(outptr[u], outptr[u + 1]):
            cnt[lab[u], outidx[t]] += 1
    unc = np.zeros(3, dtype=np.int64)
    cost = 0
    excess = 0
    for u in range(n):
        if lab[u] != 0:
            excess += max(deg[u] - cnt[lab[u], u] - r + 1, 0)
            if deg[u] - cnt[lab[u], u] >= r:
                cost += 1
            else:
                unc[lab[u]] += 1
    big = n + 1
    best = big
    best_lab = lab.copy()
    if unc[1] > 0 and unc[2] > 0:
        best = cost
    until = np.zeros(n, dtype=np.int64)
    for step in range(1, moves + 1):
        if best <= floor:
            break
        pick_u = -1
        pick_b = 0
        pick_score = 1 << 40
        ties = 0
        for u in range(n):
            for b in range(3):
                if b == lab[u]:
                    continue
                delta, dex, u1, u2 = walk_move_delta(u, b, lab, cnt, deg, outptr, outidx,
                                                     r, unc)
                valid = u1 > 0 and u2 > 0
                new = cost + delta
                if until[u] > step and not (valid and new < best):
                    continue
                score = big * ((u1 == 0) + (u2 == 0)) + excess + dex
                if score < pick_score:
                    pick_u, pick_b, pick_score, ties = u, b, score, 1
                elif score == pick_score:
                    ties += 1
                    if np.random.randint(ties) == 0:
                        pick_u, pick_b = u, b
        if pick_u < 0:
            break
        delta, dex, u1, u2 = walk_move_delta(pick_u, pick_b, lab, cnt, deg, outptr, outidx,
                                             r, unc)
        a = lab[pick_u]
        for t in range(outptr[pick_u], outptr[pick_u + 1]):
            w = outidx[t]
            cnt[a, w] -= 1
            cnt[pick_b, w] += 1
        lab[pick_u] = pick_b
        cost += delta
        excess += dex
        unc[1] = u1
        unc[2] = u2
        until[pick_u] = step + tenure + np.random.randint(3)
        if u1 > 0 and u2 > 0 and cost < best:
            best = cost
            best_lab[:] = lab
    lab[:] = best_lab
    return best
