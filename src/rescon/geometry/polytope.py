"""Exact polytopes in R^k by clipping: the double-description step on integers.

A vertex is stored in homogeneous integer coordinates (w, y) with w > 0 (the point
y / w) together with the set of constraints tight at it (a Python-int bitset).
Clipping by a·y ≤ b keeps the vertices with s = a·y − b·w ≤ 0 and adds, for every
edge (u, v) with s_u < 0 < s_v, the point s_v·u − s_u·v. Two vertices span an edge
iff no third vertex is tight on every constraint tight at both (the combinatorial
adjacency test of the double-description method, exact for polytopes of any
dimension, degenerate ones included). All arithmetic is on Python ints.

Floats only filter: the vertices as correctly rounded floats y / (w · unit), ``unit``
the power of two that puts the data at magnitudes ≤ 2^32
(:func:`.exact.float_view`), so no filter overflows at any scale of the data; each
filter's bound has an absolute term for underflow (:func:`rescon._rounding.
underflow_floor`), and inf or NaN never passes a "decided" test (every comparison
with them is False), so such pairs are decided on the integers.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from fractions import Fraction
from math import gcd

import numpy as np

from .._rounding import UNIT_ROUNDOFF as _EPS
from .._rounding import underflow_floor
from ._budget import PYTHON_STEP, require
from .exact import bareiss_rank, nullspace_exact

__all__ = ["ExactPolytope", "Farkas", "members_of", "tight_pairs"]


@dataclass(frozen=True)
class Farkas:
    """Constraints (indices) and λ ≥ 0 with Σ λ_i a_i = 0 and Σ λ_i b_i < 0."""

    ids: tuple[int, ...]
    multipliers: tuple[Fraction, ...]


def _bits(t: int):
    """Indices of the set bits of t."""
    while t:
        low = t & -t
        yield low.bit_length() - 1
        t ^= low


def tight_pairs(tight: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """(vertex, row) for every set bit of the bitsets ``tight``, ordered by vertex then
    row: the bitsets' bytes side by side, only the nonzero bytes unpacked."""
    width = max((max(tight, default=0).bit_length() + 7) // 8, 1)
    buf = np.frombuffer(b"".join(t.to_bytes(width, "little") for t in tight), dtype=np.uint8)
    at = np.flatnonzero(buf)  # vertex · width + byte, increasing
    bits = np.flatnonzero(np.unpackbits(buf[at], bitorder="little"))
    at = at[bits >> 3]
    return at // width, at % width * 8 + (bits & 7)


def members_of(tight: list[int], pairs: tuple[np.ndarray, np.ndarray] | None = None
               ) -> dict[int, list[int]]:
    """Row → the vertices whose bitset ``tight`` holds it, increasing (rows in
    increasing order, only those set somewhere). ``pairs``: :func:`tight_pairs` of
    ``tight`` when known."""
    vs, hs = tight_pairs(tight) if pairs is None else pairs
    if not len(hs):
        return {}
    hs, vs = np.divmod(np.sort(hs * len(tight) + vs), len(tight))  # by row, then vertex
    flat = vs.tolist()
    ends = [*(np.flatnonzero(hs[1:] != hs[:-1]) + 1).tolist(), len(flat)]
    starts = [0, *ends[:-1]]
    return dict(zip(hs[starts].tolist(), (flat[a:b] for a, b in zip(starts, ends, strict=True)),
                    strict=True))


def _normalise(h: tuple[int, ...]) -> tuple[int, ...]:
    g = 0
    for v in h:
        g = gcd(g, v)
    return tuple(v // g for v in h) if g > 1 else h


@dataclass
class ExactPolytope:
    """{y ∈ R^k : a_i·y ≤ b_i} with its exact vertices (bounded: starts as a box)."""

    k: int
    a: list[tuple[int, ...]] = field(default_factory=list)
    b: list[int] = field(default_factory=list)
    #: (w, y_1..y_k); the fast path's is a :class:`._lazy_vertices.LazyVertices` (a
    #: sequence solving each vertex when first read; assigning a list replaces it)
    verts: list[tuple[int, ...]] = field(default_factory=list)
    tight: list[int] = field(default_factory=list)
    farkas: Farkas | None = None  # set when a clip empties the polytope
    unit: int = 1  # a power of two: the float vertices are y / (w · unit)
    _fv: np.ndarray | None = field(default=None, repr=False)  # float vertices (cache)
    work: int = 0  # estimated steps spent clipping so far (:mod:`._budget`)
    edges: list[list[int]] | None = None  # per vertex its neighbours, when known (fast path)
    #: :func:`tight_pairs` of ``tight``, set by its builder when it has them (fast path);
    #: a clip that changes ``tight`` drops them, and a copy (``dataclasses.replace``)
    #: starts without them
    pairs: tuple[np.ndarray, np.ndarray] | None = field(default=None, init=False, repr=False,
                                                        compare=False)

    @classmethod
    def box(cls, lo: list[int], hi: list[int], unit: int = 1) -> ExactPolytope:
        """The box lo ≤ y ≤ hi (lo_j < hi_j), constraints 2j: −y_j ≤ −lo_j and
        2j+1: y_j ≤ hi_j."""
        k = len(lo)
        # 2^k vertices of k + 1 Python ints, each met with its k tight facets by the
        # first clip (whose float pass alone reads all k coordinates)
        require(f"the bounding box in dimension {k}", PYTHON_STEP * k * k * 2**k,
                (48 * (k + 1) + 64) * 2**k, "reduce d")
        P = cls(k, unit=unit)
        for j in range(k):
            e = [0] * k
            e[j] = -1
            P.a.append(tuple(e))
            P.b.append(-lo[j])
            e = [0] * k
            e[j] = 1
            P.a.append(tuple(e))
            P.b.append(hi[j])
        for corner in itertools.product((0, 1), repeat=k):
            y = tuple(hi[j] if c else lo[j] for j, c in enumerate(corner))
            tight = 0
            for j, c in enumerate(corner):
                tight |= 1 << (2 * j + c)
            P.verts.append((1, *y))
            P.tight.append(tight)
        return P

    @property
    def is_empty(self) -> bool:
        return not self.verts

    def slack(self, a: tuple[int, ...], b: int) -> list[int]:
        """s_v = a·y_v − b·w_v for every vertex (the sign of a·x − b at x = y/w)."""
        return [self._slack_at(a, b, i) for i in range(len(self.verts))]

    def _slack_at(self, a: tuple[int, ...], b: int, i: int) -> int:
        v = self.verts[i]
        return sum(ai * yi for ai, yi in zip(a, v[1:], strict=True)) - b * v[0]

    def _signs(self, a: tuple[int, ...], b: int) -> tuple[np.ndarray, dict[int, int]]:
        """sign(a·x_v − b) for every vertex: floats beyond a rounding bound, exact
        integers inside it. Also the exact slacks computed on the way.

        In float units x = y / (w · unit) the sign is that of a'·x − b' with
        a' = a / 2^e, b' = b / (unit · 2^e), 2^e > max |a_j|: |a'_j| < 1, each
        correctly rounded (int / int, no overflow whatever the integers' size), as
        are the float vertices; the bound adds the underflow term."""
        fv = self._float_array()
        e = max(abs(x) for x in a).bit_length()
        af = np.array([x / (1 << e) for x in a])
        bf = b / (self.unit << e)
        sf = fv @ af - bf
        floor = underflow_floor(self.k, float(np.abs(fv).max(initial=1.0)))
        bound = 2.0 * (self.k + 3) * _EPS * (np.abs(fv) @ np.abs(af) + abs(bf)) + floor
        sign = np.where(sf > bound, 1, np.where(sf < -bound, -1, 0))
        exact: dict[int, int] = {}
        for i in np.flatnonzero(sign == 0):
            x = exact[int(i)] = self._slack_at(a, b, int(i))
            sign[i] = (x > 0) - (x < 0)
        return sign, exact

    def _float_array(self) -> np.ndarray:
        if self._fv is None or len(self._fv) != len(self.verts):
            self._fv = np.array([[yi / (v[0] * self.unit) for yi in v[1:]] for v in self.verts],
                                dtype=np.float64).reshape(len(self.verts), self.k)
        return self._fv

    def clip(self, a: tuple[int, ...], b: int) -> bool:
        """Intersect with a·y ≤ b; False (and nothing recorded) if it cuts nothing."""
        sign, exact = self._signs(a, b)
        if not (sign > 0).any():
            return False
        self._spend(int((sign > 0).sum()))
        hid = len(self.a)
        bit = 1 << hid
        if (sign > 0).all():
            self.farkas = self._farkas(a, b, self.slack(a, b))
            self.a.append(a)
            self.b.append(b)
            self.verts, self.tight, self._fv, self.pairs = [], [], None, None
            return True

        def s_of(i: int) -> int:
            x = exact.get(i)
            if x is None:
                x = exact[i] = self._slack_at(a, b, i)
            return x

        members = members_of(self.tight)
        need = self.k - 1
        new_v, new_t, new_f = [], [], []
        for v in np.flatnonzero(sign > 0).tolist():
            tv = self.tight[v]
            shared: dict[int, int] = {}
            if need == 0:  # k = 1: every pair of a segment's ends is an edge
                shared = dict.fromkeys(range(len(self.verts)), 0)
            for h in _bits(tv):
                for u in members[h]:
                    shared[u] = shared.get(u, 0) + 1
            for u, cnt in shared.items():
                if cnt < need or sign[u] >= 0:
                    continue
                z = self.tight[u] & tv
                if not self._edge(u, v, z, members):
                    continue
                su, sv = s_of(u), s_of(v)
                p = _normalise(tuple(sv * cu - su * cv for cu, cv in
                                     zip(self.verts[u], self.verts[v], strict=True)))
                new_v.append(p)
                new_t.append(z | bit)
                new_f.append([yi / (p[0] * self.unit) for yi in p[1:]])
        keep = np.flatnonzero(sign <= 0).tolist()
        fv = self._float_array()
        self.verts = [self.verts[i] for i in keep] + new_v
        self.tight = [self.tight[i] | (bit if sign[i] == 0 else 0) for i in keep] + new_t
        self.edges = self.pairs = None
        self._fv = np.vstack([fv[keep], np.array(new_f, dtype=np.float64).reshape(-1, self.k)])
        self.a.append(a)
        self.b.append(b)
        return True

    def _spend(self, cut: int) -> None:
        """Add the estimated cost of a clip cutting off ``cut`` vertices to ``work`` and
        refuse beyond the budget (:mod:`._budget`): the edge search meets, for each
        cut-off vertex, the members of each constraint tight at it — on average
        (I/|V|)·(I/#constraints) Python steps, I the number of incidences."""
        incidences = sum(t.bit_count() for t in self.tight)
        per_vertex = incidences / max(len(self.verts), 1)
        self.work += int(PYTHON_STEP * cut * per_vertex * incidences / max(len(self.a), 1))
        require(f"the exact vertex enumeration of the kernel in dimension {self.k}",
                self.work, 0, "reduce d, or n")

    def _edge(self, u: int, v: int, z: int, members: dict[int, list[int]]) -> bool:
        """u, v span an edge: no other vertex is tight on all of z."""
        if not z:
            return len(self.verts) == 2
        smallest = min((members[h] for h in _bits(z)), key=len)
        return not any((self.tight[w] & z) == z for w in smallest if w != u and w != v)

    def _farkas(self, a: tuple[int, ...], b: int, s: list[int]) -> Farkas:
        """All vertices violate a·y ≤ b. At the vertex v* minimising a·y over the
        current polytope, −a is a nonnegative combination Σ μ_i a_i of k independent
        tight constraints (LP duality), so 1·(a, b) + Σ μ_i (a_i, b_i) has vector part 0
        and scalar part b − a·v* < 0."""
        vals = [Fraction(x, v[0]) for x, v in zip(s, self.verts, strict=True)]
        star = min(range(len(vals)), key=vals.__getitem__)  # min a·y − b
        tight_ids = _nnls_first([i for i in range(len(self.a)) if self.tight[star] >> i & 1],
                                self.a, a)
        hid = len(self.a)
        for subset in itertools.combinations(tight_ids, self.k):
            cols = [list(self.a[i]) for i in subset] + [list(a)]
            # Σ μ_i a_i + 1·a = 0  →  nullspace of the k × (k+1) matrix [a_i ... a]
            M = [[Fraction(col[r]) for col in cols] for r in range(self.k)]
            ns = nullspace_exact(M)
            if len(ns) != 1:
                continue
            lam = ns[0]
            if lam[-1] < 0:
                lam = [-x for x in lam]
            if lam[-1] == 0 or any(x < 0 for x in lam):
                continue
            total = sum(lam[t] * self.b[i] for t, i in enumerate(subset)) + lam[-1] * b
            if total < 0:
                return Farkas((*subset, hid), tuple(lam))
        raise AssertionError("no Farkas multipliers at the minimising vertex")

    # ------------------------------------------------------------------ #
    # read-out
    # ------------------------------------------------------------------ #

    def float_vertices(self) -> np.ndarray:
        """The vertices in float units, x = y / (w · unit), correctly rounded."""
        return self._float_array().copy()

    def fraction_vertices(self) -> list[tuple[Fraction, ...]]:
        return [tuple(Fraction(yi, v[0]) for yi in v[1:]) for v in self.verts]

    def dim(self) -> int:
        """Affine dimension of the vertex set (−1 if empty): k when full rank is
        certified for the vertices extreme in some coordinate (at most 2k, whose affine
        hull lies in that of all) or else for all of them — in floats
        (:func:`_full_rank_floats`), then for the extreme ones modulo a prime (a minor
        nonzero modulo p is nonzero: :func:`_rank_mod`) — else exactly (Bareiss)."""
        if not self.verts:
            return -1
        if len(self.verts) > self.k:
            V = self._float_array()
            few = np.unique(np.r_[V.argmin(axis=0), V.argmax(axis=0)]).tolist()
            if len(few) <= self.k:
                few = []
            if (few and _full_rank_floats(V[few], self.k)) or _full_rank_floats(V, self.k):
                return self.k
            if few and _rank_mod(self._differences(few), PRIME) == self.k:
                return self.k
        rows = self._differences(range(len(self.verts)))
        return bareiss_rank(rows)[0] if rows else 0

    def _differences(self, ids) -> list[list[int]]:
        """The integer rows w_0 w_i (x_i − x_0) = y_i w_0 − y_0 w_i for the vertices
        ``ids`` after the first (0 here being ``ids[0]``)."""
        ids = list(ids)
        w0, *y0 = self.verts[ids[0]]
        return [[yi * w0 - y0i * self.verts[i][0]
                 for yi, y0i in zip(self.verts[i][1:], y0, strict=True)] for i in ids[1:]]

    def incidence(self) -> dict[int, list[int]]:
        """constraint → the vertices tight on it (only constraints tight somewhere):
        :func:`members_of` (of ``pairs`` when known)."""
        return members_of(self.tight, self.pairs)


#: a prime below 2^31: a product of two residues fits an int64
PRIME = 2_147_483_647


def _full_rank_floats(V: np.ndarray, k: int) -> bool:
    """The exact points that the float rows V round have affine rank k: the smallest
    singular value of the float differences exceeds a bound on their error and the
    SVD's (σ moves by at most the perturbation's norm, so the exact rank is full too).
    The entries are off by ≤ 4ε max|V| (+ underflow), the SVD's own error ≤ a few ε ‖D‖
    (margin 8); an inf or NaN anywhere fails the test."""
    D = V[1:] - V[0]
    top = float(np.abs(V).max())
    err = np.sqrt(D.size) * (_EPS * (4.0 * top + 8.0 * np.linalg.norm(D))
                             + underflow_floor(k, top))
    return bool(np.linalg.svd(D, compute_uv=False)[-1] > 2.0 * err)


def _rank_mod(rows: list[list[int]], p: int) -> int:
    """The rank of an integer matrix modulo the prime p < 2^31 (Gaussian elimination on
    int64 residues: products of two stay below 2^62). It is at most the rank over the
    integers, as every minor nonzero modulo p is nonzero."""
    M = np.array([[v % p for v in row] for row in rows], dtype=np.int64).reshape(len(rows), -1)
    rank = 0
    for c in range(M.shape[1]):
        nz = np.flatnonzero(M[rank:, c])
        if not len(nz):
            continue
        M[[rank, rank + nz[0]]] = M[[rank + nz[0], rank]]
        M[rank] = M[rank] * pow(int(M[rank, c]), p - 2, p) % p
        M[rank + 1:] = (M[rank + 1:] - M[rank + 1:, c, None] * M[rank]) % p
        rank += 1
        if rank == len(M):
            break
    return rank


def clip_to_fixpoint(P: ExactPolytope, H, scale: int, first: np.ndarray | None = None
                     ) -> None:
    """Clip P (integer coordinates y) by every valid halfspace of ``H``
    (:class:`rescon.geometry.halfspaces.Halfspaces`, whose floats are in units of
    y / scale, which P's float vertices then use too) that a vertex violates, until
    none is.

    Floats only choose the order (each round clips by, for every vertex, its most
    violated halfspace); "satisfied" is decided with a rounding bound — covering the
    float normals' own error (c_err · permanents) and the evaluation — and in exact
    integers for the pairs the bound leaves undecided. P only shrinks, so a halfspace
    satisfied at every vertex is satisfied for good and leaves the working set.
    ``first``: indices of H to clip by before the others (the likely facets).
    """
    if P.unit != scale:
        P.unit, P._fv = scale, None
    if first is not None and 0 < len(first) < len(H):
        _clip_rounds(P, H, np.asarray(first, dtype=np.int64))
    _clip_rounds(P, H, np.arange(len(H)))


def _clip_rounds(P: ExactPolytope, H, ids: np.ndarray) -> None:
    """clip_to_fixpoint on the halfspaces ``ids`` of H.

    Each round evaluates every (halfspace, vertex) pair in floats. A per-row bound
    (valid for every vertex, as |v_j| ≤ M) splits the pairs into surely violated,
    surely satisfied and near; rows with near pairs get the per-pair bound, and the
    pairs still undecided are decided exactly. A row satisfied at every vertex is
    done for good (P only shrinks); surely violated rows are clipped by the most
    violated per vertex, exactly violated ones all. Both bounds add the underflow
    term for the data's magnitude (the vertices lie in the data's box)."""
    Af, bf, Aabs, babs = H.af[ids], H.bf[ids], H.af_abs[ids], H.b_abs[ids]
    norms = np.linalg.norm(Af, axis=1)
    c = 2.0 * (P.k + 4) * _EPS
    floor = H.floor()
    while not P.is_empty and len(ids):
        V = P.float_vertices()
        M = np.abs(V).max()
        row_bound = (H.c_err * (Aabs.sum(axis=1) * M + babs)
                     + c * (np.abs(Af).sum(axis=1) * M + np.abs(bf)) + floor)
        S = Af @ V.T - bf[:, None]
        sure = S > row_bound[:, None]
        violated = sure.any(axis=1)
        # "surely satisfied" must be shown (S < −bound); NaN or inf stays undecided
        near_rows = np.flatnonzero(~violated & ~(S.max(axis=1) < -row_bound))
        done = ~violated
        done[near_rows] = False
        exact_cuts = []
        if len(near_rows):
            absV = np.abs(V).T
            Sn = S[near_rows]
            bound = (H.c_err * (Aabs[near_rows] @ absV + babs[near_rows, None])
                     + c * (np.abs(Af[near_rows]) @ absV + np.abs(bf[near_rows])[:, None])
                     + floor)
            for r, h in enumerate(near_rows):
                if (Sn[r] > bound[r]).any():
                    exact_cuts.append(int(ids[h]))
                    continue
                a, b = H.exact(int(ids[h]))
                if any(sum(ai * yi for ai, yi in zip(a, P.verts[v][1:], strict=True))
                       - b * P.verts[v][0] > 0 for v in np.flatnonzero(~(Sn[r] < -bound[r]))):
                    exact_cuts.append(int(ids[h]))
                else:
                    done[h] = True
        if not violated.any() and not exact_cuts:
            return
        picks = []
        if violated.any():
            with np.errstate(divide="ignore", invalid="ignore"):  # rows rounded to 0
                score = np.where(sure, S / norms[:, None], -np.inf)
            picks = [int(ids[h]) for h in np.unique(score.argmax(axis=0)[sure.any(axis=0)])]
        for g in picks + exact_cuts:
            P.clip(*H.exact(g))
            if P.is_empty:
                return
        keep = ~done  # the others hold at every vertex, and P only shrinks: for good
        ids, Af, bf, Aabs, babs, norms = (ids[keep], Af[keep], bf[keep], Aabs[keep],
                                          babs[keep], norms[keep])


def _row_floats(row: tuple[int, ...]) -> np.ndarray:
    """An integer row divided by a power of two into floats of magnitude < 2^64
    (positive scaling: the signs of multipliers are those of the row itself)."""
    shift = max(max(abs(v) for v in row).bit_length() - 64, 0)
    return np.array([float(v >> shift) for v in row])


def _nnls_first(ids: list[int], rows, a: tuple[int, ...]) -> list[int]:
    """The tight constraints ordered for the Farkas search: those a float NNLS
    min ‖Σ μ_i â_i + â‖, μ ≥ 0 (rows scaled to unit size), puts in the support first,
    by decreasing μ — at a degenerate vertex (14 tight rows, k = 5, 1239-bit
    integers) the first subsets then hold the multipliers instead of the last of
    C(14, 5). Only an order: every subset is still tried and checked exactly."""
    from scipy.optimize import nnls

    M = np.array([_row_floats(rows[i]) for i in ids]).T
    try:
        mu, _ = nnls(M / np.abs(M).max(axis=0), -_row_floats(a) / np.abs(_row_floats(a)).max())
    except (RuntimeError, ValueError):  # scipy's NNLS at its iteration limit: no order
        return ids
    return [ids[j] for j in np.argsort(-mu, kind="stable")]
