"""Subgradient oracles: one small protocol on stacked points, and its checks.

An oracle for a convex f : R^d → R answers, for B stacked points Z ∈ R^{B×d},

* ``value(Z)`` → f(z_b) for every row, shape (B,);
* ``subgradient(Z)`` → one g_b ∈ ∂f(z_b) per row, shape (B, d).

:class:`Oracle` is the base every adapter derives from: its public methods check the
points (finite, 2-D, the oracle's dimension) and what the implementation returns
(shape, finiteness) so that nothing malformed reaches a simulation; subclasses only
write ``_value`` and ``_subgradient``. :func:`check_subgradient` measures the
subgradient inequality f(y) ≥ f(x) + gᵀ(y − x) on samples around given points.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, Protocol, runtime_checkable

import numpy as np

from .. import _validate
from ..errors import InputError

__all__ = ["CallableOracle", "Oracle", "SubgradientOracle", "check_subgradient"]


@runtime_checkable
class SubgradientOracle(Protocol):
    """What the RMDO engine needs of a cost: ``d`` (or None: any dimension),
    ``value(Z) -> (B,)`` and ``subgradient(Z) -> (B, d)``."""

    d: int | None

    def value(self, Z: Any) -> np.ndarray: ...

    def subgradient(self, Z: Any) -> np.ndarray: ...


class Oracle:
    """Base class of every rescon oracle.

    Attributes
    ----------
    d : int or None
        The dimension of x (None: the oracle accepts any dimension).
    name : str
        How error messages call this cost (e.g. ``"cost of agent 3"``).
    kind : str
        The adapter that made it: "atom", "expression", "callable", "casadi", "cvxpy"
        ("cvxpy-grad" for a summand CVXPY evaluates itself). CasADi and CVXPY oracles
        also say which ``path`` they took ("lowered" to atoms, "ad", "grad", "mixed").
    quadratic, polyhedral : bool
        f is a convex quadratic polynomial (argmin by linear algebra) / a polyhedral
        function (argmin by an LP). Only atoms and their sums say True.
    """

    kind = "oracle"
    quadratic = False
    polyhedral = False

    def __init__(self, d: int | None, name: str = "cost") -> None:
        self.d = d
        self.name = name

    # -- the protocol ----------------------------------------------------- #

    def value(self, Z: Any) -> np.ndarray:
        """f at every row of ``Z`` (B, d) → (B,)."""
        Z = self._points(Z)
        return self._checked("value", self._value(Z), (Z.shape[0],), Z)

    def subgradient(self, Z: Any) -> np.ndarray:
        """One subgradient per row of ``Z`` (B, d) → (B, d)."""
        Z = self._points(Z)
        return self._checked("subgradient", self._subgradient(Z), Z.shape, Z)

    # -- what subclasses write -------------------------------------------- #

    def _value(self, Z: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _subgradient(self, Z: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    # -- checks ------------------------------------------------------------ #

    def _points(self, Z: Any) -> np.ndarray:
        """``Z`` as a finite float (B, d) array of this oracle's dimension."""
        try:
            if np.iscomplexobj(Z):
                raise TypeError
            A = np.asarray(Z, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{self.name}: points must be a real (B, d) array; "
                             f"got {type(Z).__name__}") from None
        if A.ndim != 2 or (self.d is not None and A.shape[1] != self.d):
            want = f"(B, {self.d})" if self.d is not None else "(B, d)"
            raise InputError(f"{self.name}: points must be a {want} array; got shape {A.shape}")
        if not np.isfinite(A).all():
            raise InputError(f"{self.name}: points must be finite; got {_first_bad(A)}")
        return A

    def _checked(self, what: str, out: Any, shape: tuple, Z: np.ndarray) -> np.ndarray:
        """``out`` as a float array of ``shape`` with finite entries, or InputError
        naming the oracle, what it returned and at which point."""
        try:
            R = _real(out)
        except (TypeError, ValueError):
            raise InputError(f"{self.name}: {what} returned {type(out).__name__}, "
                             f"not a real array") from None
        if R.shape != tuple(shape):
            raise InputError(f"{self.name}: {what} of {Z.shape[0]} point(s) returned shape "
                             f"{R.shape}; expected {tuple(shape)}")
        if R.size == 0:
            return R
        bad = ~np.isfinite(R.reshape(Z.shape[0], -1)).all(axis=1)
        if bad.any():
            b = int(np.argmax(bad))
            raise InputError(f"{self.name}: {what} is not finite ({R[b].tolist()}) at "
                             f"point {Z[b].tolist()}")
        return R

    def __repr__(self) -> str:
        return f"<{type(self).__name__} {self.name!r} d={self.d}>"


def _real(out: Any) -> np.ndarray:
    """``out`` as a float array; TypeError for complex numbers (numpy would drop their
    imaginary part with a warning), ValueError for what is not numbers."""
    if np.iscomplexobj(out):
        raise TypeError("complex")
    return np.asarray(out, dtype=float)


def _first_bad(A: np.ndarray) -> str:
    idx = tuple(int(i) for i in np.argwhere(~np.isfinite(A))[0])
    return f"{A[idx]} at index {idx}"


class CallableOracle(Oracle):
    """A pair of user callables (f, subgrad).

    ``vectorised=False``: f(x) → float and subgrad(x) → (d,) for one point x (d,), called
    once per row. ``vectorised=True``: f(Z) → (B,) and subgrad(Z) → (B, d) on stacked
    points. Returned values are checked (shape, finiteness) like every oracle's.
    """

    kind = "callable"

    def __init__(self, f: Callable, subgrad: Callable, *, d: int | None = None,
                 vectorised: bool = False, name: str = "cost") -> None:
        if not callable(f) or not callable(subgrad):
            raise InputError(f"{name}: a pair of callables (f, subgrad) is needed; got "
                             f"({type(f).__name__}, {type(subgrad).__name__})")
        vectorised = _validate.flag("vectorised", vectorised)
        super().__init__(None if d is None else _validate.integer("d", d, low=1), name)
        self.f, self.g, self.vectorised = f, subgrad, vectorised

    def _value(self, Z: np.ndarray) -> Any:
        if self.vectorised:
            return self.f(Z)
        return [self._scalar(self.f(z), z) for z in Z]

    def _subgradient(self, Z: np.ndarray) -> Any:
        if self.vectorised:
            return self.g(Z)
        out = [self._array("subgradient", self.g(z), z) for z in Z]
        for z, g in zip(Z, out):
            if g.shape != z.shape:
                raise InputError(f"{self.name}: subgradient returned shape {g.shape} at point "
                                 f"{z.tolist()}; expected {z.shape}")
        return np.array(out).reshape(Z.shape)

    def _array(self, what: str, v: Any, z: np.ndarray) -> np.ndarray:
        """One point's answer as a float array (InputError for a complex one)."""
        try:
            return _real(v)
        except (TypeError, ValueError):
            raise InputError(f"{self.name}: {what} returned {type(v).__name__} at point "
                             f"{z.tolist()}, not a real array") from None

    def _scalar(self, v: Any, z: np.ndarray) -> float:
        a = self._array("value", v, z)
        if a.size != 1:
            raise InputError(f"{self.name}: value returned shape {a.shape} at point "
                             f"{z.tolist()}; expected a number")
        return float(a.reshape(()))


def check_subgradient(oracle: Any, points: Any, *, samples: int = 64, seed: int = 0) -> float:
    """The worst violation of the subgradient inequality found around ``points``.

    For every point x (a row of ``points``) with g = ``oracle.subgradient(x)``, sample
    y = x + s·u (u uniform on the unit sphere, s on a log grid from 10⁻⁶ to 10 times
    1 + ‖x‖∞, so kinks are probed at every scale) and return

        max over x, y of  f(x) + gᵀ(y − x) − f(y),

    which is ≤ 0 up to rounding (a few ulps of the values involved) exactly when every
    returned g is a subgradient on the samples. A positive number is a measured
    violation, not an estimate.

    Parameters
    ----------
    oracle : anything :func:`rescon.cost` accepts
    points : array (B, d)
    samples : int, number of y per point (≥ 1)
    seed : int ≥ 0, for the sample directions (one ``numpy.random.Generator``)

    Examples
    --------
    >>> import rescon
    >>> f = rescon.cost("norm2(x1, x2)")
    >>> rescon.check_subgradient(f, [[0.0, 0.0], [1.0, -2.0]]) <= 1e-12
    True
    """
    from .cost import cost

    o = cost(oracle)
    n = _validate.integer("samples", samples, low=1)
    rng = np.random.default_rng(_validate.integer("seed", seed, low=0))
    X = o._points(points)
    if not len(X):
        raise InputError("points must hold at least one point; got shape (0, d)")
    fx, G = o.value(X), o.subgradient(X)
    B, d = X.shape
    U = rng.standard_normal((B, n, d))
    U /= np.maximum(np.linalg.norm(U, axis=2, keepdims=True), 1e-300)
    scale = np.logspace(-6, 1, n) * (1.0 + np.abs(X).max(axis=1, initial=0.0))[:, None]
    Y = X[:, None, :] + scale[:, :, None] * U
    fy = o.value(Y.reshape(B * n, d)).reshape(B, n)
    lin = fx[:, None] + np.einsum("bd,bnd->bn", G, Y - X[:, None, :])
    return float((lin - fy).max())
