"""Exact argmin sets of piecewise-quadratic convex costs (used by check_redundancy).

A cost is *piecewise quadratic* (PQ) here when it is, exactly in rationals,

    F(x) = ½ xᵀHx + gᵀx + Σ_k max_{j ∈ J_k} (a_kjᵀx + b_kj) + Σ_l ‖A_l x − c_l‖₂,  H ⪰ 0,

up to a constant (constants never matter: only argmins and differences of values are
used). Quadratic / Affine atoms give H and g; |aᵀx − b|, hinge, ‖Ax − b‖₁ (one block per
row), ‖Ax − b‖∞, max of affine functions and MaxOf of polyhedral terms (expanded) give
the blocks k; ‖Ax − c‖₂ gives a norm term l; sums and nonnegative scalings add and scale.
Values are computed exactly only without norm terms (a norm of rationals is irrational).

**Optimality certificate.** A point x̄ and multipliers λ_kj ≥ 0 with Σ_j λ_kj = 1 for
every block, stationarity  Hx̄ + g + Σ λ_kj a_kj = 0  and complementary slackness
(λ_kj > 0 ⇒ piece j attains the block's max at x̄); for each norm term, A_l x̄ = c_l
exactly and a multiplier μ_l with μ_lᵀμ_l ≤ 1, and stationarity
Hx̄ + g + Σ λ_kj a_kj + Σ A_lᵀμ_l = 0. Then for every y, by convexity of the quadratic
part, max ≥ any convex combination and ‖v‖ ≥ μᵀv (Cauchy–Schwarz),

    F(y) ≥ q(x̄) + ∇q(x̄)ᵀ(y − x̄) + Σ λ_kj (a_kjᵀy + b_kj) + Σ μ_lᵀ(A_l y − c_l) = F(x̄),

with equality iff H(y − x̄) = 0 (for H ⪰ 0, (y−x̄)ᵀH(y−x̄) = 0 ⇔ H(y−x̄) = 0), the same
complementary slackness holds at y, and ‖A_l y − c_l‖ = μ_lᵀ(A_l y − c_l) — which for
μ_lᵀμ_l < 1 means A_l y = c_l. Hence, exactly,

    argmin F = { y : H y = H x̄,  a_kjᵀy + b_kj ≥ a_kj'ᵀy + b_kj'  (λ_kj > 0, all j'),
                 A_l y = c_l (μ_lᵀμ_l < 1),  ‖A_l y − c_l‖ = μ_lᵀ(A_l y − c_l) (else) }.

So argmin F ⊆ E = {y : M(y − x̄) = 0}, M = the rows of H, the differences a_kj − a_kj₀
of the pieces in the support of λ_k and the rows of A_l with μ_lᵀμ_l < 1; and when no
μ_l has norm 1 (or rank M = d: a single point), argmin F = E ∩ {the inequalities
(a_kj' − a_kj₀)ᵀy ≤ b_kj₀ − b_kj', j' outside the support}. Each inequality is made
canonical by reducing its normal modulo the reduced row echelon form R of M (on E,
R_i y = R_i x̄) and scaling it to a leading ±1; it is dropped when the normal reduces to
0 (then it is constant on E, and true at x̄). Equal R, a common point and equal sets of
canonical inequalities prove two argmins equal (E alone: affine sets, e.g. quadratics).

**Unboundedness certificate.** A direction v with Hv = 0 and gᵀv + Σ_k max_j a_kjᵀv < 0:
F(x + tv) decreases without bound in t.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from ..geometry.exact import _rref, nullspace_exact, solve_exact
from . import atoms

Piece = tuple[tuple[Fraction, ...], Fraction]  # (a, b): a·x + b
MAX_PIECES = 256  # a MaxOf expanded beyond this many pieces is not treated as PQ
_FREE_DEN = 10**6  # free coordinates of a rounded solution: denominators up to this


@dataclass
class PQ:
    """½xᵀHx + gᵀx + Σ_k max_j (a_kjᵀx + b_kj), exact (Fractions)."""

    H: list[list[Fraction]]
    g: list[Fraction]
    blocks: list[list[Piece]] = field(default_factory=list)
    norms: list[tuple[list[tuple[Fraction, ...]], list[Fraction]]] = field(default_factory=list)

    @classmethod
    def zero(cls, d: int) -> PQ:
        return cls([[Fraction(0)] * d for _ in range(d)], [Fraction(0)] * d, [], [])

    @property
    def d(self) -> int:
        return len(self.g)

    def add(self, other: PQ) -> None:
        for i, row in enumerate(other.H):
            self.g[i] += other.g[i]
            for j, v in enumerate(row):
                self.H[i][j] += v
        self.blocks.extend(other.blocks)
        self.norms.extend(other.norms)

    def value(self, x: list[Fraction]) -> Fraction:
        """F(x) exactly, up to the constant (only without norm terms)."""
        assert not self.norms, "a norm term has no exact value"
        quad = sum((xi * _dot(row, x) for xi, row in zip(x, self.H, strict=True)), Fraction(0))
        return quad / 2 + _dot(self.g, x) + sum((max(_dot(a, x) + b for a, b in blk)
                                                 for blk in self.blocks), Fraction(0))

    def float_data(self) -> dict[str, Any]:
        """H, g, pieces A, b with their block index, and per norm term (A_l, c_l), as
        float arrays."""
        pieces = [(k, a, b) for k, blk in enumerate(self.blocks) for a, b in blk]
        return {"H": np.array(self.H, dtype=float), "g": np.array(self.g, dtype=float),
                "A": np.array([[float(v) for v in a] for _, a, _ in pieces]).reshape(-1, self.d),
                "b": np.array([float(b) for _, _, b in pieces]),
                "block": np.array([k for k, _, _ in pieces], dtype=int),
                "norms": [(np.array(A, dtype=float), np.array(c, dtype=float))
                          for A, c in self.norms]}


def _dot(a: Any, x: Any) -> Fraction:
    return sum((u * v for u, v in zip(a, x, strict=True)), Fraction(0))


# --------------------------------------------------------------------------- #
# atoms -> PQ
# --------------------------------------------------------------------------- #


def of_oracle(o: Any, d: int) -> PQ | None:
    """The exact PQ form of an atom tree, or None when some term is not PQ (Norm2, Huber,
    log-sum-exp, non-atom oracles, a MaxOf of quadratics or of too many pieces)."""
    F = PQ.zero(d)
    return F if _add(o, Fraction(1), F) else None


def _add(o: Any, w: Fraction, F: PQ) -> bool:
    """F += w·o; False when o is not PQ."""
    if isinstance(o, atoms.Quadratic):
        Q, c, q = o.exact["Q"], o.exact["c"], o.exact["q"]
        for i, row in enumerate(Q):
            F.g[i] += w * (q[i] - _dot(row, c))
            for j, v in enumerate(row):
                F.H[i][j] += w * v
        return True
    if isinstance(o, atoms.Affine):
        F.g[:] = [gi + w * ai for gi, ai in zip(F.g, o.exact["a"], strict=True)]
        return True
    if isinstance(o, atoms.Scaled):
        return _add(o.term, w * o.exact["coef"], F)
    if isinstance(o, atoms.Sum):
        return all(_add(t, w, F) for t in o.terms)
    if isinstance(o, atoms.Norm2):
        if w:
            F.norms.append(([tuple(w * v for v in a) for a in o.exact["A"]],
                            [w * v for v in o.exact["b"]]))
        return True
    blocks = _blocks(o, F.d)
    if blocks is None:
        return False
    if w:
        F.blocks.extend([[(tuple(w * v for v in a), w * b) for a, b in blk] for blk in blocks])
    return True


def _blocks(o: Any, d: int) -> list[list[Piece]] | None:
    """The blocks of a polyhedral atom (each a list of affine pieces), or None."""
    if isinstance(o, atoms.MaxOf):
        return _max_of(o, d)
    if not isinstance(o, (atoms.AbsAffine, atoms.Hinge, atoms.Norm1, atoms.NormInf,
                          atoms.MaxAffine)):
        return None
    rows = [(tuple(a), b) for a, b in zip(o.exact["A"], o.exact["b"], strict=True)]
    zero = (tuple(Fraction(0) for _ in range(d)), Fraction(0))
    if isinstance(o, atoms.MaxAffine):
        return [rows]
    if isinstance(o, atoms.Hinge):
        return [[(rows[0][0], -rows[0][1]), zero]]
    absolute = [[(a, -b), (tuple(-v for v in a), b)] for a, b in rows]
    if isinstance(o, atoms.NormInf):
        return [[p for blk in absolute for p in blk]]
    return absolute  # AbsAffine, Norm1: one block per row


def _max_of(o: Any, d: int) -> list[list[Piece]] | None:
    """max_t F_t with every F_t polyhedral (H = 0): one block, the union over t of the
    pieces g_t + Σ_k a_{k,j_k} (one per choice of a piece in each of F_t's blocks)."""
    out: list[Piece] = []
    for t in o.terms:
        F = of_oracle(t, d)
        if F is None or F.norms or any(v for row in F.H for v in row):
            return None
        count = 1
        for blk in F.blocks:
            count *= len(blk)
        if len(out) + count > MAX_PIECES:
            return None
        for choice in itertools.product(*F.blocks):
            a = tuple(sum(col, gi) for gi, col in zip(F.g, zip(*(p[0] for p in choice)),
                                                      strict=True)) if choice else tuple(F.g)
            out.append((a, sum((p[1] for p in choice), Fraction(0))))
    return [out]


# --------------------------------------------------------------------------- #
# certificates from float solutions
# --------------------------------------------------------------------------- #

Mult = list[list[Fraction]]


@dataclass
class Optimal:
    """A certified minimiser: x, block multipliers lam[k][j], norm multipliers mu[l],
    and the set they describe (module docstring)."""

    x: list[Fraction]
    lam: Mult
    mu: Mult
    rref: list[list[Fraction]]  # canonical basis of the row space of M
    faces: frozenset[tuple[Fraction, ...]] | None  # canonical inequalities; None: not linear

    @property
    def affine(self) -> bool:
        """argmin F = E = {y : M(y − x) = 0}."""
        return self.faces == frozenset()

    @property
    def describable(self) -> bool:
        """argmin F = E ∩ {the ``faces``} (no norm term with |μ| = 1, or a single point)."""
        return self.faces is not None

    def contains(self, y: list[Fraction]) -> bool:
        """y ∈ E, which contains argmin F (always)."""
        diff = [a - b for a, b in zip(y, self.x, strict=True)]
        return all(_dot(row, diff) == 0 for row in self.rref)

    def violates_face(self, y: list[Fraction]) -> bool:
        """y breaks one of the ``faces`` (n·y ≤ h, stored as (*n, h))."""
        return any(_dot(f[:-1], y) > f[-1] for f in self.faces or ())

    def point_near(self, tight: list[tuple[Fraction, ...]], guess: list[Fraction]
                   ) -> list[Fraction] | None:
        """An exact point of E ∩ {the faces} (= argmin F when describable) on which the
        faces ``tight`` hold with equality: ``guess`` projected exactly onto that affine
        set (its only point when it is one), or None when the projection breaks a face
        or the equalities are inconsistent."""
        d = len(self.x)
        rows = [list(r) + [_dot(r, self.x)] for r in self.rref] + [list(f) for f in tight]
        piv = _rref(rows, d) if rows else []
        if any(row[d] for row in rows[len(piv):]):
            return None
        y = _project(rows[:len(piv)], list(guess)) if piv else list(guess)
        return None if self.violates_face(y) else y


def check_optimal(F: PQ, x: list[Fraction], lam: Mult, mu: Mult) -> str | None:
    """None when (x, lam, mu) is an optimality certificate for F, else what fails."""
    if len(lam) != len(F.blocks) or any(len(lk) != len(b) for lk, b in zip(lam, F.blocks)):
        return "multipliers do not match the blocks"
    if len(mu) != len(F.norms) or any(len(m) != len(c) for m, (_, c) in zip(mu, F.norms)):
        return "multipliers do not match the norm terms"
    stat = [_dot(row, x) + gi for row, gi in zip(F.H, F.g, strict=True)]
    for lk, blk in zip(lam, F.blocks, strict=True):
        if any(v < 0 for v in lk) or sum(lk) != 1:
            return "multipliers are not a probability vector on every block"
        vals = [_dot(a, x) + b for a, b in blk]
        top = max(vals)
        if any(v > 0 and val != top for v, val in zip(lk, vals, strict=True)):
            return "complementary slackness fails"
        stat = _axpy(stat, lk, [a for a, _ in blk])
    for m, (A, c) in zip(mu, F.norms, strict=True):
        if _dot(m, m) > 1 or any(_dot(a, x) != ci for a, ci in zip(A, c, strict=True)):
            return "a norm term's residual is not 0 or its multiplier is longer than 1"
        stat = _axpy(stat, m, A)
    return None if not any(stat) else "stationarity fails"


def _axpy(stat: list[Fraction], coefs: list[Fraction], rows: list) -> list[Fraction]:
    """stat + Σ_i coefs_i rows_i."""
    for v, a in zip(coefs, rows, strict=True):
        if v:
            stat = [s + v * ai for s, ai in zip(stat, a, strict=True)]
    return stat


def describe(F: PQ, x: list[Fraction], lam: Mult, mu: Mult) -> Optimal:
    """The argmin set certified by (x, lam, mu) (module docstring)."""
    M = [list(row) for row in F.H if any(row)]
    ineq = []  # n·y ≤ h as [*n, h]: piece j' ≤ piece j₀ of the support
    for lk, blk in zip(lam, F.blocks, strict=True):
        supp = [j for j, v in enumerate(lk) if v]
        a0, b0 = blk[supp[0]]
        M += [[u - v for u, v in zip(blk[j][0], a0, strict=True)] for j in supp[1:]]
        ineq += [[u - v for u, v in zip(blk[j][0], a0, strict=True)] + [b0 - blk[j][1]]
                 for j in range(len(blk)) if j not in supp]
    tight = False
    for m, (A, _) in zip(mu, F.norms, strict=True):
        if _dot(m, m) < 1:
            M += [list(a) for a in A]
        else:
            tight = True
    piv = _rref(M, F.d) if M else []
    R = M[:len(piv)]
    faces = None if tight and len(piv) < F.d else frozenset(
        f for f in (_canonical(v, R, piv, x) for v in ineq) if f is not None)
    return Optimal(x, lam, mu, R, faces)


def _canonical(v: list[Fraction], R: list[list[Fraction]], piv: list[int], x: list[Fraction]
               ) -> tuple[Fraction, ...] | None:
    """The inequality n·y ≤ h (v = [*n, h]) restricted to E = {R(y − x) = 0}: n reduced
    modulo the rows of R (h shifted by their values R_i·x on E), scaled so its first
    nonzero entry is ±1; None when n reduces to 0 (constant on E, true at x)."""
    w = list(v)
    for row, p in zip(R, piv, strict=True):
        if w[p]:
            f = w[p]
            w = [a - f * b for a, b in zip(w[:-1], row, strict=True)] + [w[-1] - f * _dot(row, x)]
    lead = next((a for a in w[:-1] if a), None)
    return None if lead is None else tuple(a / abs(lead) for a in w)


def rational(v: float, scale: float = 1.0) -> Fraction:
    """A short rational near the float v, to about 1/_FREE_DEN of ``scale`` (a guess;
    every use is verified exactly); scale 0: v exactly (its binary value)."""
    if not scale:
        return Fraction(float(v))
    s = Fraction(2) ** round(math.log2(scale))  # a power of two: exact rescaling
    return (Fraction(float(v)) / s).limit_denominator(_FREE_DEN) * s


def certify(F: PQ, xf: np.ndarray, lamf: list[np.ndarray], muf: list[np.ndarray]
            ) -> Optimal | None:
    """An exact optimality certificate near the float solution, or None.

    The support S_k of each block's multipliers is guessed from the floats: the
    multipliers above 1e-6 of the block's largest, then the pieces whose values are
    within 1e-6, then 1e-9, of the block's maximum *relative to the size of the block's
    terms at x* (Σ_i |a_kji x_i| + |b_kj|: no absolute threshold, so argmins at any
    scale are tried); norm terms must have a zero residual there. The linear system in
    (x, λ_S, μ) — equal values of the pieces in S_k, A_l x = c_l, stationarity,
    Σ_j λ_kj = 1 — is solved exactly with its free unknowns set to short rationals near
    the floats (x to 1e-6 of 1, then of |x|, then x's floats exactly), or else projected
    exactly (least squares) from those rationals onto the solution set, which keeps the
    interior-point multipliers positive. Thresholds and roundings only choose what is
    tried: the result is kept only when :func:`check_optimal` accepts it."""
    tried: set[tuple] = set()
    for guess, t in (("support", 1e-6), ("active", 1e-6), ("active", 1e-9)):
        S = _support(F, xf, lamf, guess, t)
        if (key := tuple(map(tuple, S))) in tried:
            continue
        tried.add(key)
        for sol in _candidates(F, S, xf, lamf, muf):
            if sol is not None and check_optimal(F, *sol) is None:
                return describe(F, *sol)
    return None


def _candidates(F: PQ, S: list[list[int]], xf: np.ndarray, lamf: list[np.ndarray],
                muf: list[np.ndarray]) -> Iterator[tuple[list[Fraction], Mult, Mult] | None]:
    """Solutions to try, lazily (the joint systems are large): two-stage, then joint
    with free unknowns at the floats, then joint projected — x rounded to 1e-6 of 1,
    then of |x|, then exactly."""
    yield _two_stage(F, S, xf, lamf, muf)
    xs = float(np.abs(xf).max(initial=0.0))
    for scale in dict.fromkeys((1.0, xs if 0 < xs < math.inf else 1.0, 0.0)):
        for project in (False, True):
            yield _solve_system(F, S, xf, lamf, muf, project, scale)


def _two_stage(F: PQ, S: list[list[int]], xf: np.ndarray, lamf: list[np.ndarray],
               muf: list[np.ndarray]) -> tuple[list[Fraction], Mult, Mult] | None:
    """The fast path when the active pieces and zero norm residuals pin x down: x from
    those equalities alone (d unknowns), then the multipliers from the d stationarity
    equations with λ_kj₀ = 1 − Σ_{j≠j₀} λ_kj substituted, projected exactly from the
    floats (a d-row system however many blocks there are). None when x is not pinned."""
    d = F.d
    eq = [[u - v for u, v in zip(F.blocks[k][j][0], F.blocks[k][s[0]][0], strict=True)]
          + [F.blocks[k][s[0]][1] - F.blocks[k][j][1]] for k, s in enumerate(S) for j in s[1:]]
    eq += [list(a) + [ci] for A, c in F.norms for a, ci in zip(A, c, strict=True)]
    eq = [list(row) for row in dict.fromkeys(tuple(row) for row in eq)]  # agents repeat them
    piv = _rref(eq, d) if eq else []
    if len(piv) < d or any(row[d] for row in eq[d:]):
        return None
    x = [row[d] for row in eq[:d]]
    rhs = [-(_dot(row, x) + gi) for row, gi in zip(F.H, F.g, strict=True)]
    cols, guess = [], []
    for k, s in enumerate(S):
        a0 = F.blocks[k][s[0]][0]
        rhs = [u - v for u, v in zip(rhs, a0, strict=True)]
        for j in s[1:]:
            cols.append([u - v for u, v in zip(F.blocks[k][j][0], a0, strict=True)])
            guess.append(rational(lamf[k][j]))
    for (A, _), m in zip(F.norms, muf, strict=True):
        cols += [list(a) for a in A]
        guess += [rational(v) for v in m]
    C = [[col[i] for col in cols] + [rhs[i]] for i in range(d)]
    cpiv = _rref(C, len(cols)) if cols else []
    if any(row[len(cols)] for row in C[len(cpiv):]):
        return None
    u = _project(C[:len(cpiv)], guess) if cpiv else guess
    lam = [[Fraction(0)] * len(blk) for blk in F.blocks]
    it = iter(u)
    for k, s in enumerate(S):
        rest = [next(it) for _ in s[1:]]
        lam[k][s[0]] = 1 - sum(rest, Fraction(0))
        for j, v in zip(s[1:], rest, strict=True):
            lam[k][j] = v
    return x, lam, [[next(it) for _ in c] for _, c in F.norms]


def _support(F: PQ, xf: np.ndarray, lamf: list[np.ndarray], guess: str, t: float
             ) -> list[list[int]]:
    """Each block's guessed support: multipliers above t·max (``guess`` "support"), or
    pieces within t·(size of the block's terms at xf) of the maximum ("active")."""
    out = []
    for blk, lk in zip(F.blocks, lamf, strict=True):
        if guess == "support":
            s = [j for j, v in enumerate(lk) if v > t * max(lk.max(), 1e-300)]
        else:
            A = np.array([[float(u) for u in a] for a, _ in blk])
            b = np.array([float(bj) for _, bj in blk])
            vals, size = A @ xf + b, np.abs(A) @ np.abs(xf) + np.abs(b)
            s = [int(j) for j in np.flatnonzero(vals >= vals.max() - t * size.max())]
        out.append(s or [int(np.argmax(lk))])
    return out


def _solve_system(F: PQ, S: list[list[int]], xf: np.ndarray, lamf: list[np.ndarray],
                  muf: list[np.ndarray], project: bool, scale: float
                  ) -> tuple[list[Fraction], Mult, Mult] | None:
    """Solve for (x, λ on the multi-piece supports, μ) exactly, free unknowns near the
    floats (module docstring of :func:`certify`)."""
    d = F.d
    multi = [(k, j) for k, s in enumerate(S) if len(s) > 1 for j in s]
    nmu = [len(c) for _, c in F.norms]
    n = d + len(multi) + sum(nmu)
    zeros = [Fraction(0)] * (n - d)
    rows: list[list[Fraction]] = []
    rhs = list(F.g)
    for k, s in enumerate(S):
        if len(s) == 1:
            rhs = [u + v for u, v in zip(rhs, F.blocks[k][s[0]][0], strict=True)]
            continue
        a0, b0 = F.blocks[k][s[0]]
        for j in s[1:]:
            a, b = F.blocks[k][j]
            rows.append([u - v for u, v in zip(a, a0, strict=True)] + zeros + [b0 - b])
        rows.append([Fraction(0)] * d + [Fraction(int(kj[0] == k)) for kj in multi]
                    + [Fraction(0)] * sum(nmu) + [Fraction(1)])
    rows += [list(a) + zeros + [ci] for A, c in F.norms for a, ci in zip(A, c, strict=True)]
    for i in range(d):
        rows.append(list(F.H[i]) + [F.blocks[k][j][0][i] for k, j in multi]
                    + [a[i] for A, _ in F.norms for a in A] + [-rhs[i]])
    guess = ([rational(v, scale) for v in xf] + [rational(lamf[k][j]) for k, j in multi]
             + [rational(v) for m in muf for v in m])
    piv = _rref(rows, n)
    if any(row[n] for row in rows[len(piv):]):
        return None
    z = _project(rows[:len(piv)], guess) if project else _free_near(rows, piv, guess)
    lam = [[Fraction(0)] * len(blk) for blk in F.blocks]
    for k, s in enumerate(S):
        if len(s) == 1:
            lam[k][s[0]] = Fraction(1)
    for i, (k, j) in enumerate(multi):
        lam[k][j] = z[d + i]
    it = iter(z[d + len(multi):])
    return z[:d], lam, [[next(it) for _ in range(m)] for m in nmu]


def _free_near(rows: list[list[Fraction]], piv: list[int], guess: list[Fraction]
               ) -> list[Fraction]:
    """The solution of the reduced system ``rows`` (rref, right-hand side last) whose free
    unknowns are the guesses."""
    n = len(guess)
    z = [Fraction(0)] * n
    for c in set(range(n)) - set(piv):
        z[c] = guess[c]
    for row, p in zip(rows, piv):
        z[p] = row[n] - sum((row[c] * z[c] for c in range(n) if c not in piv), Fraction(0))
    return z


def _project(R: list[list[Fraction]], guess: list[Fraction]) -> list[Fraction]:
    """guess − Rᵀ(RRᵀ)⁻¹(R guess − rhs): the exact solution of R z = rhs (independent
    rows, right-hand side last) nearest to ``guess``."""
    n = len(guess)
    res = [_dot(row[:n], guess) - row[n] for row in R]
    if not any(res):
        return list(guess)
    G = [[_dot(a[:n], b[:n]) for b in R] for a in R]
    y = solve_exact(G, res)
    return [gc - sum((yi * row[c] for yi, row in zip(y, R)), Fraction(0))
            for c, gc in enumerate(guess)]


def recession(F: PQ, vf: np.ndarray) -> list[Fraction] | None:
    """An exact unboundedness certificate near the float direction vf, or None.

    Tried in turn: vf / max|vf| rounded to 1/_FREE_DEN of 1 (float noise in its zero
    entries dropped), then each entry rounded relative to itself (rational(v, |v|):
    entries of every size kept, e.g. (1, 1e-8) when the data mix scales 1 and 1e8);
    when H ≠ 0, the same two roundings of v's coordinates in an exact basis of null(H).
    Roundings only choose what is tried: :func:`is_recession` decides."""
    s = float(np.abs(vf).max(initial=0.0))
    if not s > 0:
        return None
    v1 = vf / s
    cands = [[rational(v) for v in v1], [rational(v, abs(v)) for v in v1]]
    if any(v for row in F.H for v in row):  # the component of v in null(H), exactly
        null = nullspace_exact(F.H)
        if null:
            coef = np.linalg.lstsq(np.array(null, dtype=float).T, v1, rcond=None)[0]
            for cs in ([rational(c) for c in coef], [rational(c, abs(c)) for c in coef]):
                cands.append([sum((c * b[i] for c, b in zip(cs, null)), Fraction(0))
                              for i in range(F.d)])
    return next((v for v in cands if is_recession(F, v)), None)


def is_recession(F: PQ, v: list[Fraction]) -> bool:
    """Hv = 0, A_l v = 0 and gᵀv + Σ_k max_j a_kjᵀv < 0: F is unbounded below along v."""
    if any(_dot(row, v) for row in F.H) or any(_dot(a, v) for A, _ in F.norms for a in A):
        return False
    slope = _dot(F.g, v) + sum((max(_dot(a, v) for a, _ in blk) for blk in F.blocks),
                               Fraction(0))
    return slope < 0


def strongly_convex(F: PQ) -> bool:
    """H ≻ 0 (null(H) = {0}, exactly): then F ≥ ½λ_min‖x‖² − C‖x‖ − C' is bounded below
    (its pieces and norms are Lipschitz) and has exactly one minimiser."""
    return not nullspace_exact(F.H)


def quadratic_argmin(F: PQ) -> tuple[str, Any]:
    """A PQ without blocks or norms, exactly: ("optimal", Optimal) or ("unbounded", v)."""
    d = F.d
    aug = [list(row) + [-gi] for row, gi in zip(F.H, F.g, strict=True)]
    piv = _rref(aug, d)
    if any(row[d] for row in aug[len(piv):]):
        for b in nullspace_exact(F.H):
            s = _dot(F.g, b)
            if s:
                return "unbounded", [-v if s > 0 else v for v in b]
    x = [Fraction(0)] * d
    for row, p in zip(aug, piv):
        x[p] = row[d]
    return "optimal", describe(F, x, [], [])
