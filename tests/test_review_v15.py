"""Review V15: a hostile review of the d = 4–5 kernel's threaded passes
(:func:`rescon.geometry._candidates.on_threads` under the scan, the near pairs, row_top
and the cofactors), the k-subsets kept between calls (``_candidates.lex_subsets``,
dropped after this review) and the fast path's tight pairs carried by its polytope
(``ExactPolytope.pairs``).

Every answer is checked against the exact clipping (the fast path switched off:
tests/test_review_v2._clipped, as benchmarks/kernel_d45_bench._exact_clip), bit for
bit: exact vertices, constraints and certificate JSON. The threaded passes run here
under a hostile scheduler too — ranges of another, uneven split (empty ones among
them), in a shuffled order, on more threads than cores, each after a random pause —
as their docstrings claim any split and any order give the same arrays."""

from __future__ import annotations

import copy
import dataclasses
import json
import os
import random
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from math import comb
from pathlib import Path

import numpy as np
import pytest
from numba import njit

import rescon
from benchmarks.kernel_clouds import make_cloud
from rescon.geometry import _candidates
from rescon.geometry.polytope import members_of, tight_pairs
from tests.test_kernel_attack import _spied
from tests.test_kernel_d45 import _both_paths
from tests.test_review_v2 import _clipped

ROOT = Path(__file__).resolve().parents[1]
REAL_ON_THREADS = _candidates.on_threads


# --------------------------------------------------------------------------- #
# on_threads itself
# --------------------------------------------------------------------------- #

def _recorded(total: int, chunks: int, workers: int, seed: int) -> list[tuple[int, int]]:
    """The ranges on_threads hands out, each after a random pause (thread timing)."""
    rng = random.Random(seed)
    pauses = [rng.random() * 2e-4 for _ in range(max(chunks, 1))]
    seen: list[tuple[int, int, str]] = []
    lock = threading.Lock()

    def scan(lo: int, hi: int) -> None:
        time.sleep(pauses[len(seen) % len(pauses)])
        with lock:
            seen.append((lo, hi, threading.current_thread().name))

    REAL_ON_THREADS(scan, total, chunks, workers)
    return [(lo, hi) for lo, hi, _ in seen]


@pytest.mark.parametrize("workers", [1, 2, 3, 7])
@pytest.mark.parametrize("chunks", [0, 1, 2, 3, 7, 32, 64, 100])
@pytest.mark.parametrize("total", [0, 1, 2, 31, 33, 1000, 5003])
def test_on_threads_covers_every_row_once(total, chunks, workers):
    """Every row in exactly one range, every range once — chunks not dividing the rows,
    more chunks than rows (empty ranges), 0 or 1 rows, more workers than chunks."""
    got = _recorded(total, chunks, workers, total * 1000 + chunks * 10 + workers)
    want_calls = chunks if chunks > 1 and workers > 1 else 1
    assert len(got) == want_calls
    got.sort()
    assert got[0][0] == 0 and got[-1][1] == total
    assert all(a[1] == b[0] for a, b in zip(got, got[1:]))  # contiguous, no overlap
    assert all(lo <= hi for lo, hi in got)


@njit(nogil=True, cache=False)
def _fill(out, seed, lo, hi):
    for i in range(lo, hi):
        x = (i * 2654435761 + seed) % 1000003
        out[i] = x * 1e-3 - np.sqrt(x)


def test_compiled_ranges_write_disjoint_slots_under_contention():
    """A nogil compiled pass on 4 threads (2 cores, other processes): the array of one
    thread, bit for bit, over many runs (a slot written twice or skipped shows)."""
    n = 1_000_003
    want = np.empty(n)
    _fill(want, 7, 0, n)
    for run in range(30):
        out = np.full(n, np.nan)
        REAL_ON_THREADS(lambda lo, hi, out=out: _fill(out, 7, lo, hi), n, 64, 4)
        assert np.array_equal(out, want), run


def _no_new_threads(before: set[int]) -> bool:
    for _ in range(200):
        if not {t.ident for t in threading.enumerate()} - before:
            return True
        time.sleep(0.01)
    return False


@pytest.mark.parametrize("where", ["caller", "helper"])
@pytest.mark.parametrize("exc", [RuntimeError, KeyboardInterrupt, SystemExit, MemoryError])
def test_a_range_exception_propagates_and_leaves_no_thread(exc, where):
    """Raised by on_threads itself (not swallowed, no partial return, no hang), after
    which none of its threads is left running — whichever thread the range ran on."""
    before = {t.ident for t in threading.enumerate()}
    main = threading.get_ident()

    def scan(lo, hi):
        time.sleep(1e-4)
        on_caller = threading.get_ident() == main
        if lo >= 500 and on_caller == (where == "caller"):
            raise exc("range failed")

    with pytest.raises(exc, match="range failed"):
        REAL_ON_THREADS(scan, 1000, 64, 3)
    assert _no_new_threads(before)


def test_no_range_starts_after_a_failure():
    """One range fails at once, the others take 2 ms each: the failure stops the pass
    within a range or two per thread, not after all 64 (failed before 310d2d8: every
    remaining range ran — wasted work, a Ctrl-C or MemoryError waited for the pass)."""
    started = []

    def scan(lo, hi):
        started.append(lo)
        if lo == 0:
            raise RuntimeError("range failed")
        time.sleep(2e-3)

    with pytest.raises(RuntimeError):
        REAL_ON_THREADS(scan, 6400, 64, 2)
    assert len(started) <= 8, len(started)


def test_numba_thread_count_one_runs_on_the_caller_alone():
    """numba.set_num_threads(1) (as NUMBA_NUM_THREADS=1): every range on the calling
    thread, no thread started."""
    import numba

    saved = numba.get_num_threads()
    threads = set()
    numba.set_num_threads(1)
    try:
        REAL_ON_THREADS(lambda lo, hi: threads.add(threading.get_ident()), 100, 64)
    finally:
        numba.set_num_threads(saved)
    assert threads == {threading.get_ident()}


# --------------------------------------------------------------------------- #
# the kernel under a hostile scheduler, against the exact clipping
# --------------------------------------------------------------------------- #

def _hostile(seed: int):
    """An on_threads that splits the rows its own way (a prime number of uneven ranges,
    some empty), runs them in a shuffled order on 5 threads after random pauses — for
    every pass, the single-chunk ones included."""
    rng = random.Random(seed)
    lock = threading.Lock()

    def on_threads(scan, total, chunks, workers=None):
        cuts = sorted({0, total, *(rng.randrange(total + 1) for _ in range(12))})
        ranges = list(zip(cuts, cuts[1:])) + [(total // 2, total // 2)]
        rng.shuffle(ranges)
        pauses = [rng.random() * 1e-4 for _ in ranges]
        todo = iter(list(zip(ranges, pauses)))
        errors = []

        def work():
            try:
                while True:
                    with lock:
                        item = next(todo, None)
                    if item is None:
                        return
                    time.sleep(item[1])
                    scan(*item[0])
            except BaseException as e:  # noqa: BLE001 (re-raised below)
                errors.append(e)

        ts = [threading.Thread(target=work) for _ in range(5)]
        for t in ts:
            t.start()
        for t in ts:
            t.join()
        if errors:
            raise errors[0]

    return on_threads


def _public(K) -> tuple:
    return (K.exact_vertices, K._exact.constraints,
            json.dumps(K.certificate, sort_keys=True))


#: hostile clouds in d = 4–5 (tests/test_kernel_attack, benchmarks/kernel_clouds), each
#: at scale 1 and at 2^±990 (exact: the kernel scales with them)
CLOUDS = [("attack", 4, 18, 3), ("converged", 4, 22, 2), ("duplicates", 4, 45, 2),
          ("grid", 4, 24, 2), ("flat", 5, 16, 1), ("gaussian", 5, 14, 1),
          ("attack", 5, 12, 2), ("sphere", 4, 22, 3), ("gaussian", 4, 26, 3)]


#: larger ones, whose passes take the threaded branches (chunks > 1) of the scan, the
#: near pairs, row_top and the cofactors: 2–5 s of exact clipping each
LARGER = [("gaussian", 4, 40, 6), ("gaussian", 5, 18, 2), ("gaussian", 4, 50, 9),
          ("attack", 5, 20, 3)]


def _cases():
    for i, cloud in enumerate(CLOUDS + LARGER):
        for scale in (1.0, 2.0**990, 2.0**-990):
            if cloud in LARGER and scale != 1.0 and i != len(CLOUDS):
                continue
            slow = cloud in LARGER or (cloud[1] == 5 and scale != 1.0)
            yield pytest.param(cloud, scale, i * 7 + int(np.log2(scale)) % 5,
                               marks=[pytest.mark.slow] if slow else [],
                               id="-".join(map(str, cloud)) + f"-2^{int(np.log2(scale))}")


@pytest.mark.parametrize(("cloud", "scale", "seed"), list(_cases()))
def test_hostile_schedule_is_the_exact_clipping(cloud, scale, seed, monkeypatch):
    fam, d, n, F = cloud
    X = make_cloud(fam, d, n, F).X * scale
    E = _clipped(X, F)
    monkeypatch.setattr(_candidates, "on_threads", _hostile(seed))
    K, _, P = _spied(X, F)
    assert P is not None  # the fast path certified it
    assert _public(K) == _public(E)
    # its pairs are still those of its bitsets (the centring moved it in place)
    vs, hs = tight_pairs(P.tight)
    assert np.array_equal(P.pairs[0], vs) and np.array_equal(P.pairs[1], hs)


def test_threaded_branches_run_on_the_larger_clouds(monkeypatch):
    """The LARGER clouds reach every threaded branch (chunks > 1): the scan, the near
    pairs, the walks of graph_top, the cofactors, the closure (keyed and scanned), the
    proof of the vertex floats and qhull's two halves in d = 5 — so the hostile
    schedule replaced real splits (row_top runs only when a proposal fails)."""
    seen = []

    def spy(scan, total, chunks, workers=None):
        seen.append((scan.__qualname__.split(".")[0], chunks))
        REAL_ON_THREADS(scan, total, chunks, workers)

    monkeypatch.setattr(_candidates, "on_threads", spy)
    for fam, d, n, F in [("gaussian", 4, 50, 9), ("gaussian", 5, 18, 2)]:
        rescon.safe_kernel(make_cloud(fam, d, n, F).X, F)
    threaded = {name for name, chunks in seen if chunks > 1}
    assert threaded == {"classify", "_near_run", "graph_top", "cofactors", "_halves",
                        "combinatorial_rays", "_simple_ends", "rounded_points"}, seen


@pytest.mark.parametrize("scale", [1.0, pytest.param(2.0**990, marks=pytest.mark.slow)])
def test_concurrent_kernels_from_user_threads(scale):
    """Several safe_kernel calls at once from a ThreadPoolExecutor (each starting its own
    range threads): the serial answers, bit for bit, and no
    thread left behind."""
    cases = [("gaussian", 4, 26, 3), ("gaussian", 5, 14, 1), ("converged", 4, 22, 2),
             ("sphere", 4, 22, 3)]
    inputs = [(make_cloud(*c).X * scale, c[3]) for c in cases] * 2
    want = [_public(rescon.safe_kernel(X, F)) for X, F in inputs]
    before = {t.ident for t in threading.enumerate()}
    with ThreadPoolExecutor(4) as pool:
        got = list(pool.map(lambda a: _public(rescon.safe_kernel(*a)), inputs))
    assert got == want
    assert _no_new_threads(before)


def test_dask_threads_scheduler():
    """Inside Dask's threaded scheduler (worker threads calling on_threads)."""
    dask = pytest.importorskip("dask")
    cases = [("gaussian", 4, 26, 3), ("sphere", 4, 22, 3), ("gaussian", 5, 14, 1)]
    inputs = [(make_cloud(*c).X, c[3]) for c in cases]
    tasks = [dask.delayed(lambda X, F: _public(rescon.safe_kernel(X, F)))(X, F)
             for X, F in inputs]
    got = dask.compute(*tasks, scheduler="threads", num_workers=3)
    assert list(got) == [_public(rescon.safe_kernel(X, F)) for X, F in inputs]


@pytest.mark.slow
def test_numba_num_threads_one_in_a_fresh_process():
    """NUMBA_NUM_THREADS=1 (numba's layer with one thread; on_threads on the caller
    alone): the certificate JSON of this process's threaded run."""
    code = ("import json, rescon; from benchmarks.kernel_clouds import make_cloud\n"
            "out = []\n"
            "for c in [('gaussian', 4, 26, 3), ('gaussian', 5, 14, 1)]:\n"
            "    K = rescon.safe_kernel(make_cloud(*c).X, c[3])\n"
            "    out.append(json.dumps(K.certificate, sort_keys=True))\n"
            "import numba; out.append(numba.get_num_threads())\n"
            "print(json.dumps(out))\n")
    env = dict(os.environ, NUMBA_NUM_THREADS="1",
               PYTHONPATH=os.pathsep.join([str(ROOT / "src"), str(ROOT)]))
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, cwd=ROOT, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    got = json.loads(run.stdout)
    assert got[-1] == 1
    want = [json.dumps(rescon.safe_kernel(make_cloud(*c).X, c[3]).certificate, sort_keys=True)
            for c in [("gaussian", 4, 26, 3), ("gaussian", 5, 14, 1)]]
    assert got[:-1] == want


# --------------------------------------------------------------------------- #
# the kept k-subsets (lex_subsets, 1cb2aef): dropped in 310d2d8 after this review —
# any caller could setflags(write=True) on the shared table (it owned its memory), and
# it kept up to 2 × C(91, 5) × 5 × 8 B = 3.7 GB after the kernel returned
# --------------------------------------------------------------------------- #

def test_no_kept_subsets():
    assert not hasattr(_candidates, "lex_subsets")


# --------------------------------------------------------------------------- #
# ExactPolytope.pairs
# --------------------------------------------------------------------------- #

def _fast(case: int):
    rng = np.random.default_rng(5)
    X = [rng.normal(size=(24, 4)), rng.normal(size=(16, 5))][case]
    fast, box, *_ = _both_paths(X, [3, 1][case])
    assert fast is not None and fast.pairs is not None
    return fast, box


def _pairs_ok(P) -> bool:
    return P.incidence() == members_of(P.tight)


@pytest.mark.parametrize("case", [0, 1])
def test_a_copy_clipped_leaves_the_original_pairs_right(case):
    P, _ = _fast(case)
    for Q in (copy.copy(P), copy.deepcopy(P)):
        j = int(np.argmax(Q.float_vertices()[:, 0]))
        w, y0, *_ = Q.verts[j]
        assert Q.clip((1,) + (0,) * (Q.k - 1), y0 // w - 1)
        assert Q.pairs is None and _pairs_ok(Q)
        assert P.pairs is not None and _pairs_ok(P)


@pytest.mark.parametrize("case", [0, 1])
def test_a_clip_cutting_nothing_keeps_right_pairs(case):
    """A clip no vertex violates (some tight on it) records nothing: the pairs stay
    those of the unchanged bitsets."""
    P, _ = _fast(case)
    w, y0, *_ = P.verts[int(np.argmax(P.float_vertices()[:, 0]))]
    top = max(-(-v[1] // v[0]) for v in P.verts)  # ceil: no vertex above
    assert not P.clip((1,) + (0,) * (P.k - 1), top)
    assert P.pairs is not None and _pairs_ok(P)


@pytest.mark.parametrize("case", [0, 1])
def test_the_fast_polytope_has_the_exact_clipping_incidence(case):
    """incidence() from the carried pairs gives the clipping's facets (the maximal
    vertex sets of the rows), vertices named by their exact coordinates."""
    P, box = _fast(case)

    def facets(Q):
        verts = Q.fraction_vertices()
        sets = {frozenset(verts[v] for v in vs) for vs in Q.incidence().values()}
        return {s for s in sets if not any(s < t for t in sets)}

    assert facets(P) == facets(box)
    assert all(len(f) >= P.k for f in facets(P))


def test_replace_with_new_bitsets_does_not_keep_stale_pairs():
    """Failed before 310d2d8 (pairs an init field: dataclasses.replace(P, tight=...)
    carried the old pairs to incidence(); no internal path did this)."""
    P, _ = _fast(0)
    Q = dataclasses.replace(P, tight=[t | 1 << (len(P.a) - 1) for t in P.tight])
    assert _pairs_ok(Q)


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize(("k", "m"), [(4, 22), (5, 17)])
@pytest.mark.parametrize("kind", ["normal", "coplanar", "repeated", "integers", "subnormal",
                                  "huge", "nearsame", "adversary"])
def test_scan_arrays_under_any_split_equal_the_unsplit_scan(kind, k, m, seed,
                                                             monkeypatch):
    """The scan's arrays (pruned lower bounds included) when its ranges start anywhere
    — inside a prefix's run, on its last subset, empty — in any order: the unsplit
    scan's, bit for bit."""
    from tests.test_kernel_d45_around2 import _points

    Y = _points(kind, k, m, seed)
    W = np.random.default_rng([m, seed]).integers(1, 3, size=m)
    S = _candidates.k_subsets(m, k, comb(m, k))
    cases = [(0.0, 1), (1e-12, 2)]
    # one range on the calling thread: the scan unsplit
    wants = [_candidates.classify(Y, W, S, c_err, F, 1e-300, 1) for c_err, F in cases]
    monkeypatch.setattr(_candidates, "on_threads", _hostile(100 + seed))
    for (c_err, F), want in zip(cases, wants, strict=True):
        got = _candidates.classify(Y, W, S, c_err, F, 1e-300, 3)
        assert all(np.array_equal(a, b) for a, b in zip(want, got, strict=True))
    rows = np.random.default_rng(seed).choice(len(S), 300, replace=False)
    for a, b in zip(_candidates.cofactors(Y, S[rows]), _candidates.cofactors(Y, S),
                    strict=True):
        assert np.array_equal(a, b[rows], equal_nan=True)  # huge: NaN cofactors


def test_no_more_threads_than_ranges():
    started = []
    real_start = threading.Thread.start

    def counting(self):
        started.append(self)
        real_start(self)

    threading.Thread.start = counting
    try:
        REAL_ON_THREADS(lambda lo, hi: None, 1000, 8, 64)
    finally:
        threading.Thread.start = real_start
    assert len(started) <= 7


@pytest.mark.skipif(sys.platform != "linux", reason="fork")
def test_forked_workers_after_a_kernel():
    """multiprocessing's fork pool after the parent computed a d = 4 kernel (a Dask or
    joblib process pool does the same): the children compute theirs. At 181ada4 the
    prange passes had started GNU OpenMP in the parent, and each child died with
    'fork() called from a process already using GNU OpenMP' (the pool then hung)."""
    code = ("import multiprocessing as mp, numpy as np, rescon\n"
            "def run(seed):\n"
            "    X = np.random.default_rng(seed).normal(size=(50, 4))\n"
            "    return len(rescon.safe_kernel(X, 9).vertices)\n"
            "if __name__ == '__main__':\n"
            "    run(0)\n"
            "    with mp.get_context('fork').Pool(2) as p:\n"
            "        print(p.map(run, [1, 2]))\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, cwd=ROOT, timeout=300)
    assert run.returncode == 0 and "OpenMP" not in run.stderr, run.stderr[-2000:]
    assert run.stdout.strip().startswith("[")


@pytest.mark.slow
@pytest.mark.skipif(sys.platform == "win32", reason="SIGINT")
def test_ctrl_c_during_a_threaded_kernel():
    """SIGINT while a d = 5, n = 60 kernel's threaded passes run: KeyboardInterrupt
    within seconds, no range thread left, and the next kernel is right."""
    import signal

    # Python's handler explicitly: a child inherits an ignored SIGINT (a test run started
    # in the background by a non-interactive shell), and Python then installs none
    code = ("import numpy as np, rescon, signal, threading\n"
            "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
            "rescon.safe_kernel(np.random.default_rng(0).normal(size=(20, 5)), 2)\n"
            "print('ready', flush=True)\n"
            "try:\n"
            "    rescon.safe_kernel(np.random.default_rng(0).normal(size=(60, 5)), 12)\n"
            "except KeyboardInterrupt:\n"
            "    print('interrupted', len(threading.enumerate()), flush=True)\n"
            "Y = np.random.default_rng(1).normal(size=(24, 4))\n"
            "print(len(rescon.safe_kernel(Y, 3).vertices), flush=True)\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    p = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=env, cwd=ROOT)
    try:
        assert p.stdout.readline().strip() == "ready"
        time.sleep(1.0)
        p.send_signal(signal.SIGINT)
        t = time.perf_counter()
        out, err = p.communicate(timeout=120)
    finally:
        p.kill()
    assert time.perf_counter() - t < 30 and p.returncode == 0, err[-2000:]
    want = len(rescon.safe_kernel(np.random.default_rng(1).normal(size=(24, 4)), 3).vertices)
    assert out.split("\n")[:2] == ["interrupted 1", str(want)]


@pytest.mark.parametrize("seed", range(3))
def test_near_pairs_and_row_top_under_any_split(seed, monkeypatch):
    """Both near-pair passes (rows with more than NEAR_KEPT near points scanned again)
    and row_top under the hostile schedule: the one-thread arrays, in the same order."""
    from rescon.geometry._candidates import NEAR_KEPT, near_pairs, row_top

    rng = np.random.default_rng([seed, 15])
    k, nv, m = 5, 700, 400
    V = rng.uniform(-2.0, 2.0, size=(nv, k))
    V[: 3 * NEAR_KEPT, 0] = 3.0  # on row 0's hyperplane x_0 = 3: the second pass runs
    A = rng.normal(size=(m, k))
    A[0] = [1.0, 0, 0, 0, 0]
    b = (A @ V.T).max(axis=1) + rng.uniform(0.0, 0.3, m)
    b[0] = 3.0
    b[2::5] = (A[2::5] @ V.T).max(axis=1)
    A_abs, b_abs = np.abs(A) * 1.01, np.abs(b) * 1.01
    c_err, c = 1e-12, 36 * 2.0**-53
    coarse = c_err * (A_abs.sum(axis=1) * np.abs(V).max() + b_abs) + c * (
        np.abs(A).sum(axis=1) * np.abs(V).max() + np.abs(b))

    def both():
        return (near_pairs(A, b, A_abs, b_abs, V, coarse, c_err, c, 0.0),
                row_top(A, b, V, 0.0))

    monkeypatch.setattr(_candidates, "on_threads",
                        lambda scan, total, chunks, workers=None: scan(0, total))
    (one_r, one_v), one_top = both()
    assert (np.bincount(one_r) > NEAR_KEPT).any()
    monkeypatch.setattr(_candidates, "on_threads", _hostile(200 + seed))
    (r, v), top = both()
    assert r.tolist() == one_r.tolist() and v.tolist() == one_v.tolist()
    assert np.array_equal(top, one_top)


@pytest.mark.slow
@pytest.mark.skipif(sys.platform != "linux", reason="fork")
def test_forked_workers_after_a_plane_kernel():
    """Failed before (numba's prange in the plane sweep and the exact side counts: GNU
    OpenMP in the parent, each forked child died and the pool hung); every compiled pass
    now runs on Python threads (:func:`._candidates.on_threads`)."""
    code = ("import multiprocessing as mp, numpy as np, rescon\n"
            "def run(seed):\n"
            "    X = np.random.default_rng(seed).normal(size=(300, 2))\n"
            "    return len(rescon.safe_kernel(X, 20).vertices)\n"
            "if __name__ == '__main__':\n"
            "    run(0)\n"
            "    with mp.get_context('fork').Pool(2) as p:\n"
            "        print(p.map(run, [1, 2]))\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"))
    try:
        run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             env=env, cwd=ROOT, timeout=40)
    except subprocess.TimeoutExpired:
        pytest.fail("the fork pool hung")
    assert run.returncode == 0 and "OpenMP" not in run.stderr, run.stderr[-2000:]


@pytest.mark.slow
def test_concurrent_kernels_under_the_workqueue_layer():
    """Kernels from 4 user threads at once under numba's ``workqueue`` threading layer
    (not thread-safe: it aborts the process when parallel regions run concurrently):
    the same exact vertices as serially. Failed before — the plane sweep and the exact
    side counts still ran numba ``prange`` loops ("Concurrent access has been
    detected", the process aborted); every compiled pass now runs on Python threads."""
    code = ("import numpy as np, rescon\n"
            "from concurrent.futures import ThreadPoolExecutor\n"
            "cases = [(np.random.default_rng(s).normal(size=(n, d)), F) for s, (n, d, F)\n"
            "         in enumerate([(300, 2, 20), (100, 3, 10), (30, 4, 3), (400, 2, 40)] * 3)]\n"
            "with ThreadPoolExecutor(4) as ex:\n"
            "    par = list(ex.map(lambda c: rescon.safe_kernel(*c).exact_vertices, cases))\n"
            "print(par == [rescon.safe_kernel(X, F).exact_vertices for X, F in cases])\n")
    env = dict(os.environ, PYTHONPATH=str(ROOT / "src"), NUMBA_THREADING_LAYER="workqueue")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, cwd=ROOT, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.strip() == "True"
