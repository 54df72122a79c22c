"""Cen(Λ) of Algorithm 1: the box centre can leave the benign hull, the vertex mean
and the hull centroid cannot (issue 10 §4)."""

from __future__ import annotations

import numpy as np
import pytest

from rescon.consensus.adversaries import Bait
from rescon.consensus.engine import _centre, simulate
from rescon.consensus.scenario import Scenario
from rescon.errors import InputError
from rescon.graphs.generators import circulant
from rescon.graphs.robustness import is_r_robust

pytestmark = pytest.mark.filterwarnings("ignore::rescon.consensus.scenario.ScenarioWarning")


def slab_states(seed: int, n: int = 13, half: float = 0.5) -> np.ndarray:
    """n states in a tilted slab: uniform on a 10 × 10 square of the plane
    x + y + z = 15, then up to ``half`` off it along its normal (full-dimensional)."""
    rng = np.random.default_rng(seed)
    u = rng.uniform(-5, 5, size=(n, 2))
    e1 = np.array([1.0, -1.0, 0.0]) / np.sqrt(2)
    e2 = np.array([1.0, 1.0, -2.0]) / np.sqrt(6)
    normal = np.ones(3) / np.sqrt(3)
    return 5 + u[:, :1] * e1 + u[:, 1:] * e2 + rng.uniform(-half, half, size=(n, 1)) * normal


def bait_run(centre: str, steps: int = 3):
    """13-node ring lattice (k = 5: 5-robust = (d+1)F+1), d = 3, F = 1, a bait
    adversary at node 0, exact kernel points. Found by a search over seeds 0-7 with
    half-thickness 0.5: seeds 0 and 2 leave the hull with the box centre."""
    sc = Scenario(graph=circulant(13, 5), x0=slab_states(0), F=1, adversaries={0: Bait()},
                  steps=steps, residual="none", seed=0, centre=centre,
                  kernel_point="project-exact")
    return simulate(sc)


@pytest.mark.slow
def test_box_centre_leaves_the_benign_hull():
    """A counterexample with every assumption met: the box centre puts benign agents
    outside conv(benign initial states) (distance 0.135 at step 1), the vertex mean
    and the centroid of conv Λ (both in conv Λ ⊆ the benign hull) never do."""
    assert is_r_robust(circulant(13, 5), 5).holds
    box = bait_run("box")
    assert box.metrics["validity"][1] > 0.1
    for centre in ("mean", "centroid"):
        tr = bait_run(centre)
        assert tr.max_validity == 0.0, (centre, tr.metrics["validity"])


def test_centres_of_one_lambda():
    """Λ of d = 2 with its 4 points: the box centre is outside conv Λ, the vertex mean
    and the area centroid are inside; all are computed per agent row."""
    lam = np.array([[[0.0, 0.0], [4.0, 4.0], [4.0, 3.0], [3.0, 4.0]],
                    [[1.0, 1.0], [1.0, 1.0], [1.0, 1.0], [1.0, 1.0]]])
    assert np.array_equal(_centre(lam, "box"), [[2.0, 2.0], [1.0, 1.0]])
    assert np.array_equal(_centre(lam, "mean"), [[2.75, 2.75], [1.0, 1.0]])
    cen = _centre(lam, "centroid")
    # the quadrilateral (0,0),(4,3),(4,4),(3,4): two triangles of areas 2 and 2
    assert np.allclose(cen[0], (np.array([8, 7]) / 3 + np.array([7, 8]) / 3) / 2)
    assert np.array_equal(cen[1], [1.0, 1.0])


def test_default_centre_lies_in_conv_lambda():
    assert Scenario(graph=circulant(6, 2), x0=np.zeros((6, 1)), F=0).centre == "mean"


def test_centroid_centre_runs_and_agrees():
    x0 = np.random.default_rng(4).uniform(0, 10, size=(14, 2))
    sc = Scenario(graph=circulant(14, 4), x0=x0, F=1, adversaries={0: Bait()}, steps=25,
                  residual="none", centre="centroid")
    tr = simulate(sc)
    assert tr.metrics["diameter"][-1] < 1e-2 * tr.metrics["diameter"][0]
    assert tr.max_validity == 0.0 and tr.info["centre"] == "centroid"


def test_centroid_needs_d_at_most_3():
    with pytest.raises(InputError, match="centre 'centroid'.*d <= 3"):
        Scenario(graph=circulant(12, 5), x0=np.zeros((12, 4)), F=1, centre="centroid")
