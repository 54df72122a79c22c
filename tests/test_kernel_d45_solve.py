"""Safe kernels in d = 4-5 (issue 13 §3), the exact vertex solve of the fast path
(``fastpath._solve_all`` / ``_meet``) against a Fraction brute force on hostile row
sets, and the qhull option chain of the d ≥ 5 merged proposal when a proposal does
not certify — kernels bit-identical to the exact clipping."""

from __future__ import annotations

import itertools
from fractions import Fraction
from math import gcd

import numpy as np
import pytest

from rescon.geometry import fastpath
from rescon.geometry.exact import solve_exact
from tests.test_kernel_d45 import _halfspaces
from tests.test_kernel_d45_around2 import _cloud, _recorded_options, _same_as_clipping


def _brute(H, T: list[int]) -> tuple[int, ...] | None:
    """The point where the hyperplanes of rows T meet, in Fractions (None if they do
    not meet in one point), as the primitive homogeneous (w, y), w > 0."""
    rows = [H.exact(h) for h in T]
    y = solve_exact([[Fraction(v) for v in a] for a, _ in rows], [Fraction(b) for _, b in rows])
    if y is None:
        return None
    w = 1
    for v in y:
        w = w * v.denominator // gcd(w, v.denominator)
    x = (w, *(int(v * w) for v in y))
    g = gcd(*x)
    return tuple(v // g for v in x)


def _row_sets(H, k: int, count: int, seed: int) -> list[list[int]]:
    """Random k-sets of rows, and sets that share k − 1 data points in a pair of rows
    (the paired case of :func:`fastpath._meet`), some with a row repeated (dependent)."""
    rng = np.random.default_rng(seed)
    out = [sorted(rng.choice(len(H), size=k, replace=False).tolist()) for _ in range(count)]
    by_face: dict[tuple[int, ...], list[int]] = {}
    for h, pts in enumerate(H.through.tolist()):
        for face in itertools.combinations(sorted(pts), k - 1):
            by_face.setdefault(face, []).append(h)
    shared = [hs for hs in by_face.values() if len(hs) >= 2]
    for t in range(min(count, len(shared))):
        pair = shared[t][:2]
        rest = [int(h) for h in rng.choice(len(H), size=k - 2, replace=False)]
        out.append(pair + rest)
    out += [T[:-1] + T[:1] for T in out[:3]]  # a repeated row: dependent
    return out


HOSTILE = [("gaussian", 4, 14, 1), ("tiny", 4, 14, 1), ("huge", 4, 14, 1),
           ("subnormal", 4, 14, 1), ("nearsame", 4, 14, 1), ("integer", 4, 14, 2),
           ("adversary", 4, 14, 1), ("lattice", 4, 30, 2), ("gaussian", 5, 10, 1),
           ("integer", 5, 10, 1), ("gaussian", 3, 12, 2)]


@pytest.mark.parametrize("kind,d,n,F", HOSTILE)
def test_solve_all_equals_a_fraction_brute_force(kind, d, n, F):
    """Random and paired row sets, dependent ones among them (→ None), on data at
    1e-300, 1e300, subnormal, converged, integer and lattice points."""
    H, hull, *_ = _halfspaces(_cloud(kind, d, n, F), F)
    assert hull.dim == d
    Ts = _row_sets(H, d, 40, seed=n)
    H.exact_all(sorted({h for T in Ts for h in T}))
    got = fastpath._solve_all(H, Ts, d)
    assert got == [_brute(H, T) for T in Ts]
    assert any(g is None for g in got) and any(g is not None for g in got)


def test_solve_all_when_the_determinant_is_a_multiple_of_the_prime(monkeypatch):
    """det A_T ≡ 0 modulo the prime of the independence test (forced with a prime of
    2 and 3): the cross product of E_T solves those sets, with the same answers."""
    H, *_ = _halfspaces(_cloud("integer", 4, 14, 2), 2)
    Ts = _row_sets(H, 4, 60, seed=5)
    H.exact_all(sorted({h for T in Ts for h in T}))
    want = [_brute(H, T) for T in Ts]
    for p in (2, 3):
        monkeypatch.setattr(fastpath, "PRIME", p)
        assert fastpath._solve_all(H, Ts, 4) == want


def test_solve_all_with_near_parallel_rows():
    """Points on two nearly equal hyperplanes (tilted by 2^-40): their rows are nearly
    parallel, and the solve is still exact."""
    rng = np.random.default_rng(11)
    Z = rng.normal(size=(14, 4))
    Z[:7, 3] = 1.0
    Z[7:11, 3] = 1.0 + 2.0**-40 * Z[7:11, 0]
    H, *_ = _halfspaces(Z, 2)
    Ts = _row_sets(H, 4, 60, seed=2)
    H.exact_all(sorted({h for T in Ts for h in T}))
    assert fastpath._solve_all(H, Ts, 4) == [_brute(H, T) for T in Ts]


def test_d5_default_runs_when_the_first_options_proposal_does_not_certify(monkeypatch):
    """qhull's first d ≥ 5 option runs but its proposal is refused by the
    certification: qhull's default is tried next, before joggled input (it was
    skipped: the chain only moved on when qhull failed)."""
    X, F = _cloud("gaussian", 5, 14, 1), 1
    used = _recorded_options(monkeypatch)
    certify = fastpath._certify

    def refuse_first(*args, **kw):
        return None if used[-1] == fastpath.MERGED_OPTIONS_5D[0] else certify(*args, **kw)

    monkeypatch.setattr(fastpath, "_certify", refuse_first)
    K = _same_as_clipping(X, F, monkeypatch)
    assert used[0] == fastpath.MERGED_OPTIONS_5D[0]
    assert None in used and "QJ" not in used
    assert K.dim == 5


@pytest.mark.parametrize("kind,d,n,F", [
    ("gaussian", 3, 16, 2), ("sphere", 3, 16, 1), ("cube", 4, 18, 2),
    ("converged", 4, 18, 2), ("duplicates", 4, 19, 2), ("lattice", 4, 20, 3),
    ("simplex", 4, 5, 0), ("nearsame", 5, 12, 1), ("gaussian", 5, 12, 1)])
def test_kernels_identical_to_the_exact_clipping(kind, d, n, F, monkeypatch):
    _same_as_clipping(_cloud(kind, d, n, F), F, monkeypatch)


@pytest.mark.parametrize("seed", range(3))
def test_rows_violated_by_a_proposal_join_the_next_round(seed, monkeypatch):
    """A third of the defining rows given to qhull: its first proposal cuts off too
    little, the certification fails (a walk on the graph the closure proves finds a
    row cutting a vertex), the rows the proposal violates join, and the next round's
    kernel is the exact clipping's."""
    from tests.test_kernel_d45 import _both_paths

    X = np.random.default_rng(seed).normal(size=(22, 4))
    _, slow, H, unit, first = _both_paths(X, 2)
    few = np.sort(np.random.default_rng(seed).choice(first, size=len(first) // 3,
                                                     replace=False))
    rounds = []
    propose = fastpath._propose

    def spy(H_, sel, *args):
        rounds.append(len(sel))
        return propose(H_, sel, *args)

    monkeypatch.setattr(fastpath, "_propose", spy)
    P = fastpath.certified_kernel(H, 4, unit, few)
    assert len(rounds) == 2 and rounds[1] > rounds[0]
    assert P is not None and set(P.fraction_vertices()) == set(slow.fraction_vertices())


@pytest.mark.parametrize("k,r", [(3, 3), (4, 4), (5, 5), (4, 3)])
def test_paired_rows_is_the_first_pair_sharing_k_minus_1_points(k, r):
    """The compiled pair search of ``_meet`` against a brute force over the pairs of
    rows (each row k distinct points of 0..k + 2, so many pairs share k − 1)."""
    from rescon.geometry._certify_nb import paired_rows

    rng = np.random.default_rng([k, r])
    pts = np.array([[rng.choice(k + 3, size=k, replace=False) for _ in range(r)]
                    for _ in range(400)], dtype=np.int64)
    pairs = list(itertools.combinations(range(r), 2))
    want = [next((g for g, (a, b) in enumerate(pairs)
                  if len(set(row[a]) & set(row[b])) == k - 1), -1) for row in pts.tolist()]
    got = paired_rows(pts, k).tolist()
    assert got == want
    assert -1 in got and any(g > 0 for g in got)
