"""Consensus of robots on a random geometric network with two-faced Byzantine agents
and random DoS.

Shows: a networkx ``random_geometric_graph`` (robots within radius ρ talk both ways),
grown until it is ((d+1)F+1)-robust (:func:`rescon.is_r_robust`, exact), two
two-faced adversaries (:class:`rescon.consensus.adversaries.TwoFaced` with a callable,
:class:`~rescon.consensus.adversaries.TwoFacedTable` with a cycle of values), random
DoS on a few links (:class:`rescon.consensus.dos.RandomDoS`), and Algorithm 1
(:func:`rescon.simulate`). Violated assumptions (e.g. the F-local model when both
adversaries reach one robot) come as :class:`rescon.ScenarioWarning` and are printed.
Prints the final benign diameter and the maximal distance to the benign initial hull
(no residual ε here, so it is 0 when the assumptions hold).

Run::

    python examples/robot_network.py [--n 20] [--steps 60] [--seed 0] [--out DIR] [--fast]

``--fast`` (or ``RESCON_EXAMPLES_FAST=1``): 16 robots, 30 steps.
"""

from __future__ import annotations

import argparse
import json
import os
import warnings
from pathlib import Path

import networkx as nx
import numpy as np

import rescon
from rescon.consensus.adversaries import TwoFaced, TwoFacedTable
from rescon.consensus.dos import DoSAttack, RandomDoS

D, F = 2, 1


def robust_geometric_graph(n: int, seed: int) -> tuple[nx.Graph, float]:
    """The first radius 0.3, 0.35, … at which the random geometric graph on n points of
    [0, 1]² (fixed positions) is ((d+1)F+1)-robust, and that graph."""
    radius = 0.3
    while True:
        G = nx.random_geometric_graph(n, radius, seed=seed)
        if radius >= 1.5 or rescon.is_r_robust(G, (D + 1) * F + 1).holds:
            return G, radius
        radius += 0.05


def second_adversary(G: nx.Graph, first: int) -> int:
    """The robot farthest from ``first`` that shares no neighbour with it (so every
    benign robot hears at most F = 1 adversary: the F-local model), else the farthest
    robot (the scenario then warns that the model is violated)."""
    pos = nx.get_node_attributes(G, "pos")
    order = sorted((v for v in G if v != first),
                   key=lambda v: -float(np.hypot(*np.subtract(pos[v], pos[first]))))
    apart = [v for v in order if v not in G[first] and not set(G[v]) & set(G[first])]
    return (apart or order)[0]


def main() -> None:
    """Build the network, run Algorithm 1, print the warnings and one JSON line."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20, help="number of robots")
    ap.add_argument("--steps", type=int, default=60, help="number of updates")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default="out/robot_network", help="output directory (plot)")
    ap.add_argument("--fast", action="store_true",
                    default=bool(os.environ.get("RESCON_EXAMPLES_FAST")))
    args = ap.parse_args()
    n, steps = (16, 30) if args.fast else (args.n, args.steps)
    G, radius = robust_geometric_graph(n, args.seed)
    pos = nx.get_node_attributes(G, "pos")
    x0 = {v: 10.0 * np.asarray(pos[v]) for v in G}
    liar, table_liar = 0, second_adversary(G, 0)
    adversaries = {
        liar: TwoFaced(lambda t, r: np.array([50.0 * (-1) ** r, 5.0 * t])),
        table_liar: TwoFaced(TwoFacedTable(cycle=[[-30.0, 0.0], [30.0, 30.0]])),
    }
    rng = np.random.default_rng(args.seed)
    edges = [(i, j) for i, j in G.edges if liar not in (i, j) and table_liar not in (i, j)]
    links = [edges[k] for k in rng.choice(len(edges), size=min(3, len(edges)), replace=False)]
    dos = (DoSAttack("random", links, RandomDoS(rate=0.3, mean_duration=1.0, seed=args.seed)),)
    sc = rescon.Scenario(graph=G, x0=x0, F=F, adversaries=adversaries, dos=dos,
                         steps=steps, policy="hold", residual="none", seed=args.seed)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", rescon.ScenarioWarning)
        tr = rescon.simulate(sc, progress=False)
    problems = [str(w.message) for w in caught if issubclass(w.category, rescon.ScenarioWarning)]
    for p in problems:
        print(f"warning: {p}")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    tr.plot(out / "robot_network.png")
    print(f"{n} robots, radius {radius:.2f}, adversaries {liar} and {table_liar}, "
          f"DoS on {links}: final diameter {tr.final_diameter:.3g}, "
          f"max validity {tr.max_validity:.3g}")
    print(json.dumps({
        "n": n, "radius": round(radius, 2), "steps": steps,
        "adversaries": [liar, table_liar], "dos_links": [list(map(int, e)) for e in links],
        "final_diameter": tr.final_diameter, "max_validity": tr.max_validity,
        "warnings": problems, "plot": str(out / "robot_network.png"),
    }))


if __name__ == "__main__":
    main()
