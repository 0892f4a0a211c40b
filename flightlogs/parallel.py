"""Per-log work on the machine's cores, in forked worker processes.

Conditioning a log is pure Python and numpy in turn and holds the GIL for
most of its time, so the logs of a campaign are conditioned in processes,
not threads. The workers are forked: they inherit the logs already read
(nothing is pickled on the way in) and send back only each result. Each
worker runs its own per-trace work on one thread (``FLIGHT_SYSID_THREADS=1``):
the cores are the workers'. The results, the warnings raised while making
them and the first exception are those of a plain loop, in order.

Where ``fork`` is not available, inside a daemon process (a worker of a pool),
or where ``FLIGHT_SYSID_THREADS`` asks for one thread (a batch scheduler that
already runs one task per core), the work runs in a plain loop.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import traceback
import warnings
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor
from typing import Any, TypeVar

__all__ = ["map_forked", "worker_count"]

_R = TypeVar("_R")
_TASK: Callable[[int], Any] | None = None  # the work of the current map, inherited by the forked workers


def worker_count(n_tasks: int) -> int:
    """How many worker processes `n_tasks` tasks get: 1 means a plain loop in this process.

    Parameters
    ----------
    n_tasks : int
        Independent tasks.

    Returns
    -------
    int
        ``min(cores, n_tasks)``, or 1 where forking is not possible or not wanted.
    """
    wanted = os.environ.get("FLIGHT_SYSID_THREADS", "")
    if (
        n_tasks < 2
        or (wanted.isdigit() and int(wanted) == 1)
        or "fork" not in multiprocessing.get_all_start_methods()
        or multiprocessing.current_process().daemon
    ):
        return 1
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    if wanted.isdigit() and int(wanted) > 0:
        cores = min(cores, int(wanted))
    return max(1, min(cores, n_tasks))


def map_forked(function: Callable[[int], _R], n_tasks: int) -> Iterator[_R]:
    """``function(k)`` for ``k in range(n_tasks)``, spread over forked workers, the results in order.

    Parameters
    ----------
    function : callable
        ``function(k) -> result``; it reads what it needs from memory this process already holds
        (the workers inherit it) and its result must pickle.
    n_tasks : int
        Number of tasks.

    Returns
    -------
    iterator
        The results in order. Before each is returned, the warnings its task raised are raised
        again here (under this process's filters); a task's exception is raised in its turn.
    """
    workers = worker_count(n_tasks)
    if workers == 1:
        return (function(k) for k in range(n_tasks))
    return _forked(function, n_tasks, workers)


def _forked(function: Callable[[int], _R], n_tasks: int, workers: int) -> Iterator[_R]:
    global _TASK
    _TASK = function
    context = multiprocessing.get_context("fork")
    try:
        with ProcessPoolExecutor(workers, mp_context=context, initializer=_in_worker) as pool:
            futures = [pool.submit(_run, k) for k in range(n_tasks)]
            try:
                for future in futures:
                    value, error, where, caught = future.result()
                    for message, category, filename, lineno in caught:
                        warnings.warn_explicit(message, category, filename, lineno)
                    if error is not None:
                        error.add_note(f"raised in a worker process:\n{where}")  # shown under --debug
                        raise error
                    yield value
            finally:
                for future in futures:
                    future.cancel()
    finally:
        _TASK = None


def _in_worker() -> None:
    """A worker's set-up: Ctrl-C is its parent's to handle, and its per-trace work runs on one thread."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.environ["FLIGHT_SYSID_THREADS"] = "1"


def _run(k: int) -> tuple[Any, BaseException | None, str, list[tuple[Warning | str, type[Warning], str, int]]]:
    """Task `k` in a worker: its result or its exception (with the worker's traceback), and every warning it raised."""
    assert _TASK is not None, "the task is set before the workers are forked"
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")  # every one goes back; the parent's filters decide what is shown
        try:
            value, error, where = _TASK(k), None, ""
        except Exception as err:  # sent back and raised there, in its turn
            value, error, where = None, err, traceback.format_exc()
    return value, error, where, [(w.message, w.category, w.filename, w.lineno) for w in seen]
