"""Subgradient oracles (issue 11 §2): atoms, expressions, callables, CasADi, CVXPY.

Every adapter is measured with check_subgradient at kinks (0 for norms, ties for max,
the hinge corner) and every oracle kind must agree with the others on the same
function.
"""

from __future__ import annotations

import doctest
import importlib
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rescon
from rescon.errors import InputError
from rescon.optim import atoms, casadi_adapter, cvxpy_adapter
from rescon.optim.oracle import CallableOracle, Oracle

ca = pytest.importorskip("casadi")
cp = pytest.importorskip("cvxpy")

TOL = 1e-9

# points with kinks of the test functions: 0, ties x1 = x2, x1 = -x2, axes
KINKS = np.array([[0.0, 0.0], [1.0, 1.0], [-2.0, -2.0], [1.0, -1.0], [0.0, 3.0], [-3.0, 0.0],
                  [1.0, 0.5], [0.3, -0.7]])


def valid(o, P=KINKS, samples=64) -> bool:
    """check_subgradient ≤ rounding relative to the values' scale."""
    scale = 1.0 + np.abs(o.value(P)).max()
    return rescon.check_subgradient(o, P, samples=samples) <= TOL * scale * 100


# --------------------------------------------------------------------------- #
# atoms
# --------------------------------------------------------------------------- #

A2 = np.array([[1.0, 2.0], [-1.0, 0.5], [0.0, 1.0]])
ATOMS = {
    "quadratic": atoms.Quadratic([[2.0, 1.0], [1.0, 2.0]], c=[1.0, -1.0], q=[0.5, 0.0],
                                 const=3.0),
    "affine": atoms.Affine([1.0, -2.0], 0.5),
    "abs": atoms.AbsAffine([1.0, 1.0], 0.0),
    "norm1": atoms.Norm1(A2, [0.0, 0.0, 0.0]),
    "norm2": atoms.Norm2(np.eye(2)),
    "norm2-A": atoms.Norm2(A2, [1.0, 0.0, 0.0]),
    "norminf": atoms.NormInf(np.eye(2)),
    "maxaffine": atoms.MaxAffine([[1.0, 0.0], [0.0, 1.0], [-1.0, -1.0]], [0.0, 0.0, 0.0]),
    "hinge": atoms.Hinge([1.0, -1.0], 0.0),
    "huber": atoms.Huber(A2, [0.0, 1.0, 0.0], 0.5),
    "logsumexp": atoms.LogSumExp(A2, [0.0, 1.0, -1.0]),
    "sum": atoms.Sum([atoms.Norm2(np.eye(2)), atoms.AbsAffine([1.0, -1.0], 0.0)]),
    "scaled": atoms.Scaled(2.5, atoms.NormInf(np.eye(2))),
    "maxof": atoms.MaxOf([atoms.Norm2(np.eye(2)), atoms.Quadratic(np.eye(2))]),
}


@pytest.mark.parametrize("name", sorted(ATOMS))
def test_atom_subgradients_valid_at_kinks(name):
    assert valid(ATOMS[name])


def test_atom_minimum_norm_conventions_at_kinks():
    z = np.zeros((1, 2))
    assert np.array_equal(atoms.Norm2(np.eye(2)).subgradient(z), [[0.0, 0.0]])
    assert np.array_equal(atoms.AbsAffine([1.0, 1.0]).subgradient(z), [[0.0, 0.0]])
    assert np.array_equal(atoms.Norm1(np.eye(2)).subgradient([[0.0, 2.0]]), [[0.0, 1.0]])
    assert np.array_equal(atoms.Hinge([1.0, -1.0]).subgradient(z), [[0.0, 0.0]])
    # ties: the mean of the active pieces (minimum norm for A = I)
    assert np.array_equal(atoms.NormInf(np.eye(2)).subgradient([[1.0, -1.0]]), [[0.5, -0.5]])
    assert np.array_equal(atoms.NormInf(np.eye(2)).subgradient(z), [[0.0, 0.0]])
    mx = atoms.MaxAffine(np.eye(2), [0.0, 0.0])
    assert np.array_equal(mx.subgradient([[1.0, 1.0]]), [[0.5, 0.5]])


def test_atom_data_and_structure_flags():
    q = ATOMS["quadratic"]
    assert q.quadratic and not q.polyhedral and q.Q.tolist() == [[2.0, 1.0], [1.0, 2.0]]
    for name in ("abs", "norm1", "norminf", "maxaffine", "hinge", "affine"):
        assert ATOMS[name].polyhedral, name
    for name in ("norm2", "huber", "logsumexp", "sum", "maxof"):
        assert not ATOMS[name].polyhedral and not ATOMS[name].quadratic, name
    assert atoms.Sum([atoms.AbsAffine([1.0, 0.0]), atoms.MaxAffine(np.eye(2))]).polyhedral
    assert atoms.Sum([atoms.Quadratic(np.eye(2)), atoms.Affine([1.0, 0.0])]).quadratic


def test_quadratic_psd_decided_exactly():
    # eigenvalues 0 and 2 + 2e-17·…: a float test with a tolerance would accept both
    with pytest.raises(InputError, match="positive semidefinite"):
        atoms.Quadratic([[1.0, 1.0 + 2**-52], [1.0 + 2**-52, 1.0]])
    atoms.Quadratic([[1.0, 1.0], [1.0, 1.0]])  # singular PSD is fine


def test_norm2_does_not_underflow_or_overflow():
    o = atoms.Norm2(np.eye(2))
    g = o.subgradient([[3e-200, 4e-200], [3e200, 4e200]])
    assert np.allclose(g, [[0.6, 0.8], [0.6, 0.8]])
    assert np.allclose(o.value([[3e-200, 4e-200]]), [5e-200], rtol=1e-15, atol=0)


@settings(max_examples=30, deadline=None)
@given(st.integers(1, 4), st.integers(1, 4), st.integers(0, 2**32 - 1))
def test_random_affine_atoms_valid(m, d, seed):
    rng = np.random.default_rng(seed)
    A = rng.integers(-3, 4, size=(m, d)).astype(float)
    b = rng.integers(-2, 3, size=m).astype(float)
    # points on the kinks: solutions of subsets of A x = b, plus random ones
    P = [np.linalg.lstsq(A[:k], b[:k], rcond=None)[0] for k in range(1, m + 1)]
    P = np.vstack(P + [rng.standard_normal(d), np.zeros(d)])
    for o in (atoms.Norm1(A, b), atoms.Norm2(A, b), atoms.NormInf(A, b), atoms.MaxAffine(A, b),
              atoms.Huber(A, b, 1.5), atoms.LogSumExp(A, b), atoms.Hinge(A[0], b[0]),
              atoms.AbsAffine(A[0], b[0])):
        assert valid(o, P, samples=32), type(o).__name__


# --------------------------------------------------------------------------- #
# check_subgradient can fail
# --------------------------------------------------------------------------- #


def test_check_subgradient_reports_a_wrong_subgradient():
    bad = rescon.cost((lambda z: float(np.abs(z).sum()), lambda z: np.sign(z) + 0.5), d=2)
    assert rescon.check_subgradient(bad, KINKS) > 0.1
    good = rescon.cost((lambda z: float(np.abs(z).sum()), np.sign), d=2)
    assert valid(good)
    with pytest.raises(InputError, match="at least one point"):
        rescon.check_subgradient(good, np.zeros((0, 2)))
    with pytest.raises(InputError, match="samples must be an integer >= 1"):
        rescon.check_subgradient(good, KINKS, samples=0)


# --------------------------------------------------------------------------- #
# every kind agrees with the others
# --------------------------------------------------------------------------- #

FUNCTIONS = {
    # name: (expression string, casadi builder, cvxpy builder, numpy value)
    "norm2": ("norm2(x1, x2)", lambda x: ca.norm_2(x), lambda x: cp.norm(x, 2),
              lambda Z: np.hypot(Z[:, 0], Z[:, 1])),
    "sqrt-sos": ("sqrt(x1^2 + x2^2)", lambda x: ca.sqrt(x[0] ** 2 + x[1] ** 2),
                 lambda x: cp.norm(cp.hstack([x[0], x[1]]), 2),
                 lambda Z: np.hypot(Z[:, 0], Z[:, 1])),
    "norm1": ("abs(x1) + abs(x2)", lambda x: ca.norm_1(x), lambda x: cp.norm1(x),
              lambda Z: np.abs(Z).sum(axis=1)),
    "norminf": ("norminf(x1, x2)", lambda x: ca.norm_inf(x), lambda x: cp.norm_inf(x),
                lambda Z: np.abs(Z).max(axis=1)),
    "max": ("max(x1, x2)", lambda x: ca.fmax(x[0], x[1]), lambda x: cp.max(x),
            lambda Z: Z.max(axis=1)),
    "hinge": ("pos(x1 - x2)", lambda x: ca.fmax(x[0] - x[1], 0), lambda x: cp.pos(x[0] - x[1]),
              lambda Z: np.maximum(Z[:, 0] - Z[:, 1], 0)),
    "abs-sum": ("abs(x1 + x2)", lambda x: ca.fabs(x[0] + x[1]), lambda x: cp.abs(cp.sum(x)),
                lambda Z: np.abs(Z.sum(axis=1))),
    "quadratic": ("(x1 - 1)^2 + (x2 - 0.5)^2", lambda x: (x[0] - 1) ** 2 + (x[1] - 0.5) ** 2,
                  lambda x: cp.sum_squares(x - np.array([1.0, 0.5])),
                  lambda Z: (Z[:, 0] - 1) ** 2 + (Z[:, 1] - 0.5) ** 2),
    "huber": ("huber(x1 - 2*x2, 0.5)", lambda x: _ca_huber(x[0] - 2 * x[1], 0.5),
              lambda x: cp.huber(x[0] - 2 * x[1], 0.5),
              lambda Z: _np_huber(Z[:, 0] - 2 * Z[:, 1], 0.5)),
    "logsumexp": ("logsumexp(x1, x2)", lambda x: ca.log(ca.exp(x[0]) + ca.exp(x[1])),
                  lambda x: cp.log_sum_exp(x), lambda Z: np.logaddexp(Z[:, 0], Z[:, 1])),
    "mixed": ("x1^2 + x2^2 + abs(x1 - x2) + 2*max(abs(x1), abs(x2))",
              lambda x: ca.sumsqr(x) + ca.fabs(x[0] - x[1]) + 2 * ca.norm_inf(x),
              lambda x: cp.sum_squares(x) + cp.abs(x[0] - x[1]) + 2 * cp.norm_inf(x),
              lambda Z: (Z**2).sum(1) + np.abs(Z[:, 0] - Z[:, 1]) + 2 * np.abs(Z).max(1)),
}


def _ca_huber(u, M):
    return ca.if_else(ca.fabs(u) <= M, u**2, 2 * M * ca.fabs(u) - M**2)


def _np_huber(u, M):
    a = np.abs(u)
    return np.where(a <= M, a * a, 2 * M * a - M**2)


def _kinds(name):
    src, ca_f, cp_f, np_f = FUNCTIONS[name]
    xs, xm, xv = ca.SX.sym("x", 2), ca.MX.sym("x", 2), cp.Variable(2)
    ref = rescon.cost(src)
    return {
        "string": rescon.cost(src),
        "casadi-sx": rescon.cost(ca_f(xs), x=xs),
        "casadi-mx": rescon.cost(ca_f(xm), x=xm),
        "casadi-function": rescon.cost(ca.Function("f", [xm], [ca_f(xm)])),
        "cvxpy": rescon.cost(cp_f(xv), x=xv),
        "callable": rescon.cost((lambda z: float(np_f(z[None, :])[0]),
                                 lambda z: ref.subgradient(z[None, :])[0]), d=2),
        "vectorised": rescon.cost((np_f, ref.subgradient), d=2, vectorised=True),
    }


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_every_kind_agrees_and_is_valid(name):
    P = np.vstack([KINKS, np.random.default_rng(1).normal(scale=3, size=(8, 2))])
    expected = FUNCTIONS[name][3](P)
    for kind, o in _kinds(name).items():
        assert np.allclose(o.value(P), expected, rtol=1e-12, atol=1e-12), kind
        assert valid(o, P), kind


def test_casadi_and_cvxpy_paths():
    x = ca.SX.sym("x", 2)
    assert rescon.cost(ca.norm_2(x), x=x).path == "lowered"
    assert rescon.cost(ca.logsumexp(x), x=x).path == "lowered"  # max-shifted form
    assert rescon.cost(ca.exp(x[0]) + ca.norm_2(x), x=x).path == "ad"
    v = cp.Variable(2)
    assert rescon.cost(cp.norm_inf(v)).path == "lowered"  # CVXPY has no .grad for it
    mixed = rescon.cost(cp.exp(v[0]) + cp.norm_inf(v))
    assert mixed.path == "mixed" and mixed.grad_terms == [str(cp.exp(v[0]))]
    assert rescon.cost(cp.exp(v[0])).path == "grad"
    assert valid(mixed) and valid(rescon.cost(cp.exp(v[0])))


def test_casadi_ad_is_nan_at_the_kink_and_the_adapter_repairs_it():
    x = ca.SX.sym("x", 2)
    f = ca.exp(x[0]) + ca.norm_2(x)  # exp keeps it on the AD path
    raw = ca.Function("g", [x], [ca.jacobian(f, x)])
    assert np.isnan(np.asarray(raw([0.0, 0.0]))).all()  # the CasADi behaviour
    o = rescon.cost(f, x=x)
    g = o.subgradient(np.zeros((1, 2)))
    assert np.isfinite(g).all() and valid(o)
    assert 0 <= o.kink_error < 1e-12
    assert o.value(np.zeros((0, 2))).shape == (0,) and o.subgradient(np.zeros((0, 2))).shape \
        == (0, 2)


def test_lowered_casadi_norm_at_zero_is_the_minimum_norm_element():
    x = ca.MX.sym("x", 3)
    o = rescon.cost(ca.norm_2(x - np.array([1.0, 2.0, 3.0])), x=x)
    assert o.path == "lowered"
    assert np.array_equal(o.subgradient([[1.0, 2.0, 3.0]]), [[0.0, 0.0, 0.0]])


def test_cvxpy_grad_path_restores_the_variable_value():
    v = cp.Variable(2)
    v.value = np.array([7.0, 8.0])
    o = rescon.cost(cp.exp(v[0]) + cp.exp(v[1]))
    o.subgradient(KINKS)
    assert v.value.tolist() == [7.0, 8.0]


# --------------------------------------------------------------------------- #
# bad input
# --------------------------------------------------------------------------- #


def test_callable_oracle_bad_outputs_are_named():
    nan = rescon.cost((lambda z: float("nan"), lambda z: z), d=2, name="cost of agent 3")
    with pytest.raises(InputError, match=r"cost of agent 3: value is not finite .* point \[1"):
        nan.value([[1.0, 2.0]])
    shape = rescon.cost((lambda Z: Z.sum(1), lambda Z: Z[:, :1]), d=2, vectorised=True)
    with pytest.raises(InputError, match=r"subgradient of 3 point\(s\) returned shape \(3, 1\)"):
        shape.subgradient(np.ones((3, 2)))
    inf = rescon.cost((lambda z: 0.0, lambda z: np.array([np.inf, 0.0])), d=2)
    with pytest.raises(InputError, match="subgradient is not finite"):
        inf.subgradient([[0.0, 0.0]])
    wrong = rescon.cost((lambda z: 0.0, lambda z: np.zeros(3)), d=2)
    with pytest.raises(InputError, match=r"returned shape \(3,\)"):
        wrong.subgradient([[0.0, 0.0]])


def test_dimension_errors():
    o = rescon.cost("x1 + x2")
    assert o.value(np.zeros((0, 2))).shape == (0,)  # an empty batch is fine
    with pytest.raises(InputError, match=r"\(B, 2\) array; got shape \(1, 3\)"):
        o.value([[1.0, 2.0, 3.0]])
    with pytest.raises(InputError, match="finite"):
        o.value([[1.0, np.nan]])
    with pytest.raises(InputError, match="must be a real"):
        o.value(np.array([[1.0, 1j]]))
    with pytest.raises(InputError, match="x3 is used but d = 2"):
        rescon.cost("x3", d=2)
    x = ca.SX.sym("x", 3)
    with pytest.raises(InputError, match="dimension 3, not d = 2"):
        rescon.cost(ca.norm_2(x), x=x, d=2)
    with pytest.raises(InputError, match="dimension 2, not d = 4"):
        rescon.cost(cp.norm(cp.Variable(2)), d=4)
    with pytest.raises(InputError, match="cannot make a cost of list"):
        rescon.cost([1, 2])
    with pytest.raises(InputError, match="d must be an integer"):
        rescon.cost("x1", d=0)


def test_nonconvex_casadi_and_cvxpy_are_refused():
    x = ca.SX.sym("x", 2)
    with pytest.raises(InputError, match="not convex"):
        rescon.cost(x[0] * x[1], x=x)
    with pytest.raises(InputError, match="give the CasADi symbol"):
        rescon.cost(ca.norm_2(x))
    v = cp.Variable(2)
    with pytest.raises(InputError, match="cost of agent 5: the CVXPY cost is not DCP-convex"):
        rescon.cost(-cp.norm(v), name="cost of agent 5")
    with pytest.raises(InputError, match="variables other than x"):
        rescon.cost(cp.norm(v) + cp.norm(cp.Variable(2)), x=v)


def test_oracles_pass_through_and_protocol_objects_are_checked():
    o = ATOMS["norm2"]
    assert rescon.cost(o) is o

    class Duck:
        d = 2

        def value(self, Z):
            return np.zeros(len(Z))

        def subgradient(self, Z):
            return np.full(np.shape(Z), np.nan)

    duck = rescon.cost(Duck())
    assert isinstance(duck, Oracle) and isinstance(duck, CallableOracle)
    with pytest.raises(InputError, match="not finite"):
        duck.subgradient([[0.0, 0.0]])


@pytest.mark.parametrize("name", ["rescon.optim.oracle", "rescon.optim.cost",
                                  "rescon.optim.paper"])
def test_docstring_examples(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0 and result.attempted > 0


@pytest.mark.parametrize("module, make", [
    ("casadi", lambda: casadi_adapter.casadi_cost(ca.SX.sym("x"))),
    ("cvxpy", lambda: cvxpy_adapter.cvxpy_cost(cp.Variable())),
])
def test_missing_package_raises_the_registry_error(monkeypatch, module, make):
    from rescon.models import backends

    real = importlib.util.find_spec
    monkeypatch.setattr(backends.importlib.util, "find_spec",
                        lambda name, *a: None if name == module else real(name, *a))
    with pytest.raises(rescon.SolverNotFound, match=f"backend '{module}' is not installed"):
        make()


@settings(max_examples=15, deadline=None)
@given(st.integers(1, 3), st.integers(1, 3), st.integers(0, 2**32 - 1))
def test_random_residual_norms_agree_across_kinds(m, d, seed):
    """‖Ax − b‖ (1, 2, ∞) and max(Ax + b) from atoms, CasADi (lowered) and CVXPY
    (lowered): equal values, valid subgradients at the kinks A x = b."""
    rng = np.random.default_rng(seed)
    A = rng.integers(-3, 4, size=(m, d)).astype(float)
    b = rng.integers(-2, 3, size=m).astype(float)
    P = np.vstack([np.linalg.lstsq(A, b, rcond=None)[0], np.zeros(d),
                   rng.normal(size=(3, d))])
    xs, xv = ca.SX.sym("x", d), cp.Variable(d)
    r_ca, r_cp = ca.mtimes(A, xs) - b, A @ xv - b
    for atom, e_ca, e_cp in (
            (atoms.Norm1(A, b), ca.norm_1(r_ca), cp.norm1(r_cp)),
            (atoms.Norm2(A, b), ca.norm_2(r_ca), cp.norm(r_cp, 2)),
            (atoms.NormInf(A, b), ca.norm_inf(r_ca), cp.norm_inf(r_cp)),
            (atoms.MaxAffine(A, b), ca.mmax(ca.mtimes(A, xs) + b), cp.max(A @ xv + b))):
        ref = atom.value(P)
        for o in (rescon.cost(e_ca, x=xs), rescon.cost(e_cp, x=xv)):
            assert o.path == "lowered"
            assert np.allclose(o.value(P), ref, rtol=1e-12, atol=1e-12)
            assert valid(o, P, samples=16)


# --------------------------------------------------------------------------- #
# the stacked and merged fast paths of rescon.rmdo (issue 11)
# --------------------------------------------------------------------------- #


def like(o, rng):
    """An atom of ``o``'s structure (classes, shapes) with random data in quarter
    integers, so that kinks and ties at quarter-integer points are exact."""
    def r(*shape):
        return rng.integers(-8, 9, size=shape) / 4

    if isinstance(o, atoms.Quadratic):
        M = r(2, 2)
        return atoms.Quadratic(M @ M.T, c=r(2), q=r(2), const=r(1)[0])
    if isinstance(o, (atoms.Affine, atoms.AbsAffine, atoms.Hinge)):
        return type(o)(r(2), r(1)[0])
    if isinstance(o, atoms.Huber):
        return atoms.Huber(r(*o.A.shape), r(len(o.b)), 1 + rng.integers(0, 4) / 4)
    if isinstance(o, (atoms.Norm1, atoms.Norm2, atoms.NormInf, atoms.MaxAffine,
                      atoms.LogSumExp)):
        return type(o)(r(*o.A.shape), r(len(o.b)))
    if isinstance(o, atoms.Scaled):
        return atoms.Scaled(rng.integers(0, 5) / 2, like(o.term, rng))
    return type(o)([like(t, rng) for t in o.terms])


@pytest.mark.parametrize("name", sorted(ATOMS))
def test_stacked_atoms_agree_with_their_own_calls_kinks_included(name):
    """Row b evaluated with member idx[b]'s data = that member's own value and
    subgradient at z_b, to the rounding of the last dot product (A_bᵀw by einsum, not
    matmul); quarter-integer data and points make the residuals exact, so kinks and
    ties are decided alike: a different convention would differ by ≥ 1/8, not 1e-14."""
    rng = np.random.default_rng(sorted(ATOMS).index(name))
    members = [ATOMS[name]] + [like(ATOMS[name], rng) for _ in range(5)]
    Z = np.vstack([KINKS, rng.integers(-8, 9, size=(40, 2)) / 4])
    Z = np.repeat(Z, 3, axis=0)
    idx = rng.integers(0, len(members), size=len(Z))
    stacked = atoms.Stacked(members)
    own_v = np.array([members[i].value(z[None])[0] for i, z in zip(idx, Z)])
    own_g = np.vstack([members[i].subgradient(z[None]) for i, z in zip(idx, Z)])
    np.testing.assert_allclose(stacked.value(Z, idx), own_v, rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(stacked.subgradient(Z, idx), own_g, rtol=0, atol=1e-14)


def test_stacked_needs_one_signature_of_library_atoms():
    assert atoms.signature(ATOMS["norm2"]) != atoms.signature(ATOMS["norm2-A"])
    with pytest.raises(InputError, match="one signature"):
        atoms.Stacked([ATOMS["norm2"], ATOMS["norm2-A"]])
    mixed = atoms.Sum([ATOMS["abs"], rescon.cost((np.sum, np.ones_like), d=2)])
    assert atoms.signature(mixed) is None


def test_merged_sum_equals_the_weighted_sum_of_its_terms():
    """Merged(Σ w_j f_j): quadratics collapsed, rows stacked, atoms stacked by
    signature, other oracles called — values and subgradients equal to rounding."""
    rng = np.random.default_rng(5)
    terms = [(float(rng.integers(1, 4)), like(ATOMS[n], rng)) for n in sorted(ATOMS)
             for _ in range(3)]
    terms += [(2.0, rescon.cost((lambda z: float(z @ z), lambda z: 2 * z), d=2)),
              (0.5, atoms.Scaled(3.0, atoms.Sum([ATOMS["quadratic"], ATOMS["norm1"]])))]
    merged = atoms.Merged(terms, 2)
    Z = np.vstack([KINKS, rng.normal(size=(30, 2)) * 5])
    v = sum(w * o.value(Z) for w, o in terms)
    scale = sum(w * np.abs(o.value(Z)) for w, o in terms)
    assert np.all(np.abs(merged.value(Z) - v) <= 1e-13 * scale)
    G = sum(w * o.subgradient(Z) for w, o in terms)
    np.testing.assert_allclose(merged.subgradient(Z), G, rtol=1e-12, atol=1e-12 * scale.max())
    assert valid(merged)


def test_merged_quadratic_part_that_overflows_is_evaluated_term_by_term():
    big = atoms.Quadratic(np.eye(2) * 1e308)
    merged = atoms.Merged([(4.0, big), (1.0, ATOMS["abs"])], 2)
    Z = np.array([[1e-3, 0.0], [0.0, -2e-3]])
    np.testing.assert_allclose(merged.value(Z), 4 * big.value(Z) + ATOMS["abs"].value(Z),
                               rtol=1e-15)


def test_merged_quadratics_are_centred_so_nothing_cancels_near_the_minimiser():
    """Σ ½‖x − c_j‖² with c_j ≈ 10⁶: expanded as ½xᵀHx + gᵀx + C, F(x*) ≈ 10³ would be
    the difference of numbers ≈ 10¹⁵ (error ≈ 0.1); centred at the minimiser it is
    accurate to rounding of F itself."""
    rng = np.random.default_rng(2)
    terms = [(1.0, atoms.Quadratic(np.eye(2), 1e6 + rng.uniform(0, 2, 2))) for _ in range(500)]
    merged = atoms.Merged(terms, 2)
    Z = np.mean([o.c for _, o in terms], axis=0)[None] + rng.normal(size=(5, 2)) * 1e-3
    exact = [math.fsum(float(o.value(z[None])[0]) for _, o in terms) for z in Z]
    np.testing.assert_allclose(merged.value(Z), exact, rtol=1e-12)
