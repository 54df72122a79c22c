"""Tverberg partitions by MILP (HiGHS), certified in exact rational arithmetic.

A Tverberg partition of X = (x_0, …, x_{n−1}) ⊂ R^d into q parts is a family of q
pairwise disjoint nonempty index sets G_1, …, G_q whose convex hulls share a point

    y ∈ conv{x_i : i ∈ G_1} ∩ … ∩ conv{x_i : i ∈ G_q}.

Tverberg's theorem: one exists whenever n ≥ (d + 1)(q − 1) + 1. The groups need not
cover X (a point outside every group can join any group with weight 0). With
q = F + 1 the partition proves y ∈ Ψ(X, F) = ⋂{conv(S) : |S| = n − F}: removing F
points leaves at least one whole group, whose hull contains y.

Method: a MILP finds the groups in floating point; it is only a guide. With the
groups fixed, the weights are rebuilt exactly over Q from the points' exact binary
values (``Fraction(float)``), first from the MILP's support (Carathéodory: at most
d + 1 affinely independent points per group), else by an exact phase-one simplex on
the fixed-group system, and verified exactly before anything is returned.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

from .._validate import check_points, integer, positive
from ..errors import SolverError, TimeLimitReached
from ..models.backends import require_backend, silent_highs

__all__ = ["TverbergPartition", "tverberg_partition"]

Vector = tuple[Fraction, ...]
Matrix = list[list[Fraction]]
#: The MILP's weights below this are read as 0 when guessing the support. The guess
#: is only a warm start: every answer is re-derived and verified exactly.
SUPPORT_GUESS = 1e-9


@dataclass(frozen=True, eq=False)
class TverbergPartition:
    """A Tverberg partition with exact weights, or the MILP's claim that none exists.

    Attributes
    ----------
    exists : True when a partition was found (and verified exactly). False when HiGHS
        proved the MILP infeasible: a solver claim in floating point, with no
        checkable certificate (every other field is then empty).
    groups : the q disjoint groups, each sorted, ordered by their first index. Each
        group is the exact support of its weights (all weights > 0), so the groups
        need not cover 0..n−1.
    weights : exact convex weights aligned with ``groups``: Σ_i w_i = 1, w_i > 0 and
        Σ_i w_i x_i = ``point_exact`` for every group.
    point : the common point y as floats (each coordinate correctly rounded).
    point_exact : y over Q.
    certificate : the ``kernel_point`` certificate (y ∈ Ψ(X, q − 1)), JSON-ready;
        ``{}`` when ``exists`` is False.
    seconds : wall-clock time of the whole call.
    """

    exists: bool
    groups: tuple[tuple[int, ...], ...]
    weights: tuple[tuple[Fraction, ...], ...]
    point: np.ndarray
    point_exact: tuple[Fraction, ...]
    certificate: dict[str, Any]
    seconds: float


def tverberg_partition(
    X: Any, parts: int, *, time_limit: float | None = None
) -> TverbergPartition:
    """A Tverberg partition of the rows of X into ``parts`` groups, certified exactly.

    Finds disjoint nonempty G_1, …, G_q (q = ``parts``) and a point y with
    y = Σ_{i∈G_p} w_{p,i} x_i, w_{p,i} > 0, Σ_{i∈G_p} w_{p,i} = 1 for every p, all in
    exact rational arithmetic. The MILP (binaries z_{i,p}: x_i ∈ G_p; weights
    λ_{i,p} ∈ [0, 1]; y free; no objective) is, for i = 0..n−1 and p = 1..q,

        Σ_p z_{i,p} = 1                         (every point in a group; WLOG, see Notes)
        λ_{i,p} ≤ z_{i,p},  Σ_i λ_{i,p} = 1,  Σ_i λ_{i,p} x_i = y
        z_{0,1} = 1,  z_{i,p} ≤ Σ_{j<i} z_{j,p−1}   (p ≥ 2: groups ordered by first index)

    Σ_i λ_{i,p} = 1 with λ ≤ z keeps every group nonempty; ordering the groups by
    their first index picks one of the q! labellings of each partition.

    Parameters
    ----------
    X : array_like, shape (n, d)
        The points, n ≥ 1, d ≥ 1, finite real numbers (taken as float64; integers
        must be exact in float64, |x| ≤ 2^53).
    parts : int
        The number q of groups, 1 ≤ q ≤ n. With q = F + 1 the point lies in the
        safe kernel Ψ(X, F).
    time_limit : float, optional
        Seconds allowed to building and solving the MILP (the exact reconstruction
        afterwards is polynomial and not limited).

    Returns
    -------
    TverbergPartition
        ``exists`` False when the MILP is infeasible (a HiGHS claim, not certified).

    Raises
    ------
    InputError
        X is not a finite (n, d) real array, or ``parts`` / ``time_limit`` is out of range.
    TimeLimitReached
        The MILP ran out of time before finding a partition or proving there is none.
    SolverError
        HiGHS failed, claimed infeasibility where Tverberg's theorem guarantees a
        partition, or its groups admit no exact common point (a configuration
        degenerate within HiGHS's feasibility tolerance).

    Notes
    -----
    Requiring every point in some group (Σ_p z_{i,p} = 1 instead of ≤ 1) loses
    nothing: a point can join any group with weight 0. The returned groups are the
    exact supports, so points may stay unused; disjoint groups are all the kernel
    argument needs. ``exists`` False rests on HiGHS's infeasibility proof in floating
    point, which is not checked. The MILP has 2nq + d columns and O(n²q) nonzeros;
    its LP relaxation is weak (fractional z always fits), so the solve is a search
    whose time varies widely: in the plane with q = ⌊(n − 1)/3⌋ + 1 (at or just above
    Tverberg's bound), about 0.1 s for n = 10, 0.5–1.5 s for n = 20 and 20–120 s for
    n = 40. The exact step
    works on (d+1)(q−1)+1 equations over Q: O(q d³) rational operations on the fast
    path, an exact simplex on the fallback.

    References
    ----------
    H. Tverberg, "A generalization of Radon's theorem", J. London Math. Soc. 41 (1966).

    Examples
    --------
    >>> import numpy as np
    >>> square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    >>> res = tverberg_partition(square, 2)
    >>> res.exists, res.groups, res.point_exact
    (True, ((0, 2), (1, 3)), (Fraction(1, 1), Fraction(1, 1)))
    >>> res.certificate["proof"]["parts"][0]
    {'indices': [0, 2], 'weights': ['1/2', '1/2']}
    >>> tverberg_partition(square[:3], 2).exists   # a triangle has no Radon partition
    False
    """
    t0 = time.perf_counter()
    X, q = _check_input(X, parts, time_limit)
    P = [tuple(Fraction(v) for v in row) for row in X.tolist()]
    if q == 1:
        exact: list[dict[int, Fraction]] | None = [{0: Fraction(1)}]
    else:
        exact = _solve(X, P, q, time_limit)
    if exact is None:
        return TverbergPartition(False, (), (), np.empty(0), (), {}, time.perf_counter() - t0)
    exact.sort(key=min)
    groups = tuple(tuple(sorted(w)) for w in exact)
    weights = tuple(tuple(w[i] for i in g) for w, g in zip(exact, groups))
    y = _point(P, groups[0], weights[0])
    _verify(P, groups, weights, y)
    point = np.array([float(v) for v in y])
    point.flags.writeable = False
    cert = _certificate(X, q - 1, y, groups, weights)
    return TverbergPartition(True, groups, weights, point, y, cert, time.perf_counter() - t0)


# --------------------------------------------------------------------------- #
# input
# --------------------------------------------------------------------------- #


def _check_input(X: Any, parts: Any, time_limit: Any) -> tuple[np.ndarray, int]:
    """X as a finite float64 (n, d) array and ``parts`` as an int in 1..n."""
    arr = check_points(X)
    parts = integer("parts", parts, low=1, high=arr.shape[0])
    if time_limit is not None:
        positive("time_limit", time_limit, what="finite number of seconds")
    return arr, parts


# --------------------------------------------------------------------------- #
# the MILP
# --------------------------------------------------------------------------- #


def _solve(X: np.ndarray, P: list[Vector], q: int,
           time_limit: float | None) -> list[dict[int, Fraction]] | None:
    """Exact weights (per group: index → weight > 0) of a partition, None if the MILP
    is infeasible."""
    found = _milp(X, q, time_limit)
    if found is None:
        n, d = X.shape
        if n >= (d + 1) * (q - 1) + 1:
            raise SolverError(f"HiGHS reported no Tverberg partition of {n} points in R^{d} "
                              f"into {q} parts, contradicting Tverberg's theorem")
        return None
    groups, lam = found
    exact = _from_support(P, groups, lam)
    if exact is None:
        exact = _from_simplex(P, groups, lam)
    if exact is None:
        raise SolverError(f"the MILP's groups {groups} have no exact common point: the "
                          "points are degenerate within HiGHS's feasibility tolerance")
    return exact


def _normalise(X: np.ndarray) -> np.ndarray:
    """X moved and scaled per axis into [−1, 1]^d. Tverberg partitions are affinely
    invariant, so the MILP solves this better-conditioned copy."""
    Y = X - X.mean(axis=0)
    scale = np.abs(Y).max(axis=0)
    return Y / np.where(scale > 0, scale, 1.0)


def _rows(X: np.ndarray, q: int) -> list[tuple[float, float, dict[int, float]]]:
    """Constraint rows (lower, upper, {col: coef}); columns z_{i,p} = iq + p,
    λ_{i,p} = nq + iq + p, y_k = 2nq + k."""
    n, d = X.shape
    z, lam, y = 0, n * q, 2 * n * q
    rows: list[tuple[float, float, dict[int, float]]] = []
    for i in range(n):
        rows.append((1.0, 1.0, {z + i * q + p: 1.0 for p in range(q)}))
        for p in range(q):
            rows.append((-np.inf, 0.0, {lam + i * q + p: 1.0, z + i * q + p: -1.0}))
    for p in range(q):
        rows.append((1.0, 1.0, {lam + i * q + p: 1.0 for i in range(n)}))
        for k in range(d):
            row = {lam + i * q + p: float(X[i, k]) for i in range(n) if X[i, k] != 0.0}
            row[y + k] = -1.0
            rows.append((0.0, 0.0, row))
    for p in range(1, q):
        for i in range(p, n):
            row = {z + i * q + p: 1.0}
            row.update({z + j * q + p - 1: -1.0 for j in range(i)})
            rows.append((-np.inf, 0.0, row))
    return rows


def _model(X: np.ndarray, q: int):
    """The HiGHS model of the partition MILP (no objective: feasibility)."""
    require_backend("highs", "MILP")
    import highspy

    n, d = X.shape
    nz = n * q
    h = silent_highs()
    # z_{i,p} = 0 for p > i (0-based: group p starts after the first indices of 0..p−1)
    upper = np.array([1.0 if p <= i else 0.0 for i in range(n) for p in range(q)])
    lower = np.zeros(nz)
    lower[0] = 1.0  # point 0 opens group 0
    h.addVars(2 * nz + d, np.concatenate([lower, np.zeros(nz), X.min(axis=0)]),
              np.concatenate([upper, upper, X.max(axis=0)]))
    h.changeColsIntegrality(nz, np.arange(nz, dtype=np.int32),
                            np.full(nz, highspy.HighsVarType.kInteger))
    starts, index, value, lo, up = [], [], [], [], []
    for low, high, row in _rows(X, q):
        starts.append(len(index))
        index.extend(row.keys())
        value.extend(row.values())
        lo.append(low)
        up.append(high)
    h.addRows(len(lo), np.array(lo), np.array(up), len(index),
              np.array(starts, dtype=np.int32), np.array(index, dtype=np.int32),
              np.array(value, dtype=np.float64))
    return h, highspy


def _milp(X: np.ndarray, q: int,
          time_limit: float | None) -> tuple[list[list[int]], np.ndarray] | None:
    """The MILP's groups (covering 0..n−1) and weights λ (n, q); None if infeasible."""
    deadline = None if time_limit is None else time.perf_counter() + time_limit
    n = X.shape[0]
    h, highspy = _model(_normalise(X), q)
    if deadline is not None:
        h.setOptionValue("time_limit", max(deadline - time.perf_counter(), 1e-3))
    h.run()
    S = highspy.HighsModelStatus
    status = h.getModelStatus()
    if status in (S.kInfeasible, S.kUnboundedOrInfeasible):
        return None  # every column is bounded: the model cannot be unbounded
    if status not in (S.kOptimal, S.kTimeLimit):
        raise SolverError(f"HiGHS returned {h.modelStatusToString(status)} "
                          "on the Tverberg MILP")
    if h.getInfo().primal_solution_status != 2:
        raise TimeLimitReached(f"time limit of {time_limit} s reached before the MILP "
                               f"found a partition into {q} parts or proved there is none")
    x = np.asarray(h.getSolution().col_value)
    member = x[: n * q].reshape(n, q).argmax(axis=1)
    groups = [[i for i in range(n) if member[i] == p] for p in range(q)]
    return groups, x[n * q: 2 * n * q].reshape(n, q)


# --------------------------------------------------------------------------- #
# exact reconstruction over Q
# --------------------------------------------------------------------------- #


def _rref(M: Matrix, npivot: int) -> tuple[Matrix, list[int]]:
    """Reduced row echelon form of M over Q, pivoting only in columns < npivot."""
    M = [row[:] for row in M]
    pivots: list[int] = []
    for c in range(npivot):
        r = len(pivots)
        k = next((i for i in range(r, len(M)) if M[i][c] != 0), None)
        if k is None:
            continue
        M[r], M[k] = M[k], M[r]
        inv = 1 / M[r][c]
        M[r] = [v * inv for v in M[r]]
        for i in range(len(M)):
            if i != r and M[i][c] != 0:
                f = M[i][c]
                M[i] = [a - f * b for a, b in zip(M[i], M[r])]
        pivots.append(c)
    return M, pivots


def _unique_solution(A: Matrix, b: list[Fraction]) -> list[Fraction] | None:
    """The x with A x = b when there is exactly one, else None."""
    ncol = len(A[0])
    R, pivots = _rref([row + [bi] for row, bi in zip(A, b)], ncol)
    if len(pivots) < ncol or any(row[ncol] != 0 for row in R[ncol:]):
        return None
    return [R[k][ncol] for k in range(ncol)]


def _left_null_space(columns: Matrix) -> Matrix:
    """A basis of {v : v·c = 0 for every c in ``columns``} (all of one length)."""
    width = len(columns[0])
    R, pivots = _rref(columns, width)
    basis = []
    for f in (c for c in range(width) if c not in pivots):
        v = [Fraction(0)] * width
        v[f] = Fraction(1)
        for row, c in zip(R, pivots):
            v[c] = -row[f]
        basis.append(v)
    return basis


def _lifted(P: list[Vector], i: int) -> list[Fraction]:
    """(x_i, 1): convex combinations of points are linear ones of these."""
    return [*P[i], Fraction(1)]


def _independent_support(P: list[Vector], group: list[int], lam: np.ndarray) -> list[int]:
    """The group's points with MILP weight > SUPPORT_GUESS, heaviest first, keeping each
    only if affinely independent of those kept (Carathéodory)."""
    kept: list[int] = []
    for i in sorted((i for i in group if lam[i] > SUPPORT_GUESS), key=lambda i: -lam[i]):
        if len(_rref([_lifted(P, j) for j in kept + [i]], len(P[i]) + 1)[1]) > len(kept):
            kept.append(i)
    return kept


def _from_support(P: list[Vector], groups: list[list[int]],
                  lam: np.ndarray) -> list[dict[int, Fraction]] | None:
    """Exact weights on affinely independent supports S_p read off the MILP, or None.

    y ∈ aff(S_p) ⇔ v·(y, 1) = 0 for every v ⊥ {(x_i, 1) : i ∈ S_p}; these linear
    equations must fix y uniquely; then each group's weights solve
    Σ_{i∈S_p} w_i (x_i, 1) = (y, 1) uniquely, and must be ≥ 0.
    """
    d = len(P[0])
    supports = [_independent_support(P, g, lam[:, p]) for p, g in enumerate(groups)]
    if not all(supports):
        return None
    normals = [v for S in supports for v in _left_null_space([_lifted(P, i) for i in S])]
    if len(normals) < d:
        return None
    y = _unique_solution([v[:d] for v in normals], [-v[d] for v in normals])
    if y is None:
        return None
    exact = []
    for S in supports:
        A = [[P[i][k] for i in S] for k in range(d)] + [[Fraction(1)] * len(S)]
        w = _unique_solution(A, [*y, Fraction(1)])
        if w is None or min(w) < 0:
            return None
        exact.append({i: wi for i, wi in zip(S, w) if wi > 0})
    return exact


def _from_simplex(P: list[Vector], groups: list[list[int]],
                  lam: np.ndarray) -> list[dict[int, Fraction]] | None:
    """Exact weights for the fixed groups by the exact simplex, or None if none exist.

    Unknowns w_i ≥ 0 (i in any group, group g(i)); y is eliminated through group 0:
    Σ_{i∈G_0} w_i x_i − Σ_{i∈G_p} w_i x_i = 0 (p ≥ 1) and Σ_{i∈G_p} w_i = 1 (all p).
    The MILP's heaviest weights are tried first (Bland's order).
    """
    d = len(P[0])
    cols = [(p, i) for p, g in enumerate(groups) for i in g]
    rows: Matrix = []
    for p in range(1, len(groups)):
        for k in range(d):
            rows.append([P[i][k] * (1 if g == 0 else -1 if g == p else 0) for g, i in cols])
    rows += [[Fraction(int(g == p)) for g, _ in cols] for p in range(len(groups))]
    b = [Fraction(0)] * (len(rows) - len(groups)) + [Fraction(1)] * len(groups)
    order = sorted(range(len(cols)), key=lambda j: -lam[cols[j][1], cols[j][0]])
    w = _phase_one(rows, b, order)
    if w is None:
        return None
    exact: list[dict[int, Fraction]] = [{} for _ in groups]
    for (p, i), wi in zip(cols, w):
        if wi > 0:
            exact[p][i] = wi
    return exact


def _phase_one(A: Matrix, b: list[Fraction], order: list[int]) -> list[Fraction] | None:
    """Some x ≥ 0 with A x = b over Q, or None when there is none.

    Phase one of the simplex method: minimise Σ a over A x + a = b (rows signed so
    b ≥ 0), starting from the basis of artificials a. Bland's rule on the ranking
    ``order`` (then the artificials) prevents cycling; an artificial that leaves the
    basis is dropped. The optimum is 0 iff the system is feasible.
    """
    m, ncol = len(A), len(A[0])
    T = [[-v for v in row] + [-bi] if bi < 0 else row + [bi] for row, bi in zip(A, b)]
    cost = [-sum((T[r][j] for r in range(m)), Fraction(0)) for j in range(ncol + 1)]
    rank = {j: k for k, j in enumerate(order)}
    basis = [ncol + r for r in range(m)]
    rank.update({ncol + r: ncol + r for r in range(m)})
    while True:
        entering = [j for j in range(ncol) if cost[j] < 0]
        if not entering:
            break
        j = min(entering, key=rank.__getitem__)
        r = min((r for r in range(m) if T[r][j] > 0),
                key=lambda r: (T[r][ncol] / T[r][j], rank[basis[r]]))
        inv = 1 / T[r][j]
        T[r] = [v * inv for v in T[r]]
        for row in [*T[:r], *T[r + 1:], cost]:
            f = row[j]
            if f != 0:
                row[:] = [a - f * c for a, c in zip(row, T[r])]
        basis[r] = j
    if cost[ncol] != 0:
        return None
    x = [Fraction(0)] * ncol
    for r, j in enumerate(basis):
        if j < ncol:
            x[j] = T[r][ncol]
    return x


def _point(P: list[Vector], group: tuple[int, ...], weights: tuple[Fraction, ...]) -> Vector:
    """Σ_i w_i x_i over Q."""
    return tuple(sum((w * P[i][k] for i, w in zip(group, weights)), Fraction(0))
                 for k in range(len(P[0])))


def _verify(P: list[Vector], groups: tuple[tuple[int, ...], ...],
            weights: tuple[tuple[Fraction, ...], ...], y: Vector) -> None:
    """Raise SolverError unless the groups are disjoint and nonempty and every group's
    weights are > 0, sum to 1 and combine its points to y, exactly."""
    seen = [i for g in groups for i in g]
    ok = len(seen) == len(set(seen)) and all(
        g and all(w > 0 for w in ws) and sum(ws) == 1 and _point(P, g, ws) == y
        for g, ws in zip(groups, weights)
    )
    if not ok:
        raise SolverError("internal error: the exact Tverberg partition failed verification")


def _certificate(X: np.ndarray, F: int, y: Vector, groups: tuple[tuple[int, ...], ...],
                 weights: tuple[tuple[Fraction, ...], ...]) -> dict[str, Any]:
    """The ``kernel_point`` certificate: y ∈ Ψ(X, F) by a Tverberg partition into F + 1."""
    return {
        "rescon_certificate": 1,
        "kind": "kernel_point",
        "points": X.tolist(),
        "F": F,
        "x": [str(v) for v in y],
        "proof": {
            "method": "tverberg",
            "parts": [{"indices": list(g), "weights": [str(w) for w in ws]}
                      for g, ws in zip(groups, weights)],
        },
    }
