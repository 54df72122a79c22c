"""Review R2 (hostile inputs for the d = 4-5 safe kernels and the R³ validity monitor):
each test failed before the fix it names, or checks an answer against an independent
exact oracle (Fractions) on small inputs."""

from __future__ import annotations

import math
import warnings
from fractions import Fraction
from itertools import combinations, product

import numpy as np
import pytest

import rescon
from rescon.geometry import kernel as km


def _fast_path_calls(monkeypatch) -> list[bool]:
    """Records, per call of the fast path, whether it certified the kernel."""
    calls: list[bool] = []
    original = km.certified_kernel

    def recorded(*args):
        out = original(*args)
        calls.append(out is not None)
        return out

    monkeypatch.setattr(km, "certified_kernel", recorded)
    return calls


def test_converged_d4_cloud_keeps_the_fast_path(monkeypatch):
    """States converged to a point away from the origin (1 + 1e-13 z): the float
    halfspaces were formed in the data's own coordinates, where Ψ is ~1e-13 wide and
    the rows' offsets ~1, so qhull's proposal could not be certified and Ψ was clipped
    exactly (~28 s, against 0.6 s for the same cloud moved to the origin). Fixed by
    forming them about an integer centre c (Ψ(X − c) = Ψ(X) − c). The answer is the
    translate of the kernel of X − X[0] (exact: Sterbenz)."""
    rng = np.random.default_rng(0)
    X = 1.0 + rng.normal(size=(22, 4)) * 1e-13
    calls = _fast_path_calls(monkeypatch)
    K = rescon.safe_kernel(X, 3)
    assert calls == [True]
    shifted = rescon.safe_kernel(X - X[0], 3)
    x0 = tuple(map(Fraction, X[0].tolist()))
    assert set(K.exact_vertices) == {tuple(v + c for v, c in zip(x, x0, strict=True))
                                     for x in shifted.exact_vertices}


# -- an independent exact oracle: Ψ(X, F) = ⋂ conv(S), |S| = n − F, for small d = 2, 3 --


def _dot(a, b) -> Fraction:
    return sum(x * y for x, y in zip(a, b, strict=True))


def _normal(pts: tuple) -> tuple:
    """A normal of the hyperplane through d points of R^d (d = 2, 3); 0 if degenerate."""
    u, *rest = (tuple(q - p for p, q in zip(pts[0], r, strict=True)) for r in pts[1:])
    if not rest:
        return (u[1], -u[0])
    v = rest[0]
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


def _hull_halfspaces(S: list, d: int) -> set:
    """The facet halfspaces a·x ≤ b of conv S (S full-dimensional), each scaled to
    max |a_j| = 1: hyperplanes through d points with S on one side."""
    out = set()
    for T in combinations(sorted(set(S)), d):
        a = _normal(T)
        if any(a):
            b = _dot(a, T[0])
            side = [_dot(a, p) - b for p in S]
            top = max(map(abs, a))
            for sgn in (1, -1):
                if all(sgn * s <= 0 for s in side):
                    out.add((tuple(sgn * x / top for x in a), sgn * b / top))
    return out


def _solve(rows: list, rhs: list) -> tuple | None:
    """The exact solution of a square system (Gauss–Jordan on Fractions), None if singular."""
    M = [[*r, c] for r, c in zip(rows, rhs, strict=True)]
    k = len(M)
    for i in range(k):
        piv = next((r for r in range(i, k) if M[r][i] != 0), None)
        if piv is None:
            return None
        M[i], M[piv] = M[piv], M[i]
        for r in range(k):
            if r != i and M[r][i] != 0:
                f = M[r][i] / M[i][i]
                M[r] = [x - f * y for x, y in zip(M[r], M[i], strict=True)]
    return tuple(M[i][k] / M[i][i] for i in range(k))


def _kernel_oracle(X: np.ndarray, F: int) -> set:
    """The vertices of ⋂ {conv S : |S| = n − F}: the feasible meets of d independent
    facet planes of the subsets' hulls (every such subset full-dimensional)."""
    P = [tuple(map(Fraction, r)) for r in X.tolist()]
    n, d = X.shape
    H = sorted(set().union(*(_hull_halfspaces([P[i] for i in S], d)
                             for S in combinations(range(n), n - F))))
    V = set()
    for T in combinations(H, d):
        x = _solve([a for a, _ in T], [b for _, b in T])
        if x is not None and all(_dot(a, x) <= b for a, b in H):
            V.add(x)
    return V


@pytest.mark.parametrize("seed", range(8))
def test_kernel_equals_the_subset_hull_oracle_in_the_plane_and_space(seed):
    """Small integer clouds (many collinear / coplanar triples and ties) at 2^-1060
    (subnormal), about 2^48 (an exact translation) and with duplicates: the exact
    vertices are those of the intersection of the C(n, F) subset hulls, and the
    certificate checks."""
    rng = np.random.default_rng(seed)
    d = 2 + seed % 2
    n, F = (8, 2) if d == 2 else (7, 1)
    while True:
        X = rng.integers(-4, 5, size=(n, d)).astype(float)
        X[-1] = X[0]  # a duplicate
        if all(np.linalg.matrix_rank(X[list(S)] - X[S[0]]) == d
               for S in combinations(range(n), n - F)):
            break
    oracle = _kernel_oracle(X, F)
    for scale, shift in ((1.0, 0.0), (2.0**-1060, 0.0), (0.125, 2.0**48)):
        Y = X * scale + shift
        K = rescon.safe_kernel(Y, F)
        moved = {tuple(v * Fraction(scale) + Fraction(shift) for v in x) for x in oracle}
        assert set(K.exact_vertices) == moved
        assert rescon.check_certificate(K.certificate).valid


def _exact_sq_distance(facets: list, V: list, x: tuple) -> Fraction:
    """dist(x, conv V)² for a polytope of R³ with facets a·y ≤ b and vertices V: the
    least ‖x − y‖² over the candidate projections y of x (onto each vertex, each edge's
    line, each facet's plane) that lie in it — the projection is one of them."""
    if all(_dot(a, x) <= b for a, b in facets):
        return Fraction(0)
    on = {v: {i for i, (a, b) in enumerate(facets) if _dot(a, v) == b} for v in V}
    cands = list(V)
    for p, q in combinations(V, 2):
        if len(on[p] & on[q]) >= 2:  # an edge
            e = tuple(s - r for r, s in zip(p, q, strict=True))
            t = _dot(tuple(s - r for r, s in zip(p, x, strict=True)), e) / _dot(e, e)
            cands.append(tuple(r + t * s for r, s in zip(p, e, strict=True)))
    for a, b in facets:
        t = (_dot(a, x) - b) / _dot(a, a)
        cands.append(tuple(s - t * r for s, r in zip(x, a, strict=True)))
    return min(_dot(d, d) for y in cands if all(_dot(a, y) <= b for a, b in facets)
               for d in [tuple(s - r for r, s in zip(y, x, strict=True))])


@pytest.mark.parametrize("kind", ["sphere", "grid", "translated", "tiny"])
def test_monitor_distances_in_space_equal_an_exact_oracle(kind, monkeypatch):
    """The R³ monitor's certified-surface hull (forced on 24 states) on a sphere, an
    integer grid (coplanar facets, points inside facets and edges, duplicates), states
    at 2^40 + a grid of 1/8 (many-digit coordinates) and at 1e-300: 0 exactly for the
    states inside, and for the others within the monitor's own bound of the exact
    distance from the subset-free oracle above (hull facets by brute force)."""
    from rescon.consensus import _initial_hull, metrics

    monkeypatch.setattr(_initial_hull, "PROPOSE_MIN", 8)
    rng = np.random.default_rng(7)
    Z = rng.integers(-2, 3, size=(24, 3)).astype(float)
    X = {"sphere": rng.normal(size=(24, 3)), "grid": Z, "translated": 2.0**40 + Z / 8,
         "tiny": Z * 1e-300}[kind]
    if kind == "sphere":
        X /= np.linalg.norm(X, axis=1)[:, None]
    mon = metrics.ValidityMonitor(X)
    assert "cones" in mon.hull._cache  # the certified surface, not the safe kernel
    P = [tuple(map(Fraction, r)) for r in np.unique(X, axis=0).tolist()]
    facets = sorted(_hull_halfspaces(P, 3))
    V = [p for p in P if sum(_dot(a, p) == b for a, b in facets) >= 3]
    assert set(mon.hull.exact_vertices) == set(V)
    c = X.mean(axis=0)
    S = np.r_[X[:6] * 1.01, c + (X[:6] - c) * 1.5, c + (X[:6] - c) * 0.99, X[:4]]
    dist = mon.distances(S)
    for x, got in zip(S, dist, strict=True):
        exact = _exact_sq_distance(facets, V, tuple(map(Fraction, x.tolist())))
        assert (got == 0) == (exact == 0)
        if exact:
            err = mon.triangle_distances(x[None])[1][0]  # inf: the exact path (a few u)
            err = err if math.isfinite(err) else 0.0
            want = math.sqrt(exact / Fraction(4) ** -498) * 2.0 ** -498 if kind == "tiny" \
                else math.sqrt(exact)
            assert abs(got - want) <= err + 4e-16 * want


def _sqrt(q: Fraction) -> float:
    """√q of a nonnegative Fraction within ~1 ulp at any magnitude (scaled by 4^e)."""
    e = (q.numerator.bit_length() - q.denominator.bit_length()) // 2
    return math.ldexp(math.sqrt(q / Fraction(4) ** e), e) if q else 0.0


@pytest.mark.parametrize("seed", range(3))
def test_diameter_equals_the_exact_one_through_the_calipers_windows(seed, monkeypatch):
    """The plane's diameter through its rotating-calipers pair and antipodal windows
    (forced from 4 kept rows on) on states on a circle (at 1, 1e-300, about 1e15), a
    flat ellipse at 1e300, integer grids (collinear hull points, ties) and a circle with
    its centre repeated: within 4u of √(max exact squared distance) (Fractions)."""
    from rescon.consensus import metrics

    monkeypatch.setattr(metrics, "ANGULAR_MIN", 3)
    rng = np.random.default_rng(seed)
    for n in (5, 12, 40):
        t = rng.uniform(0, 2 * np.pi, n)
        C = np.c_[np.cos(t), np.sin(t)]
        for X in (C, C * 1e-300, C + 1e15, np.c_[C[:, 0], C[:, 1] * 1e-9] * 1e300,
                  rng.integers(-3, 4, size=(n, 2)).astype(float), np.r_[C, np.zeros((3, 2))]):
            P = [tuple(map(Fraction, r)) for r in X.tolist()]
            exact = _sqrt(max(_dot(d, d) for p in P for q in P
                              for d in [tuple(a - b for a, b in zip(p, q, strict=True))]))
            assert abs(metrics.diameter(X) - exact) <= 4 * 2.0**-53 * exact


def test_exact_projection_onto_a_hull_far_from_the_origin(monkeypatch):
    """150 states on a unit sphere about 1e15 (a grid of 1/8): a state one ulp outside
    a vertex raised SolverError ("more than 200000 active sets") — the guides' frame
    took the facets' offsets and the vertices from their floats at 1e15, off by ~ulp
    ≈ a tenth of the hull, so the active sets ranked first were wrong. Fixed by taking
    them from the exact facets and vertices (rounded once, about the frame's centre).
    The projection is the vertex: the distance is 1/8 · √3."""
    from rescon.consensus.metrics import ValidityMonitor

    rng = np.random.default_rng(5)
    rng.integers(0, 4, size=(150, 3))
    X = rng.normal(size=(150, 3))
    X = X / np.linalg.norm(X, axis=1)[:, None] + 1e15
    x = np.full(3, 1e15 - 0.75)
    mon = ValidityMonitor(X)
    assert not mon.hull.contains(x)
    assert abs(mon.distance(x) - math.sqrt(3) / 8) <= 4e-16


def test_exact_projection_onto_a_subnormal_hull():
    """States one ulp outside a hull of subnormal states (k · 2^-1074, |k| ≤ 50, on a
    sphere): the frame divided the floats by 4 before scaling them up, which rounds
    subnormals to a few bits, and the projection raised SolverError (> 200000 active
    sets). Every distance is now found, 0 exactly for the states in the hull."""
    from rescon.consensus.metrics import ValidityMonitor

    rng = np.random.default_rng(11)
    X = rng.normal(size=(150, 3))
    X = np.round(X / np.linalg.norm(X, axis=1)[:, None] * 50) * 5e-324
    mon = ValidityMonitor(X)
    V, c = mon.hull.vertices, X.mean(axis=0)
    S = np.array([np.nextafter(v, v + (v - c)) for v in V[:40]])
    dist = mon.distances(S)
    assert ((dist == 0) == np.array([mon.hull.contains(x) for x in S])).all()
    assert (dist[dist > 0] <= 2 * 5e-324).all()  # one step per coordinate: ≤ √3 ulp


def test_state_on_a_hull_triangle_in_floats_raises_no_warning():
    """A subnormal state just inside the corner of an integer grid's hull (the float
    closest point of a triangle is the state itself: distance 0): the lower bound of
    triangle_distances divided by it and numpy warned "divide by zero" on every such
    state of a run. Its distance is 0 (it lies in the hull), with no warning."""
    from rescon.consensus.metrics import ValidityMonitor

    X = np.array(list(product(range(4), repeat=3)) + [(1, 2, 3)], dtype=float)
    mon = ValidityMonitor(X)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert mon.distances(np.full((1, 3), 5e-324)).tolist() == [0.0]
