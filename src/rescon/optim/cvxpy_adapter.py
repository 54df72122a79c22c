"""CVXPY costs: lowered into the atom library, ``.grad`` only for what is not covered.

CVXPY evaluates ``expr.value`` and ``expr.grad`` one point at a time through its
expression tree (milliseconds per call), and ``norm_inf`` has no ``.grad`` at all. A
DCP-convex scalar expression in the Variable ``x`` is therefore walked into the exact
IR of :mod:`rescon.optim.expr` — entry-wise, with numpy broadcasting — from these
nodes: Variable ``x``, Constant, Parameter (its current value, read once), ``+``, ``−``,
``@``, ``*``, ``multiply``, ``/`` (by a constant), indexing, ``sum``, ``reshape``,
``hstack``/``vstack``, ``promote``, transpose, ``power``/``square`` (p = 2),
``sum_squares``/``quad_over_lin`` (constant denominator), ``quad_form`` (constant
matrix), ``abs``, ``pos``, ``maximum``, ``minimum``, ``max``, ``min``, ``norm1``,
``norm``/``pnorm`` (p = 2), ``norm_inf``, ``huber``, ``log_sum_exp`` (reductions over
the whole argument). The IR's convexity rules must prove it convex too.

A cost outside that set keeps CVXPY's own ``value``/``.grad``: if the expression is a
sum, each summand is tried on its own and only the ones not covered use ``.grad``.
``oracle.path`` says which: "lowered" (all atoms), "grad" (all CVXPY), or "mixed"
(``oracle.grad_terms`` lists the summands evaluated by CVXPY).
"""

from __future__ import annotations

import functools
from fractions import Fraction
from typing import Any

import numpy as np

from ..errors import InputError
from ..models.backends import require_backend
from . import atoms
from .expr import Expr, ExprError, lower
from .oracle import Oracle

__all__ = ["CvxpyGradOracle", "cvxpy_cost"]


def cvxpy_cost(spec: Any, *, x: Any = None, name: str = "cost") -> Oracle:
    """The oracle of a scalar DCP-convex CVXPY expression in the Variable ``x`` (found
    as the expression's only Variable when not given)."""
    require_backend("cvxpy", "model")
    import cvxpy as cp

    if not isinstance(spec, cp.Expression):
        raise InputError(f"{name}: a CVXPY cost must be an Expression; got "
                         f"{type(spec).__name__}")
    x = _variable(cp, spec, x, name)
    if spec.size != 1:
        raise InputError(f"{name}: a CVXPY cost must be scalar; got shape {spec.shape}")
    if not (spec.is_dcp() and spec.is_convex()):
        raise InputError(f"{name}: the CVXPY cost is not DCP-convex: {spec}")
    d = max(x.size, 1)
    summands = spec.args if type(spec).__name__ == "AddExpression" else [spec]
    parts: list[Oracle] = []
    grad: list[Any] = []
    for s in ([spec] if len(summands) == 1 else summands):
        o = _lowered(cp, s, x, d)
        if o is None:
            grad.append(s)
        else:
            parts.append(o)
    if len(grad) == len(summands) and len(summands) > 1:
        grad = [spec]
    if grad:
        parts.append(CvxpyGradOracle(functools.reduce(lambda a, b: a + b, grad), x, name=name))
    o = parts[0] if len(parts) == 1 else atoms.Sum(parts)
    o.path = "lowered" if not grad else "grad" if len(parts) == 1 else "mixed"
    o.name, o.kind, o.source = name, "cvxpy", spec
    o.grad_terms = [str(g) for g in grad]
    return o


def _variable(cp: Any, spec: Any, x: Any, name: str) -> Any:
    vs = spec.variables()
    if x is None:
        if len(vs) != 1:
            raise InputError(f"{name}: give the CVXPY Variable the cost is written in "
                             f"(rescon.cost(expr, x=x)); the cost has {len(vs)} variables")
        x = vs[0]
    if not isinstance(x, cp.Variable) or len(x.shape) > 1 and min(x.shape) > 1:
        raise InputError(f"{name}: x must be a CVXPY vector Variable; got {x!r}")
    if any(v.id != x.id for v in vs):
        raise InputError(f"{name}: the CVXPY cost depends on variables other than x")
    return x


def _lowered(cp: Any, s: Any, x: Any, d: int) -> Oracle | None:
    """The atom of the scalar expression ``s``, or None when it is not covered."""
    try:
        e = _Lower(x).arr(s).reshape(-1)[0]
        e.check_convex()
        return lower(e, d)
    except ExprError:
        return None


def _const(v: Any) -> np.ndarray:
    arr = np.asarray(v, dtype=float)
    if not np.isfinite(arr).all():
        raise ExprError("a constant is not finite", None)
    return np.vectorize(lambda t: Expr.number(Fraction(float(t))), otypes=[object])(arr) \
        if arr.size else np.empty(arr.shape, dtype=object)


_mul = np.frompyfunc(lambda a, b: a.mul(b, None), 2, 1)
_div = np.frompyfunc(lambda a, b: a.div(b, None), 2, 1)


def _sum(arr: np.ndarray) -> Expr:
    return functools.reduce(lambda a, b: a + b, arr.reshape(-1), Expr())


def _elementwise(fn: str, *arrs: np.ndarray) -> np.ndarray:
    return np.frompyfunc(lambda *a: Expr.call(fn, list(a)), len(arrs), 1)(*arrs)


class _Lower:
    """CVXPY expression → object array of :class:`Expr` with the expression's shape."""

    def __init__(self, x: Any) -> None:
        self.x = x
        n = max(x.size, 1)
        self.xs = np.array([Expr.var(i) for i in range(n)], dtype=object).reshape(x.shape)

    def arr(self, e: Any) -> np.ndarray:
        kind = type(e).__name__
        handler = getattr(self, "_" + kind, None)
        if handler is None:
            raise ExprError(f"CVXPY {kind} is not covered", None)
        out = np.asarray(handler(e, *e.args) if e.args else handler(e), dtype=object)
        if out.shape != e.shape:
            raise ExprError(f"CVXPY {kind}: shape {out.shape}, expected {e.shape}", None)
        return out

    def args(self, e: Any) -> list[np.ndarray]:
        return [self.arr(a) for a in e.args]

    # leaves
    def _Variable(self, e: Any) -> np.ndarray:
        return self.xs

    def _Constant(self, e: Any) -> np.ndarray:
        return _const(e.value)

    def _Parameter(self, e: Any) -> np.ndarray:
        if e.value is None:
            raise InputError(f"CVXPY Parameter {e.name()} has no value")
        return _const(e.value)

    # affine
    def _AddExpression(self, e: Any, *a: Any) -> np.ndarray:
        return functools.reduce(lambda p, q: p + q, self.args(e))

    def _NegExpression(self, e: Any, a: Any) -> np.ndarray:
        return -self.arr(a)

    def _MulExpression(self, e: Any, a: Any, b: Any) -> np.ndarray:
        A, B = self.arr(a), self.arr(b)
        if A.ndim == 0 or B.ndim == 0:
            return _mul(A, B)
        A2, B2 = (A[None, :] if A.ndim == 1 else A), (B[:, None] if B.ndim == 1 else B)
        out = np.empty((A2.shape[0], B2.shape[1]), dtype=object)
        for i in range(out.shape[0]):
            for j in range(out.shape[1]):
                out[i, j] = _sum(_mul(A2[i, :], B2[:, j]))
        return out.reshape(e.shape)

    def _multiply(self, e: Any, a: Any, b: Any) -> np.ndarray:
        return _mul(self.arr(a), self.arr(b))

    def _DivExpression(self, e: Any, a: Any, b: Any) -> np.ndarray:
        return _div(self.arr(a), self.arr(b))

    def _index(self, e: Any, a: Any) -> np.ndarray:
        return np.reshape(self.arr(a)[e.key], e.shape)

    _special_index = _index

    def _Sum(self, e: Any, a: Any) -> np.ndarray:
        A = self.arr(a)
        if e.axis is not None and A.ndim > 1:
            raise ExprError("sum along an axis is not covered", None)
        return np.array(_sum(A), dtype=object)

    def _reshape(self, e: Any, a: Any) -> np.ndarray:
        return np.reshape(self.arr(a), e.shape, order=getattr(e, "order", "F"))

    def _Promote(self, e: Any, a: Any) -> np.ndarray:
        return np.full(e.shape, self.arr(a).reshape(-1)[0], dtype=object)

    def _transpose(self, e: Any, a: Any) -> np.ndarray:
        return self.arr(a).T

    def _Hstack(self, e: Any, *a: Any) -> np.ndarray:
        return np.hstack(self.args(e))

    def _Vstack(self, e: Any, *a: Any) -> np.ndarray:
        return np.vstack(self.args(e))

    # nonlinear
    def _PowerApprox(self, e: Any, a: Any) -> np.ndarray:
        p = Fraction(float(e.p.value))
        return np.frompyfunc(lambda t: t.power(Expr.number(p), None), 1, 1)(self.arr(a))

    _Power = _PowerApprox

    def _quad_over_lin(self, e: Any, a: Any, b: Any) -> np.ndarray:
        A = self.arr(a)
        return np.array(_sum(_mul(A, A)).div(self.arr(b).reshape(-1)[0], None), dtype=object)

    def _QuadForm(self, e: Any, a: Any, P: Any) -> np.ndarray:
        v, M = self.arr(a).reshape(-1), self.arr(P)
        return np.array(_sum(_mul(_mul(v[:, None], M), v[None, :])), dtype=object)

    def _abs(self, e: Any, a: Any) -> np.ndarray:
        return _elementwise("abs", self.arr(a))

    def _maximum(self, e: Any, *a: Any) -> np.ndarray:
        return _elementwise("max", *self.args(e))

    def _minimum(self, e: Any, *a: Any) -> np.ndarray:
        return _elementwise("min", *self.args(e))

    def _reduce(self, fn: str, e: Any, a: Any) -> np.ndarray:
        A = self.arr(a)
        if getattr(e, "axis", None) is not None and A.ndim > 1:
            raise ExprError(f"{fn} along an axis is not covered", None)
        return np.array(Expr.call(fn, list(A.reshape(-1))), dtype=object)

    def _max(self, e: Any, a: Any) -> np.ndarray:
        return self._reduce("max", e, a)

    def _min(self, e: Any, a: Any) -> np.ndarray:
        return self._reduce("min", e, a)

    def _norm1(self, e: Any, a: Any) -> np.ndarray:
        return self._reduce("norm1", e, a)

    def _norm_inf(self, e: Any, a: Any) -> np.ndarray:
        return self._reduce("norminf", e, a)

    def _log_sum_exp(self, e: Any, a: Any) -> np.ndarray:
        return self._reduce("logsumexp", e, a)

    def _PnormApprox(self, e: Any, a: Any) -> np.ndarray:
        if float(e.p) != 2:
            raise ExprError("only the 2-norm is covered", None)
        return self._reduce("norm2", e, a)

    _Pnorm = _PnormApprox

    def _huber(self, e: Any, a: Any) -> np.ndarray:
        M = Fraction(float(e.M.value))
        return np.frompyfunc(lambda t: Expr.call("huber", [t], None, M), 1, 1)(self.arr(a))


class CvxpyGradOracle(Oracle):
    """CVXPY's own ``value`` and ``.grad``, one point at a time (the slow path). The
    Variable's value is restored after each call."""

    kind = "cvxpy-grad"

    def __init__(self, expr: Any, x: Any, *, name: str = "cost") -> None:
        super().__init__(max(x.size, 1), name)
        self.expr, self.x = expr, x

    def _at(self, Z: np.ndarray, get: Any) -> list:
        saved = self.x.value
        try:
            out = []
            for z in Z:
                self.x.value = z.reshape(self.x.shape)
                out.append(get(z))
            return out
        finally:
            self.x.value = saved

    def _value(self, Z: np.ndarray) -> np.ndarray:
        return np.array(self._at(Z, lambda z: float(np.asarray(self.expr.value).reshape(()))))

    def _subgradient(self, Z: np.ndarray) -> np.ndarray:
        return np.array(self._at(Z, self._grad)).reshape(Z.shape)

    def _grad(self, z: np.ndarray) -> np.ndarray:
        try:
            g = self.expr.grad.get(self.x)
        except NotImplementedError:
            g = None
        if g is None:
            raise InputError(f"{self.name}: CVXPY has no gradient of {self.expr} at "
                             f"{z.tolist()}")
        return np.asarray(g.todense() if hasattr(g, "todense") else g, dtype=float).reshape(-1)
