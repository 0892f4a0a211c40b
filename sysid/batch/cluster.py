"""The Dask cluster a batch runs on: a local one sized to the machine, or a scheduler the user runs."""

from __future__ import annotations

import logging
import os
import signal
import threading
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
from typing import Any

from flightlogs.errors import SysidError

__all__ = ["batch_client"]


@contextmanager
def batch_client(scheduler: str | None = None, workers: int | None = None) -> Iterator[Any]:
    """A ``distributed.Client``, closed (with its local cluster) on leaving.

    Parameters
    ----------
    scheduler : str, optional
        Address of a running scheduler (``tcp://10.0.0.5:8786``); its workers must see the logs' paths.
    workers : int, optional
        Without `scheduler`: the local cluster's worker processes (default: one per core). Each runs
        one task at a time, single-threaded inside (``FLIGHT_SYSID_THREADS=1``): the cores are the workers'.

    Yields
    ------
    distributed.Client

    Raises
    ------
    SysidError
        If the scheduler cannot be reached.
    """
    from distributed import Client, LocalCluster

    # its INFO lines are no user's business, nor a worker's lost heartbeat when the batch is interrupted (a task's
    # own error reaches the client as an exception): under --debug everything is shown
    level = logging.DEBUG if logging.getLogger().isEnabledFor(logging.DEBUG) else logging.CRITICAL
    logging.getLogger("distributed").setLevel(level)
    if scheduler is not None:
        try:
            client = Client(scheduler, timeout="5s")  # type: ignore[no-untyped-call]
        except (OSError, TimeoutError) as err:
            raise SysidError(f"cannot reach the Dask scheduler at {scheduler} ({err})") from None
        try:
            yield client
        finally:
            client.close()  # type: ignore[no-untyped-call]
        return
    n = workers or os.cpu_count() or 1
    with ExitStack() as started:
        with _signals_held():  # delivered once the cluster is up, inside `started`: it is closed like any other
            cluster = started.enter_context(
                LocalCluster(  # type: ignore[no-untyped-call]
                    n_workers=n,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    silence_logs=level,
                    env={"FLIGHT_SYSID_THREADS": "1", "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"},
                )
            )
            client = started.enter_context(Client(cluster))  # type: ignore[no-untyped-call]
        yield client


@contextmanager
def _signals_held() -> Iterator[None]:
    """Hold SIGINT and SIGTERM while the block runs, then deliver the first one caught to the handlers in force.

    A local cluster interrupted while its workers start cannot be closed: ``distributed``'s exit handler
    then fails on a worker still starting and prints its traceback after the one-line "interrupted"
    (Ctrl-C 2.5-3.1 s into ``sysid batch`` on two workers). Held, the signal arrives a second or two later,
    when the cluster is up and closes cleanly. Outside the main thread (no signal handlers there): nothing held.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    caught: list[int] = []
    held = (signal.SIGINT, signal.SIGTERM)
    previous = {s: signal.signal(s, lambda signum, _frame: caught.append(signum)) for s in held}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    if caught:
        signal.raise_signal(caught[0])
