"""V28 hostile review of RMDO's improved numerical X* (21caeb0) and of
``Assumption3Report.check()`` / ``.min_mu_d_for`` (acc7970).

Attacked:

* ``rescon.rmdo`` with a numerical X* that a benign state beats (forced by a wrong
  Nelder–Mead estimate, as R7's test does, and natural flat argmins): the gap is never
  negative, ``distance_to_optimum`` / ``optimality_gap`` equal an independent
  recomputation against ``info["optimum"]``, for d = 1..4, with an adversary, with
  ``metrics=`` subsets, at magnitudes 1e-300 and 1e150, on a 2000-step run; info is
  strict JSON; ``Trajectory.seconds`` covers the re-measurement; a given optimum and an
  exact quadratic X* are never changed; ``rescon rmdo --json`` / ``--out``.
* ``check_assumption3``: ``min_mu_d_for`` against an exact brute force over every
  window-start / window-end pair (periodic, explicit, random, mixed); the periodic
  closed form (``_HORIZON_MAX_WINDOWS`` monkeypatched) against the enumeration
  (duration == period, offsets past the horizon, horizons ending inside a window,
  T_d = inf); tiny periods with huge horizons; ``check()`` on tampered reports.

Bugs found (all fixed, markers removed): ``check()`` returns True whenever the witness
is None —
so dropping the witness of a failing report (``replace(r, witness=None)``, even with
``holds=True``) passes, and on a report with nothing blocked (or without T_d)
``holds`` / ``min_mu_d`` can be changed freely; the witness's ``bound`` and the
report's ``total_blocked`` are never re-verified. ``rmdo`` copies every benign state
(``tr.states[:, tr.benign]``) after every run, before ``remeasure`` decides whether it
has anything to do (memory: one extra (K+1)·|B|·d array, not one block).
"""

from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
import time
import warnings
from fractions import Fraction

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon import Scenario
from rescon.consensus import dos
from rescon.consensus.adversaries import Constant
from rescon.consensus.dos import DoSAttack, Explicit, Periodic, RandomDoS, check_assumption3
from rescon.optim import rmdo as rmdo_mod

pytestmark = pytest.mark.filterwarnings("ignore:Assumption 5")

# --------------------------------------------------------------------------- #
# RMDO: numerical X* improved by a benign state
# --------------------------------------------------------------------------- #


def _wrong_estimate(monkeypatch):
    """Nelder–Mead replaced by a wrong estimate (the benign mean), labelled numerical,
    so that benign states beat it during the run."""

    def bad(cls, F, x0):
        p = x0.mean(axis=0)
        val = float(F(p[None])[0])
        return cls(p, None, val, {"method": "numerical (test)", "exact": False,
                                  "point": p.tolist(), "value": val})

    monkeypatch.setattr(rmdo_mod.Optimum, "_numerical", classmethod(bad))


def _assert_contract(tr):
    m, o = tr.metrics, tr.info["optimum"]
    p = np.array(o["point"], dtype=float)
    B = tr.states[:, tr.benign]
    # independent distance: scaled per row to avoid over/underflow
    R = B - p
    s = np.abs(R).max(axis=2, keepdims=True)
    s[s == 0] = 1.0
    dist = (np.linalg.norm(R / s, axis=2) * s[..., 0]).max(axis=1)
    assert (m["optimality_gap"] >= 0).all()
    assert np.array_equal(m["optimality_gap"], m["cost"].max(axis=1) - o["value"])
    assert np.allclose(m["distance_to_optimum"], dist, rtol=1e-12, atol=0)
    json.dumps(tr.info, allow_nan=False)


def _sc(x0, steps=40, F=0, adversaries=None, **kw):
    n = len(x0)
    return Scenario(graph=nx.complete_graph(n), x0=x0, F=F, steps=steps,
                    adversaries=adversaries or {}, check_robustness=False, **kw)


@pytest.mark.parametrize("d", [1, 2, 3, 4])
def test_improved_estimate_metrics_match_recomputation(monkeypatch, d):
    _wrong_estimate(monkeypatch)
    rng = np.random.default_rng(d)
    x0 = (rng.normal(size=(6, d)) * 3).tolist()
    terms = " + ".join(f"abs(x{j + 1} - {0.1 * j + 0.3})" for j in range(d))
    tr = rescon.rmdo(_sc(x0), {i: terms for i in range(6)}, step_size=0.05)
    assert "improved" in tr.info["optimum"]
    assert tr.info["optimum"]["value"] == tr.metrics["cost"].min()
    _assert_contract(tr)


def test_improved_estimate_with_adversary_and_metric_subset(monkeypatch):
    _wrong_estimate(monkeypatch)
    x0 = [[5.0, 5.0], [0.0, 1.0], [1.0, 0.0], [2.0, 2.0], [-1.0, 3.0], [0.5, -2.0],
          [3.0, 1.0]]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tr = rescon.rmdo(_sc(x0, F=1, adversaries={0: Constant([9.0, -9.0])}),
                         {i: "abs(x1 - 0.25) + (x2 - 0.5)^2 + abs(x1 + x2)"
                          for i in range(1, 7)}, step_size=0.05, metrics=["diameter"])
    assert "improved" in tr.info["optimum"]
    assert "validity" not in tr.metrics
    _assert_contract(tr)


@pytest.mark.parametrize("scale", [1e-300, 1e150])
def test_improved_estimate_extreme_magnitudes(monkeypatch, scale):
    _wrong_estimate(monkeypatch)
    x0 = [[v * scale] for v in (0.0, 0.25, 0.5, 0.75)]
    tr = rescon.rmdo(_sc(x0, steps=30), {i: f"abs(x1 - {0.2 * scale:.17g})" for i in range(4)},
                     step_size=0.075 * scale)
    assert "improved" in tr.info["optimum"]
    _assert_contract(tr)


def test_improved_estimate_long_run_is_fast(monkeypatch):
    """2000 steps, the estimate improved at many steps: remeasure in blocks, cheap."""
    _wrong_estimate(monkeypatch)
    calls = []
    real = rmdo_mod.CostMonitor.remeasure

    def timed(self, states, benign):
        t = time.perf_counter()
        real(self, states, benign)
        calls.append(time.perf_counter() - t)

    monkeypatch.setattr(rmdo_mod.CostMonitor, "remeasure", timed)
    monkeypatch.setattr(rmdo_mod, "REMEASURE_BLOCK", 300)  # several blocks
    x0 = [[0.0, 4.0], [1.0, 3.0], [2.0, -1.0], [3.0, 0.0]]
    tr = rescon.rmdo(_sc(x0, steps=2000), {i: "abs(x1 - 1) + abs(x2 - 2)" for i in range(4)},
                     metrics=["diameter"])
    assert "improved" in tr.info["optimum"]
    assert calls and calls[0] < 0.5
    _assert_contract(tr)


def test_seconds_cover_the_remeasurement(monkeypatch):
    _wrong_estimate(monkeypatch)
    real = rmdo_mod.CostMonitor.remeasure

    def slow(self, states, benign):
        time.sleep(0.2)
        real(self, states, benign)

    monkeypatch.setattr(rmdo_mod.CostMonitor, "remeasure", slow)
    tr = rescon.rmdo(_sc([[0.0], [1.0], [2.0], [3.0]], steps=5),
                     {i: "abs(x1 - 1)" for i in range(4)}, step_size=0.3)
    assert tr.seconds >= 0.2


def test_flat_box_argmin_natural_estimate_holds_contract():
    rng = np.random.default_rng(11)
    for d in (1, 2, 3):
        x0 = (rng.normal(size=(8, d)) * 3).tolist()
        terms = " + ".join(f"pos(abs(x{j + 1} - 0.1) - 0.7)" for j in range(d))
        tr = rescon.rmdo(_sc(x0, steps=40), {i: f"{terms} + {0.1 * i}" for i in range(8)})
        assert tr.info["optimum"]["method"].startswith("numerical")
        _assert_contract(tr)


def test_given_and_exact_optimum_never_changed():
    x0 = [[0.0], [1.0], [2.0], [3.0]]
    tr = rescon.rmdo(_sc(x0, steps=30), {i: "abs(x1 - 1)" for i in range(4)},
                     optimum=[2.5], step_size=0.1)
    assert tr.info["optimum"]["point"] == [2.5] and "improved" not in tr.info["optimum"]
    tr = rescon.rmdo(_sc(x0, steps=30), {i: "(x1 - 0.3)^2" for i in range(4)})
    o = tr.info["optimum"]
    assert o["method"] == "exact (quadratic)" and o["point"] == [0.3]
    assert "improved" not in o


def test_cli_json_and_out_are_strict_json(tmp_path):
    (tmp_path / "g.edgelist").write_text("0 1\n0 2\n0 3\n1 2\n1 3\n2 3\n")
    (tmp_path / "s.toml").write_text(
        "[scenario]\nF = 0\nsteps = 30\nT = 0.5\ncheck_robustness = false\n\n"
        f'[graph]\nedgelist = "{tmp_path / "g.edgelist"}"\nundirected = true\n\n'
        "[initial]\n0 = [0.0]\n1 = [1.0]\n2 = [2.0]\n3 = [3.0]\n\n[costs]\n"
        + "".join(f'{i} = "pos(abs(x1 - 1) - 0.7) + {0.1 * i}"\n' for i in range(4)))
    exe = [sys.executable, "-m", "rescon"]
    out = subprocess.run([*exe, "rmdo", str(tmp_path / "s.toml"), "--json"],
                         capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert doc["final_gap"] >= 0 and doc["optimum"]["method"].startswith("numerical")
    out = subprocess.run([*exe, "rmdo", str(tmp_path / "s.toml"), "--out",
                          str(tmp_path / "o")], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    text = (tmp_path / "o" / "trajectory.json").read_text()
    json.loads(text)
    assert "NaN" not in text and "Infinity" not in text


# --------------------------------------------------------------------------- #
# Assumption 3: brute force, closed form, tampering
# --------------------------------------------------------------------------- #


def _exact_windows(sched, h):
    if isinstance(sched, Periodic):
        p, t, o = Fraction(sched.period), Fraction(sched.duration), Fraction(sched.offset)
        out, m = [], 0
        while o + m * p < h:
            out.append((o + m * p, o + m * p + t))
            m += 1
        return out
    if isinstance(sched, Explicit):
        return [(Fraction(s), Fraction(e)) for s, e in sched.intervals if Fraction(s) < h]
    return [(Fraction(s), Fraction(e)) for s, e in sched.windows(float(h))]


def _union_measure(ws, a, b):
    iv = sorted((max(s, a), min(e, b)) for s, e in ws if min(e, b) > max(s, a))
    tot, cur = Fraction(0), None
    for s, e in iv:
        if cur is None:
            cur = [s, e]
        elif s <= cur[1]:
            cur[1] = max(cur[1], e)
        else:
            tot += cur[1] - cur[0]
            cur = [s, e]
    return tot + (cur[1] - cur[0] if cur else 0)


def _brute(scheds, h, T_d):
    """max over window-start / window-end pairs of |Π ∩ [t1, t2]| − (t2 − t1)/T_d."""
    h = Fraction(h)
    ws = [(max(s, Fraction(0)), min(e, h)) for sc in scheds for s, e in _exact_windows(sc, h)]
    ws = [(s, e) for s, e in ws if e > s]
    inv = Fraction(0) if math.isinf(T_d) else 1 / Fraction(T_d)
    starts, ends = sorted({s for s, _ in ws}), sorted({e for _, e in ws})
    best = Fraction(0)
    for a in starts:
        for b in ends:
            if b > a:
                best = max(best, _union_measure(ws, a, b) - (b - a) * inv)
    return best


def _ceil(x):
    f = float(x)
    return math.nextafter(f, math.inf) if Fraction(f) < x else f


def _atts(scheds):
    return [DoSAttack(f"a{i}", [(1, 2)], s) for i, s in enumerate(scheds)]


_SCHEDULES = [
    [Periodic(0.3, 0.1, 0.2)],
    [Periodic(0.7, 0.7, 1.3)],                       # duration == period
    [Periodic(1.1, 0.99, 7.0)],
    [Periodic(2.5, 1.25, 100.0)],                    # offset beyond the horizon
    [Explicit([(0.1, 0.4), (0.35, 1.7), (3.3, 3.31), (8.0, 12.0)])],
    [RandomDoS(rate=1.5, mean_duration=0.4, seed=3)],
    [Periodic(0.3, 0.27, 0.0), Explicit([(1.05, 2.2), (6.6, 6.9)])],
    [Periodic(1.0, 0.5, 0.25), Periodic(0.7, 0.2, 0.1)],
]


@pytest.mark.parametrize("scheds", _SCHEDULES)
@pytest.mark.parametrize("h", [0.0, 3.3, 9.75])
def test_min_mu_d_for_matches_brute_force(scheds, h):
    r = check_assumption3(_atts(scheds), h, mu_d=1.0, T_d=2.0)
    assert r.check()
    assert r.min_mu_d == _ceil(_brute(scheds, h, 2.0))
    for T_d in (1.0000001, 1.5, 7.0, math.inf):
        assert r.min_mu_d_for(T_d) == _ceil(_brute(scheds, h, T_d)), T_d


@pytest.mark.parametrize("sched", [Periodic(0.3, 0.1, 0.2), Periodic(0.7, 0.7, 1.3),
                                   Periodic(1.1, 0.99, 7.0), Periodic(2.5, 1.25, 100.0),
                                   Periodic(1.0, 0.4, 0.0)])
@pytest.mark.parametrize("h", [0.0, 0.5, 7.3, 7.7, 12.0])
@pytest.mark.parametrize("T_d", [1.5, math.inf, 1e9])
def test_closed_form_matches_enumeration(monkeypatch, sched, h, T_d):
    atts = _atts([sched])
    r0 = check_assumption3(atts, h, mu_d=0.5, T_d=T_d)
    monkeypatch.setattr(dos, "_HORIZON_MAX_WINDOWS", -1)
    r = check_assumption3(atts, h, mu_d=0.5, T_d=T_d)
    assert r.windows is None and r0.windows is not None
    assert r.check() and r0.check()
    assert (r.min_mu_d, r.holds, r.total_blocked) == (r0.min_mu_d, r0.holds, r0.total_blocked)
    assert r.min_mu_d == _ceil(_brute([sched], h, T_d))
    for T2 in (1.5, 2.0, math.inf):
        assert r.min_mu_d_for(T2) == r0.min_mu_d_for(T2) == _ceil(_brute([sched], h, T2))


@pytest.mark.parametrize("sched,h", [(Periodic(1e-7, 5e-8), 1e12),
                                     (Periodic(1e-7, 1e-7, 3.0), 1e12),
                                     (Periodic(0.3, 0.1, 1e11), 1e12)])
def test_tiny_periods_huge_horizons_fast(sched, h):
    t = time.perf_counter()
    for T_d in (2.0, math.inf):
        r = check_assumption3(_atts([sched]), h, mu_d=1.0, T_d=T_d)
        assert r.check() and r.min_mu_d is not None
        r.min_mu_d_for(1.5)
    assert time.perf_counter() - t < 5


def _report():
    r = check_assumption3(_atts([Periodic(1.0, 0.6, 0.3)]), 10.0, mu_d=1.0, T_d=2.0)
    assert r.holds is False and r.witness is not None and r.check()
    return r


@pytest.mark.parametrize("field", ["t1", "t2", "blocked", "allowance", "excess"])
def test_tampered_witness_number_rejected(field):
    r = _report()
    w = dataclasses.replace(r.witness, **{field: getattr(r.witness, field) + 0.5})
    assert not dataclasses.replace(r, witness=w).check()


def test_tampered_holds_and_min_mu_d_rejected():
    r = _report()
    assert not dataclasses.replace(r, holds=True).check()
    assert not dataclasses.replace(r, min_mu_d=r.min_mu_d + 1).check()
    assert not dataclasses.replace(r, mu_d=5.0).check()


# Fixed (was a bug: check() returns True whenever witness is None)
def test_dropped_witness_rejected():
    r = _report()
    assert not dataclasses.replace(r, witness=None).check()


# Fixed (was a bug: a failing report with witness dropped and holds flipped to True passes check())
def test_dropped_witness_and_flipped_holds_rejected():
    r = _report()
    assert not dataclasses.replace(r, witness=None, holds=True, min_mu_d=0.0).check()


# Fixed (was a bug: the witness's bound is never re-verified)
def test_tampered_bound_rejected():
    r = _report()
    w = dataclasses.replace(r.witness, bound=99.0)
    assert not dataclasses.replace(r, witness=w).check()


# Fixed (was a bug: nothing blocked (witness None): holds is not re-verified)
def test_nothing_blocked_tampered_holds_rejected():
    r = check_assumption3(_atts([Periodic(1.0, 0.5, 100.0)]), 10.0, mu_d=1.0, T_d=2.0)
    assert r.holds is True and r.witness is None and r.min_mu_d == 0.0 and r.check()
    assert not dataclasses.replace(r, holds=False).check()


# Fixed (was a bug: nothing blocked (witness None): min_mu_d is not re-verified)
def test_nothing_blocked_tampered_min_mu_d_rejected():
    r = check_assumption3(_atts([Periodic(1.0, 0.5, 100.0)]), 10.0, mu_d=1.0, T_d=2.0)
    assert not dataclasses.replace(r, min_mu_d=5.0).check()


# Fixed (was a bug: without T_d, holds / min_mu_d may be set to anything and check() still passes)
def test_without_T_d_tampered_holds_rejected():
    r = check_assumption3(_atts([Periodic(1.0, 0.6, 0.3)]), 10.0, mu_d=1.0)
    assert r.holds is None and r.check()
    assert not dataclasses.replace(r, holds=True).check()


# Fixed (was a bug: total_blocked is never re-verified)
def test_tampered_total_blocked_rejected():
    r = _report()
    assert not dataclasses.replace(r, total_blocked=0.0).check()


# Fixed (was a bug: rmdo copies every benign state (tr.states[:, tr.benign]) after each
# run, even when nothing is re-measured)
def test_no_copy_of_the_states_after_the_run(monkeypatch):
    """An exact X* is never re-measured, yet ``rmdo`` builds ``tr.states[:, tr.benign]``
    (a fancy-index copy, (K+1)·|B|·d floats) before ``remeasure`` returns early; with
    an improved X* the copy is whole too, while the docstring promises one block."""
    import tracemalloc

    real_run = rmdo_mod.run

    def run_then_reset(*args, **kwargs):
        tr = real_run(*args, **kwargs)
        tracemalloc.reset_peak()
        base.append(tracemalloc.get_traced_memory()[0])
        return tr

    base: list[int] = []
    monkeypatch.setattr(rmdo_mod, "run", run_then_reset)
    x0 = [[0.0, 1.0, 2.0, 3.0], [1.0, 0.0, 0.0, 0.0], [2.0, 2.0, 1.0, 0.0],
          [3.0, -1.0, 0.5, 0.25]]
    tracemalloc.start()
    try:
        tr = rescon.rmdo(_sc(x0, steps=400), {i: "(x1 - 1)^2 + x2^2 + x3^2 + x4^2"
                                                 for i in range(4)}, metrics=["diameter"])
        extra = tracemalloc.get_traced_memory()[1] - base[0]
    finally:
        tracemalloc.stop()
    assert tr.info["optimum"]["method"] == "exact (quadratic)"
    assert extra < tr.states.nbytes / 4, (extra, tr.states.nbytes)
