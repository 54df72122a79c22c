"""Algorithm 2 (rescon.rmdo) on the one consensus engine: convergence to X* under
attacks, the cost metrics, X* (given, exact for quadratics, numerical), error paths,
and Algorithm 1 left bit-identical by the pluggable update rule."""

from __future__ import annotations

import doctest
import hashlib
import re
import warnings
from fractions import Fraction

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon import InputError, Scenario, ScenarioWarning, rmdo, simulate
from rescon.consensus.adversaries import Constant, NonFinite, TwoFaced, TwoFacedTable
from rescon.consensus.dos import DoSAttack, Explicit, Periodic
from rescon.graphs.generators import circulant
from rescon.optim import atoms
from rescon.optim.oracle import CallableOracle
from rescon.optim.steps import harmonic

pytestmark = pytest.mark.filterwarnings("ignore::rescon.consensus.scenario.ScenarioWarning")

C = np.array([5.0, 4.0])  # the common minimiser, inside the initial benign hull


def scenario(adversary=None, *, steps=200, n=14, d=2, F=1, seed=3, dos=True, **kw) -> Scenario:
    """A circulant in which every agent receives from 2((d+1)F+1) neighbours, agent 0
    the adversary, periodic DoS on 8 links (hold-last by default)."""
    G = circulant(n, (d + 1) * F + 1)
    x0 = np.random.default_rng(seed).uniform(0, 10, size=(n, d))
    attacks = ()
    if dos:
        links = sorted((i, j) for j, i in G.edges if i % 3 == 1)[:8]
        attacks = (DoSAttack("periodic", frozenset(links), Periodic(period=4.0, duration=1.5)),)
    return Scenario(graph=G, x0=x0, F=F, adversaries={0: adversary} if adversary else {},
                    steps=steps, seed=seed, dos=attacks, check_robustness=False, **kw)


def redundant_quadratics(sc: Scenario, seed: int = 0) -> dict:
    """½(x − C)ᵀQ_i(x − C), Q_i ⪰ I random: every subset has argmin {C}."""
    rng = np.random.default_rng(seed)
    out = {}
    for v in sc.benign:
        M = rng.normal(size=(sc.d, sc.d))
        out[v] = atoms.Quadratic(M @ M.T + np.eye(sc.d), C)
    return out


# --------------------------------------------------------------------------- #
# the update rule leaves Algorithm 1 as it was
# --------------------------------------------------------------------------- #


def fingerprint(tr) -> str:
    h = hashlib.sha256(np.ascontiguousarray(tr.states).tobytes())
    for k in tr.metrics:
        h.update(k.encode())
        h.update(np.ascontiguousarray(tr.metrics[k]).tobytes())
    return h.hexdigest()[:16]


#: computed with the engine before the update rule was made pluggable (commit f22b181):
#: states and every metric, byte for byte; the kernel points are exact, so these do not
#: depend on the float batch paths
BEFORE = {
    "alg1-exact-hold": ({"kernel_point": "project-exact"}, "11892169c319e86b"),
    "alg1-exact-drop": ({"kernel_point": "project-exact", "policy": "drop"}, "75704fde7dbb28ae"),
    "wmsr-drop": ({"algorithm": "wmsr", "policy": "drop"}, "ad6b98578e706c71"),
    # mean-zero and wmsr-drop re-recorded at 77f6cb6: the validity distance of a state
    # outside the hull is now the rounding of its exact distance (from exact differences to
    # the exact projection); 11 steps (mean-zero) and 1 step (wmsr-drop) moved by <= 1 ulp,
    # the states and every other metric unchanged. mean-zero re-recorded again at cab74c1:
    # z = αx + (1−α)x̃ is computed from the nearer end (engine._between: between x and x̃
    # in floats at every magnitude, x exactly when x̃ = x — V22's states at 5e-324 drifted
    # to 0); 42 of 744 state entries moved by ≤ 1.4e-16, spread and validity_per_agent
    # by ≤ 4.4e-16 in 3 entries, diameter and validity unchanged. All four re-recorded at
    # 9a55cfd: means held between their slice's min and max (engine._scaled_mean; 8 equal
    # values averaged to the next float, V36): 34 of 744 state entries moved by ≤ 8.9e-16,
    # every metric unchanged
    "mean-zero": ({"algorithm": "mean", "policy": "zero"}, "446b71aa7ef5f316"),
}


@pytest.mark.parametrize("case", sorted(BEFORE))
def test_algorithm1_trajectories_are_bit_identical_to_before(case, monkeypatch):
    # the exact validity path of commit f22b181 (outside a polygon the monitor now uses
    # edge distances within their bound: tests/test_validity_monitor.py)
    monkeypatch.setattr("rescon.consensus._validity_monitor._polygon_edges", lambda hull: None)
    kw, expected = BEFORE[case]
    tr = simulate(Scenario.paper_example(check_robustness=False, steps=30, **kw))
    assert list(tr.metrics) == ["spread", "diameter", "validity", "validity_per_agent",
                                "blocked_links", "starved"]
    if case == "alg1-exact-drop":
        assert tr.metrics["starved"].sum() > 0  # the holding path is covered
    assert fingerprint(tr) == expected


def test_zero_subgradients_give_algorithm1_without_residual():
    """With d_i = 0 the two rules coincide: the same receive/filter machinery."""
    sc = scenario(Constant([100.0, -50.0]), steps=40, residual="none")
    zero = atoms.Affine([0.0, 0.0])
    tr2 = rmdo(sc, {v: zero for v in sc.benign}, optimum=[0.0, 0.0])
    tr1 = simulate(sc)
    assert np.array_equal(tr1.states, tr2.states)
    for k in tr1.metrics:
        assert np.array_equal(tr1.metrics[k], tr2.metrics[k])


# --------------------------------------------------------------------------- #
# convergence to X*
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("adversary", [Constant([100.0, -50.0]), NonFinite("mixed")],
                         ids=["constant", "nan"])
def test_redundant_quadratics_converge_to_the_common_minimiser(adversary):
    sc = scenario(adversary)
    tr = rmdo(sc, redundant_quadratics(sc))
    assert tr.info["optimum"]["exact"] and tr.info["optimum"]["point"] == C.tolist()
    assert tr.metrics["blocked_links"].max() > 0
    dist = tr.metrics["distance_to_optimum"]
    assert dist[0] > 5 and dist[-1] < 0.02 and dist[-1] < dist[100]
    final = tr.states[-1, tr.benign]
    assert np.abs(final - C).max() == pytest.approx(0, abs=0.02)
    assert tr.metrics["optimality_gap"][-1] < 1e-3
    assert tr.metrics["diameter"][-1] < 0.02


def test_lasso_like_costs_converge_under_a_two_faced_adversary():
    """f_i(x) = ½‖D_i(x − C)‖² + λ_i‖x − C‖₁ (a LASSO-like sum whose parts share the
    minimiser C) with a two-faced adversary sending each receiver a different far
    value, under periodic hold-last DoS."""
    rng = np.random.default_rng(11)
    sc = scenario(TwoFaced(TwoFacedTable(cycle=[[60.0, -40.0], [-80.0, 90.0], [30.0, 30.0]])))
    costs = {v: f"0.5*({rng.uniform(0.5, 2):.3f}*(x1 - 5)^2 + {rng.uniform(0.5, 2):.3f}"
                f"*(x2 - 4)^2) + {rng.uniform(0.1, 1):.3f}*norm1(x1 - 5, x2 - 4)"
             for v in sc.benign}
    tr = rmdo(sc, costs)
    assert tr.info["optimum"]["point"] == pytest.approx(C.tolist(), abs=1e-6)
    dist = tr.metrics["distance_to_optimum"]
    assert dist[0] > 5 and dist[-1] < 0.02 and dist[-1] < dist[100]
    assert tr.metrics["diameter"][-1] < 0.02


def test_shifted_absolute_values_converge():
    sc = scenario(Constant([100.0, -50.0]))
    tr = rmdo(sc, {v: atoms.Norm1(np.eye(2), C) for v in sc.benign})
    assert not tr.info["optimum"]["exact"]  # polyhedral: X* found numerically
    assert tr.info["optimum"]["point"] == pytest.approx(C.tolist(), abs=1e-8)
    dist = tr.metrics["distance_to_optimum"]
    assert dist[-1] < 0.01 and dist[-1] < dist[50]


def test_costs_as_expression_strings_and_shared_oracles():
    sc = scenario(None, steps=150, dos=False)
    costs = {v: "(x1 - 5)^2 + (x2 - 4)^2" for v in sc.benign}
    tr = rmdo(sc, costs)
    assert tr.info["oracles"] == 1  # equal strings share one oracle
    dist = tr.metrics["distance_to_optimum"]
    assert dist[-1] < 0.02 and dist[-1] < dist[50] / 2


# --------------------------------------------------------------------------- #
# batching: one call per distinct oracle and step
# --------------------------------------------------------------------------- #


class Counting:
    """A vectorised ½‖x − C‖² counting its calls and batch sizes."""

    def __init__(self) -> None:
        self.calls = {"value": [], "subgradient": []}
        self.oracle = CallableOracle(self.f, self.g, d=2, vectorised=True)

    def f(self, Z):
        self.calls["value"].append(len(Z))
        return 0.5 * ((Z - C) ** 2).sum(axis=1)

    def g(self, Z):
        self.calls["subgradient"].append(len(Z))
        return Z - C


def test_one_vectorised_call_per_distinct_oracle_and_step():
    sc = scenario(None, steps=12, dos=False)
    a, b = Counting(), Counting()
    benign = sc.benign
    costs = {v: (a.oracle if i % 3 else b.oracle) for i, v in enumerate(benign)}
    tr = rmdo(sc, costs, optimum=C)
    na = sum(1 for i in range(len(benign)) if i % 3)
    assert a.calls["subgradient"] == [na] * sc.steps
    assert b.calls["subgradient"] == [len(benign) - na] * sc.steps
    # values: F* at the given point, then every benign state and the mean per step
    assert a.calls["value"] == [1] + [len(benign) + 1] * (sc.steps + 1)
    assert tr.info["oracles"] == 2


def per_agent_atoms(sc: Scenario, seed: int = 1) -> dict:
    """½‖x − c_i‖² + |a_iᵀx − b_i|, one distinct atom oracle per benign agent."""
    rng = np.random.default_rng(seed)
    return {v: atoms.Sum([atoms.Quadratic(np.eye(sc.d), rng.uniform(0, 10, sc.d)),
                          atoms.AbsAffine(rng.normal(size=sc.d), rng.uniform(-1, 1))])
            for v in sc.benign}


def test_per_agent_atoms_are_evaluated_stacked_not_one_call_per_agent(monkeypatch):
    """Issue 11's N = 1000 target: no oracle call per agent and step — the update is
    one stacked call, the cost monitor one merged global cost (before: N + N calls)."""
    from rescon.optim.oracle import Oracle

    sc = scenario(Constant([100.0, -50.0]), steps=6)
    costs = per_agent_atoms(sc)
    mine = {id(o) for o in costs.values()}
    calls = []

    def counted(method):
        orig = getattr(Oracle, method)

        def counting(self, Z):
            if id(self) in mine:
                calls.append(method)
            return orig(self, Z)
        return counting

    for method in ("value", "subgradient"):
        monkeypatch.setattr(Oracle, method, counted(method))
    rmdo(sc, costs, optimum=C)
    assert calls == []


def test_stacked_and_merged_paths_agree_with_per_agent_calls():
    """The same costs as opaque vectorised oracles (one call per agent, summed per
    agent): the same states and cost metrics up to rounding."""
    sc = scenario(Constant([100.0, -50.0]), steps=30)
    costs = per_agent_atoms(sc)
    opaque = {v: CallableOracle(o.value, o.subgradient, d=2, vectorised=True)
              for v, o in costs.items()}
    fast, slow = rmdo(sc, costs, optimum=C), rmdo(sc, opaque, optimum=C)
    B = fast.benign
    np.testing.assert_allclose(fast.states[:, B], slow.states[:, B], rtol=0, atol=1e-9)
    for key in ("cost", "cost_at_mean", "optimality_gap"):
        np.testing.assert_allclose(fast.metrics[key], slow.metrics[key], rtol=1e-12)


def test_a_stacked_subgradient_that_overflows_names_agent_step_and_point():
    """‖A_i x − b‖₂ with A_2's entries 1.5e308: finite value, infinite subgradient."""
    sc = Scenario(graph=nx.complete_graph(4), x0=[[float(i), 0.0] for i in range(4)], F=0,
                  steps=3, check_robustness=False)
    A = np.array([[0.0, 1.0], [0.0, 1.0]])
    costs = {v: atoms.Norm2(A * (1.5e308 if v == 2 else 1.0), [1.0, 1.0]) for v in range(4)}
    with pytest.raises(InputError, match=r"subgradient of the cost of agent 2 at step 0 "
                                         r"\(t = 0\), point \[.*\].*not finite"):
        rmdo(sc, costs, optimum=[0.0, 0.0])


def test_starved_agents_hold_and_take_no_subgradient():
    sc = scenario(None, steps=6, dos=False)
    links = frozenset((i, j) for j, i in sc.graph.edges)
    att = DoSAttack("all", links, Explicit([(0.0, 100.0)]))
    sc = scenario(None, steps=6, dos=False, policy="drop")
    sc = Scenario(graph=sc.graph, x0=sc.x0, F=sc.F, steps=6, policy="drop", dos=(att,),
                  check_robustness=False)
    count = Counting()
    tr = rmdo(sc, {v: count.oracle for v in sc.benign}, optimum=C)
    assert count.calls["subgradient"] == []
    assert np.array_equal(tr.states[0], tr.states[-1])


# --------------------------------------------------------------------------- #
# metrics
# --------------------------------------------------------------------------- #


def test_cost_metrics_agree_with_a_direct_evaluation():
    sc = scenario(Constant([100.0, -50.0]), steps=20)
    costs = redundant_quadratics(sc)
    tr = rmdo(sc, costs)
    B = tr.benign
    direct = np.array([[sum(float(costs[w].value(tr.states[k, i][None])[0]) for w in sc.benign)
                        for i in B] for k in range(sc.steps + 1)])
    np.testing.assert_allclose(tr.metrics["cost"], direct, rtol=1e-12)
    mean = tr.states[:, B].mean(axis=1)
    at_mean = [sum(float(costs[w].value(m[None])[0]) for w in sc.benign) for m in mean]
    np.testing.assert_allclose(tr.metrics["cost_at_mean"], at_mean, rtol=1e-12)
    assert np.isnan(tr.metrics["cost_rate"][0])
    np.testing.assert_allclose(tr.metrics["cost_rate"][1:],
                               np.diff(tr.metrics["cost_at_mean"]) / sc.T)
    dist = np.linalg.norm(tr.states[:, B] - C, axis=2).max(axis=1)
    np.testing.assert_allclose(tr.metrics["distance_to_optimum"], dist)
    np.testing.assert_allclose(tr.metrics["optimality_gap"],
                               direct.max(axis=1) - tr.info["optimum"]["value"])


def test_metrics_as_one_comma_separated_string():
    """rmdo takes simulate's comma form of ``metrics`` ("diameter,spread" = the list)."""
    sc = scenario(Constant([100.0, -50.0]), steps=5)
    costs = redundant_quadratics(sc)
    a = rmdo(sc, costs, metrics="diameter, spread")
    b = rmdo(sc, costs, metrics=["diameter", "spread"])
    assert "validity" not in a.metrics and set(a.metrics) == set(b.metrics)
    np.testing.assert_array_equal(a.metrics["diameter"], b.metrics["diameter"])


def test_exact_optimum_of_non_redundant_quadratics():
    """½ w_i ‖x − c_i‖²: X* = {Σ w_i c_i / Σ w_i}, computed in rationals."""
    sc = scenario(None, steps=3, dos=False)
    rng = np.random.default_rng(1)
    w = {v: int(rng.integers(1, 5)) for v in sc.benign}
    c = {v: rng.integers(-9, 9, size=2).tolist() for v in sc.benign}
    costs = {v: atoms.Quadratic(w[v] * np.eye(2), c[v]) for v in sc.benign}
    tr = rmdo(sc, costs)
    W = sum(w.values())
    exact = [float(Fraction(sum(w[v] * c[v][p] for v in sc.benign), W)) for p in range(2)]
    assert tr.info["optimum"]["point"] == exact and tr.info["optimum"]["dimension"] == 0


def test_exact_optimum_reads_the_decimals_of_cost_strings_exactly():
    """x1* = (0.1 + 0.3 + 1.1 + 0.2)/4 = 0.425 exactly; from the float-rounded data the
    rounded answer is one ulp above it."""
    sc = small()
    costs = {v: f"(x1 - {c})^2 + x2^2" for v, c in enumerate(["0.1", "0.3", "1.1", "0.2"])}
    assert rmdo(sc, costs).info["optimum"]["point"] == [0.425, 0.0]


def test_exact_optimum_set_of_dimension_one():
    sc = scenario(None, steps=5, dos=False)
    tr = rmdo(sc, {v: "(x1 - 1)^2" for v in sc.benign})
    assert tr.info["optimum"]["dimension"] == 1
    expected = np.abs(tr.states[:, tr.benign, 0] - 1).max(axis=1)
    np.testing.assert_allclose(tr.metrics["distance_to_optimum"], expected, atol=1e-12)


def test_unbounded_global_cost_is_reported_not_measured():
    sc = scenario(None, steps=3, dos=False)
    tr = rmdo(sc, {v: "x1 + x2^2" for v in sc.benign})
    assert "unbounded" in tr.info["optimum"]["reason"]
    assert "distance_to_optimum" not in tr.metrics and "cost" in tr.metrics


def test_plot_has_cost_panels(tmp_path):
    pytest.importorskip("matplotlib")
    sc = scenario(None, steps=10, dos=False)
    tr = rmdo(sc, redundant_quadratics(sc))
    fig = tr.plot(tmp_path / "rmdo.png")
    assert len(fig.axes) == sc.d + 3 and (tmp_path / "rmdo.png").stat().st_size > 0
    assert len(simulate(sc).plot().axes) == sc.d + 1
    assert rescon.Trajectory is type(tr)


def test_paper_example_runs_with_the_paper_costs():
    sc = Scenario.paper_example(check_robustness=False, steps=40)
    tr = rmdo(sc, rescon.optim.paper_costs())
    assert tr.info["update"] == "rmdo" and tr.info["step_size"] == "harmonic(5, 1)"
    assert tr.info["optimum"]["exact"] is False
    assert np.isfinite(tr.metrics["cost"]).all()
    assert tr.metrics["diameter"][-1] < tr.metrics["diameter"][1]


def test_docstring_example():
    import rescon.optim.rmdo as mod

    assert doctest.testmod(mod).failed == 0


# --------------------------------------------------------------------------- #
# bad input
# --------------------------------------------------------------------------- #


def small() -> Scenario:
    return Scenario(graph=nx.complete_graph(4), x0=[[0.0, 0.0], [1.0, 0.0], [2.0, 1.0],
                                                    [3.0, 3.0]], F=0, steps=5,
                    check_robustness=False)


def test_missing_cost_and_bad_costs():
    sc = small()
    with pytest.raises(InputError, match=r"no cost for benign agent\(s\) \[3\]"):
        rmdo(sc, {0: "x1^2", 1: "x1^2", 2: "x1^2"})
    with pytest.raises(InputError, match="costs must be a mapping"):
        rmdo(sc, ["x1^2"] * 4)
    with pytest.raises(InputError, match="not nodes of the graph"):
        rmdo(sc, {v: "x1^2" for v in range(5)})
    with pytest.raises(InputError, match="x3 is used but d = 2"):
        rmdo(sc, {v: "x3^2" for v in range(4)})
    with pytest.raises(InputError, match="scenario must be"):
        rmdo({"graph": 1}, {})


def test_adversaries_need_no_cost():
    sc = scenario(Constant([1.0, 1.0]), steps=3, dos=False)
    tr = rmdo(sc, {v: "x1^2 + x2^2" for v in sc.benign})
    assert tr.states.shape[0] == 4


def nan_at(bad_row_test):
    def g(Z):
        G = Z - C
        G[bad_row_test(Z)] = np.nan
        return G
    return CallableOracle(lambda Z: ((Z - C) ** 2).sum(axis=1), g, d=2, vectorised=True)


def test_nan_subgradient_names_agent_step_and_point():
    sc = small()
    costs = {v: "x1^2" for v in range(4)}
    costs[2] = nan_at(lambda Z: np.ones(len(Z), dtype=bool))
    with pytest.raises(InputError, match=r"subgradient of the cost of agent 2 at step 0 "
                                         r"\(t = 0\), point \[.*\].*not finite"):
        rmdo(sc, costs)


def test_nan_of_a_shared_oracle_names_the_agent_whose_point_failed():
    sc = small()
    shared = nan_at(lambda Z: Z[:, 0] > 1.9)  # only agent 3's z has x1 > 1.9 at step 0
    with pytest.raises(InputError, match=r"agent 3 at step 0") as err:
        rmdo(sc, {v: shared for v in range(4)}, optimum=[0.0, 0.0])
    point = [float(s) for s in re.search(r"point \[([^\]]*)\]", str(err.value))[1].split(",")]
    assert point[0] > 1.9


def test_wrong_shape_and_raising_oracles():
    sc = small()
    flat = CallableOracle(lambda Z: Z[:, 0], lambda Z: Z[:, 0], d=2, vectorised=True)
    with pytest.raises(InputError, match=r"agent 0 at step 0.*shape"):
        rmdo(sc, {v: flat for v in range(4)}, optimum=[0.0, 0.0])

    def boom(x):
        raise ZeroDivisionError("user bug")

    raising = CallableOracle(lambda x: 0.0, boom, d=2)
    with pytest.raises(InputError, match=r"agent 1 at step 0.*ZeroDivisionError: user bug"):
        rmdo(sc, {0: "x1^2", 1: raising, 2: "x1^2", 3: "x1^2"})


def test_nan_value_is_an_error_not_a_metric():
    sc = small()
    bad = CallableOracle(lambda Z: np.full(len(Z), np.inf), lambda Z: Z, d=2, vectorised=True)
    with pytest.raises(InputError, match=r"value of the cost of agent 0"):
        rmdo(sc, {v: bad for v in range(4)}, optimum=[0.0, 0.0])


def test_overflowing_step_is_an_error():
    sc = small()
    with pytest.raises(InputError, match=r"agent \d at step 0 .*overflows"):
        rmdo(sc, {v: "x1^2 + x2^2" for v in range(4)}, step_size=1e308, optimum=[0, 0])


def test_a_diverging_run_says_so_and_suggests_a_smaller_step():
    """Costs 1e10 x a quadratic under the paper's step size: the iterates run away until
    the cost overflows; the error says the run diverged (it named only the point)."""
    sc = Scenario(graph=nx.complete_graph(4), x0=[[0.0, 0.0], [1.0, 0.0], [2.0, 1.0],
                                                  [3.0, 3.0]], F=0, steps=60,
                  check_robustness=False)
    with pytest.raises(InputError, match=r"agent \d at step \d+ .*point .*the iterates "
                                         r"diverged \(max \|x\| = .*; the initial states "
                                         r"and X\* lie within 3\): "
                                         r".*try a smaller step_size"):
        rmdo(sc, {v: "1e10*((x1 - 1)^2 + x2^2)" for v in range(4)}, optimum=[1, 0])


def test_an_error_near_the_start_has_no_divergence_hint():
    sc = small()
    with pytest.raises(InputError) as err:
        rmdo(sc, {v: "x1^2 + x2^2" for v in range(4)}, step_size=1e308, optimum=[0, 0])
    assert "overflows" in str(err.value) and "diverged" not in str(err.value)


def test_bad_step_sizes_and_assumption5_warning():
    sc = small()
    costs = {v: "x1^2" for v in range(4)}
    for bad in (-1.0, 0, [0.1], "fast", float("nan")):
        with pytest.raises(InputError, match="step_size"):
            rmdo(sc, costs, step_size=bad)
    with pytest.raises(InputError, match=r"step_size\(2\) must be a finite number >= 0"):
        rmdo(sc, costs, step_size=lambda k: 1.0 - k)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ScenarioWarning)
        rmdo(sc, costs, step_size=harmonic(1.0, 1.0))  # Assumption 5 holds: no warning
        with pytest.raises(ScenarioWarning, match="Assumption 5.*constant step size"):
            rmdo(sc, costs, step_size=0.1)
    with pytest.warns(ScenarioWarning, match=r"Assumption 5: step size .*√\(k\+1\)") as record:
        rmdo(sc, costs, step_size=rescon.optim.steps.sqrt_decay(1.0))
    assert record[0].filename == __file__  # attributed to the caller


def test_bad_optimum():
    sc = small()
    for bad in ([1.0], [np.nan, 0.0], "x"):
        with pytest.raises(InputError, match="optimum must be"):
            rmdo(sc, {v: "x1^2" for v in range(4)}, optimum=bad)
