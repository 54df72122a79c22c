"""What a consensus run is judged by: agreement and validity of the benign states.

* spread_p(t) = max_{i∈B} x_{i,p}(t) − min_{i∈B} x_{i,p}(t) per coordinate p, and the
  diameter max_{i,j∈B} ‖x_i(t) − x_j(t)‖₂ (consensus: both → 0);
* δ-validity: dist(x_i(t), conv{x_j(0) : j ∈ B}) for every benign i (validity: it stays
  ≤ δ). The hull is computed exactly once (the safe kernel with F = 0); a state inside
  it (decided exactly) is at distance 0, one outside is projected onto it exactly.
"""

from __future__ import annotations

import numpy as np

from ..geometry.kernel import safe_kernel

__all__ = ["ValidityMonitor", "diameter", "spread"]


def spread(states: np.ndarray) -> np.ndarray:
    """Per-coordinate max − min over the rows of ``states`` (n, d)."""
    return states.max(axis=0) - states.min(axis=0)


def diameter(states: np.ndarray) -> float:
    """Largest Euclidean distance between two rows of ``states`` (n, d)."""
    diff = states[:, None, :] - states[None, :, :]
    return float(np.sqrt((diff**2).sum(axis=2)).max())


class ValidityMonitor:
    """Distances of states to conv(initial benign states), exactly."""

    def __init__(self, initial: np.ndarray) -> None:
        self.hull = safe_kernel(initial, 0)

    def distance(self, x: np.ndarray) -> float:
        if self.hull.contains(x):
            return 0.0
        y, _ = self.hull.point("project", target=x)
        return float(np.linalg.norm(x - y))

    def distances(self, states: np.ndarray) -> np.ndarray:
        """Distances of the rows of ``states``; rows surely inside the hull (every facet
        value below its rounding bound, full-dimensional hull) are 0 without exact work."""
        K = self.hull
        out = np.empty(len(states))
        sure = np.zeros(len(states), dtype=bool)
        if K.dim == states.shape[1] and len(K.b):
            S = states @ K.A.T - K.b
            bound = 16.0 * 2.0**-53 * (np.abs(states) @ np.abs(K.A).T + np.abs(K.b))
            sure = (S < -bound).all(axis=1)
        out[sure] = 0.0
        for i in np.flatnonzero(~sure):
            out[i] = self.distance(states[i])
        return out
