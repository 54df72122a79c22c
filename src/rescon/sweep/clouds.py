"""Point clouds of kernel cells: ``[points] generator, n, d, seed`` → an (n, d) array.

* ``gaussian`` — n i.i.d. standard normal points of R^d;
* ``uniform`` — n points uniform in the cube [−1, 1]^d;
* ``sphere`` — n points uniform on the unit sphere S^{d−1} (normalised Gaussians), every
  point a vertex of the hull: the kernel's hardest case for a given n.

Randomness: ``numpy.random.default_rng([seed, 3])`` (stream 3; graphs use 1, initial
states 2), so a cell's cloud depends on its seed only.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

import numpy as np

from .._validate import integer
from ..errors import InputError
from ..geometry._budget import require

__all__ = ["CLOUDS", "cloud"]

#: stream of the points in default_rng([seed, stream])
POINTS_STREAM = 3


def _gaussian(rng: np.random.Generator, n: int, d: int) -> np.ndarray:
    return rng.standard_normal((n, d))


def _uniform(rng: np.random.Generator, n: int, d: int) -> np.ndarray:
    return rng.uniform(-1.0, 1.0, size=(n, d))


def _sphere(rng: np.random.Generator, n: int, d: int) -> np.ndarray:
    z = rng.standard_normal((n, d))
    norms = np.linalg.norm(z, axis=1, keepdims=True)
    return z / np.where(norms > 0, norms, 1.0)


CLOUDS: dict[str, Callable[[np.random.Generator, int, int], np.ndarray]] = {
    "gaussian": _gaussian, "uniform": _uniform, "sphere": _sphere}


def cloud(table: Mapping[str, Any], *, where: str = "points") -> np.ndarray:
    """The cloud of ``table`` (keys generator, n ≥ 1, d ≥ 1, seed ≥ 0 (default 0)), or a
    one-line InputError naming the key (an unknown generator lists the available ones)."""
    name = table.get("generator")
    if name not in CLOUDS:
        raise InputError(f"{where}: generator must be one of {', '.join(CLOUDS)}; "
                         f"got {name!r}")
    missing = [k for k in ("n", "d") if k not in table]
    if missing:
        raise InputError(f"{where}: needs {', '.join(missing)}")
    n = integer(f"{where}: n", table["n"], low=1)
    d = integer(f"{where}: d", table["d"], low=1)
    seed = integer(f"{where}: seed", table.get("seed", 0), low=0)
    require(f"{where}: {n} points in dimension {d}", n * d, 8 * n * d, "reduce n or d")
    return CLOUDS[name](np.random.default_rng([seed, POINTS_STREAM]), n, d)
