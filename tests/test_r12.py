"""R12: the numerical redundancy path compiles each sum's support problem once.

`check_redundancy`'s numerical supports (max uᵀy on {F_S ≤ level}, 4d directions per
sum) used to go through ``Problem.solve`` per direction, which recompiles the whole
conic data each time (the weights, level and direction are Parameters). Now CVXPY
compiles the constraints once per sum and only the objective vector c = C·u changes.
These tests pin the new path to the old one bitwise (the very data Clarabel solves, so
the same verdict, gap, tolerance, witness and certificate), check that the
compilations are per sum, and compare the answers with an independent CVXPY solve.
"""

from __future__ import annotations

import itertools
import math
from fractions import Fraction

import cvxpy as cp
import numpy as np
import pytest

import rescon
from benchmarks.redundancy_bench import family
from rescon.errors import SolverError
from rescon.optim import _pq, redundancy


def shifted(N: int, t: int = 1, z: int = 0, v: float = 1.0) -> list[str]:
    """The bench's numerical family (centre (2, 0, 0) here) at x = z + t·y, values × v."""
    y = [f"((x{j} - ({z}))/{t})" for j in (1, 2, 3)]
    return [f"{v}*(huber({y[0]} - 2, 1) + sqrt(({y[0]} - 2)^2 + ({y[1]} - 1)^2 + {y[2]}^2)"
            f" + ({y[1]} - {1 + i % 2})^2)" for i in range(N)]


CASES = {
    "bench5": (family("numerical", 5), 2, 3),
    "scaled": (shifted(6, t=1024), 2, 3),
    "shifted": (shifted(6, z=1000000), 2, 3),
    "values": (shifted(6, v=2.0**-10), 2, 3),
    "holds": (["huber(x1, 1) + sqrt(x1^2 + x2^2 + 1)"] * 5, 1, 2),
    "lines": (["huber(x1 - x2, 1)", "huber(x1 - x2 - 1, 1) + abs(x1 - x2 - 1)",
               "huber(x1 - x2, 2)", "sqrt((x1 - x2)^2 + 1)"], 1, 2),
    "logsumexp": (["logsumexp(x1, -x1) + sqrt(x2^2 + 1)",
                   "logsumexp(x1 - 1, -x1 + 1) + sqrt(x2^2 + 1)",
                   "huber(x1, 1) + huber(x2 - 1, 1)"], 1, 2),
    "ray": (["x1", "norm2(0*x1, x1)", "x1^2"], 1, 1),  # exact verdict, numerical gap
    "v34": (["abs((0)*x1 - (-2048))", "norm2((1)*x1 - (2048), (-0.25)*x1 - (2048))",
             "norm2((1)*x1 - (2048), (-0.25)*x1 - (2048))", "abs(x1 - (1024))"], 1, 1),
}


def _answer(rep: rescon.RedundancyReport) -> str:
    return repr((rep.holds, rep.exact, rep.gap, rep.tolerance, rep.witness, rep.unbounded,
                 rep.unbounded_agents, rep.certificate))


def _old_support(self, members, u):
    """_Cvx.support before R12: every direction solved by Problem.solve."""
    self._level(members)
    self.u.value = u
    self._solve(self.psup)
    if self.psup.status in ("unbounded", "unbounded_inaccurate"):
        return math.inf, None, None
    h = (_pq._dot([Fraction(float(v)) for v in u], self.cq)
         + Fraction(self.s) * Fraction(float(self.psup.value)))
    return redundancy._float(h), self.c + self._offset(), h


def _old_answer(monkeypatch: pytest.MonkeyPatch, costs: list[str], r: int, d: int) -> str:
    """check_redundancy with every support solved by Problem.solve (the old path)."""
    with monkeypatch.context() as m:
        m.setattr(redundancy._Cvx, "support", _old_support)
        return _answer(rescon.check_redundancy(costs, r, d=d))


@pytest.mark.parametrize("name", list(CASES))
def test_same_answer_as_one_solve_per_direction(monkeypatch, name):
    costs, r, d = CASES[name]
    rep = rescon.check_redundancy(costs, r, d=d)
    assert _answer(rep) == _old_answer(monkeypatch, costs, r, d)


def _outcome(costs: list[str], r: int, d: int) -> str:
    try:
        return _answer(rescon.check_redundancy(costs, r, d=d))
    except SolverError as e:
        return f"SolverError: {e}"


@pytest.mark.parametrize("retries", [({"max_iter": 2}, {"max_iter": 200}),
                                     ({"max_iter": 2},)])
def test_retries_take_the_same_course(monkeypatch, retries):
    """Clarabel stopped early (MaxIterations) is retried with the next settings, on the
    same warm-started solver, as before; when every setting fails, the same
    SolverError."""
    costs, r, d = CASES["bench5"]
    monkeypatch.setattr(redundancy, "RETRIES", retries)
    new = _outcome(costs, r, d)
    with monkeypatch.context() as m:
        m.setattr(redundancy._Cvx, "support", _old_support)
        old = _outcome(costs, r, d)
    assert new == old
    assert new.startswith("SolverError") == (len(retries) == 1)


@pytest.mark.slow
def test_same_answer_on_the_bench_family_n12(monkeypatch):
    costs = family("numerical", 12)
    rep = rescon.check_redundancy(costs, 2, d=3)
    assert (rep.holds, rep.exact) == (False, False)
    assert _answer(rep) == _old_answer(monkeypatch, costs, 2, 3)


def test_compiled_data_is_cvxpys_own():
    """The data solved per direction (cached constraints, c = C·u) equal CVXPY's own
    compilation at that direction, entry for entry, also when a sum's cached data are
    used again after other sums were compiled."""
    chk = redundancy._Check(*redundancy._costs(family("numerical", 5), 3), 2)
    cvx = chk.cvx
    rng = np.random.default_rng(1)
    sums = [(0, 1, 2), (1, 3, 4), (0, 1, 2, 3, 4)]
    for members in sums:
        assert cvx.minimise(members)[0] == "optimal"
    for members in sums + sums:  # the second time from the cache, after other sums'
        for u in [*chk.dirs, *rng.standard_normal((3, 3))]:
            data = cvx._compiled(members, u)[0]
            cvx._level(members)
            own = cvx._compile(u)[0]
            for key in ("c", "A", "b"):
                a, b = (np.asarray(x.todense() if hasattr(x, "todense") else x)
                        for x in (data[key], own[key]))
                assert a.shape == b.shape and np.array_equal(a, b), key
                assert np.array_equal(np.signbit(a), np.signbit(b)), key


def test_one_compilation_per_sum(monkeypatch):
    """Support problems are compiled once per sum (+ d for the map u ↦ c), not once per
    direction (failed before: 4d compilations per sum)."""
    calls = []
    real = cp.Problem.get_problem_data

    def spy(self, *args, **kwargs):
        if isinstance(self.objective, cp.Maximize):
            calls.append(self)
        return real(self, *args, **kwargs)

    monkeypatch.setattr(cp.Problem, "get_problem_data", spy)
    N, d = 5, 3
    rep = rescon.check_redundancy(family("numerical", N), 2, d=d)
    assert not rep.exact
    sums = len(list(itertools.combinations(range(N), N - 2))) + 1  # subsets + the whole
    assert len(calls) <= sums + d


def _independent_argmin(costs: list[str], members: tuple[int, ...]) -> np.ndarray:
    """min Σ_{i∈S} f_i for the bench's numerical family, written here in CVXPY."""
    c = np.random.default_rng(0).integers(-3, 4, size=3)  # the bench's centre
    x = cp.Variable(3)
    F = sum(cp.huber(x[0] - c[0], 1) + cp.norm(x - c, 2) + cp.square(x[1] - (c[1] + i % 2))
            for i in members)
    cp.Problem(cp.Minimize(F)).solve(solver="CLARABEL")
    return np.array(x.value)


@pytest.mark.parametrize("N", [5, 8])
def test_witness_and_gap_match_an_independent_solve(N):
    """The witness's supports are, within the tolerance, uᵀ of the independently computed
    minimisers of its two sums (single points here), and the gap is their largest
    difference over the subsets (the Hausdorff distance of points)."""
    costs = family("numerical", N)
    rep = rescon.check_redundancy(costs, 2, d=3)
    assert (rep.holds, rep.exact) == (False, False)
    w = rep.witness
    u = np.array(w["direction"])
    pts = [_independent_argmin(costs, tuple(S)) for S in w["subsets"]]
    for h, x in zip(w["support"], pts, strict=True):
        assert abs(h - u @ x) <= rep.tolerance
    everyone = _independent_argmin(costs, tuple(range(N)))
    gap = max(np.abs(_independent_argmin(costs, S) - everyone).max()
              for S in itertools.combinations(range(N), N - 2))
    assert abs(rep.gap - gap) <= rep.tolerance
    assert rep.gap > rep.tolerance
