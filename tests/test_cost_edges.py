"""Cost evaluation at the edges (V22's R1 fixes): quadratics far from the origin and with
far, very negative minima (expression lowering, Quadratic, the merged global cost)
against exact Fraction evaluation; complex oracle answers; deeply nested expressions;
the CasADi symbol found from the expression."""

from __future__ import annotations

import contextlib
import io
import random
import warnings
from fractions import Fraction as Fr

import numpy as np
import pytest

import rescon
from rescon.cli import main as cli_main
from rescon.errors import InputError
from rescon.optim import atoms
from rescon.optim.expr import MAX_DEPTH


def _exact_quadratic(o: atoms.Quadratic, x) -> Fr:
    """½(x − c)ᵀQ(x − c) + qᵀx + const from the atom's exact data."""
    e = o.exact
    w = [Fr(xi) - ci for xi, ci in zip(x, e["c"])]
    quad = sum(wi * qij * wj for wi, row in zip(w, e["Q"]) for qij, wj in zip(row, w))
    return quad / 2 + sum(qi * Fr(xi) for qi, xi in zip(e["q"], x)) + e["const"]


# --------------------------------------------------------------------------- #
# expression lowering: centred at the exact minimiser
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("src, exact, points", [
    ("(x1 - 1e50)^2 + (x2 + 3e49)^2",
     lambda x: (x[0] - 10**50) ** 2 + (x[1] + 3 * 10**49) ** 2,
     [[1e50, -3e49], [1e50 + 2.0**120, -3e49], [1e50, -3e49 - 2.0**110]]),
    ("(x1 - 12345678.9)^2", lambda x: (x[0] - Fr("12345678.9")) ** 2,
     [[12345679.0], [12345678.0], [12345678.875]]),
    ("3*(x1 + x2 - 1e20)^2 + x1 - x2", lambda x: 3 * (x[0] + x[1] - 10**20) ** 2 + x[0] - x[1],
     [[5e19, 5e19], [5e19 + 2.0**20, 5e19], [1e20, 0.0]]),
    ("1e-12*(x1 - 0.1)^2 + x1", lambda x: Fr(1, 10**12) * (x[0] - Fr(1, 10)) ** 2 + x[0],
     [[1.0], [2.0], [4.0], [-5e11]]),
])
def test_expression_values_and_gradients_match_fractions(src, exact, points):
    """Each value within a few ulps of the magnitude of the user's own terms at the point
    (the square, the linear part), gradients likewise — far from the origin, and for a
    flat square whose minimum (−2.5e11 at −5e11) is far away (the centred form alone
    would lose 3e-5 at x = 1)."""
    f = rescon.cost(src)
    for x in points:
        xf = [Fr(v) for v in x]
        grad, curv = [], []
        for i in range(len(x)):  # a quadratic's exact gradient and curvature: differences
            e = [Fr(0)] * len(x)
            e[i] = Fr(1)
            up, down = exact([a + b for a, b in zip(xf, e)]), exact([a - b for a, b in zip(xf, e)])
            grad.append((up - down) / 2)
            curv.append(abs(up + down - 2 * exact(xf)))
        # the condition of f at x: an ulp of x moves f by |x|·|∇f|, ∇f by |x|·|Q|
        scale = abs(exact(xf)) + sum(abs(v * g) for v, g in zip(xf, grad))
        got = float(f.value([x])[0])
        assert abs(Fr(got) - exact(xf)) <= 1e-14 * scale, (src, x, got)
        for i, g in enumerate(f.subgradient([x])[0]):
            gscale = abs(grad[i]) + max(abs(v) for v in xf) * max(curv)
            assert abs(Fr(g) - grad[i]) <= 1e-14 * gscale, (src, x, i, g)


def test_lowered_quadratic_is_the_polynomial_exactly():
    """The centred data (c, r, f(c)) is the expression exactly (what redundancy and X*
    read): checked in Fractions at rational points."""
    rng = random.Random(5)
    src = "(x1 - 0.3)^2 + 2*(x1 + x2 - 7/3)^2 + x3 + 0.1*x2"
    o = rescon.cost(src)
    assert isinstance(o, atoms.Quadratic) and any(o.exact["c"])
    for _ in range(5):
        x = [Fr(rng.randint(-50, 50), rng.randint(1, 9)) for _ in range(3)]
        poly = ((x[0] - Fr(3, 10)) ** 2 + 2 * (x[0] + x[1] - Fr(7, 3)) ** 2 + x[2]
                + Fr(1, 10) * x[1])
        assert _exact_quadratic(o, x) == poly
    # r lies in null(Q) and c in range(Q) (the minimum-norm centre)
    Q, c, r = o.exact["Q"], o.exact["c"], o.exact["q"]
    assert all(sum(a * b for a, b in zip(row, r)) == 0 for row in Q)
    assert sum(a * b for a, b in zip(c, r)) == 0


def test_centre_beyond_floats_keeps_the_expanded_form():
    """1e-300·x² + 1e300·x has its minimiser at −5e599: not a float; the expansion at 0
    is kept (and is accurate near the origin)."""
    f = rescon.cost("1e-300*x1^2 + 1e300*x1")
    assert not f.c.any()
    assert f.value([[1.0]]).tolist() == [1e300]


def test_complete_square_exact():
    Q = [[Fr(2), Fr(2), Fr(0)], [Fr(2), Fr(2), Fr(0)], [Fr(0), Fr(0), Fr(0)]]
    q = [Fr(-4), Fr(-3), Fr(5)]
    c, r = atoms.complete_square(Q, q)
    Qc = [sum(a * b for a, b in zip(row, c)) for row in Q]
    assert [ri - qi for ri, qi in zip(r, q)] == Qc                       # q = r − Qc
    assert all(sum(a * b for a, b in zip(row, r)) == 0 for row in Q)     # r ∈ null(Q)
    assert c == [Fr(7, 8), Fr(7, 8), Fr(0)] and r == [Fr(-1, 2), Fr(1, 2), Fr(5)]


# --------------------------------------------------------------------------- #
# Quadratic: the centred or the expanded form, per point
# --------------------------------------------------------------------------- #


def test_quadratic_with_far_negative_minimum_is_accurate_near_origin():
    """1e-12(x + 5e11)² − 2.5e11 ≈ 1e-12x² + x (exactly, for the float data, plus a
    constant −5.03e-6): at x = 1..4 the centred form cancels 2.5e11 against 2.5e11 (error
    ~3e-5); the expanded form is exact to an ulp."""
    o = atoms.Quadratic([[2e-12]], c=[-5e11], const=-2.5e11)
    X = [[1.0], [2.0], [3.0], [4.0]]
    for x, v, g in zip(X, o.value(X), o.subgradient(X)[:, 0]):
        assert abs(Fr(v) - _exact_quadratic(o, x)) <= 1e-15 * x[0]
        assert abs(Fr(g) - Fr(2e-12) * (Fr(x[0]) + Fr(5e11))) <= 1e-15
    st = atoms.Stacked([o, atoms.Quadratic([[2.0]], c=[1e150])])
    vals = st.value(np.array([[2.0], [1e150]]), np.array([0, 1]))
    assert abs(Fr(vals[0]) - _exact_quadratic(o, [2.0])) <= 1e-15 and vals[1] == 0.0
    pairs = st.value_pairs(np.array([[3.0]]))
    assert abs(Fr(pairs[0, 0]) - _exact_quadratic(o, [3.0])) <= 1e-15


def test_quadratic_far_centre_is_exact_at_the_centre():
    c = [1e150, -1e150]
    o = atoms.Quadratic([[2.0, 1.0], [1.0, 2.0]], c=c, q=[0.0, 0.0], const=0.0)
    assert o.value([c]).tolist() == [0.0] and o.subgradient([c]).tolist() == [[0.0, 0.0]]


# --------------------------------------------------------------------------- #
# the merged global cost: exact collapse, against Fractions
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("scale", [1.0, 1e8, 1e50, 1e150])
def test_merged_quadratics_match_fractions(scale):
    """Σ w_j f_j of Quadratic / Affine terms with centres at ``scale`` (some Hessians
    singular) against exact Fractions at X* and around it: within a few ulps of
    Σ w_j |f_j|, and F(X*) exact when it is 0 in floats' reach."""
    rng = np.random.default_rng(int(np.log10(scale)))
    d, terms = 3, []
    centre = scale * rng.uniform(-1, 1, d)
    for j in range(6):
        L = rng.integers(-3, 4, size=(d, 2 if j % 2 else d)).astype(float)
        Q = L @ L.T  # exactly PSD (integers), singular for odd j
        terms.append((float(rng.integers(1, 4)),
                      atoms.Quadratic(Q, c=centre + rng.normal(size=d) * scale * 1e-3)))
    terms.append((2.0, atoms.Scaled(0.5, atoms.Quadratic(np.eye(d), c=centre))))
    M = atoms.Merged(terms, d)
    H = [[sum(Fr(w) * o.exact["Q"][i][k] for w, o in _flat(terms)) for k in range(d)]
         for i in range(d)]
    lin = [sum(Fr(w) * (o.exact["q"][i] - sum(a * b for a, b in zip(o.exact["Q"][i],
                                                                     o.exact["c"])))
               for w, o in _flat(terms)) for i in range(d)]
    xstar = _solve(H, [-v for v in lin])
    pts = [[float(v) for v in xstar]]
    pts += [[float(v) + s * scale * t for v, t in zip(xstar, rng.normal(size=d))]
            for s in (1e-12, 1e-6, 1.0)]
    for x in pts:
        fs = [Fr(w) * _exact_quadratic(o, x) for w, o in _flat(terms)]
        got = M.value([x])[0]
        assert abs(Fr(got) - sum(fs)) <= 1e-14 * sum(abs(v) for v in fs) + 1e-300, (x, got)


def _flat(terms):
    out = []
    for w, o in terms:
        out.append((w * o.coef, o.term) if isinstance(o, atoms.Scaled) else (w, o))
    return out


def _solve(H, b):
    from rescon.geometry.exact import solve_exact

    return solve_exact(H, b)


def test_merged_affine_only_and_far_flat_quadratic_rmdo_metric():
    """Affine terms alone collapse (H = 0); a flat quadratic plus a linear term keeps the
    cost metric exact to ~1e-15 relative (V22 measured 1.2e-4 before)."""
    M = atoms.Merged([(1.0, atoms.Affine([1.0, -2.0], 0.5)), (3.0, atoms.Affine([0.0, 1.0]))], 2)
    assert M.value([[1.0, 1.0]]).tolist() == [2.5]
    assert M.subgradient([[1.0, 1.0]]).tolist() == [[1.0, 1.0]]
    M = atoms.Merged([(4.0, rescon.cost("1e-12*(x1 - 0.1)^2 + x1"))], 1)
    for x in (1.0, 2.0, 3.0):
        exact = 4 * (Fr(1, 10**12) * (Fr(x) - Fr(1, 10)) ** 2 + Fr(x))
        assert abs(Fr(M.value([[x]])[0]) - exact) <= 1e-14 * exact
        assert abs(M.subgradient([[x]])[0, 0] - 4 * (1 + 2e-12 * (x - 0.1))) <= 1e-14


# --------------------------------------------------------------------------- #
# complex answers are refused
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("pair, vectorised", [
    ((lambda z: 1.0 + 0j, lambda z: [0.0, 0.0]), False),
    ((lambda z: np.complex128(2.0), lambda z: [0.0, 0.0]), False),
    ((lambda z: 1.0, lambda z: np.array([1 + 1j, 0.0])), False),
    ((lambda z: 1.0, lambda z: [0j, 0.0]), False),
    ((lambda Z: np.ones(len(Z)) * (1 + 1j), lambda Z: np.zeros(Z.shape)), True),
    ((lambda Z: np.ones(len(Z)), lambda Z: np.zeros(Z.shape) + 1j), True),
])
def test_complex_answers_are_input_errors(pair, vectorised):
    f = rescon.cost(pair, vectorised=vectorised)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning: refused before any cast
        with pytest.raises(InputError, match="not a real array"):
            f.value([[0.0, 0.0]])
            f.subgradient([[0.0, 0.0]])


def test_real_answers_still_accepted():
    f = rescon.cost((lambda z: [1], lambda z: (1, 2)))
    assert f.value([[0.0, 0.0]]).tolist() == [1.0]
    assert f.subgradient([[0.0, 0.0]]).tolist() == [[1.0, 2.0]]
    g = rescon.cost((lambda z: 1.0, lambda z: [[1.0, 2.0], [3.0]]))
    with pytest.raises(InputError, match="not a real array"):
        g.subgradient([[0.0, 0.0]])


# --------------------------------------------------------------------------- #
# nesting depth
# --------------------------------------------------------------------------- #


def _nested_call(depth: int, fn, *args):
    """fn(*args) from ``depth`` extra Python frames (a caller deep in its own stack)."""
    return fn(*args) if depth == 0 else _nested_call(depth - 1, fn, *args)


@pytest.mark.parametrize("make", [
    lambda k: "(" * k + "x1" + ")" * k + "^2",
    lambda k: "max(" * k + "x1" + ", 1)" * k,
    lambda k: "-" * k + "x1^2" if k % 2 == 0 else "-" * (k - 1) + "x1^2",
    lambda k: "x1" + "^1" * k,
    lambda k: "pos(" * k + "x1^2" + ")" * k,
])
def test_nesting_up_to_the_limit_works_beyond_is_one_line(make):
    f = _nested_call(150, rescon.cost, make(MAX_DEPTH - 2))
    v = f.value([[3.0]])[0]
    assert v in (3.0, 9.0)
    f.subgradient([[3.0]])
    for k in (MAX_DEPTH + 1, 5000):
        with pytest.raises(InputError, match="nests more than 100 levels") as exc:
            _nested_call(150, rescon.cost, make(k))
        assert "\n" not in str(exc.value)


def test_cli_deep_expression_is_exit_2(tmp_path):
    p = tmp_path / "deep.toml"
    p.write_text("[scenario]\nF = 0\nsteps = 2\ncheck_robustness = false\n[graph]\n"
                 "edges = [[0, 1], [1, 0]]\n[initial]\n0 = [0.0]\n1 = [1.0]\n[costs]\n"
                 f'0 = "{"(" * 400}x1{")" * 400}^2"\n1 = "x1^2"\n')
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        rc = cli_main(["rmdo", str(p), "--json", "-q"])
    assert rc == 2 and out.getvalue() == ""
    assert len(err.getvalue().strip().splitlines()) == 1 and "nests more" in err.getvalue()


# --------------------------------------------------------------------------- #
# CasADi: the symbol found from the expression
# --------------------------------------------------------------------------- #


def test_casadi_symbol_found_or_asked_for():
    ca = pytest.importorskip("casadi")
    x = ca.MX.sym("x", 3)
    f = rescon.cost(ca.norm_2(x[:2]) + x[2] ** 2)          # uses all of the MX vector
    assert f.d == 3 and f.value([[3.0, 4.0, 1.0]]).tolist() == [6.0]
    g = rescon.cost(ca.exp(x[0]))                           # the AD path; d from the symbol
    assert g.d == 3 and g.value([[0.0, 5.0, 5.0]]).tolist() == [1.0]
    z = ca.SX.sym("z")
    assert rescon.cost(ca.fabs(z) + z**2).value([[-2.0]]).tolist() == [6.0]
    y = ca.SX.sym("y", 2)
    with pytest.raises(InputError, match=r"2 symbols \(y_0, y_1\).*give the CasADi symbol"):
        rescon.cost(ca.sumsqr(y))
    assert rescon.cost(ca.sumsqr(y), x=y).value([[1.0, 2.0]]).tolist() == [5.0]
    with pytest.raises(InputError, match=r"2 symbols \(x, a\)"):
        rescon.cost(ca.sumsqr(x) + ca.MX.sym("a") ** 2)
    with pytest.raises(InputError, match="no symbol"):
        rescon.cost(ca.MX(3.0))
