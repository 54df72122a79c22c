"""R7: long runs and far optima in the DoS schedules and RMDO (fixes of V27 findings).

* ``RandomDoS.active`` is O(log K) (bisect of the cached starts), so a run's
  DoS masks cost O(K log K), not O(K^2).
"""

from __future__ import annotations

import time

import numpy as np

from rescon.consensus.dos import RandomDoS


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
