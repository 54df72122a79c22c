"""R13: fixes of V37's public-contract bugs, pinned where tests/test_review_v37.py does not.

Boolean keywords refuse non-bools; cost numbers are read exactly but refused from their
text when out of reach (beyond the float range, or a numerator / denominator of more than
4300 digits) before 10^exponent is built; input paths that are directories or not paths,
and TOML files with a byte-order mark; simulate's scenario check; progress and seed
validation; output paths checked for writability before any work.
"""

from __future__ import annotations

import inspect
import os
import shutil
import time
from fractions import Fraction
from pathlib import Path

import networkx as nx
import pytest

import rescon
from rescon.optim import expr

# --------------------------------------------------------------------------- undirected


@pytest.mark.parametrize("value", ["no", 0, 1, 1.0])
def test_is_rs_robust_refuses_a_non_bool_undirected(value):
    D = nx.DiGraph([(0, 1), (1, 2), (2, 0)])
    with pytest.raises(rescon.InputError, match="undirected must be True or False"):
        rescon.is_rs_robust(D, 1, 1, undirected=value)


def test_undirected_true_false_none_and_numpy_bools_still_work():
    import numpy as np

    D = nx.DiGraph([(0, 1), (1, 2), (2, 0)])
    for value, r in ((None, 1), (False, 1), (True, 2), (np.True_, 2), (np.False_, 1)):
        assert rescon.robustness(D, undirected=value).r_max == r


# --------------------------------------------------------------------------- cost numbers


def test_a_literal_beyond_the_float_range_is_quoted_as_typed():
    for text in ("1e400", "1.8e308", "1.7976931348623159e308", "1e5000"):
        with pytest.raises(rescon.InputError) as exc:
            rescon.cost(f"{text}*x1")
        assert f"the number {text} does not fit a float at position 0" in str(exc.value)
    # the largest float's own spelling is accepted (correctly rounded, as float() does)
    assert rescon.cost("1.7976931348623157e308*x1").exact["a"] == [
        Fraction(17976931348623157, 10**16) * 10**308]
    assert rescon.cost("1e308*x1").exact["a"] == [Fraction(10**308)]


def test_a_computed_number_beyond_the_float_range_is_shown_by_its_magnitude():
    with pytest.raises(rescon.InputError, match=r"about 1\.0e\+400\) does not fit a float"):
        rescon.cost("1e200*1e200*x1")
    # thousands of digits are not printed
    big = "*".join(["1e300"] * 14)
    with pytest.raises(rescon.InputError, match=r"about 1\.0e\+4200\) does not fit"):
        rescon.cost(f"{big}*x1")


def test_tiny_literals_are_still_read_exactly():
    """1e-400 (below the smallest subnormal) is accepted and kept exact, as before."""
    assert rescon.cost("1e-400*x1").exact["a"] == [Fraction(1, 10**400)]
    assert rescon.cost("5e-4300*x1").exact["a"] == [Fraction(1, 2 * 10**4299)]
    assert rescon.cost("0e1000000000*x1 + 1").exact["b"] == 1
    assert rescon.cost("0.5e1*x1 + 1.*x1 + .25e-1").exact["b"] == Fraction(1, 40)


@pytest.mark.parametrize("text", [
    "1e-1000000000", "1e-4300", "1e-" + "9" * 5000, "1." + "1" * 4300, "0." + "0" * 5000 + "1",
    "1." + "0" * 5000 + "1",
])
def test_literals_needing_huge_integers_are_refused_quickly(text):
    t = time.perf_counter()
    with pytest.raises(rescon.InputError, match="more than 4300 (significant )?digits") as exc:
        rescon.cost(f"{text}*x1")
    assert time.perf_counter() - t < 2
    assert "\n" not in str(exc.value)


def test_repeated_squaring_of_a_constant_is_refused_quickly():
    src = "1e300"
    for _ in range(30):
        src = f"({src})^2"
    t = time.perf_counter()
    with pytest.raises(rescon.InputError, match="product of the expression's numbers"):
        rescon.cost(f"{src}*x1")
    assert time.perf_counter() - t < 2


def test_digit_bound_is_exact():
    assert expr.MAX_DIGITS == 4300
    assert expr._fits(Fraction(10**4300 - 1, 10**4300 - 3))
    assert not expr._fits(Fraction(10**4300, 3)) and not expr._fits(Fraction(1, 10**4300))


# --------------------------------------------------------------------------- input files

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _readers():
    from rescon.optim import read_costs, read_rmdo
    from rescon.sweep.grid import read_grid

    return {"from_toml": rescon.Scenario.from_toml, "read_rmdo": read_rmdo,
            "read_costs": read_costs, "read_grid": read_grid, "sweep": rescon.sweep}


@pytest.mark.parametrize("reader", ["from_toml", "read_rmdo", "read_costs", "read_grid",
                                    "sweep"])
def test_toml_readers_refuse_a_directory_in_one_line(tmp_path, reader):
    with pytest.raises(rescon.InputError, match="is a directory") as exc:
        _readers()[reader](tmp_path)
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("path, reader", [
    ("scenarios/ring_attack.toml", "from_toml"),
    ("scenarios/rmdo_quadratic.toml", "read_rmdo"),
    ("scenarios/rmdo_quadratic.toml", "read_costs"),
    ("sweeps/small.toml", "read_grid"),
])
def test_toml_readers_read_a_file_with_a_bom_like_without(tmp_path, path, reader):
    shutil.copytree(EXAMPLES, tmp_path / "ex")  # with the files the examples name
    src = tmp_path / "ex" / path
    bom = src.with_name("bom.toml")
    bom.write_bytes(b"\xef\xbb\xbf" + src.read_bytes())
    read = _readers()[reader]
    a, b = read(src), read(bom)
    if reader == "from_toml":
        assert a.to_dict() == b.to_dict()
    elif reader == "read_rmdo":
        assert a.scenario.to_dict() == b.scenario.to_dict() and a.costs.keys() == b.costs.keys()
    elif reader == "read_costs":
        assert a[1] == b[1] and [o.source for o in a[0].values()] == [
            o.source for o in b[0].values()]
    else:
        assert a.axes == b.axes and a.kind == b.kind


def test_input_file_names_what_it_wanted(tmp_path):
    from rescon.io import input_file

    with pytest.raises(rescon.InputError, match="^graph file: path must be a str or "
                                                "os.PathLike; got NoneType$"):
        input_file(None, "graph file")
    with pytest.raises(rescon.InputError, match="^points file is a directory: "):
        input_file(tmp_path, "points file")
    with pytest.raises(rescon.InputError, match="^points file not found: "):
        input_file(tmp_path / "x", "points file")
    (tmp_path / "x").write_text("")
    assert input_file(tmp_path / "x", "points file") == tmp_path / "x"


def test_sweep_shows_its_real_signature():
    from rescon.sweep.run import sweep

    assert inspect.signature(rescon.sweep) == inspect.signature(sweep)
    assert "scheduler" in inspect.signature(rescon.sweep).parameters


# --------------------------------------------------------------------------- API arguments


def test_simulate_refuses_a_non_scenario_like_rmdo():
    for bad in (None, {"scenario": {}}, "paper.toml"):
        with pytest.raises(rescon.InputError, match="scenario must be a rescon.Scenario"):
            rescon.simulate(bad)


@pytest.mark.parametrize("value", ["no", 0, 1, "False"])
def test_progress_refuses_non_bools_everywhere(value):
    from rescon._progress import progress_bar, wanted

    with pytest.raises(rescon.InputError, match="progress must be True or False"):
        wanted(value)
    with pytest.raises(rescon.InputError, match="progress"):
        progress_bar(value, 10, "x")
    with pytest.raises(rescon.InputError, match="progress"):
        rescon.robustness(nx.complete_graph(4), progress=value)
    assert wanted(False) is False and progress_bar(False, 10, "x") is None


def test_check_subgradient_seed_zero_is_fine_and_negative_refused():
    f = rescon.cost("abs(x1)")
    assert rescon.check_subgradient(f, [[1.0]], seed=0) <= 1e-12
    with pytest.raises(rescon.InputError, match="seed must be a nonnegative integer"):
        rescon.check_subgradient(f, [[1.0]], seed=-5)


# --------------------------------------------------------------------------- output paths


def _unwritable_dir() -> Path | None:
    """A directory this process cannot create files in, even as root (/proc refuses)."""
    for d in (Path("/proc"), Path("/sys")):
        probe = d / "rescon_r13_probe"
        try:
            probe.write_text("")
        except OSError:
            return d
        probe.unlink()
    return None


def test_output_path_tries_writing_and_leaves_nothing_behind(tmp_path):
    from rescon.io import output_path

    existing = tmp_path / "keep.json"
    existing.write_text("old")
    before = existing.stat().st_mtime_ns
    assert output_path(existing, "--certificate") == existing
    assert existing.read_text() == "old" and existing.stat().st_mtime_ns == before
    new = tmp_path / "sub" / "new.json"
    assert output_path(new, "--certificate") == new and not new.exists()
    out = output_path(tmp_path / "dir", "--out", directory=True)
    assert out.is_dir() and list(out.iterdir()) == []
    assert output_path(os.devnull, "--certificate") == Path(os.devnull)


def test_output_path_refuses_an_unwritable_place_naming_the_option():
    from rescon.io import output_path

    d = _unwritable_dir()
    if d is None:
        pytest.skip("needs a directory that refuses new files (/proc or /sys)")
    with pytest.raises(rescon.InputError, match=r"^--certificate: cannot write .*rescon_r13"):
        output_path(d / "rescon_r13.json", "--certificate")
    with pytest.raises(rescon.InputError, match=r"^out: cannot write "):
        output_path(d, "out", directory=True)


def test_cli_refuses_unwritable_outputs_before_reading_input(tmp_path, capfd):
    from rescon.cli import main

    d = _unwritable_dir()
    if d is None:
        pytest.skip("needs a directory that refuses new files (/proc or /sys)")
    missing = tmp_path / "no_such_input"  # read after the outputs are checked
    for argv, option in (
            (["kernel", missing, "--F", "1", "--certificate", d / "k.json"], "--certificate"),
            (["simulate", missing, "--out", d], "--out"),
            (["robustness", missing, "--certificate", d / "r.json"], "--certificate")):
        code = main([str(a) for a in argv])
        out, err = capfd.readouterr()
        assert code == 2 and out == "" and err.startswith(f"rescon: error: {option}: "), err
        assert len(err.splitlines()) == 1


def test_a_write_that_fails_after_the_check_names_the_option(tmp_path, capfd, monkeypatch):
    from rescon import cli

    g = tmp_path / "g.txt"
    g.write_text("0 1\n1 0\n")

    def refuse(self, *args, **kwargs):
        raise PermissionError(13, "Permission denied")

    monkeypatch.setattr(Path, "write_text", refuse)
    code = cli.main(["robustness", str(g), "--certificate", str(tmp_path / "c.json")])
    err = capfd.readouterr().err
    assert code == 2 and err.startswith("rescon: error: --certificate: cannot write "), err


@pytest.mark.parametrize("reader, what", [("read_rmdo", "RMDO file"),
                                          ("read_costs", "costs file")])
def test_rmdo_and_costs_readers_refuse_a_non_path_naming_the_file_kind(reader, what):
    """Fixed (was a bug, V37: read_rmdo(None) / read_costs(None) raised a builtins
    TypeError from Path(None))."""
    from rescon.optim import files

    with pytest.raises(rescon.InputError, match=f"^{what}: path must be"):
        getattr(files, reader)(None)


def test_cost_vectorised_takes_true_or_false_only():
    """Fixed (was a bug, V37: cost("x1^2", vectorised="no") was accepted and ignored)."""
    with pytest.raises(rescon.InputError, match="vectorised must be True or False"):
        rescon.cost("x1^2", vectorised="no")
    assert rescon.cost("x1^2", vectorised=True).value([[2.0]]).tolist() == [4.0]


def test_errors_on_long_expressions_stay_short():
    """Fixed (was a bug, V37/R13 noticed: the error repeated the whole expression — a
    7 kB line for a 7 kB cost). Now a window around the error's position."""
    middle = "x1^2 + " * 500 + "x1^3 + " + "x1^2 + " * 500 + "1"
    with pytest.raises(rescon.InputError) as exc:
        rescon.cost(middle)
    msg = str(exc.value)
    assert len(msg) < 400 and "\n" not in msg
    assert "x1^3" in msg and f"({len(middle)} characters)" in msg
    assert f"at position {middle.index('x1^3') + 3}" in msg  # the exponent
    with pytest.raises(rescon.InputError, match=r"^cost: expression 'x1 \+ \(': "):
        rescon.cost("x1 + (")  # short ones whole, as before
