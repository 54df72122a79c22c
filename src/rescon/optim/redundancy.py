"""r-redundancy of convex costs (SPEC §4): :func:`check_redundancy`.

Definition: the costs f_1, …, f_N are r-redundant when every subset S of N − r agents
has the same argmin set A_S = argmin Σ_{i∈S} f_i. If that common set is nonempty, the
whole set's argmin A* equals it (Σ_all f_i is a positive multiple of Σ_S Σ_{i∈S} f_i, a
sum of functions sharing the minimisers A), so

    r-redundant  ⇔  every A_S is empty, or every A_S equals A* ≠ ∅,

decided with C(N, r) comparisons against the one reference A*. A refutation needs an
(N − r)-subset S1 with a minimiser x1 and a set S2 (another (N − r)-subset or all
agents) with x1 ∉ A_S2 (x1 ∈ A_S1 ≠ ∅ would force A_S2 = A_S1 under redundancy).

Exact verdicts (``exact=True``, with a certificate ``rescon check`` verifies) when the
sums are piecewise quadratic (:mod:`rescon.optim._pq`: quadratics, affine functions,
|aᵀx − b|, hinge, ‖·‖₁, ‖·‖∞ of affine maps, max of affine functions, sums, scalings):

* each A_S is computed by Clarabel and then *certified* in rationals (a minimiser and
  multipliers, or a recession direction when the sum is unbounded below). Clarabel
  solves in the frame x = c + s·y (c the median of the terms' kinks and centres, exact
  to the last bit even where no float is (10^50), s their spread: :func:`_centred`;
  the data transformed exactly), so argmins at 1e-7 or 1e50 are solved at unit
  scale; an uncertified solution is re-solved centred on itself, 2^20 times
  finer (``ZOOMS`` times). The certificate alone decides: thresholds and roundings
  only choose what is tried. A strongly convex sum (H ≻ 0, exactly) is never taken
  as unbounded below;
* x ∉ A_S2 is proved by exact evaluation: F_S2(y) < F_S2(x) for a certified y ∈ A_S2,
  or F_S2 unbounded below; x is the certified minimiser of S1 or an exact vertex of
  its certified argmin (the support points below);
* equality is proved when the certified argmins have the same canonical description:
  the affine set E (reduced row echelon form and a common point) and the inequalities
  that cut it, reduced modulo E and normalised (:mod:`rescon.optim._pq`) — always the
  case for equal single points and affine subspaces (quadratics), and for polyhedra
  described by the same inequalities; equal polyhedra whose descriptions differ by a
  redundant inequality get a numerical verdict.

Everything else is numerical (``exact=False``): support functions h_A(u) = max_{x∈A} uᵀx
in the fixed directions ±e_i and ±u_j (j < d, u_j seeded Gaussian unit vectors, seed 0),
from Clarabel via CVXPY (min F_S, then max uᵀx on {F_S ≤ F_S* + 1e-10(V + |F_S*|)},
F_S* the value at the minimiser found, V below; the support problem compiled once per
sum, only its objective changing with u) or,
for certified polyhedral argmins, from HiGHS on their canonical faces (centred and
scaled), each support point then made exact on the faces it makes tight; when one of
the two sets is not certified, also the distance from each set's minimiser to the other
set (Clarabel; supports are +inf in every direction on sets such as parallel lines).
Sets agree when every support and distance differs by at most ``tolerance`` = 1e-4
(s + the largest |h(u) − uᵀc| and ‖x − c‖∞ of the minimisers), (c, s) the frame below
(s the power of two nearest the spread of the kinks and centres around c, 1 when they
all coincide): the same verdict wherever the costs sit and whatever the unit of x
(scaling x by t scales the gap by t and the tolerance by t up to the rounding of s to
a power of two). The level sets' slack is relative to the sum's values: F_S is divided
by V, the power of two nearest max_j |F_S(c ± s·e_j) − F_S(c)| (its variation over the
frame; 1 when that is 0), before solving, so scaling the costs' values changes
nothing; each cost enters as f_i/κ_i with weight κ_i/V (κ_i the power of two nearest
its largest |value| at y = 0, ±e_j; the division done on its data where f_i is
positively homogeneous in them), so that after a power-of-two change of units
(f ↦ t·f(x/t), or values times t) Clarabel solves the very same numbers and the
verdict, gap and tolerance scale exactly. Clarabel is retried with other settings
(``RETRIES``) when it stalls. CVXPY solves in the same frame as
Clarabel (x = c + s·y, the atoms' data transformed exactly; Huber rows and log-sum-exp
pieces count as kinks for c and s), so costs far from the origin are solved at unit
scale. The ``gap`` is then the largest of them — a lower bound on the
Hausdorff distance (exact for single points and affine sets).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import sys
import warnings
from collections.abc import Hashable, Iterator, Mapping
from dataclasses import dataclass, field
from fractions import Fraction
from typing import Any

import numpy as np

from .. import _validate
from ..errors import InputError, SolverError
from ..geometry.exact import fraction_str
from . import _pq
from .cost import cost

__all__ = ["RedundancyReport", "check_redundancy"]

REL_TOL = 1e-4  # numerical verdicts: supports agree to REL_TOL (s + max |h − uᵀc|)
LEVEL_TOL = 1e-10  # numerical supports: on {F/V ≤ F*/V + LEVEL_TOL (1 + |F*/V|)}; a
# quadratic bottom then widens each set by ~1e-5·s, well inside REL_TOL·s
MAX_PAIRS = 5_000  # pairs of certified subsets tried for an exact witness
ZOOMS = 3  # re-solves centred at an uncertified solution, each 2^20 times finer
RETRIES = ({}, {"equilibrate_enable": False}, {"static_regularization_enable": False})
# Clarabel's settings on the numerical path, tried in turn while it fails (thin level
# sets and unbounded supports can stall its default settings: InsufficientProgress)


@dataclass(frozen=True)
class RedundancyReport:
    """The answer of :func:`check_redundancy`.

    Attributes
    ----------
    holds : whether every (N − r)-subset has the same argmin set
    exact : whether the verdict is proven in exact arithmetic (its certificate is then
        verified by ``rescon check``); False: a numerical verdict within ``tolerance``
    witness : for a violation, JSON-ready: ``subsets`` [S1, S2] (agent labels; S2 may be
        all agents), ``direction`` u, ``support`` [value for S1, value for S2],
        ``points`` [x1, x2] attaining them (x2 None when S2's sum is unbounded below),
        ``exact``, ``reason``. For exact witnesses u = x1 − x2 and the values are uᵀx1,
        uᵀx2 (the support values when both argmins are single points); for numerical
        ones, the support values in the direction where they differ most. None if holds.
    gap : the largest distance found between a subset's argmin and the whole set's
        (inf when exactly one of them is empty, or past the float range): the ε of
        (r, ε)-redundancy; nan for an exact violation whose numerical gap Clarabel
        could not compute (the verdict does not depend on it). Exact witness values
        past the float range are ±inf (the certificate holds them exactly)
    unbounded : the (N − r)-subsets whose sum has no minimiser (tuples of labels)
    unbounded_agents : the agents whose cost alone has no minimiser
    tolerance : of a numerical verdict (None when exact)
    certificate : JSON-ready (kinds ``redundancy_violation``, ``redundancy_holds``,
        ``redundancy_numerical``; see certificates/FORMAT.md)
    """

    holds: bool
    exact: bool
    witness: dict[str, Any] | None
    gap: float
    unbounded: tuple[tuple[Hashable, ...], ...]
    unbounded_agents: tuple[Hashable, ...]
    tolerance: float | None
    certificate: dict[str, Any] = field(repr=False)


def check_redundancy(costs: Any, r: int, *, d: int | None = None) -> RedundancyReport:
    """Decide whether ``costs`` are r-redundant (every N − r of them share their argmin).

    Parameters
    ----------
    costs : mapping agent label → cost (anything :func:`rescon.cost` accepts that is an
        atom tree: an expression string, atoms, a lowered CVXPY expression), or a
        sequence (labels 0, 1, …)
    r : 0 ≤ r < N, the number of agents left out
    d : the dimension (default: the costs')

    Raises
    ------
    InputError
        r ≥ N, a cost of another dimension (naming the agent), a cost that is neither
        piecewise quadratic nor convertible to CVXPY (callables, CasADi); an argmin
        beyond the float range (|x| > 1.8e308) when no exact verdict is found.

    Examples
    --------
    >>> rep = check_redundancy(["(x1 - 1)^2", "(x1 + 1)^2", "2*abs(x1)"], r=1)
    >>> rep.holds, rep.exact, rep.gap
    (True, True, 0.0)
    """
    labels, oracles, d = _costs(costs, d)
    N = len(labels)
    r = _validate.integer("r", r, low=0)
    if r >= N:
        raise InputError(f"r must be an integer < N = {N} (the number of costs); got {r}")
    return _Check(labels, oracles, d, r).run()


def _costs(costs: Any, d: int | None) -> tuple[list[Hashable], list[Any], int]:
    if isinstance(costs, Mapping):
        items = list(costs.items())
    elif isinstance(costs, (list, tuple)):
        items = list(enumerate(costs))
    else:
        raise InputError(f"costs must be a mapping agent → cost or a list; got "
                         f"{type(costs).__name__}")
    if not items:
        raise InputError("costs must hold at least one cost; got none")
    if d is not None:
        d = _validate.integer("d", d, low=1)
    out = [cost(spec, d=d, name=f"cost of agent {label}") for label, spec in items]
    for (label, _), o in zip(items, out):
        if o.d is None:
            raise InputError(f"cost of agent {label}: its dimension is unknown (give d)")
    if d is None:  # expressions may use fewer variables than the others: widen them
        d = max(o.d for o in out)
        out = [cost(spec, d=d, name=o.name) if isinstance(spec, str) else o
               for (_, spec), o in zip(items, out)]
    for (label, _), o in zip(items, out):
        if o.d != d:
            raise InputError(f"cost of agent {label}: dimension {o.d}, not d = {d}")
    return [k for k, _ in items], out, d


# --------------------------------------------------------------------------- #
# one argmin set
# --------------------------------------------------------------------------- #


_Support = tuple[float, "np.ndarray | None", "list[Fraction] | None", "Fraction | None"]
"""h_A(u), a point attaining it (None: unbounded, h = +inf), that point exactly when it
is proven in A, and h exactly as computed (uᵀ of an exact point, or uᵀc + s·h_y of the
numerical path: differences of supports are taken exactly, then rounded once)."""


@dataclass
class _Set:
    """A_S for the agents ``members`` (indices): ``status`` "optimal" / "unbounded" /
    "unknown"; exact data when certified; float point; supports computed on demand."""

    members: tuple[int, ...]
    F: _pq.PQ | None
    status: str = "unknown"
    opt: _pq.Optimal | None = None
    ray: list[Fraction] | None = None
    point: np.ndarray | None = None
    supports: dict[int, _Support] = field(default_factory=dict)

    @property
    def certified(self) -> bool:
        return self.opt is not None or self.ray is not None


class _Check:
    def __init__(self, labels: list[Hashable], oracles: list[Any], d: int, r: int) -> None:
        self.labels, self.oracles, self.d, self.r = labels, oracles, d, r
        self.pq = [_pq.of_oracle(o, d) for o in oracles]
        self.dirs = _directions(d)
        self._cvx: _Cvx | None = None
        self.far: dict[tuple[int, ...], tuple[float, Any, Any]] = {}
        self._centre: tuple[list[Fraction], float] | None = None
        self._framed: dict[int, _pq.PQ] = {}

    # -- computing argmin sets ------------------------------------------------ #

    def argmin(self, members: tuple[int, ...]) -> _Set:
        F = self._sum(members)
        s = _Set(members, F)
        if F is not None:
            self._exact(s)
        if s.status == "unknown":
            s.status, s.point = self.cvx.minimise(members)
            if s.status == "unbounded" and F is not None and _pq.strongly_convex(F):
                raise SolverError(f"Clarabel finds the sum of agents {members} unbounded "
                                  f"below, but it is strongly convex (H ≻ 0, exactly)")
        return s

    def _sum(self, members: tuple[int, ...]) -> _pq.PQ | None:
        if any(self.pq[i] is None for i in members):
            return None
        F = _pq.PQ.zero(self.d)
        for i in members:
            F.add(self.pq[i])
        return F

    def _exact(self, s: _Set) -> None:
        F = s.F
        if not F.blocks and not F.norms:
            s.status, data = _pq.quadratic_argmin(F)
            s.opt, s.ray = (data, None) if s.status == "optimal" else (None, data)
        else:
            c, sc = self.centre
            G = self._framed_sum(s.members)
            status, data = _clarabel(G)
            opt = None
            for zoom in range(ZOOMS + 1):  # y to ~1e-8: zoom in on an uncertified solution
                if status != "optimal":
                    break
                opt = (_pq.certify(F, _floats(c) + sc * data[0], data[1], data[2])
                       or _certify_framed(F, G, c, sc, data))
                if opt is not None or zoom == ZOOMS:
                    break
                c2, s2 = _moved(c, sc, data[0]), sc * 2.0**-20
                G2 = _framed(F, c2, s2)
                st2, data2 = _clarabel(G2)
                if st2 != "optimal":
                    break
                c, sc, G, data = c2, s2, G2, data2
            if status == "optimal":
                s.opt = opt
                if s.opt is not None and not s.opt.describable:
                    s.opt = None  # a norm term with |μ| = 1: not described by linear data
                s.status, s.point = "optimal", _floats(_moved(c, sc, data[0]))
            elif status == "unbounded":
                s.ray = _pq.recession(F, data)
                s.status = "unbounded"
        if s.opt is None and s.ray is None:
            s.status = "unknown"
        elif s.opt is not None:
            s.point = _floats(s.opt.x)

    @property
    def centre(self) -> tuple[list[Fraction], float]:
        """(c, s) of :func:`_centred` (c exact) for Clarabel on the exact path, CVXPY and
        the tolerance, from every cost that is piecewise quadratic or whose
        :func:`_shape` is (Huber, log-sum-exp)."""
        if self._centre is None:
            self._centre = _centred(self._shapes())
        return self._centre

    def _shapes(self) -> _pq.PQ:
        """The sum of the costs' piecewise-quadratic forms, else their :func:`_shape`."""
        F = _pq.PQ.zero(self.d)
        for o, P in zip(self.oracles, self.pq, strict=True):
            P = P if P is not None else _pq.of_oracle(_shape(o), self.d)
            if P is not None:
                F.add(P)
        return F

    def _framed_sum(self, members: tuple[int, ...]) -> _pq.PQ:
        """Σ_{i ∈ members} f_i(c + s·y) (:func:`_framed`, each cost's computed once)."""
        G = _pq.PQ.zero(self.d)
        for i in members:
            if i not in self._framed:
                self._framed[i] = _framed(self.pq[i], *self.centre)
            G.add(self._framed[i])
        return G

    @property
    def cvx(self) -> _Cvx:
        if self._cvx is None:
            self._cvx = _Cvx(self.oracles, self.d, self.centre)
        return self._cvx

    def support(self, s: _Set, k: int) -> _Support:
        """h_{A_S}(u_k) as a :data:`_Support` ((inf, None, None, None): unbounded in u_k)."""
        if k not in s.supports:
            if s.opt is not None:
                s.supports[k] = _poly_support(s.opt, self.dirs[k])
            else:
                h, pt, hq = self.cvx.support(s.members, self.dirs[k])
                s.supports[k] = (h, pt, None, hq)
        return s.supports[k]

    # -- the decision ---------------------------------------------------------- #

    def run(self) -> RedundancyReport:
        N = len(self.labels)
        ref = self.argmin(tuple(range(N)))
        subs = [self.argmin(m) for m in itertools.combinations(range(N), N - self.r)]
        alone = [self.argmin((i,)) for i in range(N)]
        unbounded = tuple(tuple(self.labels[i] for i in s.members) for s in subs
                          if s.status == "unbounded")
        nonempty = [s for s in subs if s.status != "unbounded"]
        odd = [s for s in subs if not self.equal(s, subs[0])]
        wit = self.exact_witness(odd, subs, ref) if odd else None
        try:
            gaps = [0.0 if s.status == "unbounded" and ref.status == "unbounded"
                    else math.inf if "unbounded" in (s.status, ref.status)
                    else self.gap(s, ref) for s in subs]
        except SolverError:
            if wit is None:
                raise
            gaps = [math.nan]  # a proven violation does not wait for the numerical gap
        gap = max(gaps, default=0.0) if nonempty else 0.0
        if not odd:  # every subset certified and equal to the first: the definition
            return self.report(True, True, None, gap, unbounded, alone, subs=subs)
        if wit is not None:
            return self.report(False, True, wit, gap, unbounded, alone)
        tol = self.tolerance(subs + [ref])
        holds = not nonempty or gap <= tol
        wit = None if holds else self.numerical_witness(subs, ref, gaps)
        return self.report(holds, False, wit, gap, unbounded, alone, tol=tol)

    def equal(self, s: _Set, t: _Set) -> bool:
        """A_S = A_T proven exactly: both certified empty, or the same canonical
        description (affine set E and reduced inequalities; sufficient, not necessary
        when a description has redundant inequalities)."""
        if s.ray is not None or t.ray is not None:
            return s.ray is not None and t.ray is not None
        a, b = s.opt, t.opt
        return (a is not None and b is not None and a.rref == b.rref and b.contains(a.x)
                and a.faces == b.faces)

    def gap(self, s: _Set, ref: _Set) -> float:
        """Hausdorff distance of two nonempty argmins: exact formula for affine sets,
        else the largest support difference over the directions — and, where a set is
        not certified and unbounded (a support +∞: the directions include ± each axis,
        so a finite support in each means a bounded set), the distances of the
        minimisers from the other set (:meth:`point_gap`)."""
        a, b = s.opt, ref.opt
        if self.equal(s, ref):
            return 0.0
        if a is not None and b is not None and a.affine and b.affine:
            if a.rref != b.rref:
                return math.inf
            if not a.rref:
                return 0.0
            R = np.array(a.rref, dtype=float)  # distance of parallel affine sets
            diff = np.array([float(u - v) for u, v in zip(a.x, b.x, strict=True)])
            return float(np.linalg.norm(R.T @ np.linalg.lstsq(R.T, diff, rcond=None)[0]))
        supports = [(self.support(s, k), self.support(ref, k)) for k in range(len(self.dirs))]
        sup = max(_difference(a, b) for a, b in supports)
        bounded = all(h[1] is not None for pair in supports for h in pair)
        if (a is not None and b is not None) or bounded:
            return sup
        return max(sup, self.point_gap(s, ref))

    def point_gap(self, s: _Set, ref: _Set) -> float:
        """The distances of each set's minimiser from the other set (numerical, both
        lower bounds on the Hausdorff distance): unlike supports, they see sets that are
        unbounded in every direction tried (parallel lines). The larger one is kept in
        ``self.far`` for the witness."""
        best = (0.0, None, None)
        for t, p in ((ref, s.point), (s, ref.point)):
            if p is not None:
                dist, q = self.cvx.distance(t.members, p)
                if dist > best[0]:
                    best = (dist, p, q)
        self.far[s.members] = best
        return best[0]

    def tolerance(self, sets: list[_Set]) -> float:
        """REL_TOL (s + the largest finite support or coordinate of a minimiser, both
        measured from the frame's centre c: |h(u) − uᵀc|, ‖x − c‖∞), (c, s) the frame of
        :func:`_centred` (s the power of two nearest the spread of the costs' kinks and
        centres around c; 1 when they all coincide): the verdict does not depend on
        where the costs sit, and scaling x by t scales the tolerance by t. InputError
        when a minimiser or a bounded support passes the float range (an exact verdict
        was not reached, and a numerical one has no scale there), or when the tolerance
        is below the normal floats (the costs' kinks within ~1e-304 of each other: the
        frame and the supports have lost precision there)."""
        cq, scale = self.centre
        vals = [abs(_float(hq - _pq._dot([Fraction(float(v)) for v in self.dirs[k]], cq)))
                for s in sets for k, (_, p, _, hq) in s.supports.items() if p is not None]
        vals += [float(np.abs(self._offset(s)).max()) for s in sets if s.point is not None]
        tol = REL_TOL * (scale + max(vals, default=0.0))
        if not math.isfinite(tol):
            raise InputError("check_redundancy: an argmin reaches beyond the float range "
                             "(|x| > 1.8e308) and no exact verdict was found; rescale the "
                             "costs")
        if tol < sys.float_info.min:
            raise InputError(f"check_redundancy: the costs' kinks and argmins lie within "
                             f"{scale:.3g} of each other, below what the numerical path "
                             f"resolves in floats, and no exact verdict was found; rescale x")
        return tol

    def _offset(self, s: _Set) -> np.ndarray:
        """s's minimiser − the centre c: exact then rounded for certified sets, CVXPY's
        unrounded s·y (its frame's centre is c) for the others."""
        cq = self.centre[0]
        if s.opt is not None:
            return _floats([a - b for a, b in zip(s.opt.x, cq, strict=True)])
        if self._cvx is not None and self._cvx.cq == cq and s.members in self._cvx.offsets:
            return self._cvx.offsets[s.members]
        return s.point - np.array([float(v) for v in cq])

    # -- witnesses --------------------------------------------------------------- #

    def exact_witness(self, odd: list[_Set], subs: list[_Set], ref: _Set
                      ) -> dict[str, Any] | None:
        """A certified S1 (minimiser x1) and S2 (a subset or all) with x1 ∉ A_S2, among
        the pairs involving a subset not proven equal to the first (``odd``): against
        the whole set and the first subset, then against every subset (at most
        MAX_PAIRS exact comparisons)."""
        first = [(s, t) for s in odd for t in (ref, subs[0])] + [(subs[0], s) for s in odd]
        rest = ((s, t) for s in odd for t in subs)
        for s1, s2 in itertools.islice(itertools.chain(first, rest), MAX_PAIRS):
            if s1.opt is not None and s2 is not s1 and s2.certified:
                w = _separation(s1, s2)
                if w is not None:
                    return w
        for s1, s2 in first[:MAX_PAIRS // 100]:  # the minimisers found lie in both sets
            w = self.support_separation(s1, s2)
            if w is not None:
                return w
        return None

    def support_separation(self, s1: _Set, s2: _Set) -> dict[str, Any] | None:
        """:func:`_separation` from a support point of A_S1 instead of its minimiser: the
        exact point of the certified argmin attaining each support (:func:`_poly_support`),
        kept when s1's multipliers prove it a minimiser (check_optimal, as the checker
        will) — for polyhedral argmins that are not affine, where both minimisers found
        may lie in both sets."""
        if s1.opt is None or s1.F.norms or s2 is s1 or not s2.certified:
            return None
        for k in range(len(self.dirs)):
            x = self.support(s1, k)[2]
            if x is None:
                continue
            if _pq.check_optimal(s1.F, x, s1.opt.lam, s1.opt.mu) is None:
                w = _separation(dataclasses.replace(s1, opt=dataclasses.replace(s1.opt, x=x)), s2)
                if w is not None:
                    return w
        return None

    def numerical_witness(self, subs: list[_Set], ref: _Set, gaps: list[float]
                          ) -> dict[str, Any]:
        s = subs[int(np.argmax(gaps))]
        if "unbounded" in (s.status, ref.status):
            return {"subsets": [s.members, ref.members], "direction": None,
                    "support": None, "points": [_pt(s.point), _pt(ref.point)],
                    "exact": False, "reason": "one of the two sums is unbounded below"}
        diffs = [_difference(self.support(s, k), self.support(ref, k))
                 for k in range(len(self.dirs))]
        dist, p, q = self.far.get(s.members, (0.0, None, None))
        if dist > max(diffs):
            return {"subsets": [s.members, ref.members], "direction": None, "support": None,
                    "points": [_pt(p), _pt(q)], "exact": False,
                    "reason": f"a minimiser of one sum is at distance {dist:.6g} from the "
                              f"other's argmin (the nearest point second)"}
        k = int(np.argmax(diffs))
        (h1, p1, *_), (h2, p2, *_) = self.support(s, k), self.support(ref, k)
        return {"subsets": [s.members, ref.members], "direction": self.dirs[k].tolist(),
                "support": [h1, h2], "points": [_pt(p1), _pt(p2)], "exact": False,
                "reason": "support functions differ beyond the tolerance"}

    # -- output ----------------------------------------------------------------- #

    def report(self, holds: bool, exact: bool, wit: dict | None, gap: float,
               unbounded: tuple, alone: list[_Set], *, subs: list[_Set] | None = None,
               tol: float | None = None) -> RedundancyReport:
        if exact and not holds:
            cert = self.violation_certificate(wit)
        elif exact:
            cert = self.holds_certificate(subs)
        else:
            cert = self.numerical_certificate(holds, gap, tol)
        if wit is not None:
            wit = dict(wit, subsets=[[self.labels[i] for i in m] for m in wit["subsets"]])
            wit.pop("_proof", None)
        return RedundancyReport(
            holds, exact, wit, gap, unbounded,
            tuple(self.labels[s.members[0]] for s in alone if s.status == "unbounded"),
            tol, cert)

    def _head(self, kind: str) -> dict[str, Any]:
        return {"rescon_certificate": 1, "kind": kind, "d": self.d, "r": self.r,
                "agents": _labels(self.labels)}

    def _costs_json(self) -> list[dict[str, Any] | None]:
        """Every agent's exact cost data; None for costs that are not piecewise
        quadratic (a violation certificate may not need them)."""
        return [None if F is None else
                {"H": [[fraction_str(v) for v in row] for row in F.H],
                 "g": [fraction_str(v) for v in F.g],
                 "blocks": [[[fraction_str(v) for v in (*a, b)] for a, b in blk]
                            for blk in F.blocks],
                 "norms": [[[fraction_str(v) for v in (*a, ci)] for a, ci in zip(A, c)]
                           for A, c in F.norms]} for F in self.pq]

    def violation_certificate(self, wit: dict[str, Any]) -> dict[str, Any]:
        s1, s2, proof = wit["_proof"]
        c = self._head("redundancy_violation")
        c["costs"] = self._costs_json()
        w: dict[str, Any] = {"S1": list(s1.members), "S2": list(s2.members),
                             "x1": _opt_json(s1.opt)}
        if proof == "unbounded":
            w["unbounded"] = [fraction_str(v) for v in s2.ray]
        else:
            w["x2"] = _opt_json(s2.opt)
        c["witness"] = w
        return c

    def holds_certificate(self, subs: list[_Set]) -> dict[str, Any]:
        c = self._head("redundancy_holds")
        c["costs"] = self._costs_json()
        c["subsets"] = [{"agents": list(s.members), **(
            {"unbounded": [fraction_str(v) for v in s.ray]} if s.ray is not None
            else {"x": _opt_json(s.opt)})} for s in subs]
        return c

    def numerical_certificate(self, holds: bool, gap: float, tol: float) -> dict[str, Any]:
        c = self._head("redundancy_numerical")
        c.update(holds=holds, gap=gap if math.isfinite(gap) else None, tolerance=tol,
                 directions=[u.tolist() for u in self.dirs],
                 trusted="numerical support functions (Clarabel/HiGHS floats): the verdict "
                         "is not proven")
        return c


def _separation(s1: _Set, s2: _Set) -> dict[str, Any] | None:
    """x1 = s1's certified minimiser ∉ A_S2: S2 certified unbounded, or x2 = s2's certified
    minimiser with F_S2(x2) < F_S2(x1) (exact values; without norm terms) or x1 outside
    the affine set that x2's certificate proves to be A_S2."""
    x1 = s1.opt.x
    if s2.ray is not None:
        proof: Any = "unbounded"
        u, vals, pts = s2.ray, [_dot_f(s2.ray, x1), None], [x1, None]
    elif s2.opt is not None and _outside(s2, x1):
        proof = s2.opt.x
        u = [a - b for a, b in zip(x1, proof, strict=True)]
        vals, pts = [_dot_f(u, x1), _dot_f(u, proof)], [x1, proof]
    else:
        return None
    return {"subsets": [s1.members, s2.members], "direction": _floats(u).tolist(),
            "support": vals, "points": [None if p is None else _floats(p).tolist() for p in pts],
            "exact": True, "reason": ("the second sum is unbounded below" if proof == "unbounded"
                                      else "x1 minimises the first sum but not the second"),
            "_proof": (s1, s2, proof)}


def _difference(a: _Support, b: _Support) -> float:
    """|h1 − h2| for two supports in one direction: +inf when one is unbounded, 0 when
    both are, else from their exact values, rounded once (no cancellation far from the
    origin; values past the float range included)."""
    if a[1] is None or b[1] is None:
        return 0.0 if a[1] is b[1] else math.inf
    return abs(_float(a[3] - b[3]))


def _outside(s: _Set, x: list[Fraction]) -> bool:
    """x ∉ A_S, exactly, from s's certified minimiser."""
    if not s.F.norms:
        return s.F.value(s.opt.x) < s.F.value(x)
    return not s.opt.contains(x) or s.opt.violates_face(x)


def _dot_f(u: list[Fraction], x: list[Fraction]) -> float:
    return _float(_pq._dot(u, x))


def _float(v: Fraction) -> float:
    """The float nearest v; ±inf beyond the float range (where ``float`` raises
    OverflowError): exact data whose answers pass 1.8e308 still get their exact verdict,
    with such values shown as ±inf (null in JSON)."""
    try:
        return float(v)
    except OverflowError:
        return math.inf if v > 0 else -math.inf


def _floats(x: list[Fraction]) -> np.ndarray:
    return np.array([_float(v) for v in x])


def _pt(p: np.ndarray | None) -> list[float] | None:
    return None if p is None else [float(v) for v in p]


def _labels(labels: list[Hashable]) -> list[int | str]:
    """The certificate's agent labels, distinct (FORMAT.md; agents are named by
    position): integers and strings as they are, other labels as str(x), suffixed
    " #i" (i its position, repeated while taken) when that text is another label's."""
    plain = [isinstance(x, (int, str)) and not isinstance(x, bool) for x in labels]
    out: list[Any] = [x if p else None for x, p in zip(labels, plain, strict=True)]
    taken = {repr(x) for x in out if x is not None}
    for i, x in enumerate(labels):
        if out[i] is None:
            t = str(x)
            while repr(t) in taken:
                t = f"{t} #{i}"
            taken.add(repr(t))
            out[i] = t
    return out


def _opt_json(opt: _pq.Optimal) -> dict[str, Any]:
    return {"x": [fraction_str(v) for v in opt.x],
            "lambda": [[fraction_str(v) for v in lk] for lk in opt.lam],
            "mu": [[fraction_str(v) for v in m] for m in opt.mu]}


def _directions(d: int) -> list[np.ndarray]:
    """±e_i and ±u_j (j < d; u_j Gaussian, seed 0, normalised): 4d directions."""
    U = np.random.default_rng(0).standard_normal((d, d))
    U /= np.linalg.norm(U, axis=1, keepdims=True)
    base = list(np.eye(d)) + list(U)
    return [s * u for u in base for s in (1.0, -1.0)]


# --------------------------------------------------------------------------- #
# numerical solvers
# --------------------------------------------------------------------------- #


def _clarabel(G: _pq.PQ) -> tuple[str, Any]:
    """min ½yᵀHy + gᵀy + Σ t_k + Σ s_l s.t. a_kjᵀy + b_kj ≤ t_k, ‖A_l y − c_l‖ ≤ s_l (G's
    data divided by w, the power of two nearest its largest coefficient: the same λ
    and μ), by Clarabel: ("optimal", (y, λ per block, μ per norm term)), ("unbounded",
    direction) or ("failed", status). Clarabel's duals z satisfy Py + q + Aᵀz = 0, so
    λ = z on the pieces and μ = −(z on a norm cone's residual rows). G is F in the
    frame y = (x − c)/s (:func:`_framed`)."""
    import clarabel
    import scipy.sparse as sp

    f = G.float_data()
    big = max([np.abs(f["H"]).max(initial=0.0), np.abs(f["g"]).max(initial=0.0),
               np.abs(f["A"]).max(initial=0.0)] + [np.abs(A).max(initial=0.0)
                                                   for A, _ in f["norms"]])
    w = float(_pow2(big)) if 0 < big < math.inf else 1.0
    f.update(H=f["H"] / w, g=f["g"] / w, A=f["A"] / w, b=f["b"] / w,
             norms=[(A / w, c / w) for A, c in f["norms"]])
    d, K, L, m = G.d, len(G.blocks), len(G.norms), len(f["b"])
    n = d + K + L
    P = sp.triu(sp.block_diag([sp.csc_matrix(f["H"]), sp.csc_matrix((K + L, K + L))]),
                format="csc")
    q = np.concatenate([f["g"], np.ones(K + L)])
    rows = [sp.hstack([sp.csc_matrix(f["A"]),
                       sp.csc_matrix((-np.ones(m), (np.arange(m), f["block"])), shape=(m, K)),
                       sp.csc_matrix((m, L))])]
    rhs, cones = [-f["b"]], [clarabel.NonnegativeConeT(m)]
    for k, (A, c) in enumerate(f["norms"]):  # (s_k, A_k x − c_k) in the second-order cone
        top = sp.csc_matrix(([-1.0], ([0], [d + K + k])), shape=(1, n))
        rows.append(sp.vstack([top, sp.hstack([sp.csc_matrix(-A),
                                               sp.csc_matrix((len(c), K + L))])]))
        rhs.append(np.concatenate([[0.0], -c]))
        cones.append(clarabel.SecondOrderConeT(len(c) + 1))
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    res = clarabel.DefaultSolver(P, q, sp.vstack(rows, format="csc"), np.concatenate(rhs),
                                 cones, settings).solve()
    status = str(res.status)
    x, z = np.array(res.x), np.array(res.z)
    if status in ("Solved", "AlmostSolved"):
        mus, at = [], m
        for _, c in f["norms"]:
            mus.append(-z[at + 1:at + 1 + len(c)])
            at += len(c) + 1
        return "optimal", (x[:d], [z[:m][f["block"] == k] for k in range(K)], mus)
    if status in ("DualInfeasible", "AlmostDualInfeasible"):
        return "unbounded", x[:d]
    return "failed", status


def _certify_framed(F: _pq.PQ, G: _pq.PQ, c: list[Fraction], s: float, data: tuple
                    ) -> _pq.Optimal | None:
    """:func:`_pq.certify` in the solver's frame (G(y) = F(c + s·y), at its float solution
    y: thresholds and roundings act at the frame's scale), mapped back exactly
    (x = c + s·y, the same λ and μ) and checked against F itself."""
    opt = _pq.certify(G, *data)
    if opt is None:
        return None
    x = [ci + Fraction(s) * yi for ci, yi in zip(c, opt.x, strict=True)]
    return (_pq.describe(F, x, opt.lam, opt.mu)
            if _pq.check_optimal(F, x, opt.lam, opt.mu) is None else None)


def _frame(F: _pq.PQ) -> tuple[np.ndarray, float]:
    """(c, s) centring and scaling F's data: c the coordinate-wise median of the terms'
    anchors, s the power of two nearest their largest distance from c (1 when it is 0;
    the exact path and CVXPY's map their results back exactly). A term's zero set (each
    piece's {aᵀx + b = 0}, the quadratic part's stationary set {Hx = −g}, each norm's
    {A_l x = c_l}) is anchored at its point nearest to p, the least-squares point of all
    of them (rows normalised): anchors then do not depend on where the origin is (the
    point nearest 0 of {x1 = 1e20} in the plane is (1e20, 0), whatever x2 the other
    terms want)."""
    f = F.float_data()
    systems = [(a[None, :], np.array([-bj])) for a, bj in zip(f["A"], f["b"], strict=True)
               if a.any()]
    if f["H"].any():
        systems.append((f["H"], -f["g"]))
    systems += list(f["norms"])
    with np.errstate(all="ignore"):
        systems = [(M[k] / n[k, None], r[k] / n[k]) for M, r in systems
                   if (k := (n := np.linalg.norm(M, axis=1)) > 0).any()]
        p = (np.linalg.lstsq(np.vstack([M for M, _ in systems]),
                             np.concatenate([r for _, r in systems]), rcond=None)[0]
             if systems else np.zeros(F.d))
        P = np.array([p + np.linalg.lstsq(M, r - M @ p, rcond=None)[0]
                      for M, r in systems]).reshape(-1, F.d)
    if not (np.isfinite(p).all() and np.isfinite(P).all()):
        return np.zeros(F.d), 1.0
    c = np.median(P, axis=0) if len(P) else np.zeros(F.d)
    spread = float(np.abs(P - c).max(initial=0.0))
    if not (np.isfinite(c).all() and math.isfinite(spread)):
        return np.zeros(F.d), 1.0
    return c, float(_pow2(spread)) if spread > 0 else 1.0


def _centred(F: _pq.PQ) -> tuple[list[Fraction], float]:
    """(c, s) with c exact, the data centred to the last bit: :func:`_frame` of F(c + y),
    c the sum of the frames' centres so far (floats, so each
    round gains ~53 bits: exact data at 1e50 such as 10^50, which no float is, ends up
    centred within its spread), until the centre found lies within its spread."""
    c = [Fraction(0)] * F.d
    for _ in range(40):
        cf, s = _frame(F)
        if not cf.any():
            break
        c = [a + Fraction(float(v)) for a, v in zip(c, cf, strict=True)]
        F = _framed(F, cf, 1.0)
        if np.abs(cf).max() <= s:
            break
    return c, s


def _framed(F: _pq.PQ, c: Any, s: float) -> _pq.PQ:
    """G(y) = F(c + s·y) up to a constant, exactly (c floats or Fractions, s a power of
    two): H ↦ s²H, g ↦ s(Hc + g), a ↦ s·a, b ↦ aᵀc + b, A_l ↦ s·A_l, c_l ↦ c_l − A_l c.
    Stationarity of G at y is s·stationarity of F at c + s·y with the same λ and μ."""
    cx, sf = [_fraction(v) for v in c], Fraction(s)
    if not any(cx) and sf == 1:
        return F
    return _pq.PQ(
        [[sf * sf * v for v in row] for row in F.H],
        [sf * (_pq._dot(row, cx) + gi) for row, gi in zip(F.H, F.g, strict=True)],
        [[(tuple(sf * v for v in a), _pq._dot(a, cx) + b) for a, b in blk]
         for blk in F.blocks],
        [([tuple(sf * v for v in a) for a in A],
          [ci - _pq._dot(a, cx) for a, ci in zip(A, cl, strict=True)]) for A, cl in F.norms])


def _fraction(v: Any) -> Fraction:
    """A Fraction or a float, exactly."""
    return v if isinstance(v, Fraction) else Fraction(float(v))


def _moved(c: list[Fraction], s: float, y: np.ndarray) -> list[Fraction]:
    """c + s·y exactly (y floats)."""
    return [ci + Fraction(s) * Fraction(float(v)) for ci, v in zip(c, y, strict=True)]


def _pow2(v: float) -> Fraction:
    """The power of two nearest v > 0 (exact)."""
    return Fraction(2) ** max(-1074, min(1023, round(math.log2(v))))


def _log2(v: Fraction) -> int:
    """An exponent e with 2^e within a factor 2 of the Fraction v > 0, in [−1022, 1022]
    (2^±e normal floats; 0 when v = 0)."""
    e = v.numerator.bit_length() - v.denominator.bit_length() if v else 0
    return max(-1022, min(1022, e))


def _pow2_exact(v: Fraction) -> Fraction:
    """A power of two within a factor 2 of the Fraction v > 0, also beyond the float
    range: 2^(bits of the numerator − bits of the denominator)."""
    return Fraction(2) ** (v.numerator.bit_length() - v.denominator.bit_length())


def _poly_support(opt: _pq.Optimal, u: np.ndarray) -> _Support:
    """max uᵀy over the certified argmin E ∩ {n·y ≤ h, the canonical ``faces``}: HiGHS on
    y = x̄ + σz (σ the power of two nearest the largest slack h − n·x̄, so the LP is at
    unit scale whatever the argmin's size and position), then the exact point of the
    argmin on the faces tight at HiGHS's solution (:meth:`_pq.Optimal.point_near`; the
    value is uᵀ of it). Returns a :data:`_Support` (the exact point None when the
    projection fails: then HiGHS's point, its value exact); (inf, None, None, None)
    when unbounded in u."""
    from scipy.optimize import linprog

    x, d = opt.x, len(opt.x)
    uq = [Fraction(float(v)) for v in u]
    if opt.affine and len(opt.rref) == d:
        return _float(h := _pq._dot(uq, x)), _floats(x), x, h
    faces = sorted(opt.faces)
    slack = [f[-1] - _pq._dot(f[:-1], x) for f in faces]
    sigma = _pow2_exact(max(slack)) if any(slack) else Fraction(1)
    rhs = np.array([float(v / sigma) for v in slack])
    N = np.array([[float(v) for v in f[:-1]] for f in faces]).reshape(-1, d)
    R = np.array(opt.rref, dtype=float).reshape(-1, d)
    res = linprog(-u, A_ub=N if len(N) else None, b_ub=rhs if len(N) else None,
                  A_eq=R if len(R) else None, b_eq=np.zeros(len(R)) if len(R) else None,
                  bounds=[(None, None)] * d, method="highs")
    if res.status == 3:
        return math.inf, None, None, None
    if res.status != 0:
        raise SolverError(f"HiGHS could not compute a support value: {res.message}")
    z = np.asarray(res.x)
    guess = [a + sigma * Fraction(float(b)) for a, b in zip(x, z, strict=True)]
    tight = [f for f, nz, h in zip(faces, N @ z, rhs, strict=True)
             if abs(nz - h) <= 1e-7 * (1 + abs(h))]
    y = opt.point_near(tight, guess)
    if y is None:
        return _float(h := _pq._dot(uq, guess)), _floats(guess), None, h
    return _float(h := _pq._dot(uq, y)), _floats(y), y, h


class _Cvx:
    """The numerical path: Σ w_i f_i in CVXPY (w a nonnegative Parameter, so each
    subset re-solves a compiled problem; a sum's 4d support problems share one
    compilation, :meth:`_compiled`) with Clarabel, in the frame x = c + s·y of
    :func:`_centred` (the costs' data transformed exactly, :func:`_to_cvxpy`): costs far
    from the origin or at any scale are solved at unit scale, and the results mapped
    back (points c + s·y, supports uᵀc + s·h_y, distances s·dist). CVXPY costs that
    CVXPY evaluates itself (``.grad``) are used as written: then the frame is (0, 1).
    Each cost enters as f_i/κ_i, κ_i the power of two nearest its largest |f_i| on
    y = 0, ±e_j, evaluated on data divided by 2^e_i ≈ their largest |datum|
    (:func:`_size`) so that no norm's square over- or underflows: κ_i = 2^e_i ·
    (power of two nearest max |f_i/2^e_i|), exactly the same at every magnitude."""

    def __init__(self, oracles: list[Any], d: int, frame: tuple[list[Fraction], float]
                 ) -> None:
        from ..models.backends import require_backend

        require_backend("cvxpy", "model")
        import cvxpy as cp

        self.cp = cp
        xs = {id(g.x): g.x for o in oracles for g in _grad_parts(o)}
        user = next(iter(xs.values())) if len(xs) == 1 else None
        self.cq, self.s = ([Fraction(0)] * d, 1.0) if xs else frame
        self.c = np.array([float(v) for v in self.cq])
        self.x = user if user is not None and user.shape == (d,) else cp.Variable(d)  # y
        self.w = cp.Parameter(len(oracles), nonneg=True)
        e0 = [_log2(_size(o, self.cq, Fraction(self.s))) for o in oracles]
        pre = self._grid([_to_cvxpy(cp, o, self.x, self.cq, Fraction(self.s), Fraction(2) ** e)
                          for o, e in zip(oracles, e0, strict=True)])  # f_i / 2^e0_i
        with np.errstate(all="ignore"):
            self.grid = np.ldexp(pre, e0)  # each cost at y = 0, ±e_j (_variation)
            top = np.abs(pre).max(axis=0, initial=0.0)
        self.unit = [Fraction(2) ** e * (_pow2(v) if 0 < v < math.inf else 1)
                     for e, v in zip(e0, top, strict=True)]
        self.terms = [_to_cvxpy(cp, o, self.x, self.cq, Fraction(self.s), k)
                      for o, k in zip(oracles, self.unit, strict=True)]
        F = sum(self.w[i] * t for i, t in enumerate(self.terms))
        self.u, self.level = cp.Parameter(d), cp.Parameter()
        self.p = cp.Parameter(d)
        self.pmin = cp.Problem(cp.Minimize(F))
        self.psup = cp.Problem(cp.Maximize(self.u @ self.x), [F <= self.level])
        self.pdist = cp.Problem(cp.Minimize(cp.norm(self.x - self.p, 2)), [F <= self.level])
        self.fstar: dict[tuple[int, ...], float] = {}
        self.offsets: dict[tuple[int, ...], np.ndarray] = {}  # minimiser − c, unrounded
        self.scales: dict[tuple[int, ...], float] = {}  # V of each sum (_weights)
        self.posed: tuple[int, ...] | None = None  # whose weights and level are set
        self.compiled: dict[tuple[int, ...], tuple[dict, Any]] = {}  # psup, per sum
        self.cmap: Any = None  # the linear map u ↦ psup's objective vector (_compiled)
        self.cols: np.ndarray | None = None  # y's entries in psup's compiled variables

    def _solve(self, problem: Any, compiled: tuple[dict, Any] | None = None
               ) -> tuple[str, Any]:
        """problem.solve by Clarabel with the settings of RETRIES in turn until it ends
        optimal or unbounded ("inaccurate" warnings are dropped: the verdict is numerical
        anyway); SolverError when no setting gets there (also when CVXPY finds data that
        overflowed to inf). Returns the status and, for ``compiled`` = (data, chain) of
        problem.get_problem_data, Clarabel's own solution: solved by the same
        warm-started Clarabel as problem.solve, without compiling again or unpacking
        into the problem (the status mapped as CVXPY maps it); None otherwise (the
        problem's variables then hold the solution)."""
        why, raw = "", None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            for opts in RETRIES:
                try:
                    if compiled is None:
                        problem.solve(solver="CLARABEL", **opts)
                        status = problem.status
                    else:
                        data, chain = compiled
                        raw = chain.solve_via_data(problem, data, True, False, opts)
                        status = chain.solver.STATUS_MAP.get(str(raw.status), "solver_error")
                except (self.cp.error.SolverError, ValueError) as e:  # ValueError: inf data
                    why = str(e)
                    continue
                if status in _DECIDED:
                    return status, raw
                why = f"status {status}"
        raise SolverError(f"Clarabel failed on the numerical path: {why}")

    def _weights(self, members: tuple[int, ...]) -> None:
        """Weights κ_i/V on ``members`` (0 elsewhere; each term is f_i/κ_i, κ_i its
        ``unit``), V the power of two nearest the sum's variation over the frame,
        max_j |F(±e_j) − F(0)| in y (1 when 0 or not finite): the solved sum is F/V,
        of order 1 whatever the costs' unit, so Clarabel's tolerances and the level
        sets' slack are relative to the costs' values."""
        if members not in self.scales:
            self.scales[members] = self._variation(members)
        w = np.zeros(self.w.size)
        w[list(members)] = [float(self.unit[i] / Fraction(self.scales[members]))
                            for i in members]
        self.w.value = w
        self.posed = None  # the level is not set for these weights

    def _grid(self, terms: list[Any]) -> np.ndarray:
        """Each term's value at y = 0, ±e_j (rows)."""
        d = self.x.shape[0]
        rows = []
        for y in [np.zeros(d), *np.eye(d), *-np.eye(d)]:
            self.x.value = y
            rows.append([_value(t) for t in terms])
        self.x.value = None
        return np.array(rows, dtype=float).reshape(2 * d + 1, len(terms))

    def _variation(self, members: tuple[int, ...]) -> float:
        """V of :meth:`_weights` from each cost's values at y = 0, ±e_j."""
        with np.errstate(all="ignore"):
            F = self.grid[:, list(members)].sum(axis=1)
            v = float(np.abs(F[1:] - F[0]).max())
        return float(_pow2(v)) if 0 < v < math.inf else 1.0

    def _offset(self) -> np.ndarray:
        """s·y at the solution: its x − c, unrounded (x = c + s·y is rounded to c's ulp)."""
        return self.s * np.array(self.x.value, dtype=float)

    def minimise(self, members: tuple[int, ...]) -> tuple[str, np.ndarray | None]:
        self._weights(members)
        self._solve(self.pmin)
        if self.pmin.status in ("unbounded", "unbounded_inaccurate"):
            return "unbounded", None
        at = sum(self.w.value[i] * _value(self.terms[i]) for i in members)
        self.fstar[members] = max(float(self.pmin.value), at)  # F(x*) ≥ min F: a level
        self.compiled.pop(members, None)  # compiled at the previous level
        self.offsets[members] = off = self._offset()
        return "optimal", self.c + off

    def _level(self, members: tuple[int, ...]) -> None:
        """Weights (:meth:`_weights`) and level F* + LEVEL_TOL (1 + |F*|) of the sum over
        ``members`` divided by its V: the slack is LEVEL_TOL (V + |F*|) in the costs'
        values."""
        if self.posed == members:  # set by the previous call (CVXPY validates each set)
            return
        if members not in self.fstar and self.minimise(members)[0] != "optimal":
            raise SolverError(f"Clarabel finds the sum of agents {members} unbounded below, "
                              f"but its argmin was found nonempty")
        self._weights(members)
        f = self.fstar[members]
        self.level.value = f + LEVEL_TOL * (1.0 + abs(f))
        self.posed = members

    def support(self, members: tuple[int, ...], u: np.ndarray
                ) -> tuple[float, np.ndarray | None, Fraction | None]:
        """h(u), a point attaining it and h(u) = uᵀc + s·h_y exactly as computed (None:
        unbounded, h = inf)."""
        status, raw = self._solve(self.psup, self._compiled(members, u))
        if status in ("unbounded", "unbounded_inaccurate"):
            return math.inf, None, None
        y = np.asarray(raw.x, dtype=float)[self.cols]  # the maximiser, and h_y = uᵀy
        h = (_pq._dot([Fraction(float(v)) for v in u], self.cq)
             + Fraction(self.s) * Fraction(float(u @ y)))
        return _float(h), self.c + self.s * y, h

    def _compiled(self, members: tuple[int, ...], u: np.ndarray) -> tuple[dict, Any]:
        """The support problem's Clarabel data and CVXPY's solving chain for the sum over
        ``members`` and the direction u, as CVXPY's solve compiles them: the
        constraints' data (they depend on the weights and the level only, :meth:`_level`)
        compiled once per sum, then only the objective vector c replaced by C·u, C the
        sparse map of CVXPY's compilation from u to c (its columns compiled once, at
        u = e_j). C must be −1 at y_j's column j and 0 elsewhere (max uᵀy compiled as
        min −uᵀz, z_cols = y), else SolverError: then C·u is the very vector CVXPY
        computes and y = z_cols. One compilation per sum instead of one per direction:
        the data Clarabel solves are unchanged."""
        import scipy.sparse as sp

        if members not in self.compiled:
            self._level(members)
            if self.cmap is None:
                C = sp.hstack([sp.csc_array(self._compile(e)[0]["c"].reshape(-1, 1))
                               for e in np.eye(len(u))], format="csc")
                if not ((np.diff(C.indptr) == 1).all() and (C.data == -1).all()
                        and len(set(C.indices)) == len(u)):
                    raise SolverError("CVXPY compiled the support problem's objective uᵀy "
                                      "other than as −uᵀ(y's columns)")
                self.cmap, self.cols = C, C.indices
            data, chain, _ = self._compile(u)
            self.compiled[members] = data, chain
        data, chain = self.compiled[members]
        return {**data, "c": self.cmap @ u}, chain

    def _compile(self, u: np.ndarray) -> tuple[dict, Any, Any]:
        """psup.get_problem_data for Clarabel at the direction u (the weights and level
        as posed)."""
        self.u.value = u
        return self.psup.get_problem_data("CLARABEL", solver_opts={})

    def distance(self, members: tuple[int, ...], p: np.ndarray) -> tuple[float, np.ndarray]:
        """The distance from p to {F ≤ level} for the sum over ``members`` and the
        nearest point."""
        self._level(members)
        self.p.value = np.array([float((Fraction(float(v)) - ci) / Fraction(self.s))
                                 for v, ci in zip(p, self.cq, strict=True)])
        self._solve(self.pdist)
        if self.pdist.status not in ("optimal", "optimal_inaccurate"):
            raise SolverError(f"Clarabel could not compute a distance to the argmin of "
                              f"agents {members}: {self.pdist.status}")
        return self.s * float(self.pdist.value), self.c + self._offset()


_DECIDED = ("optimal", "optimal_inaccurate", "unbounded", "unbounded_inaccurate")


def _value(e: Any) -> float:
    """A CVXPY expression's (or a number's) value at the variables' values; nan when
    it has none."""
    v = e.value if hasattr(e, "value") else e
    return math.nan if v is None else float(v)


def _grad_parts(o: Any) -> Iterator[Any]:
    """The summands CVXPY evaluates itself (``.grad``) in an oracle tree."""
    from . import atoms
    from .cvxpy_adapter import CvxpyGradOracle

    if isinstance(o, CvxpyGradOracle):
        yield o
    for t in getattr(o, "terms", []) if isinstance(o, (atoms.Sum, atoms.MaxOf)) else []:
        yield from _grad_parts(t)
    if isinstance(o, atoms.Scaled):
        yield from _grad_parts(o.term)


def _to_cvxpy(cp: Any, o: Any, y: Any, c: list[Fraction], s: Fraction,
              k: Fraction = Fraction(1)) -> Any:
    """The CVXPY expression of an atom tree at x = c + s·y, divided by k (a power of two),
    up to a constant (none is kept: F* and the level sets do not depend on where the
    origin is), its data transformed exactly before rounding (the rows' A ↦ sA/k,
    b ↦ (b ∓ Ac)/k for the positively homogeneous |·|, norms, hinge and max; a quadratic
    ½(x − m)ᵀQ(x − m) + qᵀx ↦ (½ s² yᵀQy + s(Q(c − m) + q)ᵀy)/k; an affine aᵀx ↦
    s aᵀy/k; Huber, log-sum-exp and ``.grad`` summands times 1/k): no cancellation of
    computing c + s·y in floats, and data of order 1 when k is the term's size. A CVXPY
    summand evaluated by ``.grad`` is used as is when it is written in ``y`` (every CVXPY
    cost in one Variable of shape (d,), frame (0, 1)). InputError for other oracles."""
    from . import atoms
    from .cvxpy_adapter import CvxpyGradOracle

    if isinstance(o, CvxpyGradOracle) and o.x is y:
        return float(1 / k) * o.expr

    def arr(v: Any) -> np.ndarray:
        return np.array(v, dtype=float)

    if isinstance(o, atoms.Sum):
        return sum(_to_cvxpy(cp, t, y, c, s, k) for t in o.terms)
    if isinstance(o, atoms.Scaled):
        return o.coef * _to_cvxpy(cp, o.term, y, c, s, k)
    if isinstance(o, atoms.MaxOf):
        return cp.maximum(*[_to_cvxpy(cp, t, y, c, s, k) for t in o.terms])
    if isinstance(o, atoms.Quadratic):
        M, v = _leaf_data(o, c, s)
        Q = arr([[m / k for m in row] for row in M])
        return (0.5 * cp.quad_form(y, cp.psd_wrap(Q)) if Q.any() else 0) + arr(
            [vi / k for vi in v]) @ y
    if isinstance(o, atoms.Affine):
        return arr([vi / k for vi in _leaf_data(o, c, s)[1]]) @ y
    if isinstance(o, atoms._Rows):  # r = A x ∓ b = sA y + (Ac ∓ b)
        smooth = isinstance(o, (atoms.Huber, atoms.LogSumExp))  # not homogeneous in r
        kr = Fraction(1) if smooth else k
        M, v = _leaf_data(o, c, s)
        r = arr([[m / kr for m in row] for row in M]) @ y + arr([vi / kr for vi in v])
        maps = {atoms.AbsAffine: lambda r: cp.abs(r[0]), atoms.Norm1: cp.norm1,
                atoms.Norm2: lambda r: cp.norm(r, 2), atoms.NormInf: cp.norm_inf,
                atoms.Hinge: lambda r: cp.pos(r[0]), atoms.MaxAffine: cp.max,
                atoms.LogSumExp: cp.log_sum_exp,
                atoms.Huber: lambda r: cp.sum(cp.huber(r, o.M))}
        if type(o) in maps:
            return float(kr / k) * maps[type(o)](r)
    raise InputError(f"{o.name}: check_redundancy needs costs built of atoms (an expression "
                     f"string, atoms) or CVXPY expressions in one Variable of shape (d,); "
                     f"got a {o.kind} oracle")


def _leaf_data(o: Any, c: list[Fraction], s: Fraction
               ) -> tuple[list[list[Fraction]], list[Fraction]]:
    """(M, v), the exact data of a quadratic, affine or rows atom at x = c + s·y:
    ½(x − m)ᵀQ(x − m) + qᵀx = ½ yᵀ(s²Q)y + (s(Q(c − m) + q))ᵀy + const, aᵀx = (s·a)ᵀy +
    const ([], s·a), rows r = Ax ∓ b = (sA)y + (Ac ∓ b)."""
    from . import atoms

    ex = o.exact
    if isinstance(o, atoms.Quadratic):
        shift = [a - b for a, b in zip(c, ex["c"], strict=True)]
        return ([[s * s * v for v in row] for row in ex["Q"]],
                [s * (_pq._dot(row, shift) + qi) for row, qi in zip(ex["Q"], ex["q"],
                                                                     strict=True)])
    if isinstance(o, atoms.Affine):
        return [], [s * v for v in ex["a"]]
    sign = 1 if o.pieces else -1
    return ([[s * v for v in row] for row in ex["A"]],
            [_pq._dot(row, c) + sign * bi for row, bi in zip(ex["A"], ex["b"], strict=True)])


def _size(o: Any, c: list[Fraction], s: Fraction) -> Fraction:
    """max |datum| of an atom tree at x = c + s·y (:func:`_leaf_data`; coef times its
    term's under Scaled, the max over Sum and MaxOf terms; 0 for CVXPY summands), exact:
    the scale :func:`_to_cvxpy` divides the data by before :class:`_Cvx` evaluates them
    in floats, so that no square of a norm over- or underflows."""
    from . import atoms

    if isinstance(o, (atoms.Sum, atoms.MaxOf)):
        return max((_size(t, c, s) for t in o.terms), default=Fraction(0))
    if isinstance(o, atoms.Scaled):
        return o.exact["coef"] * _size(o.term, c, s)
    if isinstance(o, (atoms.Quadratic, atoms.Affine, atoms._Rows)):
        M, v = _leaf_data(o, c, s)
        return max((abs(x) for x in [*itertools.chain.from_iterable(M), *v]),
                   default=Fraction(0))
    return Fraction(0)


def _shape(o: Any) -> Any:
    """An atom tree with the same kinks for :func:`_frame`: Huber rows as |·| rows,
    log-sum-exp as the max of its pieces (piecewise quadratic, so
    :func:`_pq.of_oracle` reads their anchors); other atoms unchanged."""
    from . import atoms

    if isinstance(o, atoms.Huber):
        return atoms.Norm1(o.exact["A"], o.exact["b"])
    if isinstance(o, atoms.LogSumExp):
        return atoms.MaxAffine(o.exact["A"], o.exact["b"])
    if isinstance(o, atoms.Sum):
        return atoms.Sum([_shape(t) for t in o.terms])
    if isinstance(o, atoms.Scaled):
        return atoms.Scaled(o.exact["coef"], _shape(o.term))
    if isinstance(o, atoms.MaxOf):
        return atoms.MaxOf([_shape(t) for t in o.terms])
    return o
