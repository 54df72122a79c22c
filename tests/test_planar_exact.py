"""The exact planar kernel point of the engine's fallback (``geometry._planar_exact``).

Sets the planar batch path declines (the nearest feature undecided in floats, a flat
kernel: converged states beside far adversary values) were computed through the whole
exact kernel, ~2.5 ms each — 270 of them took most of the paper example's 0.85 s.
``nearest_to_mean`` finds the same exact point by a direct construction; here it is
compared with the general path (``safe_kernel`` then ``exact_point``: valid
halfspaces, exact clipping, KKT in rationals) as the independent oracle, on sets
chosen to be hard: lattices ulps wide, duplicates, collinear and single-point sets,
far outliers, subnormal and 1e300 magnitudes, mixed scales."""

from __future__ import annotations

import warnings
from fractions import Fraction
from unittest import mock

import numpy as np
import pytest

from rescon.consensus import engine
from rescon.consensus.scenario import Scenario
from rescon.errors import EmptyKernel
from rescon.geometry._planar_exact import nearest_to_mean
from rescon.geometry.kernel import safe_kernel
from rescon.geometry.points import exact_point


def general(Y: np.ndarray, F: int) -> tuple[Fraction, ...] | None:
    """The general exact path's point nearest the mean (None: Ψ empty)."""
    try:
        return tuple(exact_point(safe_kernel(Y, F), method="project"))
    except EmptyKernel:
        return None


def hard_set(rng: np.random.Generator, kind: int, m: int) -> np.ndarray:
    """A planar set of m points of one of nine hard kinds."""
    if kind == 0:  # generic
        return rng.normal(size=(m, 2))
    if kind == 1:  # small integer lattice: collinear triples, duplicates
        return rng.integers(-3, 4, size=(m, 2)).astype(float)
    if kind == 2:  # converged: ulps apart, some far values
        c = rng.normal(size=2) * 10
        X = c + rng.integers(-2, 3, size=(m, 2)) * np.spacing(np.abs(c).max())
        k = int(rng.integers(0, m + 1))
        X[:k] += rng.normal(size=(k, 2)) * 10
        return X
    if kind == 3:  # collinear
        return np.outer(rng.normal(size=m), rng.normal(size=2)) + rng.normal(size=2)
    if kind == 4:  # one magnitude anywhere in the float range
        return rng.normal(size=(m, 2)) * 10.0 ** int(rng.integers(-310, 300))
    if kind == 5:  # subnormal lattice
        return rng.integers(-3, 4, size=(m, 2)) * 5e-324
    if kind == 6:  # a far outlier
        X = rng.normal(size=(m, 2))
        X[rng.integers(0, m)] = 1e300
        return X
    if kind == 7:  # every point three times
        return np.repeat(rng.normal(size=(max(1, m // 3), 2)), 3, axis=0)[:m]
    return rng.normal(size=(m, 2)) * 10.0 ** rng.integers(-20, 20, size=(m, 1))  # mixed


@pytest.mark.parametrize("kind", range(9))
def test_the_same_exact_point_as_the_general_path(kind):
    """Identical rationals (or both empty) on 60 sets of each kind, m = 1..15, every
    F < m with F ≤ (m − 1)/3 + 1 (a few beyond Tverberg's bound: possibly empty)."""
    rng = np.random.default_rng(1000 + kind)
    compared = 0
    for _ in range(60):
        m = int(rng.integers(1, 16))
        F = int(rng.integers(0, min(m, (m - 1) // 3 + 2)))
        Y = np.ascontiguousarray(hard_set(rng, kind, m))
        if not np.isfinite(Y).all():
            continue
        got, want = nearest_to_mean(Y, F), general(Y, F)
        assert (got is None) == (want is None), (Y, F, got, want)
        if want is not None:
            assert tuple(got) == want, (Y, F, got, want)
        compared += 1
    assert compared >= 50


def test_larger_converged_sets():
    """Up to the engine's PLANAR_EXACT_MAX points: converged lattices with far values."""
    rng = np.random.default_rng(7)
    for m in (16, 24, engine.PLANAR_EXACT_MAX):
        Y = hard_set(rng, 2, m)
        F = (m - 1) // 3
        assert tuple(nearest_to_mean(Y, F)) == general(Y, F)


@pytest.mark.parametrize("Y, F, want", [
    ([[1.0, 2.0]] * 4, 1, (1, 2)),  # one distinct point
    ([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0]], 1, (Fraction(3, 2), Fraction(3, 2))),
    ([[0.0, 0.0], [0.0, 0.0], [4.0, 0.0], [1.0, 0.0]], 1, (1, 0)),  # [0, 1] ∌ mean 5/4
    ([[0.0, 0.0], [0.0, 0.0], [2.0, 0.0], [1.0, 0.0]], 1, (Fraction(3, 4), 0)),  # ∋ mean
    ([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [2.0, 2.0], [1.0, 1.0]], 1, (1, 1)),  # Ψ a point
    ([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]], 1, None),  # empty
    ([[0.0, 0.0], [1.0, 0.0]], 1, None),  # collinear, F + 1 > n − F: empty
])
def test_small_cases_by_hand(Y, F, want):
    got = nearest_to_mean(np.array(Y), F)
    assert got == (None if want is None else tuple(Fraction(v) for v in want))
    assert general(np.array(Y), F) == got


def test_the_paper_example_computes_no_kernel_for_its_declined_sets():
    """The paper's example (200 steps): the ~270 sets the planar batch path declines
    were each a whole exact kernel (``safe_kernel``); now none is, and the states are
    bit for bit those of the general path (the planar construction switched off)."""
    def run():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return np.asarray(engine.simulate(Scenario.paper_example(steps=200)).states)

    calls: list[int] = []
    real = engine.safe_kernel
    with mock.patch.object(engine, "safe_kernel", lambda X, F: calls.append(1) or real(X, F)):
        fast = run()
    assert calls == []
    with mock.patch.object(engine, "PLANAR_EXACT_MAX", 0), \
            mock.patch.object(engine, "safe_kernel",
                              lambda X, F: calls.append(1) or real(X, F)):
        slow = run()
    assert len(calls) > 100  # the general path did the work
    assert np.array_equal(fast, slow)


def test_non_finite_sets_keep_the_general_paths_error():
    """A set with inf goes to the general path, whose InputError the engine reports."""
    from rescon.errors import InputError

    with pytest.raises(InputError):
        engine._kernel_points([np.array([[0.0, 0.0], [1.0, np.inf], [2.0, 1.0],
                                         [0.0, 3.0]])], 1, "project", {})


def test_spatial_sets_in_an_axis_plane_take_the_planar_construction():
    """Converged states in space reach sets with one coordinate the same in every point
    (the 3-d batch path declines them: their kernel is flat; the planar batch path then
    declines flat kernels too). Their exact point is (a, the planar point of the other
    coordinates): the same floats as the general path, without a kernel (failed
    before: every such set built one)."""
    rng = np.random.default_rng(5)
    base = np.array([5.04033371, 4.79010105, 5.14637996])
    sets = []
    for j in range(3):
        for _ in range(20):
            Y = base + rng.integers(-2, 3, size=(5, 3)) * np.spacing(base)
            Y[:, j] = base[j]
            sets.append(Y)
    sets.append(np.tile(base, (5, 1)))  # every coordinate constant
    want = np.array([[float(v) for v in general(Y, 1)] for Y in sets])
    calls: list[int] = []
    real = engine.safe_kernel
    with mock.patch.object(engine, "safe_kernel", lambda X, F: calls.append(1) or real(X, F)):
        got = engine._kernel_points(sets, 1, "project-exact", {})
    assert calls == []
    assert np.array_equal(got, want)


def test_a_far_constant_coordinate_does_not_count_for_the_wide_guard():
    """The wide-integer guard reads only the coordinates the planar construction uses:
    13 converged points with the constant third coordinate 1e300 keep the construction
    (V43 noticed the constant's exponent sent them to the general path), and give the
    general path's point."""
    rng = np.random.default_rng(9)
    Y = np.c_[5.0 + rng.integers(-2, 3, size=(13, 2)) * 2.0**-50, np.full(13, 1e300)]
    got = engine._planar_exact_point(Y, 4)
    assert got is not None and tuple(got) == general(Y, 4)
