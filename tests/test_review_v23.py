"""Review V23: a hostile review of the threaded d ≥ 5 proposal, closure and proof
(commits 18551ef, aeae10b, de4c1eb): qhull's halfspace intersection run as two halves
P ∩ {x_j ≤ c}, P ∩ {x_j ≥ c} on two threads (``fastpath._halves``, ``_on_the_cut``,
the second axis and the whole polytope as fallbacks, ``_attempt``'s unsplit retry),
the closure's check on ranges of vertices (``_closure._closures``,
``_simple_check``) and the proof of the vertex floats on ranges of proposals
(``_vertex_floats.rounded_points``).

Attacked: cuts forced exactly through vertices of P and 1 ulp beside them (an interior
point with the vertex's coordinate, ½x0 + ½q, radius r/2); symmetric clouds (reflections
across x_1 and x_2: many vertices on the cut), small-integer clouds, clouds with shared
coordinates; qhull failing selectively on a half, on both axes, on the whole polytope;
halves whose sections do not match; tampered halves' proposals (a bogus point, a moved
point, every point twice, a vertex dropped); ``_on_the_cut`` with crafted inputs
(unequal counts, two points matching one, gaps, rank k − 1 pairs, repeated unions,
2^990 magnitudes); hostile thread schedules (uneven, empty, shuffled ranges on 5
threads: tests/test_review_v15._hostile) with the threading thresholds lowered so every
threaded branch runs on small clouds; numba's thread count 1 and 2; concurrent
safe_kernel calls from user threads; d = 6; 2^±990. Every kernel is compared bit for
bit with the exact clipping (the fast path off). SPLIT_ROWS is lowered here so that
small clouds (clipping well under a second) run as halves.

Found: off-centre clouds (data around 100 or 1000) make qhull fail on a half on both
axes for every qhull option, and nothing remembers it — 1.6–2.4× the CPU and ~1.7× the
wall time of the code before this session on gaussian(5, 30, 3) + 100; and a latent
overflow in ``_on_the_cut``'s KD-tree beyond 2^511 (unreachable: qhull sees the kernel
at unit size). Both fixed (the tests below were strict xfails).

Held, beside these tests: 68 clouds (17 families, d = 5, n = 16–22, F = 1–3; 45 of
them split into halves) identical to the exact clipping, with the same vertex counts
as the code before this session (46b0fa8), whose fast path fails on the same 4 clouds
(pairs of points 1 ulp apart: both fall back to the clipping); 202 small clouds
(d = 5–6, 13 families) with SPLIT_ROWS = 20, every threaded branch on, the hostile
scheduler and the cut forced through or 1 ulp beside vertices: all identical to the
exact clipping."""

from __future__ import annotations

import functools
import itertools
import threading
from concurrent.futures import ThreadPoolExecutor

import numba
import numpy as np
import pytest

import rescon
from rescon.geometry import _candidates, _closure, _vertex_floats, fastpath
from rescon.geometry import kernel as km
from tests.test_kernel_d45_around2 import assert_identical
from tests.test_review_r2 import _fast_path_calls
from tests.test_review_v15 import _hostile

#: small clouds run as halves with this many rows
FEW_ROWS = 40


def _cloud(kind: str, d: int, n: int, F: int, seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng([23, d, n, F, seed])
    if kind == "reflect1":  # symmetric across x_1 = 0: vertices on the cut
        h = rng.normal(size=(n // 2, d))
        m = h.copy()
        m[:, 0] *= -1
        return np.vstack([h, m] + ([np.zeros((1, d))] if n % 2 else []))
    if kind == "reflect12":  # across x_1 = 0 and x_2 = 0
        q = rng.normal(size=(n // 4 + 1, d))
        out = []
        for s1, s2 in itertools.product((1, -1), repeat=2):
            c = q.copy()
            c[:, 0] *= s1
            c[:, 1] *= s2
            out.append(c)
        return np.vstack(out)[:n]
    if kind == "intgrid":  # small integers: many vertices share coordinates
        return rng.integers(-2, 3, size=(n, d)).astype(float)
    if kind == "samecol":  # half the points with x_1 = 0, half with x_2 = 0
        Z = rng.normal(size=(n, d))
        Z[: n // 2, 0] = 0.0
        Z[n // 4: 3 * n // 4, 1] = 0.0
        return Z
    if kind == "dup":
        Z = rng.normal(size=(n // 2 + 2, d))
        return np.vstack([Z, Z[: n - len(Z)]])
    return rng.normal(size=(n, d))


CLOUDS = {"reflect1": ("reflect1", 5, 12, 1), "intgrid": ("intgrid", 5, 14, 1),
          "reflect12": ("reflect12", 5, 14, 1), "gaussian6": ("gaussian", 6, 10, 1),
          "samecol": ("samecol", 5, 14, 1)}


@functools.cache
def _clipped(name: str, scale: float = 1.0) -> rescon.SafeKernel:
    """The exact clipping's kernel (the fast path off)."""
    kind, d, n, F = CLOUDS[name]
    real = km.certified_kernel
    km.certified_kernel = lambda *a: None
    try:
        return rescon.safe_kernel(_cloud(kind, d, n, F) * scale, F)
    finally:
        km.certified_kernel = real


def _fast(name: str, scale: float = 1.0) -> rescon.SafeKernel:
    kind, d, n, F = CLOUDS[name]
    return rescon.safe_kernel(_cloud(kind, d, n, F) * scale, F)


@pytest.fixture
def few_rows(monkeypatch):
    """Halves from FEW_ROWS rows on; records each _halves call (axis, rows, accepted)."""
    monkeypatch.setattr(fastpath, "SPLIT_ROWS", FEW_ROWS)
    real, calls = fastpath._halves, []

    def spy(*args):
        found = real(*args)
        calls.append((args[-1], len(args[0]), found is not None))
        return found

    monkeypatch.setattr(fastpath, "_halves", spy)
    return calls


# --------------------------------------------------------------------------- #
# _on_the_cut with crafted inputs
# --------------------------------------------------------------------------- #

A5 = np.vstack([np.eye(5), -np.eye(5), np.ones((1, 5)) / np.sqrt(5)])


def test_on_the_cut_unequal_counts_or_none_at_all():
    V = np.zeros((2, 5))
    assert fastpath._on_the_cut(A5, 5, V, [[0], [1]], V[:1], [[2]]) is None
    assert fastpath._on_the_cut(A5, 5, V[:0], [], V[:0], []) == []


def test_on_the_cut_two_points_on_one_partner_are_refused():
    """Two points of one half nearest to the same point of the other: no matching."""
    V0 = np.array([[0.0, 1, 0, 0, 0], [0.0, 1 + 1e-13, 0, 0, 0]])
    V1 = np.array([[0.0, 1, 0, 0, 0], [0.0, 5, 0, 0, 0]])
    rows = [[1, 2, 3], [1, 2, 3]]
    assert fastpath._on_the_cut(A5, 5, V0, rows, V1, rows) is None


def test_on_the_cut_gap_beyond_the_tolerance_is_refused():
    V0 = np.array([[0.0, 1, 0, 0, 0]])
    V1 = V0 + [[0.0, 3e-9, 0, 0, 0]]
    assert fastpath._on_the_cut(A5, 5, V0, [[1, 2, 3, 4]], V1, [[1, 2]]) is None
    V1 = V0 + [[0.0, 1e-10, 0, 0, 0]]  # within 1e-9 (1 + max |x|)
    (p, rows), = fastpath._on_the_cut(A5, 5, V0, [[1, 2, 3, 4]], V1, [[5]])
    assert p.tolist() == V0[0].tolist() and rows == [1, 2, 3, 4, 5]


def test_on_the_cut_rank_k_once_rank_k_minus_1_left_out():
    """Matched pairs in shuffled order: the union of both halves' rows, sorted; a union
    of rank 4 (an edge crossing the cut: e_2..e_5 and −e_2) left out, two pairs with the
    same union of rank 5 proposed once, the cut's row never among them."""
    V0 = np.array([[0.0, 0, 0, 0, 0], [0.0, 1, 0, 0, 0], [0.0, 2, 0, 0, 0],
                   [0.0, 3, 0, 0, 0]])
    V1 = V0[[2, 0, 1, 3]]
    rows0 = [[1, 2, 3, 4], [0, 1, 2], [2, 1, 0, 3], [10, 1]]
    rows1 = [[4, 0], [6], [3, 4], [2, 3, 4]]
    out = fastpath._on_the_cut(A5, 5, V0, rows0, V1, rows1)
    assert [(p.tolist(), r) for p, r in out] == [(V0[1].tolist(), [0, 1, 2, 3, 4]),
                                                 (V0[3].tolist(), [1, 2, 3, 4, 10])]


def test_qhull_never_hands_a_non_finite_point_to_the_matching(monkeypatch):
    """_on_the_cut's KD-tree raises on NaN or inf (ValueError): the only producer,
    _qhull, refuses a non-finite intersection, so no such point reaches it."""
    import scipy.spatial

    class Fake:
        def __init__(self, *a, **kw):
            self.intersections = np.array([[np.nan] * 5, [0.0] * 5])
            self.dual_facets = [[0, 1, 2, 3, 4], [5, 6, 7, 8, 9]]

    monkeypatch.setattr(scipy.spatial, "HalfspaceIntersection", Fake)
    assert fastpath._qhull(A5, np.ones(len(A5)), np.zeros(5), None) is None
    with pytest.raises(ValueError):
        fastpath._on_the_cut(A5, 5, Fake().intersections, [[0], [1]],
                             Fake().intersections, [[0], [1]])


# Fixed (was a latent bug, unreachable through safe_kernel, whose floats reach qhull at
# unit size: _on_the_cut's KD-tree squares coordinate differences — beyond 2^511 the gap
# of two floats 1 ulp apart overflowed to inf and the matched halves were refused; the
# nearest point is now found in the largest coordinate gap, nothing squared).
def test_on_the_cut_matches_points_one_ulp_apart_at_2_990():
    """Two cut points ~2^990 apart, each matched to its twin 1 ulp away in every
    coordinate (squared gaps ~2^1876 overflowed)."""
    V0 = np.array([[2.0**990, 2.0**989, 0.0, 1.0, 2.0], [2.0**990, -2.0**989, 0.0, 3.0, 4.0]])
    V1 = np.nextafter(V0, np.inf)
    A = np.vstack([np.eye(5)] * 2)
    out = fastpath._on_the_cut(A, 5, V0, [[0, 1, 2, 3], [5, 6, 7, 8]], V1, [[4], [9]])
    assert out is not None and len(out) == 2


# --------------------------------------------------------------------------- #
# cuts forced through vertices of P, or 1 ulp beside them
# --------------------------------------------------------------------------- #

def _forced(mode: str, log: list):
    """_halves with its cut moved to the coordinate most vertices of P share (the middle
    40 % of their range), or 1 ulp above / below it: the interior point ½x0 + ½q (q on
    the segment between the extreme vertices along the axis), radius r/2."""
    real_halves, real_qhull = fastpath._halves, fastpath._qhull

    def halves(A, b, x0, r, options, axis=0):
        whole = real_qhull(A, b, x0, options)
        if whole is None:
            return real_halves(A, b, x0, r, options, axis)
        V = whole[0]
        col = V[:, axis]
        span = col.max() - col.min()
        mid = (col > col.min() + 0.3 * span) & (col < col.max() - 0.3 * span)
        vals, counts = np.unique(col[mid], return_counts=True)
        if not len(vals):
            return real_halves(A, b, x0, r, options, axis)
        c = vals[np.argmax(counts)]
        c = {"on": c, "up": np.nextafter(c, np.inf), "down": np.nextafter(c, -np.inf)}[mode]
        hi, lo = V[np.argmax(col)], V[np.argmin(col)]
        lam = (2 * c - x0[axis] - lo[axis]) / (hi[axis] - lo[axis])
        if not 0.0 < lam < 1.0:  # no interior point ½x0 + ½q on the cut
            return real_halves(A, b, x0, r, options, axis)
        p = 0.5 * x0 + 0.5 * (lam * hi + (1 - lam) * lo)
        p[axis] = c
        found = real_halves(A, b, p, 0.5 * r, options, axis)
        log.append((int(counts.max()), found is not None))
        return found

    return halves


@pytest.mark.parametrize("mode", ["on", "up", "down"])
@pytest.mark.parametrize("name", ["reflect1", "intgrid", "reflect12"])
def test_cut_through_vertices_or_one_ulp_beside(name, mode, few_rows, monkeypatch):
    log: list = []
    monkeypatch.setattr(fastpath, "_halves", _forced(mode, log))
    cert = _fast_path_calls(monkeypatch)
    assert_identical(_fast(name), _clipped(name))
    assert log and cert == [True]


def test_natural_cut_through_the_symmetric_kernels_vertices(few_rows, monkeypatch):
    """A cloud symmetric across x_1 = 0: the Chebyshev centre's x_1 is 0 (−0.0), so the
    cut x_1 = c holds every vertex of the kernel on the mirror plane — matched across
    the halves, united, certified, the exact clipping's."""
    real, cuts = fastpath._halves, []

    def spy(A, b, x0, r, options, axis=0):
        cuts.append(x0[axis])
        return real(A, b, x0, r, options, axis)

    monkeypatch.setattr(fastpath, "_halves", spy)
    K = _fast("reflect1")
    assert_identical(K, _clipped("reflect1"))
    assert cuts and all(c == 0.0 for c in cuts)
    assert sum(v[0] == 0 for v in K.exact_vertices) >= 2


# --------------------------------------------------------------------------- #
# qhull failing, sections not matching, tampered proposals
# --------------------------------------------------------------------------- #

def _is_half(A: np.ndarray, axis: int, sign: float) -> bool:
    last = A[-1]
    return bool(last[axis] == sign and not np.delete(last, axis).any())


@pytest.mark.parametrize("fails", ["upper x1", "every half", "the whole", "halves x1, whole"])
def test_qhull_failing_selectively(fails, few_rows, monkeypatch):
    real = fastpath._qhull
    seen = []

    def failing(A, b, x0, options):
        half = len(A) > 1 and (_is_half(A, 0, 1.0) or _is_half(A, 0, -1.0)
                               or _is_half(A, 1, 1.0) or _is_half(A, 1, -1.0))
        drop = {"upper x1": _is_half(A, 0, -1.0), "every half": half,
                "the whole": not half,
                "halves x1, whole": not half or _is_half(A, 0, 1.0) or _is_half(A, 0, -1.0)
                }[fails]
        seen.append((half, drop))
        return None if drop else real(A, b, x0, options)

    monkeypatch.setattr(fastpath, "_qhull", failing)
    monkeypatch.setattr(fastpath, "SPLIT_ROWS", 10)  # the first round's 36 rows too
    cert = _fast_path_calls(monkeypatch)
    assert_identical(_fast("reflect1"), _clipped("reflect1"))
    assert any(d for _, d in seen) or fails == "the whole"  # halves alone: never asked
    if fails == "upper x1":
        assert [a for a, _, _ in few_rows[:2]] == [0, 1] and few_rows[1][2]
    if fails == "the whole":  # the halves alone carry it
        assert cert == [True] and few_rows[0][2]


def test_sections_that_do_not_match_fall_back_to_the_whole(few_rows, monkeypatch):
    """One half loses a point on the cut: the counts differ, both axes are refused,
    qhull runs on the whole polytope, which certifies."""
    real = fastpath._on_the_cut

    def lossy(A, k, V0, rows0, V1, rows1):
        return real(A, k, V0[1:], rows0[1:], V1, rows1)

    monkeypatch.setattr(fastpath, "_on_the_cut", lossy)
    cert = _fast_path_calls(monkeypatch)
    assert_identical(_fast("intgrid"), _clipped("intgrid"))
    assert few_rows[:2] == [(0, few_rows[0][1], False), (1, few_rows[0][1], False)]
    assert cert == [True]


@pytest.mark.parametrize("how", ["rotated", "reversed"])
def test_cut_points_matched_to_the_wrong_partners(how, few_rows, monkeypatch):
    """The other half's rows on the cut handed to the wrong points (a unique matching,
    every union wrong): the certification refuses or the unsplit retry certifies —
    the kernel is the exact clipping's."""
    real = fastpath._on_the_cut

    def wrong(A, k, V0, rows0, V1, rows1):
        rows1 = rows1[1:] + rows1[:1] if how == "rotated" else rows1[::-1]
        return real(A, k, V0, rows0, V1, rows1)

    monkeypatch.setattr(fastpath, "_on_the_cut", wrong)
    assert_identical(_fast("intgrid"), _clipped("intgrid"))


@pytest.mark.parametrize("tamper", ["bogus point", "moved point", "twice", "wrong rows",
                                    "cut rows only"])
def test_tampered_halves_cost_only_time(tamper, few_rows, monkeypatch):
    """The halves' proposal tampered with: a point inside P with k random rows, a vertex
    moved (its rows kept), every proposal twice, a vertex given another vertex's rows, or
    the points on the cut only: the certification refuses what is wrong (or the
    duplicates merge), and the kernel is the exact clipping's."""
    real = fastpath._halves
    rng = np.random.default_rng(5)

    def tampered(A, b, x0, r, options, axis=0):
        found = real(A, b, x0, r, options, axis)
        if found is None:
            return None
        V, facets = found
        V, facets = V.copy(), [list(f) for f in facets]
        if tamper == "bogus point":
            V = np.vstack([V, x0])
            facets.append(sorted(rng.choice(len(A), A.shape[1], replace=False).tolist()))
        elif tamper == "moved point":
            V[0] += 1e-3
        elif tamper == "twice":
            V, facets = np.vstack([V, V]), facets + facets
        elif tamper == "wrong rows":
            facets[0], facets[1] = facets[1], facets[0]
        else:
            on = [i for i, v in enumerate(V) if v[axis] == x0[axis]]
            if on:
                V, facets = V[on], [facets[i] for i in on]
        return V, facets

    monkeypatch.setattr(fastpath, "_halves", tampered)
    assert_identical(_fast("reflect1"), _clipped("reflect1"))


# --------------------------------------------------------------------------- #
# thread schedules
# --------------------------------------------------------------------------- #

@pytest.fixture
def every_branch_threaded(monkeypatch, few_rows):
    """The closure's and the vertex floats' ranges from a handful of vertices on."""
    monkeypatch.setattr(_closure, "CLOSURE_THREADS_MIN", 2)
    monkeypatch.setattr(_vertex_floats, "THREADS_MIN", 2)
    return few_rows


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("name", ["reflect1", "intgrid"])
def test_hostile_schedule_on_the_halves_closure_and_proof(name, seed, every_branch_threaded,
                                                          monkeypatch):
    seen = []
    hostile = _hostile(seed)

    def spy(scan, total, chunks, workers=None):
        seen.append((scan.__qualname__.split(".")[0], total, chunks))
        hostile(scan, total, chunks, workers)

    monkeypatch.setattr(_candidates, "on_threads", spy)
    assert_identical(_fast(name), _clipped(name))
    threaded = {s for s, _, c in seen if c > 1}
    assert {"_halves", "combinatorial_rays", "_simple_ends", "rounded_points"} <= threaded


@pytest.mark.parametrize("chunks", [1, 2, 3, 64])
def test_closure_and_proof_ranges_any_count(chunks, every_branch_threaded, monkeypatch):
    """The closure's and the proof's ranges at 1, 2, 3 and 64 chunks (more chunks than
    some ranges have vertices: empty ranges)."""
    monkeypatch.setattr(_closure, "CLOSURE_CHUNKS", chunks)
    monkeypatch.setattr(_vertex_floats, "THREAD_CHUNKS", chunks)
    assert_identical(_fast("reflect12"), _clipped("reflect12"))


def test_rounded_points_split_equals_unsplit(monkeypatch):
    """rounded_points on ranges (hostile: empty, uneven, shuffled) gives the floats and
    verdicts of one range, on proposals from a real kernel with singular ones mixed in."""
    real = _vertex_floats.rounded_points
    calls = []

    def record(E, at, scale, k, slack=1.0):
        calls.append((E, at.copy(), scale, k))
        return real(E, at, scale, k, slack)

    monkeypatch.setattr(_vertex_floats, "rounded_points", record)
    monkeypatch.setattr(fastpath, "SPLIT_ROWS", FEW_ROWS)
    _fast("intgrid")
    E, at, scale, k = calls[0]
    at = np.vstack([at, at[:3, [0, 0, 1, 2, 3]]])  # repeated rows: singular
    monkeypatch.setattr(_vertex_floats, "THREADS_MIN", 10**9)
    want = real(E, at, scale, k)
    monkeypatch.setattr(_vertex_floats, "THREADS_MIN", 1)
    for seed in range(3):
        monkeypatch.setattr(_candidates, "on_threads", _hostile(seed))
        got = real(E, at, scale, k)
        assert got[0].tobytes() == want[0].tobytes() and np.array_equal(got[1], want[1])
    assert not want[1][-3:].any()


@pytest.mark.parametrize("threads", [1, 2])
def test_numba_thread_count(threads, few_rows):
    saved = numba.get_num_threads()
    numba.set_num_threads(threads)
    try:
        assert_identical(_fast("samecol"), _clipped("samecol"))
    finally:
        numba.set_num_threads(saved)
    assert few_rows and few_rows[0][2]


def test_concurrent_kernels_with_halves_from_user_threads(every_branch_threaded):
    """4 user threads × 8 kernels, each starting its own halves' and ranges' threads:
    the exact clipping's answers, and no thread left behind."""
    names = ["reflect1", "intgrid", "reflect12", "samecol"] * 2
    want = [_clipped(n) for n in names]
    before = {t.ident for t in threading.enumerate()}
    with ThreadPoolExecutor(4) as pool:
        got = list(pool.map(_fast, names))
    for K, L in zip(got, want, strict=True):
        assert_identical(K, L)
    assert {t.ident for t in threading.enumerate()} <= before | {None}
    assert sum(ok for _, _, ok in every_branch_threaded) >= 8


# --------------------------------------------------------------------------- #
# d = 6, magnitudes, duplicates
# --------------------------------------------------------------------------- #

def test_halves_in_six_dimensions(few_rows):
    assert_identical(_fast("gaussian6"), _clipped("gaussian6"))
    assert few_rows and few_rows[0][2]


@pytest.mark.parametrize("scale", [2.0**990, 2.0**-990])
def test_halves_at_extreme_magnitudes(scale, few_rows):
    """At 2^±990 qhull sees the kernel at unit size (H's floats), so the halves match."""
    assert_identical(_fast("reflect1", scale), _clipped("reflect1", scale))
    assert few_rows and few_rows[0][2]


def test_duplicated_points_with_halves(few_rows):
    CLOUDS["dup"] = ("dup", 5, 16, 2)
    assert_identical(_fast("dup"), _clipped("dup"))


# --------------------------------------------------------------------------- #
# off-centre clouds: the halves fail, every round, every option
# --------------------------------------------------------------------------- #

# Fixed (was a bug: off-centre clouds — data around 100 or 1000, kernel not small enough
# for the local pass: qhull fails on a half (QH6271 dupridge) across both axes, for
# every qhull option in turn — nothing remembered it, so each proposal paid 2 axes x 2
# halves before the whole polytope: gaussian(5, 30, 3) + 100 1.0-1.3 s wall against
# 0.55-0.77 s at 46b0fa8). Now a kernel stops splitting once the halves failed on every
# axis, and clouds far off-centre (Chebyshev centre beyond SPLIT_MAX_OFFSET radii) do
# not split at all.
def test_halves_that_failed_are_not_tried_again_in_the_same_kernel(monkeypatch):
    real, failed = fastpath._halves, []

    def spy(*args):
        found = real(*args)
        failed.append(found is None)
        return found

    monkeypatch.setattr(fastpath, "_halves", spy)
    monkeypatch.setattr(fastpath, "SPLIT_MAX_OFFSET", np.inf)  # split wherever it may
    K = rescon.safe_kernel(_cloud("gaussian", 5, 16, 2) + 100.0, 2)
    assert K.dim == 5 and failed
    assert sum(failed) <= fastpath.SPLIT_AXES  # one failure per axis at most


def test_off_centre_clouds_are_not_split(monkeypatch):
    real, calls = fastpath._halves, []

    def spy(*args):
        calls.append(args[-1])
        return real(*args)

    monkeypatch.setattr(fastpath, "_halves", spy)
    for offset in (100.0, 1000.0):
        K = rescon.safe_kernel(_cloud("gaussian", 5, 16, 2) + offset, 2)
        assert K.dim == 5
    assert not calls
    rescon.safe_kernel(_cloud("gaussian", 5, 16, 2), 2)  # centred: split
    assert calls


def test_off_centre_kernel_with_halves_is_the_exact_clipping(few_rows, monkeypatch):
    monkeypatch.setattr(fastpath, "SPLIT_MAX_OFFSET", np.inf)  # off-centre: split anyway
    CLOUDS["reflect1+100"] = ("reflect1", 5, 12, 1)
    kind, d, n, F = CLOUDS["reflect1+100"]
    X = _cloud(kind, d, n, F) + 100.0
    real = km.certified_kernel
    km.certified_kernel = lambda *a: None
    try:
        want = rescon.safe_kernel(X, F)
    finally:
        km.certified_kernel = real
    assert_identical(rescon.safe_kernel(X, F), want)
    assert few_rows
