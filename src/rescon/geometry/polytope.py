"""Exact polytopes in R^k by clipping: the double-description step on integers.

A vertex is stored in homogeneous integer coordinates (w, y) with w > 0 (the point
y / w) together with the set of constraints tight at it (a Python-int bitset).
Clipping by a·y ≤ b keeps the vertices with s = a·y − b·w ≤ 0 and adds, for every
edge (u, v) with s_u < 0 < s_v, the point s_v·u − s_u·v. Two vertices span an edge
iff no third vertex is tight on every constraint tight at both (the combinatorial
adjacency test of the double-description method, exact for polytopes of any
dimension, degenerate ones included). All arithmetic is on Python ints.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from fractions import Fraction
from math import gcd

import numpy as np

from .exact import bareiss_rank, nullspace_exact

__all__ = ["ExactPolytope", "Farkas"]

_EPS = 2.0**-53


@dataclass(frozen=True)
class Farkas:
    """Constraints (indices) and λ ≥ 0 with Σ λ_i a_i = 0 and Σ λ_i b_i < 0."""

    ids: tuple[int, ...]
    multipliers: tuple[Fraction, ...]


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
    verts: list[tuple[int, ...]] = field(default_factory=list)  # (w, y_1..y_k)
    tight: list[int] = field(default_factory=list)
    farkas: Farkas | None = None  # set when a clip empties the polytope

    @classmethod
    def box(cls, lo: list[int], hi: list[int]) -> ExactPolytope:
        """The box lo ≤ y ≤ hi (lo_j < hi_j), constraints 2j: −y_j ≤ −lo_j and
        2j+1: y_j ≤ hi_j."""
        k = len(lo)
        P = cls(k)
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
        return [sum(ai * yi for ai, yi in zip(a, v[1:], strict=True)) - b * v[0]
                for v in self.verts]

    def clip(self, a: tuple[int, ...], b: int) -> bool:
        """Intersect with a·y ≤ b; False (and nothing recorded) if it cuts nothing."""
        s = self.slack(a, b)
        if all(x <= 0 for x in s):
            return False
        hid = len(self.a)
        bit = 1 << hid
        if all(x > 0 for x in s):
            self.farkas = self._farkas(a, b, s)
            self.a.append(a)
            self.b.append(b)
            self.verts, self.tight = [], []
            return True
        need = self.k - 1
        ins = [i for i, x in enumerate(s) if x < 0]
        outs = [i for i, x in enumerate(s) if x > 0]
        new_v, new_t = [], []
        for v in outs:
            tv = self.tight[v]
            for u in ins:
                z = self.tight[u] & tv
                if z.bit_count() < need or not self._edge(u, v, z):
                    continue
                su, sv = s[u], s[v]
                p = tuple(sv * cu - su * cv for cu, cv in zip(self.verts[u], self.verts[v],
                                                                strict=True))
                new_v.append(_normalise(p))
                new_t.append(z | bit)
        keep = [i for i, x in enumerate(s) if x <= 0]
        self.verts = [self.verts[i] for i in keep] + new_v
        self.tight = [self.tight[i] | (bit if s[i] == 0 else 0) for i in keep] + new_t
        self.a.append(a)
        self.b.append(b)
        return True

    def _edge(self, u: int, v: int, z: int) -> bool:
        """u, v span an edge: no other vertex is tight on all of z."""
        return not any((t & z) == z for i, t in enumerate(self.tight) if i != u and i != v)

    def _farkas(self, a: tuple[int, ...], b: int, s: list[int]) -> Farkas:
        """All vertices violate a·y ≤ b. At the vertex v* minimising a·y over the
        current polytope, −a is a nonnegative combination Σ μ_i a_i of k independent
        tight constraints (LP duality), so 1·(a, b) + Σ μ_i (a_i, b_i) has vector part 0
        and scalar part b − a·v* < 0."""
        vals = [Fraction(x, v[0]) for x, v in zip(s, self.verts, strict=True)]
        star = min(range(len(vals)), key=vals.__getitem__)  # min a·y − b
        tight_ids = [i for i in range(len(self.a)) if self.tight[star] >> i & 1]
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
        return np.array([[yi / v[0] for yi in v[1:]] for v in self.verts], dtype=np.float64
                        ).reshape(len(self.verts), self.k)

    def fraction_vertices(self) -> list[tuple[Fraction, ...]]:
        return [tuple(Fraction(yi, v[0]) for yi in v[1:]) for v in self.verts]

    def dim(self) -> int:
        """Affine dimension of the vertex set (−1 if empty)."""
        if not self.verts:
            return -1
        w0, *y0 = self.verts[0]
        rows = [[yi * w0 - y0i * v[0] for yi, y0i in zip(v[1:], y0, strict=True)]
                for v in self.verts[1:]]
        return bareiss_rank(rows)[0] if rows else 0

    def tight_vertices(self, h: int) -> list[int]:
        return [i for i, t in enumerate(self.tight) if t >> h & 1]

    def face_dim(self, members: list[int]) -> int:
        if not members:
            return -1
        w0, *y0 = self.verts[members[0]]
        rows = [[yi * w0 - y0i * self.verts[m][0]
                 for yi, y0i in zip(self.verts[m][1:], y0, strict=True)] for m in members[1:]]
        return bareiss_rank(rows)[0] if rows else 0


def clip_to_fixpoint(P: ExactPolytope, H, scale: int) -> None:
    """Clip P (scaled integer coordinates y = scale · x) by every valid halfspace of
    ``H`` (:class:`rescon.geometry.halfspaces.Halfspaces`) that a vertex violates,
    until none is.

    Floats only choose the order (each round clips by, for every vertex, its most
    violated halfspace); "satisfied" is decided with a rounding bound — covering the
    float normals' own error (c_err · permanents) and the evaluation — and in exact
    integers for the pairs the bound leaves undecided. P only shrinks, so a halfspace
    satisfied at every vertex is satisfied for good and leaves the working set.
    """
    ids = np.arange(len(H))
    Af, bf, Aabs, babs = H.af, H.bf, H.af_abs, H.b_abs
    c = 2.0 * (P.k + 4) * _EPS
    while not P.is_empty and len(ids):
        V = P.float_vertices() / scale
        absV = np.abs(V).T
        S = Af @ V.T - bf[:, None]
        bound = (H.c_err * (Aabs @ absV + babs[:, None])
                 + c * (np.abs(Af) @ absV + np.abs(bf)[:, None]))
        sure = S > bound
        unsure = np.abs(S) <= bound
        if sure.any():
            score = np.where(sure, S / np.linalg.norm(Af, axis=1)[:, None], -np.inf)
            for h in np.unique(score.argmax(axis=0)[sure.any(axis=0)]):
                P.clip(*H.exact(int(ids[h])))
                if P.is_empty:
                    return
        else:
            for h in np.flatnonzero(unsure.any(axis=1)):
                a, b = H.exact(int(ids[h]))
                if any(sum(ai * yi for ai, yi in zip(a, P.verts[v][1:], strict=True))
                       - b * P.verts[v][0] > 0 for v in np.flatnonzero(unsure[h])):
                    P.clip(a, b)
                    break
            else:
                return
        keep = (sure | unsure).any(axis=1)  # the others hold at every vertex: for good
        ids, Af, bf, Aabs, babs = ids[keep], Af[keep], bf[keep], Aabs[keep], babs[keep]
