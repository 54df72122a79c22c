"""RMDO (Algorithm 2) with the same costs written four ways: atoms, CasADi, CVXPY and
plain callables — the runs agree.

Shows: :func:`rescon.cost` accepts an atom (:class:`rescon.optim.atoms.Quadratic`,
whose data let :func:`rescon.rmdo` compute X* exactly), a CasADi expression, a CVXPY
expression and a pair of callables (value, subgradient); :func:`rescon.rmdo` runs
Algorithm 2 on a 6-agent complete graph with one constant adversary (F = 1). Agent i
has f_i(x) = ‖x − c_i‖², so X* = {mean of the benign c_i}. Prints, for each way, the
X* rescon found (exactly for atoms, numerically otherwise), the
final distance to X* and the largest difference of final states to the atom run.
(With F = 1 the filter discards honest values too, so the agents settle near X*, not
on it, unless the costs are 2F-redundant: :func:`rescon.check_redundancy`.)

Run::

    python examples/rmdo_costs.py [--steps 300] [--fast]

``--fast`` (or ``RESCON_EXAMPLES_FAST=1``): 80 steps.
"""

from __future__ import annotations

import argparse
import json
import os
from collections.abc import Callable
from typing import Any

import networkx as nx
import numpy as np

import rescon
from rescon.consensus.adversaries import Constant
from rescon.optim.atoms import Quadratic

CENTRES = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 2.0], [2.0, 2.0], [1.0, 3.0], [0.0, 0.0]])
ADVERSARY = 5


def atom(c: np.ndarray) -> Any:
    """‖x − c‖² = ½(x − c)ᵀ(2I)(x − c) as a quadratic atom."""
    return Quadratic(2 * np.eye(2), c)


def casadi_cost(c: np.ndarray) -> Any:
    """‖x − c‖² as a CasADi SX expression in the 2-vector symbol x."""
    import casadi as ca

    x = ca.SX.sym("x", 2)
    return rescon.cost(ca.sumsqr(x - ca.DM(c)), x=x)


def cvxpy_cost(c: np.ndarray) -> Any:
    """‖x − c‖² as a CVXPY expression in the Variable x."""
    import cvxpy as cp

    x = cp.Variable(2)
    return rescon.cost(cp.sum_squares(x - c), x=x)


def callable_cost(c: np.ndarray) -> Any:
    """‖x − c‖² and its gradient 2(x − c) as plain Python callables."""
    return (lambda x: float(np.sum((np.asarray(x) - c) ** 2)),
            lambda x: 2.0 * (np.asarray(x) - c))


WAYS: dict[str, Callable[[np.ndarray], Any]] = {
    "atoms": atom, "casadi": casadi_cost, "cvxpy": cvxpy_cost, "callables": callable_cost,
}


def main() -> None:
    """Run Algorithm 2 once per way of writing the costs; print the comparison."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--fast", action="store_true",
                    default=bool(os.environ.get("RESCON_EXAMPLES_FAST")))
    args = ap.parse_args()
    steps = 80 if args.fast else args.steps
    G = nx.complete_graph(len(CENTRES))
    benign = [i for i in G if i != ADVERSARY]
    x_star = CENTRES[benign].mean(axis=0)
    sc = rescon.Scenario(graph=G, x0=CENTRES, F=1, steps=steps,
                         adversaries={ADVERSARY: Constant([40.0, -40.0])},
                         check_robustness=False)
    finals: dict[str, np.ndarray] = {}
    result: dict[str, Any] = {"x_star": x_star.tolist(), "steps": steps}
    for name, make in WAYS.items():
        tr = rescon.rmdo(sc, {i: make(CENTRES[i]) for i in benign}, progress=False)
        finals[name] = tr.states[-1][tr.benign]
        dist = float(tr.metrics["distance_to_optimum"][-1])
        diff = float(np.abs(finals[name] - finals["atoms"]).max())
        found = tr.info["optimum"]
        print(f"{name:>9}: X* = {found['point']} ({found['method']}), distance to X* "
              f"{dist:.3g}, max |state - atoms state| {diff:.2g}")
        result[name] = {"optimum": found["point"], "optimum_method": found["method"],
                        "distance_to_optimum": dist, "max_difference_to_atoms": diff}
    print(json.dumps(result))


if __name__ == "__main__":
    main()
