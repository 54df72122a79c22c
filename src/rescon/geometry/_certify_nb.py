"""Compiled modular steps of the fast path's certification (:mod:`.fastpath`).

A proposal of the fast path is a set T of k rows e_h = (−b_h, a_h) (integers); where
det A_T ≠ 0 its rows meet in the single point y = A_T⁻¹ b_T. Modulo a prime p with
det A_T ≢ 0 (mod p) the residue y mod p = A_T⁻¹ b_T (mod p) is well defined, and equal
points have equal residues: the residues are a *key* of the point. Distinct points can
share a key (each coordinate then agrees modulo p by chance), so a key only proposes:
the fast path solves one proposal per key, and a vertex lost to a shared key leaves a
tangent-cone ray without an end, which the closure check refuses (the caller then
clips exactly).
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["KEY_PRIME", "nonsingular", "packed_pairs", "paired_rows", "point_keys",
           "tight_through"]

#: the largest prime below 2^31 − 1 (a compile-time constant: the reductions modulo it
#: compile to multiplications); residues < 2^31, so a product of two fits an int64
KEY_PRIME = 2_147_483_629


@njit(cache=True, nogil=True)
def _inverse(a):
    """a⁻¹ modulo KEY_PRIME (a ≢ 0), by Fermat: a^(p − 2)."""
    p = KEY_PRIME
    out, e = 1, p - 2
    a %= p
    while e:
        if e & 1:
            out = out * a % p
        a = a * a % p
        e >>= 1
    return out


@njit(cache=True, nogil=True)
def _reduce(R, k):
    """Gauss–Jordan on the k × (k + 1) residues R = [−b | A] over the columns of A,
    without divisions (row_i ← pivot·row_i − f·row_c, mod p): on success R[i, i + 1]
    ≠ 0, the other entries of A are 0, and y_i = −R[i, 0] / R[i, i + 1]. False if A is
    singular modulo p."""
    p = KEY_PRIME
    for c in range(k):
        piv = -1
        for r in range(c, k):
            if R[r, c + 1] != 0:
                piv = r
                break
        if piv < 0:
            return False
        if piv != c:
            for j in range(k + 1):
                R[c, j], R[piv, j] = R[piv, j], R[c, j]
        top = R[c, c + 1]
        for i in range(k):
            f = R[i, c + 1]
            if i == c or f == 0:
                continue
            for j in range(k + 1):
                R[i, j] = (top * R[i, j] - f * R[c, j]) % p
    return True


@njit(cache=True, nogil=True)
def point_keys(E, at, keys):
    """For each proposal i (its rows at[i] of the residues E (m, k + 1), entries in
    [0, p)), the key y mod p into keys[i] (k residues) and True, or False where A_T is
    singular modulo p (keys[i] left as is). The k divisions of each solve are one
    inversion for all proposals (Montgomery's trick: prefix products)."""
    P, k = at.shape
    p = KEY_PRIME
    ok = np.zeros(P, dtype=np.bool_)
    num = np.empty((P, k), dtype=np.int64)
    den = np.ones((P, k), dtype=np.int64)
    R = np.empty((k, k + 1), dtype=np.int64)
    for i in range(P):
        for r in range(k):
            for j in range(k + 1):
                R[r, j] = E[at[i, r], j]
        if not _reduce(R, k):
            continue
        ok[i] = True
        for r in range(k):
            num[i, r] = (p - R[r, 0]) % p
            den[i, r] = R[r, r + 1]
    # one inversion: prefix[t] = den_0 ⋯ den_{t−1}, then walk back
    flat = den.ravel()
    prefix = np.empty(len(flat) + 1, dtype=np.int64)
    prefix[0] = 1
    for t in range(len(flat)):
        prefix[t + 1] = prefix[t] * flat[t] % p
    inv = _inverse(prefix[len(flat)])
    for t in range(len(flat) - 1, -1, -1):
        i, r = t // k, t % k
        if ok[i]:
            keys[i, r] = num[i, r] * (inv * prefix[t] % p) % p
        inv = inv * flat[t] % p
    return ok


@njit(cache=True, nogil=True)
def nonsingular(A, at, p):
    """For each row set i (the rows at[i] of the residues A (m, k) modulo the prime
    p < 2^31, entries in [0, p)), whether det A_T ≢ 0 (mod p) — then det A_T ≠ 0 — by
    Gaussian elimination without divisions (row_i ← pivot·row_i − f·row_c, mod p: the
    pivot is a unit modulo p, so the determinant modulo p changes by a unit factor)."""
    P, k = at.shape
    out = np.zeros(P, dtype=np.bool_)
    R = np.empty((k, k), dtype=np.int64)
    for i in range(P):
        for r in range(k):
            for j in range(k):
                R[r, j] = A[at[i, r], j]
        full = True
        for c in range(k):
            piv = -1
            for r in range(c, k):
                if R[r, c] != 0:
                    piv = r
                    break
            if piv < 0:
                full = False
                break
            if piv != c:
                for j in range(c, k):
                    R[c, j], R[piv, j] = R[piv, j], R[c, j]
            top = R[c, c]
            for r in range(c + 1, k):
                f = R[r, c]
                if f != 0:
                    for j in range(c, k):
                        R[r, j] = (top * R[r, j] - f * R[c, j]) % p
        out[i] = full
    return out


@njit(cache=True, nogil=True)
def tight_through(through, basis, hs, vs):
    """For each pair i, whether the hyperplane of row hs[i] provably contains the point
    v = vs[i] from the data points alone: some nonempty G ⊆ basis[v] (k independent rows
    meeting only at v) has common points C_G = ⋂_{g∈G} through[g] with |C_G| = k − |G| + 1,
    all on row hs[i] (C_G ⊆ through[hs[i]]).

    Proof: C_G ⊆ through[g] is affinely independent (k points spanning a hyperplane),
    so flat(C_G) has dimension k − |G|; it lies in ⋂_G H_g, of dimension k − |G| (the rows
    are independent): the two are equal, and v ∈ ⋂_G H_g. Every exact row is the
    hyperplane through its points, so C_G ⊆ H_h, hence flat(C_G) ⊆ H_h and v ∈ H_h.
    False proves nothing (the caller decides the pair exactly). k² ≤ 62: the points of
    v's basis rows are bits of an int64."""
    k = through.shape[1]
    out = np.zeros(len(hs), dtype=np.bool_)
    points = np.empty(k * k, dtype=np.int64)
    masks = np.empty(k, dtype=np.int64)
    for i in range(len(hs)):
        n = 0  # the distinct points of v's basis rows, each a bit
        for a in range(k):
            g = basis[vs[i], a]
            m = 0
            for s in range(k):
                p = through[g, s]
                j = 0
                while j < n and points[j] != p:
                    j += 1
                if j == n:
                    points[n] = p
                    n += 1
                m |= np.int64(1) << j
            masks[a] = m
        on = 0  # those on row hs[i]
        for s in range(k):
            for j in range(n):
                if points[j] == through[hs[i], s]:
                    on |= np.int64(1) << j
                    break
        for G in range(1, 1 << k):
            common = np.int64(-1)
            size = 0
            for a in range(k):
                if G >> a & 1:
                    common &= masks[a]
                    size += 1
            if common & ~on == 0 and _popcount(common) == k - size + 1:
                out[i] = True
                break
    return out


@njit(cache=True, nogil=True, inline="always")
def _popcount(x):
    c = 0
    while x:
        x &= x - 1
        c += 1
    return c


@njit(cache=True, nogil=True)
def paired_rows(pts, k):
    """For each row set i (pts[i, a]: the k data points of its row a), the index of its
    first pair of rows a < b, in lexicographic order, that share k − 1 data points;
    −1 if none shares them."""
    out = np.empty(pts.shape[0], dtype=np.int64)
    for i in range(pts.shape[0]):
        out[i] = _first_pair(pts[i], k)
    return out


@njit(cache=True, nogil=True)
def _first_pair(rows, k):
    """The index of the first pair a < b (lexicographic) of ``rows`` (each k data
    points) sharing k − 1 of them, or −1."""
    g = 0
    for a in range(rows.shape[0]):
        for b in range(a + 1, rows.shape[0]):
            common = 0
            for s in range(k):
                for t in range(k):
                    if rows[a, s] == rows[b, t]:
                        common += 1
                        break
            if common == k - 1:
                return g
            g += 1
    return -1


@njit(cache=True, nogil=True)
def packed_pairs(vs, hs, n, nbytes):
    """The bitsets of the pairs (vs[i], hs[i]) (vertex < n, position < 8 · nbytes),
    little-endian, nbytes per vertex side by side (uint8, n · nbytes), and the distinct
    pairs ordered by vertex then position: what ``np.packbits`` of the boolean table
    and its set bits read back give, without the table."""
    packed = np.zeros(n * nbytes, dtype=np.uint8)
    for i in range(len(vs)):
        packed[vs[i] * nbytes + (hs[i] >> 3)] |= np.uint8(1 << (hs[i] & 7))
    total = 0
    for i in range(len(packed)):
        total += _popcount(np.int64(packed[i]))
    pv = np.empty(total, dtype=np.int64)
    ph = np.empty(total, dtype=np.int64)
    e = 0
    for i in range(len(packed)):
        byte = packed[i]
        if byte:
            for bit in range(8):
                if byte >> bit & 1:
                    pv[e] = i // nbytes
                    ph[e] = i % nbytes * 8 + bit
                    e += 1
    return packed, pv, ph
