"""The Examples sections of the public docstrings run as doctests."""

from __future__ import annotations

import doctest
import importlib

import pytest

MODULES = [
    "rescon.graphs.robustness",
    "rescon.graphs.sarymsakov",
    "rescon.graphs.generators",
    "rescon.graphs.attacks",
    "rescon.io",
    "rescon.geometry.kernel",
    "rescon.geometry.tverberg",
    "rescon.consensus.dos",
    "rescon.consensus.adversaries",
    "rescon.optim.redundancy",
]


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    result = doctest.testmod(importlib.import_module(name), optionflags=doctest.ELLIPSIS)
    assert result.failed == 0, f"{result.failed} doctest example(s) failed in {name}"
