"""The δ-validity monitor: dist(x, H) for H = conv{x_j(0) : j ∈ B} and every state x.

A state is at distance 0 exactly when it lies in H (the certified hull,
``_initial_hull``). Float filters with rigorous error bounds prove most states inside
or outside — H's exact facets (``_facet_filter``); for a polygon of many edges an
inner polygon of every k-th vertex, the fan of triangles from a vertex (2-D
orientations beyond Shewchuk's bound) and the facet of the state's angular cone; for a
certified polytope in R³ the tetrahedra conv(o, T_f) of its boundary triangles reached
by a walk — and exact arithmetic decides the rest. Outside H the distance is a float
with a certified error bound: in the plane the least point–segment distance to the
rounded edges (within 64uM, M the largest coordinate), in R³ the closest point over
the boundary triangles (bounded above by the rounding of the point, below by the
supporting halfspace through it), each found in O(log h) per state near H by trees of
boxes (``_distance_trees``: the same float as the dense O(h) path); otherwise (d > 3,
H flat, magnitudes beyond 1e±100, bounds not below the distance) the exact projection
onto H, rounded once (:func:`_norm`).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from .._rounding import MIN_SUBNORMAL, UNIT_ROUNDOFF
from ._distance_trees import (
    _closest_on_triangles,
    _closest_points,
    _descend,
    _edge_float,
    _edge_tree,
    _prunes,
    _triangle_tree,
)
from ._facet_filter import _filter_rows, _slack_bound, _slacks
from ._hull_surface import _cone_guesses, _cone_tree, _orient3_float
from ._initial_hull import _exact_polygon, certified_hull

#: a polygon of more vertices first filters states with an inner polygon of this many
INNER_FACETS = 64

#: rows × facets (or edges) of one block of the polygon's float filters
BLOCK = 2**20


class ValidityMonitor:
    """Distances of states to H = conv(initial benign states).

    A state is at distance 0 exactly when it lies in H (a float filter proves most
    cases, exact arithmetic decides the rest). Outside H the distance is a float:
    in the plane with H a polygon, the smallest point–segment distance to H's edges
    (:meth:`edge_distances`), within ``edge_error`` of the exact distance (a rigorous
    bound, ~1e-14 relative to the data's magnitude); in R³ the smallest point–triangle
    distance over a triangulation of H's boundary, with a certified error bound
    (:meth:`triangle_distances`); otherwise (d > 3, H flat, magnitudes beyond 1e±100,
    states the filter cannot place, bounds not below the distance) the exact
    projection onto H, rounded once (~1.5 ms per state)."""

    def __init__(self, initial: np.ndarray) -> None:
        self.hull = certified_hull(initial)
        self._initial = np.array(initial, dtype=np.float64)
        full = self.hull.dim == initial.shape[1] and bool(self.hull._exact.facets)
        self._rows = _filter_rows(self.hull._exact.facets) if full else None
        self._edges = _polygon_edges(self.hull) if full and initial.shape[1] == 2 else None
        self._triangles = _hull_triangles(self.hull) if full and initial.shape[1] == 3 else None
        self._inner = _inner_rows(self.hull) if self._edges is not None else None
        self._edge_tree = _edge_tree(*self._edges) if self._inner is not None else None
        self._cones = _cone_filter(self.hull) if full and initial.shape[1] == 3 else None
        self._tri_tree = (_triangle_tree(*self._triangles, self.hull._cache["planes"])
                          if self._cones is not None and self._triangles is not None else None)

    def distance(self, x: np.ndarray) -> float:
        """dist(x, H): 0 iff x ∈ H (exact test); else ‖x − y‖ for the exact projection y
        of x onto H, from the exact differences x_j − y_j (rounding y first made x − fl(y)
        0 or all cancellation for a state within a few ulps of H): :func:`_norm`."""
        if self.hull.contains(x):
            return 0.0
        _, cert = self.hull.point("project", target=x)
        return _norm([Fraction(float(a)) - Fraction(b) for a, b in zip(x, cert["x"])])

    def surely_inside(self, states: np.ndarray) -> np.ndarray:
        """Rows of ``states`` (n, d) that a float filter proves inside the hull (False:
        not proven). With the exact facets a·x ≤ β scaled by 1/max|a_j| and rounded
        to Â, b̂ (each entry within u of its value, or 2^-1075 of it in the subnormal
        range), the exact a·x/top − β/top differs from fl(Â x − b̂) by at most
        ((d + 2) u + O(u²)) (|Â| |x| + |b̂|) (entry rounding, then the d + 1 terms of
        the dot product) plus (d + 2)(‖x‖∞ + 1)·2^-1074 for gradual underflow; twice
        the first term covers the rounding of the bound itself. Overflow makes the
        bound inf or the value NaN, and the row unproven. A polygon of many edges first
        tries its inner polygon (:func:`_inner_rows`) and its fan (:meth:`_in_fan`), and
        rows that the facet of their angular cone proves outside (:meth:`_outside_guess`:
        S > bound there, so S < −bound on no facet) skip the loop; a polytope from
        :func:`_exact_polytope` tries the cones of its triangles (:meth:`_in_cones`);
        then its own facets in blocks."""
        sure = np.zeros(len(states), dtype=bool)
        if self._rows is None:
            return sure
        out = np.zeros(len(states), dtype=bool)  # proven outside: no facet loop
        if self._inner is not None:
            S, bound = _slacks(*self._inner, states)
            sure = (S < -bound).all(axis=1)
            todo = np.flatnonzero(~sure)
            sure[todo] = self._in_fan(states[todo])
        if self._edge_tree is not None:
            todo = np.flatnonzero(~sure)
            out[todo] = self._outside_guess(states[todo])[0]
        if self._cones is not None:
            todo = np.flatnonzero(~sure)
            sure[todo] = self._in_cones(states[todo])
        if self._tri_tree is not None:
            todo = np.flatnonzero(~sure)
            out[todo] = self._outside_cones(states[todo])[0]
        todo = np.flatnonzero(~sure & ~out)
        block = max(1, BLOCK // len(self._rows[1]))
        for s in range(0, todo.size, block):
            rows = todo[s:s + block]
            S, bound = self._slacks(states[rows])
            sure[rows] = (S < -bound).all(axis=1)
        return sure

    def _slacks(self, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """fl(Â x − b̂) per row and facet, and its error bound (:meth:`surely_inside`)."""
        return _slacks(*self._rows, states)

    def distances(self, states: np.ndarray) -> np.ndarray:
        """Distances of the rows of ``states``: rows :meth:`surely_inside` the hull or
        equal to their initial state are 0, rows a facet proves outside a polygon get
        :meth:`edge_distances` (for a polygon of many edges the same floats in
        O(log h) per row, :meth:`_nearest_edges`), outside a polytope in R³
        :meth:`triangle_distances` where their bound is below the distance, the others
        the exact :meth:`distance`."""
        out = np.zeros(len(states))
        rest = np.flatnonzero(~self._initial_rows(states))
        rest = rest[~self.surely_inside(states[rest])]
        if rest.size and self._edge_tree is not None:
            fast, dist = self._nearest_edges(states[rest])
            out[rest[fast]] = dist[fast]
            rest = rest[~fast]
        if rest.size and self._edges is not None:
            dist, err = self.edge_distances(states[rest])
            # dist > 0: a state just outside a thin polygon may get a float distance 0
            fast = self._surely_outside(states[rest]) & np.isfinite(err) & (dist > 0)
            out[rest[fast]] = dist[fast]
            rest = rest[~fast]
        if rest.size and self._tri_tree is not None:
            fast, known, dist = self._nearest_triangles(states[rest])
            out[rest[fast]] = dist[fast]
            exact, rest = rest[known & ~fast], rest[~known]
            for i in exact:
                out[i] = self.distance(states[i])
        if rest.size and self._triangles is not None:
            dist, err = self.triangle_distances(states[rest])
            fast = self._surely_outside(states[rest]) & (dist > err)
            out[rest[fast]] = dist[fast]
            rest = rest[~fast]
        for i in rest:
            out[i] = self.distance(states[i])
        return out

    def _surely_outside(self, states: np.ndarray) -> np.ndarray:
        """Rows of ``states`` that a facet's float filter proves outside the hull
        (:meth:`surely_inside`'s bound), in blocks of at most BLOCK slacks: O(BLOCK)
        memory, not (rows × facets) — 3.2 GB for 10 000 states outside a 10 000-gon."""
        out = np.zeros(len(states), dtype=bool)
        block = max(1, BLOCK // len(self._rows[1]))
        for s in range(0, len(states), block):
            S, bound = self._slacks(states[s:s + block])
            out[s:s + block] = (S > bound).any(axis=1)
        return out

    def _in_fan(self, X: np.ndarray) -> np.ndarray:
        """Rows of X (n, 2) a float filter proves inside the polygon H of many edges
        through its fan from v₀ = C₀ (cycle C, the lexicographically least vertex, so
        the rays v₀→C_j turn left as j grows, angles in (−π/2, π/2]): the float angle
        of x − v₀ names a triangle T_j = (v₀, C_j, C_{j+1}) (1 ≤ j ≤ h − 2, a guess),
        and x ∈ T_j ⊆ H is proven by orient(v₀, C_j, x) > 0, orient(v₀, C_{j+1}, x) < 0
        (float determinants beyond 8u(|l| + |r|) + 4·2^-1074, Shewchuk's bound 3u + 16u²
        with room for gradual underflow; only for max |coordinate| ≤ 1e150, where no
        product overflows) and facet j (edge C_j C_{j+1}) by the filter of
        :meth:`surely_inside` (:func:`_slack_bound`). A wrong guess leaves x unproven,
        never wrongly inside."""
        C = self._edges[0]
        A, b = self._rows
        v0 = C[0]
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            rays = np.arctan2(C[1:, 1] - v0[1], C[1:, 0] - v0[0])
            phi = np.arctan2(X[:, 1] - v0[1], X[:, 0] - v0[0])
            j = np.clip(np.searchsorted(rays, phi), 1, len(C) - 2)
            ok = _orient_sign(v0, C[j], X) > 0
            ok &= _orient_sign(v0, C[j + 1], X) < 0
            S = (X * A[j]).sum(axis=1) - b[j]
            bound = _slack_bound(2, (np.abs(X) * np.abs(A[j])).sum(axis=1), np.abs(b[j]),
                                 np.abs(X).max(axis=1))
        big = np.maximum(np.abs(X).max(axis=1), np.abs(C).max()) > 1e150
        return ok & (S < -bound) & ~big

    def _outside_guess(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(out, j) for rows of X (n, 2) and a polygon of many edges (cycle C, edge j
        from C_j to C_{j+1}, facet j): j is the edge whose angular interval about c
        (the float mean of the vertices) holds the angle of x − c — a guess, right
        when c is inside H (the angles of C about c then increase cyclically, and the
        ray from c through an outside x leaves H across edge j, beyond its line) — and
        out the rows facet j's float filter proves outside with a margin: S > 3·bound
        (:meth:`surely_inside`). Any other order of the same float operations (the
        matrix products of :meth:`_surely_outside` and :meth:`surely_inside`) is
        within the bound of the exact slack, as this one is, so it differs by at most
        the bound from S and exceeds its own bound there too: those filters reach the
        same verdict on facet j, and the fast paths the same answers as theirs. A
        wrong guess leaves a row unproven, never wrongly outside. O(n log h)."""
        A, b = self._rows
        c, order, rays = self._edge_tree[3:6]
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            phi = np.arctan2(X[:, 1] - c[1], X[:, 0] - c[0])
            j = order[np.searchsorted(rays, phi, side="right") - 1]  # −1: the last
            S = (X * A[j]).sum(axis=1) - b[j]
            bound = _slack_bound(2, (np.abs(X) * np.abs(A[j])).sum(axis=1), np.abs(b[j]),
                                 np.abs(X).max(axis=1))
        return S > 3 * bound, j

    def _nearest_edges(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(fast, dist) for rows of X (n, 2) outside a polygon of many edges: fast
        marks the rows that :meth:`distances` answers by :meth:`edge_distances` (a
        facet proves them outside — here the facet of their cone,
        :meth:`_outside_guess` —, ``edge_error`` finite, distance > 0), dist the same
        float fl(min_k f_k) over the edges k, f_k the float distance to edge k as
        :meth:`edge_distances` computes it, but in O(log h) edges per row for states
        near H: a tree of boxes over runs of consecutive edges (:func:`_edge_tree`)
        is descended, leaving out a box whose lower bound on f_k exceeds f_s for a
        seed edge s (j and its two neighbours). The bound: whatever t̂ ∈ [0, 1] the
        floats give, r̂ = fl(ŵ − t̂ê) = x − y + ε with y = p + t̂e on the rounded edge
        and |ε_i| ≤ 3u(|w_i| + |e_i|) + 2u|r_i| + 4·2^-1075 (w, e, t̂e, the
        difference); ‖w‖ ≤ ‖x − y‖ + ‖e‖ and ‖e‖ ≤ 2√2 V (V = max |vertex
        coordinate|), so f_k ≥ ‖x − y‖(1 − 7u) − 17uV − 8·2^-1074, and ‖x − y‖ ≥
        D̂_k ≥ dist(x, box) ≥ ĝ(1 − 4u) − 4·2^-1074 (ĝ = fl(hypot) of the rounded
        gaps). A box is left out when ĝ(1 − 40u) − 64uV − 16·2^-1074 > f_s (the
        factors and terms beyond those above cover this bound's own rounding; the
        bound scales with V, not with ‖x‖: far states prune as well). An edge left
        out has f_k > f_s ≥ min_k f_k, so the minimum over the edges kept is the
        minimum over all, bit for bit (the same float operations per edge). Rows
        whose cone facet proves nothing (a guess gone wrong) are not fast: the
        caller takes them to the O(h) path."""
        P, Q = self._edges
        lo, hi, leaf = self._edge_tree[:3]
        h = len(P)
        out, j = self._outside_guess(X)
        M = np.maximum(np.abs(X).max(axis=1), max(np.abs(P).max(), np.abs(Q).max()))
        rows = np.flatnonzero(out & (M > 1e-100) & (M < 1e100))
        seed = np.stack([j[rows], (j[rows] + 1) % h, (j[rows] - 1) % h], axis=1)
        best = _edge_float(X[rows, None, :], P[seed], Q[seed]).min(axis=1)
        Mv = max(np.abs(P).max(), np.abs(Q).max())
        slack = 64 * UNIT_ROUNDOFF * Mv + 16 * MIN_SUBNORMAL
        prunes = _prunes(lo, hi, best, slack, 40 * UNIT_ROUNDOFF)
        rows, best = rows[prunes], best[prunes]
        dist = np.full(len(X), np.inf)
        found = np.full(len(rows), np.inf)
        for q, k in _descend(lo, hi, leaf, h, X[rows], best, slack, 40 * UNIT_ROUNDOFF,
                             BLOCK):  # edge_distances' BLOCK pairs at a time
            np.minimum.at(found, q, _edge_float(X[rows[q]], P[k], Q[k]))
        dist[rows] = found
        fast = np.zeros(len(X), dtype=bool)
        fast[rows] = found > 0
        return fast, dist

    def _outside_cones(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(out, guesses) for rows of X (n, 3) and a polytope from
        :func:`_exact_polytope`: the triangles of the walk towards x's cone
        (:func:`_cone_guesses`, (n, CONE_STEPS + 1)) and the rows the facet of one of
        them proves outside with the margin of :meth:`_outside_guess` (S > 3·bound: the
        facet loops of :meth:`surely_inside` and :meth:`_surely_outside` then decide
        the same)."""
        corners, o, mate, e, tree = self._cones
        A, b = self._rows
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            Y = np.ldexp(X, -e)  # a guess only: rounded or inf rows merely guess worse
        guesses = _cone_guesses(tree, corners, mate, o, np.where(np.isfinite(Y), Y, 0.0))
        out = np.zeros(len(X), dtype=bool)
        top = np.abs(X).max(axis=1)
        for g in guesses.T:
            f = self._tri_tree[3][g]
            with np.errstate(over="ignore", invalid="ignore"):
                S = (X * A[f]).sum(axis=1) - b[f]
                bound = _slack_bound(3, (np.abs(X) * np.abs(A[f])).sum(axis=1),
                                     np.abs(b[f]), top)
            out |= S > 3 * bound
        return out, guesses

    def _nearest_triangles(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(fast, known, dist) for rows of X (n, 3) outside a polytope from
        :func:`_exact_polytope`: ``known`` the rows whose verdict in :meth:`distances`
        is settled here — a facet of their walk proves them outside
        (:meth:`_outside_cones`), 1e-100 < M < 1e100 —, ``fast`` those of them that
        :meth:`triangle_distances` answers (δ > its bound) and dist its δ, the same
        float, in O(log T) triangles per row for states near H (the rest of ``known``
        goes to the exact :meth:`distance`, as there). The closest point y is the
        float one of the triangle of least fl‖x − y‖² (the first such in triangle
        order, as numpy's argmin), found by descending a tree of boxes over runs of
        triangles (:func:`_triangle_tree`) and leaving out a box whose lower bound on
        ‖x − y‖ exceeds ‖x − y_s‖ for the seeds s (the walk's triangles): y =
        fl(a + s ê₀ + t ê₁) with s, t ≥ 0, s + t ≤ 1 + 8u (:func:`_closest_points`) is
        within 6u(|a| + |e₀| + |e₁|) ≤ 30uV per coordinate of a + s e₀ + t e₁ (V =
        max |corner coordinate|), which is within 8u‖e₁‖ ≤ 28uV of the triangle, in
        the box: ‖x − y‖ ≥ ĝ(1 − 4u) − 80uV (ĝ the float norm of the rounded gaps to
        the box; a gap square rounded up from below 2^-1074 adds < 2^-536), and
        fl‖x − y‖² ≥ (‖x − y‖(1 − 4u))² (x − y, squares and sum rounded; above
        2^-500 underflow is negligible). A box is left out only when ĝ(1 − 24u) −
        128uV − 2^-500 > fl(√(least seed fl‖x − y_s‖²))·(1 + 8u): each of its
        triangles then has fl‖x − y‖² > the seeds' least ≥ the least, so the least
        and its first triangle are among the triangles kept, bit for bit (the same
        float operations per triangle). δ and the bound are then
        :meth:`triangle_distances`' from y."""
        A, B, C = self._triangles
        lo, hi, leaf, _, perm = self._tri_tree
        n = len(X)
        out, guesses = self._outside_cones(X)
        M = np.maximum(np.abs(X).max(axis=1), np.abs(self.hull.vertices).max())
        rows = np.flatnonzero(out & (M > 1e-100) & (M < 1e100))
        best = np.empty(len(rows))
        block = max(1, BLOCK // 16 // guesses.shape[1])  # triangle_distances' block
        for s in range(0, len(rows), block):
            part = rows[s:s + block]
            G = guesses[part]
            sq = _closest_points(X[part, None, :], A[G], B[G], C[G])[1]
            best[s:s + block] = np.where(np.isnan(sq), np.inf, sq).min(axis=1)
        with np.errstate(invalid="ignore", over="ignore"):
            best = np.sqrt(best) * (1 + 8 * UNIT_ROUNDOFF)
        Mv = max(np.abs(A).max(), np.abs(B).max(), np.abs(C).max())
        slack = 128 * UNIT_ROUNDOFF * Mv + 2.0**-500
        prunes = _prunes(lo, hi, best, slack, 24 * UNIT_ROUNDOFF)
        rows, best = rows[prunes], best[prunes]
        parts = [(np.empty(0, dtype=np.int64), np.empty((0, 3)), np.empty(0))]
        for q, k in _descend(lo, hi, leaf, len(perm), X[rows], best, slack,
                             24 * UNIT_ROUNDOFF, BLOCK // 16):  # triangle_distances' block
            k = perm[k]
            Y, sq = _closest_points(X[rows[q]], A[k], B[k], C[k])
            sq = np.where(np.isnan(sq), np.inf, sq)
            order = np.lexsort((k, sq, q))
            first = order[np.r_[True, q[order][1:] != q[order][:-1]]] if len(q) else order
            parts.append((q[first], Y[first], sq[first]))
        q, Y, sq = (np.concatenate(part) for part in zip(*parts))
        fast = np.zeros(n, dtype=bool)
        known = np.zeros(n, dtype=bool)
        dist = np.zeros(n)
        good = np.isfinite(sq)  # else the argmin over all-inf rows: the slow path
        mine, Ysel = rows[q[good]], Y[good]
        dist[mine], err = self._triangle_bounds(X[mine], Ysel)
        known[mine] = True
        fast[mine] = dist[mine] > err
        return fast, known, dist

    def _in_cones(self, X: np.ndarray) -> np.ndarray:
        """Rows of X (n, 3) a float filter proves inside the polytope H from
        :func:`_exact_polytope`, through the tetrahedra conv(o, T_f) of its certified
        boundary triangles T_f (each lies in H): a walk guesses the triangle
        (:func:`_cone_guesses`), and x is proven strictly on the
        inner side of the three planes (o, edge) and of T_f's plane by
        :func:`_orient3_float`, on X scaled by the hull's power of two (rows that
        scaling rounds are left unproven). A wrong guess leaves x unproven, never
        wrongly inside."""
        corners, o, mate, e, tree = self._cones
        with np.errstate(over="ignore", under="ignore"):  # such rows are left unproven
            Y = np.ldexp(X, -e)
            rows = np.flatnonzero((np.ldexp(Y, e) == X).all(axis=1))
        sure = np.zeros(len(X), dtype=bool)
        for guess in _cone_guesses(tree, corners, mate, o, Y[rows]).T:
            left = ~sure[rows]
            A, B, C = corners[guess[left]].transpose(1, 0, 2)
            sure[rows[left]] = _surely_in_tetra(o, A, B, C, Y[rows[left]])
        return sure

    def _initial_rows(self, states: np.ndarray) -> np.ndarray:
        """Rows of ``states`` equal to the initial state of the same row (they generate
        H, so lie in it: step 0, and agents that held their state), often on H's
        boundary where the filter cannot decide."""
        if states.shape != self._initial.shape:
            return np.zeros(len(states), dtype=bool)
        return (states == self._initial).all(axis=1)

    def edge_distances(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For states X (n, 2) outside the polygon H: min over its edges [p, q] of
        ‖w − t e‖, e = q − p, w = x − p, t = clip(w·e / e·e, 0, 1), on the vertices
        rounded to floats, and ``edge_error`` (inf where the bound does not apply)."""
        P, Q = self._edges
        block = max(1, BLOCK // len(P))
        dist = np.empty(len(X))
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):  # 1e300: inf
            e = Q - P  # (edge_error is inf there: the exact path decides)
            ee = (e * e).sum(axis=1)
            for s in range(0, len(X), block):
                w = X[s:s + block, None, :] - P[None, :, :]
                t = np.clip(np.where(ee > 0, (w * e).sum(axis=2) / ee, 0.0), 0.0, 1.0)
                r = w - t[:, :, None] * e
                dist[s:s + block] = np.hypot(r[:, :, 0], r[:, :, 1]).min(axis=1)
        return dist, self.edge_error(X)

    def triangle_distances(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For states X (n, 3) outside H: δ = min over the boundary triangles (on the
        rounded vertices V̂) of ‖x − y‖, y the float closest point of the triangle, and
        a bound on |δ − dist(x, H)| from both sides, with M = max(‖x‖∞, max|V̂|):

        * above: y is within 64uM of a point of H (per coordinate ≤ 13uM from the
          rounding of a + s e₀ + t e₁, ≤ uM from V̂ against the exact vertices, and
          ≤ 8uM from s + t rounded past 1), so dist ≤ δ(1 + 4u) + 64uM;
        * below: for n = x − y and the exact vertices v (rounded: V̂ = ``hull.vertices``),
          dist ≥ (n·x − max_v n·v)/‖n‖ (H lies in the halfspace n·z ≤ max_v n·v), in
          floats with each dot product within 4u‖n‖₁M of its exact value (each
          further operation is one rounding relative to its result: the factors 1 ± 4u).

        The bound is inf beyond 1e±100 (squares may under- or overflow)."""
        A, B, C = self._triangles
        rows = []
        block = max(1, BLOCK // 16 // len(A))  # ~20 (rows, triangles, 3) temporaries
        for s in range(0, len(X), block):
            rows.append(_closest_on_triangles(X[s:s + block], A, B, C))
        return self._triangle_bounds(X, np.concatenate(rows) if rows else np.empty((0, 3)))

    def _triangle_bounds(self, X: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(δ, error bound) of :meth:`triangle_distances` from the states X and their
        float closest points Y on the triangles."""
        with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
            n = X - Y
            dist = np.sqrt((n * n).sum(axis=1))
            V = self.hull.vertices
            M = np.maximum(np.abs(X).max(axis=1), np.abs(V).max())
            n1 = np.abs(n).sum(axis=1)
            vb = max(1, BLOCK // len(V))  # max_v n·v in blocks: no (rows × vertices)
            top = np.concatenate([(n[s:s + vb] @ V.T).max(axis=1)
                                  for s in range(0, len(n), vb)] or [np.empty(0)])
            low = (X * n).sum(axis=1) - top - 8 * UNIT_ROUNDOFF * n1 * M
            low = low / (dist * (1 + 4 * UNIT_ROUNDOFF)) * (1 - 4 * UNIT_ROUNDOFF)
            high = dist * (1 + 4 * UNIT_ROUNDOFF) + 64 * UNIT_ROUNDOFF * M
            err = np.maximum(high - dist, dist - low) * (1 + 4 * UNIT_ROUNDOFF)
        ok = (M > 1e-100) & (M < 1e100) & np.isfinite(err)
        return dist, np.where(ok, err, np.inf)

    def edge_error(self, X: np.ndarray) -> np.ndarray:
        """A bound on |edge distance − exact distance| for each row x of X, from
        M = max(‖x‖∞, max_v ‖v̂‖∞): rounding the exact vertices moves the polygon by at
        most √2 u M (Hausdorff); on the rounded polygon, w, e and r are within a few u M
        per coordinate, the error of t moves the point along the edge by at most
        |fl(w·e) − w·e|/‖e‖ ≤ 3u‖w‖ (whatever ‖e‖ is: the distance at t̂ exceeds the
        minimum by (t̂ − t*)‖e‖ in quadrature), and hypot adds u: in all < 32 u M;
        the bound used is 64 u M. Only for 1e-100 < M < 1e100, where no square nor
        product under- or overflows past that (else inf: the exact path is taken)."""
        P, Q = self._edges
        M = np.maximum(np.abs(X).max(axis=1), max(np.abs(P).max(), np.abs(Q).max()))
        return np.where((M > 1e-100) & (M < 1e100), 64 * UNIT_ROUNDOFF * M, np.inf)


def _cone_filter(hull) -> tuple | None:
    """(corners, o, mate, e, tree) for :meth:`ValidityMonitor._in_cones`: the certified
    triangles of a hull from :func:`_exact_polytope` and its point o, scaled by 2^-e
    (max |entry| ∈ [1/2, 1)), the triangles' mates and their :func:`_cone_tree`; None
    for other hulls or when the scaling rounds a corner or o."""
    if "cones" not in hull._cache:
        return None
    corners, o, mate = hull._cache["cones"]
    e = int(np.frexp(max(np.abs(corners).max(), np.abs(o).max()))[1])
    scaled, o_scaled = np.ldexp(corners, -e), np.ldexp(o, -e)
    if not (np.array_equal(np.ldexp(scaled, e), corners)
            and np.array_equal(np.ldexp(o_scaled, e), o)):
        return None
    return scaled, o_scaled, mate, e, _cone_tree(scaled, o_scaled)


def _surely_in_tetra(o: np.ndarray, A: np.ndarray, B: np.ndarray, C: np.ndarray,
                     X: np.ndarray) -> np.ndarray:
    """Per row: x strictly inside conv(o, T) for the triangle T = (a, b, c) of the same
    row, o on its negative side — orient(o, a, b, x), orient(o, b, c, x), orient(o, c,
    a, x) > 0 and orient(a, b, c, x) < 0, each proven by :func:`_orient3_float`."""
    apex = np.broadcast_to(o, X.shape)
    sure = np.ones(len(X), dtype=bool)
    for P, Q in ((A, B), (B, C), (C, A)):
        det, bound = _orient3_float(apex, P, Q, X)
        sure &= det > bound
    det, bound = _orient3_float(A, B, C, X)
    return sure & (det < -bound)


def _orient_sign(a: np.ndarray, B: np.ndarray, X: np.ndarray) -> np.ndarray:
    """Per row: +1 / −1 when the float (b − a) × (x − a) proves that sign (beyond
    8u(|l| + |r|) + 4·2^-1074, :meth:`ValidityMonitor._in_fan`), else 0."""
    left = (B[:, 0] - a[0]) * (X[:, 1] - a[1])
    right = (B[:, 1] - a[1]) * (X[:, 0] - a[0])
    det = left - right
    bound = 8 * UNIT_ROUNDOFF * (np.abs(left) + np.abs(right)) + 4 * MIN_SUBNORMAL
    return np.where(det > bound, 1, np.where(det < -bound, -1, 0))


def _inner_rows(hull) -> tuple[np.ndarray, np.ndarray] | None:
    """The filter rows (:func:`_filter_rows`) of the exact facets of the polygon of every
    k-th vertex (in cycle order) of a polygon H from :func:`_exact_polygon` with h >
    INNER_FACETS vertices, k = ⌈h / INNER_FACETS⌉: conv of vertices of H lies in H, so a
    state that filter proves inside it is in H — ~64 facets per state instead of h
    (states in a 10 000-gon away from its boundary). None for other hulls."""
    ends = hull._cache.get("edge_ends")
    if ends is None or len(ends[0]) <= INNER_FACETS:
        return None
    inner = _exact_polygon(ends[0][::-(-len(ends[0]) // INNER_FACETS)])
    return _filter_rows(inner._exact.facets) if inner.dim == 2 else None


def _polygon_edges(hull) -> tuple[np.ndarray, np.ndarray] | None:
    """(P, Q): the rounded end vertices of a polygon's edges, an edge per exact facet
    a·x ≤ β (its two exact vertices with a·v = β); None if they do not fit in floats.
    The vertices are tried in the order of their float slack β − a·v, so each facet
    takes ~2 exact tests instead of one per vertex (h² Fraction products: 8 s for a
    1000-gon); a hull from :func:`_exact_polygon` carries its edges (facet order)."""
    if "edge_ends" in hull._cache:
        return hull._cache["edge_ends"]
    V = hull.exact_vertices
    try:
        Vf = np.array([[float(c) for c in v] for v in V])
        A, b = _filter_rows(hull._exact.facets)
    except OverflowError:
        return None
    with np.errstate(over="ignore", invalid="ignore"):
        order = np.argsort(np.abs(b[:, None] - A @ Vf.T), axis=1, kind="stable")
    ends = []
    for (a, beta), row in zip(hull._exact.facets, order):
        pq = []
        for i in row:
            if a[0] * V[i][0] + a[1] * V[i][1] == beta:
                pq.append(i)
                if len(pq) == 2:
                    break
        ends.append(pq)
    return Vf[[pq[0] for pq in ends]], Vf[[pq[1] for pq in ends]]


def _hull_triangles(hull) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """(A, B, C) (T, 3) each: a triangulation of the boundary of conv V̂ (the certified
    triangles of a hull from :func:`_exact_polytope`, else Qhull on the rounded
    vertices V̂; any triangles of points of conv V̂ serve, their quality only tightens
    :meth:`ValidityMonitor.triangle_distances`' bound); None if Qhull fails."""
    from scipy.spatial import ConvexHull, QhullError

    V = hull.vertices
    if "cones" in hull._cache:  # the certified boundary triangles
        return tuple(hull._cache["cones"][0].transpose(1, 0, 2))
    if len(V) < 4 or not np.isfinite(V).all():
        return None
    try:
        tri = V[ConvexHull(V).simplices]
    except QhullError:
        return None
    return tri[:, 0], tri[:, 1], tri[:, 2]


def _norm(v: list[Fraction]) -> float:
    """‖v‖₂ of an exact nonzero vector, within a few u: v·2^-e with max|v_j|·2^-e ∈
    [1/2, 2) rounded per coordinate (no over- or underflow), its hypot times 2^e; at
    least the smallest subnormal (a nonzero distance never rounds to 0), inf beyond
    the float range."""
    top = max(map(abs, v))
    e = top.numerator.bit_length() - top.denominator.bit_length()
    try:
        return max(math.ldexp(math.hypot(*(float(t / Fraction(2) ** e) for t in v)), e),
                   MIN_SUBNORMAL)
    except OverflowError:
        return math.inf
