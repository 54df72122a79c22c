"""R6: r-redundancy's verdicts do not depend on the unit of x, the unit of the costs'
values or where the costs sit (V26 items 1-4): the numerical tolerance is relative to
the frame's spread, the level sets' slack to the sum's variation over the frame, the
exact path is framed at the exact centre, and sqrt keeps its anchors exact."""

from __future__ import annotations

from fractions import Fraction

import pytest

import rescon


def _huber3(c0: str = "0", sx: float = 1.0) -> list[str]:
    """A Huber violation of gap 0.5·sx (x scaled by sx), centred at c0."""
    k = f"{1 / sx!r}"
    return [f"huber({k}*x1 - {c0}, 1) + ({k}*x2 - {c0})^2",
            f"huber({k}*x1 - {c0} - 2, 1) + ({k}*x2 - {c0})^2",
            f"huber({k}*x1 - {c0}, 1) + ({k}*x2 - {c0})^2"]


@pytest.mark.parametrize("sx", [1e-12, 1e-8, 1e8, 1e12])
def test_numerical_violation_keeps_its_verdict_in_any_unit_of_x(sx):
    base = rescon.check_redundancy(_huber3(), r=1)
    rep = rescon.check_redundancy(_huber3(sx=sx), r=1)
    assert (base.holds, base.exact) == (rep.holds, rep.exact) == (False, False)
    assert rep.gap == pytest.approx(base.gap * sx, rel=1e-3)
    # the frame's spread s is a power of two: the tolerance scales within a factor 2
    assert base.tolerance * sx / 2 <= rep.tolerance <= 2 * base.tolerance * sx


@pytest.mark.parametrize("sf", ["1e-12", "1e-8", "1e8", "1e12"])
def test_identical_numerical_costs_hold_in_any_unit_of_value(sf):
    rep = rescon.check_redundancy([f"{sf}*huber(x1 - 3, 1)"] * 3, r=1)
    assert (rep.holds, rep.exact) == (True, False) and rep.gap < 1e-3
    rep = rescon.check_redundancy([f"{sf}*logsumexp(x1, -x1) + {sf}*huber(x2, 1)"] * 3, r=1)
    assert (rep.holds, rep.exact) == (True, False) and rep.gap < 1e-3


@pytest.mark.parametrize("sf", ["1e-12", "1e12"])
def test_numerical_violation_keeps_its_gap_in_any_unit_of_value(sf):
    base = rescon.check_redundancy(_huber3(), r=1)
    rep = rescon.check_redundancy([f"{sf}*({c})" for c in _huber3()], r=1)
    assert (rep.holds, rep.exact) == (False, False)
    assert rep.gap == pytest.approx(base.gap, rel=1e-3)


@pytest.mark.parametrize("c", ["1e50", "-1e150", "3e300"])
def test_exact_segment_argmins_far_away_are_certified(c):
    """A_{01} = A_{02} = [c, c + 1] × {c}, A_{12} = {(c, c)}: an exact violation, gap 1."""
    costs = [f"abs(x1 - {c} - 1) + abs(x2 - {c})", f"abs(x1 - {c}) + abs(x2 - {c})",
             f"abs(x1 - {c}) + abs(x2 - {c})"]
    rep = rescon.check_redundancy(costs, r=1)
    assert (rep.holds, rep.exact, rep.gap) == (False, True, 1.0)
    assert rescon.check_certificate(rep.certificate).valid


def test_exact_segment_argmins_far_away_and_small_are_certified():
    costs = ["abs(1e12*x1 - 1e50 - 1)", "abs(1e12*x1 - 1e50)", "abs(1e12*x1 - 1e50)"]
    rep = rescon.check_redundancy(costs, r=1)
    assert (rep.holds, rep.exact) == (False, True)
    assert rep.gap == pytest.approx(1e-12, rel=1e-12)
    assert rescon.check_certificate(rep.certificate).valid


def test_sqrt_keeps_its_anchor_exact():
    """A perfect-square pivot keeps √p exact; another (2) rescales the row by a rational,
    so the anchor b/a is still 10^50 exactly."""
    for src in ("sqrt((x1 - 1e50)^2)", "sqrt(2*(x1 - 1e50)^2)"):
        atom = rescon.cost(src, d=1)
        (a,), (b,) = atom.exact["A"][0], atom.exact["b"]
        assert Fraction(b) / Fraction(a) == 10**50, src


@pytest.mark.parametrize("c", ["1e50", "-1e150"])
def test_sqrt_with_a_non_square_pivot_agrees_with_abs_far_away(c):
    costs = [f"sqrt(2*(x1 - {c})^2)", f"abs(x1 - {c})", f"abs(x1 - {c})"]
    rep = rescon.check_redundancy(costs, r=1)
    assert (rep.holds, rep.exact, rep.gap) == (True, True, 0.0)
