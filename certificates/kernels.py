"""Safe-kernel certificate kinds (``kernel_point``, ``kernel_empty``, ``safe_kernel``).

Part of the trusted checker (see FORMAT.md, "Safe kernels"): Python standard library
only, exact ``Fraction`` / integer arithmetic, never imports rescon or numpy.

X = multiset of n points in R^d (1 <= d <= 8), 0 <= F < n, and the safe kernel

    Psi(X, F) = intersection of conv(S) over all S ⊆ X with |S| = n - F
              = {x : Tukey depth of x >= F + 1}.

Facts used (proofs in FORMAT.md):

(a) a halfspace {a·x <= b} with at most F points strictly outside contains Psi (the
    >= n - F points inside it have their hull inside it); an equality a·x = b that
    holds at every point contains conv(X) ⊇ Psi.
(b) with k = dim aff(X) and pivot coordinates J (|J| = k, the projection to J is
    injective on aff(X)): x ∈ Psi iff x ∈ aff(X) and x_J lies in every halfspace that
    is bounded by a hyperplane through k affinely independent projected points and
    has at most F points strictly outside.
(c) Tverberg: F + 1 pairwise disjoint index groups, each with x in its hull, put a
    whole group inside every S with |S| = n - F, so x ∈ Psi.

Cheap tests run first (the Tukey depth of a claimed point along each axis, the Farkas
sums modulo a prime); every exact stage has a size, work and bit-size limit (work in
steps on WORD_BITS-bit integers, :func:`_cost`), beyond which the part is recorded as
unchecked (``ctx.trust``), never as invalid.

check.py calls :func:`install` with its strict-JSON helpers (``Invalid``, ``_obj``,
``_int``, ``_array``, ``_tname``) and its ``Unchecked`` exception, so the exceptions
raised here are the ones its ``check()`` catches however check.py was loaded (script,
package module, or by path).
"""

from __future__ import annotations

import math
import re
from bisect import bisect_left, bisect_right
from collections.abc import Callable, Iterable
from fractions import Fraction
from itertools import combinations
from operator import mul
from typing import Any

MAX_POINTS = 100_000  # resource limit on n
MAX_DIM = 8  # largest dimension d
MAX_CONSTRAINTS = 10_000  # halfspaces / equalities / facets per certificate
#: listed vertices per certificate (each later stage is bounded by its own work limit)
MAX_VERTICES = 25_000
MAX_EVAL_WORK = 20_000_000  # (#constraints) * n, evaluating constraints at the points
MAX_RATIONAL_CHARS = 100_000  # longest "p/q" string (exact vertex means get long)
#: C(u, k) * (u + #test points + normal cost) for (b); beyond: unchecked
MAX_HALFSPACE_WORK = 4_000_000
MAX_POLY_WORK = 10_000_000  # vertex / ray enumeration of P; beyond: unchecked
#: d >= 4: the normal fan's share, in multiples of (b)'s work, before (b) takes over
FAN_OVER_ENUMERATION = 50
MAX_NUMBER_BITS = 32_768  # numerator / denominator of one input rational; beyond: unchecked
MAX_DIGITS = MAX_NUMBER_BITS * 30_103 // 100_000 + 1  # decimal digits of such a number
MAX_SCALE_BITS = 65_536  # a common denominator (of all points, of a sum); beyond: unchecked
WORD_BITS = 1_024  # integers up to this size count as one unit of work

_HEAD = ("rescon_certificate", "kind")
_RATIONAL = re.compile(r"-?[0-9]+(/[0-9]+)?")

Vec = tuple  # a point: tuple of Fractions (or ints after scaling)

# strict-JSON helpers, bound to check.py's by install()
Invalid: Any = None
Unchecked: Any = None
_obj: Any = None
_int: Any = None
_array: Any = None
_tname: Any = None


def install(invalid: type, obj: Callable, int_: Callable, array: Callable,
            tname: Callable, *, unchecked: type) -> dict[str, Callable]:
    """Bind check.py's helpers and exception classes; return the kinds defined here."""
    global Invalid, Unchecked, _obj, _int, _array, _tname
    Invalid, Unchecked, _obj, _int, _array, _tname = invalid, unchecked, obj, int_, array, tname
    return {
        "kernel_point": kind_kernel_point,
        "kernel_empty": kind_kernel_empty,
        "safe_kernel": kind_safe_kernel,
    }


# --------------------------------------------------------------------------- #
# numbers, points, constraints
# --------------------------------------------------------------------------- #


def _rat(x: Any, where: str) -> Fraction:
    """A rational: a JSON integer, a finite JSON float (its exact binary value), or a
    string "p/q" / "p" (p, q decimal integers, q > 0, optional leading '-').  Numerators
    and denominators beyond MAX_NUMBER_BITS bits exceed the checker's limits (unchecked)."""
    if isinstance(x, bool):
        raise Invalid(f"{where} must be a rational number, got boolean")
    if isinstance(x, int):
        return _bounded(Fraction(x), where)
    if isinstance(x, float):
        if not math.isfinite(x):
            raise Invalid(f"{where} = {x!r} is not a finite number")
        return Fraction(x)
    if isinstance(x, str):
        if not _RATIONAL.fullmatch(x):
            raise Invalid(f"{where} = {_short(repr(x))} is not a rational string like "
                          "\"-3/4\" or \"5\"")
        p, _, q = x.partition("/")
        if len(x) > MAX_RATIONAL_CHARS:
            raise _too_big(where, f"a string of {len(x)} characters")
        num = _decimal(p.lstrip("-"), where) * (-1 if p.startswith("-") else 1)
        den = _decimal(q, where) if q else 1
        if den == 0:
            raise Invalid(f"{where} = {_short(repr(x))} has denominator 0")
        return _bounded(Fraction(num, den), where)
    raise Invalid(f"{where} must be a rational number (integer, finite number or "
                  f"\"p/q\" string), got {_tname(x)}")


def _decimal(digits: str, where: str) -> int:
    """The value of a string of decimal digits, up to MAX_DIGITS significant digits
    (converted in chunks: Python's int() refuses more than 4300 digits by default)."""
    digits = digits.lstrip("0") or "0"
    if len(digits) > MAX_DIGITS:
        raise _too_big(where, f"{len(digits)} decimal digits")
    value = 0
    for i in range(0, len(digits), 4000):
        chunk = digits[i:i + 4000]
        value = value * 10 ** len(chunk) + int(chunk)
    return value


def _too_big(where: str, what: str) -> Exception:
    return Unchecked("number size", f"{where} ({what}) exceeds the checker's limit of "
                     f"{MAX_NUMBER_BITS} bits per numerator / denominator")


def _bounded(t: Fraction, where: str) -> Fraction:
    bits = max(t.numerator.bit_length(), t.denominator.bit_length())
    if bits > MAX_NUMBER_BITS:
        raise _too_big(where, f"a number of {bits} bits")
    return t


def _vec(x: Any, where: str, d: int) -> Vec:
    _array(x, where)
    if len(x) != d:
        raise Invalid(f"{where} has {len(x)} coordinates, expected d = {d}")
    return tuple(_rat(t, f"{where}[{j}]") for j, t in enumerate(x))


def _points(c: dict) -> tuple[list[Vec], int]:
    """(points, d): n >= 1 points with the same d coordinates, 1 <= d <= MAX_DIM."""
    arr = _array(c["points"], "points")
    if not arr:
        raise Invalid("points is empty (n >= 1 is required)")
    if len(arr) > MAX_POINTS:
        raise Unchecked("size limit", f"points: n = {len(arr)} exceeds the checker's limit "
                        f"of {MAX_POINTS} points")
    d = len(_array(arr[0], "points[0]"))
    if not 1 <= d <= MAX_DIM:
        raise Invalid(f"points[0] has {d} coordinates: the dimension d must be 1..{MAX_DIM}")
    return [_vec(p, f"points[{i}]", d) for i, p in enumerate(arr)], d


def _constraints(x: Any, where: str, d: int) -> list[tuple[Vec, Fraction]]:
    """A list of {"a": [d rationals], "b": rational}."""
    _array(x, where)
    if len(x) > MAX_CONSTRAINTS:
        raise Unchecked("size limit", f"{where}: {len(x)} entries exceed the checker's "
                        f"limit of {MAX_CONSTRAINTS}")
    out = []
    for i, h in enumerate(x):
        w = f"{where}[{i}]"
        _obj(h, w, ("a", "b"))
        out.append((_vec(h["a"], f"{w}.a", d), _rat(h["b"], f"{w}.b")))
    return out


def _multipliers(x: Any, where: str, m: int, nonneg: bool) -> list[Fraction]:
    _array(x, where)
    if len(x) != m:
        raise Invalid(f"{where} has {len(x)} entries, expected {m} (one per constraint)")
    out = [_rat(t, f"{where}[{i}]") for i, t in enumerate(x)]
    if nonneg:
        for i, t in enumerate(out):
            if t < 0:
                raise Invalid(f"{where}[{i}] = {_fq(t)} is negative")
    return out


def _short(s: str, limit: int = 40) -> str:
    return s if len(s) <= limit else f"{s[:limit // 2 - 2]}...{s[2 - limit // 2:]}"


def _fq(t: Fraction | int) -> str:
    """A number for a message, abbreviated when long."""
    try:
        return _short(str(t))
    except ValueError:  # beyond Python's limit on int-to-string digits
        return "<a number with thousands of digits>"


def _fmtv(v: Vec) -> str:
    return "(" + ", ".join(_fq(t) for t in v) + ")"


def _fmti(idx: list[int], limit: int = 8) -> str:
    s = ", ".join(str(i) for i in idx[:limit])
    return s + (", ..." if len(idx) > limit else "")


# --------------------------------------------------------------------------- #
# exact integer linear algebra
# --------------------------------------------------------------------------- #


def _den_lcm(vectors: list[Vec], limit: int | None = None) -> int:
    """Least common denominator of all coordinates; 0 as soon as it has more than
    ``limit`` bits (distinct large denominators make it grow without bound)."""
    D = 1
    for v in vectors:
        for t in v:
            q = t.denominator
            if D % q:
                D = D // math.gcd(D, q) * q
                if limit is not None and D.bit_length() > limit:
                    return 0
    return D


def _bit_size(rows: list[list[int]]) -> int:
    """Largest bit length of an entry (that of the largest |entry|)."""
    return max((max(max(r), -min(r)).bit_length() for r in rows if r), default=0)


def _cost(work: int, bits: int) -> int:
    """``work`` arithmetic steps on integers of ``bits`` bits, counted in steps on
    WORD_BITS-bit integers (a product costs about the square of the size)."""
    return work * max(1, -(-bits // WORD_BITS)) ** 2


def _scaled_points(pts: list[Vec], ctx: Any, part: str) -> tuple[list[list[int]], int] | None:
    """(D * p for every point, D) for the points' common denominator D, or None (and
    ``part`` recorded as unchecked) when D has more than MAX_SCALE_BITS bits."""
    D = _den_lcm(pts, MAX_SCALE_BITS)
    if not D:
        ctx.trust("bit size", f"{part}: the points' common denominator exceeds the "
                  f"checker's limit of {MAX_SCALE_BITS} bits")
        return None
    return _scaled(pts, D), D


def _scaled_test(x: Vec, D: int) -> tuple[list[int], int]:
    """(X, e) with integers X, e > 0 and D * x = X / e: a test point in the coordinates of
    the points scaled by D, with a denominator of its own."""
    y = [t * D for t in x]
    e = _den_lcm([y])
    return _scaled([y], e)[0], e


def _scaled(vectors: list[Vec], D: int) -> list[list[int]]:
    """D * v for every v (integers when D is a common denominator)."""
    return [[t.numerator * (D // t.denominator) for t in v] for v in vectors]


def _int_constraint(a: Vec, b: Fraction) -> tuple[list[int], int]:
    """(A, B) = s * (a, b) with coprime integer entries, s > 0: the same halfspace /
    hyperplane (a common factor would only inflate every product that uses the row)."""
    s = _den_lcm([a + (b,)])
    row = _scaled([a + (b,)], s)[0]
    g = math.gcd(*row)
    if g > 1:
        row = [x // g for x in row]
    return row[:-1], row[-1]


def _dot(a: list[int] | Vec, v: list[int] | Vec) -> Any:
    return sum(map(mul, a, v))


def _sub(u: list[int], v: list[int]) -> list[int]:
    return [x - y for x, y in zip(u, v)]


def _reduce(v: list[int], basis: list[tuple[int, list[int]]]) -> list[int]:
    """v minus a combination of the basis rows, zero in every pivot column (scaled by a
    nonzero integer, so "v ∈ span(basis)" iff the result is 0).

    ``basis`` is reduced: row (p, b) has b[p] != 0 and 0 in the other rows' pivots."""
    for p, b in basis:
        c = v[p]
        if c:
            bp = b[p]
            v = [bp * x - c * y for x, y in zip(v, b)]
            g = math.gcd(*v)
            if g > 1:
                v = [x // g for x in v]
    return v


def _extend(basis: list[tuple[int, list[int]]], v: list[int] | Vec) -> bool:
    """Add v to the reduced basis if it is independent of it; True iff added."""
    r = _reduce(list(v), basis)
    if not any(r):
        return False
    p = next(j for j, x in enumerate(r) if x)
    rp = r[p]
    # eliminate the new pivot column from the earlier rows (their pivots stay: r is 0 there)
    for t, (q, b) in enumerate(basis):
        c = b[p]
        if c:
            nb = [rp * x - c * y for x, y in zip(b, r)]
            g = math.gcd(*nb)
            basis[t] = (q, [x // g for x in nb] if g > 1 else nb)
    basis.append((p, r))
    return True


def _echelon(rows: list[list[int]], stop: int | None = None) -> list[tuple[int, list[int]]]:
    """A reduced basis (pivot column, row) of span(rows); its length is the rank.
    Stops early once the rank reaches ``stop``."""
    basis: list[tuple[int, list[int]]] = []
    for v in rows:
        if stop is not None and len(basis) >= stop:
            break
        _extend(basis, v)
    return basis


def _rank(rows: list[list[int]]) -> int:
    return len(_echelon(rows))


def _det(M: list[list[int]]) -> int:
    """Determinant of a square integer matrix (fraction-free Bareiss elimination)."""
    A = [row[:] for row in M]
    m = len(A)
    sign, prev = 1, 1
    for k in range(m - 1):
        if A[k][k] == 0:
            for i in range(k + 1, m):
                if A[i][k]:
                    A[k], A[i] = A[i], A[k]
                    sign = -sign
                    break
            else:
                return 0
        akk = A[k][k]
        for i in range(k + 1, m):
            Ai, Ak = A[i], A[k]
            aik = Ai[k]
            for j in range(k + 1, m):
                Ai[j] = (akk * Ai[j] - aik * Ak[j]) // prev
        prev = akk
    return sign * A[m - 1][m - 1] if m else 1


def _normal(vecs: list[list[int]], k: int) -> list[int]:
    """Generalized cross product of k - 1 vectors in Z^k: a_j = (-1)^j det(M without
    column j), M = the vectors as rows.  a · v = det([v; M]) = 0 for every row v, and
    a = 0 iff the vectors are linearly dependent.  k = 1: a = (1)."""
    if k == 1:
        return [1]
    if k == 2:
        (x, y), = vecs
        return [-y, x]
    if k == 3:
        (a1, a2, a3), (b1, b2, b3) = vecs
        return [a2 * b3 - a3 * b2, a3 * b1 - a1 * b3, a1 * b2 - a2 * b1]
    return [(-1) ** j * _det([row[:j] + row[j + 1:] for row in vecs]) for j in range(k)]


def _normal_steps(k: int) -> int:
    """Products :func:`_normal` spends: k Bareiss determinants of order k − 1, about
    (k − 1)³/3 products each, beyond the closed forms of k ≤ 3."""
    return k if k <= 3 else k * (k - 1) ** 3 // 3


def _solve_steps(m: int) -> int:
    """Products :func:`_solve` spends on an m x m system, counted as 2 m³: Gauss–Jordan
    takes m²(m + 1) Fraction operations, each a few integer products and a gcd."""
    return 2 * m ** 3


def _solve(rows: list[list[int]], rhs: list[int]) -> Vec | None:
    """The unique solution of rows · x = rhs (square, exact), or None if singular."""
    m = len(rows)
    A = [[Fraction(t) for t in r] + [Fraction(b)] for r, b in zip(rows, rhs)]
    for k in range(m):
        piv = next((i for i in range(k, m) if A[i][k]), None)
        if piv is None:
            return None
        A[k], A[piv] = A[piv], A[k]
        Ak = A[k]
        inv = 1 / Ak[k]
        for i in range(m):
            if i != k and A[i][k]:
                f = A[i][k] * inv
                Ai = A[i]
                for j in range(k, m + 1):
                    Ai[j] -= f * Ak[j]
    return tuple(A[i][m] / A[i][i] for i in range(m))


# --------------------------------------------------------------------------- #
# (a): constraints valid for Psi
# --------------------------------------------------------------------------- #


def _valid_for_psi(E: list[tuple[Vec, Fraction]], ewhere: str, H: list[tuple[Vec, Fraction]],
                   hwhere: str, pts: list[Vec], F: int, ctx: Any) -> None:
    """Fact (a): every equality of E holds at every point and every halfspace of H has at
    most F points strictly outside.  Costs #constraints x n products of scaled integers;
    beyond MAX_EVAL_WORK (weighted by bit size, :func:`_cost`) or when the points' common
    denominator is too large, the part is recorded as unchecked."""
    part = f"{ewhere} and {hwhere} contain the kernel"
    sp = _scaled_points(pts, ctx, part)
    if sp is None:
        return
    P, D = sp
    Ei = [_int_constraint(a, b) for a, b in E]
    Hi = [_int_constraint(a, b) for a, b in H]
    bits = max(_bit_size(P), _bit_size([a + [b] for a, b in Ei + Hi]) + D.bit_length())
    work = _cost(len(Ei + Hi) * len(P), bits)
    if work > MAX_EVAL_WORK:
        ctx.trust("constraint evaluation", f"{part}: evaluating {len(Ei + Hi)} constraints "
                  f"at {len(P)} points ({bits}-bit numbers) needs work {work} > "
                  f"{MAX_EVAL_WORK}")
        return
    _check_equalities(Ei, ewhere, P, D)
    _check_halfspaces(Hi, hwhere, P, D, F)


def _check_halfspaces(H: list[tuple[list[int], int]], where: str, P: list[list[int]], D: int,
                      F: int) -> None:
    """Each halfspace A·x <= B (integer rows) has at most F points strictly outside (fact
    (a)). ``P`` = the points scaled by D (integers)."""
    for i, (A, B) in enumerate(H):
        BD = B * D
        out = [j for j, p in enumerate(P) if _dot(A, p) > BD]
        if len(out) > F:
            raise Invalid(f"{where}[{i}] has {len(out)} points strictly outside (points "
                          f"{_fmti(out)}), more than F = {F}: it need not contain the kernel")


def _check_equalities(E: list[tuple[list[int], int]], where: str, P: list[list[int]],
                      D: int) -> None:
    """Each equality A·x = B (integer rows) holds at every point (so it contains
    conv(X) ⊇ Psi)."""
    for i, (A, B) in enumerate(E):
        BD = B * D
        for j, p in enumerate(P):
            if _dot(A, p) != BD:
                raise Invalid(f"{where}[{i}] does not hold at points[{j}] (a·p != b)")


def _refute_by_axes(pts: list[Vec], F: int, tests: list[Vec], names: list[str]) -> None:
    """A necessary condition for x ∈ Psi that costs one sort per coordinate: Tukey depth
    >= F + 1, so each closed halfspace {y_j >= x_j}, {y_j <= x_j} holds >= F + 1 points.
    Raises Invalid naming the first test point and coordinate that fail.  (Catches, e.g.,
    a corner of the bounding box, or any x when F = n - 1 and the points differ.)"""
    n = len(pts)
    for j in range(len(pts[0])):
        col = sorted(p[j] for p in pts)
        lo, hi = col[min(F, n - 1)], col[max(n - 1 - F, 0)]
        for x, name in zip(tests, names):
            # #{y_j <= x_j} <= F iff x_j < col[F]; #{y_j >= x_j} <= F iff x_j > col[n-1-F]
            # (F < n); the counts themselves only for the message
            if lo <= x[j] <= hi:
                continue
            above = n - bisect_left(col, x[j])  # points with y_j >= x_j
            below = bisect_right(col, x[j])  # points with y_j <= x_j
            for count, rel in ((above, ">="), (below, "<=")):
                if count <= F:
                    raise Invalid(f"{name} is not in the safe kernel: the closed halfspace "
                                  f"y[{j}] {rel} {_fq(x[j])} holds only {count} <= F = {F} "
                                  f"points, so its Tukey depth is at most {count}")


# --------------------------------------------------------------------------- #
# (b): membership by the candidate halfspaces
# --------------------------------------------------------------------------- #


def _violated_halfspace(Q: list[list[int]], W: list[int], F: int,
                        T: list[tuple[list[int], int]]) -> tuple[tuple[int, ...], int, int] | None:
    """First (subset, #outside, t) such that the test point T[t] = (X, e), i.e. X / e, is
    strictly outside a halfspace bounded by the hyperplane through the k affinely
    independent points Q[subset] with at most F points (counted with multiplicity W)
    strictly outside; None if there is none."""
    k = len(Q[0])
    if k == 1:
        return _violated_interval(Q, W, F, T)
    QW = list(zip(Q, W))
    for sub in combinations(range(len(Q)), k):
        q0 = Q[sub[0]]
        a = _normal([_sub(Q[i], q0) for i in sub[1:]], k)
        if not any(a):
            continue  # affinely dependent
        b = _dot(a, q0)
        plus = minus = 0
        for q, w in QW:
            s = _dot(a, q) - b
            if s > 0:
                plus += w
            elif s < 0:
                minus += w
            else:
                continue
            if plus > F and minus > F:
                break
        if plus <= F:
            for t, (x, e) in enumerate(T):
                if _dot(a, x) > b * e:
                    return sub, plus, t
        if minus <= F:
            for t, (x, e) in enumerate(T):
                if _dot(a, x) < b * e:
                    return sub, minus, t
    return None


def _violated_interval(Q: list[list[int]], W: list[int], F: int,
                       T: list[tuple[list[int], int]]) -> tuple[tuple[int, ...], int, int] | None:
    """k = 1 of :func:`_violated_halfspace` in O(u log u): "y >= q" is valid iff at most F
    points are < q, and these q form a prefix of the sorted values, so all of them are
    implied by the largest, lo; likewise "y <= q" by the smallest valid q, hi."""
    order = sorted(range(len(Q)), key=lambda i: Q[i][0])
    lo, below, seen = order[0], 0, 0
    for i in order:  # ascending: seen = number of points < Q[i]
        if seen > F:
            break
        lo, below = i, seen
        seen += W[i]
    hi, above, seen = order[-1], 0, 0
    for i in reversed(order):
        if seen > F:
            break
        hi, above = i, seen
        seen += W[i]
    for t, ((x,), e) in enumerate(T):
        if x < Q[lo][0] * e:
            return (lo,), below, t
        if x > Q[hi][0] * e:
            return (hi,), above, t
    return None


def _in_kernel_halfspaces(pts: list[Vec], F: int, tests: list[Vec], names: list[str],
                          ctx: Any, what: str) -> str:
    """Fact (b) for every test point; raises Invalid naming the first one not in Psi.

    The points are scaled by their common denominator D (an affine bijection, which maps
    Psi to Psi); each test point keeps a denominator of its own (:func:`_scaled_test`),
    so distinct test denominators never multiply.  The affine-hull test costs n·d²
    products, the enumeration of the C(u, k) hyperplanes through the u distinct
    projected points C(u, k) * (u + #tests) (k = 1: u + #tests, by sorting), both
    weighted by bit size (:func:`_cost`); beyond MAX_EVAL_WORK, MAX_HALFSPACE_WORK or
    MAX_SCALE_BITS the part ``what`` is recorded as unchecked."""
    d = len(pts[0])
    part = f"{what} in the safe kernel (proof 'halfspaces')"
    sp = _scaled_points(pts, ctx, part)
    if sp is None:
        return "halfspaces: not checked"
    P, D = sp
    T = [_scaled_test(x, D) for x in tests]
    bits = max(_bit_size(P), _bit_size([x + [e] for x, e in T]))
    work = _cost(len(P) * d * d, bits)
    if work > MAX_EVAL_WORK:
        ctx.trust("halfspaces", f"{part}: the affine-hull test on {len(P)} points "
                  f"({bits}-bit numbers) needs work {work} > {MAX_EVAL_WORK}")
        return "halfspaces: not checked"
    p0 = P[0]
    basis = _echelon([_sub(p, p0) for p in P], stop=d)
    for (x, e), name in zip(T if len(basis) < d else [], names):  # rank d: aff(X) = R^d
        if any(_reduce([t - e * c for t, c in zip(x, p0)], basis)):
            raise Invalid(f"{name} is not in the safe kernel: it is not in the affine hull "
                          f"of the points (dimension {len(basis)})")
    k = len(basis)
    if k == 0:
        return "halfspaces"  # all points equal: Psi = {p0} = aff(X)
    J = sorted(p for p, _ in basis)
    first: dict[tuple[int, ...], int] = {}  # distinct projected point -> its slot
    rep: list[int] = []  # slot -> index of the first point there
    W: list[int] = []  # slot -> multiplicity
    for i, p in enumerate(P):
        q = tuple(p[j] for j in J)
        s = first.get(q)
        if s is None:
            first[q] = len(W)
            rep.append(i)
            W.append(1)
        else:
            W[s] += 1
    Q = [list(q) for q in first]
    u = len(Q)
    steps = math.comb(u, k) * (u + len(T) + _normal_steps(k)) if k > 1 else u + len(T)
    work = _cost(steps, bits)
    if work > MAX_HALFSPACE_WORK:
        ctx.trust("halfspaces", f"{part}: enumerating the hyperplanes through {k} of the "
                  f"{u} distinct points ({bits}-bit numbers) needs work {work} > "
                  f"{MAX_HALFSPACE_WORK}")
        return "halfspaces: not checked"
    hit = _violated_halfspace(Q, W, F, [([x[j] for j in J], e) for x, e in T])
    if hit is not None:
        sub, out, t = hit
        raise Invalid(f"{names[t]} is not in the safe kernel: it is strictly outside a "
                      f"halfspace with only {out} <= F = {F} points strictly outside "
                      f"(bounded by the hyperplane through points "
                      f"{_fmti([rep[i] for i in sub])}, in coordinates "
                      f"{_fmti(J)})")
    return "halfspaces"


def _fan_in_kernel(pts: list[Vec], F: int, V: list[Vec], tight: list[list[list[int]]],
                   names: list[str], ctx: Any, faces: list[list[int]] | None = None) -> str:
    """P = conv(V) ⊆ Psi for a full-dimensional polytope P in R^d, d >= 2 (vert(P) = V
    already proved; ``tight[i]``: the nonzero integer normals of the facets tight at V[i]), by
    the normal fan:

        P ⊆ Psi  iff  for every vertex v and every w ≠ 0 in the normal cone N_v of P
                      at v, the closed halfspace {y : w·(y − v) >= 0} holds >= F + 1 points.

    (If x ∈ P has depth <= F, a closed halfspace {a·y >= a·x} holds <= F points; a vertex
    v maximising a over P has a ∈ N_v and {a·y >= a·v} is inside it.  Conversely a
    vertex failing the test has depth <= F.)  N_v = cone(tight normals) is pointed and
    full-dimensional, and the count is smallest on an open cell of int N_v cut by the
    hyperplanes (p − v)^⊥ (at a boundary point it is at least that of a nearby cell;
    the points p = v count everywhere).
    d = 2: N_v is the arc between w1 ⊥ y1 and w2 ⊥ y2 (the edge directions y of P at v),
    one sweep (:func:`_arc_min`).  d >= 3: a point p with a·(p − v) >= 0 for every tight
    normal a is counted on every cell, one with all < 0 on none; the others ("crossing")
    cut int N_v, and :func:`_cells_min` finds whether some cell counts <= F by recursion
    on the dimension (every cell has a facet on a crossing hyperplane; d = 3: one arc
    sweep per crossing point), from the rows a·(p − v) (the slacks of p in the tight
    facets, scaled by D) alone.  Work: n·d products per vertex (the slacks a·p of each
    facet once), plus the recursion's, charged as it runs, bit-weighted; beyond
    MAX_EVAL_WORK unchecked.  In d >= 4, where the products of generators can outgrow
    the C(u, d) enumeration on small inputs, a fan that spends FAN_OVER_ENUMERATION times
    the work of (b) while (b) is within MAX_HALFSPACE_WORK hands over to (b).

    ``faces`` (from the checked adjacency, :func:`_skeleton`): faces[i][s] is the set
    (bitmask) of the extreme rays y of the tangent cone T_v at V[i] with a·y = 0 for
    a = tight[i][s].  N_v is the polar of T_v, so {w : w·y <= 0 for those y} is a
    description of N_v by its facets; under it an extreme ray of N_v is tight on a set
    that no other generator's strictly contains, and a generator that is not extreme (or
    repeats a direction) lies in a face of dimension >= 2 whose extreme rays are tight on
    strictly more (or the same) — so the tight normals are pruned to the extreme rays of
    N_v, one per direction, and :func:`_cells_min` splits them by double description."""
    part = "vertices in the safe kernel (proof 'halfspaces', normal fan)"
    sp = _scaled_points(pts, ctx, part)
    if sp is None:
        return "halfspaces: not checked"
    P, D = sp  # the points scaled by D; T: the vertices scaled by D (X / e)
    d = len(P[0])
    T = [_scaled_test(v, D) for v in V]
    bits = 2 * max(_bit_size(P), _bit_size([x + [e] for x, e in T]))
    enum = _enumeration_work(P, len(T), d, bits // 2) if d >= 4 else MAX_HALFSPACE_WORK + 1
    fallback = enum <= MAX_HALFSPACE_WORK  # (b) would decide: the fan gets a share of it
    budget = min(MAX_EVAL_WORK, FAN_OVER_ENUMERATION * enum) if fallback else MAX_EVAL_WORK
    meter = [_cost(len(V) * len(P) * (d + 2), bits), budget]  # the signs / pairs
    cache: dict[tuple[int, ...], list[int]] = {}
    gbits = max((_bit_size(rows) for rows in tight), default=0)
    for t, ((X, e), rows, name) in enumerate(zip(T, tight, names)):
        if meter[0] > meter[1]:
            break
        zs = None
        if faces is not None and d >= 3:
            zf = faces[t]
            keep = [s for s, z in enumerate(zf) if not any(
                z2 & z == z and (z2 != z or s2 < s) for s2, z2 in enumerate(zf) if s2 != s)]
            rows, zs = [rows[s] for s in keep], [zf[s] for s in keep]
        if d == 2:
            y1, y2 = _edge_directions([], rows, 2)
            w1, w2 = _inward_normal(y1, y2), _inward_normal(y2, y1)
            c1, c2 = _dot(w1, X), _dot(w2, X)
            pairs = [(e * _dot(w1, p) - c1, e * _dot(w2, p) - c2) for p in P]  # e·D·w·(p − v)
            pairs = [st for st in pairs if st[0] or st[1]]
            count, tau = _arc_min(pairs)
            count += len(P) - len(pairs)  # points at v
            w = tuple((1 - tau) * a + tau * b for a, b in zip(w1, w2))
        else:
            try:
                _charge(meter, len(P) * max(0, len(rows) - d), bits)  # slacks beyond d facets
                base, signs = _crossing(P, X, e, rows, cache)
                hit = _cells_min(base, signs, rows, d, F, meter, _bit_size(signs), gbits, zs)
            except _OverBudget:
                break
            if hit is None:
                continue
            count, w = hit
        if count <= F:
            raise Invalid(f"{name} is not in the safe kernel: its Tukey depth is at most "
                          f"{count} <= F = {F} (the closed halfspaces w·(y - {name}) >= 0 "
                          f"for w near {_fmtv(w)}, in the normal cone of P there, hold "
                          f"{count} points)")
    if meter[0] > meter[1] and fallback:
        return _in_kernel_halfspaces(pts, F, V, names, ctx, "vertices")
    if meter[0] > meter[1]:
        ctx.trust("halfspaces", f"{part}: {len(V)} vertices and {len(P)} points "
                  f"({bits // 2}-bit numbers) need work > {meter[1]}")
        return "halfspaces: not checked"
    return "halfspaces (normal fan)"


def _enumeration_work(P: list[list[int]], tests: int, d: int, bits: int) -> int:
    """The work of (b) (:func:`_in_kernel_halfspaces`) for ``tests`` points against the
    distinct points of the full-dimensional scaled cloud P in R^d."""
    u = len({tuple(p) for p in P})
    return _cost(math.comb(u, d) * (u + tests + _normal_steps(d)), bits)


def _inward_normal(y: tuple[int, ...], other: tuple[int, ...]) -> list[int]:
    """The w ⊥ y (in R^2) with w·other < 0: an extreme ray of the normal cone of the
    tangent cone cone(y, other)."""
    w = [-y[1], y[0]]
    return [-t for t in w] if _dot(w, other) > 0 else w


def _arc_min(pairs: list[tuple[int, int]]) -> tuple[int, Fraction]:
    """(min count, a tau of it) over the open intervals of (0, 1) between breakpoints of
    #{(s1, s2) : (1 − tau)·s1 + tau·s2 > 0}, for pairs not both 0: counted on all of
    (0, 1) when s1, s2 >= 0, on none when both <= 0, else for tau below (s1 > 0 > s2)
    or above (s1 < 0 < s2) t = s1 / (s1 − s2).

    The breakpoints are sorted by the float s1 / (s1 − s2) first — Python's int / int is
    correctly rounded, hence monotone (t < t' gives fl(t) <= fl(t'), also on underflow),
    so only runs of equal floats need the exact order, which they then get (exact
    rationals); cuts are merged by exact equality."""
    base, ev = 0, []  # (float, num, den, delta): t = num / den, den > 0
    for s1, s2 in pairs:
        if s1 >= 0 and s2 >= 0:
            base += 1
        elif s1 > 0 > s2:
            ev.append((s1 / (s1 - s2), s1, s1 - s2, -1))  # counted below t
        elif s1 < 0 < s2:
            ev.append((s1 / (s1 - s2), -s1, s2 - s1, 1))  # counted above t
    ev.sort(key=lambda x: x[0])
    i = 0
    while i < len(ev):  # exact order inside runs of equal floats
        j = i + 1
        while j < len(ev) and ev[j][0] == ev[i][0]:
            j += 1
        if j - i > 1:
            ev[i:j] = sorted(ev[i:j], key=lambda x: Fraction(x[1], x[2]))
        i = j
    # sweep the cuts left to right: on (lo, t) the downs > lo and the ups <= lo count
    count = base + sum(x[3] < 0 for x in ev)
    lo: tuple[int, int] = (0, 1)
    best: tuple[int, tuple[int, int], tuple[int, int]] | None = None
    i = 0
    while True:
        t = (ev[i][1], ev[i][2]) if i < len(ev) else (1, 1)
        if best is None or count < best[0]:
            best = (count, lo, t)
        if i == len(ev):
            break
        while i < len(ev) and ev[i][1] * t[1] == t[0] * ev[i][2]:
            count += ev[i][3]
            i += 1
        lo = t
    (n1, d1), (n2, d2) = best[1], best[2]
    return best[0], Fraction(n1 * d2 + n2 * d1, 2 * d1 * d2)  # the interval's midpoint


def _crossing(P: list[list[int]], X: list[int], e: int, normals: list[list[int]],
              cache: dict[tuple[int, ...], list[int]]) -> tuple[int, list[list[int]]]:
    """(number of points counted on every cell of int N_v, the rows [a·u for a in
    normals] of the crossing points) for N_v = cone(normals), the points P and the
    vertex v = X / e scaled by D, u = p − X / e = D·(p − v): a point with a·u >= 0 for
    every normal a is counted everywhere, one with all a·u < 0 nowhere (for w in
    int N_v), the others cross.  Each normal is tight at v, a·X = e·c with c = D·b an
    integer, so a·u = a·p − c (small: the slack of p); c is exact or the a·u are
    computed as (e·a·p − a·X) / e.  ``cache`` keeps [a·p for p in P] per normal a (a
    facet is tight at many vertices)."""
    base = 0
    rows: list[list[int]] = []
    cs = []
    for a in normals:
        c, r = divmod(_dot(a, X), e)
        cs.append(Fraction(c) if r == 0 else Fraction(_dot(a, X), e))
    exact = all(c.denominator == 1 for c in cs)
    ci = [c.numerator for c in cs]
    cols = []
    for a in normals:
        key = tuple(a)
        col = cache.get(key)
        if col is None:
            col = cache[key] = [_dot(a, p) for p in P]
        cols.append(col)
    for ap in zip(*cols):
        s = [t - c for t, c in zip(ap, ci)] if exact else \
            [e * t - c * e for t, c in zip(ap, cs)]  # e·a·u (not reached: the normals are tight)
        if min(s) >= 0:
            base += 1
        elif max(s) > 0:
            rows.append([int(t) for t in s])
    return base, rows


class _OverBudget(Exception):
    """The normal fan's work limit is reached (the vertex test becomes unchecked)."""


def _charge(meter: list[int], steps: int, bits: int) -> None:
    """Add ``steps`` products on ``bits``-bit integers (:func:`_cost`) to meter[0] before
    they are spent; raise :class:`_OverBudget` once it exceeds meter[1]."""
    meter[0] += _cost(steps, bits)
    if meter[0] > meter[1]:
        raise _OverBudget


def _split_cols(gens: list[list[int]], cols: list[tuple[int, int, int, int]]
                ) -> list[list[int]]:
    """The generators ti·g_j + tj·g_i named by ``cols`` (i, j, ti, tj) (as in
    :func:`_cells_min`; (i, i, 0, 1) is g_i itself).  With the g where u·g = 0 and every
    pair ti = u·g_i > 0 > −tj = u·g_j they generate cone(gens) ∩ u^⊥ (u^⊥ through the
    relative interior of the pointed cone): a point Σ λ_g g of u^⊥, λ >= 0, pairs its
    positive and negative terms into such combinations."""
    return [[ti * y + tj * x for x, y in zip(gens[i], gens[j])] for i, j, ti, tj in cols]


def _ends(gens: list[list[int]]) -> tuple[int, int]:
    """The indices of two extreme rays of a pointed 2-dimensional cone(gens) (nonzero
    generators): the generators first and last in the orientation g <= h iff
    ω(g, h) >= 0, a total preorder on a cone of angle < π, found in one pass each.
    ω(g, h) = g_i h_j − g_j h_i for coordinates i, j where a = gens[0] and the first
    generator b not parallel to it have a nonzero 2 × 2 minor: the projection to (i, j)
    is then injective on the plane span(a, b), so ω is a nonzero area form on it."""
    a = gens[0]
    i = next(t for t, x in enumerate(a) if x)
    j = None
    for g in gens[1:]:
        j = next((t for t, x in enumerate(g) if a[i] * x != a[t] * g[i]), None)
        if j is not None:
            break
    if j is None:
        return 0, 0  # one direction: not 2-dimensional (not reached)
    c = [(g[i], g[j]) for g in gens]
    i1 = i2 = 0
    for t, (x, y) in enumerate(c):
        x1, y1 = c[i1]
        if x1 * y - y1 * x < 0:
            i1 = t
        x2, y2 = c[i2]
        if x * y2 - y * x2 < 0:
            i2 = t
    return i1, i2


def _cells_min(base: int, rows: list[list[int]], gens: list[list[int]], k: int, bound: int,
               meter: list[int], rbits: int, gbits: int, zs: list[int] | None = None
               ) -> tuple[int, tuple[Fraction, ...]] | None:
    """(c, w) with c the smallest count ``base`` + #{q : q·w > 0} over the open cells of
    relint N (N = cone(gens), pointed, spanning a k-dimensional subspace L of R^d,
    k >= 3) cut by the hyperplanes q^⊥ ∩ L, and w in (the closure of) such a cell —
    when c <= ``bound``; None when every cell counts more.  The points q are given by
    their rows [q·g for g in gens] (each q takes both signs on gens: the points counted
    on every cell are in ``base``, those counted on none are dropped).

    Every cell C has a facet on some q^⊥ if there is a q: otherwise its closure, cut out
    by facets of N only, would be all of N, yet q^⊥ splits relint N.  The relative
    interior of that facet lies in relint(N ∩ q^⊥) and meets no other hyperplane q'^⊥
    unless q' ∥ q on L, so it lies in one cell C' of the arrangement in relint(N ∩ q^⊥)
    cut by the other points, and C is the cell beside C' on its side.  So, for u = q:
    N ∩ u^⊥ = cone(:func:`_split_cols`) spans L ∩ u^⊥ (dimension k − 1, as u^⊥ meets
    relint N); the points vanishing on it are ∥ u on L ("same" if they have u's sign on
    a generator g with u·g ≠ 0 — u itself is — else "opposite"), the others are
    classified on it again (counted on all of it, on none, or crossing), and the cells
    beside C' count base + (C''s count) + same, resp. + opposite; conversely every
    (C', side) is a cell.  Hence c = min over u of base + min(same, opposite) + the
    smallest count in N ∩ u^⊥, by recursion; k − 1 = 2 is one sweep of the arc between
    its two extreme rays (:func:`_ends`, :func:`_arc_min`).  A generator
    (u·g_i)·g_j − (u·g_j)·g_i of N ∩ u^⊥ has the row entry (u·g_i)(q·g_j) −
    (u·g_j)(q·g_i): the rows of the next level come from these, never from q itself.

    Exact pruning: each count beside u^⊥ is >= base + min(same, opposite) + the number
    of points on all of N ∩ u^⊥, so a u where that exceeds ``bound`` is skipped, and
    ``bound`` drops below every count found (branch and bound).  Work, charged to
    ``meter`` before it is spent, weighted by ``rbits`` and ``gbits`` (the bit sizes of
    the rows and of the generators; :func:`_cost`): per u, the classification of the
    rows on the new generators (only the two extreme rays when k = 3), the generators
    and the next rows; beyond meter[1] :class:`_OverBudget` is raised.

    ``zs`` (optional): the gens are exactly the extreme rays of N, one per direction, and
    zs[i] is the set (bitmask) of the inequalities y·w <= 0 of a fixed description of N
    tight at gens[i].  Then N ∩ u^⊥ is generated by its extreme rays alone: the g with
    u·g = 0 and the combinations of the pairs u·g_i > 0 > u·g_j adjacent in N — the
    double description step, tested combinatorially (:func:`_adjacent`: no other
    generator tight on zs[i] & zs[j]); the combination is tight exactly on zs[i] & zs[j]
    (both terms are <= 0 on every y), and the same description restricted to u^⊥
    describes N ∩ u^⊥.  Without it the generators of N ∩ u^⊥ are all the pairs, which
    multiply at every level.

    A row that is a positive multiple of one already split (a repeated point, or points
    on one ray from v) names the same hyperplane u^⊥ ∩ L and the same cells beside it:
    it is skipped (each copy would repeat the whole subproblem)."""
    if base > bound:
        return None
    if not rows:
        return base, tuple(Fraction(sum(col)) for col in zip(*gens))
    d = len(gens[0])
    best: tuple[int, tuple[Fraction, ...]] | None = None
    split: set[tuple[int, ...]] = set()
    for su in rows:
        if bound < base:
            break
        _charge(meter, len(su), rbits)  # the row's primitive form
        key = _primitive(su)
        if key in split:
            continue
        split.add(key)
        # the generators of N ∩ u^⊥ (:func:`_split_cols`) as columns: q·g_i for u·g_i = 0,
        # ti·(q·g_j) + tj·(q·g_i) for ti = u·g_i > 0, tj = −u·g_j > 0
        zero = [i for i, t in enumerate(su) if t == 0]
        pos = [i for i, t in enumerate(su) if t > 0]
        cols = [(i, i, 0, 1) for i in zero]
        if zs is None:
            cols += [(i, j, su[i], -t) for i in pos for j, t in enumerate(su) if t < 0]
        else:
            neg = [j for j, t in enumerate(su) if t < 0]
            _charge(meter, len(pos) * len(neg) // 8 + 1, 1)  # the pairs' rank filter
            cols += [(i, j, su[i], -su[j]) for i in pos for j in neg
                     if _adjacent(zs, i, j, k, meter)]
        i0 = pos[0]  # u·g_i0 > 0
        sub = None
        if k == 3 and len(cols) > 4:  # N ∩ u^⊥ = the cone over its two extreme rays
            _charge(meter, len(cols) * (2 * d + 4), rbits + gbits)  # the ends' products
            sub = _split_cols(gens, cols)
            c1, c2 = _ends(sub)
            cols, sub = [cols[c1], cols[c2]], [sub[c1], sub[c2]]
        _charge(meter, len(rows) * 2 * len(cols), rbits)
        same = opposite = on = 0
        rest: list[list[int]] = []  # rows of the points crossing N ∩ u^⊥
        for r in rows:
            plus = minus = False
            for i, j, ti, tj in cols:
                x, y = r[i], r[j]
                if x >= 0 and y >= 0:
                    if x or y:
                        plus = True
                elif x <= 0 and y <= 0:
                    minus = True
                else:
                    t = ti * y + tj * x
                    if t > 0:
                        plus = True
                    elif t < 0:
                        minus = True
                if plus and minus:
                    rest.append(r)
                    break
            else:
                if plus:
                    on += 1
                    if base + on > bound:
                        break
                elif not minus:  # q vanishes on N ∩ u^⊥: ∥ u on L
                    if r[i0] > 0:
                        same += 1
                    else:
                        opposite += 1
        m = base + min(same, opposite)
        if m + on > bound:
            continue
        # the generators (and their gcds or orientations) and the next rows: products of
        # a row entry by a generator's or another row's entry (as the classification's
        # products of two row entries above, charged at the larger operand)
        _charge(meter, len(cols) * 3 * d + len(rest) * 2 * len(cols), max(rbits, gbits))
        if sub is None:
            sub = _split_cols(gens, cols)
        if k == 3:  # N ∩ u^⊥ is 2-dimensional: the arc between its extreme rays
            c1, c2 = _ends(sub) if len(sub) > 2 else (0, len(sub) - 1)
            (i1, j1, t1, u1), (i2, j2, t2, u2) = cols[c1], cols[c2]
            count, tau = _arc_min([(t1 * r[j1] + u1 * r[i1], t2 * r[j2] + u2 * r[i2])
                                   for r in rest])
            if m + on + count <= bound:
                e1, e2 = sub[c1], sub[c2]
                best = (m + on + count, tuple((1 - tau) * a + tau * b for a, b in zip(e1, e2)))
                bound = best[0] - 1
        else:
            keep = list({_primitive(g): c for c, g in enumerate(sub)}.values())  # dedup
            nrows = [[cols[c][2] * r[cols[c][1]] + cols[c][3] * r[cols[c][0]] for c in keep]
                     for r in rest]
            ngens = [sub[c] for c in keep]
            nzs = None if zs is None else [zs[cols[c][0]] & zs[cols[c][1]] for c in keep]
            hit = _cells_min(on, nrows, ngens, k - 1, bound - m, meter, _bit_size(nrows),
                             _bit_size(ngens), nzs)
            if hit is not None:  # its count is <= bound - m
                best = (m + hit[0], hit[1])
                bound = best[0] - 1
    return best


# --------------------------------------------------------------------------- #
# (c): Tverberg partitions
# --------------------------------------------------------------------------- #


def _exact_sum(vectors: list[Vec], d: int) -> Vec | None:
    """The coordinate sums of the vectors (length d each), added over one common
    denominator; None when that denominator exceeds MAX_SCALE_BITS (adding one fraction
    at a time would cost the square of the growing size)."""
    L = _den_lcm(vectors, MAX_SCALE_BITS)
    if not L:
        return None
    return tuple(Fraction(sum(col), L) for col in zip(*_scaled(vectors, L))) if vectors \
        else (Fraction(0),) * d


def _tverberg(parts: Any, where: str, pts: list[Vec], F: int, x: Vec, name: str,
              ctx: Any) -> None:
    """At least F + 1 pairwise disjoint nonempty index groups, each with weights >= 0
    summing to 1 and sum w_i p_i = x exactly (fact (c)).  A part whose sums need a
    common denominator beyond MAX_SCALE_BITS is recorded as unchecked."""
    _array(parts, where)
    if len(parts) < F + 1:
        raise Invalid(f"{where} has {len(parts)} parts, at least F + 1 = {F + 1} are needed")
    n, d = len(pts), len(x)
    owner: dict[int, int] = {}
    for j, part in enumerate(parts):
        w = f"{where}[{j}]"
        _obj(part, w, ("indices", "weights"))
        idx = _array(part["indices"], f"{w}.indices")
        wts = _array(part["weights"], f"{w}.weights")
        if not idx:
            raise Invalid(f"{w}.indices is empty")
        if len(wts) != len(idx):
            raise Invalid(f"{w} has {len(idx)} indices but {len(wts)} weights")
        terms: list[Vec] = []  # (w_i, w_i p_i) for the nonzero weights
        for t, (i, lam) in enumerate(zip(idx, wts)):
            i = _int(i, f"{w}.indices[{t}]", 0, n - 1)
            if i in owner:
                other = "this part" if owner[i] == j else f"{where}[{owner[i]}]"
                raise Invalid(f"{w}.indices[{t}] = {i} is already used by {other} "
                              "(parts must be pairwise disjoint)")
            owner[i] = j
            lam = _rat(lam, f"{w}.weights[{t}]")
            if lam < 0:
                raise Invalid(f"{w}.weights[{t}] = {_fq(lam)} is negative")
            if lam:
                terms.append((lam,) + tuple(lam * p for p in pts[i]))
        sums = _exact_sum(terms, d + 1)
        if sums is None:
            ctx.trust("bit size", f"{w}: the common denominator of weights * points exceeds "
                      f"the checker's limit of {MAX_SCALE_BITS} bits")
            continue
        total, comb = sums[0], sums[1:]
        if total != 1:
            raise Invalid(f"{w}: the weights sum to {_fq(total)}, not 1")
        if tuple(comb) != x:
            raise Invalid(f"{w}: sum of weights * points = {_fmtv(comb)} is not "
                          f"{name} = {_fmtv(x)}")


# --------------------------------------------------------------------------- #
# kinds
# --------------------------------------------------------------------------- #


def _problem(c: dict) -> tuple[list[Vec], int, int]:
    """(points, d, F) with 0 <= F < n."""
    pts, d = _points(c)
    F = _int(c["F"], "F", 0, len(pts) - 1)
    return pts, d, F


def _proof_method(p: Any, where: str, keys: dict[str, tuple[str, ...]]) -> str:
    """The method of a kernel PROOF object, with its exact key set ``keys[method]``."""
    if not isinstance(p, dict):
        raise Invalid(f"{where} must be a JSON object, got {_tname(p)}")
    if "method" not in p:
        raise Invalid(f"{where}: missing key 'method'")
    m = p["method"]
    if not isinstance(m, str) or m not in keys:
        raise Invalid(f"{where}: unknown proof method {m!r} "
                      f"(expected {' or '.join(repr(k) for k in keys)})")
    _obj(p, where, ("method",) + keys[m])
    return m


KERNEL_KEYS = ("dim", "vertices", "equalities", "facets", "adjacency")


def kind_kernel_point(c: dict, ctx: Any) -> str:
    """x ∈ Psi(X, F), by (b) ("halfspaces"), (c) ("tverberg") or "kernel": the kernel
    itself as a ``safe_kernel`` claim Psi = P = conv(V) (checked as that kind, with the
    normal fan for V ⊆ Psi) and x ∈ P exactly."""
    _obj(c, "certificate", _HEAD + ("points", "F", "x", "proof"))
    pts, d, F = _problem(c)
    x = _vec(c["x"], "x", d)
    m = _proof_method(c["proof"], "proof", {"halfspaces": (), "tverberg": ("parts",),
                                            "kernel": KERNEL_KEYS})
    if m == "tverberg":
        _tverberg(c["proof"]["parts"], "proof.parts", pts, F, x, "x", ctx)
        how = "tverberg"
    elif m == "kernel":
        _refute_by_axes(pts, F, [x], ["x"])
        how = _in_kernel_polytope(c, x, d, ctx)
    else:
        _refute_by_axes(pts, F, [x], ["x"])
        how = _in_kernel_halfspaces(pts, F, [x], ["x"], ctx, "x")
    return f"x is in the safe kernel (n={len(pts)}, d={d}, F={F}; {how})"


def _in_kernel_polytope(c: dict, x: Vec, d: int, ctx: Any) -> str:
    """x ∈ P = {equalities, facets} of the proof, and P = Psi checked as a ``safe_kernel``
    certificate on the same points and F (so x ∈ Psi)."""
    p = c["proof"]
    sub = {"rescon_certificate": 1, "kind": "safe_kernel", "points": c["points"], "F": c["F"],
           **{k: p[k] for k in KERNEL_KEYS}, "proof": {"method": "halfspaces"}}
    try:
        how = kind_safe_kernel(sub, ctx)
    except Invalid as e:
        raise Invalid(f"proof: {e}") from None
    for key, strict in (("equalities", True), ("facets", False)):
        for j, (a, b) in enumerate(_constraints(p[key], f"proof.{key}", d)):
            ax = _dot(a, x)
            if ax > b or (strict and ax != b):
                raise Invalid(f"x = {_fmtv(x)} is not in the kernel: it violates "
                              f"proof.{key}[{j}]")
    return f"kernel: {how}"


FARKAS_PRIME = 2**61 - 1  # a Mersenne prime: the cheap modular test of the Farkas sum


def _residue(t: Fraction) -> int | None:
    """t modulo FARKAS_PRIME, or None when its denominator is a multiple of it."""
    q = t.denominator % FARKAS_PRIME
    return t.numerator * pow(q, -1, FARKAS_PRIME) % FARKAS_PRIME if q else None


def _farkas_mod_p(terms: list[tuple[Fraction, Vec]], d: int) -> int | None:
    """A coordinate j with sum t * a_j nonzero modulo FARKAS_PRIME, or None.  Reduction
    mod p is a ring homomorphism on the rationals whose denominators p does not divide,
    so a nonzero residue proves the exact sum nonzero; the test is linear in the input
    size whatever the denominators (skipped when p divides one of them)."""
    sums = [0] * d
    for t, a in terms:
        rt = _residue(t)
        ra = [_residue(x) for x in a]
        if rt is None or None in ra:
            return None
        sums = [(s + rt * x) % FARKAS_PRIME for s, x in zip(sums, ra)]
    return next((j for j, s in enumerate(sums) if s), None)


def _check_farkas(terms: list[tuple[Fraction, Vec, Fraction]], d: int, ctx: Any) -> None:
    """Farkas: sum t_i a_i = 0 and sum t_i b_i < 0 over the (multiplier, normal, rhs)
    terms.  The modular test runs first; the exact sums use one common denominator of
    the products t_i a_ij, t_i b_i, and beyond MAX_SCALE_BITS the sign condition is
    recorded as unchecked."""
    terms = [(t, a, b) for t, a, b in terms if t]
    j = _farkas_mod_p([(t, a) for t, a, _ in terms], d)
    if j is not None:
        raise Invalid(f"Farkas: sum of multipliers * normals is not 0 (coordinate {j} is "
                      f"nonzero modulo the prime 2^61 - 1)")
    sums = _exact_sum([tuple(t * x for x in a) + (t * b,) for t, a, b in terms], d + 1)
    if sums is None:
        ctx.trust("bit size", "Farkas sums: the common denominator of multipliers * "
                  f"constraints exceeds the checker's limit of {MAX_SCALE_BITS} bits")
        return
    if any(sums[:d]):
        raise Invalid(f"Farkas: sum of multipliers * normals = {_fmtv(sums[:d])} is not 0")
    if sums[d] >= 0:
        raise Invalid(f"Farkas: sum of multipliers * right-hand sides = {_fq(sums[d])} "
                      "is not < 0")


def kind_kernel_empty(c: dict, ctx: Any) -> str:
    """Psi(X, F) = ∅: valid constraints (fact (a)) with Farkas multipliers lambda >= 0,
    mu: sum lambda_i a_i + sum mu_j e_j = 0 and sum lambda_i b_i + sum mu_j f_j < 0.
    (A point x of Psi would give 0 = (sum ...)·x <= sum lambda b + sum mu f < 0.)
    The Farkas sums (cheap) are checked before the constraints are evaluated."""
    _obj(c, "certificate", _HEAD + ("points", "F", "halfspaces", "multipliers", "equalities",
                                    "eq_multipliers"))
    pts, d, F = _problem(c)
    n = len(pts)
    H = _constraints(c["halfspaces"], "halfspaces", d)
    E = _constraints(c["equalities"], "equalities", d)
    lam = _multipliers(c["multipliers"], "multipliers", len(H), nonneg=True)
    mu = _multipliers(c["eq_multipliers"], "eq_multipliers", len(E), nonneg=False)
    _check_farkas([(t, a, b) for t, (a, b) in zip(lam + mu, H + E)], d, ctx)
    _valid_for_psi(E, "equalities", H, "halfspaces", pts, F, ctx)
    return (f"the safe kernel is empty (n={n}, d={d}, F={F}; Farkas with "
            f"{len(H)} halfspaces, {len(E)} equalities)")


def _poly_enumeration(E: list[tuple[list[int], int]], Fc: list[tuple[list[int], int]],
                      d: int, V: set[Vec], ctx: Any) -> bool:
    """P = {E·x = f, Fc·x <= g} (integer rows) is bounded and every vertex of P is in V.

    Assumes P is pointed (rank of all normals = d, which a listed vertex shows).
    Bounded: a pointed nonzero recession cone {E·y = 0, Fc·y <= 0} has an extreme ray,
    the 1-dimensional null space of rank-(d-1) tight rows: a basis of E plus d-1-r_E
    facet normals.  Vertices: unique solutions of a basis of E plus d-r_E facets that
    satisfy every constraint.  Beyond MAX_POLY_WORK (weighted by bit size) the part is
    recorded as unchecked and False returned; True when verified."""
    BE = _basis_with_rhs(E, d)
    rE = len(BE)
    m = len(Fc)
    r1, r0 = d - 1 - rE, d - rE
    rays = math.comb(m, r1) if r1 >= 0 else 0
    subsets = rays + math.comb(m, r0)
    bits = _bit_size([a + [b] for a, b in E + Fc])
    steps = (rays * (_normal_steps(d) + m + len(E))
             + math.comb(m, r0) * (_solve_steps(d) + m + len(E)))
    work = _cost(steps, d * bits)
    if work > MAX_POLY_WORK:
        ctx.trust("vertex enumeration", f"facets: P bounded with every vertex listed: "
                  f"enumerating {subsets} subsets of the {m} facets ({bits}-bit rows) needs "
                  f"work {work} > {MAX_POLY_WORK}")
        return False
    if r1 >= 0:
        for sub in combinations(range(m), r1):
            y = _normal([a for a, _ in BE] + [Fc[i][0] for i in sub], d)
            if not any(y):
                continue
            for ys in (y, [-t for t in y]):
                if all(_dot(a, ys) == 0 for a, _ in E) and all(_dot(a, ys) <= 0 for a, _ in Fc):
                    raise Invalid(f"P is unbounded: direction {_fmtv(ys)} is in its recession "
                                  "cone (E·y = 0, facet normals·y <= 0)")
    found: set[Vec] = set()
    for sub in combinations(range(m), r0):
        rows = [a for a, _ in BE] + [Fc[i][0] for i in sub]
        rhs = [f for _, f in BE] + [Fc[i][1] for i in sub]
        v = _solve(rows, rhs)
        if v is None or v in found:
            continue
        found.add(v)
        Dv = _den_lcm([v])
        X = _scaled([v], Dv)[0]
        if any(_dot(a, X) != f * Dv for a, f in E) or any(_dot(a, X) > g * Dv for a, g in Fc):
            continue  # not in P
        if v not in V:
            raise Invalid(f"P has the vertex {_fmtv(v)} (tight: facets {_fmti(list(sub))} and "
                          f"the equalities), which is not listed in vertices")
    return True


def _primitive(v: list[int]) -> tuple[int, ...]:
    """The integer vector v divided by the gcd of its entries (same direction)."""
    g = math.gcd(*v)
    return tuple(t // g for t in v) if g > 1 else tuple(v)


def _edge_directions(BE: list[list[int]], tight: list[list[int]], d: int) -> set[tuple[int, ...]]:
    """The extreme rays of the tangent cone T = {y : E·y = 0, a·y <= 0 for a in
    ``tight``} (pointed: the rows have rank d), as primitive integer vectors: the null
    directions ±y of the basis BE of E plus d − 1 − |BE| tight rows, of rank d − 1, that
    lie in T (a nonzero y of a pointed cone is extreme iff the rows tight at it have
    rank d − 1)."""
    rays: set[tuple[int, ...]] = set()
    r1 = d - 1 - len(BE)
    if r1 < 0:
        return rays
    for sub in combinations(tight, r1):
        y = _normal(BE + list(sub), d)
        if not any(y):
            continue
        for ys in (y, [-t for t in y]):
            if all(_dot(a, ys) <= 0 for a in tight):
                rays.add(_primitive(ys))
    return rays


def _cone_rays(BE: list[list[int]], tight: list[list[int]], d: int,
               meter: list[int], bits: int) -> dict[int, tuple[int, ...] | None]:
    """The extreme rays of T = {y : BE·y = 0, a·y <= 0 for a in ``tight``} (pointed: the
    rows have rank d; BE independent), {Z(r): r}: r primitive integer vectors — the set
    :func:`_edge_directions` finds — and Z(r) the bitmask of the rows with a·r = 0 (bit i
    for tight[i]), by the double description method (Motzkin et al.), output-sensitive.
    Work is charged to ``meter`` (:func:`_charge`; ``bits``: the rows' bit size) before
    it is spent — each adjacency scan as far as it went, when it stops (one scan of the
    rays at most beyond the budget); beyond meter[1] :class:`_OverBudget` is raised.

    Let k = d − |BE| (the dimension of L = null(BE)).  Start: k rows S with [BE; S]
    nonsingular; C_S = {y ∈ L : a·y <= 0, a ∈ S} is simplicial, its extreme rays are the
    k null directions of BE plus S minus one row (signed to make that row negative).
    Step (R = the extreme rays of the current pointed cone C, one per direction, Z(r) =
    the added rows tight at r; add the row a):  the extreme rays of C ∩ {a·y <= 0} are
    the r ∈ R with a·r <= 0 and, for each pair p, q ∈ R with a·p > 0 > a·q that is
    adjacent in C, the ray (a·p)q − (a·q)p.  Proof: an extreme ray y of C' = C ∩ {a·y
    <= 0} has tight rows of rank k − 1 (in L); if a·y < 0 or y is extreme in C it is an
    r of the first kind; otherwise a·y = 0 and the rows of C tight at y have rank k − 2,
    so y lies in the relative interior of a 2-face G = cone(p, q) of C (p, q adjacent),
    and a·y = 0 with y not ∥ p, q forces a·p, a·q of opposite signs, so y is that
    combination.  Conversely such a combination lies in relint G (tight rows of C: rank
    k − 2) and on a·y = 0, where a is not constant 0 on span G (a·p ≠ 0): rank k − 1,
    extreme in C'; distinct 2-faces give distinct directions, none ∥ an extreme ray of C.
    Adjacency (combinatorial): the smallest face of C holding p and q is G = {y ∈ C :
    a·y = 0 for the rows in Z(p) ∩ Z(q)}; its extreme rays are the r ∈ R with Z(r) ⊇
    Z(p) ∩ Z(q), and G (pointed, dimension >= 2) is 2-dimensional, i.e. p and q are
    adjacent, iff it has no extreme ray besides p and q.  (A 2-face has k − 2
    independent tight rows: fewer in Z(p) ∩ Z(q) rules the pair out at once.)  After all
    rows, C = T and R its extreme rays."""
    k = d - len(BE)
    if k <= 0:
        return {}
    _charge(meter, len(tight) * k * d, bits)  # choosing S
    basis = _echelon(BE)
    S: list[int] = []
    for i, a in enumerate(tight):
        if _extend(basis, a):
            S.append(i)
            if len(S) == k:
                break
    if len(S) < k:
        raise ValueError("the tight rows do not have rank d")  # not reached: checked before
    M = BE + [tight[i] for i in S]
    _charge(meter, 3 * d ** 3, d * bits)  # the scaled inverse, and each ray's check
    Dm, X = _scaled_inverse(M)
    rays: list[list[int]] = []
    Z: list[int] = []
    for t, j in enumerate(S):
        # minus column |BE| + t of M^-1: zero on BE and on S but row j, negative on row j
        y = [-x if Dm > 0 else x for x in (row[len(BE) + t] for row in X)]
        if any(_dot(M[r], y) for r in range(d) if r != len(BE) + t) or _dot(tight[j], y) >= 0:
            y = _normal(BE + [tight[i] for i in S if i != j], d)  # not reached
            if _dot(tight[j], y) > 0:
                y = [-x for x in y]
        rays.append(list(_primitive(y)))
        Z.append(sum(1 << i for i in S if i != j))
    done = set(S)
    for i, a in enumerate(tight):
        if i in done or not rays:
            continue
        rbits = bits + max(x.bit_length() for r in rays for x in r)
        _charge(meter, len(rays) * d, rbits)
        s = [_dot(a, r) for r in rays]
        pos = [t for t, x in enumerate(s) if x > 0]
        bit = 1 << i
        if not pos:
            Z = [z | bit if x == 0 else z for z, x in zip(Z, s)]
            continue
        neg = [t for t, x in enumerate(s) if x < 0]
        nrays = [r for r, x in zip(rays, s) if x <= 0]
        nZ = [z | bit if x == 0 else z for z, x in zip(Z, s) if x <= 0]
        _charge(meter, len(pos) * len(neg) // 8 + 1, 1)  # the pairs' rank filter
        for p in pos:
            sp, rp = s[p], rays[p]
            for q in neg:
                if not _adjacent(Z, p, q, k, meter):
                    continue
                _charge(meter, 3 * d, rbits)
                sq, rq = s[q], rays[q]
                nrays.append(list(_primitive([sp * y - sq * x for x, y in zip(rp, rq)])))
                nZ.append(Z[p] & Z[q] | bit)
        rays, Z = nrays, nZ
    return {z: tuple(r) for z, r in zip(Z, rays)}


def _adjacent(Z: list[int], p: int, q: int, k: int, meter: list[int]) -> bool:
    """Whether the extreme rays p and q of a pointed k-dimensional cone, tight on the
    row sets Z (bitmasks, one per extreme ray), are adjacent: at least k − 2 rows tight
    at both, and no third ray tight on all of those (proof in :func:`_cone_rays`).  The
    scan is charged to ``meter`` as far as it went (one per 8 rays), when it stops."""
    z = Z[p] & Z[q]
    if z.bit_count() < k - 2:
        return False
    hit = next((t for t, zr in enumerate(Z) if zr & z == z and t != p and t != q), None)
    _charge(meter, (len(Z) if hit is None else hit + 1) // 8 + 1, 1)
    return hit is None


def _scaled_inverse(M: list[list[int]]) -> tuple[int, list[list[int]]]:
    """(D, X) with M·X = D·I for a nonsingular square integer M, D = ±det M, by
    fraction-free Gauss–Jordan elimination of [M | I] (Bareiss: every division is
    exact); the caller checks what it uses (:func:`_cone_rays` checks each column)."""
    m = len(M)
    A = [list(r) + [int(i == j) for j in range(m)] for i, r in enumerate(M)]
    prev = 1
    for i in range(m):
        p = next(r for r in range(i, m) if A[r][i])
        A[i], A[p] = A[p], A[i]
        Ai, piv = A[i], A[i][i]
        for r in range(m):
            if r != i:
                Ar, f = A[r], A[r][i]
                A[r] = [(piv * x - f * y) // prev for x, y in zip(Ar, Ai)]
        prev = piv
    return prev, [r[m:] for r in A]


def _skeleton(E: list[tuple[list[int], int]], Fc: list[tuple[list[int], int]], d: int,
              V: list[Vec], incidence: list[list[int]], adj: Any, ctx: Any,
              keys: list[list[int]] | None = None) -> bool:
    """P = conv(V) from the vertex adjacency (``adjacency[i]``: the vertices joined to
    V[i] by an edge of P), given V ⊆ P with rank-d tight rows at each v (so the tangent
    cone T_v = {y : E·y = 0, a·y <= 0 for the facets tight at v} is pointed and generated
    by its extreme rays, and P ⊆ v + T_v).

    Checked: for every v and every extreme ray y of T_v exactly one listed neighbour w
    with w − v a positive multiple of y, and no other listed neighbour.  Then for any
    linear c, walking from v to such a w whenever c·y < 0 strictly decreases c on the
    finite V and stops at a v* with c >= 0 on T_{v*}, so min_P c = c·v* is attained in
    V: P is bounded and P = conv(V) (a point of P outside conv(V) would be separated by
    some c).

    Matching by tight sets: an extreme ray y is named by Z(y), the tight facets with
    a·y = 0 (rank k − 1 with E, k = d − r_E; its face {y' ∈ T_v : a·y' = 0 on Z(y)} is
    the ray itself).  For a listed w ≠ v, w − v ∈ T_v (w ∈ P) and a·(w − v) = 0 iff the
    tight facet a of v is tight at w too, so w − v is a positive multiple of y iff those
    facets (the incidence of :func:`_vertices_of_p`, exact) are exactly Z(y): no
    arithmetic.  The Z(y): at a simple v (k distinct nonzero tight rows — rows are
    primitive, so a repeated halfspace is an equal row, and a zero row is tight on every
    y — independent modulo E as the tight rows have rank d) T_v is simplicial and they
    are the k sets "all tight facets but the copies of one row"; otherwise
    :func:`_cone_rays` (double description) finds the rays with their Z.  ``keys`` (if
    given) receives, per vertex, the Z(y) of its rays (as bitmasks over the positions in
    ``incidence[i]``; the normal fan uses them).  Work,
    charged as it runs: t_v per listed neighbour, the double description's at the
    non-simple vertices; beyond MAX_POLY_WORK unchecked (returns False); True when
    verified."""
    _array(adj, "adjacency")
    if len(adj) != len(V):
        raise Invalid(f"adjacency has {len(adj)} entries, expected one per vertex ({len(V)})")
    BE = [a for a, _ in _basis_with_rhs(E, d)]
    k = d - len(BE)
    bits = _bit_size([a + [b] for a, b in E + Fc])
    meter = [0, MAX_POLY_WORK]
    onsets = [set(on) for on in incidence]
    for i, on in enumerate(incidence):
        nbrs = [_int(j, f"adjacency[{i}][{t}]", 0, len(V) - 1)
                for t, j in enumerate(_array(adj[i], f"adjacency[{i}]"))]
        rows = [Fc[j][0] for j in on]
        try:
            _charge(meter, len(on) * (len(nbrs) + 1), 1)  # the tight sets Z(w − v)
            copies: dict[tuple[int, ...], int] = {}
            for t, a in enumerate(rows):
                if any(a):
                    copies[tuple(a)] = copies.get(tuple(a), 0) | 1 << t
            if len(copies) == k:  # simple: T_v's rays have the Z sets "all but one row"
                full = (1 << len(on)) - 1
                rays: dict[int, tuple[int, ...] | None] = {full ^ z: None
                                                           for z in copies.values()}
            else:
                rays = _cone_rays(BE, rows, d, meter, bits)
        except _OverBudget:
            ctx.trust("vertex enumeration", f"adjacency: the edges at the {len(V)} vertices "
                      f"({bits}-bit rows) need work > {MAX_POLY_WORK}")
            return False
        seen: dict[int, int] = {}
        for j in nbrs:
            z = sum(1 << t for t, f in enumerate(on) if f in onsets[j])
            if z not in rays or j == i:
                raise Invalid(f"adjacency[{i}] lists vertices[{j}], which is not joined to "
                              f"vertices[{i}] by an edge of P")
            if z in seen:
                raise Invalid(f"adjacency[{i}] lists vertices[{seen[z]}] and vertices[{j}] "
                              "along the same edge of P")
            seen[z] = j
        missing = rays.keys() - seen.keys()
        if missing:
            z = min(missing)
            y = rays[z] or _primitive(_normal(BE + [a for t, a in enumerate(rows)
                                                    if z >> t & 1], d))
            if any(_dot(a, y) > 0 for a in rows):
                y = tuple(-x for x in y)
            raise Invalid(f"adjacency[{i}]: no vertex listed along the edge of P at "
                          f"vertices[{i}] in direction {_fmtv(y)}")
        if keys is not None:
            keys.append(list(rays))
    return True


def _basis_with_rhs(E: list[tuple[list[int], int]], d: int) -> list[tuple[list[int], int]]:
    """A maximal linearly independent subset of the equality rows (with right-hand
    sides): it has the same solution set as E when E is consistent."""
    out: list[tuple[list[int], int]] = []
    basis: list[tuple[int, list[int]]] = []
    for a, f in E:
        if len(out) == d:
            break
        if _extend(basis, a):
            out.append((a, f))
    return out


def _check_dim(V: list[Vec], dim: int) -> None:
    """The affine dimension of V is ``dim``: the rank of the differences v - v_0, each
    row scaled by its own denominator (the rank does not change, and distinct vertex
    denominators never multiply).  dim = d: the rank is at most d, so a rank >= d modulo
    a prime (a lower bound, :func:`_rank_at_least_mod_p`, fed the rows as it asks for
    them) decides."""
    d = len(V[0])
    if VERTEX_FILTERS and dim == d and _rank_at_least_mod_p(
            (_int_vector(tuple(a - b for a, b in zip(v, V[0]))) for v in V[1:]), d):
        return
    rows = [_int_vector(tuple(a - b for a, b in zip(v, V[0]))) for v in V[1:]]
    k = len(_echelon(rows, stop=len(V[0]) + 1))
    if k != dim:
        raise Invalid(f"dim = {dim} but the vertices span an affine space of dimension {k}")


def _int_vector(v: Vec) -> list[int]:
    """s * v with integer entries for the least s > 0 (the same direction)."""
    return _scaled([v], _den_lcm([v]))[0]


#: the vertex test's exact filters (tests switch them off to compare verdicts)
VERTEX_FILTERS = True
_FILTER_TOL = 2.0 ** -48  # 32 u, u = 2^-53 the unit roundoff (proof in _surely_inside)
_RANK_PRIME = (1 << 61) - 1


def _float_rows(Fi: list[tuple[list[int], int]]) -> list[tuple[list[float], float, float]] | None:
    """(fl(a) + [−fl(g)], fl(|a|_1), |fl(g)|) per facet a·x <= g, or None when some entry
    has more than 600 bits (then the filter of :func:`_surely_inside` is not used)."""
    out = []
    for a, g in Fi:
        if max(abs(t) for t in a + [g]).bit_length() > 600:
            return None
        af = [float(t) for t in a]
        out.append((af + [-float(g)], math.fsum(map(abs, af)), abs(float(g))))
    return out


def _float_vertex(X: list[int], Dv: int) -> tuple[list[float], float] | None:
    """(fl(X / Dv) + [1.0], max |fl(X_i / Dv)|) when every nonzero coordinate has magnitude in
    [2^-599, 2^299] (int / int is correctly rounded; one float step outward, as the box filter
    of :func:`_left_by_filters` takes it, stays in [2^-600, 2^300]); None otherwise."""
    try:
        vf = [x / Dv for x in X]
    except OverflowError:
        return None
    vmax = 0.0
    for x, t in zip(X, vf):
        if x and not 2.0 ** -599 <= abs(t) <= 2.0 ** 299:
            return None
        vmax = max(vmax, abs(t))
    return vf + [1.0], vmax


def _surely_inside(rows: list[tuple[list[float], float, float]], vf: list[float],
                   vmax: float) -> list[bool]:
    """Per facet a·x <= g: True only when a·v < g holds for the exact v (strictly inside,
    so neither violated nor tight); False means "decide exactly".  ``vf``: the floats of v
    (:func:`_float_vertex`), or an exact float point v (a corner of :func:`_box_left`).

    Proof (exact reals a, g, v; s = a·v − g; u = 2^-53).  The entries of a, g are 0 or
    integers of magnitude in [1, 2^600] (:func:`_float_rows`), the coordinates of v are 0
    (then X_i = 0 and fl(v_i) = 0) or of magnitude in [2^-600, 2^300]
    (:func:`_float_vertex`): every float below is finite, and 0 or normal — a nonzero
    product is >= 2^-600 in magnitude and a multiple of 2^-652, so is every sum of them
    and of the integer fl(g), so the fsum below is 0 or >= 2^-652.  The conversions are
    correctly rounded: fl(a_i) = a_i(1 + δ), fl(v_i) = v_i(1 + δ'), fl(g) = g(1 + δ''),
    |δ| <= u; the product fl(fl(a_i)·fl(v_i)) = a_i v_i (1 + θ_i), |θ_i| <= (1 + u)³ − 1
    < 4u; math.fsum returns the correctly rounded sum s' of these d floats and −fl(g)
    (the product −fl(g)·1.0 is exact).  So
    |s' − s| <= 4u·Σ|a_i v_i| + u·|g| + u·|s'| <= 4u·M, M = |a|_1·max|v_i| + |g| + |s'|.
    For s' < 0 the float B = fl(fl(a1·vmax) + |fl(g)|) − s' (rounded; a1 = fsum |fl(a_i)|, vmax =
    max |fl(v_i)|: all terms >= 0, six roundings in all) is >= (1 − u)^6·M > M / 2, so
    s' < −TOL·B with TOL = 32u gives −s' > 16u·M > |s' − s|, hence s < 0.  (TOL·B is
    exact: TOL is a power of 2 and B is normal.)"""
    fsum, tol = math.fsum, -_FILTER_TOL
    return [(s := fsum(map(mul, afg, vf))) < 0 and s < tol * (a1 * vmax + ag - s)
            for afg, a1, ag in rows]


#: vertices per leaf of the box filter's tree (:func:`_left_by_filters`)
_LEAF_VERTICES = 4


def _outward_box(vfs: list[list[float]], d: int) -> tuple[list[float], list[float]]:
    """(lo, hi) with lo_i <= v_i <= hi_i for the exact v behind each float vertex of
    ``vfs`` (:func:`_float_vertex`): a nonzero fl(v_i) is the correctly rounded v_i, so
    v_i lies strictly between its float neighbours; a zero one is exact (X_i = 0).  The
    extremes are taken one float step outward (math.nextafter is monotone)."""
    lo, hi = [], []
    for t in range(d):
        col = [v[t] for v in vfs]
        a, b = min(col), max(col)
        lo.append(math.nextafter(a, -math.inf) if a else 0.0)
        hi.append(math.nextafter(b, math.inf) if b else 0.0)
    return lo, hi


def _box_left(rows: list[tuple[list[float], float, float]], ups: list[tuple[bool, ...]],
              cand: list[int], lo: list[float], hi: list[float]) -> list[int]:
    """The facets of ``cand`` not proved slack on the whole box [lo, hi]: a·v < g for
    every exact v in it when, for the corner c (c_i = hi_i where a_i > 0, else lo_i;
    ``ups[j]``: the signs a_i > 0 of facet j), a·v <= a·c on the box and
    :func:`_surely_inside` proves a·c < g for the exact float point c (its coordinates
    are 0 or of magnitude in [2^-600, 2^300], :func:`_outward_box`).  Facets with the
    same signs share their corner: one call per sign pattern."""
    groups: dict[tuple[bool, ...], list[int]] = {}
    for j in cand:
        groups.setdefault(ups[j], []).append(j)
    slack: set[int] = set()
    for up, js in groups.items():
        c = [h if u else w for u, w, h in zip(up, lo, hi)]
        proved = _surely_inside([rows[j] for j in js], c + [1.0], max(map(abs, c)))
        slack.update(j for j, ok in zip(js, proved) if ok)
    return [j for j in cand if j not in slack]


def _left_by_filters(rows: list[tuple[list[float], float, float]] | None,
                     fvs: list[tuple[list[float], float] | None], m: int, d: int,
                     meter: list[int] | None) -> list[list[int]]:
    """Per vertex, the facets (indices) the float filters leave to the exact test: all
    of them without float rows or a float vertex; else those :func:`_surely_inside` does
    not prove strictly slack, after a tree of boxes (:func:`_outward_box`, split at the
    median of their widest coordinate down to _LEAF_VERTICES vertices) drops for all of
    a box's vertices the facets :func:`_box_left` proves slack on the whole box.  The
    float steps (d per facet and box or vertex) are charged to ``meter`` as they run."""
    everything = list(range(m))
    left = [everything] * len(fvs)
    if rows is None:
        return left
    ups = [tuple(a > 0 for a in afg[:d]) for afg, _, _ in rows]
    stack = [([i for i, fv in enumerate(fvs) if fv is not None], everything)]
    while stack:
        ids, cand = stack.pop()
        if len(ids) <= _LEAF_VERTICES:
            sub = [rows[j] for j in cand]
            for i in ids:
                if meter is not None:
                    _charge(meter, len(cand) * d, 1)
                left[i] = [j for j, ok in zip(cand, _surely_inside(sub, *fvs[i])) if not ok]
            continue
        if meter is not None:
            _charge(meter, (len(cand) + len(ids)) * d, 1)
        lo, hi = _outward_box([fvs[i][0] for i in ids], d)
        cand = _box_left(rows, ups, cand, lo, hi)
        axis = max(range(d), key=lambda t: hi[t] - lo[t])
        ids.sort(key=lambda i: fvs[i][0][axis])
        half = len(ids) // 2
        stack += [(ids[:half], cand), (ids[half:], cand)]
    return left


def _rank_at_least_mod_p(rows: Iterable[list[int]], d: int) -> bool:
    """True only if the integer rows have rank >= d over Q: their rank modulo the prime
    _RANK_PRIME is a lower bound (a d x d minor nonzero mod p is a nonzero integer).
    Gaussian elimination over GF(p), stopped at rank d."""
    p = _RANK_PRIME
    piv: list[tuple[int, list[int]]] = []  # (pivot column c, row b with b[c] != 0)
    for r in rows:
        v = [x % p for x in r]
        for c, b in piv:
            f = v[c]
            if f:  # bc·v − f·b: bc is invertible mod p, so the span is unchanged
                bc = b[c]
                v = [(bc * x - f * y) % p for x, y in zip(v, b)]
        c = next((j for j, x in enumerate(v) if x), None)
        if c is None:
            continue
        piv.append((c, v))
        if len(piv) >= d:
            return True
    return False


def _vertices_of_p(Ei: list[tuple[list[int], int]], Fi: list[tuple[list[int], int]],
                   V: list[Vec], d: int, ctx: Any) -> list[list[int]] | None:
    """Every v ∈ V satisfies the equalities and facets exactly and the constraints tight
    at it have rank d (v is a vertex of P); returns, per vertex, the indices of the
    facets tight at it (the vertex–facet incidence).  Costs #V x #constraints products,
    weighted by bit size; beyond MAX_EVAL_WORK the part is recorded as unchecked and None
    is returned (the vertex enumeration and the skeleton rely on it).  Beyond it with the
    float filters on, the work is charged as it runs instead: the filters' float steps
    (:func:`_left_by_filters`), the equalities and the rank, and the exact products only
    for the slacks the filters leave."""
    SV = [(_int_vector(v), _den_lcm([v])) for v in V]
    bits = max(_bit_size([a + [b] for a, b in Ei + Fi]),
               _bit_size([X + [e] for X, e in SV]))
    work = _cost(len(V) * (len(Ei) + len(Fi) + d * d), 2 * bits)
    rows_f = _float_rows(Fi) if VERTEX_FILTERS else None
    meter = [0, MAX_EVAL_WORK] if work > MAX_EVAL_WORK and rows_f is not None else None
    if work > MAX_EVAL_WORK and meter is None:
        ctx.trust("vertex test", f"vertices: each a vertex of P ({len(V)} vertices, "
                  f"{len(Ei) + len(Fi)} constraints, {bits}-bit numbers) needs work {work} > "
                  f"{MAX_EVAL_WORK}")
        return None
    fvs = [_float_vertex(X, Dv) for X, Dv in SV] if rows_f is not None else [None] * len(V)
    try:
        left = _left_by_filters(rows_f, fvs, len(Fi), d, meter)
        if meter is not None:  # the equalities, the rank and the exact slacks left
            _charge(meter, len(V) * (len(Ei) + d * d) + sum(map(len, left)), 2 * bits)
    except _OverBudget:
        ctx.trust("vertex test", f"vertices: each a vertex of P ({len(V)} vertices, "
                  f"{len(Ei) + len(Fi)} constraints, {bits}-bit numbers) needs work > "
                  f"{MAX_EVAL_WORK}")
        return None
    incidence: list[list[int]] = []
    for i, ((X, Dv), v) in enumerate(zip(SV, V)):
        for j, (a, f) in enumerate(Ei):
            if _dot(a, X) != f * Dv:
                raise Invalid(f"vertices[{i}] = {_fmtv(v)} violates equalities[{j}]")
        on: list[int] = []
        for j in left[i]:  # the facets not proved strictly slack by the filters
            a, g = Fi[j]
            s = _dot(a, X) - g * Dv
            if s > 0:
                raise Invalid(f"vertices[{i}] = {_fmtv(v)} violates facets[{j}]")
            if s == 0:
                on.append(j)
        tight = [a for a, _ in Ei] + [Fi[j][0] for j in on]
        r = d if VERTEX_FILTERS and _rank_at_least_mod_p(tight, d) else _rank(tight)
        if r < d:
            raise Invalid(f"vertices[{i}] = {_fmtv(v)} is not a vertex of P: the constraints "
                          f"tight at it have rank {r} < d = {d}")
        incidence.append(on)
    return incidence


def kind_safe_kernel(c: dict, ctx: Any) -> str:
    """Psi(X, F) = conv(V) with dim aff(V) = dim.

    P = {equalities, facets}.  Psi ⊆ P by (a); V ⊆ P exactly and every v ∈ V is a
    vertex of P (tight rows of rank d); P is bounded and all its vertices are in V, so
    P = conv(V); V ⊆ Psi by (b) or (c).  Hence Psi ⊆ P = conv(V) ⊆ Psi."""
    _obj(c, "certificate", _HEAD + ("points", "F", "dim", "vertices", "equalities", "facets",
                                    "proof"), ("adjacency",))
    pts, d, F = _problem(c)
    n = len(pts)
    dim = _int(c["dim"], "dim", 0, d)
    varr = _array(c["vertices"], "vertices")
    if not varr:
        raise Invalid("vertices is empty (an empty kernel needs kind 'kernel_empty')")
    if len(varr) > MAX_VERTICES:
        raise Unchecked("size limit", f"vertices: {len(varr)} entries exceed the checker's "
                        f"limit of {MAX_VERTICES}")
    V = [_vec(v, f"vertices[{i}]", d) for i, v in enumerate(varr)]
    pos: dict[tuple[int, ...], int] = {}  # keyed by the lowest terms (cheap to hash)
    for i, v in enumerate(V):
        key = tuple(x for t in v for x in (t.numerator, t.denominator))
        if key in pos:
            raise Invalid(f"vertices[{i}] repeats vertices[{pos[key]}]")
        pos[key] = i
    E = _constraints(c["equalities"], "equalities", d)
    Fc = _constraints(c["facets"], "facets", d)
    m = _proof_method(c["proof"], "proof", {"halfspaces": (), "tverberg": ("vertex_parts",)})
    names = [f"vertices[{i}]" for i in range(len(V))]
    if m == "halfspaces":
        _refute_by_axes(pts, F, V, names)  # cheap first
    # Psi ⊆ P
    _valid_for_psi(E, "equalities", Fc, "facets", pts, F, ctx)
    # every vertex lies in P and is a vertex of P; P bounded, vert(P) ⊆ V
    Ei = [_int_constraint(a, b) for a, b in E]
    Fi = [_int_constraint(a, b) for a, b in Fc]
    incidence = _vertices_of_p(Ei, Fi, V, d, ctx)
    if incidence is None:
        ctx.trust("vertex enumeration", "facets: P bounded with every vertex listed: not "
                  "checked (the enumeration relies on the vertex test)")
        spanned = False
    elif "adjacency" in c:
        spanned = _skeleton(Ei, Fi, d, V, incidence, c["adjacency"], ctx, rayz := [])
    else:
        spanned = _poly_enumeration(Ei, Fi, d, set(V), ctx)
    _check_dim(V, dim)
    # V ⊆ Psi
    if m == "tverberg":
        vp = _array(c["proof"]["vertex_parts"], "proof.vertex_parts")
        if len(vp) != len(V):
            raise Invalid(f"proof.vertex_parts has {len(vp)} entries, expected one per "
                          f"vertex ({len(V)})")
        for i, parts in enumerate(vp):
            _tverberg(parts, f"proof.vertex_parts[{i}]", pts, F, V[i], names[i], ctx)
        how = "tverberg"
    elif spanned and d == dim and d >= 2:
        # a zero normal (0·x <= b, tight when b = 0) adds nothing to N_v: dropped, as
        # the d = 3 sweep needs nonzero generators of N_v ∩ u^⊥
        nz = [[s for s, j in enumerate(on) if any(Fi[j][0])] for on in incidence]
        faces = None
        if "adjacency" in c:  # per tight normal: the extreme rays of T_v it vanishes on
            faces = [[sum(1 << r for r, z in enumerate(zv) if z >> s & 1) for s in ss]
                     for ss, zv in zip(nz, rayz)]
        how = _fan_in_kernel(pts, F, V, [[Fi[on[s]][0] for s in ss]
                                         for ss, on in zip(nz, incidence)], names, ctx, faces)
    else:
        how = _in_kernel_halfspaces(pts, F, V, names, ctx, "vertices")
    nv = f"{len(V)} vertex" if len(V) == 1 else f"{len(V)} vertices"
    return (f"safe kernel = conv of {nv}, dim {dim} "
            f"(n={n}, d={d}, F={F}; {how})")
