"""Review V14: a fresh user's journey — optional dependencies missing (simulated with
``sys.modules[name] = None``, so these run where everything is installed), a closed
stdout, a read-only install without a writable numba cache, ``--json`` purity."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from rescon.cli import main

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

# every directory outside the temporary directory is read-only for numba's cache: a
# package installed read-only and a HOME without a writable cache (a container run as
# another user with HOME=/). numba (and the CLI's guard) test a directory by creating a
# temporary file in it, so refusing that outside the temporary directory simulates it.
_NO_CACHE = textwrap.dedent("""
    import sys, tempfile
    _temporary_file = tempfile.TemporaryFile
    def _deny(*args, dir=None, **kw):
        if dir is not None and not str(dir).startswith(tempfile.gettempdir()):
            raise PermissionError(13, "Permission denied (simulated read-only)", dir)
        return _temporary_file(*args, dir=dir, **kw)
    tempfile.TemporaryFile = _deny
""")


def _fresh(code: str, tmp_path: Path) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env.update(TMPDIR=str(tmp_path), PYTHONPATH=str(ROOT / "src"))
    return subprocess.run([sys.executable, "-c", _NO_CACHE + code], capture_output=True,
                          text=True, env=env, cwd=tmp_path, timeout=600)


def _square(tmp_path: Path) -> Path:
    graph = tmp_path / "c4.edgelist"
    graph.write_text("0 1\n1 2\n2 3\n3 0\n1 0\n2 1\n3 2\n0 3\n")
    return graph


_NUMBA_MODULES = ["rescon.graphs._kernels", "rescon.graphs._charged_kernels",
                  "rescon.geometry._candidates", "rescon.geometry._closure",
                  "rescon.geometry._small2d", "rescon.geometry._small3d",
                  "rescon.geometry._certify_nb", "rescon.geometry._expansions"]


def test_numba_modules_import_without_a_writable_cache(tmp_path):
    """Fast form of the next tests: every module with ``cache=True`` kernels imports in
    a read-only install, because its package runs the guard first
    (:func:`rescon._numba_cache.ensure_numba_cache`). Loaded by path, past the package's
    guard, the first one still raises numba's RuntimeError (the failure the guard
    prevents)."""
    unguarded = ("import importlib.util\n"
                 "spec = importlib.util.spec_from_file_location('k', "
                 f"{str(ROOT / 'src' / 'rescon' / 'graphs' / '_kernels.py')!r})\n"
                 "spec.loader.exec_module(importlib.util.module_from_spec(spec))\n")
    without = _fresh(unguarded, tmp_path)
    assert without.returncode != 0 and "no locator available" in without.stderr
    done = _fresh("\n".join(f"import {m}" for m in _NUMBA_MODULES), tmp_path)
    assert done.returncode == 0, done.stderr[-500:]


@pytest.mark.slow  # ~20 s: numba compiles the search kernels into the fresh cache
def test_cli_without_a_writable_numba_cache_runs(tmp_path):
    """Failed before: ``cannot cache function 'popcount': no locator available`` (a
    RuntimeError traceback from importing rescon.graphs._kernels, exit 1). The CLI now
    points numba at a private directory under the temporary directory."""
    graph = EXAMPLES / "graphs" / "paper_example.edgelist"  # needs the numba search
    done = _fresh("from rescon.cli import main\n"
                  f"sys.exit(main(['robustness', {str(graph)!r}, '--json']))", tmp_path)
    assert done.returncode == 0, done.stderr[-500:]
    assert "Traceback" not in done.stderr
    assert json.loads(done.stdout)["r_max"] == 5
    private = tmp_path / f"rescon-numba-{os.getuid()}"
    assert private.is_dir() and not private.stat().st_mode & 0o077


def test_cli_does_not_use_a_numba_cache_directory_others_can_write(tmp_path):
    """The per-user cache directory in /tmp is used only when this user owns it and no
    one else may write it (numba's cache holds pickles); else a fresh private one."""
    graph = _square(tmp_path)
    planted = tmp_path / f"rescon-numba-{os.getuid()}"
    planted.mkdir()
    planted.chmod(0o777)
    done = _fresh("import os\nfrom rescon.cli import main\n"
                  f"code = main(['robustness', {str(graph)!r}, '--json'])\n"
                  "print(os.environ['NUMBA_CACHE_DIR'], file=sys.stderr)\n"
                  "sys.exit(code)", tmp_path)
    assert done.returncode == 0, done.stderr[-500:]
    used = Path(done.stderr.strip().splitlines()[-1])
    assert used != planted and used.parent == tmp_path and list(planted.iterdir()) == []


@pytest.mark.slow  # ~20 s: numba compiles the search kernels into the fresh cache
def test_library_without_a_writable_numba_cache_runs(tmp_path):
    """Failed before (a RuntimeError at import: only the CLI set NUMBA_CACHE_DIR); the
    guard now lives in the packages that hold the kernels."""
    done = _fresh("import rescon\n"
                  "print(rescon.robustness(rescon.Scenario.paper_example().graph).r_max)",
                  tmp_path)
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr[-500:]
    assert done.stdout.strip() == "5"


def test_cli_keeps_a_users_numba_cache_dir(tmp_path, monkeypatch):
    from rescon import _numba_cache

    monkeypatch.setenv("NUMBA_CACHE_DIR", str(tmp_path / "mine"))
    monkeypatch.setattr(_numba_cache, "_checked", False)
    _numba_cache.ensure_numba_cache()
    assert os.environ["NUMBA_CACHE_DIR"] == str(tmp_path / "mine")


class _ClosedPipe:
    """A stdout whose reader has gone (``rescon ... | head -0``)."""

    def write(self, text):
        raise BrokenPipeError(32, "Broken pipe")

    def flush(self):
        raise BrokenPipeError(32, "Broken pipe")

    def fileno(self):
        raise OSError("no file descriptor")


def test_cli_closed_stdout_is_not_reported_as_an_error(tmp_path, monkeypatch, capsys):
    """Failed before: ``rescon: error: [Errno 32] Broken pipe`` and exit 2. Now silent
    with 141 (128 + SIGPIPE), as a program killed by the closed pipe."""
    pts = tmp_path / "sq.csv"
    pts.write_text("0,0\n4,0\n4,4\n0,4\n1,3\n")
    monkeypatch.setattr(sys, "stdout", _ClosedPipe())
    assert main(["kernel", str(pts), "--F", "1", "--json"]) == 141
    assert capsys.readouterr().err == ""


@pytest.mark.parametrize("missing, argv, words", [
    ("matplotlib", ["kernel", "{pts}", "--F", "1", "--plot", "{tmp}/k.png", "--json"],
     "install rescon[plot]"),
    ("distributed", ["robustness", "{graph}", "--workers", "1", "--json"],
     "install rescon[dask]"),
    ("distributed", ["robustness", "{graph}", "--r", "1", "--workers", "1"],
     "install rescon[dask]"),
    ("distributed", ["sweep", str(EXAMPLES / "sweeps" / "small.toml"), "--out", "{tmp}/s"],
     "install rescon[dask]"),
    ("pyarrow", ["sweep", str(EXAMPLES / "sweeps" / "small.toml"), "--out", "{tmp}/s",
                 "--workers", "0", "--json"], "install rescon[dask]"),
    ("pandas", ["sweep", str(EXAMPLES / "sweeps" / "small.toml"), "--out", "{tmp}/s",
                "--workers", "0"], "install rescon[dask]"),
])
def test_cli_missing_extra_is_one_line_exit_2(missing, argv, words, tmp_path, monkeypatch,
                                              capsys):
    """Held before (V14 review): each extra removed says what to install, exit 2, empty
    stdout (no half JSON)."""
    pts = tmp_path / "sq.csv"
    pts.write_text("0,0\n4,0\n4,4\n0,4\n1,3\n")
    graph = _square(tmp_path)
    monkeypatch.setitem(sys.modules, missing, None)
    args = [a.format(pts=pts, graph=graph, tmp=tmp_path) for a in argv]
    assert main(args) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and words in err, err


def test_cli_redundancy_without_cvxpy_names_the_extra(tmp_path, monkeypatch, capsys):
    """A cost outside the exact class (logsumexp) needs CVXPY: one line, exit 2."""
    costs = tmp_path / "c.toml"
    costs.write_text('d = 2\n[costs]\n1 = "logsumexp(x1, x2)"\n2 = "x1^2 + x2^2"\n'
                     '3 = "abs(x1) + x2^2"\n')
    monkeypatch.setitem(sys.modules, "cvxpy", None)
    assert main(["redundancy", str(costs), "--r", "1", "--json"]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "cvxpy" in err and "install" in err


def test_pyproject_license_is_an_spdx_string():
    """Failed before: ``license = {text = "MIT"}``, which setuptools (84 here) warns is
    deprecated and will refuse after 2027-02-18; the SPDX string needs setuptools ≥ 77."""
    import tomllib

    meta = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert meta["project"]["license"] == "MIT"
    assert "setuptools>=77" in meta["build-system"]["requires"]
