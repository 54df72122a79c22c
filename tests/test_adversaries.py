"""What adversarial agents send (rescon.consensus.adversaries)."""

from __future__ import annotations

import doctest
import math

import numpy as np
import pytest

import rescon.consensus.adversaries as adv_mod
from rescon.consensus.adversaries import (
    Bait,
    Behaviour,
    Constant,
    Crash,
    FunctionOfTime,
    NonFinite,
    OwnState,
    RandomInBox,
    StepView,
    TimePreset,
    TwoFaced,
    TwoFacedTable,
    adversary_messages,
    behaviour_from_dict,
    paper_adversaries,
)
from rescon.errors import InputError

N, D = 8, 2
ADV = (0, 5)


def make_view(k=0, t=0.0, seed=0, d=D):
    """8 agents, 0 and 5 adversarial; i hears i-1, i+1, i+2, i+3 (mod 8)."""
    rng = np.random.default_rng(100 + d)
    states = rng.uniform(-3, 3, size=(N, d))
    states[list(ADV)] = 99.0  # adversaries' own rows are arbitrary
    benign = np.ones(N, dtype=bool)
    benign[list(ADV)] = False
    nbrs = [np.array([(i + s) % N for s in (-1, 1, 2, 3)]) for i in range(N)]
    return StepView(k, t, states, benign, nbrs, np.random.default_rng(seed))


def benign_box(view, i):
    nb = [j for j in view.in_neighbours[i] if view.benign[j]]
    pts = view.states[nb]
    return pts.min(axis=0), pts.max(axis=0)


RECEIVERS = np.array([1, 2, 3, 4, 6, 7])

BEHAVIOURS = [
    FunctionOfTime(lambda t: np.array([math.sin(t), t])),
    FunctionOfTime.preset("paper_x2"),
    TwoFaced(lambda t, r: np.array([r, t])),
    TwoFaced(TwoFacedTable(cycle=[[0, 0], [1, 1]])),
    Constant([1.0, -1.0]),
    OwnState(),
    RandomInBox(),
    RandomInBox(scale=3.0),
    Bait(),
    Bait(direction=[0.0, -1.0], strength=2.0),
    Crash(3),
    Crash(0, RandomInBox()),
    NonFinite("nan"),
    NonFinite("mixed"),
]


@pytest.mark.parametrize("beh", BEHAVIOURS, ids=lambda b: type(b).__name__)
@pytest.mark.parametrize("receivers", [RECEIVERS, np.array([3]), np.array([], dtype=int)],
                         ids=["six", "one", "none"])
def test_shape_dtype_and_determinism(beh, receivers):
    view = make_view(k=2, t=1.5, seed=7)
    msg = beh.messages(0, receivers, view)
    assert isinstance(msg, np.ndarray) and msg.dtype == np.float64
    assert msg.shape == (len(receivers), D)
    again = beh.messages(0, receivers, make_view(k=2, t=1.5, seed=7))
    np.testing.assert_array_equal(msg, again)  # NaN == NaN here
    assert isinstance(beh, Behaviour)


def test_function_of_time_paper_values():
    adv = paper_adversaries()
    assert sorted(adv) == [2, 12]  # paper labels, 1-based
    for t in (0.0, 0.5, 3.0, 10.0):
        view = make_view(t=t)
        x2 = adv[2].messages(2, np.array([0, 1, 3]), view)
        x12 = adv[12].messages(5, np.array([4]), view)
        np.testing.assert_allclose(x2, np.tile([3 * math.sin(t), t + 2], (3, 1)))
        np.testing.assert_allclose(x12, [[6 * math.cos(t), 3 * t]])


def test_function_of_time_wrong_shape():
    with pytest.raises(InputError, match=r"FunctionOfTime.f must return a vector of shape \(2,\)"):
        FunctionOfTime(lambda t: [1, 2, 3]).messages(0, RECEIVERS, make_view())
    with pytest.raises(InputError, match="f must be callable"):
        FunctionOfTime(3)


def test_time_presets():
    s = TimePreset("sin", amplitude=[1, 2], frequency=2.0, phase=[0, math.pi / 2], offset=1)
    np.testing.assert_allclose(s(0.3), [1 + math.sin(0.6), 1 + 2 * math.cos(0.6)])
    lin = TimePreset("linear", start=[1, 2], velocity=[0.5, -1])
    np.testing.assert_allclose(lin(4.0), [3.0, -2.0])
    assert TimePreset("sin", amplitude=[1, 2]) == TimePreset("sin", amplitude=[1.0, 2.0])
    assert hash(FunctionOfTime.preset("paper_x12")) == hash(FunctionOfTime.preset("paper_x12"))
    with pytest.raises(InputError, match=r"preset must be one of .*; got 'cos'"):
        TimePreset("cos")
    with pytest.raises(InputError,
                       match=r"preset 'linear' is missing parameter\(s\) \['velocity'\]"):
        TimePreset("linear", start=[0, 0])
    with pytest.raises(InputError,
                       match=r"preset 'paper_x2' has unknown parameter\(s\) \['scale'\]"):
        TimePreset("paper_x2", scale=2)
    with pytest.raises(InputError, match="phase must be a number or a list of length 2; got 3"):
        TimePreset("sin", amplitude=[1, 1], phase=[0, 0, 0])
    with pytest.raises(InputError, match="equal length"):
        TimePreset("linear", start=[0, 0], velocity=[1])


def test_two_faced_differs_per_receiver():
    beh = TwoFaced(lambda t, r: np.array([float(r), -float(r)]))
    msg = beh.messages(0, RECEIVERS, make_view())
    np.testing.assert_array_equal(msg[:, 0], RECEIVERS)
    assert len({tuple(row) for row in msg}) == len(RECEIVERS)
    table = TwoFaced(TwoFacedTable(values={"1": [5, 5], 3: [-5, -5]}, default=[0, 0]))
    np.testing.assert_array_equal(table.messages(0, np.array([1, 2, 3]), make_view()),
                                  [[5, 5], [0, 0], [-5, -5]])
    silent_rest = TwoFaced(TwoFacedTable(values={1: [5, 5]}))
    out = silent_rest.messages(0, np.array([1, 2]), make_view())
    assert np.isfinite(out[0]).all() and np.isnan(out[1]).all()
    cyc = TwoFaced(TwoFacedTable(cycle=[[0, 0], [1, 1]]))
    np.testing.assert_array_equal(cyc.messages(0, np.array([2, 3, 4]), make_view()),
                                  [[0, 0], [1, 1], [0, 0]])


def test_constant_and_own_state():
    view = make_view()
    np.testing.assert_array_equal(Constant((1, 2)).messages(0, RECEIVERS, view),
                                  np.tile([1.0, 2.0], (6, 1)))
    np.testing.assert_array_equal(OwnState().messages(5, np.array([4, 6]), view),
                                  np.full((2, 2), 99.0))
    with pytest.raises(InputError, match=r"Constant value must have length d = 2; got 3"):
        Constant([1, 2, 3]).messages(0, RECEIVERS, view)
    with pytest.raises(InputError, match="value must be finite"):
        Constant([1, math.nan])
    with pytest.raises(InputError, match="value must be a nonempty 1-D list"):
        Constant([[1, 2]])


@pytest.mark.parametrize("scale", [0.0, 0.5, 1.0, 2.5])
@pytest.mark.parametrize("seed", range(5))
def test_random_in_box_stays_in_expanded_box(scale, seed):
    view = make_view(seed=seed, d=3)
    msg = RandomInBox(scale).messages(0, RECEIVERS, view)
    for row, i in zip(msg, RECEIVERS):
        lo, hi = benign_box(view, i)
        c, h = (lo + hi) / 2, scale * (hi - lo) / 2
        assert np.all(row >= c - h - 1e-12) and np.all(row <= c + h + 1e-12)
        if scale == 0:
            np.testing.assert_allclose(row, c)
    if scale > 1:  # it does leave the benign box sometimes
        outside = [np.any((row < benign_box(view, i)[0]) | (row > benign_box(view, i)[1]))
                   for row, i in zip(msg, RECEIVERS)]
        assert any(outside)


def test_random_in_box_seed_and_no_benign_neighbour():
    a = RandomInBox().messages(0, RECEIVERS, make_view(seed=1))
    b = RandomInBox().messages(0, RECEIVERS, make_view(seed=2))
    assert not np.array_equal(a, b)
    view = make_view()
    lonely = StepView(0, 0.0, view.states, view.benign,
                      [*view.in_neighbours[:3], np.array([0, 5]), *view.in_neighbours[4:]],
                      np.random.default_rng(0))
    out = RandomInBox().messages(0, np.array([3, 4]), lonely)
    assert np.isnan(out[0]).all() and np.isfinite(out[1]).all()
    with pytest.raises(InputError, match="scale must be a finite number >= 0"):
        RandomInBox(-1)


def test_bait_just_outside_the_box():
    view = make_view()
    strength = 0.5
    msg = Bait(direction=[1.0, 1.0], strength=strength).messages(0, RECEIVERS, view)
    u = np.array([1.0, 1.0]) / math.sqrt(2)
    for row, i in zip(msg, RECEIVERS):
        lo, hi = benign_box(view, i)
        c = (lo + hi) / 2
        step = row - c
        np.testing.assert_allclose(step / np.linalg.norm(step), u)  # on the ray c + s u
        assert np.any(row > hi)  # outside, on the side of the direction
        # distance beyond the box boundary = strength * diameter
        exit_len = min((hi - lo) / 2 / u)
        assert np.linalg.norm(step) - exit_len == pytest.approx(strength * np.linalg.norm(hi - lo))


def test_bait_default_direction_away_from_benign_mean():
    view = make_view()
    mean = view.states[view.benign].mean(axis=0)
    msg = Bait().messages(0, RECEIVERS, view)
    for row, i in zip(msg, RECEIVERS):
        lo, hi = benign_box(view, i)
        c = (lo + hi) / 2
        assert np.dot(row - c, c - mean) > 0
        assert np.any((row > hi) | (row < lo))
    with pytest.raises(InputError, match="direction must be a nonzero vector"):
        Bait(direction=[0, 0])
    with pytest.raises(InputError, match=r"Bait direction must have length d = 2; got 3"):
        Bait(direction=[1, 0, 0]).messages(0, RECEIVERS, view)


def test_crash_switches_at_the_right_step():
    beh = Crash(3, Constant([4.0, 4.0]))
    for k in range(6):
        msg = beh.messages(0, RECEIVERS, make_view(k=k))
        if k < 3:
            np.testing.assert_array_equal(msg, np.full((6, 2), 4.0))
        else:
            assert np.isnan(msg).all()
    default = Crash(1).messages(5, RECEIVERS, make_view(k=0))
    np.testing.assert_array_equal(default, np.full((6, 2), 99.0))  # its own (initial) row
    with pytest.raises(InputError, match="at_step must be a nonnegative integer"):
        Crash(-1)
    with pytest.raises(InputError, match="before must be a Behaviour"):
        Crash(1, before=[1, 2])


@pytest.mark.parametrize("kind, check", [
    ("nan", np.isnan), ("inf", np.isposinf), ("-inf", np.isneginf),
    ("mixed", lambda m: ~np.isfinite(m)),
])
def test_nonfinite(kind, check):
    msg = NonFinite(kind).messages(0, RECEIVERS, make_view())
    assert check(msg).all()
    if kind == "mixed":
        assert np.isnan(msg).any() and np.isposinf(msg).any() and np.isneginf(msg).any()
    with pytest.raises(InputError, match=r"kind must be one of .*; got 'huge'"):
        NonFinite("huge")


# --------------------------------------------------------------------------- #
# dict constructors
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("beh", [
    Constant([1, 2]), FunctionOfTime.preset("paper_x2"), FunctionOfTime.preset("paper_x12"),
    FunctionOfTime.preset("sin", amplitude=[1, 2], frequency=[1, 3]),
    FunctionOfTime.preset("linear", start=[0, 1], velocity=[2, 2]),
    TwoFaced(TwoFacedTable(values={1: [1, 1]}, default=[0, 0])),
    TwoFaced(TwoFacedTable(cycle=[[1, 2], [3, 4]])),
    RandomInBox(2.0), Bait(), Bait([0, 1], 0.3), Crash(4), Crash(2, Constant([1, 1])),
    NonFinite("-inf"), OwnState(),
], ids=lambda b: type(b).__name__)
def test_behaviour_dict_round_trip(beh):
    back = behaviour_from_dict(beh.to_dict())
    assert back == beh
    np.testing.assert_array_equal(back.messages(0, RECEIVERS, make_view(t=1.0)),
                                  beh.messages(0, RECEIVERS, make_view(t=1.0)))


@pytest.mark.parametrize("d, match", [
    ({"kind": "liar"}, r"behaviour kind must be one of .*; got 'liar'"),
    ({"value": [1, 2]}, "behaviour kind must be one of .*; got None"),
    ({"kind": "constant", "value": [1], "colour": 1, "size": 2},
     r"constant behaviour has unknown key\(s\) \['colour', 'size'\]"),
    ({"kind": "constant"}, r"constant behaviour is missing key\(s\) \['value'\]"),
    ({"kind": "crash"}, r"crash behaviour is missing key\(s\) \['at_step'\]"),
    ({"kind": "crash", "at_step": 1, "before": {"kind": "nope"}}, "got 'nope'"),
    ({"kind": "function_of_time"}, r"missing key\(s\) \['preset'\]"),
    ({"kind": "function_of_time", "preset": "expr", "f": "sin(t)"}, "preset must be one of"),
    ({"kind": "function_of_time", "preset": "sin", "amplitude": [1], "speed": 2},
     r"unknown parameter\(s\) \['speed'\]"),
    ({"kind": "two_faced"}, "exactly one of 'values' or 'cycle'"),
    ({"kind": "two_faced", "values": {"x": [1]}}, "values keys must be receiver indices"),
    ({"kind": "two_faced", "cycle": [[1, 2], [1]]}, "one length"),
    ({"kind": "nonfinite", "value": "big"}, "kind must be one of"),
    ({"kind": "random_in_box", "scale": "wide"}, "scale must be a real number"),
    ({"kind": "bait", "angle": 3}, r"bait behaviour has unknown key\(s\) \['angle'\]"),
    ({"kind": "own_state", "value": 1}, r"own_state behaviour has unknown key\(s\)"),
    ("constant", "behaviour must be a dict"),
])
def test_behaviour_from_dict_errors(d, match):
    with pytest.raises(InputError, match=match):
        behaviour_from_dict(d)


def test_to_dict_of_plain_callables_is_refused():
    with pytest.raises(InputError, match="needs f to be a TimePreset"):
        FunctionOfTime(lambda t: [0, 0]).to_dict()
    with pytest.raises(InputError, match="needs f to be a TwoFacedTable"):
        TwoFaced(lambda t, r: [0, 0]).to_dict()


# --------------------------------------------------------------------------- #
# all adversaries at once, and the step view
# --------------------------------------------------------------------------- #


def test_adversary_messages_deterministic_and_order_free():
    out_nbrs = {0: np.array([1, 2, 3]), 5: np.array([4, 6, 7])}
    beh1 = {0: RandomInBox(2.0), 5: RandomInBox(0.5)}
    beh2 = {5: RandomInBox(0.5), 0: RandomInBox(2.0)}  # other insertion order
    a = adversary_messages(beh1, out_nbrs, make_view(seed=9))
    b = adversary_messages(beh2, out_nbrs, make_view(seed=9))
    assert list(a) == [0, 5] and list(b) == [0, 5]
    for s in a:
        np.testing.assert_array_equal(a[s], b[s])
        assert a[s].shape == (3, D)
    c = adversary_messages(beh1, out_nbrs, make_view(seed=10))
    assert not np.array_equal(a[0], c[0])
    empty = adversary_messages({0: Constant([1, 1])}, {}, make_view())
    assert empty[0].shape == (0, D)


def test_adversary_messages_errors():
    class Broken(Behaviour):
        def messages(self, sender, receivers, view):
            return np.zeros((1, 1))

        def to_dict(self):
            return {}

    with pytest.raises(InputError,
                       match=r"Broken of sender 0 must return shape \(3, 2\); got \(1, 1\)"):
        adversary_messages({0: Broken()}, {0: np.array([1, 2, 3])}, make_view())
    with pytest.raises(InputError, match=r"behaviours\[0\] must be a Behaviour"):
        adversary_messages({0: "constant"}, {}, make_view())
    with pytest.raises(InputError, match=r"behaviours key 8 must be an agent index in \[0, 8\)"):
        adversary_messages({8: Constant([1, 1])}, {}, make_view())


def test_adversary_messages_that_are_not_numbers_are_named():
    class Words(Behaviour):
        def messages(self, sender, receivers, view):
            return [["a", "b"]] * len(receivers)

        def to_dict(self):
            return {}

    with pytest.raises(InputError, match=r"Words of sender 0 must return real numbers"):
        adversary_messages({0: Words()}, {0: np.array([1, 2])}, make_view())


def test_step_view_validation():
    v = make_view()
    assert (v.N, v.d) == (N, D)
    with pytest.raises(InputError, match=r"states must be an \(N, d\) array; got shape \(8,\)"):
        StepView(0, 0.0, v.states[:, 0], v.benign, v.in_neighbours, v.rng)
    with pytest.raises(InputError, match=r"benign must be a bool array of shape \(8,\)"):
        StepView(0, 0.0, v.states, v.benign.astype(int), v.in_neighbours, v.rng)
    with pytest.raises(InputError,
                       match=r"in_neighbours must have one entry per agent \(8\); got 7"):
        StepView(0, 0.0, v.states, v.benign, v.in_neighbours[:7], v.rng)
    with pytest.raises(InputError, match="rng must be a numpy.random.Generator"):
        StepView(0, 0.0, v.states, v.benign, v.in_neighbours, 0)


def test_doctests():
    res = doctest.testmod(adv_mod, optionflags=doctest.ELLIPSIS)
    assert res.failed == 0 and res.attempted > 5


@pytest.mark.parametrize("value", [1e308, -1.7e308, 5e-324])
def test_recorded_adversary_state_is_what_it_sent_at_any_magnitude(value):
    """The trajectory records each adversary's message (the mean of what it sent on its
    links): averaging six copies of 1e308 overflowed to inf (and warned)."""
    import warnings

    import networkx as nx

    import rescon

    G = nx.complete_graph(7).to_directed()
    x0 = {i: [float(i % 3), float(i % 2)] for i in range(7)}
    sc = rescon.Scenario(graph=G, x0=x0, F=1, steps=2,
                         adversaries={6: Constant([value, value])})
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        tr = rescon.simulate(sc)
    rec = tr.states[:, 6]
    assert np.isfinite(rec).all() and np.allclose(rec, value, rtol=4e-16, atol=0), rec
