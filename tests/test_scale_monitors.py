"""The consensus engine at scale (issue 13 §1): the benign hull from Qhull-proposed,
exactly certified vertices, the diameter at every magnitude, the monitors a user
chooses, Algorithm 1's vectorised filter step, N = 5000 in the plane."""

from __future__ import annotations

import dataclasses
import math
import tracemalloc
import warnings
from fractions import Fraction
from unittest import mock

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rescon.consensus import _initial_hull, engine, metrics
from rescon.consensus.adversaries import Constant, FunctionOfTime
from rescon.consensus.engine import simulate
from rescon.consensus.metrics import ValidityMonitor, certified_hull, diameter
from rescon.consensus.scenario import Scenario
from rescon.errors import InputError
from rescon.geometry.kernel import safe_kernel
from rescon.graphs.generators import circulant

pytestmark = pytest.mark.filterwarnings("ignore::rescon.consensus.scenario.ScenarioWarning")

U = 2.0**-53


def _exact_sq_diameter(X: np.ndarray) -> Fraction:
    """max ‖x_i − x_j‖² over all pairs, exactly (integers on a common power of two)."""
    ratios = [Fraction(float(v)) for v in X.ravel()]
    den = max(r.denominator for r in ratios)
    Z = np.array([r.numerator * (den // r.denominator) for r in ratios],
                 dtype=object).reshape(X.shape)
    best = max((sum((a - b) ** 2 for a, b in zip(p, q, strict=True))
                for i, p in enumerate(Z) for q in Z[i + 1:]), default=0)
    return Fraction(best, den * den)


def _assert_near(D: float, exact_sq: Fraction, rel: float) -> None:
    """|D − √exact_sq| ≤ rel·D + 2^-1074 (the subnormal grid), decided exactly."""
    lo = max(Fraction(D) * (1 - Fraction(rel)) - Fraction(2.0**-1074), Fraction(0))
    hi = Fraction(D) * (1 + Fraction(rel)) + Fraction(2.0**-1074)
    assert lo**2 <= exact_sq <= hi**2, (D, math.sqrt(exact_sq))


def _shapes(draw, n: int, d: int) -> np.ndarray:
    """Integer clouds: general, converged (few distinct rows), collinear."""
    kind = draw(st.sampled_from(["general", "converged", "collinear"]))
    ints = st.integers(-(2**20), 2**20)
    if kind == "collinear":
        t = np.array(draw(st.lists(ints, min_size=n, max_size=n)), dtype=float)
        u = np.array(draw(st.lists(st.integers(-9, 9), min_size=d, max_size=d)), float)
        return np.outer(t, u)
    rows = draw(st.lists(st.lists(ints, min_size=d, max_size=d), min_size=1,
                         max_size=2 if kind == "converged" else n))
    X = np.array(rows, dtype=float)
    return X[np.arange(n) % len(X)]


@st.composite
def clouds(draw, n_max: int = 30):
    """(n, d) clouds of integers times 2^j at every magnitude: j from the subnormal
    range (-1074) to rows near 1e300."""
    d = draw(st.integers(1, 3))
    n = draw(st.integers(2, n_max))
    return np.ldexp(_shapes(draw, n, d), draw(st.integers(-1074, 990)))


@settings(max_examples=120, deadline=None)
@given(clouds())
def test_diameter_is_the_exact_one_at_every_magnitude(X):
    """Within (d + 2)u of the exact diameter (scaled by 2^j, converged, collinear,
    subnormal, 1e300 rows); the n² float formula overflowed to inf at 1e300 and lost
    everything to underflow at 1e-300."""
    _assert_near(diameter(X), _exact_sq_diameter(X), (X.shape[1] + 2) * U)


@settings(max_examples=80, deadline=None)
@given(clouds(n_max=40))
def test_antipodal_diameter_is_the_exact_one(X):
    """The plane's near-antipodal pairs (forced on every input, ANGULAR_MIN = 0):
    within (d + 2)u of the exact diameter at every magnitude."""
    X = np.c_[X, X[::-1, 0]][:, :2]
    with mock.patch.object(metrics, "ANGULAR_MIN", 0):
        D = diameter(X)
    _assert_near(D, _exact_sq_diameter(X), 4 * U)


@pytest.mark.parametrize("seed", range(3))
def test_diameter_of_states_on_a_circle(seed):
    """States on a circle (every row can end a diameter: the pruning kept all of them
    and compared n² pairs, ~6 s at N = 10 000): near-antipodal pairs only, the same
    float as all pairs."""
    rng = np.random.default_rng(seed)
    th = np.sort(rng.uniform(0, 2 * np.pi, 4000))
    X = np.c_[np.cos(th), np.sin(th)] * 10.0 ** rng.integers(-5, 5) + rng.normal(size=2)
    X = X + rng.normal(size=X.shape) * 10.0 ** -rng.integers(8, 16)
    every_pair = metrics._pairwise_max(X, X)
    with mock.patch.object(metrics, "_pairwise_max", side_effect=AssertionError("n²")):
        assert diameter(X) == every_pair


def test_diameter_at_1e300_and_converged_rows():
    """A 3-4-5 triangle at 2^1020 (the n² formula's squares overflow: inf), and 1000
    rows on two points at 2^-1000 (its squares underflow: 0)."""
    X = np.ldexp(np.array([[3.0, 0.0], [0.0, -4.0], [1.0, -1.0]]), 1020)
    assert diameter(X) == math.ldexp(5.0, 1020)
    tiny = np.ldexp(np.array([[3.0, 0.0], [0.0, 4.0]]), -1000)
    assert diameter(np.repeat(tiny, 500, axis=0)) == math.ldexp(5.0, -1000)
    assert diameter(np.full((1000, 3), 7.25)) == 0.0


def _vertex_set(hull) -> set:
    return set(hull.exact_vertices)


@settings(max_examples=40, deadline=None)
@given(clouds(n_max=25), st.integers(0, 3))
def test_certified_hull_is_the_exact_hull(X, seed):
    """Qhull proposes (here on every input, PROPOSE_MIN = 0), certification decides:
    the same exact polytope as the safe kernel of all rows with F = 0, and state
    distances / inside decisions equal to those of that exact hull."""
    with mock.patch.object(_initial_hull, "PROPOSE_MIN", 0):
        hull = certified_hull(X)
    exact = safe_kernel(X, 0)
    assert hull.dim == exact.dim and _vertex_set(hull) == _vertex_set(exact)
    rng = np.random.default_rng(seed)
    S = X[rng.integers(0, len(X), 6)] * rng.choice([0.5, 1.0, 1.5], size=(6, 1))
    with mock.patch.object(_initial_hull, "PROPOSE_MIN", 0):
        mon = ValidityMonitor(X)
    for x, dist in zip(S, mon.distances(S), strict=True):
        assert (dist == 0) == exact.contains(x)


def test_distance_of_a_tiny_state_does_not_underflow():
    """The exact projection's distance at 1e-162: its square underflowed and a state
    outside the hull was reported at distance 0."""
    mon = ValidityMonitor(np.array([[2.0**-537], [2.0**-537]]))
    assert mon.distances(np.array([[2.0**-538]])).tolist() == [2.0**-538]


@pytest.mark.parametrize("seed", range(3))
def test_triangle_distances_within_their_bound(seed):
    """In R³, states a facet proves outside get the point–triangle distance: within its
    certified bound of the exact projection's distance (scales 1e-40..1e40), with no
    exact projection for states clearly outside (each took ~2 ms); zero exactly for
    the states in the hull."""
    rng = np.random.default_rng(seed)
    for scale in (1.0, 1e-40, 1e40):
        mon = ValidityMonitor(rng.normal(size=(int(rng.integers(4, 120)), 3)) * scale)
        X = rng.normal(size=(60, 3)) * scale * rng.choice([0.3, 1.0, 3.0, 1e3], size=(60, 1))
        exact = np.array([mon.distance(x) for x in X])
        far = exact > 1e-6 * scale
        with mock.patch.object(mon, "distance", side_effect=AssertionError("exact")):
            fast = mon.distances(X[far])
        _, err = mon.triangle_distances(X[far])
        assert np.all(np.abs(fast - exact[far]) <= err)
        assert np.array_equal(mon.distances(X) == 0, exact == 0)


def test_initial_states_need_no_exact_test():
    """Step 0: the initial states (many on the hull's boundary, where the filter cannot
    decide) are in the hull they generate: no exact test (~6 ms each in R³)."""
    X = np.random.default_rng(2).normal(size=(300, 3))
    mon = ValidityMonitor(X)
    with mock.patch.object(mon, "distance", side_effect=AssertionError("exact")):
        assert (mon.distances(X) == 0).all()
    moved = X.copy()
    moved[0] += 100.0
    assert mon.distances(moved)[0] > 0  # only rows equal to their own initial state


def test_a_wrong_proposal_is_corrected():
    """A proposal that misses vertices (what Qhull's rounding could do) is completed by
    the exact certification. PROPOSE_MIN off: past it the plane's exact chain and R³'s
    certified surface take no proposal (the patched one was never called)."""
    rng = np.random.default_rng(4)
    for d in (2, 3):
        X = rng.normal(size=(200, d))
        right = safe_kernel(X[_initial_hull._proposed_rows(X)], 0)
        wrong = mock.Mock(return_value=np.arange(d + 1))
        with mock.patch.object(_initial_hull, "_proposed_rows", wrong), \
                mock.patch.object(_initial_hull, "PROPOSE_MIN", 10**9):
            hull = certified_hull(X)
        assert wrong.called
        assert _vertex_set(hull) == _vertex_set(right)


@pytest.mark.parametrize("leaves", [False, True])
@pytest.mark.parametrize("d", [2, 3])
def test_validity_same_as_the_exact_monitor(d, leaves):
    """A run of N = 150 (past PROPOSE_MIN): the validity distances equal those of the
    monitor built from every initial state (the code before issue 13; PROPOSE_MIN off,
    else the exact chain / certified surface take no proposal); ``leaves``: the mean
    filter and an adversary at 50 push states out of the hull (Algorithm 1 keeps every
    distance 0: outside, the two monitors' floats agree within their certified bounds, as
    in benchmarks/consensus_bench.py)."""
    sc = _case(150, d, steps=6, centre="box")
    if leaves:
        sc = dataclasses.replace(sc, algorithm="mean", adversaries={0: Constant([50.0] * d)})
    fast = simulate(sc)
    got = fast.metrics["validity_per_agent"]
    assert (got > 0).any() == leaves
    every = mock.Mock(side_effect=lambda X: np.arange(len(X)))
    with mock.patch.object(_initial_hull, "_proposed_rows", every), \
            mock.patch.object(_initial_hull, "PROPOSE_MIN", 10**9):
        slow = simulate(sc)
        ref = ValidityMonitor(fast.states[0, fast.benign])
    assert every.called and "edge_ends" not in ref.hull._cache and "cones" not in ref.hull._cache
    want = slow.metrics["validity_per_agent"]
    assert np.array_equal(got == 0, want == 0)
    mon = ValidityMonitor(fast.states[0, fast.benign])
    for X, g, w in zip(fast.states[:, fast.benign], got, want, strict=True):
        err = (2 * mon.edge_error(X) if d == 2
               else mon.triangle_distances(X)[1] + ref.triangle_distances(X)[1])
        assert np.all(np.abs(g - w) <= err)
    assert np.array_equal(fast.states, slow.states)


def test_flat_and_thin_benign_sets():
    """Collinear (exactly and up to rounding), coplanar in R³ and a single point: the
    hull is found without the O(n^d) kernel of all rows (which refused these)."""
    rng = np.random.default_rng(0)
    t = rng.integers(-99, 99, size=6000).astype(float)
    for X in (np.outer(t, [1.0, 3.0]), np.outer(rng.normal(size=6000), [1.0, 3.0]),
              np.c_[rng.normal(size=(3000, 2)), np.ones(3000)], np.full((5000, 3), 1e300)):
        mon = ValidityMonitor(X)
        assert len(mon.hull.points) < 100
        assert (mon.distances(X[:50]) == 0).all()
        assert mon.distances(X[:1] * 1.5 + 1.0)[0] > 0


# --------------------------------------------------------------------------- #
# monitors a user chooses
# --------------------------------------------------------------------------- #


def _case(N: int, d: int, steps: int, **kw) -> Scenario:
    k = (d + 1) + 1
    x0 = np.random.default_rng(N).uniform(0, 10, size=(N, d))
    adv = {0: FunctionOfTime(lambda t: np.full(d, 3 * np.sin(t)))}
    return Scenario(graph=circulant(N, k), x0=x0, F=1, adversaries=adv, steps=steps,
                    residual="none", check_robustness=False, **kw)


def test_monitor_selection():
    sc = _case(40, 2, steps=5)
    full = simulate(sc)
    with mock.patch.object(engine, "ValidityMonitor", side_effect=AssertionError("built")):
        only = simulate(sc, metrics=["diameter", "spread"])
        none = simulate(sc, metrics=[])
    assert list(only.metrics) == ["spread", "diameter", "blocked_links", "starved"]
    assert list(none.metrics) == ["blocked_links", "starved"]
    assert np.array_equal(only.metrics["diameter"], full.metrics["diameter"])
    assert np.array_equal(only.states, full.states)
    assert list(simulate(sc, metrics="validity").metrics)[:2] == ["validity",
                                                                  "validity_per_agent"]
    for bad in (["diam"], 3):
        with pytest.raises(InputError, match="^metrics"):
            simulate(sc, metrics=bad)


# --------------------------------------------------------------------------- #
# Algorithm 1's filter step, vectorised
# --------------------------------------------------------------------------- #


def _per_agent_problems(links, values, usable, benign, m, d):
    """The filter step as it was: per agent, per coordinate, an argsort."""
    out = {}
    for r, i in enumerate(benign):
        sl = slice(links.start[i], links.start[i + 1])
        X = values[sl][usable[sl]]
        if len(X) >= m:
            sets = []
            for p in range(d):
                order = np.argsort(X[:, p], kind="stable")
                sets += [X[order[:m]], X[order[-m:]]]
            out[r] = sets
    return out


@pytest.mark.parametrize("d", [2, 3])
def test_vectorised_filter_step_selects_the_per_agent_sets(d):
    """Irregular in-degrees, blocked and non-finite links, ties: every agent's Y_p, Z_p
    are those of the per-agent argsort, the starved agents the same."""
    rng = np.random.default_rng(d)
    G = nx.gnp_random_graph(60, 0.25, seed=d, directed=True)
    x0 = rng.integers(0, 4, size=(60, d)).astype(float)  # many ties
    sc = Scenario(graph=G, x0=x0, F=1, steps=1, residual="none", check_robustness=False)
    links = engine._Links(sc)
    values = rng.integers(0, 4, size=(len(links.recv), d)).astype(float)
    usable = rng.random(len(links.recv)) < 0.7
    benign = np.arange(60)
    m = (d + 1) + 1
    seen = []
    with mock.patch.object(engine, "_kernel_points",
                           lambda P, *a: seen.append(P) or P[:, 0, :]):
        _, starved = engine._alg1_auxiliary(sc, links, x0, values, usable, benign, d, {})
    expect = _per_agent_problems(links, values, usable, benign, m, d)
    assert sorted(set(range(60)) - set(expect)) == list(starved)
    got = np.concatenate(seen).reshape(-1, 2 * d, m, d)
    order = [r for c, rows, _ in engine._usable_groups(links, usable, benign)
             if c >= m for r in rows]
    assert len(order) == len(expect) > 0
    for r, sets in zip(order, got, strict=True):
        assert np.array_equal(sets, np.stack(expect[r]))


def _wmsr_one(own, X, F):
    """W-MSR of one agent as it was computed (per coordinate, a sort and a mean)."""
    out = np.empty_like(own)
    for p in range(len(own)):
        v = np.sort(X[:, p])
        below, equal, above = v[v < own[p]], v[v == own[p]], v[v > own[p]]
        out[p] = np.concatenate([below[min(F, len(below)):], equal,
                                 above[:len(above) - min(F, len(above))], [own[p]]]).mean()
    return out


@pytest.mark.parametrize("F", [1, 3])
@pytest.mark.parametrize("algorithm", ["wmsr", "mean"])
def test_vectorised_baselines_same_floats_as_per_agent(algorithm, F):
    """W-MSR and the mean baseline, grouped by number of usable values: the same floats
    as the per-agent computation (irregular degrees up to ~25 values, unusable links,
    ties with the own value, magnitudes 1e-140..1e140)."""
    rng = np.random.default_rng(F)
    G = nx.gnp_random_graph(80, 0.2, seed=F, directed=True)
    x0 = rng.integers(0, 5, size=(80, 2)) * rng.choice([1e-140, 1.0, 1e140], size=(80, 1))
    sc = Scenario(graph=G, x0=x0, F=F, steps=1, residual="none", check_robustness=False,
                  algorithm=algorithm)
    links = engine._Links(sc)
    values = x0[links.send] * rng.choice([1.0, 1.5, 0.5], size=(len(links.send), 1))
    usable = rng.random(len(links.recv)) < 0.8
    benign = np.arange(80)
    aux, starved = engine._auxiliary(sc, links, x0, values, usable, benign, 2, {})
    assert len(starved) == 0
    for r in benign:
        sl = slice(links.start[r], links.start[r + 1])
        X = values[sl][usable[sl]]
        one = (_wmsr_one(x0[r], X, F) if algorithm == "wmsr"
               else engine._scaled_mean(np.vstack([X, x0[r]])))
        assert np.array_equal(aux[r], one), r


# --------------------------------------------------------------------------- #
# N = 5000 in the plane
# --------------------------------------------------------------------------- #


@pytest.mark.slow
def test_n5000_plane_runs_in_linear_memory():
    """simulate refused N = 5000, d = 2 (the validity hull of 5000 states by the
    O(n^d)-candidate kernel); now every monitor runs, with peak memory far below one
    N×N float array (200 MB), and the states stay in the benign hull."""
    sc = _case(5000, 2, steps=3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tracemalloc.start()
        tr = simulate(sc)
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    assert peak < 60e6, peak
    assert tr.metrics["validity"].max() == 0.0
    assert 0 < tr.metrics["diameter"][-1] < tr.metrics["diameter"][0]


def test_n600_space_every_monitor():
    """N = 600 in R³ was refused (the hull of 599 benign states by the O(n³) kernel:
    ~1e11 steps); now it runs with every monitor on."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = simulate(_case(600, 3, steps=2))
    assert tr.metrics["validity"].max() == 0.0
    assert tr.metrics["diameter"][-1] < tr.metrics["diameter"][0]
