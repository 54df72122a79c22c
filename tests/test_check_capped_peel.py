"""The checker's capped peel (certificates/check.py ``_Replay.capped``, issue 13 §4): it
peels Q \\ S of a closed superset Q of the state's core (as a stack entry of the replay
holds it) in one pass, with F_m = D − E_m so that each round is one test, and keeps the
row sums of the candidate sets. Checked against the recorder's kernel peel
(``capped_core``) on the exact core, for supersets Q, thresholds above n and the wide
slack path; the row-sum store emptied when full changes no verdict."""

from __future__ import annotations

import random
from itertools import product

import numpy as np
import pytest

from rescon.graphs._charged_kernels import capped_core
from tests.test_checker import C, in_masks, rand_edges
from tests.test_cost_tree_capped import _cert, _states, random_charged_trees

pytestmark = pytest.mark.usefixtures("fresh_facts")


def _cases(seed: int, n_lo: int, n_hi: int, wide: bool):
    """(rp, inm, t1, t2, S, X, B) for random digraphs and states; ``wide``: thresholds up
    to n + 3 and dense graphs (slack past the packed range for n = 12..15)."""
    rng = random.Random(seed)
    n = rng.randint(n_lo, n_hi)
    edges = rand_edges(rng, n, 0.8 if wide else rng.choice([0.5, 0.7, 0.9]))
    inm = in_masks(n, edges)
    hi = n + 3 if wide else 4
    t1, t2 = ([rng.randint(1, hi) for _ in range(n)] for _ in range(2))
    rp = C._Replay(C._graph({"n": n, "edges": [list(e) for e in edges]}), 1, "t")
    rp.capped_tables()
    for S, X, B in _states(rng, n, 25):
        yield rp, inm, t1, t2, S, X, B


@pytest.mark.parametrize("seeds, n_lo, n_hi, wide", [(range(k, 12, 3), 6, 9, False)
                                                     for k in range(3)]
                         + [(range(100, 106), 12, 15, True)])
def test_the_capped_peel_of_a_superset_is_the_kernels_capped_core(seeds, n_lo, n_hi, wide):
    """For every i ≤ j in S: capped() on the exact core Q = core(V \\ S \\ B), on the
    superset core(V \\ B) and on core(V \\ S' \\ B) for a part S' of S (each with S
    removed inside, as the replay's stack entries are) equals the kernel's peel of the
    exact Q (0 when a slack is negative)."""
    compared = wide_taken = 0
    for rp, inm, t1, t2, S, X, B in (case for seed in seeds
                                     for case in _cases(seed, n_lo, n_hi, wide)):
        n = len(inm)
        side1, side2 = rp.threshold_side(t1), rp.threshold_side(t2)
        P = rp.shrink(rp.full, side1.D, side1.gone | rp.pack(X), side1)[0]
        Pu = rp.unpack(P)
        part = S & random.Random(S ^ X).getrandbits(n)
        tops = [rp.shrink(rp.full, side2.D, side2.gone | rp.pack(T | B), side2)
                for T in (S, 0, part)]
        Q = rp.unpack(tops[0][0])
        arr = np.array(t2, dtype=np.int64)
        for i, j in ((a, b) for a, b in product(range(n), repeat=2)
                     if a <= b and S >> a & S >> b & 1):
            caps = []
            for m in (i, j):
                c = inm[m] & Pu & ~S
                caps += [c, c.bit_count() - ((inm[m] & ~S).bit_count() - t1[m] + 1)]
            want = 0 if min(caps[1], caps[3]) < 0 else int(capped_core(
                np.uint64(Q), np.uint64(caps[0]), caps[1], np.uint64(caps[2]), caps[3],
                np.array(inm, dtype=np.uint64), arr))
            for U, D in tops:
                got = rp.unpack(rp.capped(i, j, rp.pack(S), P, U, D, side1, side2))
                assert got == want, (i, j, S, X, B)
                compared += 1
            wide_taken += min(caps[1], caps[3]) >= 0 and max(
                min(caps[1], (caps[0] & Q).bit_count()),
                min(caps[3], (caps[2] & Q).bit_count())) + side2.most > 1 << (rp.w - 1)
    assert compared > 50
    assert not wide or wide_taken > 0


def test_emptying_the_row_sums_changes_no_verdict(monkeypatch):
    """Charged trees with capped leaves replay to the same verdicts (valid, and invalid
    when a capped leaf is moved onto a branch) with a store of 2 row sums as with the
    default one."""
    verdicts = {}
    for limit in (C.ROW_SUMS, 2):
        monkeypatch.setattr(C, "ROW_SUMS", limit)
        out = []
        for ig, _n, r, s, tree in random_charged_trees(range(12)):
            out.append(C.check(_cert(ig, r, s, tree)).verdict)
            k = next((k for k, t in enumerate(tree) if t >= 0), None)
            if k is not None:
                bad = tree[:k] + [-5] + tree[k + 1:]  # capped leaf of node 0 on a branch
                out.append(C.check(_cert(ig, r, s, bad)).verdict)
        verdicts[limit] = out
    assert verdicts[C.ROW_SUMS] == verdicts[2]
    assert "valid" in verdicts[2] and "invalid" in verdicts[2]
