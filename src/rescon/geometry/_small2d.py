"""numba batch path for many small planar kernels: exact decisions, float geometry.

For each point set Y (m points in the plane) and F, the point of Ψ(Y, F) closest to
mean(Y) is computed in floats, but every combinatorial decision — which side of a
candidate line a point lies on, which polygon vertices a halfplane cuts, which edge
or vertex is nearest — is taken only when a rounding-error bound proves it; otherwise
the problem is flagged and the caller computes it exactly (:mod:`.kernel`). So the
answer has the exact combinatorics and differs from the exact point only by the
tracked geometric error (returned per problem, typically ~1e-15 of the data scale).

Error bookkeeping: every float vertex v carries e_v ≥ ‖v − v_exact‖_∞. A value
a·v − c (a, c from the data, with their own rounding bounds) is decided when its
magnitude exceeds |a|_1 e_v + its rounding bound; an intersection of an edge with a
line inherits a bound from its endpoints and from the error of the parameter t. The
mean is the exact sum rounded (2 ulps of itself); the nearest feature is certified
(a vertex by its normal cone, an edge's interior by the mean lying outside its line
and between its ends, the point then computed on the edge's own data line). A
converged cluster — m − F points in a box a few ulps wide — is answered by one of its
points (Ψ lies in that box) before any of this. Callers use an answer only if its
bound is at most ACCEPT_REL of its magnitude.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._rounding import MIN_NORMAL
from .._rounding import UNIT_ROUNDOFF as EPS
from ._expansions import (
    PARALLEL,
    approximate,
    cross,
    difference,
    exact_mean,
    inner_kernel,
    orient,
    side_of_meet,
)
from ._scan_np import sets_in_range

OK = 0
#: a batch answer x is used only if its certified error bound is at most this times
#: ‖x‖_∞: relative to the answer itself, so no far point of the set can loosen it
#: (the sets that fail it are computed exactly)
ACCEPT_REL = 2.0**-40
#: why a problem fell back to the exact path (status ≥ 1): a meeting point of nearly
#: parallel lines, a flat kernel the path does not handle, the nearest feature
#: undecided, coordinates outside the range where expansions are exact (in_range)
CLIP_UNDECIDED, FLAT, NEAREST_UNDECIDED, OUT_OF_RANGE = 2, 3, 4, 5
#: ``_argsort`` sorts runs of at most this many keys by insertion, stably: on sets that
#: small its order is np.argsort(kind="stable")'s (the numpy cluster step's)
INSERTION_RUN = 15


@inner_kernel
def _insertion_sort(a, R, low, high):
    """Sort R[low:high + 1] by the keys a[R[·]], stably (the runs of ``_argsort``)."""
    for i in range(low + 1, high + 1):
        k = R[i]
        v = a[k]
        j = i
        while j > low and v < a[R[j - 1]]:
            R[j] = R[j - 1]
            j -= 1
        R[j] = k


@inner_kernel
def _partition(a, R, low, high):
    """Partition R[low:high + 1] by the keys a[R[·]] around the median of its first,
    middle and last key; returns the pivot's final index (``_argsort``'s step)."""
    mid = (low + high) >> 1
    if a[R[mid]] < a[R[low]]:
        R[low], R[mid] = R[mid], R[low]
    if a[R[high]] < a[R[mid]]:
        R[high], R[mid] = R[mid], R[high]
    if a[R[mid]] < a[R[low]]:
        R[low], R[mid] = R[mid], R[low]
    pivot = a[R[mid]]
    R[high], R[mid] = R[mid], R[high]
    i = low
    j = high - 1
    while True:
        while i < high and a[R[i]] < pivot:
            i += 1
        while j >= low and pivot < a[R[j]]:
            j -= 1
        if i >= j:
            break
        R[i], R[j] = R[j], R[i]
        i += 1
        j -= 1
    R[i], R[high] = R[high], R[i]
    return i


@inner_kernel
def _argsort(a):
    """np.argsort(a) for finite a, exactly as numba's own (its quicksort: partitions
    while a run has more than INSERTION_RUN keys, the larger part pushed, then insertion
    sort), ties in the same order — written out because the generic one takes seconds
    to compile. The stack holds at most log2(n) runs (each push halves what is left)."""
    n = a.shape[0]
    R = np.arange(n)
    lows = np.empty(64, dtype=np.int64)
    highs = np.empty(64, dtype=np.int64)
    lows[0], highs[0] = 0, n - 1
    top = 1 if n >= 2 else 0
    while top > 0:
        top -= 1
        low, high = lows[top], highs[top]
        while high - low >= INSERTION_RUN:
            i = _partition(a, R, low, high)
            if high - i > i - low:
                if high > i:
                    lows[top], highs[top] = i + 1, high
                    top += 1
                high = i - 1
            else:
                if i > low:
                    lows[top], highs[top] = low, i - 1
                    top += 1
                low = i + 1
        _insertion_sort(a, R, low, high)
    return R


@inner_kernel
def _sorted_column(Y, c):
    """Column c of Y (a fresh array) and its ``_argsort`` order."""
    col = np.empty(Y.shape[0])
    for q in range(Y.shape[0]):
        col[q] = Y[q, c]
    return col, _argsort(col)


@inner_kernel
def _sorted_values(Y, c):
    """Column c of Y in increasing order (insertion sort: a few dozen values, of the
    collinear sets only)."""
    vals = np.empty(Y.shape[0])
    for q in range(Y.shape[0]):
        v = Y[q, c]
        j = q
        while j > 0 and v < vals[j - 1]:
            vals[j] = vals[j - 1]
            j -= 1
        vals[j] = v
    return vals


@inner_kernel
def cluster_box(Y, F, out):
    """Ψ(Y, F) ⊂ conv(S) ⊂ box(S) for every m − F of the points S (Ψ is the intersection
    of those hulls): with S the m − F points nearest the coordinate-wise median (max
    norm), the point of S nearest it is within w — box(S)'s largest side, rounded up —
    of every point of Ψ, the exact projection included (max norm). Writes that point,
    returns w; converged states make w a few ulps whatever the set's degeneracy.
    (Y finite; the median is np.median's, the order np.argsort's, ties included.)"""
    m, d = Y.shape
    med = np.empty(d)
    for c in range(d):
        col, rank = _sorted_column(Y, c)
        h = m >> 1
        med[c] = col[rank[h]] if m & 1 else (col[rank[h - 1]] + col[rank[h]]) / 2
    dist = np.zeros(m)
    for q in range(m):
        for c in range(d):
            dist[q] = max(dist[q], abs(Y[q, c] - med[c]))
    order = _argsort(dist)
    w = 0.0
    for c in range(d):
        lo = hi = Y[order[0], c]
        for r in range(m - F):
            lo = min(lo, Y[order[r], c])
            hi = max(hi, Y[order[r], c])
        w = max(w, hi - lo)
        out[c] = Y[order[0], c]
    return w * (1.0 + 2.0 * EPS)


@inner_kernel
def _orient(Y, i, j, q):
    """Sign of (p_j − p_i) × (p_q − p_i): the float value when its rounding bound
    decides it, else the exact sign."""
    a0 = Y[j, 0] - Y[i, 0]
    a1 = Y[j, 1] - Y[i, 1]
    u0 = Y[q, 0] - Y[i, 0]
    u1 = Y[q, 1] - Y[i, 1]
    s = a0 * u1 - a1 * u0
    bound = 8.0 * EPS * (abs(a0 * u1) + abs(a1 * u0))
    if s > bound:
        return 1
    if s < -bound:
        return -1
    return orient(Y[i, 0], Y[i, 1], Y[j, 0], Y[j, 1], Y[q, 0], Y[q, 1])


@inner_kernel
def _representatives(Y, rep):
    """rep[q] = the first index with exactly the coordinates of point q; returns the
    number of distinct points."""
    distinct = 0
    for q in range(Y.shape[0]):
        rep[q] = q
        for r in range(q):
            if Y[r, 0] == Y[q, 0] and Y[r, 1] == Y[q, 1]:
                rep[q] = r
                break
        if rep[q] == q:
            distinct += 1
    return distinct


@inner_kernel
def _lines(Y, F, rep, A, C, Aerr, Cerr, ends, sgn):
    """Valid halfplanes a·x ≤ c of Ψ(Y, F): through two distinct points, ≤ F points
    strictly outside (sides decided exactly; copies of an endpoint lie on the line).
    a = sgn·(−(y_j − y_i), x_j − x_i), so a·(p − p_i) = sgn·orient(i, j, p).
    Returns their number."""
    m = Y.shape[0]
    nh = 0
    for i in range(m):
        if rep[i] != i:
            continue
        for j in range(i + 1, m):
            if rep[j] != j:
                continue
            plus = 0
            minus = 0
            for q in range(m):
                if rep[q] == i or rep[q] == j:
                    continue
                o = _orient(Y, i, j, q)
                if o > 0:
                    plus += 1
                elif o < 0:
                    minus += 1
            a0, a1 = -(Y[j, 1] - Y[i, 1]), Y[j, 0] - Y[i, 0]  # relative error ≤ ε each
            for sign, outside in ((1.0, plus), (-1.0, minus)):
                if outside <= F:
                    A[nh, 0] = sign * a0
                    A[nh, 1] = sign * a1
                    C[nh] = sign * (a0 * Y[i, 0] + a1 * Y[i, 1])
                    Aerr[nh] = EPS * (abs(a0) + abs(a1))
                    ends[nh, 0] = i
                    ends[nh, 1] = j
                    sgn[nh] = 1 if sign > 0 else -1
                    Cerr[nh] = 4.0 * EPS * (abs(a0 * Y[i, 0]) + abs(a1 * Y[i, 1])) + Aerr[nh] * (
                        abs(Y[i, 0]) + abs(Y[i, 1]))
                    nh += 1
    return nh


@inner_kernel
def _collinear(Y, F, rep, mean, merr, out):
    """When all distinct points lie on one line, Ψ is the segment between the
    (F+1)-th smallest and the (F+1)-th largest point along it (points with multiplicity,
    ordered by x, or by y on a vertical line), and the point nearest the mean (which lies
    on the line) is the mean clamped to it. Returns its error bound; −1 when the mean's
    position against an end is undecided or Ψ is empty, −2 when not collinear."""
    m = Y.shape[0]
    i0 = 0
    j0 = -1
    for q in range(m):
        if rep[q] == q and q != i0:
            if j0 < 0:
                j0 = q
            elif _orient(Y, i0, j0, q) != 0:
                return -2.0
    p = 0 if Y[j0, 0] != Y[i0, 0] else 1
    vals = _sorted_values(Y, p)
    lo, hi = vals[F], vals[m - 1 - F]
    if lo > hi:
        return -1.0
    mp = mean[p]
    if mp + merr < lo or mp - merr > hi:
        target = lo if mp < lo else hi
        for q in range(m):
            if Y[q, p] == target:
                out[0], out[1] = Y[q, 0], Y[q, 1]
                return 0.0
    if lo < mp - merr and mp + merr < hi:
        out[0], out[1] = mean[0], mean[1]
        return merr
    return -1.0


@inner_kernel
def _pinned(Y, rep, nh, ends, sgn):
    """Two different lines through a data point p, each valid on both sides (so both
    halfplanes of each are in the list, consecutively), give Ψ ⊂ {p}; then Ψ = {p} iff
    p satisfies every valid halfplane (exact orientations). Returns p, or −1 (no such
    pair, or Ψ empty)."""
    for h in range(nh - 1):
        if ends[h, 0] != ends[h + 1, 0] or ends[h, 1] != ends[h + 1, 1]:
            continue
        for g in range(h + 2, nh - 1):
            if ends[g, 0] != ends[g + 1, 0] or ends[g, 1] != ends[g + 1, 1]:
                continue
            for p in (ends[h, 0], ends[h, 1]):
                if p != ends[g, 0] and p != ends[g, 1]:
                    continue
                a = ends[h, 0] + ends[h, 1] - p
                b = ends[g, 0] + ends[g, 1] - p
                if _orient(Y, p, a, b) == 0:
                    continue
                for k in range(nh):
                    if ends[k, 0] != p and ends[k, 1] != p and \
                            sgn[k] * _orient(Y, ends[k, 0], ends[k, 1], p) > 0:
                        return -1
                return p
    return -1


@inner_kernel
def _on_side(Y, i, side, box):
    """Data point i lies on box side ``side`` (0 bottom, 1 right, 2 top, 3 left):
    exactly, since the box is made of the data's own extreme coordinates."""
    if side == 0:
        return Y[i, 1] == box[2]
    if side == 1:
        return Y[i, 0] == box[1]
    if side == 2:
        return Y[i, 1] == box[3]
    return Y[i, 0] == box[0]


@inner_kernel
def _meet(g, a0, a1, c, aerr, cerr, A, C, Aerr, Cerr, box, out):
    """The intersection of the edge line g (a data line, or box side −1−g) with
    a0 x + a1 y = c by Cramer's rule, into out; returns its error bound (the lines'
    own errors and the rounding, divided by the certified part of the determinant),
    −1 if the lines are too close to parallel to tell."""
    if g >= 0:
        b0, b1, d, berr, derr = A[g, 0], A[g, 1], C[g], Aerr[g], Cerr[g]
    else:
        side = -1 - g
        berr, derr = 0.0, 0.0
        if side == 0:
            b0, b1, d = 0.0, -1.0, -box[2]
        elif side == 1:
            b0, b1, d = 1.0, 0.0, box[1]
        elif side == 2:
            b0, b1, d = 0.0, 1.0, box[3]
        else:
            b0, b1, d = -1.0, 0.0, -box[0]
    det = b0 * a1 - b1 * a0
    x_num = d * a1 - c * b1
    y_num = b0 * c - a0 * d
    na, nb = abs(a0) + abs(a1), abs(b0) + abs(b1)
    det_err = berr * na + aerr * nb + 4.0 * EPS * (abs(b0 * a1) + abs(b1 * a0))
    x_err = derr * na + abs(d) * aerr + cerr * nb + abs(c) * berr \
        + 4.0 * EPS * (abs(d * a1) + abs(c * b1))
    y_err = berr * abs(c) + nb * cerr + aerr * abs(d) + na * derr \
        + 4.0 * EPS * (abs(b0 * c) + abs(a0 * d))
    if abs(det) <= 2.0 * det_err:
        return -1.0
    x = x_num / det
    y = y_num / det
    out[0] = x
    out[1] = y
    denom = abs(det) - det_err
    return max((x_err + abs(x) * det_err) / denom, (y_err + abs(y) * det_err) / denom) \
        + 4.0 * EPS * max(abs(x), abs(y))


@inner_kernel
def _line_of(g, Y, ends, box, base, u):
    """Line g as base point and direction with two-term components: a data line through
    its two points, or box side −1−g (0 bottom, 1 right, 2 top, 3 left)."""
    if g >= 0:
        i, j = ends[g, 0], ends[g, 1]
        base[0], base[1] = Y[i, 0], Y[i, 1]
        difference(Y[j, 0], Y[i, 0], u[0])
        difference(Y[j, 1], Y[i, 1], u[1])
        return
    side = -1 - g
    base[0] = box[1] if side == 1 else box[0]
    base[1] = box[3] if side == 2 else box[2]
    u[:, :] = 0.0
    u[side % 2, 1] = 1.0  # along x for the bottom and top, along y for the sides


@inner_kernel
def _exact_side(h, v, P, E, VA, VB, Y, ends, box):
    """Exact sign of orient(h's points, vertex v) for a computed vertex: from its float
    coordinates when they are exact (E = 0, the box corners), else from the two lines
    it lies on. PARALLEL when those lines are parallel."""
    i0, i1 = ends[h, 0], ends[h, 1]
    if E[v] == 0.0:
        return orient(Y[i0, 0], Y[i0, 1], Y[i1, 0], Y[i1, 1], P[v, 0], P[v, 1])
    b1, b2, b5 = np.empty(2), np.empty(2), np.empty(2)
    u1, u2, u5 = np.empty((2, 2)), np.empty((2, 2)), np.empty((2, 2))
    _line_of(VA[v], Y, ends, box, b1, u1)
    _line_of(VB[v], Y, ends, box, b2, u2)
    _line_of(h, Y, ends, box, b5, u5)
    return side_of_meet(b1, u1, b2, u2, b5, u5)


@inner_kernel
def _clip(P, E, PT, EL, VA, VB, nv, h, A, C, Aerr, Cerr, ends, sgn, Y, box,
          Q, QE, QPT, QEL, QVA, QVB):
    """Clip the convex polygon P[:nv] (errors E; PT[v] = the data point (representative)
    v equals exactly, or −1; EL[v] = line of the edge v → v+1, −1−k for box side k;
    VA[v], VB[v] = the two lines a computed vertex lies on) by line h into Q….
    Every sign is exact: the float value when its error bound decides it, else an
    orientation of data points or of a meeting point of two lines (expansions). An
    intersection of h with an edge whose line shares an endpoint with h is exactly that
    data point. Returns the new vertex count, or −1 when a meeting point cannot be
    bounded (nearly parallel lines in floats)."""
    a0, a1, c = A[h, 0], A[h, 1], C[h]
    aerr, cerr = Aerr[h], Cerr[h]
    i0, i1 = ends[h, 0], ends[h, 1]
    s = np.empty(nv)
    for v in range(nv):
        if PT[v] == i0 or PT[v] == i1:
            s[v] = 0.0
            continue
        if PT[v] >= 0:
            s[v] = sgn[h] * _orient(Y, i0, i1, PT[v])
            continue
        val = a0 * P[v, 0] + a1 * P[v, 1] - c
        bound = (abs(a0) + abs(a1)) * E[v] + aerr * (abs(P[v, 0]) + abs(P[v, 1])) + cerr \
            + 4.0 * EPS * (abs(a0 * P[v, 0]) + abs(a1 * P[v, 1]) + abs(c))
        if abs(val) > bound:
            s[v] = val
            continue
        o = _exact_side(h, v, P, E, VA, VB, Y, ends, box)
        if o == PARALLEL:
            return -1
        s[v] = sgn[h] * o
    nq = 0
    for v in range(nv):
        w = (v + 1) % nv
        if s[v] <= 0:
            Q[nq, 0] = P[v, 0]
            Q[nq, 1] = P[v, 1]
            QE[nq] = E[v]
            QPT[nq] = PT[v]
            # the edge leaving v: still on its line if w is kept or cut, else on h
            QEL[nq] = EL[v] if s[w] <= 0 or s[v] < 0 else h
            QVA[nq] = VA[v]
            QVB[nq] = VB[v]
            nq += 1
        if (s[v] < 0 and s[w] > 0) or (s[v] > 0 and s[w] < 0):
            g = EL[v]
            shared = -1
            if g >= 0:
                if ends[g, 0] == i0 or ends[g, 0] == i1:
                    shared = ends[g, 0]
                elif ends[g, 1] == i0 or ends[g, 1] == i1:
                    shared = ends[g, 1]
            else:  # a side of the bounding box: the data points on it are exactly on it
                side = -1 - g
                if _on_side(Y, i0, side, box):
                    shared = i0
                elif _on_side(Y, i1, side, box):
                    shared = i1
            if shared >= 0:
                Q[nq, 0] = Y[shared, 0]
                Q[nq, 1] = Y[shared, 1]
                QE[nq] = 0.0
                QPT[nq] = shared
            else:
                e = _meet(g, a0, a1, c, aerr, cerr, A, C, Aerr, Cerr, box, Q[nq])
                if e < 0:
                    return -1
                QE[nq] = e
                QPT[nq] = -1
            QVA[nq] = g
            QVB[nq] = h
            # entering (v out, w in): the new edge continues on g; leaving: it runs on h
            QEL[nq] = g if s[v] > 0 else h
            nq += 1
    return nq


@inner_kernel
def _project(P, E, EL, nv, Y, ends, box, m0, m1, merr, out):
    """Nearest point of the polygon P[:nv] to (m0, m1), if the nearest feature (inside,
    an edge's interior, a vertex) is decided; returns its error bound or −1. Outside,
    the float-nearest feature is certified: a vertex by its normal cone, an edge by m
    lying outside its line and between its ends along it (then the answer is computed
    on the edge's own data line, not from the computed vertices)."""
    # inside: every edge (counter-clockwise) has the point on its left
    inside = True
    undecided = False
    for v in range(nv):
        w = (v + 1) % nv
        ex = P[w, 0] - P[v, 0]
        ey = P[w, 1] - P[v, 1]
        cr = ex * (m1 - P[v, 1]) - ey * (m0 - P[v, 0])
        err = (abs(ex) + abs(ey)) * (2.0 * max(E[v], E[w]) * 2.0 + merr) + 8.0 * EPS * (
            abs(ex * (m1 - P[v, 1])) + abs(ey * (m0 - P[v, 0])))
        if cr < -err:
            inside = False
        elif cr <= err:
            undecided = True
    if inside and not undecided:
        out[0] = m0
        out[1] = m1
        return merr
    if inside and undecided:
        return -1.0
    best = np.inf
    bv = 0
    bt = 0.0
    for v in range(nv):
        w = (v + 1) % nv
        ex = P[w, 0] - P[v, 0]
        ey = P[w, 1] - P[v, 1]
        ll = ex * ex + ey * ey
        t = 0.0
        if ll > 0:
            t = ((m0 - P[v, 0]) * ex + (m1 - P[v, 1]) * ey) / ll
        t = min(1.0, max(0.0, t))
        dist = np.hypot(P[v, 0] + t * ex - m0, P[v, 1] + t * ey - m1)
        if dist < best:
            best = dist
            bv = v
            bt = t
    if 0.0 < bt < 1.0:
        return _edge_nearest(P, E, EL, nv, bv, Y, ends, box, m0, m1, merr, out)
    return _vertex_nearest(P, E, nv, bv if bt == 0.0 else (bv + 1) % nv, m0, m1, merr, out)


@inner_kernel
def _dot_bound(a0, a1, ea, b0, b1, eb):
    """fl(a · b) and a bound on its distance to a* · b* for |a* − a|, |b* − b| ≤ ea, eb
    per coordinate (a, b themselves rounded differences: their u|·| is added here)."""
    e0a, e1a = ea + EPS * abs(a0), ea + EPS * abs(a1)
    e0b, e1b = eb + EPS * abs(b0), eb + EPS * abs(b1)
    bound = (e0a * abs(b0) + e0b * abs(a0) + e0a * e0b + e1a * abs(b1) + e1b * abs(a1)
             + e1a * e1b + 4.0 * EPS * (abs(a0 * b0) + abs(a1 * b1)))
    return a0 * b0 + a1 * b1, bound * (1.0 + 8.0 * EPS)


@inner_kernel
def _vertex_nearest(P, E, nv, c, m0, m1, merr, out):
    """Vertex c is the nearest point iff m − P_c makes an angle ≥ 90° with both edges
    at c (its normal cone); decided strictly from the bounds, then the answer is P_c
    (error E[c]); else −1."""
    for nb in ((c + nv - 1) % nv, (c + 1) % nv):
        val, bnd = _dot_bound(m0 - P[c, 0], m1 - P[c, 1], merr + E[c],
                              P[nb, 0] - P[c, 0], P[nb, 1] - P[c, 1], E[nb] + E[c])
        if not val < -bnd:
            return -1.0
    out[0] = P[c, 0]
    out[1] = P[c, 1]
    return E[c]


@inner_kernel
def _edge_nearest(P, E, EL, nv, v, Y, ends, box, m0, m1, merr, out):
    """The edge v → v+1 holds the nearest point in its interior iff m lies strictly
    outside its line and strictly between its ends along it (convex polygon). Then the
    answer is m projected onto the edge's line (through its data point b nearer m,
    direction u of exact components rounded): b + ((m − b)·u / u·u) u, within merr + 16u‖m − b‖ +
    4u‖answer‖ of the exact projection (u's direction is within 2u relative). −1 if
    undecided."""
    w = (v + 1) % nv
    g = EL[v]
    base = np.empty(2)
    u2 = np.empty((2, 2))
    _line_of(g, Y, ends, box, base, u2)
    if g >= 0:  # anchored at the line's data point nearer m (the bounds scale with it)
        q = ends[g, 1]
        if np.hypot(m0 - Y[q, 0], m1 - Y[q, 1]) < np.hypot(m0 - base[0], m1 - base[1]):
            base[0], base[1] = Y[q, 0], Y[q, 1]
    u0, u1 = u2[0, 0] + u2[0, 1], u2[1, 0] + u2[1, 1]
    ue = 2.0 * EPS * max(abs(u0), abs(u1))
    sm, em = _dot_bound(m0 - base[0], m1 - base[1], merr, u0, u1, ue)
    sv, ev = _dot_bound(P[v, 0] - base[0], P[v, 1] - base[1], E[v], u0, u1, ue)
    sw, ew = _dot_bound(P[w, 0] - base[0], P[w, 1] - base[1], E[w], u0, u1, ue)
    lo, elo, hi, ehi = (sv, ev, sw, ew) if sv < sw else (sw, ew, sv, ev)
    if not (lo + elo < sm - em and sm + em < hi - ehi):
        return -1.0
    cr, ecr = _dot_bound(P[w, 0] - P[v, 0], P[w, 1] - P[v, 1], E[v] + E[w],
                         m1 - P[v, 1], -(m0 - P[v, 0]), merr + E[v])
    if not cr < -ecr:  # (w − v) × (m − v) < 0: m right of a counter-clockwise edge
        return -1.0
    t = sm / (u0 * u0 + u1 * u1)
    out[0] = base[0] + t * u0
    out[1] = base[1] + t * u1
    dm = np.hypot(m0 - base[0], m1 - base[1])
    return merr + 16.0 * EPS * dm + 4.0 * EPS * max(abs(out[0]), abs(out[1]))


#: for each of 4 points, the other three (ascending)
_OTHERS = ((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2))
#: (0, j) and the other two points, for each j: (0, j) is a diagonal of 4 points in
#: convex position iff those two lie on opposite sides of it
_DIAGONALS = ((0, 1, 2, 3), (0, 2, 1, 3), (0, 3, 1, 2))


@inner_kernel
def _radon4(Y, out):
    """Ψ(Y, 1) for 4 points in general position is one point: the crossing of the
    diagonals (convex position) or the point inside the triangle of the others.
    Returns its error bound, or −1 when an orientation is undecided."""
    for k in range(4):
        a, b, c = _OTHERS[k]
        if _orient(Y, a, b, c) == 0:
            return -1.0
    for k in range(4):
        if _inside(Y, k):
            out[0] = Y[k, 0]
            out[1] = Y[k, 1]
            return 0.0
    for a, j, c, d in _DIAGONALS:
        if _orient(Y, a, j, c) * _orient(Y, a, j, d) < 0:
            return _crossing(Y, a, j, c, d, out)
    return -1.0


@inner_kernel
def _crossing(Y, a, b, c, d, out):
    """The crossing of the lines p_a p_b and p_c p_d (which cross: decided before),
    x = p_a + t (p_b − p_a) with t = ((p_c − p_a) × (p_d − p_c)) / ((p_b − p_a) ×
    (p_d − p_c)), both cross products exact (expansions) then rounded (3 ulps each),
    so t is within 7u of itself however flat the four points are; into out. Returns
    the error bound (max norm): 12u |t| |p_b − p_a| + 2u |x| — relative to the
    diagonal and the answer, not to the coordinates' size or the lines' angle."""
    u = np.empty((2, 2))
    w = np.empty((2, 2))
    v = np.empty((2, 2))
    buf = np.empty(16)
    for k in range(2):
        difference(Y[b, k], Y[a, k], u[k])
        difference(Y[d, k], Y[c, k], w[k])
        difference(Y[c, k], Y[a, k], v[k])
    den = approximate(buf, cross(u, w, buf))
    num = approximate(buf, cross(v, w, buf))
    if den == 0.0:
        return -1.0
    t = num / den
    e = 0.0
    for k in range(2):
        uk = u[k, 0] + u[k, 1]
        out[k] = Y[a, k] + t * uk
        e = max(e, 12.0 * EPS * abs(t * uk) + 2.0 * EPS * abs(out[k]))
    return e + MIN_NORMAL


@inner_kernel
def _inside(Y, k):
    """Point k strictly inside the triangle of the other three (decided orientations)."""
    a, b, c = _OTHERS[k]
    s0 = _orient(Y, a, b, k)
    s1 = _orient(Y, b, c, k)
    s2 = _orient(Y, c, a, k)
    return s0 != 0 and s0 == s1 and s1 == s2


def project_small_2d(Ys: np.ndarray, F: int, out: np.ndarray, err: np.ndarray,
                     status: np.ndarray) -> None:
    """For each problem b: the point of Ψ(Ys[b], F) nearest to mean(Ys[b]) into out[b],
    its error bound into err[b], status OK or the reason to compute it exactly.

    Ys (B, m, 2) float64, C-contiguous; out (B, 2), err (B,), status (B,) int64. The
    steps are kernels of their own, each run on the sets still open (and compiled only
    when some set reaches it): converged clusters (m ≥ 3F + 1), the range check, the
    Radon point of 4 points for F = 1, then halfplanes, clipping and projection."""
    B, m, _ = Ys.shape
    status[:] = FLAT
    todo = np.arange(B)
    if m >= 3 * F + 1:  # (Ψ ≠ ∅) a converged cluster: any of its points will do
        if m <= INSERTION_RUN:
            _clusters_np(Ys, F, out, err, status)
        else:
            _clusters(Ys, todo, F, out, err, status)
        todo = todo[status[todo] != OK]
    fits = sets_in_range(Ys[todo])
    status[todo[~fits]] = OUT_OF_RANGE
    todo = todo[fits]
    if m == 4 and F == 1 and len(todo):  # in general position Ψ is one (Radon) point
        _radon_points(Ys, todo, out, err, status)
        todo = todo[status[todo] != OK]
    if len(todo):
        _polygons(Ys, todo, F, out, err, status)


def _clusters_np(Ys: np.ndarray, F: int, out: np.ndarray, err: np.ndarray,
                 status: np.ndarray) -> None:
    """_clusters for every set in numpy, nothing to compile (m ≤ INSERTION_RUN, where a
    stable argsort orders as _argsort): the same floats — the median of each coordinate
    (its middle value, or the rounded half-sum of the middle two), the max-norm distances
    to it, the m − F nearest points in the same order, their box."""
    m = Ys.shape[1]
    med = np.median(Ys, axis=1)
    dist = np.abs(Ys - med[:, None, :]).max(axis=2)
    order = np.argsort(dist, axis=1, kind="stable")
    near = np.take_along_axis(Ys, order[:, :m - F, None], axis=1)
    w = (near.max(axis=1) - near.min(axis=1)).max(axis=1) * (1.0 + 2.0 * EPS)
    out[:] = near[:, 0]
    ok = w <= ACCEPT_REL * np.abs(out).max(axis=1)
    err[ok] = w[ok]
    status[ok] = OK


@inner_kernel
def _bounding_box(Y):
    """[min x, max x, min y, max y] over the rows of Y."""
    box = np.empty(4)
    box[0] = box[1] = Y[0, 0]
    box[2] = box[3] = Y[0, 1]
    for q in range(1, Y.shape[0]):
        for c in range(2):
            if Y[q, c] < box[2 * c]:
                box[2 * c] = Y[q, c]
            if Y[q, c] > box[2 * c + 1]:
                box[2 * c + 1] = Y[q, c]
    return box


@njit(cache=True, nogil=True)
def _clusters(Ys, todo, F, out, err, status):
    """cluster_box for the sets todo; OK where its width is at most ACCEPT_REL of the
    point's magnitude."""
    for b in todo:
        e = cluster_box(Ys[b], F, out[b])
        if e <= ACCEPT_REL * max(abs(out[b, 0]), abs(out[b, 1])):
            err[b] = e
            status[b] = OK


@njit(cache=True, nogil=True)
def _radon_points(Ys, todo, out, err, status):
    """_radon4 for the sets todo (m = 4, F = 1); OK where it is decided."""
    for b in todo:
        e = _radon4(Ys[b], out[b])
        if e >= 0:
            err[b] = e
            status[b] = OK


@njit(cache=True, nogil=True)
def _polygons(Ys, todo, F, out, err, status):
    """The general path for the sets todo (status FLAT on entry): a single point, a
    collinear set, a pinned point, else the polygon cut from the bounding box by the
    valid halfplanes and its point nearest the exact mean."""
    _, m, _ = Ys.shape
    H = m * (m - 1)
    A = np.empty((H, 2))
    C = np.empty(H)
    Aerr = np.empty(H)
    Cerr = np.empty(H)
    ends = np.empty((H, 2), dtype=np.int64)
    sgn = np.empty(H, dtype=np.int64)
    rep = np.empty(m, dtype=np.int64)
    cap = 4 + 2 * H + 4
    P = np.empty((cap, 2))
    E = np.empty(cap)
    PT = np.empty(cap, dtype=np.int64)
    EL = np.empty(cap, dtype=np.int64)
    Q = np.empty((cap, 2))
    QE = np.empty(cap)
    QPT = np.empty(cap, dtype=np.int64)
    QEL = np.empty(cap, dtype=np.int64)
    VA = np.empty(cap, dtype=np.int64)
    VB = np.empty(cap, dtype=np.int64)
    QVA = np.empty(cap, dtype=np.int64)
    QVB = np.empty(cap, dtype=np.int64)
    mean = np.empty(2)
    merrs = np.empty(2)
    for b in todo:
        Y = Ys[b]
        exact_mean(Y, mean, merrs)  # (the exact mean rounded: 2 ulps of itself)
        merr = max(merrs[0], merrs[1])
        if _representatives(Y, rep) == 1:  # every point the same: Ψ is that point
            out[b, 0], out[b, 1] = Y[0, 0], Y[0, 1]
            err[b] = 0.0
            status[b] = OK
            continue
        e = _collinear(Y, F, rep, mean, merr, out[b])
        if e != -2.0:
            if e >= 0:
                err[b] = e
                status[b] = OK
            continue
        nh = _lines(Y, F, rep, A, C, Aerr, Cerr, ends, sgn)
        p = _pinned(Y, rep, nh, ends, sgn)
        if p >= 0:
            out[b, 0], out[b, 1] = Y[p, 0], Y[p, 1]
            err[b] = 0.0
            status[b] = OK
            continue
        box = _bounding_box(Y)
        lo0, hi0, lo1, hi1 = box[0], box[1], box[2], box[3]
        P[0, 0], P[0, 1] = lo0, lo1
        P[1, 0], P[1, 1] = hi0, lo1
        P[2, 0], P[2, 1] = hi0, hi1
        P[3, 0], P[3, 1] = lo0, hi1
        E[:4] = 0.0
        PT[:4] = -1
        for k in range(4):  # a corner may be a data point (extreme in x and in y)
            for q in range(m):
                if Y[q, 0] == P[k, 0] and Y[q, 1] == P[k, 1]:
                    PT[k] = rep[q]
        for k in range(4):
            EL[k] = -1 - k  # box side k: edge k → k+1 (bottom, right, top, left)
            VA[k] = -1 - k
            VB[k] = -1 - (k + 3) % 4  # corner k is on sides k and k − 1
        nv = 4
        for h in range(nh):
            nq = _clip(P, E, PT, EL, VA, VB, nv, h, A, C, Aerr, Cerr, ends, sgn, Y, box,
                       Q, QE, QPT, QEL, QVA, QVB)
            if nq < 0:
                status[b] = CLIP_UNDECIDED
                nv = -1
                break
            nv = 0
            for v in range(nq):  # copy, merging runs of the same data point
                w = (v + 1) % nq
                if QPT[v] >= 0 and QPT[v] == QPT[w] and v != w:
                    continue
                P[nv, 0] = Q[v, 0]
                P[nv, 1] = Q[v, 1]
                E[nv] = QE[v]
                PT[nv] = QPT[v]
                EL[nv] = QEL[v]
                VA[nv] = QVA[v]
                VB[nv] = QVB[v]
                nv += 1
            if nv == 0 and nq > 0:  # all one data point
                P[0, 0], P[0, 1], E[0], PT[0], EL[0] = Q[0, 0], Q[0, 1], 0.0, QPT[0], QEL[0]
                nv = 1
            if nv == 2 or nv == 0:
                nv = -1  # a segment or empty: exact path
                break
        if nv == 1:  # Ψ is a single data point (only data points are merged)
            out[b, 0], out[b, 1] = P[0, 0], P[0, 1]
            err[b] = 0.0
            status[b] = OK
            continue
        if nv < 3:
            continue
        e = _project(P, E, EL, nv, Y, ends, box, mean[0], mean[1], merr, out[b])
        if e < 0:
            status[b] = NEAREST_UNDECIDED
            continue
        err[b] = e
        status[b] = OK
