"""Point clouds of BENCHMARKS.md §2 (safe kernels) with fixed seeds.

Self-contained (numpy only; does not use rescon). Every cloud is a function of
``(family, d, n, F)`` alone: the generator is ``numpy.random.default_rng([k, seed])``
with ``k`` the family's index in :data:`CLOUD_FAMILIES` and
``seed = 10_000_000·d + 1000·n + F`` (:func:`seed_for`), so the same instance is
produced by any run, on any machine with the same numpy.

Families (``n`` points in ``R^d``; "benign" = the ``n − F`` points an attacker did not
place):

* ``gaussian``: i.i.d. N(0, I).
* ``cube``: i.i.d. uniform on [−1, 1]^d.
* ``sphere``: uniform on the unit sphere (convex position: every point is a vertex of
  conv X).
* ``attack``: ``n − F`` benign points clustered (N(0, 0.01² I)) and ``F`` far outliers
  (radius 100, random directions).
* ``converged``: ``n − F`` benign points within 1e-7 of a random centre (uniform
  in a box of half-width 1e-7) and ``F`` outliers at distance 1–10.
* ``grid``: ``n`` distinct points of the integer grid {0..g−1}^d, g = ⌈(2n)^{1/d}⌉
  (many ties, collinear triples, coplanar quadruples).
* ``duplicates``: ``⌈n/3⌉`` distinct Gaussian points, each used at least once and the
  rest drawn with replacement (a multiset: duplicates count).
* ``flat``: points exactly on an affine hyperplane of R^d (``x_d = Σ_{j<d} c_j x_j + c_0``
  with small integer c and dyadic coordinates, so the floats lie *exactly* on it): the
  kernel is at most (d−1)-dimensional.
* ``above_helly``: the Helly-tight configuration: d+1 tight clusters (N(0, 0.02² I)) at
  the vertices of a regular-ish simplex, sizes as equal as possible. Run with
  ``F ∈ {h+1, h+2, h+3}``, ``h = ⌊(n−1)/(d+1)⌋``: every cluster has ≤ F points, so
  the kernel is empty. (The other families are run at those F too: "possibly empty".)

F values (:func:`f_values`): ``{1, ⌊n/10⌋, h, h+1, h+2, h+3}`` (only those with
``1 ≤ F < n``; ``above_helly``: the last three only).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

__all__ = [
    "Cloud",
    "CloudFamily",
    "CLOUD_FAMILIES",
    "clouds",
    "make_cloud",
    "f_values",
    "helly_bound",
    "seed_for",
    "DEFAULT_SIZES",
]


class Cloud(NamedTuple):
    family: str
    d: int
    n: int
    F: int
    seed: int
    X: np.ndarray  # (n, d) float64
    expect_empty: bool | None  # known answer when the construction forces it, else None

    @property
    def label(self) -> str:
        return f"{self.family}(d={self.d}, n={self.n}, F={self.F})"


MakeFn = Callable[[np.random.Generator, int, int, int], np.ndarray]


@dataclass(frozen=True)
class CloudFamily:
    name: str
    make: MakeFn
    description: str
    above_helly_only: bool = False


def helly_bound(n: int, d: int) -> int:
    """h = ⌊(n−1)/(d+1)⌋: the largest F for which Ψ(X, F) ≠ ∅ for every X (Helly)."""
    return (n - 1) // (d + 1)


def f_values(n: int, d: int, family: str = "gaussian") -> list[int]:
    """The F grid of BENCHMARKS.md §2 for (n, d), sorted, deduplicated, 1 ≤ F < n."""
    h = helly_bound(n, d)
    above = [h + 1, h + 2, h + 3]
    vals = above if CLOUD_FAMILIES[family].above_helly_only else [1, n // 10, h, *above]
    return sorted({F for F in vals if 1 <= F < n})


def seed_for(d: int, n: int, F: int) -> int:
    return 10_000_000 * d + 1000 * n + F


# --------------------------------------------------------------------------- generators


def _unit(rng: np.random.Generator, m: int, d: int) -> np.ndarray:
    v = rng.standard_normal((m, d))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def _gaussian(rng, n, d, F):
    return rng.standard_normal((n, d))


def _cube(rng, n, d, F):
    return rng.uniform(-1.0, 1.0, (n, d))


def _sphere(rng, n, d, F):
    return _unit(rng, n, d)


def _attack(rng, n, d, F):
    benign = 0.01 * rng.standard_normal((n - F, d))
    out = 100.0 * _unit(rng, F, d)
    X = np.vstack([benign, out])
    return X[rng.permutation(n)]


def _converged(rng, n, d, F):
    c = rng.uniform(-1.0, 1.0, d)
    benign = c + rng.uniform(-1e-7, 1e-7, (n - F, d))
    out = c + rng.uniform(1.0, 10.0, (F, 1)) * _unit(rng, F, d)
    X = np.vstack([benign, out])
    return X[rng.permutation(n)]


def _grid(rng, n, d, F):
    g = math.ceil((2 * n) ** (1.0 / d))
    while g**d < n:
        g += 1
    idx = rng.choice(g**d, size=n, replace=False)
    pts = np.array(np.unravel_index(idx, (g,) * d)).T
    return pts.astype(np.float64)


def _duplicates(rng, n, d, F):
    m = math.ceil(n / 3)
    base = rng.standard_normal((m, d))
    pick = np.concatenate([np.arange(m), rng.integers(0, m, n - m)])
    return base[rng.permutation(pick)]


def _flat(rng, n, d, F):
    # dyadic coordinates with few bits and small integer coefficients: every product
    # and sum below is exact in binary floating point, so the points lie exactly on
    # the hyperplane x_d = c·x_{<d} + c_0.
    free = rng.integers(-1024, 1025, (n, d - 1)) / 1024.0
    c = rng.integers(-3, 4, d - 1).astype(np.float64)
    c[c == 0] = 1.0
    c0 = rng.integers(-8, 9) / 4.0
    last = free @ c + c0
    X = np.column_stack([free, last])
    assert np.all(X[:, -1] - (X[:, :-1] @ c + c0) == 0.0)
    return X


def _simplex_vertices(d: int) -> np.ndarray:
    """d+1 vertices of a regular simplex in R^d, centred at 0, edge ≈ 2."""
    E = np.eye(d + 1) - 1.0 / (d + 1)
    # orthonormal basis of the hyperplane sum = 0
    q, _ = np.linalg.qr(E[:, :d])
    V = E @ q
    return V / np.linalg.norm(V[0] - V[1]) * 2.0


def _above_helly(rng, n, d, F):
    V = _simplex_vertices(d)
    lab = np.arange(n) % (d + 1)
    X = V[lab] + 0.02 * rng.standard_normal((n, d))
    return X[rng.permutation(n)]


CLOUD_FAMILIES: dict[str, CloudFamily] = {
    f.name: f
    for f in [
        CloudFamily("gaussian", _gaussian, "i.i.d. N(0, I)"),
        CloudFamily("cube", _cube, "uniform on [-1, 1]^d"),
        CloudFamily("sphere", _sphere, "uniform on the unit sphere (convex position)"),
        CloudFamily("attack", _attack, "n-F benign in N(0, 0.01^2 I), F outliers at radius 100"),
        CloudFamily("converged", _converged,
                    "n-F benign within 1e-7 of a centre, F outliers at distance 1-10"),
        CloudFamily("grid", _grid, "n distinct points of {0..g-1}^d, g = ceil((2n)^(1/d))"),
        CloudFamily("duplicates", _duplicates, "ceil(n/3) distinct Gaussian points, repeated"),
        CloudFamily("flat", _flat, "exactly on an affine hyperplane (dyadic coordinates)"),
        CloudFamily("above_helly", _above_helly,
                    "d+1 tight clusters at simplex vertices, F > h: empty kernel",
                    above_helly_only=True),
    ]
}

#: BENCHMARKS.md §2 sizes: d -> n values (n = 1000 only for d = 2; "a few" d = 4, 5).
DEFAULT_SIZES: dict[int, tuple[int, ...]] = {
    2: (10, 20, 50, 100, 1000),
    3: (10, 20, 50, 100),
    4: (10, 20),
    5: (10,),
}

#: families run for d >= 4 (the expensive dimensions): a few only.
HIGH_D_FAMILIES = ("gaussian", "sphere", "grid", "above_helly")


def make_cloud(family: str, d: int, n: int, F: int) -> Cloud:
    if family not in CLOUD_FAMILIES:
        raise ValueError(f"unknown cloud family {family!r}; known: {', '.join(CLOUD_FAMILIES)}")
    if not (d >= 1 and n >= 2 and 0 <= F < n):
        raise ValueError(f"need d >= 1, n >= 2, 0 <= F < n; got d={d}, n={n}, F={F}")
    fam = CLOUD_FAMILIES[family]
    if family == "flat" and d < 2:
        raise ValueError("flat clouds need d >= 2")
    k = list(CLOUD_FAMILIES).index(family)
    seed = seed_for(d, n, F)
    rng = np.random.default_rng([k, seed])
    X = np.ascontiguousarray(fam.make(rng, n, d, F), dtype=np.float64)
    assert X.shape == (n, d), (family, X.shape)
    expect = True if (fam.above_helly_only and F > helly_bound(n, d)) else None
    if F <= helly_bound(n, d):
        expect = False  # Helly: nonempty for every X
    return Cloud(family, d, n, F, seed, X, expect)


def clouds(families: Iterable[str], sizes: dict[int, Iterable[int]],
           f_override: Iterable[int] | None = None,
           high_d_families: Iterable[str] | None = HIGH_D_FAMILIES) -> Iterator[Cloud]:
    """Every (family, d, n, F) of the grid. ``f_override``: use these F (those < n)
    instead of :func:`f_values`. For d ≥ 4 only ``high_d_families`` are generated
    (None: all)."""
    fams = list(families)
    for d in sorted(sizes):
        for n in sorted(sizes[d]):
            for fam in fams:
                if d >= 4 and high_d_families is not None and fam not in high_d_families:
                    continue
                if fam == "flat" and d < 2:
                    continue
                Fs = (sorted({F for F in f_override if 1 <= F < n}) if f_override
                      else f_values(n, d, fam))
                for F in Fs:
                    yield make_cloud(fam, d, n, F)
