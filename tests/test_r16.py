"""R16: d = 5 safe kernels with less qhull and Python work, the same answers.

* qhull's options in d = 5 (the merged proposal and a failed half's retry) leave out
  the final pass over the outer planes ("Q5"): the same dual facets and intersections,
  bit for bit, on the halves of d = 5 benchmark clouds, and the same failure where
  "C-0 Q14" fails (sphere(5, 30, 3)'s lower half);
* ``fastpath._qhull`` reads only the dual facets and equations (``fastpath._lean``: no
  volume and area of the dual hull): the same floats and facets as scipy's
  HalfspaceIntersection; a stand-in that is not such a class is used as it is;
* ``fastpath._halves`` (vectorised; the float ranks of the cut's vertices batched)
  against the per-vertex loops it replaces;
* the kernels of sphere(5, 30, 1) and sphere(5, 30, 3) pinned to those of the code
  before (floats bit for bit, exact vertices and constraints).
"""

from __future__ import annotations

import hashlib
import itertools

import numpy as np
import pytest
import scipy.spatial as sp

import rescon
from rescon.geometry import fastpath
from tests.test_kernel_d45_around2 import _cloud


def _recorded_rows(monkeypatch, kind: str, n: int, F: int) -> list:
    """The (A, b, x0, options) of every qhull intersection of the kernel of the d = 5
    benchmark cloud (kind, n, F)."""
    real, seen = fastpath._qhull, []

    def record(A, b, x0, options):
        seen.append((A.copy(), b.copy(), x0.copy(), options))
        return real(A, b, x0, options)

    with monkeypatch.context() as mp:
        mp.setattr(fastpath, "_qhull", record)
        rescon.safe_kernel(_cloud(kind, 5, n, F), F)
    return seen


def _scipy(A, b, x0, options):
    """scipy's own HalfspaceIntersection (every attribute computed), or None."""
    try:
        hs = sp.HalfspaceIntersection(np.hstack([A, -b[:, None]]), x0,
                                      qhull_options=options)
    except sp.QhullError:
        return None
    return hs.intersections, hs.dual_facets


def _without_q5(options: str) -> str:
    return " ".join(o for o in options.split() if o != "Q5")


def test_d5_options_skip_the_outer_plane_pass():
    assert "Q5" in fastpath.MERGED_OPTIONS_5D[0].split()
    assert "Q5" in fastpath.HALF_RETRY_OPTIONS.split()
    assert _without_q5(fastpath.MERGED_OPTIONS_5D[0]) == "C-0 Q14"


@pytest.mark.parametrize(("kind", "n", "F"), [("gaussian", 20, 2), ("cube", 20, 1),
                                               ("sphere", 30, 3)])
def test_d5_q5_halves_are_the_proposals_without_it_bit_for_bit(monkeypatch, kind, n, F):
    """Every qhull run of the kernel (the halves; sphere(5, 30, 3)'s lower half fails
    with the merged option and is retried): with and without "Q5", the same failure or
    the same dual facets and intersections, bit for bit — through fastpath._qhull
    (lean) and through scipy's full class."""
    seen = _recorded_rows(monkeypatch, kind, n, F)
    assert any(o and "Q5" in o.split() for *_, o in seen)
    for A, b, x0, options in seen:
        if not options or "Q5" not in options.split():
            continue
        ours, theirs = fastpath._qhull(A, b, x0, options), _scipy(A, b, x0,
                                                                 _without_q5(options))
        assert (ours is None) == (theirs is None)
        if ours is not None:
            assert ours[0].tobytes() == theirs[0].tobytes()
            assert ours[1] == theirs[1]
    if (kind, n, F) == ("sphere", 30, 3):
        assert any(fastpath._qhull(A, b, x0, o) is None for A, b, x0, o in seen)


def test_lean_intersection_skips_the_volume_and_equals_scipy():
    """The lean class computes no dual volume or area and gives scipy's floats and
    facets; a stand-in function is used unchanged."""
    rng = np.random.default_rng(16)
    A = rng.normal(size=(200, 5))
    b = np.linalg.norm(A, axis=1) * (1.0 + rng.random(200))
    lean = fastpath._lean(sp.HalfspaceIntersection)
    assert lean is not sp.HalfspaceIntersection and issubclass(lean, sp.HalfspaceIntersection)
    hs = lean(np.hstack([A, -b[:, None]]), np.zeros(5), qhull_options="C-0 Q14 Q5")
    assert not hasattr(hs, "dual_volume")
    full = _scipy(A, b, np.zeros(5), "C-0 Q14 Q5")
    assert hs.intersections.tobytes() == full[0].tobytes()
    assert hs.dual_facets == full[1]

    def stand_in(*args, **kw):
        return None

    assert fastpath._lean(stand_in) is stand_in


def _halves_by_loop(A, b, x0, r, options, axis):
    """fastpath._halves as it was: the halves' vertices one by one, the vertices on
    the cut by :func:`_on_the_cut_by_loop`."""
    k, m = A.shape[1], len(A)
    cut = np.zeros(k)
    cut[axis] = 1.0
    shift = 0.5 * r * cut
    found = [fastpath._qhull(np.vstack([A, cut]), np.append(b, x0[axis]), x0 - shift,
                             options),
             fastpath._qhull(np.vstack([A, -cut]), np.append(b, -x0[axis]), x0 + shift,
                             options)]
    if found[0] is None or found[1] is None:
        return None
    points, facets, cuts = [], [], []
    for V, dual in found:
        on = [m in f for f in dual]
        for i, f in enumerate(dual):
            if not on[i]:
                points.append(V[i])
                facets.append(f)
        at = np.flatnonzero(on)
        cuts.append((V[at], [[h for h in dual[i] if h != m] for i in at.tolist()]))
    more = _on_the_cut_by_loop(A, k, *cuts[0], *cuts[1])
    if more is None:
        return None
    for p, f in more:
        points.append(p)
        facets.append(f)
    return (np.array(points), facets) if facets else None


def _on_the_cut_by_loop(A, k, V0, rows0, V1, rows1):
    """fastpath._on_the_cut as it was: one float rank per set of rows."""
    from scipy.spatial import cKDTree

    if len(V0) != len(V1):
        return None
    if not len(V0):
        return []
    tol = 1e-9 * (1.0 + max(np.abs(V0).max(), np.abs(V1).max()))
    gap, match = cKDTree(V1).query(V0, p=np.inf)
    if not (gap <= tol).all() or len(np.unique(match)) != len(V0):
        return None
    out, seen = [], set()
    for i, j in enumerate(match.tolist()):
        rows = sorted(set(rows0[i]).union(rows1[j]))
        if len(rows) < k or tuple(rows) in seen:
            continue
        seen.add(tuple(rows))
        if np.linalg.matrix_rank(A[rows]) == k:
            out.append((V0[i], rows))
    return out


@pytest.mark.parametrize(("seed", "axis"), list(itertools.product(range(4), range(2))))
def test_vectorised_halves_equal_the_loop(seed, axis):
    """Random polytopes (tangent planes of a sphere, some through a common point, and
    the cross-polytope, whose vertices lie on the cut — each proposed from the union of
    both halves' rows, rank k): the same points, bit for bit, and the same rows, in the
    same order."""
    rng = np.random.default_rng([16, seed])
    if seed == 3:
        A = np.array(list(itertools.product((-1.0, 1.0), repeat=5)))
        b = np.ones(len(A))
    else:
        A = rng.normal(size=(300, 5))
        b = np.linalg.norm(A, axis=1)
        b[:40] = A[:40] @ (0.3 * np.ones(5)) + 0.5 * np.linalg.norm(A[:40], axis=1)
    norms = np.linalg.norm(A, axis=1)
    A, b = A / norms[:, None], b / norms
    box = (np.full(5, -1e3), np.full(5, 1e3))
    x0, r = fastpath._chebyshev(A, b, *box, np.zeros(5))
    options = fastpath.MERGED_OPTIONS_5D[0]
    got, want = fastpath._halves(A, b, x0, r, options, axis), _halves_by_loop(
        A, b, x0, r, options, axis)
    assert (got is None) == (want is None)
    if got is not None:
        assert got[0].tobytes() == want[0].tobytes() and got[0].shape == want[0].shape
        assert got[1] == want[1]


#: sha256 of (float vertices, A, b, exact vertices, exact constraints) of the kernels
#: at the code before R16 (dd426a9)
PINNED = {
    1: "5ec16a57aea9de3acbe7a501ea85533394e58c8b122b72f76f67d0b0e1541221",
    3: "b1a72411bcf0048a060275636d1e1ae3f8bf337b906d2de73b1cf8d18de3af9d",
}


@pytest.mark.parametrize("F", [1, 3])
def test_sphere_5_30_kernels_are_those_before(F):
    K = rescon.safe_kernel(_cloud("sphere", 5, 30, F), F)
    digest = hashlib.sha256(repr((K.vertices.tobytes(), K.A.tobytes(), K.b.tobytes(),
                                  K.exact_vertices, K._exact.constraints)).encode())
    assert digest.hexdigest() == PINNED[F]
