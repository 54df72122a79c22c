"""The nearest edge or triangle of a hull through trees of boxes, bit for bit.

Outside H the validity monitor's distance is fl(min_k f_k) over H's edges k (the
plane; f_k the float point–segment distance) or from the float closest point of the
triangle of least fl‖x − y‖² (R³). This module holds the per-item floats —
:func:`_edge_float` and :func:`_closest_points` (Ericson's Voronoi regions), the same
operations in the same order as the dense paths (:meth:`ValidityMonitor.edge_distances`,
:func:`_closest_on_triangles`) — and binary trees of boxes over runs of EDGE_LEAF
consecutive items (:func:`_edge_tree` in cycle order, :func:`_triangle_tree` in the
Morton order of the centroids). :func:`_descend` leaves a box out for a row x when a
lower bound on the float of every item in it, fl‖gaps of x to the box‖·(1 − rel) −
slack, exceeds the float best[x] of seed items: an item left out has a float above the
minimum, so the minimum over the items kept is the minimum over all, and the first
item reaching it the same (the bounds are proven by the callers,
:meth:`ValidityMonitor._nearest_edges` and :meth:`ValidityMonitor._nearest_triangles`).
Pairs come at most ``limit`` at a time (memory O(limit) also when nothing can be left
out); :func:`_prunes` leaves rows so far from H that no box can be left out to the
dense path — a choice of speed, not of answers.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from .._rounding import UNIT_ROUNDOFF


def _prunes(lo: list, hi: list, best: np.ndarray, slack: float, rel: float) -> np.ndarray:
    """Rows for which :func:`_descend` can leave boxes out: the uncertainty rel·best +
    slack of its bound is below an eighth of the root box's diagonal (states so far
    from H that the rounding of their distance exceeds H's size compare every item:
    the dense O(h) path does that faster; a choice of speed, not of answers)."""
    with np.errstate(over="ignore", invalid="ignore"):
        diag = float(np.hypot.reduce(hi[0][0] - lo[0][0]))
        return rel * best + slack < diag / 8


def _descend(lo: list, hi: list, leaf: int, count: int, X: np.ndarray, best: np.ndarray,
             slack: float, rel: float, limit: int) -> Iterator[tuple[np.ndarray, np.ndarray]]:
    """(q, k) in parts: the pairs (row q of X, item k < ``count``) of the leaves of a
    tree of boxes (:func:`_box_levels`, ``leaf`` items per leaf) that no bound leaves out: a
    box is left out for row x when fl‖gaps of x to the box‖·(1 − ``rel``) −
    ``slack`` > best[q] (the callers' proofs, :meth:`ValidityMonitor._nearest_edges`
    and :meth:`ValidityMonitor._nearest_triangles`). Rows are taken in halves while
    a level would hold more than ``limit``/``leaf`` boxes, and the pairs are yielded
    per such part of the rows (all the pairs of a row in one part): at most
    ``limit`` pairs at a time (memory O(limit) in the callers too, also when nothing
    can be left out: states 1e8 beyond a thin hull keep all N·h pairs)."""
    todo = [np.arange(len(X))]
    while todo:
        rows = todo.pop()
        q, node = np.arange(len(rows)), np.zeros(len(rows), dtype=np.int64)
        for level, (L, H) in enumerate(zip(lo, hi)):
            if level:
                q, node = np.repeat(q, 2), np.repeat(2 * node, 2) + np.tile([0, 1], len(q))
                real = node < len(L)
                q, node = q[real], node[real]
            if len(q) > limit // leaf and len(rows) > 1:
                todo += [rows[:len(rows) // 2], rows[len(rows) // 2:]]
                break
            x = X[rows[q]]
            with np.errstate(over="ignore", under="ignore", invalid="ignore"):
                gap = np.maximum(np.maximum(L[node] - x, x - H[node]), 0.0)
                g = np.sqrt((gap * gap).sum(axis=1)) if x.shape[1] > 2 else np.hypot(
                    gap[:, 0], gap[:, 1])
                keep = ~(g * (1 - rel) - slack > best[rows[q]])
            q, node = q[keep], node[keep]
        else:
            q = np.repeat(q, leaf)
            k = np.repeat(node * leaf, leaf) + np.tile(np.arange(leaf), len(node))
            real = k < count
            yield rows[q[real]], k[real]


def _triangle_tree(A: np.ndarray, B: np.ndarray, C: np.ndarray, planes: np.ndarray
                   ) -> tuple:
    """(lo, hi, EDGE_LEAF, planes, perm) for :meth:`ValidityMonitor._nearest_triangles`
    over the triangles (A_k, B_k, C_k): ``perm`` the triangles in the Morton order of
    their centroids (nearby triangles in the same runs), lo[ℓ], hi[ℓ] the boxes of
    level ℓ as in :func:`_edge_tree` over runs of EDGE_LEAF triangles of ``perm``, and
    ``planes`` the facet of each triangle (:func:`_polytope_of`)."""
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):  # 1e308: any order
        cent = A / 3 + B / 3 + C / 3
        span = cent.max(axis=0) - cent.min(axis=0)
        cell = np.nan_to_num((cent - cent.min(axis=0)) / span * 1023)
    cell = np.clip(cell, 0, 1023).astype(np.int64)
    code = np.zeros(len(A), dtype=np.int64)
    for bit in range(10):
        for axis in range(3):
            code |= ((cell[:, axis] >> bit) & 1) << (3 * bit + axis)
    perm = np.argsort(code, kind="stable")
    pad = -(-len(A) // EDGE_LEAF) * EDGE_LEAF
    box = np.stack([A, B, C], axis=1)[np.r_[perm, np.full(pad - len(A), perm[-1])]]
    return (*_box_levels(box.min(axis=1), box.max(axis=1)), EDGE_LEAF, planes, perm)


def _box_levels(lo: np.ndarray, hi: np.ndarray) -> tuple[list, list]:
    """The levels (root first) of a binary tree of boxes over leaves of EDGE_LEAF
    consecutive items of boxes [lo, hi] (rows; len a multiple of EDGE_LEAF)."""
    d = lo.shape[1]
    los = [lo.reshape(-1, EDGE_LEAF, d).min(axis=1)]
    his = [hi.reshape(-1, EDGE_LEAF, d).max(axis=1)]
    while len(los[-1]) > 1:
        L, H = los[-1], his[-1]
        if len(L) % 2:
            L, H = np.concatenate([L, L[-1:]]), np.concatenate([H, H[-1:]])
        los.append(L.reshape(-1, 2, d).min(axis=1))
        his.append(H.reshape(-1, 2, d).max(axis=1))
    return los[::-1], his[::-1]


#: edges per leaf of a polygon's tree of boxes (:func:`_edge_tree`)
EDGE_LEAF = 8


def _edge_tree(P: np.ndarray, Q: np.ndarray) -> tuple:
    """(lo, hi, EDGE_LEAF, c, order, rays) for :meth:`ValidityMonitor._nearest_edges`
    and :meth:`ValidityMonitor._outside_guess` over the edges [P_k, Q_k] of a polygon
    (cycle order): lo[ℓ], hi[ℓ] the corners of the boxes of level ℓ (root first; a
    box of level ℓ holds the boxes 2i and 2i + 1 of level ℓ + 1, a leaf EDGE_LEAF
    consecutive edges), c the float mean of the vertices and ``order`` the edges
    sorted by the angle ``rays`` of P_k about c."""
    h = len(P)
    pad = -(-h // EDGE_LEAF) * EDGE_LEAF
    box = np.stack([P, Q], axis=1)  # (h, 2, 2)
    box = np.concatenate([box, np.repeat(box[-1:], pad - h, axis=0)])
    lo, hi = _box_levels(box.min(axis=1), box.max(axis=1))
    with np.errstate(over="ignore", invalid="ignore"):  # 1e308: a worse guess only
        c = P.mean(axis=0)
        angle = np.arctan2(P[:, 1] - c[1], P[:, 0] - c[0])
    order = np.argsort(angle, kind="stable")
    return lo, hi, EDGE_LEAF, c, order, angle[order]


def _edge_float(X: np.ndarray, P: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """fl‖w − t e‖ per broadcast row (e = q − p, w = x − p, t = clip(w·e / e·e, 0, 1)):
    the same operations, in the same order, as :meth:`ValidityMonitor.edge_distances`."""
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        e = Q - P
        ee = (e * e).sum(axis=-1)
        w = X - P
        t = np.clip(np.where(ee > 0, (w * e).sum(axis=-1) / ee, 0.0), 0.0, 1.0)
        r = w - t[..., None] * e
        return np.hypot(r[..., 0], r[..., 1])


def _closest_on_triangles(X: np.ndarray, A: np.ndarray, B: np.ndarray,
                          C: np.ndarray) -> np.ndarray:
    """For each row x of X (n, 3), the closest point to x over the triangles (A, B, C)
    (floats): per triangle y = a + s(b − a) + t(c − a) by the Voronoi regions of its
    vertices, edges and face (Ericson, Real-Time Collision Detection §5.1.5)."""
    Y, sq = _closest_points(X[:, None, :], A[None], B[None], C[None])
    best = np.argmin(np.where(np.isnan(sq), np.inf, sq), axis=1)
    return Y[np.arange(len(X)), best]


def _closest_points(x: np.ndarray, A: np.ndarray, B: np.ndarray, C: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
    """(y, fl‖x − y‖²) per broadcast row of x and the triangle (a, b, c) (shapes
    (..., 3)): :func:`_closest_on_triangles`' float closest point. In the face region
    s = v_b/denom and t = v_c/denom are clipped to [0, 1], and t to 1 − s where
    s + t > 1 + 8u — no change when v_a, v_b, v_c > 0 in floats (the exact partition
    of the regions: then denom ≥ fl(v_b + v_c), so 0 ≤ s, t ≤ 1 and s + t ≤ 1 + 3u);
    floats that break it (a sliver or flat triangle, a far x: v_b/denom was ±inf or
    huge) now give a point of the triangle (s, t ≥ 0, s + t ≤ 1 + 8u), not one far
    off it, as the bounds of :meth:`ValidityMonitor.triangle_distances` and
    :meth:`ValidityMonitor._nearest_triangles` assume (every other region's s, t are
    in [0, 1] with s + t ≤ 1: quotients of same-signed terms)."""
    ab, ac = B - A, C - A
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        ap, bp, cp = x - A, x - B, x - C
        d1, d2 = (ab * ap).sum(-1), (ac * ap).sum(-1)
        d3, d4 = (ab * bp).sum(-1), (ac * bp).sum(-1)
        d5, d6 = (ab * cp).sum(-1), (ac * cp).sum(-1)
        va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
        denom = va + vb + vc
        s, t = np.clip(vb / denom, 0.0, 1.0), np.clip(vc / denom, 0.0, 1.0)  # the face
        t = np.where(s + t > 1 + 8 * UNIT_ROUNDOFF, 1 - s, t)
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6))
        for mask, s_, t_ in (  # later regions take precedence, as in Ericson's order
                ((va <= 0) & (d4 >= d3) & (d5 >= d6), 1 - w, w),
                ((vb <= 0) & (d2 >= 0) & (d6 <= 0), 0.0, d2 / (d2 - d6)),
                ((d6 >= 0) & (d5 <= d6), 0.0, 1.0),
                ((vc <= 0) & (d1 >= 0) & (d3 <= 0), d1 / (d1 - d3), 0.0),
                ((d3 >= 0) & (d4 <= d3), 1.0, 0.0),
                ((d1 <= 0) & (d2 <= 0), 0.0, 0.0)):
            s, t = np.where(mask, s_, s), np.where(mask, t_, t)
        Y = A + s[..., None] * ab + t[..., None] * ac
        sq = ((x - Y) ** 2).sum(-1)
    return Y, sq
