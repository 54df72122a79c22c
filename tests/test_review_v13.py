"""Hostile review V13 of the consensus engine at large N (issue 13 §1): the validity
monitor's fast paths (n > 64 initial states) and the diameter against independent exact
brute force (Fractions / integers), memory of the monitors when states leave the hull,
long converging runs, mixed magnitudes and the exact oracle the review tests share."""

from __future__ import annotations

import math
import tracemalloc
import warnings
from fractions import Fraction
from itertools import combinations

import networkx as nx
import numpy as np
import pytest
from conftest import solve_exact
from test_metrics_review import _exact_diameter, _seg2, _tri2, exact_distance

from rescon._rounding import UNIT_ROUNDOFF
from rescon.consensus.adversaries import Constant
from rescon.consensus.engine import simulate
from rescon.consensus.metrics import ValidityMonitor, diameter
from rescon.consensus.scenario import Scenario


def test_solve_exact_stays_exact_with_an_int_pivot_row():
    """The shared oracle divided an int pivot row by its int pivot (1 / 3 = 0.333…):
    its λ were floats, rounded, or an OverflowError on coordinates ~1e-300 (a
    collinear hull: the row of 1s became a pivot row)."""
    assert solve_exact([[3]], [1]) == [Fraction(1, 3)]
    col = [Fraction(2.0**-1000), Fraction(3 * 2.0**-1000)]
    assert solve_exact([col, [1, 1]], [Fraction(2.5 * 2.0**-1000), 1]) == [
        Fraction(1, 4), Fraction(3, 4)]


def _circle(n: int, d: int = 2, seed: int = 1) -> np.ndarray:
    X = np.random.default_rng(seed).standard_normal((n, d))
    return X / np.linalg.norm(X, axis=1)[:, None]


def test_distances_outside_a_many_sided_polygon_use_no_n_by_h_array():
    """States all just outside a 3000-gon (initial states on a circle, a residual ε
    pushing them out): distances() built the slacks of every outside state against
    every facet at once — (3000, 3000) arrays, 290 MB peak (3.2 GB at N = 10 000);
    now in blocks, same distances."""
    X0 = _circle(3000)
    mon = ValidityMonitor(X0)
    S = X0 * (1 + 2.0**-20)
    tracemalloc.start()
    got = mon.distances(S)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 100e6, peak
    err = mon.edge_error(S)
    for i in range(0, 3000, 500):
        want = mon.distance(S[i])  # the exact projection
        assert 0 < got[i] and abs(got[i] - want) <= err[i], (got[i], want)
