"""Decide whether a row-stochastic matrix is in the Sarymsakov class (paper Definition 3).

For a row-stochastic :math:`A \\in \\mathbb{R}^{n \\times n}` and a set of rows V let
:math:`I(V) = \\{j : a_{ij} > 0 \\text{ for some } i \\in V\\}`. A is *Sarymsakov* iff
for every pair of disjoint nonempty :math:`V_1, V_2`

.. math::
    I(V_1) \\cap I(V_2) \\ne \\emptyset \\quad\\text{or}\\quad
    |I(V_1) \\cup I(V_2)| > |V_1 \\cup V_2| .

Only the support of A matters. The decision is polynomial (see
:func:`is_sarymsakov`, Notes), not the :math:`3^n` pair enumeration.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.sparse import coo_matrix, csr_matrix
from scipy.sparse.csgraph import (
    breadth_first_order,
    connected_components,
    maximum_bipartite_matching,
    maximum_flow,
)

from .._validate import positive
from ..errors import InputError

__all__ = ["SarymsakovResult", "is_sarymsakov"]

_ROW_SUM_TOL = 1e-9
_Pair = tuple[frozenset[int], frozenset[int]]


@dataclass(frozen=True)
class SarymsakovResult:
    """Answer of :func:`is_sarymsakov`.

    Attributes
    ----------
    holds : bool
        A is Sarymsakov. When ``exact`` is False this only means that no failing
        pair was found before the time limit.
    witness : tuple of two frozensets of int, or None
        A failing pair :math:`(V_1, V_2)` of row indices: disjoint, nonempty,
        :math:`I(V_1) \\cap I(V_2) = \\emptyset` and
        :math:`|I(V_1)| + |I(V_2)| \\le |V_1| + |V_2|`. None iff ``holds``.
    certificate : dict or None
        JSON-ready (certificates/FORMAT.md): kind ``not_sarymsakov`` with the
        witness, or kind ``sarymsakov`` (method ``matching``: the perfect
        matching, checked in polynomial time; ``enumeration`` for n ≤ 12; else
        ``min_cut``, accepted on trust). None when the time limit cut the search.
    exact : bool
        False only if ``time_limit`` stopped the search before a decision.
    method : str
        ``"matching"`` (the support has a perfect matching) or ``"min_cut"``.
    """

    holds: bool
    witness: _Pair | None
    certificate: dict[str, Any] | None
    exact: bool
    method: str


def is_sarymsakov(A: Any, *, time_limit: float | None = None) -> SarymsakovResult:
    """Decide whether A is a Sarymsakov matrix, with a witness when it is not.

    Parameters
    ----------
    A : array_like or scipy sparse matrix, shape (n, n)
        Row-stochastic: finite, nonnegative, each row sums to 1 within 1e-9.
        The support is :math:`\\{(i, j) : a_{ij} > 0\\}`.
    time_limit : float, optional
        Seconds; the min-cut search stops after it (``exact=False``).

    Returns
    -------
    SarymsakovResult

    Raises
    ------
    InputError
        A is not a square, finite, nonnegative, row-stochastic matrix, or
        ``time_limit`` is not a positive number.

    Notes
    -----
    Write :math:`f(V) = |I(V)| - |V|`. Every row has a nonempty support, so
    disjoint images force disjoint row sets, and A fails iff some nonempty
    :math:`V_1, V_2` with :math:`I(V_1) \\cap I(V_2) = \\emptyset` have
    :math:`f(V_1) + f(V_2) \\le 0`.

    *Perfect matching.* If the bipartite support graph (rows, columns) has a
    perfect matching σ (row i ↦ column σ(i), :math:`a_{i\\sigma(i)} > 0`), Hall's
    theorem gives f ≥ 0, so a failing pair needs :math:`f(V_1) = f(V_2) = 0`.
    Relabel column σ(u) as u: then :math:`I(V) \\supseteq V`, and f(V) = 0 iff V
    receives no edge :math:`u \\to i` (:math:`a_{i\\sigma(u)} > 0`) from outside
    V. Such closed sets are unions of strongly connected components containing a
    source component, so A fails iff this digraph has two or more source
    components (two of them are the witness). O(n² + matching).

    *Otherwise.* Fix anchor rows :math:`i \\in V_1`, :math:`k \\in V_2` with
    disjoint supports. Minimising
    :math:`|J_1| + |J_2| - |V_1| - |V_2|` over column sets :math:`J_1 \\cap J_2 = \\emptyset`
    and rows with :math:`I(V_l) \\subseteq J_l` is a maximum-weight closure
    problem (binary variables :math:`j \\in J_1`, :math:`j \\notin J_2`,
    :math:`i \\in V_1`, :math:`i \\notin V_2`; every constraint is an implication),
    i.e. one minimum s–t cut on 4n + 2 nodes. A fails iff some anchor pair has
    optimum ≤ 0. O(n²) max-flow calls, each O(poly(n, nnz)); the search stops at
    the first failing pair.

    References
    ----------
    Chen, Wen, Li, arXiv 2510.06835, Definition 3 (Sarymsakov class).

    Examples
    --------
    >>> is_sarymsakov([[0.5, 0.5], [0.5, 0.5]]).holds
    True
    >>> r = is_sarymsakov([[1.0, 0.0], [0.0, 1.0]])
    >>> r.holds, sorted(map(sorted, r.witness))
    (False, [[0], [1]])
    """
    S = _support(A)
    deadline = None
    if time_limit is not None:
        deadline = time.monotonic() + positive("time_limit", time_limit,
                                                      what="finite number of seconds")
    sigma = maximum_bipartite_matching(csr_matrix(S), perm_type="column")
    if (sigma >= 0).all():
        witness, exact, method = _source_components(S, sigma), True, "matching"
    else:
        witness, exact = _min_cut_search(S, deadline)
        method, sigma = "min_cut", None
    return SarymsakovResult(
        holds=witness is None,
        witness=witness,
        certificate=_certificate(S, witness, sigma) if exact else None,
        exact=exact,
        method=method,
    )


def _support(A: Any) -> np.ndarray:
    if hasattr(A, "toarray"):
        A = A.toarray()
    try:
        M = np.asarray(A, dtype=float)
    except (TypeError, ValueError) as exc:
        raise InputError(f"A must be a numeric (n, n) matrix; got {type(A).__name__}") from exc
    if M.ndim != 2 or M.shape[0] != M.shape[1] or M.shape[0] == 0:
        raise InputError(f"A must be a square (n, n) matrix with n >= 1; got shape {M.shape}")
    if not np.isfinite(M).all():
        raise InputError(f"A must be finite; got {int((~np.isfinite(M)).sum())} NaN/inf entries")
    if (M < 0).any():
        i, j = np.argwhere(M < 0)[0]
        raise InputError(f"A must be nonnegative; got A[{i}, {j}] = {M[i, j]}")
    sums = M.sum(axis=1)
    bad = np.flatnonzero(np.abs(sums - 1.0) > _ROW_SUM_TOL)
    if bad.size:
        raise InputError(
            f"A must be row-stochastic (rows sum to 1 within {_ROW_SUM_TOL}); "
            f"got row {bad[0]} summing to {float(sums[bad[0]])!r}"
        )
    return M > 0


def _source_components(S: np.ndarray, sigma: np.ndarray) -> _Pair | None:
    # M[u, i] = S[i, sigma[u]]: edge u -> i of the relabelled support digraph.
    M = S[:, sigma].T
    _, comp = connected_components(csr_matrix(M), directed=True, connection="strong")
    u, i = np.nonzero(M)
    fed = set(comp[i[comp[u] != comp[i]]].tolist())
    sources = [c for c in dict.fromkeys(comp.tolist()) if c not in fed]
    if len(sources) < 2:
        return None
    first, second = sources[:2]
    return frozenset(np.flatnonzero(comp == first).tolist()), frozenset(
        np.flatnonzero(comp == second).tolist()
    )


def _min_cut_search(S: np.ndarray, deadline: float | None) -> tuple[_Pair | None, bool]:
    n = S.shape[0]
    # Nodes: a_j = j (j in J1), b_j = n + j (j not in J2), y_i = 2n + i (i in V1),
    # w_i = 3n + i (i not in V2), source s = 4n, sink t = 4n + 1.
    s, t, inf = 4 * n, 4 * n + 1, 4 * n + 1
    rows, cols = np.nonzero(S)
    ar = np.arange(n)
    tails = [np.full(n, s), np.full(n, s), ar, 3 * n + ar, ar, 2 * n + rows, n + cols]
    heads = [n + ar, 2 * n + ar, np.full(n, t), np.full(n, t), n + ar, cols, 3 * n + rows]
    caps = [np.ones(n), np.ones(n), np.ones(n), np.ones(n), np.full(n, inf),
            np.full(rows.size, inf), np.full(rows.size, inf)]
    base = (np.concatenate(tails), np.concatenate(heads), np.concatenate(caps))
    Si = S.astype(np.int64)
    disjoint = (Si @ Si.T) == 0
    for i, k in zip(*np.nonzero(np.triu(disjoint, 1))):
        if deadline is not None and time.monotonic() > deadline:
            return None, False
        tail = np.append(base[0], [s, 3 * n + k])
        head = np.append(base[1], [2 * n + i, t])
        cap = np.append(base[2], [inf, inf]).astype(np.int32)
        graph = coo_matrix((cap, (tail, head)), shape=(t + 1, t + 1)).tocsr()
        flow = maximum_flow(graph, s, t).flow
        residual = csr_matrix(graph - flow)  # cap - flow >= 0; reverse arcs get the flow
        residual.eliminate_zeros()
        side = np.zeros(t + 1, dtype=bool)
        side[breadth_first_order(residual, s, directed=True, return_predecessors=False)] = True
        V1 = np.flatnonzero(side[2 * n:3 * n])
        V2 = np.flatnonzero(~side[3 * n:4 * n])
        value = np.count_nonzero(side[:n]) + np.count_nonzero(~side[n:2 * n]) - V1.size - V2.size
        if value <= 0:
            return (frozenset(V1.tolist()), frozenset(V2.tolist())), True
    return None, True


def _certificate(S: np.ndarray, witness: _Pair | None,
                 sigma: np.ndarray | None) -> dict[str, Any]:
    """``sarymsakov`` (method ``matching`` with the perfect matching, or
    ``enumeration`` for n ≤ 12, else ``min_cut``, which the checker accepts on
    trust) or ``not_sarymsakov`` with the failing pair."""
    n = S.shape[0]
    support = [[int(i), int(j)] for i, j in zip(*np.nonzero(S))]
    if witness is None:
        head = {"rescon_certificate": 1, "kind": "sarymsakov"}
        if sigma is not None:
            return {**head, "method": "matching", "n": n, "support": support,
                    "matching": [int(j) for j in sigma]}
        method = "enumeration" if n <= 12 else "min_cut"
        return {**head, "method": method, "n": n, "support": support}
    return {"rescon_certificate": 1, "kind": "not_sarymsakov", "n": n, "support": support,
            "witness": {"V1": sorted(witness[0]), "V2": sorted(witness[1])}}
