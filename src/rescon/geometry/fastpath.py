"""Certified fast path for full-dimensional kernels: qhull proposes, integers decide.

Floats (a Chebyshev LP for an interior point, then qhull's halfspace intersection —
in d ≥ 5 as two halves on two threads, :func:`_halves`) propose the vertices of Ψ
and, for each vertex, the valid halfspaces that qhull finds
tight there (k of them at a simple vertex, more where qhull merged a non-simple one —
common in d ≥ 4, where many hyperplanes through data points meet). Each proposal is
solved exactly from k of its rows that floats suggest are independent: det A ≠ 0 is
shown modulo a prime, then the vertex is found in the flat of the data points that
two of its hyperplanes share (:func:`_meet`, on integers a third the size of Cramer's
rule); the proposal is accepted only if, in exact arithmetic,

1. every proposed vertex v satisfies every valid halfspace, and its tight set within
   the defining halfspaces S (the rows of all proposals) is computed exactly — so
   conv(V) ⊆ Ψ by the characterisation theorem (a row the floats cannot place is tight
   where a flat of data points on it holds v, :func:`._certify_nb.tight_through` — on
   the bench clouds every such row — else its slack is computed on the integers). The
   rows of S are decided pair by pair; the valid rows outside S (most of them) only
   once step 2 has proven conv(V) = P_S and its graph: a linear function's maximum over
   a polytope is at any vertex no neighbour of which is above it, found by a walk on
   the graph and proven with rounding bounds (:func:`._candidates.graph_top`), the
   rows it leaves open pair by pair;
2. every extreme ray of every vertex's tangent cone {d : a_h·d ≤ 0, h tight at v}
   leads to another proposed vertex: for a simple vertex the rays keep all but one of
   its k rows tight; for a non-simple one they are the directions u − v to the
   proposed vertices u whose tight rows shared with v have rank k − 1, where a check
   on the exact tight sets proves that these are all the rays (:mod:`._closure`: the
   faces they span are closed under adjacency, level by level down the face figures),
   else they come from an integer double description of the cone. The rows Z tight
   along a ray have rank k − 1, so a vertex u ≠ v with
   Z ⊆ tight(u) lies on the ray's line, hence on the ray (v is a vertex) and the edge of
   P_S = ⋂ S leaving v along it is bounded and ends at a proposed vertex. So V is
   closed under adjacency; the graph of a polyhedron is connected, hence V is all of
   P_S's vertices and P_S is the polytope conv(V).

Then Ψ ⊆ P_S (valid halfspaces) = conv(V) ⊆ Ψ. Anything else — a lower-dimensional
kernel, a qhull failure, a vertex the check rejects, or one missed (e.g. its k chosen
rows were dependent, or a joggled proposal was not solved because its modular key
equalled another's: :func:`_one_per_point`) — returns None and the caller clips
exactly (:mod:`.polytope`). Only the proposals' vertices are taken as V, so leaving a
proposal out can lose a vertex of P_S but never add a point that is not one.

The exact solves are off the critical path: each proposal's correctly rounded floats
are proven from floats alone where possible (:mod:`._vertex_floats`: a residual in
doubled precision and a Rump-style bound on the correction) — all that the float
filters, the merge of equal points (correct rounding is a function of the point:
distinct floats are distinct points) and the public floats read. A vertex is solved
exactly (:func:`_solve_rows`, the same integers as an eager solve) only where read:
floats that coincide, a pair the filters and the data points leave open, a proposal
whose floats are not proven, or the first read of the exact vertices
(:class:`._lazy_vertices.LazyVertices`).
"""

from __future__ import annotations

import contextlib
import gc
import itertools
import operator
import threading
from math import gcd

import numpy as np

from .._rounding import UNIT_ROUNDOFF as _EPS
from ._lazy_vertices import LazyVertices, RowsOf
from .exact import cross_all
from .polytope import PRIME, ExactPolytope, _bits, members_of, tight_pairs

__all__ = ["certified_kernel"]

MAX_ROUNDS = 4
#: a Chebyshev radius below this fraction of the coordinates triggers the local pass
LOCAL_RADIUS = 1e-4
#: in the local pass, halfspaces farther than FAR kernel sizes from the centre are left out
FAR = 1e4
#: vertices with more tight rows than this are left out of the fast closure count
#: (C(t, k − 1) keys each); rays ending there are found by a scan
MAX_TIGHT = 12
#: qhull's options, tried in turn until a proposal is certified: merged facets (one
#: proposal per vertex), then joggled input (simplicial pieces; qhull's merging can
#: fail on the many near-coincident hyperplanes of d = 5 clouds)
QHULL_OPTIONS = (None, "QJ")


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


#: the merged proposal (``options`` None) in dimension k ≥ 5 tries these qhull options
#: in turn, each until its proposal is certified or fails (:func:`_chain`):
#: zero-centrum pre-merges with pinched-vertex merging first, which completed
#: on all 6 d = 5, n = 30 and 8 of 9 n = 20 bench clouds, 1.2–2.4× faster than qhull's
#: default "Qx" where both completed — "Qx" failed with a duplicate ridge (QH6271) or
#: a precision error on 3 of the 6 n = 30 clouds, whose proposals then came joggled
#: (3× as many pieces to certify). Only proposals: the certification decides.
MERGED_OPTIONS_5D = ("C-0 Q14", None)
#: the merged proposal in dimension 4: qhull's default ("" below 5 dimensions) with
#: "Q5", which leaves out qhull's final pass over the outer planes (it computes the
#: largest distance of a point above its facet, for precision reports; the facets
#: and vertices are those already built, and nothing here reads the outer planes):
#: the same dual facets and intersections, bit for bit, on the 18 d = 4 bench
#: clouds, with 6–10 % less qhull time (sphere(4, 50, 5) 20.7 → 18.8 CPU-ms, medians
#: of 8 alternating). A proposal alone: the certification decides.
MERGED_OPTIONS_4D = ("Q5",)
#: qhull's intersection in dimension ≥ SPLIT_DIM with at least SPLIT_ROWS halfspaces
#: runs as two halves on two threads (:func:`_halves`)
SPLIT_DIM = 5
SPLIT_ROWS = 400
#: the axes across which the halves are cut, tried in turn
SPLIT_AXES = 2
#: ... and only when the Chebyshev centre lies within this many radii of the origin:
#: about a point far from the origin the float rows' offsets carry more rounding
#: (up to CENTRE_MIN_RATIO spreads of the data: kernel.py), and qhull failed (QH6271)
#: on a half across both axes of every d = 5 cloud tried 180–3400 radii out (data
#: around 100 or 1000), often on P itself too; at 25–35 radii it failed on some and
#: not on others (the bench clouds: ≤ 1.5). Only a choice of proposal: a failure
#: costs time, once per kernel (:class:`_Split`)
SPLIT_MAX_OFFSET = 64.0
#: a half on which qhull fails with a merged option is retried at once, on its thread,
#: with these options (qhull's initial simplex from all points): 2 of the 72 halves
#: (both axes) of 18 d = 5, n = 24–30 bench-family clouds failed with "C-0 Q14", both
#: succeeded thus (sphere(5, 30, 3)'s lower half across x_0: 0.08 s, where both halves
#: across x_1 took 0.09 s wall, 0.14 CPU-s, after the failure)
HALF_RETRY_OPTIONS = "Qs C-0 Q14"


def _propose(H, sel: np.ndarray, options: str | None = None, split: _Split | None = None
             ) -> tuple[np.ndarray, list[list[int]]] | None:
    """Vertices and their defining halfspaces (indices into sel) of {A x ≤ b}, from
    qhull around a Chebyshev centre. A kernel small against its coordinates (states
    that have nearly converged) is re-centred and rescaled first: x = o + s y with o
    the first centre, s the distance from o to its (k+1)-th nearest halfspace, so the
    LP and qhull see it at unit size. ``options``: qhull's option string (None: its
    default); ``split``: whether large ones in d ≥ 5 may still come from two halves
    (:func:`_intersection`; None: they may). None for a flat or empty kernel or a qhull failure."""
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
    found = _intersection(A, b, x0, r, options, _Split() if split is None else split)
    if found is None:
        return None
    V, facets = found  # facets: lists of ints, positions in rows
    if len(rows) < len(sel):  # the local pass left rows out: positions in sel
        kept = rows.tolist()
        facets = [[kept[i] for i in f] for f in facets]
    return o + s * V, facets


class _Split:
    """Whether a kernel's qhull proposals may (still) come from two halves
    (:func:`_halves`: ``on``, off for the rest of the kernel once the halves failed on
    every axis or their proposal was refused) and whether the last one did (``used``)."""

    def __init__(self) -> None:
        self.on, self.used = True, False


def _intersection(A: np.ndarray, b: np.ndarray, x0: np.ndarray, r: float,
                  options: str | None, split: _Split
                  ) -> tuple[np.ndarray, list[list[int]]] | None:
    """The vertices of P = {A x ≤ b} (x0 inside, with the ball of radius r around it)
    and, for each, the rows qhull finds tight there (positions in A): qhull's
    halfspace intersection — while ``split`` is on, in dimension ≥ SPLIT_DIM with at
    least SPLIT_ROWS rows and x0 within SPLIT_MAX_OFFSET radii of the origin, as two
    halves on two threads (:func:`_halves`, cut across the first axis, else the
    second: qhull can fail on one half of a cut and not on another's), on P itself
    where that fails. None if qhull fails."""
    split.used = False
    if (split.on and A.shape[1] >= SPLIT_DIM and len(A) >= SPLIT_ROWS
            and np.abs(x0).max() <= SPLIT_MAX_OFFSET * r):
        for axis in range(SPLIT_AXES):
            found = _halves(A, b, x0, r, options, axis)
            if found is not None:
                split.used = True
                return found
        split.on = False  # failed on every axis: not again in this kernel
    return _qhull(A, b, x0, options)


def _qhull(A: np.ndarray, b: np.ndarray, x0: np.ndarray, options: str | None
           ) -> tuple[np.ndarray, list[list[int]]] | None:
    """qhull's intersection of {A x ≤ b} around the interior point x0: its vertices
    and dual facets; None if qhull fails or gives a non-finite vertex."""
    from scipy.spatial import HalfspaceIntersection, QhullError

    try:  # a flat kernel can make qhull divide by zero: a proposal, checked exactly
        with np.errstate(divide="ignore", invalid="ignore"):
            hs = HalfspaceIntersection(np.hstack([A, -b[:, None]]), x0,
                                       qhull_options=options)
    except (QhullError, ValueError):
        return None
    if not np.isfinite(hs.intersections).all():
        return None
    return hs.intersections, hs.dual_facets


def _halves(A: np.ndarray, b: np.ndarray, x0: np.ndarray, r: float, options: str | None,
            axis: int = 0) -> tuple[np.ndarray, list[list[int]]] | None:
    """:func:`_intersection` from the halves P⁻ = P ∩ {x_j ≤ c} and P⁺ = P ∩ {x_j ≥ c}
    (j = ``axis``, c = x0's coordinate j; x0 ∓ (r/2) e_j are inside them, r/2 from
    their boundaries), one qhull each on two threads (numba's thread count; one thread
    runs them in turn) — qhull runs without the GIL, and its work follows its output;
    a half it fails on with a merged option is retried with HALF_RETRY_OPTIONS.

    With the cut as row m: a vertex of P off the cut is a vertex of the half holding
    it, tight on the same rows; every other vertex of a half lies on the cut — a
    vertex of the section of P by the cut, which both halves share: where an edge of
    P crosses the cut, or a vertex of P on it. So the proposals are the halves'
    vertices not tight on m and those of :func:`_on_the_cut`. Proposals only: the
    certification decides, and :func:`_attempt` asks qhull for P itself when the
    halves' proposal fails. None if qhull fails on a half or the halves' sections
    do not match."""
    from ._candidates import on_threads

    k, m = A.shape[1], len(A)
    cut = np.zeros(k)
    cut[axis] = 1.0
    shift = 0.5 * r * cut
    sides = ((np.vstack([A, cut]), np.append(b, x0[axis]), x0 - shift),
             (np.vstack([A, -cut]), np.append(b, -x0[axis]), x0 + shift))
    found: list = [None, None]

    def run(lo: int, hi: int) -> None:
        for side in range(lo, hi):
            found[side] = _qhull(*sides[side], options)
            if found[side] is None and options in MERGED_OPTIONS_5D:
                found[side] = _qhull(*sides[side], HALF_RETRY_OPTIONS)

    on_threads(run, 2, 2)
    if found[0] is None or found[1] is None:
        return None
    points: list[np.ndarray] = []
    facets: list[list[int]] = []
    cuts = []  # per half: its vertices on the cut (points) and their other rows
    for V, dual in found:
        on = [m in f for f in dual]
        for i, f in enumerate(dual):
            if not on[i]:
                points.append(V[i])
                facets.append(f)
        at = np.flatnonzero(on)
        cuts.append((V[at], [[h for h in dual[i] if h != m] for i in at.tolist()]))
    more = _on_the_cut(A, k, *cuts[0], *cuts[1])
    if more is None:
        return None
    for p, f in more:
        points.append(p)
        facets.append(f)
    if not facets:
        return None
    return np.array(points), facets


def _on_the_cut(A: np.ndarray, k: int, V0: np.ndarray, rows0: list[list[int]],
                V1: np.ndarray, rows1: list[list[int]]
                ) -> list[tuple[np.ndarray, list[int]]] | None:
    """The vertices of P among the two halves' vertices on the cut (points V0, V1 and
    their rows other than the cut): the halves share the section of P by the cut, so
    each point of one matches a point of the other (the nearest in the largest
    coordinate gap, within 10⁻⁹ of the coordinates: floats of two qhull runs) — else
    None. A matched pair whose rows (their union: a half sees only the rows of P that
    bound it near the point) have rank k in floats is a vertex of P on the cut, or
    near it where qhull merged it with the cut's vertices: proposed once; rank k − 1
    is an edge of P crossing the cut (k − 1 rows at a simple one; more, common, where
    the edge lies in several hyperplanes through data points, each solve of which
    would find no point)."""
    if len(V0) != len(V1):
        return None
    if not len(V0):
        return []
    from scipy.spatial import cKDTree

    tol = 1e-9 * (1.0 + max(np.abs(V0).max(), np.abs(V1).max()))
    # the largest coordinate gap: nothing squared, no overflow at any magnitude
    gap, match = cKDTree(V1).query(V0, p=np.inf)
    if not (gap <= tol).all() or len(np.unique(match)) != len(V0):
        return None
    out, seen = [], set()
    for i, j in enumerate(match.tolist()):
        rows = sorted(set(rows0[i]).union(rows1[j]))
        if len(rows) < k or tuple(rows) in seen:
            continue
        seen.add(tuple(rows))
        if np.linalg.matrix_rank(A[rows]) == k:
            out.append((V0[i], rows))
    return out


def certified_kernel(H, k: int, scale: int, first: np.ndarray) -> ExactPolytope | None:
    """Ψ in scaled integer coordinates as an ExactPolytope (constraints: the facets),
    or None when the fast path cannot certify it. ``scale``: the float unit of H (its
    floats are the integer coordinates / scale)."""
    if len(H) < k + 1:
        return None
    sel = np.asarray(first if len(first) >= k + 1 else np.arange(len(H)), dtype=np.int64)
    split = _Split()
    with _collections_spaced():
        for options in QHULL_OPTIONS:
            for opts in _chain(options, k):
                P = _attempt(H, k, scale, sel, opts, split)
                if P is not None:
                    return P
    return None


#: the cyclic collector's first threshold while the fast path runs
SPACED_THRESHOLD = 1_000_000
_spacing_lock = threading.Lock()
_spacing = {"depth": 0, "saved": (0, 0, 0)}


@contextlib.contextmanager
def _collections_spaced():
    """Python's cyclic garbage collector runs rarely while the fast path runs: its first
    threshold raised to SPACED_THRESHOLD (unless the caller's is 0 or higher), restored
    when the last fast path running in the process ends. The fast path allocates ~10⁵
    acyclic containers (vertex tuples, lists of rows), which set off collections of
    the whole heap: 5–25 % of the wall time of a d = 5, n = 30 kernel. Reference
    counting still frees everything. The collector's on/off switch is left alone (it
    was switched off: a ``gc.disable()`` another thread made meanwhile was undone,
    V38); a ``gc.set_threshold`` another thread makes during the call is overwritten
    at its end."""
    with _spacing_lock:
        if _spacing["depth"] == 0:
            _spacing["saved"] = gc.get_threshold()
            first, *rest = _spacing["saved"]
            if 0 < first < SPACED_THRESHOLD:
                gc.set_threshold(SPACED_THRESHOLD, *rest)
        _spacing["depth"] += 1
    try:
        yield
    finally:
        with _spacing_lock:
            _spacing["depth"] -= 1
            if _spacing["depth"] == 0:
                gc.set_threshold(*_spacing["saved"])


def _chain(options: str | None, k: int) -> tuple[str | None, ...]:
    """The qhull options tried in turn for an entry of QHULL_OPTIONS: the merged proposal
    (None) in k ≥ 5 is MERGED_OPTIONS_5D, each option in an attempt of its own — so
    qhull's default still runs when the first option's proposal fails the
    certification, not only when qhull fails; in k = 4 it is MERGED_OPTIONS_4D (the
    default's facets: no second attempt)."""
    if options is None and k >= 5:
        return MERGED_OPTIONS_5D
    return MERGED_OPTIONS_4D if options is None and k == 4 else (options,)


def _attempt(H, k: int, scale: int, sel: np.ndarray, options: str | None,
             split: _Split) -> ExactPolytope | None:
    """Proposals from qhull with ``options``, certified by :func:`_certify`; None on
    failure. If the certification fails, the halfspaces clearly violated by a proposed
    vertex (:func:`_row_max` of the float proposals) join ``sel`` for the next round;
    if none is, the next round's proposal comes from qhull on P itself if the refused
    one came from its halves (:func:`_halves`; ``split``, shared by the kernel's
    attempts, then turned off), else the attempt fails."""
    for _ in range(MAX_ROUNDS):
        prop = _propose(H, sel, options, split)
        if prop is None:
            return None
        V, facets = prop
        if any(len(f) < k for f in facets):
            return None
        P = _certify(H, k, scale, sel, facets, pieces=options == "QJ")
        if P is not None:
            return P
        bad = _row_max(H, V) > 1e-9 * (1.0 + np.abs(H.bf))
        if not bad.any():
            if not split.used:
                return None
            split.on = False  # the halves may have lost a vertex on their cut
        sel = np.union1d(sel, np.flatnonzero(bad))
    return None


def _row_max(H, V: np.ndarray) -> np.ndarray:
    """Per row h, an upper bound on max_v a_h·v − b_h over the float vertices V (the
    value itself where it may be ≥ 0): :func:`._candidates.row_top` — balls around
    chunks of nearby vertices bound the rows that pass far from them, only the
    chunks a row may reach are evaluated vertex by vertex."""
    from ._candidates import row_top

    return row_top(H.af, H.bf, V, H.floor())


def _certify(H, k: int, scale: int, sel: np.ndarray, facets: list[list[int]],
             pieces: bool = False) -> ExactPolytope | None:
    """Exact vertices from the proposed defining sets (merged when equal), their full
    tight sets among the defining halfspaces S, feasibility against every valid
    halfspace, and closure: every extreme ray of every vertex's tangent cone leads to
    another proposed vertex (see the module docstring). ``pieces``: the proposals are
    simplicial pieces (joggled qhull), several per non-simple vertex — one per point
    is solved (:func:`_one_per_point`). The rows of S are decided against every vertex
    before the closure; the others after it, by walks on the graph it proves
    (:func:`_outside_feasible`)."""
    sizes = np.fromiter(map(len, facets), dtype=np.int64, count=len(facets))
    flat = sel[np.fromiter(itertools.chain.from_iterable(facets), dtype=np.int64,
                           count=int(sizes.sum()))]
    S = np.flatnonzero(np.bincount(flat)).astype(np.int64)  # the distinct rows, sorted
    S_set = S.tolist()
    H.exact_all(S_set)
    at_S = _positions(S)
    Ts = _basis_array(H, flat, sizes, k)  # (proposals, k): rows of H
    solved = _one_per_point(H, Ts, k) if pieces else np.arange(len(Ts))
    # the proposals' points (exact, solved when read) and their correctly rounded
    # floats y / (w · unit): the floats of the vertices, and the key on which equal
    # points are merged
    found = _proposed_points(H, Ts, np.asarray(solved, dtype=np.int64), S, k, scale)
    if found is None:
        return None
    W, Vx, kept = found
    of_proposal, firsts = _distinct_points(W, Vx)
    W, Vx = W.select(firsts), Vx[firsts]
    verts = W
    T_kept = Ts[kept]
    # per vertex: k independent rows tight at it (positions in S), its first proposal's
    basis = at_S[T_kept[firsts]].tolist()
    # (vertex, position in S) of the rows tight by construction; more are found below
    tight_v = [np.repeat(of_proposal, k)]
    tight_h = [at_S[T_kept].ravel()]
    # h · len(facets) + i: row h tight at vertex i by construction
    known = np.sort((T_kept * len(facets) + of_proposal[:, None]).ravel())
    # exact feasibility, and the complete tight sets within S: floats of the exact
    # vertices (correctly rounded, int / int) with a rounding bound, plus the underflow
    # term, decide the clear cases; inf or NaN is never "clear"
    c = 2.0 * (k + 4) * _EPS
    M = np.abs(Vx).max()
    floor = H.floor()
    l1, perm_sum, babs = H.row_terms()
    coarse = H.c_err * (perm_sum * M + H.b_abs) + c * (l1 * M + babs) + floor
    # the defining rows' pairs: feasibility and the complete tight sets within S
    on_S = _decided_pairs(H, scale, verts, W, T_kept[firsts], S, Vx, coarse[S], c, floor,
                          known, len(facets), k)
    if on_S is None:
        return None
    tight_v.append(on_S[1])
    tight_h.append(at_S[on_S[0]])
    tight, pairs = _tight_sets(np.concatenate(tight_v), np.concatenate(tight_h), len(verts),
                               len(S))
    normals = [H.exact(h)[0] for h in S_set]
    edges = _closed(tight, basis, normals, k,
                    lambda bases: _simplicial_rays(H, S_set, normals, bases, k), pairs)
    if edges is None:
        return None
    if not _outside_feasible(H, scale, verts, W, T_kept[firsts], S, Vx, coarse, c, floor,
                             edges, k):
        return None
    P = ExactPolytope(k, unit=scale)
    for h in S_set:
        a, b = H.exact(h)
        P.a.append(a)
        P.b.append(b)
    P.verts = verts
    P.tight = tight
    P.pairs = pairs
    P.edges = edges
    P._fv = Vx
    return P


def _positions(S: np.ndarray) -> np.ndarray:
    """The table of positions in the sorted distinct rows S: table[S[i]] = i (what
    np.searchsorted(S, h) gives for h in S, by one lookup instead of a binary search —
    tens of thousands of tight rows per d = 5 kernel)."""
    table = np.zeros(int(S[-1]) + 1 if len(S) else 0, dtype=np.int64)
    table[S] = np.arange(len(S))
    return table


def _proposed_points(H, Ts: np.ndarray, solved: np.ndarray, S: np.ndarray, k: int,
                     scale: int) -> tuple[LazyVertices, np.ndarray, np.ndarray] | None:
    """The points of the proposals ``solved`` (rows Ts[solved], all in S) that are single
    points: their exact homogeneous (w, y) as a :class:`._lazy_vertices.LazyVertices`
    (each solved by :func:`_solve_rows` when first read), their correctly rounded
    floats y / (w · scale) and the proposals kept; None if none is a point.

    The floats are proven correctly rounded without the exact solve where
    :func:`._vertex_floats.rounded_points` can (it also proves det A_T ≠ 0: such a
    proposal is a point); the others are solved now, as before: their floats are
    int / int, and x_0 = 0 (k dependent rows: a zero-volume piece of a triangulated
    non-simple vertex) leaves the proposal out — the other proposals or the closure
    decide. Correct rounding is a function of the point, so the floats are those the
    exact vertices give, and the exact vertices, solved from the same rows by the same
    code, are those the eager solve gave."""
    from ._vertex_floats import rounded_points  # looked up per call: tests replace it

    T = Ts[solved]
    if not len(T):
        return None
    _, at, E = _row_table(H, T, k)
    Vx, met = rounded_points(E, at, scale, k)
    late = np.flatnonzero(~met)
    rows_late: list = []
    if len(late):
        X = _solve_rows(H, T[late], k)
        point = X[:, 0] != 0
        late, X = late[point], X[point]
        met[late] = True
        if len(late):
            Vx[late] = (X[:, 1:] / (X[:, :1] * scale)).astype(np.float64)
            rows_late = X.tolist()
    kept = np.flatnonzero(met)
    if not len(kept):
        return None
    position = np.cumsum(met) - 1  # a kept proposal's index among the kept
    known = {int(position[j]): tuple(row)
             for j, row in zip(late.tolist(), rows_late, strict=True)}
    Sl = S.tolist()
    ab = [H.exact(h) for h in Sl]
    rows = RowsOf([a for a, _ in ab], [b for _, b in ab], H.through[S], H.Yi)
    W = LazyVertices(rows, _positions(S)[T[kept]], k, known)
    return W, Vx[kept], solved[kept]


def _decided_pairs(H, scale: int, verts: list[tuple[int, ...]], W: np.ndarray,
                   basis: np.ndarray, rows: np.ndarray, Vx: np.ndarray, coarse: np.ndarray,
                   c: float, floor: float, known: np.ndarray, n_props: int, k: int
                   ) -> tuple[np.ndarray, np.ndarray] | None:
    """The pairs (row of H, vertex) among ``rows`` × the vertices (homogeneous W, floats
    Vx; ``basis``: per vertex k rows tight by construction) whose row passes through the
    vertex, beyond those tight by construction (``known``: h · n_props + vertex, sorted),
    or None if a row cuts a vertex: floats with a rounding bound decide the clear pairs
    (:func:`_near_pairs`; ``coarse``: per row the bound for every vertex), the rest by
    data points on the row (:func:`_tight_through`) or on the integers."""
    near = _near_pairs(H, rows, Vx, coarse, c, floor)
    if near is None:
        return None
    near_r, near_v = near
    # not tight by construction
    pair = rows[near_r] * n_props + near_v
    if len(known):
        fresh = known[np.minimum(np.searchsorted(known, pair), len(known) - 1)] != pair
        near_r, near_v = near_r[fresh], near_v[fresh]
    hs = rows[near_r]
    # the pairs whose row provably passes through the vertex (a flat of data points on
    # the row holds it: :func:`._certify_nb.tight_through`) are tight; the others are
    # decided on the integers
    on = _tight_through(H, basis, hs, near_v, k)
    rest = np.flatnonzero(~on)
    Wr = W[near_v[rest]]  # the exact vertices of these pairs (solved now if lazy)
    slacks = _int64_slacks(H, scale, Wr, hs[rest])
    if slacks is None:  # in Python integers: a·y − b·w, all pairs at once
        used, at = np.unique(hs[rest], return_inverse=True)
        H.exact_all(used.tolist())
        E = _homogeneous(H, used.tolist(), k)[at.ravel()]  # (−b, a), each row built once
        slacks = (E * Wr).sum(axis=1) if len(rest) else np.zeros(0, dtype=object)
    if (slacks > 0).any():
        return None
    on[rest] = slacks == 0
    return hs[on], near_v[on]


def _outside_feasible(H, scale: int, verts: list[tuple[int, ...]], W: np.ndarray,
                      basis: np.ndarray, S: np.ndarray, Vx: np.ndarray, coarse: np.ndarray,
                      c: float, floor: float, edges: list[list[int]], k: int) -> bool:
    """Every valid row outside S holds at every vertex, given P_S = conv(V) with the
    complete graph ``edges`` (proven by the closure): each row's maximum over V by a
    walk on the graph (:func:`._candidates.graph_top`: a vertex no neighbour of which
    is above it is the maximum), and the rows it leaves open (not proven slack
    everywhere) by :func:`_decided_pairs`."""
    from ._candidates import graph_top

    out = np.ones(len(H), dtype=np.bool_)
    out[S] = False
    rows = np.flatnonzero(out)
    if not len(rows):
        return True
    sizes = np.fromiter(map(len, edges), dtype=np.int64, count=len(edges))
    ptr = np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64)
    nbr = np.fromiter(itertools.chain.from_iterable(edges), dtype=np.int64,
                      count=int(ptr[-1]))
    top = graph_top(H.af[rows], H.bf[rows], H.af_abs[rows], H.b_abs[rows], Vx, ptr, nbr,
                    H.c_err, c, floor)
    rows = rows[~(top < -coarse[rows])]
    if not len(rows):
        return True
    return _decided_pairs(H, scale, verts, W, basis, rows, Vx, coarse[rows], c, floor,
                          np.zeros(0, dtype=np.int64), 1, k) is not None


def _tight_sets(vs: np.ndarray, hs: np.ndarray, n: int, width: int
                ) -> tuple[list[int], tuple[np.ndarray, np.ndarray]]:
    """For each of n vertices the bitset (a Python int) of the positions hs[i] < width
    paired with it (vs[i]): the bitsets packed to bytes
    (:func:`._certify_nb.packed_pairs`), one int per vertex; and the distinct pairs
    (vertex, position) ordered by vertex then position, read off the packed bytes
    (what :func:`.polytope.tight_pairs` gives for the bitsets)."""
    from ._certify_nb import packed_pairs

    nbytes = max((width + 7) // 8, 1)
    packed, pv, ph = packed_pairs(np.asarray(vs, dtype=np.int64),
                                  np.asarray(hs, dtype=np.int64), n, nbytes)
    buf = packed.tobytes()
    tight = [int.from_bytes(buf[i:i + nbytes], "little") for i in range(0, n * nbytes, nbytes)]
    return tight, (pv, ph)


def _closed(tight: list[int], basis: list[list[int]], normals: list[tuple[int, ...]],
            k: int, start_rays, pairs: tuple[np.ndarray, np.ndarray] | None = None
            ) -> list[list[int]] | None:
    """The edges of P_S — for each vertex, its neighbours, increasing — if every extreme
    ray of every vertex's tangent cone leads to another vertex, else None. The rows Z
    tight along a ray have rank k − 1, so a vertex u ≠ v lies on the ray's line iff
    Z ⊆ tight[u], and then it is the other end of the edge (the line meets P_S in that
    edge). Every vertex is settled from the tight sets where
    :func:`._closure.combinatorial_rays` concludes. It looks at every vertex holding
    k − 1 of a simple vertex's k (independent) rows, so a simple vertex it does not
    settle has a ray that leads nowhere. A non-simple one's rays then come from
    :func:`_tangent_rays`, their ends through the (k − 1)-subsets of the tight sets
    (:class:`_RayIndex`). ``start_rays``: for a list of bases, their simplicial cones'
    rays (:func:`_simplicial_rays`), where the double descriptions start. ``pairs``:
    :func:`.polytope.tight_pairs` of ``tight`` when known."""
    from ._closure import combinatorial_rays

    settled, edges = combinatorial_rays(tight, normals, k, pairs)
    rest = np.flatnonzero(~settled).tolist()
    if not rest:
        return edges
    if any(tight[vi].bit_count() <= k for vi in rest):
        return None
    starts = start_rays([basis[vi] for vi in rest])
    ray_v: list[int] = []
    ray_z: list[int] = []
    for vi, start in zip(rest, starts, strict=True):
        for Z in _tangent_rays(normals, basis[vi], list(_bits(tight[vi])), k, start):
            ray_v.append(vi)
            ray_z.append(Z)
    ends = _RayIndex(tight, basis, len(normals), k).other_ends(ray_v, ray_z)
    if ends is None:
        return None
    found: dict[int, set[int]] = {vi: set() for vi in rest}
    for vi, u in zip(ray_v, ends, strict=True):
        found[vi].add(u)
    for vi, us in found.items():
        edges[vi] = sorted(us)
    return edges


class _RayIndex:
    """The vertices by the (k − 1)-subsets of their tight sets (of at most MAX_TIGHT
    rows), each subset a key: its positions p₁ < … < p_{k−1} in base |S| (int64 when
    it fits — sorted, so the vertices sharing a key are a run). A simple vertex's
    tight set is its basis (``simple_rows``, sorted)."""

    def __init__(self, tight: list[int], basis: list[list[int]], n_rows: int, k: int
                 ) -> None:
        self.tight, self.k = tight, k
        self._members: dict[int, list[int]] | None = None
        counts = np.array([t.bit_count() for t in tight], dtype=np.int64)
        self.simple = np.flatnonzero(counts == k)
        self.non_simple = np.flatnonzero(counts > k).tolist()
        self.simple_rows = np.sort(np.array([basis[vi] for vi in self.simple.tolist()],
                                            dtype=np.int64).reshape(-1, k), axis=1)
        wide = np.int64 if n_rows ** (k - 1) < 2**62 else object  # the keys fit int64?
        self.W = np.array([n_rows**i for i in range(k - 1)], dtype=wide)
        keys, owners = [], []
        groups = [(self.simple, self.simple_rows)]
        keyed = [vi for vi in self.non_simple if counts[vi] <= MAX_TIGHT]
        rows = tight_pairs([tight[vi] for vi in keyed])[1]  # by vertex, increasing
        starts = np.concatenate([[0], np.cumsum(counts[keyed])]).astype(np.int64)
        for t in range(k + 1, MAX_TIGHT + 1):  # the non-simple ones, by their size t
            at = np.flatnonzero(counts[keyed] == t)
            if len(at):
                groups.append((np.asarray(keyed, dtype=np.int64)[at],
                               rows[starts[at][:, None] + np.arange(t)]))
        for vs, rows in groups:
            combos = np.array(list(itertools.combinations(range(rows.shape[1]), k - 1)),
                              dtype=np.int64)
            keys.append((rows[:, combos] @ self.W).ravel())
            owners.append(np.repeat(vs, len(combos)))
        K = np.concatenate(keys)
        order = np.argsort(K, kind="stable")
        self.keys, self.owners = K[order], np.concatenate(owners)[order]

    def other_ends(self, ray_v: list[int], ray_z: list[int]) -> list[int] | None:
        """For each ray (vertex v, tight rows Z), a vertex u ≠ v with Z ⊆ tight[u]: among
        those registered under the key of Z's first k − 1 rows (every u with Z ⊆ tight[u]
        and at most MAX_TIGHT rows is), else by :meth:`_scan`; None if one has none."""
        if not ray_v:
            return []
        _, rows = tight_pairs(ray_z)  # by ray, increasing: each ray's first k − 1
        counts = np.array([Z.bit_count() for Z in ray_z], dtype=np.int64)
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        K = rows[starts[:, None] + np.arange(self.k - 1)] @ self.W
        # Z of k − 1 rows is its key: every owner of the key holds Z
        out = np.where(counts == self.k - 1,
                       self._other_owner(K, np.asarray(ray_v, dtype=np.int64)), -1).tolist()
        lo = np.searchsorted(self.keys, K, side="left").tolist()
        hi = np.searchsorted(self.keys, K, side="right").tolist()
        owners, tight = self.owners.tolist(), self.tight
        for i in (i for i, u in enumerate(out) if u < 0):
            v, Z = ray_v[i], ray_z[i]
            u = next((u for u in owners[lo[i]:hi[i]] if u != v and tight[u] & Z == Z), None)
            if u is None:
                u = self._scan(v, Z)
                if u is None:
                    return None
            out[i] = u
        return out

    def _other_owner(self, K: np.ndarray, own: np.ndarray) -> np.ndarray:
        """For each key of K, a vertex registered under it other than ``own`` (which
        broadcasts against K), or −1 if there is none: the first of its run, else the
        second."""
        if not len(self.owners):  # every vertex has > MAX_TIGHT rows: none registered
            return np.full(np.broadcast(K, own).shape, -1, dtype=np.int64)
        lo = np.searchsorted(self.keys, K, side="left")
        hi = np.searchsorted(self.keys, K, side="right")
        last = len(self.owners) - 1
        first = self.owners[np.minimum(lo, last)]
        second = self.owners[np.minimum(lo + 1, last)]
        return np.where((hi > lo) & (first != own), first,
                        np.where(hi - lo >= 2, second, -1))

    def _scan(self, vi: int, Z: int) -> int | None:
        """A vertex u ≠ vi with Z ⊆ tight[u] among those on Z's rarest row."""
        fewest = min((self._on(h) for h in _bits(Z)), key=len)
        return next((u for u in fewest if u != vi and (self.tight[u] & Z) == Z), None)

    def _on(self, h: int) -> list[int]:
        """The vertices tight on row h (all rows' lists built on first use)."""
        if self._members is None:
            self._members = members_of(self.tight)
        return self._members[h]


def _near_pairs(H, rows: np.ndarray, Vx: np.ndarray, coarse: np.ndarray, c: float,
                floor: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The pairs (index into rows, vertex) whose float slack s = a·v − b is within its
    rounding bound of 0 — to be decided exactly — or None if some s is surely > 0.

    The bound of a pair is c_err (|a|_perm·|v| + b_abs) + c (|a|·|v| + |b|) + floor;
    ``coarse`` bounds it per row for every vertex (|v| ≤ max |V|), so only the pairs with
    |s| ≤ coarse get their own bound (:func:`._candidates.near_pairs`, which skips the
    chunks of vertices a row surely passes by)."""
    from ._candidates import near_pairs

    return near_pairs(H.af[rows], H.bf[rows], H.af_abs[rows], H.b_abs[rows], Vx, coarse,
                      H.c_err, c, floor)


def _tight_through(H, basis: np.ndarray, hs: np.ndarray, vs: np.ndarray, k: int) -> np.ndarray:
    """For each pair (hs[i], vs[i]), True where row hs[i] provably passes through vertex
    vs[i] by the data points of the rows alone (:func:`._certify_nb.tight_through`;
    ``basis``: per vertex its k independent rows tight by construction, as rows of H);
    False where that proves nothing (and for k² > 62)."""
    if k * k > 62 or not len(hs):
        return np.zeros(len(hs), dtype=np.bool_)
    from ._certify_nb import tight_through

    return tight_through(np.ascontiguousarray(H.through, dtype=np.int64), basis,
                         np.asarray(hs, dtype=np.int64), np.asarray(vs, dtype=np.int64))


def _int64_slacks(H, scale: int, V: np.ndarray, hs: np.ndarray) -> np.ndarray | None:
    """a_h·y − b_h·w for the pairs (hs[i], V[i]) (V: the vertices (w, y), an object
    array) in int64 — when the float normals are exact integers (integer data, exact
    float arithmetic: c_err = 0, scale 1) and every term provably fits — else None (the
    caller works in Python integers)."""
    if H.c_err != 0.0 or scale != 1 or not len(hs):
        return None
    A, b = H.af[hs], H.bf[hs]
    if not (np.all(A == np.round(A)) and np.all(b == np.round(b))):
        return None
    top = max(abs(c) for v in V.tolist() for c in v)
    reach = (np.abs(A).sum(axis=1).max() + np.abs(b).max()) * float(top)
    if not reach < 2.0**62:
        return None
    V = V.astype(np.int64)
    return (A.astype(np.int64) * V[:, 1:]).sum(axis=1) - b.astype(np.int64) * V[:, 0]


def _basis_array(H, flat: np.ndarray, sizes: np.ndarray, k: int) -> np.ndarray:
    """For each proposal's rows T (``flat``: the proposals' rows one after another,
    ``sizes``: how many each, all ≥ k), k of them that floats suggest are independent,
    an int64 array (proposals, k): T itself when it has k rows; else the rows a merged
    (non-simple) proposal is solved from, by QR with column pivoting of their unit
    normals (at each step the row of largest norm once the chosen ones are projected
    out), all proposals of one size at once. Only these k are tight by construction;
    the others are decided exactly later."""
    starts = np.cumsum(sizes) - sizes
    out = np.empty((len(sizes), k), dtype=np.int64)
    simple = sizes == k
    out[simple] = flat[starts[simple][:, None] + np.arange(k)]
    for t in np.unique(sizes[~simple]).tolist():
        ps = np.flatnonzero(sizes == t)
        T = flat[starts[ps][:, None] + np.arange(t)]  # (m, t)
        R = H.af[T]  # (m, t, k)
        R = R / np.linalg.norm(R, axis=2)[:, :, None]
        m = np.arange(len(ps))
        chosen = np.empty((len(ps), k), dtype=np.int64)
        for j in range(k):
            norms = (R * R).sum(axis=2)
            c = chosen[:, j] = norms.argmax(axis=1)
            q = R[m, c] / np.sqrt(norms[m, c])[:, None]
            R = R - (R @ q[:, :, None]) * q[:, None, :]
            R[m, c] = 0.0
        out[ps] = np.take_along_axis(T, chosen, axis=1)
    return out


def _row_table(H, Ts: list[list[int]], k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The lists Ts of k rows as an int64 array B, the homogeneous rows E of the distinct
    rows in B (:func:`_homogeneous`, the row at infinity last) and the position in E of
    each entry of B."""
    B = np.asarray(Ts, dtype=np.int64).reshape(len(Ts), k)
    # np.unique(B, return_inverse=True) by a table over the rows of H (no sort)
    used = np.flatnonzero(np.bincount(B.ravel()))
    return B, _positions(used)[B], _homogeneous(H, used.tolist(), k)


def _one_per_point(H, Ts: list[list[int]], k: int) -> np.ndarray:
    """The proposals to solve exactly, increasing: the first of those sharing a modular
    key (:func:`._certify_nb.point_keys`: the joggled pieces of one non-simple vertex
    share it) and every proposal without one. Dropping the others is sound: a point
    lost to a key shared by chance is a vertex missed, which the closure check
    refuses (module docstring)."""
    from ._certify_nb import KEY_PRIME, point_keys

    if not len(Ts):
        return np.zeros(0, dtype=np.int64)
    _, at, E = _row_table(H, Ts, k)
    residues = np.array([[v % KEY_PRIME for v in e] for e in E[:-1].tolist()], dtype=np.int64)
    keys = np.zeros((len(Ts), k), dtype=np.int64)
    ok = point_keys(residues, at, keys)
    first = np.flatnonzero(ok)[np.unique(keys[ok], axis=0, return_index=True)[1]]
    return np.sort(np.concatenate([first, np.flatnonzero(~ok)]))


def _solve_all(H, Ts: list[list[int]], k: int) -> list[tuple[int, ...] | None]:
    """For each list T of k rows, the point where their hyperplanes meet, homogeneous
    (w, y) with w > 0 and primitive, or None if they do not meet in one point: the rows
    of :func:`_solve_rows` divided by their gcd (the fast path itself reads them as
    they come)."""
    out: list[tuple[int, ...] | None] = []
    for row in _solve_rows(H, Ts, k).tolist():
        g = gcd(*row)
        out.append(tuple(v // g for v in row) if row[0] else None)
    return out


def _solve_rows(H, Ts: list[list[int]], k: int) -> np.ndarray:
    """For each list T of k rows, a nonzero homogeneous (w, y) spanning the null space
    of the k × (k+1) integer matrix E_T with rows e_h = (−b_h, a_h), with w > 0 if the
    rows meet in one point y / w, else w = 0; an object array (len(Ts), k + 1) of
    Python ints, not reduced by their gcd (its readers do not need it: a point's
    Fraction, its correctly rounded float, the signs of slacks and :func:`_same_point`
    are the same for every positive multiple).

    The rows are hyperplanes through data points, and :func:`_meet` solves through
    them, on far smaller integers than the cross product of E_T (whose minors share
    factors of a third to two thirds of their bits): when det A_T ≠ 0 — shown modulo a
    prime (:func:`._certify_nb.nonsingular`, compiled; :func:`_det_mod` is its numpy
    reference; a multiple of the prime, ~2^-31 of bases, is left to the cross product
    of E_T, which is exact either way) — the null space is the line of
    the vertex, and any nonzero x with E_T x = 0 spans it. Where det A_T = 0 the cross
    product of E_T has x_0 = ±det A_T = 0."""
    X = np.empty((len(Ts), k + 1), dtype=object)
    if not len(Ts):
        return X
    from ._certify_nb import nonsingular

    B, at, E = _row_table(H, Ts, k)
    A = np.array([[v % PRIME for v in a] for a in E[:-1, 1:].tolist()], dtype=np.int64)
    sure = nonsingular(A.reshape(-1, k), at, PRIME)
    if sure.any():
        X[sure] = _meet(H, E, B[sure], at[sure], k)
    if not sure.all():  # the cross product of E_T: x_0 = ±det A_T (0: no single point)
        X[~sure] = cross_all(E[at[~sure]])
    flip = X[:, 0] < 0
    if flip.any():
        X[flip] = -X[flip]
    return X


def _distinct_points(W: np.ndarray, Vx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct points among the homogeneous rows W (w > 0), numbered in order of
    first appearance: for each row its point's number, and for each point its first
    row. ``Vx``: the rows' correctly rounded floats y / (w · unit) — a function of the
    point alone, so equal points have bit-identical floats and the floats are a key;
    rows sharing a key are compared exactly (:func:`_same_point`), and where two
    distinct points share one (closer than the floats resolve) the rows are grouped
    one by one."""
    n, width = Vx.shape
    keys = np.ascontiguousarray(Vx).view(np.dtype((np.void, 8 * width))).ravel()
    _, first, inverse = np.unique(keys, return_index=True, return_inverse=True)
    by_first = np.argsort(first)
    number = np.empty(len(first), dtype=np.int64)
    number[by_first] = np.arange(len(first))
    of_row, firsts = number[inverse.ravel()], first[by_first]
    shared = np.flatnonzero(firsts[of_row] != np.arange(n))
    if all(_same_point(u, v) for u, v in zip(W[shared].tolist(),
                                             W[firsts[of_row[shared]]].tolist(), strict=True)):
        return of_row, firsts
    rows = W.tolist()
    found: dict[bytes, list[int]] = {}  # key → the points (first rows) holding it
    of_list: list[int] = []
    first_list: list[int] = []
    for i, row in enumerate(rows):
        points = found.setdefault(keys[i].tobytes(), [])
        j = next((j for j in points if _same_point(row, rows[first_list[j]])), None)
        if j is None:
            j = len(first_list)
            first_list.append(i)
            points.append(j)
        of_list.append(j)
    return np.array(of_list, dtype=np.int64), np.array(first_list, dtype=np.int64)


def _same_point(u: list[int], v: list[int]) -> bool:
    """(w, y) and (w', y') (w, w' > 0) are the same point y / w = y' / w'."""
    return all(a * v[0] == b * u[0] for a, b in zip(u[1:], v[1:], strict=True))


def _det_mod(A: np.ndarray, p: int) -> np.ndarray:
    """det A[i] mod p for the (P, m, m) int64 residues A (entries in [0, p)), by
    Laplace expansion along the rows (the minors of the first r rows on every r-set of
    columns), reduced after every product."""
    m = A.shape[1]
    minors = {(c,): A[:, 0, c] for c in range(m)}
    for r in range(1, m):
        nxt = {}
        for cols in itertools.combinations(range(m), r + 1):
            acc = np.zeros(len(A), dtype=np.int64)
            for i, c in enumerate(cols):
                term = A[:, r, c] * minors[cols[:i] + cols[i + 1:]] % p
                acc = acc + term if (r + i) % 2 == 0 else acc - term
            nxt[cols] = acc % p
        minors = nxt
    return minors[tuple(range(m))]


def _homogeneous(H, hs: list[int], k: int) -> np.ndarray:
    """The rows e_h = (−b_h, a_h) of the halfspaces hs, then the row at infinity
    (1, 0, …, 0) (x_0 = 0: a direction), as an object array (len(hs) + 1, k + 1)."""
    return _object_rows([*((-b, *a) for a, b in map(H.exact, hs)), (1, *[0] * k)], k + 1)


def _meet(H, E: np.ndarray, R: np.ndarray, at: np.ndarray, k: int,
          direction: bool = False) -> np.ndarray:
    """For each row set R[i] (k rows with det A ≠ 0; or, with ``direction``, k − 1 of
    such a basis and the row at infinity, the last of E; ``at``: R's positions in E),
    a nonzero homogeneous x = (x_0, y) with e_h·x = 0 for those rows, through the data
    points (with ``direction``: x_0 = 0 and y the null direction of the k − 1 normals).

    Take a group G of the rows whose hyperplanes share a set Q of k − |G| + 1 data
    points (two rows through k − 1 common points; else G one row, Q its k points):
    the points of Q are affinely independent, so flat(Q) (projective: its points at
    infinity too) has dimension k − |G|, the dimension of ⋂_G H_h (independent rows),
    and flat(Q) ⊆ ⋂_G H_h: they are equal and hold the answer. So x = Σ_{q ∈ Q} λ_q
    (1, q) with M λ = 0 for the other rows, M_{hq} = e_h·(1, q) (brackets of k + 1
    data points; 1 for the row at infinity): λ is the cross product of M
    (:func:`.exact.cross_all`), nonzero as M has full rank (the rows, the one at
    infinity included, are independent, so x spans their null space)."""
    from ._certify_nb import paired_rows

    r = R.shape[1]
    pts = np.ascontiguousarray(H.through[R], dtype=np.int64)  # (P, r, k): the rows' points
    pairs = list(itertools.combinations(range(r), 2))
    group = paired_rows(pts, k)
    L = _object_rows([(1, *y) for y in H.Yi], k + 1)
    X = np.empty((len(R), k + 1), dtype=object)
    extra = np.full((len(R), int(direction)), len(E) - 1)  # the row at infinity
    paired = group >= 0
    if paired.any():
        g = group[paired]
        ij = np.array(pairs, dtype=np.int64)[g]
        rest = np.array([[c for c in range(r) if c not in pair] for pair in pairs],
                        dtype=np.int64).reshape(len(pairs), r - 2)[g]
        first = pts[paired, ij[:, 0]]  # (P', k)
        inside = (first[:, :, None] == pts[paired, ij[:, 1]][:, None, :]).any(axis=2)
        Q = first[inside].reshape(-1, k - 1)
        others = np.hstack([np.take_along_axis(at[paired], rest, axis=1), extra[paired]])
        X[paired] = _through(E, L, others, Q)
    if not paired.all():
        X[~paired] = _through(E, L, np.hstack([at[~paired, 1:], extra[~paired]]),
                              pts[~paired, 0])
    return X


def _through(E: np.ndarray, L: np.ndarray, others: np.ndarray, Q: np.ndarray) -> np.ndarray:
    """x = Σ_q λ_q L[q] over the points Q[i] with λ the cross product of M_{hq} =
    E[h]·L[q], h ∈ others[i] (:func:`_meet`); x = L[q] when no other row is left."""
    Lq = L[Q]  # (P, r + 1, k + 1)
    if others.shape[1] == 0:
        return Lq[:, 0]
    # M (P, r, r + 1): each bracket once (neighbouring vertices share most of them),
    # e_h·(1, q) = e_h0 + Σ_j e_hj q_j
    pairs, where = np.unique(others[:, :, None] * len(L) + Q[:, None, :],
                             return_inverse=True)
    Eh, Lp = E[pairs // len(L)], L[pairs % len(L)]
    brackets = Eh[:, 0] + (Eh[:, 1:] * Lp[:, 1:]).sum(axis=1)
    lam = cross_all(brackets[where].reshape(*others.shape, Q.shape[1]))
    x = np.empty((len(Q), L.shape[1]), dtype=object)  # Σ_q λ_q (1, q)
    x[:, 0] = lam.sum(axis=1)
    x[:, 1:] = np.matmul(lam[:, None, :], Lq[:, :, 1:])[:, 0]
    return x


def _object_rows(rows: list[tuple[int, ...]], width: int) -> np.ndarray:
    """Rows of Python ints as an object array (len(rows), width) — never a fixed-width
    integer array, whatever the values' size."""
    E = np.empty((len(rows), width), dtype=object)
    E[:] = rows
    return E


def _simplicial_rays(H, S_set: list[int], normals: list[tuple[int, ...]],
                     bases: list[list[int]], k: int) -> list[list[tuple[int, ...]]]:
    """For each basis B (k independent rows, positions in S_set), the extreme rays of
    {d : a_h·d ≤ 0, h ∈ B}: for each h ∈ B the null direction of B − {h}
    (:func:`_meet` with the row at infinity), signed so that a_h·d < 0."""
    if not bases:
        return []
    rows = [[g for g in B if g != h] for B in bases for h in B]
    used, at = np.unique(np.array(rows, dtype=np.int64), return_inverse=True)
    S = np.asarray(S_set, dtype=np.int64)
    E = _homogeneous(H, S[used].tolist(), k)
    D = _meet(H, E, S[used][at.reshape(len(rows), k - 1)], at.reshape(len(rows), k - 1), k,
              direction=True)[:, 1:]
    up = (_object_rows([normals[h] for B in bases for h in B], k) * D).sum(axis=1) > 0
    D = list(map(tuple, np.where(up[:, None], -D, D).tolist()))
    return [D[p:p + k] for p in range(0, len(D), k)]


def _tangent_rays(normals: list[tuple[int, ...]], basis: list[int], T: list[int], k: int,
                  start: list[tuple[int, ...]]):
    """For the pointed cone C = {d : a_h·d ≤ 0, h ∈ T} (``basis``: k independent rows of
    T), the bitset of the rows of T tight along each extreme ray, by the
    double-description method on integers: start from the simplicial cone of the basis
    (its rays ``start``, one per basis row: :func:`_simplicial_rays`), then
    cut by each further row h, keeping the rays with a_h·d ≤ 0 and adding
    s_p·q − s_q·p for every adjacent pair with s_p = a_h·p > 0 > s_q = a_h·q. Two
    extreme rays are adjacent iff no third ray is tight on every row tight on both (the
    combinatorial test, exact for degenerate cones)."""
    # (direction, tight rows as a bitset); the last cut needs no new directions
    rays = [(d, sum(1 << g for g in basis if g != h)) for h, d in zip(basis, start, strict=True)]
    cuts = [h for h in T if h not in basis]
    for c, h in enumerate(cuts):
        s = [_dot(normals[h], d) for d, _ in rays]
        zs = [z for _, z in rays]
        minus = [q for q, sq in enumerate(s) if sq < 0]
        new = []
        for p in (p for p, sp in enumerate(s) if sp > 0):
            for q in minus:
                common = zs[p] & zs[q]
                if common.bit_count() < k - 2 or not _adjacent(zs, common):
                    continue
                d = None if c == len(cuts) - 1 else _combined(s[p], rays[q][0], s[q],
                                                              rays[p][0])
                new.append((d, common | 1 << h))
        rays = [(d, z | (1 << h if v == 0 else 0)) for (d, z), v in zip(rays, s, strict=True)
                if v <= 0] + new
    return [z for _, z in rays]


def _adjacent(zs: list[int], common: int) -> bool:
    """Two rays tight on the rows ``common`` (both among zs) are adjacent: no third ray
    of zs is tight on all of them."""
    count = 0
    for z in zs:
        if z & common == common:
            count += 1
            if count > 2:
                return False
    return True


def _combined(sp: int, q: tuple[int, ...], sq: int, p: tuple[int, ...]) -> tuple[int, ...]:
    """The primitive direction of sp·q − sq·p (sp > 0 > sq: on the cut's hyperplane),
    its multipliers divided by their gcd first (smaller products)."""
    g = gcd(sp, sq)
    sp, sq = sp // g, sq // g
    return _primitive_direction(tuple(sp * x - sq * y for x, y in zip(q, p, strict=True)))


def _dot(a: tuple[int, ...], d: tuple[int, ...]) -> int:
    return sum(map(operator.mul, a, d))


def _primitive_direction(d: tuple[int, ...]) -> tuple[int, ...]:
    g = gcd(*d)
    return tuple(v // g for v in d) if g > 1 else d
