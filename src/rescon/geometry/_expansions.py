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

#: Dekker's splitter for doubles: 2^27 + 1
_SPLITTER = 134217729.0
#: what :func:`side_of_meet` returns for parallel lines
PARALLEL = 2


@njit(cache=True, nogil=True)
def two_sum(a, b):
    """a + b = x + y exactly (Knuth)."""
    x = a + b
    bv = x - a
    av = x - bv
    return x, (a - av) + (b - bv)


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
def sign(e, n):
    """Sign of an expansion of length n (its largest component)."""
    if n == 0:
        return 0
    return 1 if e[n - 1] > 0 else -1


@njit(cache=True, nogil=True)
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


@njit(cache=True, nogil=True)
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
