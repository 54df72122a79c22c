"""Combinatorial closure of the vertices' tangent cones (:mod:`.fastpath`).

The fast path must show that every extreme ray of the tangent cone
C_v = {d : a_h·d ≤ 0, h ∈ T(v)} of every proposed vertex v (T(v): the rows of S tight at
v, computed exactly, of rank k) leads to another proposed vertex. This module does it
from the exact tight sets alone, simple and non-simple vertices alike; where it cannot
conclude at a non-simple v, the caller runs the double description of C_v.

**Faces and zero sets.** C_v is pointed (v is a vertex: T(v) has rank k). A face F of
C_v is C_v ∩ {a_h·d = 0, h ∈ Z_F} with Z_F ⊆ T(v) the rows tight on all of F (its zero
set), and dim F = k − rank Z_F (the zero set's equations cut out F's linear span).
Distinct faces have distinct zero sets.

**Found rays.** For a proposed vertex u ≠ v, d = u − v lies in C_v (u ∈ P_S) and the
rows of T(v) tight along d are Z_u = T(v) ∩ T(u). The face of C_v with zero set Z_u holds
d and has rank Z_u ≤ k − 1 (u ≠ v both satisfy Z_u's equations). Where the rank of Z_u's
normals modulo a prime p is k − 1 — a lower bound of the rank over ℚ — it is k − 1, so
d spans an extreme ray of C_v; the face of P_S cut out by Z_u is then an edge on d's line
with the vertex v as one end, and the vertex u of P_S on it is its other end. Distinct
u are distinct rays. A modular rank that falls short by chance only leaves u out.

**Joins.** Let G ≠ G' be two found faces of dimension j, both containing a face A of
dimension j − 1 (for j = 1, A = {0}), rank Z_G = r = k − j. The face H with zero set
Z_G ∩ Z_G' contains both, so dim H ≥ j + 1 and rank(Z_G ∩ Z_G') ≤ r − 1; a modular rank
≥ r − 1 proves equality: H is the (j + 1)-face G ∨ G'. Distinct G' give distinct H (a
(j + 1)-face over A holds exactly two j-faces over A, see below).

**Lemma.** The faces of C_v that contain a face A form the face lattice of a pointed
cone C/A of dimension m = k − dim A (the face figure), whose extreme rays are the faces
of dimension dim A + 1 over A and whose 2-faces those of dimension dim A + 2. A set R of
extreme rays of a pointed cone of dimension m ≥ 2 is all of them if R is non-empty and
every 2-face containing a ray of R contains a second one: the rays and 2-faces are the
vertices and edges of a (m − 1)-polytope (a cross-section), whose graph is connected.
For m = 2 the cone has exactly two extreme rays.

**The check.** Found faces R of dimension j over A (rank r = k − j, m = r + 1) are all
such faces if R ≠ ∅ and: r = 1 and |R| = 2; or r ≥ 2 and for each G ∈ R the joins
{G ∨ G' : G' ∈ R} are all the (j + 1)-faces containing G — the extreme rays of C/G
(dimension r), each a 2-face of C/A at G holding a second member G' of R. That is the
same check one level down (faces of dimension j + 1 over G), except where Z_G is
independent (|Z_G| = r): near G, C_v is the cone of Z_G's r rows, so C/G is simplicial
and its extreme rays are the r faces with zero sets Z_G − {g}: all r must be joins.
Started from the found rays (j = 1, A = {0}), a pass proves they are all the extreme
rays of C_v, each ending at a proposed vertex; the proposed vertices u found are then
exactly v's neighbours on P_S. A check that exceeds its work bound, a vertex of more than
MAX_ROWS (or fewer than k) tight rows, a missing face, more than two at r = 1, or two
found faces of one dimension whose zero sets contain one another (impossible for
distinct faces: the tight sets are then not exact, e.g. a vertex copied) fails. The
caller then runs the double description of a non-simple C_v; a simple v has a ray
without an end (every vertex holding k − 1 of its k rows was looked at), and the caller
refuses.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from ._candidates import _popcount
from .polytope import PRIME, tight_pairs

__all__ = ["combinatorial_rays"]

#: vertices with more tight rows are left to the double description (the zero sets are
#: int64 bitmasks over a vertex's rows)
MAX_ROWS = 62
#: join computations per vertex before the check gives up (the double description
#: decides then)
WORK = 200_000
#: vertices with at most this many tight rows register their (k − 1)-subsets as keys
#: for the simple vertices' pass (:func:`_simple_ends`; C(10, 4) = 210 keys at most in
#: k = 5); a simple vertex sharing k − 1 rows with a larger one is left to the scan
KEYED_ROWS = 10
#: from this many vertices on, the closure's check runs on threads, CLOSURE_CHUNKS
#: ranges of vertices (:func:`._candidates.on_threads`)
CLOSURE_THREADS_MIN = 1000
CLOSURE_CHUNKS = 8


def combinatorial_rays(tight: list[int], normals: list[tuple[int, ...]], k: int,
                       pairs: tuple[np.ndarray, np.ndarray] | None = None
                       ) -> tuple[np.ndarray, list[list[int]]]:
    """For every vertex v (``tight``: its rows, of rank k), whether the check (module
    docstring) proves that the proposed vertices u with rank(T(v) ∩ T(u)) = k − 1 end
    all the extreme rays of its tangent cone, and those u, increasing (empty where it
    does not). At a simple vertex (k rows, independent) every k − 1 of them have rank
    k − 1: no modular rank is needed, and the check passes iff each of its k rays has
    an end. ``pairs``: :func:`.polytope.tight_pairs` of ``tight`` when known. Each
    vertex's check is its own: from CLOSURE_THREADS_MIN vertices on, ranges of them run
    on threads (:func:`._candidates.on_threads`)."""
    from ._candidates import on_threads  # looked up per call: tests replace it

    v_of, h_of = tight_pairs(tight) if pairs is None else pairs  # by vertex, then row
    v_ptr = np.searchsorted(v_of, np.arange(len(tight) + 1)).astype(np.int64)
    by_row = np.argsort(h_of, kind="stable")  # by row, then vertex
    h_ptr = np.searchsorted(h_of[by_row], np.arange(len(normals) + 1)).astype(np.int64)
    residues = np.array([[x % PRIME for x in a] for a in normals], dtype=np.int64)
    ok = np.zeros(len(tight), dtype=np.bool_)
    v_rows, h_verts = h_of.astype(np.int64), v_of[by_row].astype(np.int64)
    pre = np.zeros(len(tight), dtype=np.bool_)
    pre_ends = np.zeros((len(tight), k), dtype=np.int64)
    if k >= 2 and len(normals) ** (k - 1) < 2**62:  # the keys fit int64
        _simple_ends(v_ptr, v_rows, h_ptr, h_verts, len(normals), k, KEYED_ROWS, pre,
                     pre_ends)
    n = len(tight)
    chunks = CLOSURE_CHUNKS if n >= CLOSURE_THREADS_MIN else 1
    parts: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}
    R = residues.reshape(-1, k)

    def scan(lo: int, hi: int) -> None:
        parts[lo, hi] = _closures(v_ptr, v_rows, h_ptr, h_verts, R, k, ok, pre, pre_ends,
                                  lo, hi)

    on_threads(scan, n, chunks)
    out: list[list[int]] = []
    for lohi in sorted(parts):  # the ranges in order (empty ones add nothing)
        ptr, ends = parts[lohi]
        ends = ends.tolist()
        out.extend(ends[a:b] for a, b in zip(ptr[:-1].tolist(), ptr[1:].tolist(), strict=True))
    return ok, out


@njit(cache=True, nogil=True)
def _closures(v_ptr, v_rows, h_ptr, h_verts, residues, k, ok, pre, pre_ends, lo, hi):
    """:func:`combinatorial_rays` for the vertices lo ≤ v < hi, on the incidences in
    CSR form (v_rows[v_ptr[v]:v_ptr[v + 1]]: the rows of vertex v, increasing; h_verts
    likewise the vertices of each row): ok[v], and the ends of the passing vertices
    (ends[ptr[v − lo]:ptr[v − lo + 1]]). The simple vertices with ``pre`` set pass with
    the k ends ``pre_ends`` (found by :func:`_simple_ends`, the same as the check's:
    see there) without a scan. Each vertex's check reads only the shared incidences
    (ranges on threads write disjoint entries of ``ok``)."""
    n = len(v_ptr) - 1
    count = np.zeros(n, dtype=np.int64)
    mask = np.zeros(n, dtype=np.int64)
    touched = np.empty(n, dtype=np.int64)
    ptr = np.zeros(hi - lo + 1, dtype=np.int64)
    ends = np.empty(16 * (hi - lo) + 16, dtype=np.int64)
    found_u = np.empty(n, dtype=np.int64)
    found_z = np.empty(n, dtype=np.int64)
    R = np.empty((MAX_ROWS, k), dtype=np.int64)
    work = np.empty((MAX_ROWS, k), dtype=np.int64)
    for v in range(lo, hi):
        i = v - lo
        ptr[i + 1] = ptr[i]
        t = v_ptr[v + 1] - v_ptr[v]
        if t < k or t > MAX_ROWS:
            continue
        if pre[v]:
            ok[v] = True
            if ptr[i] + k > len(ends):
                grown = np.empty(2 * (ptr[i] + k), dtype=np.int64)
                grown[:ptr[i]] = ends[:ptr[i]]
                ends = grown
            _sorted_into(pre_ends[v], ends, ptr[i])
            ptr[i + 1] = ptr[i] + k
            continue
        # the vertices sharing rows with v: how many, and which (bits over v's rows)
        m = 0
        for j in range(t):
            h = v_rows[v_ptr[v] + j]
            R[j] = residues[h]
            for e in range(h_ptr[h], h_ptr[h + 1]):
                u = h_verts[e]
                if u == v:
                    continue
                if count[u] == 0:
                    touched[m] = u
                    m += 1
                count[u] += 1
                mask[u] |= np.int64(1) << j
        f = 0
        for e in range(m):
            u = touched[e]
            if count[u] >= k - 1 and (t == k or _rank_at_least(R, mask[u], k - 1, work)):
                found_u[f] = u
                found_z[f] = mask[u]
                f += 1
            count[u] = 0
            mask[u] = 0
        if not _faces_closed(found_z[:f].copy(), k - 1, R, work):
            continue
        ok[v] = True
        if ptr[i] + f > len(ends):
            grown = np.empty(2 * (ptr[i] + f), dtype=np.int64)
            grown[:ptr[i]] = ends[:ptr[i]]
            ends = grown
        ends[ptr[i]:ptr[i] + f] = np.sort(found_u[:f])
        ptr[i + 1] = ptr[i] + f
    return ptr, ends[:ptr[-1]]


def _simple_ends(v_ptr, v_rows, h_ptr, h_verts, n_rows, k, keyed, pre, pre_ends):
    """The check at simple vertices (k tight rows, independent) from keys instead of a
    scan: sets pre[v] and the k ends pre_ends[v] where it passes; a vertex it leaves
    unset is scanned by :func:`_closures` (which then refuses it or not, as always).

    At a simple v the scan finds U = {u ≠ v : |T(u) ∩ T(v)| ≥ k − 1} and passes iff
    u ↦ T(u) ∩ T(v) maps U one-to-one onto the k sets Z_g = T(v) − {g} (a u with
    T(u) ⊇ T(v), two u on one Z_g or a Z_g on none fails :func:`_faces_closed`:
    equal or nested zero sets, fewer than r joins), with ends U. Every vertex u of
    k − 1 ≤ |T(u)| ≤ ``keyed`` rows (fewer than k only in tampered input) registers
    each (k − 1)-subset of T(u) as a key (its rows p₁ < … < p_{k−1} in base
    ``n_rows``); a simple v sharing k − 1 rows with a
    larger u is left unset (such u are few: their rows are scanned). For the other
    simple v, U is the set of owners ≠ v of the keys Z_g, and the map is one-to-one
    onto the Z_g iff each Z_g has exactly one owner u_g ≠ v and g ∉ T(u_g) (then
    T(u_g) ∩ T(v) = Z_g, and u_g holds no other Z_g', whose union with Z_g is T(v)):
    the scan's verdict and ends, exactly."""
    from ._candidates import on_threads  # looked up per call: tests replace it

    keys, owners, left = _simple_keys(v_ptr, v_rows, h_ptr, h_verts, n_rows, k, keyed)
    n = len(v_ptr) - 1

    def scan(lo: int, hi: int) -> None:
        _simple_check(v_ptr, v_rows, keys, owners, left, n_rows, k, pre, pre_ends, lo, hi)

    on_threads(scan, n, CLOSURE_CHUNKS if n >= CLOSURE_THREADS_MIN else 1)


@njit(cache=True, nogil=True, inline="always")
def _sorted_into(x, out, at):
    """x, increasing, into out[at:at + len(x)] (insertion sort: a simple vertex's k
    ends, without allocating an array per vertex)."""
    for i in range(len(x)):
        v = x[i]
        j = at + i
        while j > at and out[j - 1] > v:
            out[j] = out[j - 1]
            j -= 1
        out[j] = v


@njit(cache=True, nogil=True)
def _simple_keys(v_ptr, v_rows, h_ptr, h_verts, n_rows, k, keyed):
    """The keys of :func:`_simple_ends`, sorted, with their owners, and per vertex
    whether it shares k − 1 rows with a vertex of more than ``keyed`` rows (``left``)."""
    n = len(v_ptr) - 1
    total = 0
    for u in range(n):
        t = v_ptr[u + 1] - v_ptr[u]
        if k - 1 <= t <= keyed:
            c = 1
            for i in range(k - 1):  # C(t, k − 1)
                c = c * (t - i) // (i + 1)
            total += c
    keys = np.empty(total, dtype=np.int64)
    owners = np.empty(total, dtype=np.int64)
    idx = np.empty(k - 1, dtype=np.int64)
    e = 0
    for u in range(n):
        t = v_ptr[u + 1] - v_ptr[u]
        if t < k - 1 or t > keyed:
            continue
        rows = v_rows[v_ptr[u]:v_ptr[u + 1]]
        for i in range(k - 1):
            idx[i] = i
        while True:
            key = np.int64(0)
            for i in range(k - 1):
                key = key * n_rows + rows[idx[i]]
            keys[e] = key
            owners[e] = u
            e += 1
            i = k - 2
            while i >= 0 and idx[i] == t - k + 1 + i:
                i -= 1
            if i < 0:
                break
            idx[i] += 1
            for j in range(i + 1, k - 1):
                idx[j] = idx[j - 1] + 1
    keys, owners = _radix_sorted(keys, owners)
    # the simple vertices sharing k − 1 rows with a vertex of more than ``keyed`` rows
    left = np.zeros(n, dtype=np.bool_)
    count = np.zeros(n, dtype=np.int64)
    touched = np.empty(n, dtype=np.int64)
    for u in range(n):
        if v_ptr[u + 1] - v_ptr[u] <= keyed:
            continue
        m = 0
        for j in range(v_ptr[u], v_ptr[u + 1]):
            h = v_rows[j]
            for f in range(h_ptr[h], h_ptr[h + 1]):
                w = h_verts[f]
                if count[w] == 0:
                    touched[m] = w
                    m += 1
                count[w] += 1
        for f in range(m):
            w = touched[f]
            if count[w] >= k - 1 and w != u:
                left[w] = True
            count[w] = 0
    return keys, owners, left


#: the digit of :func:`_radix_sorted`, in bits (2^11 counters: within the L1 cache)
RADIX_BITS = 11


@njit(cache=True, nogil=True)
def _radix_sorted(keys, owners):
    """keys (≥ 0) sorted, with owners permuted alongside (the two arrays are
    overwritten: the result may be them): a least-significant-digit radix sort, stable,
    RADIX_BITS per pass, as many passes as the largest key has digits (4 in k = 5 with
    ~900 rows; numba's argsort of the 1.4 · 10⁵ keys of sphere(5, 30, 3) took 2.5× as
    long). The order among equal keys is not read (:func:`_simple_check` looks at every
    owner of a key)."""
    n = len(keys)
    top = np.int64(0)
    for i in range(n):
        top = max(top, keys[i])
    size = 1 << RADIX_BITS
    mask = np.int64(size - 1)
    count = np.empty(size + 1, dtype=np.int64)
    src_k, src_o = keys, owners
    dst_k = np.empty_like(keys)
    dst_o = np.empty_like(owners)
    shift = 0
    while shift == 0 or (shift < 63 and top >> shift):
        count[:] = 0
        for i in range(n):
            count[((src_k[i] >> shift) & mask) + 1] += 1
        for d in range(size):
            count[d + 1] += count[d]
        for i in range(n):
            d = (src_k[i] >> shift) & mask
            dst_k[count[d]] = src_k[i]
            dst_o[count[d]] = src_o[i]
            count[d] += 1
        src_k, dst_k = dst_k, src_k
        src_o, dst_o = dst_o, src_o
        shift += RADIX_BITS
    return src_k, src_o


@njit(cache=True, nogil=True)
def _simple_check(v_ptr, v_rows, keys, owners, left, n_rows, k, pre, pre_ends, lo, hi):
    """:func:`_simple_ends` at the simple vertices lo ≤ v < hi, from the keys of
    :func:`_simple_keys` (ranges on threads write disjoint rows of pre, pre_ends)."""
    for v in range(lo, hi):
        if v_ptr[v + 1] - v_ptr[v] != k or left[v]:
            continue
        rows = v_rows[v_ptr[v]:v_ptr[v + 1]]
        passed = True
        for g in range(k):
            key = np.int64(0)
            for i in range(k):
                if i != g:
                    key = key * n_rows + rows[i]
            u = -1
            for f in range(np.searchsorted(keys, key), len(keys)):
                if keys[f] != key:
                    break
                w = owners[f]
                if w == v:
                    continue
                if u >= 0:  # a second owner
                    u = -2
                    break
                u = w
            if u < 0:
                passed = False
                break
            a = v_ptr[u]  # g ∉ T(u): rows of u are increasing
            b = v_ptr[u + 1]
            while a < b:
                mid = (a + b) // 2
                if v_rows[mid] < rows[g]:
                    a = mid + 1
                else:
                    b = mid
            if a < v_ptr[u + 1] and v_rows[a] == rows[g]:
                passed = False
                break
            pre_ends[v, g] = u
        pre[v] = passed


@njit(cache=True, nogil=True)
def _faces_closed(faces, r, R, work):
    """The check of the module docstring, a task per face set: ``faces`` (distinct zero
    sets over a common face, rank r each) are all the faces of their dimension over it.
    Tasks are kept in a queue (start, count, rank) over a growing array of zero sets;
    False as soon as one fails or the work exceeds WORK joins."""
    store = faces
    top = len(faces)
    tasks = [(0, len(faces), r)]
    spent = 0
    while tasks:
        start, n, r = tasks.pop()
        if n == 0:
            return False
        if r == 1:  # exactly two facets over the face, neither's zero set in the other's
            J = store[start] & store[start + n - 1]
            if n != 2 or J == store[start] or J == store[start + 1]:
                return False
            continue
        for a in range(start, start + n):
            G = store[a]
            simplicial = _popcount(G) == r
            first = top
            for b in range(start, start + n):
                if b == a:
                    continue
                spent += 1
                if spent > WORK:
                    return False
                J = G & store[b]
                if J == G:  # G' ⊇ G: not two distinct faces of one dimension
                    return False
                size = _popcount(J)
                if size < r - 1 or (simplicial and size != r - 1):
                    continue
                seen = False
                for c in range(first, top):
                    if store[c] == J:
                        seen = True
                        break
                if seen or not (simplicial or _rank_at_least(R, J, r - 1, work)):
                    continue
                if top == len(store):
                    grown = np.empty(2 * len(store) + 16, dtype=np.int64)
                    grown[:top] = store[:top]
                    store = grown
                store[top] = J
                top += 1
            if simplicial:
                if top - first != r:
                    return False
                top = first  # the joins are not looked at again
            else:
                tasks.append((first, top - first, r - 1))
    return True


@njit(cache=True, nogil=True)
def _rank_at_least(R, bits, r, work):
    """The rows of R (residues modulo PRIME) whose bits are set span rank ≥ r modulo
    PRIME (then over ℚ too): elimination without divisions, row_i ← p_c·row_i −
    f·row_c."""
    p = PRIME
    k = R.shape[1]
    m = 0
    b = bits
    j = 0
    while b:
        if b & 1:
            work[m] = R[j]
            m += 1
        b >>= 1
        j += 1
    if m < r:
        return False
    rank = 0
    for c in range(k):
        piv = -1
        for i in range(rank, m):
            if work[i, c] != 0:
                piv = i
                break
        if piv < 0:
            continue
        if piv != rank:
            for x in range(k):
                work[rank, x], work[piv, x] = work[piv, x], work[rank, x]
        top = work[rank, c]
        for i in range(rank + 1, m):
            g = work[i, c]
            if g != 0:
                for x in range(k):
                    work[i, x] = (top * work[i, x] - g * work[rank, x]) % p
        rank += 1
        if rank >= r:
            return True
    return False
