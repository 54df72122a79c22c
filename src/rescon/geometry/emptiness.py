"""Fast emptiness certificates for Ψ(X, F) from a few directional halfspaces.

For a direction u, the halfspace H_u = {x : u·x ≤ β_u}, β_u the (F+1)-th largest of
the values u·x_i (points counted with multiplicity), has at most F points strictly
outside, so Ψ(X, F) ⊆ H_u (fact (a) of certificates/FORMAT.md). When the halfspaces of
a few small-integer directions already have an empty intersection, Farkas
multipliers prove Ψ = ∅ without enumerating the candidate hyperplanes:

1. floats choose β_u, the value of one data point: for small-integer data the values
   are exact (at most F lie strictly above β_u); otherwise a direction whose
   (F+1)-th value is not separated from its neighbours by more than the rounding
   error is skipped, so exactly F points lie strictly above it. The values are taken
   of X / 2^e (max |X| / 2^e in [1/2, 1)), so they cannot overflow at any scale of
   X; the error bound adds the underflow term (entries rounded into the subnormal
   range included), and an inf or NaN separation never counts as separated;
2. the LP max t s.t. u·x + t ≤ β_u (HiGHS) with t* < 0 proposes the directions that
   matter — the support of its dual solution, at most d + 1 of them;
3. exact multipliers λ ≥ 0 with Σ λ_u u = 0, Σ λ_u = 1 are solved in rationals on
   that support, and Σ λ_u β_u < 0 is checked exactly.

Anything else (a kernel that is not empty, or not clearly so for these directions)
returns None and the full algorithm decides. Worth trying only when n ≤ (d+1)F:
above that, Helly's theorem makes Ψ nonempty.
"""

from __future__ import annotations

import functools
import itertools
from fractions import Fraction
from math import gcd
from typing import Any

import numpy as np

from .._rounding import UNIT_ROUNDOFF as _EPS
from .._rounding import underflow_floor
from ._budget import PYTHON_STEP, fits
from .exact import fraction_str, halfspaces_json, solve_exact

#: an exact vector
Vector = tuple[Fraction, ...]

#: component range of the directions tried: {−R..R}^d (primitive vectors), by dimension
_RANGE = {1: 1, 2: 3, 3: 2, 4: 1, 5: 1}
#: share of the budget the directions may take (they are only a shortcut)
QUICK_SHARE = 1 / 64


@functools.lru_cache(maxsize=8)
def _directions(d: int) -> np.ndarray:
    """Primitive integer vectors with components in {−R..R}, one per ray (read-only,
    cached: listing them took ~0.3 ms of a 3-D certificate). (Adding pseudo-random
    directions was measured: slower, and it certified nothing more on the benchmark
    clouds — the kernels it misses are barely empty.)"""
    R = _RANGE.get(d, 1)
    out = [u for u in itertools.product(range(-R, R + 1), repeat=d)
           if any(u) and gcd(*map(abs, u)) == 1]
    U = np.array(out, dtype=np.float64).reshape(len(out), d)
    U.flags.writeable = False
    return U


def _directions_fit(n: int, d: int) -> bool:
    """Whether the (2R+1)^d candidate directions, listed in Python, and the (n, m)
    tables of their values fit in :data:`QUICK_SHARE` of the budget (:mod:`._budget`);
    beyond it the step is skipped — it is only a shortcut (3^16 directions in R^16
    took 10 GB)."""
    m = (2 * _RANGE.get(d, 1) + 1) ** d
    return fits(m * (PYTHON_STEP * d + n * d), m * (64 + 8 * d + 24 * n), QUICK_SHARE)


def empty_certificate(X: np.ndarray, F: int
                      ) -> tuple[dict[str, Any], list[tuple[Vector, Fraction]]] | None:
    """A ``kernel_empty`` certificate for Ψ(X, F) from directional halfspaces and those
    halfspaces (a, b) exactly, or None.

    X: (n, d) finite floats, 0 ≤ F < n."""
    n, d = X.shape
    if n > (d + 1) * F or not _directions_fit(n, d):
        return None
    U = _directions(d)
    top = float(np.abs(X).max())
    Xs = np.ldexp(X, -np.frexp(top)[1]) if top > 0 else X  # max |Xs| in [1/2, 1)
    V = Xs @ U.T  # (n, m)
    Usum = np.abs(U).sum(axis=1)
    err = 4.0 * d * _EPS * Usum * np.abs(Xs).max() + underflow_floor(d, Usum.max())
    if np.all(X == np.round(X)) and top < 2.0**52 / Usum.max():
        err[:] = 0.0  # small integers (exact over 2^e too): exact values, real ties
    order = np.argsort(-V, axis=0, kind="stable")
    ranked = np.take_along_axis(V, order, axis=0)
    beta = ranked[F]
    above = ranked[F - 1] - beta if F > 0 else np.full(len(U), np.inf)
    below = beta - ranked[F + 1] if F + 1 < n else np.full(len(U), np.inf)
    keep = np.flatnonzero(((above > 2 * err) & (below > 2 * err)) | (err == 0.0))
    if len(keep) < d + 1:
        return None
    support = _lp_support(U[keep], beta[keep], Xs.min(axis=0), Xs.max(axis=0),
                          np.median(Xs, axis=0))
    if support is None:
        return None
    rows = keep[support]
    pts = [tuple(Fraction(v) for v in X[order[F, r]]) for r in rows]
    normals = [tuple(Fraction(v) for v in U[r]) for r in rows]
    b = [sum((a * x for a, x in zip(u, p, strict=True)), Fraction(0))
         for u, p in zip(normals, pts, strict=True)]
    lam = _farkas(normals, b, d)
    if lam is None:
        return None
    cert = {"rescon_certificate": 1, "kind": "kernel_empty", "points": X.tolist(), "F": F,
            "halfspaces": halfspaces_json(zip(normals, b)),
            "multipliers": [fraction_str(v) for v in lam], "equalities": [], "eq_multipliers": []}
    return cert, list(zip(normals, b))


def _farkas(normals, offsets, k: int) -> list[Fraction] | None:
    """Exact multipliers λ ≥ 0 with Σ λ_i a_i = 0, Σ λ_i = 1 and Σ λ_i b_i < 0 for the
    halfspaces a_i·x ≤ b_i (integers or Fractions) — a proof that they have no common
    point — or None."""
    M = [[Fraction(a[j]) for a in normals] for j in range(k)] + [[Fraction(1)] * len(normals)]
    lam = solve_exact(M, [Fraction(0)] * k + [Fraction(1)])
    if lam is None or any(v < 0 for v in lam) or \
            sum(v * b for v, b in zip(lam, offsets, strict=True)) >= 0:
        return None
    return lam


def _lp_support(A: np.ndarray, b: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                centre: np.ndarray) -> np.ndarray | None:
    """Rows with a positive dual in max t s.t. a_i·x + ‖a_i‖ t ≤ b_i, when t* < 0 (the
    halfspaces have no common point), else None. lo, hi: the data's box, which
    (widened) bounds x; centre: a deep point, whose nearest rows start the row
    generation (:mod:`._lp`)."""
    from ._lp import max_margin

    norms = np.linalg.norm(A, axis=1)  # cofactor rows can be ~1e-14: unit rows
    if not norms.all():  # a float row rounded to zero: no proposal
        return None
    reach = max(float((hi - lo).max()), 1e-300)
    found = max_margin(A / norms[:, None], b / norms, np.ones(len(b)), lo - reach,
                       hi + reach, centre=centre, stop_below=0.0)
    if found is None or found.t >= 0 or found.bounded_by_box:
        return None
    support = np.flatnonzero(found.duals > 1e-12 * found.duals.max())
    return support if 0 < len(support) <= A.shape[1] + 1 else None


def empty_from_halfspaces(H, k: int):
    """Ψ = ∅ from the valid halfspaces H (:class:`.halfspaces.Halfspaces`, k
    coordinates) before any clipping: the LP proposes at most k + 1 of them, exact
    multipliers on their integer rows make the Farkas certificate. Returns an empty
    :class:`.polytope.ExactPolytope` carrying it, or None (the LP finds a common point,
    or the exact check fails)."""
    from .polytope import ExactPolytope, Farkas

    if len(H) < 2:
        return None
    support = _lp_support(H.af, H.bf, *H.box)
    if support is None:
        return None
    rows = [H.exact(int(h)) for h in support]
    lam = _farkas([a for a, _ in rows], [b for _, b in rows], k)
    if lam is None:
        return None
    P = ExactPolytope(k)
    P.a = [a for a, _ in rows]
    P.b = [b for _, b in rows]
    P.farkas = Farkas(tuple(range(len(rows))), tuple(lam))
    return P
