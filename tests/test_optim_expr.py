"""The cost-expression grammar: parsing, errors with positions, convexity, lowering."""

from __future__ import annotations

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from rescon.errors import InputError
from rescon.optim import atoms

P = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, -1.0], [0.5, 0.3], [-2.0, 2.0], [3.0, -0.25]])


@pytest.mark.parametrize("src, ref", [
    ("x1^2 + x2^2", lambda x, y: x**2 + y**2),
    ("-(-x1) - -x2 + 3", lambda x, y: x + y + 3),
    ("2*x1*x1 + x1*x2*2 + x2^2/2", lambda x, y: 2 * x * x + 2 * x * y + y**2 / 2),
    ("(x1 + 0.3)^2 + (x1 - 0.2)^2", lambda x, y: (x + 0.3) ** 2 + (x - 0.2) ** 2),
    ("abs(x1 + x2)", lambda x, y: np.abs(x + y)),
    ("sqrt(x1^2 + x2^2)", lambda x, y: np.hypot(x, y)),
    ("sqrt((x1 - x2)^2 + 4)", lambda x, y: np.sqrt((x - y) ** 2 + 4)),
    ("max(x1, x2)", lambda x, y: np.maximum(x, y)),
    ("-min(x1, -x2, 1)", lambda x, y: -np.minimum(np.minimum(x, -y), 1)),
    ("pos(x1^2 - 1) + pos(x2)", lambda x, y: np.maximum(x**2 - 1, 0) + np.maximum(y, 0)),
    ("max(abs(x1), x2^2, norm2(x1, x2))",
     lambda x, y: np.maximum(np.maximum(np.abs(x), y**2), np.hypot(x, y))),
    ("norm1(x1, 2*x2 - 1)", lambda x, y: np.abs(x) + np.abs(2 * y - 1)),
    ("norminf(x1, x2, 0.5)", lambda x, y: np.maximum(np.maximum(np.abs(x), np.abs(y)), 0.5)),
    ("huber(x1 - x2)", lambda x, y: np.where(np.abs(x - y) <= 1, (x - y) ** 2,
                                               2 * np.abs(x - y) - 1)),
    ("huber(x1, 0.5) * 3", lambda x, y: 3 * np.where(np.abs(x) <= 0.5, x**2,
                                                      np.abs(x) - 0.25)),
    ("logsumexp(x1, x2)", lambda x, y: np.logaddexp(x, y)),
    ("1.5e-1 * x1 + .5", lambda x, y: 0.15 * x + 0.5),
    ("x1^1 + x2^0", lambda x, y: x + 1),
])
def test_expressions_evaluate_as_written(src, ref):
    o = rescon.cost(src, d=2)
    assert np.allclose(o.value(P), ref(P[:, 0], P[:, 1]), rtol=1e-13, atol=1e-13)
    assert rescon.check_subgradient(o, P) <= 1e-9 * (1 + np.abs(o.value(P)).max())
    assert o.kind == "expression" and o.source == src


@pytest.mark.parametrize("src, pos, msg", [
    ("x1 + * 2", 5, "expected a number"),
    ("x1 x2", 3, "unexpected 'x2'"),
    ("(x1", 3, "expected ')'"),
    ("abs(x1", 6, "expected ')'"),
    ("x1 + foo(x2)", 5, "unknown name 'foo'"),
    ("x0", 0, "unknown name 'x0'"),
    ("x1 # 2", 3, "unexpected character '#'"),
    ("", 0, "found the end"),
    ("abs(x1, x2)", 0, "abs takes 1 argument"),
    ("huber(x1, x2)", 10, "huber's M must be a positive constant"),
    ("huber(x1, -1)", 0, "huber's M must be a positive constant"),
    ("x1 / x2", 3, "can only divide by a constant"),
    ("x1 / (1 - 1)", 3, "division by zero"),
    ("x1^3", 3, "exponent must be the number 0, 1 or 2"),
    ("x1 * abs(x2)", 3, "product of non-constant"),
    ("abs(x1)^2", 7, "^2 needs an affine base"),
])
def test_syntax_errors_name_the_position(src, pos, msg):
    with pytest.raises(InputError, match=rf"{re.escape(msg)}.* at position {pos}$"):
        rescon.cost(src, name="cost of agent 4")


@pytest.mark.parametrize("src, pos, msg", [
    ("x1*x2", 0, "neither convex nor concave"),
    ("x1^2 - x2^2", 0, "neither convex nor concave"),
    ("-x1^2", 0, "concave, not convex"),
    ("-abs(x1)", 0, "concave, not convex"),
    ("abs(x1^2)", 4, "abs needs affine arguments"),
    ("norm2(x1, abs(x2))", 10, "norm2 needs affine arguments"),
    ("max(x1, -x1^2)", 8, "max needs convex"),
    ("min(x1^2, 1)", 4, "min needs concave"),
    ("sqrt(x1)", 5, "sqrt needs a sum of squares"),
    ("sqrt(x1^2 - 1)", 5, "sqrt needs a sum of squares"),
    ("x1^2 + min(x1, x2)", None, "sum of convex and concave"),
])
def test_nonconvex_expressions_are_refused_with_position(src, pos, msg):
    at = rf" at position {pos}$" if pos is not None else ""
    with pytest.raises(InputError, match=rf"cost of agent 4: expression .*{re.escape(msg)}.*{at}"):
        rescon.cost(src, name="cost of agent 4")


def test_convexity_of_the_quadratic_part_is_exact():
    # (x1 + x2)^2 written out is convex although no term is
    assert rescon.cost("x1^2 + 2*x1*x2 + x2^2").quadratic
    # 2 + 1e-20 rounds to 2.0 in floats: a float eigenvalue test would accept this
    # indefinite form; the rational test refuses it
    with pytest.raises(InputError, match="neither convex nor concave"):
        rescon.cost("x1^2 + 2.00000000000000000001*x1*x2 + x2^2")
    # sqrt of a sum of squares is decided on the exact homogenised matrix
    with pytest.raises(InputError, match="sum of squares"):
        rescon.cost("sqrt(x1^2 + 2*x1 + 0.99999999999999999999)")
    assert rescon.cost("sqrt(x1^2 + 2*x1 + 1)").value([[-1.0]]).tolist() == [0.0]


def test_lowering_keeps_the_structure():
    o = rescon.cost("(x1 - 1)^2 + 2*(x2 - 0.5)^2 + 3")
    assert isinstance(o, atoms.Quadratic) and o.quadratic
    assert o.Q.tolist() == [[2.0, 0.0], [0.0, 4.0]]
    assert rescon.cost("abs(x1) + max(x1, x2) + pos(x2 - 1) + norminf(x1, x2)").polyhedral
    assert not rescon.cost("abs(x1) + x2^2").polyhedral
    assert isinstance(rescon.cost("-min(x1, x2)"), atoms.MaxAffine)
    assert isinstance(rescon.cost("sqrt(x1^2 + x2^2)"), atoms.Norm2)
    # an expression in x1 only still has the requested dimension
    assert rescon.cost("x1^2", d=3).d == 3 and rescon.cost("5").d == 1


def test_expression_must_be_a_string_and_numbers_fit_floats():
    from rescon.optim.expr import expression_cost

    with pytest.raises(InputError, match="must be a string"):
        expression_cost(3)
    with pytest.raises(InputError, match="does not fit a float"):
        rescon.cost("1e400 * x1")


_TERMS = st.sampled_from([
    ("abs(x1 - {c})", lambda x, y, c: np.abs(x - c)),
    ("(x2 + {c})^2", lambda x, y, c: (y + c) ** 2),
    ("max(x1, x2, {c})", lambda x, y, c: np.maximum(np.maximum(x, y), c)),
    ("norm2(x1 - {c}, x2)", lambda x, y, c: np.hypot(x - c, y)),
    ("pos({c} - x1 - x2)", lambda x, y, c: np.maximum(c - x - y, 0)),
    ("huber(x1 + {c}, 2)", lambda x, y, c: np.where(np.abs(x + c) <= 2, (x + c) ** 2,
                                                     4 * np.abs(x + c) - 4)),
    ("-min(x1, {c})", lambda x, y, c: -np.minimum(x, c)),
])


@settings(max_examples=40, deadline=None)
@given(st.lists(st.tuples(_TERMS, st.integers(0, 5), st.integers(-3, 3)), min_size=1,
                max_size=4), st.integers(0, 2**32 - 1))
def test_random_sums_of_terms(terms, seed):
    """A nonnegative sum of random convex terms: values as written, valid subgradients
    at the kinks (points on the terms' breakpoints) and at random points."""
    src = " + ".join(f"{w}*({t.format(c=c)})" for (t, _), w, c in terms)
    o = rescon.cost(src, d=2)
    rng = np.random.default_rng(seed)
    pts = np.vstack([rng.integers(-3, 4, size=(6, 2)).astype(float),
                     rng.normal(scale=2, size=(4, 2))])
    ref = sum(w * f(pts[:, 0], pts[:, 1], c) for (_, f), w, c in terms)
    assert np.allclose(o.value(pts), ref, rtol=1e-12, atol=1e-12)
    assert rescon.check_subgradient(o, pts, samples=16) <= 1e-9 * (1 + np.abs(ref).max())


@pytest.mark.parametrize("p, q", [(1, 5), (1, 10), (2, 7), (13, 3), (7, 29)])
def test_singular_convex_quadratics_survive_float_rounding(p, q):
    """(x1 + (p/q) x2)² has a singular PSD Hessian; rounded to floats it can be
    indefinite by one ulp (these were refused as non-convex). Convexity is decided on
    the exact data, which the atom keeps."""
    from fractions import Fraction

    o = rescon.cost(f"(x1 + {p}/{q}*x2)^2")
    a = Fraction(p, q)
    assert o.exact["Q"] == [[2, 2 * a], [2 * a, 2 * a * a]]
    assert o.value([[1.0, 2.0]])[0] == pytest.approx((1 + 2 * p / q) ** 2, rel=1e-14)


def test_atoms_keep_exact_data():
    from fractions import Fraction

    o = rescon.cost("3*abs(x1 - 0.1) + abs(x2)/3 + huber(x1, 0.3) + max(x1, x2 + 0.7)")
    data = {type(t).__name__: t.exact for t in o.terms}
    assert data["Norm1"] == {"A": [[3, 0], [0, Fraction(1, 3)]], "b": [Fraction(3, 10), 0]}
    assert data["Huber"]["M"] == Fraction(3, 10)
    assert data["MaxAffine"] == {"A": [[1, 0], [0, 1]], "b": [0, Fraction(7, 10)]}
    f = atoms.AbsAffine([0.1, 1.0], 0.2)  # floats: their exact binary values
    assert f.exact == {"A": [[Fraction(0.1), 1]], "b": [Fraction(0.2)]}
    with pytest.raises(InputError, match="symmetric"):
        atoms.Quadratic([[1.0, 2.0], [0.0, 1.0]])
