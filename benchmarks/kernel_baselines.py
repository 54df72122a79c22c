"""Baselines for safe kernels Ψ(X, F) = ⋂ {conv(S) : S ⊆ X, |S| = n − F}, kept OUT of
the library (BENCHMARKS.md §2). Both enumerate the C(n, F) subsets, as published:

* **subset LP** (:func:`subset_lp`): one LP with ``d + C(n,F)·(n−F)`` variables: x and,
  for every subset S of size n − F, weights λ_S ≥ 0, Σ λ_S = 1, x = Σ_{i∈S} λ_{S,i} p_i.
  Feasible ⟺ Ψ ≠ ∅; maximising a random linear objective c·x gives a point of Ψ (a
  vertex in general) and the support value max_{x∈Ψ} c·x. Solved by HiGHS through
  ``scipy.optimize.linprog(method="highs")``, default settings.
* **subset-hull intersection via qhull** (:func:`subset_hull_qhull`): for every subset
  S, ``scipy.spatial.ConvexHull(X[S])`` gives its facet halfspaces; facets repeated in
  several subsets (same vertex indices, same orientation) are stacked once; an interior
  point comes from the Chebyshev LP (HiGHS) and ``scipy.spatial.HalfspaceIntersection`` gives the
  vertices of Ψ. Qhull only handles full-dimensional kernels: degenerate subsets (a
  flat S) or a kernel without interior are reported as ``n/a``.

Plus :func:`compare_lp` / :func:`compare_qhull`, the agreement checks against a
``rescon.SafeKernel`` that the runner makes before any time is reported, and
:func:`hausdorff`.

Statuses: ``optimal`` (a point / the vertices), ``infeasible`` / ``empty`` (Ψ = ∅),
``n/a`` (qhull cannot), ``skipped`` (more than ``max_subsets`` subsets),
``time_limit``, ``error:<what>``.
"""

from __future__ import annotations

import itertools
import math
import time
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp
from scipy.optimize import linprog
from scipy.spatial import ConvexHull, HalfspaceIntersection, QhullError
from scipy.spatial.distance import cdist

__all__ = [
    "LpResult",
    "QhullResult",
    "MAX_SUBSETS",
    "n_subsets",
    "subsets",
    "subset_lp",
    "subset_hull_qhull",
    "hausdorff",
    "compare_lp",
    "compare_qhull",
    "objective_for",
    "tukey_depth_2d_exact",
]

#: default cap on the number of subsets C(n, F) a baseline enumerates
MAX_SUBSETS = 200_000


def n_subsets(n: int, F: int) -> int:
    return math.comb(n, F)


def subsets(n: int, F: int) -> np.ndarray:
    """(C(n,F), n−F) int array: every subset of size n − F of range(n), in the order of
    ``itertools.combinations(range(n), F)`` of the removed indices."""
    C = math.comb(n, F)
    if F == 0:
        return np.arange(n)[None, :]
    removed = np.fromiter(itertools.chain.from_iterable(itertools.combinations(range(n), F)),
                          dtype=np.int64, count=C * F).reshape(C, F)
    keep = np.ones((C, n), dtype=bool)
    keep[np.arange(C)[:, None], removed] = False
    return np.nonzero(keep)[1].reshape(C, n - F)


def objective_for(d: int, seed: int = 0) -> np.ndarray:
    """The random unit objective c of the subset LP (fixed seed)."""
    c = np.random.default_rng(seed).standard_normal(d)
    return c / np.linalg.norm(c)


# --------------------------------------------------------------------------- subset LP


class LpResult(NamedTuple):
    status: str  # optimal, infeasible, skipped, time_limit, error:...
    x: np.ndarray | None
    value: float | None  # max c·x over Ψ
    c: np.ndarray
    n_vars: int
    detail: str = ""


def subset_lp(X: Any, F: int, *, objective: np.ndarray | None = None,
              max_subsets: int = MAX_SUBSETS, time_limit: float | None = None) -> LpResult:
    """max c·x s.t. x ∈ conv(S) for every S of size n − F (one LP, HiGHS).

    ``objective`` None: a random unit vector (:func:`objective_for`); pass zeros for a
    pure feasibility problem. The time covers building and solving the model.
    """
    X = np.asarray(X, dtype=np.float64)
    n, d = X.shape
    c = objective_for(d) if objective is None else np.asarray(objective, dtype=np.float64)
    C = math.comb(n, F)
    k = n - F
    nv = d + C * k
    if C > max_subsets:
        return LpResult("skipped", None, None, c, nv, f"C({n},{F}) = {C} > {max_subsets} subsets")
    S = subsets(n, F)  # (C, k)
    lam = d + np.arange(C * k).reshape(C, k)  # variable index of λ_{s,j}
    # rows s(d+1)+t, t < d: Σ_j λ_{s,j} X[S_{s,j}, t] − x_t = 0; row s(d+1)+d: Σ_j λ = 1
    base = (np.arange(C) * (d + 1))[:, None]
    r_l, c_l, v_l = [], [], []
    for t in range(d):
        r_l.append(np.broadcast_to(base + t, (C, k)).ravel())
        c_l.append(lam.ravel())
        v_l.append(X[S, t].ravel())
        r_l.append(np.arange(C) * (d + 1) + t)
        c_l.append(np.full(C, t))
        v_l.append(np.full(C, -1.0))
    r_l.append(np.broadcast_to(base + d, (C, k)).ravel())
    c_l.append(lam.ravel())
    v_l.append(np.ones(C * k))
    A = sp.csc_matrix((np.concatenate(v_l), (np.concatenate(r_l), np.concatenate(c_l))),
                      shape=(C * (d + 1), nv))
    beq = np.tile(np.r_[np.zeros(d), 1.0], C)
    cost = np.zeros(nv)
    cost[:d] = -c
    bounds = np.zeros((nv, 2))
    bounds[:, 1] = np.inf
    bounds[:d, 0] = -np.inf
    opts: dict[str, Any] = {}
    if time_limit is not None:
        opts["time_limit"] = float(time_limit)
    res = linprog(cost, A_eq=A, b_eq=beq, bounds=bounds, method="highs", options=opts)
    if res.status == 0:
        x = np.array(res.x[:d])
        return LpResult("optimal", x, float(c @ x), c, nv)
    if res.status == 2:
        return LpResult("infeasible", None, None, c, nv, res.message)
    if res.status == 1 and "time" in str(res.message).lower():
        return LpResult("time_limit", None, None, c, nv, res.message)
    return LpResult(f"error:status{res.status}", None, None, c, nv, str(res.message))


# --------------------------------------------------------------------------- qhull


class QhullResult(NamedTuple):
    status: str  # optimal, empty, n/a, skipped, time_limit, error:...
    vertices: np.ndarray | None
    n_halfspaces: int
    inradius: float | None
    detail: str = ""


def subset_hull_qhull(X: Any, F: int, *, max_subsets: int = MAX_SUBSETS,
                      time_limit: float | None = None, interior_tol: float = 1e-12
                      ) -> QhullResult:
    """Vertices of Ψ as the intersection of the facet halfspaces of every conv(S).

    Returns status ``n/a`` when a subset is not full-dimensional (qhull fails on it) or
    the intersection has inradius ≤ ``interior_tol`` (qhull needs an interior point),
    ``empty`` when the Chebyshev LP proves the intersection empty (inradius <
    −``interior_tol``, i.e. no point satisfies all halfspaces).
    """
    X = np.asarray(X, dtype=np.float64)
    n, d = X.shape
    C = math.comb(n, F)
    if C > max_subsets:
        return QhullResult("skipped", None, 0, None, f"C({n},{F}) = {C} > {max_subsets} subsets")
    t0 = time.perf_counter()
    seen: dict[tuple[tuple[int, ...], bool], np.ndarray] = {}
    for s, S in enumerate(itertools.combinations(range(n), n - F)):
        if time_limit is not None and s % 256 == 0 and time.perf_counter() - t0 > time_limit:
            return QhullResult("time_limit", None, len(seen), None, f"after {s} of {C} subsets")
        idx = np.fromiter(S, dtype=np.int64, count=n - F)
        try:
            hull = ConvexHull(X[idx])
        except QhullError as exc:
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else "QhullError"
            return QhullResult("n/a", None, len(seen), None,
                               f"subset not full-dimensional ({first[:80]})")
        glob = np.sort(idx[hull.simplices], axis=1)
        eqs = hull.equations
        # the same facet points may bound different subsets from opposite sides: the
        # key is the vertex set and the orientation (sign of the largest normal entry)
        big = np.argmax(np.abs(eqs[:, :d]), axis=1)
        pos = eqs[np.arange(len(eqs)), big] > 0
        for key, p, eq in zip(map(tuple, glob), pos, eqs, strict=True):
            if (key, p) not in seen:
                seen[(key, p)] = eq
    H = np.array(list(seen.values()))  # rows (a, b0): a·x + b0 ≤ 0, |a| = 1
    A, b = H[:, :d], -H[:, d]
    # Chebyshev centre: max r s.t. a·x + r|a| ≤ b, inside the data's bounding box
    lo, hi = X.min(axis=0), X.max(axis=0)
    span = float(np.max(hi - lo)) or 1.0
    norms = np.linalg.norm(A, axis=1)
    cost = np.zeros(d + 1)
    cost[d] = -1.0
    bounds = [(lo[j] - span, hi[j] + span) for j in range(d)] + [(-span, span)]
    opts: dict[str, Any] = {}
    if time_limit is not None:
        opts["time_limit"] = max(1.0, time_limit - (time.perf_counter() - t0))
    res = linprog(cost, A_ub=np.column_stack([A, norms]), b_ub=b, bounds=bounds,
                  method="highs", options=opts)
    if res.status != 0:
        return QhullResult(f"error:chebyshev_lp_status{res.status}", None, len(H), None,
                           str(res.message))
    r = float(res.x[d])
    if r < -interior_tol:
        return QhullResult("empty", None, len(H), r, f"Chebyshev LP: inradius {r:.3g} < 0")
    if r <= interior_tol:
        return QhullResult("n/a", None, len(H), r,
                           f"kernel without interior (inradius {r:.3g}): qhull cannot")
    try:
        hs = HalfspaceIntersection(H, np.asarray(res.x[:d]))
    except QhullError as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else "QhullError"
        return QhullResult("error:qhull", None, len(H), r, first[:120])
    V = hs.intersections
    V = V[np.all(np.isfinite(V), axis=1)]
    return QhullResult("optimal", V, len(H), r)


# --------------------------------------------------------------------------- agreement


def hausdorff(P: np.ndarray, Q: np.ndarray) -> float:
    """Hausdorff distance between two finite point sets (vertex sets of polytopes:
    the same as between their convex hulls only up to the vertices; used for
    vertex-set agreement)."""
    if len(P) == 0 or len(Q) == 0:
        return 0.0 if len(P) == len(Q) else math.inf
    D = cdist(P, Q)
    return float(max(D.min(axis=1).max(), D.min(axis=0).max()))


def compare_lp(K: Any, r: LpResult, tol: float = 1e-6) -> str | None:
    """None if the subset LP agrees with the kernel K, else what disagrees.

    Nonempty: the LP point must satisfy ``K.contains(x, tol)`` and its value c·x must
    equal max over K's vertices of c·v (within tol·(1 + |value|)). Empty ⟺ infeasible.
    """
    if r.status == "infeasible":
        return None if K.is_empty else (f"subset LP infeasible but rescon kernel has dim "
                                        f"{K.dim} and {len(K.vertices)} vertices")
    if r.status != "optimal":
        return None  # skipped / time-out / solver error: nothing to compare
    if K.is_empty:
        return f"subset LP feasible (x = {r.x.tolist()}) but rescon says the kernel is empty"
    errs = []
    if not K.contains(r.x, tol=tol):
        errs.append(f"LP point {r.x.tolist()} not in the rescon kernel (tol {tol:g})")
    best = float(np.max(K.vertices @ r.c))
    if abs(best - r.value) > tol * (1.0 + abs(best)):
        errs.append(f"support value max c·x: LP {r.value!r} vs rescon vertices {best!r} "
                    f"(c = {r.c.tolist()})")
    return "; ".join(errs) or None


def compare_qhull(K: Any, r: QhullResult, tol: float = 1e-6, margin: float = 1e-9
                  ) -> tuple[str | None, float | None]:
    """(disagreement or None, Hausdorff distance or None) between qhull and K.

    ``margin``: inradii within ±margin of 0 are not compared (thin kernels, where a
    float Chebyshev LP cannot tell full-dimensional from degenerate)."""
    d = K.points.shape[1]
    if r.status == "empty":
        if K.is_empty or (r.inradius is not None and r.inradius > -margin):
            return None, None
        return (f"qhull/Chebyshev LP says empty (inradius {r.inradius:.3g}) but rescon "
                f"kernel has dim {K.dim}"), None
    if r.status == "n/a":
        if (r.inradius is not None and K.dim == d and r.inradius < -margin):
            return f"qhull inradius {r.inradius:.3g} but rescon kernel is full-dimensional", None
        return None, None
    if r.status != "optimal":
        return None, None
    if K.dim < d:
        if r.inradius is not None and r.inradius <= margin:
            return None, None
        what = "empty" if K.is_empty else f"of dim {K.dim}"
        return (f"qhull finds an interior (inradius {r.inradius:.3g}) but rescon kernel is "
                f"{what}"), None
    h = hausdorff(r.vertices, K.vertices)
    if not h <= tol:
        return f"vertices differ: Hausdorff distance {h:.3g} > {tol:g}", h
    return None, h


# --------------------------------------------------------------------------- referee


def tukey_depth_2d_exact(X: Any, x: Any) -> int:
    """Exact Tukey (halfspace) depth of x in the planar multiset X: the least number of
    points of X in a closed halfplane whose boundary passes through x. Rational
    arithmetic on the floats' exact values, O(n²); used to settle a disagreement about
    a baseline's point (x ∈ Ψ(X, F) ⟺ depth ≥ F + 1)."""
    from fractions import Fraction as Q

    P = [(Q(float(a)), Q(float(b))) for a, b in np.asarray(X, dtype=np.float64)]
    z = (Q(float(x[0])), Q(float(x[1])))
    at = sum(1 for p in P if p == z)
    best = len(P)
    for p in P:
        if p == z:
            continue
        v = (p[0] - z[0], p[1] - z[1])
        for s in (1, -1):
            u = (-s * v[1], s * v[0])
            pos = plus = minus = 0
            for q in P:
                if q == z:
                    continue
                w = (q[0] - z[0], q[1] - z[1])
                a = u[0] * w[0] + u[1] * w[1]
                if a > 0:
                    pos += 1
                elif a == 0:
                    if v[0] * w[0] + v[1] * w[1] > 0:
                        plus += 1
                    else:
                        minus += 1
            # rotating the boundary slightly about x drops one of the two rays' points
            best = min(best, at + pos + min(plus, minus))
    return best if len(P) > at else at
