"""The charged-set proof of (r, s)-robustness: one decision tree per configuration.

A pair of cost c < s whose sets both keep an r-closed member is S_k = U_k ∪ Q_k with
Q_k = reach_r(S_k), |Q1| + |Q2| = c, and U_k ≠ ∅ closed for the thresholds
t_k(i) = r + |N(i) ∩ Q_k| (see _charged_kernels). The configurations (Q1, Q2) with
|Q1| + |Q2| ≤ s − 1 are taken up to swapping the sides, in the order of
:func:`configurations`; each gets the decision search's tree for its thresholds, all
concatenated: the ``charged_tree`` of a ``cost_search`` proof (certificates/FORMAT.md).
Small when s is small and the decision trees are (sparse and medium graphs, where the
sized search's tree is not).
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from itertools import combinations
from math import comb

import numpy as np

from .indexed import IndexedGraph

__all__ = ["MAX_CONFIGS", "charged_tree", "configurations", "count_configurations"]

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


def count_configurations(n: int, c: int) -> int:
    """The number of :func:`configurations`."""
    return 1 + sum(comb(n, k) << (k - 1) for k in range(1, c + 1))


def charged_tree(ig: IndexedGraph, r: int, s: int, *, deadline: float | None = None,
                 max_tokens: int = 4_000_000) -> tuple[int, ...] | None:
    """The charged tree proving (r, s)-robustness, in the order
    ``search.search_order(ig)``; None for r < 1, beyond ``max_tokens`` tokens (also when
    the first configuration's tree times the number of configurations passes twice that),
    ``MAX_CONFIGS`` configurations or ``deadline``; ValueError when a configuration has
    a violating pair (a pair cheaper than s)."""
    from ._charged_kernels import OVERFLOW, config_tree
    from .search import _kernel_inputs

    count = count_configurations(ig.n, s - 1)
    if r < 1 or count > MAX_CONFIGS:
        return None
    _, inmask, outmask, order = _kernel_inputs(ig)
    masks = ig.in_masks()
    tokens = np.empty(max_tokens, dtype=np.int32)
    ntok = 0
    for index, (Q1, Q2) in enumerate(configurations(ig.n, s - 1)):
        if index == 1 and ntok * count > 2 * max_tokens:
            return None  # each configuration costs about as much as the first: too many
        t1, t2 = (np.array([r + (m & q).bit_count() for m in masks], dtype=np.int64)
                  for q in (_mask(Q1), _mask(Q2)))
        ntok = config_tree(inmask, outmask, order, t1, t2, not Q1, np.uint64(_mask(Q1)),
                           np.uint64(_mask(Q2)), tokens, ntok)
        if ntok == OVERFLOW:
            return None
        if ntok < 0:
            raise ValueError(f"the configuration Q1 = {Q1}, Q2 = {Q2} has a pair cheaper "
                             f"than s = {s}")
        if deadline is not None and time.perf_counter() > deadline:
            return None
    return tuple(tokens[:ntok].tolist())


def _mask(nodes: tuple[int, ...]) -> int:
    return sum(1 << v for v in nodes)
