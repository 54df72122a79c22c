"""The edges of an exact polytope, for the ``adjacency`` of a ``safe_kernel`` certificate.

The checker (certificates/FORMAT.md, ``safe_kernel`` step 5) proves P = conv(V) from
them in work linear in the number of vertices instead of enumerating C(m, d) facet
subsets; this module only proposes them (exactly, so that a correct certificate is
never refused).
"""

from __future__ import annotations

import math
from collections import Counter
from fractions import Fraction

from .polytope import _bits

Row = tuple[tuple[Fraction, ...], Fraction]


def _integer_row(a: tuple[Fraction, ...], b: Fraction) -> tuple[list[int], int]:
    """s·(a, b) with integer entries for the least s > 0 (the same halfspace)."""
    s = math.lcm(*(t.denominator for t in (*a, b)))
    return [int(t * s) for t in a], int(b * s)


def vertex_adjacency(verts: tuple[tuple[Fraction, ...], ...], rows: tuple[Row, ...]
                     ) -> list[list[int]]:
    """For each vertex of the polytope P = conv(verts) ⊆ {a·x ≤ b : (a, b) ∈ rows}
    (``rows`` tight at every vertex of P's facets), the indices of the vertices joined to
    it by an edge, increasing.

    Two vertices v ≠ w are adjacent iff the face F_C = {x ∈ P : a·x = b, (a, b) ∈ C} for C =
    the rows tight at both has exactly the vertices v and w: F_C is the smallest face
    containing [v, w] (a row tight at both ends is tight on the segment), and a face with
    two vertices is the segment between them.  With three or more vertices P has
    dimension ≥ 2, so every edge lies on a row not tight everywhere: the candidates w
    share such a row with v."""
    nv = len(verts)
    if nv <= 2:
        return [[j for j in range(nv) if j != i] for i in range(nv)]
    everywhere = (1 << nv) - 1
    scaled = [_integer_row(v, Fraction(1)) for v in verts]  # v = X / e, integers
    members: list[int] = []  # row -> bitmask of the vertices tight on it
    for a, b in rows:
        A, B = _integer_row(a, b)
        mask = 0
        for i, (X, e) in enumerate(scaled):
            if sum(x * y for x, y in zip(A, X)) == B * e:
                mask |= 1 << i
        if mask != everywhere:
            members.append(mask)
    on = [[h for h, mask in enumerate(members) if mask >> i & 1] for i in range(nv)]
    out: list[list[int]] = []
    for i in range(nv):
        shared = Counter(j for h in on[i] for j in _bits(members[h]) if j != i)
        pair = []
        for j in sorted(shared):
            mask = everywhere
            for h in set(on[i]).intersection(on[j]):
                mask &= members[h]
            if mask == (1 << i) | (1 << j):
                pair.append(j)
        out.append(pair)
    return out

