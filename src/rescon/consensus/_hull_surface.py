"""The certified boundary of a hull in R³: Qhull's triangles proven to bound conv U.

Qhull's triangulated boundary of the distinct rows U is only a proposal.
:func:`_certified_surface` proves it with exact orientation signs (:class:`_Orient3`:
a float filter with Shewchuk's error bound on rows scaled by a power of two, exact
integers where it is unsure): a point o strictly on the inner side of every
triangle's plane, every directed edge once each way (closed), the far corner across
each edge not beyond the plane (locally convex), one ray from o meeting one cone only,
and every other row in some conv(o, T_f). Then conv U = ⋃_f conv(o, T_f) = ⋂_f
{a_f·x ≤ β_f} (the proof is in :func:`_certified_surface`; Mehlhorn et al., Comput.
Geom. 12 (1999)). :func:`_polytope_of` builds the exact polytope from the certified
triangles: the distinct planes as facets (primitive integer normals), the corners on
≥ 3 planes as vertices, chains of crease edges as the polytope's edges. The walk of
:func:`_cone_guesses` (Devillers, Pion, Teillaud 2002) guesses the cone from o that
holds a point; a wrong guess only leaves the point to a later test. The validity
monitor reuses the triangles, the walk and the float orientation.
"""

from __future__ import annotations

import math
import operator
from fractions import Fraction
from typing import Any

import numpy as np

from .._rounding import MIN_SUBNORMAL, UNIT_ROUNDOFF
from ..geometry.exact import exact_points, fraction_str, halfspaces_json
from ..geometry.kernel import SafeKernel, _affine_of, _Exact, _unit_rows


class _Orient3:
    """Exact signs of orient(a, b, c, q) = det[b − a, c − a, q − a] for rows of a point
    array R: a float filter (:func:`_orient3_float`) on R·2^-e (max |entry| < 1; rows
    that scaling rounds are never decided by it), exact integers where it is unsure."""

    def __init__(self, R: np.ndarray) -> None:
        self.R = R
        self.e = int(np.frexp(np.abs(R).max())[1])
        self.Y = np.ldexp(R, -self.e)
        self.ok = (np.ldexp(self.Y, self.e) == R).all(axis=1)
        self.P = exact_points(R)

    def __call__(self, a: np.ndarray, b: np.ndarray, c: np.ndarray,
                 q: np.ndarray) -> np.ndarray:
        Y = self.Y
        det, bound = _orient3_float(Y[a], Y[b], Y[c], Y[q])
        bound[~(self.ok[a] & self.ok[b] & self.ok[c] & self.ok[q])] = np.inf
        sign = np.where(det > bound, 1, np.where(det < -bound, -1, 0))
        ints = self.P.ints
        for r in np.flatnonzero(sign == 0):
            sign[r] = _orient3_exact(ints[a[r]], ints[b[r]], ints[c[r]], ints[q[r]])
        return sign


def _orient3_float(A: np.ndarray, B: np.ndarray, C: np.ndarray, Q: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Per row, fl(orient(a, b, c, q)) = −fl(det[a − q, b − q, c − q]) and a bound on
    its error: Shewchuk's 7u + 56u² times the permanent (taken as 8u), plus
    8(M + 1)·2^-1074 for gradual underflow (each of the 9 products may lose 2^-1075,
    the inner ones then multiplied by at most M = the largest |difference|).
    Overflow makes the value or the bound inf or NaN: undecided."""
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        a, b, c = A - Q, B - Q, C - Q
        m0 = b[:, 1] * c[:, 2] - b[:, 2] * c[:, 1]
        m1 = b[:, 2] * c[:, 0] - b[:, 0] * c[:, 2]
        m2 = b[:, 0] * c[:, 1] - b[:, 1] * c[:, 0]
        det = -(a[:, 0] * m0 + a[:, 1] * m1 + a[:, 2] * m2)
        ab, ac = np.abs(b), np.abs(c)
        perm = (np.abs(a[:, 0]) * (ab[:, 1] * ac[:, 2] + ab[:, 2] * ac[:, 1])
                + np.abs(a[:, 1]) * (ab[:, 2] * ac[:, 0] + ab[:, 0] * ac[:, 2])
                + np.abs(a[:, 2]) * (ab[:, 0] * ac[:, 1] + ab[:, 1] * ac[:, 0]))
        top = np.maximum(np.abs(a).max(axis=1), np.maximum(ab.max(axis=1), ac.max(axis=1)))
        bound = 8 * UNIT_ROUNDOFF * perm + 8 * MIN_SUBNORMAL * (top + 1)
    return det, np.where(np.isnan(bound), np.inf, bound)


def _orient3_exact(a, b, c, q) -> int:
    """The sign of det[b − a, c − a, q − a] for integer points."""
    u = [y - x for x, y in zip(a, b)]
    v = [y - x for x, y in zip(a, c)]
    w = [y - x for x, y in zip(a, q)]
    det = (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
           + u[2] * (v[0] * w[1] - v[1] * w[0]))
    return (det > 0) - (det < 0)


def _certified_surface(U: np.ndarray, simplices: np.ndarray):
    """Certify that the triangles ``simplices`` (rows of U, (T, 3)) bound conv U:
    (orient, T, mate) with the triangles oriented outwards and mate[f, r] the
    triangle across edge r of triangle f, or None. With o a float point (the mean of
    the corners) and exact orientation tests (:class:`_Orient3`), it checks

    1. o lies strictly on one side of each triangle's plane (the triangle is then
       ordered so that o is on its negative side);
    2. closed: every directed edge (i, j) occurs once, and (j, i) once;
    3. locally convex: across each edge, the far corner of the other triangle is not
       on the positive side of this one's plane;
    4. one ray: the ray from o through a point c strictly inside the cone of one
       triangle f₀ (its float centroid) meets no other closed cone {o + t(y − o) :
       y ∈ T_g, t ≥ 0};
    5. every row of U not a corner lies in conv(o, T_f) for some f (three cone sides
       and f's plane, :func:`_located`).

    Proof that then conv U = K := ⋃_f conv(o, T_f) = ⋂_f {a_f·x ≤ β_f}: by 1 the
    radial projection from o maps each triangle onto a spherical triangle with
    positive orientation, and by 2 these form a 2-cycle on the sphere, so every
    direction off their edges is covered the same number of times — once, by 4. The
    surface S = ⋃ T_f is thus a closed surface star-shaped about o, and with 3 it is
    the boundary of a convex polytope (Mehlhorn, Näher, Schilz, Schirra, Seel, Seidel,
    Uhrig, "Checking geometric programs or verification of geometric structures",
    Comput. Geom. 12 (1999) 85–103: a closed oriented surface locally convex at every
    edge, a point on the negative side of every facet and a ray from it meeting one
    facet only); that polytope is K, the intersection of the triangles' halfspaces
    (a point beyond S on a ray from o is beyond the plane of the triangle the ray
    crosses). Its boundary S lies in conv U (each T_f does) and so does K = conv S;
    the corners lie on S and, by 5, every other row in K: conv U ⊆ K ⊆ conv U."""
    m, T = len(U), np.asarray(simplices, dtype=np.int64)
    corners = np.unique(T)
    scale = int(np.frexp(np.abs(U).max())[1])
    tri = np.ldexp(U, -scale)[T]
    f0 = int(np.argmax(np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]),
                                      axis=1)))
    o = np.ldexp(np.ldexp(U[corners], -scale).mean(axis=0), scale)
    c = np.ldexp(tri[f0].mean(axis=0), scale)
    orient = _Orient3(np.vstack([U, o, c]))
    a, b, cc = T.T
    side = orient(a, b, cc, np.full(len(T), m))
    if not side.all():
        return None
    T = np.stack([a, np.where(side > 0, cc, b), np.where(side > 0, b, cc)], axis=1)
    mate = _closed_convex(orient, T)
    if mate is None or not _one_ray(orient, T, f0, m, m + 1):
        return None
    rest = np.setdiff1d(np.arange(m), corners)
    if rest.size and not _located(orient, T, mate, m, rest).all():
        return None
    return orient, T, mate


def _closed_convex(orient: _Orient3, T: np.ndarray) -> np.ndarray | None:
    """Conditions 2 and 3 of :func:`_certified_surface`: mate (T, 3), mate[f, r] the
    triangle across edge r (T[f, r] → T[f, r + 1]) of triangle f, or None."""
    n = len(orient.Y)
    head, tail, third = T.ravel(), T[:, [1, 2, 0]].ravel(), T[:, [2, 0, 1]].ravel()
    key = head * n + tail
    order = np.argsort(key, kind="stable")
    ordered = key[order]
    if (ordered[1:] == ordered[:-1]).any():
        return None
    pos = np.minimum(np.searchsorted(ordered, tail * n + head), len(key) - 1)
    if not (ordered[pos] == tail * n + head).all():
        return None
    across = order[pos]
    once = head < tail
    if (orient(head[once], tail[once], third[once], third[across][once]) > 0).any():
        return None
    return (across // 3).reshape(-1, 3)


def _one_ray(orient: _Orient3, T: np.ndarray, f0: int, o: int, c: int) -> bool:
    """Condition 4 of :func:`_certified_surface`: the direction c − o is strictly
    inside the cone of triangle f0 from o and in no other triangle's closed cone."""
    sides = _cone_sides(orient, T, np.full(len(T), o), np.full(len(T), c))
    inside = (sides >= 0).all(axis=0)
    return bool((sides[:, f0] > 0).all() and inside.sum() == 1)


def _cone_sides(orient: _Orient3, T: np.ndarray, o: np.ndarray, q: np.ndarray
                ) -> np.ndarray:
    """(3, len(T)): the signs of orient(o, a, b, q), orient(o, b, c, q), orient(o, c,
    a, q) for triangles (a, b, c) = T and points q (all ≥ 0: q in the closed cone of
    the triangle from o, when o is on the triangle's negative side)."""
    a, b, c = T.T
    return np.stack([orient(o, a, b, q), orient(o, b, c, q), orient(o, c, a, q)])


def _located(orient: _Orient3, T: np.ndarray, mate: np.ndarray, o: int, rows: np.ndarray
             ) -> np.ndarray:
    """Condition 5 of :func:`_certified_surface`: which ``rows`` are proven in
    conv(o, T_f) for some triangle f — the closed cone of T_f from o and the closed
    negative side of its plane. The triangles tried first are those of a walk
    towards the row (:func:`_cone_guesses`); rows none of them takes are tried against
    every triangle."""
    found = np.zeros(len(rows), dtype=bool)
    Y = orient.Y
    guesses = _cone_guesses(_cone_tree(Y[T], Y[o]), Y[T], mate, Y[o], Y[rows])
    for g in guesses.T:
        todo = np.flatnonzero(~found)
        found[todo] = _in_tetra(orient, T[g[todo]], o, rows[todo])
    for i in np.flatnonzero(~found):
        found[i] = _in_tetra(orient, T, o, np.full(len(T), rows[i])).any()
    return found


def _in_tetra(orient: _Orient3, T: np.ndarray, o: int, q: np.ndarray) -> np.ndarray:
    """Per row: q ∈ conv(o, T_f) for the triangle T_f in the same row of T (exact)."""
    inside = (_cone_sides(orient, T, np.full(len(T), o), q) >= 0).all(axis=0)
    a, b, c = T[inside].T
    inside[inside] = orient(a, b, c, q[inside]) <= 0
    return inside


#: steps of the walk that guesses a state's cone (:func:`_cone_guesses`)
CONE_STEPS = 8


def _cone_tree(corners: np.ndarray, o: np.ndarray):
    """A k-d tree of the triangles' centroid directions from o (corners (T, 3, 3))."""
    from scipy.spatial import cKDTree

    return cKDTree(_directions(corners.mean(axis=1) - o))


def _cone_guesses(tree, corners: np.ndarray, mate: np.ndarray, o: np.ndarray,
                  X: np.ndarray) -> np.ndarray:
    """(len(X), CONE_STEPS + 1): for each row x, guesses of the triangle whose cone from
    o holds x (a wrong one only leaves x to a later test): the triangle whose centroid
    direction is nearest to x's (``tree``, :func:`_cone_tree`), then a walk (Devillers,
    Pion, Teillaud, "Walking in a triangulation", 2002): each step crosses to the
    triangle across the side of the current cone that x is most outside of, by the
    float orientations (mate (T, 3): the triangle across edge r of triangle f)."""
    f = tree.query(_directions(X - o))[1].reshape(len(X))
    apex = np.broadcast_to(o, X.shape)
    visited = [f]
    for _ in range(CONE_STEPS):
        A, B, C = corners[f].transpose(1, 0, 2)
        sides = np.stack([_orient3_float(apex, P, Q, X)[0] for P, Q in ((A, B), (B, C), (C, A))],
                         axis=1)
        r = np.argmin(np.where(np.isnan(sides), np.inf, sides), axis=1)
        f = np.where(sides[np.arange(len(X)), r] < 0, mate[f, r], f)
        visited.append(f)
    return np.stack(visited, axis=1)


def _directions(V: np.ndarray) -> np.ndarray:
    """Rows of V divided by their norms (rows of norm 0 or not finite: (1, 0, 0))."""
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        D = V / np.linalg.norm(V, axis=1)[:, None]
    D[~np.isfinite(D).all(axis=1)] = (1.0, 0.0, 0.0)
    return D


def _polytope_of(U: np.ndarray, orient: _Orient3, T: np.ndarray, mate: np.ndarray,
                 seconds: float):
    """The SafeKernel of conv U from a certified surface (:func:`_certified_surface`):
    facets a·x ≤ β from the distinct planes of the triangles (a = the primitive
    integer normal (b − a) × (c − a) / gcd, outward; β = a·a_f / scale), vertices the
    corners on ≥ 3 distinct planes (a corner on 1 lies inside a facet, on 2 inside an
    edge), the certificate's adjacency from the chains of crease edges
    (:func:`_crease_adjacency`); its cache keeps the triangles and o for the
    validity monitor's cone filter and the facet of each triangle ("planes")."""
    P = orient.P
    planes: dict[tuple[int, ...], int] = {}
    facets = []
    plane_of = np.empty(len(T), dtype=np.int64)
    for f, (i, j, k) in enumerate(T.tolist()):
        p, q, r = P.ints[i], P.ints[j], P.ints[k]
        u = [y - x for x, y in zip(p, q)]
        v = [y - x for x, y in zip(p, r)]
        n = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
        g = math.gcd(*n)
        n = tuple(t // g for t in n)
        plane_of[f] = planes.setdefault(n, len(planes))
        if plane_of[f] == len(facets):
            facets.append((tuple(map(Fraction, n)),
                           Fraction(sum(map(operator.mul, n, p)), P.scale)))
    facets = tuple(facets)
    pairs = np.unique(T.ravel() * len(facets) + np.repeat(plane_of, 3))
    is_vertex = np.bincount(pairs // len(facets), minlength=len(U)) >= 3
    rows = np.flatnonzero(is_vertex)  # lexicographic order, as safe_kernel's
    verts = tuple(P.fraction(i) for i in rows)
    V = U[rows]
    dim, origin, basis, Aeq, beq, _ = _affine_of(verts, 3, True)
    A, b = _unit_rows(facets, 3)
    crease = (plane_of[mate] != plane_of[:, None]).ravel()

    def certificate() -> dict[str, Any]:
        return {"rescon_certificate": 1, "kind": "safe_kernel", "points": V.tolist(), "F": 0,
                "dim": dim, "vertices": [[fraction_str(v) for v in x] for x in verts],
                "equalities": [], "facets": halfspaces_json(facets),
                "adjacency": _crease_adjacency(T, crease, is_vertex),
                "proof": {"method": "halfspaces"}}

    return SafeKernel(V, 0, dim, V.copy(), A, b, origin, basis, Aeq, beq, seconds, verts,
                      _Exact(verts, facets, (), facets), certificate,
                      {"cones": (U[T], orient.R[len(U)], mate), "planes": plane_of})


def _crease_adjacency(T: np.ndarray, crease: np.ndarray, is_vertex: np.ndarray
                      ) -> list[list[int]]:
    """The polytope's edges between its vertices (numbered in order): an edge of the
    polytope is a chain of crease edges (the two triangles across lie on distinct
    planes) whose inner corners lie on 2 planes, each with exactly two crease edges."""
    head, tail = T.ravel()[crease], T[:, [1, 2, 0]].ravel()[crease]
    links: dict[int, list[int]] = {}
    for i, j in zip(head.tolist(), tail.tolist()):
        links.setdefault(i, []).append(j)
    where = {int(v): k for k, v in enumerate(np.flatnonzero(is_vertex))}
    adjacency: list[list[int]] = [[] for _ in where]
    for v, k in where.items():
        for w in links.get(v, ()):
            prev = v
            while not is_vertex[w]:
                prev, w = w, next(x for x in links[w] if x != prev)
            adjacency[k].append(where[w])
    return [sorted(a) for a in adjacency]
