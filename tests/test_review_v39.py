"""V39: hostile review of this session's changes (248e26d..HEAD).

Attacked:

* ``optim/expr.py``: number literals read from their digits and exponent (float-range
  limit for a literal, 4300-digit limit for numerators/denominators of literals and
  products). Fuzzed (20 000 seeded literals of every grammar form: leading zeros,
  ``1.``, ``.5``, ``e+``/``E-``, exponents near 308/324/4300/8600) against
  ``Fraction(text)``: every literal in the float range whose reduced numerator and
  denominator fit is read exactly, everything else refused. The float boundary follows
  ``float(text)`` exactly; subnormal and underflowing literals kept exact; Unicode
  digits (which ``\\d`` matches) read as before. Bug: a literal of more than 4300
  significant digits whose reduced fraction fits (the old parser read it) is refused.
* ``io.output_path``'s writability probe: symlinks, FIFO, /dev/null, read-only file as
  root, missing parents, directories, /proc and /sys; content, mtime and directory
  listing unchanged. Bugs: a refused path leaves the parent directories created for
  it (a 300-character file name under new directories); the probe of a new file
  creates and then deletes the output path itself, so a run that wrote that file in
  between loses it, and two runs probing the same new path at once refuse it ("File
  exists").
* ``graphs/bounds._out_lists`` cache and ``in_degrees`` cached_property: 100 random
  graphs gave identical reports to 248e26d (checked in the review, certificates valid);
  here: equal graphs with labels 1 / 1.0 / True keep their own labels, cached lists are
  those of a fresh build.
* kernels at d = 4-5 (hash of vertices, exact vertices, kernel points) identical to
  248e26d (checked in the review), simulate on the example scenarios too; here: the
  lock of ``_Deferred`` builds once.
* ``optim/redundancy.py`` (support problem compiled once per sum): reports on Huber /
  norm2 / log-sum-exp / quadratic families shifted by 2^0, 2^10, 2^-10, 1e8, 1e-8 equal
  248e26d's (verdict, gap, tolerance, witness); the one SolverError case is the same
  class on the same course, only its message differs ("status solver_error").
"""

from __future__ import annotations

import os
import random
import sys
import threading
from fractions import Fraction
from pathlib import Path

import networkx as nx
import numpy as np
import pytest

import rescon
from rescon.errors import InputError
from rescon.io import output_path
from rescon.optim import expr as E

# --------------------------------------------------------------------------- literals


def _literal(rng: random.Random) -> str:
    w = "".join(rng.choice("0123456789") for _ in range(rng.choice([0, 0, 1, 2, 5, 20])))
    f = "".join(rng.choice("0000123456789") for _ in range(rng.choice([0, 0, 1, 3, 10])))
    form = rng.randrange(4)
    s = [(w or "0") + "." + f, (w or "1") + ".", w or "7", "." + (f or "5")][form]
    if rng.random() < 0.6:
        e = abs(rng.choice([0, 1, 3, 300, 307, 308, 309, 323, 324, 330, 400, 4300])
                + rng.randrange(-3, 4))
        s += rng.choice("eE") + rng.choice(["", "+", "-"]) + str(e).zfill(rng.choice([1, 3]))
    return s


def test_literal_values_equal_fraction_of_text_fuzz():
    rng = random.Random(39)
    bound = 10**E.MAX_DIGITS
    accepted = 0
    for _ in range(1500):
        s = _literal(rng)
        ref = Fraction(s)
        ok = (not np.isinf(float(s)) and abs(ref.numerator) < bound
              and ref.denominator < bound)
        try:
            v = E.parse(s).const
        except E.ExprError:
            assert not ok, s
            continue
        accepted += 1
        assert ok and v == ref, s
    assert accepted > 500


@pytest.mark.parametrize("text", [
    "1.7976931348623157e308", "1.7976931348623158e308", "1.797693134862315807e308",
    "4.9e-324", "2e-324", "2.4703282292062328e-324", "1e-400", "0e999999",
    "00.000e-5", "1e+3", "1E-3", ".5", "1.", "007.50e0", "0.000000000000000000001e21"])
def test_literal_boundary_accepted_exact(text):
    assert E.parse(text).const == Fraction(text)


@pytest.mark.parametrize("text", ["1.797693134862315808e308", "1.7976931348623159e308",
                                  "1e309", "1e-5000", "1e1000000000", "1e-1000000000"])
def test_literal_boundary_refused_quickly(text):
    with pytest.raises(E.ExprError, match="the number"):
        E.parse(text)


def test_zero_with_huge_exponent_is_zero_at_once():
    assert E.parse("0e" + "9" * 30).const == 0  # Fraction(text) would build 10**(10**30)


def test_unicode_digits_read_as_before():
    assert E.parse("\u0661\u0662.\u0665").const == Fraction(25, 2)
    assert E.parse("\uff13.\uff15e\uff12").const == 350


def test_cost_from_max_float_literal():
    with pytest.raises(InputError, match="does not fit a float"):  # its gradient 2c
        rescon.cost("1.7976931348623158e308*x1^2")
    z = np.array([[0.5]])
    c = rescon.cost("0.5*1.7976931348623158e308*x1^2")
    assert c.value(z)[0] == 2.2471164185778946e307
    assert c.subgradient(z)[0, 0] == 8.988465674311579e307
    c = rescon.cost("1.7976931348623158e308*abs(x1)")
    assert c.value(z)[0] == 8.988465674311579e307
    assert c.subgradient(z)[0, 0] == sys.float_info.max


def test_products_of_literals_exact_when_they_fit():
    rng = random.Random(7)
    bound = 10**E.MAX_DIGITS
    for _ in range(300):
        a, b = _literal(rng), _literal(rng)
        try:
            fa, fb = E.parse(a).const, E.parse(b).const
        except E.ExprError:
            continue
        ref = fa * fb
        fits = abs(ref.numerator) < bound and ref.denominator < bound
        try:
            v = E.parse(f"{a}*{b}").const
        except E.ExprError:
            assert not fits, (a, b)
            continue
        assert fits and v == ref, (a, b)


def test_cost_from_subnormal_literal():
    z = np.array([[0.5]])
    c = rescon.cost("5e-324*x1^2 + x1^2")
    assert c.value(z)[0] == 0.25 and c.subgradient(z)[0, 0] == 1.0
    c = rescon.cost("1e-400*x1^2+x1")
    assert c.value(z)[0] == 0.5 and c.subgradient(z)[0, 0] == 1.0
    assert rescon.cost("2e-324*x1").value(z)[0] == 0.0


def test_repeated_squaring_refused_fast():
    with pytest.raises(InputError, match="4300 digits"):
        rescon.cost("((((((((((1e-300)^2)^2)^2)^2)^2)^2)^2)^2)^2)^2*x1^2")


def _long_literal() -> str:
    old = sys.get_int_max_str_digits()
    sys.set_int_max_str_digits(0)
    try:
        digits = str(5**6200)  # 4334 digits, no trailing zero
    finally:
        sys.set_int_max_str_digits(old)
    return digits[:2000] + "." + digits[2000:] + "e-2000"  # = 5**6200 / 10**4334


def test_long_literal_value_fits_the_documented_limit():
    value = Fraction(5**1866, 2**4334)  # the literal reduced: 1305-digit parts
    assert abs(value.numerator) < 10**4300 and value.denominator < 10**4300
    assert 0.41 < float(value) < 0.42


def test_long_literal_with_small_reduced_fraction_is_refused_truthfully():
    """Fixed (was a bug: a literal of > 4300 significant digits whose reduced fraction
    fits was refused as having 'a numerator or denominator of more than 4300 digits' —
    false. Now documented: a number as written has at most 4300 significant digits,
    and the message says that)."""
    with pytest.raises(E.ExprError, match="more than 4300 significant digits as written"):
        E.parse(_long_literal())


# --------------------------------------------------------------------------- output_path


def _state(d: Path) -> dict:
    return {p.name: (p.lstat().st_mtime_ns, p.read_bytes() if p.is_file() else None)
            for p in sorted(d.iterdir())}


def test_probe_leaves_existing_files_untouched(tmp_path):
    f = tmp_path / "f.json"
    f.write_text("DATA")
    os.utime(f, (1_000_000, 1_000_000))
    ro = tmp_path / "ro.json"
    ro.write_text("RO")
    os.chmod(ro, 0o444)
    os.utime(ro, (1_000_000, 1_000_000))
    (tmp_path / "ln").symlink_to("f.json")
    os.mkfifo(tmp_path / "fifo")
    before = _state(tmp_path)
    for name in ("f.json", "ln", "fifo"):
        assert output_path(tmp_path / name, "--x") == tmp_path / name
    if os.geteuid() == 0:  # root writes a 0444 file: accepted, as the write would be
        assert output_path(ro, "--x") == ro
    else:
        with pytest.raises(InputError, match="cannot write"):
            output_path(ro, "--x")
    assert output_path("/dev/null", "--x") == Path("/dev/null")
    assert _state(tmp_path) == before


def test_probe_refusals_leave_nothing(tmp_path):
    (tmp_path / "dang").symlink_to("nowhere")
    (tmp_path / "dir").mkdir()
    (tmp_path / "file").write_text("x")
    before = _state(tmp_path)
    for path, directory in [("dang", False), ("dang", True), ("dir", False),
                            ("file", True)]:
        with pytest.raises(InputError, match="--x"):
            output_path(tmp_path / path, "--x", directory=directory)
    assert _state(tmp_path) == before
    assert list((tmp_path / "dir").iterdir()) == []


def test_probe_new_file_and_directory_leave_no_stray_file(tmp_path):
    p = output_path(tmp_path / "a" / "b" / "c.json", "--x")
    assert not p.exists() and list(p.parent.iterdir()) == []
    d = output_path(tmp_path / "out", "--x", directory=True)
    assert d.is_dir() and list(d.iterdir()) == []


def test_refused_output_leaves_no_created_directories(tmp_path):
    """Fixed (was a bug: the parent directories created for a refused path stayed)."""
    with pytest.raises(InputError, match="cannot write"):
        output_path(tmp_path / "nd" / "sub" / ("a" * 300), "--certificate")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not Path("/proc/version").exists(), reason="needs /proc")
def test_probe_refuses_proc_without_side_effects():
    with pytest.raises(InputError, match="cannot write"):
        output_path("/proc/version", "--x")


def test_probe_never_deletes_a_file_written_meanwhile(tmp_path, monkeypatch):
    """Fixed (was a bug: the new-file probe created and removed the output path itself,
    deleting a file another run wrote meanwhile; it now probes the directory with a
    file of its own). Another run writes the output while the probe removes its file."""
    target = tmp_path / "cert.json"
    real_path_unlink, real_os_unlink = Path.unlink, os.unlink

    def path_unlink(self, *args, **kwargs):
        if self != target:
            target.write_text("CERTIFICATE")
        return real_path_unlink(self, *args, **kwargs)

    def os_unlink(path, *args, **kwargs):
        if Path(path) != target:
            target.write_text("CERTIFICATE")
        return real_os_unlink(path, *args, **kwargs)

    monkeypatch.setattr(Path, "unlink", path_unlink)
    monkeypatch.setattr(os, "unlink", os_unlink)
    output_path(target, "--certificate")
    monkeypatch.undo()
    assert target.read_text() == "CERTIFICATE"
    assert [q.name for q in tmp_path.iterdir()] == ["cert.json"]  # no probe left


def test_concurrent_probes_of_one_new_path_both_accepted(tmp_path, monkeypatch):
    """Fixed (was a bug: two runs probing one new path at once: 'File exists')."""
    target = tmp_path / "cert.json"
    real_exists = Path.exists

    def exists(self, *args, **kwargs):
        answer = real_exists(self, *args, **kwargs)
        if self == target and not answer:  # the other run's probe creates it now
            target.touch()
        return answer

    monkeypatch.setattr(Path, "exists", exists)
    output_path(target, "--certificate")


# --------------------------------------------------------------------------- graphs


def test_equal_graphs_with_equal_labels_keep_their_own_labels():
    from rescon.graphs.bounds import _out_lists
    from rescon.graphs.indexed import index_graph

    graphs = [nx.DiGraph([(a, 2), (2, 3), (3, a)]) for a in (1, 1.0, True)]
    igs = [index_graph(G) for G in graphs]
    assert igs[0] == igs[1] == igs[2]
    for G, a in zip(graphs, (1, 1.0, True)):
        w = rescon.robustness(G, progress=False).witness
        labels = [x for s in w for x in s]
        assert any(x is a or (type(x) is type(a) and x == a) for x in labels)
    fresh = [[] for _ in range(3)]
    for v, s in enumerate(igs[2].in_nbrs):
        for u in s:
            fresh[u].append(v)
    assert _out_lists(igs[2]) == fresh


def test_cached_out_lists_match_fresh_build_on_random_graphs():
    from rescon.graphs.bounds import _out_lists
    from rescon.graphs.indexed import index_graph

    for seed in range(20):
        G = nx.gnp_random_graph(12, 0.4, seed=seed, directed=True)
        ig = index_graph(G)
        first = _out_lists(ig)
        again = _out_lists(index_graph(G.copy()))
        fresh = [sorted(v for v in range(ig.n) if u in ig.in_nbrs[v]) for u in range(ig.n)]
        assert first == again == fresh
        assert ig.in_degrees == tuple(len(s) for s in ig.in_nbrs)


@pytest.mark.parametrize("seed", range(6))
def test_robustness_answers_valid_certificates(seed):
    G = nx.gnp_random_graph(8, 0.6, seed=seed, directed=bool(seed % 2))
    rep = rescon.robustness(G, progress=False)
    assert rescon.check_certificate(rep.certificate).valid
    assert rescon.max_s(G, rep.r_max) == rep.s_max
    assert rescon.is_rs_robust(G, rep.r_max, rep.s_max).holds


# --------------------------------------------------------------------------- kernel


def test_deferred_built_once_under_threads():
    from rescon.geometry.kernel import _Deferred

    calls = []
    barrier = threading.Barrier(8)

    def make():
        calls.append(1)
        return object()

    dv = _Deferred(make)
    got = []

    def read():
        barrier.wait()
        got.append(dv.get())

    ts = [threading.Thread(target=read) for _ in range(8)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert len(calls) == 1 and len({id(g) for g in got}) == 1


# --------------------------------------------------------------------------- redundancy

_FAM = ["logsumexp(x1 - {a}, x2 - {b}, 0) + (x1-{a})^2", "huber(x1-{a},2)+huber(x2-{b},1)",
        "logsumexp(x1-{a}, {b}-x2)+x1^2", "sqrt((x1-{a})^2+1)+(x2-{b})^2"]


def test_redundancy_numerical_verdicts_as_before():
    # verdicts and witnesses equal 248e26d's (one solve per direction) in the review
    costs = ["huber(x1 - 0.5, 1) + sqrt((x1-0.5)^2 + (x2+1.25)^2 + 1)"] * 4
    rep = rescon.check_redundancy(costs, 1)
    assert rep.holds and not rep.exact and rep.gap < rep.tolerance
    rep = rescon.check_redundancy([f.format(a=0.5, b=-1.25) for f in _FAM], 1)
    assert rep.holds is False and not rep.exact
    assert rep.witness["subsets"] == [[0, 1, 3], [0, 1, 2, 3]]


def test_redundancy_solver_failure_still_a_solver_error():
    # the old path raised the same SolverError here (message "Solver 'CLARABEL'
    # failed"; now "status solver_error"): same class, same retries
    a, b = 0.5 * 2.0**-10, -1.25 * 2.0**-10
    with pytest.raises(rescon.SolverError, match="Clarabel failed on the numerical path"):
        rescon.check_redundancy([f.format(a=repr(a), b=repr(b)) for f in _FAM], 1)
