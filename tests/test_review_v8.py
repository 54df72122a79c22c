"""Review V8 (issue 13): hostile tests of this session's changes.

A. The d = 4–5 fast path: ``_distinct_points`` (float keys, exact ties), the compiled
   nonsingularity test mod p (``_certify_nb.nonsingular``), ``tight_through``.
B. The checker's normal fan in d ≥ 3 (``certificates/kernels.py``).
C. Capped charged-tree leaves (``certificates/cost_tree.py``, ``graphs/_charged_kernels``).
"""

from __future__ import annotations

import itertools
from fractions import Fraction

import numpy as np
import pytest

import rescon
from rescon.geometry import _certify_nb, fastpath
from tests.test_kernel_d45_around2 import _cloud, _same_as_clipping
from tests.test_review_v5 import _det as _fraction_det

# --- A. the fast path ----------------------------------------------------------------


def _det(M) -> Fraction:
    """The exact determinant of an integer / rational matrix."""
    return _fraction_det([[Fraction(x) for x in r] for r in M])


@pytest.mark.parametrize("k", [2, 3, 4, 5])
def test_nonsingular_never_calls_a_singular_system_nonsingular(k):
    """``nonsingular`` against exact determinants on small integer rows full of
    dependencies (copies, sums, zero rows), rows whose determinant is a nonzero multiple
    of p (must say "maybe singular"), and residues near p: True ⇒ det ≠ 0 and
    det ≢ 0 (mod p) ⇒ True."""
    from rescon.geometry.polytope import PRIME

    rng = np.random.default_rng(k)
    rows = [list(r) for r in rng.integers(-2, 3, size=(40, k)).tolist()]
    rows += [[a + b for a, b in zip(rows[i], rows[i + 1], strict=True)] for i in range(10)]
    rows += [[0] * k, rows[0], [PRIME - 1] * k, [PRIME] + [0] * (k - 1)]
    rows += [[2**40 + i] + [3**j for j in range(k - 1)] for i in range(3)]
    # det = PRIME·(something nonzero): a diagonal with PRIME in one entry
    for j in range(k):
        rows.append([PRIME if c == j else 0 for c in range(k)])
        rows.append([1 if c == j else 0 for c in range(k)])
    m = len(rows)
    A = np.array([[v % PRIME for v in r] for r in rows], dtype=np.int64)
    sets = [rng.choice(m, k, replace=False).tolist() for _ in range(3000)]
    sets += [[m - 2 * k + 2 * j + (j != 0) for j in range(k)]]  # PRIME · e_0, e_1, …
    sets += [list(range(m - 2 * k, m, 2))]  # PRIME · I
    at = np.array(sets, dtype=np.int64)
    got = _certify_nb.nonsingular(A, at, PRIME)
    for T, ok in zip(sets, got.tolist(), strict=True):
        det = _det([rows[i] for i in T])
        if ok:
            assert det != 0, T
        if det.numerator % PRIME:
            assert ok, T
    assert not got[-1] and not got[-2]  # det = PRIME^j ≠ 0, "maybe singular"


def _lattice_rows(rng, k: int, n: int, m: int):
    """n lattice points in {0, 1, 2}^k (many on common hyperplanes) and m rows through k
    affinely independent ones (exact primitive (a, b))."""
    Y = [tuple(p) for p in rng.integers(0, 3, size=(4 * n, k)).tolist()]
    Y = list(dict.fromkeys(Y))[:n]
    through, ab = [], []
    while len(through) < m:
        T = sorted(rng.choice(len(Y), k, replace=False).tolist())
        D = [[x - y for x, y in zip(Y[t], Y[T[0]], strict=True)] for t in T[1:]]
        a = tuple(int((-1) ** j * _det([[r[c] for c in range(k) if c != j] for r in D]))
                  for j in range(k))
        if any(a):
            through.append(T)
            ab.append((a, sum(x * y for x, y in zip(a, Y[T[0]], strict=True))))
    return Y, np.array(through, dtype=np.int64), ab


@pytest.mark.parametrize("k", [3, 4, 5])
def test_tight_through_only_claims_exactly_tight_pairs(k):
    """Brute force: random lattice points (many points on common hyperplanes, rows
    sharing k − 1 or fewer points), vertices solved from k independent rows; every pair
    (row, vertex) ``tight_through`` calls tight has exact slack 0 — and it finds some."""
    rng = np.random.default_rng([k, 8])
    Y, through, ab = _lattice_rows(rng, k, 3 * k + 2, 120)
    basis, verts = [], []
    while len(basis) < 60:
        # bases sharing points: a row and others through some of its points
        B = sorted(rng.choice(len(through), k, replace=False).tolist())
        A = [ab[h][0] for h in B]
        det = _det(A)
        if det == 0:
            continue
        # Cramer: v = A⁻¹ b
        v = []
        for j in range(k):
            Aj = [[ab[h][1] if c == j else ab[h][0][c] for c in range(k)] for h in B]
            v.append(_det(Aj) / det)
        basis.append(B)
        verts.append(v)
    hs = np.repeat(np.arange(len(through)), len(verts))
    vs = np.tile(np.arange(len(verts)), len(through))
    got = _certify_nb.tight_through(through, np.array(basis, dtype=np.int64), hs, vs)
    claimed = 0
    for h, v, ok in zip(hs.tolist(), vs.tolist(), got.tolist(), strict=True):
        slack = sum(Fraction(a) * x for a, x in zip(ab[h][0], verts[v], strict=True)) - ab[h][1]
        if ok:
            claimed += 1
            assert slack == 0, (h, v)
    assert claimed >= len(verts)  # at least the basis rows themselves


def test_tight_through_on_a_hand_made_flat():
    """k = 3: rows g1, g2 share the two points {p, q} (their line holds v); a row h
    through p and q holds v (True); a row through p alone and two other points does
    not have to (False unless another flat proves it)."""
    # points (0,0,0) (1,0,0) (0,1,0) (0,0,1) (1,1,1) (2,0,5) (0,3,1)
    # g1 = {0,1,2} (z = 0), g2 = {0,1,3} (y = 0), g3 = {2,3,4}: v on the x-axis
    through = np.array([[0, 1, 2], [0, 1, 3], [2, 3, 4], [0, 1, 5], [0, 5, 6]],
                       dtype=np.int64)
    basis = np.array([[0, 1, 2]], dtype=np.int64)
    got = _certify_nb.tight_through(through, basis, np.array([3, 4]), np.array([0, 0]))
    assert got.tolist() == [True, False]


def test_distinct_points_merge_exactly_whatever_the_floats():
    """Homogeneous rows of distinct points closer than a float resolves (1e-300 apart
    around 1, 1/(2^200) apart, points rounding to the same subnormal or to 0), equal
    points written with different positive scalings, and keys forced equal: equal
    points merge, distinct ones never do."""
    pts = [(Fraction(1), Fraction(2)), (1 + Fraction(1, 10**300), Fraction(2)),
           (Fraction(1), 2 + Fraction(1, 2**200)), (Fraction(1, 2**1100), Fraction(0)),
           (Fraction(1, 2**1101), Fraction(0)), (Fraction(0), Fraction(0)),
           (Fraction(-1, 2**1100), Fraction(0)), (Fraction(10**300), Fraction(1)),
           (Fraction(10**300) + 1, Fraction(1))]
    rng = np.random.default_rng(8)
    order = rng.integers(0, len(pts), size=60).tolist()
    rows = []
    for i in order:
        x, y = pts[i]
        w = x.denominator * y.denominator * int(rng.integers(1, 1000))
        rows.append([w, int(x * w), int(y * w)])
    W = np.empty((len(rows), 3), dtype=object)
    W[:] = rows
    Vx = (W[:, 1:] / W[:, :1]).astype(np.float64)
    for V in (Vx, np.zeros_like(Vx), np.round(Vx)):
        of_row, firsts = fastpath._distinct_points(W, V)
        assert len(firsts) == len(set(order))
        for i, j in itertools.combinations(range(len(order)), 2):
            assert (of_row[i] == of_row[j]) == (order[i] == order[j])
        assert all(of_row[f] == n for n, f in enumerate(firsts.tolist()))
        assert sorted(firsts.tolist()) == firsts.tolist()  # numbered by first appearance


@pytest.mark.parametrize("kind,d,n,F", [("lattice", 4, 40, 3), ("grid", 4, 20, 2),
                                        ("integer", 4, 20, 3), ("nearsame", 5, 13, 1),
                                        ("cell24", 4, 28, 4)])
def test_kernels_unchanged_when_every_float_key_collides(kind, d, n, F, monkeypatch):
    """The float keys of ``_distinct_points`` made to collide (all equal, or rounded to
    integers of the scaled coordinates): the exact ties decide, the kernel stays bit
    for bit the exact clipping's."""
    real = fastpath._distinct_points
    for coarse in (np.zeros_like, lambda V: np.round(V / 8)):
        with monkeypatch.context() as mp:
            mp.setattr(fastpath, "_distinct_points", lambda W, V, c=coarse: real(W, c(V)))
            _same_as_clipping(_cloud(kind, d, n, F), F, monkeypatch)


# --- B. the checker's normal fan -----------------------------------------------------


def _kernels_modules():
    import importlib.util
    import subprocess
    import sys
    from pathlib import Path

    from rescon_certificates import kernels

    C = sys.modules["rescon_certificates.check"]
    old = Path(__file__).parent / "data" / ".." / ".."  # repository root
    src = subprocess.run(["git", "-C", str(old), "show", "e79e53b:certificates/kernels.py"],
                         capture_output=True, text=True)
    KO = None
    if src.returncode == 0:
        spec = importlib.util.spec_from_loader("kernels_e79e53b", loader=None)
        KO = importlib.util.module_from_spec(spec)
        exec(compile(src.stdout, "kernels_e79e53b.py", "exec"), KO.__dict__)
        KO.install(C.Invalid, C._obj, C._int, C._array, C._tname, unchecked=C.Unchecked)
    return C, kernels, KO


class _Ctx:
    def __init__(self) -> None:
        self.trusted: list[str] = []

    def trust(self, name: str, part: str) -> None:
        self.trusted.append(part)


def _verdict(C, fn, *args) -> str:
    ctx = _Ctx()
    try:
        fn(*args, ctx)
    except C.Invalid:
        return "invalid"
    return "unchecked" if ctx.trusted else "valid"


def _facets(V):
    """The facets (a, b) of conv(V) (integer points): qhull's simplices, each checked
    exactly; None if qhull's answer does not check."""
    from math import gcd

    from scipy.spatial import ConvexHull

    d = len(V[0])
    out = set()
    for s in ConvexHull(np.array(V, dtype=float)).simplices:
        p0 = V[s[0]]
        D = [[x - y for x, y in zip(V[i], p0, strict=True)] for i in s[1:]]
        a = [int((-1) ** j * _det([[r[c] for c in range(d) if c != j] for r in D]))
             for j in range(d)]
        if not any(a):
            continue
        g = gcd(*a)
        a = [x // g for x in a]
        b = sum(x * y for x, y in zip(a, p0, strict=True))
        sides = {(t > b) - (t < b) for t in (sum(x * y for x, y in zip(a, p, strict=True))
                                             for p in V)}
        if {-1, 1} <= sides:
            return None
        if 1 in sides:
            a, b = [-x for x in a], -b
        out.add((tuple(a), b))
    return sorted(out)


def _fan_instance(seed: int, d: int):
    """(points, F, V, tight normals) of an arbitrary lattice polytope P (not a kernel):
    near the points' centre at three sizes, or the hull of some data points; data with
    ties, duplicates and points on common hyperplanes. None if degenerate."""
    from scipy.spatial import ConvexHull

    rng = np.random.default_rng([seed, d, 88])
    n = int(rng.integers(d + 2, d + 7))
    S = 2 * int(rng.integers(1, 5))
    X = [rng.integers(-3, 4, (n, d)), rng.integers(-1, 2, (n, d)),
         rng.integers(-3, 4, (n, d)), rng.integers(-2, 3, (n, d))][seed % 4]
    if seed % 4 == 2:
        X[n // 2:] = X[: n - n // 2]
    if seed % 4 == 3:
        X[:, 0] = np.where(rng.random(n) < 0.5, 0, X[:, 0])
    pts = [tuple(Fraction(int(x) * S) for x in p) for p in X]
    F = int(rng.integers(0, max(1, n // (d + 1))))
    c = [round(sum(p[j] for p in pts) / n) for j in range(d)]
    m = int(rng.integers(d + 1, d + 6))
    if rng.integers(0, 3) == 2:
        W = [pts[i] for i in rng.choice(n, min(n, m), replace=False)]
        F = int(rng.integers(0, 2))
    else:
        R = [1, S // 2 + 1, S][int(rng.integers(0, 3))]
        W = [tuple(c[j] + int(rng.integers(-R, R + 1)) for j in range(d)) for _ in range(m)]
    W = list(dict.fromkeys(W))
    try:
        V = [W[i] for i in sorted(ConvexHull(np.array(W, dtype=float)).vertices)]
    except Exception:  # flat
        return None
    fs = _facets(V)
    if fs is None:
        return None
    tight = [[list(a) for a, b in fs if sum(x * y for x, y in zip(a, v, strict=True)) == b]
             for v in V]
    if any(np.linalg.matrix_rank(np.array(t, dtype=float)) < d for t in tight):
        return None
    return pts, F, V, tight


@pytest.mark.parametrize("d", [3, 4])
def test_fan_agrees_with_the_enumeration_on_arbitrary_polytopes(d):
    """Not kernels: arbitrary lattice polytopes P (small, medium, large around the
    centre; hulls of data points, where every vertex is a data point) against data with
    ties, duplicates and points on common hyperplanes. The fan's verdict on conv(V) ⊆ Ψ
    equals fact (b)'s enumeration on V, and in d = 3 the verdict of the checker before
    this session (e79e53b)."""
    C, K, KO = _kernels_modules()
    seen = set()
    for seed in range(60 if d == 3 else 40):
        inst = _fan_instance(seed, d)
        if inst is None:
            continue
        pts, F, V, tight = inst
        names = [f"v{i}" for i in range(len(V))]
        new = _verdict(C, K._fan_in_kernel, pts, F, V, tight, names)
        ref = _verdict(C, lambda *a: K._in_kernel_halfspaces(*a[:4], a[4], "vertices"),
                       pts, F, V, names)
        assert new == ref, (seed, new, ref)
        if d == 3 and KO is not None:
            assert _verdict(C, KO._fan_in_kernel, pts, F, V, tight, names) == new, seed
        seen.add(new)
    assert seen == {"valid", "invalid"}


@pytest.mark.parametrize("seed", [4, 8, 12, 25, 27, 33, 36])
def test_fan_decides_tiny_d5_instances(seed):
    """Seed 4 of :func:`_fan_instance` in d = 5: 9 points, F = 0, 8 vertices, valid by
    (b) (seeds 8, 12, 25, 27, 33, 36 alike: n = 7–11). The fan spent its whole work
    budget (4–6 CPU-s) and said 'unchecked', where (b)'s C(9, 5) = 126 hyperplanes
    decide in milliseconds; now it hands over to (b) after FAN_OVER_ENUMERATION times
    (b)'s work."""
    C, K, _ = _kernels_modules()
    pts, F, V, tight = _fan_instance(seed, 5)
    if seed == 4:
        assert (len(pts), F, len(V)) == (9, 0, 8)
    names = [f"v{i}" for i in range(len(V))]
    new = _verdict(C, K._fan_in_kernel, pts, F, V, tight, names)
    ref = _verdict(C, lambda *a: K._in_kernel_halfspaces(*a[:4], a[4], "vertices"),
                   pts, F, V, names)
    assert new == ref != "unchecked", (new, ref)
    if seed == 4:
        assert new == "valid"


def _by_enumeration(cert: dict):
    """check(cert) with V ⊆ Ψ decided by (b) instead of the normal fan."""
    import copy

    from rescon_certificates import kernels
    from rescon_certificates.check import check

    with pytest.MonkeyPatch.context() as m:
        m.setattr(kernels, "_fan_in_kernel",
                  lambda pts, F, V, tight, names, ctx, *_:
                  kernels._in_kernel_halfspaces(pts, F, V, names, ctx, "vertices"))
        m.setattr(kernels, "MAX_HALFSPACE_WORK", 10**9)
        return check(copy.deepcopy(cert))


@pytest.mark.parametrize("d,n,F", [(3, 10, 2), (4, 10, 2), (4, 12, 3),
                                   pytest.param(5, 11, 1, marks=pytest.mark.slow)])
def test_certificate_of_a_nudged_cloud(d, n, F):
    """The certificate of Ψ(X', F) presented for X, X' = X with one point moved by one
    ulp, by 2^-20 of its size, or onto another point (a duplicate), and with a facet
    dropped or its offset moved by 2^-60: the checker (fan) and the enumeration (b)
    never disagree on valid / invalid, and the true kernel stays valid."""
    import copy

    from rescon_certificates.check import check

    import rescon

    rng = np.random.default_rng([d, n, F, 8])
    decided = set()
    for trial in range(6):
        X = np.round(rng.normal(size=(n, d)) * 8) / 8
        i = int(rng.integers(n))
        Y = X.copy()
        move = trial % 3
        if move == 0:
            Y[i, 0] = np.nextafter(Y[i, 0], np.inf)
        elif move == 1:
            Y[i] += 2.0**-20 * rng.normal(size=d)
        else:
            Y[i] = X[(i + 1) % n]
        K = rescon.safe_kernel(Y, F)
        if K.is_empty or K.dim < d:
            continue
        own = check(copy.deepcopy(K.certificate))
        assert own.verdict != "invalid", own.reason
        cert = copy.deepcopy(K.certificate)
        cert["points"] = [[repr(float(x)) for x in p] for p in X] if isinstance(
            cert["points"][0][0], str) else X.tolist()
        variants = [cert]
        dropped = copy.deepcopy(cert)
        del dropped["facets"][int(rng.integers(len(dropped["facets"])))]
        variants.append(dropped)
        moved = copy.deepcopy(cert)
        f = moved["facets"][0]
        f["b"] = str(Fraction(f["b"]) + Fraction(1, 2**60))
        variants.append(moved)
        for c in variants:
            fan, ref = check(copy.deepcopy(c)), _by_enumeration(c)
            if "unchecked" in (fan.verdict, ref.verdict):
                continue
            assert fan.verdict == ref.verdict, (trial, fan.reason, ref.reason)
            decided.add(fan.verdict)
    assert "invalid" in decided


@pytest.mark.parametrize("d,n,F", [(3, 10, 2), (4, 11, 2),
                                   pytest.param(5, 10, 1, marks=pytest.mark.slow)])
def test_kernel_certificate_with_interior_points_added(d, n, F):
    """The certificate of Ψ(X, F) presented for X plus copies of points of Ψ (its
    vertex mean, a vertex, the midpoint of two vertices — exact rationals): every
    facet keeps its outside count, so Ψ' ⊆ P ⊆ Ψ ⊆ Ψ' and the claim is true; the
    checker must not call it invalid. Claimed for F + 1 as well: the fan's verdict
    equals (b)'s."""
    import copy

    from rescon_certificates.check import check

    import rescon

    rng = np.random.default_rng([d, n, F, 9])
    X = np.round(rng.normal(size=(n, d)) * 4) / 4
    K = rescon.safe_kernel(X, F)
    assert K.dim == d
    V = [tuple(Fraction(x) for x in v) for v in K.exact_vertices]
    mean = tuple(sum(c) / len(V) for c in zip(*V))
    mid = tuple((a + b) / 2 for a, b in zip(V[0], V[-1], strict=True))
    decided = set()
    for extra in ([mean], [mean, mean], [V[0]], [mid, V[1], mean]):
        cert = copy.deepcopy(K.certificate)
        cert["points"] = [*cert["points"], *([str(x) for x in q] for q in extra)]
        got = check(copy.deepcopy(cert))
        assert got.verdict != "invalid", got.reason
        up = {**copy.deepcopy(cert), "F": F + 1}
        fan, ref = check(copy.deepcopy(up)), _by_enumeration(up)
        if "unchecked" not in (fan.verdict, ref.verdict):
            assert fan.verdict == ref.verdict, (fan.reason, ref.reason)
            decided.add(fan.verdict)
    assert decided


# --- C. capped charged-tree leaves ---------------------------------------------------


def _charged_cert(ig, r, s, tree, order):
    return {"rescon_certificate": 1, "kind": "rs_robust", "graph": ig.graph_json(), "r": r,
            "s": s, "proof": {"method": "cost_search", "order": order,
                              "charged_tree": list(tree)}}


def _greediest_tree(ig, n, r, s, order, limit):
    """The most aggressive charged tree the checker lets through, built token by token
    with the checker as the oracle: at each state any leaf it accepts (-1 … -4, then
    every capped leaf −5 − (i·n + j), i ≤ j), else the first node it accepts as a branch.
    ("tree", tokens) when the checker calls the tree valid, ("stuck", tokens) when no
    token is accepted at some state, ("limit", tokens) beyond ``limit`` tokens."""
    from tests.test_checker import C

    leaves = [-1, -2, -3, -4] + [-5 - (i * n + j) for i in range(n) for j in range(i, n)]
    toks: list[int] = []
    while len(toks) < limit:
        for cand in leaves + list(range(n)):
            res = C.check(_charged_cert(ig, r, s, toks + [cand], order))
            if res.verdict == "valid":
                return "tree", toks + [cand]
            if "ends early" in res.reason or "ends before" in res.reason:
                toks.append(cand)
                break
        else:
            return "stuck", toks
    return "limit", toks


def _greedy_claims(seeds, nodes):
    import random

    from rescon.graphs.charged import charged_order
    from rescon.graphs.indexed import index_graph
    from tests.test_checker import digraph, in_masks, is_robust, rand_edges, rho_and_s

    capped = controls = 0
    for seed in seeds:
        rng = random.Random(seed)
        n = rng.choice(nodes)
        ig = index_graph(digraph(n, rand_edges(rng, n, rng.choice([0.4, 0.6, 0.8, 0.9]),
                                               rng.random() < 0.3)))
        inm = in_masks(n, ig.edges())
        rho, _ = rho_and_s(n, inm)
        order = charged_order(ig).tolist()
        for r in range(1, rho + 1):
            s_star = 1
            while s_star < n and is_robust(n, inm, r, s_star + 1):
                s_star += 1
            if s_star < n:  # a false claim: the checker must never be talked into it
                how, toks = _greediest_tree(ig, n, r, s_star + 1, order, 1500)
                assert how != "tree", (seed, n, r, s_star, toks)
                capped += sum(t <= -5 for t in toks)
            how, toks = _greediest_tree(ig, n, r, s_star, order, 150)  # a true one
            assert how != "stuck", (seed, n, r, s_star, toks)
            controls += how == "tree"
    return capped, controls


@pytest.mark.slow
def test_the_greediest_charged_tree_never_proves_a_false_claim():
    """Random digraphs (n = 5; directed and undirected, p 0.4–0.9), every r ≤ ρ: a
    tree for s*(r) + 1 (brute force) built from whatever the checker accepts — every
    capped leaf it lets through — never becomes valid; for s*(r) the same builder
    finds a valid tree (or a long one), so the oracle is not vacuous."""
    capped, controls = _greedy_claims(range(16), [5])  # seeds 10, 13: capped leaves
    assert capped > 0 and controls >= 5


@pytest.mark.slow
def test_the_greediest_charged_tree_never_proves_a_false_claim_n6_n7():
    """The same on n = 6, 7 (~2 min)."""
    capped, controls = _greedy_claims(range(100, 124), [6, 7])
    assert capped > 0


def _checker_before(tmp_path):
    """check() of the checker as it was before this session (e79e53b), or None."""
    import importlib.util
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    arch = subprocess.run(["git", "-C", str(root), "archive", "e79e53b", "certificates"],
                          capture_output=True)
    if arch.returncode:
        return None
    subprocess.run(["tar", "-x", "-C", str(tmp_path)], input=arch.stdout, check=True)
    spec = importlib.util.spec_from_file_location("check_e79e53b",
                                                  tmp_path / "certificates" / "check.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules["check_e79e53b"] = mod
    spec.loader.exec_module(mod)
    return mod.check


@pytest.mark.slow
def test_rescon_s_star_is_brute_force_with_charged_trees(monkeypatch):
    """Hundreds of random digraphs (n = 4–9, p 0.3–0.9, directed and undirected), the
    sized tree switched off and the checker's enumeration too (MAX_ENUM_N = 0), so every
    proof of s* ≥ 2 is a charged tree (plain or uniform): (ρ, s*) equals brute force,
    the certificate is valid, and claimed for s* + 1 it is invalid. ~15 CPU-s."""
    import copy
    import random

    import rescon
    from rescon.graphs import robustness as R
    from rescon.graphs.facts import clear_cache
    from tests.test_checker import C, digraph, in_masks, rand_edges, rho_and_s

    monkeypatch.setattr(R, "cost_tree", lambda *a, **k: None)
    monkeypatch.setattr(R, "MAX_ENUM_N", 0)
    charged = capped = 0
    for seed in range(300):
        clear_cache()
        rng = random.Random(seed)
        n = rng.randint(4, 9)
        edges = rand_edges(rng, n, rng.uniform(0.3, 0.9), rng.random() < 0.4)
        G = digraph(n, edges)
        rho, s = rho_and_s(n, in_masks(n, edges))
        for method in ("search", "dp"):
            rep = rescon.robustness(G, method=method)
            assert (rep.r_max, rep.s_max) == (rho, s), (seed, method)
            res = C.check(copy.deepcopy(rep.certificate))
            assert res.verdict == "valid", (seed, method, res.reason)
            proof = rep.certificate.get("lower_s") or {}
            if "charged_tree" in proof:
                charged += 1
                capped += any(t <= -5 for t in proof["charged_tree"])
                if s < n:
                    assert C.check({**copy.deepcopy(rep.certificate), "s": s + 1}
                                   ).verdict == "invalid", seed
    assert charged > 200 and capped > 0


@pytest.mark.parametrize("d", [2, 3])
def test_kernel_verdicts_in_d2_d3_unchanged_since_e79e53b(d, tmp_path):
    """rescon's kernel certificates (random, integer and duplicated clouds) and their
    F + 1 / F − 1 claims, and the examples: the same verdict from the checker before
    this session and now."""
    import copy
    import json
    from pathlib import Path

    from rescon_certificates.check import check

    import rescon

    old = _checker_before(tmp_path)
    if old is None:
        pytest.skip("no git history")
    certs = [json.loads(p.read_text()) for p in
             sorted((Path(__file__).resolve().parent.parent / "certificates" / "examples")
                    .glob("*.json"))]
    rng = np.random.default_rng([d, 8])
    for trial in range(10):
        n = int(rng.integers(d + 2, 12))
        X = [rng.normal(size=(n, d)), np.round(rng.normal(size=(n, d)) * 2),
             np.repeat(np.round(rng.normal(size=((n + 1) // 2, d)) * 2), 2, axis=0)][trial % 3]
        F = int(rng.integers(0, max(1, len(X) // (d + 1))))
        K = rescon.safe_kernel(X, F)
        certs.append(K.certificate)
        certs.append({**copy.deepcopy(K.certificate), "F": F + 1})
        if F:
            certs.append({**copy.deepcopy(K.certificate), "F": F - 1})
    verdicts = set()
    for c in certs:
        a, b = check(copy.deepcopy(c)), old(copy.deepcopy(c))
        assert a.verdict == b.verdict, (a.reason, b.reason)
        verdicts.add(a.verdict)
    assert {"valid", "invalid"} <= verdicts


def _on_hyperplanes(d: int, n: int, seed: int, kind: str) -> np.ndarray:
    rng = np.random.default_rng([d, n, seed, 88])
    Z = np.round(rng.normal(size=(n, d)) * 3)
    if kind == "one_plane":  # two thirds on x_0 = 1: many rows coincide
        Z[: 2 * n // 3, 0] = 1
    elif kind == "two_planes":  # on x_0 = 1 and x_1 = x_0
        Z[: n // 2, 0] = 1
        Z[n // 2:, 1] = Z[n // 2:, 0]
    elif kind == "collinear":  # a third on one line
        Z[: n // 3] = np.outer(np.arange(n // 3) - n // 6, np.arange(1, d + 1))
    elif kind == "ulp_lattice":  # 1 + small multiples of one ulp
        Z = 1.0 + 2.0**-52 * Z
    return Z


@pytest.mark.parametrize("kind,d,n,F", [("one_plane", 4, 18, 2), ("two_planes", 4, 18, 2),
                                        ("collinear", 4, 18, 2), ("ulp_lattice", 4, 16, 2),
                                        pytest.param("one_plane", 5, 13, 1, marks=pytest.mark.slow),
                                        ("ulp_lattice", 5, 12, 1)])
def test_conservative_stand_ins_keep_the_kernel(kind, d, n, F, monkeypatch):
    """Data with many points on common hyperplanes / lines and a one-ulp lattice; the
    fast path's internal shortcuts replaced by their most conservative answers — every
    (row, vertex) pair near (the float filter keeps nothing out), ``tight_through``
    proving nothing, ``nonsingular`` always "maybe singular" (the cross products
    solve every basis) — and as they are: the kernel is the exact clipping's, bit for
    bit."""
    import rescon.geometry._candidates as cand
    import rescon.geometry._certify_nb as nb
    from tests.test_review_r2 import _fast_path_calls

    X = _on_hyperplanes(d, n, 0, kind)
    with monkeypatch.context() as mp:
        calls = _fast_path_calls(mp)
        rescon.safe_kernel(X, F)
    assert calls and calls[-1]  # the fast path certifies this kernel
    _same_as_clipping(X, F, monkeypatch)
    real_near = cand.near_pairs
    used = []

    def all_pairs(af, bf, af_abs, b_abs, Vx, coarse, c_err, c, floor):
        used.append(1)
        got = real_near(af, bf, af_abs, b_abs, Vx, coarse, c_err, c, floor)
        if got is None:
            return None
        r, v = np.meshgrid(np.arange(len(af)), np.arange(len(Vx)), indexing="ij")
        return r.ravel().astype(np.int64), v.ravel().astype(np.int64)

    with monkeypatch.context() as mp:
        mp.setattr(cand, "near_pairs", all_pairs)
        mp.setattr(nb, "tight_through", lambda through, basis, hs, vs:
                   np.zeros(len(hs), dtype=np.bool_))
        mp.setattr(nb, "nonsingular", lambda A, at, p: np.zeros(len(at), dtype=np.bool_))
        calls = _fast_path_calls(mp)
        K = _same_as_clipping(X, F, monkeypatch)
    assert used and calls[0]  # the stand-ins ran, and the fast path still certified
    from rescon_certificates.check import check

    got = check(K.certificate)
    assert got.verdict != "invalid", got.reason


@pytest.mark.slow
def test_rescon_s_star_is_brute_force_after_the_capped_prunes():
    """The decision engines' capped prunes (decide_step, min_cost_step): (ρ, s*) by
    ``method="search"`` and ``"auto"`` equal brute force on 300 random digraphs
    (n = 7–11, p 0.3–0.95, directed and undirected; 1100 of them agreed in review)."""
    import random

    import rescon
    from rescon.graphs.facts import clear_cache
    from tests.test_checker import digraph, in_masks, rand_edges, rho_and_s

    for seed in range(300):
        rng = random.Random(seed)
        n = rng.randint(7, 11)
        edges = rand_edges(rng, n, rng.uniform(0.3, 0.95), rng.random() < 0.4)
        G = digraph(n, edges)
        want = rho_and_s(n, in_masks(n, edges))
        for method in ("search", "auto"):
            clear_cache()
            rep = rescon.robustness(G, method=method)
            assert (rep.r_max, rep.s_max) == want, (seed, method)


@pytest.mark.parametrize("seed", [0, 1])
def test_d4_kernel_point_certificates_reject_a_point_just_outside(seed):
    """kernel_point in d = 4 with the "kernel" proof (52bc154): a vertex of Ψ is valid;
    the vertex pushed outward across a facet tight there by 2^-60 of the facet's normal
    is invalid (and the F + 1 claim is never valid)."""
    import copy

    from rescon_certificates.check import check

    from rescon.geometry.points import point_certificate

    X = np.random.default_rng(seed).normal(size=(14, 4))
    K = rescon.safe_kernel(X, 2)
    c = point_certificate(K, tuple(float(x) for x in K.vertices[0]))
    assert c["proof"]["method"] == "kernel"
    V = [tuple(Fraction(x) for x in v) for v in c["proof"]["vertices"]]
    f = c["proof"]["facets"][0]
    a, b = [Fraction(x) for x in f["a"]], Fraction(f["b"])
    v = next(v for v in V if sum(x * y for x, y in zip(a, v, strict=True)) == b)
    for eps, want in ((Fraction(0), "valid"), (Fraction(1, 2**60), "invalid")):
        bad = copy.deepcopy(c)
        bad["x"] = [str(x + eps * y) for x, y in zip(v, a, strict=True)]
        assert check(bad).verdict == want
    assert check({**copy.deepcopy(c), "F": 3}).verdict != "valid"
