"""Certified fast path for full-dimensional, simple kernels: qhull proposes, integers decide.

Floats (a Chebyshev LP for an interior point, then qhull's halfspace intersection)
propose the vertices of Ψ and, for each vertex, the k valid halfspaces that define it.
The proposal is accepted only if, in exact arithmetic,

1. every proposed vertex v (the exact solution of its k defining equations) satisfies
   every valid halfspace, and is tight on none but its own k (a simple vertex) —
   so conv(V) ⊆ Ψ by the characterisation theorem;
2. for every vertex and every k − 1 of its defining halfspaces there is another
   proposed vertex with the same k − 1: the edge of P_S = ⋂ (defining halfspaces)
   leaving v along them ends at a proposed vertex (it lies on that line and in P_S),
   so every edge of P_S is bounded and the vertex set V is closed under adjacency;
   the graph of a polyhedron is connected, hence V is all of P_S's vertices and P_S
   is the polytope conv(V).

Then Ψ ⊆ P_S (valid halfspaces) = conv(V) ⊆ Ψ. Anything else — a lower-dimensional
or degenerate kernel, a qhull failure, a vertex the check rejects — returns None and
the caller clips exactly (:mod:`.polytope`).
"""

from __future__ import annotations

import itertools

import numpy as np

from .._rounding import UNIT_ROUNDOFF as _EPS
from .polytope import ExactPolytope, _normalise

__all__ = ["certified_kernel"]

MAX_ROUNDS = 4
#: a Chebyshev radius below this fraction of the coordinates triggers the local pass
LOCAL_RADIUS = 1e-4
#: in the local pass, halfspaces farther than FAR kernel sizes from the centre are left out
FAR = 1e4


def _chebyshev(A: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray,
               centre: np.ndarray) -> tuple[np.ndarray, float] | None:
    """Centre and radius of the largest ball in {x : A x ≤ b} (unit rows) whose centre
    lies in the box [lo, hi] (which contains the kernel), by the margin LP started
    from the rows nearest ``centre``; None if the LP fails (e.g. the set is empty)."""
    from ._lp import max_margin

    found = max_margin(A, b, np.ones(len(b)), lo, hi, centre=centre, t_min=0.0)
    if found is None:
        return None
    return found.x, found.t


def _propose(H, sel: np.ndarray) -> tuple[np.ndarray, list[list[int]]] | None:
    """Vertices and their defining halfspaces (indices into sel) of {A x ≤ b}, from
    qhull around a Chebyshev centre. A kernel small against its coordinates (states
    that have nearly converged) is re-centred and rescaled first: x = o + s y with o
    the first centre, s the distance from o to its (k+1)-th nearest halfspace, so the
    LP and qhull see it at unit size. None for a flat or empty kernel or a qhull
    failure."""
    from scipy.spatial import HalfspaceIntersection, QhullError

    norms = np.linalg.norm(H.af[sel], axis=1)  # cofactor rows can be ~1e-14: unit rows
    if not norms.all():  # a float row rounded to zero: no proposal
        return None
    A, b = H.af[sel] / norms[:, None], H.bf[sel] / norms
    rows = np.arange(len(sel))
    lo, hi, median = H.box
    found = _chebyshev(A, b, lo, hi, median)
    if found is None:
        return None
    x0, r = found
    k = A.shape[1]
    o, s = np.zeros(k), 1.0
    if r <= LOCAL_RADIUS * (1.0 + np.abs(x0).max()):
        # the kernel is tiny: measure it by the (k+1)-th nearest halfspace to o, and
        # leave out the halfspaces far beyond that (they cannot cut it; the exact
        # certificate checks every valid halfspace anyway)
        o = x0
        b = b - A @ o
        s = float(np.sort(np.abs(b))[k])
        if not s > 0.0:
            return None
        rows = np.flatnonzero(b <= FAR * s)
        A, b = A[rows], b[rows] / s
        found = _chebyshev(A, b, (lo - o) / s, (hi - o) / s, np.zeros(k))
        if found is None:
            return None
        x0, r = found
    if r <= 1e-9 * (1.0 + np.abs(x0).max()):
        return None
    try:  # a flat kernel can make qhull divide by zero: a proposal, checked exactly
        with np.errstate(divide="ignore", invalid="ignore"):
            hs = HalfspaceIntersection(np.hstack([A, -b[:, None]]), x0, qhull_options="Qt")
    except (QhullError, ValueError):
        return None
    if not np.isfinite(hs.intersections).all():
        return None
    return o + s * hs.intersections, [[int(rows[i]) for i in f] for f in hs.dual_facets]


def certified_kernel(H, k: int, scale: int, first: np.ndarray) -> ExactPolytope | None:
    """Ψ in scaled integer coordinates as an ExactPolytope (constraints: the facets),
    or None when the fast path cannot certify it. ``scale``: the float unit of H (its
    floats are the integer coordinates / scale)."""
    if len(H) < k + 1:
        return None
    sel = np.asarray(first if len(first) >= k + 1 else np.arange(len(H)), dtype=np.int64)
    for _ in range(MAX_ROUNDS):
        prop = _propose(H, sel)
        if prop is None:
            return None
        V, facets = prop
        if any(len(f) != k for f in facets):
            return None
        # floats first: halfspaces clearly violated by a proposed vertex join sel
        from ._candidates import row_max

        top = row_max(H.af, H.bf, np.ascontiguousarray(V))
        bad = top > 1e-9 * (1.0 + np.abs(H.bf))
        if bad.any():
            sel = np.union1d(sel, np.flatnonzero(bad))
            continue
        return _certify(H, k, scale, sel, facets, V, top)
    return None


def _certify(H, k: int, scale: int, sel: np.ndarray, facets: list[list[int]],
             V: np.ndarray | None = None, top: np.ndarray | None = None
             ) -> ExactPolytope | None:
    """Exact vertices from the proposed defining sets (merged when equal), their full
    tight sets among the defining halfspaces S, feasibility against every valid
    halfspace, and closure: every extreme ray of every vertex's tangent cone leads to
    another proposed vertex (see the module docstring)."""
    S_set = sorted({int(sel[i]) for f in facets for i in f})
    where = {h: i for i, h in enumerate(S_set)}
    index: dict[tuple[int, ...], int] = {}
    verts: list[tuple[int, ...]] = []
    tight: list[int] = []
    of_proposal: list[int] = []
    for f in facets:
        T = [int(sel[i]) for i in f]
        v = _solve(H, T)
        if v is None:
            return None
        i = index.setdefault(v, len(verts))
        of_proposal.append(i)
        if i == len(verts):
            verts.append(v)
            tight.append(0)
        for h in T:
            tight[i] |= 1 << where[h]
    # exact feasibility, and the complete tight sets within S: floats of the exact
    # vertices (correctly rounded, int / int) with a rounding bound, plus the underflow
    # term, decide the clear cases; inf or NaN is never "clear"
    Vx = np.array([[yi / (v[0] * scale) for yi in v[1:]] for v in verts])
    c = 2.0 * (k + 4) * _EPS
    M = np.abs(Vx).max()
    floor = H.floor()
    l1, perm_sum, babs = H.row_terms()
    row_bound = H.c_err * (perm_sum * M + H.b_abs) + c * (l1 * M + babs) + floor
    if V is None or top is None:
        from ._candidates import row_max

        top = row_max(H.af, H.bf, np.ascontiguousarray(Vx))
    else:  # the proposals' maxima, moved by at most ‖a‖₁ · max |V − Vx|
        shift = np.abs(V - Vx[of_proposal]).max()
        row_bound = row_bound + l1 * shift
    rows = np.flatnonzero(~(top < -row_bound))  # the rows not surely slack at every vertex
    absV = np.abs(Vx).T
    Sv = H.af[rows] @ Vx.T - H.bf[rows, None]
    bound = H.c_err * (H.af_abs[rows] @ absV + H.b_abs[rows, None]) + c * (
        np.abs(H.af[rows]) @ absV + np.abs(H.bf[rows])[:, None]) + floor
    if (Sv > bound).any():
        return None
    near_r, near_v = np.nonzero(~(np.abs(Sv) > bound))
    slacks = _int64_slacks(H, scale, verts, rows[near_r], near_v)
    if slacks is not None:  # small integers: all undecided pairs at once
        if (slacks > 0).any():
            return None
        for h, vi in zip(rows[near_r][slacks == 0], near_v[slacks == 0], strict=True):
            if int(h) in where:
                tight[int(vi)] |= 1 << where[int(h)]
        near_r = near_v = ()
    for r, vi in zip(near_r, near_v, strict=True):
        h, vi = int(rows[r]), int(vi)
        if h in where and tight[vi] >> where[h] & 1:
            continue
        a, b = H.exact(h)
        w, *y = verts[vi]
        slack = sum(ai * yi for ai, yi in zip(a, y, strict=True)) - b * w
        if slack > 0:
            return None
        if slack == 0 and h in where:
            tight[vi] |= 1 << where[h]
    normals = [H.exact(h)[0] for h in S_set]
    members: dict[int, list[int]] = {}
    for vi, t in enumerate(tight):
        for h in _bits(t):
            members.setdefault(h, []).append(vi)
    for vi in range(len(verts)):
        T = list(_bits(tight[vi]))
        # a simple vertex (k independent tight rows) has a simplicial tangent cone: its
        # extreme rays keep all but one row tight
        rays = ([tight[vi] ^ (1 << h) for h in T] if len(T) == k
                else _extreme_rays(normals, T, k))
        for Z in rays:
            fewest = min((members[h] for h in _bits(Z)), key=len)
            if not any((tight[u] & Z) == Z for u in fewest if u != vi):
                return None
    P = ExactPolytope(k, unit=scale)
    for h in S_set:
        a, b = H.exact(h)
        P.a.append(a)
        P.b.append(b)
    P.verts = verts
    P.tight = tight
    return P


def _int64_slacks(H, scale: int, verts: list[tuple[int, ...]], hs: np.ndarray,
                  vs: np.ndarray) -> np.ndarray | None:
    """a_h·y − b_h·w for the pairs (hs[i], vs[i]) in int64 — when the float normals are
    exact integers (integer data, exact float arithmetic: c_err = 0, scale 1) and every
    term provably fits — else None (the caller works in Python integers)."""
    if H.c_err != 0.0 or scale != 1 or not len(hs):
        return None
    A, b = H.af[hs], H.bf[hs]
    if not (np.all(A == np.round(A)) and np.all(b == np.round(b))):
        return None
    top = max(max(abs(c) for c in v) for v in verts)
    reach = (np.abs(A).sum(axis=1).max() + np.abs(b).max()) * float(top)
    if not reach < 2.0**62:
        return None
    V = np.array(verts, dtype=np.int64)[vs]
    return (A.astype(np.int64) * V[:, 1:]).sum(axis=1) - b.astype(np.int64) * V[:, 0]


def _solve(H, T: list[int]) -> tuple[int, ...] | None:
    """The point where the k hyperplanes T meet, homogeneous (w > 0, primitive), by
    Cramer's rule on integers; None if they do not meet in one point."""
    from .halfspaces import _int_det

    rows = [H.exact(h) for h in T]
    A = [list(a) for a, _ in rows]
    w = _int_det(A)
    if w == 0:
        return None
    y = []
    for j in range(len(A)):
        Aj = [r[:j] + [b] + r[j + 1:] for r, (_, b) in zip(A, rows, strict=True)]
        y.append(_int_det(Aj))
    if w < 0:
        w, y = -w, [-v for v in y]
    return _normalise((w, *y))


def _extreme_rays(normals: list[tuple[int, ...]], T: list[int], k: int):
    """For the cone {d : a_h·d ≤ 0, h ∈ T} (a pointed cone: T has rank k), the bitset of
    the constraints tight along each extreme ray. A ray is the null direction of k − 1
    independent normals, signed to satisfy all of T."""
    seen = set()
    for sub in itertools.combinations(T, k - 1):
        d = _null_direction([normals[h] for h in sub], k)
        if d is None:
            continue
        vals = [sum(x * y for x, y in zip(normals[h], d, strict=True)) for h in T]
        if all(v <= 0 for v in vals):
            pass
        elif all(v >= 0 for v in vals):
            vals = [-v for v in vals]
        else:
            continue
        Z = sum(1 << h for h, v in zip(T, vals, strict=True) if v == 0)
        if Z not in seen:
            seen.add(Z)
            yield Z


def _null_direction(rows: list[tuple[int, ...]], k: int) -> tuple[int, ...] | None:
    """The generalised cross product of k − 1 integer vectors in Z^k (None if they are
    dependent)."""
    from .halfspaces import _int_det

    d = tuple((-1) ** (k - 1 + j) * _int_det([list(r[:j] + r[j + 1:]) for r in rows])
              for j in range(k))
    return d if any(d) else None


def _bits(t: int):
    while t:
        low = t & -t
        yield low.bit_length() - 1
        t ^= low
