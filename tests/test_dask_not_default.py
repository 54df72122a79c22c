"""The clients rescon makes for its own work (an embedded LocalCluster, or a scheduler
address) are not made the process's default Dask client: rescon submits to them
explicitly, and the caller's ``dask.compute`` must not be sent to rescon's cluster
while it runs (R5 noticed an abandoned rescon client become the default)."""

from __future__ import annotations

import dask
import pytest

pytest.importorskip("distributed")

from distributed import default_client  # noqa: E402

from rescon import _dask  # noqa: E402


def _no_default() -> bool:
    try:
        default_client()
    except ValueError:
        return True
    return False


def test_embedded_cluster_client_is_not_the_default():
    assert _no_default()
    before = dask.config.get("scheduler", None)
    with _dask.client(None, 1) as connected:
        assert connected.submit(sum, [1, 2]).result() == 3  # rescon's own use works
        assert _no_default()  # the caller's dask.compute is not sent there
        assert dask.config.get("scheduler", None) == before
    assert _no_default() and dask.config.get("scheduler", None) == before
