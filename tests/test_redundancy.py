"""check_redundancy: exact and numerical verdicts, witnesses, certificates (issue 11 §3, §6)."""

from __future__ import annotations

import copy
import itertools
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rescon
from rescon import InputError, check_certificate, check_redundancy
from rescon.optim import atoms, paper_costs

ROOT = Path(__file__).resolve().parents[1]


# --------------------------------------------------------------------------- #
# an independent brute force: every pair of (N − r)-subsets, CVXPY supports
# --------------------------------------------------------------------------- #

def _cvx_sum(specs, S, x):
    import cvxpy as cp

    env = {"abs": cp.abs, "x1": x[0], "x2": x[1], "square": cp.square}
    return sum(eval(specs[i].replace("^2", "**2"), env) for i in S)


def _support_profile(specs, S, d=2):
    """(unbounded?, supports in ±e_i and ±(1, 2)/√5) of argmin Σ_S, by CVXPY."""
    import cvxpy as cp

    x = cp.Variable(d)
    F = _cvx_sum(specs, S, x)
    p = cp.Problem(cp.Minimize(F))
    p.solve(solver="CLARABEL")
    if p.status.startswith("unbounded"):
        return None
    level = p.value + 1e-9 * (1 + abs(p.value))
    out = []
    for u in [np.array(v, float) for v in ([1, 0], [-1, 0], [0, 1], [0, -1], [1, 2], [-1, -2])]:
        q = cp.Problem(cp.Maximize(u @ x), [F <= level])
        q.solve(solver="CLARABEL")
        out.append(np.inf if q.status.startswith("unbounded") else q.value)
    return np.array(out)


def _same(a, b):
    if a is None or b is None:
        return a is None and b is None
    fin = np.isfinite(a) & np.isfinite(b)
    return bool((np.isfinite(a) == np.isfinite(b)).all()
                and np.allclose(a[fin], b[fin], atol=1e-3))


def brute_force(specs, r):
    subsets = list(itertools.combinations(range(len(specs)), len(specs) - r))
    prof = [_support_profile(specs, S) for S in subsets]
    return all(_same(prof[i], prof[j]) for i, j in itertools.combinations(range(len(prof)), 2))


def _random_specs(rng, kind, N):
    out = []
    c = rng.integers(-2, 3, size=2)
    for _ in range(N):
        if kind == "common":  # share the minimiser c; some costs are flat in a direction
            a, b = rng.integers(-2, 3, size=2)
            out.append(f"({a}*(x1 - {c[0]}) + {b}*(x2 - {c[1]}))^2 + (x1 - {c[0]})^2"
                       if rng.random() < 0.2 else f"({a}*(x1 - {c[0]}) + {b}*(x2 - {c[1]}))^2")
        elif kind == "shifted":
            s = rng.integers(-1, 2, size=2) * (rng.random() < 0.4)
            out.append(f"(x1 - {c[0] + s[0]})^2 + (x2 - {c[1] + s[1]})^2")
        elif kind == "mixed":  # a quadratic in x1 and a kink, through c or shifted
            a = rng.integers(-2, 3, size=2)
            s = int(rng.integers(-1, 2)) if rng.random() < 0.3 else 0
            out.append(f"{int(rng.integers(0, 3))}*(x1 - {c[0] + s})^2 + "
                       f"abs({a[0]}*x1 + {a[1]}*x2 - {int(a @ c)}) + abs(x2 - {c[1]})")
        else:  # polyhedral: |a·x − b| with kinks through c, or shifted ones
            a = rng.integers(-2, 3, size=2)
            shift = int(rng.integers(0, 2)) if rng.random() < 0.3 else 0
            out.append(f"abs({a[0]}*x1 + {a[1]}*x2 - {int(a @ c) + shift}) + abs(x1 - {c[0]})")
    return out


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["common", "shifted", "polyhedral", "mixed"])
def test_brute_force_over_all_pairs_agrees(kind):
    rng = np.random.default_rng({"common": 1, "shifted": 2, "polyhedral": 3, "mixed": 4}[kind])
    verdicts = []
    for _ in range(6):
        N = int(rng.integers(3, 5))
        r = int(rng.integers(1, N - 1))
        specs = _random_specs(rng, kind, N)
        rep = check_redundancy(specs, r, d=2)
        assert rep.exact, specs
        assert rep.holds == brute_force(specs, r), (specs, r)
        assert check_certificate(rep.certificate).valid
        verdicts.append(rep.holds)
    assert kind != "shifted" or not all(verdicts)


# --------------------------------------------------------------------------- #
# known cases
# --------------------------------------------------------------------------- #

def test_spec4_example_holds_exactly_though_minimisers_differ():
    """SPEC §4: f1 = (x−1)², f2 = (x+1)², f3 = 2|x|: every pair has argmin {0}."""
    rep = check_redundancy(["(x1 - 1)^2", "(x1 + 1)^2", "2*abs(x1)"], r=1)
    assert (rep.holds, rep.exact, rep.gap, rep.witness) == (True, True, 0.0, None)
    assert rep.certificate["kind"] == "redundancy_holds"
    assert check_certificate(rep.certificate).valid
    # the pairs' argmins are the point 0 in the certificate
    assert {tuple(s["x"]["x"]) for s in rep.certificate["subsets"]} == {("0",)}
    # ... while f1 alone is minimised at 1: redundancy is not a common minimiser
    assert not check_redundancy(["(x1 - 1)^2", "(x1 + 1)^2", "2*abs(x1)"], r=2).holds


def test_shifted_quadratics_violate_with_a_checkable_witness():
    rep = check_redundancy({"a": "(x1-1)^2 + x2^2", "b": "(x1+1)^2 + x2^2",
                            "c": "abs(x1) + abs(x2)", "d": "x1^2"}, r=1)
    assert not rep.holds and rep.exact
    w = rep.witness
    assert len(w["subsets"][0]) == 3 and set(w["subsets"][0]) <= {"a", "b", "c", "d"}
    assert w["points"][0] != w["points"][1] and w["support"][0] > w["support"][1]
    assert rep.gap > 0
    assert check_certificate(rep.certificate).valid


def test_quadratics_with_a_common_line_of_minimisers():
    same = ["(x1 + x2 - 1)^2", "2*(x1 + x2 - 1)^2", "3*(x1 + x2 - 1)^2"]
    rep = check_redundancy(same, r=1)
    assert rep.holds and rep.exact and rep.gap == 0.0
    assert check_certificate(rep.certificate).valid
    parallel = ["(x1 + x2 - 1)^2", "(x1 + x2 - 1)^2", "(x1 + x2 + 1)^2"]
    rep = check_redundancy(parallel, r=1)  # parallel lines x1 + x2 = 1, = 1/3 (distance √2/3)
    assert not rep.holds and rep.exact
    assert rep.gap == pytest.approx(np.sqrt(2) / 3)
    crossing = ["(x1 + x2 - 1)^2", "(x1 + x2 - 1)^2", "x1^2"]
    assert check_redundancy(crossing, r=1).gap == np.inf  # a line and a point


def test_unbounded_sums():
    rep = check_redundancy(["x1", "x1 + abs(x2)", "x1"], r=1)
    assert rep.holds and rep.exact  # every pair is unbounded below: the same (empty) argmin
    assert len(rep.unbounded) == 3 and rep.unbounded_agents == (0, 1, 2)
    assert check_certificate(rep.certificate).valid
    rep = check_redundancy(["x1", "-x1"], r=1)  # the whole sum is 0: argmin R, subsets empty
    assert rep.holds and rep.exact
    rep = check_redundancy(["x1", "-x1", "x1^2"], r=1)
    assert not rep.holds and rep.exact
    assert check_certificate(rep.certificate).valid
    rep = check_redundancy(["max(x1, x2)", "x1^2 + x2^2", "x1^2 + x2^2 + max(x1, x2)"], r=2)
    assert not rep.holds and rep.exact and rep.unbounded == ((0,),)
    assert rep.witness["exact"] and len(rep.witness["subsets"][0]) == 1
    assert rep.gap == np.inf
    assert check_certificate(rep.certificate).valid


def test_paper_costs_are_2_redundant_exactly():
    """The paper's ten costs: every 8 of them have argmin {0} (the norms' kinks at 0
    outweigh f5, f6, f7), although f6 alone is unbounded below and f1, f5 differ."""
    rep = check_redundancy(paper_costs(), r=2)
    assert (rep.holds, rep.exact, rep.gap) == (True, True, 0.0)
    assert rep.unbounded == () and rep.unbounded_agents == (6,)
    assert check_certificate(rep.certificate).valid
    assert {tuple(s["x"]["x"]) for s in rep.certificate["subsets"]} == {("0", "0")}
    assert check_redundancy(paper_costs("x2"), r=2).holds
    four = check_redundancy(paper_costs(), r=4)
    assert not four.holds and four.exact
    assert check_certificate(four.certificate).valid


def test_paper_certificate_through_rescon_check(tmp_path):
    rep = check_redundancy(paper_costs(), r=4)
    path = tmp_path / "cert.json"
    path.write_text(json.dumps(rep.certificate))
    out = subprocess.run([sys.executable, str(ROOT / "certificates" / "check.py"), str(path)],
                         capture_output=True, text=True, check=False)
    assert out.returncode == 0 and out.stdout.strip() == "valid"


def test_interval_argmins():
    """|x−1| + |x+1| has argmin [−1, 1]: the minimisers found (0) lie in every set, the
    witness is a support point (1) proven a minimiser by the same multipliers."""
    box = "abs(x1 - 1) + abs(x1 + 1)"
    rep = check_redundancy([box, box, "abs(x1)"], r=1)
    assert not rep.holds and rep.exact and rep.gap == pytest.approx(1.0)
    assert rep.witness["points"] == [[1.0], [0.0]]
    assert check_certificate(rep.certificate).valid
    same = check_redundancy([box, box, box], r=1)  # the same inequalities: exact
    assert same.holds and same.exact and same.gap == 0.0
    assert check_certificate(same.certificate).valid
    # equal intervals whose descriptions differ by a redundant x ≤ 5: numerical
    slack = check_redundancy([box, box, box + " + pos(x1 - 5)"], r=1)
    assert slack.holds and not slack.exact and slack.gap <= slack.tolerance


def test_nonpolyhedral_costs_get_a_numerical_verdict_unchecked():
    costs = ["huber(x1 - 1, 1) + x2^2", "huber(x1 - 1, 1) + abs(x2)",
             "logsumexp(x1 - 1, 1 - x1) + x2^2"]
    rep = check_redundancy(costs, r=1)
    assert rep.holds and not rep.exact and rep.tolerance > 0 and rep.gap <= rep.tolerance
    res = check_certificate(rep.certificate)
    assert res.verdict == "unchecked" and res.unchecked
    shifted = check_redundancy(costs + ["huber(x1 + 1, 1)"], r=1)
    assert not shifted.holds and not shifted.exact
    assert shifted.witness["exact"] is False and shifted.witness["direction"] is not None


def test_norm2_at_its_kink_is_exact():
    """3‖x‖₂ + (x1 − 1)² has argmin {0} (|∇| = 2 < 3): μ = (2/3, 0) certifies it, and
    (1, 1), the minimiser of the other pair, lies outside — no exact value of a norm
    is needed; tampering with μ is refuted."""
    rep = check_redundancy(["3*sqrt(x1^2+x2^2)", "(x1-1)^2", "(x1-1)^2 + (x2-1)^2"], r=1)
    assert not rep.holds and rep.exact
    assert rep.witness["points"] == [[1.0, 1.0], [0.0, 0.0]]
    cert = rep.certificate
    assert check_certificate(cert).valid and "x2" in cert["witness"]
    assert _tampered(cert, lambda c: c["witness"]["x2"].__setitem__(
        "mu", [["1", "0"]])).verdict == "invalid"


def test_exact_witness_among_subsets_without_the_other_costs():
    """Agent 0 (Huber) is not piecewise quadratic; pairs of the others differ exactly."""
    rep = check_redundancy(["huber(x1, 1)", "x1^2", "(x1-1)^2", "(x1-2)^2"], r=2)
    assert not rep.holds and rep.exact
    cert = rep.certificate
    assert cert["costs"][0] is None and check_certificate(cert).valid
    forged = _tampered(cert, lambda c: c["witness"].__setitem__("S2", [0, 1]))
    assert forged.verdict == "invalid" and "not recorded" in forged.reason


def test_cvxpy_costs_in_one_variable():
    import cvxpy as cp

    x = cp.Variable(2)
    costs = [cp.sum_squares(x) + cp.exp(x[0]), cp.exp(x[0]) + cp.sum_squares(x),
             cp.abs(x[1]) + cp.exp(x[0]) + cp.sum_squares(x)]
    rep = check_redundancy(costs, r=1)
    assert rep.holds and not rep.exact
    assert not check_redundancy(costs + [cp.sum_squares(x - 1)], r=1).holds
    with pytest.raises(InputError, match="cost of agent [01]: .*one Variable"):
        check_redundancy([costs[0], cp.exp(cp.Variable(2)[0]) + 0], r=1)


def test_norm2_term_with_tight_multiplier_is_not_claimed_exact():
    """‖x‖₂ + (x1 − 1)²: the minimiser (0.5, 0)... is off the norm's kink: numerical."""
    rep = check_redundancy(["sqrt(x1^2 + x2^2)", "(x1 - 2)^2 + x2^2"], r=0)
    assert rep.holds and not rep.exact


def test_atoms_and_mappings_accepted():
    rep = check_redundancy({1: atoms.Quadratic(np.eye(2)), 2: atoms.Norm1(np.eye(2)),
                            3: atoms.NormInf(np.eye(2)), 4: atoms.Hinge([1.0, 1.0], 1.0)}, r=1)
    assert rep.holds and rep.exact
    assert rescon.RedundancyReport is type(rep)


# --------------------------------------------------------------------------- #
# certificates: tampering
# --------------------------------------------------------------------------- #

def _tampered(cert, edit):
    c = copy.deepcopy(cert)
    edit(c)
    return check_certificate(c)


def test_tampered_violation_certificates_are_rejected():
    cert = check_redundancy(["(x1-1)^2 + x2^2", "(x1+1)^2 + x2^2", "abs(x1) + abs(x2)",
                             "x1^2"], r=1).certificate
    assert check_certificate(cert).valid
    edits = {
        "x1 moved": lambda c: c["witness"]["x1"]["x"].__setitem__(0, "1/7"),
        "x2 = x1": lambda c: c["witness"].__setitem__("x2", c["witness"]["x1"]),
        "x2 moved": lambda c: c["witness"]["x2"].__setitem__("x", ["1", "0"]),
        "cost changed": lambda c: c["costs"][0]["g"].__setitem__(0, "5"),
        "non-convex cost": lambda c: c["costs"][3]["H"][0].__setitem__(0, "-2"),
        "S1 too large": lambda c: c["witness"].__setitem__("S1", [0, 1, 2, 3]),
        "S1 = S2": lambda c: c["witness"].__setitem__("S2", c["witness"]["S1"]),
        "r changed": lambda c: c.__setitem__("r", 2),
    }
    for what, edit in edits.items():
        assert not _tampered(cert, edit).valid, what
        assert _tampered(cert, edit).verdict == "invalid", what


def test_tampered_holds_certificates_are_rejected():
    cert = check_redundancy(["(x1 - 1)^2", "(x1 + 1)^2", "2*abs(x1)"], r=1).certificate
    assert any(s["x"]["lambda"] for s in cert["subsets"]), "2|x| needs block multipliers"
    edits = {
        "subset dropped": lambda c: c["subsets"].pop(),
        "subset twice": lambda c: c["subsets"].__setitem__(1, c["subsets"][0]),
        "point moved": lambda c: c["subsets"][2]["x"].__setitem__("x", ["1"]),
        "cost changed": lambda c: c["costs"][0]["g"].__setitem__(0, "-4"),
        "multiplier": lambda c: next(s for s in c["subsets"] if s["x"]["lambda"])["x"]
        .__setitem__("lambda", [["1/2", "1/2"]]),
        "negative multiplier": lambda c: next(s for s in c["subsets"] if s["x"]["lambda"])["x"]
        .__setitem__("lambda", [["2", "-1"]]),
    }
    for what, edit in edits.items():
        assert _tampered(cert, edit).verdict == "invalid", what
    unb = check_redundancy(["x1", "x1 + abs(x2)", "x1"], r=1).certificate
    flipped = _tampered(unb, lambda c: c["subsets"][0].__setitem__(
        "unbounded", [str(-int(v)) for v in c["subsets"][0]["unbounded"]]))
    assert flipped.verdict == "invalid"


def test_forged_holds_certificate_with_valid_proofs_is_rejected():
    """Every subset's optimality proof is valid, but the argmins differ."""
    from rescon.optim.redundancy import _Check

    specs = ["(x1-1)^2 + x2^2", "(x1+1)^2 + x2^2", "abs(x1) + abs(x2)", "x1^2"]
    chk = _Check(list(range(4)), [rescon.cost(f, d=2) for f in specs], 2, 1)
    subs = [chk.argmin(m) for m in itertools.combinations(range(4), 3)]
    res = check_certificate(chk.holds_certificate(subs))
    assert res.verdict == "invalid" and "differs" in res.reason
    box1, box2 = "abs(x1 - 1) + abs(x1 + 1)", "abs(x1 - 2) + abs(x1 + 2)"  # [−1, 1], [−2, 2]
    chk = _Check(list(range(3)), [rescon.cost(f, d=1) for f in (box1, box2, box2)], 1, 1)
    subs = [chk.argmin(m) for m in itertools.combinations(range(3), 2)]
    res = check_certificate(chk.holds_certificate(subs))
    assert res.verdict == "invalid" and "differs" in res.reason


def test_numerical_certificate_cannot_pass_as_valid():
    cert = check_redundancy(["huber(x1, 1)", "huber(x1, 2)"], r=1).certificate
    assert cert["kind"] == "redundancy_numerical"
    assert check_certificate(cert).verdict == "unchecked"
    assert _tampered(cert, lambda c: c.__setitem__("holds", "yes")).verdict == "invalid"


# --------------------------------------------------------------------------- #
# bad input
# --------------------------------------------------------------------------- #

def test_errors():
    with pytest.raises(InputError, match="r must be an integer < N = 2"):
        check_redundancy(["x1^2", "x1^2"], r=2)
    with pytest.raises(InputError, match="r must be a nonnegative integer"):
        check_redundancy(["x1^2", "x1^2"], r=-1)
    with pytest.raises(InputError, match="cost of agent a: dimension 2, not d = 3"):
        check_redundancy({"a": atoms.Quadratic(np.eye(2)), "b": atoms.Quadratic(np.eye(3))}, r=1)
    with pytest.raises(InputError, match="cost of agent b"):
        check_redundancy({"a": "x1^2 + x2^2", "b": atoms.Quadratic(np.eye(3))}, r=1, d=2)
    with pytest.raises(InputError, match="cost of agent 1"):
        check_redundancy(["x1^2", "x3^2"], r=1, d=2)
    with pytest.raises(InputError, match="cost of agent 0.*callable"):
        check_redundancy([(lambda x: x @ x, lambda x: 2 * x), "x1^2"], r=1, d=1)
    with pytest.raises(InputError, match="costs must"):
        check_redundancy([], r=0)
    with pytest.raises(InputError, match="costs must"):
        check_redundancy("x1^2", r=0)
