"""The Dask client shared by everything rescon runs on a cluster (sweeps, split searches).

``client(scheduler, workers)`` connects to a running scheduler by address, with guards
against an address where nothing (or no Dask scheduler) answers and a scheduler without
workers, or starts an embedded ``distributed.LocalCluster`` of worker processes that is
closed with the client. dask is imported here, on first use, never with rescon.
"""

from __future__ import annotations

import os
from typing import Any

from ._validate import integer
from .errors import InputError, MissingDependency

__all__ = ["CONNECT_SECONDS", "WORKER_SECONDS", "check_workers", "client", "require"]

#: seconds to reach a scheduler given by address before giving up
CONNECT_SECONDS = 5
#: seconds to wait for a first worker on a scheduler that has none (else: no task runs)
WORKER_SECONDS = 30


def check_workers(scheduler: str | None, workers: int | None) -> int | None:
    """``workers`` as a Python int (numpy integers accepted) or None; refuses both a
    scheduler and a worker count, or a count that is not an integer ≥ 0 (0: run
    serially in this process)."""
    if scheduler is not None and workers is not None:
        raise InputError("workers: give either scheduler (an existing cluster) or workers")
    return None if workers is None else integer("workers", workers, low=0)


def require() -> None:
    """Refuse, in one line, to go on without dask[distributed]."""
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise MissingDependency("dask[distributed] is not installed: install "
                                "rescon[dask]") from None


def client(scheduler: str | None, workers: int | None) -> Any:
    """A context manager giving a distributed.Client on ``scheduler`` (refused within
    CONNECT_SECONDS when unreachable, within WORKER_SECONDS when no worker joins it: its
    tasks would wait forever) or on an embedded LocalCluster of ``workers`` processes
    (default: the CPU count), one thread each, closed with the client."""
    require()
    from distributed import Client, LocalCluster

    if scheduler is not None:
        if not isinstance(scheduler, str) or not scheduler:
            raise InputError(f"scheduler must be an address such as tcp://host:8786; got "
                             f"{scheduler!r}")
        try:
            connected = Client(scheduler, timeout=CONNECT_SECONDS)
        except Exception as exc:  # noqa: BLE001 (whatever answers there may be no Dask
            # scheduler: an HTTP reply read as a frame length is a MemoryError)
            raise InputError(f"scheduler {scheduler}: cannot connect ({type(exc).__name__}: "
                             f"{str(exc).splitlines()[0] if str(exc) else ''})") from None
        try:
            connected.wait_for_workers(1, timeout=WORKER_SECONDS)
        except TimeoutError:
            connected.close()
            raise InputError(f"scheduler {scheduler}: no worker joined in {WORKER_SECONDS} s "
                             f"(start one: dask worker {scheduler})") from None
        return connected
    n = workers if workers is not None else (os.cpu_count() or 1)
    cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    return _Owned(Client(cluster), cluster)


class _Owned:
    """A client with the LocalCluster it owns: both closed on exit."""

    def __init__(self, owned_client: Any, cluster: Any) -> None:
        self.client, self.cluster = owned_client, cluster

    def __enter__(self) -> Any:
        return self.client

    def __exit__(self, *exc: Any) -> None:
        self.client.close()
        self.cluster.close()
