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

This module holds the names and the cheap monitors (:func:`spread`, :func:`diameter`
with its antipodal pairs); the validity monitor is split by job, each module with its
maths, and its public names are re-exported here:

* ``_validity_monitor`` — :class:`ValidityMonitor`: 0 iff inside (float filters, then
  exact), a certified float distance outside, else the exact projection;
* ``_initial_hull`` — :func:`certified_hull`: Qhull proposes, exact arithmetic
  certifies (the plane's exact monotone chain, R³'s certified surface);
* ``_hull_surface`` — Qhull's triangles in R³ proven to bound the hull (exact
  orientations), the polytope built from them, the walk that guesses a point's cone;
* ``_distance_trees`` — trees of boxes over edges and triangles and the per-item
  closest-point floats: the nearest edge / triangle in O(log h), bit for bit the dense
  path's float;
* ``_facet_filter`` — the float filter of exact facets and its error bound.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .._rounding import UNIT_ROUNDOFF
from ..errors import InputError
from ..geometry.exact import exact_points
from ._initial_hull import _chain, certified_hull
from ._validity_monitor import ValidityMonitor

__all__ = ["MONITORS", "ValidityMonitor", "certified_hull", "diameter", "monitor_names",
           "spread"]

#: the metrics a consensus run can record: "spread" (K+1, d), "diameter" (K+1,),
#: "validity" (the max (K+1,) and "validity_per_agent" (K+1, |B|))
MONITORS = ("spread", "diameter", "validity")


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
