"""The safe_kernel checker's vertex test with its exact filters (issue 13 §4): a facet
proved strictly slack at a vertex by a float evaluation with a rigorous error bound
(``kernels._surely_inside``) skips its exact slack, and a rank >= d modulo a prime
(``kernels._rank_at_least_mod_p``, a lower bound on the rank over Q) skips the exact
rank, also in ``_check_dim`` when dim = d.

Oracle: the same certificate checked with ``kernels.VERTEX_FILTERS`` off (the exact
path alone): verdict, reason and the unchecked parts must be identical, on valid,
unchecked and tampered certificates; the filters are also checked against exact
arithmetic on hostile inputs (slacks far below a float's resolution, huge and tiny
coordinates)."""

from __future__ import annotations

import copy
import random
from fractions import Fraction

import numpy as np
import pytest
from rescon_certificates import kernels
from rescon_certificates.check import check

import rescon


def _both(monkeypatch, cert: dict):
    """(check with the filters, check without them) as comparable tuples."""
    out = []
    for on in (True, False):
        with monkeypatch.context() as m:
            m.setattr(kernels, "VERTEX_FILTERS", on)
            r = check(copy.deepcopy(cert))
        out.append((r.verdict, r.reason, tuple(r.unchecked)))
    return out


def _bench(family: str, d: int, n: int, F: int) -> dict:
    from benchmarks.kernel_clouds import make_cloud

    return rescon.safe_kernel(make_cloud(family, d, n, F).X, F).certificate


@pytest.mark.parametrize(("family", "d", "n", "F"), [
    ("gaussian", 2, 50, 3), ("cube", 3, 40, 2), ("sphere", 3, 20, 1),
    ("gaussian", 4, 12, 1), ("cube", 5, 12, 1)])
def test_filters_change_no_verdict_on_bench_certificates(monkeypatch, family, d, n, F):
    cert = _bench(family, d, n, F)
    on, off = _both(monkeypatch, cert)
    assert on == off
    assert on[0] == "valid"  # d = 5 too since issue 13 §4 (the skeleton by double description)


def _tamper_vertex(cert: dict, i: int, shift: Fraction) -> dict:
    """vertices[i] moved by ``shift`` along the normal a / max|a_j| of a facet tight at it."""
    c = copy.deepcopy(cert)
    v = [Fraction(t) for t in c["vertices"][i]]
    for f in c["facets"]:
        a, b = [Fraction(t) for t in f["a"]], Fraction(f["b"])
        if sum(x * y for x, y in zip(a, v)) == b:
            top = max(abs(x) for x in a)
            c["vertices"][i] = [str(t + shift * x / top) for t, x in zip(v, a)]
            return c
    raise AssertionError("no tight facet")


@pytest.mark.parametrize("shift", [Fraction(1, 10**60), Fraction(-1, 10**60),
                                   Fraction(1, 10**6), Fraction(-1, 10**6)])
def test_filters_refute_the_same_tampered_vertex(monkeypatch, shift):
    """A vertex moved 1e-60 (far below a float's resolution) or 1e-6 along a tight
    facet's normal: outside (violates that facet) or inside (the tight rows lose rank):
    invalid with the same reason with and without the filters."""
    cert = rescon.safe_kernel(np.random.default_rng(5).standard_normal((14, 3)), 2).certificate
    for i in (0, len(cert["vertices"]) // 2):
        on, off = _both(monkeypatch, _tamper_vertex(cert, i, shift))
        assert on == off
        assert on[0] == "invalid"
        assert f"vertices[{i}]" in on[1]
        assert ("violates facets" if shift > 0 else "not a vertex of P") in on[1]


def test_filters_refute_a_wrong_dimension(monkeypatch):
    cert = rescon.safe_kernel(np.random.default_rng(2).standard_normal((10, 3)), 1).certificate
    on, off = _both(monkeypatch, {**cert, "dim": 2})
    assert on == off and on[0] == "invalid" and "dim = 2" in on[1]


def _exact_sign(a, g, v) -> int:
    s = sum(x * y for x, y in zip(a, v)) - g
    return (s > 0) - (s < 0)


def test_surely_inside_is_exact_on_hostile_slacks():
    """_surely_inside says True only where the exact slack a·v − g is < 0: slacks of
    ±1, ±tiny (down to 2^-700 relative) around 0, huge (2^590-bit) rows, coordinates
    near 2^-600 and 2^300, and zeros.  Where its inputs leave its range it returns None
    upstream (no filter)."""
    rng = random.Random(7)
    checked = hits = 0
    for trial in range(4000):
        d = rng.choice((2, 3, 5))
        scale = rng.choice((1, 2**100, 2**590))
        a = [rng.randint(-scale, scale) for _ in range(d)]
        if trial % 7 == 0:
            a[0] = 0
        vexp = rng.choice((0, -590, 290, -40))
        den = rng.randint(1, 2**200)
        X = [rng.randint(-2**200, 2**200) for _ in range(d)]
        if trial % 5 == 0:
            X[-1] = 0
        v = [Fraction(x, den) * Fraction(2) ** vexp for x in X]
        dot = sum(x * y for x, y in zip(a, v))
        eps = Fraction(rng.choice((0, 1, -1)), 2 ** rng.choice((0, 60, 300, 700)))
        g = dot + eps * (abs(dot) + 1)
        g = Fraction(round(g * 2**20), 2**20) if trial % 3 else g  # g need not be exact
        # the integer row and the scaled vertex, as _vertices_of_p forms them
        row = kernels._int_constraint(tuple(Fraction(t) for t in a), g)
        Dv = kernels._den_lcm([tuple(v)])
        Xs = kernels._scaled([tuple(v)], Dv)[0]
        rows = kernels._float_rows([row])
        fv = kernels._float_vertex(Xs, Dv)
        if rows is None or fv is None:
            continue
        checked += 1
        inside = kernels._surely_inside(rows, *fv)[0]
        if inside:
            hits += 1
            assert _exact_sign(row[0], Fraction(row[1]), [Fraction(x, Dv) for x in Xs]) < 0
    assert checked > 2000 and hits > 200  # the filter is exercised and often decides


def test_float_vertex_refuses_out_of_range_coordinates():
    assert kernels._float_vertex([1, 0], 2**700) is None  # 2^-700 < 2^-600
    assert kernels._float_vertex([2**400, 1], 1) is None  # > 2^300
    assert kernels._float_vertex([2**1100, 1], 3) is None  # overflows a float
    assert kernels._float_vertex([0, 3], 2) == ([0.0, 1.5, 1.0], 1.5)
    assert kernels._float_rows([([2**601, 1], 0)]) is None


@pytest.mark.parametrize("seed", range(8))
def test_box_tree_drops_only_strictly_slack_facets(seed):
    """_left_by_filters keeps, per vertex, every facet whose exact slack a·v − g is >= 0
    (violated or tight): clusters of exact vertices around a centre at 2^-400 .. 2^290
    scales, with exact zeros, and facets through vertices (tight), just beyond them
    (violated by 2^-200 relative) and far away (the ones the boxes should drop)."""
    rng = random.Random(100 + seed)
    d = rng.choice((2, 3, 4, 5))
    e = rng.choice((-400, -40, 0, 290))
    unit = Fraction(2) ** e
    centre = [Fraction(rng.randint(-2**40, 2**40), 2**40) for _ in range(d)]
    verts = []
    for _ in range(rng.choice((5, 40, 200))):
        v = [(c + Fraction(rng.randint(-2**30, 2**30), 2**50)) * unit for c in centre]
        if rng.random() < 0.2:
            v[rng.randrange(d)] = Fraction(0)
        verts.append(v)
    rows = []
    for _ in range(60):
        a = [Fraction(rng.randint(-2**20, 2**20)) for _ in range(d)]
        through = verts[rng.randrange(len(verts))]
        top = max(sum(x * y for x, y in zip(a, v)) for v in verts)
        g = rng.choice((sum(x * y for x, y in zip(a, through)),  # tight at one, violated at others
                        top,  # tight at the top vertex
                        top - abs(top) / 2**200,  # violated by a hair
                        top + abs(top) / 2**200,  # slack by a hair
                        top + abs(top) + unit))  # far
        row = kernels._int_constraint(tuple(a), g)
        if kernels._float_rows([row]) is not None:  # <= 600-bit entries: filtered
            rows.append(row)
    rows_f = kernels._float_rows(rows)
    SV = [(kernels._int_vector(tuple(v)), kernels._den_lcm([tuple(v)])) for v in verts]
    fvs = [kernels._float_vertex(X, Dv) for X, Dv in SV]
    assert len(rows) >= 20 and all(fv is not None for fv in fvs)
    left = kernels._left_by_filters(rows_f, fvs, len(rows), d, None)
    dropped = 0
    for v, kept in zip(verts, left):
        assert kept == sorted(kept)
        for j, (a, g) in enumerate(rows):
            if _exact_sign(a, Fraction(g), v) >= 0:
                assert j in kept
            dropped += j not in kept
    assert dropped > 0


def test_box_corners_stay_in_the_filter_range():
    """A float vertex coordinate is accepted in [2^-599, 2^299] only, so the boxes'
    corners, one float step outward, stay in [2^-600, 2^300] (_surely_inside's range)."""
    assert kernels._float_vertex([2**299, 1], 1) is not None
    assert kernels._float_vertex([2**299 + 2**247, 1], 1) is None
    assert kernels._float_vertex([1, 1], 2**599) is not None
    assert kernels._float_vertex([1, 1], 2**600) is None
    lo, hi = kernels._outward_box([[2.0 ** 299, -(2.0 ** -599), 0.0], [1.0, 2.0 ** -599, 0.0]], 3)
    assert hi[0] <= 2.0 ** 300 and 2.0 ** -600 <= -lo[1] and 2.0 ** -600 <= hi[1]
    assert lo[2] == hi[2] == 0.0


def test_box_tree_keeps_a_large_vertex_test_within_budget(monkeypatch):
    """sphere(4, 30, 3), 1583 vertices x 288 facets: the float filter vertex by vertex
    (no boxes: the test as it was) charges more than 10^6 work, with the box tree the
    vertex test fits (the normal fan is then what exceeds that budget)."""
    cert = _bench("sphere", 4, 30, 3)
    monkeypatch.setattr(kernels, "MAX_EVAL_WORK", 1_000_000)
    monkeypatch.setattr(kernels, "_LEAF_VERTICES", 10**9)
    before = check(copy.deepcopy(cert))
    assert before.verdict == "unchecked" and before.unchecked[0].startswith("vertices: each")
    monkeypatch.setattr(kernels, "_LEAF_VERTICES", 4)
    after = check(copy.deepcopy(cert))
    assert after.verdict == "unchecked"
    assert not any(u.startswith("vertices: each") for u in after.unchecked), after.unchecked


@pytest.mark.parametrize("seed", range(6))
def test_rank_mod_p_is_a_lower_bound(seed):
    """True only when the exact rank is >= d: rank-deficient integer rows with huge
    entries (combinations of d − 1 rows) are never accepted; random full-rank rows
    are."""
    rng = random.Random(seed)
    d = 3 + seed % 3
    big = 2 ** rng.choice((10, 200, 900))
    base = [[rng.randint(-big, big) for _ in range(d)] for _ in range(d - 1)]
    coef = [[rng.randint(-5, 5) for _ in base] for _ in range(8)]
    dep = [[sum(c * b[j] for c, b in zip(cs, base)) for j in range(d)] for cs in coef]
    rows = base + dep
    assert kernels._rank(rows) < d
    assert not kernels._rank_at_least_mod_p(rows, d)
    # rows that vanish mod p but not over Q: the lower bound may say False, never
    # wrongly True
    p = kernels._RANK_PRIME
    assert not kernels._rank_at_least_mod_p([[p * r for r in row] for row in rows], d)
    full = rows + [[rng.randint(-big, big) for _ in range(d)]]
    assert kernels._rank(full) == d
    assert kernels._rank_at_least_mod_p(full, d)
    assert kernels._rank_at_least_mod_p(iter(full), d)  # an iterator works too


def test_d5_unchecked_certificate_spends_few_exact_slacks(monkeypatch):
    """d = 5, n = 12 (512 vertices; 'unchecked' before issue 13 §4, valid now); the
    vertex test now evaluates exactly only the slacks the float
    filter cannot decide (the tight ones and a few near ones), not all |V| x |facets|
    (before: every one, the bulk of the 6 CPU-s on d = 5, n = 20)."""
    cert = _bench("cube", 5, 12, 1)
    calls = [0]
    dot = kernels._dot

    def counting(a, v):
        calls[0] += 1
        return dot(a, v)

    def run():
        calls[0] = 0
        with monkeypatch.context() as m:
            m.setattr(kernels, "_dot", counting)
            m.setattr(kernels, "_fan_in_kernel", lambda *a: "not run")
            m.setattr(kernels, "_in_kernel_halfspaces", lambda *a: "not run")
            m.setattr(kernels, "_skeleton", lambda *a: False)
            r = check(copy.deepcopy(cert))
        return r, calls[0]

    r_on, n_on = run()
    monkeypatch.setattr(kernels, "VERTEX_FILTERS", False)
    r_off, n_off = run()
    pairs = len(cert["vertices"]) * len(cert["facets"])
    assert n_off >= pairs
    assert n_on < pairs // 4, (n_on, pairs)
    assert (r_on.verdict, r_on.reason) == (r_off.verdict, r_off.reason)
    full = check(copy.deepcopy(cert))
    assert full.verdict == "valid"  # since issue 13 §4: the skeleton by double description


def _refute_by_axes_reference(pts, F, tests, names):
    """The axis test as it was (both counts by bisection for every test point)."""
    from bisect import bisect_left, bisect_right

    n = len(pts)
    for j in range(len(pts[0])):
        col = sorted(p[j] for p in pts)
        for x, name in zip(tests, names):
            for count, rel in ((n - bisect_left(col, x[j]), ">="),
                               (bisect_right(col, x[j]), "<=")):
                if count <= F:
                    return f"{name} {j} {rel} {count}"
    return None


@pytest.mark.parametrize("seed", range(40))
def test_axis_test_by_order_statistics_matches_bisection(seed):
    """_refute_by_axes compares x_j with the (F+1)-th smallest / largest coordinate and
    counts only to word a refutation: same first failure (point, coordinate, side,
    count) as counting every time, on integer clouds with ties, F = 0 .. n − 1."""
    rng = random.Random(seed)
    n, d = rng.randint(1, 9), rng.randint(1, 3)
    pts = [tuple(Fraction(rng.randint(-3, 3)) for _ in range(d)) for _ in range(n)]
    F = rng.randint(0, n - 1)
    tests = [tuple(Fraction(rng.randint(-8, 8), 2) for _ in range(d)) for _ in range(5)]
    names = [f"t{i}" for i in range(5)]
    want = _refute_by_axes_reference(pts, F, tests, names)
    try:
        kernels._refute_by_axes(pts, F, tests, names)
        got = None
    except Exception as e:  # check.py's Invalid
        m = __import__("re").search(r"(t\d) is .*y\[(\d)\] (>=|<=) .* holds only (\d+)", str(e))
        got = " ".join(m.groups())
    assert got == want


def test_degenerate_cloud_still_refutes_a_point_off_its_affine_hull():
    """The affine-hull test of (b) is skipped only when aff(X) = R^d: a flat cloud in
    R^3 still refutes a point 1e-30 off its plane; a full-dimensional one accepts it."""
    X = [[0, 0, 0], [4, 0, 0], [0, 4, 0], [4, 4, 0], [2, 1, 0], [1, 3, 0]]
    pts = [tuple(Fraction(t) for t in p) for p in X]
    x = (Fraction(2), Fraction(2), Fraction(1, 10**30))
    with pytest.raises(Exception, match="not in the affine hull of the points"):
        kernels._in_kernel_halfspaces(pts, 1, [x], ["x"], None, "vertices")
    pts[-1] = (Fraction(1), Fraction(3), Fraction(1))
    with pytest.raises(Exception, match="strictly outside a halfspace"):
        kernels._in_kernel_halfspaces(pts, 1, [x], ["x"], None, "vertices")
