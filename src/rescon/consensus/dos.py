"""Denial-of-service (DoS) attacks on links, and the check of Assumption 3 (SPEC §3, §5).

Conventions
-----------
* A **link** ``(i, j)`` is *agent i's link from j*: i receives j's state over it
  (the paper's edge :math:`e_{ij}` and the ``(i, j)`` of its table, SPEC §5). In the
  graph convention of SPEC §1 it is the DiGraph edge ``(j, i)``.
* Time is continuous, :math:`t \\ge 0`; the engine samples it at :math:`t_k = kT`.
* The m-th attack of a schedule occupies the **half-open** window
  :math:`[h_m, h_m + \\tau_m)`: a link is blocked at :math:`h_m` and free again at
  :math:`h_m + \\tau_m`. (The paper writes closed intervals; the endpoints have
  measure zero, so Assumption 3 is unaffected, and half-open windows make "blocked
  at :math:`t_k`" unambiguous when a window ends exactly on a sampling instant.)

A :class:`DoSAttack` is a named set of links plus a schedule. Schedules are
:class:`Periodic`, :class:`Explicit` and :class:`RandomDoS`; each has
``windows(horizon)`` and ``active(t)``.

Assumption 3 (DoS duration). With :math:`\\Pi_D` the set of instants at which at
least one link is blocked (the union of all windows of all attacks),

.. math::

    |\\Pi_D \\cap [t_1, t_2]| \\le \\mu_d + \\frac{t_2 - t_1}{T_d}
    \\qquad \\forall\\, 0 \\le t_1 \\le t_2, \\quad T_d > 1,\\ \\mu_d > 0.

:func:`check_assumption3` decides it exactly (rational arithmetic) on a finite
horizon and, for periodic and explicit schedules, for all time.

The paper's DoS timing
----------------------
The paper's DoS_1..DoS_3 are drawn in a figure ("Types of DoS Attacks") that is
missing from the source, and its text even speaks of four types while the table
uses three. Their timing is therefore **unknown**; :func:`paper_schedules` supplies
three documented periodic schedules chosen to satisfy Assumption 3, and
:func:`paper_attacks` attaches them to exactly the links of the paper's table.
"""

from __future__ import annotations

import bisect
import math
from abc import ABC, abstractmethod
from collections.abc import Hashable, Iterable, Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from .._validate import integer, nonnegative, positive, real
from ..errors import InputError
from ._config import check_keys

__all__ = [
    "PAPER_MU_D",
    "PAPER_T_D",
    "Assumption3Report",
    "Assumption3Witness",
    "DoSAttack",
    "Explicit",
    "Periodic",
    "RandomDoS",
    "Schedule",
    "attack_from_dict",
    "blocked_links",
    "blocked_mask",
    "blocked_mask_series",
    "check_assumption3",
    "paper_attacks",
    "paper_schedules",
    "schedule_from_dict",
]

Link = tuple[Hashable, Hashable]

#: Largest number of windows the exact long-run analysis of periodic schedules will
#: enumerate (over ``[0, o + 2H]``, H the hyperperiod); beyond it the long-run
#: quantities are reported as unknown.
_LONG_RUN_MAX_WINDOWS = 200_000

#: Largest number of windows :func:`check_assumption3` will enumerate on
#: ``[0, horizon]`` (exact rationals); beyond it the finite-horizon quantities
#: (``holds``, ``witness``, ``min_mu_d``, ``windows``, ``total_blocked``) are reported
#: as unknown (None), never guessed, except for a single periodic schedule (closed
#: form). The long-run answer does not depend on it.
_HORIZON_MAX_WINDOWS = 200_000


# --------------------------------------------------------------------------- #
# input validation
# --------------------------------------------------------------------------- #


def _merge(windows: Iterable[tuple[Any, Any]]) -> list[tuple[Any, Any]]:
    """Sort and merge overlapping or touching half-open windows."""
    out: list[list[Any]] = []
    for s, e in sorted(windows):
        if out and s <= out[-1][1]:
            out[-1][1] = max(out[-1][1], e)
        else:
            out.append([s, e])
    return [(s, e) for s, e in out]


# --------------------------------------------------------------------------- #
# schedules
# --------------------------------------------------------------------------- #


class Schedule(ABC):
    """When an attack is on: a union of half-open windows :math:`[h_m, h_m + \\tau_m)`."""

    @abstractmethod
    def windows(self, horizon: float) -> list[tuple[float, float]]:
        """Sorted attack windows ``(start, end)`` that intersect ``[0, horizon)``."""

    @abstractmethod
    def active(self, t: float) -> bool:
        """Is ``t`` inside an attack window (``start <= t < end``)?"""

    @abstractmethod
    def to_dict(self) -> dict[str, Any]:
        """The TOML-style dict :func:`schedule_from_dict` reads back."""

    def _exact_windows(self, horizon: Fraction) -> list[tuple[Fraction, Fraction]]:
        """Windows with start < horizon, in exact rational arithmetic (not merged)."""
        return [(Fraction(s), Fraction(e)) for s, e in self.windows(float(horizon))
                if Fraction(s) < horizon]


@dataclass(frozen=True)
class Periodic(Schedule):
    """Attacks :math:`[o + m p,\\ o + m p + \\tau)`, :math:`m = 0, 1, \\dots`

    Parameters
    ----------
    period : float
        :math:`p > 0`.
    duration : float
        :math:`\\tau`, with :math:`0 < \\tau \\le p` (``duration == period`` blocks
        everything from ``offset`` on).
    offset : float, optional
        :math:`o \\ge 0`, the start of the first attack.

    Notes
    -----
    The long-run blocked fraction is :math:`\\tau / p`. ``windows`` and ``active``
    compute endpoints in floating point as ``offset + m * period`` (and
    ``+ duration``), consistently with each other; :func:`check_assumption3`
    uses the exact rational values of the three parameters.

    Examples
    --------
    >>> s = Periodic(period=4.0, duration=1.0, offset=0.5)
    >>> s.windows(9.0)
    [(0.5, 1.5), (4.5, 5.5), (8.5, 9.5)]
    >>> s.active(1.5), s.active(4.5)
    (False, True)
    """

    period: float
    duration: float
    offset: float = 0.0

    def __post_init__(self) -> None:
        period = positive("period", self.period)
        duration = positive("duration", self.duration)
        offset = nonnegative("offset", self.offset)
        if duration > period:
            raise InputError(
                f"duration must be <= period; got duration={duration!r} > period={period!r}"
            )
        object.__setattr__(self, "period", period)
        object.__setattr__(self, "duration", duration)
        object.__setattr__(self, "offset", offset)

    @property
    def fraction(self) -> float:
        """Long-run blocked fraction :math:`\\tau / p`."""
        return self.duration / self.period

    def windows(self, horizon: float) -> list[tuple[float, float]]:
        horizon = nonnegative("horizon", horizon)
        if horizon <= self.offset:
            return []
        n = math.ceil((horizon - self.offset) / self.period) + 1
        out = []
        for m in range(n):
            s = self.offset + m * self.period
            if s >= horizon:
                break
            out.append((s, s + self.duration))
        return out

    def active(self, t: float) -> bool:
        t = nonnegative("t", t)
        if t < self.offset:
            return False
        m = math.floor((t - self.offset) / self.period)
        for mm in (m - 1, m, m + 1):
            if mm >= 0:
                s = self.offset + mm * self.period
                if s <= t < s + self.duration:
                    return True
        return False

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "periodic", "period": self.period, "duration": self.duration,
                "offset": self.offset}

    def _exact_windows(self, horizon: Fraction) -> list[tuple[Fraction, Fraction]]:
        p, tau, o = Fraction(self.period), Fraction(self.duration), Fraction(self.offset)
        out = []
        s = o
        while s < horizon:
            out.append((s, s + tau))
            s += p
        return out


@dataclass(frozen=True)
class Explicit(Schedule):
    """Attacks on given windows ``[(start, end), ...]``, ``0 <= start < end``.

    Overlapping or touching windows are merged (``[0, 1)`` and ``[1, 2)`` become
    ``[0, 2)``); the stored ``windows`` attribute is the merged, sorted tuple.

    Examples
    --------
    >>> Explicit([(3, 4), (0, 1), (0.5, 2)]).windows(10)
    [(0.0, 2.0), (3.0, 4.0)]
    """

    intervals: tuple[tuple[float, float], ...]

    def __init__(self, windows: Iterable[Any]) -> None:
        if isinstance(windows, (str, bytes)) or not isinstance(windows, Iterable):
            raise InputError(
                f"windows must be a list of (start, end) pairs; got {type(windows).__name__}"
            )
        clean = []
        for k, w in enumerate(windows):
            try:
                s, e = w
            except (TypeError, ValueError):
                raise InputError(
                    f"windows[{k}] must be a (start, end) pair; got {w!r}"
                ) from None
            s = nonnegative(f"windows[{k}] start", s)
            e = nonnegative(f"windows[{k}] end", e)
            if not s < e:
                raise InputError(f"windows[{k}] must have start < end; got ({s!r}, {e!r})")
            clean.append((s, e))
        object.__setattr__(self, "intervals", tuple(_merge(clean)))

    def windows(self, horizon: float) -> list[tuple[float, float]]:
        horizon = nonnegative("horizon", horizon)
        return [w for w in self.intervals if w[0] < horizon]

    def active(self, t: float) -> bool:
        t = nonnegative("t", t)
        k = bisect.bisect_right(self.intervals, (t, math.inf)) - 1
        return k >= 0 and t < self.intervals[k][1]

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "explicit", "windows": [list(w) for w in self.intervals]}


_CHUNK = 256  # arrivals drawn per refill; fixed, so the stream never depends on horizons


@dataclass(frozen=True)
class RandomDoS(Schedule):
    """Poisson arrivals of rate :math:`\\lambda` with exponential durations of mean
    :math:`\\bar\\tau`; overlapping attacks merge.

    Arrival times :math:`h_1 < h_2 < \\dots` have i.i.d. gaps
    :math:`\\mathrm{Exp}(\\lambda)` from 0, durations are i.i.d.
    :math:`\\mathrm{Exp}(1/\\bar\\tau)`, drawn in fixed-size chunks from
    ``numpy.random.default_rng(seed)``. Windows are generated lazily and cached;
    the same seed gives the same windows, and ``windows(h1)`` is the prefix of
    ``windows(h2)`` for ``h1 <= h2`` (a window is only returned once no later
    arrival can extend it).

    The link is blocked while at least one attack is on (an
    :math:`M/M/\\infty` queue is busy), so the long-run blocked fraction is
    :math:`1 - e^{-\\lambda \\bar\\tau}` almost surely.

    Parameters
    ----------
    rate : float
        :math:`\\lambda > 0`, arrivals per unit time.
    mean_duration : float
        :math:`\\bar\\tau > 0`.
    seed : int
        Nonnegative seed.

    Examples
    --------
    >>> s = RandomDoS(rate=0.2, mean_duration=1.0, seed=7)
    >>> s.windows(50.0) == s.windows(100.0)[:len(s.windows(50.0))]
    True
    """

    rate: float
    mean_duration: float
    seed: int
    _cache: dict[str, Any] = field(default_factory=dict, init=False, repr=False,
                                   compare=False, hash=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "rate", positive("rate", self.rate))
        object.__setattr__(self, "mean_duration", positive("mean_duration",
                                                            self.mean_duration))
        object.__setattr__(self, "seed", integer("seed", self.seed, low=0))

    @property
    def fraction(self) -> float:
        """Almost-sure long-run blocked fraction :math:`1 - e^{-\\lambda \\bar\\tau}`."""
        return -math.expm1(-self.rate * self.mean_duration)

    def _extend(self, horizon: float) -> list[list[float]]:
        c = self._cache
        if not c:
            c.update(rng=np.random.default_rng(self.seed), last=0.0, pending=[],
                     merged=[], starts=[], done_until=-1.0)
        merged: list[list[float]] = c["merged"]
        while c["done_until"] < horizon:
            if not c["pending"]:
                gaps = c["rng"].exponential(1.0 / self.rate, _CHUNK)
                durs = c["rng"].exponential(self.mean_duration, _CHUNK)
                c["pending"] = list(zip(gaps.tolist(), durs.tolist()))[::-1]
            gap, dur = c["pending"].pop()
            s = c["last"] + gap
            c["last"] = s
            e = s + dur
            if merged and s <= merged[-1][1]:
                merged[-1][1] = max(merged[-1][1], e)
            else:
                # every window before this one is final: no later arrival reaches it
                c["done_until"] = s
                merged.append([s, e])
                c["starts"].append(s)
        return merged

    def windows(self, horizon: float) -> list[tuple[float, float]]:
        horizon = nonnegative("horizon", horizon)
        merged = self._extend(horizon)
        k = bisect.bisect_left(self._cache["starts"], horizon)
        return [(s, e) for s, e in merged[:k]]

    def active(self, t: float) -> bool:
        """O(log K): bisect the cached window starts (every window starting at or
        before ``t`` is final once ``_extend`` passed ``t``)."""
        t = nonnegative("t", t)
        merged = self._extend(math.nextafter(t, math.inf))
        k = bisect.bisect_right(self._cache["starts"], t) - 1
        return k >= 0 and merged[k][0] <= t < merged[k][1]

    def to_dict(self) -> dict[str, Any]:
        return {"kind": "random", "rate": self.rate, "mean_duration": self.mean_duration,
                "seed": self.seed}


_SCHEDULE_KEYS: dict[str, tuple[type, tuple[str, ...], tuple[str, ...]]] = {
    "periodic": (Periodic, ("period", "duration"), ("offset",)),
    "explicit": (Explicit, ("windows",), ()),
    "random": (RandomDoS, ("rate", "mean_duration", "seed"), ()),
}


def schedule_from_dict(d: Mapping[str, Any]) -> Schedule:
    """Build a schedule from a TOML-style dict.

    Forms: ``{"kind": "periodic", "period": p, "duration": tau, "offset": o}``
    (offset optional), ``{"kind": "explicit", "windows": [[s, e], ...]}``,
    ``{"kind": "random", "rate": r, "mean_duration": m, "seed": n}``.

    Raises
    ------
    InputError
        Not a dict, unknown ``kind``, unknown or missing keys, or bad values.

    Examples
    --------
    >>> schedule_from_dict({"kind": "periodic", "period": 4, "duration": 1})
    Periodic(period=4.0, duration=1.0, offset=0.0)
    """
    if not isinstance(d, Mapping):
        raise InputError(f"schedule must be a dict with a 'kind'; got {type(d).__name__}")
    kind = d.get("kind")
    if kind not in _SCHEDULE_KEYS:
        raise InputError(
            f"schedule kind must be one of {sorted(_SCHEDULE_KEYS)}; got {kind!r}"
        )
    cls, required, optional = _SCHEDULE_KEYS[kind]
    check_keys(f"{kind} schedule", d, required, optional)
    kwargs = {k: d[k] for k in required + optional if k in d}
    return cls(**kwargs)  # type: ignore[no-any-return]


# --------------------------------------------------------------------------- #
# attacks
# --------------------------------------------------------------------------- #


def _link(name: str, value: Any) -> Link:
    try:
        i, j = value
        hash(i), hash(j)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be a pair (i, j) of agent labels; got {value!r}") from None
    i = int(i) if isinstance(i, np.integer) else i
    j = int(j) if isinstance(j, np.integer) else j
    if i == j:
        raise InputError(f"{name} must join two different agents; got ({i!r}, {j!r})")
    return (i, j)


@dataclass(frozen=True)
class DoSAttack:
    """A named DoS attack: it blocks ``links`` whenever ``schedule`` is active.

    Parameters
    ----------
    name : str
    links : iterable of (i, j)
        ``(i, j)`` = agent i's link from j (i receives j). Stored as a frozenset of
        tuples; labels are the user's agent labels (ints in the paper's example).
    schedule : Schedule

    Examples
    --------
    >>> a = DoSAttack("cut", [(1, 3)], Periodic(2.0, 1.0))
    >>> a.links, a.blocks((1, 3), 0.5), a.blocks((1, 3), 1.0)
    (frozenset({(1, 3)}), True, False)
    """

    name: str
    links: frozenset[Link]
    schedule: Schedule

    def __post_init__(self) -> None:
        if not isinstance(self.name, str):
            raise InputError(f"name must be a str; got {self.name!r}")
        if isinstance(self.links, (str, bytes)) or not isinstance(self.links, Iterable):
            raise InputError(
                f"links must be an iterable of (i, j) pairs; got {type(self.links).__name__}"
            )
        links = frozenset(_link(f"links of {self.name!r}", v) for v in self.links)
        object.__setattr__(self, "links", links)
        if not isinstance(self.schedule, Schedule):
            raise InputError(
                f"schedule must be a Periodic, Explicit or RandomDoS; "
                f"got {type(self.schedule).__name__}"
            )

    def blocks(self, link: Link, t: float) -> bool:
        """Is ``link`` blocked by this attack at time ``t``?"""
        return link in self.links and self.schedule.active(t)


def attack_from_dict(d: Mapping[str, Any]) -> DoSAttack:
    """``{"name": ..., "links": [[i, j], ...], "schedule": {...}}`` → :class:`DoSAttack`.

    Raises
    ------
    InputError
        Unknown or missing keys, or a bad schedule (see :func:`schedule_from_dict`).
    """
    if not isinstance(d, Mapping):
        raise InputError(f"attack must be a dict; got {type(d).__name__}")
    check_keys("attack", d, ("name", "links", "schedule"), tag=None)
    if not isinstance(d["links"], (list, tuple)):
        raise InputError(f"links must be a list of [i, j] pairs; got {d['links']!r}")
    links = [tuple(v) if isinstance(v, list) else v for v in d["links"]]
    return DoSAttack(d["name"], links, schedule_from_dict(d["schedule"]))


def _attacks(attacks: Any) -> tuple[DoSAttack, ...]:
    if isinstance(attacks, DoSAttack):
        return (attacks,)
    if isinstance(attacks, (str, bytes)) or not isinstance(attacks, Iterable):
        raise InputError(
            f"attacks must be an iterable of DoSAttack; got {type(attacks).__name__}"
        )
    out = tuple(attacks)
    for a in out:
        if not isinstance(a, DoSAttack):
            raise InputError(f"attacks must contain DoSAttack objects; got {type(a).__name__}")
    return out


def blocked_links(attacks: Iterable[DoSAttack], t: float) -> frozenset[Link]:
    """Links blocked at time ``t``: the union of the links of the active attacks.

    Examples
    --------
    >>> a = DoSAttack("a", [(1, 3), (1, 7)], Periodic(4.0, 1.0, 0.5))
    >>> sorted(blocked_links([a], 0.5)), sorted(blocked_links([a], 1.5))
    ([(1, 3), (1, 7)], [])
    """
    atts = _attacks(attacks)
    t = nonnegative("t", t)
    out: set[Link] = set()
    for a in atts:
        if a.links and a.schedule.active(t):
            out |= a.links
    return frozenset(out)


def _index_size(links_index: Any) -> int:
    if not isinstance(links_index, Mapping):
        raise InputError(
            f"links_index must be a dict {{(i, j): index}}; got {type(links_index).__name__}"
        )
    return len(links_index)


def _unknown_links(atts: tuple[DoSAttack, ...], links_index: Mapping[Link, int]) -> None:
    for a in atts:
        extra = sorted(a.links - set(links_index), key=repr)
        if extra:
            raise InputError(f"attack {a.name!r} targets link(s) not in links_index: {extra}")


def blocked_mask(attacks: Iterable[DoSAttack], links_index: Mapping[Link, int], t: float, *,
                 strict: bool = False) -> np.ndarray:
    """Boolean mask over indexed links: ``mask[links_index[l]]`` iff l is blocked at t.

    Parameters
    ----------
    attacks : iterable of DoSAttack
    links_index : dict mapping (i, j) to an int in ``0 .. len(links_index) - 1``
    t : float
    strict : bool, optional
        Raise if an attack targets a link absent from ``links_index`` (by default
        such links are ignored: they carry no message).

    Returns
    -------
    numpy.ndarray of bool, shape ``(len(links_index),)``

    Examples
    --------
    >>> a = DoSAttack("a", [(1, 3)], Periodic(4.0, 1.0))
    >>> blocked_mask([a], {(1, 3): 0, (1, 2): 1}, 0.0)
    array([ True, False])
    """
    atts = _attacks(attacks)
    n = _index_size(links_index)
    if strict:
        _unknown_links(atts, links_index)
    t = nonnegative("t", t)
    mask = np.zeros(n, dtype=bool)
    for a in atts:
        if a.links and a.schedule.active(t):
            idx = [links_index[link] for link in a.links if link in links_index]
            mask[idx] = True
    return mask


def blocked_mask_series(attacks: Iterable[DoSAttack], links_index: Mapping[Link, int],
                        times: Any, *, strict: bool = False) -> np.ndarray:
    """Vectorised :func:`blocked_mask` for many instants (e.g. all :math:`t_k = kT`).

    Returns
    -------
    numpy.ndarray of bool, shape ``(len(times), len(links_index))``; row k equals
    ``blocked_mask(attacks, links_index, times[k])``.

    Examples
    --------
    >>> a = DoSAttack("a", [(1, 3)], Periodic(2.0, 1.0))
    >>> blocked_mask_series([a], {(1, 3): 0}, [0.0, 0.5, 1.0, 2.0])[:, 0]
    array([ True,  True, False,  True])
    """
    atts = _attacks(attacks)
    n = _index_size(links_index)
    if strict:
        _unknown_links(atts, links_index)
    ts = np.asarray(times, dtype=float).reshape(-1)
    if ts.size and (not np.all(np.isfinite(ts)) or np.any(ts < 0)):
        raise InputError("times must be finite numbers >= 0; got a negative or non-finite value")
    out = np.zeros((ts.size, n), dtype=bool)
    if not ts.size:
        return out
    horizon = math.nextafter(float(ts.max()), math.inf)
    for a in atts:
        idx = [links_index[link] for link in a.links if link in links_index]
        if not idx:
            continue
        ws = a.schedule.windows(horizon)
        if not ws:
            continue
        # windows of one schedule never overlap after merging; merge to be safe
        merged = _merge(ws)
        starts = np.array([w[0] for w in merged])
        ends = np.array([w[1] for w in merged])
        k = np.searchsorted(starts, ts, side="right") - 1
        on = (k >= 0) & (ts < ends[np.maximum(k, 0)])
        out[np.ix_(on, idx)] = True
    return out


# --------------------------------------------------------------------------- #
# Assumption 3
# --------------------------------------------------------------------------- #


@dataclass(frozen=True)
class Assumption3Witness:
    """The pair :math:`(t_1, t_2)` maximising :math:`|\\Pi_D\\cap[t_1,t_2]| - (t_2-t_1)/T_d`.

    Attributes
    ----------
    t1, t2 : float
        A window start and a (later) window end of :math:`\\Pi_D`.
    blocked : float
        :math:`|\\Pi_D \\cap [t_1, t_2]|`.
    allowance : float
        :math:`(t_2 - t_1) / T_d`.
    excess : float
        ``blocked - allowance``: the smallest :math:`\\mu_d` for this pair.
    bound : float or None
        :math:`\\mu_d + (t_2 - t_1)/T_d` when :math:`\\mu_d` was given.
    """

    t1: float
    t2: float
    blocked: float
    allowance: float
    excess: float
    bound: float | None


@dataclass(frozen=True)
class Assumption3Report:
    """Answer of :func:`check_assumption3`.

    Attributes
    ----------
    horizon : float
    mu_d, T_d : float or None
        As given.
    holds : bool or None
        Assumption 3 holds on ``[0, horizon]`` (None unless both mu_d and T_d given,
        or when the horizon holds too many windows to list, see ``notes``).
    witness : Assumption3Witness or None
        The worst pair for ``T_d`` (None without T_d or without any attack window).
    min_mu_d : float or None
        For the given ``T_d``: the smallest float :math:`\\mu_d` with the bound on
        ``[0, horizon]`` (the exact supremum, rounded up). 0.0 when nothing is
        blocked: then every :math:`\\mu_d > 0` works.
    windows : tuple of (float, float), or None
        :math:`\\Pi_D \\cap [0, \\text{horizon}]` as merged disjoint windows; None
        (as are ``holds``, ``witness``, ``min_mu_d`` and ``total_blocked``) when the
        horizon holds more than ``_HORIZON_MAX_WINDOWS`` (200 000) windows: not
        decided on the horizon (the long-run quantities are still computed), except
        for a single periodic schedule, decided in closed form (only ``windows`` is
        None then, :func:`_periodic_horizon`).
    total_blocked : float or None
        :math:`|\\Pi_D \\cap [0, \\text{horizon}]|`.
    long_run_fraction : float or None
        :math:`\\lim |\\Pi_D \\cap [0, t]| / t` (exact for periodic and explicit
        schedules; almost sure for random ones; None if not computable).
    max_T_d : float or None
        :math:`1/\\rho`: Assumption 3 can hold for all time exactly when
        :math:`T_d \\le 1/\\rho` (inf when :math:`\\rho = 0`).
    any_T_d_works : bool or None
        Some :math:`T_d > 1` works for all time, i.e. :math:`\\rho < 1`.
    min_mu_d_long_run : float or None
        For the given T_d, the smallest :math:`\\mu_d` valid for **all**
        :math:`t_2 > t_1 \\ge 0` (inf if :math:`T_d > 1/\\rho`); periodic and
        explicit schedules only.
    holds_long_run : bool or None
        ``mu_d >= min_mu_d_long_run`` (None if either is unknown).
    notes : tuple of str
    """

    horizon: float
    mu_d: float | None
    T_d: float | None
    holds: bool | None
    witness: Assumption3Witness | None
    min_mu_d: float | None
    windows: tuple[tuple[float, float], ...] | None
    total_blocked: float | None
    long_run_fraction: float | None
    max_T_d: float | None
    any_T_d_works: bool | None
    min_mu_d_long_run: float | None
    holds_long_run: bool | None
    notes: tuple[str, ...]
    #: what the finite-horizon answer was computed from, exactly: Π_D ∩ [0, horizon]
    #: (``windows`` are its endpoints rounded), or the one periodic schedule decided in
    #: closed form; and the witness's (t1, t2) before rounding
    exact_windows: tuple[tuple[Fraction, Fraction], ...] | None = field(
        default=None, repr=False, compare=False)
    periodic: Periodic | None = field(default=None, repr=False, compare=False)
    exact_pair: tuple[Fraction, Fraction] | None = field(default=None, repr=False,
                                                         compare=False)

    def min_mu_d_for(self, T_d: float) -> float:
        """Smallest float :math:`\\mu_d` on ``[0, horizon]`` for another ``T_d``."""
        T_d = _check_T_d(T_d)
        H = Fraction(self.horizon)
        if self.periodic is not None:
            return _ceil_float(_periodic_horizon(self.periodic, H, _inv(T_d))[1])
        if self.exact_windows is None:
            raise InputError("too many DoS windows on the horizon to compute min_mu_d "
                             "(the report's windows were not listed)")
        sup, _ = _sup_excess(list(self.exact_windows), _inv(T_d))
        return _ceil_float(sup)

    def check(self) -> bool:
        """Re-verify the finite-horizon answer in exact arithmetic from what it was
        computed from (the exact windows, or the periodic schedule's closed form):
        ``windows`` and ``total_blocked`` are their roundings; with ``T_d``, the
        supremum σ of the excess |Π ∩ [t1, t2]| − (t2 − t1)/T_d gives ``min_mu_d``
        (rounded up) and ``holds`` (μ_d ≥ σ), and the witness is an exact pair (t1, t2)
        attaining σ whose endpoints, blocked time, allowance, excess and bound round to
        its values — no witness exactly when nothing is blocked (σ = 0); without
        ``T_d`` there is no witness, ``holds`` nor ``min_mu_d``. A horizon not decided
        (neither) has every finite-horizon field None."""
        H = Fraction(self.horizon)
        inv = None if self.T_d is None else _inv(self.T_d)
        if self.periodic is not None:
            sched = self.periodic
            total, sup, _ = _periodic_horizon(sched, H, inv)
            ok = self.windows is None

            def blocked_on(a: Fraction, b: Fraction) -> Fraction:
                return _periodic_measure(sched, H, a, b)
        elif self.exact_windows is not None:
            wins = list(self.exact_windows)
            total = sum((e - s for s, e in wins), Fraction(0))
            sup = _sup_excess(wins, inv)[0] if inv is not None else Fraction(0)
            ok = self.windows == tuple((float(s), float(e)) for s, e in wins)

            def blocked_on(a: Fraction, b: Fraction) -> Fraction:
                return _measure(wins, a, b)
        else:
            return all(v is None for v in (self.windows, self.total_blocked, self.witness,
                                           self.holds, self.min_mu_d, self.exact_pair))
        ok = ok and self.total_blocked == float(total)
        if inv is None:
            return ok and all(v is None for v in (self.witness, self.holds, self.min_mu_d,
                                                  self.exact_pair))
        holds = None if self.mu_d is None else Fraction(self.mu_d) >= sup
        ok = ok and self.min_mu_d == _ceil_float(sup) and self.holds == holds
        w = self.witness
        if w is None or self.exact_pair is None:
            return ok and w is None and self.exact_pair is None and total == 0
        t1, t2 = self.exact_pair
        blocked = blocked_on(t1, t2)
        allowance = (t2 - t1) * inv
        bound = None if self.mu_d is None else float(Fraction(self.mu_d) + allowance)
        return (ok and t1 <= t2 and blocked - allowance == sup
                and (float(t1), float(t2)) == (w.t1, w.t2) and float(blocked) == w.blocked
                and float(allowance) == w.allowance and _ceil_float(sup) == w.excess
                and w.bound == bound)


def _check_T_d(T_d: Any) -> float:
    v = real("T_d", T_d)
    if math.isnan(v) or not v > 1:
        raise InputError(f"T_d must be a number > 1 (inf allowed); got {T_d!r}")
    return v


def _inv(T_d: float) -> Fraction:
    return Fraction(0) if math.isinf(T_d) else 1 / Fraction(T_d)


def _ceil_float(x: Fraction) -> float:
    """Smallest float >= x."""
    f = float(x)
    return math.nextafter(f, math.inf) if Fraction(f) < x else f


def _measure(windows: list[tuple[Fraction, Fraction]], t1: Fraction, t2: Fraction) -> Fraction:
    return sum((max(Fraction(0), min(e, t2) - max(s, t1)) for s, e in windows), Fraction(0))


def _sup_excess(windows: list[tuple[Fraction, Fraction]],
                inv: Fraction) -> tuple[Fraction, tuple[int, int] | None]:
    """Exact :math:`\\sup_{t_1 \\le t_2} |\\Pi\\cap[t_1,t_2]| - (t_2 - t_1)\\,\\mathrm{inv}`.

    ``windows`` merged and disjoint. With :math:`T_d > 1` the objective grows in
    :math:`t_2` inside a window and falls outside it, so the supremum is attained
    at :math:`t_1 = a_i`, :math:`t_2 = b_j`, :math:`i \\le j`. Writing
    :math:`B` for the cumulative blocked time,
    :math:`g(a_i, b_j) = P_j - Q_i`, :math:`P_j = B(b_j) - b_j\\,\\mathrm{inv}`,
    :math:`Q_i = B(a_i) - a_i\\,\\mathrm{inv}`; a running minimum of Q gives the
    answer in O(m). Returns (sup, (i, j)) or (0, None) without windows.
    """
    best: Fraction = Fraction(0)
    arg: tuple[int, int] | None = None
    cum = Fraction(0)
    q_min: Fraction | None = None
    i_min = -1
    for j, (a, b) in enumerate(windows):
        q = cum - a * inv
        if q_min is None or q < q_min:
            q_min, i_min = q, j
        cum += b - a
        p = cum - b * inv
        if arg is None or p - q_min > best:
            best, arg = p - q_min, (i_min, j)
    return best, arg


def _window_count(sched: Schedule, horizon: Fraction) -> float:
    """How many windows of ``sched`` start before ``horizon``, without listing them
    (exact for periodic and explicit schedules; the expected number of arrivals
    :math:`\\lambda h` for random ones)."""
    if isinstance(sched, Periodic):
        o = Fraction(sched.offset)
        return 0.0 if horizon <= o else float(math.ceil((horizon - o) / Fraction(sched.period)))
    if isinstance(sched, Explicit):
        return float(len(sched.intervals))
    if isinstance(sched, RandomDoS):
        return sched.rate * float(horizon)
    return float(len(sched.windows(float(horizon))))


def _periodic_horizon(sched: Periodic, horizon: Fraction, inv: Fraction | None
                      ) -> tuple[Fraction, Fraction, tuple[Fraction, Fraction] | None]:
    """Closed form of (|Π ∩ [0, h]|, sup excess, worst (t1, t2)) for one periodic
    schedule, without listing its windows.

    With n windows starting before h (the last of length ℓ = min(τ, h − o − (n−1)p))
    and δ = τ − p·inv, the pair (a_i, b_j) has excess (j − i)δ + τ(1 − inv) when
    j < n − 1 and (n − 1 − i)δ + ℓ(1 − inv) when j = n − 1 (ℓ ≤ τ, 1 − inv > 0), so
    the supremum is the largest of the pairs (a_0, b_j), j ∈ {0, n − 2, n − 1}
    (δ ≤ 0: one window; δ > 0: from the first window to one of the last two)."""
    p, tau, o = Fraction(sched.period), Fraction(sched.duration), Fraction(sched.offset)
    if horizon <= o:
        return Fraction(0), Fraction(0), None
    n = math.ceil((horizon - o) / p)
    last = min(tau, horizon - o - (n - 1) * p)
    total = (n - 1) * tau + last
    if inv is None:
        return total, Fraction(0), None
    best: tuple[Fraction, Fraction, Fraction] | None = None
    for j in sorted({0, max(n - 2, 0), n - 1}):
        length = tau if j < n - 1 else last
        g = j * (tau - p * inv) + length * (1 - inv)
        if best is None or g > best[0]:
            best = (g, o, o + j * p + length)
    assert best is not None
    return total, best[0], (best[1], best[2])


def _periodic_measure(sched: Periodic, horizon: Fraction, t1: Fraction, t2: Fraction
                      ) -> Fraction:
    """|Π ∩ [0, h] ∩ [t1, t2]| for one periodic schedule in closed form: M(b) − M(a)
    with M(t) = |Π ∩ [0, t]| = nτ + min(r, τ) (t − o = np + r, 0 ≤ r < p) for t > o,
    a, b the clips of t1, t2 to [0, h]."""
    p, tau, o = Fraction(sched.period), Fraction(sched.duration), Fraction(sched.offset)

    def upto(t: Fraction) -> Fraction:
        if t <= o:
            return Fraction(0)
        n = math.floor((t - o) / p)
        return n * tau + min(t - o - n * p, tau)

    a, b = (min(max(t, Fraction(0)), horizon) for t in (t1, t2))
    return upto(b) - upto(a) if a < b else Fraction(0)


def _union_exact(atts: tuple[DoSAttack, ...], horizon: Fraction) -> list[tuple[Fraction, Fraction]]:
    raw: list[tuple[Fraction, Fraction]] = []
    for sched in {a.schedule for a in atts if a.links}:
        raw.extend(sched._exact_windows(horizon))
    return _merge(raw)


def _clip(windows: list[tuple[Fraction, Fraction]], lo: Fraction,
          hi: Fraction) -> list[tuple[Fraction, Fraction]]:
    out = []
    for s, e in windows:
        s, e = max(s, lo), min(e, hi)
        if s < e:
            out.append((s, e))
    return out


def _lcm(values: list[Fraction]) -> Fraction:
    num, den = values[0].numerator, values[0].denominator
    for v in values[1:]:
        num = num * v.numerator // math.gcd(num, v.numerator)
        den = math.gcd(den, v.denominator)
    return Fraction(num, den)


def _long_run(atts: tuple[DoSAttack, ...], inv: Fraction | None,
              notes: list[str]) -> tuple[Fraction | float | None, Fraction | None]:
    """(long-run fraction rho, exact all-time sup for ``inv``, or None)."""
    scheds = {a.schedule for a in atts if a.links}
    per = [s for s in scheds if isinstance(s, Periodic)]
    exp = [s for s in scheds if isinstance(s, Explicit)]
    rnd = [s for s in scheds if isinstance(s, RandomDoS)]
    # union of periodic and explicit: H-periodic after o' (H = hyperperiod)
    o = max([Fraction(s.offset) for s in per] + [Fraction(s.intervals[-1][1])
                                                 for s in exp if s.intervals] + [Fraction(0)])
    rho_pe: Fraction | None
    sup_all: Fraction | None = None
    if not per:
        rho_pe = Fraction(0)
        H = Fraction(0)
    else:
        H = _lcm([Fraction(s.period) for s in per])
        count = sum((o + 2 * H) / Fraction(s.period) for s in per)
        if count > _LONG_RUN_MAX_WINDOWS:
            rho_pe = None
            notes.append(
                f"the hyperperiod of the periodic schedules is {float(H):.6g} "
                f"(about {float(count):.3g} windows): long-run quantities not computed; "
                "periods that are exact binary fractions (integers, 0.5, 0.25) keep it short"
            )
        else:
            one = _clip(_union_exact(tuple(a for a in atts if a.schedule in per),
                                     o + H), o, o + H)
            rho_pe = sum((e - s for s, e in one), Fraction(0)) / H
    if rho_pe is not None and inv is not None and not rnd:
        if inv < rho_pe:
            sup_all = None  # infinite; signalled by the caller through rho
        else:
            pe_atts = tuple(a for a in atts if a.schedule in per or a.schedule in exp)
            end = o + 2 * H
            sup_all, _ = _sup_excess(_clip(_union_exact(pe_atts, end), Fraction(0), end), inv)
    if rnd:
        notes.append("random schedules: the long-run fraction is the almost-sure limit "
                     "1 - (1 - rho_periodic) * prod exp(-rate * mean_duration); the "
                     "all-time mu_d is not computed")
        if rho_pe is None:
            return None, None
        q = float(1 - rho_pe) * math.prod(math.exp(-s.rate * s.mean_duration) for s in rnd)
        return 1.0 - q, None
    return rho_pe, sup_all


def check_assumption3(attacks: Iterable[DoSAttack], horizon: float, *,
                      mu_d: float | None = None, T_d: float | None = None) -> Assumption3Report:
    """Check Assumption 3 (DoS duration) exactly on ``[0, horizon]`` and in the long run.

    :math:`\\Pi_D` is the union of all windows of all attacks that target at least
    one link. Assumption 3 asks, for all :math:`0 \\le t_1 \\le t_2`,

    .. math::

        |\\Pi_D \\cap [t_1, t_2]| \\le \\mu_d + \\frac{t_2 - t_1}{T_d},
        \\qquad T_d > 1,\\ \\mu_d > 0 .

    For :math:`T_d > 1` the left side minus :math:`(t_2 - t_1)/T_d` increases in
    :math:`t_2` inside a window and decreases outside, so its supremum is attained
    with :math:`t_1` a window start and :math:`t_2` a window end; it is computed
    exactly in rational arithmetic (every float endpoint converted with
    :class:`fractions.Fraction`), so ``holds`` is a yes/no answer without
    tolerance.

    Long run: if all schedules are periodic or explicit, :math:`\\Pi_D` is periodic
    with the hyperperiod H (lcm of the periods) after :math:`o'` (the last offset /
    explicit end), its blocked fraction :math:`\\rho` is exact, and for
    :math:`1/T_d \\ge \\rho` the supremum over all time equals the supremum over
    :math:`[0, o' + 2H]` (shift a pair by H until :math:`t_1 < o' + H`, then cut
    full periods off :math:`[t_1, t_2]`, which cannot lower the excess); for
    :math:`1/T_d < \\rho` it is infinite. Hence some :math:`T_d > 1` works for all
    time iff :math:`\\rho < 1`, namely every :math:`T_d \\in (1, 1/\\rho]`.

    Parameters
    ----------
    attacks : iterable of DoSAttack
    horizon : float
        Finite, >= 0.
    mu_d : float, optional
        > 0. With ``T_d`` it makes ``holds`` a bool.
    T_d : float, optional
        > 1 (``math.inf`` allowed: total blocked time bounded by :math:`\\mu_d`).

    Returns
    -------
    Assumption3Report

    Raises
    ------
    InputError
        Bad attacks, horizon < 0 or not finite, mu_d <= 0, T_d <= 1.

    Notes
    -----
    O(m) rational operations for m windows on the horizon, after sorting.

    Examples
    --------
    >>> r = check_assumption3(paper_attacks(), 120.0, mu_d=PAPER_MU_D, T_d=PAPER_T_D)
    >>> r.holds, r.holds_long_run, r.long_run_fraction, r.max_T_d
    (True, True, 0.5583333333333333, 1.791044776119403)
    >>> always = DoSAttack("all", [(1, 2)], Periodic(1.0, 1.0))
    >>> r = check_assumption3([always], 10.0, mu_d=2.0, T_d=2.0)
    >>> r.holds, (r.witness.t1, r.witness.t2, r.witness.blocked), r.any_T_d_works
    (False, (0.0, 10.0, 10.0), False)
    """
    atts = _attacks(attacks)
    horizon = nonnegative("horizon", horizon)
    if mu_d is not None:
        mu_d = positive("mu_d", mu_d)
    if T_d is not None:
        T_d = _check_T_d(T_d)
    notes: list[str] = []
    H = Fraction(horizon)
    count = sum(_window_count(a.schedule, H) for a in atts if a.links)
    win: list[tuple[Fraction, Fraction]] | None = None
    total: Fraction | None = None
    inv = _inv(T_d) if T_d is not None else None
    scheds = {a.schedule for a in atts if a.links}
    closed = None
    if count > _HORIZON_MAX_WINDOWS and len(scheds) == 1 and isinstance(
            next(iter(scheds)), Periodic):
        closed = _periodic_horizon(next(iter(scheds)), H, inv)
        total = closed[0]
        notes.append(f"about {count:.3g} attack windows on [0, {horizon:g}]: one periodic "
                     "schedule, decided in closed form (windows not listed: None)")
    elif count > _HORIZON_MAX_WINDOWS:
        notes.append(f"about {count:.3g} attack windows on [0, {horizon:g}]: the "
                     "finite-horizon check is not computed (holds, witness, min_mu_d, "
                     "windows, total_blocked are None)")
    else:
        win = _clip(_union_exact(atts, H), Fraction(0), H)
        total = sum((e - s for s, e in win), Fraction(0))

    witness = None
    min_mu = None
    holds = None
    if inv is not None and (win is not None or closed is not None):
        if closed is not None:
            sup, pair = closed[1], closed[2]
        else:
            sup, arg = _sup_excess(win, inv)
            pair = None if arg is None else (win[arg[0]][0], win[arg[1]][1])
        min_mu = _ceil_float(sup)
        if pair is None:
            notes.append("nothing is blocked on the horizon: every mu_d > 0 works")
        else:
            t1, t2 = pair
            allowance = (t2 - t1) * inv
            blocked = sup + allowance if closed is not None else _measure(win, t1, t2)
            witness = Assumption3Witness(
                t1=float(t1), t2=float(t2), blocked=float(blocked),
                allowance=float(allowance), excess=_ceil_float(sup),
                bound=None if mu_d is None else float(Fraction(mu_d) + allowance),
            )
        if mu_d is not None:
            holds = Fraction(mu_d) >= sup

    rho, sup_all = _long_run(atts, inv, notes)
    long_run = None if rho is None else float(rho)
    max_T_d = None
    any_ok: bool | None = None
    if rho is not None:
        any_ok = rho < 1
        max_T_d = math.inf if rho == 0 else float(1 / Fraction(rho))
    else:
        per = [a.schedule for a in atts if a.links and isinstance(a.schedule, Periodic)]
        fr = [Fraction(s.duration) / Fraction(s.period) for s in per]
        if fr and max(fr) == 1:
            any_ok = False
        elif sum(fr, Fraction(0)) < 1 and all(
                not isinstance(a.schedule, RandomDoS) for a in atts if a.links):
            any_ok = True
    min_all: float | None = None
    if inv is not None and isinstance(rho, Fraction):
        min_all = math.inf if inv < rho else (None if sup_all is None else _ceil_float(sup_all))
    holds_all = None
    if min_all is not None and mu_d is not None:
        holds_all = (not math.isinf(min_all)) and sup_all is not None and \
            Fraction(mu_d) >= sup_all
    if any_ok is False:
        notes.append("the long-run blocked fraction is 1: no T_d > 1 works for all time")
    return Assumption3Report(
        horizon=horizon, mu_d=mu_d, T_d=T_d, holds=holds, witness=witness, min_mu_d=min_mu,
        windows=None if win is None else tuple((float(s), float(e)) for s, e in win),
        total_blocked=None if total is None else float(total),
        exact_windows=None if win is None else tuple(win),
        periodic=None if closed is None else next(iter(scheds)),
        exact_pair=None if witness is None else pair,
        long_run_fraction=long_run, max_T_d=max_T_d, any_T_d_works=any_ok,
        min_mu_d_long_run=min_all, holds_long_run=holds_all, notes=tuple(notes),
    )


# --------------------------------------------------------------------------- #
# the paper's example (SPEC §5)
# --------------------------------------------------------------------------- #

#: Assumption 3 constants the paper schedules satisfy for all time (see
#: :func:`paper_schedules`).
PAPER_T_D = 1.5
PAPER_MU_D = 2.0

_PAPER_LINKS: dict[str, tuple[tuple[int, int], ...]] = {
    "DoS_1": ((1, 3), (1, 7), (1, 9), (3, 4), (3, 7), (3, 11), (5, 1), (5, 11), (6, 2),
              (6, 10), (10, 1), (10, 12)),
    "DoS_2": ((4, 2), (4, 3), (7, 5), (7, 9), (7, 10), (8, 3), (8, 5), (9, 7), (9, 8)),
    "DoS_3": ((3, 2), (3, 6), (5, 3), (5, 7), (7, 1), (7, 2), (7, 3), (11, 1), (11, 3),
              (11, 12)),
}


def paper_schedules() -> dict[str, Periodic]:
    """Documented stand-ins for the paper's DoS_1..DoS_3 timing (which is unknown).

    The paper's timing figure is missing from its source, so these are choices,
    not the paper's data:

    ====== ======== ======== ======== ===============
    name   period   duration offset   blocked fraction
    ====== ======== ======== ======== ===============
    DoS_1  4 s      1 s      0.5 s    1/4
    DoS_2  5 s      1.5 s    1.0 s    3/10
    DoS_3  6 s      1 s      2.0 s    1/6
    ====== ======== ======== ======== ===============

    Their union :math:`\\Pi_D` is periodic with hyperperiod 60 s after t = 2 s and
    blocks a long-run fraction :math:`\\rho = 67/120 \\approx 0.558` (less than the
    sum 43/60 of the three fractions, as the windows overlap), so Assumption 3 holds
    for all time for every :math:`T_d \\in (1, 120/67]` (120/67 ≈ 1.79) with a
    suitable :math:`\\mu_d`; in particular with :math:`T_d` = :data:`PAPER_T_D` = 1.5
    and :math:`\\mu_d` = :data:`PAPER_MU_D` = 2.0 (the exact smallest
    :math:`\\mu_d` for :math:`T_d = 1.5` is 7/6, attained e.g. on
    :math:`[t_1, t_2] = [44, 53.5]`, 7.5 s blocked). :func:`check_assumption3`
    certifies this, for a finite horizon and for all time.

    All times are in seconds; with :math:`T = 0.5` s every window boundary is a
    sampling instant.
    """
    return {
        "DoS_1": Periodic(period=4.0, duration=1.0, offset=0.5),
        "DoS_2": Periodic(period=5.0, duration=1.5, offset=1.0),
        "DoS_3": Periodic(period=6.0, duration=1.0, offset=2.0),
    }


def paper_attacks() -> list[DoSAttack]:
    """The paper's three DoS attacks on exactly the links of its table (SPEC §5).

    Agents are numbered 1..12 as in the paper; a link ``(i, j)`` is agent i's link
    from j. Schedules from :func:`paper_schedules`.

    Examples
    --------
    >>> [(a.name, len(a.links)) for a in paper_attacks()]
    [('DoS_1', 12), ('DoS_2', 9), ('DoS_3', 10)]
    """
    sch = paper_schedules()
    return [DoSAttack(name, frozenset(links), sch[name]) for name, links in _PAPER_LINKS.items()]
