"""CasADi costs: lowered to atoms where the graph allows, else compiled AD with a
kink repair.

CasADi's automatic differentiation is the chain rule on the expression graph, which is
wrong at kinks: ``norm_2(x)`` is ``sqrt(sq(x_0) + sq(x_1))`` and its derivative at 0 is
0/0 = NaN. (``fabs`` differentiates to sign, 0 at 0, and ``fmax`` to ½, ½ at a tie —
both subgradients — so the square root is the broken case.) The adapter therefore
takes two paths, and says which one a cost took in ``oracle.path``:

``"lowered"``
    The expression (MX is first expanded to SX) is walked node by node into the exact
    IR of :mod:`rescon.optim.expr` — constants, the symbol's entries, ``+ − * /``,
    ``sq``, ``x**2``, ``sqrt`` (of a sum of squares, so ``norm_2``), ``fabs``
    (``norm_1``), ``fmax``/``fmin`` (``norm_inf``, ``mmax``, ``mmin``), and
    ``log(Σ exp(·))`` (including ``casadi.logsumexp``'s max-shifted form) — its
    convexity checked by the same rules as a cost string, and evaluated by the atom
    library: exact subgradient conventions, true subgradients at every kink.
``"ad"``
    Anything else (``exp``, ``if_else``, a Function that cannot be expanded, …). Value
    and Jacobian are compiled once into one CasADi Function and ``map``-ped over the
    batch (one mapped Function per batch size, cached). Convexity is not verified on
    this path (``oracle.convex_verified`` is False; :func:`rescon.check_subgradient`
    measures it on samples). Where the Jacobian is not finite at x, the gradient g_y
    at a probe y = x + h·u (fixed direction u, h = 10⁻⁸, 10⁻⁶, 10⁻⁴ times 1 + ‖x‖∞) is
    returned: for a convex f it satisfies f(z) ≥ f(x) + g_yᵀ(z − x) − δ with
    δ = f(x) − f(y) − g_yᵀ(x − y) ≥ 0, which is 0 when f is positively homogeneous
    around x (a norm at its centre) and O(h²) for a smooth part; the largest δ
    returned so far is kept in ``oracle.kink_error``. No finite probe → InputError.
"""

from __future__ import annotations

import re
from fractions import Fraction
from typing import Any

import numpy as np

from ..errors import InputError
from ..models.backends import require_backend
from .expr import Expr, ExprError, lower
from .oracle import Oracle

__all__ = ["CasadiOracle", "casadi_cost"]


def casadi_cost(spec: Any, *, x: Any = None, d: int | None = None,
                name: str = "cost") -> Oracle:
    """The oracle of a scalar CasADi SX/MX expression in the symbol ``x`` (a d-vector;
    None: the expression's only symbol, e.g. an MX vector or one scalar SX), or of a
    CasADi Function of one d-vector with a scalar first output; the lowered atom when
    the graph allows (see the module notes), else a :class:`CasadiOracle`."""
    require_backend("casadi", "model")
    import casadi as ca

    fn = _function(ca, spec, x, name)
    dim = int(fn.size1_in(0) * fn.size2_in(0))
    if d is not None and d != dim:
        raise InputError(f"{name}: the CasADi cost has dimension {dim}, not d = {d}")
    try:
        sx_fn = fn.expand() if fn.is_a("MXFunction") else fn
        xs = ca.SX.sym("x", dim)
        e = _Lower(ca, xs).expr(sx_fn(xs) if sx_fn.n_out() == 1 else sx_fn(xs)[0])
        e.check_convex()
        o = lower(e, dim)
    except ExprError as exc:
        if exc.nonconvex:
            raise InputError(f"{name}: the CasADi cost is not convex ({exc.msg})") from None
        return CasadiOracle(fn, dim, name=name)
    except RuntimeError:  # an MX Function that cannot be expanded
        return CasadiOracle(fn, dim, name=name)
    o.name, o.kind, o.path, o.convex_verified = name, "casadi", "lowered", True
    o.function = fn
    return o


def _function(ca: Any, spec: Any, x: Any, name: str) -> Any:
    """``spec`` as a CasADi Function of one vector with a scalar first output."""
    if isinstance(spec, ca.Function):
        fn = spec
    else:
        if not isinstance(spec, (ca.SX, ca.MX)):
            raise InputError(f"{name}: a CasADi cost must be an SX/MX expression or a "
                             f"Function; got {type(spec).__name__}")
        if x is None:
            x = _symbol(ca, spec, name)
        if type(x) is not type(spec) or not x.is_valid_input():
            raise InputError(f"{name}: give the CasADi symbol the cost is written in "
                             f"(rescon.cost(expr, x=x), x of the same type as expr)")
        try:
            fn = ca.Function("f", [x], [spec])
        except RuntimeError as exc:
            free = re.search(r"variables \[.*?\]", str(exc))
            raise InputError(f"{name}: the CasADi cost depends on more than x "
                             f"({free.group(0) if free else 'free symbols'})") from None
    if fn.n_in() != 1 or min(fn.size1_in(0), fn.size2_in(0)) != 1 or fn.n_out() < 1 \
            or fn.numel_out(0) != 1:
        raise InputError(f"{name}: a CasADi cost must be a scalar function of one vector; "
                         f"got inputs {[fn.size_in(i) for i in range(fn.n_in())]}, first "
                         f"output {fn.size_out(0) if fn.n_out() else None}")
    return fn


def _symbol(ca: Any, spec: Any, name: str) -> Any:
    """The one symbol ``spec`` is written in (``casadi.symvar``); InputError when it has
    none or several (an SX vector's entries are separate symbols: give x= then)."""
    syms = ca.symvar(spec)
    if len(syms) == 1:
        return syms[0]
    names = ", ".join(str(s) for s in syms[:4]) + (", …" if len(syms) > 4 else "")
    have = f"{len(syms)} symbols ({names})" if syms else "no symbol"
    raise InputError(f"{name}: the CasADi cost has {have}; give the CasADi symbol it is "
                     f"written in "
                     f"(rescon.cost(expr, x=x))")


class _Lower:
    """SX graph → :class:`~rescon.optim.expr.Expr` (ExprError when an op is outside the
    covered set); shared subexpressions are converted once."""

    def __init__(self, ca: Any, xs: Any) -> None:
        self.ca = ca
        self.index = {xs[i].element_hash(): i for i in range(xs.numel())}
        self.memo: dict[int, Expr] = {}
        ops = {"ADD": lambda a, b: a + b, "SUB": lambda a, b: a - b,
               "MUL": lambda a, b: a.mul(b, None), "DIV": lambda a, b: a.div(b, None),
               "NEG": lambda a: -a, "TWICE": lambda a: a.scale(Fraction(2)),
               "SQ": lambda a: a.mul(a, None),
               "CONSTPOW": lambda a, b: a.power(b, None), "POW": lambda a, b: a.power(b, None),
               "FABS": lambda a: Expr.call("abs", [a]), "SQRT": lambda a: Expr.call("sqrt", [a]),
               "FMAX": lambda a, b: Expr.call("max", _flat("max", a) + _flat("max", b)),
               "FMIN": lambda a, b: Expr.call("min", _flat("min", a) + _flat("min", b))}
        self.ops = {getattr(ca, "OP_" + k): f for k, f in ops.items()}

    def expr(self, s: Any) -> Expr:
        h = s.element_hash()
        if h not in self.memo:
            self.memo[h] = self._convert(s)
        return self.memo[h]

    def _convert(self, s: Any) -> Expr:
        ca = self.ca
        if s.is_constant():
            return Expr.number(float(s))
        if s.is_symbolic():
            return Expr.var(self.index[s.element_hash()])
        op = s.op()
        if op == ca.OP_LOG:
            return self._log_sum_exp(s.dep(0))
        if op not in self.ops:
            raise ExprError(f"CasADi operation {s} is not covered", None)
        return self.ops[op](*(self.expr(s.dep(i)) for i in range(s.n_dep())))

    def _log_sum_exp(self, s: Any) -> Expr:
        """log(Σ exp(a_i − m)) = logsumexp(a_i) − m, for affine a_i and a common m."""
        ca, exps, todo = self.ca, [], [s]
        while todo:
            t = todo.pop()
            if t.op() == ca.OP_ADD:
                todo += [t.dep(0), t.dep(1)]
            elif t.op() == ca.OP_EXP:
                exps.append(self.expr(t.dep(0)))
            else:
                raise ExprError("log is covered only as log(sum of exp)", None)
        shift = Expr(terms=exps[0].terms, quad=exps[0].quad)
        affine = [e - shift for e in exps]
        if any(a.degree > 1 for a in affine):
            raise ExprError("log(sum of exp) needs affine exponents", None)
        return Expr.call("logsumexp", affine) + shift


def _flat(fn: str, e: Expr) -> list[Expr]:
    """The arguments of a nested max/min (fmax(fmax(a, b), c) → a, b, c)."""
    if e.const == 0 and not e.lin and not e.quad and len(e.terms) == 1:
        coef, call = e.terms[0]
        if coef == 1 and call.fn == fn:
            return call.args
    return [e]


class CasadiOracle(Oracle):
    """The AD path: value and Jacobian compiled once, ``map``-ped over batches, with the
    kink repair of the module notes."""

    kind = "casadi"
    path = "ad"
    convex_verified = False

    def __init__(self, fn: Any, d: int, *, name: str = "cost") -> None:
        import casadi as ca

        super().__init__(d, name)
        self.function = fn
        xs = ca.MX.sym("x", d)
        f = fn(xs) if fn.n_out() == 1 else fn(xs)[0]
        self._fg = ca.Function("fg", [xs], [f, ca.jacobian(f, xs)])
        self._maps: dict[int, Any] = {}
        self.kink_error = 0.0
        self._u = np.random.default_rng(0).standard_normal(d)
        self._u /= np.linalg.norm(self._u)

    def _both(self, Z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        B = Z.shape[0]
        if B == 0:
            return np.zeros(0), np.zeros((0, self.d))
        if B not in self._maps:
            self._maps[B] = self._fg.map(B)
        v, J = self._maps[B](Z.T)
        return np.asarray(v, dtype=float).reshape(B), \
            np.asarray(J, dtype=float).reshape(B, self.d)

    def _value(self, Z: np.ndarray) -> np.ndarray:
        return self._both(Z)[0]

    def _subgradient(self, Z: np.ndarray) -> np.ndarray:
        v, G = self._both(Z)
        bad = np.flatnonzero(~np.isfinite(G).all(axis=1))
        for b in bad:
            G[b] = self._probe(Z[b], v[b])
        return G

    def _probe(self, z: np.ndarray, fz: float) -> np.ndarray:
        """A gradient at a nearby point (see the module notes)."""
        for h in (1e-8, 1e-6, 1e-4):
            y = z + h * (1.0 + np.abs(z).max()) * self._u
            fy, g = self._both(y[None, :])
            if np.isfinite(g).all() and np.isfinite(fy).all():
                delta = float(fz - fy[0] - g[0] @ (z - y))
                self.kink_error = max(self.kink_error, delta)
                return g[0]
        raise InputError(f"{self.name}: CasADi gives no finite gradient at or near the point "
                         f"{z.tolist()}")
