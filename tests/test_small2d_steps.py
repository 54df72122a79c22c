"""The planar batch path's steps that exist to compile less (issue 12 §5): the numpy
cluster step and the written-out argsort give the floats of the numba code they
replace, bit for bit."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numba import njit

from rescon.geometry._small2d import (
    FLAT,
    INSERTION_RUN,
    _argsort,
    _clusters,
    _clusters_np,
)


def _tied(rng, shape, kind):
    """Values with many exact ties (and signed zeros), or ulp-close clusters."""
    if kind == 0:
        return rng.integers(-1, 2, size=shape).astype(float)
    if kind == 1:
        return rng.choice([0.0, -0.0, 1e-300, 2.0, -2.0], size=shape)
    if kind == 2:
        c = rng.normal(size=shape[:-2] + (1, shape[-1])) if len(shape) == 3 else 1.0
        return c + rng.integers(-2, 3, size=shape) * 1e-17
    return rng.normal(size=shape) * 10.0 ** rng.integers(-3, 3, size=shape)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), m=st.integers(1, INSERTION_RUN), kind=st.integers(0, 3),
       F=st.integers(0, 4))
def test_numpy_cluster_step_equals_the_kernel(seed, m, kind, F):
    F = min(F, (m - 1) // 3)  # the step runs for m ≥ 3F + 1
    Ys = np.ascontiguousarray(_tied(np.random.default_rng(seed), (30, m, 2), kind))
    runs = []
    for numpy_step in (False, True):
        out, err = np.full((30, 2), np.nan), np.full(30, np.nan)
        status = np.full(30, FLAT, dtype=np.int64)
        if numpy_step:
            _clusters_np(Ys, F, out, err, status)
        else:
            _clusters(Ys, np.arange(30), F, out, err, status)
        runs.append((out.tobytes(), err.tobytes(), status.tobytes()))
    assert runs[0] == runs[1]


@njit(cache=True)
def _numba_argsort(a):
    return np.argsort(a)


@njit(cache=True)
def _compiled_argsort(a):
    return _argsort(a)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(0, 70), kind=st.integers(0, 3))
def test_argsort_orders_ties_as_numba_does(seed, n, kind):
    """The same permutation as numba's np.argsort (its quicksort), ties included, above
    and below INSERTION_RUN; below it, numpy's stable argsort's."""
    a = np.ascontiguousarray(_tied(np.random.default_rng(seed), (n,), kind))
    order = _compiled_argsort(a)
    assert np.array_equal(order, _numba_argsort(a))
    if n <= INSERTION_RUN:
        assert np.array_equal(order, np.argsort(a, kind="stable"))
