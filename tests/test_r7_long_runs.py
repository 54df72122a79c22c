"""R7: long runs and far optima in the DoS schedules and RMDO (fixes of V27 findings).

* ``RandomDoS.active`` is O(log K) (bisect of the cached starts), so a run's
  DoS masks cost O(K log K), not O(K^2).
* ``check_assumption3`` lists at most ``_HORIZON_MAX_WINDOWS`` windows on the
  horizon; beyond, the finite-horizon answer is None ("not decided"), never wrong.
"""

from __future__ import annotations

import signal
import time

import numpy as np
import pytest

from rescon.consensus.dos import DoSAttack, Periodic, RandomDoS, check_assumption3
from rescon.errors import InputError


def test_random_dos_active_logarithmic_and_consistent():
    s = RandomDoS(rate=1.0, mean_duration=0.2, seed=3)
    ws = s.windows(3e5)
    t0 = time.perf_counter()
    got = [s.active(2.9e5 + 0.37 * k) for k in range(2000)]
    assert time.perf_counter() - t0 < 1.0
    W = np.array(ws)
    ts = 2.9e5 + 0.37 * np.arange(2000)
    k = np.searchsorted(W[:, 0], ts, side="right") - 1
    want = ((k >= 0) & (ts < W[k, 1])).tolist()
    assert got == want
    # windows exactly at their endpoints (half-open)
    for a, b in ws[:50]:
        assert s.active(a) and not s.active(b)


def _within(seconds, fn):
    def boom(*_):
        raise TimeoutError(f"still running after {seconds} s")

    old = signal.signal(signal.SIGALRM, boom)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        return fn()
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


def test_assumption3_many_windows_not_decided_on_horizon_but_long_run_exact():
    a = DoSAttack("a", {(0, 1)}, Periodic(period=1e-6, duration=5e-7))
    r = _within(3.0, lambda: check_assumption3([a], 10.0, mu_d=1.0, T_d=1.5))
    assert r.holds is None and r.witness is None and r.min_mu_d is None
    assert r.windows is None and r.total_blocked is None
    assert any("not computed" in n for n in r.notes)
    assert r.long_run_fraction == 0.5 and r.any_T_d_works is True
    with pytest.raises(InputError):
        r.min_mu_d_for(2.0)
    # a horizon under the cap is still decided exactly
    small = check_assumption3([a], 1e-4, mu_d=1.0, T_d=1.5)
    assert small.holds is True and small.windows is not None
