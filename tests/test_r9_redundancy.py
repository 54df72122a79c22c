"""R9: check_redundancy after V34 — exact violations that do not wait for the numerical
path, agent labels that print alike, and numerical verdicts that do not depend on the
scale (powers of two)."""

from __future__ import annotations

import json
import math
import warnings
from decimal import Decimal

import pytest

import rescon
from rescon.errors import SolverError
from rescon.optim import redundancy


def _verdicts(cert):
    return (rescon.check_certificate(cert).verdict,
            rescon.check_certificate(json.loads(json.dumps(cert))).verdict)


def test_ray_argmin_exact_violation():
    # {x1, x1^2}: argmin {-1/2}, {norm2(0*x1, x1), x1^2}: argmin {0}, both certified;
    # {x1, norm2(0*x1, x1)} = x1 + |x1|: argmin (-inf, 0] (Clarabel stalls on its
    # support in −e1 instead of saying unbounded)
    rep = rescon.check_redundancy(["x1", "norm2(0*x1, x1)", "x1^2"], 1, d=1)
    assert not rep.holds and rep.exact
    assert rep.gap > 1  # (-inf, 0] is at infinite distance from {0}: a lower bound
    assert _verdicts(rep.certificate) == ("valid", "valid")


def test_exact_violation_survives_a_failing_numerical_gap(monkeypatch):
    def fail(*_a, **_k):
        raise SolverError("Clarabel failed on the numerical path")

    monkeypatch.setattr(redundancy._Cvx, "support", fail)
    rep = rescon.check_redundancy(["x1", "norm2(0*x1, x1)", "x1^2"], 1, d=1)
    assert not rep.holds and rep.exact and math.isnan(rep.gap)
    assert _verdicts(rep.certificate) == ("valid", "valid")


@pytest.mark.parametrize("pair", [((1, 2), "(1, 2)"), (2.5, "2.5"), (None, "None")])
def test_labels_that_print_alike(pair):
    a, b = pair
    costs = {a: "(x1 - 1)^2", b: "(x1 + 1)^2", "c": "2*abs(x1)"}
    for r, holds in ((1, True), (2, False)):
        rep = rescon.check_redundancy(costs, r)
        assert (rep.holds, rep.exact) == (holds, True)
        assert _verdicts(rep.certificate) == ("valid", "valid")


def test_labels_written_distinct():
    # integers and strings as they are; others as str(x), " #i" (position) when taken
    costs = {"(1, 2)": "x1^2", (1, 2): "x1^2", "(1, 2) #1": "x1^2", 2.5: "x1^2", 3: "x1^2"}
    cert = rescon.check_redundancy(costs, 1).certificate
    assert cert["agents"] == ["(1, 2)", "(1, 2) #1 #1", "(1, 2) #1", "2.5", 3]
    assert _verdicts(cert) == ("valid", "valid")


def _scaled(s):
    return [f"abs((0)*x1 - ({-2 * s}))", f"norm2((1)*x1 - ({2 * s}), (-0.25)*x1 - ({2 * s}))",
            f"norm2((1)*x1 - ({2 * s}), (-0.25)*x1 - ({2 * s}))", f"abs(x1 - ({s}))"]


@pytest.mark.slow
def test_numerical_verdict_scale_free():
    base = rescon.check_redundancy(_scaled(1), 1, d=1)
    assert (base.holds, base.exact) == (False, False)
    assert rescon.check_certificate(base.certificate).verdict == "unchecked"
    for e in range(-20, 21):
        s = 2.0**e
        rep = rescon.check_redundancy(_scaled(s), 1, d=1)
        assert (rep.holds, rep.exact) == (base.holds, base.exact), e
        assert rep.gap == base.gap * s and rep.tolerance == base.tolerance * s, e


def test_numerical_verdict_scale_free_at_1024():
    base, big = (rescon.check_redundancy(_scaled(s), 1, d=1) for s in (1, 1024))
    assert (big.holds, big.exact) == (base.holds, base.exact) == (False, False)
    assert big.gap == base.gap * 1024


def _scaled_exact(s):
    """_scaled(s) written with the floats' exact decimal values."""
    return [c.replace(f"({v})", f"({Decimal(v)})") for c, v in
            zip(_scaled(s), (-2 * s, 2 * s, 2 * s, s), strict=True)]


@pytest.mark.parametrize("e", [510, 700, 1010, -540, -800, -1000])
def test_numerical_verdict_scale_free_past_the_norm_squares(e):
    # V35: a Norm2 cost evaluated in numpy as sqrt(r·r) overflowed (underflowed) past
    # ~2^511 (below ~2^-537), so its unit κ fell back to 1 and Clarabel failed; κ now
    # comes from the data divided by their size first
    base = rescon.check_redundancy(_scaled(1), 1, d=1)
    s = 2.0**e
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no numpy RuntimeWarning either
        rep = rescon.check_redundancy(_scaled_exact(s), 1, d=1)
    assert (rep.holds, rep.exact) == (base.holds, base.exact) == (False, False)
    assert rep.gap == base.gap * s and rep.tolerance == base.tolerance * s


@pytest.mark.parametrize("e", [-1012, -1030, -1070])
def test_numerical_verdict_refused_below_the_normal_floats(e):
    """Costs whose kinks lie within ~1e-304 of each other (V35's family at 2^-1012 and
    below): the numerical tolerance would be subnormal (0 at 2^-1070) and the frame has
    lost precision — a one-line InputError, not a verdict (R11 saw holds=True there where
    scale 1 says False)."""
    with pytest.raises(rescon.InputError, match="below what the numerical path resolves"):
        rescon.check_redundancy(_scaled_exact(2.0**e), 1, d=1)
