"""What a user waits for (BENCHMARKS.md §6): ``import rescon`` and the command line's
start load nothing heavy; every public name is still there.

Each check runs in a fresh interpreter and reads its ``sys.modules``, so a module-level
import added anywhere on the path fails it.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from math import comb

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

import rescon

#: modules that must not load with ``import rescon`` (nor with the CLI's parser)
HEAVY = ("scipy", "networkx", "distributed", "dask", "pandas", "pyarrow", "matplotlib",
         "numba", "llvmlite", "cvxpy", "casadi", "tqdm", "sympy")
#: rescon's own modules that hold numba code
COMPILED = ("rescon.graphs._kernels", "rescon.geometry._candidates",
            "rescon.geometry._small2d", "rescon.geometry._small3d",
            "rescon.geometry._expansions")


def _loaded(code: str) -> list[str]:
    """The modules loaded after running ``code`` in a fresh interpreter."""
    probe = f"{code}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    proc = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=True)
    return json.loads(proc.stdout.splitlines()[-1])


def _heavy(mods: list[str]) -> list[str]:
    return [m for m in mods if m.split(".")[0] in HEAVY or m in COMPILED]


def test_import_rescon_loads_nothing_heavy():
    mods = _loaded("import rescon")
    assert _heavy(mods) == []
    assert "numpy" not in mods  # nothing at all beyond the package's own lazy table


def test_cli_parser_loads_nothing_heavy():
    """``rescon --help`` / ``--version`` / a usage error answer without the science."""
    mods = _loaded("from rescon.cli import _parser\n_parser().parse_args(['check', 'x'])")
    assert _heavy(mods) == []


def test_every_public_name_is_reachable_and_star_import_works():
    names: dict[str, object] = {}
    exec("from rescon import *", names)  # noqa: S102 - the star import under test
    assert set(rescon.__all__) <= set(names)
    for name in rescon.__all__:
        assert getattr(rescon, name) is names[name]
    assert names["sweep"] is sys.modules["rescon.sweep"] and callable(names["sweep"])
    assert rescon.sweep.sweep.__module__ == "rescon.sweep.run"
    assert set(rescon.__all__) <= set(dir(rescon))


def test_unknown_attribute_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        rescon.nope  # noqa: B018
    assert not hasattr(rescon, "__wrapped__")


def test_submodules_stay_reachable_as_attributes():
    mods = _loaded("import rescon\nassert rescon.graphs.__name__ == 'rescon.graphs'\n"
                   "assert rescon.geometry.__name__ == 'rescon.geometry'")
    assert "rescon.graphs" in mods and "networkx" not in mods
    out = subprocess.run([sys.executable, "-c", "import rescon; print(rescon.__version__)"],
                         capture_output=True, text=True, timeout=60, check=True).stdout
    assert json.dumps(out.strip()) == json.dumps(rescon.__version__)


# --------------------------------------------------------------- small inputs, no numba

def test_small_kernel_from_the_cli_loads_no_numba(tmp_path):
    """``rescon kernel`` on 12 points: nothing compiled, nothing of numba imported."""
    pts = tmp_path / "p.csv"
    pts.write_text("\n".join(f"{math.cos(t):.6f},{math.sin(2 * t):.6f}"
                             for t in range(12)) + "\n")
    mods = _loaded("from rescon.cli import main\nimport contextlib, io\n"
                   f"with contextlib.redirect_stdout(io.StringIO()):\n"
                   f"    assert main(['kernel', {str(pts)!r}, '--F', '2']) == 0")
    assert [m for m in _heavy(mods) if m.split(".")[0] in ("numba", "llvmlite")
            or m in COMPILED] == []


def _scan_inputs(k, m, kind, seed):
    rng = np.random.default_rng(seed)
    Y = rng.normal(size=(m, k))
    if kind == 1:  # ties: many points exactly on candidate hyperplanes
        Y = np.round(Y * 2) / 2
    elif kind == 2:  # tiny magnitudes: the underflow term decides
        Y = Y * 1e-300
    elif kind == 3:  # repeated points and a degenerate coordinate
        if k > 1:
            Y[:, 0] = Y[:, 1]
        Y[1] = Y[0]
    return Y, rng.integers(1, 3, size=m)


@settings(max_examples=60, deadline=None)
@given(k=st.integers(1, 5), extra=st.integers(1, 8), kind=st.integers(0, 3),
       seed=st.integers(0, 2**32 - 1), F=st.integers(0, 8), exact=st.booleans())
@example(k=4, extra=7, kind=0, seed=0, F=0, exact=True)
def test_numpy_scan_decides_as_the_numba_scan(k, extra, kind, seed, F, exact):
    """Same cofactors, same degenerate flags, and every count compared with F the same
    (the numba scan stops a subset early, so only counts ≤ F must be equal). ``exact``
    (no error bound) is what rescon passes for data whose float arithmetic is exact —
    small integers — so there the data are small integers: with no error bound on
    rounded data the two scans' different float sums may disagree (the numba scan's
    octant prune, k ≥ 4, reads 2 × 2 forms)."""
    from rescon.geometry import _candidates, _scan_np

    m = k + extra
    Y, W = _scan_inputs(k, m, kind, seed)
    if exact:
        Y = np.round(Y * 4) if kind != 2 else np.round(Y * 4e300)
    subsets = _scan_np.k_subsets(m, k)
    assert np.array_equal(subsets, _candidates.k_subsets(m, k, comb(m, k)))
    c_err, floor = (0.0, 0.0) if exact else (1e-15, 1e-300)
    a = _candidates.classify(Y, W.astype(np.int64), subsets, c_err, F, floor)
    b = _scan_np.classify(Y, W, subsets, c_err, F, floor)
    assert np.array_equal(a[3], b[3])
    for x, y in zip(_candidates.cofactors(Y, subsets), _scan_np.cofactors(Y, subsets),
                    strict=True):
        assert np.array_equal(x, y)
    plus_a, minus_a, unc_a = a[:3]
    plus_b, minus_b, unc_b = b[:3]
    for x, y in ((plus_a, plus_b), (minus_a, minus_b), (plus_a + unc_a, plus_b + unc_b),
                 (minus_a + unc_a, minus_b + unc_b)):
        assert np.array_equal(x <= F, y <= F)
        assert np.array_equal(x[x <= F], y[x <= F])


@pytest.mark.parametrize("d, n, F, scale", [(2, 12, 2, 1.0), (2, 9, 1, 1e-200),
                                            (3, 10, 1, 1.0), (3, 9, 1, 1e150),
                                            (4, 8, 1, 1.0)])
def test_small_kernels_equal_the_numba_path(monkeypatch, d, n, F, scale):
    """The small path (numpy scan, integer side counts) gives the very same kernel as
    the numba path: the same facets, vertices and certificate."""
    from rescon.geometry import halfspaces
    from rescon.geometry.kernel import safe_kernel

    X = np.random.default_rng(n + d).normal(size=(n, d)) * scale
    X[-1] = X[0] + (X[1] - X[0]) * 0.5  # a point on a segment: exact ties
    small = safe_kernel(X, F)
    monkeypatch.setattr(halfspaces, "SMALL_SCAN", -1)
    big = safe_kernel(X, F)
    assert small.is_empty == big.is_empty and small.dim == big.dim
    assert np.array_equal(small.A, big.A) and np.array_equal(small.b, big.b)
    assert np.array_equal(small.vertices, big.vertices)
    assert json.dumps(small.certificate, sort_keys=True) == json.dumps(big.certificate,
                                                                       sort_keys=True)


# --------------------------------------------------------- the first simulate, cold

@pytest.mark.slow
def test_cold_paper_simulate_compiles_each_kernel_once(tmp_path):
    """The first simulate of the paper example after install (empty numba cache) compiles
    each planar kernel once — no second, literal-typed specialisation — and neither the
    Radon step (m = 4, F = 1 only) nor the cluster kernel (numpy for m ≤ 15). Its time
    (target ≤ 10 s wall on 2 idle cores; it took 17-20 s of CPU) is measured by
    ``benchmarks/latency_bench.py``, not here: a CPU bound in this unit test failed on a
    busy 2-core machine (15.3 CPU-s, and e79e53b alike)."""
    code = ("import warnings\nimport rescon\nwarnings.simplefilter('ignore')\n"
            "tr = rescon.simulate(rescon.Scenario.paper_example(), progress=False)\n"
            "print(tr.final_diameter)")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, timeout=600, check=True).stdout.split()
    assert float(out[0]) < 1e-9
    kernels = [p.name.split("-")[0] for p in tmp_path.rglob("*.nbc")]
    assert len(kernels) == len(set(kernels)), sorted(kernels)
    assert not {"_small2d._radon4", "_small2d.cluster_box", "_small2d._clusters"} & set(kernels)
    assert "_small2d._polygons" in kernels  # (the cache the run wrote)
