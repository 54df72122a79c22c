"""Work the d = 4-5 fast path shares instead of redoing (issue 13 §3): the fast path's
tight pairs read by the incidence, and its compiled passes on threads taking ranges as
they come — each against the computation it replaces."""

from __future__ import annotations

from math import comb

import numpy as np
import pytest

from rescon.geometry import _candidates
from rescon.geometry.polytope import members_of, tight_pairs
from tests.test_kernel_d45 import _both_paths
from tests.test_kernel_d45_around2 import KINDS, _points


def _clouds():
    rng = np.random.default_rng(5)
    yield rng.normal(size=(24, 4)), 3
    yield rng.integers(-3, 4, size=(22, 4)).astype(float), 2  # ties, coplanar points
    yield rng.normal(size=(16, 5)), 1
    yield 1.0 + 1e-13 * rng.normal(size=(20, 4)), 2  # converged states


@pytest.mark.parametrize("case", range(3))  # the converged cloud needs the centring
def test_fast_path_pairs_are_the_tight_pairs_and_give_the_same_incidence(case):
    X, F = list(_clouds())[case]
    fast, box, _, _, _ = _both_paths(X, F)
    assert fast is not None
    vs, hs = tight_pairs(fast.tight)
    assert np.array_equal(fast.pairs[0], vs) and np.array_equal(fast.pairs[1], hs)
    assert fast.incidence() == members_of(fast.tight)
    assert box.pairs is None  # the clipping path has none


def test_a_clip_drops_the_pairs():
    X, F = list(_clouds())[0]
    fast, *_ = _both_paths(X, F)
    V = fast.float_vertices()
    j = int(np.argmax(V[:, 0]))
    w, y0, *_ = fast.verts[j]
    # y_0 ≤ the float vertex's coordinate floored: cuts the vertex j off
    assert fast.clip((1,) + (0,) * (fast.k - 1), y0 // w - 1)
    assert fast.pairs is None
    assert fast.incidence() == members_of(fast.tight)
    # a clip that empties the polytope drops them too
    fast2, *_ = _both_paths(X, F)
    lo = min(v[1] // v[0] for v in fast2.verts)
    assert fast2.clip((1,) + (0,) * (fast2.k - 1), lo - 10**6)
    assert fast2.pairs is None and fast2.incidence() == {}


#: the threaded pass itself (the tests below replace it by spies and one-thread twins)
ON_THREADS = _candidates.on_threads


def _one_thread(scan, total, chunks, workers=None):
    ON_THREADS(scan, total, 1)


@pytest.fixture
def thread_passes(monkeypatch):
    """The chunk counts of the threaded passes a test makes (they still run)."""
    ran = []

    def spy(scan, total, chunks, workers=None):
        ran.append(chunks)
        ON_THREADS(scan, total, chunks, workers)

    monkeypatch.setattr(_candidates, "on_threads", spy)
    return ran


@pytest.mark.parametrize("workers", [2, 3])
@pytest.mark.parametrize(("k", "m"), [(3, 40), (4, 22), (5, 17)])
@pytest.mark.parametrize("kind", KINDS)
def test_threaded_scan_equals_the_unsplit_scan(kind, k, m, workers):
    """:func:`_candidates.classify` on threads taking ranges as they come gives the
    arrays of one thread scanning every subset at once, the exact-float case (c_err =
    0: ties, degenerate subsets) and the rounding-bound one (c_err > 0) alike."""
    Y = _points(kind, k, m, workers)
    W = np.random.default_rng([m, workers]).integers(1, 3, size=m)
    S = _candidates.k_subsets(m, k, comb(m, k))
    assert len(S) >= _candidates.PARALLEL_MIN_SUBSETS  # the threaded branch runs
    for c_err, F in [(0.0, 1), (1e-12, 2)]:
        want = _candidates.classify(Y, W, S, c_err, F, 1e-300, 1)  # one range, unsplit
        got = _candidates.classify(Y, W, S, c_err, F, 1e-300, workers)
        assert all(np.array_equal(a, b) for a, b in zip(want, got, strict=True))


def test_a_failing_range_raises_from_the_threaded_scan(monkeypatch):
    def broken(*args):
        raise RuntimeError("range failed")

    monkeypatch.setattr(_candidates, "_classify_range", broken)
    Y = _points("normal", 4, 22, 0)
    S = _candidates.k_subsets(22, 4, comb(22, 4))
    with pytest.raises(RuntimeError, match="range failed"):
        _candidates.classify(Y, np.ones(22, dtype=np.int64), S, 1e-12, 1, 0.0, 2)


@pytest.mark.parametrize("seed", range(2))
def test_near_pairs_on_threads_equal_one_thread_and_brute_force(seed, monkeypatch,
                                                                 thread_passes):
    """Enough rows × chunks for the threaded passes (rows with more near points than
    NEAR_KEPT among them, scanned again): the pairs of one thread, and every slack's."""
    from rescon.geometry._candidates import NEAR_KEPT, near_pairs

    rng = np.random.default_rng(seed)
    k, nv, m = 4, 900, 1000
    V = rng.uniform(-1.0, 1.0, size=(nv, k))
    V[: 2 * NEAR_KEPT, 0] = 2.0  # on the hyperplane x_0 = 2 of row 0
    A = rng.normal(size=(m, k))
    A[0] = [1, 0, 0, 0]
    b = (A @ V.T).max(axis=1) + rng.uniform(0.0, 1.0, m)
    b[0] = 2.0
    b[1::3] = (A[1::3] @ V.T).max(axis=1)  # rows touching their highest point
    A_abs, b_abs = np.abs(A) * 1.01, np.abs(b) * 1.01
    c_err, c = 1e-12, 32 * 2.0**-53
    M = np.abs(V).max()
    coarse = c_err * (A_abs.sum(axis=1) * M + b_abs) + c * (np.abs(A).sum(axis=1) * M
                                                            + np.abs(b))
    S = A @ V.T - b[:, None]
    bound = c_err * (A_abs @ np.abs(V).T + b_abs[:, None]) + c * (
        np.abs(A) @ np.abs(V).T + np.abs(b)[:, None])
    want = sorted(zip(*np.nonzero((np.abs(S) <= coarse[:, None]) & ~(np.abs(S) > bound)),
                      strict=True))
    got_r, got_v = near_pairs(A, b, A_abs, b_abs, V, coarse, c_err, c, 0.0)
    assert thread_passes == [64, 64]  # both passes on threads
    monkeypatch.setattr(_candidates, "on_threads", _one_thread)
    one_r, one_v = near_pairs(A, b, A_abs, b_abs, V, coarse, c_err, c, 0.0)
    assert got_r.tolist() == one_r.tolist() and got_v.tolist() == one_v.tolist()
    assert sorted(zip(got_r.tolist(), got_v.tolist(), strict=True)) == [
        (int(r), int(v)) for r, v in want]


def test_row_top_on_threads_equals_one_thread(thread_passes):
    """Enough rows × chunks for the threaded pass: the bounds of the calling thread
    alone, bit for bit, and never below the true maxima."""
    from rescon.geometry._candidates import row_top

    rng = np.random.default_rng(3)
    V = rng.normal(size=(1200, 4))
    A = rng.normal(size=(900, 4))
    b = (A @ V.T).max(axis=1) + rng.uniform(-0.1, 0.5, 900)
    got = row_top(A, b, V, 0.0)
    one = row_top(A, b, V, 0.0, parallel=False)
    assert thread_passes == [64, 1]
    assert np.array_equal(got, one)
    assert (got >= (A @ V.T - b[:, None]).max(axis=1) - 1e-12).all()


def test_cofactors_on_threads_equal_one_thread(monkeypatch):
    Y = _points("normal", 4, 30, 1)
    S = _candidates.k_subsets(30, 4, comb(30, 4))
    assert len(S) >= _candidates.COFACTOR_THREADS_MIN
    got = _candidates.cofactors(Y, S)
    monkeypatch.setattr(_candidates, "on_threads", _one_thread)
    one = _candidates.cofactors(Y, S)
    assert all(np.array_equal(a, b) for a, b in zip(got, one, strict=True))
    rows = [3, 17, len(S) - 1]  # against the numpy twin too
    from rescon.geometry import _scan_np

    for a, b in zip(_candidates.cofactors(Y, S[rows]), _scan_np.cofactors(Y, S[rows]),
                    strict=True):
        assert np.array_equal(a, b)


def test_a_copy_of_a_fast_polytope_has_no_pairs():
    """``pairs`` is not an init field: ``dataclasses.replace`` with new bitsets cannot
    carry the old pairs to the incidence (V15's finding, failed before)."""
    import dataclasses

    X, F = list(_clouds())[0]
    fast, *_ = _both_paths(X, F)
    Q = dataclasses.replace(fast, tight=[t | 1 << (len(fast.a) - 1) for t in fast.tight])
    assert Q.pairs is None and Q.incidence() == members_of(Q.tight)


def test_no_range_starts_after_a_failure():
    """A failing range stops the pass: the other threads start no further range
    (V15's finding: they took every remaining one, failed before)."""
    import threading
    import time

    started, lock = [], threading.Lock()

    def scan(lo, hi):
        with lock:
            started.append(lo)
        if lo == 0:
            raise RuntimeError("range failed")
        time.sleep(0.002)

    with pytest.raises(RuntimeError, match="range failed"):
        _candidates.on_threads(scan, 64, 64, workers=2)
    assert len(started) <= 4
