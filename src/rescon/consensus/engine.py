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
3. the update rule on z_i = α_i x_i + (1 − α_i) x̃_i (:func:`_between`: between x_i and
   x̃_i in floats, x_i itself when x̃_i = x_i): Algorithm 1's x_i ← z_i + ε(t_k)·1
   (:class:`ConvexStep`, what :func:`simulate` runs); Algorithm 2's subgradient step
   x_i ← z_i − β_k d_i, d_i ∈ ∂f_i(z_i), lives in :mod:`rescon.optim.rmdo` and is
   passed to the same loop (:func:`run`), as are the per-step monitors (consensus
   metrics here, RMDO's cost metrics there): ``consensus`` never imports ``optim``.

Links are kept as flat arrays (receiver, sender) sorted by receiver, so gathering,
DoS masks and the hold-last memory are array operations; the kernel points of a step
are computed together (:func:`_kernel_points`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from fractions import Fraction
from typing import Any, Protocol

import numpy as np

from .._rounding import MIN_SUBNORMAL
from ..errors import InputError
from ..geometry._planar_exact import nearest_to_mean
from ..geometry.centroid import hull_centroid
from ..geometry.kernel import safe_kernel
from ..geometry.points import exact_point
from .adversaries import StepView, adversary_messages
from .dos import blocked_mask
from .metrics import ValidityMonitor, diameter, monitor_names, spread
from .scenario import STATE_LIMIT, Scenario
from .trajectory import Trajectory

__all__ = ["ConsensusMonitor", "ConvexStep", "Monitor", "UpdateRule", "run", "simulate"]


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


def simulate(scenario: Scenario, *, metrics: Sequence[str] | str | None = None,
             progress: bool | None = None) -> Trajectory:
    """Run the scenario (Algorithm 1 or a baseline); see the module docstring for one step.

    Parameters
    ----------
    metrics : the monitors to run, names from :data:`rescon.consensus.metrics.MONITORS`
        ("spread", "diameter", "validity"; default: every one), as a list or as one
        string of comma-separated names (``"validity,spread"``, as the CLI's
        ``--metrics``). ``blocked_links`` and ``starved`` are always recorded.

    Returns
    -------
    Trajectory (states, metrics per step, the violated assumptions in ``info``).

    Raises
    ------
    InputError
        ``scenario`` is not a :class:`Scenario`; ``progress`` is not True, False or
        None; a metric passing the float range (:meth:`ConsensusMonitor.record`: benign
        states dragged apart to ±1e308 by adversaries, with F = 0 or the "mean"
        baseline). States themselves stay finite at every magnitude.
    """
    t0 = time.perf_counter()
    if not isinstance(scenario, Scenario):
        raise InputError(f"scenario must be a rescon.Scenario; got {type(scenario).__name__}")
    monitor = ConsensusMonitor(scenario, metrics)
    problems = scenario.warn()
    return run(scenario, ConvexStep(scenario.residual), monitors=[monitor],
               progress=progress, started=t0, info={"assumptions_violated": problems})


class UpdateRule(Protocol):
    """Step 3 of an algorithm: the new states of the benign agents that move at step k
    from z = α x + (1 − α) x̃ (rows of ``z``, (R, d)); ``agents`` (R,) are their row
    indices in the scenario's node order. ``name`` labels the run."""

    name: str

    def __call__(self, k: int, t: float, z: np.ndarray, agents: np.ndarray) -> np.ndarray: ...


class Monitor(Protocol):
    """Per-step metrics: ``metrics`` maps names to arrays whose first axis is the step
    k = 0..K; ``record`` fills row k from the benign states (|B|, d) at t_k."""

    metrics: dict[str, np.ndarray]

    def record(self, k: int, t: float, xb: np.ndarray) -> None: ...


class ConvexStep:
    """Algorithm 1's update x ← z + ε(t_k)·1, z = α x + (1 − α) x̃ (the residual
    ``residual`` is the scenario's t ↦ ε(t))."""

    name = "simulate"

    def __init__(self, residual: Callable[[float], float]) -> None:
        self.residual = residual

    def __call__(self, k: int, t: float, z: np.ndarray, agents: np.ndarray) -> np.ndarray:
        """z + ε(t)·1; InputError when ε(t) is not a finite real (a user's callable
        returning NaN, inf or an array) or the sum passes the float range."""
        eps = self.residual(t)
        if (isinstance(eps, bool) or not isinstance(eps, (int, float, np.integer, np.floating))
                or not np.isfinite(eps)):
            raise InputError(f"the residual ε(t) at t = {t:g} is {eps!r}: it must be a "
                             f"finite real number")
        out = z + eps
        if not np.isfinite(out).all():
            raise InputError(f"the states at step {k} (t = {t:g}) pass the float range after "
                             f"adding the residual ε(t) = {eps:g}: they diverged")
        return out


class ConsensusMonitor:
    """``spread`` (K+1, d), ``diameter`` (K+1,), ``validity`` (K+1,) and
    ``validity_per_agent`` (K+1, |B|) of the benign states (:mod:`.metrics`), or those
    of the ``metrics`` named (:func:`~rescon.consensus.metrics.monitor_names`)."""

    def __init__(self, scenario: Scenario, metrics: Sequence[str] | None = None) -> None:
        self.names = monitor_names(metrics)
        benign = _benign_rows(scenario)
        K, d = scenario.steps, scenario.d
        shapes = {"spread": [("spread", (K + 1, d))], "diameter": [("diameter", K + 1)],
                  "validity": [("validity", K + 1),
                               ("validity_per_agent", (K + 1, len(benign)))]}
        self.metrics = {key: np.empty(shape) for name in self.names
                        for key, shape in shapes[name]}
        self.validity = (ValidityMonitor(scenario.x0[benign]) if "validity" in self.names
                         else None)

    def record(self, k: int, t: float, xb: np.ndarray) -> None:
        """Row k of each metric; InputError when one passes the float range (benign
        states stay finite — means and convex combinations of finite values, plus
        ε ≤ 1 — but a rule that follows the adversaries, F = 0 or the "mean" baseline,
        can be dragged to ±1e308, where a distance between them overflows)."""
        m = self.metrics
        if "spread" in m:
            m["spread"][k] = spread(xb)
        if "diameter" in m:
            m["diameter"][k] = diameter(xb)
        if self.validity is not None:
            dist = self.validity.distances(xb)
            m["validity_per_agent"][k] = dist
            m["validity"][k] = dist.max()
        over = [key for key, v in m.items() if not np.isfinite(v[k]).all()]
        if over:
            raise InputError(f"the benign states at step {k} (t = {t:g}) are too far apart "
                             f"for floats ({over[0]} > 1.8e308; max |x| = "
                             f"{float(np.abs(xb).max()):.3g}): the states diverged — "
                             f"adversary values this large drag a rule without filtering "
                             f"(F = 0, the 'mean' baseline) along; keep them within "
                             f"{STATE_LIMIT:g}, the bound on initial states")


def _benign_rows(sc: Scenario) -> np.ndarray:
    """Row indices (node order) of the benign agents."""
    return np.array([r for r, v in enumerate(sc.nodes) if v not in sc.adversaries],
                    dtype=np.int64)


def run(scenario: Scenario, rule: UpdateRule, *, monitors: Sequence[Monitor] | None = None,
        progress: bool | None = None, info: dict[str, Any] | None = None,
        started: float | None = None) -> Trajectory:
    """The one loop behind :func:`simulate` and :func:`rescon.rmdo`: receive (adversary
    messages, DoS, policy), filter (the scenario's ``algorithm``: x̃_i, or hold when
    starved), then x_i ← ``rule(k, t_k, α x_i + (1 − α) x̃_i, i)`` for the agents that
    move, and every monitor records the benign states at every t_k.

    Parameters
    ----------
    monitors : per-step metrics (default: :class:`ConsensusMonitor` of the scenario);
        their arrays come first in ``Trajectory.metrics``, then ``blocked_links`` and
        ``starved``.
    info : entries added to the trajectory's ``info``.
    started : ``time.perf_counter()`` at which the caller's work began (for
        ``Trajectory.seconds``).
    """
    t0 = time.perf_counter() if started is None else started
    sc = scenario
    nodes = sc.nodes
    n, d, K = len(nodes), sc.d, sc.steps
    links = _Links(sc)
    adv_idx = {nodes.index(a): beh for a, beh in sc.adversaries.items()}
    benign = _benign_rows(sc)
    benign_mask = np.zeros(n, dtype=bool)
    benign_mask[benign] = True
    rng = np.random.default_rng(sc.seed)
    x = np.array(sc.x0, dtype=np.float64)
    last = np.zeros((len(links.recv), d))
    has_last = np.zeros(len(links.recv), dtype=bool)
    states = np.empty((K + 1, n, d))
    adv_rows = np.setdiff1d(np.arange(n), benign)
    sent_range = np.full((K + 1, len(adv_rows), 2, d), np.nan)
    monitors = [ConsensusMonitor(sc)] if monitors is None else list(monitors)
    metrics: dict[str, np.ndarray] = {}
    for mon in monitors:
        metrics.update(mon.metrics)
    metrics.update({"blocked_links": np.zeros(K + 1, dtype=np.int64),
                    "starved": np.zeros(K + 1, dtype=np.int64)})
    alpha = sc.alpha[benign][:, None]
    exact_cache: dict = {}
    bar = _bar(progress, K, rule.name)
    for k in range(K + 1):
        t = k * sc.T
        values, usable, sent = _receive(sc, links, x, adv_idx, benign_mask, k, t, rng,
                                        last, has_last, metrics, d)
        states[k] = x
        for a, msg in sent.items():
            states[k, a] = msg[0]
            sent_range[k, np.searchsorted(adv_rows, a)] = msg[1:]
        xb = x[benign]
        for mon in monitors:
            mon.record(k, t, xb)
        if k == K:
            break
        aux, starved = _auxiliary(sc, links, x, values, usable, benign, d, exact_cache)
        metrics["starved"][k] = len(starved)
        moving = np.ones(len(benign), dtype=bool)
        moving[starved] = False  # starved agents hold their state
        z = _between(xb[moving], aux[moving], alpha[moving])
        x = x.copy()
        if moving.any():
            x[benign[moving]] = rule(k, t, z, benign[moving])
        if bar is not None:
            bar.update(1)
    if bar is not None:
        bar.close()
    base = {"algorithm": sc.algorithm, "policy": sc.policy, "centre": sc.centre, "F": sc.F,
            "T": sc.T, "steps": K, "kernel_point": sc.kernel_point, "seed": sc.seed}
    return Trajectory(np.arange(K + 1) * sc.T, states, tuple(nodes), benign, metrics,
                      {**base, **(info or {})}, time.perf_counter() - t0, sent=sent_range)


def _between(x: np.ndarray, aux: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """z = α x + (1 − α) x̃ row by row (``alpha`` (R, 1), 0 < α < 1), computed so that
    every coordinate of z lies between those of x and x̃ at every magnitude, and z = x
    exactly where x̃ = x (converged states and states at X* stay put).

    With δ = fl(x̃ − x): z = fl(x + fl((1 − α)δ)) when α ≥ ½, z = fl(x̃ − fl(αδ)) when
    α < ½, and z = fl(fl(αx) + fl((1 − α)x̃)) where δ overflows. (The plain
    αx + (1 − α)x̃ rounds 0.5·5e-324 to 0: states at ±5e-324 drifted to 0.)

    Proof, per coordinate. Let a be the end z starts from (x, or x̃ when α < ½), b the
    other end and t ∈ [0, ½] the weight of b − a (1 − α, exact for α ≥ ½ by Sterbenz's
    lemma, or α); by symmetry (fl(−v) = −fl(v)) a ≤ b. Rounding is monotone, so
    δ = fl(b − a) ≥ 0 and s = fl(tδ) satisfy 0 ≤ s ≤ fl(δ/2). If δ ≥ 2^-1021, δ/2 is a
    float and δ/2 ≤ (1 + 2^-53)(b − a)/2 ≤ b − a; else b − a < 2^-1021 is a multiple
    of 2^-1074, hence a float, δ = b − a and fl(δ/2) ≤ δ. Either way a ≤ a + s ≤ b, so
    a ≤ fl(a + s) ≤ b (a, b are floats). No overflow: |b − a| ≤ max(|a|, |b|) unless
    a < 0 < b, and the last form is used only there, where fl(αx) and fl((1 − α)x̃)
    lie between 0 and x, x̃ respectively, have opposite signs, and their rounded sum
    lies between them. Where x̃ = x, δ = 0 and z = x + 0 or x̃ − 0 = x."""
    with np.errstate(over="ignore"):  # δ = ±inf is replaced below
        step = aux - x
        z = np.where(alpha >= 0.5, x + (1 - alpha) * step, aux - alpha * step)
    far = np.nonzero(~np.isfinite(step))
    if far[0].size:
        a = alpha[far[0], 0]
        z[far] = a * x[far] + (1 - a) * aux[far]
    return z


def _receive(sc, links, x, adv_idx, benign_mask, k, t, rng, last, has_last, metrics, d):
    """Values on every link at step k and which are usable; updates the hold memory.
    Returns (values (L, d), usable (L,), what each adversary sent (for the record):
    the mean, per-coordinate min and max of its finite messages, a (3, d) array)."""
    values = x[links.send].copy()
    sent: dict[int, np.ndarray] = {}
    if adv_idx:
        view = StepView(k=k, t=t, states=x, benign=benign_mask, in_neighbours=links.in_nbrs,
                        rng=rng)
        for a in sorted(adv_idx):  # a fixed order: random draws do not depend on dicts
            rows = np.flatnonzero(links.send == a)
            if not len(rows):  # no receiver: it sent nothing (NaN, not its x0 held)
                sent[a] = np.full((3, d), np.nan)
                continue
            try:  # one (len(rows), d) array: never broadcast to every receiver
                msgs = adversary_messages({a: adv_idx[a]}, {a: links.recv[rows]}, view)[a]
            except InputError as exc:
                raise InputError(f"adversary {sc.nodes[a]!r}: {exc}") from None
            values[rows] = msgs
            finite = msgs[np.isfinite(msgs).all(axis=1)]
            sent[a] = (np.vstack([_scaled_mean(finite), finite.min(axis=0),
                                  finite.max(axis=0)]) if len(finite) else np.full((3, d), np.nan))
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


def _scaled_mean(a: np.ndarray, axis: int = 0) -> np.ndarray:
    """Mean of a finite array along ``axis`` without overflow: each slice is divided by
    its own power of two 2^e ≥ max |entry| (exact), averaged (|mean| ≤ 1), and scaled
    back — ``a.mean(axis)`` overflows to inf once the sum passes 1.8e308 — then held
    between the slice's smallest and largest entries: the rounded sum can pass them by
    an ulp (8 copies of one value averaged to its neighbour float, so converged states
    drifted out of their one-point hull), and the mean of equal entries is that entry."""
    top = np.abs(a).max(axis=axis, keepdims=True)
    e = np.frexp(np.where(top > 0.0, top, 1.0))[1]
    mean = np.ldexp(np.ldexp(a, -e).mean(axis=axis), np.squeeze(e, axis=axis))
    return np.clip(mean, a.min(axis=axis), a.max(axis=axis))


def _auxiliary(sc, links, x, values, usable, benign, d, cache):
    """x̃_i for every benign agent (rows in ``benign`` order) and the rows (positions in
    ``benign``) that must hold their state."""
    if sc.algorithm == "alg1":
        return _alg1_auxiliary(sc, links, x, values, usable, benign, d, cache)
    if sc.algorithm in ("wmsr", "mean"):
        return _baseline_auxiliary(sc, links, x, values, usable, benign, d), []
    m = (d + 1) * sc.F + 1
    aux = np.empty((len(benign), d))
    starved: list[int] = []
    problems: list[np.ndarray] = []
    where: list[tuple[int, int, int]] = []  # (row, p, 0 = y / 1 = z)
    for r, i in enumerate(benign):
        sl = slice(links.start[i], links.start[i + 1])
        X = values[sl][usable[sl]]
        if len(X) < m:
            starved.append(r)
            aux[r] = x[i]
            continue
        problems.append(X)
        where.append((r, 0, 0))
    points = _kernel_points(problems, sc.F, sc.kernel_point, cache)
    for (r, _, _), pt in zip(where, points, strict=True):
        aux[r] = pt
    return aux, starved


def _alg1_auxiliary(sc, links, x, values, usable, benign, d, cache):
    """:func:`_auxiliary` for Algorithm 1, one array operation per group of agents with
    the same number c of usable values: their values (R, c, d) are sorted per
    coordinate (stable: ties by sender order) and Y_p, Z_p are the first and last m
    rows in that order; the 2d kernel problems of an agent come in turn (p = 1..d, Y
    then Z)."""
    m = (d + 1) * sc.F + 1
    aux = np.empty((len(benign), d))
    starved: list[np.ndarray] = []
    problems: list[np.ndarray] = []
    moved: list[np.ndarray] = []
    for c, rows, idx in _usable_groups(links, usable, benign):
        if c < m:
            starved.append(rows)
            aux[rows] = x[benign[rows]]
            continue
        V = values[idx]  # (R, c, d)
        order = np.argsort(V, axis=1, kind="stable").transpose(0, 2, 1)  # (R, d, c)
        ends = np.concatenate([order[:, :, None, :m], order[:, :, None, -m:]], axis=2)
        picked = np.take_along_axis(V[:, None, None], ends[..., None], axis=3)
        problems.append(picked.reshape(-1, m, d))  # (R, d, 2, m, d): Y_p, Z_p in turn
        moved.append(rows)
    if moved:
        points = _kernel_points(np.concatenate(problems), sc.F, sc.kernel_point, cache)
        rows = np.concatenate(moved)
        aux[rows] = _centre(np.reshape(points, (len(rows), 2 * d, d)), sc.centre)
    return aux, np.sort(np.concatenate(starved)) if starved else starved


def _usable_groups(links, usable, benign):
    """(c, rows, idx) for each count c of usable received values among the benign
    agents: ``rows`` their positions in ``benign``, ``idx`` (len(rows), c) their usable
    links (in link order: by sender)."""
    ulinks = np.flatnonzero(usable)  # links are sorted by receiver
    count = np.bincount(links.recv[ulinks], minlength=len(links.start) - 1)
    first = np.concatenate([[0], np.cumsum(count)])
    per_agent = count[benign]
    for c in np.unique(per_agent):
        rows = np.flatnonzero(per_agent == c)
        yield int(c), rows, ulinks[first[benign[rows]][:, None] + np.arange(c)]


def _centre(lam: np.ndarray, centre: str) -> np.ndarray:
    """Cen(Λ) for every agent: ``lam`` (R, 2d, d) holds one Λ per row.

    "box": (min + max)/2 per coordinate (the paper's agreement proof; may leave
    conv Λ); "mean": the vertex mean (1/2d) Σ λ (a convex combination, in conv Λ);
    "centroid": the centroid of conv Λ (the paper's definition; exact, per agent,
    :func:`rescon.geometry.centroid.hull_centroid`)."""
    if centre == "box":
        return _scaled_mean(np.stack([lam.min(axis=1), lam.max(axis=1)]))
    if centre == "mean":
        return _scaled_mean(lam, axis=1)
    return np.array([hull_centroid(L) for L in lam])


#: largest point sets the batch paths take, by dimension (they hold m(m−1) lines,
#: m(m−1)(m−2)/3 planes per set)
SMALL_BATCH_MAX = {2: 64, 3: 24}
#: largest planar sets whose exact point :func:`_kernel_points` finds by the direct
#: planar construction (O(m³) orientations; beyond, generic sets are as fast through
#: the kernel)
PLANAR_EXACT_MAX = 32
#: ... except sets of more than PLANAR_EXACT_WIDE points whose nonzero coordinates span
#: more than PLANAR_EXACT_BITS binary orders of magnitude: the construction's integers
#: are that wide, and its orientations have no float filter (31 points at 1e300 and one
#: at 5e-324: ~2 070-bit integers, 0.15–0.2 s against 7–16 ms, V42)
PLANAR_EXACT_WIDE = 12
PLANAR_EXACT_BITS = 256


def _kernel_points(problems: list[np.ndarray] | np.ndarray, F: int, method: str,
                   cache: dict) -> np.ndarray:
    """A point of Ψ(X, F) for every X (Ψ is nonempty for |X| ≥ (d+1)F+1), as rows
    (P, d); ``problems`` is a list of sets or one array (P, m, d) of sets of one size.

    "project" in the plane goes through the numba batch path
    (:mod:`rescon.geometry._small2d`: exact decisions, float geometry, certified error
    bound), in space through :mod:`rescon.geometry._small3d` (exact halfspaces, a float
    QP, a KKT certificate with rigorous rounding bounds); a batch point is used only if
    its certified error bound is within :func:`_allowance` (ACCEPT_REL of its own
    magnitude and of the size of the box Ψ lies in), so neither a far value in the set
    nor a far origin can loosen it. Sets declined thus are tried once more moved next
    to the origin (:func:`_batch_points_moved`): converged states, whose Ψ is ulps of
    its magnitude wide, were all declined (their bounds are ulps of the magnitude),
    and computing each exactly made a step of 1000 converged agents take seconds.
    The sets still declined and every other case are
    computed exactly, once per distinct set in a run (``cache``: held values and
    converged states repeat the same sets) — the sets :func:`_planar_exact_point` takes
    by the exact planar construction (the same exact point, ~10× faster than building
    the kernel: converged states beside far adversary values leave the nearest feature
    to exact arithmetic), the others through the kernel. "project-exact" computes
    everything exactly."""
    if not len(problems):
        return np.empty((0, 0))
    out = np.empty((len(problems), problems[0].shape[1]))
    done = np.zeros(len(problems), dtype=bool)
    if method == "project":
        for (m, d), idx in _same_shape(problems).items():
            if m > SMALL_BATCH_MAX.get(d, 0):
                continue
            Ys = np.ascontiguousarray(problems[idx] if isinstance(problems, np.ndarray)
                                      else np.stack([problems[k] for k in idx]),
                                      dtype=np.float64)
            pts, err, found = _batch_points(Ys, F)
            found &= err <= _allowance(Ys, F, pts)
            rest = np.flatnonzero(~found)
            if len(rest):  # e.g. converged sets, Ψ a few ulps wide: moved next to 0
                moved, bound, ok = _batch_points_moved(Ys[rest], F)
                ok &= bound <= _allowance(Ys[rest], F, moved)
                pts[rest[ok]], found[rest[ok]] = moved[ok], True
            out[idx[found]] = pts[found]
            done[idx[found]] = True
    exact = "project" if method == "project-exact" else method
    for k in np.flatnonzero(~done):
        X = problems[k]
        key = (X.shape, X[np.lexsort(X.T[::-1])].tobytes())  # Ψ ignores the order
        if key not in cache:
            x = _planar_exact_point(X, F) if exact == "project" else None
            if x is None:
                x = exact_point(safe_kernel(X, F), method=exact)
            cache[key] = np.array([float(v) for v in x])
        out[k] = cache[key]
    return out


def _planar_exact_point(X: np.ndarray, F: int) -> list[Fraction] | None:
    """The exact point of Ψ(X, F) nearest the mean of X by the planar construction
    (:func:`rescon.geometry._planar_exact.nearest_to_mean`) for finite sets of at most
    PLANAR_EXACT_MAX points in the plane, or in space with a coordinate j the same in
    every point: X lies in the plane x_j = a, so Ψ(X, F) = {a} × Ψ(X', F) (X' the
    other coordinates; a halfspace meets the plane in a halfplane, and every halfplane
    is such a meet) and the mean is (a, mean X'), so the point sought is (a, the planar
    point of X') — converged states reach such sets, where the batch paths decline
    flat kernels. None otherwise — also for sets of more than PLANAR_EXACT_WIDE points
    whose planar coordinates span more than PLANAR_EXACT_BITS binary orders of
    magnitude — or when Ψ is empty: the general path decides."""
    m, d = X.shape
    if m > PLANAR_EXACT_MAX or d not in (2, 3) or not np.isfinite(X).all():
        return None
    fixed = [int(j) for j in np.flatnonzero((X == X[0]).all(axis=0))][:1] if d == 3 else []
    if d == 3 and not fixed:
        return None
    Y = np.ascontiguousarray(np.delete(X, fixed, axis=1))
    exponents = np.frexp(Y[Y != 0])[1]
    if len(exponents) and m > PLANAR_EXACT_WIDE and np.ptp(exponents) > PLANAR_EXACT_BITS:
        return None  # O(m³) orientations on integers that wide: the general path is faster
    x = nearest_to_mean(Y, F)
    if x is None:
        return None
    point = list(x)
    for j in fixed:  # the constant coordinate back in its place
        point.insert(j, Fraction(float(X[0, j])))
    return point


def _batch_points(Ys: np.ndarray, F: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The batch paths' points of Ψ(Y, F) nearest the mean of Y for sets Ys (B, m, d),
    d = 2 or 3: the points (B, d), bounds on their distances to the exact ones, and
    whether each is certified within ACCEPT_REL of its magnitude.

    A set in space that the 3-d path declines with one coordinate j the same in every
    point (converging states reach it: one coordinate agrees exactly while the others
    still differ by ulps; the 3-d path takes full-dimensional kernels only) lies in
    the plane x_j = a, so Ψ(Y, F) = {a} × Ψ(Y', F) (Y' the other two coordinates) and
    the point nearest the mean is (a, the planar point of Y'): the planar path's
    answer, its ∞-norm bound times 1.5 ≥ √2 as a bound in the 2-norm."""
    from ..geometry._small2d import ACCEPT_REL, OK, project_small_2d
    from ..geometry._small3d import project_small_3d

    if Ys.shape[2] == 3:
        pts, err, found = project_small_3d(Ys, F)
        same = (Ys == Ys[:, :1, :]).all(axis=1)  # (B, 3): coordinates constant per set
        for j in range(3):
            flat = np.flatnonzero(~found & same[:, j] & (same.sum(axis=1) == 1))
            if not len(flat):
                continue
            others = [i for i in range(3) if i != j]
            p2, e2, ok2 = _batch_points(np.ascontiguousarray(Ys[flat][:, :, others]), F)
            pts[flat[:, None], others], pts[flat, j] = p2, Ys[flat, 0, j]
            err[flat] = 1.5 * e2
            found[flat] = ok2 & (err[flat] <= ACCEPT_REL * np.abs(pts[flat]).max(axis=1))
        return pts, err, found
    pts = np.empty((len(Ys), 2))
    err = np.empty(len(Ys))
    status = np.empty(len(Ys), dtype=np.int64)
    project_small_2d(Ys, F, pts, err, status)
    return pts, err, (status == OK) & (err <= ACCEPT_REL * np.abs(pts).max(axis=1))


def _batch_points_moved(Ys: np.ndarray, F: int
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`_batch_points` of the sets moved next to the origin: per set a point c of
    its own coordinates (the median of each) is subtracted and the differences scaled
    by a power of two 2^−e to unit size; Ψ((Y − c) 2^−e, F) = (Ψ(Y, F) − c) 2^−e and
    the point nearest the mean moves with it, so 2^e q + c is the point sought for q
    the batch point of the moved set. Only sets whose moved entries are all exact
    (y − c a float: TwoSum's error 0, no overflow; the scaling undone exactly) are
    taken — converged states, whose Ψ is a few ulps of its magnitude wide, then
    become sets of unit scale, whose points the batch paths certify to ulps of Ψ's
    width instead of ulps of the magnitude. Returns the points fl(2^e q + c) (2^e q
    exact: a power of two; its bound scaled alike), bounds on their distances to the exact
    points — the batch bound for q plus the rounding of the sum (at most half the
    spacing of the largest |coordinate| per coordinate: ≤ one spacing in 2-norm for
    d ≤ 4) and, where 2^e q or 2^e times the bound is subnormal, their roundings (< 2
    of the smallest subnormal in 2-norm), the float sum enlarged by 2⁻⁵⁰ — and
    whether each is certified."""
    from ..geometry._small2d import ACCEPT_REL

    B, m, d = Ys.shape
    c = np.sort(Ys, axis=1)[:, m // 2]  # (B, d): a coordinate of the set per axis
    with np.errstate(all="ignore"):
        moved = Ys - c[:, None, :]
        back = moved - Ys
        exact = ((Ys - (moved - back)) + (-c[:, None, :] - back) == 0.0).all(axis=(1, 2))
    pts = np.zeros((B, d))
    bound = np.full(B, np.inf)
    found = np.zeros(B, dtype=bool)
    # ... and of unit scale: times 2^−e, e the exponent of the largest |y − c| (exact
    # unless an entry then falls below the normal range: such sets are left out)
    top = np.abs(moved).max(axis=(1, 2))
    e = np.frexp(np.where((top > 0.0) & np.isfinite(top), top, 1.0))[1]
    unit = np.ldexp(moved, -e[:, None, None])
    exact &= (np.ldexp(unit, e[:, None, None]) == moved).all(axis=(1, 2))
    idx = np.flatnonzero(exact & np.isfinite(moved).all(axis=(1, 2)))
    if not len(idx):
        return pts, bound, found
    q, err, ok = _batch_points(np.ascontiguousarray(unit[idx]), F)
    with np.errstate(all="ignore"):
        q, err = np.ldexp(q, e[idx, None]), np.ldexp(err, e[idx])
        p = q + c[idx]
        size = np.abs(p).max(axis=1)
        b = (err + np.spacing(size) + 2.0 * MIN_SUBNORMAL) * (1.0 + 2.0**-50)
    pts[idx], bound[idx] = p, b
    found[idx] = ok & np.isfinite(p).all(axis=1) & (b <= ACCEPT_REL * size)
    return pts, bound, found


#: a batch point may be off by at most this share of the widest side of the box Ψ
#: lies in (besides ACCEPT_REL of its magnitude) ...
WIDTH_REL = 2.0**-20
#: ... plus this share of its magnitude (two units in the last place: the exact point
#: rounded is off by up to half of one)
ROUNDING_SLACK = 2.0**-51


def _allowance(Ys: np.ndarray, F: int, pts: np.ndarray) -> np.ndarray:
    """Per set, the largest certified error a batch kernel point may have: ACCEPT_REL of
    its magnitude or WIDTH_REL of the widest side of the box Ψ lies in, whichever is
    smaller, plus ROUNDING_SLACK of the magnitude. Ψ(Y, F) lies between the (F+1)-th
    smallest and the (F+1)-th largest value of every coordinate (a point beyond has a
    closed halfspace {y_j ≤ x_j} or {y_j ≥ x_j} with ≤ F points), so the allowance
    also follows the size of Ψ, not only its distance from the origin: 1e15 + a spread
    of 1 was allowed ~900 by its magnitude alone, and states left their benign hull
    (V36); converged states (Ψ 1e-6 of its magnitude wide) keep ACCEPT_REL. The
    rounding slack is of the coordinates in which that box has room (in the others the
    exact coordinate is a float)."""
    from ..geometry._small2d import ACCEPT_REL

    Z = np.sort(Ys, axis=1)
    m = Ys.shape[1]
    with np.errstate(over="ignore", invalid="ignore"):  # ±inf widths: the magnitude's
        widths = Z[:, m - 1 - F] - Z[:, F]
    size = np.abs(pts).max(axis=1)
    # the rounding slack only of coordinates where Ψ has room: where the box is one
    # value, the exact coordinate is that float (a constant 1e140 licensed errors of
    # 4e124 in the others, V43)
    spread = np.where(widths != 0, np.abs(pts), 0.0).max(axis=1)
    return np.fmin(ACCEPT_REL * size, WIDTH_REL * widths.max(axis=1)) + ROUNDING_SLACK * spread


def _same_shape(problems: list[np.ndarray] | np.ndarray) -> dict[tuple[int, ...], np.ndarray]:
    """Indices of the problems by shape (one group for an array of problems)."""
    if isinstance(problems, np.ndarray):
        return {problems.shape[1:]: np.arange(len(problems))}
    groups: dict[tuple[int, ...], list[int]] = {}
    for k, X in enumerate(problems):
        groups.setdefault(X.shape, []).append(k)
    return {shape: np.array(idx) for shape, idx in groups.items()}


def _baseline_auxiliary(sc, links, x, values, usable, benign, d):
    """x̃_i of the baselines for every benign agent, one array operation per group of
    agents with the same number c of usable values (values V (R, c, d), own states
    O (R, d)): "mean" averages V and O (:func:`_scaled_mean`); "wmsr" per coordinate
    sorts V, drops the F largest values above the own value and the F smallest below
    it (fewer if there are fewer) and averages the rest with the own value — the kept
    values are the contiguous run v[lo:hi] of the sorted ones, averaged per run
    length (the same float sum as one agent's)."""
    aux = np.empty((len(benign), d))
    for c, rows, idx in _usable_groups(links, usable, benign):
        own = x[benign[rows]]
        if sc.algorithm == "mean":
            aux[rows] = _scaled_mean(np.concatenate([values[idx], own[:, None]], axis=1),
                                     axis=1)
            continue
        V = np.sort(values[idx], axis=1)
        lo = np.minimum(sc.F, (V < own[:, None]).sum(axis=1))  # (R, d)
        hi = c - np.minimum(sc.F, (V > own[:, None]).sum(axis=1))
        for L in np.unique(hi - lo):
            r, p = np.nonzero(hi - lo == L)
            kept = V[r[:, None], lo[r, p][:, None] + np.arange(L), p[:, None]]
            aux[rows[r], p] = _scaled_mean(np.concatenate([kept, own[r, p][:, None]], axis=1),
                                           axis=1)
    return aux


def _bar(progress: bool | None, total: int, desc: str = "simulate") -> Any:
    """A bar over the steps on stderr, or None (the rule of :mod:`rescon._progress`)."""
    from .._progress import progress_bar

    return progress_bar(progress, total, desc, unit="step")
