"""V27 hostile review: ``rescon.simulate`` / ``rescon.rmdo`` at the edges a long run or
a hostile user reaches (engine, monitors, adversaries, DoS, scenario, RMDO steps).

Attacked: horizons whose times pass the float range (T huge), user residual callables
returning NaN with the monitors deselected (``metrics=[]``), W-MSR with F = 0 and
adversaries sending ±1.7e308, the trajectory-size memory check against what a run
really allocates (adversaries' ``sent`` band), RMDO with a far optimum (1e200, a
state-limit violation of ``optimum=``), T tiny in ``cost_rate``; and, holding:
metrics recomputed from ``Trajectory.states`` (spread, diameter, 1-D and 2-D validity
against an exact Fractions/LP recomputation), states converging to 1 ulp over 2000
steps, 1e-300 / subnormal / 1e140 mixed states, adversaries at ±1e300, alternating
and non-finite messages, adversaries copying benign states (filter ties), duplicate
benign states, F at its largest, DoS windows covering everything / nothing / every
other step, α at and beyond its bounds, RMDO step sizes tiny/huge, a far (1e100)
argmin, N = 2 benign agents, runs repeated and pickled scenarios (bit-identical).
"""

from __future__ import annotations

import json
import pickle
import signal
import warnings
from fractions import Fraction

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon import Scenario
from rescon.consensus import scenario as scenario_mod
from rescon.consensus.adversaries import Constant, NonFinite, OwnState, TwoFaced, TwoFacedTable
from rescon.consensus.dos import DoSAttack, Explicit, Periodic
from rescon.errors import InputError


@pytest.fixture(autouse=True)
def _quiet():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def _complete(n: int) -> nx.DiGraph:
    return nx.complete_graph(n).to_directed()


def _sc(n=4, x0=None, **kw) -> Scenario:
    x0 = [[float(i)] for i in range(n)] if x0 is None else x0
    kw.setdefault("check_robustness", False)
    return Scenario(graph=_complete(n), x0=x0, **kw)


def _frac_hull_dist_1d(x: float, pts: list[float]) -> Fraction:
    lo, hi = min(map(Fraction, pts)), max(map(Fraction, pts))
    X = Fraction(x)
    return max(lo - X, X - hi, Fraction(0))


# ------------------------------------ bugs (strict xfails at first; all fixed)


# Fixed (was a bug: T*steps past the float range puts inf in Trajectory.times;
# trajectory.json then holds 'Infinity' (invalid JSON))
def test_huge_T_times_are_finite_json():
    try:  # refused when read (a one-line InputError), or finite times
        tr = rescon.simulate(_sc(F=1, steps=3, T=1e308))
    except InputError as exc:
        assert "steps·T" in str(exc)
        return
    assert np.isfinite(tr.times).all()
    json.dumps(tr.to_json(), allow_nan=False)


# Fixed (was a bug: a residual callable returning NaN reaches the states unchecked
# (ConvexStep adds it blindly); with metrics=[] the run completes with NaN states)
def test_nan_residual_refused():
    sc = _sc(F=1, steps=3, residual=lambda t: float("nan"))
    try:
        tr = rescon.simulate(sc, metrics=[])
    except InputError:
        return
    assert np.isfinite(tr.states[:, tr.benign]).all()


# Fixed (was a bug: W-MSR averages kept values with a plain .mean
# (engine._baseline_auxiliary): two adversaries at 1.7e308 with F = 0 make benign states
# inf)
def test_wmsr_huge_adversaries_states_finite():
    sc = _sc(F=0, steps=3, algorithm="wmsr",
             adversaries={0: Constant([1.7e308]), 1: Constant([1.7e308])})
    try:
        tr = rescon.simulate(sc, metrics=[])
    except InputError:
        return
    assert np.isfinite(tr.states[:, tr.benign]).all()


# Fixed (was a bug: with metrics on, the same W-MSR run stops with a misleading
# validity-monitor message ('x must be a finite point') instead of the documented 'diverged'
# error)
def test_wmsr_huge_adversaries_diverged_message():
    sc = _sc(F=0, steps=3, algorithm="wmsr",
             adversaries={0: Constant([1.7e308]), 1: Constant([1.7e308])})
    try:
        rescon.simulate(sc)
    except InputError as exc:
        assert "diverged" in str(exc)
    else:  # finite states are fine too
        pass


# Fixed (was a bug: the trajectory-size check (8(K+1)(Nd+N+d+4) bytes) omits the
# adversaries' sent band (K+1, |A|, 2, d): a run it admits allocates ~2x its estimate)
def test_memory_estimate_covers_sent_band(monkeypatch):
    # (integrator: the check is that the estimate covers what the run allocates — with
    # the machine's memory just below the allocation, the scenario is refused)
    from rescon.consensus import scenario as scenario_module

    n, d, K = 10, 4, 200
    x0 = [[float(i + p) for p in range(d)] for i in range(n)]
    advs = {i: Constant([0.5] * d) for i in range(1, n)}

    def make():
        return Scenario(graph=_complete(n), x0=x0, F=0, steps=K, adversaries=advs,
                        check_robustness=False)

    tr = rescon.simulate(make())
    used = tr.states.nbytes + tr.sent.nbytes + sum(v.nbytes for v in tr.metrics.values())
    monkeypatch.setattr(scenario_module, "_memory_bytes", lambda: used - 1)
    with pytest.raises(InputError, match="trajectory would need"):
        make()


# Fixed (was a bug: rmdo's distance_to_optimum is np.linalg.norm of x - x*, which overflows
# to inf for x* = 1e200 (optimum= is only checked finite, not against the state limit))
def test_rmdo_far_optimum_distance_finite():
    sc = _sc(F=0, steps=3)
    try:
        tr = rescon.rmdo(sc, {i: "abs(x1 - 1e200)" for i in range(4)}, optimum=[1e200])
    except InputError:
        return
    assert np.isfinite(tr.metrics["distance_to_optimum"]).all()


# Fixed (was a bug: Scenario.warn (run by simulate/rmdo) enumerates every DoS window on [0,
# steps*T] in Fractions (check_assumption3 -> _union_exact -> Periodic._exact_windows): a
# 10-step run with period 1e-5 takes ~75 s and 230 MB (1e-7: hours, GBs))
def test_fine_periodic_dos_does_not_hang():
    def boom(*_):
        raise TimeoutError("warn() still running after 3 s")

    sc = _sc(F=1, steps=10, dos=(DoSAttack("a", {(0, 1)}, Periodic(period=1e-5,
                                                                  duration=5e-6)),))
    old = signal.signal(signal.SIGALRM, boom)
    signal.setitimer(signal.ITIMER_REAL, 3.0)
    try:
        sc.warn()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


# Fixed (was a bug: rmdo's cost_rate = dF/T overflows to -inf for a valid tiny T (1e-310);
# no InputError, inf in the metrics)
def test_rmdo_cost_rate_finite_tiny_T():
    sc = _sc(F=0, steps=3, T=1e-310)
    try:
        tr = rescon.rmdo(sc, {i: f"(x1 - {10 * i})^2" for i in range(4)}, step_size=0.01)
    except InputError:
        return
    assert np.isfinite(tr.metrics["cost_rate"][1:]).all()


# Fixed (was a bug: rmdo's numerical X* (Optimum._numerical, Nelder-Mead from the benign
# mean in the raw frame) stops at 1.5 for a sum whose argmin is ~3.3e99: F looks flat there
# in floats; the optimality gap then goes negative (-2.8e199))
def test_rmdo_numerical_optimum_far_argmin():
    sc = _sc(F=0, steps=10)
    costs = {0: "(x1 - 1e100)^2", 1: "abs(x1 - 3)", 2: "x1^2", 3: "x1^2"}
    tr = rescon.rmdo(sc, costs, step_size=0.1)
    if "point" not in tr.info["optimum"]:
        return  # "not found" is an honest answer
    gap = tr.metrics["optimality_gap"]
    assert (gap >= -1e-12 * np.abs(tr.metrics["cost"]).max()).all(), gap.min()


# Fixed (was a bug: RandomDoS.active(t) rebuilds the list of every merged window up to t
# (windows(): [w[0] for w in merged] and a copy) at each call, so a run is O(K^2): 8000
# steps spend 5 s in blocked_mask, 200 checks near t = 2e5 take ~5 s)
def test_random_dos_active_is_not_linear_in_t():
    from rescon.consensus.dos import RandomDoS

    def boom(*_):
        raise TimeoutError("RandomDoS.active too slow")

    s = RandomDoS(rate=1.0, mean_duration=0.2, seed=1)
    s.windows(2e5)  # ~1.7e5 windows, built once (0.2 s)
    old = signal.signal(signal.SIGALRM, boom)
    signal.setitimer(signal.ITIMER_REAL, 2.0)
    try:
        for k in range(200):
            s.active(1.9e5 + k)
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


# ---------------------------------------------------------------- attacks that held


def test_memory_check_refuses_and_admits(monkeypatch):
    monkeypatch.setattr(scenario_mod, "_memory_bytes", lambda: 10_000)
    with pytest.raises(InputError, match="memory"):
        _sc(F=1, steps=10_000)
    _sc(F=1, steps=10)


@pytest.mark.parametrize("d", [1, 2, 3, pytest.param(4, marks=pytest.mark.slow)])
def test_spread_diameter_recomputed(d):
    rng = np.random.default_rng(d)
    n = 3 * ((d + 1) + 1) + 2
    x0 = rng.normal(size=(n, d))
    G = nx.circulant_graph(n, range(1, (d + 2) + 1)).to_directed()
    sc = Scenario(graph=G, x0=x0, F=1, steps=40, adversaries={0: Constant([50.0] * d)},
                  residual="none",
                  check_robustness=False)
    tr = rescon.simulate(sc)
    xb = tr.states[:, tr.benign]
    assert np.array_equal(tr.metrics["spread"], xb.max(axis=1) - xb.min(axis=1))
    for k in range(0, 41, 10):
        D = max(np.linalg.norm(a - b) for a in xb[k] for b in xb[k])
        assert tr.metrics["diameter"][k] == pytest.approx(D, rel=1e-14, abs=0)
    assert tr.max_validity == 0.0


def test_validity_1d_exact_with_residual_and_adversary():
    n = 6
    sc = _sc(n=n, x0=[[float(i)] for i in range(n)], F=1, steps=30,
             adversaries={0: Constant([1e300])}, residual="0.5^t")
    tr = rescon.simulate(sc)
    init = [float(v) for v in sc.x0[tr.benign, 0]]
    for k in range(31):
        exact = max(_frac_hull_dist_1d(float(v), init) for v in tr.states[k, tr.benign, 0])
        assert tr.metrics["validity"][k] == float(exact)


def test_validity_2d_exact_lp_small():
    from scipy.optimize import linprog

    x0 = [[0, 0], [4, 0], [0, 4], [1, 1], [3, 0.5], [0.5, 3], [2, 2], [1, 2]]
    G = _complete(8)
    sc = Scenario(graph=G, x0=x0, F=1, steps=5, residual="0.9^t",
                  adversaries={7: Constant([100.0, 100.0])}, check_robustness=False)
    tr = rescon.simulate(sc)
    B = np.asarray(x0, float)[tr.benign]
    for k in (0, 1, 5):
        for i, x in zip(tr.benign, tr.states[k, tr.benign], strict=True):
            inside = linprog(np.zeros(len(B)), A_eq=np.vstack([B.T, np.ones(len(B))]),
                             b_eq=np.append(x, 1), bounds=(0, None)).status == 0
            got = tr.metrics["validity_per_agent"][k, list(tr.benign).index(i)]
            assert (got == 0) == inside


def test_long_run_converges_to_ulp_d2():
    x0 = [[i % 3 + 0.1 * i, i // 3 - 0.05 * i] for i in range(9)]
    G = nx.circulant_graph(9, [1, 2, 3, 4]).to_directed()
    sc = Scenario(graph=G, x0=x0, F=1, steps=2000, residual="none",
                  adversaries={0: TwoFaced(TwoFacedTable(cycle=[[1e150, -1e150],
                                                                [-1e150, 1e150]]))},
                  check_robustness=False)
    tr = rescon.simulate(sc)
    xb = tr.states[-1, tr.benign]
    assert np.isfinite(tr.states[:, tr.benign]).all()
    assert tr.final_diameter <= 4 * np.spacing(np.abs(xb).max())
    assert tr.max_validity == 0.0


def test_mixed_magnitudes_subnormal_and_1e140():
    x0 = [[5e-324], [1e-300], [1.0], [1e140], [-1e140], [0.0]]
    sc = _sc(n=6, x0=x0, F=1, steps=50, residual="none",
             adversaries={5: Constant([-1e300])})
    tr = rescon.simulate(sc)
    xb = tr.states[:, tr.benign, 0]
    assert np.isfinite(xb).all()
    assert tr.max_validity == 0.0
    assert (xb >= -1e140).all() and (xb <= 1e140).all()
    assert np.array_equal(tr.metrics["spread"][:, 0], xb.max(axis=1) - xb.min(axis=1))


def test_adversary_copies_benign_state_ties():
    x0 = [[1.0, 1.0]] * 3 + [[2.0, 0.0], [0.0, 2.0], [1.0, 1.0], [2.0, 2.0], [0.0, 0.0]]
    sc = Scenario(graph=_complete(8), x0=x0, F=1, steps=50, residual="none",
                  adversaries={0: OwnState()}, check_robustness=False)
    tr = rescon.simulate(sc)
    assert tr.max_validity == 0.0
    assert tr.final_diameter < 1e-9


def test_nonfinite_adversary_is_nothing_sent():
    sc = _sc(n=6, F=1, steps=20, adversaries={0: NonFinite("mixed")})
    tr = rescon.simulate(sc)
    assert np.isfinite(tr.states[:, tr.benign]).all()
    assert tr.max_validity == 0.0


@pytest.mark.parametrize("sched", [Periodic(period=1.0, duration=1.0),
                                   Explicit([[100.0, 200.0]]),
                                   Periodic(period=1.0, duration=0.5)])
def test_dos_everything_nothing_every_other(sched):
    n = 5
    links = {(i, j) for i in range(n) for j in range(n) if i != j}
    sc = _sc(n=n, F=1, steps=10, T=0.5, dos=(DoSAttack("all", links, sched),))
    tr = rescon.simulate(sc)
    assert np.isfinite(tr.states).all()
    assert tr.max_validity == 0.0
    blocked = tr.metrics["blocked_links"]
    assert set(np.unique(blocked)) <= {0, len(links)}


def test_dos_everything_from_start_all_starved():
    n = 5
    links = {(i, j) for i in range(n) for j in range(n) if i != j}
    sc = _sc(n=n, F=1, steps=5, dos=(DoSAttack("all", links, Periodic(period=1.0,
                                                                     duration=1.0)),))
    tr = rescon.simulate(sc)
    assert np.array_equal(tr.states[-1], tr.states[0])
    assert (tr.metrics["starved"][:-1] == n).all()


def test_alpha_bounds():
    with pytest.raises(InputError):
        _sc(F=1, alpha=0.25, c=0.75)
    with pytest.raises(InputError):
        _sc(F=1, alpha=0.75, c=0.75)
    tr = rescon.simulate(_sc(F=1, steps=20, alpha=np.nextafter(0.75, 0), c=0.75,
                             residual="none"))
    assert tr.max_validity == 0.0


def test_F_at_largest():
    with pytest.raises(InputError):
        _sc(n=4, F=3)
    tr = rescon.simulate(_sc(n=4, F=2, steps=5))
    assert np.isfinite(tr.states).all()


def test_repeat_and_pickle_identical():
    sc = Scenario.paper_example(steps=30)
    a = rescon.simulate(sc)
    b = rescon.simulate(sc)
    c = rescon.simulate(pickle.loads(pickle.dumps(sc)))
    for t in (b, c):
        assert np.array_equal(a.states, t.states, equal_nan=True)
        for k, v in a.metrics.items():
            assert np.array_equal(v, t.metrics[k], equal_nan=True)


def test_metrics_selection_same_states():
    sc = _sc(n=6, F=1, steps=20, adversaries={0: Constant([7.0])})
    a = rescon.simulate(sc)
    b = rescon.simulate(sc, metrics="diameter")
    assert np.array_equal(a.states, b.states, equal_nan=True)
    assert "validity" not in b.metrics and np.array_equal(a.metrics["diameter"],
                                                          b.metrics["diameter"])
    with pytest.raises(InputError):
        rescon.simulate(sc, metrics=" , ")


def test_two_benign_agents():
    G = _complete(3)
    sc = Scenario(graph=G, x0=[[0.0], [1.0], [9.0]], F=0, steps=50, residual="none",
                  adversaries={2: Constant([1e150])}, check_robustness=False)
    tr = rescon.simulate(sc)
    assert np.isfinite(tr.states[:, tr.benign]).all()


@pytest.mark.parametrize("beta", [1e-300, 1e-12])
def test_rmdo_tiny_steps_stay_put_finite(beta):
    sc = _sc(F=0, steps=20)
    tr = rescon.rmdo(sc, {i: "(x1 - 1)^2" for i in range(4)}, step_size=beta)
    assert np.isfinite(tr.metrics["cost"]).all()
    assert tr.max_validity == 0.0


def test_rmdo_huge_step_refused_one_line():
    sc = _sc(F=0, steps=50)
    with pytest.raises(InputError) as exc:
        rescon.rmdo(sc, {i: f"(x1 - {i})^2" for i in range(4)}, step_size=1e150)
    assert "\n" not in str(exc.value)


def test_rmdo_far_argmin_exact_distance():
    sc = _sc(F=0, steps=10)
    tr = rescon.rmdo(sc, {i: "(x1 - 1e100)^2" for i in range(4)})
    assert tr.info["optimum"]["point"] == [1e100]
    assert np.isfinite(tr.metrics["distance_to_optimum"]).all()


def test_rmdo_distance_recomputed():
    sc = _sc(F=0, steps=30)
    tr = rescon.rmdo(sc, {i: f"(x1 - {i})^2" for i in range(4)}, step_size=0.05)
    xb = tr.states[:, tr.benign, 0]
    assert np.allclose(tr.metrics["distance_to_optimum"], np.abs(xb - 1.5).max(axis=1),
                       rtol=0, atol=1e-15)
    cost = sum((xb - i) ** 2 for i in range(4))
    assert np.allclose(tr.metrics["cost"], cost, rtol=1e-14, atol=1e-14)


def test_cli_json_one_object(tmp_path, capsys):
    from rescon.cli import main

    p = tmp_path / "s.toml"
    p.write_text('[scenario]\nF = 1\nsteps = 5\n[graph]\nedges = [[0,1],[1,0],[0,2],[2,0],'
                 '[1,2],[2,1],[0,3],[3,0],[1,3],[3,1],[2,3],[3,2]]\n[initial]\n'
                 '0 = [0.0]\n1 = [1e-300]\n2 = [1e140]\n3 = [5e-324]\n'
                 '[adversaries.0]\nkind = "constant"\nvalue = [1e300]\n')
    rc = main(["simulate", str(p), "--json", "--out", str(tmp_path / "o")])
    out = capsys.readouterr().out
    assert rc in (0, None)
    obj = json.loads(out)
    assert obj["max_validity"] == 0.0
    json.loads((tmp_path / "o" / "trajectory.json").read_text(),
               parse_constant=lambda c: pytest.fail(c))


def test_to_dict_roundtrip_and_pickle_random_parts_identical():
    from rescon.consensus.adversaries import RandomInBox
    from rescon.consensus.dos import RandomDoS

    G = nx.circulant_graph(9, [1, 2, 3, 4]).to_directed()
    x0 = np.random.default_rng(1).normal(size=(9, 2))
    sc = Scenario(graph=G, x0=x0, F=1, steps=30, T=0.1, residual="0.3^t",
                  alpha={1: 0.3, 2: 0.7}, adversaries={0: RandomInBox(scale=3.0)},
                  dos=(DoSAttack("r", {(1, 2), (3, 4)}, RandomDoS(rate=0.5,
                                                                   mean_duration=0.3,
                                                                   seed=4)),),
                  check_robustness=False)
    a = rescon.simulate(sc)
    for other in (Scenario.from_dict(sc.to_dict()), pickle.loads(pickle.dumps(sc))):
        assert np.array_equal(a.states, rescon.simulate(other).states, equal_nan=True)


@pytest.mark.slow
def test_d3_two_faced_1e300_mixed_magnitudes():
    n = 13
    G = nx.circulant_graph(n, [1, 2, 3, 4, 5]).to_directed()
    x0 = np.random.default_rng(3).normal(size=(n, 3)) * np.array([1e140, 1, 1e-300])
    cyc = [[1e300, -1e300, 1e300], [-1e300, 1e300, -1e300], [0, 0, 0]]
    sc = Scenario(graph=G, x0=x0, F=1, steps=25, residual="none",
                  adversaries={0: TwoFaced(TwoFacedTable(cycle=cyc))}, check_robustness=False)
    tr = rescon.simulate(sc)
    xb = tr.states[:, tr.benign]
    assert np.isfinite(xb).all() and tr.max_validity == 0.0
    assert np.array_equal(tr.metrics["spread"], xb.max(axis=1) - xb.min(axis=1))
    assert tr.metrics["diameter"][-1] < tr.metrics["diameter"][0]


def test_cli_rmdo_json_one_object_with_warnings(tmp_path, capsys):
    from rescon.cli import main

    p = tmp_path / "r.toml"
    p.write_text('[scenario]\nF = 1\nsteps = 5\n[graph]\nedges = [[0,1],[1,0],[0,2],[2,0],'
                 '[1,2],[2,1],[0,3],[3,0],[1,3],[3,1],[2,3],[3,2]]\n[initial]\n'
                 '0 = [0.0]\n1 = [1.0]\n2 = [2.0]\n3 = [3.0]\n[costs]\n'
                 '0 = "(x1 - 1e100)^2"\n1 = "x1^2"\n2 = "x1^2"\n3 = "x1^2 + 1"\n'
                 '[step_size]\nkind = "sqrt_decay"\nc = 0.001\n')
    rc = main(["rmdo", str(p), "--json"])
    cap = capsys.readouterr()
    assert rc in (0, None)
    obj = json.loads(cap.out)
    assert obj["optimum"]["exact"] is True
    assert "Assumption 5" in cap.err
