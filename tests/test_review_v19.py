"""Hostile review V19 (issue 13): the checker's d >= 3 adjacency by double description
(``kernels._cone_rays``, tight-set matching in ``kernels._skeleton``) and the normal fan
pruned to the extreme rays of N_v (``_fan_in_kernel`` / ``_cells_min`` with ``faces``).

Oracles independent of the code under test: an exact brute force for the extreme rays
(every (k − 1)-subset of rows, null space by Gauss–Jordan in Fractions, both signs);
the Fraction inverse for ``_scaled_inverse``; the enumeration (b) for P ⊆ Ψ (the fan
monkeypatched away, its size limit lifted) on the kernel of F − 1 claimed for F."""

from __future__ import annotations

import copy
import itertools
import math
import random
import time
from fractions import Fraction

import numpy as np
import pytest
from rescon_certificates import kernels
from rescon_certificates.check import check

# --------------------------------------------------------------------------- #
# the double description against an exact brute force
# --------------------------------------------------------------------------- #


def _nullspace(M: list[list[int]], d: int) -> list[list[Fraction]]:
    A = [[Fraction(x) for x in r] for r in M]
    piv: list[int] = []
    r = 0
    for c in range(d):
        p = next((i for i in range(r, len(A)) if A[i][c]), None)
        if p is None:
            continue
        A[r], A[p] = A[p], A[r]
        A[r] = [x / A[r][c] for x in A[r]]
        for i in range(len(A)):
            if i != r and A[i][c]:
                f = A[i][c]
                A[i] = [x - f * y for x, y in zip(A[i], A[r])]
        piv.append(c)
        r += 1
    out = []
    for f in (c for c in range(d) if c not in piv):
        v = [Fraction(0)] * d
        v[f] = Fraction(1)
        for i, c in enumerate(piv):
            v[c] = -A[i][f]
        out.append(v)
    return out


def _prim(v: list[Fraction]) -> tuple[int, ...]:
    L = 1
    for x in v:
        L = L * x.denominator // math.gcd(L, x.denominator)
    w = [int(x * L) for x in v]
    g = 0
    for x in w:
        g = math.gcd(g, x)
    return tuple(x // g for x in w)


def _brute_rays(BE: list[list[int]], rows: list[list[int]], d: int) -> set[tuple[int, ...]]:
    """Extreme rays of {y : BE·y = 0, rows·y <= 0} (pointed): every 1-dimensional null
    space of BE plus k − 1 rows, signed into the cone."""
    k = d - len(BE)
    out = set()
    for sub in itertools.combinations(range(len(rows)), k - 1):
        ns = _nullspace(BE + [rows[i] for i in sub], d)
        if len(ns) != 1:
            continue
        for s in (1, -1):
            y = [s * x for x in ns[0]]
            if all(sum(a * b for a, b in zip(r, y)) <= 0 for r in rows):
                out.add(_prim(y))
    return out


def _same_rays(BE: list[list[int]], rows: list[list[int]], d: int) -> None:
    got = kernels._cone_rays(BE, rows, d, [0, 10 ** 13], 1)
    want = _brute_rays(BE, rows, d)
    assert set(got.values()) == want and len(got) == len(want), (BE, rows)
    for z, r in got.items():  # the key is exactly the set of rows tight at the ray
        assert z == sum(1 << i for i, a in enumerate(rows) if kernels._dot(a, r) == 0)
        assert not any(kernels._dot(e, r) for e in BE)


@pytest.mark.parametrize("seed", range(24))
def test_cone_rays_match_an_exact_brute_force(seed):
    """Random pointed cones in d = 2–6, with equalities, duplicated and antiparallel rows,
    2^80-scaled entries (the fraction-free inverse and the ray combinations on big
    integers); held on 2983 cones in the review (24 seeds × ~12 here)."""
    rng = random.Random(1900 + seed)
    done = 0
    while done < 12:
        d = rng.choice((2, 3, 4, 5, 5, 6))
        ne = rng.choice((0, 0, 0, 1, 2)) if d > 3 else 0
        BE = [[rng.randint(-3, 3) for _ in range(d)] for _ in range(ne)]
        if BE and kernels._rank(BE) < ne:
            continue
        m = rng.randint(d - ne, d - ne + (5 if d == 6 else 7))
        scale = rng.choice((1, 1, 2 ** 80))
        rows = [[rng.randint(-3, 3) * rng.choice((1, scale)) for _ in range(d)]
                for _ in range(m)]
        if rng.random() < 0.3:
            rows += [list(rows[0]), list(rows[0]), [-x for x in rows[-1]]]
        if kernels._rank(BE + rows) < d:
            continue
        _same_rays(BE, rows, d)
        done += 1


def _polar_rows(kind: str, d: int) -> list[list[int]]:
    """Rows a = −(p, 1) for the points p of a polytope in R^(d−1): the cone
    {y : a·y <= 0} is the polar of the cone over it (rays = its facets)."""
    m = d - 1
    if kind == "cube":
        pts = [list(p) for p in itertools.product((-1, 1), repeat=m)]
    elif kind == "cross":
        pts = [[s * (i == j) for j in range(m)] for i in range(m) for s in (-1, 1)]
    else:
        pts = [[t ** e for e in range(1, m + 1)] for t in range(-3, 5)]
    return [[-x for x in p] + [-1] for p in pts]


@pytest.mark.parametrize("d", [3, 4, 5])
@pytest.mark.parametrize("kind", ["cube", "cross", "cyclic"])
@pytest.mark.parametrize("order", ["redundant-first", "reversed", "interleaved"])
def test_cone_rays_adversarial_row_order(kind, d, order):
    """Degenerate cones (every ray on many rows) with redundant rows (positive sums of
    two rows: never tight alone), duplicates and the initial simplicial cone taken from
    rows that are not facets of T."""
    rows = _polar_rows(kind, d)
    red = [[x + y for x, y in zip(a, b)] for a, b in zip(rows, rows[1:] + rows[:1])]
    red = red[:6] if d == 5 else red  # the brute force is C(#rows, 4) null spaces
    if order == "redundant-first":
        rows = red + rows + rows[:2]
    elif order == "reversed":
        rows = (rows + red)[::-1]
    else:
        rows = [r for pair in zip(rows, red) for r in pair] + rows[len(red):]
    _same_rays([], rows, d)


def test_cone_rays_flat_cone_with_equalities():
    """T inside an equality plane, the facets of the square written as pairs of
    antiparallel rows plus their sums (T is a 2-dimensional cone in R^4)."""
    BE = [[1, 1, 1, 1], [0, 1, -1, 2]]
    rows = [[1, 0, 0, 0], [0, 0, 1, 0], [-1, 0, 0, 0], [1, 0, 1, 0], [0, 2, 0, 1]]
    rows += [[-x for x in rows[3]]]
    _same_rays(BE, rows, 4)


@pytest.mark.parametrize("seed", range(4))
def test_scaled_inverse_is_exact(seed):
    """M·X = D·I with |D| = |det M| (Bareiss divisions exact), including zero pivots that
    force row swaps and 2^200 entries."""
    rng = random.Random(seed)
    for _ in range(30):
        m = rng.randint(1, 6)
        M = [[rng.choice((0, 0, 1, -1, 2, 2 ** 200 + 1)) for _ in range(m)] for _ in range(m)]
        if kernels._rank(M) < m:
            continue
        D, X = kernels._scaled_inverse(M)
        for i in range(m):
            for j in range(m):
                assert sum(M[i][t] * X[t][j] for t in range(m)) == D * (i == j)
        A = [[Fraction(x) for x in r] for r in M]
        det = Fraction(1)
        for c in range(m):
            p = next(r for r in range(c, m) if A[r][c])
            if p != c:
                A[c], A[p] = A[p], A[c]
                det = -det
            det *= A[c][c]
            for r in range(c + 1, m):
                f = A[r][c] / A[c][c]
                A[r] = [x - f * y for x, y in zip(A[r], A[c])]
        assert abs(D) == abs(det)


def _cyclic_polar(m: int) -> list[list[int]]:
    """T = {y : (1, t, t², t³, t⁴)·y >= 0, t = −m/2 .. m/2 − 1} in R^5: the polar of the
    cone over the cyclic polytope C(m, 4), m(m − 3)/2 extreme rays."""
    return [[-1, -t, -t * t, -t ** 3, -t ** 4] for t in range(-(m // 2), m - m // 2)]


def test_cone_rays_many_rays_correct_and_metered():
    """1710 rays (C(60, 4)'s facets) computed, all on the cone with 4 tight rows; with
    the checker's limit the meter stops m = 160 at once (no loop, no memory blow-up)."""
    rows = _cyclic_polar(60)
    t0 = time.process_time()
    got = kernels._cone_rays([], rows, 5, [0, 10 ** 12], kernels._bit_size(rows))
    assert len(got) == 60 * 57 // 2
    assert all(z.bit_count() == 4 for z in got)
    rows = _cyclic_polar(160)
    with pytest.raises(kernels._OverBudget):
        kernels._cone_rays([], rows, 5, [0, kernels.MAX_POLY_WORK], kernels._bit_size(rows))
    assert time.process_time() - t0 < 20


def test_cone_rays_charge_is_not_far_above_the_real_work():
    """V19: every pos × neg pair was charged a full scan of the rays (28–66× the scan
    done): 40 tight facets in d = 5 (740 rays, ~0.1 CPU-s) were 'unchecked'."""
    rows = _cyclic_polar(40)
    meter = [0, kernels.MAX_POLY_WORK]
    got = kernels._cone_rays([], rows, 5, meter, kernels._bit_size(rows))
    assert len(got) == 40 * 37 // 2


def _random_fan_case(rng: random.Random):
    """(rows, gens, zs, d): N = cone over a polytope in R^(d−1) × {1} (cube,
    cross-polytope or random points), gens its extreme rays (sheared), zs their tight
    sets over N's facets (brute force), rows = q·g for random crossing q."""
    d = rng.choice((3, 4, 5))
    m = d - 1
    kind = rng.choice(("cube", "cross", "rand"))
    if kind == "cube":
        pts = [list(p) for p in itertools.product((-1, 1), repeat=m)]
    elif kind == "cross":
        pts = [[s * (i == j) for j in range(m)] for i in range(m) for s in (-1, 1)]
    else:
        pts = [[rng.randint(-3, 3) for _ in range(m)] for _ in range(d + 4)]
    gens0 = [p + [1] for p in pts]
    if kernels._rank(gens0) < d:
        return None
    ys = sorted(_brute_rays([], gens0, d))  # N = {w : w·y <= 0}
    z0 = [sum(1 << r for r, y in enumerate(ys) if kernels._dot(g, y) == 0) for g in gens0]
    keep = [s for s, z in enumerate(z0) if not any(
        z2 & z == z and (z2 != z or s2 < s) for s2, z2 in enumerate(z0) if s2 != s)]
    U = [[int(i == j) for j in range(d)] for i in range(d)]
    for _ in range(d):
        i, j = rng.sample(range(d), 2)
        U[i] = [x + rng.choice((-1, 1)) * y for x, y in zip(U[i], U[j])]
    gens = [[kernels._dot(row, gens0[s]) for row in U] for s in keep]
    rows = []
    for _ in range(rng.randint(1, 9)):
        q = [rng.randint(-3, 3) for _ in range(d)]
        r = [kernels._dot(q, g) for g in gens]
        if min(r) < 0 < max(r):
            rows.append(r)
    return (rows, gens, [z0[s] for s in keep], d) if rows else None


@pytest.mark.parametrize("seed", range(8))
def test_cells_min_with_faces_equals_all_pairs(seed):
    """The fan's double-description split (zs given) finds the same smallest cell count
    as the split into all pairs (zs None), with no bound; review: 380 cones, 0 diffs."""
    rng = random.Random(7700 + seed)
    done = 0
    while done < 6:
        case = _random_fan_case(rng)
        if case is None:
            continue
        rows, gens, zs, d = case
        a = kernels._cells_min(0, rows, gens, d, 10 ** 6, [0, 10 ** 15], 1, 1, zs)
        b = kernels._cells_min(0, rows, gens, d, 10 ** 6, [0, 10 ** 15], 1, 1, None)
        assert a is not None and b is not None and a[0] == b[0], (rows, gens, zs)
        done += 1


# --------------------------------------------------------------------------- #
# whole certificates: correct ones never invalid, tampered ones invalid
# --------------------------------------------------------------------------- #


def _cloud(name: str, d: int) -> np.ndarray:
    rng = np.random.default_rng(d)
    cube = np.array(list(itertools.product((-1, 1), repeat=d)), float)
    cross = np.vstack([np.eye(d), -np.eye(d)])
    g = rng.standard_normal((d + 5, d))
    if name == "cube":
        return cube
    if name == "cube2x":
        return np.vstack([cube, cube])
    if name == "cube+cross":
        return np.vstack([cube, 2 * cross])
    if name == "grid":
        grid = np.array(list(itertools.product((0, 1, 2), repeat=min(d, 3))), float)
        if d > 3:
            grid = np.hstack([grid, rng.integers(0, 2, (len(grid), d - 3))])
        return grid
    if name == "int":
        return rng.integers(-2, 3, (d + 6, d)).astype(float)
    if name == "mixed":
        g[:, 0] *= 2.0 ** 1000
        g[:, -1] *= 2.0 ** -1000
        return g
    if name == "flat":
        return np.hstack([rng.standard_normal((d + 5, d - 1)), np.zeros((d + 5, 1))])
    assert name == "sym"
    return np.vstack([g, -g])


_CORRECT = [(name, d, F) for d in (3, 4) for name, Fs in (
    ("cube", (0, 1, 2)), ("cube2x", (1, 3)), ("cube+cross", (1, 2, 3)), ("grid", (1, 4)),
    ("int", (1, 2)), ("mixed", (0, 1)), ("flat", (1,)), ("sym", (1, 3))) for F in Fs] + [
    ("cube", 5, 1), ("cube", 5, 4), ("cube+cross", 5, 1), ("grid", 5, 1), ("grid", 5, 3),
    ("int", 5, 1), ("mixed", 5, 1), ("flat", 5, 1),
    pytest.param("sym", 5, 1, marks=pytest.mark.slow)]


def _cert(name: str, d: int, F: int) -> dict:
    import rescon

    return rescon.safe_kernel(_cloud(name, d), F).certificate


def _variants(c: dict) -> list[tuple[str, dict]]:
    """The same (correct) claim written differently: duplicated facets, facets scaled by
    2^400 and by 1/3, a zero facet 0·x <= 0 (tight everywhere), a zero equality, shuffled
    facets, permuted vertices with reversed adjacency lists, an equality as two facets."""
    d = len(c["points"][0])
    f = c["facets"]
    out = [("as is", copy.deepcopy(c))]
    out.append(("duplicated facets", {**copy.deepcopy(c), "facets": f + [f[0], f[-1], f[0]]}))
    out.append(("scaled facets", {**copy.deepcopy(c), "facets": [
        {"a": [str(Fraction(x) * s) for x in g["a"]], "b": str(Fraction(g["b"]) * s)}
        for g, s in zip(f, itertools.cycle((Fraction(2 ** 400), Fraction(1, 3))))]}))
    out.append(("zero facet", {**copy.deepcopy(c), "facets": f + [{"a": ["0"] * d, "b": "0"}]}))
    out.append(("zero equality", {**copy.deepcopy(c), "equalities": c["equalities"] + [
        {"a": ["0"] * d, "b": "0"}]}))
    perm = list(range(len(f)))
    random.Random(len(f)).shuffle(perm)
    out.append(("shuffled facets", {**copy.deepcopy(c), "facets": [f[i] for i in perm]}))
    perm = list(range(len(c["vertices"])))
    random.Random(len(perm)).shuffle(perm)
    inv = {p: i for i, p in enumerate(perm)}
    out.append(("permuted vertices", {**copy.deepcopy(c),
                                      "vertices": [c["vertices"][p] for p in perm],
                                      "adjacency": [[inv[j] for j in reversed(
                                          c["adjacency"][p])] for p in perm]}))
    if c["equalities"]:
        e = c["equalities"][0]
        out.append(("equality as two facets", {
            **copy.deepcopy(c), "equalities": c["equalities"][1:],
            "facets": f + [e, {"a": [str(-Fraction(x)) for x in e["a"]],
                               "b": str(-Fraction(e["b"]))}]}))
    return out


@pytest.mark.parametrize("name,d,F", _CORRECT)
def test_correct_certificates_are_valid(name, d, F):
    """Degenerate vertices (cubes, cross-polytopes, grids, duplicated and symmetric
    clouds), flat kernels, 2^±1000 columns: every rewriting of rescon's certificate is
    valid ('invalid' would break the contract), except one rewriting that is only
    unchecked (:func:`test_zero_facet_keeps_simple_vertices_simple`)."""
    c = _cert(name, d, F)
    for how, v in _variants(c):
        res = check(v)
        if (name, d, F, how) == ("mixed", 5, 1, "zero facet"):
            assert res.verdict in ("valid", "unchecked"), res.reason  # valid once fixed
            continue
        assert res.verdict == "valid", (how, res.verdict, res.reason, res.unchecked)


def test_zero_facet_keeps_simple_vertices_simple():
    """V19: a facet 0·x <= 0 made every vertex non-simple (double description at all of
    them: 'unchecked')."""
    c = _cert("mixed", 5, 1)
    d = len(c["points"][0])
    c["facets"] = c["facets"] + [{"a": ["0"] * d, "b": "0"}]
    res = check(c)
    assert res.verdict == "valid", res.unchecked


def test_facets_with_a_common_factor_cost_nothing():
    """V19: facets written as 2^3000·(a, b) kept the factor (3000-bit fan generators:
    'unchecked')."""
    c = _cert("cube", 5, 4)
    s = Fraction(2 ** 3000)
    c["facets"] = [{"a": [str(Fraction(x) * s) for x in f["a"]], "b": str(Fraction(f["b"]) * s)}
                   for f in c["facets"]]
    res = check(c)
    assert res.verdict == "valid", res.unchecked


def test_duplicated_points_do_not_multiply_the_fan():
    """V19: the fan split along every copy of a repeated point (cube(5) doubled, F = 9:
    'unchecked'; cube(5), F = 4, the same kernel, valid in ~1 s)."""
    import rescon

    cube = np.array(list(itertools.product((-1, 1), repeat=5)), float)
    c = rescon.safe_kernel(np.vstack([cube, cube]), 9).certificate
    res = check(c)
    assert res.verdict == "valid", res.unchecked


def _by_enumeration(cert: dict, monkeypatch) -> str:
    with monkeypatch.context() as m:
        m.setattr(kernels, "_fan_in_kernel", lambda pts, F, V, tight, names, ctx, *_:
                  kernels._in_kernel_halfspaces(pts, F, V, names, ctx, "vertices"))
        m.setattr(kernels, "MAX_HALFSPACE_WORK", 10 ** 9)
        return check(copy.deepcopy(cert)).verdict


_SHIFTED = [("cube", 4, F) for F in (1, 2, 3, 4)] + [
    ("cube2x", 4, F) for F in (2, 3, 5)] + [("cube+cross", 4, F) for F in (2, 3, 4, 5)] + [
    ("grid", 4, F) for F in (2, 3, 6)] + [("sym", 4, F) for F in (2, 3, 4)] + [
    ("int", 4, 2), ("grid", 3, 3), ("grid", 3, 6), ("sym", 3, 3), ("cube+cross", 3, 3),
    ("cube", 5, 2), ("cube", 5, 4), ("cube+cross", 5, 2), ("grid", 5, 2)]


@pytest.mark.parametrize("name,d,F", _SHIFTED)
def test_kernel_of_F_minus_1_claimed_for_F(name, d, F, monkeypatch):
    """P = Ψ(F − 1) with its correct adjacency claimed as Ψ(F): step 2 passes (each
    facet has <= F − 1 points outside), so only the pruned normal fan decides P ⊆ Ψ(F);
    it must agree with the enumeration (b) — invalid when some vertex has depth <= F,
    valid when Ψ(F − 1) = Ψ(F).  (Review: 91 such claims in d = 3–5, 0 disagreements,
    with and without the pruning.)"""
    c = _cert(name, d, F - 1)
    assert c["kind"] == "safe_kernel" and c["dim"] == d
    c["F"] = F
    got = check(copy.deepcopy(c)).verdict
    assert got in ("valid", "invalid")
    assert got == _by_enumeration(c, monkeypatch)


def _fr(c: dict, key: str) -> list:
    return [[Fraction(x) for x in v] for v in c[key]]


def _tampered(c: dict) -> list[tuple[str, dict]]:
    """Tamperings at a most degenerate vertex (most tight facets) and its neighbours."""
    V = _fr(c, "vertices")
    fac = [([Fraction(x) for x in f["a"]], Fraction(f["b"])) for f in c["facets"]]
    tight = [[t for t, (a, b) in enumerate(fac) if sum(x * y for x, y in zip(a, v)) == b]
             for v in V]
    i = max(range(len(V)), key=lambda t: len(tight[t]))
    adj = c["adjacency"]
    j = adj[i][0]
    out = []
    # a vertex dropped with its adjacency entries (the region near it goes missing)
    t = copy.deepcopy(c)
    del t["vertices"][i]
    t["adjacency"] = [[x - (x > i) for x in a if x != i] for s, a in enumerate(adj) if s != i]
    out.append(("vertex dropped", t))
    # a spurious vertex: the midpoint of an edge, joined to both ends
    t = copy.deepcopy(c)
    t["vertices"].append([str((x + y) / 2) for x, y in zip(V[i], V[j])])
    m = len(V)
    t["adjacency"][i] = [m if x == j else x for x in adj[i]]
    t["adjacency"][j] = [m if x == i else x for x in adj[j]]
    t["adjacency"].append([i, j])
    out.append(("edge midpoint as a vertex", t))
    # a vertex moved by 10^-30 (rational) along the first axis
    t = copy.deepcopy(c)
    t["vertices"][i] = [str(V[i][0] + Fraction(1, 10 ** 30))] + c["vertices"][i][1:]
    out.append(("vertex moved", t))
    # two adjacency lists swapped
    k = next(s for s in range(len(V)) if sorted(adj[s]) != sorted(adj[i]))
    t = copy.deepcopy(c)
    t["adjacency"][i], t["adjacency"][k] = adj[k], adj[i]
    out.append(("adjacency swapped", t))
    # a neighbour listed twice, a non-neighbour, the vertex itself
    for how, lst in (("neighbour twice", adj[i] + adj[i][:1]),
                     ("self as neighbour", adj[i][1:] + [i]),
                     ("neighbour dropped", adj[i][1:])):
        t = copy.deepcopy(c)
        t["adjacency"][i] = lst
        out.append((how, t))
    # a facet tight at the degenerate vertex removed / loosened / tightened
    s = tight[i][0]
    t = copy.deepcopy(c)
    del t["facets"][s]
    out.append(("facet removed", t))
    for how, db in (("facet loosened", Fraction(1, 10 ** 30)),
                    ("facet tightened", -Fraction(1, 10 ** 30))):
        t = copy.deepcopy(c)
        t["facets"][s] = {"a": c["facets"][s]["a"], "b": str(fac[s][1] + db)}
        out.append((how, t))
    return out


@pytest.mark.parametrize("name,d,F", [("cube+cross", 4, 3), ("grid", 4, 4), ("sym", 4, 2),
                                      ("cube", 5, 4), ("grid", 5, 1),
                                      pytest.param("sym", 5, 1, marks=pytest.mark.slow)])
def test_tampered_certificates_are_invalid(name, d, F):
    c = _cert(name, d, F)
    assert check(copy.deepcopy(c)).verdict == "valid"
    for how, t in _tampered(c):
        res = check(t)
        assert res.verdict == "invalid", (how, res.verdict, res.reason)


# --------------------------------------------------------------------------- #
# no regression in d <= 4
# --------------------------------------------------------------------------- #


@pytest.mark.parametrize("family", ["cube", "gaussian"])
def test_d4_bench_clouds_stay_valid(family):
    """cube/gaussian(4, 30, 3): valid; review: 0.86 / 0.84 CPU-s (1.72 / 1.62 at
    1650523, before C6; load 4.8)."""
    import rescon
    from benchmarks.kernel_clouds import make_cloud

    c = rescon.safe_kernel(make_cloud(family, 4, 30, 3).X, 3).certificate
    t0 = time.process_time()
    res = check(c)
    assert res.verdict == "valid", (res.reason, res.unchecked)
    assert time.process_time() - t0 < 10
