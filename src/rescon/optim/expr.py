"""Cost expressions: a small exact IR, the TOML grammar's parser, convexity, lowering.

Grammar (DESIGN.md; a recursive-descent parser, no ``eval``)::

    expr  := term (("+" | "-") term)*
    term  := unary (("*" | "/") unary)*
    unary := ("+" | "-") unary | power
    power := atom ("^" unary)?
    atom  := NUMBER | x1 | x2 | … | FUNC "(" expr ("," expr)* ")" | "(" expr ")"
    FUNC  := abs | pos | max | min | norm1 | norm2 | norminf | huber | sqrt | logsumexp

Numbers are read exactly (``0.3`` is 3/10). A number as written must lie in the float
range (``1e400`` is refused: ``float`` of its text is infinite, the same correctly rounded
test as every computed coefficient's) and have at most :data:`MAX_DIGITS` significant
digits; every number, as written or as a product, must
have a numerator and a denominator of at most :data:`MAX_DIGITS` (4300, Python's
int-string limit) digits (``1e-400`` is read exactly, ``1e-5000`` is refused, and
``((1e300)^2)^2…`` is refused rather than squared into billions of digits).
Parentheses, calls, signs and exponents nest at most :data:`MAX_DEPTH` (100) levels deep.
Every expression is kept in a canonical form: a polynomial of degree ≤ 2 with rational
coefficients plus a list of coef · call terms. Convexity is decided by DCP-style rules,
with one exact refinement: the polynomial part is convex iff its Hessian is positive
semidefinite, decided in rational arithmetic (so ``x1^2 + 2*x1*x2 + x2^2`` is convex).

* ``abs``, ``norm1/2/inf``, ``huber``, ``logsumexp``: convex, of affine arguments;
* ``pos``, ``max``: convex and nondecreasing: arguments convex (or affine);
* ``min``: concave and nondecreasing: arguments concave (or affine);
* ``sqrt(q)``: convex when q is a sum of squares of affine functions, i.e. the
  homogenised matrix [[S, l/2], [l/2ᵀ, k]] of q = xᵀSx + lᵀx + k is positive
  semidefinite (exactly); it is then the norm ‖R(x, 1)‖₂ of an exact LDLᵀ factor;
* ``e^2`` of an affine e, products of polynomials up to degree 2, ``/`` by a nonzero
  constant; a nonnegative sum of convex terms is convex, a negated concave one too.

The same IR is the target of the CasADi and CVXPY lowerings (:mod:`.casadi_adapter`,
:mod:`.cvxpy_adapter`), so every source gets the atom library's conventions.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from ..errors import InputError
from . import atoms
from .oracle import Oracle

__all__ = ["FUNCTIONS", "Expr", "ExprError", "expression_cost", "lower", "parse"]

#: the grammar's functions and their number of arguments (None: one or more)
FUNCTIONS = {"abs": 1, "pos": 1, "sqrt": 1, "huber": (1, 2), "max": None, "min": None,
             "norm1": None, "norm2": None, "norminf": None, "logsumexp": None}
_AFFINE_ARGS = {"abs", "norm1", "norm2", "norminf", "huber", "logsumexp"}

#: the most digits of the numerator and of the denominator of a number in an expression,
#: as written or as a product (numbers are exact rationals: 1e-1000000000 would need a
#: 10^9-digit denominator)
MAX_DIGITS = 4300
_DIGITS_BOUND = 10**MAX_DIGITS  # the least integer of MAX_DIGITS + 1 digits


class ExprError(Exception):
    """An expression cannot be built or is not convex; ``pos`` locates it (an offset in
    the source string, or None). ``nonconvex`` is True when non-convexity is proven
    (an indefinite or concave quadratic polynomial), not only outside the rules."""

    def __init__(self, msg: str, pos: int | None, nonconvex: bool = False) -> None:
        super().__init__(msg)
        self.msg, self.pos, self.nonconvex = msg, pos, nonconvex


@dataclass
class Call:
    """fn(args) with an optional parameter (Huber's M)."""

    fn: str
    args: list[Expr]
    pos: int | None = field(compare=False)
    param: Fraction | None = None


@dataclass
class Expr:
    """const + Σ lin[i] x_i + Σ_{i≤j} quad[i, j] x_i x_j + Σ coef · call."""

    pos: int | None = field(default=None, compare=False)
    const: Fraction = Fraction(0)
    lin: dict[int, Fraction] = field(default_factory=dict)
    quad: dict[tuple[int, int], Fraction] = field(default_factory=dict)
    terms: list[tuple[Fraction, Call]] = field(default_factory=list)

    # -- constructors ------------------------------------------------------ #

    @classmethod
    def number(cls, value: Any, pos: int | None = None) -> Expr:
        return cls(pos, Fraction(value))

    @classmethod
    def var(cls, i: int, pos: int | None = None) -> Expr:
        return cls(pos, lin={i: Fraction(1)})

    @classmethod
    def call(cls, fn: str, args: list[Expr], pos: int | None = None,
             param: Any = None) -> Expr:
        if not args:
            raise ExprError(f"{fn} needs at least one argument", pos)
        par = None if param is None else Fraction(param)
        if fn == "huber" and (par is None or par <= 0):
            raise ExprError("huber's M must be a positive constant", pos)
        return cls(pos, terms=[(Fraction(1), Call(fn, list(args), pos, par))])

    # -- shape ------------------------------------------------------------- #

    @property
    def degree(self) -> int:
        """Polynomial degree (3 stands for "has call terms")."""
        if self.terms:
            return 3
        if any(self.quad.values()):
            return 2
        return 1 if any(self.lin.values()) else 0

    @property
    def variables(self) -> set[int]:
        vs = {i for i, c in self.lin.items() if c} | {v for k in self.quad for v in k}
        for _, call in self.terms:
            for a in call.args:
                vs |= a.variables
        return vs

    # -- arithmetic -------------------------------------------------------- #

    def __add__(self, other: Expr) -> Expr:
        """The sum; equal call terms are merged (so m − m cancels)."""
        terms = list(self.terms)
        for coef, call in other.terms:
            k = next((k for k, (_, t) in enumerate(terms) if t == call), None)
            if k is None:
                terms.append((coef, call))
            else:
                terms[k] = (terms[k][0] + coef, call)
        out = Expr(self.pos, self.const + other.const, dict(self.lin), dict(self.quad),
                   [(c, t) for c, t in terms if c])
        for k, v in other.lin.items():
            out.lin[k] = out.lin.get(k, 0) + v
        for k, v in other.quad.items():
            out.quad[k] = out.quad.get(k, 0) + v
        return out

    def scale(self, c: Fraction) -> Expr:
        return Expr(self.pos, c * self.const, {k: c * v for k, v in self.lin.items()},
                    {k: c * v for k, v in self.quad.items()},
                    [(c * a, t) for a, t in self.terms if c * a])

    def __neg__(self) -> Expr:
        return self.scale(Fraction(-1))

    def __sub__(self, other: Expr) -> Expr:
        return self + (-other)

    def mul(self, other: Expr, pos: int | None) -> Expr:
        if self.degree == 0:
            return _check_size(other.scale(self.const), pos)
        if other.degree == 0:
            return _check_size(self.scale(other.const), pos)
        if self.degree + other.degree > 2:
            raise ExprError("a product of non-constant expressions must be a polynomial "
                            "of degree <= 2", pos)
        out = Expr(self.pos)
        for a, b in ((self, other), (other, self)):
            out = out + Expr(lin={i: a.const * c for i, c in b.lin.items()},
                             quad={k: a.const * c for k, c in b.quad.items()})
        out.const = self.const * other.const
        for i, a in self.lin.items():
            for j, b in other.lin.items():
                k = (min(i, j), max(i, j))
                out.quad[k] = out.quad.get(k, 0) + a * b
        return _check_size(out, pos)

    def div(self, other: Expr, pos: int | None) -> Expr:
        if other.degree != 0:
            raise ExprError("can only divide by a constant", pos)
        if other.const == 0:
            raise ExprError("division by zero", pos)
        return _check_size(self.scale(1 / other.const), pos)

    def power(self, exponent: Expr, pos: int | None) -> Expr:
        p = exponent.const if exponent.degree == 0 else None
        if p == 0:
            return Expr.number(1, self.pos)
        if p == 1:
            return self
        if p == 2:
            if self.degree > 1:
                raise ExprError("^2 needs an affine base", pos)
            return self.mul(self, pos)
        raise ExprError("the exponent must be the number 0, 1 or 2", exponent.pos)

    # -- curvature --------------------------------------------------------- #

    def hessian(self, d: int) -> list[list[Fraction]]:
        """Q with ½xᵀQx the quadratic part."""
        Q = [[Fraction(0)] * d for _ in range(d)]
        for (i, j), c in self.quad.items():
            Q[i][j] += c
            Q[j][i] += c
        return Q

    def curvature(self) -> tuple[str, tuple[str, int | None] | None]:
        """("constant" | "affine" | "convex" | "concave" | "none", why-not-convex)."""
        deg = _poly_degree(self)
        d = 1 + max(self.variables, default=-1)
        if deg < 2:
            curv = ("constant", "affine")[deg]
        else:
            Q = self.hessian(d)
            curv = ("convex" if atoms.is_psd(Q) else
                    "concave" if atoms.is_psd([[-v for v in r] for r in Q]) else "none")
        why = None if curv != "none" else (_INDEFINITE, self.pos)
        for coef, call in self.terms:
            c, w = _call_curvature(call)
            if coef < 0:
                c = {"convex": "concave", "concave": "convex"}.get(c, c)
            curv, why = _combine(curv, why, c, w, call.pos)
        return curv, why

    def check_convex(self) -> None:
        """Raise :class:`ExprError` (with the position) unless the rules prove convexity."""
        curv, why = self.curvature()
        if curv in ("constant", "affine", "convex"):
            return
        if why is None:
            why = ("the expression is concave, not convex", self.pos)
        poly_only = not self.terms
        raise ExprError(why[0], why[1], nonconvex=poly_only)


def _check_size(e: Expr, pos: int | None) -> Expr:
    """``e``, or ExprError when a coefficient's numerator or denominator has more than
    MAX_DIGITS digits (checked after each product, so no product multiplies numbers of
    more than ~2·MAX_DIGITS digits: repeated squaring stops at the first one too large)."""
    coefs = [e.const, *e.lin.values(), *e.quad.values(), *(c for c, _ in e.terms)]
    if not all(_fits(v) for v in coefs):
        raise ExprError(f"a product of the expression's numbers has a numerator or "
                        f"denominator of more than {MAX_DIGITS} digits", pos)
    return e


def _fits(v: Fraction) -> bool:
    return abs(v.numerator) < _DIGITS_BOUND and v.denominator < _DIGITS_BOUND


def _poly_degree(e: Expr) -> int:
    if any(e.quad.values()):
        return 2
    return 1 if any(e.lin.values()) else 0


_ORDER = {"constant": 0, "affine": 1}
_INDEFINITE = "the quadratic part is neither convex nor concave"


def _combine(a: str, wa: Any, b: str, wb: Any, pos: int | None) -> tuple[str, Any]:
    """Curvature of a sum."""
    if a == "none":
        return a, wa
    if b == "none":
        return b, wb
    if a in _ORDER and b in _ORDER:
        return max(a, b, key=_ORDER.get), None
    if a in _ORDER:
        return b, None
    if b in _ORDER or a == b:
        return a, None
    return "none", ("a sum of convex and concave terms is not convex", pos)


def _call_curvature(call: Call) -> tuple[str, tuple[str, int | None] | None]:
    fn, args = call.fn, call.args
    if fn in _AFFINE_ARGS:
        for a in args:
            if a.degree > 1:
                return "none", (f"{fn} needs affine arguments", a.pos)
        return "convex", None
    if fn == "sqrt":
        if args[0].degree > 2 or atoms.ldl_psd(_homogenised(args[0])) is None:
            return "none", ("sqrt needs a sum of squares of affine expressions", args[0].pos)
        return "convex", None
    want = ("concave",) if fn == "min" else ("convex",)
    for a in args:
        c, w = a.curvature()
        if c == "none":
            return c, w
        if c not in _ORDER and c not in want:
            return "none", (f"{fn} needs {want[0]} (or affine) arguments", a.pos)
    return ("concave" if fn == "min" else "convex"), None


def _homogenised(e: Expr) -> list[list[Fraction]]:
    """H with e(x) = (x, 1)ᵀ H (x, 1), for a polynomial e of degree ≤ 2."""
    d = 1 + max(e.variables, default=-1)
    H = [[v / 2 for v in row] + [Fraction(0)] for row in e.hessian(d)]
    H.append([Fraction(0)] * (d + 1))
    for i, c in e.lin.items():
        H[i][d] += c / 2
        H[d][i] += c / 2
    H[d][d] = e.const
    return H


# --------------------------------------------------------------------------- #
# lowering to atoms
# --------------------------------------------------------------------------- #


def _float(v: Fraction) -> float:
    try:
        f = float(v)
    except OverflowError:
        f = math.inf
    if not math.isfinite(f):
        raise ExprError(f"a number computed from the expression's numbers (about "
                        f"{_magnitude(v)}) does not fit a float", None)
    return f


def _magnitude(v: Fraction) -> str:
    """±m·10^e with one decimal of m, for a message (str(v) may have thousands of
    digits, beyond Python's int-string limit)."""
    e = math.log10(abs(v.numerator)) - math.log10(v.denominator)
    return f"{'-' if v < 0 else ''}{10 ** (e - math.floor(e)):.1f}e+{math.floor(e)}"


_NUMBER = re.compile(r"(\d*)\.?(\d*)(?:[eE]([+-]?\d+))?")


def _abridged(text: str, limit: int, at: int | None = None) -> str:
    """``text`` itself up to ``limit`` characters; longer, a window of about ``limit``
    characters around position ``at`` (else its start and end) with "…" where text is
    left out and the full length — error messages stay one readable line."""
    if len(text) <= limit:
        return text
    half = limit // 2 - 8
    if at is None or at < half or at > len(text) - half:
        return f"{text[:half]}…{text[-half:]} ({len(text)} characters)"
    return f"…{text[at - half:at + half]}… ({len(text)} characters)"


def _number(text: str, pos: int) -> Fraction:
    """The number token ``text`` exactly, or ExprError quoting it: beyond the float range
    (``float(text)`` is infinite: correctly rounded, as :func:`_float` decides for computed
    numbers), more than :data:`MAX_DIGITS` significant digits as written (V39: even where
    the reduced fraction would be shorter), or a numerator or denominator of more than
    :data:`MAX_DIGITS` digits. A
    number too large, or too small for its denominator, is refused from its digits and
    exponent, before 10^exponent is built (``1e1000000000``, ``1e-1000000000``)."""
    shown = _abridged(text, 40)
    whole, frac, exp = _NUMBER.fullmatch(text).groups()  # type: ignore[union-attr]
    digits = (whole + frac).lstrip("0")
    sig = digits.rstrip("0")
    if not sig:
        return Fraction(0)
    if math.isinf(float(text)):
        raise ExprError(f"the number {shown} does not fit a float", pos)
    too_long = ExprError(f"the number {shown} has a numerator or denominator of more than "
                         f"{MAX_DIGITS} digits (numbers are kept exact)", pos)
    try:
        k = int(exp or 0) - len(frac) + len(digits) - len(sig)  # value = int(sig)·10^k
    except ValueError:  # an exponent of more digits than Python's int-string limit
        raise too_long from None
    if len(sig) > MAX_DIGITS:  # int(sig) itself would pass Python's int-string limit
        raise ExprError(f"the number {shown} has more than {MAX_DIGITS} significant "
                        "digits as written (numbers are kept exact)", pos)
    # k >= 0: below 1.8e308, so len(sig) + k <= 309; k < 0: the denominator 10^-k / gcd
    # is at least 10^(-k - len(sig)), too long when -k > 2·MAX_DIGITS
    if -k > 2 * MAX_DIGITS:
        raise too_long
    m = int(sig)
    v = Fraction(m * 10**k) if k >= 0 else Fraction(m, 10**-k)
    if not _fits(v):
        raise too_long
    return v


def _sqrt(p: Fraction) -> Fraction:
    """√p for a pivot p > 0 of sqrt's LDLᵀ: exact when p is the square of a rational,
    else the float √p read exactly. A row √p·l of the Norm2 is then a rational multiple
    of l, so its anchor (the ratios of l's entries, e.g. 10^50 in sqrt((x1 − 1e50)^2))
    stays exact; only the row's weight may be off by an ulp."""
    a, b = math.isqrt(p.numerator), math.isqrt(p.denominator)
    if a * a == p.numerator and b * b == p.denominator:
        return Fraction(a, b)
    return Fraction(math.sqrt(_float(p)))


def _affine_rows(args: list[Expr], d: int) -> tuple[np.ndarray, np.ndarray]:
    """A, c (object arrays of Fractions, each fitting a float) with
    args[i] = A[i] x + c[i] (affine args)."""
    A = np.full((len(args), d), Fraction(0), dtype=object)
    c = np.array([a.const for a in args] + [None], dtype=object)[:-1]
    for r, a in enumerate(args):
        _float(a.const)
        for i, v in a.lin.items():
            _float(v)
            A[r, i] = v
    return A, c


def lower(e: Expr, d: int) -> Oracle:
    """The atom (tree) computing the convex expression ``e`` over x ∈ R^d
    (:meth:`Expr.check_convex` must have passed): the polynomial part as one
    Quadratic (or Affine), two or more positive ``abs`` terms as one Norm1 (one
    matrix product instead of one per term), each other term as its atom. The
    polynomial part is centred at its (minimum-norm) minimiser, exactly (see
    :func:`_quadratic`)."""
    parts: list[Oracle] = []
    A, c = _affine_rows([_linear(e)], d)
    if any(e.quad.values()):
        Q = e.hessian(d)
        for v in (v for row in Q for v in row):
            _float(v)
        parts.append(_quadratic(Q, list(A[0]), c[0]))
    elif any(e.lin.values()) or e.const or not e.terms:
        parts.append(atoms.Affine(A[0], c[0]))
    absolute = [(coef, call) for coef, call in e.terms if coef > 0 and call.fn == "abs"]
    if len(absolute) > 1:  # Σ c_i |a_iᵀx + k_i| = ‖Ax − b‖₁ with rows scaled by c_i
        A, c = _affine_rows([call.args[0].scale(coef) for coef, call in absolute], d)
        parts.append(atoms.Norm1(A, -c))
    for coef, call in e.terms:
        if len(absolute) > 1 and call.fn == "abs" and coef > 0:
            continue
        atom = _lower_call(call, d) if coef > 0 else _lower_negated_min(call, d)
        parts.append(atom if abs(coef) == 1 else atoms.Scaled(abs(coef), atom))
    return parts[0] if len(parts) == 1 else atoms.Sum(parts)


def _quadratic(Q: list[list[Fraction]], q: list[Fraction], k: Fraction) -> Oracle:
    """½xᵀQx + qᵀx + k as a Quadratic centred at c = −Q⁺q, completed exactly
    (:func:`~rescon.optim.atoms.complete_square`): ½(x − c)ᵀQ(x − c) + rᵀx + f(c), which
    the atom evaluates in this or the expanded form, whichever rounds less at the point
    (so (x1 − 1e50)^2 is 0 at 1e50); the expanded form alone when c, r or f(c) does not
    fit a float."""
    c, r = atoms.complete_square(Q, q)
    fc = k - sum(ci * sum(a * b for a, b in zip(row, c)) for ci, row in zip(c, Q)) / 2
    try:
        for v in (*c, *r, fc):
            _float(v)
    except ExprError:
        return atoms.Quadratic(Q, q=q, const=k)
    return atoms.Quadratic(Q, c=c, q=r, const=fc)


def _linear(e: Expr) -> Expr:
    return Expr(e.pos, e.const, e.lin)


def _lower_call(call: Call, d: int) -> Oracle:
    fn, args = call.fn, call.args
    if fn == "sqrt":
        fac = atoms.ldl_psd(_homogenised(args[0]))
        n = 1 + max(args[0].variables, default=-1)
        R = np.full((max(len(fac), 1), d + 1), Fraction(0), dtype=object)
        for r, (p, col) in enumerate(fac):
            root = _sqrt(p)
            R[r, :n] = [root * v for v in col[:n]]
            R[r, d] = root * col[n]
            for v in R[r]:
                _float(v)  # each entry must fit a float: else ExprError
        return atoms.Norm2(R[:, :d], -R[:, d])
    if fn == "pos":
        if args[0].degree <= 1:
            A, c = _affine_rows(args, d)
            return atoms.Hinge(A[0], -c[0])
        return atoms.MaxOf([lower(args[0], d), atoms.Affine(np.zeros(d), 0.0)])
    if fn == "max":
        if all(a.degree <= 1 for a in args):
            return atoms.MaxAffine(*_affine_rows(args, d))
        return atoms.MaxOf([lower(a, d) for a in args])
    A, c = _affine_rows(args, d)
    if fn == "abs":
        return atoms.AbsAffine(A[0], -c[0])
    if fn == "huber":
        return atoms.Huber(A, -c, call.param)
    if fn == "logsumexp":
        return atoms.LogSumExp(A, c)
    return {"norm1": atoms.Norm1, "norm2": atoms.Norm2, "norminf": atoms.NormInf}[fn](A, -c)


def _lower_negated_min(call: Call, d: int) -> Oracle:
    """−min(e_1, …) = max(−e_1, …)."""
    return _lower_call(Call("max", [-a for a in call.args], call.pos), d)


# --------------------------------------------------------------------------- #
# the parser
# --------------------------------------------------------------------------- #

_TOKEN = re.compile(r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)"
                    r"|(?P<name>[A-Za-z_][A-Za-z_0-9]*)|(?P<op>[-+*/^(),]))")


def _tokens(src: str) -> list[tuple[str, str, int]]:
    out, i = [], 0
    while True:
        m = _TOKEN.match(src, i)
        if m is None:
            j = len(src) - len(src[i:].lstrip())
            if j == len(src):
                break
            raise ExprError(f"unexpected character {src[j]!r}", j)
        kind = m.lastgroup or ""
        out.append((kind, m.group(kind), m.start(kind)))
        i = m.end()
    out.append(("end", "", len(src)))
    return out


#: how deeply parentheses, calls, signs and exponents may nest (each level is a few
#: Python frames of the recursive descent; deeper input is refused, not a RecursionError)
MAX_DEPTH = 100


class _Parser:
    def __init__(self, src: str) -> None:
        self.toks = _tokens(src)
        self.i = 0
        self.depth = 0

    def nested(self, parse: Any, pos: int) -> Expr:
        """``parse()`` one level deeper (ExprError beyond :data:`MAX_DEPTH`)."""
        if self.depth == MAX_DEPTH:
            raise ExprError(f"the expression nests more than {MAX_DEPTH} levels deep "
                            f"(parentheses, calls, signs, exponents)", pos)
        self.depth += 1
        e = parse()
        self.depth -= 1
        return e

    def peek(self) -> tuple[str, str, int]:
        return self.toks[self.i]

    def take(self, want: str | None = None) -> tuple[str, str, int]:
        tok = self.toks[self.i]
        if want is not None and tok[1] != want:
            got = "the end" if tok[0] == "end" else repr(tok[1])
            raise ExprError(f"expected {want!r}, found {got}", tok[2])
        self.i += 1
        return tok

    def expr(self) -> Expr:
        e = self.term()
        while self.peek()[1] in ("+", "-"):
            op = self.take()[1]
            t = self.term()
            e = e + t if op == "+" else e - t
        return e

    def term(self) -> Expr:
        e = self.unary()
        while self.peek()[1] in ("*", "/"):
            _, op, pos = self.take()
            u = self.unary()
            e = e.mul(u, pos) if op == "*" else e.div(u, pos)
        return e

    def unary(self) -> Expr:
        if self.peek()[1] in ("+", "-"):
            _, op, pos = self.take()
            e = self.nested(self.unary, pos)
            e = e if op == "+" else -e
            e.pos = pos
            return e
        return self.power()

    def power(self) -> Expr:
        e = self.atom()
        if self.peek()[1] == "^":
            pos = self.take()[2]
            e = e.power(self.nested(self.unary, pos), pos)
        return e

    def atom(self) -> Expr:
        kind, text, pos = self.take()
        if kind == "num":
            return Expr.number(_number(text, pos), pos)
        if text == "(":
            e = self.nested(self.expr, pos)
            self.take(")")
            e.pos = pos
            return e
        if kind == "name":
            m = re.fullmatch(r"x([1-9]\d*)", text)
            if m:
                return Expr.var(int(m.group(1)) - 1, pos)
            if text in FUNCTIONS:
                return self.call(text, pos)
            raise ExprError(f"unknown name {text!r} (variables are x1, x2, …; functions: "
                            f"{', '.join(FUNCTIONS)})", pos)
        got = "the end" if kind == "end" else repr(text)
        raise ExprError(f"expected a number, a variable, a function or '(', found {got}", pos)

    def call(self, fn: str, pos: int) -> Expr:
        self.take("(")
        args = [self.nested(self.expr, pos)]
        while self.peek()[1] == ",":
            self.take()
            args.append(self.nested(self.expr, pos))
        self.take(")")
        n = FUNCTIONS[fn]
        lo, hi = (n, n) if isinstance(n, int) else n if n else (1, None)
        if len(args) < lo or (hi is not None and len(args) > hi):
            raise ExprError(f"{fn} takes {lo if lo == hi else f'{lo} or {hi}'} argument(s); "
                            f"got {len(args)}", pos)
        if fn == "huber" and len(args) == 2:
            if args[1].degree != 0:
                raise ExprError("huber's M must be a positive constant", args[1].pos)
            return Expr.call(fn, args[:1], pos, args[1].const)
        return Expr.call(fn, args, pos, 1 if fn == "huber" else None)


def parse(src: str) -> Expr:
    """The expression ``src`` in canonical form (raises :class:`ExprError`)."""
    p = _Parser(src)
    e = p.expr()
    kind, text, pos = p.peek()
    if kind != "end":
        raise ExprError(f"unexpected {text!r}", pos)
    return e


def expression_cost(src: Any, *, d: int | None = None, name: str = "cost") -> Oracle:
    """The oracle of the cost expression ``src`` (the grammar above) over x ∈ R^d
    (d defaults to the largest variable index used; 1 for a constant).

    Raises
    ------
    InputError
        A syntax error, an expression the rules cannot prove convex, or a variable
        beyond ``d`` — one line naming the expression and the position (0-based).
    """
    if not isinstance(src, str):
        raise InputError(f"{name}: a cost expression must be a string; got {type(src).__name__}")
    try:
        e = parse(src)
        e.check_convex()
        used = 1 + max(e.variables, default=0)
        if d is not None and used > d:
            raise ExprError(f"x{used} is used but d = {d}", None)
        o = lower(e, d if d is not None else used)
    except ExprError as exc:
        at = "" if exc.pos is None else f" at position {exc.pos}"
        raise InputError(f"{name}: expression {_abridged(src, 200, exc.pos)!r}: "
                         f"{exc.msg}{at}") from None
    o.name, o.kind, o.source = name, "expression", src
    return o
