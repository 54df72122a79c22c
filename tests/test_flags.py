"""Boolean keyword arguments are True or False, never read by their truth value (V33:
``read_graph(path, undirected="no")`` built an undirected graph)."""

from __future__ import annotations

import numpy as np
import pytest

import rescon
from rescon.errors import InputError
from rescon.graphs.generators import circulant
from rescon.io import read_graph
from rescon.optim.oracle import CallableOracle


@pytest.mark.parametrize("bad", ["no", "False", 0, 1, None, [], np.int64(1)])
def test_boolean_keywords_refuse_other_values(tmp_path, bad):
    path = tmp_path / "g.edgelist"
    path.write_text("1 2\n2 3\n")
    with pytest.raises(InputError, match="undirected must be True or False"):
        read_graph(path, undirected=bad)
    with pytest.raises(InputError, match="directed must be True or False"):
        circulant(8, 2, directed=bad)
    with pytest.raises(InputError, match="vectorised must be True or False"):
        CallableOracle(lambda x: 0.0, lambda x: x, d=1, vectorised=bad)
    tr = rescon.simulate(rescon.Scenario.paper_example(steps=2))
    with pytest.raises(InputError, match="log_diameter must be True or False"):
        tr.plot(log_diameter=bad)


def test_boolean_keywords_take_numpy_booleans(tmp_path):
    path = tmp_path / "g.edgelist"
    path.write_text("1 2\n2 3\n")
    assert not read_graph(path, undirected=np.bool_(True)).is_directed()
    assert circulant(8, 2, directed=np.bool_(True)).is_directed()
