"""Safe kernels against independent references.

* **Optional** (``-m optional``; skipped with a reason when ``Rscript`` or the R package
  ddalpha is missing — Debian ``r-cran-ddalpha``): the exact Tukey depth from ddalpha,
  ``depth.halfspace(x, data, exact=TRUE)`` (a fraction: × n gives the count). Since
  Ψ(X, F) is the region of Tukey depth ≥ F + 1, for random clouds (d = 2, 3, n ≤ 40)
  and query points that are random or placed near the kernel's boundary, depth ≥ F+1
  ⟺ ``K.contains(x)`` for every query at distance > 1e-7 from the boundary. All
  queries go to R in one ``Rscript`` call.
* **Plain** (always run, < 10 s): the benchmark baselines of
  ``benchmarks/kernel_baselines.py`` on tiny inputs — the subset LP and the
  subset-hull qhull intersection agree with ``rescon.safe_kernel``, the exact planar
  Tukey-depth referee agrees with ``K.contains`` — and ``benchmarks.run kernels``
  runs end to end.
"""

from __future__ import annotations

import csv
import functools
import math
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

import rescon

REPO = Path(__file__).resolve().parent.parent
if str(REPO) not in sys.path:
    sys.path.insert(0, str(REPO))

from benchmarks import kernel_baselines as KB  # noqa: E402
from benchmarks import kernel_clouds as KC  # noqa: E402

# --------------------------------------------------------------------------- ddalpha


@functools.lru_cache(maxsize=1)
def _ddalpha_missing() -> str | None:
    """None when Rscript with ddalpha works, else why not."""
    rs = shutil.which("Rscript")
    if rs is None:
        return "Rscript not found (install Debian r-cran-ddalpha for the Tukey-depth oracle)"
    try:
        p = subprocess.run([rs, "-e", "suppressMessages(library(ddalpha)); cat('ok')"],
                           check=False, capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return f"Rscript failed: {exc}"
    if p.returncode != 0 or "ok" not in p.stdout:
        return ("R package ddalpha not available (install Debian r-cran-ddalpha): "
                + (p.stderr.strip().splitlines() or ["?"])[-1])
    return None


_R_SCRIPT = r"""
suppressMessages(library(ddalpha))
args <- commandArgs(trailingOnly = TRUE)
dir <- args[1]
m <- as.integer(args[2])
for (i in seq_len(m)) {
  data <- as.matrix(read.table(file.path(dir, sprintf("data_%d.txt", i))))
  q <- as.matrix(read.table(file.path(dir, sprintf("query_%d.txt", i))))
  dep <- depth.halfspace(q, data, exact = TRUE)
  write.table(format(dep, digits = 17), file.path(dir, sprintf("depth_%d.txt", i)),
              row.names = FALSE, col.names = FALSE, quote = FALSE)
}
"""


def ddalpha_depths(batch: list[tuple[np.ndarray, np.ndarray]]) -> list[np.ndarray]:
    """Exact Tukey depths (counts) of each query set in its data set, one R call."""
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        for i, (X, Q) in enumerate(batch, 1):
            np.savetxt(d / f"data_{i}.txt", X, fmt="%.17g")
            np.savetxt(d / f"query_{i}.txt", np.atleast_2d(Q), fmt="%.17g")
        (d / "depth.R").write_text(_R_SCRIPT)
        p = subprocess.run([shutil.which("Rscript") or "Rscript", str(d / "depth.R"), str(d),
                            str(len(batch))], check=False, capture_output=True, text=True,
                           timeout=600)
        assert p.returncode == 0, p.stderr
        out = []
        for i, (X, Q) in enumerate(batch, 1):
            frac = np.loadtxt(d / f"depth_{i}.txt", ndmin=1)
            cnt = frac * len(X)
            assert np.all(np.abs(cnt - np.round(cnt)) < 1e-6), cnt
            assert len(cnt) == len(np.atleast_2d(Q))
            out.append(np.round(cnt).astype(int))
        return out


def _queries(K, X: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Random points of the bounding box (slightly enlarged) plus, when K is
    full-dimensional, points along random rays from an interior point at distances
    1e-6 .. 1e-2 (relative to the cloud) inside and outside the boundary."""
    lo, hi = X.min(axis=0), X.max(axis=0)
    span = hi - lo
    d = X.shape[1]
    Q = [rng.uniform(lo - 0.1 * span, hi + 0.1 * span, (40, d))]
    if K.dim == d:
        c = K.vertices.mean(axis=0)
        scale = float(np.max(span))
        for _ in range(12):
            u = rng.standard_normal(d)
            u /= np.linalg.norm(u)
            Au = K.A @ u
            with np.errstate(divide="ignore"):
                t = np.where(Au > 0, (K.b - K.A @ c) / np.where(Au > 0, Au, 1), np.inf)
            tb = float(t.min())
            for eps in (1e-6, 1e-4, 1e-2):
                for s in (-1, 1):
                    Q.append((c + (tb + s * eps * scale) * u)[None, :])
        Q.append(K.vertices + 1e-5 * scale * rng.standard_normal(K.vertices.shape))
    return np.vstack(Q)


def _margin(K, x: np.ndarray) -> float:
    """Distance-like margin of x from ∂K: positive inside (exact distance to the nearest
    facet hyperplane), positive outside too (a lower bound of the distance to K);
    +inf for an empty kernel (every point is far from it)."""
    if K.is_empty:
        return math.inf
    viol = K.A @ x - K.b
    eq = np.abs(K.Aeq @ x - K.beq) if len(K.beq) else np.zeros(0)
    if len(eq) and eq.max() > 0:
        return float(max(eq.max(), viol.max(initial=0.0)))
    if viol.max(initial=-math.inf) > 0:
        return float(viol.max())
    return float(-viol.max()) if len(viol) else math.inf


def _oracle_clouds() -> list[tuple[str, np.ndarray, int]]:
    """Random Gaussian / uniform clouds, plus the benchmark's special clouds (integer
    grid with ties and collinear triples, duplicates, convex position, attack,
    converged), d = 2, 3, n ≤ 40, F ∈ {1, n/10, h, h+1}."""
    out = []
    rng = np.random.default_rng(20240607)
    for d in (2, 3):
        for n in (9, 16, 25, 40):
            h = (n - 1) // (d + 1)
            for F in sorted({1, max(1, n // 10), h, h + 1}):
                X = rng.standard_normal((n, d)) if n % 2 else rng.uniform(-1, 1, (n, d))
                out.append((f"random d={d} n={n} F={F}", X, F))
        for fam in ("grid", "duplicates", "sphere", "attack", "converged"):
            for n in (12, 30):
                h = (n - 1) // (d + 1)
                for F in sorted({1, h, h + 1}):
                    c = KC.make_cloud(fam, d, n, F)
                    out.append((c.label, c.X, F))
    return out


@pytest.mark.optional
def test_tukey_depth_oracle_agrees_with_kernel():
    why = _ddalpha_missing()
    if why:
        pytest.skip(why)
    rng = np.random.default_rng(7)
    cases = []
    for name, X, F in _oracle_clouds():
        K = rescon.safe_kernel(X, F)
        Q = _queries(K, X, rng)
        if np.all(X == np.round(X)):  # grid: also half-integer points (on many lines)
            Q = np.vstack([Q, rng.integers(-1, 2 * int(X.max()) + 2, (40, X.shape[1])) / 2.0])
        keep = np.array([_margin(K, q) > 1e-7 for q in Q])
        cases.append((name, X, F, K, Q[keep]))
    depths = ddalpha_depths([(X, Q) for _, X, _, _, Q in cases])
    bad = []
    n_in = n_out = 0
    for (name, X, F, K, Q), dep in zip(cases, depths, strict=True):
        for q, k in zip(Q, dep, strict=True):
            inside = K.contains(q)
            n_in += inside
            n_out += not inside
            if (k >= F + 1) != inside:
                bad.append(f"{name}: x={q.tolist()} ddalpha depth {k} (F+1 = {F + 1}) but "
                           f"K.contains = {inside} (margin {_margin(K, q):.3g}); "
                           f"X={X.tolist()}")
    assert not bad, f"{len(bad)} disagreements:\n" + "\n".join(bad[:10])
    assert n_in > 500 and n_out > 2000  # the queries really probe both sides


# --------------------------------------------------------------------------- baselines


def _tiny():
    rng = np.random.default_rng(5)
    cases = [
        (np.array([[0, 0], [4, 0], [0, 4], [1, 1]], float), 1),  # kernel = a point
        (np.array([[0, 0], [1, 0], [0, 1]], float), 1),  # empty
        (rng.standard_normal((7, 2)), 1),
        (rng.standard_normal((7, 2)), 2),
        (rng.standard_normal((8, 3)), 1),
        (rng.standard_normal((9, 2)), 3),  # above Helly
        (KC.make_cloud("grid", 2, 9, 2).X, 2),
        (KC.make_cloud("flat", 3, 8, 1).X, 1),  # degenerate: qhull n/a
        (KC.make_cloud("duplicates", 2, 9, 2).X, 2),
        (KC.make_cloud("above_helly", 2, 9, 3).X, 3),  # empty by construction
    ]
    return cases


@pytest.mark.parametrize("i", range(10))
def test_subset_lp_agrees_with_rescon(i):
    X, F = _tiny()[i]
    K = rescon.safe_kernel(X, F)
    for obj in (None, np.zeros(X.shape[1])):
        r = KB.subset_lp(X, F, objective=obj)
        assert r.status in ("optimal", "infeasible"), r
        assert (r.status == "infeasible") == K.is_empty
        assert KB.compare_lp(K, r) is None
        if r.x is not None and X.shape[1] == 2:
            # the LP's point has exact Tukey depth >= F + 1 (up to the LP tolerance: the
            # point may sit on the boundary, so only check depth >= F when not inside)
            dep = KB.tukey_depth_2d_exact(X, r.x)
            assert dep >= F + 1 or not K.contains(r.x)


@pytest.mark.parametrize("i", range(10))
def test_qhull_baseline_agrees_with_rescon(i):
    X, F = _tiny()[i]
    K = rescon.safe_kernel(X, F)
    r = KB.subset_hull_qhull(X, F)
    err, h = KB.compare_qhull(K, r)
    assert err is None, err
    if r.status == "optimal":
        assert K.dim == X.shape[1] and h is not None and h <= 1e-9
    if K.is_empty:
        assert r.status in ("empty", "n/a")
    if K.dim < X.shape[1] and not K.is_empty:
        assert r.status == "n/a"


def test_baselines_skip_and_subsets():
    assert KB.subset_lp(np.zeros((30, 2)), 10, max_subsets=1000).status == "skipped"
    assert KB.subset_hull_qhull(np.zeros((30, 2)), 10, max_subsets=1000).status == "skipped"
    S = KB.subsets(5, 2)
    assert S.shape == (10, 3)
    assert len({tuple(r) for r in S}) == 10 and all(list(r) == sorted(r) for r in S)


def test_compare_detects_a_wrong_answer():
    X = np.random.default_rng(3).standard_normal((8, 2))
    K = rescon.safe_kernel(X, 1)
    assert K.dim == 2
    r = KB.subset_lp(X, 1)
    bad = r._replace(x=r.x + 1.0, value=r.value + 10.0)
    assert KB.compare_lp(K, bad) is not None
    assert KB.compare_lp(K, r._replace(status="infeasible", x=None)) is not None
    q = KB.subset_hull_qhull(X, 1)
    assert q.status == "optimal"
    err, _ = KB.compare_qhull(K, q._replace(vertices=q.vertices + 1e-3))
    assert err is not None


def test_exact_depth_referee_matches_kernel():
    rng = np.random.default_rng(11)
    X = rng.integers(0, 4, (12, 2)).astype(float)  # ties and collinear points
    for F in (1, 2, 3):
        K = rescon.safe_kernel(X, F)
        for q in np.vstack([X, rng.integers(0, 7, (30, 2)) / 2.0]):
            assert (KB.tukey_depth_2d_exact(X, q) >= F + 1) == K.contains(q), (F, q)


def test_clouds_are_deterministic_and_as_documented():
    for fam in KC.CLOUD_FAMILIES:
        a = KC.make_cloud(fam, 2, 20, 3)
        b = KC.make_cloud(fam, 2, 20, 3)
        assert np.array_equal(a.X, b.X) and a.X.shape == (20, 2)
    g = KC.make_cloud("grid", 3, 20, 2).X
    assert np.all(g == np.round(g)) and len({tuple(r) for r in g}) == 20
    assert len({tuple(r) for r in KC.make_cloud("duplicates", 2, 20, 2).X}) == 7
    assert KC.f_values(100, 2) == [1, 10, 33, 34, 35, 36]
    assert KC.f_values(10, 2, "above_helly") == [4, 5, 6]


def test_runner_kernels_end_to_end(tmp_path):
    from benchmarks import run as R

    rc = R.main(["kernels", "--families", "gaussian,above_helly,flat", "--dims", "2",
                 "--sizes", "8", "--no-reference", "--repeats", "1", "--out", str(tmp_path),
                 "--name", "t"])
    assert rc == 0
    with open(tmp_path / "kernels_t.csv") as fh:
        rows = list(csv.DictReader(fh))
    methods = {r["method"] for r in rows}
    assert {"rescon_polytope", "rescon_empty", "rescon_point", "subset_lp", "qhull"} <= methods
    assert not [r for r in rows if r["method"] == "check"]
    md = (tmp_path / "kernels_t.md").read_text()
    assert "## Targets" in md and "No rescon error" in md
    assert R.main(["kernels", "--families", "nope", "--out", str(tmp_path)]) == 2
