"""Step sizes (Assumption 5) and the paper's costs (SPEC §5)."""

from __future__ import annotations

import numpy as np
import pytest

import rescon
from rescon.errors import InputError
from rescon.optim import paper_costs, steps
from rescon.optim.paper import PAPER_COSTS


def test_paper_step_is_one_over_five_t_plus_one():
    st = steps.step_size("paper")
    T = 0.5
    k = np.arange(6)
    assert np.array_equal(st.values(k, T), 1 / (5 * k * T + 1))
    assert st.assumption5(T) == []
    assert steps.harmonic(2, 3)(4, 0.5) == 1 / (2 * 2.0 + 3)


@pytest.mark.parametrize("spec, fragment", [
    (0.1, "constant step size 0.1: Σβ² = ∞"),
    (steps.constant(2), "constant step size 2"),
    (steps.sqrt_decay(1.5), "Σβ² = 1.5² Σ 1/(k+1) = ∞"),
    (steps.harmonic(0, 2), "is constant"),
])
def test_presets_violating_assumption5_are_decided_analytically(spec, fragment):
    v = steps.step_size(spec).assumption5(0.5)
    assert len(v) == 1 and fragment in v[0]


def test_sqrt_decay_values():
    assert np.allclose(steps.sqrt_decay(2).values(np.arange(4)), 2 / np.sqrt(np.arange(1, 5)))


def test_callables_are_checked_on_a_horizon():
    assert steps.step_size(lambda k: 1 / (k + 1)).assumption5(horizon=1000) == []
    assert steps.step_size(lambda k: 0.3 / (k + 1) ** 0.75).assumption5(horizon=1000) == []
    summable = steps.step_size(lambda k: 1 / (k + 1) ** 2).assumption5(horizon=1000)
    assert len(summable) == 1 and "Σβ < ∞" in summable[0] and "estimated" in summable[0]
    slow = steps.step_size(lambda k: 1 / (k + 1) ** 0.4).assumption5(horizon=1000)
    assert len(slow) == 1 and "Σβ² = ∞" in slow[0]
    bumpy = steps.step_size(lambda k: 1 / (k + 1) + (k == 7)).assumption5(horizon=1000)
    assert "not non-increasing: β_7" in bumpy[0]
    zero = steps.step_size(lambda k: max(0.0, 1 - k / 10)).assumption5(horizon=100)
    assert any("reaches 0" in v for v in zero)


@pytest.mark.parametrize("spec, match", [
    (-0.1, "step_size must be a finite number > 0"),
    (0, "step_size must be a finite number > 0"),
    (float("nan"), "step_size must be a finite number > 0"),
    ("fast", "step_size must be 'paper'"),
    ([0.1], "step_size must be 'paper'"),
    (True, "step_size must be 'paper'"),
])
def test_bad_step_sizes(spec, match):
    with pytest.raises(InputError, match=match):
        steps.step_size(spec)


def test_bad_preset_parameters_and_callable_values():
    with pytest.raises(InputError, match="a must be"):
        steps.harmonic(-1, 1)
    with pytest.raises(InputError, match="b must be a finite number > 0"):
        steps.harmonic(1, 0)
    with pytest.raises(InputError, match="c must be a finite number > 0"):
        steps.sqrt_decay(-2)
    with pytest.raises(InputError, match=r"step_size\(3\) must be a finite number >= 0"):
        steps.step_size(lambda k: 1.0 if k < 3 else -1.0).assumption5(horizon=10)
    with pytest.raises(InputError, match=r"step_size\(0\) must be a real number"):
        steps.step_size(lambda k: "big")(0)


# --------------------------------------------------------------------------- #
# the paper's costs
# --------------------------------------------------------------------------- #


def test_paper_costs_keys_and_values():
    costs = paper_costs()
    benign = sorted(rescon.Scenario.paper_example().benign)
    assert sorted(costs) == benign == [1, 3, 4, 5, 6, 7, 8, 9, 10, 11]
    x, y = 0.7, -1.3
    expected = {1: x * x + y * y, 3: abs(x + y), 4: np.hypot(x, y),
                5: (x - 1) ** 2 + (y - 0.5) ** 2, 6: max(x, y),
                7: (x + 0.3) ** 2 + (x - 0.2) ** 2, 8: abs(x) + abs(y), 9: abs(x) + y * y,
                10: x * x + y * y + abs(x - y), 11: max(abs(x), abs(y))}
    for i, o in costs.items():
        assert o.d == 2 and o.name == f"cost of agent {i}"
        assert o.value([[x, y]])[0] == pytest.approx(expected[i], rel=1e-14), i
    assert paper_costs("x2")[7].value([[x, y]])[0] == pytest.approx(
        (x + 0.3) ** 2 + (y - 0.2) ** 2, rel=1e-14)
    assert paper_costs("x2")[7].source != PAPER_COSTS[7]


def test_paper_costs_subgradients_at_their_kinks():
    kinks = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, -1.0], [0.0, 2.0], [-1.0, 0.0]])
    for i, o in paper_costs().items():
        assert rescon.check_subgradient(o, kinks) <= 1e-9, i


def test_paper_costs_structure():
    c = paper_costs()
    assert {i for i, o in c.items() if o.quadratic} == {1, 5, 7}
    assert {i for i, o in c.items() if o.polyhedral} == {3, 6, 8, 11}


def test_paper_costs_bad_f7():
    with pytest.raises(InputError, match="f7 must be"):
        paper_costs("x3")
