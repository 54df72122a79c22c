"""r-redundancy at the edges (V22 follow-ups): argmins at tiny and huge scales, hairs
decided exactly from the certified faces, supports on the normalised faces, parallel
unbounded argmins on the numerical path, and bounded sums never called unbounded."""

from __future__ import annotations

from fractions import Fraction

import pytest

import rescon
from rescon.errors import SolverError
from rescon.optim import _pq, redundancy

FAR = ["abs(x1 - {c})", "abs(x1 - {c}) + abs(x2)", "abs(x1 - {c}) + abs(x1 + x2 - {c})"]


def _valid(rep):
    return rescon.check_certificate(rep.certificate).verdict == "valid"


def test_argmins_away_from_zero_at_small_scale_are_certified():
    # [1e-7, 2e-7] for every subset: x is rounded at the scale of |x|, not to 1e-6
    rep = rescon.check_redundancy(["abs(x1 - 1e-7) + abs(x1 - 2e-7)"] * 3, 1)
    assert (rep.holds, rep.exact, rep.gap) == (True, True, 0.0)
    assert _valid(rep)


def test_small_scale_violation_is_exact_with_its_gap():
    # [1e-7, 2e-7] vs [1e-7, 3e-7]: Hausdorff distance 1e-7
    rep = rescon.check_redundancy(["abs(x1 - 1e-7) + abs(x1 - 2e-7)"] * 2
                                  + ["abs(x1 - 1e-7) + abs(x1 - 3e-7)"], 2)
    assert (rep.holds, rep.exact) == (False, True)
    assert rep.gap == pytest.approx(1e-7, rel=1e-9)
    assert _valid(rep)


def test_small_scale_hair_is_exact():
    # [0, 1e-7] vs [0, 1.0000001e-7]: differ by 1e-14, decided from the exact vertex
    rep = rescon.check_redundancy(["abs(x1) + abs(x1 - 1e-7)"] * 2
                                  + ["abs(x1) + abs(x1 - 1.0000001e-7)"], 2)
    assert (rep.holds, rep.exact) == (False, True)
    assert _valid(rep)
    assert Fraction(rep.witness["points"][0][0]) == Fraction(1.0000001e-7)


def test_small_scale_face_gap():
    # [0, 2e-7] vs [0, 1e-7] (a face 1e-3·pos(x1 − 1e-7)): HiGHS on unscaled rows saw
    # the face only to its 1e-7 feasibility tolerance
    rep = rescon.check_redundancy(["abs(x1) + abs(x1 - 2e-7)"] * 2
                                  + ["abs(x1) + abs(x1 - 2e-7) + 1e-3*pos(x1 - 1e-7)"], 2)
    assert (rep.holds, rep.exact) == (False, True)
    assert rep.gap == pytest.approx(1e-7, rel=1e-9)


@pytest.mark.parametrize("c", ["1e20", "1e50"])
def test_far_polyhedral_holds_exactly(c):
    rep = rescon.check_redundancy([s.format(c=c) for s in FAR]
                                  + [f"abs(x2) + 3*abs(x1 - {c})"], 1)
    assert (rep.holds, rep.exact) == (True, True)
    assert _valid(rep)


@pytest.mark.parametrize("c", ["1e8", "1e12", "1e20"])
def test_far_polyhedral_unit_violation_is_exact(c):
    # the last cost's kink is 1 away from the others', at c: below the float resolution
    # of c for 1e20 (the solver zooms in; the certificate is exact)
    rep = rescon.check_redundancy([s.format(c=c) for s in FAR]
                                  + [f"abs(x2) + 3*abs(x1 - {c} - 1)"], 1)
    assert (rep.holds, rep.exact) == (False, True)
    assert _valid(rep)


def test_strongly_convex_far_sums_are_bounded():
    rep = rescon.check_redundancy(["(x1 - 1e12)^2", "(x1 + 1e12)^2", "2*abs(x1)"], 1)
    assert (rep.holds, rep.exact, rep.unbounded) == (False, True, ())
    assert rep.gap == pytest.approx(1e12 - 1)
    assert _valid(rep)


def test_strongly_convex_sum_is_never_reported_unbounded(monkeypatch):
    # both solvers fooled: the exact data still say the sum is bounded below
    monkeypatch.setattr(redundancy, "_clarabel", lambda G: ("failed", "x"))
    monkeypatch.setattr(redundancy._Cvx, "minimise", lambda self, m: ("unbounded", None))
    with pytest.raises(SolverError, match="strongly convex"):
        rescon.check_redundancy(["(x1 - 1)^2 + abs(x1)", "(x1 + 1)^2", "x1^2"], 1)


def test_strongly_convex_is_exact():
    F = _pq.of_oracle(rescon.cost("x1^2 + abs(x2)", d=2), 2)
    assert not _pq.strongly_convex(F)
    F = _pq.of_oracle(rescon.cost("x1^2 + x2^2 + abs(x2)", d=2), 2)
    assert _pq.strongly_convex(F)


def test_numerical_equal_lines_still_hold():
    rep = rescon.check_redundancy(["huber(x1 - x2)"] * 3, 1)
    assert (rep.holds, rep.exact) == (True, False)
    assert rep.gap <= rep.tolerance


def test_numerical_parallel_strip_witness_names_the_distance():
    rep = rescon.check_redundancy(["huber(x1 - x2)"] * 2 + ["huber(x1 - x2 - 5)"], 2)
    assert (rep.holds, rep.exact) == (False, False)
    assert "distance" in rep.witness["reason"]
    p, q = rep.witness["points"]
    assert abs((p[0] - p[1]) - (q[0] - q[1])) > 1.0


def test_rational_is_relative_to_its_scale():
    assert _pq.rational(1.5e-7) == 0                       # the old guess: to 1e-6 of 1
    assert _pq.rational(1.5e-7, 1e-7) == pytest.approx(1.5e-7, rel=1e-6)
    assert _pq.rational(1.000000001, 0.0) == Fraction(1.000000001)


def test_paper_costs_are_f_redundant_as_documented():
    from rescon.optim.paper import paper_costs
    assert "*are* F-redundant" in paper_costs.__doc__
    for f7 in ("as-written", "x2"):
        rep = rescon.check_redundancy(paper_costs(f7), 2)
        assert (rep.holds, rep.exact) == (True, True)
