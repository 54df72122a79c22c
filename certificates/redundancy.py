"""r-redundancy certificate kinds (``redundancy_violation``, ``redundancy_holds``,
``redundancy_numerical``).

Part of the trusted checker (see FORMAT.md, "Redundancy of costs"): Python standard
library only, exact ``Fraction`` arithmetic, never imports rescon or numpy.

Each of the N agents' costs is recorded, up to a constant, as

    f(x) = ½ xᵀHx + gᵀx + Σ_k max_j (a_kjᵀx + b_kj) + Σ_l ‖A_l x − c_l‖₂,   H ⪰ 0,

and F_S = Σ_{i∈S} f_i. The costs are r-redundant when every S with |S| = N − r has
the same argmin set. Facts used (proofs in FORMAT.md):

(a) optimality: x with multipliers λ_k (a probability vector on block k, positive only
    on pieces attaining the block's max at x) and μ_l (A_l x = c_l, μ_lᵀμ_l ≤ 1) with
    Hx + g + Σ λ_kj a_kj + Σ A_lᵀμ_l = 0 minimises F; and
    argmin F ⊆ E = {y : M(y − x) = 0} — M the rows of H, the differences a_kj − a_kj₀ on
    the support of λ_k and the rows of A_l with μ_lᵀμ_l < 1 — and, when rank M = d or no
    μ_l has norm 1, argmin F = E ∩ {(a_kj' − a_kj₀)ᵀy ≤ b_kj₀ − b_kj' : j' outside the
    support of λ_k}; each such inequality is canonical once reduced modulo the rows of
    M's reduced row echelon form (on E, R_i y = R_i x) and scaled to a leading ±1, and
    dropped when its normal reduces to 0 (constant on E, true at x). Equal E and equal
    sets of canonical inequalities give equal argmins.
(b) unboundedness: Hv = 0, A_l v = 0 and gᵀv + Σ_k max_j a_kjᵀv < 0.
(c) a violation: |S1| = N − r, x1 ∈ argmin F_S1 by (a), and x1 ∉ argmin F_S2 (S2 of
    size N − r or all agents): by (b) for F_S2, or by x2 ∈ argmin F_S2 (a) with
    F_S2(x2) < F_S2(x1) (no norm terms) or x1 outside the description (a) gives. Under
    r-redundancy argmin F_S1 ≠ ∅ would be the common argmin, which is also the whole
    set's (the whole sum is a positive multiple of the sum of all F_S).
"""

from __future__ import annotations

from collections.abc import Callable
from fractions import Fraction
from itertools import combinations
from math import comb
from typing import Any

MAX_DIM = 64  # largest dimension d
MAX_AGENTS = 1_000
MAX_SUBSETS = 100_000  # C(N, r) beyond this: the holds claim is not checked
MAX_PIECES = 10_000  # pieces and norm rows over all costs

Invalid: Any = None
Unchecked: Any = None
_obj: Any = None
_int: Any = None
_array: Any = None
_tname: Any = None
_rat: Any = None

Vec = list  # of Fractions


def install(invalid: type, obj: Callable, int_: Callable, array: Callable, tname: Callable,
            *, unchecked: type, rat: Callable) -> dict[str, Callable]:
    """Bind check.py's helpers (and the rational parser of kernels.py); return the kinds."""
    global Invalid, Unchecked, _obj, _int, _array, _tname, _rat
    Invalid, Unchecked, _obj, _int, _array, _tname, _rat = (
        invalid, unchecked, obj, int_, array, tname, rat)
    return {"redundancy_violation": kind_violation, "redundancy_holds": kind_holds,
            "redundancy_numerical": kind_numerical}


# --------------------------------------------------------------------------- #
# parsing
# --------------------------------------------------------------------------- #

_COMMON = ("rescon_certificate", "kind", "d", "r", "agents", "costs")


def _vec(x: Any, where: str, n: int) -> Vec:
    a = _array(x, where)
    if len(a) != n:
        raise Invalid(f"{where} must have {n} entries, got {len(a)}")
    return [_rat(v, f"{where}[{i}]") for i, v in enumerate(a)]


class _Cost:
    """One agent's recorded cost (or a sum of them)."""

    def __init__(self, d: int) -> None:
        self.H = [[Fraction(0)] * d for _ in range(d)]
        self.g = [Fraction(0)] * d
        self.blocks: list[list[tuple[Vec, Fraction]]] = []
        self.norms: list[tuple[list[Vec], Vec]] = []

    def add(self, o: _Cost) -> None:
        for i, row in enumerate(o.H):
            self.g[i] += o.g[i]
            for j, v in enumerate(row):
                self.H[i][j] += v
        self.blocks += o.blocks
        self.norms += o.norms


def _rows(x: Any, where: str, d: int) -> list[tuple[Vec, Fraction]]:
    a = _array(x, where)
    if not a:
        raise Invalid(f"{where} must be a nonempty list")
    out = []
    for i, p in enumerate(a):
        v = _vec(p, f"{where}[{i}]", d + 1)
        out.append((v[:d], v[d]))
    return out


def _cost(x: Any, where: str, d: int) -> _Cost | None:
    """An agent's recorded cost; null: not recorded (no sum using it can be checked)."""
    if x is None:
        return None
    _obj(x, where, ("H", "g", "blocks", "norms"))
    c = _Cost(d)
    H = _array(x["H"], f"{where}.H")
    if len(H) != d:
        raise Invalid(f"{where}.H must have {d} rows, got {len(H)}")
    c.H = [_vec(row, f"{where}.H[{i}]", d) for i, row in enumerate(H)]
    if any(c.H[i][j] != c.H[j][i] for i in range(d) for j in range(i)):
        raise Invalid(f"{where}.H is not symmetric")
    if not _psd(c.H):
        raise Invalid(f"{where}.H is not positive semidefinite (the cost is not convex)")
    c.g = _vec(x["g"], f"{where}.g", d)
    c.blocks = [_rows(b, f"{where}.blocks[{k}]", d)
                for k, b in enumerate(_array(x["blocks"], f"{where}.blocks"))]
    for k, nrm in enumerate(_array(x["norms"], f"{where}.norms")):
        rows = _rows(nrm, f"{where}.norms[{k}]", d)
        c.norms.append(([a for a, _ in rows], [b for _, b in rows]))
    return c


def _psd(M: list[Vec]) -> bool:
    """Exact symmetric elimination: a negative pivot, or a zero pivot with a nonzero
    rest of its row, refutes positive semidefiniteness."""
    A = [list(r) for r in M]
    n = len(A)
    for k in range(n):
        p = A[k][k]
        if p < 0 or (p == 0 and any(A[k][j] for j in range(k + 1, n))):
            return False
        if p:
            for i in range(k + 1, n):
                f = A[i][k] / p
                if f:
                    for j in range(k + 1, n):
                        A[i][j] -= f * A[k][j]
    return True


def _head(c: dict, optional: tuple[str, ...], required: tuple[str, ...] = ()
          ) -> tuple[int, int, int, list[_Cost | None]]:
    _obj(c, "certificate", _COMMON + required, optional)
    d = _int(c["d"], "d", 1)
    if d > MAX_DIM:
        raise Unchecked("size", f"d = {d} > {MAX_DIM}: beyond the checker's limits")
    agents = _array(c["agents"], "agents")
    N = len(agents)
    if not 1 <= N <= MAX_AGENTS:
        raise Invalid(f"agents must hold 1 to {MAX_AGENTS} labels, got {N}")
    for i, a in enumerate(agents):
        if isinstance(a, bool) or not isinstance(a, (str, int)):
            raise Invalid(f"agents[{i}] must be a string or an integer, got {_tname(a)}")
    if len({repr(a) for a in agents}) != N:
        raise Invalid("agents has a repeated label")
    r = _int(c["r"], "r", 0, N - 1)
    costs = _array(c["costs"], "costs")
    if len(costs) != N:
        raise Invalid(f"costs must have one entry per agent ({N}), got {len(costs)}")
    pieces = 0
    for x in costs:
        if isinstance(x, dict):
            pieces += sum(len(b) for k in ("blocks", "norms")
                          for b in _listed(x.get(k)) if isinstance(b, list))
    if pieces > MAX_PIECES:
        raise Unchecked("size", f"{pieces} pieces > {MAX_PIECES}: beyond the checker's limits")
    return d, r, N, [_cost(x, f"costs[{i}]", d) for i, x in enumerate(costs)]


def _listed(x: Any) -> list:
    """x if it is a JSON array, else [] (the size count runs before the structure is
    checked; :func:`_cost` then refuses what is not an array)."""
    return x if isinstance(x, list) else []


def _subset(x: Any, where: str, N: int, sizes: tuple[int, ...]) -> tuple[int, ...]:
    a = _array(x, where)
    idx = tuple(_int(v, f"{where}[{i}]", 0, N - 1) for i, v in enumerate(a))
    if list(idx) != sorted(set(idx)):
        raise Invalid(f"{where} must list distinct agent indices in increasing order")
    if len(idx) not in sizes:
        raise Invalid(f"{where} must hold {' or '.join(map(str, sizes))} agents, got {len(idx)}")
    return idx


def _sum(costs: list[_Cost | None], S: tuple[int, ...], d: int) -> _Cost:
    F = _Cost(d)
    for i in S:
        if costs[i] is None:
            raise Invalid(f"a sum uses agent {i}, whose cost is not recorded (null)")
        F.add(costs[i])
    return F


# --------------------------------------------------------------------------- #
# facts (a) and (b)
# --------------------------------------------------------------------------- #


def _dot(a: Vec, x: Vec) -> Fraction:
    return sum((u * v for u, v in zip(a, x)), Fraction(0))


def _value(F: _Cost, x: Vec, where: str) -> Fraction:
    if F.norms:
        raise Invalid(f"{where}: a sum with norm terms has no exact value to compare")
    return (sum((xi * _dot(row, x) for xi, row in zip(x, F.H)), Fraction(0)) / 2
            + _dot(F.g, x) + sum((max(_dot(a, x) + b for a, b in blk) for blk in F.blocks),
                                 Fraction(0)))


def _optimal(F: _Cost, x: Any, where: str, d: int) -> tuple[Vec, list[Vec], list[Vec]]:
    """Parse {x, lambda, mu} and verify fact (a)'s optimality conditions."""
    _obj(x, where, ("x", "lambda", "mu"))
    p = _vec(x["x"], f"{where}.x", d)
    lam_in, mu_in = _array(x["lambda"], f"{where}.lambda"), _array(x["mu"], f"{where}.mu")
    if len(lam_in) != len(F.blocks) or len(mu_in) != len(F.norms):
        raise Invalid(f"{where}: {len(lam_in)} block and {len(mu_in)} norm multipliers for "
                      f"{len(F.blocks)} blocks and {len(F.norms)} norm terms")
    lam = [_vec(v, f"{where}.lambda[{k}]", len(b))
           for k, (v, b) in enumerate(zip(lam_in, F.blocks))]
    mu = [_vec(v, f"{where}.mu[{k}]", len(c)) for k, (v, (_, c)) in enumerate(zip(mu_in, F.norms))]
    stat = [_dot(row, p) + gi for row, gi in zip(F.H, F.g)]
    for k, (lk, blk) in enumerate(zip(lam, F.blocks)):
        if any(v < 0 for v in lk) or sum(lk) != 1:
            raise Invalid(f"{where}.lambda[{k}] is not a probability vector")
        vals = [_dot(a, p) + b for a, b in blk]
        if any(v and val != max(vals) for v, val in zip(lk, vals)):
            raise Invalid(f"{where}.lambda[{k}] is positive on a piece that is not maximal at x")
        stat = _axpy(stat, lk, [a for a, _ in blk])
    for k, (m, (A, c)) in enumerate(zip(mu, F.norms)):
        if _dot(m, m) > 1:
            raise Invalid(f"{where}.mu[{k}] is longer than 1")
        if any(_dot(a, p) != ci for a, ci in zip(A, c)):
            raise Invalid(f"{where}: norm term {k} has a nonzero residual at x")
        stat = _axpy(stat, m, A)
    if any(stat):
        raise Invalid(f"{where}: stationarity fails (Hx + g + Σλa + ΣAᵀμ ≠ 0)")
    return p, lam, mu


def _axpy(stat: Vec, coefs: Vec, rows: list[Vec]) -> Vec:
    for v, a in zip(coefs, rows):
        if v:
            stat = [s + v * ai for s, ai in zip(stat, a)]
    return stat


def _rref(M: list[Vec], n: int) -> tuple[list[Vec], list[int]]:
    """Reduced row echelon form (independent rows) and pivot columns."""
    A = [list(r) for r in M]
    piv: list[int] = []
    for col in range(n):
        r = len(piv)
        pr = next((i for i in range(r, len(A)) if A[i][col]), None)
        if pr is None:
            continue
        A[r], A[pr] = A[pr], A[r]
        A[r] = [v / A[r][col] for v in A[r]]
        for i in range(len(A)):
            if i != r and A[i][col]:
                f = A[i][col]
                A[i] = [u - f * w for u, w in zip(A[i], A[r])]
        piv.append(col)
    return A[:len(piv)], piv


def _description(F: _Cost, p: Vec, lam: list[Vec], mu: list[Vec], where: str, d: int
                 ) -> tuple[list[Vec], frozenset | None]:
    """Fact (a): (rref of M, canonical inequalities) — None for the inequalities when
    a norm multiplier has length 1 and rank M < d (then only argmin F ⊆ E is known)."""
    M, ineq, tight = [list(r) for r in F.H if any(r)], [], False
    for lk, blk in zip(lam, F.blocks):
        supp = [j for j, v in enumerate(lk) if v]
        a0, b0 = blk[supp[0]]
        M += [[u - v for u, v in zip(blk[j][0], a0)] for j in supp[1:]]
        ineq += [[u - v for u, v in zip(blk[j][0], a0)] + [b0 - blk[j][1]]
                 for j in range(len(blk)) if j not in supp]
    for m, (A, _) in zip(mu, F.norms):
        if _dot(m, m) < 1:
            M += [list(a) for a in A]
        else:
            tight = True
    R, piv = _rref(M, d)
    if tight and len(piv) < d:
        return R, None
    faces = (_canonical(v, R, piv, p) for v in ineq)
    return R, frozenset(f for f in faces if f is not None)


def _canonical(v: Vec, R: list[Vec], piv: list[int], p: Vec) -> tuple | None:
    w = list(v)
    for row, c in zip(R, piv):
        if w[c]:
            f = w[c]
            w = [a - f * b for a, b in zip(w[:-1], row)] + [w[-1] - f * _dot(row, p)]
    lead = next((a for a in w[:-1] if a), None)
    return None if lead is None else tuple(a / abs(lead) for a in w)


def _outside(R: list[Vec], faces: frozenset | None, p: Vec, y: Vec) -> bool:
    """y ∉ E = {R(z − p) = 0}, or y breaks a canonical inequality."""
    diff = [a - b for a, b in zip(y, p)]
    return (any(_dot(row, diff) for row in R)
            or any(_dot(list(f[:-1]), y) > f[-1] for f in faces or ()))


def _recession(F: _Cost, x: Any, where: str, d: int) -> None:
    """Fact (b), or Invalid."""
    v = _vec(x, where, d)
    if any(_dot(row, v) for row in F.H) or any(_dot(a, v) for A, _ in F.norms for a in A):
        raise Invalid(f"{where}: H v ≠ 0 or A_l v ≠ 0")
    slope = _dot(F.g, v) + sum((max(_dot(a, v) for a, _ in blk) for blk in F.blocks),
                               Fraction(0))
    if slope >= 0:
        raise Invalid(f"{where}: the sum does not decrease along v (slope {slope} >= 0)")


# --------------------------------------------------------------------------- #
# kinds
# --------------------------------------------------------------------------- #


def kind_violation(c: dict, ctx: Any) -> str:
    """Fact (c)."""
    d, r, N, costs = _head(c, (), ("witness",))
    w = _obj(c["witness"], "witness", ("S1", "S2", "x1"), ("x2", "unbounded"))
    S1 = _subset(w["S1"], "witness.S1", N, (N - r,))
    S2 = _subset(w["S2"], "witness.S2", N, (N - r, N))
    if S1 == S2:
        raise Invalid("witness: S1 and S2 are the same set")
    x1, _, _ = _optimal(_sum(costs, S1, d), w["x1"], "witness.x1", d)
    F2 = _sum(costs, S2, d)
    if ("x2" in w) == ("unbounded" in w):
        raise Invalid("witness must have exactly one of 'x2' and 'unbounded'")
    if "unbounded" in w:
        _recession(F2, w["unbounded"], "witness.unbounded", d)
    else:
        p2, lam2, mu2 = _optimal(F2, w["x2"], "witness.x2", d)
        if F2.norms:
            R, faces = _description(F2, p2, lam2, mu2, "witness.x2", d)
            if not _outside(R, faces, p2, x1):
                raise Invalid("witness: x1 lies in the argmin over S2 that x2 describes")
        elif not _value(F2, p2, "witness.x2") < _value(F2, x1, "witness.x2"):
            raise Invalid("witness: x2 does not lower the sum over S2 below its value at x1")
    return (f"not {r}-redundant: agents {list(S1)} are minimised at x1, which does not "
            f"minimise the sum over agents {list(S2)}")


def kind_holds(c: dict, ctx: Any) -> str:
    """Every (N − r)-subset listed once, all certified empty, or all the same affine set."""
    d, r, N, costs = _head(c, (), ("subsets",))
    subs = _array(c["subsets"], "subsets")
    need = comb(N, N - r)
    if need > MAX_SUBSETS:
        raise Unchecked("size", f"C({N}, {r}) = {need} subsets > {MAX_SUBSETS}: beyond the "
                        "checker's limits")
    seen: set[tuple[int, ...]] = set()
    common: tuple[list[Vec], frozenset, Vec] | None = None
    kinds = set()
    for i, s in enumerate(subs):
        where = f"subsets[{i}]"
        _obj(s, where, ("agents",), ("x", "unbounded"))
        S = _subset(s["agents"], f"{where}.agents", N, (N - r,))
        if S in seen:
            raise Invalid(f"{where}: subset {list(S)} listed twice")
        seen.add(S)
        F = _sum(costs, S, d)
        if ("x" in s) == ("unbounded" in s):
            raise Invalid(f"{where} must have exactly one of 'x' and 'unbounded'")
        kinds.add("x" in s)
        if "unbounded" in s:
            _recession(F, s["unbounded"], f"{where}.unbounded", d)
            continue
        p, lam, mu = _optimal(F, s["x"], f"{where}.x", d)
        R, faces = _description(F, p, lam, mu, where, d)
        if faces is None:
            raise Invalid(f"{where}: a norm multiplier of length 1 leaves the argmin undescribed")
        if common is None:
            common = (R, faces, p)
        elif (R, faces) != common[:2] or any(_dot(row, [a - b for a, b in zip(p, common[2])])
                                             for row in R):
            raise Invalid(f"{where}: its argmin differs from that of {list(min(seen))}")
    if len(seen) != need or seen != set(combinations(range(N), N - r)):
        raise Invalid(f"subsets must list all C({N}, {r}) = {need} subsets of {N - r} agents")
    if len(kinds) > 1:
        raise Invalid("subsets mix bounded and unbounded sums: the argmins differ")
    what = "are unbounded below (empty argmins)" if kinds == {False} else "have the same argmin"
    return f"{r}-redundant: all {need} sums of {N - r} costs {what}"


def kind_numerical(c: dict, ctx: Any) -> str:
    """A numerical verdict: well-formed, taken on trust (unchecked)."""
    _obj(c, "certificate", ("rescon_certificate", "kind", "d", "r", "agents", "holds", "gap",
                            "tolerance", "directions", "trusted"))
    if not isinstance(c["holds"], bool):
        raise Invalid(f"holds must be a boolean, got {_tname(c['holds'])}")
    ctx.trust("numerical", f"redundancy verdict (holds = {c['holds']}) from numerical "
                           "support functions: accepted on trust")
    return "numerical redundancy verdict"
