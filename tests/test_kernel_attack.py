"""Attack clouds (``benchmarks/kernel_clouds.py``, family ``attack``): n − F benign
points in N(0, 0.01² I) and F outliers at radius 100.

A hyperplane through an outlier and benign points has float cofactors that cancel
~1e12-fold in d = 5 (terms ~100⁴ against a normal ~100 · 0.01³), so their error bound
was as large as the normal itself; every (row, vertex) pair of the fast path's
certification then fell inside its rounding bound and was decided in Python integers
(attack(5, 30, 3): 12.7 M pairs, ~130 CPU-s). Such rows now carry their exact normal,
rounded (:func:`rescon.geometry.halfspaces.valid_halfspaces`). Checked here: the float
rows' bounds are tight and hold against the exact normals, and the fast path certifies
kernels bit-identical to the exact clipping.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest

import rescon
from benchmarks.kernel_clouds import make_cloud
from rescon.geometry import kernel as km
from tests.test_review_v2 import _clipped


def _spied(X, F):
    """safe_kernel(X, F), the Halfspaces the fast path saw and what it returned."""
    seen = {}
    original = km.certified_kernel

    def spy(H, k, scale, first):
        seen["H"] = H
        seen["P"] = original(H, k, scale, first)
        return seen["P"]

    km.certified_kernel = spy
    try:
        K = rescon.safe_kernel(X, F)
    finally:
        km.certified_kernel = original
    return K, seen["H"], seen["P"]


def _check_rows(H):
    """Every float row's error bound is below 1e-9 of the row (no cancelled cofactor
    left with its huge bound), and the float direction is within that bound of the
    exact normal's."""
    l1, perm, _ = H.row_terms()
    assert (H.c_err * perm <= 1e-9 * l1).all(), (H.c_err * perm / l1).max()
    for h in range(len(H)):
        a = [Fraction(v) for v in H.exact(h)[0]]
        top_a, top_f = max(map(abs, a)), float(np.abs(H.af[h]).max())
        bound = 4 * H.c_err * perm[h] / top_f + 1e-15
        for fj, aj in zip(H.af[h].tolist(), a, strict=True):
            assert abs(Fraction(fj) / Fraction(top_f) - aj / top_a) <= Fraction(bound)


@pytest.mark.parametrize(("d", "n", "F"), [(3, 24, 2), (4, 16, 2), (4, 18, 3), (5, 12, 2)])
def test_attack_fast_path_is_the_exact_clipping(d, n, F):
    X = make_cloud("attack", d, n, F).X
    K, H, P = _spied(X, F)
    assert P is not None  # the fast path certified it
    _check_rows(H)
    E = _clipped(X, F)
    assert K.exact_vertices == E.exact_vertices
    assert K._exact.constraints == E._exact.constraints


@pytest.mark.parametrize(("family", "d", "n", "F"),
                         [("attack", 4, 50, 3), ("attack", 5, 20, 3), ("converged", 4, 30, 3)])
def test_rows_are_well_conditioned(family, d, n, F):
    """Also the ``converged`` family (a tight cluster, outliers at 1–10): converged(5,
    30, 3) took 163 CPU-s in the certification's integer slacks, 5 now."""
    K, H, P = _spied(make_cloud(family, d, n, F).X, F)
    assert P is not None
    _check_rows(H)


@pytest.mark.slow
def test_attack_5_30_3_certified_fast():
    K, H, P = _spied(make_cloud("attack", 5, 30, 3).X, 3)
    assert P is not None
    _check_rows(H)
    assert len(K.vertices) == len(P.verts)
