"""The checker's skeleton in d = 5 (issue 13 §4): the extreme rays of the tangent cones
at degenerate vertices by the double description method (``kernels._cone_rays``)
instead of the C(t, d − 1) enumeration of ``kernels._edge_directions``.

Oracle: the brute force ``_edge_directions`` (every null direction of d − 1 rows) on
cones over cubes, cross-polytopes, cyclic polytopes and random 0/±1 sets, with
duplicated and redundant rows and with equalities — the ray sets must be identical."""

from __future__ import annotations

import itertools
import random

import pytest
from rescon_certificates import kernels


def _facets(points: list[list[int]], d: int) -> list[list[int]]:
    """The facet normals a (a·p <= 0 on the points) of the cone over the points in R^d
    (brute force over (d − 1)-subsets), primitive and distinct."""
    out = set()
    for sub in itertools.combinations(points, d - 1):
        a = kernels._normal([list(p) for p in sub], d)
        if not any(a):
            continue
        s = [kernels._dot(a, p) for p in points]
        if max(s) <= 0:
            out.add(kernels._primitive(a))
        elif min(s) >= 0:
            out.add(kernels._primitive([-t for t in a]))
    return [list(a) for a in sorted(out)]


def _base(kind: str, m: int, rng: random.Random) -> list[list[int]]:
    """Points of a polytope in R^m (integer coordinates)."""
    if kind == "cube":
        return [list(p) for p in itertools.product((-1, 1), repeat=m)]
    if kind == "cross":
        return [[s * (i == j) for j in range(m)] for i in range(m) for s in (-1, 1)]
    if kind == "cyclic":
        ts = rng.sample(range(-4, 5), m + 3)
        return [[t ** e for e in range(1, m + 1)] for t in ts]
    if kind == "simplex":
        return [[0] * m] + [[int(i == j) for j in range(m)] for i in range(m)]
    assert kind == "random01"
    pts = {tuple(rng.choice((-1, 0, 1)) for _ in range(m)) for _ in range(3 * m)}
    return [list(p) for p in pts]


def _cone(kind: str, d: int, rng: random.Random) -> list[list[int]]:
    """The rows of a pointed cone in R^d: the facets of the cone over a polytope in
    R^(d − 1) (its points get last coordinate 1), a random unimodular-ish change of
    coordinates, duplicated rows, positive combinations of rows (redundant) and
    shuffled."""
    pts = [p + [1] for p in _base(kind, d - 1, rng)]
    rows = _facets(pts, d)
    if not rows or kernels._rank(rows) < d:
        return []
    U = [[int(i == j) for j in range(d)] for i in range(d)]
    for _ in range(d):  # shear: a row operation keeps the cone's combinatorics
        i, j = rng.sample(range(d), 2)
        U[i] = [x + rng.choice((-1, 1)) * y for x, y in zip(U[i], U[j])]
    rows = [[kernels._dot(a, col) for col in zip(*U)] for a in rows]
    extra = [list(rng.choice(rows)) for _ in range(2)]
    extra += [[2 * x + 3 * y for x, y in zip(*rng.sample(rows, 2))] for _ in range(2)]
    rows = rows + extra
    rng.shuffle(rows)
    return rows


def _check_same(BE: list[list[int]], rows: list[list[int]], d: int) -> None:
    brute = kernels._edge_directions(BE, rows, d)
    got = kernels._cone_rays(BE, rows, d, [0, 10 ** 12], 1)
    assert set(got.values()) == brute
    for z, r in got.items():  # the keys are the rows tight at each ray
        assert z == sum(1 << i for i, a in enumerate(rows) if kernels._dot(a, r) == 0)


@pytest.mark.parametrize("d", [3, 4, 5])
@pytest.mark.parametrize("kind", ["cube", "cross", "cyclic", "simplex", "random01"])
def test_double_description_matches_the_brute_force(kind, d):
    rng = random.Random(f"{kind}-{d}")
    done = 0
    for _ in range(6):
        rows = _cone(kind, d, rng)
        if rows:
            _check_same([], rows, d)
            done += 1
    assert done >= 3


@pytest.mark.parametrize("d", [3, 4, 5])
def test_double_description_with_equalities(d):
    """T in R^(d + 1) with one equality: the cone of R^d embedded in a hyperplane."""
    rng = random.Random(d)
    for kind in ("cube", "cross", "cyclic", "random01"):
        rows = _cone(kind, d, rng)
        if not rows:
            continue
        e = [rng.randint(-2, 2) for _ in range(d)] + [1]  # y_(d+1) = −e'·y
        BE = [e]
        lifted = [a + [rng.randint(-3, 3)] for a in rows]
        _check_same(BE, lifted, d + 1)


@pytest.mark.parametrize("seed", range(40))
def test_double_description_on_random_rows(seed):
    """Random small rows (often {0}, or a cone with few rays), rank d."""
    rng = random.Random(seed)
    d = rng.choice((3, 4, 5))
    rows = [[rng.randint(-2, 2) for _ in range(d)] for _ in range(rng.randint(d, d + 8))]
    if kernels._rank(rows) < d:
        return
    _check_same([], rows, d)


def test_double_description_meter_stops_it():
    rows = _cone("cube", 5, random.Random(1))
    with pytest.raises(kernels._OverBudget):
        kernels._cone_rays([], rows, 5, [0, 100], 1)


# --------------------------------------------------------------------------- #
# whole certificates in d = 5
# --------------------------------------------------------------------------- #


def _bench(family: str, d: int, n: int, F: int) -> dict:
    import rescon
    from benchmarks.kernel_clouds import make_cloud

    return rescon.safe_kernel(make_cloud(family, d, n, F).X, F).certificate


@pytest.fixture(scope="module")
def cert5() -> dict:
    """gaussian(d = 5, n = 10, F = 1): 186 vertices, some degenerate (the adjacency was
    beyond MAX_POLY_WORK by the C(t, 4) enumeration: "unchecked" before issue 13 §4)."""
    return _bench("gaussian", 5, 10, 1)


def _check(cert: dict):
    import copy

    from rescon_certificates.check import check

    return check(copy.deepcopy(cert))


def test_d5_bench_certificate_is_valid(cert5):
    res = _check(cert5)
    assert res.verdict == "valid", res.unchecked or res.reason
    assert "normal fan" in res.reason


def _simple_and_degenerate(cert: dict) -> tuple[int, int]:
    """A vertex with d tight facets and one with more."""
    from fractions import Fraction

    d = len(cert["points"][0])
    fac = [([Fraction(x) for x in f["a"]], Fraction(f["b"])) for f in cert["facets"]]
    tight = [sum(sum(x * Fraction(y) for x, y in zip(a, v)) == b for a, b in fac)
             for v in cert["vertices"]]
    simple = next(i for i, t in enumerate(tight) if t == d)
    degen = max(range(len(tight)), key=tight.__getitem__)
    assert tight[degen] > d
    return simple, degen


@pytest.mark.parametrize("which", [0, 1])
def test_d5_adjacency_tampering_is_refuted(cert5, which):
    import copy

    i = _simple_and_degenerate(cert5)[which]
    adj = cert5["adjacency"]
    # a neighbour removed
    c = copy.deepcopy(cert5)
    c["adjacency"][i] = adj[i][1:]
    res = _check(c)
    assert res.verdict == "invalid" and "no vertex listed along the edge" in res.reason
    # a wrong neighbour (a vertex not joined to vertices[i]), or vertices[i] itself
    far = next(j for j in range(len(adj)) if j != i and j not in adj[i])
    for bad in (far, i):
        c = copy.deepcopy(cert5)
        c["adjacency"][i] = [bad] + adj[i][1:]
        res = _check(c)
        assert res.verdict == "invalid" and "not joined" in res.reason, res.reason
    # a neighbour listed twice
    c = copy.deepcopy(cert5)
    c["adjacency"][i] = adj[i] + adj[i][:1]
    res = _check(c)
    assert res.verdict == "invalid" and "same edge" in res.reason, res.reason


@pytest.mark.parametrize("which", [0, 1])
def test_d5_missing_or_moved_vertex_is_refuted(cert5, which):
    import copy
    from fractions import Fraction

    i = _simple_and_degenerate(cert5)[which]
    # vertices[i] left out (its edges' other ends lose a neighbour)
    c = copy.deepcopy(cert5)
    del c["vertices"][i]
    c["adjacency"] = [[j - (j > i) for j in a if j != i]
                      for t, a in enumerate(cert5["adjacency"]) if t != i]
    res = _check(c)
    assert res.verdict == "invalid", res.reason
    # vertices[i] moved a little
    c = copy.deepcopy(cert5)
    v = [Fraction(x) for x in c["vertices"][i]]
    v[0] += Fraction(1, 10**40)
    c["vertices"][i] = [str(x) for x in v]
    res = _check(c)
    assert res.verdict == "invalid", res.reason


def test_d5_fan_pruning_agrees_with_the_enumeration(monkeypatch, cert5):
    """The normal fan with its generators pruned to extreme rays (faces from the
    adjacency) against (b), on the kernel and on a false claim (Ψ for F = 2)."""
    import copy

    from rescon_certificates.check import check

    for cert, want in ((cert5, "valid"), ({**copy.deepcopy(cert5), "F": 2}, "invalid")):
        assert _check(cert).verdict == want
        with monkeypatch.context() as m:
            m.setattr(kernels, "_fan_in_kernel",
                      lambda pts, F, V, tight, names, ctx, *_:
                      kernels._in_kernel_halfspaces(pts, F, V, names, ctx, "vertices"))
            m.setattr(kernels, "MAX_HALFSPACE_WORK", 10**9)
            assert check(copy.deepcopy(cert)).verdict == want


def _vertex_test_inputs(cert: dict):
    from fractions import Fraction

    d = len(cert["points"][0])
    Ei = [kernels._int_constraint(tuple(Fraction(x) for x in e["a"]), Fraction(e["b"]))
          for e in cert["equalities"]]
    Fi = [kernels._int_constraint(tuple(Fraction(x) for x in f["a"]), Fraction(f["b"]))
          for f in cert["facets"]]
    V = [tuple(Fraction(x) for x in v) for v in cert["vertices"]]
    return Ei, Fi, V, d


class _Ctx:
    def __init__(self) -> None:
        self.parts: list[str] = []

    def trust(self, name: str, part: str) -> None:
        self.parts.append(part)


@pytest.mark.slow
def test_vertex_test_meter_runs_past_the_a_priori_estimate(monkeypatch):
    """The vertex test beyond its a-priori estimate (#V x #constraints at the full bit
    size): with the float filter it is charged as it runs and decides (unchecked
    before: d = 5, n = 20, F = 2 needed 2.3·10^7 > 2·10^7 by the estimate); without the
    filter, or with too small a limit, it stays unchecked; a moved vertex is refuted."""
    from fractions import Fraction

    Ei, Fi, V, d = _vertex_test_inputs(_bench("gaussian", 5, 20, 2))
    monkeypatch.setattr(kernels, "MAX_EVAL_WORK", 10**9)
    ref = kernels._vertices_of_p(Ei, Fi, V, d, _Ctx())
    bits = max(kernels._bit_size([a + [b] for a, b in Ei + Fi]),
               kernels._bit_size([kernels._int_vector(v) + [kernels._den_lcm([v])] for v in V]))
    est = kernels._cost(len(V) * (len(Ei) + len(Fi) + d * d), 2 * bits)
    assert est > 20_000_000  # the real limit
    monkeypatch.setattr(kernels, "MAX_EVAL_WORK", 20_000_000)
    ctx = _Ctx()
    assert kernels._vertices_of_p(Ei, Fi, V, d, ctx) == ref and not ctx.parts
    bad = list(V)
    bad[3] = (bad[3][0] + Fraction(1, 10**30),) + bad[3][1:]
    with pytest.raises(kernels.Invalid):
        kernels._vertices_of_p(Ei, Fi, bad, d, _Ctx())
    monkeypatch.setattr(kernels, "MAX_EVAL_WORK", est // 20)
    ctx = _Ctx()
    assert kernels._vertices_of_p(Ei, Fi, V, d, ctx) is None and ctx.parts
    monkeypatch.setattr(kernels, "MAX_EVAL_WORK", 20_000_000)
    monkeypatch.setattr(kernels, "VERTEX_FILTERS", False)
    ctx = _Ctx()
    assert kernels._vertices_of_p(Ei, Fi, V, d, ctx) is None and ctx.parts


@pytest.mark.slow
def test_d5_n30_certificates_have_their_polytope_checked():
    """d = 5, n = 30 (issue 13 §4): cube(F = 1), 7 755 vertices, is valid — its vertex test
    was beyond the work limit when every facet was filtered at every vertex (the box tree
    of ``kernels._left_by_filters``); sphere(F = 1), 10 428 vertices, was refused by the
    size limit of 10 000 vertices — now P = conv(V) is checked (vertex test, skeleton)
    and only the normal fan's work (V ⊆ Ψ) is beyond its limit."""
    from rescon_certificates.check import check

    assert check(_bench("cube", 5, 30, 1)).verdict == "valid"
    r = check(_bench("sphere", 5, 30, 1))
    assert r.verdict == "unchecked"
    assert len(r.unchecked) == 1 and "normal fan" in r.unchecked[0], r.unchecked
