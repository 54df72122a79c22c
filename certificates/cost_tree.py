"""Replay of a recorded ``cost_search`` tree (FORMAT.md): the proof that every pair of
disjoint sets that both keep an r-closed member has ≥ s r-reachable members.

Part of the trusted checker: Python standard library only, exact integers, never
imports rescon or numpy. Node sets are int bitmasks (bit i = node i).

The tree is the sized search's (rescon.graphs._kernels.min_cost_sized_step) below
cap s. A pair (S1, S2) is named so that the first node of S1 ∪ S2 in ``order`` —
order[k] — lies in S1; then B = order[:k] lies in R = V \\ (S1 ∪ S2). Roots k = 0..n−1
and, within a root, the size combinations (|S1|, |S2|) = (s1, s2), s1 = 1, 2, ... and
s2 = 1, 2, ... with s1 + s2 ≤ n − k, each own one subtree, in that order. A state is a
partial labelling L1 ⊆ S1, L2 ⊆ S2, L0 ⊆ R (start: {order[k]}, ∅, B); its token is a
node u unlabelled in it (children, in preorder: u into S1, into S2, into R) or -1, a
leaf whose lower bound (:func:`bound`) is ≥ s. Every pair lies in the subtree of its
root and sizes and on one path of it, down to a leaf whose bound is at most its cost,
so every pair costs ≥ s.
"""

from __future__ import annotations

__all__ = ["MAX_COST_TREE_WORK", "bound", "install", "replay"]

MAX_COST_TREE_WORK = 25_000_000  # n·⌈n / 1024⌉ per replayed state (~10 s)

Invalid: type = ValueError  # check.py's exception, bound by install()


def install(invalid: type) -> None:
    """Bind check.py's ``Invalid`` exception."""
    global Invalid
    Invalid = invalid


def _cap(i: int, L: int, room: int, size: int, inmask: list[int], mmask: list[int]) -> int:
    """Upper bound on |N(i) ∩ S| for every S with L ⊆ S ⊆ L ∪ room, |S| = size, i ∈ S:
    those in-neighbours lie in L ∪ room, and S \\ {i} has size − 1 members, of which
    the non-in-neighbours M(i) ∩ L do not send to i."""
    return min((inmask[i] & (L | room)).bit_count(), size - 1 - (mmask[i] & L).bit_count())


def bound(L1: int, L2: int, L0: int, s1: int, s2: int, inmask: list[int], mmask: list[int],
          r: int) -> int:
    """Lower bound on |reach_r(S1)| + |reach_r(S2)| over the pairs with L1 ⊆ S1, L2 ⊆ S2,
    L0 ∩ (S1 ∪ S2) = ∅, |S1| = s1, |S2| = s2 whose sets both keep an r-closed member;
    n + 1 when there is none (FORMAT.md, ``cost_search``).

    i ∈ S_k is not r-reachable iff |N(i) ∩ S_k| ≥ d_i − r + 1. A labelled member whose
    ``_cap`` is below that is reachable in every completion. Each unlabelled node u goes
    to S1, S2 or R, whose free rooms c1, c2, c0 it fills exactly; it may be unreachable
    in S_k only if its cap there reaches d_u − r + 1 and c_k > 0, and costs 1 when placed
    in S_k otherwise. The most nodes placed at no cost is a b-matching of nodes to rooms
    (R admits every node), of size min over room sets T ∋ R of
    Σ_{b∈T} c_b + #{u : the rooms admitting u ⊄ T} (max-flow = min-cut).
    """
    n = len(inmask)
    A = ((1 << n) - 1) & ~(L1 | L2 | L0)
    c1, c2 = s1 - L1.bit_count(), s2 - L2.bit_count()
    c0 = n - s1 - s2 - L0.bit_count()
    if min(c0, c1, c2) < 0:
        return n + 1
    cost, open1, open2 = 0, False, False
    for L, size, side in ((L1, s1, 1), (L2, s2, 2)):
        for i in _bits(L):
            if _cap(i, L, A, size, inmask, mmask) >= inmask[i].bit_count() - r + 1:
                open1, open2 = open1 or side == 1, open2 or side == 2
            else:
                cost += 1
    only1 = only2 = both = 0
    for u in _bits(A):
        need, bu = inmask[u].bit_count() - r + 1, 1 << u
        h1 = c1 > 0 and _cap(u, L1 | bu, A, s1, inmask, mmask) >= need
        h2 = c2 > 0 and _cap(u, L2 | bu, A, s2, inmask, mmask) >= need
        open1, open2 = open1 or h1, open2 or h2
        both, only1, only2 = both + (h1 and h2), only1 + (h1 and not h2), only2 + (h2 and not h1)
    if not (open1 and open2):
        return n + 1
    na = A.bit_count()
    free = min(na, c0 + only1 + only2 + both, c0 + c1 + only2 + both, c0 + c2 + only1 + both)
    return cost + na - free


def _bits(mask: int):
    while mask:
        low = mask & -mask
        yield low.bit_length() - 1
        mask ^= low


def replay(inmask: list[int], r: int, s: int, order: list[int], tree: list[int] | tuple,
           where: str, max_work: int = MAX_COST_TREE_WORK) -> bool:
    """Replay ``tree``: True when every leaf's bound is ≥ s and the tokens are exactly
    the tree's; False when the replay passes ``max_work`` (a state costs n operations on
    n-bit sets, charged n·⌈n / 1024⌉; then nothing is decided). Raises ``Invalid`` with
    the first fault."""
    n = len(inmask)
    full = (1 << n) - 1
    mmask = [full & ~inmask[i] & ~(1 << i) for i in range(n)]
    state_work = n * max(1, -(-n // 1024))
    pos, work, B = 0, 0, 0
    for k in range(n):
        room = n - k
        for s1 in range(1, room):
            for s2 in range(1, room - s1 + 1):
                stack = [(1 << order[k], 0, B)]
                while stack:
                    L1, L2, L0 = stack.pop()
                    if pos >= len(tree):
                        raise Invalid(f"{where}.tree ends before the search does "
                                      f"(root {k}, sizes {s1}, {s2})")
                    t = tree[pos]
                    work += state_work
                    if work > max_work:
                        return False
                    if t == -1:
                        if bound(L1, L2, L0, s1, s2, inmask, mmask, r) < s:
                            raise Invalid(f"{where}.tree[{pos}]: a leaf whose bound is below "
                                          f"s = {s} (root {k}, sizes {s1}, {s2})")
                    elif 0 <= t < n and (full & ~(L1 | L2 | L0)) >> t & 1:
                        bu = 1 << t
                        stack += [(L1, L2, L0 | bu), (L1, L2 | bu, L0), (L1 | bu, L2, L0)]
                    else:
                        raise Invalid(f"{where}.tree[{pos}] = {t!r} is neither -1 nor an "
                                      "unlabelled node")
                    pos += 1
        B |= 1 << order[k]
    if pos != len(tree):
        raise Invalid(f"{where}.tree has {len(tree) - pos} tokens after the search's end")
    return True
