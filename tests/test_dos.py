"""DoS schedules, blocked links and the exact Assumption 3 check (rescon.consensus.dos)."""

from __future__ import annotations

import doctest
import itertools
import math
from fractions import Fraction

import numpy as np
import pytest

import rescon.consensus.dos as dos_mod
from rescon.consensus.dos import (
    PAPER_MU_D,
    PAPER_T_D,
    DoSAttack,
    Explicit,
    Periodic,
    RandomDoS,
    attack_from_dict,
    blocked_links,
    blocked_mask,
    blocked_mask_series,
    check_assumption3,
    paper_attacks,
    paper_schedules,
    schedule_from_dict,
)
from rescon.errors import InputError

# --------------------------------------------------------------------------- #
# schedules
# --------------------------------------------------------------------------- #


def test_periodic_windows_and_half_open_boundaries():
    s = Periodic(period=4.0, duration=1.0, offset=0.5)
    assert s.windows(0.5) == []  # first window starts at 0.5, not inside [0, 0.5)
    assert s.windows(0.6) == [(0.5, 1.5)]
    assert s.windows(12.5) == [(0.5, 1.5), (4.5, 5.5), (8.5, 9.5)]
    assert s.windows(12.6)[-1] == (12.5, 13.5)  # intersects [0, horizon): not clipped
    assert not s.active(0.0) and not s.active(0.49)
    assert s.active(0.5) and s.active(1.4999)
    assert not s.active(1.5)  # [h, h + tau) is half-open
    assert s.active(4.5) and not s.active(5.5) and not s.active(4.4999)


def test_periodic_full_duty_blocks_everything_after_offset():
    s = Periodic(period=1.0, duration=1.0, offset=2.0)
    assert not s.active(1.99)
    assert all(s.active(t) for t in np.linspace(2.0, 50.0, 977))


def test_periodic_active_agrees_with_windows():
    s = Periodic(period=0.7, duration=0.3, offset=0.1)
    ws = s.windows(30.0)
    for t in np.linspace(0, 29.9, 3001).tolist() + [w[0] for w in ws] + [w[1] for w in ws]:
        if t >= 30.0:
            continue
        assert s.active(t) == any(a <= t < b for a, b in ws), t


@pytest.mark.parametrize("kwargs, match", [
    ({"period": 1.0, "duration": 2.0}, "duration must be <= period"),
    ({"period": 0.0, "duration": 0.0}, "period must be a finite number > 0"),
    ({"period": 1.0, "duration": 0.0}, "duration must be a finite number > 0"),
    ({"period": 1.0, "duration": 0.5, "offset": -1.0}, "offset must be a finite number >= 0"),
    ({"period": math.nan, "duration": 0.5}, "period must be"),
    ({"period": 1.0, "duration": math.nan}, "duration must be"),
    ({"period": 1.0, "duration": 0.5, "offset": math.inf}, "offset must be"),
    ({"period": "1", "duration": 0.5}, "period must be a real number"),
])
def test_periodic_bad_input(kwargs, match):
    with pytest.raises(InputError, match=match):
        Periodic(**kwargs)


@pytest.mark.parametrize("t", [-1.0, math.nan, math.inf])
def test_bad_times(t):
    s = Periodic(2.0, 1.0)
    with pytest.raises(InputError, match="t must be a finite number >= 0"):
        s.active(t)
    with pytest.raises(InputError, match="horizon must be"):
        s.windows(t)
    with pytest.raises(InputError, match="t must be"):
        blocked_links([DoSAttack("a", [(1, 2)], s)], t)


def test_explicit_merging_and_activity():
    s = Explicit([(5, 6), (0, 1), (0.5, 2), (2, 3), (7, 7.5)])
    assert s.intervals == ((0.0, 3.0), (5.0, 6.0), (7.0, 7.5))  # touching [.., 2) [2, ..) merge
    assert s.windows(5.0) == [(0.0, 3.0)]
    assert s.windows(5.01) == [(0.0, 3.0), (5.0, 6.0)]
    assert s.active(0.0) and s.active(2.0) and not s.active(3.0)
    assert s.active(5.0) and not s.active(6.0) and not s.active(100.0)
    assert Explicit([]).windows(10) == [] and not Explicit([]).active(1.0)


@pytest.mark.parametrize("windows, match", [
    ([(1, 0)], r"windows\[0\] must have start < end; got \(1.0, 0.0\)"),
    ([(0, 1), (2, 2)], r"windows\[1\] must have start < end; got \(2.0, 2.0\)"),
    ([(-1, 1)], r"windows\[0\] start must be a finite number >= 0"),
    ([(0, math.nan)], r"windows\[0\] end must be"),
    ([(0, 1, 2)], r"windows\[0\] must be a \(start, end\) pair"),
    ("0-1", "windows must be a list"),
])
def test_explicit_bad_windows(windows, match):
    with pytest.raises(InputError, match=match):
        Explicit(windows)


def test_random_determinism_and_prefix_stability():
    a = RandomDoS(rate=0.5, mean_duration=0.8, seed=42)
    b = RandomDoS(rate=0.5, mean_duration=0.8, seed=42)
    long = b.windows(500.0)
    assert a == b and hash(a) == hash(b)
    for h in (0.0, 3.0, 17.5, 100.0, 250.0, 500.0):
        short = a.windows(h)  # a's cache grows step by step, b's was filled at once
        assert short == [w for w in long if w[0] < h]
        assert short == RandomDoS(0.5, 0.8, 42).windows(h)
    assert long != RandomDoS(0.5, 0.8, 43).windows(500.0)
    starts = [w[0] for w in long]
    assert starts == sorted(starts)
    assert all(w[0] < w[1] for w in long)
    assert all(w1[1] < w2[0] for w1, w2 in itertools.pairwise(long))  # merged, disjoint


def test_random_active_and_long_run_fraction():
    s = RandomDoS(rate=0.5, mean_duration=1.0, seed=3)
    ws = s.windows(4000.0)
    for t in np.linspace(0, 60, 601):
        assert s.active(float(t)) == any(a <= t < b for a, b in ws)
    blocked = sum(min(b, 4000.0) - a for a, b in ws)
    assert blocked / 4000.0 == pytest.approx(s.fraction, abs=0.03)
    assert s.fraction == pytest.approx(1 - math.exp(-0.5))


@pytest.mark.parametrize("kwargs, match", [
    ({"rate": 0, "mean_duration": 1, "seed": 0}, "rate must be"),
    ({"rate": 1, "mean_duration": -1, "seed": 0}, "mean_duration must be"),
    ({"rate": 1, "mean_duration": 1, "seed": -3}, "seed must be a nonnegative integer"),
    ({"rate": 1, "mean_duration": 1, "seed": 1.5}, "seed must be"),
])
def test_random_bad_input(kwargs, match):
    with pytest.raises(InputError, match=match):
        RandomDoS(**kwargs)


# --------------------------------------------------------------------------- #
# attacks and masks
# --------------------------------------------------------------------------- #


def test_attack_links_and_blocking():
    a = DoSAttack("a", [(1, 3), [1, 7]], Periodic(4.0, 1.0, 0.5))
    b = DoSAttack("b", frozenset({(1, 3), (2, 5)}), Explicit([(0.0, 1.0)]))
    assert a.links == frozenset({(1, 3), (1, 7)})
    assert blocked_links([a, b], 0.2) == frozenset({(1, 3), (2, 5)})
    assert blocked_links([a, b], 0.5) == frozenset({(1, 3), (1, 7), (2, 5)})
    assert blocked_links([a, b], 1.0) == frozenset({(1, 3), (1, 7)})
    assert blocked_links([a, b], 1.5) == frozenset()
    index = {(1, 3): 0, (1, 7): 1, (2, 5): 2, (9, 10): 3}
    assert blocked_mask([a, b], index, 0.5).tolist() == [True, True, True, False]
    assert blocked_mask([a, b], index, 1.2).tolist() == [True, True, False, False]
    assert blocked_mask([], index, 1.2).dtype == bool


def test_blocked_mask_unknown_links():
    a = DoSAttack("a", [(1, 3), (4, 5)], Periodic(2.0, 1.0))
    assert blocked_mask([a], {(1, 3): 0}, 0.0).tolist() == [True]
    with pytest.raises(InputError, match=r"attack 'a' targets link\(s\) not in links_index"):
        blocked_mask([a], {(1, 3): 0}, 0.0, strict=True)


def test_blocked_mask_series_matches_pointwise():
    atts = paper_attacks() + [DoSAttack("r", [(1, 2), (3, 2)], RandomDoS(0.3, 1.0, 5)),
                              DoSAttack("e", [(4, 2)], Explicit([(1.0, 2.5), (7, 8)]))]
    links = sorted({link for a in atts for link in a.links})
    index = {link: k for k, link in enumerate(links)}
    times = np.arange(0, 200) * 0.5
    series = blocked_mask_series(atts, index, times)
    assert series.shape == (200, len(links)) and series.dtype == bool
    for k, t in enumerate(times):
        assert series[k].tolist() == blocked_mask(atts, index, float(t)).tolist()
        expect = blocked_links(atts, float(t))
        assert {links[j] for j in np.flatnonzero(series[k])} == expect


def test_attack_bad_input():
    with pytest.raises(InputError, match="must join two different agents"):
        DoSAttack("a", [(1, 1)], Periodic(1.0, 0.5))
    with pytest.raises(InputError, match="must be a pair"):
        DoSAttack("a", [(1, 2, 3)], Periodic(1.0, 0.5))
    with pytest.raises(InputError, match="schedule must be a Periodic, Explicit or RandomDoS"):
        DoSAttack("a", [(1, 2)], {"kind": "periodic"})
    with pytest.raises(InputError, match="name must be a str"):
        DoSAttack(3, [(1, 2)], Periodic(1.0, 0.5))
    with pytest.raises(InputError, match="attacks must contain DoSAttack"):
        blocked_links([Periodic(1.0, 0.5)], 0.0)


# --------------------------------------------------------------------------- #
# dict constructors
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("sched", [
    Periodic(4.0, 1.0, 0.5), Periodic(2.0, 2.0), Explicit([(0, 1), (3, 4.5)]),
    RandomDoS(0.2, 1.5, 11),
])
def test_schedule_dict_round_trip(sched):
    assert schedule_from_dict(sched.to_dict()) == sched


def test_schedule_from_dict_defaults():
    assert schedule_from_dict({"kind": "periodic", "period": 5, "duration": 1.5}) == \
        Periodic(5.0, 1.5, 0.0)


@pytest.mark.parametrize("d, match", [
    ({"kind": "burst", "period": 1}, r"schedule kind must be one of .*; got 'burst'"),
    ({"period": 1, "duration": 1}, "schedule kind must be one of .*; got None"),
    ({"kind": "periodic", "period": 4, "duration": 1, "phase": 2, "jitter": 0},
     r"periodic schedule has unknown key\(s\) \['jitter', 'phase'\]"),
    ({"kind": "periodic", "period": 4}, r"periodic schedule is missing key\(s\) \['duration'\]"),
    ({"kind": "explicit", "windows": [[2, 1]]}, r"windows\[0\] must have start < end"),
    ({"kind": "random", "rate": 1, "mean_duration": 1}, r"missing key\(s\) \['seed'\]"),
    ({"kind": "periodic", "period": 1, "duration": 3}, "duration must be <= period"),
    ([1, 2], "schedule must be a dict"),
])
def test_schedule_from_dict_errors(d, match):
    with pytest.raises(InputError, match=match):
        schedule_from_dict(d)


def test_attack_from_dict():
    a = attack_from_dict({"name": "x", "links": [[1, 2], [3, 4]],
                          "schedule": {"kind": "explicit", "windows": [[0, 1]]}})
    assert a == DoSAttack("x", frozenset({(1, 2), (3, 4)}), Explicit([(0, 1)]))
    with pytest.raises(InputError, match=r"attack has unknown key\(s\) \['when'\]"):
        attack_from_dict({"name": "x", "links": [], "schedule": {}, "when": 1})
    with pytest.raises(InputError, match=r"attack is missing key\(s\) \['schedule'\]"):
        attack_from_dict({"name": "x", "links": []})


# --------------------------------------------------------------------------- #
# Assumption 3: exact supremum against brute force
# --------------------------------------------------------------------------- #


def _measure(windows, t1, t2):
    """|union ∩ [t1, t2]| straight from (possibly overlapping) windows, by a sweep."""
    pts = sorted({t1, t2, *[max(t1, min(t2, x)) for w in windows for x in w]})
    total = Fraction(0)
    for a, b in itertools.pairwise(pts):
        mid = (a + b) / 2
        if any(s <= mid < e for s, e in windows):
            total += b - a
    return total


def _random_attacks(rng, n_att):
    atts = []
    for m in range(n_att):
        wins = []
        for _ in range(rng.integers(0, 4)):
            s = rng.integers(0, 40) / 4
            wins.append((s, s + rng.integers(1, 12) / 4))
        atts.append(DoSAttack(f"A{m}", [(1, m + 2)], Explicit(wins)))
    if rng.random() < 0.5:
        atts.append(DoSAttack("P", [(2, 3)], Periodic(float(rng.integers(2, 6)),
                                                      float(rng.integers(1, 3)) / 2,
                                                      float(rng.integers(0, 4)) / 2)))
    return atts


@pytest.mark.parametrize("seed", range(25))
def test_exact_sup_against_grid(seed):
    rng = np.random.default_rng(seed)
    atts = _random_attacks(rng, int(rng.integers(1, 4)))
    horizon = 12.0
    T_d = [1.25, 1.5, 2.0, 3.0][seed % 4]
    r = check_assumption3(atts, horizon, T_d=T_d)
    assert r.check()
    raw = [(Fraction(s), Fraction(e)) for a in atts for s, e in a.schedule.windows(horizon)]
    H, inv = Fraction(horizon), 1 / Fraction(T_d)
    assert Fraction(r.total_blocked) == _measure(raw, Fraction(0), H)
    grid = [Fraction(k, 4) for k in range(49)]  # every endpoint lies on this grid
    best = max(_measure(raw, a, b) - (b - a) * inv for a in grid for b in grid if a <= b)
    if r.witness is None:
        assert best == 0 and r.min_mu_d == 0.0 and not raw
        return
    w = r.witness
    t1, t2 = Fraction(w.t1), Fraction(w.t2)
    exact = _measure(raw, t1, t2) - (t2 - t1) * inv
    # the witness attains the supremum, which dominates every grid value
    assert exact == best
    off_grid = [Fraction(k, 3) for k in range(37)]  # t1, t2 off the endpoint grid too
    assert all(_measure(raw, a, b) - (b - a) * inv <= exact
               for a in off_grid for b in off_grid if a <= b)
    assert Fraction(w.blocked) == _measure(raw, t1, t2)
    assert r.min_mu_d >= exact and Fraction(math.nextafter(r.min_mu_d, 0)) < exact
    # witness endpoints are a window start and a window end of Pi_D
    assert t1 in {Fraction(s) for s, _ in r.windows}
    assert t2 in {Fraction(e) for _, e in r.windows}
    # holds is exactly mu_d >= sup
    lo = check_assumption3(atts, horizon, T_d=T_d, mu_d=math.nextafter(float(exact), 0))
    hi = check_assumption3(atts, horizon, T_d=T_d, mu_d=r.min_mu_d)
    assert hi.holds and (lo.holds is (Fraction(lo.mu_d) >= exact))
    assert lo.check() and hi.check()


def test_sup_equals_all_endpoint_pairs():
    """O(m^2) enumeration of (window start, window end) pairs agrees with the O(m) scan."""
    s = [Periodic(3.0, 1.0, 0.25), Periodic(7.0, 2.5, 1.0), Explicit([(10, 13.5)])]
    atts = [DoSAttack(f"a{k}", [(1, k + 2)], sch) for k, sch in enumerate(s)]
    r = check_assumption3(atts, 40.0, T_d=1.75)
    ws = [(Fraction(a), Fraction(b)) for a, b in r.windows]
    inv = 1 / Fraction(1.75)
    best = max(_measure(ws, ws[i][0], ws[j][1]) - (ws[j][1] - ws[i][0]) * inv
               for i in range(len(ws)) for j in range(i, len(ws)))
    assert Fraction(r.witness.excess) >= best > Fraction(math.nextafter(r.witness.excess, 0))
    assert r.min_mu_d_for(1.75) == r.min_mu_d


# --------------------------------------------------------------------------- #
# Assumption 3: the paper's schedules, and schedules that fail
# --------------------------------------------------------------------------- #

PAPER_TABLE = {
    "DoS_1": {(1, 3), (1, 7), (1, 9), (3, 4), (3, 7), (3, 11), (5, 1), (5, 11), (6, 2),
              (6, 10), (10, 1), (10, 12)},
    "DoS_2": {(4, 2), (4, 3), (7, 5), (7, 9), (7, 10), (8, 3), (8, 5), (9, 7), (9, 8)},
    "DoS_3": {(3, 2), (3, 6), (5, 3), (5, 7), (7, 1), (7, 2), (7, 3), (11, 1), (11, 3),
              (11, 12)},
}


def test_paper_attacks_have_the_table_links():
    atts = paper_attacks()
    assert [a.name for a in atts] == ["DoS_1", "DoS_2", "DoS_3"]
    for a in atts:
        assert a.links == frozenset(PAPER_TABLE[a.name])
        assert a.schedule == paper_schedules()[a.name]
        assert all(1 <= i <= 12 and 1 <= j <= 12 for i, j in a.links)


def test_paper_schedules_satisfy_assumption3():
    r = check_assumption3(paper_attacks(), 300.0, mu_d=PAPER_MU_D, T_d=PAPER_T_D)
    assert r.holds and r.holds_long_run and r.check()
    assert r.long_run_fraction == 67 / 120
    assert r.any_T_d_works and r.max_T_d == pytest.approx(120 / 67)
    assert r.min_mu_d == pytest.approx(7 / 6) and r.min_mu_d_long_run == r.min_mu_d
    assert r.witness.blocked - r.witness.allowance == pytest.approx(7 / 6)
    # the long-run mu_d is the supremum over any longer horizon too
    assert check_assumption3(paper_attacks(), 1200.0, T_d=PAPER_T_D).min_mu_d == r.min_mu_d
    # beyond 1/rho no mu_d works for all time, although a finite horizon still has one
    r2 = check_assumption3(paper_attacks(), 300.0, mu_d=PAPER_MU_D, T_d=1.85)
    assert r2.min_mu_d_long_run == math.inf and r2.holds_long_run is False
    assert math.isfinite(r2.min_mu_d)


def test_blocking_everything_fails_with_witness():
    always = DoSAttack("all", [(1, 2)], Periodic(1.0, 1.0))
    r = check_assumption3([always], 20.0, mu_d=5.0, T_d=2.0)
    assert r.holds is False and r.check()
    w = r.witness
    assert (w.t1, w.t2, w.blocked) == (0.0, 20.0, 20.0)
    assert w.blocked > w.bound == 5.0 + 10.0
    assert r.min_mu_d == 10.0
    assert r.long_run_fraction == 1.0 and r.any_T_d_works is False and r.max_T_d == 1.0
    assert r.min_mu_d_long_run == math.inf and r.holds_long_run is False
    # also with an explicit window covering the whole horizon
    r = check_assumption3([DoSAttack("e", [(1, 2)], Explicit([(0, 30)]))], 20.0,
                          mu_d=5.0, T_d=2.0)
    assert r.holds is False and r.witness.blocked == 20.0
    assert r.long_run_fraction == 0.0 and r.any_T_d_works  # finite attacks: ok in the long run


def test_assumption3_no_attacks_and_no_T_d():
    r = check_assumption3([], 10.0, mu_d=1.0, T_d=2.0)
    assert r.holds and r.witness is None and r.min_mu_d == 0.0 and r.check()
    r = check_assumption3(paper_attacks(), 60.0)
    assert r.holds is None and r.witness is None and r.min_mu_d is None
    assert r.min_mu_d_for(1.5) == pytest.approx(7 / 6)
    # attacks that target no link block nothing
    r = check_assumption3([DoSAttack("idle", [], Periodic(1.0, 1.0))], 10.0, T_d=2.0)
    assert r.total_blocked == 0.0


def test_assumption3_random_and_long_hyperperiod():
    atts = [DoSAttack("r", [(1, 2)], RandomDoS(0.1, 1.0, 0)),
            DoSAttack("p", [(1, 3)], Periodic(4.0, 1.0))]
    r = check_assumption3(atts, 200.0, mu_d=10.0, T_d=1.5)
    assert r.holds is not None and r.check()
    assert r.long_run_fraction == pytest.approx(1 - 0.75 * math.exp(-0.1))
    assert r.min_mu_d_long_run is None and r.holds_long_run is None and r.notes
    r = check_assumption3([DoSAttack("p", [(1, 2)], Periodic(0.1, 0.03)),
                           DoSAttack("q", [(1, 3)], Periodic(0.3, 0.01))], 5.0, T_d=2.0)
    assert r.long_run_fraction is None and r.any_T_d_works is True
    assert any("hyperperiod" in n for n in r.notes)


@pytest.mark.parametrize("kwargs, match", [
    ({"horizon": -1.0}, "horizon must be a finite number >= 0"),
    ({"horizon": math.inf}, "horizon must be"),
    ({"horizon": 1.0, "T_d": 1.0}, "T_d must be a number > 1"),
    ({"horizon": 1.0, "T_d": math.nan}, "T_d must be"),
    ({"horizon": 1.0, "mu_d": 0.0}, "mu_d must be a finite number > 0"),
])
def test_assumption3_bad_input(kwargs, match):
    with pytest.raises(InputError, match=match):
        check_assumption3(paper_attacks(), **kwargs)


def test_T_d_infinite_bounds_total_blocked_time():
    atts = [DoSAttack("e", [(1, 2)], Explicit([(1, 2), (5, 7)]))]
    r = check_assumption3(atts, 10.0, mu_d=3.0, T_d=math.inf)
    assert r.holds and r.min_mu_d == 3.0
    assert not check_assumption3(atts, 10.0, mu_d=2.5, T_d=math.inf).holds


def test_doctests():
    res = doctest.testmod(dos_mod, optionflags=doctest.ELLIPSIS)
    assert res.failed == 0 and res.attempted > 10


def _random_periodic_report(rng, horizon_scale: float = 50.0):
    p = float(rng.choice([0.1, 0.3, 0.7, 1 / 3, 0.01]))
    sched = Periodic(period=p, duration=p * float(rng.uniform(0.01, 1)),
                     offset=float(rng.uniform(0, 1)))
    T_d = float(rng.uniform(1.1, 5))
    att = DoSAttack(name="D", links=[(0, 1)], schedule=sched)
    return att, check_assumption3([att], float(rng.uniform(1, horizon_scale)), mu_d=1.0,
                                  T_d=T_d)


def test_check_accepts_reports_whose_numbers_are_not_floats():
    """Windows o + m·p with p = 0.3 are not floats: check() re-verified the witness on the
    rounded windows and rejected 255 of 300 correct reports."""
    rng = np.random.default_rng(11)
    for _ in range(300):
        _, r = _random_periodic_report(rng)
        assert r.witness is not None and r.check()


def test_check_rejects_a_tampered_witness():
    import dataclasses

    rng = np.random.default_rng(12)
    for _ in range(50):
        _, r = _random_periodic_report(rng)
        w = r.witness
        for change in ({"blocked": math.nextafter(w.blocked, 0)},
                       {"excess": math.nextafter(w.excess, math.inf)},
                       {"t2": math.nextafter(w.t2, math.inf)},
                       {"allowance": w.allowance * 2}):
            bad = dataclasses.replace(r, witness=dataclasses.replace(w, **change))
            assert not bad.check()
        assert not dataclasses.replace(r, holds=not r.holds).check()


def test_periodic_closed_form_report_checks_and_answers_other_T_d(monkeypatch):
    """Past the window cap a single periodic schedule is decided in closed form: its
    report's check() said False (no windows to re-verify from) and min_mu_d_for raised;
    both now use the closed form, and agree with the enumeration (cap lifted)."""
    rng = np.random.default_rng(13)
    for _ in range(40):
        att, full = _random_periodic_report(rng, horizon_scale=20.0)
        monkeypatch.setattr(dos_mod, "_HORIZON_MAX_WINDOWS", 0)
        closed = check_assumption3([att], full.horizon, mu_d=1.0, T_d=full.T_d)
        monkeypatch.undo()
        assert closed.windows is None and closed.periodic is not None
        assert closed.check()
        assert (closed.witness, closed.min_mu_d, closed.holds) == (
            full.witness, full.min_mu_d, full.holds)
        for T_d in (1.5, 3.0, math.inf):
            assert closed.min_mu_d_for(T_d) == full.min_mu_d_for(T_d)


def test_periodic_measure_matches_the_windows():
    rng = np.random.default_rng(14)
    for _ in range(300):
        att, r = _random_periodic_report(rng, horizon_scale=10.0)
        H = Fraction(r.horizon)
        t1, t2 = sorted(Fraction(float(v)) for v in rng.uniform(-1, 12, 2))
        assert dos_mod._periodic_measure(att.schedule, H, t1, t2) == dos_mod._measure(
            list(r.exact_windows), t1, t2)
