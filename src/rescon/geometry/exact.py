"""Exact arithmetic for point sets: integer coordinates, ranks, affine hulls.

Every float is a dyadic rational m·2^e, so a point set X ∈ R^{n×d} of floats is
exactly ``X_int / D`` for one power of two D and a Python-int matrix ``X_int``.
All combinatorial decisions of the safe-kernel code (which side of a hyperplane a
point lies on, affine dimensions) are taken on these integers, or on floats only
when a rounding-error bound proves the float answer right.
"""

from __future__ import annotations

import functools
import itertools
from collections.abc import Iterable
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np

__all__ = [
    "AffineHull",
    "ExactPoints",
    "affine_hull",
    "bareiss_rank",
    "cross_all",
    "exact_points",
    "exact_sum",
    "float_view",
    "fraction_str",
    "halfspaces_json",
    "nullspace_exact",
    "solve_exact",
]


@dataclass(frozen=True)
class ExactPoints:
    """X = ints / scale exactly, with ``ints`` a tuple of rows of Python ints."""

    ints: tuple[tuple[int, ...], ...]
    scale: int  # a power of two

    @property
    def n(self) -> int:
        return len(self.ints)

    def fraction(self, i: int) -> tuple[Fraction, ...]:
        return tuple(Fraction(v, self.scale) for v in self.ints[i])


def exact_points(X: np.ndarray) -> ExactPoints:
    """The exact integer form of a finite float array (n, d)."""
    ratios = [[float(v).as_integer_ratio() for v in row] for row in X.tolist()]
    scale = max((den for row in ratios for _, den in row), default=1)
    ints = tuple(tuple(num * (scale // den) for num, den in row) for row in ratios)
    return ExactPoints(ints, scale)


#: the data keep their own units when the largest |coordinate| lies in [2^-WINDOW,
#: 2^WINDOW] (integer data stay integers: exact float arithmetic, int64 paths)
WINDOW = 32


def float_view(rows: list[tuple[int, ...]], scale: int) -> tuple[np.ndarray, int, bool]:
    """The integer rows (the points times ``scale``, a power of two) as floats
    ``rows / unit``, for the float filters, with ``unit`` a power of two: ``scale``
    itself (the data's own values) when the largest |coordinate| lies in
    [2^-WINDOW, 2^WINDOW], else the unit that brings it into [1/2, 1). Since
    Ψ(2^j X) = 2^j Ψ(X), the filters then see magnitudes ≤ 2^WINDOW at any scale of
    the data, and no product of a few of them overflows.

    Each entry is v / unit correctly rounded (Python's int / int: it cannot overflow).
    ``exact`` says no entry was rounded: an entry v = odd · 2^t (odd < 2^53, from a
    float) is representable iff its last bit 2^t / unit is ≥ 2^-1074; entries more
    than ~2^1074 below the largest can fall below that and are rounded (to 0 or a
    subnormal), which the caller's filters must allow for."""
    top = max((abs(v) for row in rows for v in row), default=0)
    low = 0
    for row in rows:
        for v in row:
            low |= abs(v)
    s = scale.bit_length() - 1  # scale = 2^s; 2^(L−1) ≤ top < 2^L
    L = top.bit_length()
    unit = scale if top == 0 or -WINDOW <= L - 1 - s < WINDOW else 1 << L
    u = unit.bit_length() - 1
    exact = low == 0 or (low & -low).bit_length() - 1 - u >= -1074
    Yf = np.array([[v / unit for v in row] for row in rows], dtype=np.float64)
    return Yf.reshape(len(rows), -1), unit, exact


def bareiss_rank(rows: list[list[int]]) -> tuple[int, list[int], list[int]]:
    """Rank of an integer matrix by fraction-free (Bareiss) elimination.

    Returns (rank, pivot columns, pivot rows) — the pivot rows index ``rows``
    and give a maximal independent subset of them.
    """
    if not rows:
        return 0, [], []
    m = [list(r) for r in rows]
    order = list(range(len(m)))
    ncols = len(m[0])
    rank, prev = 0, 1
    pivots: list[int] = []
    for col in range(ncols):
        pr = next((i for i in range(rank, len(m)) if m[i][col] != 0), None)
        if pr is None:
            continue
        m[rank], m[pr] = m[pr], m[rank]
        order[rank], order[pr] = order[pr], order[rank]
        piv = m[rank][col]
        for i in range(rank + 1, len(m)):
            f = m[i][col]
            row_i, row_r = m[i], m[rank]
            for j in range(col, ncols):
                row_i[j] = (row_i[j] * piv - f * row_r[j]) // prev
        prev = piv
        pivots.append(col)
        rank += 1
        if rank == len(m):
            break
    return rank, pivots, order[:rank]


@dataclass(frozen=True)
class AffineHull:
    """aff(X) of an exact point set: dimension k, k+1 affinely independent points
    ``basis`` (indices, basis[0] the origin), and k ``coords`` such that projecting
    onto those coordinates is injective on aff(X)."""

    dim: int
    basis: tuple[int, ...]
    coords: tuple[int, ...]

    def lift(self, P: ExactPoints, y: tuple[Fraction, ...]) -> tuple[Fraction, ...]:
        """The point of aff(X) whose ``coords`` are y (exact)."""
        o = P.fraction(self.basis[0])
        if self.dim == 0:
            return o
        if self.dim == len(o):  # full-dimensional: the coordinates are all of x
            return tuple(y)
        dirs = [[Fraction(P.ints[b][j] - P.ints[self.basis[0]][j], P.scale)
                 for j in range(len(o))] for b in self.basis[1:]]
        # y - o[coords] = Σ c_i dirs_i[coords]
        M = [[dirs[i][c] for i in range(self.dim)] for c in self.coords]
        rhs = [y[t] - o[c] for t, c in enumerate(self.coords)]
        coef = solve_exact(M, rhs)
        assert coef is not None, "projection onto the pivot coordinates is injective"
        return tuple(o[j] + sum(coef[i] * dirs[i][j] for i in range(self.dim))
                     for j in range(len(o)))

    def equalities(self, P: ExactPoints) -> list[tuple[tuple[Fraction, ...], Fraction]]:
        """d − k independent equalities a·x = b satisfied by every point of aff(X):
        x_j = (the affine function of the pivot coordinates) for each other j."""
        d = len(P.ints[0])
        out = []
        for j in range(d):
            if j in self.coords:
                continue
            # x_j − Σ_t g_t x_{coords[t]} = h on aff(X): fit through the basis points
            rows = [[Fraction(P.ints[b][c], P.scale) for c in self.coords] + [Fraction(1)]
                    for b in self.basis]
            rhs = [Fraction(P.ints[b][j], P.scale) for b in self.basis]
            sol = solve_exact(rows, rhs)
            assert sol is not None
            a = [Fraction(0)] * d
            a[j] = Fraction(1)
            for t, c in enumerate(self.coords):
                a[c] -= sol[t]
            out.append((tuple(a), sol[-1]))
        return out


def affine_hull(P: ExactPoints) -> AffineHull:
    """Exact affine hull of the points (Bareiss on the differences p_i − p_0)."""
    p0 = P.ints[0]
    diffs = [[a - b for a, b in zip(row, p0, strict=True)] for row in P.ints[1:]]
    diffs_t = [list(col) for col in zip(*diffs, strict=True)] if diffs else []
    # rank and pivot *rows* of the transposed matrix = pivot coordinates
    k, _, coords = bareiss_rank(diffs_t)
    if k == 0:
        return AffineHull(0, (0,), ())
    _, _, rows = bareiss_rank(diffs)
    return AffineHull(k, (0, *(r + 1 for r in sorted(rows))), tuple(sorted(coords)))


def _rref(A: list[list[Fraction]], ncols: int) -> list[int]:
    """Reduce A in place to reduced row echelon form on its first ``ncols`` columns
    (the others, e.g. a right-hand side, follow along); returns the pivot columns."""
    pivots: list[int] = []
    r = 0
    for col in range(ncols):
        pr = next((i for i in range(r, len(A)) if A[i][col] != 0), None)
        if pr is None:
            continue
        A[r], A[pr] = A[pr], A[r]
        piv = A[r][col]
        A[r] = [v / piv for v in A[r]]
        for i in range(len(A)):
            if i != r and A[i][col] != 0:
                f = A[i][col]
                A[i] = [vi - f * vr for vi, vr in zip(A[i], A[r], strict=True)]
        pivots.append(col)
        r += 1
        if r == len(A):
            break
    return pivots


def solve_exact(M: list[list[Fraction]], rhs: list[Fraction]) -> list[Fraction] | None:
    """The unique solution of M c = rhs (M with at least as many rows as columns), or
    None when M has dependent columns or the system is inconsistent."""
    A = [list(map(Fraction, row)) + [Fraction(r)] for row, r in zip(M, rhs, strict=True)]
    ncols = len(A[0]) - 1
    if len(_rref(A, ncols)) < ncols:
        return None
    if any(A[i][-1] != 0 for i in range(ncols, len(A))):  # extra rows: consistent?
        return None
    return [A[i][-1] for i in range(ncols)]


#: below this many bits an int's decimal string is well inside Python's default limit on
#: int → str conversions (4300 digits ≈ 14 284 bits)
_STR_BITS = 14_000


def _int_str(n: int) -> str:
    """Decimal digits of n at any size: halves by a power of ten (divmod) until each
    part is below the limit on int → str."""
    if n < 0:
        return "-" + _int_str(-n)
    if n.bit_length() < _STR_BITS:
        return str(n)
    k = int(n.bit_length() * 0.30103) // 2  # about half the digits
    high, low = divmod(n, _power_of_ten(k))
    return _int_str(high) + _int_str(low).zfill(k)


@functools.lru_cache(maxsize=256)
def _power_of_ten(k: int) -> int:
    """10**k, kept: the halves of one number's digits ask for the same powers."""
    return 10**k


def exact_sum(values: Iterable[Fraction]) -> Fraction:
    """Σ values exactly, added in a balanced tree: adding n fractions of unrelated
    denominators one by one grows the running sum's denominator at every step (O(n²)
    in its size); in pairs each level adds numbers of equal size (1 095 vertices of a
    d = 5 kernel: 4.4 s one by one, 1.3 s in pairs)."""
    level = [Fraction(v) for v in values]
    if not level:
        return Fraction(0)
    while len(level) > 1:
        level = [level[i] + level[i + 1] if i + 1 < len(level) else level[i]
                 for i in range(0, len(level), 2)]
    return level[0]


def fraction_str(x: Fraction) -> str:
    """x as str(Fraction) writes it ("p/q", or "p" for an integer), at any size (a
    kernel of points spanning the exponent range can have vertices of > 4300 digits)."""
    x = Fraction(x)
    num = _int_str(x.numerator)
    return num if x.denominator == 1 else f"{num}/{_int_str(x.denominator)}"


def halfspaces_json(rows) -> list[dict[str, Any]]:
    """Rows (a, b) of a·x ≤ b (or = b) as certificate JSON: {"a": [...], "b": ...}, the
    rationals written by :func:`fraction_str`."""
    return [{"a": [fraction_str(v) for v in a], "b": fraction_str(b)} for a, b in rows]


def nullspace_exact(M: list[list[Fraction]]) -> list[list[Fraction]]:
    """A basis of {c : M c = 0} (exact reduced row echelon form)."""
    if not M:
        return []
    A = [list(map(Fraction, row)) for row in M]
    cols = len(A[0])
    pivots = _rref(A, cols)
    free = [c for c in range(cols) if c not in pivots]
    basis = []
    for fc in free:
        v = [Fraction(0)] * cols
        v[fc] = Fraction(1)
        for i, pc in enumerate(pivots):
            v[pc] = -A[i][fc]
        basis.append(v)
    return basis


def cross_all(R: np.ndarray) -> np.ndarray:
    """The generalised cross products of the m × (m+1) integer matrices R[p] (an object
    array (P, m, m+1) of Python ints): x_j = (−1)^j det R_{−j} (R without column j), so
    R x = 0, and x = 0 iff the rows are dependent. All P at once, by Laplace expansion
    along the rows — the minors of the first r rows on every r-set of columns from those
    of the first r − 1: Σ_r r·C(m+1, r) products of arrays, exact."""
    m = R.shape[1]
    minors = {(c,): R[:, 0, c] for c in range(m + 1)}
    for r in range(1, m):
        nxt = {}
        for cols in itertools.combinations(range(m + 1), r + 1):
            # Σ_i (−1)^(r+i) R[r, c_i] · minor(cols − c_i), from a term with sign +
            terms = [R[:, r, c] * minors[cols[:i] + cols[i + 1:]] for i, c in enumerate(cols)]
            acc = terms[r % 2]
            for i in range(r % 2 + 1, len(terms)):
                acc = acc + terms[i] if (r + i) % 2 == 0 else acc - terms[i]
            if r % 2:
                acc = acc - terms[0]
            nxt[cols] = acc
        minors = nxt
    full = tuple(range(m + 1))
    out = [minors[full[:j] + full[j + 1:]] for j in range(m + 1)]
    return np.stack([-x if j % 2 else x for j, x in enumerate(out)], axis=1)
