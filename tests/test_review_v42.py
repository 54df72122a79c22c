"""Hostile review V42 of the engine's exact planar fallback (``geometry._planar_exact``).

``nearest_to_mean(Y, F)`` must give the general exact path's point
(``exact_point(safe_kernel(Y, F), method="project")``; None ↔ EmptyKernel) on every
planar set, and the engine's runs must be bit for bit those with the planar
construction switched off (``engine.PLANAR_EXACT_MAX = 0``), errors included.

Failures found (``xfail(strict=True)``, minimal cases):

* collinear multisets with 2F ≥ n whose (F + 1)-th and (n − F)-th points coincide:
  Ψ is that one point, ``nearest_to_mean`` says empty (``_collinear_kernel`` compares
  the ranks, not the points);
* sets with a facet or the affine hull of Ψ farther than 1.8e308 from the origin: the
  general path raises InputError, the planar one returns a point, so runs (and
  ``rescon simulate``) that stopped with a one-line error (exit 2) now finish;
* 32-point sets whose integers are ~2000 bits (values near 1e300 beside a subnormal):
  the O(m³) orientation tests on Python ints make the planar path 10–20× slower than
  the general path it replaces.

The guards that passed follow: the hard families of the brief against the general
path, and whole runs (the paper's example, complete graphs with adversaries, every
algorithm and kernel point reaching the path, `rescon rmdo` on the paper example)
bit-identical with the planar path off.
"""

from __future__ import annotations

import json
import warnings
from fractions import Fraction
from pathlib import Path
from unittest import mock

import networkx as nx
import numpy as np
import pytest

from rescon import cli
from rescon.consensus import engine
from rescon.consensus.adversaries import Bait, Constant, NonFinite, TwoFaced
from rescon.consensus.scenario import Scenario
from rescon.errors import EmptyKernel, InputError
from rescon.geometry._planar_exact import nearest_to_mean
from rescon.geometry.kernel import safe_kernel
from rescon.geometry.points import exact_point

BIG = 1.7976931348623157e308  # the largest float
RMDO_TOML = Path(__file__).parent.parent / "examples" / "scenarios" / "paper_rmdo.toml"


def general(Y: np.ndarray, F: int):
    """The general exact path's point (None: Ψ empty; ("InputError", msg) if raised)."""
    try:
        return tuple(exact_point(safe_kernel(Y, F), method="project"))
    except EmptyKernel:
        return None
    except InputError as exc:
        return ("InputError", str(exc))


def planar(Y: np.ndarray, F: int):
    got = nearest_to_mean(np.asarray(Y, dtype=float), F)
    return None if got is None else tuple(got)


def outcome(sc: Scenario):
    """('ok', states) or ('error', type, message) of a run."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return ("ok", np.asarray(engine.simulate(sc).states))
        except Exception as exc:  # noqa: BLE001 - the outcome is what is compared
            return ("error", type(exc).__name__, str(exc))


def same_run(sc: Scenario) -> tuple[bool, tuple, tuple, int]:
    """The run with and without the planar path, bit for bit (NaN rows of silent
    adversaries equal, the sign of zero compared), and how many sets it computed."""
    calls: list[int] = []
    real = engine.nearest_to_mean
    with mock.patch.object(engine, "nearest_to_mean",
                           lambda X, F: calls.append(1) or real(X, F)):
        on = outcome(sc)
    with mock.patch.object(engine, "PLANAR_EXACT_MAX", 0):
        off = outcome(sc)
    if on[0] != off[0]:
        return False, on[:2], off, len(calls)
    if on[0] == "ok":
        a, b = on[1], off[1]
        same = (np.array_equal(a, b, equal_nan=True)
                and np.array_equal(np.signbit(a), np.signbit(b)))
        return same, on[:1], off[:1], len(calls)
    return on == off, on, off, len(calls)


# --------------------------------------------------------------------------- #
# failures
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("Y, want", [
    ([[0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [2.0, 0.0]], (1, 0)),  # on a line
    ([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [1.0, 1.0]], (0, 0)),  # two distinct points
])
def test_collinear_tie_beyond_half_is_one_point(Y, want):
    """n = 4, F = 2: every S of n − F = 2 points has the repeated point in conv S."""
    assert general(np.array(Y), 2) == tuple(Fraction(v) for v in want)
    assert planar(Y, 2) == general(np.array(Y), 2)


@pytest.mark.xfail(strict=True, reason="a facet of Ψ farther than 1.8e308 from the "
                   "origin: the general path raises InputError (no float row), the "
                   "planar path returns the (representable) point")
def test_far_facet_set_same_outcome_as_the_general_path():
    Y = np.array([[BIG, BIG / 2], [BIG / 2, BIG], [0.0, 0.0]])
    assert planar(Y, 0) == general(Y, 0)


def far_facet_scenario(kernel_point: str) -> Scenario:
    """F = 0 (no filtering) with far adversaries, algorithm "kernel": "project-exact",
    K3 with adversaries at (BIG, BIG/2) and (BIG/2, BIG) (agent 2's set is the two,
    their affine hull 1.9e308 from the origin); "project", K5 with one adversary at
    (BIG, BIG) (the hull of the received values gets a facet beyond 1.8e308)."""
    if kernel_point == "project-exact":
        adv = {0: Constant((BIG, BIG / 2)), 1: Constant((BIG / 2, BIG))}
        n, steps = 3, 1
    else:
        adv, n, steps = {0: Constant((BIG, BIG))}, 5, 5
    return Scenario(graph=nx.complete_graph(n), x0=np.zeros((n, 2)), F=0, adversaries=adv,
                    steps=steps, algorithm="kernel", kernel_point=kernel_point,
                    check_robustness=False)


@pytest.mark.xfail(strict=True, reason="the run stopped with InputError (a facet or the "
                   "affine hull of Ψ farther than 1.8e308) before the planar path; it "
                   "now finishes")
@pytest.mark.parametrize("kernel_point", ["project-exact", "project"])
def test_far_facet_run_same_outcome_with_the_planar_path_off(kernel_point):
    same, on, off, calls = same_run(far_facet_scenario(kernel_point))
    assert calls and same, (on, off)


@pytest.mark.xfail(strict=True, reason="rescon simulate on a far-facet scenario exited "
                   "2 with a one-line error before the planar path; it now exits 0")
def test_far_facet_cli_exit_status_unchanged(tmp_path, capsys):
    path = tmp_path / "far.toml"
    path.write_text(
        "[scenario]\nF = 0\nsteps = 1\nalgorithm = \"kernel\"\n"
        "kernel_point = \"project-exact\"\ncheck_robustness = false\n"
        "[graph]\nedges = [[0, 1], [0, 2], [1, 2]]\nundirected = true\n"
        "[initial]\n0 = [0.0, 0.0]\n1 = [0.0, 0.0]\n2 = [0.0, 0.0]\n"
        f"[adversaries.0]\nkind = \"constant\"\nvalue = [{BIG!r}, {BIG / 2!r}]\n"
        f"[adversaries.1]\nkind = \"constant\"\nvalue = [{BIG / 2!r}, {BIG!r}]\n")
    argv = ["simulate", "--json", "--quiet", str(path)]
    on = cli.main(argv)
    capsys.readouterr()
    with mock.patch.object(engine, "PLANAR_EXACT_MAX", 0):
        off = cli.main(argv)
    _, err = capsys.readouterr()
    assert off == 2 and len(err.strip().splitlines()) == 1  # the error before
    assert on == off


def circle_and_a_subnormal() -> np.ndarray:
    """31 points on a circle of radius 1e300 and one at 5e-324: ~2070-bit integers."""
    t = np.sort(np.random.default_rng(2).uniform(0, 2 * np.pi, 31))
    return np.vstack([np.c_[np.cos(t), np.sin(t)] * 1e300, [[5e-324, 0.0]]])


def test_huge_integer_sets_go_to_the_general_path():
    """Was a strict xfail: 15 872 orientation tests on ~2 070-bit Python ints (no float
    filter) took ~150–200 ms, the general path ~7–16 ms. The engine now sends sets of
    more than PLANAR_EXACT_WIDE points whose coordinates span more than
    PLANAR_EXACT_BITS binary orders of magnitude to the general path (the same exact
    point either way); smaller or narrower sets keep the planar construction."""
    Y, F = circle_and_a_subnormal(), 5
    assert engine._planar_exact_point(Y, F) is None
    assert engine._kernel_points([Y], F, "project-exact", {}).tolist() == [
        [float(v) for v in general(Y, F)]]
    few = np.vstack([Y[:7], Y[-1:]])  # 8 points: still the planar construction
    assert engine._planar_exact_point(few, 1) == list(general(few, 1))
    narrow = np.ascontiguousarray(Y[:-1])  # 31 points at one magnitude
    assert engine._planar_exact_point(narrow, 5) == list(general(narrow, 5))


# --------------------------------------------------------------------------- #
# guards that passed: the function
# --------------------------------------------------------------------------- #


def hard_family(rng: np.random.Generator, kind: str, m: int) -> np.ndarray:
    """A planar set of m points of the brief's hard kinds; |coordinates| ≤ 1e308 (no
    line through two points is 1.8e308 from the origin: the far-facet failure above)."""
    if kind == "mixed":  # subnormal to 1e308 in one set
        mags = 10.0 ** rng.choice([-323, -310, -300, 0, 300, 307], size=(m, 1))
        return rng.normal(size=(m, 2)) * mags / 2
    if kind == "zeros":  # -0.0, 0.0, ±5e-324
        return rng.choice([-0.0, 0.0, 5e-324, -5e-324, 1e-323, 1.0], size=(m, 2))
    if kind == "collinear":  # with duplicates, any direction
        t = rng.integers(-3, 4, size=m).astype(float)
        d = rng.integers(-3, 4, size=2).astype(float)
        d[0] += d.any() == 0
        return np.outer(t, d) + rng.integers(-3, 4, size=2)
    if kind == "nearly":  # collinear but one point an ulp off
        X = np.outer(rng.normal(size=m), [1.0, 3.0])
        k = rng.integers(0, m)
        X[k, 1] = np.nextafter(X[k, 1], np.inf)
        return X
    if kind == "lattice":  # ulps wide beside far values
        c = rng.normal(size=2) * 10.0 ** rng.integers(-300, 300)
        X = c + rng.integers(-2, 3, size=(m, 2)) * np.spacing(np.abs(c).max())
        k = int(rng.integers(0, m // 3 + 1))
        X[:k] = rng.choice([1e308, -1e308, 1e-300, 5e-324], size=(k, 2))
        return X
    if kind == "overflow":  # orientation differences overflow floats, not ints
        return rng.choice([1e308, -1e308, 5e307, -5e307, 0.0], size=(m, 2))
    if kind == "multiplicity":  # a few points, many copies
        base = rng.normal(size=(int(rng.integers(1, 4)), 2))
        return base[rng.integers(0, len(base), size=m)]
    if kind == "columns":  # one coordinate 1e-300, the other 1e300
        return rng.normal(size=(m, 2)) * np.array([1e-300, 1e300])
    X = np.zeros((m, 2))  # "axis": on an axis, with far and subnormal values
    X[:, int(rng.integers(0, 2))] = rng.choice([-1e308, 5e-324, 0.0, 1.0, 1e308], size=m)
    return X


KINDS = ["mixed", "zeros", "collinear", "nearly", "lattice", "overflow", "multiplicity",
         "columns", "axis"]


@pytest.mark.parametrize("kind", KINDS)
def test_hard_sets_match_the_general_path(kind):
    """n = 1..32 (32 = PLANAR_EXACT_MAX included), F = 0 up to 2F < n (at and beyond
    Tverberg's bound n ≤ 3F: possibly empty): identical rationals, or both empty."""
    rng = np.random.default_rng([42, KINDS.index(kind)])
    empty = 0
    for i in range(40):
        m = 32 if i < 2 else int(rng.choice([1, 2, 3, 4, 5, 6, 7, 8, 10, 13, 16]))
        F = int(rng.integers(0, (m + 1) // 2))  # 2F < n
        Y = np.ascontiguousarray(hard_family(rng, kind, m))
        want = general(Y, F)
        assert planar(Y, F) == want, (Y.tolist(), F, want)
        empty += want is None
    assert empty < 40


@pytest.mark.parametrize("Y, F", [
    ([[3.0, -4.0]], 0),  # n = 1
    ([[-0.0, 0.0], [0.0, -0.0]], 0),  # -0.0 is 0
    ([[-0.0, 1.0], [0.0, 1.0], [1.0, -0.0]], 1),  # n = 3F, -0.0 duplicates
    ([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]], 1),  # n = 3F + 1, a point
    ([[5e-324, 0.0], [0.0, 5e-324], [-5e-324, 0.0], [0.0, -5e-324], [0.0, 0.0]], 1),
    ([[1e308, 1e308], [-1e308, 1e308], [1e308, -1e308], [-1e308, -1e308],
      [5e-324, 5e-324]], 1),
    ([[1.0, 2.0]] * 7, 2),  # one point, F = 2
])
def test_small_edge_cases(Y, F):
    Y = np.array(Y)
    assert planar(Y, F) == general(Y, F)


def test_kernel_points_round_the_same_rationals():
    """engine._kernel_points on declined-looking sets: the same floats (bits and sign
    of zero) with and without the planar path, "project" and "project-exact"."""
    rng = np.random.default_rng(9)
    sets = [np.ascontiguousarray(hard_family(rng, kind, 7)) for kind in KINDS for _ in range(3)]
    for method in ("project", "project-exact"):
        on = engine._kernel_points(sets, 2, method, {})
        with mock.patch.object(engine, "PLANAR_EXACT_MAX", 0):
            off = engine._kernel_points(sets, 2, method, {})
        assert np.array_equal(on, off) and np.array_equal(np.signbit(on), np.signbit(off))


# --------------------------------------------------------------------------- #
# guards that passed: whole runs
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("kw", [
    {"algorithm": "alg1", "centre": "box", "steps": 60},
    {"algorithm": "alg1", "centre": "centroid", "steps": 60},
    {"algorithm": "alg1", "policy": "drop", "steps": 100},
    {"algorithm": "kernel", "steps": 100},
    {"algorithm": "alg1", "kernel_point": "project-exact", "steps": 30},
    {"algorithm": "kernel", "kernel_point": "project-exact", "policy": "drop", "steps": 30},
])
def test_paper_example_variants_bit_identical(kw):
    same, on, off, calls = same_run(Scenario.paper_example(**kw))
    assert same, (on, off)
    assert calls > 0  # the planar path was taken


@pytest.mark.slow
@pytest.mark.parametrize("kw", [
    {"policy": "zero", "steps": 200},
    {"kernel_point": "project-exact", "policy": "zero", "steps": 60},
])
def test_paper_example_long_variants_bit_identical(kw):
    same, on, off, calls = same_run(Scenario.paper_example(**kw))
    assert same and calls > 0, (on, off)


def adversaries(kind: str, F: int, rng: np.random.Generator) -> dict:
    if kind == "constant":
        return {i: Constant(tuple(rng.normal(size=2) * 100)) for i in range(F)}
    if kind == "bait":
        return {i: Bait(strength=1.0) for i in range(F)}
    if kind == "far":  # ±1.8e308
        return {i: Constant(((-1) ** i * BIG, -BIG)) for i in range(F)}
    if kind == "twofaced":  # 1e300 and 1e-300 to different receivers
        return {i: TwoFaced(lambda t, r: np.array([r * 1e300, -r * 1e-300])) for i in range(F)}
    return {i: NonFinite("mixed") for i in range(F)}


@pytest.mark.parametrize("adv", ["constant", "bait", "far", "twofaced", "nonfinite"])
@pytest.mark.parametrize("algorithm", ["alg1", "kernel"])
def test_complete_graph_runs_bit_identical(adv, algorithm):
    """K8, F = 1, run to convergence in the plane ("project", 80 steps) and exactly
    ("project-exact", 15 steps); initial states with -0.0 and a subnormal."""
    rng = np.random.default_rng(5)
    x0 = rng.normal(size=(8, 2)) * 10
    x0[3], x0[4] = (-0.0, 5e-324), (0.0, -0.0)
    for kp, steps in (("project", 80), ("project-exact", 15)):
        sc = Scenario(graph=nx.complete_graph(8), x0=x0, F=1, steps=steps,
                      adversaries=adversaries(adv, 1, rng), algorithm=algorithm,
                      kernel_point=kp, check_robustness=False, seed=3)
        same, on, off, _ = same_run(sc)
        assert same, (kp, on, off)


@pytest.mark.slow
@pytest.mark.parametrize("adv", ["far", "twofaced", "bait"])
def test_sets_of_exactly_32_points_bit_identical(adv):
    """K33, F = 3, algorithm "kernel": every set is the 32 received values (with the
    far or two-faced adversaries' values they span > PLANAR_EXACT_BITS binary orders
    of magnitude: the general path's, by the engine's guard since V42)."""
    rng = np.random.default_rng(6)
    sc = Scenario(graph=nx.complete_graph(33), x0=rng.normal(size=(33, 2)), F=3, steps=4,
                  adversaries=adversaries(adv, 3, rng), algorithm="kernel",
                  kernel_point="project-exact", check_robustness=False)
    same, on, off, calls = same_run(sc)
    assert same and (calls == 0 if adv in ("far", "twofaced") else calls > 0), (on, off, calls)


def test_error_runs_unchanged():
    """A run the engine stopped before still stops, with the same message: F = 0 and an
    adversary at (BIG, BIG) drag Algorithm 1's states apart ("diverged"), the planar
    path computing its sets ("project-exact")."""
    far = Scenario(graph=nx.complete_graph(5), x0=np.zeros((5, 2)), F=0,
                   adversaries={0: Constant((BIG, BIG))}, steps=5, algorithm="alg1",
                   kernel_point="project-exact", check_robustness=False)
    same, on, off, calls = same_run(far)
    assert same and calls > 0, (on, off)
    assert on[0] == "error" and "diverged" in on[2] and "\n" not in on[2]


def test_cli_far_values_within_F_unchanged(tmp_path, capsys):
    """rescon simulate --json with adversaries at ±1.8e308 (≤ F of them): the same exit
    status and JSON (but seconds) with the planar path on and off."""
    path = tmp_path / "far.toml"
    rows = "\n".join(f"{i} = [{float(i % 3)}, {float(i // 3)}]" for i in range(2, 8))
    path.write_text(
        "[scenario]\nF = 2\nsteps = 20\nkernel_point = \"project-exact\"\n"
        "check_robustness = false\n[graph]\nedges = "
        + json.dumps([[i, j] for i in range(8) for j in range(i + 1, 8)])
        + "\nundirected = true\n[initial]\n0 = [0.0, 0.0]\n1 = [0.0, 0.0]\n" + rows
        + f"\n[adversaries.0]\nkind = \"constant\"\nvalue = [{BIG!r}, {-BIG!r}]\n"
        f"[adversaries.1]\nkind = \"two_faced\"\ncycle = [[{-BIG!r}, 5e-324], [-0.0, {BIG!r}]]\n")
    argv = ["simulate", "--json", "--quiet", str(path)]
    results = []
    for off in (False, True):
        with mock.patch.object(engine, "PLANAR_EXACT_MAX", 0 if off else 32):
            code = cli.main(argv)
        out, err = capsys.readouterr()
        data = json.loads(out)
        data.pop("seconds")
        results.append((code, data))
    assert results[0] == results[1] and results[0][0] == 0


def test_rmdo_paper_example_bit_identical(tmp_path, capsys):
    """rescon rmdo on the paper's RMDO scenario (Algorithm 2 filters through the same
    kernel points): the same trajectory file with the planar path on and off."""
    files = []
    for off in (False, True):
        out = tmp_path / f"run{int(off)}"
        with mock.patch.object(engine, "PLANAR_EXACT_MAX", 0 if off else 32):
            code = cli.main(["rmdo", "--quiet", "--out", str(out), str(RMDO_TOML)])
        capsys.readouterr()
        assert code == 0
        files.append((out / "trajectory.csv").read_bytes())
    assert files[0] == files[1]
