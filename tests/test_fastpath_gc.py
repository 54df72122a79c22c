"""The d ≥ 4 fast path spaces the cyclic collector's runs (its first threshold raised
while it runs) instead of switching the collector off: V38 found that switching it
off and on undid a ``gc.disable()`` another thread made meanwhile. Checked: the
threshold is raised only during the call and restored after it — also after an
exception, with a caller's threshold of 0 (automatic collection off) left alone, and
across overlapping calls in threads (restored when the last ends)."""

from __future__ import annotations

import gc
import threading

import numpy as np
import pytest

import rescon
from rescon.geometry import fastpath


def _cloud(n: int = 14, d: int = 5, seed: int = 0) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(n, d))


@pytest.fixture
def thresholds():
    saved = gc.get_threshold()
    yield
    gc.set_threshold(*saved)


def test_threshold_raised_during_the_fast_path_and_restored(monkeypatch, thresholds):
    gc.set_threshold(700, 10, 10)
    seen = []
    real = fastpath._attempt

    def spy(*args, **kwargs):
        seen.append((gc.get_threshold(), gc.isenabled()))
        return real(*args, **kwargs)

    monkeypatch.setattr(fastpath, "_attempt", spy)
    K = rescon.safe_kernel(_cloud(), 1)
    assert seen and len(K.vertices)
    assert all(t == (fastpath.SPACED_THRESHOLD, 10, 10) and on for t, on in seen)
    assert gc.get_threshold() == (700, 10, 10) and gc.isenabled()


def test_callers_zero_threshold_is_left_alone(monkeypatch, thresholds):
    gc.set_threshold(0, 10, 10)  # the caller turned automatic collection off
    seen = []
    real = fastpath._attempt
    monkeypatch.setattr(fastpath, "_attempt",
                        lambda *a, **k: seen.append(gc.get_threshold()) or real(*a, **k))
    rescon.safe_kernel(_cloud(), 1)
    assert seen and all(t == (0, 10, 10) for t in seen)
    assert gc.get_threshold() == (0, 10, 10)


def test_restored_after_an_exception(monkeypatch, thresholds):
    gc.set_threshold(500, 7, 3)

    def boom(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(fastpath, "_attempt", boom)
    with pytest.raises(KeyboardInterrupt):
        rescon.safe_kernel(_cloud(), 1)
    assert gc.get_threshold() == (500, 7, 3)


def test_overlapping_calls_restore_when_the_last_ends(thresholds):
    gc.set_threshold(600, 10, 10)
    inside, release = threading.Event(), threading.Event()

    def first():
        with fastpath._collections_spaced():
            inside.set()
            release.wait(30)

    t = threading.Thread(target=first)
    t.start()
    assert inside.wait(30)
    with fastpath._collections_spaced():  # a second call while the first runs
        pass
    assert gc.get_threshold()[0] == fastpath.SPACED_THRESHOLD  # the first still runs
    release.set()
    t.join(30)
    assert gc.get_threshold() == (600, 10, 10)


def test_same_kernel_and_switch_kept_with_the_collector_off(thresholds):
    X = _cloud(16, 4, 3)
    a = rescon.safe_kernel(X, 2)
    gc.disable()
    try:
        b = rescon.safe_kernel(X, 2)
        assert not gc.isenabled()  # the caller's switch is kept
    finally:
        gc.enable()
    assert np.array_equal(a.vertices, b.vertices) and a == b
