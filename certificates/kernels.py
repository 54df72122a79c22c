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

check.py calls :func:`install` with its strict-JSON helpers (``Invalid``, ``_obj``,
``_int``, ``_array``, ``_tname``), so the exception raised here is the one its
``check()`` catches however check.py was loaded (script, package module, or by path).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from fractions import Fraction
from itertools import combinations
from typing import Any

MAX_POINTS = 100_000  # resource limit on n
MAX_DIM = 8  # largest dimension d
MAX_CONSTRAINTS = 10_000  # halfspaces / equalities / facets per certificate
MAX_EVAL_WORK = 20_000_000  # (#constraints) * n, evaluating constraints at the points
MAX_RATIONAL_CHARS = 100_000  # longest "p/q" string (exact vertex means get long)
MAX_HALFSPACE_WORK = 3_000_000  # C(u, k) * (u + #test points) for (b); beyond: trusted
MAX_POLY_WORK = 3_000_000  # vertex / ray enumeration of P; beyond: invalid

_HEAD = ("rescon_certificate", "kind")
_RATIONAL = re.compile(r"-?[0-9]+(/[0-9]+)?")

Vec = tuple  # a point: tuple of Fractions (or ints after scaling)

# strict-JSON helpers, bound to check.py's by install()
Invalid: Any = None
_obj: Any = None
_int: Any = None
_array: Any = None
_tname: Any = None


def install(invalid: type, obj: Callable, int_: Callable, array: Callable,
            tname: Callable) -> dict[str, Callable]:
    """Bind check.py's helpers and exception class; return the kinds defined here."""
    global Invalid, _obj, _int, _array, _tname
    Invalid, _obj, _int, _array, _tname = invalid, obj, int_, array, tname
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
    string "p/q" / "p" (p, q decimal integers, q > 0, optional leading '-')."""
    if isinstance(x, bool):
        raise Invalid(f"{where} must be a rational number, got boolean")
    if isinstance(x, int):
        return Fraction(x)
    if isinstance(x, float):
        if not math.isfinite(x):
            raise Invalid(f"{where} = {x!r} is not a finite number")
        return Fraction(x)
    if isinstance(x, str):
        if len(x) > MAX_RATIONAL_CHARS:
            raise Invalid(f"{where} is a string of {len(x)} characters "
                          f"(at most {MAX_RATIONAL_CHARS})")
        if not _RATIONAL.fullmatch(x):
            raise Invalid(f"{where} = {_short(repr(x))} is not a rational string like "
                          "\"-3/4\" or \"5\"")
        p, _, q = x.partition("/")
        try:
            num, den = int(p), int(q) if q else 1
        except ValueError:  # beyond Python's limit on int-from-string digits
            raise Invalid(f"{where} = {_short(repr(x))} has too many digits") from None
        if den == 0:
            raise Invalid(f"{where} = {_short(repr(x))} has denominator 0")
        return Fraction(num, den)
    raise Invalid(f"{where} must be a rational number (integer, finite number or "
                  f"\"p/q\" string), got {_tname(x)}")


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
        raise Invalid(f"too large to check: n = {len(arr)} > {MAX_POINTS} points")
    d = len(_array(arr[0], "points[0]"))
    if not 1 <= d <= MAX_DIM:
        raise Invalid(f"points[0] has {d} coordinates: the dimension d must be 1..{MAX_DIM}")
    return [_vec(p, f"points[{i}]", d) for i, p in enumerate(arr)], d


def _constraints(x: Any, where: str, d: int) -> list[tuple[Vec, Fraction]]:
    """A list of {"a": [d rationals], "b": rational}."""
    _array(x, where)
    if len(x) > MAX_CONSTRAINTS:
        raise Invalid(f"too large to check: {where} has {len(x)} entries > {MAX_CONSTRAINTS}")
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


def _den_lcm(vectors: list[Vec]) -> int:
    """Least common denominator of all coordinates."""
    D = 1
    for v in vectors:
        for t in v:
            q = t.denominator
            if D % q:
                D = D // math.gcd(D, q) * q
    return D


def _scaled(vectors: list[Vec], D: int) -> list[list[int]]:
    """D * v for every v (integers when D is a common denominator)."""
    return [[t.numerator * (D // t.denominator) for t in v] for v in vectors]


def _int_constraint(a: Vec, b: Fraction) -> tuple[list[int], int]:
    """(A, B) = s * (a, b) with integer entries, s > 0: same halfspace / hyperplane."""
    s = _den_lcm([a + (b,)])
    row = _scaled([a + (b,)], s)[0]
    return row[:-1], row[-1]


def _dot(a: list[int] | Vec, v: list[int] | Vec) -> Any:
    return sum(x * y for x, y in zip(a, v))


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


def _check_work(m: int, n: int) -> None:
    if m * n > MAX_EVAL_WORK:
        raise Invalid(f"too large to check: {m} constraints x {n} points > {MAX_EVAL_WORK}")


def _check_halfspaces(H: list[tuple[Vec, Fraction]], where: str, P: list[list[int]], D: int,
                      F: int) -> None:
    """Each halfspace a·x <= b has at most F points strictly outside (fact (a)).
    ``P`` = the points scaled by D (integers)."""
    for i, (a, b) in enumerate(H):
        A, B = _int_constraint(a, b)
        BD = B * D
        out = [j for j, p in enumerate(P) if _dot(A, p) > BD]
        if len(out) > F:
            raise Invalid(f"{where}[{i}] has {len(out)} points strictly outside (points "
                          f"{_fmti(out)}), more than F = {F}: it need not contain the kernel")


def _check_equalities(E: list[tuple[Vec, Fraction]], where: str, P: list[list[int]],
                      D: int) -> None:
    """Each equality a·x = b holds at every point (so it contains conv(X) ⊇ Psi)."""
    for i, (a, b) in enumerate(E):
        A, B = _int_constraint(a, b)
        BD = B * D
        for j, p in enumerate(P):
            if _dot(A, p) != BD:
                raise Invalid(f"{where}[{i}] does not hold at points[{j}] "
                              f"(a·p != b = {_fq(b)})")


# --------------------------------------------------------------------------- #
# (b): membership by the candidate halfspaces
# --------------------------------------------------------------------------- #


def _violated_halfspace(Q: list[list[int]], W: list[int], F: int,
                        T: list[list[int]]) -> tuple[tuple[int, ...], int, int] | None:
    """First (subset, #outside, t) such that T[t] is strictly outside a halfspace bounded
    by the hyperplane through the k affinely independent points Q[subset] with at most
    F points (counted with multiplicity W) strictly outside; None if there is none."""
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
            for t, x in enumerate(T):
                if _dot(a, x) > b:
                    return sub, plus, t
        if minus <= F:
            for t, x in enumerate(T):
                if _dot(a, x) < b:
                    return sub, minus, t
    return None


def _violated_interval(Q: list[list[int]], W: list[int], F: int,
                       T: list[list[int]]) -> tuple[tuple[int, ...], int, int] | None:
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
    for t, (x,) in enumerate(T):
        if x < Q[lo][0]:
            return (lo,), below, t
        if x > Q[hi][0]:
            return (hi,), above, t
    return None


def _in_kernel_halfspaces(pts: list[Vec], F: int, tests: list[Vec], names: list[str],
                          ctx: Any) -> str:
    """Fact (b) for every test point; raises Invalid naming the first one not in Psi.

    Everything is scaled by one common denominator (an affine bijection, which maps
    Psi to Psi).  The enumeration of the C(u, k) hyperplanes through the u distinct
    projected points costs C(u, k) * (u + #tests) (k = 1: u + #tests, by sorting);
    beyond MAX_HALFSPACE_WORK that part is accepted on trust (aff(X) membership is
    always checked)."""
    d = len(pts[0])
    D = _den_lcm(pts + tests)
    P = _scaled(pts, D)
    T = _scaled(tests, D)
    p0 = P[0]
    basis = _echelon([_sub(p, p0) for p in P], stop=d)
    for x, name in zip(T, names):
        if any(_reduce(_sub(x, p0), basis)):
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
    work = math.comb(u, k) * (u + len(T)) if k > 1 else u + len(T)
    if work > MAX_HALFSPACE_WORK:
        ctx.trust("halfspaces")
        return "halfspaces: trusted"
    hit = _violated_halfspace(Q, W, F, [[x[j] for j in J] for x in T])
    if hit is not None:
        sub, out, t = hit
        raise Invalid(f"{names[t]} is not in the safe kernel: it is strictly outside a "
                      f"halfspace with only {out} <= F = {F} points strictly outside "
                      f"(bounded by the hyperplane through points "
                      f"{_fmti([rep[i] for i in sub])}, in coordinates "
                      f"{_fmti(J)})")
    return "halfspaces"


# --------------------------------------------------------------------------- #
# (c): Tverberg partitions
# --------------------------------------------------------------------------- #


def _tverberg(parts: Any, where: str, pts: list[Vec], F: int, x: Vec, name: str) -> None:
    """At least F + 1 pairwise disjoint nonempty index groups, each with weights >= 0
    summing to 1 and sum w_i p_i = x exactly (fact (c))."""
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
        total = Fraction(0)
        comb = [Fraction(0)] * d
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
                total += lam
                comb = [c + lam * p for c, p in zip(comb, pts[i])]
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


def kind_kernel_point(c: dict, ctx: Any) -> str:
    """x ∈ Psi(X, F), by (b) ("halfspaces") or (c) ("tverberg")."""
    _obj(c, "certificate", _HEAD + ("points", "F", "x", "proof"))
    pts, d, F = _problem(c)
    x = _vec(c["x"], "x", d)
    m = _proof_method(c["proof"], "proof", {"halfspaces": (), "tverberg": ("parts",)})
    if m == "tverberg":
        _tverberg(c["proof"]["parts"], "proof.parts", pts, F, x, "x")
        how = "tverberg"
    else:
        how = _in_kernel_halfspaces(pts, F, [x], ["x"], ctx)
    return f"x is in the safe kernel (n={len(pts)}, d={d}, F={F}; {how})"


def kind_kernel_empty(c: dict, ctx: Any) -> str:
    """Psi(X, F) = ∅: valid constraints (fact (a)) with Farkas multipliers lambda >= 0,
    mu: sum lambda_i a_i + sum mu_j e_j = 0 and sum lambda_i b_i + sum mu_j f_j < 0.
    (A point x of Psi would give 0 = (sum ...)·x <= sum lambda b + sum mu f < 0.)"""
    _obj(c, "certificate", _HEAD + ("points", "F", "halfspaces", "multipliers", "equalities",
                                    "eq_multipliers"))
    pts, d, F = _problem(c)
    n = len(pts)
    H = _constraints(c["halfspaces"], "halfspaces", d)
    E = _constraints(c["equalities"], "equalities", d)
    lam = _multipliers(c["multipliers"], "multipliers", len(H), nonneg=True)
    mu = _multipliers(c["eq_multipliers"], "eq_multipliers", len(E), nonneg=False)
    _check_work(len(H) + len(E), n)
    D = _den_lcm(pts)
    P = _scaled(pts, D)
    _check_halfspaces(H, "halfspaces", P, D, F)
    _check_equalities(E, "equalities", P, D)
    normal = [Fraction(0)] * d
    rhs = Fraction(0)
    for t, (a, b) in zip(lam + mu, H + E):
        if t:
            normal = [s + t * aj for s, aj in zip(normal, a)]
            rhs += t * b
    if any(normal):
        raise Invalid(f"Farkas: sum of multipliers * normals = {_fmtv(normal)} is not 0")
    if rhs >= 0:
        raise Invalid(f"Farkas: sum of multipliers * right-hand sides = {_fq(rhs)} is not < 0")
    return (f"the safe kernel is empty (n={n}, d={d}, F={F}; Farkas with "
            f"{len(H)} halfspaces, {len(E)} equalities)")


def _poly_enumeration(E: list[tuple[list[int], int]], Fc: list[tuple[list[int], int]],
                      d: int, V: set[Vec]) -> None:
    """P = {E·x = f, Fc·x <= g} (integer rows) is bounded and every vertex of P is in V.

    Assumes P is pointed (rank of all normals = d, which a listed vertex shows).
    Bounded: a pointed nonzero recession cone {E·y = 0, Fc·y <= 0} has an extreme ray,
    the 1-dimensional null space of rank-(d-1) tight rows: a basis of E plus d-1-r_E
    facet normals.  Vertices: unique solutions of a basis of E plus d-r_E facets that
    satisfy every constraint."""
    BE = _basis_with_rhs(E, d)
    rE = len(BE)
    m = len(Fc)
    r1, r0 = d - 1 - rE, d - rE
    subsets = (math.comb(m, r1) if r1 >= 0 else 0) + math.comb(m, r0)
    work = subsets * (m + len(E) + d * d)
    if work > MAX_POLY_WORK:
        raise Invalid(f"too large to check: enumerating the vertices of P needs "
                      f"{subsets} subsets of the {m} facets (work {work} > {MAX_POLY_WORK})")
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


def kind_safe_kernel(c: dict, ctx: Any) -> str:
    """Psi(X, F) = conv(V) with dim aff(V) = dim.

    P = {equalities, facets}.  Psi ⊆ P by (a); V ⊆ P exactly and every v ∈ V is a
    vertex of P (tight rows of rank d); P is bounded and all its vertices are in V, so
    P = conv(V); V ⊆ Psi by (b) or (c).  Hence Psi ⊆ P = conv(V) ⊆ Psi."""
    _obj(c, "certificate", _HEAD + ("points", "F", "dim", "vertices", "equalities", "facets",
                                    "proof"))
    pts, d, F = _problem(c)
    n = len(pts)
    dim = _int(c["dim"], "dim", 0, d)
    varr = _array(c["vertices"], "vertices")
    if not varr:
        raise Invalid("vertices is empty (an empty kernel needs kind 'kernel_empty')")
    if len(varr) > MAX_CONSTRAINTS:
        raise Invalid(f"too large to check: {len(varr)} vertices > {MAX_CONSTRAINTS}")
    V = [_vec(v, f"vertices[{i}]", d) for i, v in enumerate(varr)]
    pos: dict[Vec, int] = {}
    for i, v in enumerate(V):
        if v in pos:
            raise Invalid(f"vertices[{i}] repeats vertices[{pos[v]}]")
        pos[v] = i
    E = _constraints(c["equalities"], "equalities", d)
    Fc = _constraints(c["facets"], "facets", d)
    m = _proof_method(c["proof"], "proof", {"halfspaces": (), "tverberg": ("vertex_parts",)})
    _check_work(len(E) + len(Fc), n + len(V))
    # Psi ⊆ P
    D = _den_lcm(pts)
    P = _scaled(pts, D)
    _check_equalities(E, "equalities", P, D)
    _check_halfspaces(Fc, "facets", P, D, F)
    # every vertex lies in P and is a vertex of P
    Ei = [_int_constraint(a, b) for a, b in E]
    Fi = [_int_constraint(a, b) for a, b in Fc]
    for i, v in enumerate(V):
        Dv = _den_lcm([v])
        X = _scaled([v], Dv)[0]
        for j, (a, f) in enumerate(Ei):
            if _dot(a, X) != f * Dv:
                raise Invalid(f"vertices[{i}] = {_fmtv(v)} violates equalities[{j}]")
        tight = [a for a, _ in Ei]
        for j, (a, g) in enumerate(Fi):
            s = _dot(a, X) - g * Dv
            if s > 0:
                raise Invalid(f"vertices[{i}] = {_fmtv(v)} violates facets[{j}]")
            if s == 0:
                tight.append(a)
        r = _rank(tight)
        if r < d:
            raise Invalid(f"vertices[{i}] = {_fmtv(v)} is not a vertex of P: the constraints "
                          f"tight at it have rank {r} < d = {d}")
    # P bounded, vert(P) ⊆ V
    _poly_enumeration(Ei, Fi, d, set(V))
    # affine dimension
    DV = _den_lcm(V)
    SV = _scaled(V, DV)
    k = len(_echelon([_sub(v, SV[0]) for v in SV]))
    if k != dim:
        raise Invalid(f"dim = {dim} but the vertices span an affine space of dimension {k}")
    # V ⊆ Psi
    names = [f"vertices[{i}]" for i in range(len(V))]
    if m == "tverberg":
        vp = _array(c["proof"]["vertex_parts"], "proof.vertex_parts")
        if len(vp) != len(V):
            raise Invalid(f"proof.vertex_parts has {len(vp)} entries, expected one per "
                          f"vertex ({len(V)})")
        for i, parts in enumerate(vp):
            _tverberg(parts, f"proof.vertex_parts[{i}]", pts, F, V[i], names[i])
        how = "tverberg"
    else:
        how = _in_kernel_halfspaces(pts, F, V, names, ctx)
    nv = f"{len(V)} vertex" if len(V) == 1 else f"{len(V)} vertices"
    return (f"safe kernel = conv of {nv}, dim {dim} "
            f"(n={n}, d={d}, F={F}; {how})")
