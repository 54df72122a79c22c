"""The consensus engine at every magnitude (issue 10): properties a whole run must have
whatever scale the states and the adversaries' values take."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rescon.consensus.adversaries import Constant
from rescon.consensus.engine import simulate
from rescon.consensus.scenario import Scenario
from rescon.graphs.generators import circulant


def _run(x0, adversary, kernel_point, d, steps=6):
    """A 12-node ring lattice with k = (d+1)F+1 = d + 2 neighbours a side (so it is
    ((d+1)F+1)-robust), F = 1, one constant adversary at node 0, no residual."""
    k = (d + 1) + 1
    sc = Scenario(graph=circulant(12, k), x0=x0, F=1, adversaries={0: Constant(adversary)},
                  steps=steps, residual="none", kernel_point=kernel_point,
                  check_robustness=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(sc)


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**16), j=st.integers(-900, 480), d=st.sampled_from([2, 3]),
       kernel_point=st.sampled_from(["project", "project-exact"]))
def test_scaling_a_run_by_a_power_of_two_scales_every_state_exactly(seed, j, d, kernel_point):
    """Ψ(2^j X) = 2^j Ψ(X), the centres and x ← αx + (1−α)x̃ commute with an exact
    power-of-two scaling, so with exact kernel points the whole trajectory scales bit
    for bit; the certified batch paths stay within their bound (2^-40 of the answer
    per point) of it, whatever the scale."""
    rng = np.random.default_rng(seed)
    x0 = rng.uniform(-10, 10, size=(12, d))
    adversary = rng.uniform(-1e3, 1e3, size=d)
    base = _run(x0, adversary, kernel_point, d)
    scaled = _run(np.ldexp(x0, j), np.ldexp(adversary, j), kernel_point, d)
    expected = np.ldexp(base.states, j)
    if kernel_point == "project-exact":
        assert np.array_equal(scaled.states, expected)
    else:
        assert np.abs(scaled.states - expected).max() <= 1e-9 * np.abs(expected).max()
    assert scaled.max_validity == math.ldexp(base.max_validity, j) == 0.0


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**16), exponent=st.integers(10, 307), d=st.sampled_from([2, 3]))
def test_no_adversary_magnitude_moves_a_benign_agent_outside_the_benign_hull(seed, exponent,
                                                                            d):
    """Every assumption met (((d+1)F+1)-robust lattice, F = 1): one adversary sending
    ±10^exponent in every coordinate; the benign states stay in their initial hull
    (validity exactly 0) and agree with the exact kernel points."""
    rng = np.random.default_rng(seed)
    x0 = rng.uniform(-10, 10, size=(12, d))
    adversary = rng.choice([-1.0, 1.0], size=d) * 10.0**exponent
    fast = _run(x0, adversary, "project", d, steps=8)
    exact = _run(x0, adversary, "project-exact", d, steps=8)
    assert np.isfinite(fast.states[:, 1:]).all()
    assert fast.max_validity == 0.0 and exact.max_validity == 0.0
    assert np.abs(fast.states[:, 1:] - exact.states[:, 1:]).max() <= 1e-9


def test_batch_point_allowance_follows_the_size_of_the_kernel():
    """engine._allowance: at 1e15 + a spread of 1 a batch point may be off by ~2 ulps
    (it was ACCEPT_REL of the magnitude, ~900: states left their benign hull, V36); near
    the origin and for converged sets ACCEPT_REL of the magnitude as before; a set whose
    trimmed box overflows falls back to the magnitude's."""
    from rescon.consensus import engine
    from rescon.geometry._small2d import ACCEPT_REL

    rng = np.random.default_rng(0)
    Y = rng.normal(size=(1, 9, 3))
    pts = Y[:, 0]
    size = np.abs(pts).max()
    far = engine._allowance(Y + 1e15, 1, pts + 1e15)[0]
    assert 2 * np.spacing(1e15) <= far < 1.0  # 4 ulps of 1e15 = 0.5; before: ~900
    near = engine._allowance(Y, 1, pts)[0]
    assert near == pytest.approx(ACCEPT_REL * size + engine.ROUNDING_SLACK * size)
    converged = 1.0 + 1e-9 * Y
    got = engine._allowance(converged, 1, converged[:, 0])[0]
    assert got == pytest.approx(ACCEPT_REL * np.abs(converged[:, 0]).max(), rel=1e-3)
    wide = Y.copy()
    wide[0, :4, 0], wide[0, 4:, 0] = -1.7e308, 1.7e308
    assert engine._allowance(wide, 1, pts)[0] == pytest.approx(
        ACCEPT_REL * size + engine.ROUNDING_SLACK * size)
