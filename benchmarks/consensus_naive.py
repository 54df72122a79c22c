"""The obvious implementation of Algorithm 1, as a reference and a baseline.

A per-agent Python loop that, for every kernel Ψ(Y, F), builds a fresh CVXPY problem
with one set of convex weights per subset S ⊆ Y of size |Y| − F (the subset QP):

    minimise ‖x − mean(Y)‖²  s.t.  x = Σ_{i∈S} λ_{S,i} y_i, λ_S ≥ 0, Σ λ_S = 1  ∀ S,

which is the "project" kernel point of rescon. Only the hold-last policy and
adversaries given as functions of time (the paper's example) are supported.
"""

from __future__ import annotations

import itertools

import numpy as np


def kernel_point_cvxpy(Y: np.ndarray, F: int) -> np.ndarray:
    """argmin ‖x − mean(Y)‖² over Ψ(Y, F) by the subset QP (CVXPY, Clarabel)."""
    import cvxpy as cp

    n, d = Y.shape
    x = cp.Variable(d)
    cons = []
    for S in itertools.combinations(range(n), n - F):
        lam = cp.Variable(len(S), nonneg=True)
        cons += [cp.sum(lam) == 1, Y[list(S)].T @ lam == x]
    prob = cp.Problem(cp.Minimize(cp.sum_squares(x - Y.mean(axis=0))), cons)
    prob.solve(solver=cp.CLARABEL, tol_gap_abs=1e-10, tol_gap_rel=1e-10, tol_feas=1e-10)
    return np.asarray(x.value, dtype=float)


def simulate_naive(sc) -> np.ndarray:
    """States (K+1, N, d) of Algorithm 1 for a Scenario ``sc`` (policy "hold",
    centre as in ``sc``), one agent and one CVXPY problem at a time."""
    return run_naive(sc, lambda i, k, t, z: z + sc.residual(t))


def run_naive(sc, update) -> np.ndarray:
    """The naive loop with its update rule: agent i (a node label) at step k, time t
    moves to ``update(i, k, t, z)``, z = α x_i + (1 − α) x̃_i (Algorithm 1: z + ε(t);
    Algorithm 2: z − β_k d_i, d_i ∈ ∂f_i(z))."""
    from rescon.consensus.dos import blocked_links

    nodes = sc.nodes
    pos = {v: k for k, v in enumerate(nodes)}
    d, F = sc.d, sc.F
    m = (d + 1) * F + 1
    x = np.array(sc.x0, dtype=float)
    last: dict[tuple, np.ndarray] = {}
    out = [x.copy()]
    for k in range(sc.steps):
        t = k * sc.T
        blocked = blocked_links(sc.dos, t)
        new = x.copy()
        for i in nodes:
            if i in sc.adversaries:
                continue
            X = []
            for j in sorted(sc.graph.predecessors(i), key=pos.get):
                if j in sc.adversaries:
                    v = np.asarray(sc.adversaries[j].f(t), dtype=float)
                else:
                    v = x[pos[j]]
                if (i, j) in blocked:
                    if (i, j) in last:
                        X.append(last[(i, j)])
                    continue
                if np.isfinite(v).all():
                    last[(i, j)] = v
                    X.append(v)
            X = np.array(X)
            xi = x[pos[i]]
            if len(X) < m:
                continue
            pts = []
            for p in range(d):
                order = np.argsort(X[:, p], kind="stable")
                pts.append(kernel_point_cvxpy(X[order[:m]], F))
                pts.append(kernel_point_cvxpy(X[order[-m:]], F))
            L = np.array(pts)
            aux = (L.min(axis=0) + L.max(axis=0)) / 2 if sc.centre == "box" else L.mean(axis=0)
            a = sc.alpha[pos[i]]
            new[pos[i]] = update(i, k, t, a * xi + (1 - a) * aux)
        for a_node, beh in sc.adversaries.items():
            new[pos[a_node]] = np.asarray(beh.f((k + 1) * sc.T), dtype=float)
        x = new
        out.append(x.copy())
    return np.array(out)
