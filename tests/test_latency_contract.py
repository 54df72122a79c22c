"""What a user waits for (BENCHMARKS.md §6): ``import rescon`` and the command line's
start load nothing heavy; every public name is still there.

Each check runs in a fresh interpreter and reads its ``sys.modules``, so a module-level
import added anywhere on the path fails it.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

import rescon

#: modules that must not load with ``import rescon`` (nor with the CLI's parser)
HEAVY = ("scipy", "networkx", "distributed", "dask", "pandas", "pyarrow", "matplotlib",
         "numba", "llvmlite", "cvxpy", "casadi", "tqdm", "sympy")
#: rescon's own modules that hold numba code
COMPILED = ("rescon.graphs._kernels", "rescon.geometry._candidates",
            "rescon.geometry._small2d", "rescon.geometry._small3d",
            "rescon.geometry._expansions")


def _loaded(code: str) -> list[str]:
    """The modules loaded after running ``code`` in a fresh interpreter."""
    probe = f"{code}\nimport json, sys\nprint(json.dumps(sorted(sys.modules)))"
    proc = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True,
                          timeout=120, check=True)
    return json.loads(proc.stdout.splitlines()[-1])


def _heavy(mods: list[str]) -> list[str]:
    return [m for m in mods if m.split(".")[0] in HEAVY or m in COMPILED]


def test_import_rescon_loads_nothing_heavy():
    mods = _loaded("import rescon")
    assert _heavy(mods) == []
    assert "numpy" not in mods  # nothing at all beyond the package's own lazy table


def test_cli_parser_loads_nothing_heavy():
    """``rescon --help`` / ``--version`` / a usage error answer without the science."""
    mods = _loaded("from rescon.cli import _parser\n_parser().parse_args(['check', 'x'])")
    assert _heavy(mods) == []


def test_every_public_name_is_reachable_and_star_import_works():
    names: dict[str, object] = {}
    exec("from rescon import *", names)  # noqa: S102 - the star import under test
    assert set(rescon.__all__) <= set(names)
    for name in rescon.__all__:
        assert getattr(rescon, name) is names[name]
    assert names["sweep"] is sys.modules["rescon.sweep"] and callable(names["sweep"])
    assert rescon.sweep.sweep.__module__ == "rescon.sweep.run"
    assert set(rescon.__all__) <= set(dir(rescon))


def test_unknown_attribute_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        rescon.nope  # noqa: B018
    assert not hasattr(rescon, "__wrapped__")


def test_submodules_stay_reachable_as_attributes():
    mods = _loaded("import rescon\nassert rescon.graphs.__name__ == 'rescon.graphs'\n"
                   "assert rescon.geometry.__name__ == 'rescon.geometry'")
    assert "rescon.graphs" in mods and "networkx" not in mods
    out = subprocess.run([sys.executable, "-c", "import rescon; print(rescon.__version__)"],
                         capture_output=True, text=True, timeout=60, check=True).stdout
    assert json.dumps(out.strip()) == json.dumps(rescon.__version__)
