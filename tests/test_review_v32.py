"""V32 hostile review of the figure and output changes of 53b511a, 79516dc and c24e442.

Attacked: ``rescon.plot.unit_exponent`` / ``in_units`` / ``unit_label`` (boundaries
1e±100 and 9.99e99, subnormals, |k| up to 324 against exact rationals, values that
leave the float range in units); ``Trajectory.plot`` (ordinary runs: the line data
against the trajectory; benign states at 1e-150 with adversaries at 1e150, states
crossing zero, all zeros, NaN / ±inf in states and metrics, one coordinate at 1e-300
and another at 1, a trajectory and its copy scaled by 1e-200, two-faced bands, RMDO
cost / rate panels and the linear diameter at 1e±300, the caller's non-Agg pyplot
backends); ``SafeKernel.plot`` in 2-D / 3-D (one axis at 1e-300, the others at 1; all
at 1e±300); ``new_figure`` (figures with / without a path in pyplot, many plots in a
loop, the caller's backend after ``Trajectory.plot``, ``SafeKernel.plot``,
``rescon.paper``'s figure functions and ``rescon.sweep``'s summary.png);
``Trajectory.to_json`` (numpy / tuple / str labels, NaN and ±inf, integer metrics,
numpy values in ``info``; nothing in the project reads trajectory.json back, so it is
checked with ``json.loads``); the CLI's ``simulate --out DIR --plot`` (files
overwritten, a directory or a symlink at DIR/trajectory.json, dangling symlinks,
``--json`` stdout).

Bugs are the tests under "bugs" (all fixed since, markers removed); the rest held.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from fractions import Fraction

import networkx as nx
import numpy as np
import pytest

pytest.importorskip("matplotlib")

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import rescon  # noqa: E402
from rescon.cli import main  # noqa: E402
from rescon.consensus.adversaries import Constant  # noqa: E402
from rescon.consensus.trajectory import Trajectory  # noqa: E402
from rescon.plot import in_units, new_figure, unit_exponent, unit_label  # noqa: E402

TOP = np.finfo(float).max


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _hand(states, benign, metrics=None, *, times=None, sent=None, info=None, nodes=None):
    states = np.asarray(states, dtype=float)
    K, N, _ = states.shape
    return Trajectory(np.arange(K) * 0.5 if times is None else np.asarray(times, float),
                      states, tuple(range(N)) if nodes is None else tuple(nodes),
                      np.asarray(benign, dtype=int), metrics or {},
                      info or {"algorithm": "alg1", "policy": "hold", "F": 1}, sent=sent)


def _plot(traj, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # matplotlib's RuntimeWarnings at the float limit
        fig = traj.plot(**kw)
        fig.canvas.draw()
    return fig


def _rmdo(cost, rate, K=5):
    st = np.zeros((K, 3, 1))
    st[:, :, 0] = [-1.0, 0.0, 1.0]
    m = {"diameter": np.full(K, 2.0), "cost": np.tile(np.asarray(cost, float), (K, 1)),
         "cost_at_mean": np.full(K, float(np.mean(cost))), "cost_rate": np.full(K, rate)}
    return _hand(st, [0, 1, 2], m, info={"update": "rmdo", "policy": "hold", "F": 1,
                                          "optimum": {}})


def _contains(lim, values):
    lo, hi = min(lim), max(lim)
    return all(lo <= v <= hi for v in np.ravel(values))


def _complete(labels):
    return nx.relabel_nodes(nx.complete_graph(len(labels)).to_directed(),
                            dict(enumerate(labels)))


SCENARIO = """\
[scenario]
F = 1
steps = 3
residual = "none"
[graph]
generator = "complete"
n = 6
[initial]
0 = [0.0, 1.0]
1 = [1.0, 0.0]
2 = [2.0, 2.0]
3 = [3.0, 1.0]
4 = [4.0, 5.0]
5 = [5.0, 3.0]
"""


def _cli(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


# --------------------------------------------------------------------------- held: units


def test_unit_exponent_boundaries():
    assert unit_exponent([1e100]) == 0 and unit_exponent([-1e100]) == 0
    assert unit_exponent([9.99e99]) == 0 and unit_exponent([1e-100]) == 0
    assert unit_exponent([np.nextafter(1e100, np.inf)]) == 100
    assert unit_exponent([np.nextafter(1e-100, 0.0)]) in (-101, -100)  # log10 rounds
    assert unit_exponent(np.zeros(4)) == 0 and unit_exponent([]) == 0
    assert unit_exponent([np.nan, np.inf, -np.inf, 3.0]) == 0  # non-finite ignored
    assert unit_exponent([5e-324]) == -324 and unit_exponent([TOP]) == 308
    assert unit_exponent([1e-150], [2.0]) == 0  # the largest magnitude decides


def test_in_units_is_v_over_10_to_k_to_float_accuracy():
    values = [1.0, -3.7, 5e-324, 1e-310, 2.2250738585072014e-308, 1.2345e-200, TOP]
    for k in range(-324, 325, 7):
        got = in_units(values, k)
        for v, g in zip(values, got, strict=True):
            exact = Fraction(v) / Fraction(10) ** k
            if abs(exact) > Fraction(TOP):
                assert g == math.copysign(math.inf, v)
                continue
            e = float(exact)
            tol = 2 * math.ulp(e) if abs(e) >= 2.2250738585072014e-308 else 2 * 5e-324
            assert abs(g - e) <= tol, (v, k, g, e)


def test_in_units_extremes_and_label():
    assert in_units([5e-324], -324)[0] == pytest.approx(4.94065645841247, rel=1e-12)
    assert in_units([TOP], 308)[0] == pytest.approx(1.7976931348623157, rel=1e-15)
    assert in_units([1e300, -1e300], -100).tolist() == [math.inf, -math.inf]
    assert in_units([3.0], 0).tolist() == [3.0]
    assert unit_label("t", -300, "s") == "t (×1e-300 s)"
    assert unit_label("x₁", 308) == "x₁ (×1e308)" and unit_label("x", 0) == "x"
    assert unit_label("t", 0, "s") == "t (s)"


# --------------------------------------------------------------------------- held: figures


def test_ordinary_figure_draws_the_trajectory_values_without_units():
    labels = list(range(6))
    x0 = {lab: [1e-3 * (i + 1), 1e6 * (i - 2.5)] for i, lab in enumerate(labels)}
    sc = rescon.Scenario(graph=_complete(labels), x0=x0, F=1, steps=4,
                         adversaries={5: Constant([2e-3, 4e6])})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        traj = rescon.simulate(sc)
    fig = _plot(traj)
    assert all("×1e" not in a.get_ylabel() for a in fig.axes)
    assert fig.axes[-1].get_xlabel() == "t (s)"
    coord_axes = [a for a in fig.axes if a.get_ylabel().startswith("x(")]
    for p, ax in enumerate(coord_axes[:2]):
        segs = ax.collections[0].get_segments()
        for seg, i in zip(segs, traj.benign, strict=True):
            np.testing.assert_array_equal(seg[:, 0], traj.times)
            np.testing.assert_array_equal(seg[:, 1], traj.states[:, i, p])
        adv = traj.adversary_rows[0]
        np.testing.assert_array_equal(ax.lines[0].get_xydata(),
                                      np.c_[traj.times, traj.states[:, adv, p]])
    dia = [a for a in fig.axes if a.get_ylabel() == "diameter (benign)"][0]
    np.testing.assert_array_equal(dia.lines[0].get_ydata(), traj.metrics["diameter"])


def test_mixed_magnitudes_benign_tiny_adversary_huge():
    K = 5
    st = np.zeros((K, 4, 1))
    st[:, :3, 0] = np.array([1.0, 2.0, 3.0]) * 1e-150
    st[:, 3, 0] = 1e150
    fig = _plot(_hand(st, [0, 1, 2], {"diameter": np.full(K, 2e-150)}))
    labels = [a.get_ylabel() for a in fig.axes]
    assert labels[:2] == ["x(1) (×1e-150), benign range", "x(1) (×1e-150), full range"]
    zoom = fig.axes[0]
    assert _contains(zoom.get_ylim(), [1.0, 3.0]) and max(zoom.get_ylim()) < 4
    for seg, want in zip(zoom.collections[0].get_segments(), [1.0, 2.0, 3.0], strict=True):
        np.testing.assert_allclose(seg[:, 1], want, rtol=1e-15)
    np.testing.assert_allclose(fig.axes[1].lines[0].get_ydata(), 1e300, rtol=1e-15)
    assert _contains(fig.axes[1].get_ylim(), [1.0, *fig.axes[1].lines[0].get_ydata()])


def test_zero_and_sign_crossing_states_draw_as_they_are():
    K = 4
    zeros = _plot(_hand(np.zeros((K, 3, 1)), [0, 1, 2], {"diameter": np.zeros(K)}))
    assert zeros.axes[0].get_ylabel() == "x(1)"
    st = np.zeros((K, 3, 1))
    st[:, :, 0] = [-1.0, 0.0, 1.0]
    fig = _plot(_hand(st, [0, 1, 2], {"diameter": np.array([np.nan, np.inf, 1.0, 0.0])}))
    assert fig.axes[0].get_ylabel() == "x(1)"
    assert [s[0, 1] for s in fig.axes[0].collections[0].get_segments()] == [-1.0, 0.0, 1.0]


def test_each_coordinate_has_its_own_unit():
    K = 4
    st = np.zeros((K, 2, 2))
    st[:, 0] = [1e-300, 1.0]
    st[:, 1] = [2e-300, 2.0]
    fig = _plot(_hand(st, [0, 1], {"diameter": np.ones(K)}))
    assert [a.get_ylabel() for a in fig.axes[:2]] == ["x(1) (×1e-300)", "x(2)"]
    for ax in fig.axes[:2]:
        ys = sorted(s[0, 1] for s in ax.collections[0].get_segments())
        np.testing.assert_allclose(ys, [1.0, 2.0], rtol=1e-15)


def test_scaled_copy_draws_the_same_lines():
    """A trajectory and its copy scaled by 1e-200 (states and times) draw the same
    numbers, the copy in units of 1e-200."""
    K = 6
    st = np.zeros((K, 5, 1))
    st[:, :3, 0] = np.linspace(0, 1, K)[:, None] * [1.0, 2.0, 3.0]
    st[:, 3, 0] = np.linspace(40, -40, K)
    st[:, 4, 0] = 1e5
    a = _plot(_hand(st, [0, 1, 2], {"diameter": np.full(K, 2.0)}))
    b = _plot(_hand(st * 1e-200, [0, 1, 2], {"diameter": np.full(K, 2e-200)},
                    times=np.arange(K) * 0.5e-200))
    assert len(a.axes) == len(b.axes)
    assert b.axes[-1].get_xlabel() == "t (×1e-200 s)"
    for ax_a, ax_b in zip(a.axes[:2], b.axes[:2], strict=True):
        assert ax_b.get_ylabel() == ax_a.get_ylabel().replace("x(1)", "x(1) (×1e-200)")
        for la, lb in zip(ax_a.lines, ax_b.lines, strict=True):
            np.testing.assert_allclose(lb.get_ydata(), la.get_ydata(), rtol=1e-14)


@pytest.mark.parametrize("scale", [1e-100, 1e100 / 3, 9.99e99 / 3])
def test_states_at_the_unit_boundary_are_drawn_as_they_are(scale):
    K = 4
    st = np.zeros((K, 3, 1))
    st[:, :, 0] = np.array([1.0, 2.0, 3.0]) * scale
    fig = _plot(_hand(st, [0, 1, 2], {"diameter": np.full(K, 2 * scale)}))
    assert fig.axes[0].get_ylabel() == "x(1)"
    ys = [s[0, 1] for s in fig.axes[0].collections[0].get_segments()]
    assert ys == (np.array([1.0, 2.0, 3.0]) * scale).tolist()
    lo, hi = fig.axes[0].get_ylim()
    assert lo < scale and 3 * scale < hi < 4 * scale


@pytest.mark.parametrize("scale", [1e-300, 1e300])
def test_kernel_2d_and_3d_in_one_unit(scale):
    X2 = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [0.5, 0.5]], float)
    X3 = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1], [.3, .3, .3]])
    k = round(math.log10(scale))
    for X in (X2, X3):
        ax = rescon.safe_kernel(X * scale, F=1).plot()
        names = [ax.get_xlabel(), ax.get_ylabel()] + (
            [ax.get_zlabel()] if X.shape[1] == 3 else [])
        assert all(n.endswith(f"(×1e{k})") for n in names)
        if X.shape[1] == 2:
            np.testing.assert_allclose(ax.collections[0].get_offsets(), X, rtol=1e-15)


def test_kernel_one_axis_tiny_the_other_one_keeps_equal_scale():
    X = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [0.5, 0.5]], float) * [1e-300, 1.0]
    ax = rescon.safe_kernel(X, F=1).plot()
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x₁", "x₂")
    np.testing.assert_array_equal(ax.collections[0].get_offsets(), X)


def test_legend_collapses_beyond_ten_adversaries_and_keeps_48_characters():
    K, n_adv = 3, 11
    st = np.zeros((K, 3 + n_adv, 1))
    st[:, :3, 0] = [0.0, 1.0, 2.0]
    st[:, 3:, 0] = np.arange(n_adv) + 10.0
    fig = _plot(_hand(st, [0, 1, 2]))
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "11 adversaries (styles cycled)" in texts
    assert not any(t.startswith("adversary ") and t[10:].isdigit() for t in texts)
    st10 = st[:, :13]
    texts10 = [t.get_text() for t in _plot(_hand(st10, [0, 1, 2])).legends[0].get_texts()]
    assert sum(t.startswith("adversary ") and t[10:].isdigit() for t in texts10) == 10
    long = ("n" * 60,)
    fig = _plot(_hand(st[:, :4], [0, 1, 2], nodes=(0, 1, 2) + long))
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert ("adversary " + "n" * 60)[:47] + "…" in texts


# --------------------------------------------------------------------------- held: canvases


def test_new_figure_with_and_without_path(tmp_path):
    before = plt.get_fignums()
    shown = new_figure()
    assert plt.get_fignums() == before + [shown.number]
    written = new_figure(tmp_path / "x.png")
    assert plt.get_fignums() == before + [shown.number]
    assert written.canvas.__class__.__name__ == "FigureCanvasAgg"


def test_many_plots_to_files_leave_no_open_figures(tmp_path):
    K = 3
    st = np.zeros((K, 3, 1))
    st[:, :, 0] = [0.0, 1.0, 2.0]
    traj = _hand(st, [0, 1, 2], {"diameter": np.full(K, 2.0)})
    K2 = rescon.safe_kernel(np.array([[0, 0], [1, 0], [0, 1], [1, 1.0]]), F=1)
    before = plt.get_fignums()
    for i in range(12):
        traj.plot(tmp_path / f"t{i}.png")
        K2.plot(path=tmp_path / f"k{i}.png")
    assert plt.get_fignums() == before
    assert (tmp_path / "t11.png").stat().st_size > 0 and (tmp_path / "k11.png").exists()
    traj.plot()
    assert len(plt.get_fignums()) == len(before) + 1  # without a path: through pyplot


def test_callers_backend_and_figures_kept_by_files(tmp_path):
    from rescon.paper import _plot_centres, _plot_distance

    K = 4
    st = np.zeros((K, 3, 1))
    st[:, :, 0] = [0.0, 1.0, 2.0]
    m = {"diameter": np.array([2.0, 1.0, 0.0, 0.0]), "validity": np.zeros(K),
         "distance_to_optimum": np.array([1.0, 0.5, 0.0, 0.0])}
    traj = _hand(st, [0, 1, 2], m)
    plt.switch_backend("svg")
    try:
        mine = plt.figure()
        traj.plot(tmp_path / "a.png")
        rescon.safe_kernel(np.array([[0, 0], [1, 0], [0, 1], [1, 1.0]]), F=1).plot(
            path=tmp_path / "k.png")
        _plot_centres({"box": traj, "mean": traj}, tmp_path / "c.png")
        _plot_distance(traj, traj, tmp_path / "d.png")
        assert matplotlib.get_backend().lower() == "svg"
        assert plt.get_fignums() == [mine.number]
    finally:
        plt.switch_backend("Agg")
    for name in ("a.png", "k.png", "c.png", "d.png"):
        assert (tmp_path / name).stat().st_size > 0


# --------------------------------------------------------------------------- held: to_json


def test_to_json_plain_types_nulls_ints_and_labels():
    K = 3
    st = np.zeros((K, 4, 1))
    st[:, 0, 0], st[:, 1, 0], st[:, 2, 0], st[:, 3, 0] = 1.0, np.nan, np.inf, -np.inf
    sent = np.full((K, 1, 2, 1), np.nan)
    sent[:, 0, 1, 0] = np.inf
    nodes = (np.int64(3), (1, 2), "a b", np.uint8(7))
    traj = _hand(st, [0, 1, 2], {"diameter": np.array([1.0, np.nan, -np.inf]),
                                 "blocked_links": np.array([1, 2, 3])},
                 sent=sent, nodes=nodes,
                 info={"x": np.float32(0.5), "n": np.int32(4), "arr": np.arange(2),
                       "optimum": {"value": np.float64(np.nan)}})
    j = traj.to_json()
    back = json.loads(json.dumps(j, allow_nan=False))
    assert back == j
    assert back["nodes"] == [3, [1, 2], "a b", 7] and back["benign"] == [3, [1, 2], "a b"]
    assert back["states"][0] == [[1.0], [None], [None], [None]]
    assert back["metrics"]["diameter"] == [1.0, None, None]
    assert back["metrics"]["blocked_links"] == [1, 2, 3]
    assert all(type(v) is int for v in back["metrics"]["blocked_links"])
    assert back["info"] == {"x": 0.5, "n": 4, "arr": [0, 1], "optimum": {"value": None}}
    assert back["sent"] == {"nodes": [7], "min": [[[None]]] * K, "max": [[[None]]] * K}


# --------------------------------------------------------------------------- held: CLI


def test_cli_overwrites_and_refuses_directories_before_the_run(tmp_path, capsys):
    sc = tmp_path / "s.toml"
    sc.write_text(SCENARIO, encoding="utf-8")
    out = tmp_path / "o"
    out.mkdir()
    for name in ("trajectory.json", "trajectory.csv", "trajectory.png"):
        (out / name).write_text("old\n", encoding="utf-8")
    code, stdout, err = _cli(["simulate", sc, "--out", out, "--plot", "--json", "-q"], capsys)
    assert code == 0, err
    assert json.loads(stdout)["out"] == str(out)  # one JSON object, nothing else
    assert json.loads((out / "trajectory.json").read_text(encoding="utf-8"))["nodes"]
    assert (out / "trajectory.png").read_bytes()[:4] == b"\x89PNG"
    for kind in ("dir", "symlink"):
        d = tmp_path / kind
        d.mkdir()
        if kind == "dir":
            (d / "trajectory.json").mkdir()
        else:
            (tmp_path / "target").mkdir()
            os.symlink(tmp_path / "target", d / "trajectory.json")
        code, stdout, err = _cli(["simulate", sc, "--out", d, "--plot", "--json", "-q"],
                                 capsys)
        assert code == 2 and stdout == ""
        assert err.count("\n") == 1 and err.startswith("rescon: error: --out:"), err
        assert sorted(p.name for p in d.iterdir()) == ["trajectory.json"]


# --------------------------------------------------------------------------- bugs


# Fixed (was a bug: an adversary at ±inf is drawn at ±1.797e308 (a finite value, with a full-range
# panel and off-scale marks) once the benign coordinate is drawn in units: _drawn clips inf to the
# float limit)
def test_infinite_adversary_is_not_drawn_as_finite_in_units():
    K = 5
    out = []
    for s in (1.0, 1e-200):
        st = np.zeros((K, 4, 1))
        st[:, :3, 0] = np.array([1.0, 2.0, 3.0]) * s
        st[:, 3, 0] = [-np.inf, 2 * s, -np.inf, 2 * s, 2 * s]
        fig = _plot(_hand(st, [0, 1, 2]))
        out.append((len(fig.axes), fig.axes[0].lines[0].get_ydata()))
    (n1, y1), (n2, y2) = out
    assert n1 == n2 == 1  # all agents fit: no zoom, no full-range panel
    np.testing.assert_array_equal(np.isfinite(y2), np.isfinite(y1))


# Fixed (was a bug: a two-faced adversary whose messages underflow in the benign unit (sent band
# 1e-200..2e-200, benign at 1e150) vanishes: _sent_band compares the scaled bounds (both 0.0),
# finds no band and draws its NaN states row)
def test_two_faced_band_survives_the_benign_unit():
    K = 5
    st = np.zeros((K, 4, 1))
    st[:, :3, 0] = np.array([1.0, 2.0, 3.0]) * 1e150
    st[:, 3, 0] = np.nan
    sent = np.zeros((K, 1, 2, 1))
    sent[:, 0, 0, 0], sent[:, 0, 1, 0] = 1e-200, 2e-200
    fig = _plot(_hand(st, [0, 1, 2], sent=sent))
    texts = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "adversary 3: range sent" in texts
    assert any(np.isfinite(line.get_ydata()).any() for line in fig.axes[0].lines)


# Fixed (was a bug: Trajectory.plot() without a path on the caller's pdf/svg/ps backend:
# AttributeError 'FigureCanvasSVG' object has no attribute 'get_renderer' (_figure_legend,
# plot/consensus.py:419))
@pytest.mark.parametrize("backend", ["svg", "pdf"])
def test_plot_without_path_on_a_vector_backend(backend):
    K = 3
    st = np.zeros((K, 3, 1))
    st[:, :, 0] = [0.0, 1.0, 2.0]
    plt.switch_backend(backend)
    try:
        fig = _hand(st, [0, 1, 2], {"diameter": np.full(K, 2.0)}).plot()
        assert fig.number in plt.get_fignums() and fig.legends
    finally:
        plt.close("all")
        plt.switch_backend("Agg")


# Fixed (was a bug: RMDO cost and change-rate panels at ±1e300 get y-limits (-0.001, 0.001): the
# curves are off the axes (the metric panels are drawn as they are, not in units, on a symlog
# autoscale that fails))
def test_rmdo_panels_at_1e300_show_their_values():
    fig = _plot(_rmdo([-1e300, 2e300, 3e300], 1e300))
    cost, rate = fig.axes[2], fig.axes[3]
    # drawn in units of 1e300, named in the labels
    assert (cost.get_ylabel(), rate.get_ylabel()) == ("global cost (×1e300)",
                                                      "change rate (×1e300 1/s)")
    assert _contains(_data_lim(cost), [-1e300, 3e300])
    assert _contains(_data_lim(rate), [1e300])


RMDO_BIG = SCENARIO.split("[initial]")[0] + """\
[initial]
0 = [1e149]
1 = [-1e149]
2 = [2e149]
3 = [3e149]
4 = [5e148]
5 = [0.0]
[costs]
""" + "".join(f'{i} = "(x1 - {1 + i % 2})^2"\n' for i in range(6))


# Fixed (was a bug: rescon rmdo with states at 1e149 (within x0's 1e150 limit): the global cost
# panel is a log axis with y-limits (1, 10) while the costs run 15 .. 5.4e299: F(benign mean) is
# drawn off the axes)
def test_rmdo_run_near_the_state_limit_shows_its_cost(tmp_path):
    from rescon.optim.files import read_rmdo
    from rescon.optim.rmdo import rmdo

    sc = tmp_path / "r.toml"
    sc.write_text(RMDO_BIG, encoding="utf-8")
    f = read_rmdo(sc)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        traj = rmdo(f.scenario, f.costs, step_size=f.step_size, progress=False)
    fig = _plot(traj)
    cost = [a for a in fig.axes if a.get_ylabel().startswith("global cost")][0]
    assert _contains(_data_lim(cost), traj.metrics["cost_at_mean"])


# Fixed (was a bug: a cost between 1e-300 and 3e-300 (and the diameter with log_diameter=False at
# 1e-300) is drawn flat on a linear axis widened to ±0.055: the metric panels have no unit)
def test_tiny_metrics_are_not_flat():
    fig = _plot(_rmdo([1e-300, 2e-300, 3e-300], 1e-300))
    lo, hi = _data_lim(fig.axes[2])
    assert hi - lo < 1e3 * 2e-300 and _contains((lo, hi), [1e-300, 3e-300])
    K = 4
    st = np.zeros((K, 3, 1))
    st[:, :, 0] = np.array([-1.0, 0.0, 1.0]) * 1e-300
    fig = _plot(_hand(st, [0, 1, 2], {"diameter": np.linspace(2e-300, 1e-300, K)}),
                log_diameter=False)
    lo, hi = _data_lim(fig.axes[-1])
    assert hi - lo < 1e3 * 2e-300


def _data_lim(ax):
    """y-limits in data units (a label "… (×1eK …)" says units of 10^K)."""
    import re

    m = re.search(r"×1e(-?\d+)", ax.get_ylabel())
    return tuple(v * 10.0 ** int(m.group(1)) if m else v for v in ax.get_ylim())


# Fixed (was a bug: a diameter near the float limit (1e308, 1.7e308, then 0) breaks the diameter
# panel: log axis (default) OverflowError 'cannot convert float infinity to integer' in
# matplotlib's tick formatter, linear ValueError 'arange: cannot compute length' (metrics drawn
# unscaled))
@pytest.mark.parametrize("log", [True, False])
def test_diameter_at_the_float_limit_draws(log):
    K = 4
    st = np.zeros((K, 3, 1))
    st[:, :, 0] = np.array([-1.0, 0.0, 1.0]) * 8e307
    fig = _plot(_hand(st, [0, 1, 2], {"diameter": np.array([1e308, 1.7e308, 0.0, 0.0])}),
                log_diameter=log)
    assert _contains(_data_lim(fig.axes[-1]), [1e308, 1.7e308])


# Fixed (was a bug: a dangling symlink at DIR/trajectory.json (or .png) passes the pre-run check;
# the run happens, then a bare '[Errno 2] No such file or directory' (not naming --out/--plot),
# and for .png after trajectory.json/.csv were written)
@pytest.mark.parametrize("name", ["trajectory.json", "trajectory.png"])
def test_dangling_symlink_refused_before_the_run(tmp_path, capsys, name):
    sc = tmp_path / "s.toml"
    sc.write_text(SCENARIO, encoding="utf-8")
    d = tmp_path / "o"
    d.mkdir()
    os.symlink(tmp_path / "missing" / "x", d / name)
    code, stdout, err = _cli(["simulate", sc, "--out", d, "--plot", "--json", "-q"], capsys)
    assert code == 2 and stdout == ""
    assert "warning" not in err  # refused before the scenario ran
    assert err.count("\n") == 1 and ("--out" in err or "--plot" in err), err
    assert sorted(p.name for p in d.iterdir()) == [name]
