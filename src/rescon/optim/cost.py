"""``rescon.cost``: one adapter for every way a user writes a convex cost."""

from __future__ import annotations

from typing import Any

from .. import _validate
from ..errors import InputError
from .oracle import CallableOracle, Oracle, SubgradientOracle

__all__ = ["cost"]


def cost(spec: Any, *, x: Any = None, d: int | None = None, vectorised: bool = False,
         name: str = "cost") -> Oracle:
    """The subgradient oracle of a convex cost, whatever its source.

    Parameters
    ----------
    spec
        * an expression string over ``x1, x2, …`` (the grammar of
          :mod:`rescon.optim.expr`; convexity is checked);
        * a CasADi SX/MX expression in the symbol ``x`` (a d-vector), or a CasADi
          ``Function`` of one d-vector (:mod:`rescon.optim.casadi_adapter`);
        * a CVXPY expression in the Variable ``x`` (:mod:`rescon.optim.cvxpy_adapter`);
        * a pair of callables ``(f, subgrad)``: per point (default) or on stacked points
          (``vectorised=True``);
        * an :class:`~rescon.optim.oracle.Oracle` (returned as is), or any object with
          ``value``/``subgradient``/``d`` (wrapped so its answers are checked).
    x : the CasADi symbol or CVXPY Variable ``spec`` is written in (CasADi: found from
        the expression when it has exactly one symbol — an MX vector, or one scalar SX;
        an SX vector's entries are separate symbols, so give x there).
    d : the dimension (an expression may use fewer variables than d; a callable pair
        without d accepts any dimension).
    vectorised : for a pair of callables, whether they take stacked points.
    name : how error messages call this cost (e.g. ``"cost of agent 3"``).

    Raises
    ------
    InputError
        A malformed or non-convex cost, or a dimension that disagrees with ``d``.
    SolverNotFound
        A CasADi or CVXPY object without the package installed (names what to install).

    Examples
    --------
    >>> import rescon
    >>> f = rescon.cost("abs(x1 + x2) + (x1 - 1)^2")
    >>> f.value([[1.0, 2.0]]).tolist(), f.subgradient([[1.0, -1.0]]).tolist()
    ([3.0], [[0.0, 0.0]])
    """
    if d is not None:
        d = _validate.integer("d", d, low=1)
    vectorised = _validate.flag("vectorised", vectorised)  # checked for every spec
    if isinstance(spec, Oracle):
        return _dimension(spec, d, name)
    if isinstance(spec, str):
        from .expr import expression_cost

        return expression_cost(spec, d=d, name=name)
    if isinstance(spec, tuple) and len(spec) == 2:
        return CallableOracle(spec[0], spec[1], d=d, vectorised=vectorised, name=name)
    module = type(spec).__module__.split(".")[0]
    if module == "casadi":
        from .casadi_adapter import casadi_cost

        return _dimension(casadi_cost(spec, x=x, d=d, name=name), d, name)
    if module == "cvxpy":
        from .cvxpy_adapter import cvxpy_cost

        return _dimension(cvxpy_cost(spec, x=x, name=name), d, name)
    if isinstance(spec, SubgradientOracle):
        return CallableOracle(spec.value, spec.subgradient, d=d if d is not None else spec.d,
                              vectorised=True, name=name)
    raise InputError(f"{name}: cannot make a cost of {type(spec).__name__} (give an expression "
                     f"string, a CasADi or CVXPY expression, a pair (f, subgrad) or an Oracle)")


def _dimension(o: Oracle, d: int | None, name: str) -> Oracle:
    if d is not None and o.d is not None and o.d != d:
        raise InputError(f"{name}: the cost has dimension {o.d}, not d = {d}")
    return o
