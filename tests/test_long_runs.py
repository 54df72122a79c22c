"""Long consensus runs in R³ (issue 10 §1): as the states converge the kernel-point
sets become tiny, flat or ill-conditioned; the batch path certifies or declines them
(to the exact path) and never raises."""

from __future__ import annotations

import warnings

import networkx as nx
import numpy as np
import pytest

from rescon.consensus.adversaries import Constant
from rescon.consensus.engine import simulate
from rescon.consensus.scenario import Scenario
from rescon.graphs.generators import circulant


def run(graph, x0, F, steps, adversaries=None, kernel_point="project"):
    sc = Scenario(graph=graph, x0=x0, F=F, adversaries=adversaries or {}, steps=steps,
                  residual="none", kernel_point=kernel_point)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(sc)


@pytest.mark.slow
@pytest.mark.parametrize("N,seed,adversary", [(20, 0, None), (20, 1, None), (25, 2, None),
                                              (20, 3, [1e20, 1e20, 1e20])])
def test_200_steps_in_space_converge_inside_the_benign_hull(N, seed, adversary):
    """5-robust ring lattices, d = 3, F = 1: crashed with LinAlgError after ~15 steps
    for every seed; with an adversary at 1e20 the agents left the benign hull (1.7e4)."""
    x0 = np.random.default_rng(seed).uniform(-10, 10, size=(N, 3))
    advs = {0: Constant(adversary)} if adversary else None
    tr = run(circulant(N, 5), x0, 1, 200, advs)
    assert np.isfinite(tr.states).all()
    assert tr.metrics["validity"].max() <= 1e-9
    assert tr.metrics["diameter"][-1] <= 1e-6 * tr.metrics["diameter"][0]


@pytest.mark.slow
def test_readme_case_runs_past_step_71():
    """The README's N = 100, d = 3, F = 2 benchmark case crashed at step ~71."""
    k = 3 * 2 + 1
    x0 = np.random.default_rng(1).uniform(0, 10, size=(100, 3))
    tr = run(circulant(100, k), x0, 2, 80)
    assert np.isfinite(tr.states).all()
    assert tr.metrics["validity"].max() <= 1e-9


@pytest.mark.parametrize("value", [4e5, 5.5e5, 7e5])
def test_far_adversary_on_k6_matches_the_exact_path(value):
    """An adversary at ~4e5–7e5 on K6 (d = 3, F = 1) raised LinAlgError."""
    x0 = np.random.default_rng(6).uniform(-10, 10, size=(6, 3))
    advs = {0: Constant([value, -value, value])}
    runs = [run(nx.complete_graph(6), x0, 1, 15, advs, kp).states[:, 1:]
            for kp in ("project", "project-exact")]
    assert np.abs(runs[0] - runs[1]).max() <= 1e-9
