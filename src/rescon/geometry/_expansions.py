"""Exact signs of planar predicates on float data, by floating-point expansions.

An expansion is a list of doubles whose exact sum is the value represented, kept
nonoverlapping and in increasing magnitude (Shewchuk, "Adaptive precision
floating-point arithmetic and fast robust geometric predicates", 1997), so its sign is
the sign of its last component. Sums and products of doubles are exact as two-term
expansions (``two_sum``, ``two_prod``); a sum of many terms is compressed by
grow-expansion with zero elimination. No rounding ever decides a sign here — these
are the fallbacks the float filters of :mod:`._small2d` call when they cannot decide.

Lines are given by a base point b (two doubles) and a direction u whose components
are two-term expansions (the exact difference of two data points, or a unit vector).

Exact as long as no product underflows or overflows: for nonzero |coordinates| in
[2^-120, 2^120] (the planar path checks this and declines other sets); subnormal
inputs can make a sign wrong.
"""

from __future__ import annotations

import numpy as np
from numba import njit
from numba.extending import register_jitable

from .._rounding import MIN_NORMAL
from .._rounding import UNIT_ROUNDOFF as EPS
from ._scan_np import HUGE, TINY

#: Dekker's splitter for doubles: 2^27 + 1
_SPLITTER = 134217729.0
#: what :func:`side_of_meet` returns for parallel lines
PARALLEL = 2
#: the decorator of a kernel called from other kernels: compiled when a kernel uses it,
#: without the Python- and C-callable wrappers of an njit function (a third of a small
#: kernel's compile time) and typed with plain int64 for literal arguments (no second
#: specialisation); called from Python it runs as Python
inner_kernel = register_jitable(cache=True, no_cfunc_wrapper=True)
#: nonzero |coordinates| must lie in [TINY, HUGE] for the predicates here to be exact
#: (defined with the numpy twins of :mod:`._scan_np`, which check the same range)


@njit(cache=True, nogil=True)
def in_range(Y):
    """Every nonzero |coordinate| in [TINY, HUGE]."""
    for v in Y.ravel():
        a = abs(v)
        if a != 0.0 and not TINY <= a <= HUGE:
            return False
    return True


@inner_kernel
def two_sum(a, b):
    """a + b = x + y exactly (Knuth)."""
    x = a + b
    bv = x - a
    av = x - bv
    return x, (a - av) + (b - bv)


@inner_kernel
def two_prod(a, b):
    """a · b = x + y exactly (Dekker)."""
    x = a * b
    c = _SPLITTER * a
    ahi = c - (c - a)
    alo = a - ahi
    c = _SPLITTER * b
    bhi = c - (c - b)
    blo = b - bhi
    return x, alo * blo - (((x - ahi * bhi) - alo * bhi) - ahi * blo)


@inner_kernel
def compress(e, n):
    """Sum the terms e[:n] into a nonoverlapping expansion, in place; returns its length."""
    h = 0
    for t in range(n):
        q = e[t]
        k = 0
        for r in range(h):
            q, lo = two_sum(q, e[r])
            if lo != 0.0:
                e[k] = lo
                k += 1
        if q != 0.0:
            e[k] = q
            k += 1
        h = k
    return h


@inner_kernel
def sign(e, n):
    """Sign of an expansion of length n (its largest component)."""
    if n == 0:
        return 0
    return 1 if e[n - 1] > 0 else -1


@inner_kernel
def product(e, ne, f, nf, out):
    """e · f exactly into out (room for 2·ne·nf terms); returns the length."""
    k = 0
    for i in range(ne):
        for j in range(nf):
            out[k], out[k + 1] = two_prod(e[i], f[j])
            k += 2
    return compress(out, k)


@njit(cache=True, nogil=True)
def difference(a, b, out):
    """a − b exactly as a two-term expansion into out[0:2] (increasing magnitude)."""
    x, y = two_sum(a, -b)
    out[0] = y
    out[1] = x


@inner_kernel
def cross(u, w, out):
    """u₀w₁ − u₁w₀ exactly, for vectors with two-term components (u[k, 0:2]); out needs
    16 slots. Returns the length."""
    k = 0
    for a in range(2):
        for b in range(2):
            out[k], out[k + 1] = two_prod(u[0, a], w[1, b])
            x, y = two_prod(u[1, a], w[0, b])
            out[k + 2], out[k + 3] = -x, -y
            k += 4
    return compress(out, k)


@njit(cache=True, nogil=True)
def orient(ax, ay, bx, by, cx, cy):
    """Exact sign of (b − a) × (c − a)."""
    u = np.empty((2, 2))
    w = np.empty((2, 2))
    difference(bx, ax, u[0])
    difference(by, ay, u[1])
    difference(cx, ax, w[0])
    difference(cy, ay, w[1])
    out = np.empty(16)
    return sign(out, cross(u, w, out))


@njit(cache=True, nogil=True)
def side_of_meet(b1, u1, b2, u2, b5, u5):
    """Exact sign of u5 × (v − b5) at v = the meeting point of the lines (b1, u1) and
    (b2, u2), which must not be parallel.

    With v = b1 + t u1, t = ((b2 − b1) × u2) / (u1 × u2): the sign of
    D·(u5 × (b1 − b5)) + N·(u5 × u1), times the sign of D = u1 × u2, N = (b2 − b1) × u2.
    Returns PARALLEL when u1 × u2 = 0 (there is no meeting point)."""
    t1 = np.empty((2, 2))
    t2 = np.empty((2, 2))
    D = np.empty(16)
    nD = cross(u1, u2, D)
    if nD == 0:
        return PARALLEL
    difference(b2[0], b1[0], t1[0])
    difference(b2[1], b1[1], t1[1])
    N = np.empty(16)
    nN = cross(t1, u2, N)
    difference(b1[0], b5[0], t2[0])
    difference(b1[1], b5[1], t2[1])
    A = np.empty(16)
    nA = cross(u5, t2, A)
    B = np.empty(16)
    nB = cross(u5, u1, B)
    S = np.empty(1024)
    n1 = product(D, nD, A, nA, S)
    n2 = product(N, nN, B, nB, S[n1:])
    return sign(S, compress(S, n1 + n2)) * sign(D, nD)


@inner_kernel
def _normal3(Y, i, j, k, C, nC):
    """The cofactors of (p_j − p_i, p_k − p_i) — the normal (p_j − p_i) × (p_k − p_i)
    — exactly, as three expansions C[c, :nC[c]] (16 slots each)."""
    u = np.empty((3, 2))
    w = np.empty((3, 2))
    for c in range(3):
        difference(Y[j, c], Y[i, c], u[c])
        difference(Y[k, c], Y[i, c], w[c])
    pair_u = np.empty((2, 2))
    pair_w = np.empty((2, 2))
    for c in range(3):  # component c from the other two coordinates, cyclically
        a, b = (c + 1) % 3, (c + 2) % 3
        pair_u[0], pair_u[1] = u[a], u[b]
        pair_w[0], pair_w[1] = w[a], w[b]
        nC[c] = cross(pair_u, pair_w, C[c])


@inner_kernel
def _orient3(Y, i, j, k, q, S):
    """((p_j − p_i) × (p_k − p_i)) · (p_q − p_i) exactly, as an expansion in S (192
    slots); returns its length."""
    C = np.empty((3, 16))
    nC = np.empty(3, dtype=np.int64)
    _normal3(Y, i, j, k, C, nC)
    d = np.empty(2)
    n = 0
    for c in range(3):
        difference(Y[q, c], Y[i, c], d)
        n += product(C[c], nC[c], d, 2, S[n:])
    return compress(S, n)


@inner_kernel
def orient3(Y, i, j, k, q):
    """Exact sign of ((p_j − p_i) × (p_k − p_i)) · (p_q − p_i) for rows of Y."""
    S = np.empty(3 * 2 * 2 * 16)
    return sign(S, _orient3(Y, i, j, k, q, S))


@inner_kernel
def det3(Y, i, j, k, q):
    """((p_j − p_i) × (p_k − p_i)) · (p_q − p_i), its exact value rounded (within 3
    ulps; 0 only when it is 0)."""
    S = np.empty(3 * 2 * 2 * 16)
    return approximate(S, _orient3(Y, i, j, k, q, S))


@inner_kernel
def exact_mean(Y, mean, err):
    """The mean of the rows of Y per coordinate: the exact sum (an expansion) rounded,
    then divided by the row count, into mean; err bounds |mean − exact mean| (2 ulps
    from the two roundings, plus the smallest normal for an underflowing quotient)."""
    lo = np.empty(Y.shape[1])
    mean_two(Y, mean, lo, np.empty(Y.shape[1]))
    for c in range(Y.shape[1]):
        err[c] = 4.0 * EPS * abs(mean[c]) + MIN_NORMAL


@inner_kernel
def mean_two(Y, hi, lo, err):
    """The mean of the rows of Y as two doubles per coordinate: hi = fl(fl(Σ)/m) as in
    exact_mean, lo = the rest (Σ − m·hi, exact as an expansion, rounded, over m);
    err bounds |hi + lo − exact mean| (4 ulps of lo, plus the smallest normal)."""
    m = Y.shape[0]
    e = np.empty(m + 2)
    for c in range(Y.shape[1]):
        for q in range(m):
            e[q] = Y[q, c]
        n = compress(e, m)
        hi[c] = approximate(e, n) / m
        p, r = two_prod(float(m), hi[c])
        e[n], e[n + 1] = -p, -r
        lo[c] = approximate(e, compress(e, n + 2)) / m
        err[c] = 4.0 * EPS * abs(lo[c]) + MIN_NORMAL


@inner_kernel
def approximate(e, n):
    """The value of an expansion, rounded (summed from its smallest component)."""
    s = 0.0
    for t in range(n):
        s += e[t]
    return s


@inner_kernel
def normal3(Y, i, j, k, out):
    """The normal (p_j − p_i) × (p_k − p_i), each component its exact value rounded
    (within 3 ulps, however close to collinear the triple is; exactly 0 only when the
    component is), into out."""
    C = np.empty((3, 16))
    nC = np.empty(3, dtype=np.int64)
    _normal3(Y, i, j, k, C, nC)
    for c in range(3):
        out[c] = approximate(C[c], nC[c])


@njit(cache=True, nogil=True)
def normals3(Y, subsets, out):
    """normal3 for each triple of ``subsets``, into the rows of out."""
    for t in range(subsets.shape[0]):
        normal3(Y, subsets[t, 0], subsets[t, 1], subsets[t, 2], out[t])


@njit(cache=True, nogil=True)
def _side_counts_range(Y, W, subsets, F, t0, t1, plus, minus, degenerate):
    """side_counts for the subsets t0 ≤ t < t1."""
    k = Y.shape[1]
    C = np.empty((3, 16))
    nC = np.zeros(3, dtype=np.int64)
    d = np.empty(2)
    a = np.empty(3)
    S = np.empty(3 * 2 * 2 * 16)
    for t in range(t0, t1):
        i = subsets[t, 0]
        plus[t] = 0
        minus[t] = 0
        if k == 3:
            _normal3(Y, i, subsets[t, 1], subsets[t, 2], C, nC)
        else:  # the normal (−(y_j − y_i), x_j − x_i)
            j = subsets[t, 1]
            difference(Y[i, 1], Y[j, 1], C[0])
            difference(Y[j, 0], Y[i, 0], C[1])
            nC[0] = compress(C[0], 2)
            nC[1] = compress(C[1], 2)
        degenerate[t] = True
        for c in range(k):
            a[c] = approximate(C[c], nC[c])
            degenerate[t] = degenerate[t] and nC[c] == 0
        if degenerate[t]:
            continue
        for q in range(Y.shape[0]):
            member = False
            for r in range(k):
                if subsets[t, r] == q:
                    member = True
            if member:
                continue
            # filter with the rounded exact normal (error ≤ ε|a_j|), else exactly
            val = 0.0
            bound = 0.0
            for c in range(k):
                dc = Y[q, c] - Y[i, c]
                val += a[c] * dc
                bound += abs(a[c] * dc)
            if val > 8.0 * EPS * bound:
                o = 1
            elif val < -8.0 * EPS * bound:
                o = -1
            else:
                n = 0
                for c in range(k):
                    difference(Y[q, c], Y[i, c], d)
                    n += product(C[c], nC[c], d, 2, S[n:])
                o = sign(S, compress(S, n))
            if o > 0:
                plus[t] += W[q]
            elif o < 0:
                minus[t] += W[q]
            if plus[t] > F and minus[t] > F:
                break


#: from this many subsets on, the exact side counts run on threads
PARALLEL_MIN_SUBSETS = 200


def side_counts(Y, W, subsets, F, plus, minus, degenerate):
    """Exact weighted numbers of points strictly on the + and − side of the plane (k = 3)
    or line (k = 2) through each subset (+: the side of the cofactor normal), and
    whether the subset is affinely dependent. A subset's scan stops once both sides
    hold more than F (it bounds no valid halfspace), so counts above F are lower
    bounds; counts ≤ F are exact. Many subsets: ranges of them on threads
    (:func:`._candidates.on_threads`; each subset's counts are its own)."""
    from ._candidates import on_threads

    def scan(lo: int, hi: int) -> None:
        _side_counts_range(Y, W, subsets, F, lo, hi, plus, minus, degenerate)

    on_threads(scan, len(subsets), 64 if len(subsets) >= PARALLEL_MIN_SUBSETS else 1)
