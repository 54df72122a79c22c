"""Tests for rescon.graphs.sarymsakov against brute-force pair enumeration (n <= 7)."""

from __future__ import annotations

import importlib.util
import itertools
import sys
from pathlib import Path

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.sparse import csr_matrix

import rescon
from rescon.errors import InputError
from rescon.graphs.sarymsakov import SarymsakovResult, is_sarymsakov
from rescon.io import read_graph

EXAMPLES = Path(__file__).parent.parent / "examples" / "graphs"
CHECK_PY = Path(__file__).parent.parent / "certificates" / "check.py"


def _stochastic(S: np.ndarray) -> np.ndarray:
    return S / S.sum(axis=1, keepdims=True)


def _image(S: np.ndarray, V) -> set[int]:
    return set(np.flatnonzero(S[sorted(V)].any(axis=0)).tolist()) if V else set()


def _fails(S: np.ndarray, V1, V2) -> bool:
    I1, I2 = _image(S, V1), _image(S, V2)
    return not (I1 & I2) and len(I1) + len(I2) <= len(V1) + len(V2)


def _brute_holds(S: np.ndarray) -> bool:
    n = len(S)
    for labels in itertools.product((0, 1, 2), repeat=n):
        V1 = {i for i in range(n) if labels[i] == 1}
        V2 = {i for i in range(n) if labels[i] == 2}
        if V1 and V2 and min(V1) < min(V2) and _fails(S, V1, V2):
            return False
    return True


def _check_answer(S: np.ndarray, r: SarymsakovResult) -> None:
    n = len(S)
    support = [[int(i), int(j)] for i, j in zip(*np.nonzero(S))]
    assert r.exact
    if r.holds:
        assert r.witness is None
        cert = r.certificate
        assert cert["kind"] == "sarymsakov" and cert["support"] == support and cert["n"] == n
        assert cert["method"] in ("matching", "enumeration")
        assert rescon.check_certificate(cert).valid
    else:
        V1, V2 = r.witness
        assert V1 and V2 and not V1 & V2 and _fails(S, V1, V2)
        assert r.certificate == {"rescon_certificate": 1, "kind": "not_sarymsakov", "n": n,
                                 "support": support,
                                 "witness": {"V1": sorted(V1), "V2": sorted(V2)}}


@st.composite
def supports(draw, max_n: int = 7):
    n = draw(st.integers(1, max_n))
    p = draw(st.sampled_from([0.15, 0.3, 0.5, 0.8]))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    S = rng.random((n, n)) < p
    if draw(st.booleans()):
        np.fill_diagonal(S, True)
    empty = ~S.any(axis=1)
    S[np.flatnonzero(empty), rng.integers(n, size=int(empty.sum()))] = True
    return S


@settings(max_examples=300, deadline=None)
@given(supports())
def test_matches_brute_force(S):
    r = is_sarymsakov(_stochastic(S))
    assert r.holds == _brute_holds(S)
    _check_answer(S, r)


def test_both_methods_are_exercised_on_n7():
    rng = np.random.default_rng(11)
    seen: dict[tuple[str, bool], int] = {}
    for _ in range(150):
        S = rng.random((7, 7)) < rng.choice([0.2, 0.3, 0.45])
        S[~S.any(axis=1), 0] = True
        r = is_sarymsakov(_stochastic(S))
        assert r.holds == _brute_holds(S)
        _check_answer(S, r)
        seen[r.method, r.holds] = seen.get((r.method, r.holds), 0) + 1
    assert set(seen) == set(itertools.product(("matching", "min_cut"), (True, False)))


@pytest.mark.skipif(not CHECK_PY.exists(), reason="certificates/check.py not present")
def test_witness_certificates_pass_the_independent_checker(monkeypatch):
    spec = importlib.util.spec_from_file_location("_rescon_check_for_sarymsakov", CHECK_PY)
    checker = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, spec.name, checker)  # dataclasses look the module up
    spec.loader.exec_module(checker)
    rng = np.random.default_rng(8)
    checked = 0
    for _ in range(200):
        n = int(rng.integers(2, 10))
        S = rng.random((n, n)) < 0.3
        S[~S.any(axis=1), 0] = True
        r = is_sarymsakov(_stochastic(S))
        if not r.holds:
            checked += 1
            result = checker.check(r.certificate)
            assert result.valid, result.reason
    assert checked > 50


def test_small_examples():
    assert is_sarymsakov([[1.0]]).holds
    r = is_sarymsakov(np.eye(3))
    assert not r.holds and r.method == "matching"
    # every row reads column 0: images always meet (no perfect matching)
    r = is_sarymsakov([[1, 0, 0], [1, 0, 0], [0.5, 0.5, 0]])
    assert r.holds and r.method == "min_cut"
    # rows 0 and 1 both read only column 0; row 2 reads column 1: V1={0,1}, V2={2}
    r = is_sarymsakov([[1, 0, 0], [1, 0, 0], [0, 1, 0]])
    assert not r.holds and r.method == "min_cut"


def test_products_of_sarymsakov_matrices_stay_sarymsakov():
    rng = np.random.default_rng(3)
    found = 0
    while found < 30:
        A, B = (_stochastic((rng.random((6, 6)) < 0.35) | np.eye(6, k=1, dtype=bool)
                            | np.eye(6, k=-5, dtype=bool)) for _ in range(2))
        if is_sarymsakov(A).holds and is_sarymsakov(B).holds:
            found += 1
            assert is_sarymsakov(A @ B).holds


def test_paper_consensus_matrix_is_sarymsakov():
    # A = alpha I + (1 - alpha) * (uniform average over in-neighbours), alpha = 0.5
    G = read_graph(EXAMPLES / "paper_example.edgelist")
    W = nx.to_numpy_array(G, nodelist=sorted(G)).T  # W[i, j] = 1 iff j -> i
    A = 0.5 * np.eye(12) + 0.5 * W / W.sum(axis=1, keepdims=True)
    r = is_sarymsakov(A)
    assert r.holds and r.exact and r.method == "matching"


def test_sparse_input_and_large_n():
    # Row i reads {i, i + 1}, the last row reads itself: one source component, holds.
    n = 400
    S = np.eye(n, dtype=bool) | np.eye(n, k=1, dtype=bool)
    r = is_sarymsakov(csr_matrix(_stochastic(S)))
    assert r.holds and r.exact and r.method == "matching"
    assert not is_sarymsakov(csr_matrix(np.eye(n))).holds


def _cycle_with_hub(n: int) -> np.ndarray:
    """Row 0 reads columns 1..n-1; row i >= 1 reads {i, i+1} on the cycle 1..n-1.

    Column 0 is unused (no perfect matching); Sarymsakov; ~n^2/2 anchor pairs.
    """
    S = np.zeros((n, n), dtype=bool)
    S[0, 1:] = True
    for i in range(1, n):
        S[i, i] = S[i, i + 1 if i + 1 < n else 1] = True
    return S


def test_time_limit_gives_honest_inexact_answer():
    small = _cycle_with_hub(7)
    r = is_sarymsakov(_stochastic(small), time_limit=60)
    assert r.holds and r.exact and r.method == "min_cut" and _brute_holds(small)
    r = is_sarymsakov(_stochastic(_cycle_with_hub(60)), time_limit=1e-3)
    assert (r.holds, r.exact, r.certificate, r.witness) == (True, False, None, None)


@pytest.mark.parametrize(
    ("A", "pattern"),
    [
        ([1.0, 0.0], r"square \(n, n\) matrix with n >= 1; got shape \(2,\)"),
        (np.ones((2, 3)) / 3, r"got shape \(2, 3\)"),
        (np.zeros((0, 0)), r"got shape \(0, 0\)"),
        ([[0.5, np.nan], [0.5, 0.5]], r"A must be finite; got 1 NaN/inf"),
        ([[1.5, -0.5], [0.5, 0.5]], r"A must be nonnegative; got A\[0, 1\] = -0.5"),
        ([[0.5, 0.4], [0.5, 0.5]], r"row-stochastic .* got row 0 summing to 0.9"),
        ([["a", "b"], ["c", "d"]], r"A must be a numeric \(n, n\) matrix; got list"),
    ],
)
def test_input_errors(A, pattern):
    with pytest.raises(InputError, match=pattern):
        is_sarymsakov(A)


@pytest.mark.parametrize("limit", [0, -1.0, True, "1"])
def test_bad_time_limit(limit):
    with pytest.raises(InputError,
                       match="time_limit must be a (real number|finite number of seconds > 0)"):
        is_sarymsakov(np.eye(2), time_limit=limit)


def test_holds_certificates_are_checked_not_trusted():
    """A Sarymsakov matrix gets a `sarymsakov` certificate the checker verifies
    (matching: polynomial; enumeration: n ≤ 12); tampering with it is caught."""
    import copy
    import json
    from pathlib import Path

    import jsonschema

    schema = json.loads((Path(__file__).parents[1] / "certificates" / "schema"
                         / "certificate.schema.json").read_text())
    A = np.full((4, 4), 0.25)
    res = rescon.is_sarymsakov(A)
    cert = res.certificate
    assert res.holds and cert["kind"] == "sarymsakov" and cert["method"] == "matching"
    jsonschema.validate(cert, schema)
    check = rescon.check_certificate(cert)
    assert check.valid and check.trusted == ()
    # the identity support has n source components: a claimed matching proof must fail
    bad = copy.deepcopy(cert)
    bad["support"] = [[i, i] for i in range(4)]
    bad["matching"] = [0, 1, 2, 3]
    assert "source components" in rescon.check_certificate(bad).reason
    bad = copy.deepcopy(cert)
    bad["matching"] = [0, 0, 1, 2]
    assert not rescon.check_certificate(bad).valid
    # enumeration re-checks: the identity is not Sarymsakov
    enum = {"rescon_certificate": 1, "kind": "sarymsakov", "method": "enumeration", "n": 3,
            "support": [[0, 0], [1, 1], [2, 2]]}
    assert not rescon.check_certificate(enum).valid
    enum["support"] = [[i, j] for i in range(3) for j in range(3)]
    assert rescon.check_certificate(enum).valid
