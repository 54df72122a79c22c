"""The point of a small planar safe kernel nearest the mean, exactly, on Python ints.

The consensus engine's exact fallback for the point sets its float batch path declines
(:mod:`._small2d`: the nearest feature undecided or the kernel flat — converged states
beside far adversary values). The general path (:func:`.kernel.safe_kernel`, then
:func:`.points.exact_point`) builds the kernel with its certificate machinery and
solves KKT systems in Fractions: ~2.5 ms for 7 points. Here the same exact answer
comes from a direct construction in the plane, ~10× faster:

* the points in integer units (:func:`.exact.exact_points`: y = Y · 2^E exactly);
* Ψ(Y, F) = ⋂ {closed halfplanes H : at most F points of Y lie strictly outside H}
  (the Tukey region of depth ≥ F + 1), whose boundaries may be taken through two
  distinct points of Y when Y spans the plane; each line through two distinct points
  gives one or both of its sides by an exact orientation count (multiplicities
  counted);
* the bounding box clipped by those halfplanes, vertices in homogeneous integer
  coordinates (w, x, y), w > 0: an edge (u, v) with s_u < 0 < s_v of the clipping
  value s = a·(x, y) − b·w gives the vertex s_v·u − s_u·v. Degenerate kernels (a
  segment or a point) are kept as rings of two or one vertex;
* the projection of the mean m = (1/n) Σ y (duplicates counted) onto the resulting
  convex polygon: m itself if it satisfies every halfplane, else the nearest of the
  projections onto the ring's edges (a convex set has one nearest point).

When Y is collinear, Ψ is the segment of the line between the (F + 1)-th and the
(n − F)-th point in their order along it. The answer is the unique exact point, so it
equals the general path's (tests compare them on thousands of sets); None when Ψ is
empty (fewer than 3F + 1 points can leave it so), for the caller's general path to
report.
"""

from __future__ import annotations

from fractions import Fraction
from math import gcd

import numpy as np

from .exact import exact_points

__all__ = ["nearest_to_mean"]

Vertex = tuple[int, int, int]  # (w, x, y), w > 0, gcd 1: the point (x / w, y / w)


def nearest_to_mean(Y: np.ndarray, F: int) -> tuple[Fraction, Fraction] | None:
    """argmin ‖x − mean(Y)‖ over Ψ(Y, F) for finite Y (n, 2), exactly; None if Ψ is
    empty."""
    pts = exact_points(np.asarray(Y, dtype=np.float64))
    P, scale = pts.ints, pts.scale
    n = len(P)
    mean: Vertex = (n, sum(p[0] for p in P), sum(p[1] for p in P))
    distinct: dict[tuple[int, int], int] = {}
    for p in P:
        distinct[p] = distinct.get(p, 0) + 1
    U, W = list(distinct), list(distinct.values())
    if len(U) == 1:
        return Fraction(U[0][0], scale), Fraction(U[0][1], scale)
    halfplanes = _valid_halfplanes(U, W, F)
    if halfplanes is None:  # collinear
        ring = _collinear_kernel(P, F)
    else:
        xs, ys = [u[0] for u in U], [u[1] for u in U]
        ring = [(1, min(xs), min(ys)), (1, max(xs), min(ys)),
                (1, max(xs), max(ys)), (1, min(xs), max(ys))]
        for a1, a2, b in halfplanes:
            ring = _clip(ring, a1, a2, b)
            if not ring:
                return None
        if all(a1 * mean[1] + a2 * mean[2] <= b * mean[0] for a1, a2, b in halfplanes):
            return Fraction(mean[1], n * scale), Fraction(mean[2], n * scale)
    if not ring:
        return None
    x, y = _nearest_on_ring(ring, Fraction(mean[1], n), Fraction(mean[2], n))
    return x / scale, y / scale


def _valid_halfplanes(U: list[tuple[int, int]], W: list[int], F: int
                      ) -> list[tuple[int, int, int]] | None:
    """(a1, a2, b) with Ψ ⊆ {a1 x + a2 y ≤ b}, one per valid side of every line through
    two distinct points of U (multiplicities W): the left side of u → v, where
    cross = dx (y − y_u) − dy (x − x_u) ≥ 0, i.e. dy x − dx y ≤ dy x_u − dx y_u, is
    valid when the points with cross < 0 weigh at most F (and the right side likewise).
    None when U is collinear (every cross 0)."""
    out: list[tuple[int, int, int]] = []
    flat = True
    m = len(U)
    for i in range(m):
        xu, yu = U[i]
        for j in range(i + 1, m):
            dx, dy = U[j][0] - xu, U[j][1] - yu
            left = right = 0
            for k in range(m):
                c = dx * (U[k][1] - yu) - dy * (U[k][0] - xu)
                if c > 0:
                    left += W[k]
                elif c < 0:
                    right += W[k]
            if left or right:
                flat = False
            b = dy * xu - dx * yu
            if right <= F:
                out.append(_primitive(dy, -dx, b))
            if left <= F:
                out.append(_primitive(-dy, dx, -b))
    return None if flat else out


def _primitive(a1: int, a2: int, b: int) -> tuple[int, int, int]:
    g = gcd(a1, a2, b)
    return (a1 // g, a2 // g, b // g) if g > 1 else (a1, a2, b)


def _vertex(w: int, x: int, y: int) -> Vertex:
    """(w, x, y) scaled to w > 0 and gcd 1 (a unique key per point)."""
    g = gcd(w, x, y)
    if w < 0:
        g = -g
    return (w // g, x // g, y // g)


def _clip(ring: list[Vertex], a1: int, a2: int, b: int) -> list[Vertex]:
    """The convex ring (polygon, segment or point) cut by a1 x + a2 y ≤ b."""
    s = [a1 * x + a2 * y - b * w for w, x, y in ring]
    if all(v <= 0 for v in s):
        return ring
    out: list[Vertex] = []
    m = len(ring)
    for i in range(m):
        j = (i + 1) % m
        if s[i] <= 0:
            out.append(ring[i])
        if (s[i] < 0 < s[j]) or (s[j] < 0 < s[i]):
            u, v = ring[i], ring[j]
            out.append(_vertex(*(s[j] * cu - s[i] * cv for cu, cv in zip(u, v, strict=True))))
    kept: list[Vertex] = []
    for v in out:  # a segment's two edges meet the line at the same point
        if not kept or v != kept[-1]:
            kept.append(v)
    while len(kept) > 1 and kept[0] == kept[-1]:
        kept.pop()
    return kept


def _collinear_kernel(P: tuple[tuple[int, ...], ...], F: int) -> list[Vertex]:
    """Ψ of points on one line: from the (F + 1)-th to the (n − F)-th in their order
    along it (lexicographic order is an order along any line) — when F + 1 > n − F,
    nonempty only if those two points coincide (then every point between them in the
    order is that point, which lies in the hull of any n − F points: V42)."""
    order = sorted(P)
    lo, hi = F, len(P) - 1 - F
    if lo > hi and order[lo] != order[hi]:
        return []
    ends = [order[lo], order[hi]] if order[lo] != order[hi] else [order[lo]]
    return [(1, x, y) for x, y in ends]


def _nearest_on_ring(ring: list[Vertex], mx: Fraction, my: Fraction
                     ) -> tuple[Fraction, Fraction]:
    """The point of the ring's edges (or its one vertex) nearest (mx, my)."""
    pts = [(Fraction(x, w), Fraction(y, w)) for w, x, y in ring]
    if len(pts) == 1:
        return pts[0]
    best, best_d = pts[0], None
    for i in range(len(pts)):
        (ux, uy), (vx, vy) = pts[i], pts[(i + 1) % len(pts)]
        ex, ey = vx - ux, vy - uy
        t = ((mx - ux) * ex + (my - uy) * ey) / (ex * ex + ey * ey)
        t = min(max(t, Fraction(0)), Fraction(1))
        px, py = ux + t * ex, uy + t * ey
        dist = (px - mx) ** 2 + (py - my) ** 2
        if best_d is None or dist < best_d:
            best, best_d = (px, py), dist
    return best
