"""Edges of the engine's step z = αx + (1 − α)x̃ and of RMDO runs and files (V22):
subnormal and huge states, iterates beyond the scenario's bound, unhashable TOML
values, RMDO files missing a cost."""

from __future__ import annotations

import contextlib
import io
import json
import warnings
from fractions import Fraction as Fr

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon.cli import main as cli_main
from rescon.consensus.engine import _between
from rescon.consensus.scenario import STATE_LIMIT
from rescon.errors import InputError
from rescon.optim.files import read_costs

TINY = 5e-324
MAX = np.finfo(float).max


def _magnitudes(rng: np.random.Generator, n: int) -> np.ndarray:
    """n floats of both signs from every binade: subnormal, normal, near ±MAX, 0."""
    e = rng.integers(-1074, 1024, size=n)
    m = rng.uniform(0.5, 1.0, size=n)
    v = np.ldexp(m, e)
    v[np.isinf(v)] = MAX
    v[rng.random(n) < 0.05] = 0.0
    v[rng.random(n) < 0.05] = TINY
    return np.where(rng.random(n) < 0.5, -v, v)


def _alphas(rng: np.random.Generator, n: int) -> np.ndarray:
    a = rng.uniform(0.0, 1.0, size=(n, 1))
    pick = rng.random((n, 1))
    a[pick < 0.2] = 0.5
    a[(pick >= 0.2) & (pick < 0.3)] = 2.0**-52 + 2.0**-60  # 1 − α rounds to 1 − 2^-53
    a[(pick >= 0.3) & (pick < 0.4)] = 1 - 2.0**-53
    return a


@pytest.mark.parametrize("seed", range(4))
def test_between_stays_in_the_segment_at_every_magnitude(seed):
    rng = np.random.default_rng(seed)
    n, d = 400, 3
    x = _magnitudes(rng, n * d).reshape(n, d)
    aux = _magnitudes(rng, n * d).reshape(n, d)
    near = rng.random((n, d)) < 0.3  # x̃ close to x (differences of few ulps)
    aux[near] = x[near] + np.spacing(x[near]) * rng.integers(-3, 4, size=near.sum())
    alpha = _alphas(rng, n)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no overflow, even discarded
        z = _between(x, aux, alpha)
    assert np.isfinite(z).all()
    assert ((np.minimum(x, aux) <= z) & (z <= np.maximum(x, aux))).all()
    u = Fr(1, 2**53)
    for r in range(n):
        a = Fr(float(alpha[r, 0]))
        for p in range(d):
            xv, yv = Fr(float(x[r, p])), Fr(float(aux[r, p]))
            exact = a * xv + (1 - a) * yv
            err = abs(Fr(float(z[r, p])) - exact)
            # a few roundings relative to |x̃ − x|, one of z itself (or the subnormal step)
            bound = 4 * u * abs(yv - xv) + Fr(abs(float(np.spacing(float(exact)))))
            assert err <= bound, (x[r, p], aux[r, p], alpha[r, 0], z[r, p])


@pytest.mark.parametrize("v", [TINY, -TINY, 3 * TINY, 2.0**-1022, 1.0, -0.0, 1e150, MAX, -MAX])
@pytest.mark.parametrize("a", [0.5, 0.3, 0.7, 2.0**-52 + 2.0**-60])
def test_between_is_the_state_itself_when_the_auxiliary_point_is(v, a):
    x = np.full((2, 2), v)
    assert np.array_equal(_between(x, x.copy(), np.full((2, 1), a)), x)


def test_between_opposite_ends_of_the_float_range():
    """x̃ − x overflows: the result is still between them and finite, without warning."""
    x = np.array([[-MAX, -1e308, MAX]])
    aux = np.array([[MAX, 1e308, -MAX]])
    for a in (0.5, 0.25, 0.75):
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)
            z = _between(x, aux, np.array([[a]]))
        exact = [Fr(a) * Fr(xv) + (1 - Fr(a)) * Fr(yv) for xv, yv in zip(x[0], aux[0])]
        assert np.isfinite(z).all()
        assert all(abs(Fr(float(zv)) - e) <= Fr(2.0**-50) * abs(e) + Fr(2.0**970)
                   for zv, e in zip(z[0], exact))


def test_consensus_at_subnormal_states_stays_put():
    """Algorithm 1 (no residual) with every agent at (5e-324, −5e-324): nothing moves
    (αx + (1 − α)x̃ rounded 0.5·5e-324 to 0, so the states left the initial hull)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sc = rescon.Scenario(graph=nx.complete_graph(6).to_directed(), x0=[[TINY, -TINY]] * 6,
                             F=1, steps=5, residual="none", check_robustness=False)
    tr = rescon.simulate(sc)
    assert np.array_equal(tr.states, np.broadcast_to([TINY, -TINY], tr.states.shape))
    assert tr.metrics["validity"].max() == 0.0


# --------------------------------------------------------------------------- #
# RMDO: iterates beyond the scenario's bound on states
# --------------------------------------------------------------------------- #


def _scenario(x0, steps=3):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rescon.Scenario(graph=nx.complete_graph(len(x0)).to_directed(), x0=x0, F=0,
                               steps=steps, check_robustness=False)


def _rmdo(sc, costs, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return rescon.rmdo(sc, costs, **kw)


def test_iterates_beyond_the_state_bound_are_refused_as_diverged():
    sc = _scenario([[-1.0], [0.25], [1.0]])
    with pytest.raises(InputError) as info:
        _rmdo(sc, {i: "abs(x1)" for i in range(3)}, step_size=1e200)
    msg = str(info.value)
    assert f"{STATE_LIMIT:g}" in msg and "diverged" in msg and "step_size" in msg
    assert "agent" in msg and "\n" not in msg


def test_a_step_past_the_bound_near_it_is_refused_without_a_divergence_claim():
    """States at 0.9e150 pushed to ~1.9e150: beyond the bound, but not 2^20 times farther
    than where they started (no "diverged" hint), still refused."""
    sc = _scenario([[0.9e150], [0.9e150], [0.9e150]], steps=2)
    with pytest.raises(InputError, match=r"leaves the states' bound \|x\| <= 1e\+150") as info:
        _rmdo(sc, {i: "-x1" for i in range(3)}, step_size=1e150)
    assert "diverged" not in str(info.value)


def test_iterates_at_the_bound_are_accepted():
    sc = _scenario([[-STATE_LIMIT], [STATE_LIMIT], [0.0]], steps=4)
    tr = _rmdo(sc, {i: "abs(x1)" for i in range(3)}, step_size=1.0)
    assert np.abs(tr.states).max() <= STATE_LIMIT


# --------------------------------------------------------------------------- #
# files and the command line
# --------------------------------------------------------------------------- #


BASE = """\
[scenario]
F = 0
steps = 5
check_robustness = false
[graph]
edges = [[0, 1], [1, 0], [1, 2], [2, 1], [0, 2], [2, 0], [3, 0], [3, 1], [3, 2], [0, 3]]
[initial]
0 = [0.0, 1.0]
1 = [1.0, 0.0]
2 = [2.0, 2.0]
3 = [5.0, 5.0]
"""


def _cli(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = cli_main(argv)
    return rc, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("kind", ['["paper"]', '{name = "paper"}', "3", "true", '"Paper"'])
def test_step_size_kind_of_any_toml_type_is_a_one_line_error(tmp_path, kind):
    p = tmp_path / "bad.toml"
    p.write_text(BASE + '[costs]\n0 = "x1^2"\n1 = "x1^2"\n2 = "x1^2"\n3 = "x1^2"\n'
                 f"[step_size]\nkind = {kind}\n")
    for argv in (["rmdo", str(p), "--json", "-q"], ["redundancy", str(p), "--r", "1", "--json"]):
        rc, out, err = _cli(argv)
        assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1, (argv, err)
        assert "kind must be one of" in err


def test_redundancy_refuses_an_rmdo_file_missing_a_benign_cost(tmp_path):
    p = tmp_path / "missing.toml"
    p.write_text(BASE + '[costs]\n0 = "x1^2"\n2 = "x1^2"\n3 = "x1^2"\n')
    with pytest.raises(InputError, match=r"missing\.toml \[costs\]: no cost for benign agent"
                                         r"\(s\) \[1\]"):
        read_costs(p)
    rc, out, err = _cli(["redundancy", str(p), "--r", "1", "--json", "-q"])
    assert rc == 2 and out == "" and len(err.strip().splitlines()) == 1 and "[1]" in err


def test_redundancy_of_an_rmdo_file_needs_no_cost_for_an_adversary(tmp_path):
    p = tmp_path / "adv.toml"
    p.write_text(BASE + '[adversaries.3]\nkind = "constant"\nvalue = [9.0, 9.0]\n'
                 '[costs]\n2 = "(x1 - 1)^2"\n0 = "(x1 - 1)^2 + x2^2"\n1 = "abs(x1 - 1)"\n')
    costs, d = read_costs(p)
    assert list(costs) == [2, 0, 1] and d == 2  # the file's order, benign agents only
    rc, out, err = _cli(["redundancy", str(p), "--r", "1", "--json", "-q"])
    assert rc == 0 and json.loads(out)["N"] == 3, err
