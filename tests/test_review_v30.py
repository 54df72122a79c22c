"""V30: hostile review of the changes since 22bf8d9.

Attacked:

* ``check_point`` (``target=`` of kernel_point / kernel_points and ``SafeKernel.contains``):
  lists, tuples, 0-d arrays, numpy scalars (float32, int64, bool_, longdouble), float32 /
  longdouble arrays, ints around 2^53, bools, None, ragged lists, pandas Series.
* ``check_choice``: unknown / wrong-capability backends and methods on one-point and
  empty kernels, before any data.
* ``rescon.models`` ``_checked`` / ``_scaled_target``: every backend of ``qp_backends()`` /
  ``lp_backends()`` on flat, thin, far-off (1e300) and tiny (1e-300) polytopes, targets
  beyond the float range, polytopes whose frame is 0 (h ≡ 0: a point with k > 0, a cone
  at its apex), ``project_batch`` with ``on_failure`` "raise" / "nan"; chebyshev "auto"
  (Clarabel) on random kernels in R^1..R^3 at magnitudes 1e-300..1e300.
* RMDO ``GlobalCost`` (overflowing sums named, cancelling huge constants and huge finite
  costs accepted), ``CostMonitor.remeasure`` (block-wise, nothing copied without an
  improvement).
* ``Assumption3Report.check()`` on random periodic / explicit / random / mixed
  schedules, T_d None / inf / near 1, mu_d None, closed form (``_HORIZON_MAX_WINDOWS``
  monkeypatched to 0 and 3), tampered reports; ``min_mu_d_for`` closed form vs windows.

Bugs found (all fixed, markers removed): chebyshev "auto" (Clarabel only) refuses thin kernels
HiGHS decided (F = 1 kernel of V29's hexagon, 1.2e-9 thick: 'AlmostSolved');
``check_point`` turns numpy scalars into a TypeError
traceback (valid float32 / longdouble input refused); ``_checked`` refuses exact
answers when the polytope's frame is 0 (h ≡ 0); ``project_batch`` still computes the
target as B (y − o) (RuntimeWarning on overflow) and does not work in the unit frame
(a feasible but wrong point is returned for a 1e-300 polytope).
"""

from __future__ import annotations

import dataclasses
import math
import random
import warnings

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon import Scenario
from rescon.consensus import dos as dos_mod
from rescon.consensus.dos import DoSAttack, Explicit, Periodic, RandomDoS, check_assumption3
from rescon.errors import InputError, SolverError, SolverNotFound
from rescon.models import kernel_models as km

pytestmark = pytest.mark.filterwarnings("ignore:Assumption 5")

SQUARE = [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]]
X4 = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]


def _one_line_input_error(fn, name):
    with pytest.raises(InputError) as e:
        fn()
    msg = str(e.value)
    assert "\n" not in msg and name in msg, msg


# --------------------------------------------------------------------------- #
# check_point: targets and contains(x)
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("x", [[0.5, 0.5], (0.5, 0.5), np.array([0.5, 0.5]),
                               np.array([0.5, 0.5], dtype=np.float32), [[0.5, 0.5]],
                               [1, 0], np.array([0.5, 0.5], dtype=object)])
def test_contains_valid_inputs_still_work(x):
    K = rescon.safe_kernel(X4, 0)
    assert K.contains(x) is True or K.contains(x) == bool(K.contains(x))
    assert K.contains(x) == K.contains(np.asarray(x, dtype=float).reshape(-1))


def test_target_series_and_exact_ints_accepted():
    pd = pytest.importorskip("pandas")
    a, _ = rescon.kernel_point(X4, 0, target=pd.Series([3.0, 0.25]))
    b, _ = rescon.kernel_point(X4, 0, target=[3, 0.25])
    assert a.tolist() == b.tolist() == [1.0, 0.25]
    K = rescon.safe_kernel([[0.0], [2.0**53]], 0)
    assert K.contains([2**53]) and K.contains(np.int64(2**52))


@pytest.mark.parametrize("bad", [None, [[1.0, 2.0], [3.0]], [2**53 + 1, 0], [10**400, 0],
                                 [1 + 0j, 0], [float("inf"), 0], [1.0, 2.0, 3.0], {1: 2},
                                 ["a", "b"], []])
def test_bad_target_and_x_one_line_input_error(bad):
    if bad is not None:  # target=None is the points' mean
        _one_line_input_error(lambda: rescon.kernel_point(X4, 0, target=bad), "target")
    K = rescon.safe_kernel(X4, 0)
    _one_line_input_error(lambda: K.contains(bad), "x")


# Fixed (was a bug: check_point converts x to an object array, then Fraction(np.float32(0.5))
# raises TypeError (_validate.py:107/131))
def test_numpy_float32_scalars_in_a_list_accepted():
    K = rescon.safe_kernel(X4, 0)
    assert K.contains([np.float32(0.5), np.float32(0.5)]) is True


# Fixed (was a bug: a longdouble target that is exactly a float is a TypeError traceback (object
# array of np.longdouble → Fraction))
def test_longdouble_exact_target_accepted():
    x, _ = rescon.kernel_point(X4, 0, target=np.array([3.0, 0.25], dtype=np.longdouble))
    assert x.tolist() == [1.0, 0.25]


# Fixed (was a bug: np.bool_ in a target was a TypeError traceback). A target is
# validated like X: a mixed bool / float row is upcast to floats by numpy for X too
# (accepted), an all-boolean one is refused like an all-boolean X
def test_numpy_bool_target_like_x():
    x, _ = rescon.kernel_point(X4, 0, target=[np.True_, 0.5])
    y, _ = rescon.kernel_point(X4, 0, target=[1.0, 0.5])
    assert x.tolist() == y.tolist()
    with pytest.raises(InputError):
        rescon.safe_kernel([[True, False], [False, True], [True, True]], 0)
    _one_line_input_error(lambda: rescon.kernel_point(X4, 0, target=[True, False]),
                          "target")


# --------------------------------------------------------------------------- #
# check_choice
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("X,F", [(X4, 0), ([[1.0, 2.0]] * 3, 0), (X4, 3)])
def test_choice_resolved_before_data(X, F):
    with pytest.raises(SolverNotFound):
        rescon.kernel_point(X, F, backend="nope")
    with pytest.raises(InputError, match="backend='exact'"):
        rescon.kernel_points([X], F, method="chebyshev", backend="exact")
    with pytest.raises(SolverNotFound):
        rescon.kernel_point(X, F, method="chebyshev", backend="cvxpy:OSQP")
    with pytest.raises(InputError, match="method must be one of"):
        rescon.kernel_points([X], F, method=None)


# --------------------------------------------------------------------------- #
# rescon.models: _checked, _scaled_target, project_batch
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("backend", km.qp_backends())
def test_project_far_origin_flat_every_backend(backend):
    # the segment [1e300 − ?, …] × {0} × {5}: flat (k = 1 < d = 3), far off
    A = [[1.0, 0, 0], [-1.0, 0, 0]]
    x = km.project(A, [1e300 + 2.0**970, 2.0**970 - 1e300], [1e300, 0.0, 5.0],
                   [[1.0, 0, 0]], [1e300 + 2.0**972, 2.0, 1.0], backend=backend)
    assert abs(x[0] / (1e300 + 2.0**970) - 1) < 1e-6 and x[1:].tolist() == [0.0, 5.0]


@pytest.mark.parametrize("backend", km.lp_backends())
def test_chebyshev_thin_rectangle_every_backend(backend):
    c, r = km.chebyshev(SQUARE, [1, 1, 2.0**-40, 2.0**-40], [0.0, 0.0], np.eye(2),
                        backend=backend)
    # (SCS: radius 1.3e-11 for 9.1e-13, inside the 1e-9 asked of every solver)
    assert abs(c[1]) <= 2.0**-40 and 0 <= r <= 2.0**-40 + 1e-9


def test_target_beyond_frame_one_line_solver_error():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(SolverError) as e:
            km.project(SQUARE, [1e308 + 1, 1 - 1e308, 1, 1], [1e308, 0.0], np.eye(2),
                       [-1e308, 0.0])
    assert "\n" not in str(e.value) and "float range" in str(e.value)
    # far but inside the range: the right point or a one-line SolverError, never NaN
    for y in ([1e12, -1e12], [1.7e308, -1.7e308]):
        try:
            x = km.project(SQUARE, [1, 1, 1, 1], [0.0, 0.0], np.eye(2), y)
        except SolverError as exc:
            assert "\n" not in str(exc)
        else:
            assert np.allclose(x, [1.0, -1.0], atol=1e-6)


def test_wrong_backend_answer_refused_in_project_and_batch(monkeypatch):
    for name in ("clarabel", "highs"):
        monkeypatch.setitem(km._SOLVE_QP, name, lambda m, c, s: np.array([5.0, 0.0]))
    prob = (SQUARE, [1, 1, 1, 1], [0.0, 0.0], np.eye(2), [3.0, 0.0])
    with pytest.raises(SolverError, match="clarabel: reported optimal, but .* outside"):
        km.project(*prob)
    with pytest.raises(SolverError, match=r"problems\[1\]"):
        km.project_batch([(SQUARE, [1, 1, 1, 1], [0.0, 0.0], np.zeros((0, 2)), [0, 0]), prob],
                         backend="highs")
    out = km.project_batch([prob, prob], backend="highs", on_failure="nan")
    assert np.isnan(out).all()


# Fixed (was a bug: _checked's frame is max(|h|, |t|, 1e-300): with h ≡ 0 (a point with k = 2)
# Clarabel's exact-to-1.7e-14 answer is 'outside by 1 of its frame' (kernel_models.py:408))
def test_project_onto_zero_frame_polytope_not_refused():
    x = km.project(SQUARE, [0, 0, 0, 0], [0.0, 0.0], np.eye(2), [1.0, 1.0])
    assert np.abs(x).max() < 1e-9


# Fixed (was a bug: the cone x, y <= 0 at its apex: proxsuite's answer 4e-10 from (0, 0) refused
# (frame 4e-10), project_batch default)
def test_project_batch_cone_apex_not_refused():
    out = km.project_batch([([[1.0, 0.0], [0.0, 1.0]], [0, 0], [0.0, 0.0], np.eye(2),
                             [1.0, 1.0])])
    assert np.abs(out).max() < 1e-8


# Fixed (was a bug: project_batch still takes c = B (y − o) (kernel_models.py:289/380):
# RuntimeWarning 'overflow in subtract', then a solver status, not _scaled_target's one-line
# SolverError)
def test_project_batch_target_beyond_float_range_no_warning():
    prob = (SQUARE, [1e308 + 1, 1 - 1e308, 1, 1], [1e308, 0.0], np.eye(2), [-1e308, 0.0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(SolverError, match="float range"):
            km.project_batch([prob], backend="highs")


# Fixed (was a bug: project_batch skips _unit_scale: HiGHS puts the projection of (1e-300, 3e-300)
# on [-1e-300, 1e-300]^2 at (0, 0), feasible so _checked passes it; project gives (1e-300,
# 1e-300))
def test_project_batch_tiny_polytope_matches_project():
    prob = (SQUARE, [1e-300] * 4, [0.0, 0.0], np.eye(2), [1e-300, 3e-300])
    single = km.project(*prob, backend="highs")
    batch = km.project_batch([prob], backend="highs")[0]
    assert np.allclose(single, [1e-300, 1e-300], rtol=1e-6, atol=0)
    assert np.allclose(batch, single, rtol=1e-6, atol=0)


# Fixed (was a bug: chebyshev 'auto' is Clarabel only (points.py CHEBYSHEV_AUTO): on the F = 1
# kernel of V29's hexagon (1 long, 1.2e-9 thick) it ends 'AlmostSolved' -> SolverError; HiGHS
# (before) gave a certified point)
@pytest.mark.parametrize("k", [28, 34, 40])
def test_chebyshev_auto_thin_kernel_f1_not_refused(k):
    e = 2.0**-k
    X = [[0.0, 0.0], [2.0, 0.0], [0.5, e], [1.5, e], [0.5, -e], [1.5, -e]]
    x, _ = rescon.kernel_point(X, 1, method="chebyshev")
    assert rescon.safe_kernel(X, 1).contains(x, tol=1e-12)


def test_chebyshev_auto_thin_kernel_f0_held():
    for k in range(4, 45, 4):
        e = 2.0**-k
        X = [[0.0, 0.0], [2.0, 0.0], [0.5, e], [1.5, e], [0.5, -e], [1.5, -e]]
        x, _ = rescon.kernel_point(X, 0, method="chebyshev")
        assert rescon.safe_kernel(X, 0).contains(x, tol=1e-12)


def test_kernel_points_random_all_backends_certified():
    rng = np.random.default_rng(5)
    for _ in range(25):
        d, n = int(rng.integers(1, 4)), int(rng.integers(3, 9))
        F = int(rng.integers(0, (n - 1) // (d + 1) + 1))
        scale = 10.0 ** rng.choice([-300, 0, 300])
        off = float(rng.choice([0.0, 1e300, -1e10]))
        X = np.round(rng.normal(size=(n, d)) * 8) / 8 * scale + off
        if rng.random() < 0.3:
            X[:, -1] = off
        K = rescon.safe_kernel(X, F)
        if K.is_empty:
            continue
        for m, b in (("chebyshev", "auto"), ("project", "clarabel"), ("project", "highs")):
            x, _ = rescon.kernel_point(X, F, method=m, backend=b)
            assert K.contains(x, tol=1e-9 * max(1.0, float(np.abs(X).max())))


# --------------------------------------------------------------------------- #
# RMDO global cost and remeasure
# --------------------------------------------------------------------------- #


def _sc(n=4, steps=5):
    return Scenario(graph=nx.complete_graph(n), x0=[[float(i)] for i in range(n)], F=0,
                    steps=steps, residual="none", check_robustness=False)


def test_cancelling_huge_constants_and_huge_finite_costs_accepted():
    tr = rescon.rmdo(_sc(), {0: "x1^2 + 1.5e308", 1: "x1^2 + 1.5e308",
                             2: "x1^2 - 1.5e308", 3: "x1^2 - 1.5e308"}, step_size=0.1)
    assert np.isfinite(tr.metrics["cost_at_mean"]).all()
    tr = rescon.rmdo(_sc(), {i: "abs(x1) + 4e307" for i in range(4)}, step_size=0.1)
    assert np.isfinite(tr.metrics["cost"]).all() and tr.metrics["cost"].max() > 1.5e308


def test_global_cost_values_inf_call_named():
    from rescon.optim import rmdo as R

    F = R.GlobalCost(R._groups(_sc(), {i: "abs(x1 + 1.7e308)" for i in range(4)}), 1)
    P = np.array([[0.0], [-1.7e308]])
    v = F.values(P)
    assert math.isinf(v[0]) and v[1] == 0.0
    with pytest.raises(InputError, match=r"overflows at step 9 at the point \[0.0\]") as e:
        F(P, "at step 9")
    assert "\n" not in str(e.value)


def test_remeasure_blockwise_equals_whole(monkeypatch):
    from rescon.optim import rmdo as R

    def bad(cls, F, x0):
        p = x0.mean(axis=0)
        val = float(F(p[None])[0])
        return cls(p, None, val, {"method": "numerical (test)", "exact": False,
                                  "point": p.tolist(), "value": val})

    costs = {0: "(x1 - 1e100)^2", 1: "abs(x1 - 3)", 2: "x1^2", 3: "x1^2"}
    monkeypatch.setattr(R.Optimum, "_numerical", classmethod(bad))
    a = rescon.rmdo(_sc(steps=10), costs, step_size=0.1)
    monkeypatch.setattr(R, "REMEASURE_BLOCK", 3)
    b = rescon.rmdo(_sc(steps=10), costs, step_size=0.1)
    assert "improved" in a.info["optimum"]
    for key in ("distance_to_optimum", "optimality_gap"):
        assert np.array_equal(a.metrics[key], b.metrics[key])
    assert (b.metrics["optimality_gap"] >= 0).all()


def test_remeasure_untouched_without_improvement(monkeypatch):
    from rescon.optim import rmdo as R

    def boom(self, states, benign):
        if "improved" in self.optimum.info:
            raise AssertionError("improved")
        return orig(self, states, benign)

    orig = R.CostMonitor.remeasure
    monkeypatch.setattr(R.CostMonitor, "remeasure", boom)
    monkeypatch.setattr(R.Optimum, "distance", lambda self, X: (
        (_ for _ in ()).throw(AssertionError("copied")) if X.ndim == 2 and len(X) > 4
        else np.abs(X - self.point).max(axis=1)))
    tr = rescon.rmdo(_sc(steps=10), {i: f"(x1 - {i})^2" for i in range(4)}, step_size=0.1)
    assert np.isfinite(tr.metrics["distance_to_optimum"]).all()


# --------------------------------------------------------------------------- #
# Assumption3Report.check()
# --------------------------------------------------------------------------- #


def _random_reports(seed, n):
    rng = random.Random(seed)
    for _ in range(n):
        p = rng.choice([0.3, 0.1, 1.0, 2.5, 0.7, 1 / 3, 0.25])
        tau = p * rng.choice([0.1, 0.5, 1.0, 0.3, 0.999])
        o = rng.choice([0.0, 0.2, 5.0, 1e-9])
        kind = rng.randrange(4)
        a = DoSAttack("a", [(1, 2)], Periodic(p, tau, o))
        if kind == 1:
            atts = [a, DoSAttack("b", [(2, 1)], Periodic(2 * p, 0.7 * p, rng.choice([0, 0.5])))]
        elif kind == 2:
            atts = [DoSAttack("a", [(1, 2)], Explicit([(0.1, 0.4), (0.35, 1.2),
                                                       (3.0, 3.0001)]))]
        elif kind == 3:
            atts = [DoSAttack("r", [(1, 2)], RandomDoS(rng.choice([0.5, 2.0]), 0.3,
                                                       seed=rng.randrange(100))), a]
        else:
            atts = [a]
        kw = {}
        T_d = rng.choice([None, math.inf, 1.0000001, 1.5, 2.0, 10.0])
        mu = rng.choice([None, 0.5, 1.0, 3.0])
        if T_d is not None:
            kw["T_d"] = T_d
        if mu is not None:
            kw["mu_d"] = mu
        yield check_assumption3(atts, rng.choice([0.0, 0.05, 1.0, 3.3, 10.0, 0.35]), **kw)


def test_check_true_on_every_report():
    assert all(r.check() for r in _random_reports(7, 200))


@pytest.mark.parametrize("limit", [0, 3])
def test_check_true_closed_form_and_undecided(monkeypatch, limit):
    monkeypatch.setattr(dos_mod, "_HORIZON_MAX_WINDOWS", limit)
    reps = list(_random_reports(11, 150))
    assert all(r.check() for r in reps)
    assert any(r.periodic is not None for r in reps)
    assert any(r.windows is None and r.periodic is None for r in reps)


def test_closed_form_matches_windows_and_min_mu_d_for(monkeypatch):
    rng = random.Random(3)
    for _ in range(60):
        p = rng.choice([0.3, 0.7, 1.0, 2.5, 1 / 3])
        atts = [DoSAttack("a", [(1, 2)], Periodic(p, p * rng.choice([0.1, 0.5, 1.0]),
                                                  rng.choice([0, 0.2, 3.0])))]
        H, T_d = rng.choice([1.0, 3.3, 10.0, 5.1]), rng.choice([1.0000001, 2.0, math.inf])
        monkeypatch.setattr(dos_mod, "_HORIZON_MAX_WINDOWS", 200_000)
        a = check_assumption3(atts, H, T_d=T_d, mu_d=1.0)
        monkeypatch.setattr(dos_mod, "_HORIZON_MAX_WINDOWS", 0)
        b = check_assumption3(atts, H, T_d=T_d, mu_d=1.0)
        assert (a.min_mu_d, a.holds, a.total_blocked, a.witness) == \
            (b.min_mu_d, b.holds, b.total_blocked, b.witness)
        for T2 in (1.01, 3.0, 1e9):
            assert a.min_mu_d_for(T2) == b.min_mu_d_for(T2)


def test_tampered_reports_rejected():
    r = check_assumption3([DoSAttack("a", [(1, 2)], Periodic(1.0, 0.5))], 10.0, T_d=2.0,
                          mu_d=1.0)
    assert r.check()
    w = r.witness
    for bad in (dict(holds=not r.holds), dict(min_mu_d=r.min_mu_d * 2),
                dict(total_blocked=r.total_blocked + 1), dict(witness=None),
                dict(witness=dataclasses.replace(w, bound=w.bound + 1)),
                dict(witness=dataclasses.replace(w, t2=w.t2 - 0.5)),
                dict(mu_d=0.1), dict(windows=r.windows[1:])):
        assert not dataclasses.replace(r, **bad).check(), bad
