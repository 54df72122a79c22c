"""Review V40 (hostile): rescon in d = 4 and d = 5, the dimensions least attacked.

Attacked:

* ``rescon.simulate`` / ``rescon.rmdo`` with d = 4 and d = 5 states (Scenario in Python
  and from TOML through the CLI's ``--json``): complete graphs below and at the
  robustness the theorems ask for, runs to convergence (diameter ≤ 1e-12, exactly 0),
  every monitor on, adversaries at 1e300 / -1e308, copying a benign agent, sitting on a
  vertex of the benign hull, sending the benign states' mean ± one ulp, initial states
  at 1e-300 … 1e150 and mixed, all agents identical, states on a 3-flat of R⁵. Checked:
  finite states, the validity monitor's verdict (0 or not) against an exact
  Carathéodory test in Fractions (independent of rescon), determinism, CLI = API.
* ``rescon.safe_kernel`` in d = 4–5 on converged clouds (1e-9 … 1e-15 relative around
  0, 1e6, 1e200, -1e300), last-bit clouds, duplicates, F + 1 copies, flats: the public
  outputs against the exact clipping (fast path switched off, as in test_review_v3),
  every certificate checked, and every point method's exact point checked against the
  kernel's exact constraints and, for small n, against the definition
  Ψ = ⋂ conv(S), |S| = n − F (Carathéodory in Fractions).

Found (xfail strict): ``SafeKernel.point("chebyshev")`` raises SolverError on a
nonempty 4-dimensional kernel of a d = 5 cloud of 0/1 multiples of the smallest
subnormal: the unit frame of ``points._frame`` is computed from float vertices divided
by len(V) and by 4, which underflow to 0 (o = 0, e = 0), so the backend's LP sees the
kernel at its own subnormal size and its centre is not in the kernel.
"""

from __future__ import annotations

import itertools
import json
import math
import subprocess
import sys
import time
import warnings
from fractions import Fraction

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon.consensus import engine
from rescon.consensus.adversaries import Behaviour, Constant
from rescon.geometry import kernel as km

# --------------------------------------------------------------------------- #
# exact oracles (Fractions only; nothing from rescon)
# --------------------------------------------------------------------------- #


def _eliminate(M: list[list[Fraction]], ncols: int) -> tuple[list[list[Fraction]], int]:
    """Reduced row echelon form of M over its first ``ncols`` columns; (M, rank)."""
    M = [row[:] for row in M]
    r = 0
    for c in range(ncols):
        p = next((i for i in range(r, len(M)) if M[i][c] != 0), None)
        if p is None:
            continue
        M[r], M[p] = M[p], M[r]
        pv = M[r][c]
        M[r] = [v / pv for v in M[r]]
        for i in range(len(M)):
            if i != r and M[i][c] != 0:
                f = M[i][c]
                M[i] = [a - f * b for a, b in zip(M[i], M[r], strict=True)]
        r += 1
    return M, r


def _in_simplex(S: tuple, x: list[Fraction]) -> bool:
    """x ∈ conv(S) for affinely independent S: the unique λ with Σ λ_j (s_j, 1) = (x, 1)
    exists and is ≥ 0 (None if S is dependent: the caller skips it)."""
    s = len(S)
    rows = [[p[i] for p in S] + [x[i]] for i in range(len(x))]
    rows.append([Fraction(1)] * s + [Fraction(1)])
    M, r = _eliminate(rows, s)
    if r < s or any(M[i][s] != 0 for i in range(r, len(M))):
        return False
    return all(M[i][s] >= 0 for i in range(s))


def _independent(S: tuple) -> bool:
    return _eliminate([list(p) + [Fraction(1)] for p in S], len(S[0]) + 1)[1] == len(S)


def exact_in_hull(P, x) -> bool:
    """x ∈ conv(P), exactly: by Carathéodory x lies in the hull of an affinely
    independent subset of P."""
    pts = list(dict.fromkeys(tuple(Fraction(float(v)) for v in p) for p in np.asarray(P)))
    xf = [v if isinstance(v, Fraction) else Fraction(float(v)) for v in x]
    for s in range(1, min(len(pts), len(xf) + 1) + 1):
        for S in itertools.combinations(pts, s):
            if _independent(S) and _in_simplex(S, xf):
                return True
    return False


def exact_in_safe_kernel(X, F: int, x) -> bool:
    """x ∈ Ψ(X, F) = ⋂ {conv(S) : |S| = n − F}, by the definition (small n only)."""
    X = np.asarray(X)
    n = len(X)
    return all(exact_in_hull(X[list(S)], x) for S in itertools.combinations(range(n), n - F))


def check_validity_verdicts(tr, H, steps) -> None:
    """For every benign agent at the given steps: the monitor's distance is 0 exactly
    when the state is in conv(H) (exact test)."""
    per = tr.metrics["validity_per_agent"]
    for k in steps:
        for r, i in enumerate(tr.benign):
            inside = exact_in_hull(H, tr.states[k, i])
            assert (per[k, r] == 0) == inside, (k, int(i), per[k, r])
            assert math.isfinite(per[k, r])


# --------------------------------------------------------------------------- #
# scenarios
# --------------------------------------------------------------------------- #


def _complete(n: int) -> nx.DiGraph:
    return nx.complete_graph(n).to_directed()


def _run(graph, x0, F, steps, adversaries=None, **kw):
    sc = rescon.Scenario(graph=graph, x0=x0, F=F, adversaries=adversaries or {},
                         steps=steps, residual="none", **kw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rescon.simulate(sc)


class CopyAgent(Behaviour):
    """Sends benign agent j's current state to everyone."""

    def __init__(self, j: int) -> None:
        self.j = j

    def messages(self, sender, receivers, view):
        return np.tile(view.states[self.j], (len(receivers), 1))

    def to_dict(self):
        raise NotImplementedError


class MeanUlp(Behaviour):
    """Sends the benign states' mean moved by one ulp up (``sign`` = 1) or down, a
    different direction to alternate receivers (a two-faced converged point)."""

    def __init__(self, sign: float) -> None:
        self.sign = sign

    def messages(self, sender, receivers, view):
        m = view.states[view.benign].mean(axis=0)
        up = np.nextafter(m, self.sign * np.inf)
        down = np.nextafter(m, -self.sign * np.inf)
        return np.array([up if r % 2 else down for r in receivers])

    def to_dict(self):
        raise NotImplementedError


# --------------------------------------------------------------------------- #
# simulate: d = 4, 5
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("d,value", [(4, 1e300),
                                     pytest.param(5, -1e308, marks=pytest.mark.slow)])
def test_far_adversary_validity_verdicts_are_exact(d, value):
    """K_{d+3} (one adversary, m = (d+1)F+1 values each, below the theorems'
    robustness): a benign agent's Radon point lies on a face of its neighbours'
    simplex, so states sit on the benign hull's boundary and rounding puts some an
    ulp outside. Each verdict (0 or not) must match the exact test."""
    N = d + 3
    x0 = np.random.default_rng(d).uniform(-1, 1, size=(N, d))
    tr = _run(_complete(N), x0, 1, 6, {0: Constant([value] * d)})
    assert np.isfinite(tr.states[:, 1:]).all()
    check_validity_verdicts(tr, x0[1:], range(7))


@pytest.mark.slow
def test_d4_adversary_copying_a_benign_agent_keeps_every_state_in_the_hull_exactly():
    """An adversary that repeats benign agent 3's state is a benign value: the filter
    may keep it, and nothing should leave the hull beyond the monitor's exact verdict."""
    x0 = np.random.default_rng(11).uniform(0, 10, size=(8, 4))
    tr = _run(_complete(8), x0, 1, 8, {0: CopyAgent(3)})
    assert np.isfinite(tr.states).all()
    check_validity_verdicts(tr, x0[1:], range(9))


@pytest.mark.slow
def test_d5_adversary_on_a_hull_vertex_verdicts_are_exact():
    """The adversary sends a vertex of the benign hull (benign agent 1's initial state)
    in d = 5 on K9: the monitor's verdicts match the exact test."""
    x0 = np.random.default_rng(12).uniform(-5, 5, size=(9, 5))
    tr = _run(_complete(9), x0, 1, 4, {0: Constant(x0[1])})
    assert np.isfinite(tr.states).all()
    check_validity_verdicts(tr, x0[1:], range(5))


@pytest.mark.slow
def test_d4_adversary_at_the_mean_plus_minus_one_ulp_on_a_converged_run():
    """States start a few ulps apart around 1 (already converged); the adversary sends
    the benign mean ± one ulp, two-faced. States stay finite, the monitor agrees with
    the exact test, the run is deterministic."""
    rng = np.random.default_rng(13)
    x0 = 1.0 + rng.integers(-4, 5, size=(8, 4)) * np.spacing(1.0)
    runs = [_run(_complete(8), x0, 1, 10, {0: MeanUlp(1.0)}) for _ in range(2)]
    tr = runs[0]
    assert np.array_equal(runs[0].states, runs[1].states)
    assert np.isfinite(tr.states).all()
    check_validity_verdicts(tr, x0[1:], range(11))


@pytest.mark.parametrize("scale", [1e-300, 1e-200, 1.0, 1e150])
def test_d4_magnitudes_stay_finite_and_verdicts_are_exact(scale):
    """Initial states at 1e-300 … 1e150 (the documented limit), the adversary at the
    far end of the float range with the opposite sign."""
    x0 = np.random.default_rng(14).uniform(-1, 1, size=(7, 4)) * scale
    tr = _run(_complete(7), x0, 1, 8, {0: Constant([-1.7e308, 1.7e308, -1e300, 1e300])})
    assert np.isfinite(tr.states[:, 1:]).all()
    assert np.isfinite(tr.metrics["diameter"]).all()
    check_validity_verdicts(tr, x0[1:], (0, 1, 4, 8))


def test_d4_mixed_magnitudes_and_a_value_1e_300_from_a_benign_one():
    """Benign states mixing 1e-300 and 1e150 coordinates; the adversary sends a benign
    state moved by 1e-300 (a different float only where that coordinate is tiny)."""
    rng = np.random.default_rng(15)
    x0 = rng.uniform(-1, 1, size=(7, 4)) * np.array([1e-300, 1e150, 1.0, 1e-200])
    bait = x0[2] + np.array([1e-300, 1e-300, 1e-300, 1e-300])
    assert bait[0] != x0[2, 0]
    tr = _run(_complete(7), x0, 1, 6, {0: Constant(bait)})
    assert np.isfinite(tr.states).all()
    check_validity_verdicts(tr, x0[1:], range(7))


@pytest.mark.parametrize("scale", [1e200, 1e300])
def test_initial_states_beyond_1e150_are_a_one_line_input_error(scale):
    """The README bounds initial states by 1e150: beyond, one InputError line."""
    x0 = np.full((7, 4), scale)
    with pytest.raises(rescon.InputError) as exc:
        rescon.Scenario(graph=_complete(7), x0=x0, F=1)
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("d", [4, 5])
def test_all_agents_identical_stay_bit_identical(d):
    """Every benign state (and the adversary's message) the same point: the exact
    kernel is that point, so nothing moves, diameter 0, validity 0."""
    p = np.array([0.1, -3e-300, 7e149, -1.0, 2.5][:d])
    x0 = np.tile(p, (d + 3, 1))
    tr = _run(_complete(d + 3), x0, 1, 5, {0: Constant(p)})
    assert (tr.states == p).all()
    assert tr.final_diameter == 0 and tr.max_validity == 0


@pytest.mark.slow
def test_d5_states_on_a_3_flat_verdicts_are_exact():
    """Benign states on a 3-dimensional flat of R⁵ (exact integer combinations of three
    directions through an offset point): the hull is flat, the monitor goes exact."""
    rng = np.random.default_rng(16)
    B = rng.integers(-3, 4, size=(3, 5)).astype(float)
    x0 = 2.0 + rng.integers(-4, 5, size=(9, 3)).astype(float) @ B / 8
    tr = _run(_complete(9), x0, 1, 5, {0: Constant([1e300, -1e300, 0, 0, 1e300])})
    assert np.isfinite(tr.states).all()
    check_validity_verdicts(tr, x0[1:], range(6))


@pytest.mark.slow
def test_d5_runs_are_deterministic_with_random_adversaries():
    """Two runs of a seeded scenario with a random-in-box and a bait adversary (d = 5,
    K10, F = 1) give bit-identical states and metrics."""
    from rescon.consensus.adversaries import Bait, RandomInBox

    x0 = np.random.default_rng(17).uniform(-1, 1, size=(10, 5))
    advs = {0: RandomInBox(scale=3.0), 1: Bait()}
    a, b = (_run(_complete(10), x0, 1, 4, advs, seed=5) for _ in range(2))
    assert np.array_equal(a.states, b.states)
    for key in a.metrics:
        assert np.array_equal(a.metrics[key], b.metrics[key], equal_nan=True), key


def _toml(sc_rows: str, nodes: int, x0: np.ndarray, adv: list[float]) -> str:
    edges = [[u, v] for u in range(nodes) for v in range(nodes) if u != v]
    lines = ["[scenario]", sc_rows, "[graph]", f"edges = {edges}", "[initial]"]
    lines += [f'{i} = [{", ".join(repr(float(v)) for v in x0[i])}]' for i in range(nodes)]
    lines += ["[adversaries.0]", 'kind = "constant"',
              f"value = [{', '.join(repr(v) for v in adv)}]"]
    return "\n".join(lines) + "\n"


@pytest.mark.slow
def test_d4_cli_json_equals_the_python_api(tmp_path):
    """`rescon simulate FILE --json` and Scenario.from_toml + simulate: the same
    final diameter and max validity (floats through JSON round-trip exactly)."""
    x0 = np.random.default_rng(18).uniform(-1e-200, 1e-200, size=(7, 4))
    adv = [1e300, -1e308, 5e-324, 0.0]
    path = tmp_path / "d4.toml"
    path.write_text(_toml('F = 1\nsteps = 12\nresidual = "none"', 7, x0, adv))
    done = subprocess.run([sys.executable, "-m", "rescon", "simulate", str(path), "--json",
                           "--quiet"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    out = json.loads(done.stdout)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = rescon.Scenario.from_toml(path)
        tr = rescon.simulate(sc)
    assert (out["d"], out["N"], out["steps"]) == (4, 7, 12)
    assert out["final_diameter"] == tr.final_diameter
    assert out["max_validity"] == tr.max_validity
    assert np.array_equal(sc.x0, x0)


@pytest.mark.slow
def test_d4_rmdo_is_finite_and_deterministic():
    """RMDO in d = 4 on K7 with a far adversary: finite iterates, two runs identical,
    and the distance to the exact optimum (1, 2, 3, 4) shrinks."""
    x0 = np.random.default_rng(19).uniform(-5, 5, size=(7, 4))
    sc = rescon.Scenario(graph=_complete(7), x0=x0, F=1, steps=25, residual="none",
                         adversaries={0: Constant([1e300, -1e300, 1e300, -1e300])})
    costs = {i: "(x1 - 1)^2 + (x2 - 2)^2 + (x3 - 3)^2 + (x4 - 4)^2" for i in range(1, 7)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        a, b = rescon.rmdo(sc, costs), rescon.rmdo(sc, costs)
    assert np.array_equal(a.states, b.states)
    assert np.isfinite(a.states).all()
    dist = a.metrics["distance_to_optimum"]
    assert np.isfinite(dist).all() and dist[-1] < dist[0]


class _Clock:
    """A monitor recording the wall time of every step."""

    metrics: dict = {}

    def __init__(self) -> None:
        self.t: list[float] = []

    def record(self, k, t, xb) -> None:
        self.t.append(time.perf_counter())


@pytest.mark.slow
def test_d4_long_run_on_a_6_robust_graph_converges_with_bounded_step_time():
    """K11 (6-robust = (d+1)F+1 for d = 4, F = 1), 200 steps, an adversary at 1e300:
    the benign states reach diameter ≤ 1e-12; steps after convergence are no slower than
    the first ones; the final verdicts match the exact test."""
    x0 = np.random.default_rng(20).uniform(-1, 1, size=(11, 4))
    sc = rescon.Scenario(graph=_complete(11), x0=x0, F=1, steps=200, residual="none",
                         adversaries={0: Constant([1e300] * 4)})
    clock = _Clock()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = engine.run(sc, engine.ConvexStep(sc.residual),
                        monitors=[engine.ConsensusMonitor(sc), clock])
    dt = np.diff(clock.t)
    assert np.isfinite(tr.states[:, 1:]).all()
    assert tr.metrics["diameter"][-1] <= 1e-12
    assert np.median(dt[-50:]) <= 2 * np.median(dt[:20]) + 0.01
    check_validity_verdicts(tr, x0[1:], (200,))


@pytest.mark.slow
def test_d5_run_at_1e_300_converges_to_one_point_without_growing_step_time():
    """d = 5, K8, states at 1e-300 and an adversary at 1e300: the states converge (the
    diameter ends within 1e-15 of the initial one, subnormal), every verdict of the
    last step is exact, and the late steps are not slower than the early ones."""
    x0 = np.random.default_rng(21).uniform(-1, 1, size=(8, 5)) * 1e-300
    sc = rescon.Scenario(graph=_complete(8), x0=x0, F=1, steps=120, residual="none",
                         adversaries={0: Constant([1e300] * 5)})
    clock = _Clock()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = engine.run(sc, engine.ConvexStep(sc.residual),
                        monitors=[engine.ConsensusMonitor(sc), clock])
    dt = np.diff(clock.t)
    assert np.isfinite(tr.states).all()
    assert tr.metrics["diameter"][-1] <= 1e-15 * tr.metrics["diameter"][0]
    assert np.median(dt[-30:]) <= 2 * np.median(dt[:20]) + 0.01
    check_validity_verdicts(tr, x0[1:], (120,))


# --------------------------------------------------------------------------- #
# safe_kernel in d = 4, 5
# --------------------------------------------------------------------------- #


def _outputs(K) -> tuple:
    """Everything a caller can read of a kernel, exactly (as in test_review_v3)."""
    return (K.dim, K.vertices.tolist(), K.A.tolist(), K.b.tolist(), K.Aeq.tolist(),
            K.beq.tolist(), K.exact_vertices)


def _clipped(X, F, monkeypatch):
    with monkeypatch.context() as m:
        m.setattr(km, "certified_kernel", lambda *a: None)
        return rescon.safe_kernel(X, F)


def _exact_point(cert) -> tuple[Fraction, ...]:
    """The certificate's exact point (a vertex mean of ~1000 vertices has numerators of
    ~3·10⁵ digits, beyond Python's default int-string limit)."""
    old = sys.get_int_max_str_digits()
    sys.set_int_max_str_digits(0)
    try:
        return tuple(Fraction(v) for v in cert["x"])
    finally:
        sys.set_int_max_str_digits(old)


def _in_kernel_constraints(K, x) -> bool:
    """x satisfies the kernel's exact equalities and relative facets."""
    ex = K._exact

    def dot(a):
        return sum((ai * xi for ai, xi in zip(a, x, strict=True)), Fraction(0))

    return (all(dot(a) == b for a, b in ex.kernel_eqs)
            and all(dot(a) == b for a, b in ex.equalities)
            and all(dot(a) <= b for a, b in ex.facets))


def _check_kernel(X, F, monkeypatch, *, small=False):
    K = rescon.safe_kernel(X, F)
    assert _outputs(K) == _outputs(_clipped(X, F, monkeypatch))
    assert np.isfinite(K.vertices).all()
    assert rescon.check_certificate(K.certificate).verdict in ("valid", "unchecked")
    for method in ("project", "chebyshev", "vertex-mean"):
        x, cert = K.point(method)
        assert np.isfinite(x).all(), method
        verdict = rescon.check_certificate(cert).verdict
        assert verdict in ("valid", "unchecked"), method
        if max(map(len, cert["x"])) > 4300:  # a vertex mean of ~1000 vertices: 3e5 digits
            assert K.contains(x, tol=1e-12), method
            continue
        xe = _exact_point(cert)
        assert _in_kernel_constraints(K, xe), method
        if small:
            assert exact_in_safe_kernel(X, F, xe), method
    return K


def _cloud(rng, n, d, centre, rel):
    spread = rel * (abs(centre) if centre else 1.0)
    return centre + rng.standard_normal((n, d)) * spread


@pytest.mark.parametrize("d,n,F,centre,rel", [
    pytest.param(4, 30, 2, 0.0, 1e-9, marks=pytest.mark.slow),
    pytest.param(4, 30, 2, 1e6, 1e-15, marks=pytest.mark.slow),
    pytest.param(4, 30, 2, -1e300, 1e-12, marks=pytest.mark.slow),
    (4, 12, 1, 1e200, 1e-15),
    pytest.param(5, 12, 1, 1.0, 1e-12, marks=pytest.mark.slow),
    pytest.param(5, 14, 1, -1e300, 1e-15, marks=pytest.mark.slow),
    pytest.param(5, 12, 1, 1e200, 1e-9, marks=pytest.mark.slow),
])
def test_converged_clouds_match_the_clipping_with_points_inside(d, n, F, centre, rel,
                                                                 monkeypatch):
    """Clouds the consensus runs reach: n points within rel of a centre. Fast path =
    exact clipping; certificates valid or unchecked; every point method's exact point
    in the kernel; each call well under 30 s."""
    X = _cloud(np.random.default_rng(int(abs(math.log10(rel))) + n + d), n, d, centre, rel)
    t0 = time.perf_counter()
    K = _check_kernel(X, F, monkeypatch)
    assert K.dim == d
    assert time.perf_counter() - t0 < 30


def test_d4_kernel_of_a_tiny_cloud_matches_the_definition(monkeypatch):
    """n = 7 in R⁴ within 1e-15 of 1 (a few ulps apart), F = 1: every point method's
    exact point is in ⋂ conv(S), |S| = 6 (Carathéodory in Fractions)."""
    rng = np.random.default_rng(22)
    X = 1.0 + rng.integers(-6, 7, size=(7, 4)) * np.spacing(1.0)
    _check_kernel(X, 1, monkeypatch, small=True)


@pytest.mark.parametrize("d,centre", [(4, 1e6), (4, -1e300), (5, 1.0), (5, 1e200)])
def test_last_bit_clouds_match_the_clipping(d, centre, monkeypatch):
    """Every coordinate either the centre or the next float above it."""
    rng = np.random.default_rng(23 + d)
    bits = rng.integers(0, 2, size=(14, d))
    base = np.full(d, centre)
    X = np.where(bits == 1, np.nextafter(base, np.inf), base)
    _check_kernel(X, 1, monkeypatch)


@pytest.mark.parametrize("d", [4, 5])
def test_duplicates_and_f_plus_one_copies_match_the_clipping(d, monkeypatch):
    """Six points repeated twice and three of them thrice (F = 2: a flat kernel), and
    d + 2 points each copied F + 1 = 3 times (a full-dimensional one)."""
    rng = np.random.default_rng(24 + d)
    P = 1e6 + rng.standard_normal((6, d)) * 1e-6
    _check_kernel(np.vstack([P, P, P[:3]]), 2, monkeypatch)
    Q = -1e300 + rng.standard_normal((d + 2, d)) * 1e291
    K = _check_kernel(np.repeat(Q, 3, axis=0), 2, monkeypatch)
    assert K.dim == d  # conv of the d + 2 points: every point has depth ≥ F + 1 = 3


@pytest.mark.parametrize("d,k,scale", [
    (4, 2, 1.0), pytest.param(5, 3, 2.0**-1000, marks=pytest.mark.slow),
    pytest.param(5, 3, 2.0**660, marks=pytest.mark.slow)])
def test_points_on_a_lower_dimensional_flat_match_the_clipping(d, k, scale, monkeypatch):
    """14 points on a k-flat of R^d (exact integer combinations): the kernel is flat,
    in the flat, and equal to the clipping's."""
    rng = np.random.default_rng(25 + k)  # scale: a power of two, so X stays on the flat
    B = rng.integers(-3, 4, size=(k, d)).astype(float)
    X = (3.0 + rng.integers(-4, 5, size=(14, k)).astype(float) @ B) * scale
    K = _check_kernel(X, 1, monkeypatch)
    assert K.dim <= k


@pytest.mark.parametrize("d", [4, 5])
def test_identical_points_give_that_point(d, monkeypatch):
    X = np.tile(np.array([-1e300, 5e-324, 1.0, 1e200, -7.0][:d]), (9, 1))
    K = _check_kernel(X, 2, monkeypatch)
    assert K.dim == 0 and K.vertices.tolist() == [X[0].tolist()]


#: 12 points of R⁵ with coordinates 0 or 1, times the smallest subnormal 2^-1074
SUBNORMAL_01 = np.array([[0, 1, 1, 1, 0], [0, 1, 0, 1, 1], [1, 1, 1, 1, 0], [0, 1, 0, 1, 0],
                         [1, 1, 1, 1, 1], [0, 1, 1, 0, 0], [0, 1, 0, 1, 1], [0, 1, 0, 1, 0],
                         [1, 1, 1, 0, 0], [0, 1, 1, 1, 1], [0, 1, 0, 1, 1], [0, 0, 0, 1, 1]],
                        dtype=float)


def test_subnormal_01_cloud_kernel_and_other_points_hold(monkeypatch):
    """The cloud of the Chebyshev failure below: its kernel (dimension 4) equals the
    clipping's, and the project / vertex-mean points are exact kernel points."""
    X = SUBNORMAL_01 * 5e-324
    K = rescon.safe_kernel(X, 1)
    assert K.dim == 4
    assert _outputs(K) == _outputs(_clipped(X, 1, monkeypatch))
    for method in ("project", "vertex-mean"):
        x, cert = K.point(method)
        assert _in_kernel_constraints(K, _exact_point(cert))
        assert rescon.check_certificate(cert).verdict == "valid"


def test_chebyshev_point_of_a_subnormal_flat_d5_kernel():
    """Fixed (was a bug: point('chebyshev') raised SolverError "the Chebyshev centre
    returned by the backend is not in the kernel" — points._frame's float mean and
    extent of the vertices underflowed to 0, and the centre mapped back to floats fell
    on the subnormal grid, outside Ψ). The same integer cloud × 1 or × 2^-1000 gives a
    Chebyshev point; × 2^-1074 the kernel is still a nonempty 4-dimensional polytope of
    exact rationals, so a point of it exists and the method must return one."""
    X = SUBNORMAL_01 * 5e-324
    K = rescon.safe_kernel(X, 1)
    assert not K.is_empty
    x, cert = K.point("chebyshev")
    assert np.isfinite(x).all()
    assert _in_kernel_constraints(K, _exact_point(cert))
    assert rescon.check_certificate(cert).verdict in ("valid", "unchecked")
