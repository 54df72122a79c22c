"""The charged-set proof of (r, s)-robustness: one decision tree per configuration.

A pair of cost c < s whose sets both keep an r-closed member is S_k = U_k ∪ Q_k with
Q_k = reach_r(S_k), |Q1| + |Q2| = c, and U_k ≠ ∅ closed for the thresholds
t_k(i) = r + |N(i) ∩ Q_k| (see _charged_kernels). The configurations (Q1, Q2) with
|Q1| + |Q2| ≤ s − 1 are taken up to swapping the sides, in the order of
:func:`configurations`; each gets the decision search's tree for its thresholds, all
concatenated: the ``charged_tree`` of a ``cost_search`` proof (certificates/FORMAT.md).
Small when s is small and the decision trees are (sparse and medium graphs, where the
sized search's tree is not). The *uniform* charged tree (:func:`uniform_tree`) covers
all configurations with one tree per type (|Q1| ≤ c1, |Q2| ≤ c2) when such trees exist.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Iterator
from itertools import combinations
from math import comb
from typing import TYPE_CHECKING

import numpy as np

from .indexed import IndexedGraph

if TYPE_CHECKING:
    from .bounds import Pair

__all__ = ["MAX_CONFIGS", "charged_order", "charged_tree", "configurations",
           "count_configurations", "uniform_excluded", "uniform_tree", "uniform_types"]

MAX_CONFIGS = 20_000  # beyond, no charged tree is tried (each configuration costs ≥ n tokens)


def configurations(n: int, c: int) -> Iterator[tuple[tuple[int, ...], tuple[int, ...]]]:
    """The configurations (Q1, Q2) with |Q1| + |Q2| ≤ c, one of each swapped pair: by
    size, then Q = Q1 ∪ Q2 in lexicographic order, then Q1 = {min Q} ∪ T for the
    subsets T of the rest of Q by their bitmask over it (bit j: its j-th node)."""
    yield (), ()
    for size in range(1, c + 1):
        for Q in combinations(range(n), size):
            rest = Q[1:]
            for mask in range(1 << (size - 1)):
                Q1 = (Q[0],) + tuple(v for j, v in enumerate(rest) if mask >> j & 1)
                yield Q1, tuple(v for j, v in enumerate(rest) if not mask >> j & 1)


def charged_order(ig: IndexedGraph) -> np.ndarray:
    """The root order of the charged trees: descending in-degree, ties by index (the
    first roots, hard to close, end their subtrees soonest, and later roots find their
    easy nodes in B). ER(30, 0.5), r = 8, s = 3 with the capped leaf: 1.7× fewer tokens
    (directed) and 4.3× (undirected) than ``search.search_order``'s ascending one."""
    deg = np.array(ig.in_degrees)
    return np.lexsort((np.arange(ig.n), -deg)).astype(np.int64)


def count_configurations(n: int, c: int) -> int:
    """The number of :func:`configurations`."""
    return 1 + sum(comb(n, k) << (k - 1) for k in range(1, c + 1))


def charged_tree(ig: IndexedGraph, r: int, s: int, *, deadline: float | None = None,
                 max_tokens: int = 4_000_000) -> tuple[int, ...] | None:
    """The charged tree proving (r, s)-robustness, in the order :func:`charged_order`;
    None for r < 1, beyond ``max_tokens`` tokens (also when
    the first configuration's tree times the number of configurations passes twice that),
    ``MAX_CONFIGS`` configurations or ``deadline``; ValueError when a configuration has
    a violating pair (a pair cheaper than s)."""
    count = count_configurations(ig.n, s - 1)
    if r < 1 or count > MAX_CONFIGS:
        return None
    masks = ig.in_masks()
    parts = ((Q1, Q2, *(tuple(r + (m & _mask(Q)).bit_count() for m in masks) for Q in (Q1, Q2)))
             for Q1, Q2 in configurations(ig.n, s - 1))
    try:
        return _record(ig, parts, count, deadline, max_tokens)
    except _Violated as exc:
        raise ValueError(f"the configuration Q1 = {exc.args[0]}, Q2 = {exc.args[1]} has a "
                         f"pair cheaper than s = {s}") from None


def uniform_types(s: int) -> list[tuple[int, int]]:
    """The types (c1, c2) of a uniform charged tree: c1 + c2 = s − 1, c1 ≥ c2, by c2."""
    return [(s - 1 - c2, c2) for c2 in range((s - 1) // 2 + 1)]


def uniform_tree(ig: IndexedGraph, r: int, s: int, *, deadline: float | None = None,
                 max_tokens: int = 4_000_000) -> tuple[int, ...] | None:
    """The *uniform* charged tree proving (r, s)-robustness (certificates/FORMAT.md): for
    each type (c1, c2) of :func:`uniform_types`, the decision tree for the thresholds
    t_k(i) = r + min(c_k, d_i) and no charged node, which covers every configuration
    with |Q1| ≤ c1, |Q2| ≤ c2 at once (r + |N(i) ∩ Q_k| ≤ t_k(i)). None for r < 1 or
    s < 2, beyond ``max_tokens`` or ``deadline``, or when a type has a violating pair
    (always for s ≥ 3 at r = ρ: (1, 1) asks for two (r + 1)-closed sets). ER(30, 0.5),
    s = 2: on one graph of three, 0.33M tokens where the configurations took 2.2M before
    the capped leaf (13k with it)."""
    if r < 1 or s < 2:
        return None
    deg = ig.in_degrees
    parts = (((), (), *(tuple(r + min(c, d) for d in deg) for c in types))
             for types in uniform_types(s))
    try:
        return _record(ig, parts, len(uniform_types(s)), deadline, max_tokens)
    except _Violated:
        return None


def uniform_excluded(ig: IndexedGraph, r: int, s: int, pairs: Iterable[Pair]) -> bool:
    """True when one of ``pairs`` (e.g. the violating pairs met so far) proves that
    :func:`uniform_tree` has no tree for (r, s), so that it need not be tried: its sets,
    disjoint and nonempty, are both closed for the thresholds t(i) = r + min(c, d_i) of
    the last type (s − 1 − c, c), c = ⌊(s − 1)/2⌋, of :func:`uniform_types`.

    Proof: that type's thresholds are t2 = t and t1 ≥ t (s − 1 − c ≥ c), and a set
    closed for t is closed for any larger thresholds; so the pair is a violating pair of
    that type's decision search, which meets one if there is any (uniform_tree: None).
    For s ≥ 3 (c ≥ 1) every pair violating (r + 1)-robustness is one, since its members
    have |N(i) \\ S| ≤ min(r, d_i) < r + min(c, d_i) outside in-neighbours: at r = ρ the
    pair that refuted (ρ + 1)-robustness excludes the uniform tree of every s ≥ 3."""
    t = [r + min((s - 1) // 2, d) for d in ig.in_degrees]
    return any(pair.S1 and pair.S2 and not pair.S1 & pair.S2
               and all(len(ig.in_nbrs[i] - S) < t[i] for S in (pair.S1, pair.S2) for i in S)
               for pair in pairs)


class _Violated(Exception):
    """A part of a charged tree has a violating pair; args: its (Q1, Q2)."""


def _record(ig: IndexedGraph, parts: Iterator[tuple], count: int, deadline: float | None,
            max_tokens: int) -> tuple[int, ...] | None:
    """The concatenated trees of ``parts`` (Q1, Q2, t1, t2: the charged nodes, which the
    -4 leaf checks, and the thresholds; one side when Q1 = ∅ and t1 = t2); None beyond
    ``max_tokens`` (also when the first part's tree times ``count`` passes twice that)
    or ``deadline``; raises _Violated for a part with a violating pair."""
    from ._charged_kernels import OVERFLOW, config_tree
    from .search import _kernel_inputs

    _, inmask, outmask, _ = _kernel_inputs(ig)
    order = charged_order(ig)
    tokens = np.empty(max_tokens, dtype=np.int32)
    ntok = 0
    for index, (Q1, Q2, t1, t2) in enumerate(parts):
        if index == 1 and ntok * count > 2 * max_tokens:
            return None  # each part costs about as much as the first: too many
        ntok = config_tree(inmask, outmask, order, np.array(t1, dtype=np.int64),
                           np.array(t2, dtype=np.int64), not Q1 and t1 == t2,
                           np.uint64(_mask(Q1)), np.uint64(_mask(Q2)), tokens, ntok)
        if ntok == OVERFLOW:
            return None
        if ntok < 0:
            raise _Violated(Q1, Q2)
        if deadline is not None and time.perf_counter() > deadline:
            return None
    return tuple(tokens[:ntok].tolist())


def _mask(nodes: tuple[int, ...]) -> int:
    return sum(1 << v for v in nodes)
