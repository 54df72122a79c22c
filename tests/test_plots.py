"""Figures a researcher would put in a paper (issue 12 §5): the Figure objects are
inspected — axis scales and limits, legend entries, marker styles, bands — not only
the files written."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

pytest.importorskip("matplotlib")

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import PathCollection, PolyCollection  # noqa: E402
from matplotlib.markers import MarkerStyle  # noqa: E402

import rescon  # noqa: E402
from rescon.consensus.adversaries import Constant, TwoFaced  # noqa: E402
from rescon.consensus.trajectory import Trajectory  # noqa: E402


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _synthetic(K: int = 40, diameter: np.ndarray | None = None) -> Trajectory:
    """4 benign agents converging from [0, 10] to 5, adversary "a" a ramp to 300 in
    x(2) (a sine in x(1)), adversary "b" constant (−3, 2); N = 6, d = 2."""
    t = np.arange(K + 1) * 0.5
    start = np.array([[0.0, 1.0], [10.0, 9.0], [3.0, 0.0], [7.0, 10.0]])
    decay = np.exp(-t / 5)[:, None, None]
    benign = 5.0 + (start[None] - 5.0) * decay
    ramp = np.stack([3 * np.sin(t), 300 * t / t[-1]], axis=1)[:, None]
    const = np.tile([-3.0, 2.0], (K + 1, 1))[:, None]
    states = np.concatenate([benign[:, :2], ramp, benign[:, 2:], const], axis=1)
    rows = np.array([0, 1, 3, 4])
    if diameter is None:
        diameter = np.array([np.ptp(s[rows], axis=0).max() for s in states])
    metrics = {"diameter": diameter}
    return Trajectory(t, states, ("u", "v", "a", "w", "z", "b"), rows, metrics,
                      {"algorithm": "alg1", "policy": "hold", "F": 1})


def _panel(fig, ylabel: str):
    return next(ax for ax in fig.axes if ax.get_ylabel() == ylabel)


def _legend_labels(fig) -> list[str]:
    return [t.get_text() for lg in fig.legends for t in lg.get_texts()]


def _same_marker(collection: PathCollection, marker: str) -> bool:
    """Whether a scatter's marker path is ``marker``'s (up to scale)."""
    ms = MarkerStyle(marker)
    want = ms.get_path().transformed(ms.get_transform()).vertices
    got = collection.get_paths()[0].vertices
    return got.shape == want.shape and np.allclose(got / np.abs(got).max(),
                                                   want / np.abs(want).max())


def _two_faced_run() -> rescon.consensus.trajectory.Trajectory:
    """K7, F = 1: node 0 tells receiver r the value (10 (−1)^r, 1) (two-faced in x(1),
    one value in x(2)); node 6 is a stubborn (4, 4)."""
    G = nx.complete_graph(7)
    x0 = {v: [float(v), float(6 - v)] for v in G}
    adv = {0: TwoFaced(lambda t, r: np.array([10.0 * (-1) ** r, 1.0])),
           6: Constant([4.0, 4.0])}
    sc = rescon.Scenario(graph=G, x0=x0, F=2, adversaries=adv, steps=6, residual="none",
                         check_robustness=False)
    with pytest.warns(rescon.ScenarioWarning):
        return rescon.simulate(sc, progress=False)


# --------------------------------------------------------------------------- diameter


def test_log_diameter_axis_stops_above_zero_and_marks_the_zeros():
    dia = np.array([10.0, 1.0, 1e-3, 1e-9, 3e-15] + [0.0] * 36)
    fig = _synthetic(diameter=dia).plot()
    ax = _panel(fig, "diameter (benign)")
    assert ax.get_yscale() == "log"
    bottom = ax.get_ylim()[0]
    assert 1e-17 <= bottom < 3e-15  # a decade below the smallest positive value, not 1e-308
    line = ax.get_lines()[0]
    assert np.min(line.get_ydata()) >= bottom
    zero_marks = [c for c in ax.collections if _same_marker(c, "v")]
    assert len(zero_marks) == 1 and np.allclose(zero_marks[0].get_offsets()[:, 0], [2.5])
    assert "exactly 0 (drawn at the axis floor)" in _legend_labels(fig)


def test_log_floor_is_a_decade_below_the_smallest_positive_value():
    from rescon.plot.consensus import log_floor

    assert log_floor([5.0, 2e-15, 0.0]) == pytest.approx(1e-16)
    assert log_floor([5.0, 1e-3], [0.0, 7e-300]) == pytest.approx(1e-301)
    assert log_floor([5.0, 1e-3]) is None  # no zero: the axis autoscales
    assert log_floor([0.0, 0.0]) == pytest.approx(1e-16)
    assert log_floor([0.0, 5e-324]) == 5e-324  # no power of ten below it


# --------------------------------------------------------------------------- states


def test_one_legend_entry_for_benign_agents_and_one_style_per_adversary():
    fig = _synthetic().plot()
    labels = _legend_labels(fig)
    assert labels.count("benign agents") == 1
    assert "adversary a" in labels and "adversary b" in labels
    ax = _panel(fig, "x(1)")
    styles = {ln.get_label(): (ln.get_color(), ln.get_marker(), ln.get_linestyle())
              for ln in ax.get_lines() if ln.get_label().startswith("adversary")}
    assert set(styles) == {"adversary a", "adversary b"}
    a, b = styles.values()
    assert a[0] != b[0] and a[1] != b[1]
    benign = [c for c in ax.collections if c.get_label() == "benign agents"]
    assert len(benign) == 1 and len(benign[0].get_segments()) == 4  # one artist, N curves


def test_initial_states_marked_x_benign_and_o_adversarial():
    tr = _synthetic()
    ax = _panel(tr.plot(), "x(1)")
    starts = {c.get_label(): c for c in ax.collections if isinstance(c, PathCollection)}
    benign = starts["x_i(0), benign"]
    assert _same_marker(benign, "x")
    assert np.allclose(sorted(benign.get_offsets()[:, 1]), sorted(tr.states[0, tr.benign, 0]))
    assert np.allclose(benign.get_offsets()[:, 0], 0.0)
    circles = [c for c in ax.collections if c.get_label() == "x_i(0), adversary"]
    assert len(circles) == 2 and all(_same_marker(c, "o") for c in circles)
    assert all(c.get_facecolor().size == 0 or c.get_facecolor()[0, 3] == 0 for c in circles)
    assert sorted(float(c.get_offsets()[0, 1]) for c in circles) == sorted(
        tr.states[0, tr.adversary_rows, 0].tolist())


def test_adversary_ramp_does_not_flatten_the_benign_curves():
    tr = _synthetic()
    fig = tr.plot()
    zoom = _panel(fig, "x(2), benign range")
    lo, hi = zoom.get_ylim()
    b = tr.states[:, tr.benign, 1]
    assert lo <= b.min() and b.max() <= hi
    assert hi - lo <= 1.2 * np.ptp(b)  # the ramp to 300 does not set the scale
    ups = [c for c in zoom.collections if _same_marker(c, "^") and len(c.get_offsets())]
    assert ups  # the ramp marked ▲ at the top edge
    full = _panel(fig, "x(2), full range")
    assert full.get_ylim()[1] >= 300
    # x(1): the sine (amplitude 3) does not dominate: one panel with everyone in it
    assert all(ax.get_ylabel() != "x(1), full range" for ax in fig.axes)
    lo1, hi1 = _panel(fig, "x(1)").get_ylim()
    assert lo1 <= -3 and hi1 >= 10


def test_adversary_at_the_float_limit_still_draws(tmp_path):
    tr = _synthetic()
    tr.states[5:, 2, 1] = 1.7e308
    tr.states[5:, 5, 0] = -1.7e308
    fig = tr.plot(tmp_path / "huge.png")
    assert (tmp_path / "huge.png").stat().st_size > 0
    assert _panel(fig, "x(2), full range").get_yscale() == "symlog"
    lo, hi = _panel(fig, "x(1), benign range").get_ylim()
    assert -1 <= lo and hi <= 11


# --------------------------------------------------------------------------- two-faced


def test_two_faced_adversary_recorded_as_the_range_it_sent():
    tr = _two_faced_run()
    assert tr.sent.shape == (7, 2, 2, 2)  # (K+1, |A|, min/max, d): no O(N²) record
    assert np.allclose(tr.sent[:, 0, 0], [-10.0, 1.0])
    assert np.allclose(tr.sent[:, 0, 1], [10.0, 1.0])
    assert np.allclose(tr.sent[:, 1, 0], tr.sent[:, 1, 1])  # the stubborn one: one value
    js = tr.to_json()
    assert {"nodes", "benign", "times", "states", "metrics", "info", "seconds"} <= set(js)
    assert js["sent"]["nodes"] == [0, 6] and js["sent"]["max"][3][0] == [10.0, 1.0]


def test_two_faced_adversary_drawn_as_a_band_not_its_mean():
    tr = _two_faced_run()
    fig = tr.plot()
    ax = next(a for a in fig.axes if a.get_ylabel().startswith("x(1)"))
    bands = [c for c in ax.collections if isinstance(c, PolyCollection)
             and c.get_label() == "adversary 0: range sent"]
    assert len(bands) == 1
    ys = np.concatenate([p.vertices[:, 1] for p in bands[0].get_paths()])
    assert ys.min() == -10.0 and ys.max() == 10.0
    mean = tr.states[:, 0, 0]  # what the old figure drew: the mean of the messages
    assert not any(np.array_equal(ln.get_ydata(), mean) for ln in ax.get_lines())
    # in x(2) it sent one value to everyone: a line
    ax2 = next(a for a in fig.axes if a.get_ylabel().startswith("x(2)"))
    assert any(ln.get_label() == "adversary 0" for ln in ax2.get_lines())


# --------------------------------------------------------------------------- RMDO


def test_positive_cost_panel_on_a_log_scale():
    tr = _synthetic()
    K = len(tr.times)
    cost = np.linspace(50, 2, K)[:, None] * np.array([1.0, 1.5, 2.0, 3.0])
    tr.metrics.update(cost=cost, cost_at_mean=cost.mean(axis=1),
                      cost_rate=np.r_[0.0, np.diff(cost.mean(axis=1)) / 0.5])
    tr.info.update(update="rmdo", optimum={"value": 1.5})
    fig = tr.plot()
    ax = _panel(fig, "global cost")
    assert ax.get_yscale() == "log" and 0 < ax.get_ylim()[0] <= 1.5
    assert fig.texts[-1].get_text().startswith("Algorithm 2")


# --------------------------------------------------------------------------- kernels


def test_kernel_plot_2d_has_axis_labels_and_equal_scale():
    ax = rescon.safe_kernel([[0, 0], [4, 0], [4, 1], [0, 1], [2, 3]], 1).plot()
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x₁", "x₂")
    assert ax.get_aspect() == 1.0


def test_kernel_plot_3d_labels_view_equal_scale_and_translucent_faces(tmp_path):
    rng = np.random.default_rng(3)
    X = rng.integers(-20, 21, size=(14, 3)) * np.array([3, 1, 1])
    K = rescon.safe_kernel(X, 2)
    assert K.dim == 3
    ax = K.plot(path=tmp_path / "k.png", view=(30, -40))
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_zlabel()) == ("x₁", "x₂", "x₃")
    assert (ax.elev, ax.azim) == (30, -40)
    span = np.ptp(X, axis=0).astype(float)
    assert np.allclose(ax.get_box_aspect() / ax.get_box_aspect()[0], span / span[0],
                       rtol=1e-6)
    faces = [c for c in ax.collections if c.get_label().startswith("safe kernel")]
    assert len(faces) == 1 and faces[0].get_alpha() < 1
    assert len(faces[0].get_paths()) == len(K._exact.facets)  # one polygon per facet
    assert K.plot().elev != 90  # the default view is oblique


def test_kernel_plot_3d_of_a_planar_kernel_is_one_polygon():
    X = [[0, 0, 0], [6, 0, 0], [6, 6, 0], [0, 6, 0], [3, 7, 0], [-1, 3, 0], [7, 3, 0]]
    K = rescon.safe_kernel(X, 1)
    assert K.dim == 2
    ax = K.plot()
    faces = [c for c in ax.collections if c.get_label().startswith("safe kernel")]
    assert len(faces) == 1 and len(faces[0].get_paths()) == 1
    assert ax.get_zlabel() == "x₃"


@settings(max_examples=60, deadline=None)
@example([0.0, 9.999999999999346e+299])  # log10 rounds up to 300: the floor was 1e299
@given(st.lists(st.floats(min_value=0.0, max_value=1e300, allow_subnormal=True)
                | st.sampled_from([0.0, 5e-324, 1e-310]), min_size=1, max_size=20))
def test_log_floor_property(values):
    """With a zero shown, the floor is > 0 and a power of ten at least a decade below
    every positive value (unless that is deep in the subnormals); without one, None."""
    from rescon.plot.consensus import log_floor

    floor = log_floor(values)
    positive = [v for v in values if v > 0]
    if 0.0 not in values:
        assert floor is None
        return
    assert floor > 0
    if all(v > 1e-300 for v in positive):
        assert all(floor <= v / 10 for v in positive)
        assert np.isclose(np.log10(floor), round(np.log10(floor)))
