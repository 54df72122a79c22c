"""Algorithm 1 (resilient multi-dimensional consensus) and baselines, vectorised.

One step k (t_k = k T), for every benign agent i (SPEC §3):

1. received values: over the links (i, j), j ∈ N_i^in, j's state (a benign sender) or
   its message to i (an adversary); a link under DoS delivers, by ``policy``, the last
   value received before the attack ("hold"), the zero vector ("zero") or nothing
   ("drop"). A non-finite message is treated as missing and never stored;
2. Algorithm 1: m = (d+1)F+1; for each coordinate p the m smallest (Y) and m largest
   (Z) values by coordinate p (ties by sender order), y_p ∈ Ψ(Y, F), z_p ∈ Ψ(Z, F),
   Λ = {y_1..y_d, z_1..z_d}, x̃_i = Cen(Λ) by ``centre`` (:func:`_centre`): "mean"
   (default, the vertex mean) and "centroid" (the centroid of conv Λ, the paper's
   definition) lie in conv Λ, as the δ-validity proof needs; "box" ((min + max)/2 per
   coordinate, what the agreement proof computes) may leave conv Λ and, with it, the
   benign hull. With fewer than m usable values the agent holds its state this step
   (counted in ``starved``);
3. x_i ← α_i x_i + (1 − α_i) x̃_i + ε(t_k)·1.

Links are kept as flat arrays (receiver, sender) sorted by receiver, so gathering,
DoS masks and the hold-last memory are array operations; the kernel points of a step
are computed together (:func:`_kernel_points`).
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from ..errors import InputError
from ..geometry.centroid import hull_centroid
from ..geometry.kernel import safe_kernel
from .adversaries import StepView, adversary_messages
from .dos import blocked_mask
from .metrics import ValidityMonitor, diameter, spread
from .scenario import Scenario
from .trajectory import Trajectory

__all__ = ["simulate"]


class _Links:
    """All links (receiver i ← sender j) as arrays, sorted by receiver."""

    def __init__(self, sc: Scenario) -> None:
        nodes = sc.nodes
        pos = {v: k for k, v in enumerate(nodes)}
        pairs = sorted((pos[i], pos[j]) for j, i in sc.graph.edges if i != j)
        self.recv = np.array([p[0] for p in pairs], dtype=np.int64)
        self.send = np.array([p[1] for p in pairs], dtype=np.int64)
        self.index = {(nodes[i], nodes[j]): k for k, (i, j) in enumerate(pairs)}
        n = len(nodes)
        self.start = np.searchsorted(self.recv, np.arange(n + 1))
        self.in_nbrs = [self.send[self.start[i]:self.start[i + 1]] for i in range(n)]


def simulate(scenario: Scenario, *, progress: bool | None = None) -> Trajectory:
    """Run the scenario; see the module docstring for one step.

    Returns
    -------
    Trajectory (states, metrics per step, the violated assumptions in ``info``).
    """
    t0 = time.perf_counter()
    sc = scenario
    problems = sc.warn()
    nodes = sc.nodes
    n, d, K = len(nodes), sc.d, sc.steps
    links = _Links(sc)
    adv_idx = {nodes.index(a): beh for a, beh in sc.adversaries.items()}
    benign_mask = np.ones(n, dtype=bool)
    benign_mask[list(adv_idx)] = False
    benign = np.flatnonzero(benign_mask)
    rng = np.random.default_rng(sc.seed)
    x = np.array(sc.x0, dtype=np.float64)
    last = np.zeros((len(links.recv), d))
    has_last = np.zeros(len(links.recv), dtype=bool)
    states = np.empty((K + 1, n, d))
    monitor = ValidityMonitor(sc.x0[benign])
    metrics = {"spread": np.empty((K + 1, d)), "diameter": np.empty(K + 1),
               "validity": np.empty(K + 1), "validity_per_agent": np.empty((K + 1, len(benign))),
               "blocked_links": np.zeros(K + 1, dtype=np.int64),
               "starved": np.zeros(K + 1, dtype=np.int64)}
    exact_cache: dict = {}
    bar = _bar(progress, K)
    for k in range(K + 1):
        t = k * sc.T
        values, usable, sent = _receive(sc, links, x, adv_idx, benign_mask, k, t, rng,
                                        last, has_last, metrics, d)
        states[k] = x
        for a, msg in sent.items():
            states[k, a] = msg
        xb = x[benign]
        metrics["spread"][k] = spread(xb)
        metrics["diameter"][k] = diameter(xb)
        dist = monitor.distances(xb)
        metrics["validity_per_agent"][k] = dist
        metrics["validity"][k] = dist.max()
        if k == K:
            break
        aux, starved = _auxiliary(sc, links, x, values, usable, benign, d, exact_cache)
        metrics["starved"][k] = len(starved)
        alpha = sc.alpha[benign][:, None]
        new = alpha * x[benign] + (1 - alpha) * aux + sc.residual(t)
        if starved:
            new[starved] = x[benign][starved]
        x = x.copy()
        x[benign] = new
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()
    info = {"algorithm": sc.algorithm, "policy": sc.policy, "centre": sc.centre, "F": sc.F,
            "T": sc.T, "steps": K, "kernel_point": sc.kernel_point, "seed": sc.seed,
            "assumptions_violated": problems}
    return Trajectory(np.arange(K + 1) * sc.T, states, tuple(nodes), benign, metrics, info,
                      time.perf_counter() - t0)


def _receive(sc, links, x, adv_idx, benign_mask, k, t, rng, last, has_last, metrics, d):
    """Values on every link at step k and which are usable; updates the hold memory.
    Returns (values (L, d), usable (L,), what each adversary sent (for the record))."""
    values = x[links.send].copy()
    sent: dict[int, np.ndarray] = {}
    if adv_idx:
        view = StepView(k=k, t=t, states=x, benign=benign_mask, in_neighbours=links.in_nbrs,
                        rng=rng)
        for a in sorted(adv_idx):  # a fixed order: random draws do not depend on dicts
            rows = np.flatnonzero(links.send == a)
            if not len(rows):
                continue
            try:  # one (len(rows), d) array: never broadcast to every receiver
                msgs = adversary_messages({a: adv_idx[a]}, {a: links.recv[rows]}, view)[a]
            except InputError as exc:
                raise InputError(f"adversary {sc.nodes[a]!r}: {exc}") from None
            values[rows] = msgs
            finite = msgs[np.isfinite(msgs).all(axis=1)]
            sent[a] = finite.mean(axis=0) if len(finite) else np.full(d, np.nan)
    finite = np.isfinite(values).all(axis=1)
    blocked = blocked_mask(sc.dos, links.index, t) if sc.dos else np.zeros(len(values), bool)
    metrics["blocked_links"][k] = int(blocked.sum())
    delivered = finite & ~blocked
    usable = delivered.copy()
    if sc.policy == "hold":
        values[blocked] = last[blocked]
        usable |= blocked & has_last
    elif sc.policy == "zero":
        values[blocked] = 0.0
        usable |= blocked
    last[delivered] = values[delivered]
    has_last |= delivered
    values[~usable] = np.nan
    return values, usable, sent


def _auxiliary(sc, links, x, values, usable, benign, d, cache):
    """x̃_i for every benign agent (rows in ``benign`` order) and the rows (positions in
    ``benign``) that must hold their state."""
    m = (d + 1) * sc.F + 1
    aux = np.empty((len(benign), d))
    starved: list[int] = []
    problems: list[np.ndarray] = []
    where: list[tuple[int, int, int]] = []  # (row, p, 0 = y / 1 = z)
    for r, i in enumerate(benign):
        sl = slice(links.start[i], links.start[i + 1])
        X = values[sl][usable[sl]]
        if sc.algorithm in ("alg1", "kernel") and len(X) < m:
            starved.append(r)
            aux[r] = x[i]
            continue
        if sc.algorithm == "alg1":
            for p in range(d):
                order = np.argsort(X[:, p], kind="stable")
                problems.append(X[order[:m]])
                where.append((r, p, 0))
                problems.append(X[order[-m:]])
                where.append((r, p, 1))
        elif sc.algorithm == "kernel":
            problems.append(X)
            where.append((r, 0, 0))
        elif sc.algorithm == "wmsr":
            aux[r] = _wmsr(x[i], X, sc.F)
        else:
            aux[r] = np.vstack([X, x[i]]).mean(axis=0) if len(X) else x[i]
    points = _kernel_points(problems, sc.F, sc.kernel_point, cache)
    if sc.algorithm == "kernel":
        for (r, _, _), pt in zip(where, points, strict=True):
            aux[r] = pt
    elif sc.algorithm == "alg1" and points:
        rows = [r for r, _, _ in where[::2 * d]]  # each row has its 2d points in turn
        aux[rows] = _centre(np.reshape(points, (len(rows), 2 * d, d)), sc.centre)
    return aux, starved


def _centre(lam: np.ndarray, centre: str) -> np.ndarray:
    """Cen(Λ) for every agent: ``lam`` (R, 2d, d) holds one Λ per row.

    "box": (min + max)/2 per coordinate (the paper's agreement proof; may leave
    conv Λ); "mean": the vertex mean (1/2d) Σ λ (a convex combination, in conv Λ);
    "centroid": the centroid of conv Λ (the paper's definition; exact, per agent,
    :func:`rescon.geometry.centroid.hull_centroid`)."""
    if centre == "box":
        return (lam.min(axis=1) + lam.max(axis=1)) / 2
    if centre == "mean":
        return lam.mean(axis=1)
    return np.array([hull_centroid(L) for L in lam])


#: largest point sets the batch paths take, by dimension (they hold m(m−1) lines,
#: m(m−1)(m−2)/3 planes per set)
SMALL_BATCH_MAX = {2: 64, 3: 24}


def _kernel_points(problems: list[np.ndarray], F: int, method: str,
                   cache: dict) -> list[np.ndarray]:
    """A point of Ψ(X, F) for every X (Ψ is nonempty for |X| ≥ (d+1)F+1).

    "project" in the plane goes through the numba batch path
    (:mod:`rescon.geometry._small2d`: exact decisions, float geometry, certified error
    bound), in space through :mod:`rescon.geometry._small3d` (exact halfspaces, a float
    QP, a KKT certificate with rigorous rounding bounds); a batch point is used only if
    its certified error bound is at most ACCEPT_REL of its own magnitude, so no far
    value in the set can loosen it. The sets they decline and every other case are
    computed exactly, once per distinct set in a run (``cache``: held values and
    converged states repeat the same sets). "project-exact" computes everything
    exactly."""
    from ..geometry._small2d import ACCEPT_REL, OK, project_small_2d
    from ..geometry._small3d import project_small_3d

    out: list[np.ndarray | None] = [None] * len(problems)
    if method == "project":
        groups: dict[tuple[int, int], list[int]] = {}
        for k, X in enumerate(problems):
            if len(X) <= SMALL_BATCH_MAX.get(X.shape[1], 0):
                groups.setdefault(X.shape, []).append(k)
        for (_, d), idx in groups.items():
            Ys = np.ascontiguousarray(np.stack([problems[k] for k in idx]), dtype=np.float64)
            if d == 2:
                pts = np.empty((len(idx), 2))
                err = np.empty(len(idx))
                status = np.empty(len(idx), dtype=np.int64)
                project_small_2d(Ys, F, pts, err, status)
                found = (status == OK) & (err <= ACCEPT_REL * np.abs(pts).max(axis=1))
            else:
                pts, _, found = project_small_3d(Ys, F)
            for k, p, ok in zip(idx, pts, found, strict=True):
                if ok:
                    out[k] = p
    exact = "project" if method == "project-exact" else method
    for k, X in enumerate(problems):
        if out[k] is None:
            key = (X.shape, X[np.lexsort(X.T[::-1])].tobytes())  # Ψ ignores the order
            if key not in cache:
                cache[key] = safe_kernel(X, F).point(exact)[0]
            out[k] = cache[key]
    return out


def _wmsr(own: np.ndarray, X: np.ndarray, F: int) -> np.ndarray:
    """Coordinate-wise W-MSR: per coordinate, drop the F largest received values above
    the own value and the F smallest below it (fewer if there are fewer), average the
    rest with the own value."""
    out = np.empty_like(own)
    for p in range(len(own)):
        v = np.sort(X[:, p])
        above = v[v > own[p]]
        below = v[v < own[p]]
        equal = v[v == own[p]]
        keep = np.concatenate([below[min(F, len(below)):], equal,
                               above[:len(above) - min(F, len(above))], [own[p]]])
        out[p] = keep.mean()
    return out


def _bar(progress: bool | None, total: int) -> Any:
    import sys

    if progress is None:
        progress = sys.stderr.isatty()
    if not progress:
        return None
    from tqdm import tqdm

    return tqdm(total=total, desc="simulate", unit="step", leave=False)
