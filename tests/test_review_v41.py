"""V41 hostile review of this session's changes (b681b37..HEAD).

Attacked:

* ``consensus/engine.py`` ``_batch_points_moved`` / ``_batch_points`` (ff91558): the
  kernel sets the batch paths decline, moved next to the origin (per-coordinate median
  c subtracted, exact differences only, scaled by 2^-e) and tried again; sets in space
  with one constant coordinate sent to the planar path. Every accepted point is compared
  exactly (Fractions) with the certificate's rational point of
  ``safe_kernel(Y, F).point("project")``: ulp lattices around 0, ±1e-300, subnormals,
  0.75, 1e15, ±1e300, 1.7e308, mixed signs, duplicates, collinear and coplanar sets,
  one and two constant coordinates, far power-of-two outliers, overflowing
  differences, medians that are outliers (seeded fuzz; 6000 sets off-line, ~2000
  accepted by the moved pass, none outside its bound). The planar path's bound is an
  ∞-norm bound (the spatial one a 2-norm bound), so each is checked in its own norm.
  ``_kernel_points`` "project" against "project-exact" (within ``_allowance``), and
  whole runs (``simulate``: validity 0, finite, deterministic, the same states to
  ~2^-40 with the moved pass switched off).
* ``geometry/points.py`` (557669d): ``_frame`` on the vertices times 2^-s and the
  exact ``_from_frame``: Chebyshev centres and projections (also onto far targets) at
  every magnitude, d = 1..5, flat kernels — certificate valid, the exact point in Ψ.
  Off-line against b681b37 (191 kernels): every projection the same rational point; the
  Chebyshev centres' rationals differ (now exact, before rounded to floats), their
  floats agree except a few subnormal kernels (one subnormal apart, both valid), and a
  d = 3 kernel of subnormal multiples that b681b37 refused (SolverError) now works.
* R14's compiled vertex-float proofs (``_vertex_floats._rounded_nb``, 4fd255a,
  a51a420): d = 4-5 kernels on gaussian, sphere, grid, duplicate, converged, 1e-300 and
  1e300 clouds give the same exact vertices, constraints and certificates as b681b37
  (108 clouds off-line); a few are pinned here by hashes computed with b681b37.

Found: the spatial batch path's bound is rounded to nearest when it is scaled back to a
subnormal magnitude (``_small3d.py`` ``_project`` / ``project_small_3d``, older than this
session), so a point a fraction of a subnormal off comes with the bound 0.
"""

from __future__ import annotations

import hashlib
import math
import warnings
from fractions import Fraction

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon.consensus import engine
from rescon.consensus.adversaries import Constant, RandomInBox
from rescon.consensus.scenario import Scenario

TINY = 5e-324


def exact_point(Y: np.ndarray, F: int) -> list[Fraction]:
    """The certificate's rational point of Ψ(Y, F) nearest mean(Y) — of Y − Y[0] plus
    Y[0] where the differences are exact floats (Ψ and the mean move with Y; the exact
    path refuses kernels next to ±1.8e308)."""
    o = Y[0].copy()
    with np.errstate(all="ignore"):
        D = Y - o
    if not all(Fraction(float(a)) == Fraction(float(b)) - Fraction(float(c))
               for a, b, c in zip(D.ravel(), Y.ravel(), np.tile(o, len(Y)), strict=True)):
        D, o = Y, np.zeros_like(o)
    x = rescon.safe_kernel(D, F).point("project")[1]["x"]
    return [Fraction(s) + Fraction(float(c)) for s, c in zip(x, o, strict=True)]


def within(p: np.ndarray, x: list[Fraction], bound: float, d: int) -> bool:
    """|p − x| ≤ bound exactly: the ∞-norm for the planar path's bounds, else the 2-norm."""
    diff = [Fraction(float(a)) - b for a, b in zip(p, x, strict=True)]
    B = Fraction(float(bound))
    if d == 2:
        return max(abs(t) for t in diff) <= B
    return sum(t * t for t in diff) <= B * B


def lattice(rng, m, d, base, unit, span):
    """m points base + k·unit, k integer in [−span, span] per coordinate."""
    with np.errstate(all="ignore"):
        return base + rng.integers(-span, span + 1, size=(m, d)).astype(float) * unit


def fuzz_sets(seed: int, count: int):
    """(Y, F) sets of the kinds the moved pass sees (converged lattices) and others."""
    rng = np.random.default_rng(seed)
    bases = [0.0, 1e-300, -1e-300, 0.75, 1e15, -1e15, 1e300, -1e300, 1.7e308, 1.0]
    for _ in range(count):
        d = int(rng.choice([2, 3]))
        F = int(rng.integers(1, 3))
        lo = (d + 1) * F + 1
        m = int(rng.integers(lo, min(engine.SMALL_BATCH_MAX[d], lo + 8) + 1))
        base = bases[rng.integers(len(bases))]
        unit = math.ulp(base) if base else float(rng.choice([TINY, 1e-300, 1.0]))
        Y = lattice(rng, m, d, base, unit, int(rng.choice([1, 2, 4, 50])))
        kind = rng.integers(0, 5)
        if kind == 1:  # duplicates
            Y = Y[rng.integers(0, max(1, m // 3), size=m)]
        elif kind == 2:  # a constant coordinate
            Y[:, rng.integers(d)] = Y[0, 0]
        elif kind == 3:  # F far outliers at powers of two
            Y[:F] = np.ldexp(1.0, int(rng.integers(-1074, 1000))) * rng.choice([-1.0, 1.0], d)
        elif kind == 4:  # more than half the points far on one axis: c is off the cluster
            Y[: m // 2 + 1, 0] += np.ldexp(1.0, int(rng.integers(-30, 40)))
        if np.isfinite(Y).all():
            yield np.ascontiguousarray(Y), F


def quiet_simulate(sc):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rescon.simulate(sc)


def declined(Ys, F):
    """_batch_points_moved declining everything (the pass switched off)."""
    B, _, d = Ys.shape
    return np.zeros((B, d)), np.full(B, np.inf), np.zeros(B, dtype=bool)


# --- _batch_points_moved / _batch_points: soundness ------------------------------------


@pytest.mark.slow
def test_moved_points_within_their_bounds_fuzz():
    """Seeded fuzz (400 sets, ~235 certified by the moved pass): every point the moved
    pass certifies is within its bound of the exact point (Fractions; the planar
    path's bound in the ∞-norm, the spatial one's in the 2-norm)."""
    accepted = 0
    for Y, F in fuzz_sets(41, 400):
        d = Y.shape[1]
        p, b, ok = engine._batch_points_moved(Y[None], F)
        if not ok[0]:
            continue
        accepted += 1
        assert np.isfinite(p).all()
        assert within(p[0], exact_point(Y, F), b[0], d), (Y.tolist(), F)
    assert accepted >= 100


@pytest.mark.parametrize("base", [1e-300, -1e-300, 0.75, 1e15, -1e300, 1.7e308])
@pytest.mark.parametrize("d,F", [(2, 1), (2, 2), (3, 1)])
def test_converged_lattice_moved_point_is_sound(base, d, F):
    """Converged states (a few ulps around base): the moved pass certifies them and its
    point is within its bound of the exact one (around 0 it declines: the bound is
    relative to the answer's magnitude)."""
    rng = np.random.default_rng(10 * d + F)
    unit = math.ulp(base) if base else 1e-300
    Y = lattice(rng, (d + 1) * F + 3, d, base, unit, 3)
    p, b, ok = engine._batch_points_moved(Y[None], F)
    assert ok[0]
    assert within(p[0], exact_point(Y, F), b[0], d)


def test_moved_pass_declines_rounded_and_overflowing_differences_quietly():
    """y − c not a float (1 and 2^-60) or overflowing (±1.7e308): declined, no warning."""
    Y1 = np.array([[1.0, 1.0], [2.0**-60, 0.0], [0.0, 2.0**-60], [1.0, 0.0], [0.0, 1.0]])
    Y2 = np.array([[1.7e308, 1.7e308]] * 3 + [[-1.7e308, -1.7e308]] * 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _, b, ok = engine._batch_points_moved(np.stack([Y1, Y2]), 1)
    assert not ok.any() and np.isinf(b).all()


def test_median_off_the_clusters_stays_sound():
    """Four points 2^20 away on x, three 2^20 away on y, in clusters 2^-30 wide: the
    per-coordinate median is an outlier for three (or four) of them and the moved set's
    clusters are 2^-51 of its scale. Differences are exact; whatever the passes certify
    is within its bound, and the engine's point within _allowance of the exact one."""
    Y = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [2, 1], [1, 2], [2, 2]], float) * 2.0**-30
    Y[:4, 0] += 2.0**20
    Y[4:, 1] += 2.0**20
    x = exact_point(Y, 1)
    for fn in (engine._batch_points, engine._batch_points_moved):
        p, b, ok = fn(Y[None], 1)
        if ok[0]:
            assert within(p[0], x, b[0], 2)
    a = engine._kernel_points([Y], 1, "project", {})
    allow = engine._allowance(Y[None], 1, a)[0]
    assert max(abs(Fraction(float(v)) - t) for v, t in zip(a[0], x)) <= Fraction(float(allow))


@pytest.mark.parametrize("j", [0, 1, 2])
def test_one_constant_coordinate_in_space_goes_to_the_plane(j):
    """A spatial set with coordinate j constant: the answer has that coordinate exactly
    and the planar point of the other two; within its (2-norm) bound of the exact point."""
    rng = np.random.default_rng(j)
    Y = lattice(rng, 9, 3, 1e15, 0.125, 3)
    Y[:, j] = 1e15 + 0.375
    p, e, ok = engine._batch_points(Y[None], 1)
    others = [i for i in range(3) if i != j]
    p2, _, ok2 = engine._batch_points(np.ascontiguousarray(Y[None][:, :, others]), 1)
    assert ok[0] == ok2[0]
    if ok[0]:
        assert p[0, j] == 1e15 + 0.375
        assert np.array_equal(p[0, others], p2[0])
        assert within(p[0], exact_point(Y, 1), e[0], 3)


def test_two_constant_coordinates_in_space_do_not_break_the_pass():
    """Two constant coordinates (a line): no planar reduction, no exception; whatever is
    certified is sound, and the engine answers the exact point."""
    Y = np.zeros((7, 3))
    Y[:, 0] = 0.75 + np.array([0, 1, 2, 3, 1, 2, 0]) * 2.0**-53
    Y[:, 1], Y[:, 2] = 1e15, -1e-300
    for fn in (engine._batch_points, engine._batch_points_moved):
        p, b, ok = fn(Y[None], 1)
        if ok[0]:
            assert within(p[0], exact_point(Y, 1), b[0], 3)
    out = engine._kernel_points([Y], 1, "project", {})
    assert np.array_equal(out, engine._kernel_points([Y], 1, "project-exact", {}))


@pytest.mark.parametrize("base", [2.0**-1023, -2.0**-1023, 2.0**-1022, 3 * 2.0**-1024])
def test_subnormal_lattice_moved_bound_covers_its_rounding(base):
    """Lattices of 2^-1074 steps at the top of the subnormal range: 2^e q and its bound
    round on the subnormal grid; the moved pass adds two subnormals for that and its
    answers are within their bounds (around 0 it declines them: two subnormals exceed
    ACCEPT_REL of the answer)."""
    rng = np.random.default_rng(7)
    n_ok = 0
    for d, F in ((2, 1), (3, 1), (2, 2), (3, 2)):
        for _ in range(3):
            Y = lattice(rng, (d + 1) * F + 4, d, base, TINY, 3)
            p, b, ok = engine._batch_points_moved(Y[None], F)
            if ok[0]:
                n_ok += 1
                assert within(p[0], exact_point(Y, F), b[0], d)
    assert n_ok >= 8


def test_spatial_batch_bound_covers_subnormal_rounding():
    """Fixed (was a bug: 12 points of {−1, 0, 1}·2^-1074 in space, F = 2: the spatial
    path certified (0, 0, −0) with the bound 0 — accepted, the allowance is 0 too — but
    the exact point is (5, 1, −2)/2^1077-ish, a fraction of a subnormal, not 0: the
    point and its bound scaled back into the subnormal range were rounded, and the
    rounding was not in the bound). The bound now covers the exact point; such a
    set is no longer certified (two subnormals are more than ACCEPT_REL of it)."""
    K = np.array([[0, 1, 1], [0, 1, 1], [1, 1, -1], [1, -1, -1], [1, 0, 0], [1, -1, -1],
                  [0, 1, -1], [0, -1, -1], [1, -1, 1], [1, 1, 0], [0, 0, 0], [-1, 0, 0]],
                 float)
    Y = K * TINY
    p, err, ok = engine._batch_points(Y[None], 2)
    assert within(p[0], exact_point(Y, 2), err[0], 3)
    assert not ok[0]


# --- _kernel_points end to end -------------------------------------------------------


@pytest.mark.parametrize("base", [0.75, 1e15, -1e-300, 1e300])
@pytest.mark.parametrize("d", [2, 3])
def test_kernel_points_project_within_allowance_of_exact(base, d):
    """A batch of converged sets: "project" is within _allowance (exactly) of the exact
    point, and "project-exact" is that point rounded."""
    rng = np.random.default_rng(int(d + 10 * abs(math.log10(abs(base)) + 1)))
    F = 1
    sets = [lattice(rng, (d + 1) * F + 2, d, base, math.ulp(base), 2) for _ in range(6)]
    a = engine._kernel_points(sets, F, "project", {})
    b = engine._kernel_points(sets, F, "project-exact", {})
    allow = engine._allowance(np.stack(sets), F, a)
    for k, Y in enumerate(sets):
        x = exact_point(Y, F)
        assert np.array_equal(b[k], [float(t) for t in x])
        assert max(abs(Fraction(float(v)) - t) for v, t in zip(a[k], x)) <= Fraction(
            float(allow[k]))


def test_kernel_points_at_the_float_limit_use_the_moved_pass():
    """A converged set a few ulps around 1.7e308: the answer is finite and the exact one."""
    u = math.ulp(1.7e308)
    Y = 1.7e308 + np.array([[0, 0], [1, 0], [0, 1], [1, 1], [2, 1], [1, 2], [0, 0]],
                           float) * u
    a = engine._kernel_points([Y], 1, "project", {})
    assert np.isfinite(a).all()
    assert np.array_equal(a, engine._kernel_points([Y], 1, "project-exact", {}))


# --- whole runs -----------------------------------------------------------------------


def _scenario(d, F, adversary, N, steps, seed, scale=1.0):
    rng = np.random.default_rng(seed)
    x0 = rng.uniform(-1, 1, size=(N, d)) * scale
    k = (d + 1) * F + 2 * F + 3
    k += (k * N) % 2
    G = nx.DiGraph(nx.random_regular_graph(k, N, seed=seed))
    advs = {"constant": {i: Constant([0.3] * d) for i in range(F)},
            "far": {i: Constant([1e20] * d) for i in range(F)},
            "copy": {i: RandomInBox(scale=0.0) for i in range(F)}}[adversary]
    return Scenario(graph=G, x0=x0, F=F, adversaries=advs, steps=steps, residual="none")


def _compare_with_pass_off(monkeypatch, sc):
    a = quiet_simulate(sc)
    assert np.isfinite(a.states).all()
    assert a.metrics["validity"].max() == 0.0
    assert np.array_equal(a.states, quiet_simulate(sc).states)  # deterministic
    monkeypatch.setattr(engine, "_batch_points_moved", declined)
    c = quiet_simulate(sc)
    assert c.metrics["validity"].max() == 0.0
    scale = np.abs(c.states).max(axis=(1, 2), keepdims=True)
    assert (np.abs(a.states - c.states) <= 2.0**-40 * scale).all()


def test_short_run_matches_the_run_without_the_moved_pass(monkeypatch):
    """d = 3, F = 1, a copying adversary, 60 steps (converged well before the end)."""
    _compare_with_pass_off(monkeypatch, _scenario(3, 1, "copy", 16, 60, 3))


@pytest.mark.slow
@pytest.mark.parametrize("d,F,adversary,N,steps,seed,scale", [
    (2, 1, "constant", 30, 150, 1, 1.0), (2, 2, "far", 40, 120, 2, 1.0),
    (3, 2, "constant", 30, 80, 4, 1.0), (2, 1, "copy", 30, 200, 5, 1e-300),
    (3, 1, "constant", 30, 200, 8, 5e-310)])
def test_runs_match_the_runs_without_the_moved_pass(monkeypatch, d, F, adversary, N,
                                                    steps, seed, scale):
    """Converging runs (fast-mixing random regular digraphs): validity 0, finite,
    deterministic, and the states of the run without the moved pass to 2^-40."""
    _compare_with_pass_off(monkeypatch, _scenario(d, F, adversary, N, steps, seed, scale))


# --- points.py: Chebyshev centres and projections at every magnitude -------------------


def _check_point(K, method, **kw):
    x, cert = K.point(method, **kw)
    assert np.isfinite(x).all()
    assert K._exact.contains(tuple(Fraction(s) for s in cert["x"]))
    assert rescon.check_certificate(cert).verdict == "valid"
    return x, cert


@pytest.mark.parametrize("d", [1, 2, 3, 4, 5])
@pytest.mark.parametrize("mag", [TINY, 8e-323, 1e-310, 1e-300, 1.0, 1e300, 4.25e307])
def test_chebyshev_and_far_projection_at_every_magnitude(d, mag):
    """A doubled simplex plus corners (full-dimensional Ψ) scaled to mag: the Chebyshev
    centre and the projection of a far target are certified points of Ψ."""
    rng = np.random.default_rng(d)
    X = np.vstack([np.zeros(d), np.eye(d), rng.integers(0, 2, size=(2, d))]) * mag
    K = rescon.safe_kernel(np.vstack([X, X]), 1)
    assert K.dim == d
    _check_point(K, "chebyshev")
    far = np.full(d, -1.7e308 if mag < 1e300 else TINY)
    _check_point(K, "project", target=far)


@pytest.mark.parametrize("d", [2, 3, 4, 5])
def test_kernel_one_wide_at_1e15(d):
    """Ψ about 1 wide at 1e15 (ulp 1/8), a target 1e300 away: certified points."""
    rng = np.random.default_rng(100 + d)
    X = 1e15 + rng.integers(-3, 4, size=((d + 1) + 3, d)).astype(float)
    K = rescon.safe_kernel(X, 1)
    _check_point(K, "chebyshev")
    _check_point(K, "project", target=np.full(d, 1e300))
    x, _ = _check_point(K, "project")
    assert np.array_equal(x, rescon.kernel_point(X, 1)[0])


def test_subnormal_chebyshev_that_b681b37_refused():
    """d = 3, six points of small multiples of 2^-1074, F = 1 (Ψ flat, 2-dimensional):
    b681b37 raised SolverError ('not in the kernel'); now a certified point."""
    X = np.array([[1, 0, -2], [-1, 0, 2], [0, -1, 1], [1, 1, 1], [-1, 0, 1], [1, -1, 1]],
                 float) * TINY
    K = rescon.safe_kernel(X, 1)
    _check_point(K, "chebyshev")


@pytest.mark.parametrize("d", [2, 3, 4, 5])
def test_flat_kernels_at_1e_minus_310(d):
    """One coordinate constant (a flat Ψ) at subnormal scale: certified points."""
    rng = np.random.default_rng(200 + d)
    X = rng.normal(size=((d + 1) + 2, d)) * 1e-310
    X[:, -1] = X[0, -1]
    K = rescon.safe_kernel(X, 1)
    if K.is_empty:
        pytest.skip("empty kernel")
    assert K.dim < d
    _check_point(K, "chebyshev")
    _check_point(K, "project", target=np.full(d, 1e150))


def test_chebyshev_scales_with_powers_of_two():
    """2^j X has the Chebyshev centre 2^j times X's (the frame is a power of two), also
    across the subnormal boundary where 557669d rescales the vertices."""
    X = np.array([[0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4], [1, 1, 1], [3, 1, 0],
                  [0, 0, 0], [4, 0, 0], [0, 4, 0], [0, 0, 4]], float)
    ref = rescon.safe_kernel(X, 1).point("chebyshev")[1]["x"]
    for j in (-1000, -1060, 900):
        got = rescon.safe_kernel(np.ldexp(X, j), 1).point("chebyshev")[1]["x"]
        assert [Fraction(s) for s in got] == [Fraction(s) * Fraction(2) ** j for s in ref]


# --- d = 4-5 kernels: the compiled vertex-float proofs --------------------------------


def _d45_clouds():
    rng = np.random.default_rng(20261207)
    yield "gauss4", rng.normal(size=(12, 4)), 1
    S = rng.normal(size=(9, 5))
    yield "sphere5", S / np.linalg.norm(S, axis=1)[:, None], 1
    yield "grid4", rng.integers(-2, 3, size=(13, 4)).astype(float), 2
    G = rng.normal(size=(6, 5))
    yield "dups5", np.vstack([G, G[:3]]), 1
    yield "converged4", 0.75 + rng.integers(-2, 3, size=(11, 4)) * 2.0**-53, 1
    yield "tiny5", rng.normal(size=(9, 5)) * 1e-300, 1
    yield "huge4", rng.normal(size=(12, 4)) * 1e300, 1


#: sha256 prefixes of (dim, exact vertices, constraints, equalities), computed with
#: b681b37 (before the compiled proofs) — the same with HEAD
D45_PINNED = {"gauss4": (4, 151, "7890434eb54cfe06"), "sphere5": (5, 91, "0ac8b45e30d0e259"),
              "grid4": (4, 152, "f1b74eebce255d09"), "dups5": (2, 3, "d04749acb78376fd"),
              "converged4": (4, 111, "8b02b02bced8fc9a"), "tiny5": (5, 75, "1d62298a2ae4c3ba"),
              "huge4": (4, 167, "48edc4a3528faddf")}


@pytest.mark.parametrize("name,X,F", list(_d45_clouds()),
                         ids=lambda v: v if isinstance(v, str) else "")
def test_d45_kernels_as_before_the_compiled_proofs(name, X, F):
    K = rescon.safe_kernel(X, F)
    h = hashlib.sha256(repr((K.dim, K.exact_vertices, K._exact.constraints,
                             K._exact.equalities)).encode()).hexdigest()[:16]
    assert (K.dim, len(K.vertices), h) == D45_PINNED[name]
    assert rescon.check_certificate(K.certificate).verdict == "valid"
