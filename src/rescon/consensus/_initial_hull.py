"""The certified hull H = conv{x_j(0) : j ∈ B} of the initial benign states.

H is computed exactly once, as the exact polytope that safe_kernel(X, 0) returns.
Qhull proposes the vertices V (:func:`_proposed_rows`: on X's principal axes, so a
thin X becomes a fat one; its degeneracy failure retried joggled), the exact polytope
conv X[V] (the safe kernel of X[V] with F = 0) is built, and every other row is
proven in it — the float filter of its exact facets (``_facet_filter``), the exact
test where the filter is unsure — or added to V and the hull rebuilt
(:func:`certified_hull`): a wrong proposal costs time, never the answer. Past
PROPOSE_MIN rows the plane's hull is an exact monotone chain (:func:`_exact_polygon`,
Andrew's :func:`_chain` in integers; each counter-clockwise edge [p, q] gives the
facet a·x ≤ a·p, a = (q₂ − p₂, p₁ − q₁)) and R³'s Qhull's triangulated boundary
certified exactly (:func:`_exact_polytope`, ``_hull_surface``): initial states that
are all vertices (a circle, a sphere) cost O(n log n), not O(h³) or O(h⁴).
"""

from __future__ import annotations

import time
from fractions import Fraction
from typing import Any

import numpy as np

from ..geometry.exact import exact_points, fraction_str, halfspaces_json
from ..geometry.kernel import SafeKernel, _affine_of, _Exact, _unit_rows, safe_kernel
from ._facet_filter import _filter_rows, _slacks
from ._hull_surface import _certified_surface, _polytope_of

#: up to this many initial states the hull is built from all of them (no proposal)
PROPOSE_MIN = 64


def certified_hull(X: np.ndarray):
    """conv X (rows of X, (n, d)) as the exact polytope safe_kernel(X[V], 0) for rows V
    with conv X[V] = conv X. V is proposed by Qhull (:func:`_proposed_rows`) and then
    certified: every other row is proven in conv X[V] (the float filter of its exact
    facets, :meth:`ValidityMonitor.surely_inside`, and the exact test where the filter
    is unsure); rows that are not are added to V and conv X[V] is rebuilt. The hull of
    n points costs one Qhull call, the exact kernel of its h vertices and O(n·facets)
    float work, instead of the O(n^d) candidates of safe_kernel(X, 0). For n >
    PROPOSE_MIN the plane's hull comes from an exact monotone chain
    (:func:`_exact_polygon`) and R³'s from Qhull's triangulated boundary certified
    exactly (:func:`_exact_polytope`): initial states that are all vertices (a circle,
    a sphere) cost O(n log n), not O(h³) or O(h⁴)."""
    X = np.asarray(X, dtype=np.float64)
    if X.ndim == 2 and len(X) > PROPOSE_MIN and np.isfinite(X).all():
        if X.shape[1] == 2:
            return _exact_polygon(X)
        hull = _exact_polytope(X) if X.shape[1] == 3 else None
        if hull is not None:
            return hull
    rows = _proposed_rows(X)
    while True:
        hull = safe_kernel(X[rows], 0)
        outside = _rows_outside(hull, X, rows)
        if not outside.size:
            return hull
        rows = np.union1d(rows, outside)


def _exact_polygon(X: np.ndarray):
    """conv X in the plane (rows of X finite, (n, 2)) as the exact polytope that
    safe_kernel(X, 0) returns, built from the vertices of an exact monotone chain
    (:func:`_chain`): for a counter-clockwise cycle v_0 … v_{h−1} (h ≥ 3) each edge
    [p, q] gives the facet a·x ≤ a·p with a = (q₂ − p₂, p₁ − q₁) (outward: the cycle
    turns left); its certificate lists each vertex's two cycle neighbours as its
    adjacency, and its cache the rows ending each edge (:func:`_polygon_edges`).
    O(n log n) and h exact facets instead of safe_kernel's O(n³) side tests; a flat X
    (h ≤ 2) is left to safe_kernel on those vertices."""
    t0 = time.perf_counter()
    U = np.unique(X, axis=0)  # distinct rows in lexicographic order (exact comparisons)
    P = exact_points(U)
    cycle = _chain(P.ints)
    if len(cycle) < 3:
        return safe_kernel(U[cycle], 0)
    order = sorted(cycle)  # lexicographic order of the vertices, as safe_kernel's
    where = {c: j for j, c in enumerate(order)}
    verts = tuple(P.fraction(c) for c in order)
    facets = []
    for i, c in enumerate(cycle):
        (p1, p2), (q1, q2) = P.ints[c], P.ints[cycle[(i + 1) % len(cycle)]]
        a = (q2 - p2, p1 - q1)
        facets.append(((Fraction(a[0]), Fraction(a[1])),
                       Fraction(a[0] * p1 + a[1] * p2, P.scale)))
    facets = tuple(facets)
    adjacency = [[] for _ in order]
    for i, c in enumerate(cycle):
        adjacency[where[c]] = sorted((where[cycle[i - 1]], where[cycle[(i + 1) % len(cycle)]]))
    V = U[order]
    dim, origin, basis, Aeq, beq, _ = _affine_of(verts, 2, True)
    A, b = _unit_rows(facets, 2)

    def certificate() -> dict[str, Any]:
        return {"rescon_certificate": 1, "kind": "safe_kernel", "points": V.tolist(), "F": 0,
                "dim": dim, "vertices": [[fraction_str(v) for v in x] for x in verts],
                "equalities": [], "facets": halfspaces_json(facets), "adjacency": adjacency,
                "proof": {"method": "halfspaces"}}

    return SafeKernel(V, 0, dim, V.copy(), A, b, origin, basis, Aeq, beq,
                      time.perf_counter() - t0, verts, _Exact(verts, facets, (), facets),
                      certificate, {"edge_ends": (U[cycle], U[np.roll(cycle, -1)])})


def _chain(ints: tuple[tuple[int, ...], ...]) -> list[int]:
    """Andrew's monotone chain on distinct points given in lexicographic order (exact
    integer coordinates): the indices of the vertices of their convex hull, counter-
    clockwise from the first point. A point is popped while the last turn is not
    strictly left — the cross product (b − o) × (c − o) ≤ 0, exact in Python integers
    — so points on an edge (collinear) and repeated ones are dropped."""
    def half(indices) -> list[int]:
        out: list[int] = []
        for c in indices:
            cx, cy = ints[c]
            while len(out) >= 2:
                (ox, oy), (bx, by) = ints[out[-2]], ints[out[-1]]
                if (bx - ox) * (cy - oy) - (by - oy) * (cx - ox) > 0:
                    break
                out.pop()
            out.append(c)
        return out

    n = len(ints)
    if n == 1:
        return [0]
    return half(range(n))[:-1] + half(range(n - 1, -1, -1))[:-1]


def _exact_polytope(X: np.ndarray):
    """conv X in R³ (rows of X finite, (n, 3)) as the exact polytope that
    safe_kernel(X, 0) returns, from Qhull's triangulated boundary of the distinct rows
    U, certified exactly (:func:`_certified_surface`); its facets are the distinct
    planes of the triangles, its vertices the triangle corners on ≥ 3 of them
    (:func:`_polytope_of`). O(n log n) floats and O(n) filtered orientation tests,
    instead of safe_kernel's O(n⁴) side tests; None when no proposal (Qhull's
    default, then joggled) is certified — a flat X, or one Qhull fails on."""
    t0 = time.perf_counter()
    U = np.unique(X, axis=0)  # distinct rows in lexicographic order (exact comparisons)
    Z = _principal(U)
    if Z.shape[1] < 3:
        return None
    for options in QHULL_OPTIONS:
        found = _qhull(Z, options)
        surface = None if found is None else _certified_surface(U, found.simplices)
        if surface is not None:
            return _polytope_of(U, *surface, time.perf_counter() - t0)
    return None


def _rows_outside(hull, X: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """Rows of X (other than ``rows``, the hull's own points) not in ``hull`` (exact)."""
    rest = np.setdiff1d(np.arange(len(X)), rows)
    if hull.dim == X.shape[1] and hull._exact.facets:
        A, b = _filter_rows(hull._exact.facets)
        S, bound = _slacks(A, b, X[rest])
        rest = rest[~(S < -bound).all(axis=1)]
    return np.array([i for i in rest if not hull.contains(X[i])], dtype=np.int64)


def _proposed_rows(X: np.ndarray) -> np.ndarray:
    """Row indices that Qhull finds to be the vertices of conv X (a proposal: rounding
    may add or miss some; :func:`certified_hull` decides). All rows for small n or
    d > 3; Qhull on X's principal axes (:func:`_principal`), its own degeneracy
    failure retried joggled ("QJ"), then every row is proposed."""
    n, d = X.shape
    if n <= PROPOSE_MIN or d > 3:
        return np.arange(n)
    Z = _principal(X)
    if Z.shape[1] <= 1:
        return np.unique([0, *(np.argmin(Z, axis=0)), *(np.argmax(Z, axis=0))])
    for options in QHULL_OPTIONS:
        found = _qhull(Z, options)
        if found is not None:
            return np.sort(found.vertices)
    return np.arange(n)  # too few points for Qhull


#: Qhull's options, tried in turn: its default (merged facets, triangulated), joggled
QHULL_OPTIONS = (None, "QJ")


def _principal(X: np.ndarray) -> np.ndarray:
    """X put on its principal axes, each scaled to unit width (an affine map keeps the
    vertices and the facets: a thin or flat X becomes a fat one), axes of width
    exactly 0 dropped; X first scaled by a power of two to max |x| ∈ [1/2, 1)."""
    top = np.abs(X).max()
    Y = np.ldexp(X, -int(np.frexp(top)[1])) if top > 0 else X
    Y = Y - Y.mean(axis=0)
    Z = Y @ np.linalg.svd(Y, full_matrices=False)[2].T
    width = Z.max(axis=0) - Z.min(axis=0)
    return Z[:, width > 0] / width[width > 0]


def _qhull(Z: np.ndarray, options: str | None):
    """scipy's ConvexHull of Z (triangulated facets), or None where Qhull fails."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        return ConvexHull(Z, qhull_options=options)
    except QhullError:
        return None
