"""numba kernel: classify every point against every hyperplane through k points.

For a k-subset {p_0, ..., p_{k-1}} of points in R^k and a point q, the orientation

    s(q) = det[p_1 − p_0; ...; p_{k−1} − p_0; q − p_0] = Σ_j (q − p_0)_j · C_j

(C_j the cofactors of the last row) is > 0, = 0 or < 0 as q lies on the positive
side of, on, or on the negative side of the hyperplane through the subset. With
``c_err > 0`` the float value is trusted only when |s| exceeds the rounding-error
bound c_err · Σ_j |q − p_0|_j · |C|_j + floor (|C|_j: the same cofactors of the
absolute values, a permanent; floor: the underflow term of
:func:`rescon._rounding.underflow_floor`); otherwise — and whenever s or the bound is
inf or NaN, as no comparison with them holds — the point is counted as *uncertain*
and decided later in exact integer arithmetic. With ``c_err = 0`` the caller guarantees that
float arithmetic is exact (small integers), and s = 0 means "on the hyperplane".
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .._rounding import UNIT_ROUNDOFF


@njit(cache=True, nogil=True)
def _cofactors(Y, idx, k, C, Cabs):
    """Cofactors of the last row of [p_1 − p_0; ...; p_{k−1} − p_0; ·] and their
    absolute-value permanents, into C and Cabs (length k), for k = 2, 3 (closed
    forms; k ≥ 4: :func:`_prefix_minors` and :func:`_last_row_cofactors`)."""
    p0, p1 = idx[0], idx[1]
    if k == 2:
        C[0] = -(Y[p1, 1] - Y[p0, 1])
        C[1] = Y[p1, 0] - Y[p0, 0]
        Cabs[0] = abs(C[0])
        Cabs[1] = abs(C[1])
        return
    p2 = idx[2]
    a0, a1, a2 = Y[p1, 0] - Y[p0, 0], Y[p1, 1] - Y[p0, 1], Y[p1, 2] - Y[p0, 2]
    b0, b1, b2 = Y[p2, 0] - Y[p0, 0], Y[p2, 1] - Y[p0, 1], Y[p2, 2] - Y[p0, 2]
    C[0] = a1 * b2 - a2 * b1
    C[1] = a2 * b0 - a0 * b2
    C[2] = a0 * b1 - a1 * b0
    Cabs[0] = abs(a1 * b2) + abs(a2 * b1)
    Cabs[1] = abs(a2 * b0) + abs(a0 * b2)
    Cabs[2] = abs(a0 * b1) + abs(a1 * b0)


@njit(cache=True, nogil=True, inline="always")
def _expand_last(R, r, mask, mdet, mper):
    """det and permanent of |·| of the minor on the difference rows R[0..r] and the
    columns in ``mask`` (r + 1 of them), expanded along row r over the minors of rows
    0..r − 1 on ``mask`` less one column (mdet, mper, indexed by column bitmask):
    Σ_t (−1)^(r + t) R[r, c_t] · minor(mask − c_t), c_0 < c_1 < …"""
    det = 0.0
    per = 0.0
    plus = r % 2 == 0  # the sign of the next term: (−1)^(r + t) > 0
    for col in range(R.shape[1]):
        if mask >> col & 1:
            sub = mask ^ (1 << col)
            v = R[r, col]
            term = v * mdet[sub]
            if plus:
                det += term
            else:
                det -= term
            per += abs(v) * mper[sub]
            plus = not plus
    return det, per


@njit(cache=True, nogil=True)
def _prefix_minors(Y, idx, k, R, mdet, mper):
    """For k ≥ 4: every minor (and permanent of |·|) of the first k − 2 difference rows
    p_i − p_0 (i = 1..k − 2, into R) on k − 2 of the k columns, into mdet, mper indexed
    by column bitmask — with the smaller minors on the way: the mask of r + 1 columns
    holds the minor of rows 0..r (:func:`_expand_last`; mask 0 the empty one, 1), built
    in increasing order of the masks, so each after the r-column masks it expands over.
    They depend on p_0..p_{k−2} only: the subsets in lexicographic order share them
    along runs of the last index. O(k 2^k) steps."""
    p0 = idx[0]
    for i in range(k - 2):
        for j in range(k):
            R[i, j] = Y[idx[i + 1], j] - Y[p0, j]
    mdet[0] = 1.0
    mper[0] = 1.0
    for mask in range(1, 1 << k):
        r = _popcount(mask) - 1
        if r < k - 2:
            mdet[mask], mper[mask] = _expand_last(R, r, mask, mdet, mper)


@njit(cache=True, nogil=True, inline="always")
def _popcount(mask):
    c = 0
    while mask:
        mask &= mask - 1
        c += 1
    return c


@njit(cache=True, nogil=True)
def _last_row_cofactors(Y, idx, k, R, mdet, mper, C, Cabs):
    """For k ≥ 4, the cofactors C_j = (−1)^(k−1+j) det(D without column j) of the last
    row of [D; ·], D the k − 1 difference rows, each determinant expanded along D's
    last row p_{k−1} − p_0 (into R[k − 2]) over the prefix minors of
    :func:`_prefix_minors`; Cabs likewise, unsigned. Every product passes through
    k(k − 1)/2 roundings at most (a difference, then per row one product and a sum),
    fewer than the scan's c_err allows."""
    p0 = idx[0]
    for j in range(k):
        R[k - 2, j] = Y[idx[k - 1], j] - Y[p0, j]
    _expand_cofactors(R, k, mdet, mper, C, Cabs)


@njit(cache=True, nogil=True, inline="always")
def _expand_cofactors(R, k, mdet, mper, C, Cabs):
    """The cofactors of the last row of [R[0..k−2]; ·] and their permanents, expanded
    along R[k − 2] over the prefix minors (:func:`_last_row_cofactors`)."""
    full = (1 << k) - 1
    for j in range(k):
        det, per = _expand_last(R, k - 2, full ^ (1 << j), mdet, mper)
        C[j] = det if (k - 1 + j) % 2 == 0 else -det
        Cabs[j] = per


@njit(cache=True, nogil=True)
def _prefix_octants(Y, YT, idx, k, R, mdet, mper, c_err, floor, M, C, Cabs, S, T,
                    octant, weight, W):
    """For k ≥ 4 and the prefix p_0..p_{k−2} of ``idx`` (its minors in mdet, mper:
    :func:`_prefix_minors`): each point's open octant (0..7, 8 when not sure) in the
    plane of the prefix, and the weight of each (``weight``, 9 entries).

    ω(u, v) = det[p_1 − p_0; …; p_{k−2} − p_0; u; v] is an alternating form vanishing
    on the prefix's directions, so of rank ≤ 2: ω = α ∧ β for two linear forms. The
    subset (prefix, p) sees q on the side sign ω(p − p_0, q − p_0) (the scan's
    orientation s(q)). Take the columns a ≠ b of the largest prefix minor |ω(e_a, e_b)|
    and P(v) = (ω(e_a, v), ω(e_b, v)) = L (α(v), β(v)) with det L = ω(e_a, e_b), so
    cross(P(u), P(v)) = ω(e_a, e_b) ω(u, v): the hyperplane through the prefix and p
    separates the points q as the line through 0 and P(p − p_0) separates the P(q − p_0)
    in the plane (if ω(e_a, e_b) = 0, every P lies on one line through 0, so no point
    is strictly off the line and nothing is counted on a side). Each coordinate of P
    is an orientation whose last difference row is a unit vector, computed as the scan
    computes s(q), so within its coarse bound e = c_err · 2M · Σ_j |C|_j + floor (M =
    max |coordinate|; the scan's own, :func:`classify`); a point counts in an
    open octant only when every comparison clears the bounds: |x̃| > e, |ỹ| > e, and
    fl(|x̃| − |ỹ|) beyond ±2e (rounding is monotone, so fl(u) > 2e implies u > 2e)."""
    n = Y.shape[0]
    full = (1 << k) - 1
    a, b, top = 0, 1, -1.0
    for i in range(k):
        for j in range(i + 1, k):
            v = abs(mdet[full ^ (1 << i) ^ (1 << j)])
            if v > top:
                a, b, top = i, j, v
    e = max(_unit_row_orientations(Y, YT, idx, k, a, R, mdet, mper, c_err, floor, M, C,
                                   Cabs, S),
            _unit_row_orientations(Y, YT, idx, k, b, R, mdet, mper, c_err, floor, M, C,
                                   Cabs, T))
    for o in range(9):
        weight[o] = 0
    for q in range(n):
        o = _octant(S[q], T[q], e)
        octant[q] = o
        weight[o] += W[q]


@njit(cache=True, nogil=True)
def _unit_row_orientations(Y, YT, idx, k, axis, R, mdet, mper, c_err, floor, M, C, Cabs,
                           out):
    """ω(e_axis, q − p_0) for every point q into ``out`` (:func:`_prefix_octants`), as the
    scan computes orientations (:func:`_orientations`); returns their coarse error
    bound."""
    for j in range(k):
        R[k - 2, j] = 1.0 if j == axis else 0.0
    _expand_cofactors(R, k, mdet, mper, C, Cabs)
    perm = 0.0
    for j in range(k):
        perm += Cabs[j]
    _orientations(Y, YT, idx[0], C, out)
    return perm * c_err * 2.0 * M + floor


@njit(cache=True, nogil=True, inline="always")
def _octant(x, y, e):
    """The open octant (0..7 counterclockwise from the positive x axis) surely holding
    the point whose coordinates are within e of x, y; 8 if none is sure (NaN too):
    quadrant 0..3 by the signs, then the half of it by |x| against |y|."""
    big = abs(x) - abs(y)
    wide, tall = big > 2.0 * e, big < -2.0 * e
    left, low = x < -e, y < -e
    sure = (x > e or left) and (y > e or low) and (wide or tall)
    quadrant = 2 * low + (left != low)
    o = 2 * quadrant + (wide if quadrant % 2 else tall)
    return o if sure else 8


@njit(cache=True, nogil=True, inline="always")
def _both_sides_full(octant, weight, last, F):
    """The hyperplane through the prefix and point ``last`` surely has more than F
    points strictly on each side (:func:`_prefix_octants`): P(last) lies in the open
    octant o, so the open half-planes on either side of its line contain the open
    octants o + 1..o + 3 and o + 5..o + 7 (mod 8) whole."""
    o = octant[last]
    if o == 8:
        return False
    left = weight[(o + 1) % 8] + weight[(o + 2) % 8] + weight[(o + 3) % 8]
    right = weight[(o + 5) % 8] + weight[(o + 6) % 8] + weight[(o + 7) % 8]
    return left > F and right > F


#: the octant prune (:func:`_prefix_octants`) runs for a prefix shared by at least this
#: many subsets (its cost is a few subsets' scans). Measured on one thread, the bench
#: clouds: C(50, 4) subsets 27 → 15 ms at F = 1, 27 → 19 ms at F = 5, 26 → 23 ms at
#: F = 9; C(30, 5) 20 → 16–18 ms
PRUNE_MIN_RUN = 8

#: below this many subsets the scan runs on one thread (thread start-up dominates;
#: measured: 5000 saves ~10 % at d = 3, n = 50, 2000 costs ~20 % at d = 2, n = 100)
PARALLEL_MIN_SUBSETS = 5_000


#: the scan's share of work a thread takes at a time (:func:`classify`): 1/32 of the
#: subsets
CLASSIFY_CHUNKS = 32


def classify(Y, W, subsets, c_err, F, floor=0.0, workers=None):
    """For every k-subset (rows of ``subsets``): the weighted numbers of points surely
    on the + side, surely on the − side and uncertain, and whether its cofactors C
    (:func:`cofactors`) are surely zero (degenerate subset; only decided when
    c_err = 0).

    A point is first tested against the subset's coarse bound c_err · 2M · Σ|C|_j
    (M = max |coordinate|, so |q − p_0|_j ≤ 2M), and only near the hyperplane against
    the precise one (both plus ``floor``, 0 when c_err = 0). For k ≤ 3 the scan of a
    subset stops once both sides surely hold more than F points (it can then bound no
    valid halfspace), so counts above F are not exact; for k ≥ 4 every point is
    counted (:func:`_scan_all`), except for the subsets whose both sides the octants of
    their prefix already show to hold more than F points (:func:`_prefix_octants`,
    for prefixes shared by ≥ PRUNE_MIN_RUN subsets): F + 1 on each side, a lower
    bound, and none uncertain.

    On one thread for small inputs, else on ``workers`` threads (default: numba's
    thread count) that each take the next of CLASSIFY_CHUNKS ranges of subsets as they
    finish one (:func:`_classify_range`, compiled without the GIL). Each subset's
    counts depend on it alone (a range recomputes its first prefix's minors), so any
    split gives the same arrays. Taken as they come, the
    ranges keep both cores busy when another process holds one part of the time —
    numba's own parallel loop gives each thread a fixed half and waits for the slower
    (measured, cube(4, 50, 9) at load ~3.7: 60 → 40–48 ms wall, 40 → 31–35 CPU-ms)."""
    count, k = subsets.shape
    out = (np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.int64),
           np.zeros(count, dtype=np.int64), np.zeros(count, dtype=np.bool_))
    M = float(np.abs(Y).max()) if Y.size else 0.0
    YT = np.ascontiguousarray(Y.T)
    none = np.empty((0, k))
    chunks = CLASSIFY_CHUNKS if count >= PARALLEL_MIN_SUBSETS else 1

    def scan(lo: int, hi: int) -> None:
        _classify_range(Y, YT, W, subsets, c_err, F, floor, M, lo, hi, *out, none, none)

    on_threads(scan, count, chunks, workers)
    return out


def on_threads(scan, total: int, chunks: int, workers: int | None = None) -> None:
    """scan(lo, hi) over ``chunks`` consecutive ranges covering range(total), on
    ``workers`` threads (default: numba's thread count; the calling thread is one of
    them) each taking the next range when it finishes one — for compiled scans without
    the GIL whose ranges write disjoint outputs. The caller sleeps only in the final
    joins (no wake-up per range: on a loaded machine each costs a time slice). On the
    calling thread alone for one chunk or one worker. A range's exception is raised
    here (the first one, after every thread has stopped; no range starts after it)."""
    if workers is None:
        import numba

        workers = numba.get_num_threads()
    workers = min(workers, chunks)  # no thread without a range to take
    if workers <= 1:
        scan(0, total)
        return
    import threading

    # each range is taken once: next() under a lock (a list iterator's next() is atomic
    # only under the GIL, not on a free-threaded build)
    ranges = iter([(total * c // chunks, total * (c + 1) // chunks) for c in range(chunks)])
    taking = threading.Lock()
    errors: list[BaseException] = []

    def work() -> None:
        try:
            while not errors:  # another range failed: start no more
                with taking:
                    lohi = next(ranges, None)
                if lohi is None:
                    return
                scan(*lohi)
        except BaseException as exc:  # re-raised by the caller below
            errors.append(exc)

    helpers = [threading.Thread(target=work, daemon=True) for _ in range(workers - 1)]
    for t in helpers:
        t.start()
    work()
    for t in helpers:
        t.join()
    if errors:
        raise errors[0]


#: from this many subsets on, :func:`cofactors` runs on threads (8 ranges)
COFACTOR_THREADS_MIN = 20_000


def cofactors(Y, subsets):
    """The cofactors C and their permanents |C| of the subsets (rows), (count, k) each,
    exactly as the scan (:func:`classify`) computes them — only for the
    subsets the caller keeps (the scan stores none: tables of C(n, k) rows cost more
    to allocate than to fill). Many subsets: ranges of them on threads
    (:func:`on_threads`; each row is computed alone, so the split changes nothing)."""
    count, k = subsets.shape
    cof = np.empty((count, k))
    cof_abs = np.empty((count, k))
    none = np.zeros(0, dtype=np.int64)
    flags = np.zeros(0, dtype=np.bool_)
    Y = np.ascontiguousarray(Y, dtype=np.float64)
    subsets = np.ascontiguousarray(subsets)

    def scan(lo: int, hi: int) -> None:
        _classify_range(Y, Y, none, subsets, 0.0, 0, 0.0, 0.0, lo, hi, none, none, none,
                        flags, cof, cof_abs)

    on_threads(scan, count, 8 if count >= COFACTOR_THREADS_MIN else 1)
    return cof, cof_abs


@njit(cache=True)
def k_subsets(n, k, count):
    """The first ``count`` k-subsets of range(n) in lexicographic order, (count, k)."""
    subsets = np.empty((count, k), dtype=np.int32)
    idx = np.arange(k)
    for t in range(count):
        for i in range(k):
            subsets[t, i] = idx[i]
        i = k - 1
        while i >= 0 and idx[i] == n - k + i:
            i -= 1
        if i < 0:
            break
        idx[i] += 1
        for j in range(i + 1, k):
            idx[j] = idx[j - 1] + 1
    return subsets


@njit(cache=True, nogil=True, inline="always")
def _side(s, bound, c_err):
    """+1 / −1: surely on that side; 0: on the hyperplane (exact mode, c_err = 0);
    2: undecided (within the rounding bound)."""
    if s > bound:
        return 1
    if s < -bound:
        return -1
    return 0 if c_err == 0.0 else 2


@njit(cache=True, nogil=True, inline="always")
def _tally(side, w, np_, nm, nu):
    """Add weight w to the count of ``side`` (see _side)."""
    if side == 1:
        return np_ + w, nm, nu
    if side == -1:
        return np_, nm + w, nu
    if side == 2:
        return np_, nm, nu + w
    return np_, nm, nu


@njit(cache=True, nogil=True, inline="always")
def _scan3(Y, W, i0, i1, i2, C, Cabs, coarse, c_err, floor, F):
    """The point scan of _classify_range for k = 3 with scalars (the hot loop; the
    counts are accumulated without branches on the side, which is unpredictable)."""
    c0, c1, c2 = C[0], C[1], C[2]
    a0, a1, a2 = Cabs[0], Cabs[1], Cabs[2]
    x0, x1, x2 = Y[i0, 0], Y[i0, 1], Y[i0, 2]
    np_, nm, nu = 0, 0, 0
    for q in range(Y.shape[0]):
        if q == i0 or q == i1 or q == i2:
            continue
        d0 = Y[q, 0] - x0
        d1 = Y[q, 1] - x1
        d2 = Y[q, 2] - x2
        s = d0 * c0 + d1 * c1 + d2 * c2
        bound = coarse
        if c_err != 0.0 and abs(s) <= coarse:
            bound = c_err * (abs(d0) * a0 + abs(d1) * a1 + abs(d2) * a2) + floor
        pos = s > bound
        neg = s < -bound
        w = W[q]
        np_ += w * pos
        nm += w * neg
        if c_err != 0.0:
            nu += w * (not (pos or neg))
        if np_ > F and nm > F:
            break
    return np_, nm, nu


@njit(cache=True, nogil=True, inline="always")
def _scan_all(Y, YT, W, idx, C, Cabs, coarse, c_err, floor, S):
    """The point scan of _classify_range for k ≥ 4: the orientations s(q) of every
    point at once into S (:func:`_orientations`, each summed in the order j = 0..k−1,
    as the other scans), their signs against the coarse bound counted without
    branches, the subset's own points taken out again, and only the points within the
    coarse bound (or NaN) tested against their precise one. No early stop: the counts
    are exact."""
    n, k = Y.shape
    p0 = idx[0]
    _orientations(Y, YT, p0, C, S)
    np_, nm, near = _coarse_counts(S, W, coarse, 0, n)
    for i in range(k):  # the subset's own points
        a, b, e = _coarse_counts(S, W, coarse, idx[i], idx[i] + 1)
        np_, nm, near = np_ - a, nm - b, near - e
    nu = 0
    if near == 0:
        return np_, nm, nu
    for q in range(n):
        s = S[q]
        if s > coarse or s < -coarse or _member(idx, q):
            continue
        bound = 0.0
        for j in range(k):
            bound += abs(Y[q, j] - Y[p0, j]) * Cabs[j]
        np_, nm, nu = _tally(_side(s, bound * c_err + floor, c_err), W[q], np_, nm, nu)
    return np_, nm, nu


@njit(cache=True, nogil=True, inline="always")
def _orientations(Y, YT, p0, C, S):
    """s(q) = Σ_j (q − p_0)_j C_j of every point q into S, summed in the order
    j = 0..k − 1, coordinate by coordinate over the rows of YT = Yᵀ (loops the
    compiler vectorises)."""
    n, k = Y.shape
    x, c, yt = Y[p0, 0], C[0], YT[0]
    for q in range(n):
        S[q] = (yt[q] - x) * c
    for j in range(1, k):
        x, c, yt = Y[p0, j], C[j], YT[j]
        for q in range(n):
            S[q] += (yt[q] - x) * c


@njit(cache=True, nogil=True, inline="always")
def _coarse_counts(S, W, coarse, lo, hi):
    """Weighted numbers of the points lo ≤ q < hi with S[q] > coarse and S[q] < −coarse,
    and the number of the others (within the bound, or NaN)."""
    np_, nm, near = 0, 0, 0
    for q in range(lo, hi):
        s = S[q]
        pos = s > coarse
        neg = s < -coarse
        w = W[q]
        np_ += w * pos
        nm += w * neg
        near += 1 - pos - neg
    return np_, nm, near


@njit(cache=True, nogil=True, inline="always")
def _member(idx, q):
    for i in range(idx.shape[0]):
        if idx[i] == q:
            return True
    return False


@njit(cache=True, nogil=True)
def _classify_range(Y, YT, W, subsets, c_err, F, floor, M, t0, t1,
                    plus, minus, unc, degenerate, cof, cof_abs):
    """classify for rows t0 ≤ t < t1 (written into the output arrays) — or,
    when ``cof`` has rows, only the subsets' cofactors and permanents, into cof and
    cof_abs (:func:`cofactors`: the same code computes them)."""
    n, k = Y.shape
    C = np.empty(k)
    Cabs = np.empty(k)
    # k ≥ 4: the difference rows (the current prefix's, then the subset's last), the
    # prefix's minors and their permanents (by column bitmask), and its points
    R = np.empty((max(k - 1, 1), k))
    mdet = np.empty(1 << k)
    mper = np.empty(1 << k)
    prefix = np.full(max(k - 1, 1), -1)
    S = np.empty(n)
    # k ≥ 4: the prefix's octants (:func:`_prefix_octants`), in the counting pass
    T = np.empty(n)
    octant = np.empty(n, dtype=np.int64)
    weight = np.zeros(9, dtype=np.int64)
    counting = len(cof) == 0
    pruning = False
    for t in range(t0, t1):
        idx = subsets[t]
        if k >= 4:
            same = True
            for i in range(k - 1):
                same = same and prefix[i] == idx[i]
            if not same:
                _prefix_minors(Y, idx, k, R, mdet, mper)
                for i in range(k - 1):
                    prefix[i] = idx[i]
                # the octants pay when many subsets share the prefix: its run in
                # lexicographic order ends with the last point n − 1
                pruning = counting and n - 1 - idx[k - 2] >= PRUNE_MIN_RUN
                if pruning:
                    _prefix_octants(Y, YT, idx, k, R, mdet, mper, c_err, floor, M, C, Cabs,
                                    S, T, octant, weight, W)
            if pruning and _both_sides_full(octant, weight, idx[k - 1], F):
                plus[t], minus[t] = F + 1, F + 1  # lower bounds: the subset is not valid
                continue
            _last_row_cofactors(Y, idx, k, R, mdet, mper, C, Cabs)
        elif k > 1:
            _cofactors(Y, idx, k, C, Cabs)
        else:
            C[0] = 1.0
            Cabs[0] = 1.0
        if len(cof):
            for j in range(k):
                cof[t, j] = C[j]
                cof_abs[t, j] = Cabs[j]
            continue
        zero = True
        coarse = 0.0
        for j in range(k):
            coarse += Cabs[j]
            if C[j] != 0.0:
                zero = False
        coarse = coarse * c_err * 2.0 * M + floor
        if zero and c_err == 0.0:
            degenerate[t] = True
            continue
        p0 = idx[0]
        if k >= 3:
            plus[t], minus[t], unc[t] = (
                _scan_all(Y, YT, W, idx, C, Cabs, coarse, c_err, floor, S) if k >= 4
                else _scan3(Y, W, idx[0], idx[1], idx[2], C, Cabs, coarse, c_err, floor, F))
            continue
        np_, nm, nu = 0, 0, 0
        for q in range(n):
            if _member(idx, q):
                continue
            s = 0.0
            for j in range(k):
                s += (Y[q, j] - Y[p0, j]) * C[j]
            if abs(s) <= coarse:
                bound = 0.0
                for j in range(k):
                    bound += abs(Y[q, j] - Y[p0, j]) * Cabs[j]
                bound = bound * c_err + floor
            else:
                bound = coarse
            np_, nm, nu = _tally(_side(s, bound, c_err), W[q], np_, nm, nu)
            if np_ > F and nm > F:
                break
        plus[t] = np_
        minus[t] = nm
        unc[t] = nu


#: angle error bound of atan2 on a correctly rounded difference vector (radians):
#: the difference has relative error ≤ ε per component (≤ √2 ε in direction), atan2
#: a few ulps of π; 64 ε is a wide margin.
ANGLE_ERR = 64.0 * UNIT_ROUNDOFF * np.pi


def sweep_pairs_2d(Y, W, subsets):
    """Side counts of the lines through every pair (rows of ``subsets``, i < j) of
    distinct points in the plane by an angular sweep around each point, O(n² log n).

    For the directed line i → j, + is the left side (the sign of the cofactor
    normal (−Δy, Δx)). A point whose angle around i is within 2·ANGLE_ERR of the
    line's two directions is counted as uncertain (decided exactly later); the others
    are certainly on their side, since each float angle is within ANGLE_ERR of the
    true one. The points i are swept in ranges on threads (:func:`on_threads`: each
    writes only the rows of its own pairs (i, ·), so any split gives the same arrays)."""
    n = Y.shape[0]
    count = subsets.shape[0]
    plus = np.zeros(count, dtype=np.int64)
    minus = np.zeros(count, dtype=np.int64)
    unc = np.zeros(count, dtype=np.int64)
    # row offset of the pairs (i, ·): pairs are in lexicographic order
    start = np.zeros(n + 1, dtype=np.int64)
    start[1:] = np.cumsum(np.arange(n - 1, -1, -1))

    def scan(lo: int, hi: int) -> None:
        _sweep_points(Y, W, start, lo, hi, plus, minus, unc)

    on_threads(scan, max(n - 1, 0), 64 if count >= PARALLEL_MIN_SUBSETS else 1)
    return plus, minus, unc, np.zeros(count, dtype=np.bool_)


@njit(cache=True, nogil=True)
def _sweep_points(Y, W, start, i0, i1, plus, minus, unc):
    """:func:`sweep_pairs_2d` around the points i0 ≤ i < i1 (the rows of their pairs
    (i, j), j > i)."""
    n = Y.shape[0]
    two_pi = 2.0 * np.pi
    tol = 2.0 * ANGLE_ERR
    for i in range(i0, i1):
        m = n - 1
        ang = np.empty(m)
        wts = np.empty(m, dtype=np.int64)
        others = np.empty(m, dtype=np.int64)
        c = 0
        for q in range(n):
            if q != i:
                ang[c] = np.arctan2(Y[q, 1] - Y[i, 1], Y[q, 0] - Y[i, 0])
                wts[c] = W[q]
                others[c] = q
                c += 1
        order = np.argsort(ang)
        a2 = np.empty(2 * m)
        cw = np.zeros(2 * m + 1, dtype=np.int64)
        for t in range(m):
            a2[t] = ang[order[t]]
            a2[t + m] = ang[order[t]] + two_pi
        for t in range(2 * m):
            cw[t + 1] = cw[t] + wts[order[t % m]]
        for t in range(m):
            j = others[t]
            if j <= i:
                continue
            th = ang[t]
            # window sums over (lo, hi] of the doubled, sorted angles
            a = np.searchsorted(a2, th + tol, side="right")
            b = np.searchsorted(a2, th + np.pi - tol, side="left")
            cc = np.searchsorted(a2, th + np.pi + tol, side="right")
            e = np.searchsorted(a2, th + two_pi - tol, side="left")
            left = cw[b] - cw[a] if b > a else 0
            right = cw[e] - cw[cc] if e > cc else 0
            total = cw[m]
            row = start[i] + (j - i - 1)
            plus[row] = left
            minus[row] = right
            # everything else but j itself is uncertain
            unc[row] = total - left - right - W[j]


def ball_chunks(V: np.ndarray, leaf: int = 32
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The rows of V grouped into chunks of ≤ ``leaf`` nearby points (a k-d split at the
    median of the widest coordinate, :func:`_kd_split`): (order, starts, centres,
    radii) — chunk c is V[order[starts[c]:starts[c+1]]], within ``radii[c]`` (the
    float max of ‖v − centre‖: a few ulps from the exact one where the squares do not
    underflow, else up to √k·2^-537 below it — :func:`_chunk_top` allows for both) of
    ``centres[c]`` (its mean)."""
    order = np.arange(len(V))
    cuts = np.empty(len(V) + 1, dtype=np.int64)
    count = _kd_split(np.ascontiguousarray(V, dtype=np.float64), leaf, order, cuts)
    starts = np.append(np.sort(cuts[:count]), len(V))
    W = V[order]
    counts = np.diff(starts)
    centres = np.add.reduceat(W, starts[:-1], axis=0) / counts[:, None]
    gap = ((W - np.repeat(centres, counts, axis=0)) ** 2).sum(axis=1)
    radii = np.sqrt(np.maximum.reduceat(gap, starts[:-1]))
    return order, starts, centres, radii


@njit(cache=True)
def _kd_split(V, leaf, order, cuts):
    """Reorder ``order`` (in place) so that runs of ≤ ``leaf`` rows of V are the leaves
    of a k-d tree — each node's rows split in halves at the median of their widest
    coordinate — and write the leaves' starts into ``cuts``; returns their number."""
    n, k = V.shape
    if n == 0:
        return 0
    stack = np.empty((128, 2), dtype=np.int64)  # depth-first: ≤ 2 log2(n) pending nodes
    stack[0, 0], stack[0, 1] = 0, n
    top, count = 1, 0
    while top > 0:
        top -= 1
        lo, hi = stack[top, 0], stack[top, 1]
        if hi - lo <= leaf:
            cuts[count] = lo
            count += 1
            continue
        widest, span = 0, -1.0
        for j in range(k):
            small, large = np.inf, -np.inf
            for t in range(lo, hi):
                v = V[order[t], j]
                small = min(small, v)
                large = max(large, v)
            if large - small > span:
                widest, span = j, large - small
        mid = lo + (hi - lo) // 2
        _select(V[:, widest], order, lo, hi, mid)
        stack[top, 0], stack[top, 1] = lo, mid
        stack[top + 1, 0], stack[top + 1, 1] = mid, hi
        top += 2
    return count


@njit(cache=True, nogil=True)
def _select(key, order, lo, hi, mid):
    """Permute order[lo:hi] so that key[order[mid]] is the value of rank mid − lo among
    them, none after it smaller and none before it larger (Hoare's selection)."""
    while hi - lo > 1:
        pivot = key[order[(lo + hi) // 2]]
        i, j = lo, hi - 1
        while i <= j:
            while key[order[i]] < pivot:
                i += 1
            while key[order[j]] > pivot:
                j -= 1
            if i <= j:
                order[i], order[j] = order[j], order[i]
                i += 1
                j -= 1
        if mid <= j:
            hi = j + 1
        elif mid >= i:
            lo = i
        else:
            return


@njit(cache=True, nogil=True, inline="always")
def _chunk_top(A, b, h, centres, radii, norm, c, floor):
    """An upper bound on a_h·v − b_h over the ball of chunk c (the exact value of
    a·centre − b + ‖a‖ r, plus 1e-6 of its terms' magnitudes — far above the
    rounding of these few operations and of ‖a‖, r — and the underflow term).
    ‖a‖ and r are square roots of float sums of k squares, each square off by up to
    2^-1075 where it underflows (offsets ≲ 1e-154: r came out 0 for a cluster of
    points ~1e-170): as √(x + y) ≤ √x + √y, the true values lie within
    e = √k · 2^-537 of the float ones, so (‖a‖ + e)(r + e) bounds the reach."""
    k = A.shape[1]
    s = 0.0
    mag = 0.0
    for j in range(k):
        s += A[h, j] * centres[c, j]
        mag += abs(A[h, j] * centres[c, j])
    e = np.sqrt(k) * 2.0**-537
    reach = (norm + e) * (radii[c] + e)
    return s - b[h] + reach + 1e-6 * (mag + abs(b[h]) + reach) + floor


@njit(cache=True, nogil=True)
def _chunked_max_range(A, b, W, starts, centres, radii, groups, g_centres, g_radii, norms,
                       floor, h0, h1, out):
    k = A.shape[1]
    for h in range(h0, h1):
        best = -np.inf
        for g in range(len(groups) - 1):
            top = _chunk_top(A, b, h, g_centres, g_radii, norms[h], g, floor)
            if top < 0.0:  # the whole group's ball is below: its bound will do
                best = max(best, top)
                continue
            for c in range(groups[g], groups[g + 1]):
                top = _chunk_top(A, b, h, centres, radii, norms[h], c, floor)
                if top < 0.0:  # the whole ball is below: its bound will do
                    best = max(best, top)
                    continue
                for v in range(starts[c], starts[c + 1]):
                    s = 0.0
                    for j in range(k):
                        s += A[h, j] * W[v, j]
                    best = max(best, s - b[h])
        out[h] = best


#: row_top groups this many consecutive chunks (neighbours in the k-d tree) under one
#: ball, tested first
GROUP_CHUNKS = 8


def ball_groups(W: np.ndarray, starts: np.ndarray, per: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Runs of ``per`` consecutive chunks (:func:`ball_chunks`; W: the points in chunk
    order) as balls: (groups, centres, radii) — group g is chunks groups[g] to
    groups[g + 1] − 1, its points within ``radii[g]`` (the float max of ‖v − centre‖,
    as for the chunks) of ``centres[g]`` (their mean)."""
    groups = np.append(np.arange(0, len(starts) - 1, per), len(starts) - 1)
    first = starts[groups]
    counts = np.diff(first)
    centres = np.add.reduceat(W, first[:-1], axis=0) / counts[:, None]
    gap = ((W - np.repeat(centres, counts, axis=0)) ** 2).sum(axis=1)
    return groups, centres, np.sqrt(np.maximum.reduceat(gap, first[:-1]))


def row_top(A: np.ndarray, b: np.ndarray, V: np.ndarray, floor: float,
            parallel: bool = True) -> np.ndarray:
    """Per row h an upper bound on max_v a_h·v − b_h over the float points V, which is
    the maximum itself (evaluated in floats) wherever that may be ≥ 0: groups of
    chunks (:func:`ball_groups`), then chunks of V (:func:`ball_chunks`) whose ball
    lies surely below the hyperplane contribute their ball's bound, the others their
    points' values. ``floor``: the underflow
    term of these products. ``parallel``: for large inputs on threads taking 64 ranges
    of rows as they come (:func:`on_threads`); False: on the calling thread only,
    without the GIL (for a caller that works meanwhile). Where k · max|A| · max|V| + max|b|
    is not below 1e307 (or not finite) a value may overflow — inf − inf is NaN, which
    max drops — and every row gets +inf instead (the fast path's data, |v| ≤ 2^32,
    never come near)."""
    big = (A.shape[1] * float(np.abs(A).max(initial=0.0)) * float(np.abs(V).max(initial=0.0))
           + float(np.abs(b).max(initial=0.0)))
    if len(V) and not big < 1e307:
        return np.full(A.shape[0], np.inf)
    order, starts, centres, radii = ball_chunks(V)
    W = np.ascontiguousarray(V[order])
    A = np.ascontiguousarray(A)
    b = np.ascontiguousarray(b)
    norms = np.sqrt((A**2).sum(axis=1))
    out = np.empty(A.shape[0])
    balls = (starts, centres, radii, *ball_groups(W, starts, GROUP_CHUNKS), norms, floor)
    def scan(lo: int, hi: int) -> None:
        _chunked_max_range(A, b, W, *balls, lo, hi, out)

    on_threads(scan, A.shape[0], 64 if parallel and A.shape[0] * (len(starts) - 1) >= 20_000
               else 1)
    return out


@njit(cache=True, nogil=True)
def _near_range(A, b, A_abs, b_abs, W, starts, centres, radii, norms, coarse, c_err, c,
                floor, h0, h1, fill, offsets, out_r, out_v, first):
    """Rows h0 ≤ h < h1 of :func:`near_pairs`: with ``fill`` False, count each row's
    near pairs into offsets[h] (−1: a pair surely violated) and keep the points of its
    first ones in first[h] (as many as fit); with ``fill`` True, write the pairs of the
    rows with offsets[h] ≥ 0 from offsets[h] on (the others are skipped)."""
    k = A.shape[1]
    keep = first.shape[1]
    for h in range(h0, h1):
        if fill and offsets[h] < 0:
            continue
        at = offsets[h] if fill else 0
        for cc in range(len(starts) - 1):
            if _chunk_top(A, b, h, centres, radii, norms[h], cc, floor) < -coarse[h]:
                continue  # every point of the chunk surely satisfies row h
            for v in range(starts[cc], starts[cc + 1]):
                s = 0.0
                for j in range(k):
                    s += A[h, j] * W[v, j]
                s -= b[h]
                if s > coarse[h]:
                    at = -1
                    break
                if abs(s) > coarse[h]:
                    continue
                perm = 0.0
                mag = 0.0
                for j in range(k):
                    perm += A_abs[h, j] * abs(W[v, j])
                    mag += abs(A[h, j] * W[v, j])
                bound = c_err * (perm + b_abs[h]) + c * (mag + abs(b[h])) + floor
                if s > bound:
                    at = -1
                    break
                if not abs(s) > bound:  # NaN stays undecided
                    if fill:
                        out_r[at] = h
                        out_v[at] = v
                    elif at < keep:
                        first[h, at] = v
                    at += 1
            if at < 0:
                break
        if not fill:
            offsets[h] = at


def near_pairs(A, b, A_abs, b_abs, V, coarse, c_err: float, c: float, floor: float
               ) -> tuple[np.ndarray, np.ndarray] | None:
    """The pairs (row, point of V) whose float slack s = a·v − b lies within its
    rounding bound c_err (A_abs·|v| + b_abs) + c (|a|·|v| + |b|) + floor of 0, or None
    if some s surely exceeds it (> 0 exactly). ``coarse[h]`` bounds that bound for every
    point, so only the pairs with |s| ≤ coarse get their own, and chunks of V whose
    ball lies more than coarse below row h are skipped whole. NaN stays undecided."""
    order, starts, centres, radii = ball_chunks(V)
    W = np.ascontiguousarray(V[order])
    args = [np.ascontiguousarray(x) for x in (A, b, A_abs, b_abs)]
    norms = np.sqrt((args[0] ** 2).sum(axis=1))
    common = (*args, W, starts, centres, radii, norms, np.ascontiguousarray(coarse), c_err,
              c, floor)
    parallel = len(b) * (len(starts) - 1) >= 20_000
    counts = np.zeros(len(b), dtype=np.int64)
    first = np.empty((len(b), NEAR_KEPT), dtype=np.int64)
    none = np.zeros(0, dtype=np.int64)
    _near_run(common, parallel, False, counts, none, none, first)
    if (counts < 0).any():
        return None
    offsets = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    out_r = np.repeat(np.arange(len(b), dtype=np.int64), counts)
    out_v = np.empty_like(out_r)
    _kept_pairs(counts, offsets, first, out_v)
    if (counts > NEAR_KEPT).any():  # only those rows again, writing every pair
        _near_run(common, parallel, True, np.where(counts > NEAR_KEPT, offsets, -1), out_r,
                  out_v, first)
    return out_r, order[out_v]


#: near_pairs keeps this many pairs per row from its counting pass; rows with more are
#: scanned again (d = 4, n = 50: at most ~90; d = 5: up to ~580 — of sphere(5, 30, 3)'s
#: 857 defining rows 35 are scanned twice, 328 when 96 were kept)
NEAR_KEPT = 256


@njit(cache=True, nogil=True)
def _kept_pairs(counts, offsets, first, out_v):
    """The points of the rows whose near pairs the counting pass kept whole (counts[h]
    ≤ NEAR_KEPT; first[h, :counts[h]]) into out_v from offsets[h] on."""
    keep = first.shape[1]
    for h in range(len(counts)):
        if 0 < counts[h] <= keep:
            for i in range(counts[h]):
                out_v[offsets[h] + i] = first[h, i]


def _near_run(common: tuple, parallel: bool, fill: bool, offsets, out_r, out_v, first
              ) -> None:
    """One pass of :func:`near_pairs` over every row (for large inputs on threads taking
    64 ranges of rows as they come: :func:`on_threads`)."""
    def scan(lo: int, hi: int) -> None:
        _near_range(*common, lo, hi, fill, offsets, out_r, out_v, first)

    on_threads(scan, len(offsets), 64 if parallel else 1)


@njit(cache=True, nogil=True, inline="always")
def _pair_bound(A, b, A_abs, b_abs, V, h, v, c_err, c, floor):
    """The rounding bound of the float slack of (row h, point v), as in :func:`_near_range`."""
    perm = 0.0
    mag = 0.0
    for j in range(A.shape[1]):
        perm += A_abs[h, j] * abs(V[v, j])
        mag += abs(A[h, j] * V[v, j])
    return c_err * (perm + b_abs[h]) + c * (mag + abs(b[h])) + floor


@njit(cache=True, nogil=True, inline="always")
def _slack(A, b, V, h, v):
    s = 0.0
    for j in range(A.shape[1]):
        s += A[h, j] * V[v, j]
    return s - b[h]


@njit(cache=True, nogil=True)
def _walk_range(A, b, A_abs, b_abs, V, ptr, nbr, seeds, c_err, c, floor, tiny, h0, h1, out):
    """Rows h0 ≤ h < h1 of :func:`graph_top` (``tiny``: its WALK_TINY, an argument so
    that it is read at call time, not frozen into the compiled code)."""
    last = seeds[0]
    for h in range(h0, h1):
        cur = last  # the previous row's end: neighbouring rows often share data points
        best = _slack(A, b, V, h, cur)
        for i in range(len(seeds)):
            s = _slack(A, b, V, h, seeds[i])
            if s > best:
                best, cur = s, seeds[i]
        while True:  # steepest ascent: the float values increase strictly, so it ends
            nxt = -1
            for p in range(ptr[cur], ptr[cur + 1]):
                s = _slack(A, b, V, h, nbr[p])
                if s > best:
                    best, nxt = s, nbr[p]
            if nxt < 0:
                break
            cur = nxt
        own = _pair_bound(A, b, A_abs, b_abs, V, h, cur, c_err, c, floor)
        ok = True
        for p in range(ptr[cur], ptr[cur + 1]):
            u = nbr[p]
            drop = best - _slack(A, b, V, h, u)
            need = own + _pair_bound(A, b, A_abs, b_abs, V, h, u, c_err, c, floor)
            if not (need < np.inf and drop < np.inf):  # NaN or inf: nothing proven
                ok = False
                break
            # drop ≥ max(need, tiny) (1 + 4ε): the real s_h(v*) − s_h(u) ≥ e_h(v*) +
            # e_h(u) (see graph_top)
            if not drop >= max(need, tiny) * (1.0 + 4.0 * UNIT_ROUNDOFF):
                ok = False
                break
        out[h] = best if ok else np.inf
        last = cur


#: :func:`graph_top`'s final comparisons raise a smaller bound to this normal float (a
#: larger bound only makes them stricter; it keeps the product by 1 + 4ε relative)
WALK_TINY = 2.0**-1000
#: :func:`graph_top` starts each row's walk from the best of this many vertices spread
#: over the polytope (those extreme along each coordinate, then evenly spaced ones)
WALK_SEEDS = 8
#: from this many rows on, :func:`graph_top` runs on threads (16 ranges)
WALK_THREADS_MIN = 4_000


def graph_top(A, b, A_abs, b_abs, V, ptr, nbr, c_err: float, c: float, floor: float
              ) -> np.ndarray:
    """Per row h a float t_h with max_v g_h(v) ≤ t_h + e_h(v*) for some vertex v* of the
    polytope P, or t_h = +inf where the walk proves nothing. g_h is the exact affine
    function the row's floats a_h, b_h approximate: the float slack s_h(v) = a_h·v − b_h
    at a vertex's float v (row of V) is within e_h(v) = c_err (A_abs·|v| + b_abs) +
    c (|a|·|v| + |b|) + floor of g_h at the exact vertex (the bound :func:`near_pairs`
    decides on). ``ptr``, ``nbr``: P's graph in CSR form (v's neighbours nbr[ptr[v]:
    ptr[v + 1]]), which must be complete — every edge of P listed at both ends.

    Each row starts at the best of a few seeds (the vertices extreme along each
    coordinate, evenly spaced ones, and the previous row's end — neighbouring rows
    often share data points) and walks to the neighbour of largest float slack while
    one is larger (steepest ascent; the float values increase strictly, so the walk
    ends) — floats only guide it. At its end v* the row gets t_h = s_h(v*) when
    the real s_h(v*) − s_h(u) ≥ e_h(v*) + e_h(u) for every neighbour u, so g_h(u) ≤
    g_h(v*). In floats (e_h's as computed, the bound :func:`near_pairs` decides on):
    d = fl(s_h(v*) − s_h(u)) and E = max(fl(e_h(v*) + e_h(u)), WALK_TINY) are within a
    factor 1 ± ε of the reals (a sum or difference of floats rounds relatively, also
    below the normal range), and fl(E (1 + 4ε)) ≥ E (1 + 4ε)(1 − ε) ≥ E (1 + ε)/(1 − ε)
    (E normal), so d ≥ fl(E (1 + 4ε)) with d and E finite proves it (NaN or inf fails:
    t_h = +inf). Then g_h ≤ g_h(v*) on P:
    P = conv(vertices) lies in v* + its tangent cone at v*, which the edge directions
    u − v* generate (a polytope's cone at a vertex is spanned by its edges), and
    g_h − g_h(v*) is ≤ 0 on each of them. Hence max g_h = g_h(v*) ≤ t_h + e_h(v*):
    the caller's per-row bound of e_h over P (its ``coarse``) turns t_h into a
    certificate that row h is slack at every vertex (t_h < −coarse_h) or not."""
    n, k = V.shape
    out = np.full(len(b), np.inf)
    if not n:
        return out
    V = np.ascontiguousarray(V, dtype=np.float64)
    spread = np.linspace(0, n - 1, max(WALK_SEEDS - 2 * k, 1)).astype(np.int64)
    seeds = np.unique(np.concatenate([V.argmax(axis=0), V.argmin(axis=0), spread]))
    args = [np.ascontiguousarray(x) for x in (A, b, A_abs, b_abs)]
    tiny = float(WALK_TINY)

    def scan(lo: int, hi: int) -> None:
        _walk_range(*args, V, ptr, nbr, seeds, c_err, c, floor, tiny, lo, hi, out)

    on_threads(scan, len(b), 16 if len(b) >= WALK_THREADS_MIN else 1)
    return out
