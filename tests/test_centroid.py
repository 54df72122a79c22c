"""The exact centroid of conv Λ (Cen(Λ) of the paper) in d ≤ 3."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial import Delaunay

from rescon.errors import InputError
from rescon.geometry.centroid import hull_centroid
from rescon.geometry.kernel import safe_kernel

CUBE = np.array([[i, j, k] for i in (0, 1) for j in (0, 1) for k in (0, 1)], dtype=float)


@pytest.mark.parametrize("X, expected", [
    ([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.25, 0.25, 0.25]),
    (CUBE, [0.5, 0.5, 0.5]),
    ([[0, 0], [3, 0], [0, 3], [0.5, 0.5]], [1, 1]),  # a point inside changes nothing
    ([[0, 0], [2, 0], [2, 2], [0, 2], [1, 0]], [1, 1]),  # nor one on an edge
    ([[0, 0, 1], [2, 0, 1], [0, 2, 1], [0.5, 0.5, 1]], [2 / 3, 2 / 3, 1]),  # flat in R^3
    ([[0, 0, 0], [3, 3, 3], [1, 1, 1], [1, 1, 1]], [1.5, 1.5, 1.5]),  # a segment
    ([[3, 1, 2], [3, 1, 2]], [3, 1, 2]),  # a point
    ([[-1.0], [4.0], [0.5]], [1.5]),
    # the area centroid, not the vertex mean: a triangle with a vertex repeated
    ([[0, 0], [0, 0], [6, 0], [0, 6]], [2, 2]),
])
def test_known_centroids(X, expected):
    assert np.array_equal(hull_centroid(np.array(X, dtype=float)), np.array(expected))


def test_area_not_vertex_mean():
    """A quadrilateral whose area centroid differs from its vertex mean."""
    X = np.array([[0, 0], [4, 0], [4, 1], [0, 3]], dtype=float)
    # triangles (0,0),(4,0),(4,1): area 2, centroid (8/3, 1/3);
    #           (0,0),(4,1),(0,3): area 6, centroid (4/3, 4/3)
    expected = (2 * np.array([8 / 3, 1 / 3]) + 6 * np.array([4 / 3, 4 / 3])) / 8
    assert np.allclose(hull_centroid(X), expected, rtol=0, atol=1e-15)
    assert not np.allclose(hull_centroid(X), X.mean(axis=0))


def test_polytope_with_coplanar_facet_points():
    """Extra points on the cube's faces and edges (facets with more than 3 points)."""
    extra = np.array([[0.5, 0.5, 0], [0.5, 0, 0.5], [1, 0.25, 0.75], [0.5, 0, 0]])
    assert np.array_equal(hull_centroid(np.vstack([CUBE, extra])), [0.5, 0.5, 0.5])


def _delaunay_centroid(X: np.ndarray) -> np.ndarray:
    tri = Delaunay(X)
    w = np.array([abs(np.linalg.det(X[s[1:]] - X[s[0]])) for s in tri.simplices])
    c = np.array([X[s].mean(axis=0) for s in tri.simplices])
    return w @ c / w.sum()


@settings(max_examples=60, deadline=None)
@given(d=st.integers(2, 3), seed=st.integers(0, 2**32 - 1), k=st.integers(-1000, 1000))
def test_matches_triangulation_lies_inside_and_scales_exactly(d, seed, k):
    X = np.random.default_rng(seed).normal(size=(2 * d, d))
    c = hull_centroid(X)
    assert np.allclose(c, _delaunay_centroid(X), rtol=0, atol=1e-12)
    assert safe_kernel(X, 0).contains(c)
    # exact in rationals: scaling by 2^k scales the answer exactly (no over/underflow)
    # (coordinates in the normal range: rounding commutes with scaling by 2^k there)
    scaled, expected = hull_centroid(np.ldexp(X, k)), np.ldexp(c, k)
    normal = np.abs(expected) > 2.0**-1000
    assert np.array_equal(scaled[normal], expected[normal])


@pytest.mark.parametrize("X", [np.zeros((3, 4)), np.zeros((0, 2)), [[np.nan, 0.0]], [1.0, 2.0]])
def test_bad_input(X):
    with pytest.raises(InputError, match="X must be"):
        hull_centroid(X)
