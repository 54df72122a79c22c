"""The two published baselines for graph robustness, kept OUT of the library.

* **LeBlanc exhaustive search** (LeBlanc, Zhang, Koutsoukos, Sundaram, IEEE JSAC
  31(4), 2013): enumerate all ``(3^n - 2^(n+1) + 1) / 2`` unordered pairs of disjoint
  nonempty subsets ``S1, S2`` of ``V``.
* **Usevitch--Panagou MILP** (Usevitch, Panagou, Automatica 2020, arXiv:1901.11000):
  the rho MILP and the s*(r) MILP exactly as published (no symmetry breaking, no
  extra cuts), solved by HiGHS through ``highspy``.

Definitions (SPEC.md §1). Edge ``(u, v)`` of a DiGraph means v receives u's state
(u is an in-neighbour of v); undirected edges count both ways; self-loops ignored.
For ``S ⊆ V``::

    e(S)       = max_{i ∈ S} |N_in(i) \\ S|
    reach_r(S) = {i ∈ S : |N_in(i) \\ S| >= r}        (X_S^r in the paper)
    rho(G)     = min over pairs of max(e(S1), e(S2))
    s*(r)      = min over pairs with reach_r(S1) != S1 and reach_r(S2) != S2
                 of |reach_r(S1)| + |reach_r(S2)|;  n if there is no such pair.

``s*(r) = 0`` exactly when G is not r-robust (a pair with both reach sets empty
exists). ``s*(0) = n`` (every set is fully 0-reachable).

Both baselines are here to be compared against, in the same process, by
``benchmarks/run.py``; they are deliberately not "improved" beyond what the
brief allows (precomputed per-subset tables for LeBlanc, default HiGHS settings
for the MILP).
"""

from __future__ import annotations

import math
import time
from collections.abc import Hashable
from typing import Any, NamedTuple

import networkx as nx
import numpy as np
from numba import njit

from rescon.models.backends import silent_highs

__all__ = [
    "MilpResult",
    "in_neighbour_sets",
    "n_pairs",
    "leblanc_rho",
    "leblanc_max_s",
    "leblanc_rho_pair",
    "leblanc_warmup",
    "milp_rho",
    "milp_max_s",
    "LEBLANC_MAX_N",
]

#: Largest n accepted by the LeBlanc baseline (tables of 2^n bytes; 3^n/2 pairs).
LEBLANC_MAX_N = 24

# ---------------------------------------------------------------------------
# graph normalisation (self-contained: does not use rescon)
# ---------------------------------------------------------------------------


def in_neighbour_sets(G: Any) -> tuple[list[Hashable], list[set[int]]]:
    """Return ``(nodes, in_nbrs)`` with ``in_nbrs[i]`` the in-neighbour indices of i.

    Node order is ``list(G.nodes)``. Undirected edges count both ways, self-loops
    are dropped, multigraph parallel edges count once.
    """
    if not isinstance(G, nx.Graph):
        raise TypeError(f"G must be a networkx Graph or DiGraph; got {type(G).__name__}")
    nodes = list(G.nodes)
    pos = {v: i for i, v in enumerate(nodes)}
    in_nbrs: list[set[int]] = [set() for _ in nodes]
    for u, v in G.edges():
        if u == v:
            continue
        in_nbrs[pos[v]].add(pos[u])
        if not G.is_directed():
            in_nbrs[pos[u]].add(pos[v])
    return nodes, in_nbrs


def n_pairs(n: int) -> int:
    """Number of unordered pairs of disjoint nonempty subsets of an n-set."""
    return (3**n - 2 ** (n + 1) + 1) // 2


# ---------------------------------------------------------------------------
# LeBlanc exhaustive search (numba, bitmasks)
# ---------------------------------------------------------------------------


@njit(cache=True)
def _popcount(x):  # pragma: no cover - compiled
    # SWAR popcount on int64; all masks here are < 2^62 so the result's top byte
    # (<= 64) never touches the sign bit.
    x = x - ((x >> 1) & 0x5555555555555555)
    x = (x & 0x3333333333333333) + ((x >> 2) & 0x3333333333333333)
    x = (x + (x >> 4)) & 0x0F0F0F0F0F0F0F0F
    return ((x * 0x0101010101010101) >> 56) & 0x7F


@njit(cache=True)
def _e_table(in_masks, n):  # pragma: no cover - compiled
    """e[S] = max_{i in S} |N_in(i) minus S| for every mask S (e[0] = 0, unused)."""
    N = 1 << n
    full = N - 1
    e = np.zeros(N, np.int8)
    for S in range(1, N):
        comp = full & ~S
        best = 0
        for i in range(n):
            if (S >> i) & 1:
                k = _popcount(in_masks[i] & comp)
                if k > best:
                    best = k
        e[S] = best
    return e


@njit(cache=True)
def _c_table(in_masks, n, r, big):  # pragma: no cover - compiled
    """c[S] = |reach_r(S)| if reach_r(S) != S, else ``big`` (S fully r-reachable)."""
    N = 1 << n
    full = N - 1
    c = np.empty(N, np.int16)
    c[0] = big
    for S in range(1, N):
        comp = full & ~S
        cnt = 0
        size = 0
        for i in range(n):
            if (S >> i) & 1:
                size += 1
                if _popcount(in_masks[i] & comp) >= r:
                    cnt += 1
        c[S] = big if cnt == size else cnt
    return c


@njit(cache=True)
def _rho_pairs(e, n):  # pragma: no cover - compiled
    """min over unordered disjoint nonempty pairs of max(e[S1], e[S2]), and a witness.

    Each unordered pair is visited once: S1 is the set holding the lowest-indexed
    node of S1 ∪ S2, S2 ranges over nonempty submasks of the complement of S1 that
    lie above that node.
    """
    full = (1 << n) - 1
    best = 1 << 30
    w1 = 0
    w2 = 0
    for S1 in range(1, full + 1):
        low = S1 & -S1
        allowed = full & ~S1 & ~((low << 1) - 1)
        e1 = e[S1]
        sub = allowed
        while sub:
            e2 = e[sub]
            v = e1 if e1 > e2 else e2
            if v < best:
                best = v
                w1 = S1
                w2 = sub
            sub = (sub - 1) & allowed
    return best, w1, w2


@njit(cache=True)
def _s_pairs(c, n):  # pragma: no cover - compiled
    """min over unordered pairs of c[S1] + c[S2] (>= big when either is full), witness."""
    full = (1 << n) - 1
    best = 1 << 30
    w1 = 0
    w2 = 0
    for S1 in range(1, full + 1):
        low = S1 & -S1
        allowed = full & ~S1 & ~((low << 1) - 1)
        c1 = np.int64(c[S1])
        sub = allowed
        while sub:
            v = c1 + c[sub]
            if v < best:
                best = v
                w1 = S1
                w2 = sub
            sub = (sub - 1) & allowed
    return best, w1, w2


@njit(cache=True)
def _count_pairs(n):  # pragma: no cover - compiled
    """Number of pairs the enumeration visits (equals n_pairs(n)); for tests."""
    full = (1 << n) - 1
    total = 0
    for S1 in range(1, full + 1):
        low = S1 & -S1
        allowed = full & ~S1 & ~((low << 1) - 1)
        sub = allowed
        while sub:
            total += 1
            sub = (sub - 1) & allowed
    return total


def _masks(G: Any, max_n: int) -> tuple[int, np.ndarray]:
    _, in_nbrs = in_neighbour_sets(G)
    n = len(in_nbrs)
    if n < 2:
        raise ValueError(f"G must have at least 2 nodes; got {n}")
    if n > max_n:
        raise ValueError(
            f"LeBlanc exhaustive search needs 2^n memory and 3^n/2 steps; n = {n} > max_n = {max_n}"
        )
    in_masks = np.array([sum(1 << j for j in s) for s in in_nbrs], dtype=np.int64)
    return n, in_masks


def _mask_to_set(mask: int, n: int) -> frozenset[int]:
    return frozenset(i for i in range(n) if (mask >> i) & 1)


def leblanc_rho_pair(G: Any, *, max_n: int = LEBLANC_MAX_N) -> tuple[int, frozenset, frozenset]:
    """rho(G) by exhaustive search, with a minimising pair (node indices, list(G) order)."""
    n, in_masks = _masks(G, max_n)
    e = _e_table(in_masks, n)
    best, w1, w2 = _rho_pairs(e, n)
    return int(best), _mask_to_set(int(w1), n), _mask_to_set(int(w2), n)


def leblanc_rho(G: Any, *, max_n: int = LEBLANC_MAX_N) -> int:
    """rho(G) = max r such that G is r-robust, by LeBlanc's exhaustive search.

    Cost: O(n 2^n) to tabulate e(S), then one pass over all
    (3^n - 2^(n+1) + 1)/2 pairs. Memory 2^n bytes.
    """
    return leblanc_rho_pair(G, max_n=max_n)[0]


def leblanc_max_s(G: Any, r: int, *, max_n: int = LEBLANC_MAX_N) -> int:
    """s*(r) = max s such that G is (r, s)-robust; 0 if G is not r-robust; n if no
    pair has both sets not fully r-reachable (in particular for r = 0)."""
    if int(r) != r or r < 0:
        raise ValueError(f"r must be a nonnegative integer; got {r!r}")
    n, in_masks = _masks(G, max_n)
    big = 4 * n + 8  # any pair containing a fully r-reachable set sums to >= big > n
    c = _c_table(in_masks, n, int(r), big)
    best, _, _ = _s_pairs(c, n)
    return int(best) if best < big else n


def leblanc_warmup() -> None:
    """Compile (or load from cache) every numba kernel, so timings exclude JIT."""
    G = nx.complete_graph(4)
    leblanc_rho(G)
    leblanc_max_s(G, 1)
    _count_pairs(3)


# ---------------------------------------------------------------------------
# Usevitch--Panagou MILP (HiGHS via highspy)
# ---------------------------------------------------------------------------


class MilpResult(NamedTuple):
    """``(value, seconds, status)``; value is None unless status is 'optimal' (or
    'infeasible' for the s*(r) MILP, where value = n by definition)."""

    value: int | None
    seconds: float
    status: str


def _highs_status(h: Any) -> str:
    import highspy

    ms = h.getModelStatus()
    if ms == highspy.HighsModelStatus.kOptimal:
        return "optimal"
    if ms == highspy.HighsModelStatus.kTimeLimit:
        return "time_limit"
    if ms == highspy.HighsModelStatus.kInfeasible:
        return "infeasible"
    return "error:" + h.modelStatusToString(ms)


def _laplacian_rows(in_nbrs: list[set[int]]) -> list[list[tuple[int, float]]]:
    """In-Laplacian L = D_in - A_in, row i: d_in(i) at i, -1 at each in-neighbour."""
    rows = []
    for i, s in enumerate(in_nbrs):
        row = [(i, float(len(s)))] + [(j, -1.0) for j in sorted(s)]
        rows.append(row)
    return rows


def _solve(
    n_cols: int,
    cost: list[float],
    col_lo: list[float],
    col_hi: list[float],
    integer: list[bool],
    rows: list[tuple[float, float, list[tuple[int, float]]]],
    time_limit: float,
) -> tuple[Any, float]:
    """Build the LP row-wise, pass it to HiGHS and run. Returns (highs, objective)."""
    import highspy

    inf = highspy.kHighsInf
    lp = highspy.HighsLp()
    lp.num_col_ = n_cols
    lp.num_row_ = len(rows)
    lp.col_cost_ = np.asarray(cost, dtype=np.float64)
    lp.col_lower_ = np.asarray(col_lo, dtype=np.float64)
    lp.col_upper_ = np.asarray(col_hi, dtype=np.float64)
    lp.row_lower_ = np.array([-inf if lo is None else lo for lo, _, _ in rows], dtype=np.float64)
    lp.row_upper_ = np.array([inf if hi is None else hi for _, hi, _ in rows], dtype=np.float64)
    start = [0]
    index: list[int] = []
    value: list[float] = []
    for _, _, entries in rows:
        for j, a in entries:
            index.append(j)
            value.append(a)
        start.append(len(index))
    lp.a_matrix_.format_ = highspy.MatrixFormat.kRowwise
    lp.a_matrix_.num_col_ = n_cols
    lp.a_matrix_.num_row_ = len(rows)
    lp.a_matrix_.start_ = np.asarray(start, dtype=np.int32)
    lp.a_matrix_.index_ = np.asarray(index, dtype=np.int32)
    lp.a_matrix_.value_ = np.asarray(value, dtype=np.float64)
    lp.integrality_ = [
        highspy.HighsVarType.kInteger if z else highspy.HighsVarType.kContinuous for z in integer
    ]
    h = silent_highs()
    h.setOptionValue("time_limit", float(time_limit))
    h.passModel(lp)
    h.run()
    return h, h.getInfo().objective_function_value


def _integral(x: float) -> int:
    k = round(x)
    if abs(x - k) > 1e-6:
        raise ArithmeticError(f"MILP objective {x!r} is not integral")
    return int(k)


def milp_rho(G: Any, time_limit: float = 600.0, *, integer_t: bool = True) -> MilpResult:
    """rho(G) by the Usevitch--Panagou MILP (their Theorem for r-robustness)::

        min t  s.t.  L b1 <= t 1,  L b2 <= t 1,  b1 + b2 <= 1,
                     1 <= 1^T b_k <= n - 1,  b_k in {0,1}^n,  0 <= t <= ceil(n/2)

    with L the in-Laplacian. For i in S, (L 1_S)_i = |N_in(i) minus S| and for i
    not in S it is <= 0, so the optimum is min over pairs of max(e(S1), e(S2)).
    ``integer_t=True`` declares t integer as in the paper (the optimum is integral
    either way). No symmetry breaking, default HiGHS settings otherwise.

    Returns ``MilpResult(value, seconds, status)`` with status 'optimal',
    'time_limit' (value None) or 'error:<HiGHS status>'. ``seconds`` is wall time
    for building and solving the model.
    """
    t0 = time.perf_counter()
    _, in_nbrs = in_neighbour_sets(G)
    n = len(in_nbrs)
    if n < 2:
        raise ValueError(f"G must have at least 2 nodes; got {n}")
    L = _laplacian_rows(in_nbrs)
    b1 = list(range(n))
    b2 = list(range(n, 2 * n))
    t = 2 * n
    n_cols = 2 * n + 1
    cost = [0.0] * (2 * n) + [1.0]
    col_lo = [0.0] * n_cols
    col_hi = [1.0] * (2 * n) + [float(math.ceil(n / 2))]
    integer = [True] * (2 * n) + [bool(integer_t)]
    rows: list[tuple[float | None, float | None, list[tuple[int, float]]]] = []
    for bk in (b1, b2):
        for i in range(n):
            rows.append((None, 0.0, [(bk[j], a) for j, a in L[i]] + [(t, -1.0)]))
    for i in range(n):
        rows.append((None, 1.0, [(b1[i], 1.0), (b2[i], 1.0)]))
    for bk in (b1, b2):
        rows.append((1.0, float(n - 1), [(j, 1.0) for j in bk]))
    h, obj = _solve(n_cols, cost, col_lo, col_hi, integer, rows, time_limit)
    status = _highs_status(h)
    value = _integral(obj) if status == "optimal" else None
    return MilpResult(value, time.perf_counter() - t0, status)


def milp_max_s(G: Any, r: int, time_limit: float = 600.0) -> MilpResult:
    """s*(r) by the Usevitch--Panagou (r,s) MILP::

        min s  s.t.  s >= 1^T y1 + 1^T y2,
                     1^T y_k <= 1^T b_k - 1,
                     L b_k - (n-1) y_k <= (r-1) 1,
                     b1 + b2 <= 1,  1 <= 1^T b_k <= n-1,  b_k, y_k in {0,1}^n

    y_k must be 1 on every r-reachable node of S_k, so 1^T y_k >= |reach_r(S_k)|
    and the minimum is attained with y_k = indicator of reach_r(S_k); the
    constraint 1^T y_k <= |S_k| - 1 then says reach_r(S_k) != S_k. ``y_k <= b_k``
    is therefore not needed for the optimal value and is not added (as published).
    Infeasible means no pair has both sets not fully r-reachable: s*(r) = n.

    Requires r >= 1 (for r = 0, s*(0) = n by definition and the big-M row is not
    valid). Returns ``MilpResult(value, seconds, status)``; status 'optimal',
    'infeasible' (value n), 'time_limit' (value None) or 'error:<HiGHS status>'.
    """
    if int(r) != r or r < 1:
        raise ValueError(f"r must be an integer >= 1; got {r!r}")
    t0 = time.perf_counter()
    _, in_nbrs = in_neighbour_sets(G)
    n = len(in_nbrs)
    if n < 2:
        raise ValueError(f"G must have at least 2 nodes; got {n}")
    L = _laplacian_rows(in_nbrs)
    b = [list(range(0, n)), list(range(n, 2 * n))]
    y = [list(range(2 * n, 3 * n)), list(range(3 * n, 4 * n))]
    s = 4 * n
    n_cols = 4 * n + 1
    cost = [0.0] * (4 * n) + [1.0]
    col_lo = [0.0] * n_cols
    col_hi = [1.0] * (4 * n) + [float(n)]
    integer = [True] * (4 * n) + [False]
    rows: list[tuple[float | None, float | None, list[tuple[int, float]]]] = []
    for k in range(2):
        rows.append((None, -1.0, [(j, 1.0) for j in y[k]] + [(j, -1.0) for j in b[k]]))
        for i in range(n):
            rows.append(
                (None, float(r - 1), [(b[k][j], a) for j, a in L[i]] + [(y[k][i], -(n - 1.0))])
            )
    for i in range(n):
        rows.append((None, 1.0, [(b[0][i], 1.0), (b[1][i], 1.0)]))
    for k in range(2):
        rows.append((1.0, float(n - 1), [(j, 1.0) for j in b[k]]))
    rows.append((None, 0.0, [(j, 1.0) for j in y[0] + y[1]] + [(s, -1.0)]))
    h, obj = _solve(n_cols, cost, col_lo, col_hi, integer, rows, time_limit)
    status = _highs_status(h)
    if status == "optimal":
        value: int | None = _integral(obj)
    elif status == "infeasible":
        value = n
    else:
        value = None
    return MilpResult(value, time.perf_counter() - t0, status)
