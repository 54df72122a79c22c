"""The centroid of the convex hull of a few points in R^d, d ≤ 3, exactly.

Cen(Λ) of Algorithm 1 in the paper is the centroid of conv Λ. For k = dim conv Λ it
is taken with respect to the k-dimensional measure of conv Λ in its affine hull:

* k = 0: the point; k = 1: the midpoint of the segment;
* k = 2: Σ_t A_t (a_t + b_t + c_t)/3 / Σ_t A_t over a fan triangulation of the
  polygon (A_t its areas; projected areas suffice, as the projection onto the pivot
  coordinates of the affine hull scales every area by the same factor);
* k = 3: Σ_t V_t (a_t + b_t + c_t + o)/4 / Σ_t V_t over the tetrahedra joining a
  hull vertex o to a fan triangulation of every facet not through o.

This lies in the relative interior of conv Λ (a convex combination with positive
weights of the simplices covering it). Everything is computed on the exact integer
form of the floats (:func:`rescon.geometry.exact.exact_points`); the only rounding is
the final correctly rounded conversion of each coordinate to a float. (When conv Λ
is flat and tilted, no float may lie on its plane: the returned point is then within
half an ulp per coordinate of conv Λ, as the vertex mean's is.)
"""

from __future__ import annotations

from fractions import Fraction
from itertools import combinations

import numpy as np

from ..errors import InputError
from .exact import ExactPoints, affine_hull, exact_points

__all__ = ["hull_centroid"]

Vec = tuple[int, ...]


def hull_centroid(X: np.ndarray) -> np.ndarray:
    """Centroid of conv X (rows of X, finite floats, 1 ≤ d ≤ 3), see the module
    docstring; each coordinate is the exact centroid correctly rounded."""
    X = np.asarray(X, dtype=np.float64)
    if X.ndim != 2 or not 1 <= X.shape[1] <= 3 or not len(X) or not np.isfinite(X).all():
        raise InputError(f"X must be a finite (n, d) array with n >= 1, 1 <= d <= 3; "
                         f"got shape {X.shape}")
    P = exact_points(X)
    pts = sorted(set(P.ints))
    hull = affine_hull(ExactPoints(tuple(pts), P.scale))
    if hull.dim == 0:
        num, den = [Fraction(v) for v in pts[0]], 1
    elif hull.dim == 1:
        c = hull.coords[0]
        lo, hi = min(pts, key=lambda p: p[c]), max(pts, key=lambda p: p[c])
        num, den = [Fraction(a + b) for a, b in zip(lo, hi, strict=True)], 2
    elif hull.dim == 2:
        num, den = _planar(pts, hull.coords)
    else:
        num, den = _solid(pts)
    return np.array([float(v / (den * P.scale)) for v in num])


def _planar(pts: list[Vec], coords: tuple[int, ...]) -> tuple[list[Fraction], int]:
    """Area-weighted triangle centroids of a fan over the polygon conv pts (coplanar,
    2-dimensional; projecting onto ``coords`` is injective on their plane)."""
    tri = _fan(pts, coords)
    w = [abs(_cross2(a, b, c, coords)) for a, b, c in tri]
    return _weighted(tri, w, None), 3


def _solid(pts: list[Vec]) -> tuple[list[Fraction], int]:
    """Volume-weighted centroids of the tetrahedra joining o = pts[0] (the
    lexicographic minimum, a vertex) to the facets of conv pts (full-dimensional in
    R^3) not through o."""
    o = pts[0]
    tets: list[tuple[Vec, Vec, Vec]] = []
    for face, n in _facets(pts):
        if o in face:
            continue
        drop = max(range(3), key=lambda j: abs(n[j]))  # n_drop ≠ 0: projection injective
        tets.extend(_fan(face, tuple(j for j in range(3) if j != drop)))
    w = [abs(_det3(_sub(a, o), _sub(b, o), _sub(c, o))) for a, b, c in tets]
    return _weighted(tets, w, o), 4


def _facets(pts: list[Vec]) -> list[tuple[list[Vec], Vec]]:
    """The facets of conv pts (full-dimensional in R^3), each as the list of the
    points on its plane and a normal: the planes through three points with points
    on one side only."""
    seen: set[frozenset[Vec]] = set()
    out = []
    for a, b, c in combinations(pts, 3):
        n = _normal(a, b, c)
        if n == (0, 0, 0):
            continue
        side = [_dot(n, _sub(p, a)) for p in pts]
        if min(side) < 0 < max(side):
            continue
        face = frozenset(p for p, s in zip(pts, side, strict=True) if s == 0)
        if face not in seen:
            seen.add(face)
            out.append((sorted(face), n))
    return out


def _fan(pts: list[Vec], coords: tuple[int, ...]) -> list[tuple[Vec, Vec, Vec]]:
    """Triangles (v_0, v_i, v_{i+1}) over the vertices of the convex polygon conv pts
    in cyclic order (monotone chain on the projection onto ``coords``)."""
    p, q = coords
    order = sorted(pts, key=lambda v: (v[p], v[q]))

    def chain(seq: list[Vec]) -> list[Vec]:
        out: list[Vec] = []
        for v in seq:
            while len(out) >= 2 and _cross2(out[-2], out[-1], v, coords) <= 0:
                out.pop()
            out.append(v)
        return out

    ring = chain(order)[:-1] + chain(order[::-1])[:-1]
    return [(ring[0], ring[i], ring[i + 1]) for i in range(1, len(ring) - 1)]


def _weighted(simplices: list[tuple[Vec, ...]], w: list[int],
              apex: Vec | None) -> list[Fraction]:
    """Σ w_t (sum of the vertices of simplex t [+ apex]) / Σ w_t, per coordinate."""
    total = sum(w)
    d = len(simplices[0][0])
    num = [0] * d
    for s, wt in zip(simplices, w, strict=True):
        verts = (*s, apex) if apex is not None else s
        for j in range(d):
            num[j] += wt * sum(v[j] for v in verts)
    return [Fraction(v, total) for v in num]


def _sub(a: Vec, b: Vec) -> Vec:
    return tuple(x - y for x, y in zip(a, b, strict=True))


def _dot(a: Vec, b: Vec) -> int:
    return sum(x * y for x, y in zip(a, b, strict=True))


def _normal(a: Vec, b: Vec, c: Vec) -> Vec:
    u, v = _sub(b, a), _sub(c, a)
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


def _det3(u: Vec, v: Vec, w: Vec) -> int:
    return _dot(u, _normal((0, 0, 0), v, w))


def _cross2(a: Vec, b: Vec, c: Vec, coords: tuple[int, ...]) -> int:
    """Twice the signed area of (a, b, c) projected onto ``coords``."""
    p, q = coords
    return (b[p] - a[p]) * (c[q] - a[q]) - (b[q] - a[q]) * (c[p] - a[p])
