"""Scenario warnings tell the truth: Assumption 3, cut-off agents, robustness at any N
and for the F-total model (issue 10 §4)."""

from __future__ import annotations

import re

import networkx as nx
import numpy as np
import pytest

from rescon.consensus import scenario as scenario_module
from rescon.consensus.dos import DoSAttack, Explicit, Periodic
from rescon.consensus.scenario import Scenario
from rescon.errors import InputError
from rescon.graphs import robustness as robustness_module
from rescon.graphs.generators import circulant
from rescon.graphs.robustness import RobustnessCheck


def ring(n: int, k: int, *, d: int = 2, F: int = 1, **kw) -> Scenario:
    x0 = np.random.default_rng(1).uniform(0, 10, size=(n, d))
    return Scenario(graph=circulant(n, k), x0=x0, F=F, steps=kw.pop("steps", 20), **kw)


def in_links(sc: Scenario, i) -> frozenset:
    return frozenset((i, j) for j in sc.graph.predecessors(i))


def test_robustness_is_checked_beyond_64_nodes():
    """A 100-node ring lattice with ρ = 2 < (d+1)F+1 = 4: a witness, at any N."""
    msgs = ring(100, 2).assumptions()
    bad = [m for m in msgs if "not 4-robust" in m]
    assert len(bad) == 1 and "witness S1 = " in bad[0]


def test_undecided_robustness_is_reported_with_bounds(monkeypatch):
    """When the exact check stops at its time limit, the warning says "not decided"
    and gives the proven bounds instead of saying nothing."""
    monkeypatch.setattr(scenario_module, "ROBUSTNESS_SECONDS", 1e-3)
    G = nx.gnp_random_graph(40, 0.35, seed=0)  # bounds 4 <= rho <= 8
    sc = Scenario(graph=G, x0=np.zeros((40, 1)), F=3, steps=1)  # needs 7-robust
    msgs = [m for m in sc.assumptions() if "robust" in m]
    assert len(msgs) == 1 and msgs[0].startswith("not decided"), msgs
    lo, hi = map(int, re.search(r"(\d+) <= rho\(G\) <= (\d+)", msgs[0]).groups())
    assert 4 <= lo < 7 <= hi <= 8  # the bounds alone give [4, 8]


@pytest.mark.parametrize("n, k, verdict", [(100, 2, "not 4-robust"), (14, 4, None)])
def test_bounds_settle_what_the_stopped_check_left_open(monkeypatch, n, k, verdict):
    """When the exact check stops, bounds that decide give the verdict: ρ ≤ 2 < 4 a
    failure with its witness, ρ ≥ 4 (circulant(14, 4) is 4-robust) no warning."""
    undecided = RobustnessCheck(4, 1, None, None, None, None, method="search", seconds=0.0)
    monkeypatch.setattr(robustness_module, "is_rs_robust", lambda *a, **kw: undecided)
    msgs = [m for m in ring(n, k).assumptions() if "robust" in m]
    if verdict is None:
        assert not msgs
    else:
        assert len(msgs) == 1 and verdict in msgs[0] and "witness S1 = [" in msgs[0]


def test_total_model_needs_dF1_F1_robustness_only():
    """circulant(9, 3) is (3, 2)-robust, not 4-robust: enough for F-total with d = 2,
    F = 1 ((dF+1, F+1) = (3, 2)), not for F-local ((d+1)F+1 = 4)."""
    total = ring(9, 3, model="total")
    assert not [m for m in total.assumptions() if "robust" in m]
    local = ring(9, 3)
    assert any("not 4-robust" in m for m in local.assumptions())


def test_total_model_failure_names_the_rs_condition():
    msgs = ring(9, 2, model="total").assumptions()  # circulant(9, 2): rho = 2 < 3
    assert any("not (3, 2)-robust" in m and "F-total" in m for m in msgs), msgs


def test_dos_blocking_forever_breaks_assumption3():
    """A schedule on for its whole period blocks its links all the time: no T_d > 1,
    μ_d > 0 satisfy Assumption 3, and agent 3 (all in-links attacked) is cut off."""
    sc = ring(14, 4)
    att = DoSAttack("always", in_links(sc, 3), Periodic(1.0, 1.0))
    msgs = Scenario(**{**_fields(sc), "dos": (att,)}).assumptions()
    a3 = [m for m in msgs if m.startswith("Assumption 3 fails")]
    assert len(a3) == 1 and "[0, 10] s holds 10 s blocked" in a3[0], msgs
    assert any("every in-link" in m and "[3]" in m for m in msgs), msgs


def test_agent_cut_off_for_the_whole_horizon():
    """An explicit window longer than the run: Assumption 3 holds (μ_d covers it), but
    agent 5 receives nothing during the run; one link left open clears the warning."""
    sc = ring(14, 4)
    links = in_links(sc, 5)
    cut = Scenario(**{**_fields(sc), "dos": (DoSAttack("w", links, Explicit([(0, 100)])),)})
    msgs = cut.assumptions()
    assert not any("Assumption 3" in m for m in msgs)
    assert any("every in-link" in m and "[5]" in m for m in msgs), msgs
    open_one = DoSAttack("w", links - {min(links)}, Explicit([(0, 100)]))
    msgs = Scenario(**{**_fields(sc), "dos": (open_one,)}).assumptions()
    assert not any("every in-link" in m for m in msgs)


def test_assumption3_not_decided_is_said():
    """Two periodic schedules with an enormous hyperperiod and blocked fractions
    summing above 1: the long-run fraction is not computed, and the warning says so."""
    sc = ring(14, 4)
    a = DoSAttack("a", frozenset({(1, 0)}), Periodic(1.0, 0.6))
    b = DoSAttack("b", frozenset({(2, 1)}), Periodic(0.1, 0.06))
    msgs = Scenario(**{**_fields(sc), "dos": (a, b)}).assumptions()
    assert any(m.startswith("Assumption 3 not decided") and "hyperperiod" in m
               for m in msgs), msgs


def test_paper_example_dos_meets_assumption3():
    msgs = Scenario.paper_example(steps=40).assumptions()
    assert not any("Assumption 3" in m or "every in-link" in m for m in msgs), msgs


def _fields(sc: Scenario) -> dict:
    keep = ("graph", "x0", "F", "adversaries", "T", "steps", "model", "policy",
            "algorithm", "centre", "c", "residual", "seed", "kernel_point")
    return {k: getattr(sc, k) for k in keep}


def test_dataclasses_replace_rebuilds_a_constructed_scenario():
    """A constructed Scenario holds normalised fields (alpha per node, a Residual);
    ``dataclasses.replace`` must accept them back (it raised on alpha before)."""
    from dataclasses import replace

    sc = Scenario.paper_example()
    again = replace(sc, residual="none")
    assert again.residual(0.0) == 0.0
    assert replace(sc).to_dict() == sc.to_dict()
    per_node = replace(sc, alpha=[0.4] * len(sc.nodes))
    assert (per_node.alpha == 0.4).all()
    with pytest.raises(InputError, match="12 numbers in node order"):
        replace(sc, alpha=[0.5, 0.5])
