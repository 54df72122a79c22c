"""R4: edges of r-redundancy, costs and the engines (each test failed before its fix)."""

from __future__ import annotations

import math
import shutil
import warnings
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

import rescon
from rescon.cli import main
from rescon.consensus.adversaries import Constant
from rescon.consensus.engine import simulate
from rescon.consensus.scenario import Scenario
from rescon.errors import InputError
from rescon.graphs.generators import circulant
from rescon.optim import _pq, atoms
from rescon.optim.files import read_costs, read_rmdo
from rescon.optim.redundancy import _poly_support

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "scenarios"

# --------------------------------------------------------------------------- #
# 1. argmins past the float range: exact verdicts, values shown as ±inf
# --------------------------------------------------------------------------- #


def test_argmins_at_the_float_range_get_their_exact_verdict():
    """A_{S} = {±1e308} for the 3-subsets, [−1e308, 1e308] for all four: the witness's
    values (u = x1 − x2 = 2e308, uᵀx1 = 2e616) and the gap (2e308) pass the float range
    — they were an OverflowError; now the exact verdict, those values ±inf."""
    c = ["abs(x1 - 1e308)", "abs(x1 + 1e308)", "abs(x1 - 1e308)", "abs(x1 + 1e308)"]
    rep = rescon.check_redundancy(c, r=1)
    assert (rep.holds, rep.exact, rep.gap) == (False, True, math.inf)
    assert rep.certificate["kind"] == "redundancy_violation"
    assert math.isinf(rep.witness["direction"][0])


def test_poly_support_of_a_segment_longer_than_the_float_range():
    """The certified argmin [−1e308, 1e308] of |x − 1e308| + |x + 1e308| seen from its
    end x̄ = 1e308: the slack 2e308 of the face −x ≤ 1e308 was float()-ed
    (OverflowError); the support values are exact points of the segment."""
    F = _pq.of_oracle(rescon.cost("abs(x1 - 1e308) + abs(x1 + 1e308)"), 1)
    x = [Fraction(10**308)]
    lam = [[Fraction(0), Fraction(1)], [Fraction(1), Fraction(0)]]
    assert _pq.check_optimal(F, x, lam, []) is None
    opt = _pq.describe(F, x, lam, [])
    for u, end in ((1.0, 10**308), (-1.0, -10**308)):
        h, yf, y, _ = _poly_support(opt, np.array([u]))
        assert y == [Fraction(end)] and h == 1e308 and yf[0] == float(end)


# --------------------------------------------------------------------------- #
# 3. recession directions whose entries differ by 1e8
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("S", ["1", "100000000", "0.00000001"])
def test_recession_verdict_does_not_depend_on_a_coordinate_scale(S):
    """F = (x1 − S x2)² + |x1 − S x2 + c| − x1 is unbounded below along (S, 1): at
    S = 1e8 the direction (1, 1e-8) was rounded to 1/10^6 (to (1, 0), not a recession
    direction), so the verdict was numerical; now exact at every S."""
    f = f"(x1 - {S}*x2)^2 + abs(x1 - {S}*x2) - x1"
    g = f"(x1 - {S}*x2)^2 + 2*abs(x1 - {S}*x2 + 1) - x1"
    rep = rescon.check_redundancy([f, g, f], r=1)
    assert (rep.holds, rep.exact) == (True, True)
    assert rep.certificate["kind"] == "redundancy_holds"
    assert len(rep.unbounded) == 3


@pytest.mark.parametrize("scale", [1e-8, 1.0, 1e8])
def test_recession_certified_at_every_data_scale(scale):
    """The same unbounded sum with every coefficient scaled by 1e-8, 1, 1e8 (and x2's
    axis by 1e8 against x1's): :func:`_pq.recession` certifies it from the float
    direction at every scale."""
    F = _pq.of_oracle(rescon.cost(f"{scale}*((x1 - 100000000*x2)^2 + abs(x1 - 100000000*x2)"
                                  f" - x1)"), 2)
    v = _pq.recession(F, np.array([1.0, 1e-8]) * (1 + 1e-12))
    assert v is not None and _pq.is_recession(F, v)


# --------------------------------------------------------------------------- #
# 4. rescon rmdo: a benign agent without a cost, the file named
# --------------------------------------------------------------------------- #


def _rmdo_without(tmp_path: Path, agent: int) -> Path:
    for name in ("rmdo_quadratic.toml", "ring_lattice_20_x0.csv"):
        shutil.copy(EXAMPLES / name, tmp_path / name)
    (tmp_path / "graphs").mkdir()
    shutil.copy(EXAMPLES.parent / "graphs" / "ring_lattice_20.edgelist", tmp_path / "graphs")
    p = tmp_path / "sub" / "no_cost.toml"
    p.parent.mkdir()
    text = (tmp_path / "rmdo_quadratic.toml").read_text()
    text = text.replace("../graphs/", "../graphs/").replace('file = "ring', 'file = "../ring')
    lines = [ln for ln in text.splitlines() if not ln.startswith(f"{agent} = ")]
    p.write_text("\n".join(lines) + "\n")
    return p


def test_rmdo_missing_cost_names_the_file(tmp_path, capsys, monkeypatch):
    p = _rmdo_without(tmp_path, 3)
    with pytest.raises(InputError, match=r"no_cost\.toml \[costs\]: no cost for benign "
                                         r"agent\(s\) \[3\]"):
        read_rmdo(p)
    with pytest.raises(InputError, match=r"no_cost\.toml \[costs\]: no cost"):
        read_costs(p)
    monkeypatch.chdir(tmp_path)
    assert main(["rmdo", "sub/no_cost.toml"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "sub/no_cost.toml [costs]: no cost for benign agent(s) [3]" in err[0]


# --------------------------------------------------------------------------- #
# 5. atoms.Merged: weights × Scaled coefficients exactly
# --------------------------------------------------------------------------- #


def test_merged_weights_times_scalings_are_exact():
    """0.1 · 0.3 rounds in floats (0.030000000000000002 ≠ the exact product of the two
    floats); the collapsed quadratic is now the exact weighted sum of the terms."""
    w, c = 0.1, 0.3
    assert Fraction(w * c) != Fraction(w) * Fraction(c)
    q = atoms.Quadratic([[2.0]], c=[0.7], q=[0.0])
    aff = atoms.Affine([1.1], 0.0)
    m = atoms.Merged([(w, atoms.Scaled(c, q)), (0.7, atoms.Scaled(0.9, aff))], 1)
    H = Fraction(w) * Fraction(c) * 2
    lin = Fraction(w) * Fraction(c) * (-2 * Fraction(0.7)) + Fraction(0.7) * Fraction(0.9) * \
        Fraction(1.1)
    assert m._quad.exact["Q"] == [[H]]
    assert m._quad.exact["c"] == [-lin / H]


# --------------------------------------------------------------------------- #
# 6. Algorithm 1's engine: the 'mean' baseline dragged past the states' bound
# --------------------------------------------------------------------------- #


def _mean_run(v: float, steps: int = 40):
    x0 = np.random.default_rng(0).uniform(-10, 10, size=(12, 2))
    sc = Scenario(graph=circulant(12, 1), x0=x0, F=1, algorithm="mean", steps=steps,
                  adversaries={0: Constant([v, v]), 6: Constant([-v, -v])},
                  residual="none", check_robustness=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(sc)


def test_mean_baseline_dragged_apart_past_the_float_range_is_refused():
    """Adversaries at ±1.8e308 drag the mean's benign states to ±1.2e308: their diameter
    and spread (2.4e308) were recorded as inf; now the run stops with a 'diverged'
    InputError at the first step whose metrics would overflow."""
    with pytest.raises(InputError, match=r"benign states at step \d+ .*too far apart for "
                                         r"floats \(diameter > 1\.8e308.*diverged"):
        _mean_run(np.finfo(float).max)


@pytest.mark.parametrize("v", [1e140, 1e300])
def test_mean_baseline_dragged_far_keeps_finite_correct_metrics(v):
    """Below that, states dragged past 1e150 (the bound on initial states) are kept and
    every metric is finite: the diameter is that of the final benign states."""
    tr = _mean_run(v)
    assert all(np.isfinite(np.asarray(m, dtype=float)).all() for m in tr.metrics.values())
    B = tr.states[-1, tr.benign]
    far = max(np.linalg.norm((B[i] - B[j]) / v) * v for i in range(len(B)) for j in range(i))
    assert np.isclose(tr.metrics["diameter"][-1], far, rtol=1e-12)
    assert np.abs(B).max() > (1e130 if v < 1e150 else 1e290)


def test_cli_simulate_mean_baseline_refused_in_one_line(tmp_path, capsys):
    p = tmp_path / "mean.toml"
    edges = [[i, (i + 1) % 12] for i in range(12)]
    p.write_text(f"""[scenario]
F = 1
steps = 60
algorithm = "mean"
residual = "none"
check_robustness = false

[graph]
edges = {edges}
undirected = true

[initial]
{chr(10).join(f"{i} = [{i}.0, {-i}.0]" for i in range(12))}

[adversaries.0]
kind = "constant"
value = [1.7e308, 1.7e308]

[adversaries.6]
kind = "constant"
value = [-1.7e308, -1.7e308]
""")
    assert main(["simulate", str(p), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "diverged" in err[0]


# --------------------------------------------------------------------------- #
# 2. non-piecewise-quadratic costs far from the origin (CVXPY in the frame)
# --------------------------------------------------------------------------- #


def _huber_costs(c0: float) -> list[str]:
    return [f"huber(x1 - {c0}, 1) + (x2 - {c0})^2", f"huber(x1 - {c0} - 2, 1) + (x2 - {c0})^2",
            f"huber(x1 - {c0}, 1) + (x2 - {c0})^2"]


@pytest.mark.parametrize("c0", [1e8, 1e20, 1e50, -1e150])
def test_huber_costs_far_away_get_the_verdict_they_get_at_the_origin(c0):
    """Huber costs (not piecewise quadratic: CVXPY's numerical path) centred at c0: at
    1e8 and 1e20 the verdict was 'holds' (the tolerance grew with |x|, the supports
    lost the gap 0.5 in rounding), at 1e50 a SolverError. Solved in the centred frame
    (the data shifted exactly), with the tolerance measured from the centre, the
    verdict, gap and tolerance are those at the origin."""
    base = rescon.check_redundancy(_huber_costs(0.0), r=1)
    rep = rescon.check_redundancy(_huber_costs(c0), r=1)
    assert (base.holds, base.exact) == (rep.holds, rep.exact) == (False, False)
    assert rep.gap == pytest.approx(base.gap, rel=1e-6) and rep.gap == pytest.approx(0.5,
                                                                                     rel=1e-3)
    assert rep.tolerance == pytest.approx(base.tolerance, rel=1e-6)


@pytest.mark.parametrize("c0", [1e8, 1e300])
def test_equal_huber_and_logsumexp_sums_hold_far_away(c0):
    """Equal argmins stay equal far away: three Huber costs with one minimiser (their
    log-sum-exp shape gives the frame its kinks), the exact decimal 10^300 included."""
    c = [f"huber(x1 - {c0}, 1) + huber(x2 - {c0}, 1)"] * 2 + [
        f"logsumexp(x1 - {c0}, {c0} - x1) + huber(x2 - {c0}, 2)"]
    rep = rescon.check_redundancy(c, r=1)
    assert (rep.holds, rep.exact) == (True, False)
    assert rep.gap <= 1e-3 and rep.tolerance <= 2e-4
