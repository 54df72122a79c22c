"""V31 hostile review: everything rescon draws or writes for a user to read later.

Attacked: ``Trajectory.plot()`` (consensus and RMDO panels: single steps, exact-zero
diameters, NaN change rates, unknown X*, metric subsets, d = 1 and 3, N = 2000, node
labels with spaces / unicode / 300 characters, 100 adversaries, values at 1e-300 and
at the float limit), ``SafeKernel.plot(path)`` (d = 1, 2, 3; flat, single-point and
empty kernels; coordinates 1e-300, 1e300, ±1e308), ``Trajectory.to_json`` /
``to_csv`` re-read with ``json.load`` / ``pandas.read_csv`` (NaN from a non-finite
adversary, numpy and string labels), the CLI's ``--out`` / ``--plot`` / ``--json`` /
``--metrics`` for ``simulate``, ``rmdo``, ``kernel``, ``sweep`` and ``paper`` (paths
with spaces and unicode, missing parents, an existing file or directory where the
other is expected), a sweep whose cells all fail (``summary.png``, the parquet table
re-read), and matplotlib missing (``sys.modules['matplotlib'] = None`` in a fresh
process; runs without ``--plot`` must not need it), and the user's matplotlib state
(the backend) after a figure is written.

The 13 bugs found (the tests under "bugs") are fixed: each test runs as an ordinary
one, with a comment "Fixed (was a bug: ...)"; the rest held. Values beyond 1e±100 are
drawn in units of 10^k named in the axis label (matplotlib widens any axis range below
~2e-287 and overflows on spans beyond the float limit), so the tests of tiny values
read the axis limits back in data units (:func:`_data_lim`).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import textwrap
import warnings
from pathlib import Path

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

PY = sys.executable


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def _complete(labels):
    return nx.relabel_nodes(nx.complete_graph(len(labels)).to_directed(),
                            dict(enumerate(labels)))


def _run(labels=None, *, steps=3, d=1, scale=1.0, adversaries=None, **kw):
    labels = list(range(6)) if labels is None else labels
    x0 = {lab: [scale * float(i)] * d for i, lab in enumerate(labels)}
    sc = rescon.Scenario(graph=_complete(labels), x0=x0, F=1, steps=steps,
                         adversaries=adversaries or {}, **kw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rescon.simulate(sc)


def _hand(states, benign, metrics=None, nodes=None):
    K, N, _ = states.shape
    return Trajectory(np.arange(K) * 0.5, np.asarray(states, float),
                      tuple(range(N) if nodes is None else nodes),
                      np.asarray(benign, dtype=int), metrics or {},
                      {"algorithm": "alg1", "policy": "hold", "F": 1})


def _cli(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


SCENARIO = """\
[scenario]
F = 1
steps = 4
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
[adversaries.0]
kind = "two_faced"
cycle = [[40.0, 40.0], [-40.0, 0.0]]
"""

RMDO_UNBOUNDED = SCENARIO.replace("[adversaries.0]\nkind = \"two_faced\"\n"
                                  "cycle = [[40.0, 40.0], [-40.0, 0.0]]\n", "") + (
    "[costs]\n" + "".join(f'{i} = "x1 + x2"\n' for i in range(6)))


def _file(tmp_path, name, text):
    p = tmp_path / name
    p.write_text(text, encoding="utf-8")
    return p


def _data_lim(lim, label):
    """Axis limits in data units: a label "… (×1eK …)" says the axis is drawn in units
    of 10^K."""
    m = re.search(r"×1e(-?\d+)", label)
    return tuple(v * 10.0 ** int(m.group(1)) for v in lim) if m else tuple(lim)


def _no_nonfinite_tokens(text):
    for token in ("NaN", "Infinity"):
        assert token not in text


# --------------------------------------------------------------------------- held


def test_cli_simulate_out_plot_json_files_round_trip(tmp_path, capsys):
    sc = _file(tmp_path, "s.toml", SCENARIO)
    out = tmp_path / "new dir ü" / "deeper"
    code, stdout, err = _cli(["simulate", sc, "--out", out, "--plot", "--json", "-q"], capsys)
    assert code == 0, err
    summary = json.loads(stdout)  # exactly one object on stdout
    assert stdout.count("\n") == 1 and summary["out"] == str(out)
    text = (out / "trajectory.json").read_text(encoding="utf-8")
    _no_nonfinite_tokens(text)
    data = json.loads(text)
    traj = rescon.simulate(rescon.Scenario.from_toml(sc))
    states = np.array(data["states"], dtype=float)
    np.testing.assert_array_equal(states, traj.states)
    assert data["metrics"]["diameter"][-1] == summary["final_diameter"] == traj.final_diameter
    import pandas as pd

    df = pd.read_csv(out / "trajectory.csv")
    np.testing.assert_array_equal(df[["x1", "x2"]].to_numpy().reshape(traj.states.shape),
                                  traj.states)
    assert (out / "trajectory.png").stat().st_size > 0


def test_nan_states_are_null_in_json_and_nan_in_csv(tmp_path):
    traj = _hand(np.array([[[0.0], [1.0], [np.nan]], [[0.5], [0.5], [np.nan]]]), [0, 1],
                 {"diameter": np.array([1.0, 0.0])})
    text = json.dumps(traj.to_json(), allow_nan=False)
    back = json.loads(text)
    assert back["states"][0][2] == [None] and back["states"][1][2] == [None]
    import pandas as pd

    df = pd.read_csv(traj.to_csv(tmp_path / "a" / "t.csv"))
    assert df["x1"].isna().sum() == 2 and df["x1"].iloc[0] == 0.0


def test_string_labels_with_spaces_and_unicode_round_trip(tmp_path):
    labels = ["alice smith", "bøb ü 中文", " lead", "d", "e", "f"]
    traj = _run(labels)
    back = json.loads(json.dumps(traj.to_json()))
    assert back["nodes"] == labels
    import pandas as pd

    df = pd.read_csv(traj.to_csv(tmp_path / "t.csv"), keep_default_na=False)
    assert list(dict.fromkeys(df["node"])) == labels


@pytest.mark.parametrize("steps", [0, 1])
def test_single_step_trajectory_draws_a_visible_diameter(steps, tmp_path):
    fig = _run(steps=steps, residual="none").plot(tmp_path / f"s{steps}.png")
    ax = next(a for a in fig.axes if a.get_ylabel() == "diameter (benign)")
    line = ax.get_lines()[0]
    assert len(line.get_xdata()) > 1 or line.get_marker() not in ("None", "", " ", None)
    assert (tmp_path / f"s{steps}.png").stat().st_size > 0


def test_converged_diameter_exact_zero_on_log_axis(tmp_path):
    traj = _hand(np.array([[[0.0], [2.0]], [[1.0], [1.0]], [[1.0], [1.0]]]), [0, 1],
                 {"diameter": np.array([2.0, 0.0, 0.0])})
    fig = traj.plot(tmp_path / "z.png")
    ax = next(a for a in fig.axes if a.get_ylabel() == "diameter (benign)")
    assert ax.get_yscale() == "log" and 0 < ax.get_ylim()[0] < 0.2
    assert any("exactly 0 at 2 of 3 steps" in t.get_text() for t in ax.texts)


def test_subnormal_diameter_floor_is_positive(tmp_path):
    traj = _hand(np.zeros((3, 2, 1)), [0, 1], {"diameter": np.array([5e-324, 0.0, 0.0])})
    fig = traj.plot(tmp_path / "sub.png")
    ax = next(a for a in fig.axes if a.get_ylabel().startswith("diameter (benign)"))
    assert ax.get_ylim()[0] > 0  # (in units of 1e-324: the floor is positive there too)


def test_d3_trajectory_has_one_panel_per_coordinate(tmp_path):
    fig = _run(d=3, steps=2).plot(tmp_path / "d3.png")
    labels = [a.get_ylabel() for a in fig.axes]
    assert labels[:3] == ["x(1)", "x(2)", "x(3)"] and "diameter (benign)" in labels


def test_metrics_subset_cli_nulls_and_plot_without_diameter(tmp_path, capsys):
    sc = _file(tmp_path, "s.toml", SCENARIO)
    code, stdout, err = _cli(["simulate", sc, "--out", tmp_path / "o", "--plot",
                              "--metrics", "spread", "--json", "-q"], capsys)
    assert code == 0, err
    out = json.loads(stdout)
    assert out["final_diameter"] is None and out["max_validity"] is None
    assert (tmp_path / "o" / "trajectory.png").exists()


def test_cli_rmdo_unknown_optimum_nulls_and_plot(tmp_path, capsys):
    sc = _file(tmp_path, "r.toml", RMDO_UNBOUNDED)
    code, stdout, err = _cli(["rmdo", sc, "--out", tmp_path / "o", "--plot", "--json", "-q"],
                             capsys)
    assert code == 0, err
    out = json.loads(stdout)
    assert out["final_distance_to_optimum"] is None and out["final_gap"] is None
    assert out["optimum"]["value"] is None
    text = (tmp_path / "o" / "trajectory.json").read_text(encoding="utf-8")
    _no_nonfinite_tokens(text)
    assert json.loads(text)["metrics"]["cost_rate"][0] is None  # NaN at k = 0
    assert (tmp_path / "o" / "trajectory.png").stat().st_size > 0


def test_many_agents_plot_is_bounded(tmp_path):
    G = nx.circulant_graph(2000, [1, 2, 3]).to_directed()
    x0 = np.random.default_rng(0).uniform(size=(2000, 2))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        traj = rescon.simulate(rescon.Scenario(graph=G, x0=x0, F=1, steps=5,
                                               residual="none", algorithm="mean"))
    fig = traj.plot(tmp_path / "big.png")
    w, h = fig.get_size_inches()
    assert w <= 8 and h <= 12


@pytest.mark.parametrize("points", [
    [[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0.5, 0.5, 0], [2, 2, 0]],  # flat in R^3
    [[1, 2, 3]] * 4,                                                       # one point
    [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],                          # empty
    [[0, 0], [1, 0], [0, 1]],                                              # empty, d = 2
    np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]]) * 1e300,
])
def test_kernel_plots_of_degenerate_kernels_are_written(points, tmp_path):
    K = rescon.safe_kernel(np.asarray(points, float), 1)
    path = tmp_path / "sub dir ü" / "k.pdf"
    ax = K.plot(path=path)
    assert path.stat().st_size > 0
    assert any("safe kernel" in t.get_text() for t in ax.get_legend().get_texts())


def test_kernel_plot_d1_is_a_one_line_error(tmp_path, capsys):
    K = rescon.safe_kernel([[0.0], [1.0], [2.0]], 1)
    with pytest.raises(rescon.InputError, match="d = 2 or 3"):
        K.plot(path=tmp_path / "k.png")
    pts = _file(tmp_path, "p.txt", "0\n1\n2\n")
    code, stdout, err = _cli(["kernel", pts, "--F", 1, "--plot", tmp_path / "k.png"], capsys)
    assert code == 2 and stdout == "" and err.count("\n") == 1


def test_cli_out_path_of_the_wrong_kind(tmp_path, capsys):
    sc = _file(tmp_path, "s.toml", SCENARIO)
    (tmp_path / "afile").write_text("x")
    for argv in (["simulate", sc, "--out", tmp_path / "afile"],
                 ["simulate", sc, "--out", tmp_path / "afile" / "sub"],
                 ["simulate", sc, "--plot"],
                 ["paper", "--out", tmp_path / "afile"]):
        code, stdout, err = _cli(argv + ["--json"], capsys)
        assert code == 2 and stdout == "" and err.startswith("rescon: error:")
        assert err.count("\n") == 1
    (tmp_path / "d" / "trajectory.png").mkdir(parents=True)
    code, _, err = _cli(["simulate", sc, "--out", tmp_path / "d", "--plot"], capsys)
    assert code == 2 and "is a directory" in err
    assert not (tmp_path / "d" / "trajectory.json").exists()  # refused before the run


def test_sweep_whose_cells_all_failed(tmp_path, capsys):
    grid = _file(tmp_path, "g.toml", textwrap.dedent("""\
        [base.scenario]
        steps = 3
        F = 1
        [base.graph]
        generator = "complete"
        n = 6
        [base.initial.random]
        low = 0.0
        high = 1.0
        d = 2
        seed = 0
        [axes]
        "scenario.F" = [7, 8]
        [run]
        repetitions = 1
        """))
    out = tmp_path / "sw ü"
    code, stdout, err = _cli(["sweep", grid, "--workers", 0, "--out", out, "--json", "-q"],
                             capsys)
    assert code == 0, err
    assert json.loads(stdout)["failed"] == 2
    import pandas as pd

    table = rescon.sweep(grid, workers=0, out=out)  # resumed: the same rows
    back = pd.read_parquet(out / "results.parquet")
    pd.testing.assert_frame_equal(back, table)
    assert (back["status"] == "failed").all()
    assert (out / "summary.png").stat().st_size > 0


@pytest.mark.slow
def test_cli_paper_json_is_the_summary_file_without_nonfinite_values(tmp_path, capsys):
    out = tmp_path / "paper ü"
    code, stdout, err = _cli(["paper", "--out", out, "--json", "-q"], capsys)
    assert code == 0, err
    assert stdout.count("\n") == 1
    for f in out.glob("*.json"):
        _no_nonfinite_tokens(f.read_text(encoding="utf-8"))
    assert json.loads(stdout) == json.loads((out / "summary.json").read_text(encoding="utf-8"))
    assert all((out / name).stat().st_size > 0 for name in json.loads(stdout).get("figures", []))


def test_without_matplotlib(tmp_path):
    sc = _file(tmp_path, "s.toml", SCENARIO)
    prog = textwrap.dedent(f"""\
        import sys
        sys.modules["matplotlib"] = None
        from rescon.cli import main
        a = main(["simulate", {str(sc)!r}, "--out", {str(tmp_path / "a")!r}, "--json", "-q"])
        b = main(["simulate", {str(sc)!r}, "--out", {str(tmp_path / "b")!r}, "--plot", "-q"])
        import rescon
        tr = rescon.simulate(rescon.Scenario.from_toml({str(sc)!r}))
        try:
            tr.plot()
        except rescon.errors.MissingDependency as exc:
            print("MD", exc, file=sys.stderr)
        sys.exit(10 * a + b)
        """)
    r = subprocess.run([PY, "-c", prog], capture_output=True, text=True, timeout=120,
                       env={**os.environ, "MPLBACKEND": "Agg"})
    assert r.returncode == 2, r.stderr  # a = 0 (no --plot), b = 2
    assert json.loads(r.stdout)["out"] == str(tmp_path / "a")
    assert (tmp_path / "a" / "trajectory.json").exists()
    assert "Traceback" not in r.stderr and "install rescon[plot]" in r.stderr
    assert "MD matplotlib is not installed" in r.stderr


# --------------------------------------------------------------------------- bugs


# Fixed (was a bug: Trajectory.to_json() keeps numpy integer node labels, so json.dumps raises
#   TypeError (to_json promises a JSON-ready dict))
def test_to_json_of_numpy_integer_labels_is_json_ready():
    traj = _run([np.int64(i) for i in range(6)])
    back = json.loads(json.dumps(traj.to_json()))
    assert back["nodes"] == list(range(6))


# Fixed (was a bug: SafeKernel.plot of points at ±1e308 raises matplotlib's ValueError (axis
#   limits inf: the data span overflows))
@pytest.mark.parametrize("d", [2, 3])
def test_kernel_plot_at_the_float_limit(d, tmp_path):
    corners = np.array(np.meshgrid(*[[-1.0, 1.0]] * d)).reshape(d, -1).T
    X = np.vstack([corners, np.zeros((1, d))]) * 1e308
    K = rescon.safe_kernel(X, 1)
    K.plot(path=tmp_path / "k.png")
    assert (tmp_path / "k.png").stat().st_size > 0


# Fixed (was a bug: rescon kernel --plot of points at ±1.7e308 ends in a matplotlib traceback
#   (exit 1), after the certificate was written)
def test_cli_kernel_plot_at_the_float_limit_is_not_a_traceback(tmp_path, capsys):
    pts = _file(tmp_path, "p.txt", "-1.7e308 -1.7e308\n1.7e308 -1.7e308\n1.7e308 1.7e308\n"
                                   "-1.7e308 1.7e308\n0 0\n1e308 0\n")
    try:
        code, stdout, err = _cli(["kernel", pts, "--F", 1, "--json", "--plot",
                                  tmp_path / "k.png"], capsys)
    except ValueError:
        pytest.fail("traceback")
    assert code == 0 or (code == 2 and err.count("\n") == 1)


# Fixed (was a bug: SafeKernel.plot of points 1e-300 apart draws every point at one spot on axes
#   ±0.05 (matplotlib's singular-limit expansion))
def test_kernel_plot_of_tiny_coordinates_keeps_them_apart(tmp_path):
    X = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5]]) * 1e-300
    ax = rescon.safe_kernel(X, 1).plot(path=tmp_path / "k.png")
    lo, hi = _data_lim(ax.get_xlim(), ax.get_xlabel())
    assert hi - lo < 1e-290  # the points span 1e-300: they must not collapse onto one pixel


# Fixed (was a bug: Trajectory.plot of states at 1e-300 draws flat curves at 0 on a ±0.055 axis
#   (matplotlib's singular-limit expansion))
def test_trajectory_plot_of_tiny_states_shows_them(tmp_path):
    traj = _run(scale=1e-300, steps=5, residual="none")
    fig = traj.plot(tmp_path / "t.png")
    lo, hi = _data_lim(fig.axes[0].get_ylim(), fig.axes[0].get_ylabel())
    assert hi - lo < 1e-290 and hi > traj.states[:, :, 0].max()


# Fixed (was a bug: Trajectory.plot of a run with T = 1e-300 draws every step at t = 0 on a
#   ±0.055 time axis (singular-limit expansion))
def test_trajectory_plot_of_a_tiny_sampling_period_spreads_the_steps(tmp_path):
    traj = _run(steps=5, T=1e-300, residual="none")
    fig = traj.plot(tmp_path / "t.png")
    lo, hi = _data_lim(fig.axes[-1].get_xlim(), fig.axes[-1].get_xlabel())
    assert hi - lo < 1e-290 and hi >= traj.times[-1]


# Fixed (was a bug: an RMDO run of steps = 0 has an empty cost panel: F(benign mean) is a one-
#   point line without a marker (the diameter panel gets a dot, the cost panel does not))
def test_rmdo_single_step_cost_panel_is_visible(tmp_path):
    G = nx.complete_graph(6).to_directed()
    sc = rescon.Scenario(graph=G, x0=[[float(i), 0.0] for i in range(6)], F=1, steps=0,
                         residual="none")
    costs = {i: f"(x1 - {i})^2 + x2^2" for i in range(6)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        traj = rescon.rmdo(sc, costs)
    fig = traj.plot(tmp_path / "r.png")
    ax = next(a for a in fig.axes if a.get_ylabel() == "global cost")
    line = next(ln for ln in ax.get_lines() if ln.get_label() == "F(benign mean)")
    assert len(line.get_xdata()) > 1 or line.get_marker() not in ("None", "", " ", None)


def _legend_box(fig):
    fig.canvas.draw()
    return fig.legends[0].get_window_extent(fig.canvas.get_renderer())


# Fixed (was a bug: a 300-character node label makes the figure legend wider than the figure:
#   every legend entry is cut off)
def test_long_adversary_label_legend_fits_the_figure(tmp_path):
    labels = ["x" * 300, "b", "c", "d", "e", "f"]
    traj = _run(labels, adversaries={"x" * 300: Constant([1e3])})
    fig = traj.plot(tmp_path / "t.png")
    box = _legend_box(fig)
    assert box.x0 >= 0 and box.x1 <= fig.bbox.x1


# Fixed (was a bug: with 100 adversaries (one legend entry each) the figure legend is drawn over
#   every panel (the figure does not grow))
def test_many_adversaries_legend_does_not_cover_the_panels(tmp_path):
    K, N, A = 3, 104, 100
    states = np.zeros((K, N, 1))
    states[:, :A, 0] = 1e4 + np.arange(A)
    states[:, A:, 0] = np.arange(N - A)
    traj = _hand(states, np.arange(A, N), {"diameter": np.array([3.0, 2.0, 1.0])})
    fig = traj.plot(tmp_path / "t.png")
    box = _legend_box(fig)
    top = max(ax.get_window_extent().y1 for ax in fig.axes)
    assert box.y0 >= top - 1


# Fixed (was a bug: Trajectory.plot(path) calls matplotlib.use('Agg') and switches the caller's
#   backend (an interactive/inline session loses it))
def test_plot_to_a_file_keeps_the_callers_backend(tmp_path):
    prog = textwrap.dedent(f"""\
        import matplotlib
        matplotlib.use("svg")
        import matplotlib.pyplot as plt
        import numpy as np
        from rescon.consensus.trajectory import Trajectory
        tr = Trajectory(np.arange(3) * 0.5, np.zeros((3, 2, 1)), (0, 1), np.array([0, 1]),
                        {{"diameter": np.array([1.0, 0.5, 0.0])}}, {{"F": 1}})
        tr.plot({str(tmp_path / "t.png")!r})
        print(matplotlib.get_backend())
        """)
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    r = subprocess.run([PY, "-c", prog], capture_output=True, text=True, timeout=120, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().lower() == "svg"


def test_sweep_summary_keeps_the_callers_backend(tmp_path):
    """rescon.sweep's summary.png (and rescon.paper's figures) switched the caller's
    backend to Agg too (pyplot(path)); now drawn on their own canvas."""
    grid = str(Path(__file__).resolve().parents[1] / "examples" / "sweeps" / "small.toml")
    prog = textwrap.dedent(f"""\
        import matplotlib
        matplotlib.use("svg")
        import rescon
        rescon.sweep({grid!r}, workers=0, out={str(tmp_path / "sw")!r}, progress=False)
        print(matplotlib.get_backend())
        """)
    env = {k: v for k, v in os.environ.items() if k != "MPLBACKEND"}
    r = subprocess.run([PY, "-c", prog], capture_output=True, text=True, timeout=300, env=env)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().lower() == "svg"
    assert (tmp_path / "sw" / "summary.png").stat().st_size > 0


# Fixed (was a bug: rescon simulate --out DIR checks only DIR/trajectory.png before the run: a
#   directory at DIR/trajectory.csv is refused after the run, leaving trajectory.json written
#   and exit 2)
def test_cli_directory_at_trajectory_csv_refused_before_anything_is_written(tmp_path, capsys):
    sc = _file(tmp_path, "s.toml", SCENARIO)
    (tmp_path / "o" / "trajectory.csv").mkdir(parents=True)
    code, stdout, err = _cli(["simulate", sc, "--out", tmp_path / "o", "--json"], capsys)
    assert code == 2 and err.splitlines()[-1].startswith("rescon: error:")
    assert not (tmp_path / "o" / "trajectory.json").exists()


# Fixed (was a bug: Trajectory.plot raises matplotlib's ValueError (axis limits inf) when benign
#   states span ±1.7e308: _padded's 0.05*(hi - lo) overflows)
def test_trajectory_plot_of_benign_states_at_the_float_limit(tmp_path):
    states = np.zeros((3, 4, 1))
    states[:, 0, 0] = [-1.7e308, -1e308, -5e307]
    states[:, 1, 0] = [1.7e308, 1e308, 5e307]
    states[:, 3, 0] = 1.79e308
    _hand(states, [0, 1, 2]).plot(tmp_path / "t.png")
    assert (tmp_path / "t.png").stat().st_size > 0
