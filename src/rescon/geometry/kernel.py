"""Safe kernels Ψ(X, F) = ⋂ {conv(S) : S ⊆ X, |S| = n − F}, exactly.

Pipeline: exact integer form of X (:mod:`.exact`) → its affine hull aff(X) (dimension
k, k pivot coordinates in which the projection is injective) → the valid halfspaces
through k points with ≤ F points outside (:mod:`.halfspaces`) → exact clipping of the
bounding box by them (:mod:`.polytope`) → vertices, facets, affine hull and a
certificate (``safe_kernel``, or ``kernel_empty`` with Farkas multipliers).
"""

from __future__ import annotations

import functools
import math
import operator
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction
from os import PathLike
from typing import Any

import numpy as np

from .._validate import check_F, check_point, check_points
from ..errors import EmptyKernel, InputError
from ._skeleton import vertex_adjacency
from .emptiness import empty_certificate, empty_from_halfspaces
from .exact import (
    AffineHull,
    ExactPoints,
    affine_hull,
    exact_points,
    float_view,
    fraction_str,
    halfspaces_json,
    nullspace_exact,
    solve_exact,
)
from .fastpath import certified_kernel
from .halfspaces import valid_halfspaces
from .points import check_choice, kernel_point_of
from .polytope import ExactPolytope, Farkas, _bits, clip_to_fixpoint

__all__ = ["SafeKernel", "kernel_point", "kernel_points", "safe_kernel"]


#: below this many valid halfspaces exact clipping is faster than the fast path's
#: LP + qhull set-up (and tiny kernels are often flat, which the fast path declines)
FAST_PATH_MIN_HALFSPACES = 60


class _Deferred:
    """A value built on its first use, then kept: a kernel's exact vertices (a reduced
    Fraction — a gcd of 500-1300-bit integers in d = 4-5 — per coordinate, which most
    callers never read; the floats, the order and the facets come without them).
    Built once also when threads read it at the same time: the others wait for the
    first (V38: 8 threads sharing one kernel each solved its vertices)."""

    def __init__(self, make: Callable[[], Any]) -> None:
        self._make: Callable[[], Any] | None = make
        self._value: Any = None
        self._lock = threading.Lock()

    def get(self) -> Any:
        if self._make is not None:
            with self._lock:
                if self._make is not None:  # not built while this thread waited
                    self._value, self._make = self._make(), None
        return self._value


class _Lazy:
    """Makes a dataclass field accept a _Deferred, built on the field's first read and
    stored in its place (any other value is stored as given). Installed on the class
    after @dataclass, so the field keeps its declaration (repr, eq, order); frozen
    dataclasses set fields through object.__setattr__, which calls __set__."""

    def __init__(self, name: str) -> None:
        self.slot = f"_{name}_value"

    def __get__(self, obj: Any, objtype: Any = None) -> Any:
        if obj is None:
            raise AttributeError(self.slot)
        value = obj.__dict__[self.slot]
        if isinstance(value, _Deferred):
            value = obj.__dict__[self.slot] = value.get()
        return value

    def __set__(self, obj: Any, value: Any) -> None:
        obj.__dict__[self.slot] = value


@dataclass(frozen=True)
class _Exact:
    """The exact data behind a SafeKernel (ambient coordinates, Fractions)."""

    vertices: tuple[tuple[Fraction, ...], ...]
    constraints: tuple[tuple[tuple[Fraction, ...], Fraction], ...]  # a·x ≤ b, tight somewhere
    equalities: tuple[tuple[tuple[Fraction, ...], Fraction], ...]  # aff(X): a·x = b
    facets: tuple[tuple[tuple[Fraction, ...], Fraction], ...] = ()  # relative to aff(Ψ)
    kernel_eqs: tuple[tuple[tuple[Fraction, ...], Fraction], ...] = ()  # aff(Ψ): a·x = b

    def contains(self, x: tuple[Fraction, ...]) -> bool:
        if not self.vertices:
            return False
        def dot(a: tuple[Fraction, ...]) -> Fraction:
            return sum(map(operator.mul, a, x))

        return (all(dot(a) == b for a, b in self.equalities)
                and all(dot(a) <= b for a, b in self.constraints))


@dataclass(frozen=True)
class _Given:
    """A certificate builder that returns an already built certificate (picklable)."""

    certificate: dict[str, Any]

    def __call__(self) -> dict[str, Any]:
        return self.certificate


@dataclass(frozen=True)
class SafeKernel:
    """Ψ(X, F) as an exact polytope.

    Attributes
    ----------
    points : the input X, (n, d).
    F : the number of points that may be removed.
    dim : affine dimension of Ψ (−1 when empty).
    vertices : (m, d) floats of the exact vertices (``exact_vertices``: Fractions).
    A, b : facets, Ψ = {x ∈ aff(Ψ) : A x ≤ b}, rows of unit norm; facets are taken
        relative to aff(Ψ) (none when dim = 0).
    affine_origin, affine_basis : aff(Ψ) = {origin + basisᵀ t}, basis (dim, d) with
        orthonormal rows (origin None when empty).
    Aeq, beq : aff(Ψ) = {x : Aeq x = beq} ((d − dim, d); empty when dim = d).
    certificate : ``safe_kernel`` or ``kernel_empty`` certificate (certificates/FORMAT.md).
    seconds : wall time.
    """

    points: np.ndarray = field(repr=False)
    F: int
    dim: int
    vertices: np.ndarray
    A: np.ndarray = field(repr=False)
    b: np.ndarray = field(repr=False)
    affine_origin: np.ndarray | None = field(repr=False)
    affine_basis: np.ndarray = field(repr=False)
    Aeq: np.ndarray = field(repr=False)
    beq: np.ndarray = field(repr=False)
    seconds: float
    exact_vertices: tuple[tuple[Fraction, ...], ...] = field(repr=False)
    _exact: _Exact = field(repr=False, compare=False)
    _make_certificate: Callable[[], dict[str, Any]] = field(repr=False, compare=False)
    _cache: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    def __eq__(self, other: object) -> bool:
        """The same input (X bit for bit, F) and the same exact kernel (dimension and
        exact vertices, in their canonical order); the wall time is not compared."""
        if not isinstance(other, SafeKernel):
            return NotImplemented
        return (self.F == other.F and self.dim == other.dim
                and self.points.shape == other.points.shape
                and np.array_equal(self.points, other.points)
                and self.exact_vertices == other.exact_vertices)

    def __hash__(self) -> int:
        return hash((self.F, self.dim, self.points.shape, self.exact_vertices))

    @property
    def certificate(self) -> dict[str, Any]:
        """The ``safe_kernel`` / ``kernel_empty`` certificate (built on first use: the
        exact rationals are written out as "p/q" strings)."""
        if "certificate" not in self._cache:
            self._cache["certificate"] = self._make_certificate()
        return self._cache["certificate"]

    def __getstate__(self) -> dict[str, Any]:
        """Pickled with its certificate built (the builder is a closure): a kernel
        computed on a Dask worker travels whole."""
        for name in ("vertices", "constraints", "facets"):  # built now: the builders are
            getattr(self._exact, name)  # closures
        self.exact_vertices  # noqa: B018
        return {**self.__dict__, "_make_certificate": _Given(self.certificate)}

    @property
    def is_empty(self) -> bool:
        return self.dim < 0

    def contains(self, x: Any, tol: float = 0.0) -> bool:
        """x ∈ Ψ. With ``tol = 0`` (default) decided exactly for the floats given (their
        exact binary values) — so a float rounded from an exact boundary point, such as
        the ``x`` of :meth:`point`, may test False; with tol > 0, up to that distance in
        each (unit-normal) constraint."""
        xv = check_point(x, self.points.shape[1], "x")
        if self.is_empty:
            return False
        if tol == 0.0:
            return self._exact.contains(tuple(Fraction(float(v)) for v in xv))
        if tol < 0 or not np.isfinite(tol):
            raise InputError(f"tol must be a finite number >= 0; got {tol}")
        ok_eq = np.all(np.abs(self.Aeq @ xv - self.beq) <= tol) if len(self.beq) else True
        ok_in = np.all(self.A @ xv - self.b <= tol) if len(self.b) else True
        return bool(ok_eq and ok_in)

    def point(self, method: str = "project", *, backend: str = "auto",
              target: Any = None) -> tuple[np.ndarray, dict[str, Any]]:
        """A canonical point of Ψ and its ``kernel_point`` certificate; see
        :func:`rescon.kernel_point`."""
        return kernel_point_of(self, method=method, backend=backend, target=target)

    def plot(self, ax: Any = None, *, point: Any = None, path: Any = None,
             view: tuple[float, float] | None = None) -> Any:
        """Points, kernel and (optionally) a chosen point; d = 2 or 3 (matplotlib), axes
        x₁, x₂ (, x₃) at equal scale, a 3-D kernel seen from ``view`` = (elevation,
        azimuth) in degrees (:func:`rescon.plot.kernel.plot_kernel`). A file name in
        place of ``ax`` is the ``path`` (``K.plot("kernel.png")``, as ``Trajectory.plot``)."""
        from ..plot.kernel import plot_kernel

        if isinstance(ax, (str, PathLike)):
            ax, path = None, ax
        return plot_kernel(self, ax=ax, point=point, path=path, view=view)


_Exact.vertices = _Lazy("vertices")  # type: ignore[assignment]
_Exact.constraints = _Lazy("constraints")  # type: ignore[assignment]
_Exact.facets = _Lazy("facets")  # type: ignore[assignment]
SafeKernel.exact_vertices = _Lazy("exact_vertices")  # type: ignore[assignment]


def _ambient(hull: AffineHull, d: int, a: tuple[int, ...], b: int, scale: int
             ) -> tuple[tuple[Fraction, ...], Fraction]:
    """a·y ≤ b on the pivot coordinates y = scale · x[coords] as an ambient halfspace."""
    full = [Fraction(0)] * d
    for t, c in enumerate(hull.coords):
        full[c] = Fraction(a[t])
    return tuple(full), Fraction(b, scale)


def _along_hull(rows: list[tuple[tuple[Fraction, ...], Fraction]], eqs, v0
                ) -> list[tuple[tuple[Fraction, ...], Fraction]]:
    """Each row a·x ≤ b rewritten on aff Ψ = {x : E x = f} as a'·x ≤ b' with a' the
    orthogonal projection of a onto the directions of aff Ψ, exactly:
    a' = a − Eᵀc, (E Eᵀ) c = E a, b' = b − (a − a')·v0 (v0 ∈ aff Ψ), so a·x − b =
    a'·x − b' on aff Ψ. A facet relative to a flat Ψ may have a normal nearly
    orthogonal to Ψ; its float rounding would then no longer bound Ψ, a' does."""
    if not eqs or not rows:
        return rows
    E = [a for a, _ in eqs]
    gram = [[sum(map(operator.mul, g, h)) for h in E] for g in E]
    out = []
    for a, b in rows:
        c = solve_exact(gram, [sum(map(operator.mul, g, a)) for g in E])
        assert c is not None, "the kernel's equalities are independent"
        p = tuple(aj - sum(ci * g[j] for ci, g in zip(c, E, strict=True))
                  for j, aj in enumerate(a))
        out.append((p, b - sum((aj - pj) * vj for aj, pj, vj in zip(a, p, v0, strict=True))))
    return out


def _unit_rows(rows: list[tuple[tuple[Fraction, ...], Fraction]], d: int
               ) -> tuple[np.ndarray, np.ndarray]:
    """Float rows a/‖a‖, b/‖a‖ (each row first divided exactly by its largest |a_j|, so
    the float conversion cannot overflow in a; b/‖a‖ is rounded once from the exact
    quotient by the float norm, so it overflows only when the facet's distance from
    the origin does: InputError, as no float row can state it)."""
    if not rows:
        return np.zeros((0, d)), np.zeros(0)
    tops = [_max_abs(a) for a, _ in rows]
    offsets = [bb / top for (_, bb), top in zip(rows, tops, strict=True)]
    return _normalised(_direction_floats([a for a, _ in rows], tops),
                       [(x.numerator, x.denominator) for x in offsets], "a facet")


def _normalised(D: np.ndarray, offsets: list[tuple[int, int]], what: str
                ) -> tuple[np.ndarray, np.ndarray]:
    """The rows D / ‖D‖ and their offsets p/q / ‖D‖ (``offsets``: integer pairs (p, q),
    q > 0), for rows D of directions a / t and offsets b / t (any t > 0)."""
    norm = np.linalg.norm(D, axis=1)
    return D / norm[:, None], _unit_offsets(offsets, norm, what)


def _unit_offsets(offsets: list[tuple[int, int]], norms: np.ndarray, what: str) -> np.ndarray:
    """b / ‖a‖ for exact offsets b = p/q (integer pairs, q > 0) and the float norms of
    their rows, each rounded once from the exact quotient: it overflows only when the
    plane's distance from the origin does, and then no float row can state it —
    InputError naming ``what``."""
    try:
        return np.array([p * den / (q * num)  # int / int, rounded once
                         for (p, q), (num, den) in zip(offsets, map(float.as_integer_ratio,
                                                                     norms.tolist()),
                                                        strict=True)],
                        dtype=np.float64)
    except OverflowError:
        raise InputError(f"X: {what} of the safe kernel lies farther than 1.8e308 from the "
                         "origin, so its float row cannot be represented; translate X "
                         "towards the origin") from None


def safe_kernel(X: Any, F: Any) -> SafeKernel:
    """Ψ(X, F) = ⋂ {conv(S) : S ⊆ X, |S| = n − F}, exactly, with a certificate.

    Parameters
    ----------
    X : array (n, d) of finite floats (a multiset: duplicates count).
    F : integer, 0 ≤ F < n.

    Returns
    -------
    SafeKernel

    Notes
    -----
    Ψ(X, F) is the Tukey-depth region of depth ≥ F + 1, the intersection of the
    halfspaces bounded by hyperplanes through k affinely independent points of X with
    at most F points strictly outside (k = dim aff X), so the work is O(n^{k+1})
    side tests (numba, float-filtered, exact integers when undecided) plus an exact
    clipping of the bounding box. Nonempty when n ≥ (d+1)F + 1 (Helly).

    Examples
    --------
    >>> import rescon
    >>> K = rescon.safe_kernel([[0, 0], [1, 0], [1, 1], [0, 1]], 1)
    >>> K.dim, K.vertices.tolist()
    (0, [[0.5, 0.5]])
    >>> rescon.safe_kernel([[0, 0], [1, 0], [0, 1]], 1).is_empty
    True
    """
    t0 = time.perf_counter()
    Xa = check_points(X)
    n, d = Xa.shape
    F = check_F(F, n)
    quick = empty_certificate(Xa, F) if n <= (d + 1) * F else None
    if quick is not None:  # a few directional halfspaces already prove Ψ = ∅
        cert, halfspaces = quick
        return SafeKernel(Xa, F, -1, np.zeros((0, d)), np.zeros((0, d)), np.zeros(0), None,
                          np.zeros((0, d)), np.zeros((0, d)), np.zeros(0),
                          time.perf_counter() - t0, (), _Exact((), tuple(halfspaces), ()),
                          lambda: cert)
    P = exact_points(Xa)
    hull = affine_hull(P)
    eqs = tuple(hull.equalities(P))
    if hull.dim == 0:
        poly = None
        point = P.fraction(0)
        verts = _Deferred(lambda: (point,))
        order: list[int] = []
        constraints: tuple | _Deferred = ()
        V = np.array([[float(v) for v in point]])
    else:
        poly = _clip(P, hull, F)
        verts, order, V = _lifted_vertices(poly, hull, P)
        incidence = poly.incidence()
        sizes = {h: len(members) for h, members in incidence.items()}
        # one constraint per halfspace: the fast path keeps every row (through other
        # data points) that states the same primitive (a, b)
        first = {(tuple(poly.a[h]), poly.b[h]): h for h in sorted(incidence, reverse=True)}
        incidence = {h: incidence[h] for h in sorted(first.values())}
        constraints = _ambient_rows(poly, hull, list(incidence), P.scale, d)
    if not len(V):
        exact = _Exact((), constraints, eqs)
        return SafeKernel(Xa, F, -1, np.zeros((0, d)), np.zeros((0, d)), np.zeros(0), None,
                          np.zeros((0, d)), np.zeros((0, d)), np.zeros(0),
                          time.perf_counter() - t0, (), exact,
                          lambda: _empty_certificate(Xa, F, hull, poly, P.scale, d))
    if poly is not None and hull.dim == d and poly.dim() == d:  # no exact vertex needed
        dim, origin, basis, Aeq, beq, kernel_eqs = _full_affine(V[0].copy(), d)
    else:
        dim, origin, basis, Aeq, beq, kernel_eqs = _affine_of(verts.get(), d, False)
    facets: tuple | _Deferred = ()
    A, b = _unit_rows([], d)
    if poly is not None:
        ids, D, tops = _facet_order(poly, hull, _relative_facets(poly, incidence, sizes, dim), d)
        facets = _ambient_rows(poly, hull, ids, P.scale, d)
        constraints = _ambient_rows(poly, hull, _needed_rows(poly, incidence, ids),
                                    P.scale, d)
        if kernel_eqs:
            A, b = _unit_rows(_along_hull(list(facets.get()), kernel_eqs, verts.get()[0]), d)
        elif ids:
            A, b = _normalised(D, [(poly.b[h], P.scale * top) for h, top in zip(ids, tops)],
                               "a facet")
    exact = _Exact(verts, constraints, eqs, facets, kernel_eqs)

    def certificate() -> dict[str, Any]:
        return {"rescon_certificate": 1, "kind": "safe_kernel", "points": Xa.tolist(),
                "F": F, "dim": dim,
                "vertices": [[fraction_str(v) for v in x] for x in verts.get()],
                "equalities": halfspaces_json(eqs),
                "facets": halfspaces_json(exact.constraints),
                "adjacency": _adjacency(poly, order, verts.get(), exact.constraints),
                "proof": {"method": "halfspaces"}}

    return SafeKernel(Xa, F, dim, V, A, b, origin, basis, Aeq, beq,
                      time.perf_counter() - t0, verts, exact, certificate)


def _lifted_vertices(poly: ExactPolytope, hull: AffineHull, P: ExactPoints
                     ) -> tuple[_Deferred, list[int], np.ndarray]:
    """The vertices of Ψ in the original coordinates, exactly (from the homogeneous
    scaled-integer vertices (w, y) of the clipped polytope: x = y / (w · scale)), in
    lexicographic order — independent of how the polytope was built and of a scaling
    of X by 2^j, as is then everything computed from them in floats (origin, basis,
    the guides' frame) — built when first read. Also ``order``: the polytope's index
    of each vertex returned, and the vertices' correctly rounded floats (in that
    order)."""
    if hull.dim == len(P.ints[0]):  # the pivot coordinates are all of x
        def exact(i: int) -> tuple[Fraction, ...]:
            w, *ys = poly.verts[i]
            return tuple(Fraction(y, w * P.scale) for y in ys)

        V = _scaled_floats(poly, P.scale)
        order = _lex_order(V, exact)
        return _Deferred(lambda: tuple(map(exact, order))), order, V[order]
    pts = [hull.lift(P, tuple(Fraction(v, P.scale) for v in y))
           for y in poly.fraction_vertices()]
    order = sorted(range(len(pts)), key=lambda i: _lex_key(pts[i]))
    verts = tuple(pts[i] for i in order)
    return _Deferred(lambda: verts), order, np.array(
        [[float(v) for v in x] for x in verts]).reshape(len(verts), len(P.ints[0]))


def _scaled_floats(poly: ExactPolytope, scale: int) -> np.ndarray:
    """The vertices y / (w · scale), correctly rounded: the polytope's own float
    vertices when its unit is ``scale``, else one int / int per coordinate."""
    if poly.unit == scale:
        return poly.float_vertices()
    return np.array([[y / (v[0] * scale) for y in v[1:]] for v in poly.verts],
                    dtype=np.float64).reshape(len(poly.verts), poly.k)


def _lex_order(V: np.ndarray, exact: Callable[[int], tuple[Fraction, ...]],
               rows: np.ndarray | None = None, col: int = 0,
               equal: Callable[[list[int], int], bool] | None = None) -> list[int]:
    """The indices of the rows of V (those in ``rows``, by default all) ordered as the
    exact points they round (``exact(i)``) in lexicographic order, V's columns before
    ``col`` being equal on them: correct rounding is monotone (fl(s) < fl(t) implies
    s < t), so the floats of column ``col`` order all rows but those that round alike
    there. A run of those whose exact values are equal too (entries ±1 of directions
    scaled by their largest |entry|) is ordered on the next column in the same way;
    any other run is sorted exactly (by :func:`_lex_key`). ``equal(ids, col)``:
    whether the exact values of column ``col`` are all equal on the rows ids, decided
    without building them (default: by ``exact``)."""
    if rows is None:
        rows = np.arange(len(V))
    order = rows[np.argsort(V[rows, col], kind="stable")]
    first = V[order, col]
    tie = np.flatnonzero(first[1:] == first[:-1])  # order[i] and order[i + 1] tie
    out = order.tolist()
    if not len(tie):
        return out
    # the runs of ties, [lo, hi): each is re-ordered in place, the rest stays
    starts = tie[np.r_[True, tie[1:] != tie[:-1] + 1]]
    ends = tie[np.r_[tie[1:] != tie[:-1] + 1, True]] + 2
    for lo, hi in zip(starts.tolist(), ends.tolist(), strict=True):
        if equal is not None and col + 1 < V.shape[1] and equal(out[lo:hi], col):
            out[lo:hi] = _lex_order(V, exact, order[lo:hi], col + 1, equal)
            continue
        run = {i: exact(i) for i in out[lo:hi]}
        if col + 1 < V.shape[1] and len({x[col] for x in run.values()}) == 1:
            out[lo:hi] = _lex_order(V, exact, order[lo:hi], col + 1, equal)
        else:
            out[lo:hi] = sorted(run, key=lambda i: _lex_key(run[i][col:]))
    return out


def _adjacency(poly: ExactPolytope | None, order: list[int], verts, constraints
               ) -> list[list[int]]:
    """The certificate's edges: those the fast path found while proving closure
    (renumbered as the sorted vertices), else from the incidence
    (:func:`._skeleton.vertex_adjacency`)."""
    if poly is None or poly.edges is None:
        return vertex_adjacency(verts, constraints)
    where = {p: j for j, p in enumerate(order)}
    return [sorted(where[u] for u in poly.edges[p]) for p in order]


def _lex_key(x: tuple[Fraction, ...]) -> tuple:
    """A sort key giving the lexicographic order of x: each coordinate's correctly
    rounded float (monotone: fl(s) < fl(t) implies s < t) before its exact value, so
    Fractions are compared only when the floats tie."""
    return tuple(z for v in x for z in (float(v), v))


def _clip(P: ExactPoints, hull: AffineHull, F: int) -> ExactPolytope:
    """Ψ in the pivot coordinates (scaled integers): the bounding box clipped by
    every valid halfspace. The float filters see the points in units chosen by
    :func:`.exact.float_view` (magnitudes ≤ 2^32 at any scale of the data)."""
    index: dict[tuple[int, ...], int] = {}
    weights: list[int] = []
    rows: list[tuple[int, ...]] = []
    for row in P.ints:
        y = tuple(row[c] for c in hull.coords)
        j = index.setdefault(y, len(rows))
        if j == len(rows):
            rows.append(y)
            weights.append(0)
        weights[j] += 1
    centre = _centre(rows)
    rows = [tuple(v - c for v, c in zip(y, centre, strict=True)) for y in rows]
    return _moved(_clip_rows(rows, weights, P.scale, hull.dim, F), centre)


#: X is clipped about its median only when its distance from the origin exceeds this
#: many times its spread (:func:`_centre`)
CENTRE_MIN_RATIO = 1024


def _centre(rows: list[tuple[int, ...]]) -> list[int]:
    """The integer point c about which Ψ is clipped (Ψ(X − c) = Ψ(X) − c): the
    coordinate-wise median of the rows when every y − c is still a float times the
    scale (odd part < 2^53: what :func:`.exact.float_view` reads exactly), else the
    origin. About it the float rows' offsets are ~ the spread of X, not its distance
    from the origin: states converged at 1 (Ψ ~1e-13 wide) kept no float precision
    and lost the fast path (d = 4, n = 22: 28 s of exact clipping, now 0.6 s). Data
    within CENTRE_MIN_RATIO spreads of the origin lose no precision there (at most
    10 bits of the offsets) and stay put: moving Ψ back costs every vertex's exact
    translation and correctly rounded floats again (cube(5, 30, 4): ~0.1 CPU-s)."""
    cols = list(zip(*rows, strict=True))
    spread = max(max(col) - min(col) for col in cols)
    if max(max(map(abs, col)) for col in cols) <= CENTRE_MIN_RATIO * spread:
        return [0] * len(cols)
    centre = [sorted(col)[len(col) // 2] for col in cols]
    for y in rows:
        for v, c in zip(y, centre, strict=True):
            s = abs(v - c)
            if s and s >> (s & -s).bit_length() - 1 >= 1 << 53:
                return [0] * len(centre)
    return centre


def _moved(poly: ExactPolytope, c: list[int]) -> ExactPolytope:
    """``poly`` translated by c (in place): y = z + c, so a·z ≤ b becomes
    a·y ≤ b + a·c (gcd(a, b) unchanged; a Farkas certificate stays one, as Σ λ_i a_i
    = 0) and a vertex (w, z) becomes (w, z + w c); its floats are recomputed."""
    if not any(c):
        return poly
    poly.b = [b + sum(map(operator.mul, a, c)) for a, b in zip(poly.a, poly.b, strict=True)]
    poly.verts = [(w, *(z + w * cj for z, cj in zip(v, c, strict=True)))
                  for w, *v in poly.verts]
    poly._fv = None
    return poly


#: the pivot rows' columns are brought to one magnitude before clipping
#: (:func:`_column_shifts`) only when their bit lengths differ by more than this: data
#: whose columns lie within a factor 2^8 of each other is clipped as it is
COLUMN_SPREAD_MAX_BITS = 8


def _column_shifts(rows: list[tuple[int, ...]]) -> list[int]:
    """e_j ≥ 0 with 2^{e_j} · max_i |y_ij| of one bit length L = max_j L_j for every
    column j (L_j the bit length of column j's largest |entry|), or all 0 when the
    L_j (of the nonzero columns) differ by at most COLUMN_SPREAD_MAX_BITS."""
    lengths = [max(map(abs, col)).bit_length() for col in zip(*rows, strict=True)]
    top = max(lengths)
    if top - min((L for L in lengths if L), default=top) <= COLUMN_SPREAD_MAX_BITS:
        return [0] * len(lengths)
    return [top - L if L else 0 for L in lengths]


def _clip_rows(rows: list[tuple[int, ...]], weights: list[int], scale: int, k: int,
               F: int) -> ExactPolytope:
    """:func:`_clip` for the distinct pivot rows (scaled integers) and their weights.

    Rows whose columns differ in magnitude by more than 2^COLUMN_SPREAD_MAX_BITS
    (units mixed: metres and millimetres) are clipped with column j shifted left by
    e_j (:func:`_column_shifts`): Ψ(Y D) = Ψ(Y) D for the invertible diagonal
    D = diag(2^{e_j}) (conv, and so every intersection of hulls, is affinely
    equivariant; the weights go with the rows), so the float filters, the Chebyshev
    centre and qhull of the fast path see a round cloud instead of one elongated by
    up to 2^1200 — which they could not certify, leaving seconds of exact clipping —
    and :func:`_unshifted` maps the exact answer back."""
    shifts = _column_shifts(rows)
    if not any(shifts):
        return _clip_rows_as_given(rows, weights, scale, k, F)
    wide = [tuple(v << e for v, e in zip(y, shifts, strict=True)) for y in rows]
    return _unshifted(_clip_rows_as_given(wide, weights, scale, k, F), shifts,
                      float_view(rows, scale)[1])


def _unshifted(poly: ExactPolytope, shifts: list[int], unit: int) -> ExactPolytope:
    """``poly`` ⊂ R^k in the coordinates z'_j = 2^{e_j} z_j (e_j = ``shifts``) mapped
    back to z (in place), exactly: the twin of :func:`_moved` for D = diag(2^{e_j}).

    * a vertex (w, z') — the point z'/w — becomes (2^E w, 2^{E − e_j} z'_j), E = max e_j
      (integers, w > 0 kept: the point z = D⁻¹ z'/w), divided by the gcd of its entries;
    * a row a'·z' ≤ b' is (a'_j 2^{e_j})·z ≤ b' (as a'·Dz = (a'D)·z), divided by
      g = gcd(a'D, b') > 0 to stay primitive — the same primitive (a, b) whichever
      data point's row stated it, which :func:`safe_kernel` dedupes on; box rows
      ±2^{e_j} z_j ≤ ±lo'_j become ±z_j ≤ ±lo_j;
    * a Farkas certificate (λ_i ≥ 0, Σ λ_i a'_i = 0, Σ λ_i b'_i < 0) gets λ_i g_i:
      Σ λ_i g_i a_i = (Σ λ_i a'_i) D = 0 and Σ λ_i g_i b_i = Σ λ_i b'_i < 0;
    * the tight bitsets, their pairs and the edges are unchanged (same rows, same
      vertices, same order: D preserves incidences and adjacency);
    * ``unit`` is :func:`.exact.float_view`'s unit for the unshifted rows (the floats
      y / (w · unit) then lie within its magnitudes, the vertices lying in the rows'
      hull, as for rows clipped as given), the float vertices recomputed from it."""
    top = max(shifts)
    poly.verts = [_divided((w << top, *(z << top - e for z, e in zip(v, shifts, strict=True))))[0]
                  for w, *v in poly.verts]
    rows = [_divided((*(x << e for x, e in zip(a, shifts, strict=True)), b))
            for a, b in zip(poly.a, poly.b, strict=True)]
    poly.a = [row[:-1] for row, _ in rows]
    poly.b = [row[-1] for row, _ in rows]
    if poly.farkas is not None:
        poly.farkas = Farkas(poly.farkas.ids, tuple(
            lam * rows[i][1] for i, lam in zip(poly.farkas.ids, poly.farkas.multipliers,
                                               strict=True)))
    poly.unit, poly._fv = unit, None
    return poly


def _divided(row: tuple[int, ...]) -> tuple[tuple[int, ...], int]:
    """The integer row divided by g = gcd of its entries (> 0), and g."""
    g = math.gcd(*row)
    return (tuple(v // g for v in row), g) if g > 1 else (row, 1)


def _clip_rows_as_given(rows: list[tuple[int, ...]], weights: list[int], scale: int, k: int,
                        F: int) -> ExactPolytope:
    """:func:`_clip_rows` on the rows as they are."""
    Yf, unit, exact_view = float_view(rows, scale)
    H = valid_halfspaces(Yf, rows, np.array(weights), F, exact_view)
    lo = [min(y[j] for y in rows) for j in range(k)]
    hi = [max(y[j] for y in rows) for j in range(k)]
    first = np.flatnonzero(H.outside == F)
    # Ψ may be empty (n ≤ (k+1)F) and clipping is costly (k ≥ 4, where the fast path
    # does not apply): the LP's Farkas first (for k ≤ 3 the emptiness certificates
    # already meet their target: measured max 7 ms in d = 3, no need)
    if k >= 4 and sum(weights) <= (k + 1) * F:
        empty = empty_from_halfspaces(H, k)
        if empty is not None:
            return empty
    if k >= 2 and len(H) >= FAST_PATH_MIN_HALFSPACES:
        fast = certified_kernel(H, k, unit, first)
        if fast is not None:
            return fast
    poly = ExactPolytope.box(lo, hi, unit)
    clip_to_fixpoint(poly, H, unit, first=first)
    return poly


def _direction_floats(rows, tops=None) -> np.ndarray:
    """Nonzero rational rows as floats, each divided exactly by its largest |entry|
    (``tops``, computed when not given) first (entries in [−1, 1]: no overflow, and tiny
    rows keep their precision) — for rows that stand for directions, whose length is
    free. Each entry is v / top correctly rounded, as float(v / top), but from one
    division of integers (Python's int / int) instead of a reduced Fraction."""
    if tops is None:
        tops = [_max_abs(row) for row in rows]
    return np.array([[v.numerator * top.denominator / (v.denominator * top.numerator)
                      for v in row] for row, top in zip(rows, tops, strict=True)],
                    dtype=np.float64).reshape(len(rows), -1)


def _full_affine(origin: np.ndarray, d: int):
    """:func:`_affine_of` for d-dimensional vertices whose first is ``origin``."""
    return d, origin, np.eye(d), np.zeros((0, d)), np.zeros(0), ()


def _max_abs(row) -> Fraction | int:
    """max_j |row_j| of rational entries, compared as integers when all are integral
    (Fraction's own comparisons are Python code: ~1 µs each)."""
    if all(v.denominator == 1 for v in row):
        return max(abs(v.numerator) for v in row)
    return max(map(abs, row))


def _affine_of(verts, d: int, full: bool):
    """dim, origin, orthonormal basis and equalities (floats, and exact) of
    aff(vertices); ``full``: already known to be d-dimensional."""
    v0 = verts[0]
    if full:
        return _full_affine(np.array([float(v) for v in v0]), d)
    diffs = [[vi - v0i for vi, v0i in zip(v, v0, strict=True)] for v in verts[1:]]
    ns = nullspace_exact(diffs) if diffs else [
        [Fraction(int(i == j)) for i in range(d)] for j in range(d)]
    dim = d - len(ns)
    origin = np.array([float(v) for v in v0])
    if dim == 0:
        basis = np.zeros((0, d))
    else:
        _, _, vt = np.linalg.svd(_direction_floats(diffs), full_matrices=False)
        basis = vt[:dim]
    kernel_eqs = tuple((tuple(row), sum(r * v for r, v in zip(row, v0, strict=True)))
                       for row in ns)
    if ns:
        Aeq = _direction_floats(ns)
        norms = np.linalg.norm(Aeq, axis=1)
        Aeq /= norms[:, None]
        beq = _unit_offsets([(x.numerator, x.denominator) for x in
                             (b / max(map(abs, a)) for a, b in kernel_eqs)], norms,
                            "the affine hull")
    else:
        Aeq, beq = np.zeros((0, d)), np.zeros(0)
    return dim, origin, basis, Aeq, beq, kernel_eqs


def _relative_facets(poly: ExactPolytope, incidence: dict[int, list[int]],
                     sizes: dict[int, int], dim: int) -> list[int]:
    """The constraints h (keys of ``incidence``, increasing) whose faces
    F_h = {v : h tight at v} are facets of Ψ relative to its affine hull; ``sizes``:
    the number of vertices tight on each row of ``poly`` (every row tight somewhere).

    Every facet of a polytope {y : a_i·y ≤ b_i} is F_g for some row g that is not an
    implicit equality (tight at every vertex), and F_h of such a row is a proper face,
    so the facets are the F_h maximal under inclusion. The rows g tight at every vertex
    of F_h — the AND of those vertices' exact tight sets — have F_g ⊇ F_h; so F_h is a
    facet iff each of them has F_g = F_h (as many vertices) or is an implicit equality.
    A combinatorial test on the exact incidences: no rank is computed."""
    if dim == 0:
        return []
    nv = len(poly.verts)
    tight = poly.tight
    out = []
    for h, members in sorted(incidence.items()):
        m = len(members)
        if m < dim or m == nv:  # a facet has ≥ dim vertices; h is an implicit equality
            continue
        common = functools.reduce(operator.and_, map(tight.__getitem__, members))
        if all(sizes[g] == m or sizes[g] == nv for g in _bits(common)):
            out.append(h)
    return out


def _facet_order(poly: ExactPolytope, hull: AffineHull, ids: list[int], d: int
                 ) -> tuple[list[int], np.ndarray, list[int]]:
    """The rows ``ids`` ordered by their ambient directions a / max|a_j|
    (lexicographic, exact) — an order that does not depend on how the polytope was
    built, nor on a scaling of X by 2^j (so neither do the rows A, b, nor the float
    guides that read them) — with those directions as floats (each entry a_j / top
    correctly rounded, int / int) and the tops max|a_j|, in that order."""
    rows = [_scattered(poly.a[h], hull.coords, d) for h in ids]
    tops = [max(map(abs, a)) for a in rows]
    D = np.array([[v / top for v in a] for a, top in zip(rows, tops, strict=True)],
                 dtype=np.float64).reshape(len(rows), d)
    def equal(run: list[int], col: int) -> bool:  # a_i / t_i = a_0 / t_0, tops t > 0
        a0, t0 = rows[run[0]][col], tops[run[0]]
        return all(rows[i][col] * t0 == a0 * tops[i] for i in run)

    order = _lex_order(D, lambda i: tuple(Fraction(v, tops[i]) for v in rows[i]),
                       equal=equal)
    return [ids[i] for i in order], D[order], [tops[i] for i in order]


def _scattered(a: tuple[int, ...], coords: tuple[int, ...], d: int) -> tuple[int, ...]:
    """The pivot-coordinate row a as an ambient integer row (zeros off ``coords``)."""
    if coords == tuple(range(d)):
        return a
    full = [0] * d
    for t, c in enumerate(coords):
        full[c] = a[t]
    return tuple(full)


def _needed_rows(poly: ExactPolytope, incidence: dict, facets: list[int]) -> list[int]:
    """The constraints that state Ψ: those tight at every vertex (they cut out aff Ψ
    within aff X) and the relative ``facets``. A polytope is the intersection of its
    facets within its affine hull, and each vertex is the meet of the facets through
    it, so the rows tight only on smaller faces (the fast path's extra supporting
    planes at degenerate vertices) are redundant — the certificate leaves them out."""
    nv = len(poly.verts)
    return [h for h, members in sorted(incidence.items()) if len(members) == nv] + facets


def _ambient_rows(poly: ExactPolytope, hull: AffineHull, hs: list[int], scale: int, d: int
                  ) -> _Deferred:
    """The rows ``hs`` of ``poly`` as ambient halfspaces (Fractions, :func:`_ambient`),
    built on first read (most callers read only the float rows A, b)."""
    return _Deferred(lambda: tuple(_ambient(hull, d, poly.a[h], poly.b[h], scale)
                                   for h in hs))


def _empty_certificate(Xa, F, hull, poly, scale, d) -> dict[str, Any]:
    far = poly.farkas
    assert far is not None
    hs = [_ambient(hull, d, poly.a[i], poly.b[i], scale) for i in far.ids]
    return {"rescon_certificate": 1, "kind": "kernel_empty", "points": Xa.tolist(), "F": F,
            "halfspaces": halfspaces_json(hs),
            "multipliers": [fraction_str(x) for x in far.multipliers],
            "equalities": [], "eq_multipliers": []}


def kernel_point(X: Any, F: Any, *, method: str = "project", backend: str = "auto",
                 target: Any = None) -> tuple[np.ndarray, dict[str, Any]]:
    """A canonical point of Ψ(X, F) and its ``kernel_point`` certificate.

    Parameters
    ----------
    X, F : as for :func:`safe_kernel`.
    method : ``"project"`` — the unique point of Ψ closest to ``target`` (default the
        mean of X), argmin ‖x − target‖² over Ψ; ``"chebyshev"`` — the centre of the
        largest ball in Ψ within its affine hull (not unique in general);
        ``"vertex-mean"`` — the mean of Ψ's vertices.
    backend : QP/LP backend that guides the exact computation ("auto": clarabel for
        the QP, HiGHS for the LP; or any name of
        :func:`rescon.models.kernel_models.qp_backends`). The returned point is exact
        (KKT conditions checked in rationals), so it does not depend on the backend.
    target : a point of R^d for ``"project"``.

    Returns
    -------
    (x, certificate) : x as floats (rounded from the exact rational point that the
        certificate states).

    Raises
    ------
    EmptyKernel
        Ψ(X, F) = ∅ (the kernel's ``kernel_empty`` certificate proves it).

    Examples
    --------
    >>> import rescon
    >>> x, cert = rescon.kernel_point([[0, 0], [4, 0], [0, 4], [1, 1]], 1)
    >>> x.tolist(), cert["kind"]
    ([1.0, 1.0], 'kernel_point')
    """
    return safe_kernel(X, F).point(method, backend=backend, target=target)


#: what :func:`kernel_points` does with an empty kernel
ON_EMPTY = ("raise", "nan")


def kernel_points(batch: Any, F: Any, *, method: str = "project", backend: str = "auto",
                  on_empty: str = "raise") -> np.ndarray:
    """:func:`kernel_point` for many point sets at once: ``batch`` is (B, n, d) or a
    list of (n_i, d) arrays of one dimension d; returns the (B, d) points (certificates
    are dropped).

    ``on_empty``: ``"raise"`` — an empty Ψ(batch[i], F) raises EmptyKernel naming i;
    ``"nan"`` — its row is NaN and the others are computed (``np.isnan(out[:, 0])``
    is the mask of the empty ones). A malformed item, or one whose dimension differs
    from batch[0]'s, is an InputError naming it."""
    if on_empty not in ON_EMPTY:
        raise InputError(f"on_empty must be one of {', '.join(ON_EMPTY)}; got {on_empty!r}")
    check_choice(method, backend)  # also when no item calls a solver
    try:
        items = list(batch)
    except TypeError:
        raise InputError(f"batch must be a (B, n, d) array or a list of (n, d) arrays; got "
                         f"{type(batch).__name__}") from None
    if not items:
        raise InputError("batch must hold at least one point set; got none")
    sets = [check_points(X, name=f"batch[{i}]") for i, X in enumerate(items)]
    d = sets[0].shape[1]
    for i, X in enumerate(sets):
        if X.shape[1] != d:
            raise InputError(f"batch[{i}] has dimension {X.shape[1]}, batch[0] has {d}: "
                             f"every point set of a batch must have the same dimension")
    out = np.full((len(sets), d), np.nan)
    for i, X in enumerate(sets):
        try:
            out[i] = kernel_point(X, F, method=method, backend=backend)[0]
        except EmptyKernel as exc:
            if on_empty == "raise":
                raise EmptyKernel(f"batch[{i}]: {exc}") from None
    return out
