"""The Dask client shared by everything rescon runs on a cluster (sweeps, split searches).

``client(scheduler, workers)`` connects to a running scheduler by address, with guards
against an address where nothing (or no Dask scheduler, or a silent peer) answers and a
scheduler without workers, or starts an embedded ``distributed.LocalCluster`` of worker
processes that is closed with the client. :class:`Workers` ends a wait on tasks once
the cluster has had no worker for ``WORKER_SECONDS``. dask is imported here, on first
use, never with rescon.
"""

from __future__ import annotations

import logging
import os
import threading
import time
from collections.abc import Iterator
from typing import Any

from ._validate import integer
from .errors import InputError, MissingDependency, SolverError

__all__ = ["CONNECT_SECONDS", "POLL_SECONDS", "WORKER_SECONDS", "Workers", "check_workers",
           "client", "require"]

#: seconds to reach a scheduler given by address, handshake included, before giving up
CONNECT_SECONDS = 5
#: seconds to wait for a first worker on a scheduler that has none (else: no task runs),
#: and for a worker again on a cluster that lost its last one
WORKER_SECONDS = 30
#: seconds between two looks at the cluster while tasks run
POLL_SECONDS = 0.2


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
    (default: the CPU count), one thread each, closed with the client. The client is
    not made the process's default (``set_as_default=False``): rescon submits to it
    explicitly, and the caller's own ``dask.compute`` keeps going where it went (R5)."""
    require()
    from distributed import Client, LocalCluster

    if scheduler is not None:
        if not isinstance(scheduler, str) or not scheduler:
            raise InputError(f"scheduler must be an address such as tcp://host:8786; got "
                             f"{scheduler!r}")
        connected = _connect(Client, scheduler)
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
    return _Owned(Client(cluster, set_as_default=False), cluster)


def _connect(Client: Any, scheduler: str) -> Any:
    """``Client(scheduler)``, or InputError "cannot connect" when it fails or has not
    connected within CONNECT_SECONDS + 2 s. Client's own timeout bounds reaching the
    address but not the handshake, which a peer that accepts and never answers (a
    tarpit, a server waiting for a request) never ends: the attempt runs in a daemon
    thread, and one that ends after the deadline closes what it made."""
    _parsed(scheduler)
    lock = threading.Lock()
    box: dict[str, Any] = {}

    def attempt() -> None:
        try:
            made = Client(scheduler, timeout=CONNECT_SECONDS, set_as_default=False)
        except Exception as exc:  # noqa: BLE001 (whatever answers there may be no Dask
            # scheduler: an HTTP reply read as a frame length is a MemoryError)
            made, box["error"] = None, exc
        with lock:
            if "abandoned" not in box:
                box["client"] = made
                return
        if made is not None:
            made.close()

    thread = threading.Thread(target=attempt, name="rescon-connect", daemon=True)
    thread.start()
    thread.join(CONNECT_SECONDS + 2)
    with lock:
        if "client" not in box:
            box["abandoned"] = True
    if box.get("client") is not None:
        return box["client"]
    exc = box.get("error")
    why = (f"no Dask handshake in {CONNECT_SECONDS + 2} s" if exc is None else
           f"{type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''}")
    raise InputError(f"scheduler {scheduler}: cannot connect ({why})")


def _parsed(scheduler: str) -> None:
    """InputError "cannot connect" for a tcp / tls address without a host and a numeric
    port, before any Client exists: a Client that fails in its constructor is closed by
    its finaliser, which can wait 10 s for its event loop — in whichever thread the
    garbage collector runs it (a later attempt's, which then missed its deadline)."""
    from distributed.comm import get_address_host_port, parse_address

    try:
        if parse_address(scheduler)[0] in ("tcp", "tls"):
            get_address_host_port(scheduler)
    except ValueError as exc:
        raise InputError(f"scheduler {scheduler}: cannot connect (ValueError: {exc})"
                         ) from None


class Workers:
    """Watches that the cluster still has a worker while the caller waits on its tasks:
    they would wait forever without one (a worker killed, no nanny to restart it)."""

    def __init__(self, client: Any) -> None:
        self.client, self.seen = client, time.perf_counter()

    def check(self) -> None:
        """SolverError once no worker has been seen for ``WORKER_SECONDS`` (the wait
        :func:`client` allows a scheduler for a first worker)."""
        now = time.perf_counter()
        if self.client.nthreads():
            self.seen = now
        elif now - self.seen > WORKER_SECONDS:
            raise SolverError(f"the Dask cluster has had no worker for {WORKER_SECONDS} s: "
                              "its tasks cannot run")

    def as_completed(self, futures: list[Any]) -> Iterator[Any]:
        """The futures as they finish (distributed's ``as_completed``: callbacks, O(1)
        per future), checking while none is ready that the cluster still has a worker
        (:meth:`check`, every POLL_SECONDS; ready ones are looked for every
        POLL_SECONDS / 10)."""
        from distributed import as_completed

        # the client's own loop: rescon's client is not the default one as_completed
        # would look up
        ready, idle = as_completed(futures, loop=self.client.loop), time.perf_counter()
        while not ready.is_empty():
            batch = ready.next_batch(block=False)
            if batch:
                idle = time.perf_counter()
                yield from batch
                continue
            time.sleep(POLL_SECONDS / 10)
            if time.perf_counter() - idle > POLL_SECONDS:
                self.check()
                idle = time.perf_counter()

    def finished(self, running: Any) -> set[Any]:
        """The futures of ``running`` (an iterable of futures) done within
        ``POLL_SECONDS``; when none is, the cluster must still have a worker
        (:meth:`check`) — the caller then checks its deadline."""
        from distributed import wait

        try:  # wait() asks for the current client; rescon's is not the default
            with self.client.as_current():
                return wait(list(running), timeout=POLL_SECONDS,
                            return_when="FIRST_COMPLETED").done
        except TimeoutError:
            self.check()
            return set()


#: seconds a worker of an embedded LocalCluster is given to stop (80 %) before it is killed
STOP_SECONDS = 0.25


class _Owned:
    """A client with the LocalCluster it owns: both closed on exit, the worker
    processes first, each given ``STOP_SECONDS`` to stop, then killed: a task still
    running (a search part, cancelled) holds its worker's thread, and the cluster's own
    close would wait 4 s for it (distributed's Nanny.close default) — after the caller's
    time limit. The workers hold nothing but their tasks' inputs."""

    def __init__(self, owned_client: Any, cluster: Any) -> None:
        self.client, self.cluster = owned_client, cluster

    def __enter__(self) -> Any:
        return self.client

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def close(self) -> None:
        """Close the client, stop the workers (killed after ``STOP_SECONDS``), close
        the cluster."""
        import asyncio

        self.client.close()
        nannies = list(self.cluster.workers.values())

        async def stop() -> None:
            await asyncio.gather(*(w.close(timeout=STOP_SECONDS) for w in nannies))

        log = logging.getLogger("distributed.nanny")
        log.addFilter(_kill_notice)
        try:
            self.cluster.sync(stop)
        finally:
            log.removeFilter(_kill_notice)
            self.cluster.close()


def _kill_notice(record: logging.LogRecord) -> bool:
    """Drops the nanny's warning that a worker it stops is killed (expected here)."""
    return "still alive after" not in record.getMessage()
