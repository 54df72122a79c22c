"""The checker's normal fan in d >= 4 (issue 13): V ⊆ Ψ by the recursion on the
dimension of the normal cone (``kernels._cells_min``) instead of the C(n, d) hyperplane
enumeration of fact (b).

Oracle: the same certificate checked with the fan replaced by (b)
(``kernels._in_kernel_halfspaces``, exact, independent of the fan) — the two verdicts
must agree; a correct certificate is never invalid, a false claim never valid."""

from __future__ import annotations

import copy
from fractions import Fraction

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from rescon_certificates import kernels
from rescon_certificates.check import check

import rescon


def _by_enumeration(monkeypatch, cert: dict):
    """check(cert) with V ⊆ Ψ decided by (b) instead of the normal fan."""
    with monkeypatch.context() as m:
        m.setattr(kernels, "_fan_in_kernel",
                  lambda pts, F, V, tight, names, ctx, *_:
                  kernels._in_kernel_halfspaces(pts, F, V, names, ctx, "vertices"))
        m.setattr(kernels, "MAX_HALFSPACE_WORK", 10**9)
        return check(copy.deepcopy(cert))


def _cloud(rng, kind: str, n: int, d: int) -> np.ndarray:
    if kind == "gauss":
        return rng.standard_normal((n, d))
    if kind == "int":  # ties, points on facet hyperplanes, non-simple vertices
        return rng.integers(-2, 3, (n, d)).astype(float)
    if kind == "dup":  # a multiset
        X = rng.integers(-2, 3, (n, d)).astype(float)
        X[n // 2:] = X[: n - n // 2]
        return X
    if kind == "grid":  # distinct points of {0, 1, 2}^d: highly degenerate
        idx = rng.choice(3 ** d, size=n, replace=False)
        return np.array([[(i // 3 ** j) % 3 for j in range(d)] for i in idx], dtype=float)
    if kind == "huge":
        return rng.standard_normal((n, d)) * 1e300
    assert kind == "tiny"
    return rng.standard_normal((n, d)) * 1e-300


def _claims(X: np.ndarray, F: int):
    """(certificate, label): rescon's kernel for F, and claims that may be false —
    Ψ(X, F) claimed for F + 1 and Ψ(X, F − 1) claimed for F (each is a polytope with
    valid facets; the claim is true iff the kernels are equal)."""
    K = rescon.safe_kernel(X, F)
    if K.is_empty:
        return
    yield K.certificate, "own"
    if K.dim == X.shape[1] and F + 1 < len(X):
        yield {**copy.deepcopy(K.certificate), "F": F + 1}, "F + 1"
    if F >= 1:
        big = rescon.safe_kernel(X, F - 1)
        if big.dim == X.shape[1]:
            yield {**copy.deepcopy(big.certificate), "F": F}, "F - 1"


def _agree(monkeypatch, X: np.ndarray, F: int) -> tuple[int, int]:
    """Check every claim of :func:`_claims` with the fan and with (b); returns how many
    were decided (valid or invalid) by both, and how many of them were invalid."""
    d = X.shape[1]
    decided = invalid = 0
    for cert, label in _claims(X, F):
        fan = check(cert)
        ref = _by_enumeration(monkeypatch, cert)
        if label == "own":
            assert fan.verdict != "invalid", fan.reason
        assert "invalid" not in {fan.verdict, ref.verdict} or fan.verdict == ref.verdict, \
            (label, fan.verdict, fan.reason, ref.verdict, ref.reason)
        if fan.verdict == "valid" and cert["dim"] == d:
            assert "normal fan" in fan.reason, fan.reason
        if ref.verdict != "unchecked":
            assert fan.verdict == ref.verdict, (label, fan.reason, ref.reason)
            decided += 1
            invalid += fan.verdict == "invalid"
    return decided, invalid


def _agree_many(monkeypatch, d: int, kind: str, clouds: int, nmax: int) -> tuple[int, int]:
    rng = np.random.default_rng([d, sum(map(ord, kind))])
    decided = invalid = 0
    for _ in range(clouds):
        n = int(rng.integers(8, nmax))
        X = _cloud(rng, kind, n, d)
        for F in range(0, max(1, n // (d + 1)) + 1):
            a, b = _agree(monkeypatch, X, F)
            decided, invalid = decided + a, invalid + b
    return decided, invalid


@pytest.mark.parametrize("kind", ["gauss", "int"])
def test_fan_agrees_with_the_enumeration(monkeypatch, kind):
    """Small d = 4 kernels (n = 8–11, several F), correct and false claims: the fan's
    verdict is (b)'s, and some claims are false."""
    decided, invalid = _agree_many(monkeypatch, 4, kind, 2, 12)
    assert decided > 0 and invalid > 0, (decided, invalid)


@pytest.mark.slow
@pytest.mark.parametrize("d", [4, 5])
@pytest.mark.parametrize("kind", ["gauss", "int", "dup", "grid"])
def test_fan_agrees_with_the_enumeration_more(monkeypatch, d, kind):
    """As above, n = 8–14 (d = 4), 8–11 (d = 5), duplicates and grids too."""
    decided, invalid = _agree_many(monkeypatch, d, kind, 4 if d == 4 else 2, 15 if d == 4 else 12)
    assert decided > 0, (decided, invalid)


@pytest.mark.slow
@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 10**6), d=st.sampled_from([4, 5]),
       kind=st.sampled_from(["gauss", "int", "dup", "grid", "huge", "tiny"]))
def test_fan_agrees_with_the_enumeration_random(seed, d, kind):
    """As above, on random clouds (hypothesis), with 1e±300 magnitudes too."""
    mp = pytest.MonkeyPatch()
    try:
        rng = np.random.default_rng(seed)
        n = int(rng.integers(d + 4, 14 if d == 4 else 12))
        X = _cloud(rng, kind, n, d)
        F = int(rng.integers(0, n // (d + 1) + 1))
        _agree(mp, X, F)
    finally:
        mp.undo()


def _scaled(cert: dict, factor: Fraction) -> dict:
    """The claim P scaled by ``factor`` about the mean of its vertices (facets moved
    with it; the adjacency stays right): false for factor > 1 when P = Ψ."""
    V = [[Fraction(t) for t in v] for v in cert["vertices"]]
    d = len(V[0])
    c0 = [Fraction(float(sum(v[j] for v in V) / len(V))) for j in range(d)]  # short numbers
    out = copy.deepcopy(cert)
    out["vertices"] = [[str(c0[j] + factor * (v[j] - c0[j])) for j in range(d)] for v in V]
    for h in out["facets"]:
        ac = sum(Fraction(a) * x for a, x in zip(h["a"], c0))
        h["b"] = str(ac + factor * (Fraction(h["b"]) - ac))
    return out


@pytest.mark.parametrize("d", [4, pytest.param(5, marks=pytest.mark.slow)])
def test_enlarged_kernel_is_refuted_by_the_fan(d, monkeypatch):
    """Ψ scaled by 1 + 1e-6 keeps <= F points outside each facet (no data point in
    between), so only the vertex test can refute it; the fan does, in d = 4, 5 (in
    d = 5, n = 10 it would hand over to the cheaper (b) after 50× (b)'s work: both
    routes decide; the fan is then run to its own limit)."""
    n, F = (14, 2) if d == 4 else (10, 1)  # d = 5: steps 4–5 within their work limit
    X = np.random.default_rng(d).standard_normal((n, d))
    K = rescon.safe_kernel(X, F)
    assert K.dim == d
    assert check(K.certificate).verdict == "valid"
    assert check(_scaled(K.certificate, 1 + Fraction(1, 10**6))).verdict == "invalid"
    monkeypatch.setattr(kernels, "FAN_OVER_ENUMERATION", 10**12)  # no hand-over to (b)
    res = check(K.certificate)
    assert res.verdict == "valid" and "normal fan" in res.reason, res.reason
    res = check(_scaled(K.certificate, 1 + Fraction(1, 10**6)))
    assert res.verdict == "invalid" and "Tukey depth is at most" in res.reason, res.reason


def test_fan_work_limit_is_unchecked_not_invalid(monkeypatch):
    """Beyond the work limit the vertex test is unchecked, whether the claim is true or
    false, and no arc is swept once the limit is reached."""
    X = np.random.default_rng(11).standard_normal((14, 4))
    K = rescon.safe_kernel(X, 2)
    n, d = len(X), 4
    calls = []
    real = kernels._arc_min
    monkeypatch.setattr(kernels, "_arc_min", lambda pairs: calls.append(1) or real(pairs))
    fan = kernels._fan_in_kernel

    def tight_fan(*args):  # the limits are lowered for step 7 only, after steps 1–6
        monkeypatch.setattr(kernels, "MAX_EVAL_WORK", len(K.certificate["vertices"]) * n * (d + 2))
        monkeypatch.setattr(kernels, "MAX_HALFSPACE_WORK", 0)  # no hand-over to (b)
        return fan(*args)

    monkeypatch.setattr(kernels, "_fan_in_kernel", tight_fan)
    for cert in (K.certificate, _scaled(K.certificate, 1 + Fraction(1, 10**6))):
        monkeypatch.setattr(kernels, "MAX_EVAL_WORK", 20_000_000)
        res = check(copy.deepcopy(cert))
        assert res.verdict == "unchecked" and res.trusted == ("halfspaces",), res.unchecked
    assert calls == []


def _cone_points(rng, d: int, t: int, K: int, span: int):
    """A pointed cone cone(G) in R^d (t integer generators with positive last entry, of
    rank d) and K integer points that cross it (both signs on G)."""
    while True:
        G = [list(map(int, rng.integers(-span, span + 1, d - 1))) + [int(rng.integers(1, span + 1))]
             for _ in range(t)]
        if kernels._rank(G) == d:
            break
    cross = []
    while len(cross) < K:
        q = list(map(int, rng.integers(-span, span + 1, d)))
        s = [kernels._dot(g, q) for g in G]
        if min(s) < 0 < max(s):
            cross.append(q)
    return G, cross


@pytest.mark.parametrize("d", [3, 4, 5])
def test_cells_min_is_at_most_every_sampled_cell(d):
    """The recursion's minimum (no bound) is a count attained near its witness and is at
    most the count at every sampled interior direction of the cone (sampling sees some
    cells; the recursion must see all, so it can never report more); with a bound
    below it the answer is None."""
    rng = np.random.default_rng(d)
    for _ in range(25):
        t = int(rng.integers(d, d + 4))
        G, cross = _cone_points(rng, d, t, int(rng.integers(1, 9)), 3)
        rows = [[kernels._dot(g, q) for g in G] for q in cross]
        c, w = kernels._cells_min(0, rows, G, d, len(cross), [0, 10**12], 8, 8)
        sampled = len(cross)
        for _ in range(300):
            lam = rng.integers(1, 50, len(G))
            v = [sum(int(x) * g[j] for x, g in zip(lam, G)) for j in range(d)]
            sampled = min(sampled, sum(kernels._dot(q, v) > 0 for q in cross))
        assert c <= sampled
        # the witness lies in the closure of a cell with count c: nearby counts are >= c
        # (the count is lower semicontinuous on the open side) and <= c + #{q·w = 0}
        on = sum(kernels._dot(q, w) > 0 for q in cross)
        zero = sum(kernels._dot(q, w) == 0 for q in cross)
        assert on <= c <= on + zero
        if c > 0:
            assert kernels._cells_min(0, rows, G, d, c - 1, [0, 10**12], 8, 8) is None


def _arc_min_reference(pairs):
    """The sweep as it was before the float-keyed sort (Fractions and bisection)."""
    from bisect import bisect_left, bisect_right

    base, down, up = 0, [], []
    for s1, s2 in pairs:
        if s1 >= 0 and s2 >= 0:
            base += 1
        elif s1 > 0 > s2:
            down.append(Fraction(s1, s1 - s2))
        elif s1 < 0 < s2:
            up.append(Fraction(s1, s1 - s2))
    down.sort()
    up.sort()
    cuts = sorted({Fraction(0), Fraction(1), *down, *up})
    best = None
    for lo, hi in zip(cuts, cuts[1:]):
        count = base + len(down) - bisect_left(down, hi) + bisect_right(up, lo)
        if best is None or count < best[0]:
            best = (count, (lo + hi) / 2)
    return best


@settings(max_examples=300, deadline=None)
@given(pairs=st.lists(st.tuples(st.integers(-6, 6), st.integers(-6, 6)), max_size=12),
       scale=st.sampled_from([1, 2**80, 10**400]), tiny=st.integers(0, 3))
def test_arc_min_is_the_exact_sweep(pairs, scale, tiny):
    """The float-keyed sort gives the exact sweep: ties (equal breakpoints), huge
    numbers, and breakpoints closer than a float can tell apart (t and t + 1/10^400)."""
    pairs = [(a * scale, b * scale) for a, b in pairs if a or b]
    if tiny:  # breakpoints equal as floats, different exactly
        big = 10**400
        pairs += [(big, -big), (big + tiny, -big), (-big - tiny, big)][:tiny]
    assert kernels._arc_min(pairs) == _arc_min_reference(pairs)


@pytest.mark.parametrize(("family", "n", "F"), [("sphere", 30, 1), ("gaussian", 30, 9)])
def test_benchmark_kernels_in_d4_are_verified(family, n, F):
    """Before: 'unchecked' (V ⊆ Ψ fell back to the C(n, 4) hyperplane enumeration,
    beyond its work limit); now valid by the normal fan (1156 resp. 121 vertices)."""
    from benchmarks.kernel_clouds import make_cloud

    cert = rescon.safe_kernel(make_cloud(family, 4, n, F).X, F).certificate
    res = check(cert)
    assert res.verdict == "valid", (res.reason, res.unchecked)
    assert "normal fan" in res.reason


def test_kernel_point_by_its_kernel_in_d4():
    """A kernel_point certificate whose proof is the kernel itself (checked as a
    safe_kernel, by the fan) is valid in d = 4 too; a point just outside is not."""
    X = np.random.default_rng(3).standard_normal((12, 4))
    c = rescon.safe_kernel(X, 2).certificate
    v, w = (c["vertices"][i] for i in (0, c["adjacency"][0][0]))
    x = [str((Fraction(a) + Fraction(b)) / 2) for a, b in zip(v, w)]  # on an edge of Ψ
    proof = {"method": "kernel", **{k: c[k] for k in kernels.KERNEL_KEYS}}
    cert = {"rescon_certificate": 1, "kind": "kernel_point", "points": c["points"], "F": 2,
            "x": x, "proof": proof}
    res = check(cert)
    assert res.verdict == "valid" and "normal fan" in res.reason, res.reason
    h = c["facets"][0]
    out = [str(Fraction(t) + Fraction(a) * 10**6) for t, a in zip(x, h["a"])]
    assert check({**cert, "x": out}).verdict == "invalid"
