"""What a consensus run is judged by: agreement and validity of the benign states.

* spread_p(t) = max_{i∈B} x_{i,p}(t) − min_{i∈B} x_{i,p}(t) per coordinate p, and the
  diameter max_{i,j∈B} ‖x_i(t) − x_j(t)‖₂ (consensus: both → 0);
* δ-validity: dist(x_i(t), conv{x_j(0) : j ∈ B}) for every benign i (validity: it stays
  ≤ δ). The hull is computed exactly once: Qhull proposes its vertices V, the exact
  polytope conv V (the safe kernel of V with F = 0) is built and every initial state is
  proven in it (:func:`certified_hull`; in the plane an exact monotone chain, in R³
  Qhull's triangulated boundary certified exactly); a state
  inside it (decided exactly) is at distance 0, one outside gets a certified float
  distance or the exact projection.

:data:`MONITORS` names the metrics a run can record (``simulate(..., metrics=...)``).
"""

from __future__ import annotations

import math
import operator
import time
from collections.abc import Iterator
from fractions import Fraction
from typing import Any

import numpy as np

from .._rounding import MIN_SUBNORMAL, UNIT_ROUNDOFF
from ..errors import InputError
from ..geometry.exact import exact_points, fraction_str, halfspaces_json
from ..geometry.kernel import SafeKernel, _affine_of, _Exact, _unit_rows, safe_kernel

__all__ = ["MONITORS", "ValidityMonitor", "certified_hull", "diameter", "monitor_names",
           "spread"]

#: the metrics a consensus run can record: "spread" (K+1, d), "diameter" (K+1,),
#: "validity" (the max (K+1,) and "validity_per_agent" (K+1, |B|))
MONITORS = ("spread", "diameter", "validity")

#: up to this many initial states the hull is built from all of them (no proposal)
PROPOSE_MIN = 64
#: a polygon of more vertices first filters states with an inner polygon of this many
INNER_FACETS = 64
#: rows × facets (or edges) of one block of the polygon's float filters
BLOCK = 2**20


def monitor_names(metrics: Any) -> tuple[str, ...]:
    """The :data:`MONITORS` a run records: every one for None, else the names given —
    a string of comma-separated names (the CLI's ``--metrics a,b``; blanks around a
    name ignored) or a sequence of such strings; duplicates ignored, order of
    MONITORS. Bytes, and items that are not strings, are refused (bytes iterate as
    integer codes)."""
    if metrics is None:
        return MONITORS
    names = [metrics] if isinstance(metrics, str) else metrics
    wrong = InputError(f"metrics must be a string of comma-separated names or a list of "
                       f"names from {', '.join(MONITORS)}; got {metrics!r}")
    if isinstance(metrics, (bytes, bytearray, memoryview)):
        raise wrong
    try:
        items = list(names)
    except TypeError:
        raise wrong from None
    if not all(isinstance(item, str) for item in items):
        raise wrong
    chosen = {name.strip() for item in items for name in item.split(",") if name.strip()}
    if items and not chosen:
        raise InputError(f"metrics {metrics!r} names no monitor; give some of "
                         f"{', '.join(MONITORS)}")
    unknown = sorted(map(repr, chosen - set(MONITORS)))
    if unknown:
        raise InputError(f"metrics: unknown name(s) {', '.join(unknown)}; "
                         f"choose from {', '.join(MONITORS)}")
    return tuple(m for m in MONITORS if m in chosen)


def spread(states: np.ndarray) -> np.ndarray:
    """Per-coordinate max − min over the rows of ``states`` (n, d)."""
    return states.max(axis=0) - states.min(axis=0)


def diameter(states: np.ndarray) -> float:
    """Largest Euclidean distance between two rows of ``states`` (n, d).

    The rows are first scaled by a power of two 2^-e so that max |x| ∈ [1/2, 1) (when
    that is exact: no entry becomes subnormal), which changes no rounding: the answer is
    2^e times the plain n² formula on the scaled rows, and that formula neither
    overflows (rows at 1e300) nor underflows (rows at 1e-300); each distance is then
    within (d + 2)u of its exact value.

    Only rows that can end a diameter are compared with every row: for any point c
    (here the float mean) and R = max_j ‖x_j − c‖, a row p has max_j ‖p − x_j‖ ≤
    ‖p − c‖ + R, so p ends no diameter when ‖p − c‖ + R < L for a lower bound L (the
    distances from the row farthest from c). Both ends of a diameter pass that test;
    the float test gets a relative slack 4(d + 2)u, far above the rounding of its
    norms (each ‖x − c‖ is computed from exact-rounded differences); repeated rows
    are kept once (states at a few values: every row may end a diameter). When R or L
    is ≤ 1e-100 after scaling (converged rows: their float mean is off by a rounding,
    so R alone does not see it) or a row is not finite, the distinct rows are compared
    pairwise by chained hypot (no square underflows). In the plane, when more than
    ANGULAR_MIN rows are kept (states on a circle), only near-antipodal pairs about
    the midpoint of an exact diametral pair are compared (:func:`_caliper_pair`,
    :func:`_antipodal_max`). Memory O(n·d) (pairs in blocks); time O(n·kept), in the
    plane O(n log n) for states on a circle."""
    X = np.asarray(states, dtype=float)
    if len(X) < 2:
        return _pairwise_max(X, X)
    scale = 0
    rounded = None
    if np.isfinite(X).all():
        scale = int(np.frexp(np.abs(X).max())[1])
        if not np.array_equal(np.ldexp(np.ldexp(X, -scale), scale), X):
            rounded = np.ldexp(X, -scale)  # subnormal entries lose bits: see below
            scale = 0
        X = np.ldexp(X, -scale)
        keep = _diameter_ends(X)
        if keep is not None:
            K = np.unique(X[keep], axis=0)  # states at a few values: all ends
            if X.shape[1] == 2 and len(K) > ANGULAR_MIN:
                p, q = K[list(_caliper_pair(K))]
                L = float(np.sqrt(((p - q) ** 2).sum()))
                return math.ldexp(_antipodal_max(K, (p + q) / 2, L), scale)
            return math.ldexp(_pairwise_max(K, X), scale)
    distinct = np.unique(X, axis=0)
    keep = None if rounded is None else _diameter_ends(rounded)
    ends = distinct if keep is None else np.unique(X[keep], axis=0)
    return math.ldexp(_pairwise_max(ends, distinct, hypot=True), scale)


def _diameter_ends(X: np.ndarray) -> np.ndarray | None:
    """The rows of X (finite, max |x| < 1) that can end a diameter (:func:`diameter`:
    ‖p − c‖ + R ≥ L(1 − 4(d + 2)u)), or None when R or L is not in (1e-100, 1e100).
    Rows given rounded (each entry within 2^-1075: states at 1e300 beside subnormal
    ones, scaled by 2^-e) keep every end: the rounding moves each distance by at most
    2√d·2^-1075, far below the slack 4(d + 2)u·L ≥ 1e-115 — the ends are then compared
    on the rows as given, by hypot, not every pair (7 s at N = 10 000)."""
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        r = np.sqrt(((X - X.mean(axis=0)) ** 2).sum(axis=1))
        far = np.sqrt(((X - X[np.argmax(r)]) ** 2).sum(axis=1)).max()
        if 1e-100 < r.max() < 1e100 and far > 1e-100:
            return r + r.max() >= far * (1 - 4 * (X.shape[1] + 2) * UNIT_ROUNDOFF)
    return None


#: kept rows beyond which the plane's diameter compares near-antipodal pairs only
ANGULAR_MIN = 2048


def _antipodal_max(K: np.ndarray, c: np.ndarray, L: float) -> float:
    """max fl‖p − q‖ over rows of K (n, 2), |K| ≤ 1 in scale, given a pair of rows at
    float distance L and a point c: only pairs whose angle about c is within w_p of
    antipodal are compared. With ρ_p = ‖p − c‖, R = max ρ and α = |∠(p, q) − π|,
    ‖p − q‖² = ρ_p² + ρ_q² − 2 ρ_p ρ_q cos ∠ ≤ ρ_p² + R² + 2 ρ_p R cos α when cos α ≥ 0
    (and < L² otherwise, if L² > ρ_p² + R²), so a pair at true distance ≥ L' =
    L(1 − 8u) has cos α ≥ γ_p = (L'² − ρ_p² − R²)/(2 ρ_p R), ρ and R enlarged by 8u.
    γ_p is rounded within E_p = 16u(L'² + ρ_p² + R²)/(2 ρ_p R) and each angle within
    ~8u: w_p = arccos(γ_p − E_p) + 1e-12 (π when L'² ≤ ρ_p² + R²). Every pair left out
    is shorter than L' and its float below L: the result is the all-pairs float."""
    u8 = 8 * UNIT_ROUNDOFF
    rho = np.hypot(K[:, 0] - c[0], K[:, 1] - c[1]) * (1 + u8)
    R = rho.max()
    Lo = L * (1 - u8)
    with np.errstate(divide="ignore", invalid="ignore"):
        num = Lo * Lo - rho * rho - R * R
        gamma = (num - 16 * UNIT_ROUNDOFF * (Lo * Lo + rho * rho + R * R)) / (2 * rho * R)
        w = np.where(num > 0, np.arccos(np.clip(gamma, -1.0, 1.0)) + 1e-12, np.pi)
    w = np.where(np.isnan(w), np.pi, w)
    theta = np.arctan2(K[:, 1] - c[1], K[:, 0] - c[0])
    order = np.argsort(theta)
    ring = np.concatenate([theta[order] - 2 * np.pi, theta[order], theta[order] + 2 * np.pi])
    who = np.tile(order, 3)
    lo = np.searchsorted(ring, theta + np.pi - w, side="left")
    hi = np.searchsorted(ring, theta + np.pi + w, side="right")
    counts = hi - lo
    if counts.sum() > 64 * len(K) + 10**6:  # not a thin ring: compare every pair
        return _pairwise_max(K, K)
    p = np.repeat(np.arange(len(K)), counts)
    q = who[np.repeat(lo - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())]
    diff = K[p] - K[q]
    return float(np.sqrt((diff**2).sum(axis=1)).max())


def _caliper_pair(K: np.ndarray) -> tuple[int, int]:
    """Rows (i, j) of K (distinct, in lexicographic order, (n, 2)) at the exact
    diameter: rotating calipers (Shamos) on the exact hull of K (:func:`_chain`,
    counter-clockwise, no three vertices collinear), in integers. For each edge
    (v_i, v_{i+1}), the vertex v_j farthest from its line — reached by advancing j while
    (v_{i+1} − v_i) × (v_{j+1} − v_j) > 0, and j only advances as i does — is paired
    with both ends of the edge, and v_{j+1} too when that cross product is 0 (an edge
    parallel to it). Every antipodal pair (u, v) (parallel supporting lines through u
    and v) appears: turn the lines about u and v until one lies along an edge; that
    edge ends at u or v and the other is farthest from it. A diametral pair is
    antipodal (the lines through its ends perpendicular to it support the set)."""
    ints = exact_points(K).ints
    cycle = _chain(ints)
    V = [ints[c] for c in cycle]
    h = len(V)
    best, pair = -1, (cycle[0], cycle[-1])
    j = 1 % h
    for i in range(h if h > 2 else 0):
        (p0, p1), (q0, q1) = V[i], V[(i + 1) % h]
        while True:
            (r0, r1), (s0, s1) = V[j], V[(j + 1) % h]
            turn = (q0 - p0) * (s1 - r1) - (q1 - p1) * (s0 - r0)
            if turn <= 0:
                break
            j = (j + 1) % h
        for k in (j, (j + 1) % h) if turn == 0 else (j,):
            for e in (i, (i + 1) % h):
                dist = (V[e][0] - V[k][0]) ** 2 + (V[e][1] - V[k][1]) ** 2
                if dist > best:
                    best, pair = dist, (cycle[e], cycle[k])
    return pair


def _pairwise_max(P: np.ndarray, X: np.ndarray, chunk: int = 256, hypot: bool = False
                  ) -> float:
    """max ‖p − x‖₂ over rows p of ``P`` and x of ``X``, in blocks of ``chunk`` rows;
    ``hypot``: by chained hypot (no square under- or overflows: rows that differ by
    1e-200 beside entries ~1, or at 1e300; within (d + 1)u, ~3x slower)."""
    best = -np.inf
    for s in range(0, max(len(P), 1), chunk):
        diff = P[s:s + chunk, None, :] - X[None, :, :]
        with np.errstate(over="ignore"):  # a difference beyond the float range: inf
            dist = (np.hypot.reduce(np.abs(diff), axis=2) if hypot
                    else np.sqrt((diff**2).sum(axis=2)))
        best = np.maximum(best, dist.max())  # NaN propagates
    return float(best)


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


def _orient_sign(a: np.ndarray, B: np.ndarray, X: np.ndarray) -> np.ndarray:
    """Per row: +1 / −1 when the float (b − a) × (x − a) proves that sign (beyond
    8u(|l| + |r|) + 4·2^-1074, :meth:`ValidityMonitor._in_fan`), else 0."""
    left = (B[:, 0] - a[0]) * (X[:, 1] - a[1])
    right = (B[:, 1] - a[1]) * (X[:, 0] - a[0])
    det = left - right
    bound = 8 * UNIT_ROUNDOFF * (np.abs(left) + np.abs(right)) + 4 * MIN_SUBNORMAL
    return np.where(det > bound, 1, np.where(det < -bound, -1, 0))


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


def _slacks(A: np.ndarray, b: np.ndarray, states: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """fl(Â x − b̂) per row of ``states`` and facet (Â, b̂), and its error bound
    (:meth:`ValidityMonitor.surely_inside`)."""
    with np.errstate(over="ignore", invalid="ignore"):
        S = states @ A.T - b
        bound = _slack_bound(states.shape[1], np.abs(states) @ np.abs(A).T, np.abs(b),
                             np.abs(states).max(axis=1)[:, None])
    return S, bound


def _slack_bound(d: int, abs_dot: np.ndarray, abs_b: np.ndarray,
                 top: np.ndarray) -> np.ndarray:
    """Error bound of fl(â·x − b̂) in R^d from |â|·|x| (``abs_dot``), |b̂| and
    max |x_p| (``top``): 2(d+2)u(|â|·|x| + |b̂|) + (d+2)·2^-1074·(max |x_p| + 1), the
    last term for gradual underflow (one rule for :func:`_slacks` and the fan test)."""
    return (2 * (d + 2) * UNIT_ROUNDOFF * (abs_dot + abs_b)
            + (d + 2) * MIN_SUBNORMAL * (top + 1))


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


def _filter_rows(facets) -> tuple[np.ndarray, np.ndarray]:
    """Floats of the exact facets a·x ≤ β, each divided exactly by max|a_j| (so the
    entries of Â are in [−1, 1]; b̂ is ±inf beyond the float range), each quotient
    rounded once (:func:`_quotient`)."""
    tops = [max(map(abs, a)) for a, _ in facets]
    A = np.array([[_quotient(v, top) for v in a] for (a, _), top in zip(facets, tops)])
    return A, np.array(
        [_quotient(beta, top) for (_, beta), top in zip(facets, tops)], dtype=np.float64)


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


def _quotient(v: Fraction, w: Fraction) -> float:
    """v / w (w > 0) correctly rounded (Python's int / int, no Fraction built: 20 000
    facets took 1.3 s), ±inf beyond the float range."""
    num, den = v.numerator * w.denominator, v.denominator * w.numerator
    try:
        return num / den
    except OverflowError:
        return math.inf if num > 0 else -math.inf
