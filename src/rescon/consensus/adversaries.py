"""What adversarial agents send (SPEC §3, §5; STYLE §8).

*Where* the adversaries are (F-local / F-total placement) is decided elsewhere
(:func:`rescon.graphs.attacks.check_attack_model`); this module only says *what*
they send. Every message is per ``(sender, receiver)``, so two-faced Byzantine
agents are first-class.

Protocol
--------
At step k the engine builds a :class:`StepView` and asks each adversary's
behaviour for ``messages(sender, receivers, view)``: an array of shape
``(len(receivers), d)``, row r being what ``sender`` sends to ``receivers[r]``.
A row with a non-finite entry (NaN by convention) means *nothing was sent*; the
engine treats it as a missing message.

Indices
-------
Behaviours work with the engine's **0-based agent indices**: ``sender``,
``receivers``, the rows of ``view.states`` and the ``receiver`` passed to a
:class:`TwoFaced` function are indices. The paper numbers its agents 1..12;
:func:`paper_adversaries` is keyed by those **paper labels** (2 and 12) and the
engine maps labels to indices.

Randomness
----------
Only ``view.rng`` (one seeded :class:`numpy.random.Generator`) is used, and
:func:`adversary_messages` calls senders in increasing index order, so the same
seed gives the same messages.
"""

from __future__ import annotations

import math
from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..errors import InputError
from ._config import check_keys

__all__ = [
    "Bait",
    "Behaviour",
    "Constant",
    "Crash",
    "FunctionOfTime",
    "NonFinite",
    "OwnState",
    "RandomInBox",
    "StepView",
    "TimePreset",
    "TwoFaced",
    "TwoFacedTable",
    "adversary_messages",
    "behaviour_from_dict",
    "paper_adversaries",
]


# --------------------------------------------------------------------------- #
# the per-step context
# --------------------------------------------------------------------------- #


@dataclass(frozen=True, eq=False)
class StepView:
    """What an adversary may look at in step k (an omniscient adversary).

    Attributes
    ----------
    k : int
        Step number, :math:`t_k = kT`.
    t : float
        Time :math:`t_k`.
    states : numpy.ndarray, shape (N, d)
        Current states of all agents; the adversaries' own rows are whatever the
        engine keeps there.
    benign : numpy.ndarray of bool, shape (N,)
    in_neighbours : list of numpy.ndarray of int
        ``in_neighbours[i]`` = indices of i's in-neighbours.
    rng : numpy.random.Generator
    """

    k: int
    t: float
    states: np.ndarray
    benign: np.ndarray
    in_neighbours: list[np.ndarray]
    rng: np.random.Generator

    def __post_init__(self) -> None:
        st = self.states
        if not isinstance(st, np.ndarray) or st.ndim != 2:
            raise InputError(f"states must be an (N, d) array; got {_shape_of(st)}")
        n = st.shape[0]
        b = self.benign
        if not isinstance(b, np.ndarray) or b.dtype != bool or b.shape != (n,):
            raise InputError(f"benign must be a bool array of shape ({n},); got {_shape_of(b)}")
        if len(self.in_neighbours) != n:
            raise InputError(
                f"in_neighbours must have one entry per agent ({n}); "
                f"got {len(self.in_neighbours)}"
            )
        if not isinstance(self.rng, np.random.Generator):
            raise InputError(f"rng must be a numpy.random.Generator; got {type(self.rng).__name__}")

    @property
    def N(self) -> int:
        """Number of agents."""
        return int(self.states.shape[0])

    @property
    def d(self) -> int:
        """State dimension."""
        return int(self.states.shape[1])

    def benign_in_neighbours(self, i: int) -> np.ndarray:
        """Indices of the benign in-neighbours of agent ``i``."""
        nb = np.asarray(self.in_neighbours[i], dtype=np.intp)
        return nb[self.benign[nb]]

    def benign_box(self, i: int) -> tuple[np.ndarray, np.ndarray] | None:
        """Per-coordinate (min, max) of the benign in-neighbours' states of ``i``.

        None when ``i`` has no benign in-neighbour.
        """
        nb = self.benign_in_neighbours(i)
        if nb.size == 0:
            return None
        pts = self.states[nb]
        return pts.min(axis=0), pts.max(axis=0)


def _shape_of(x: Any) -> str:
    if isinstance(x, np.ndarray):
        return f"shape {x.shape} dtype {x.dtype}"
    return type(x).__name__


# --------------------------------------------------------------------------- #
# behaviours
# --------------------------------------------------------------------------- #


class Behaviour(ABC):
    """What one adversary sends; see the module docstring for the protocol."""

    @abstractmethod
    def messages(self, sender: int, receivers: np.ndarray, view: StepView) -> np.ndarray:
        """Messages to ``receivers``: float array ``(len(receivers), d)``; NaN row = none."""

    @abstractmethod
    def to_dict(self) -> dict[str, Any]:
        """The TOML-style dict :func:`behaviour_from_dict` reads back (if expressible)."""


def _vector(name: str, value: Any, *, finite: bool = True) -> tuple[float, ...]:
    try:
        arr = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a 1-D list of numbers; got {value!r}") from None
    if arr.ndim != 1 or arr.size == 0:
        raise InputError(f"{name} must be a nonempty 1-D list of numbers; got shape {arr.shape}")
    if finite and not np.all(np.isfinite(arr)):
        raise InputError(f"{name} must be finite; got {arr.tolist()}")
    return tuple(float(v) for v in arr)


def _row(name: str, value: Any, d: int) -> np.ndarray:
    try:
        arr = np.atleast_1d(np.asarray(value, dtype=float))
    except (TypeError, ValueError):
        raise InputError(f"{name} must return a vector of {d} numbers; got {value!r}") from None
    if arr.shape != (d,):
        raise InputError(f"{name} must return a vector of shape ({d},); got shape {arr.shape}")
    return arr


def _receivers(receivers: Any) -> np.ndarray:
    return np.asarray(receivers, dtype=np.intp).reshape(-1)


def _real(name: str, value: Any, *, lo: float | None = None, strict: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise InputError(f"{name} must be a real number; got {value!r}")
    v = float(value)
    if not math.isfinite(v) or (lo is not None and (v <= lo if strict else v < lo)):
        rel = ">" if strict else ">="
        raise InputError(f"{name} must be a finite number {rel} {lo}; got {value!r}")
    return v


@dataclass(frozen=True)
class FunctionOfTime(Behaviour):
    """Send :math:`f(t_k) \\in \\mathbb{R}^d` to every receiver (a malicious agent
    following its own trajectory, e.g. the paper's :math:`x_2, x_{12}`).

    Parameters
    ----------
    f : callable ``f(t: float) -> array of shape (d,)``
        For TOML use :meth:`preset`.

    Examples
    --------
    >>> import numpy as np
    >>> from rescon.consensus.adversaries import _demo_view
    >>> b = FunctionOfTime.preset("paper_x12")
    >>> b.messages(0, np.array([1, 2]), _demo_view(t=0.0))
    array([[6., 0.],
           [6., 0.]])
    """

    f: Callable[[float], Any]

    def __post_init__(self) -> None:
        if not callable(self.f):
            raise InputError(f"f must be callable f(t) -> (d,) array; got {self.f!r}")

    @classmethod
    def preset(cls, name: str, **params: Any) -> FunctionOfTime:
        """A :class:`FunctionOfTime` from a named :class:`TimePreset`."""
        return cls(TimePreset(name, **params))

    def messages(self, sender: int, receivers: np.ndarray, view: StepView) -> np.ndarray:
        rec = _receivers(receivers)
        row = _row("FunctionOfTime.f", self.f(view.t), view.d)
        return np.tile(row, (rec.size, 1))

    def to_dict(self) -> dict[str, Any]:
        if isinstance(self.f, TimePreset):
            return {"kind": "function_of_time", **self.f.to_dict()}
        raise InputError("FunctionOfTime.to_dict needs f to be a TimePreset; got a callable")


class TimePreset:
    """Named trajectories :math:`t \\mapsto x(t)` usable from TOML.

    ==============  ==========================================================
    ``paper_x2``    :math:`(3\\sin t,\\ t + 2)` (paper, agent 2)
    ``paper_x12``   :math:`(6\\cos t,\\ 3t)` (paper, agent 12)
    ``sin``         :math:`x_p = c_p + a_p \\sin(\\omega_p t + \\phi_p)`; parameters
                    ``amplitude`` a (list, required), ``frequency`` ω (number or
                    list, default 1), ``phase`` φ (default 0), ``offset`` c
                    (default 0)
    ``linear``      :math:`x = x_0 + v t`; parameters ``start`` x0 and
                    ``velocity`` v (lists of equal length, required)
    ==============  ==========================================================

    Instances compare equal by name and parameters, so behaviours built from them
    are hashable and comparable.
    """

    _SPEC: ClassVar[dict[str, tuple[tuple[str, ...], tuple[str, ...]]]] = {
        "paper_x2": ((), ()),
        "paper_x12": ((), ()),
        "sin": (("amplitude",), ("frequency", "phase", "offset")),
        "linear": (("start", "velocity"), ()),
    }

    def __init__(self, name: str, **params: Any) -> None:
        if name not in self._SPEC:
            raise InputError(
                f"preset must be one of {sorted(self._SPEC)}; got {name!r}"
            )
        required, optional = self._SPEC[name]
        unknown = sorted(set(params) - set(required) - set(optional))
        if unknown:
            raise InputError(
                f"preset {name!r} has unknown parameter(s) {unknown}; "
                f"allowed: {sorted(required + optional)}"
            )
        missing = [k for k in required if k not in params]
        if missing:
            raise InputError(f"preset {name!r} is missing parameter(s) {missing}")
        self.name = name
        self._arrays: dict[str, np.ndarray] = {}
        if name == "sin":
            a = np.array(_vector("amplitude", params["amplitude"]))
            d = a.size
            self._arrays = {
                "amplitude": a,
                "frequency": self._broadcast("frequency", params.get("frequency", 1.0), d),
                "phase": self._broadcast("phase", params.get("phase", 0.0), d),
                "offset": self._broadcast("offset", params.get("offset", 0.0), d),
            }
        elif name == "linear":
            x0 = np.array(_vector("start", params["start"]))
            v = np.array(_vector("velocity", params["velocity"]))
            if x0.shape != v.shape:
                raise InputError(
                    f"preset 'linear' needs start and velocity of equal length; "
                    f"got {x0.size} and {v.size}"
                )
            self._arrays = {"start": x0, "velocity": v}
        self._key = (name, tuple((k, tuple(v.tolist())) for k, v in self._arrays.items()))

    @staticmethod
    def _broadcast(name: str, value: Any, d: int) -> np.ndarray:
        if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
            return np.full(d, _real(name, value))
        arr = np.array(_vector(name, value))
        if arr.size != d:
            raise InputError(f"{name} must be a number or a list of length {d}; got {arr.size}")
        return arr

    def __call__(self, t: float) -> np.ndarray:
        if self.name == "paper_x2":
            return np.array([3.0 * math.sin(t), t + 2.0])
        if self.name == "paper_x12":
            return np.array([6.0 * math.cos(t), 3.0 * t])
        a = self._arrays
        if self.name == "sin":
            return a["offset"] + a["amplitude"] * np.sin(a["frequency"] * t + a["phase"])
        return a["start"] + a["velocity"] * t

    def to_dict(self) -> dict[str, Any]:
        return {"preset": self.name, **{k: v.tolist() for k, v in self._arrays.items()}}

    def __eq__(self, other: object) -> bool:
        return isinstance(other, TimePreset) and other._key == self._key

    def __hash__(self) -> int:
        return hash(self._key)

    def __repr__(self) -> str:
        args = "".join(f", {k}={v.tolist()!r}" for k, v in self._arrays.items())
        return f"TimePreset({self.name!r}{args})"


@dataclass(frozen=True)
class TwoFaced(Behaviour):
    """Send :math:`f(t_k, r)` to receiver r: a different value to each receiver.

    Parameters
    ----------
    f : callable ``f(t: float, receiver: int) -> array of shape (d,)``
        ``receiver`` is the receiver's 0-based index.

    Examples
    --------
    >>> import numpy as np
    >>> from rescon.consensus.adversaries import _demo_view
    >>> b = TwoFaced(lambda t, r: np.array([r, -r]))
    >>> b.messages(0, np.array([1, 2]), _demo_view())
    array([[ 1., -1.],
           [ 2., -2.]])
    """

    f: Callable[[float, int], Any]

    def __post_init__(self) -> None:
        if not callable(self.f):
            raise InputError(f"f must be callable f(t, receiver) -> (d,) array; got {self.f!r}")

    def messages(self, sender: int, receivers: np.ndarray, view: StepView) -> np.ndarray:
        rec = _receivers(receivers)
        out = np.empty((rec.size, view.d))
        for r, i in enumerate(rec.tolist()):
            out[r] = _row("TwoFaced.f", self.f(view.t, i), view.d)
        return out

    def to_dict(self) -> dict[str, Any]:
        if isinstance(self.f, TwoFacedTable):
            return {"kind": "two_faced", **self.f.to_dict()}
        raise InputError("TwoFaced.to_dict needs f to be a TwoFacedTable; got a callable")


class TwoFacedTable:
    """Receiver-indexed values for :class:`TwoFaced` from TOML.

    ``TwoFacedTable(values={r: x_r, ...}, default=x)`` sends ``x_r`` to receiver r
    and ``default`` to everyone else (``default=None``: nothing, a NaN row);
    ``TwoFacedTable(cycle=[x_0, x_1, ...])`` sends ``x_{r mod len}`` to receiver r.
    Receivers are 0-based indices; TOML table keys (strings) are converted.
    """

    def __init__(self, *, values: Mapping[Any, Any] | None = None, default: Any = None,
                 cycle: Any = None) -> None:
        if (values is None) == (cycle is None):
            raise InputError("two_faced needs exactly one of 'values' or 'cycle'; "
                             f"got values={values!r}, cycle={cycle!r}")
        self._values: dict[int, tuple[float, ...]] = {}
        self._cycle: tuple[tuple[float, ...], ...] = ()
        self._default: tuple[float, ...] | None = None
        if values is not None:
            if not isinstance(values, Mapping):
                raise InputError(
                    f"values must be a table {{receiver: vector}}; got {type(values).__name__}"
                )
            for key, vec in values.items():
                try:
                    r = int(key)
                except (TypeError, ValueError):
                    raise InputError(
                        f"values keys must be receiver indices; got {key!r}"
                    ) from None
                self._values[r] = _vector(f"values[{key!r}]", vec)
            if default is not None:
                self._default = _vector("default", default)
            elif not self._values:
                raise InputError("two_faced 'values' is empty and there is no 'default'")
        else:
            if isinstance(cycle, (str, bytes)) or not hasattr(cycle, "__len__") or not cycle:
                raise InputError(f"cycle must be a nonempty list of vectors; got {cycle!r}")
            self._cycle = tuple(_vector(f"cycle[{k}]", v) for k, v in enumerate(cycle))
        dims = {len(v) for v in [*self._values.values(), *self._cycle]}
        if self._default is not None:
            dims.add(len(self._default))
        if len(dims) > 1:
            raise InputError("two_faced vectors must all have one length; got lengths "
                             f"{sorted(dims)}")

    def __call__(self, t: float, receiver: int) -> np.ndarray:
        if self._cycle:
            return np.array(self._cycle[receiver % len(self._cycle)])
        v = self._values.get(receiver, self._default)
        if v is None:
            d = len(next(iter(self._values.values()))) if self._values else 1
            return np.full(d, np.nan)
        return np.array(v)

    def to_dict(self) -> dict[str, Any]:
        if self._cycle:
            return {"cycle": [list(v) for v in self._cycle]}
        out: dict[str, Any] = {"values": {str(k): list(v) for k, v in self._values.items()}}
        if self._default is not None:
            out["default"] = list(self._default)
        return out

    def _key(self) -> tuple[Any, ...]:
        return (tuple(sorted(self._values.items())), self._cycle, self._default)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, TwoFacedTable) and other._key() == self._key()

    def __hash__(self) -> int:
        return hash(self._key())

    def __repr__(self) -> str:
        return f"TwoFacedTable({self.to_dict()!r})"


@dataclass(frozen=True)
class Constant(Behaviour):
    """A stubborn agent: send ``value`` to everyone at every step.

    Examples
    --------
    >>> import numpy as np
    >>> from rescon.consensus.adversaries import _demo_view
    >>> Constant([1.0, 2.0]).messages(0, np.array([1, 2]), _demo_view())
    array([[1., 2.],
           [1., 2.]])
    """

    value: tuple[float, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "value", _vector("value", self.value))

    def messages(self, sender: int, receivers: np.ndarray, view: StepView) -> np.ndarray:
        rec = _receivers(receivers)
        if len(self.value) != view.d:
            raise InputError(
                f"Constant value must have length d = {view.d}; got {len(self.value)}"
            )
        return np.tile(np.array(self.value), (rec.size, 1))

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "constant", "value": list(self.value)}


@dataclass(frozen=True)
class OwnState(Behaviour):
    """Send the sender's own row of ``view.states`` (its initial value, as long as
    the engine leaves adversaries' rows untouched). The default ``before`` of
    :class:`Crash`."""

    def messages(self, sender: int, receivers: np.ndarray, view: StepView) -> np.ndarray:
        rec = _receivers(receivers)
        return np.tile(np.asarray(view.states[sender], dtype=float), (rec.size, 1))

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "own_state"}


@dataclass(frozen=True)
class RandomInBox(Behaviour):
    """Uniform noise inside each receiver's (expanded) benign box.

    For receiver r let :math:`[\\ell, u] \\subset \\mathbb{R}^d` be the box of its
    benign in-neighbours' current states (per-coordinate min and max),
    :math:`c = (\\ell + u)/2`, :math:`h = (u - \\ell)/2`. The message is uniform in
    :math:`[c - s h,\\ c + s h]` with :math:`s` = ``scale`` (``scale > 1`` reaches
    outside the benign values, ``scale = 0`` sends the centre). A receiver with no
    benign in-neighbour gets nothing (NaN row). Draws one
    ``view.rng.random((len(receivers), d))`` per call.

    Parameters
    ----------
    scale : float, optional
        :math:`s \\ge 0`.
    """

    scale: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "scale", _real("scale", self.scale, lo=0.0))

    def messages(self, sender: int, receivers: np.ndarray, view: StepView) -> np.ndarray:
        rec = _receivers(receivers)
        u = view.rng.random((rec.size, view.d))
        out = np.full((rec.size, view.d), np.nan)
        for r, i in enumerate(rec.tolist()):
            box = view.benign_box(i)
            if box is None:
                continue
            lo, hi = box
            c, h = (lo + hi) / 2.0, self.scale * (hi - lo) / 2.0
            out[r] = c - h + 2.0 * h * u[r]
        return out

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "random_in_box", "scale": self.scale}


@dataclass(frozen=True)
class Bait(Behaviour):
    """A point just outside each receiver's benign box, to pull its safe kernel.

    For receiver r with benign box :math:`[\\ell, u]` (centre c, half-widths h,
    diameter :math:`D = \\|u - \\ell\\|_2`) and unit direction :math:`\\hat v`, the
    message is

    .. math::

        c + \\big(\\rho(\\hat v) + \\sigma D\\big)\\hat v, \\qquad
        \\rho(\\hat v) = \\min_{p:\\,\\hat v_p \\ne 0} h_p / |\\hat v_p|,

    i.e. the exit point of the ray from c through the box boundary, pushed a
    further :math:`\\sigma D` out (:math:`\\sigma` = ``strength``; when D = 0 the
    push is :math:`\\sigma` in absolute units). Default direction: away from the
    benign mean, :math:`\\hat v \\propto c - \\bar x_B` with :math:`\\bar x_B` the
    mean of all benign states; if that is 0, :math:`x_r - \\bar x_B`; if that is
    0 too, :math:`e_1`. A receiver with no benign in-neighbour gets nothing.

    Parameters
    ----------
    direction : sequence of float, optional
        Fixed direction (nonzero, length d), normalised here.
    strength : float, optional
        :math:`\\sigma \\ge 0`.

    Examples
    --------
    >>> import numpy as np
    >>> from rescon.consensus.adversaries import _demo_view
    >>> Bait(direction=[1.0, 0.0], strength=0.5).messages(0, np.array([3]), _demo_view())
    array([[1.5, 0. ]])
    """

    direction: tuple[float, ...] | None = None
    strength: float = 1.0

    def __post_init__(self) -> None:
        if self.direction is not None:
            v = np.array(_vector("direction", self.direction))
            n = float(np.linalg.norm(v))
            if n == 0:
                raise InputError(f"direction must be a nonzero vector; got {v.tolist()}")
            object.__setattr__(self, "direction", tuple((v / n).tolist()))
        object.__setattr__(self, "strength", _real("strength", self.strength, lo=0.0))

    def messages(self, sender: int, receivers: np.ndarray, view: StepView) -> np.ndarray:
        rec = _receivers(receivers)
        out = np.full((rec.size, view.d), np.nan)
        fixed = None
        if self.direction is not None:
            if len(self.direction) != view.d:
                raise InputError(
                    f"Bait direction must have length d = {view.d}; got {len(self.direction)}"
                )
            fixed = np.array(self.direction)
        mean = view.states[view.benign].mean(axis=0) if view.benign.any() else None
        for r, i in enumerate(rec.tolist()):
            box = view.benign_box(i)
            if box is None:
                continue
            lo, hi = box
            c, h = (lo + hi) / 2.0, (hi - lo) / 2.0
            v = fixed if fixed is not None else self._away(c, view.states[i], mean, view.d)
            nz = v != 0
            rho = float(np.min(h[nz] / np.abs(v[nz])))
            diam = float(np.linalg.norm(hi - lo))
            push = self.strength * (diam if diam > 0 else 1.0)
            out[r] = c + (rho + push) * v
        return out

    @staticmethod
    def _away(c: np.ndarray, x: np.ndarray, mean: np.ndarray | None, d: int) -> np.ndarray:
        if mean is not None:
            for v in (c - mean, np.asarray(x, dtype=float) - mean):
                n = float(np.linalg.norm(v))
                if n > 0 and math.isfinite(n):
                    return v / n
        e = np.zeros(d)
        e[0] = 1.0
        return e

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"kind": "bait", "strength": self.strength}
        if self.direction is not None:
            out["direction"] = list(self.direction)
        return out


@dataclass(frozen=True)
class Crash(Behaviour):
    """Behave like ``before`` for steps :math:`k <` ``at_step``, then send nothing.

    Parameters
    ----------
    at_step : int
        First silent step (``0``: never sends).
    before : Behaviour, optional
        Default :class:`OwnState` (the sender's own row, i.e. a constant initial
        value when the engine does not overwrite adversaries' rows); pass
        ``Constant(x0)`` to fix the value explicitly.

    Examples
    --------
    >>> import numpy as np
    >>> from rescon.consensus.adversaries import _demo_view
    >>> b = Crash(2, Constant([1.0, 1.0]))
    >>> b.messages(0, np.array([1]), _demo_view(k=1)), b.messages(0, np.array([1]), _demo_view(k=2))
    (array([[1., 1.]]), array([[nan, nan]]))
    """

    at_step: int
    before: Behaviour = OwnState()

    def __post_init__(self) -> None:
        k = self.at_step
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 0:
            raise InputError(f"at_step must be a nonnegative integer; got {k!r}")
        object.__setattr__(self, "at_step", int(k))
        if not isinstance(self.before, Behaviour):
            raise InputError(f"before must be a Behaviour; got {type(self.before).__name__}")

    def messages(self, sender: int, receivers: np.ndarray, view: StepView) -> np.ndarray:
        if view.k < self.at_step:
            return self.before.messages(sender, receivers, view)
        return np.full((_receivers(receivers).size, view.d), np.nan)

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "crash", "at_step": self.at_step, "before": self.before.to_dict()}


_NONFINITE = {"nan": (math.nan,), "inf": (math.inf,), "-inf": (-math.inf,),
              "mixed": (math.nan, math.inf, -math.inf)}


@dataclass(frozen=True)
class NonFinite(Behaviour):
    """Send non-finite values: ``"nan"``, ``"inf"``, ``"-inf"`` or ``"mixed"``
    (entry (r, p) is ``[nan, inf, -inf][(r + p) % 3]``). Tests the engine's
    handling of garbage: any non-finite row counts as *nothing sent*.

    Examples
    --------
    >>> import numpy as np
    >>> from rescon.consensus.adversaries import _demo_view
    >>> NonFinite("mixed").messages(0, np.array([1, 2]), _demo_view())
    array([[ nan,  inf],
           [ inf, -inf]])
    """

    kind: str = "nan"

    def __post_init__(self) -> None:
        if self.kind not in _NONFINITE:
            raise InputError(f"kind must be one of {sorted(_NONFINITE)}; got {self.kind!r}")

    def messages(self, sender: int, receivers: np.ndarray, view: StepView) -> np.ndarray:
        n = _receivers(receivers).size
        vals = np.array(_NONFINITE[self.kind])
        idx = (np.arange(n)[:, None] + np.arange(view.d)[None, :]) % vals.size
        return vals[idx]

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "nonfinite", "value": self.kind}


# --------------------------------------------------------------------------- #
# construction from TOML-style dicts, and the paper's adversaries
# --------------------------------------------------------------------------- #


_KINDS = ("bait", "constant", "crash", "function_of_time", "nonfinite", "own_state",
          "random_in_box", "two_faced")


def behaviour_from_dict(d: Mapping[str, Any]) -> Behaviour:
    """Build a behaviour from a TOML-style dict.

    ==================== =============================================================
    ``kind``             other keys
    ==================== =============================================================
    ``constant``         ``value`` (list)
    ``function_of_time`` ``preset`` (``paper_x2``, ``paper_x12``, ``sin``,
                         ``linear``) and that preset's parameters (:class:`TimePreset`)
    ``two_faced``        ``values`` (table receiver index → list) with optional
                         ``default``, or ``cycle`` (list of lists); see
                         :class:`TwoFacedTable`
    ``random_in_box``    ``scale`` (optional)
    ``bait``             ``direction``, ``strength`` (optional)
    ``crash``            ``at_step``, ``before`` (optional, a behaviour dict)
    ``nonfinite``        ``value``: ``"nan"``, ``"inf"``, ``"-inf"`` or ``"mixed"``
    ``own_state``        —
    ==================== =============================================================

    Arbitrary expressions for :math:`f(t)` are deliberately not parsed.

    Raises
    ------
    InputError
        Not a dict, unknown ``kind``, unknown or missing keys, or bad values.

    Examples
    --------
    >>> behaviour_from_dict({"kind": "constant", "value": [1, 2]})
    Constant(value=(1.0, 2.0))
    >>> behaviour_from_dict({"kind": "function_of_time", "preset": "linear",
    ...                      "start": [0, 0], "velocity": [1, 0]}).f(2.0)
    array([2., 0.])
    """
    if not isinstance(d, Mapping):
        raise InputError(f"behaviour must be a dict with a 'kind'; got {type(d).__name__}")
    kind = d.get("kind")
    if kind not in _KINDS:
        raise InputError(f"behaviour kind must be one of {list(_KINDS)}; got {kind!r}")
    if kind == "constant":
        check_keys("constant behaviour", d, ("value",))
        return Constant(d["value"])
    if kind == "function_of_time":
        if "preset" not in d:
            raise InputError("function_of_time behaviour is missing key(s) ['preset']")
        params = {k: v for k, v in d.items() if k not in ("kind", "preset")}
        return FunctionOfTime(TimePreset(d["preset"], **params))
    if kind == "two_faced":
        check_keys("two_faced behaviour", d, (), ("values", "default", "cycle"))
        return TwoFaced(TwoFacedTable(values=d.get("values"), default=d.get("default"),
                                      cycle=d.get("cycle")))
    if kind == "random_in_box":
        check_keys("random_in_box behaviour", d, (), ("scale",))
        return RandomInBox(d.get("scale", 1.0))
    if kind == "bait":
        check_keys("bait behaviour", d, (), ("direction", "strength"))
        return Bait(d.get("direction"), d.get("strength", 1.0))
    if kind == "crash":
        check_keys("crash behaviour", d, ("at_step",), ("before",))
        before = behaviour_from_dict(d["before"]) if "before" in d else OwnState()
        return Crash(d["at_step"], before)
    if kind == "nonfinite":
        check_keys("nonfinite behaviour", d, ("value",))
        return NonFinite(d["value"])
    check_keys("own_state behaviour", d, ())
    return OwnState()


def paper_adversaries() -> dict[int, Behaviour]:
    """The paper's two malicious agents, keyed by **paper label** (agents 1..12).

    Agent 2 sends :math:`x_2(t_k) = (3\\sin t_k,\\ t_k + 2)` and agent 12 sends
    :math:`x_{12}(t_k) = (6\\cos t_k,\\ 3t_k)` to all out-neighbours (SPEC §5: the
    paper's text says "2 and 3", but its table lists 3 as benign and gives
    :math:`x_{12}`). Keys are the paper's 1-based labels, not engine indices.

    Examples
    --------
    >>> sorted(paper_adversaries())
    [2, 12]
    """
    return {2: FunctionOfTime(TimePreset("paper_x2")),
            12: FunctionOfTime(TimePreset("paper_x12"))}


def adversary_messages(behaviours: Mapping[int, Behaviour],
                       out_neighbours: Mapping[int, Any],
                       view: StepView) -> dict[int, np.ndarray]:
    """All adversaries' messages for one step.

    Parameters
    ----------
    behaviours : dict index -> Behaviour
        Keyed by the senders' 0-based indices.
    out_neighbours : dict index -> array of int
        Receivers of each sender (missing: no receivers).
    view : StepView

    Returns
    -------
    dict index -> numpy.ndarray of float, shape ``(len(out_neighbours[s]), d)``
        Senders are processed in increasing index order, so the draws from
        ``view.rng`` do not depend on dict order.

    Raises
    ------
    InputError
        A sender index out of range, a behaviour that is not a Behaviour, or a
        behaviour returning the wrong shape.
    """
    out: dict[int, np.ndarray] = {}
    for s in sorted(behaviours):
        b = behaviours[s]
        if not isinstance(b, Behaviour):
            raise InputError(f"behaviours[{s!r}] must be a Behaviour; got {type(b).__name__}")
        if not 0 <= int(s) < view.N:
            raise InputError(f"behaviours key {s!r} must be an agent index in [0, {view.N})")
        rec = _receivers(out_neighbours.get(s, np.empty(0, dtype=np.intp)))
        raw = b.messages(int(s), rec, view)
        try:
            msg = np.asarray(raw, dtype=float)
        except (TypeError, ValueError):
            raise InputError(f"{type(b).__name__} of sender {s} must return real numbers, "
                             f"shape ({rec.size}, {view.d}); got {_summary(raw)}") from None
        if msg.shape != (rec.size, view.d):
            raise InputError(
                f"{type(b).__name__} of sender {s} must return shape ({rec.size}, {view.d}); "
                f"got {msg.shape}"
            )
        out[int(s)] = msg
    return out


def _demo_view(k: int = 0, t: float = 0.0, seed: int = 0) -> StepView:
    """A 4-agent view for the examples: agent 0 adversarial at (9, 9); 1, 2, 3
    benign at (0, 0), (1, 0), (0, 1); everyone hears everyone."""
    states = np.array([[9.0, 9.0], [0.0, 0.0], [1.0, 0.0], [0.0, 1.0]])
    nbrs = [np.array([j for j in range(4) if j != i]) for i in range(4)]
    return StepView(k, t, states, np.array([False, True, True, True]), nbrs,
                    np.random.default_rng(seed))


def _summary(value: Any) -> str:
    """A short description of what a behaviour returned, for an error message."""
    text = repr(value)
    return text if len(text) <= 60 else f"{type(value).__name__} {text[:57]}..."
