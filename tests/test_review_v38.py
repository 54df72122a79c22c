"""V38 hostile review: rescon as a library inside someone else's program.

Attacked: process-wide state and the caller's environment — the cyclic GC switch (the
kernel fast path turns it off while it runs), ``np.geterr``, ``warnings.filters``, the
SIGINT handler, threads left running, numba's thread count, logging, print options, the
recursion limit, open file descriptors, the robustness facts cache's size — after normal
returns and after errors; the caller's own ``np.seterr(all="raise")`` and
``warnings.simplefilter("error")``; the same API from several threads at once on
different and on the SAME inputs (one shared SafeKernel whose exact vertices,
certificate and points are built lazily; one graph whose proven facts are cached),
compared bit for bit with the serial answer; forked / spawned worker pools after the
parent ran the kernels, numba and the robustness MILP; reentrancy (an adversary or a cost
oracle that itself calls rescon).

Found (were xfail strict; fixed, the tests say "Fixed (was a bug: …)"):
* ``simulate`` / ``rmdo`` fail with ``FloatingPointError: underflow`` under the caller's
  ``np.seterr(all="raise")`` (or ``under="raise"``): the validity monitor's error bound
  (consensus/_facet_filter.py ``_slack_bound``) multiplies the smallest subnormal and
  its caller's ``np.errstate`` ignores only over/invalid.
* a ``gc.disable()`` made by another thread of the caller while a fast-path kernel runs
  is undone when the kernel returns (geometry/fastpath.py ``_collection_deferred``).

Held: everything else listed above (the tests without xfail).
"""

from __future__ import annotations

import gc
import json
import logging
import multiprocessing as mp
import os
import signal
import sys
import threading
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon.consensus.adversaries import Behaviour
from rescon.graphs import facts

TIMEOUT = 60


def _cloud(n: int, d: int, seed: int) -> np.ndarray:
    return np.random.default_rng(seed).normal(size=(n, d))


def _ring_scenario(steps: int = 4, **kw) -> rescon.Scenario:
    ring = nx.circulant_graph(10, [1, 2, 3]).to_directed()
    x0 = [[i % 3, i // 3] for i in range(10)]
    return rescon.Scenario(graph=ring, x0=x0, F=1, steps=steps, **kw)


def _kernel_summary(K) -> tuple:
    x, c = K.point("project")
    y, e = K.point("chebyshev")
    return (K.dim, K.vertices.tobytes(), K.A.tobytes(), K.b.tobytes(), K.exact_vertices,
            json.dumps(K.certificate, sort_keys=True), x.tobytes(),
            json.dumps(c, sort_keys=True), y.tobytes(), json.dumps(e, sort_keys=True))


def _quiet_simulate(sc, **kw):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rescon.ScenarioWarning)
        return rescon.simulate(sc, **kw)


# --------------------------------------------------------------------------- #
# the caller's numpy error settings and warning filters
# --------------------------------------------------------------------------- #


def test_simulate_under_the_callers_seterr_all_raise():
    """Fixed (was a bug: FloatingPointError from the validity monitor's error bound,
    whose products round to subnormals, under the caller's np.seterr(all="raise"))."""
    sc = _ring_scenario(steps=2)
    ref = _quiet_simulate(sc)
    with np.errstate(all="raise"):
        got = _quiet_simulate(sc)
    assert np.array_equal(got.states, ref.states)


def test_paper_example_validity_monitor_under_seterr_under_raise():
    """Fixed (was a bug: the same underflow under np.seterr(under="raise"))."""
    sc = replace(rescon.Scenario.paper_example(), steps=3)
    with np.errstate(under="raise"):
        out = _quiet_simulate(sc, metrics=["validity"])
    assert out.max_validity == 0.0


def test_simulate_metrics_without_validity_under_seterr_all_raise():
    """Only the validity monitor trips: the engine and the other monitors honour it."""
    sc = _ring_scenario(steps=3)
    ref = _quiet_simulate(sc, metrics=["diameter", "spread"])
    with np.errstate(all="raise"):
        got = _quiet_simulate(sc, metrics=["diameter", "spread"])
    assert np.array_equal(got.states, ref.states)
    assert np.array_equal(got.metrics["diameter"], ref.metrics["diameter"])


@pytest.mark.parametrize("d,n", [(2, 20), (3, 18), (4, 16)])
def test_kernels_and_points_under_seterr_all_raise(d, n):
    X = _cloud(n, d, d)
    ref = _kernel_summary(rescon.safe_kernel(X, 1))
    with np.errstate(all="raise"):
        got = _kernel_summary(rescon.safe_kernel(X, 1))
        assert rescon.check_certificate(rescon.kernel_point(X, 1)[1]).valid
        tiny = rescon.safe_kernel(X * 1e-300, 1)
        huge = rescon.safe_kernel(X * 1e300, 1)
        assert len(tiny.vertices) == len(huge.vertices) == len(rescon.safe_kernel(X, 1).vertices)
    assert got == ref


def test_graphs_and_redundancy_under_seterr_all_raise():
    sc = rescon.Scenario.paper_example()
    costs = {i: "(x1 - 1)^2 + (x2 - 2)^2" for i in sc.benign}
    with np.errstate(all="raise"):
        rep = rescon.robustness(sc.graph)
        assert (rep.r_max, rep.s_max) == (5, 1)
        assert rescon.check_certificate(rep.certificate).valid
        assert rescon.max_s(sc.graph, 3) == 9
        assert rescon.check_redundancy(costs, r=2).holds
        assert rescon.kernel_points(np.random.default_rng(1).normal(size=(4, 12, 2)), 1).shape \
            == (4, 2)


def test_warnings_as_errors_only_the_documented_scenario_warning_escapes():
    """Under simplefilter("error") the only warning raised is the public ScenarioWarning
    (an intended user-facing warning); no internal warning (numpy, numba, solvers)
    escapes as an error from any API."""
    sc = rescon.Scenario.paper_example()
    costs = {i: "(x1 - 1)^2 + (x2 - 2)^2" for i in sc.benign}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(rescon.ScenarioWarning):
            rescon.simulate(_ring_scenario(steps=2))
        warnings.filterwarnings("ignore", category=rescon.ScenarioWarning)
        for d in (2, 3, 4):
            K = rescon.safe_kernel(_cloud(16, d, 7), 1)
            assert rescon.check_certificate(K.certificate).valid
        assert rescon.safe_kernel([[0, 0], [1, 0], [0, 1]], 1).is_empty
        assert rescon.robustness(sc.graph).r_max == 5
        assert rescon.check_redundancy(costs, r=2).holds
        assert rescon.simulate(_ring_scenario(steps=3)).states.shape == (4, 10, 2)


# --------------------------------------------------------------------------- #
# process-wide state
# --------------------------------------------------------------------------- #


def _state() -> dict:
    import numba

    root = logging.getLogger()
    return {"gc": gc.isenabled(), "err": np.geterr(), "filters": list(warnings.filters),
            "sigint": signal.getsignal(signal.SIGINT), "threads": threading.active_count(),
            "numba": numba.get_num_threads(), "log": (list(root.handlers), root.level),
            "print": np.get_printoptions(), "recursion": sys.getrecursionlimit(),
            "switch": sys.getswitchinterval(), "env": dict(os.environ)}


def test_process_state_unchanged_after_returns_and_errors():
    sc = rescon.Scenario.paper_example()
    calls = [
        lambda: rescon.safe_kernel(_cloud(16, 4, 1), 1).certificate,
        lambda: rescon.kernel_point(_cloud(20, 2, 2), 1),
        lambda: rescon.robustness(sc.graph),
        lambda: rescon.robustness(nx.gnp_random_graph(14, 0.6, seed=2, directed=True),
                                  method="milp"),
        lambda: rescon.robustness(nx.gnp_random_graph(40, 0.5, seed=1, directed=True),
                                  time_limit=0.2),
        lambda: _quiet_simulate(_ring_scenario(steps=3)),
        lambda: rescon.safe_kernel([[0.0, float("nan")], [1.0, 2.0]], 0),
        lambda: rescon.robustness(nx.DiGraph(), time_limit=-1),
        lambda: rescon.check_redundancy({0: "x1^2"}, r=5),
    ]
    for call in calls:  # first use: imports, numba compilation
        try:
            call()
        except rescon.RESCONError:
            pass
    before = _state()
    for call in calls * 2:
        try:
            call()
        except rescon.RESCONError:
            pass
    time.sleep(0.1)
    assert _state() == before


@pytest.mark.parametrize("raises", [False, True])
def test_gc_disabled_by_the_caller_stays_disabled(raises):
    X = _cloud(14, 5, 3) if not raises else [[0.0, 0.0, 0.0], [1.0, 2.0, float("inf")]]
    gc.disable()
    try:
        if raises:
            with pytest.raises(rescon.InputError):
                rescon.safe_kernel(X, 0)
        else:
            rescon.safe_kernel(X, 1)
        assert not gc.isenabled()
    finally:
        gc.enable()


def test_two_concurrent_fast_path_kernels_leave_gc_enabled():
    X, Y = _cloud(14, 5, 4), _cloud(15, 4, 5)
    assert gc.isenabled()
    for _ in range(3):
        with ThreadPoolExecutor(2) as ex:
            fs = [ex.submit(rescon.safe_kernel, Z, 1) for Z in (X, Y, Y, X)]
            for f in fs:
                f.result(timeout=TIMEOUT)
        assert gc.isenabled()


def test_callers_gc_disable_during_a_kernel_in_another_thread_is_kept():
    """Fixed (was a bug: the fast path switched the cyclic collector off and on
    process-wide, undoing a gc.disable() made meanwhile by another thread; it now only
    spaces the collector's runs by its threshold, tests/test_fastpath_gc.py)."""
    X = _cloud(14, 5, 0)
    rescon.safe_kernel(X, 1)  # warm (numba)
    worker = threading.Thread(target=rescon.safe_kernel, args=(X, 1))
    try:
        worker.start()
        stop = time.monotonic() + 20
        while worker.is_alive() and gc.isenabled() and time.monotonic() < stop:
            pass
        gc.disable()  # the caller's program turns the collector off for good
        worker.join(TIMEOUT)
        assert not gc.isenabled()
    finally:
        worker.join(TIMEOUT)
        gc.enable()


def test_caller_numba_thread_count_is_honoured_and_kept():
    import numba

    old = numba.get_num_threads()
    X = _cloud(16, 4, 6)
    ref = _kernel_summary(rescon.safe_kernel(X, 1))
    numba.set_num_threads(1)
    try:
        assert _kernel_summary(rescon.safe_kernel(X, 1)) == ref
        assert rescon.robustness(rescon.Scenario.paper_example().graph).r_max == 5
        assert numba.get_num_threads() == 1
    finally:
        numba.set_num_threads(old)


def test_no_descriptor_leak_and_bounded_facts_cache():
    def fds() -> int:
        return len(os.listdir("/proc/self/fd"))

    rescon.robustness(nx.gnp_random_graph(10, 0.5, seed=0, directed=True), method="milp")
    before = fds()
    for i in range(50):
        G = nx.gnp_random_graph(10, 0.5, seed=i, directed=True)
        rescon.robustness(G, method="milp")
        rescon.kernel_point(_cloud(12, 2, i), 1)
    assert fds() <= before
    assert len(facts._CACHE) <= facts.CACHE_SIZE


# --------------------------------------------------------------------------- #
# threads
# --------------------------------------------------------------------------- #


def test_concurrent_kernels_on_different_clouds_match_the_serial_answers():
    clouds = [_cloud(n, d, 10 + d) for d, n in [(2, 24), (3, 18), (4, 15), (2, 40)]]
    ref = [_kernel_summary(rescon.safe_kernel(X, 1)) for X in clouds]
    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-5)
    try:
        with ThreadPoolExecutor(6) as ex:
            fs = [(i, ex.submit(lambda X=X: _kernel_summary(rescon.safe_kernel(X, 1))))
                  for i, X in enumerate(clouds * 2)]
            for i, f in fs:
                assert f.result(timeout=TIMEOUT) == ref[i % len(clouds)]
    finally:
        sys.setswitchinterval(old)


@pytest.mark.parametrize("d,n", [(3, 18), (4, 15)])
def test_one_shared_kernel_read_by_eight_threads(d, n):
    """Lazily built exact vertices (LazyVertices, _Deferred), the cached certificate
    and the points' cached frame, first read by 8 threads at once."""
    X = _cloud(n, d, 20 + d)
    ref = _kernel_summary(rescon.safe_kernel(X, 1))
    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-5)
    try:
        for _ in range(3):
            K = rescon.safe_kernel(X, 1)
            with ThreadPoolExecutor(8) as ex:
                fs = [ex.submit(_kernel_summary, K) for _ in range(8)]
                assert all(f.result(timeout=TIMEOUT) == ref for f in fs)
            assert _kernel_summary(K) == ref
    finally:
        sys.setswitchinterval(old)


def test_concurrent_questions_on_one_graph_share_the_facts_cache_safely():
    G = nx.gnp_random_graph(14, 0.5, seed=3, directed=True)
    facts.clear_cache()
    rho = rescon.robustness(G).r_max
    ref_s = {r: rescon.max_s(G, r) for r in range(1, rho + 1)}
    ref_r = {r: rescon.is_r_robust(G, r).holds for r in range(1, rho + 2)}
    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-5)
    try:
        for _ in range(4):
            facts.clear_cache()
            with ThreadPoolExecutor(8) as ex:
                fs = [(r, ex.submit(rescon.max_s, G, r)) for r in ref_s]
                gs = [(r, ex.submit(rescon.is_r_robust, G, r)) for r in ref_r]
                hs = [ex.submit(rescon.robustness, G) for _ in range(2)]
                assert all(f.result(timeout=TIMEOUT) == ref_s[r] for r, f in fs)
                for r, g in gs:
                    out = g.result(timeout=TIMEOUT)
                    assert out.holds == ref_r[r]
                    assert rescon.check_certificate(out.certificate).valid
                assert all(h.result(timeout=TIMEOUT).r_max == rho for h in hs)
    finally:
        sys.setswitchinterval(old)


def test_concurrent_milp_robustness_on_different_graphs():
    graphs = [nx.gnp_random_graph(n, p, seed=s, directed=True)
              for n, p, s in [(10, .5, 1), (12, .6, 2), (11, .5, 3), (12, .7, 4)]]
    ref = []
    for G in graphs:
        facts.clear_cache()
        rep = rescon.robustness(G, method="milp")
        ref.append((rep.r_max, rep.s_max))
    facts.clear_cache()
    # daemon threads other tests of the session left (Dask's IO loops and offload
    # executor, tqdm's monitor) are not this test's: only new ones count
    before = set(threading.enumerate())
    with ThreadPoolExecutor(4) as ex:
        fs = [ex.submit(rescon.robustness, G, method="milp") for G in graphs * 2]
        for i, f in enumerate(fs):
            rep = f.result(timeout=TIMEOUT)
            assert (rep.r_max, rep.s_max) == ref[i % len(graphs)]
            assert rescon.check_certificate(rep.certificate).verdict in ("valid", "unchecked")
    time.sleep(0.1)
    assert not [t for t in threading.enumerate() if t.daemon and t.is_alive()
                and t not in before and "ThreadPoolExecutor" not in t.name]


def test_concurrent_simulate_and_redundancy_are_bit_identical():
    sc = rescon.Scenario.paper_example()
    small = _ring_scenario(steps=20)
    costs = {i: "(x1 - 1)^2 + abs(x2 - 2)" for i in sc.benign}
    ref_sim = _quiet_simulate(small)
    ref_red = rescon.check_redundancy(costs, r=2)
    with ThreadPoolExecutor(4) as ex:
        fs = [ex.submit(_quiet_simulate, small) for _ in range(4)]
        gs = [ex.submit(rescon.check_redundancy, costs, r=2) for _ in range(4)]
        for f in fs:
            out = f.result(timeout=TIMEOUT)
            assert np.array_equal(out.states, ref_sim.states)
            for k, v in ref_sim.metrics.items():
                assert np.array_equal(out.metrics[k], v, equal_nan=True), k
        for g in gs:
            out = g.result(timeout=TIMEOUT)
            assert (out.holds, out.exact) == (ref_red.holds, ref_red.exact)
            assert json.dumps(out.certificate, sort_keys=True) == \
                json.dumps(ref_red.certificate, sort_keys=True)


def test_time_limited_robustness_leaves_no_thread_running():
    G = nx.gnp_random_graph(40, 0.5, seed=1, directed=True)
    before = threading.active_count()
    for limit in (0.05, 0.3):
        rep = rescon.robustness(G, time_limit=limit)
        assert rep.exact or rep.r_lower <= rep.r_upper
    time.sleep(0.2)
    assert threading.active_count() == before


# --------------------------------------------------------------------------- #
# reentrancy
# --------------------------------------------------------------------------- #


class _KernelSpy(Behaviour):
    """Sends 5 + the kernel point of the benign states; ``nested`` also calls
    safe_kernel (fast path), robustness and a whole simulate inside the step."""

    def __init__(self, nested: bool) -> None:
        self.nested = nested

    def messages(self, sender, receivers, view):
        x, _ = rescon.kernel_point(view.states[view.benign], 1)
        if self.nested:
            _ = rescon.safe_kernel(_cloud(15, 4, view.k), 1).vertices
            rescon.robustness(nx.gnp_random_graph(10, 0.6, seed=view.k, directed=True))
            inner = rescon.Scenario(graph=nx.complete_graph(5).to_directed(),
                                    x0=np.eye(5)[:, :2], F=0, steps=2)
            _quiet_simulate(inner)
        return np.tile(x + 5.0, (len(receivers), 1))

    def to_dict(self):
        return {}


def test_adversary_calling_rescon_does_not_corrupt_the_outer_run():
    plain = _quiet_simulate(_ring_scenario(steps=6, adversaries={0: _KernelSpy(False)}))
    nested = _quiet_simulate(_ring_scenario(steps=6, adversaries={0: _KernelSpy(True)}))
    assert np.array_equal(plain.states, nested.states)
    for k, v in plain.metrics.items():
        assert np.array_equal(nested.metrics[k], v, equal_nan=True), k
    assert gc.isenabled()


def test_adversary_raising_after_a_nested_kernel_propagates_and_restores_state():
    class Boom(Behaviour):
        def messages(self, sender, receivers, view):
            rescon.safe_kernel(_cloud(15, 4, 0), 1)
            raise KeyError("boom")

        def to_dict(self):
            return {}

    before = _state()
    with pytest.raises(KeyError, match="boom"):
        _quiet_simulate(_ring_scenario(steps=2, adversaries={0: Boom()}))
    assert _state() == before


@pytest.mark.slow
def test_cost_oracle_calling_rescon_in_rmdo():
    """(~35 s: the oracle is called for every agent at every step.)"""
    sc = replace(rescon.Scenario.paper_example(), steps=4)

    def pair(i):
        def f(Z):
            Z = np.asarray(Z, float)
            rescon.kernel_point(_cloud(8, 2, i), 1)
            return (Z[..., 0] - 1) ** 2 + (Z[..., 1] - 2) ** 2

        def g(Z):
            Z = np.asarray(Z, float)
            _ = rescon.safe_kernel(_cloud(12, 3, i), 1).vertices
            return np.stack([2 * (Z[..., 0] - 1), 2 * (Z[..., 1] - 2)], axis=-1)
        return f, g

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", rescon.ScenarioWarning)
        ref = rescon.rmdo(sc, {i: "(x1 - 1)^2 + (x2 - 2)^2" for i in sc.benign})
        got = rescon.rmdo(sc, {i: pair(i) for i in sc.benign})
    assert np.array_equal(got.states, ref.states)


# --------------------------------------------------------------------------- #
# worker pools after the parent used numba, the kernels and the MILP
# --------------------------------------------------------------------------- #


def _pool_job(seed: int) -> tuple:
    G = nx.gnp_random_graph(12, 0.6, seed=seed, directed=True)
    rep = rescon.robustness(G, method="milp")
    K = rescon.safe_kernel(_cloud(15, 4, seed), 1)
    return rep.r_max, rep.s_max, K.vertices.tobytes()


@pytest.mark.slow
@pytest.mark.skipif(sys.platform != "linux", reason="fork")
@pytest.mark.parametrize("method", ["fork", "spawn"])
def test_worker_pool_after_parent_used_milp_numba_and_kernels(method):
    ref = [_pool_job(s) for s in range(3)]
    rescon.safe_kernel(_cloud(14, 5, 9), 1)
    with mp.get_context(method).Pool(2) as pool:
        got = pool.map_async(_pool_job, range(3)).get(timeout=TIMEOUT)
    assert got == ref
