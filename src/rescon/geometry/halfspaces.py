"""The valid halfspaces of Ψ(X, F): hyperplanes through k points with ≤ F outside.

In coordinates where the points span R^k (see :mod:`.exact`), Tukey-depth theory
gives

    Ψ(X, F) = ⋂ { {y : a·y ≤ a·p_0} : a ⊥ a hyperplane through k affinely
                  independent points p_0..p_{k−1}, #{q : a·q > a·p_0} ≤ F },

O(n^k) candidates instead of C(n, F) subsets. Each candidate's side counts are
decided by the float filter of :mod:`._candidates`; the undecided ones (points within
the rounding-error bound of the hyperplane, or degenerate subsets) are re-decided in
exact integer arithmetic, so the set returned never depends on a tolerance. On small
inputs in the plane and in space a second float filter comes first: the orientation
about each of the k + 1 points in turn, with a proven bound
(:func:`._scan_np.side_signs`) — a hyperplane through a far point and a tight cluster
cancels about the far point, not about a cluster point.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from math import comb, factorial, gcd
from typing import Any

import numpy as np

from .._rounding import MIN_NORMAL, underflow_floor
from .._rounding import UNIT_ROUNDOFF as _EPS
from ._budget import MAX_WORK, PYTHON_STEP, require
from .exact import cross_all

__all__ = ["MAX_CANDIDATE_COST", "Halfspaces", "candidate_cost", "valid_halfspaces"]

#: refuse inputs whose candidate enumeration needs more point tests than this (the
#: budget of every exponential table, :mod:`._budget`)
MAX_CANDIDATE_COST = MAX_WORK
#: from this many distinct points on, lines in the plane are counted by the angular
#: sweep (O(n² log n)) instead of the direct scan (O(n³))
SWEEP_MIN_POINTS = 150
#: float cofactors with |C|₁ below this fraction of their permanent are replaced by the
#: rounded exact normal (their relative error would exceed ~1e-12)
ILL_CONDITIONED = 1e-3
#: up to this many point tests (:func:`candidate_cost`) the candidates are classified
#: by numpy (:mod:`._scan_np`, the same decisions) and the undecided ones in Python
#: integers: numba's start-up — ~0.5 s warm, ~10 s compiling on a cold cache — would
#: dominate such inputs (a 12-point kernel in the plane needs 660 tests)
SMALL_SCAN = 20_000
#: the compiled scan's tables of all k-subsets of range(m) (:func:`_all_subsets`) are
#: kept for the last few (m, k) of up to this many subsets
SUBSET_CACHE_ROWS = 1_000_000
_SUBSET_TABLES: dict[tuple[int, int], np.ndarray] = {}


@dataclass
class Halfspaces:
    """Valid halfspaces, halfspace h being sign[h] · C_h · (y − p_0) ≤ 0 for the
    hyperplane through the k points ``through[h]`` (indices into the unique points).

    Floats (unscaled coordinates, for guidance): ``af[h]·y ≤ bf[h]`` with per-entry
    error ≤ ``err[h]`` · (|y|_1 + 1)-weighted bound terms given by ``af_abs``
    (see :func:`rescon.geometry.polytope.clip_to_fixpoint`). Exact (scaled integer
    coordinates): :meth:`exact`.
    """

    Yi: list[tuple[int, ...]]
    through: np.ndarray  # (h, k) int
    sign: np.ndarray  # (h,) ±1
    af: np.ndarray  # (h, k)
    bf: np.ndarray  # (h,)
    af_abs: np.ndarray  # (h, k) permanents bounding the error of af
    b_abs: np.ndarray  # (h,) the same for bf
    outside: np.ndarray  # (h,) points surely strictly outside (at most F)
    c_err: float
    box: tuple[np.ndarray, np.ndarray, np.ndarray]  # the points' (min, max, median), floats
    _cache: dict[int, Any] = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.sign)

    def row_terms(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(Σ_j |af|_j, Σ_j af_abs_j, |bf|) per row, for per-row rounding bounds."""
        out = self._cache.get(-1)
        if out is None:
            out = self._cache[-1] = (np.abs(self.af).sum(axis=1), self.af_abs.sum(axis=1),
                                     np.abs(self.bf))
        return out

    def floor(self) -> float:
        """The underflow term of every float bound on these rows (|coordinates| ≤ the
        data's box; :func:`rescon._rounding.underflow_floor`)."""
        lo, hi, _ = self.box
        top = max(float(np.abs(lo).max(initial=0.0)), float(np.abs(hi).max(initial=0.0)))
        return underflow_floor(len(lo), top)

    def exact(self, h: int) -> tuple[tuple[int, ...], int]:
        """(a, b), primitive integers: a·y ≤ b in the scaled integer coordinates."""
        out = self._cache.get(h)
        if out is None:
            self._store(h, exact_normal(self.Yi, self.through[h]))
            out = self._cache[h]
        return out

    def exact_all(self, hs) -> None:
        """:meth:`exact` for the rows ``hs`` at once (into the cache): their cofactor
        normals (−1)^(k−1) × the generalised cross products of the difference rows
        p_i − p_0 (:func:`.exact.cross_all`, one numpy pass of Python ints per
        minor instead of a Bareiss elimination per row)."""
        k = len(self.Yi[0])
        todo = [h for h in dict.fromkeys(np.asarray(hs, dtype=np.int64).tolist())
                if h not in self._cache]
        if k < 2 or len(todo) < 2:
            return
        Y = np.empty((len(self.Yi), k), dtype=object)
        Y[:] = self.Yi
        sub = self.through[todo]
        # the signed normals a, b = a·p_0, and (a, b) divided by their gcd (:meth:`_store`
        # row by row), on object arrays of Python ints
        a = cross_all(Y[sub[:, 1:]] - Y[sub[:, :1]]) * (
            self.sign[todo] * (-1) ** (k - 1)).astype(object)[:, None]
        b = (a * Y[sub[:, 0]]).sum(axis=1)
        g = np.gcd.reduce(np.column_stack([a, b]), axis=1)
        for h, row, off in zip(todo, (a // g[:, None]).tolist(), (b // g).tolist(),
                               strict=True):
            self._cache[h] = tuple(row), off

    def _store(self, h: int, normal) -> None:
        """Cache row h from the cofactor normal of its subset (signed, primitive)."""
        a = tuple(int(self.sign[h]) * c for c in normal)
        b = sum(ai * pi for ai, pi in zip(a, self.Yi[self.through[h][0]], strict=True))
        self._cache[h] = _primitive(a, b)


def candidate_cost(n_unique: int, k: int) -> int:
    """Point tests needed to classify all candidates: C(n, k) · (n − k)."""
    return comb(n_unique, k) * max(n_unique - k, 0)


def _scan_plan(m: int, k: int, sweep: bool) -> tuple[bool, float, float]:
    """(exact_only, work, bytes) of classifying the C(m, k) candidates by the method
    that will run (:mod:`._budget` units): the angular sweep in the plane,
    ~m² log₂ m; else the float scan, C(m, k) · (m − k) tests plus, for k ≥ 4, the
    k(k − 1) products of a subset's cofactors and the k 2^k steps (and 2^k-entry
    tables) of the minors of each of its first k − 1 points that it builds
    (:mod:`._candidates`: at most one per subset, or per (k − 1)-subset of the points)
    — or, when that costs more, every subset in Python integers (Bareiss cofactors,
    O(k⁴), and an exact scan)."""
    count = comb(m, k)
    tables = count * (4 * k + 25)  # subsets, counts, flags
    if sweep:
        return False, 4.0 * m * m * max(m.bit_length(), 1), tables
    if k < 4:
        return False, count * (m - k), tables
    minors = min(count, comb(m, k - 1)) * k * 2.0**k
    exact = PYTHON_STEP * (k**4 + (m - k) * k)
    if count * exact < count * k * (k - 1) + minors:
        return True, count * exact, tables
    return False, count * (m - k + k * (k - 1)) + minors, tables + 16.0 * 2**k


def _exact_float_bits(k: int) -> int:
    """Integer coordinates below 2^B make the float orientation exact:
    k! · (2^{B+1})^k < 2^53."""
    return int((53 - np.log2(factorial(k))) // k) - 2


def _rounded_normals(Yi, through: np.ndarray, sign: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, float]:
    """Float rows for exact-only candidates: each exact normal sign · C (integers),
    scaled by a power of two to max |·| ∈ [1/2, 1) and correctly rounded, so
    |af − a| ≤ ε|a| + 2^-1075 componentwise (a the scaled exact normal); returns
    (af, af_abs, c_err) with af_abs = |af|(1 + 4ε) + 2^-1022 and c_err = 8ε, the
    convention of :class:`Halfspaces`."""
    af = np.zeros(through.shape)
    for r, (sub, s) in enumerate(zip(through.tolist(), sign.tolist(), strict=True)):
        normal = exact_normal(Yi, sub)
        unit = 1 << max(map(abs, normal)).bit_length()
        af[r] = [s * v / unit for v in normal]
    return af, np.abs(af) * (1.0 + 4 * _EPS) + MIN_NORMAL, 8 * _EPS


def _int_det(rows: list[list[int]]) -> int:
    """det of a square integer matrix: closed forms up to 3 × 3, beyond them Bareiss's
    fraction-free elimination (O(m³) steps; each entry after step c is a minor of
    order c + 1, so every division is exact) — never an m!-term expansion."""
    m = len(rows)
    if m == 0:
        return 1
    if m == 1:
        return rows[0][0]
    if m == 2:
        return rows[0][0] * rows[1][1] - rows[0][1] * rows[1][0]
    if m == 3:
        (a, b, c), (d, e, f), (g, h, i) = rows
        return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
    M = [list(r) for r in rows]
    sign, prev = 1, 1
    for c in range(m - 1):
        p = next((i for i in range(c, m) if M[i][c]), None)
        if p is None:
            return 0
        if p != c:
            M[c], M[p] = M[p], M[c]
            sign = -sign
        piv, top = M[c][c], M[c]
        for row in M[c + 1:]:
            f = row[c]
            for j in range(c + 1, m):
                row[j] = (row[j] * piv - f * top[j]) // prev
        prev = piv
    return sign * M[m - 1][m - 1]


def exact_normal(Yi: list[tuple[int, ...]], subset) -> tuple[int, ...]:
    """Integer cofactor normal C of the hyperplane through the points ``subset``
    (zero vector when they are affinely dependent): s(q) = C·(q − p_0)."""
    k = len(Yi[0])
    p0 = Yi[subset[0]]
    D = [[Yi[i][j] - p0[j] for j in range(k)] for i in subset[1:]]
    if k == 1:
        return (1,)
    out = []
    for j in range(k):
        minor = [row[:j] + row[j + 1:] for row in D]
        out.append((-1) ** (k - 1 + j) * _int_det(minor))
    return tuple(out)


def _primitive(a: tuple[int, ...], b: int) -> tuple[tuple[int, ...], int]:
    g = abs(b)
    for v in a:
        g = gcd(g, v)
    return tuple(v // g for v in a), b // g


def valid_halfspaces(Y: np.ndarray, Yi: list[tuple[int, ...]], W: np.ndarray, F: int,
                     exact_view: bool = True) -> Halfspaces:
    """All valid halfspaces of the unique points Y (float, (m, k)) with exact integer
    coordinates Yi (Yi = Y · unit, unit a power of two) and multiplicities W.

    ``exact_view``: Y is exactly Yi / unit (:func:`.exact.float_view`); otherwise some
    tiny entries were rounded, and only the filters whose bounds allow for that (the
    underflow term) run — not the angular sweep nor the exact float expansions.

    Raises InputError when the enumeration would exceed MAX_CANDIDATE_COST.
    """
    m, k = Y.shape
    count = comb(m, k)
    small = candidate_cost(m, k) <= SMALL_SCAN  # no numba (the same sets, see SMALL_SCAN)
    if small:
        from ._scan_np import classify, cofactors, in_range, k_subsets
    else:
        from ._candidates import ANGLE_ERR, classify, cofactors
        from ._expansions import in_range
    bits = max(abs(v) for row in Yi for v in row).bit_length()
    # k = 1: the sign of a float difference is exact — of exact floats; k ≥ 2: small
    # integers give exact float orientations of Y = Yi / unit only while no product
    # of k entries underflows or overflows, which float_view's units ensure
    # (2^-32 ≤ max |Y| < 2^32); a direct call in other units gets the bounded filters
    exact_floats = exact_view and (k == 1 or (
        bits <= _exact_float_bits(k) and 2.0**-32 <= float(np.abs(Y).max()) < 2.0**32))
    # small integers in the plane: two distinct directions between data points differ
    # by an angle ≥ 1/(2D²) (D the coordinate span: |cross| ≥ 1, |u|, |v| ≤ √2 D), so
    # when that exceeds the sweep's window (4·ANGLE_ERR, 2× margin) a point inside the
    # window is exactly on the line
    sweep = k == 2 and m >= SWEEP_MIN_POINTS and exact_view and not small
    separated = sweep and exact_floats and 16 * ANGLE_ERR * 2 * max(
        max(col) - min(col) for col in zip(*Yi)) ** 2 < 1
    sweep = sweep and (separated or not exact_floats)  # else the direct scan decides
    exact_only, work, nbytes = _scan_plan(m, k, sweep)
    require(f"the safe kernel of {m} distinct points in dimension {k}", work, nbytes,
            "reduce n or d")
    c_err = 0.0 if exact_floats else 4.0 * (3 * k + factorial(k) + 4) * _EPS
    # exact floats: Y holds small integers over a unit ≤ 2^(bits + 32), so no product of
    # k + 1 of them underflows either
    floor = 0.0 if exact_floats else underflow_floor(k, float(np.abs(Y).max()))
    expansions = exact_view and in_range(Y)
    subsets = k_subsets(m, k) if small else _all_subsets(m, k, count)
    if sweep:
        from ._candidates import sweep_pairs_2d

        plus, minus, unc, degenerate = sweep_pairs_2d(
            np.ascontiguousarray(Y, dtype=np.float64), W.astype(np.int64), subsets)
        if separated:
            unc[:] = 0  # on the line: on neither side
    elif exact_only:  # no float filter: every subset is decided exactly below
        plus, minus, degenerate = (np.zeros(count, dtype=t) for t in (np.int64, np.int64, np.bool_))
        unc = np.full(count, int(W.sum()), dtype=np.int64)
    elif small:  # with the decided (subset, point) pairs, for the pivot filter below
        plus, minus, unc, degenerate, signs = classify(
            np.ascontiguousarray(Y, dtype=np.float64), W.astype(np.int64), subsets, c_err, F,
            floor, pairs=True)
    else:
        plus, minus, unc, degenerate = classify(
            np.ascontiguousarray(Y, dtype=np.float64), W.astype(np.int64), subsets, c_err, F,
            floor)
    live = ~degenerate
    sure_plus = live & (plus + unc <= F)
    sure_minus = live & (minus + unc <= F)
    sure_p, sure_m = np.flatnonzero(sure_plus), np.flatnonzero(sure_minus)
    maybe = np.flatnonzero(live & (((plus <= F) & ~sure_plus) | ((minus <= F) & ~sure_minus)))
    pivots = small and expansions and not exact_only
    n_plus, n_minus, dependent = _exact_side_counts(
        Y, Yi, W, subsets[maybe], F, expansions and not small,  # exactly
        pivots=pivots, start=signs[maybe] if pivots else None)
    add_p = ~dependent & (n_plus <= F) & ~sure_plus[maybe]
    add_m = ~dependent & (n_minus <= F) & ~sure_minus[maybe]
    idx = np.concatenate([sure_p, sure_m, maybe[add_p], maybe[add_m]])
    sign = np.repeat(np.array([1, -1, 1, -1], dtype=np.int64),
                     [len(sure_p), len(sure_m), int(add_p.sum()), int(add_m.sum())])
    out = np.concatenate([plus[sure_p], minus[sure_m], n_plus[add_p], n_minus[add_m]])
    through = subsets[idx].astype(np.int64)
    p0 = Y[through[:, 0]] if len(idx) else np.zeros((0, k))
    if exact_only:
        af, af_abs, c_err = _rounded_normals(Yi, through, sign)
    else:
        af, af_abs = cofactors(np.ascontiguousarray(Y, dtype=np.float64), subsets[idx])
        af *= sign[:, None]
    if k >= 3 and not exact_floats and (expansions if k == 3 else exact_view):
        # nearly dependent subsets (collinear triples; in k ≥ 4 a hyperplane through
        # far outliers and a tight cluster, whose cofactors cancel ~1e12-fold): their
        # float cofactors' error (relative to the permanents) can exceed a tiny kernel,
        # so take the exact normals, rounded (error ≤ ε|a_j| + 2^-1075); the others
        # keep their cofactors with the permanents scaled to the smaller c_err
        c_new = max(8, k + 4) * _EPS  # |af − a| ≤ ε|a|; |bf − b| ≤ ~(k + 1.1)ε Σ|a_j p0_j|
        ill = np.flatnonzero(np.abs(af).sum(axis=1) < ILL_CONDITIONED * af_abs.sum(axis=1))
        af_abs = af_abs * (1.1 * c_err / c_new)
        c_err = c_new
        if len(ill):
            af[ill] = (_exact_normals3(Y, Yi, through[ill], small) if k == 3
                       else _rounded_cofactors(Y, Yi, through[ill])) * sign[ill, None]
            af_abs[ill] = np.abs(af[ill]) * (1.0 + 4 * _EPS) + (k > 3) * MIN_NORMAL
    bf = np.einsum("ij,ij->i", af, p0)
    b_abs = np.einsum("ij,ij->i", af_abs, np.abs(p0))
    if c_err == 0.0 and k >= 3:  # exact rows: drop repeats (coplanar data: one plane many times)
        keep = _distinct_rows(af, bf)
        idx, through, sign, af, bf, af_abs, b_abs, out = (
            v[keep] for v in (idx, through, sign, af, bf, af_abs, b_abs, out))
    box = (Y.min(axis=0), Y.max(axis=0), np.median(Y, axis=0))
    hs = Halfspaces(Yi, through, sign, af, bf, af_abs, b_abs, out, c_err, box)
    # an affinely dependent subset has every other point within the rounding bound,
    # so only subsets with no point surely off their hyperplane can be degenerate
    # (their zero normal has no primitive form: exact_normal, not hs.exact)
    suspect = [h for h in np.flatnonzero(plus[idx] + minus[idx] == 0)
               if not any(exact_normal(Yi, through[h]))]
    if suspect:
        keep = np.setdiff1d(np.arange(len(hs)), suspect)
        hs = Halfspaces(Yi, through[keep], sign[keep], af[keep], bf[keep], af_abs[keep],
                        b_abs[keep], out[keep], c_err, box)
    return hs


def _all_subsets(m: int, k: int, count: int) -> np.ndarray:
    """The table of all count = C(m, k) k-subsets of range(m), in lexicographic order
    (:func:`._candidates.k_subsets`), kept for the last 4 (m, k) of at most
    SUBSET_CACHE_ROWS rows, so that repeated kernels of one size do not rebuild it
    (1.8–4 ms for C(50, 4)). Shared and read-only by convention: every reader indexes
    it (copies) or reads it."""
    out = _SUBSET_TABLES.get((m, k))
    if out is None:
        from ._candidates import k_subsets

        out = k_subsets(m, k, count)
        if count <= SUBSET_CACHE_ROWS:
            while len(_SUBSET_TABLES) >= 4:
                _SUBSET_TABLES.pop(next(iter(_SUBSET_TABLES)), None)
            _SUBSET_TABLES[(m, k)] = out
    return out


def _exact_normals3(Y: np.ndarray, Yi: list[tuple[int, ...]], triples: np.ndarray,
                    small: bool) -> np.ndarray:
    """The normals (p_j − p_i) × (p_k − p_i) of the triples (i, j, k) of rows of Y, each
    component its exact value rounded: by numba expansions (within 3 ulps), or for
    small inputs correctly rounded from the integer normal (:func:`_rounded_cofactors`:
    for k = 3 the cofactor normal is this cross product; Y = Yi / unit exactly)."""
    if not small:
        from ._expansions import normals3

        out = np.empty((len(triples), 3))
        normals3(np.ascontiguousarray(Y, dtype=np.float64), triples, out)
        return out
    return _rounded_cofactors(Y, Yi, triples)


def _rounded_cofactors(Y: np.ndarray, Yi: list[tuple[int, ...]], subsets: np.ndarray
                       ) -> np.ndarray:
    """The cofactor normals of the subsets in the float coordinates Y = Yi / unit (Y
    exact, unit a power of two): the integer normal over unit^(k−1), each component
    correctly rounded (Fraction to float)."""
    k = Y.shape[1]
    i, j = np.unravel_index(np.abs(Y).argmax(), Y.shape)
    unit = Fraction(Yi[i][j]) / Fraction(float(Y[i, j]))
    den = unit ** (k - 1)
    num, dnm = den.denominator, den.numerator
    if k == 3:  # the cross product (p_1 − p_0) × (p_2 − p_0), in plain Python ints
        flat: list[int] = []
        for i0, i1, i2 in subsets.tolist():
            (x, y, z), (x1, y1, z1), (x2, y2, z2) = Yi[i0], Yi[i1], Yi[i2]
            a0, a1, a2, b0, b1, b2 = x1 - x, y1 - y, z1 - z, x2 - x, y2 - y, z2 - z
            flat += (a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)
        return _quotients(flat, num, dnm).reshape(-1, 3)
    if k < 2 or not len(subsets):
        return np.array([[float(c / den) for c in exact_normal(Yi, sub)]
                         for sub in subsets.tolist()], dtype=np.float64).reshape(-1, k)
    # all normals at once (:func:`.exact.cross_all` on object arrays of Python ints,
    # (−1)^(k−1) × the cross product is :func:`exact_normal`), then c / den = c·q / p
    # (den = p/q) by int true division, which is correctly rounded like float(Fraction)
    P = np.empty((len(Yi), k), dtype=object)
    P[:] = Yi
    N = cross_all(P[subsets[:, 1:]] - P[subsets[:, :1]])
    if k % 2 == 0:
        N = -N
    return _quotients(N.ravel().tolist(), num, dnm).reshape(-1, k)


def _quotients(ints: list[int], num: int, dnm: int) -> np.ndarray:
    """c · num / dnm correctly rounded for each integer c (num, dnm > 0). For num = 1,
    dnm = 2^e: float(c) is c correctly rounded and the scaling by 2^-e is exact unless
    the result leaves the normal range, so each such result is the correctly rounded
    quotient; a c beyond the float range (OverflowError) or a result below 2^-1022
    (nonzero c: the scaling may round a second time) is divided as integers, Python's
    int / int being correctly rounded."""
    if num == 1 and dnm & (dnm - 1) == 0:
        try:
            out = np.ldexp(np.array([float(c) for c in ints], dtype=np.float64),
                           1 - dnm.bit_length())
        except OverflowError:
            pass
        else:
            for i in np.flatnonzero(np.abs(out) < MIN_NORMAL).tolist():
                out[i] = ints[i] / dnm
            return out
    return np.array([c * num / dnm for c in ints], dtype=np.float64)


def _distinct_rows(af: np.ndarray, bf: np.ndarray) -> np.ndarray:
    """Indices (in order) of the first of each set of equal halfspaces a·x ≤ b, for
    exact integral rows that fit in int64 (compared in lowest terms); all rows
    otherwise."""
    rows = np.arange(len(bf))
    M = np.column_stack([af, bf])
    if not len(bf) or not np.all(M == np.round(M)) or np.abs(M).max() >= 2.0**62:
        return rows
    M = M.astype(np.int64)
    g = np.gcd.reduce(np.abs(M), axis=1)
    g[g == 0] = 1
    M //= g[:, None]
    lo = M.min(axis=0)
    span = M.max(axis=0) - lo + 1
    if np.prod(span.astype(np.float64)) < 2.0**62:  # one mixed-radix int64 key per row
        key = np.zeros(len(M), dtype=np.int64)
        for j in range(M.shape[1]):
            key = key * span[j] + (M[:, j] - lo[j])
        _, first = np.unique(key, return_index=True)
        return np.sort(first)
    order = np.lexsort(M.T[::-1])  # stable: each run of equal rows starts at its first
    S = M[order]
    starts = np.ones(len(S), dtype=np.bool_)
    starts[1:] = np.any(S[1:] != S[:-1], axis=1)
    return np.sort(order[starts])


#: (subset, point) pairs per block of :func:`_exact_side_counts`' integer path
EXACT_BLOCK = 4096


def _exact_side_counts(Y, Yi, W, subsets, F, expansions: bool, pivots: bool = False,
                       start: np.ndarray | None = None
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Exact weighted numbers of points strictly on the + and − side of the hyperplane
    through each subset (those above F may be lower bounds), and whether the subset is
    affinely dependent: by floating-point expansions in numba for k ≤ 3 when
    ``expansions`` (Y exact and in their range), else in integers — after, when
    ``pivots`` (k ≤ 3, Y exact and in range), the pivoted float filter
    (:func:`._scan_np.side_signs`), which settles every subset whose other points it
    all decides: its counts are then exact and complete, and it is independent (a
    dependent subset has every det exactly 0). The rest go to the integers.
    ``start``: signs already proven (:func:`._scan_np.classify` with ``pairs``)."""
    k = Y.shape[1]
    plus = np.zeros(len(subsets), dtype=np.int64)
    minus = np.zeros(len(subsets), dtype=np.int64)
    dependent = np.zeros(len(subsets), dtype=np.bool_)
    if k in (2, 3) and expansions:
        from ._expansions import side_counts

        side_counts(np.ascontiguousarray(Y, dtype=np.float64), W.astype(np.int64),
                    np.ascontiguousarray(subsets), F, plus, minus, dependent)
        return plus, minus, dependent
    if pivots and k in (2, 3) and len(Y) > k and len(subsets):
        from ._scan_np import side_signs

        sg = np.zeros((len(subsets), len(Y)), dtype=np.int8) if start is None else \
            np.array(start, dtype=np.int8)
        sg[np.arange(len(subsets))[:, None], subsets] = 2  # members: on the hyperplane
        sg = side_signs(np.ascontiguousarray(Y, dtype=np.float64), subsets, sg)
        done = np.flatnonzero(np.all(sg != 0, axis=1))
        Wi = np.asarray(W, dtype=np.int64)
        plus[done] = (sg[done] == 1) @ Wi
        minus[done] = (sg[done] == -1) @ Wi
        rest = np.flatnonzero(np.any(sg == 0, axis=1))
        if len(rest):
            p, m, dep = _exact_side_counts(Y, Yi, W, subsets[rest], F, False)
            plus[rest], minus[rest], dependent[rest] = p, m, dep
        return plus, minus, dependent
    # in integers: s(q) = C·(q − p_0) for every point q at once (object arrays, in
    # blocks of ≤ EXACT_BLOCK (subset, point) pairs); a member q of the subset lies on
    # its hyperplane (s = 0), so it counts on neither side; a dependent subset's zero
    # normal puts every point there
    P = np.array(Yi, dtype=object).reshape(len(Yi), k)
    Wi = np.asarray(W, dtype=np.int64)
    block = max(1, EXACT_BLOCK // max(1, len(Yi)))
    for s0 in range(0, len(subsets), block):
        sub = subsets[s0:s0 + block]
        N = np.array([exact_normal(Yi, t) for t in sub.tolist()], dtype=object
                     ).reshape(len(sub), k)
        S = ((P[None, :, :] - P[sub[:, 0]][:, None, :]) * N[:, None, :]).sum(axis=2)
        plus[s0:s0 + len(sub)] = np.asarray(S > 0, dtype=np.bool_) @ Wi
        minus[s0:s0 + len(sub)] = np.asarray(S < 0, dtype=np.bool_) @ Wi
        dependent[s0:s0 + len(sub)] = ~np.asarray(N != 0, dtype=np.bool_).any(axis=1)
    return plus, minus, dependent
