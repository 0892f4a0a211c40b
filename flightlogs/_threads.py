"""Per-trace work on the machine's cores: numpy's FFTs, partitions and reductions release the GIL.

Maneuver detection treats each logged trace alone (its band envelopes, its
activity), so the traces are independent tasks. Threads, not processes: the
arrays are shared, not copied. The results are those of a plain loop, in
order. ``FLIGHT_SYSID_THREADS`` caps the threads (1: no pool), for a batch
scheduler that already runs one task per core.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

__all__ = ["map_traces"]

_T = TypeVar("_T")
_R = TypeVar("_R")
_MAX_THREADS = 4  # the per-trace tasks are few (4-20); beyond this threads only contend


def map_traces(function: Callable[[_T], _R], items: Iterable[_T]) -> Iterator[_R]:
    """``function(item)`` for each item, the items spread over the available cores, the results in order.

    Parameters
    ----------
    function : callable
        Applied to each item; it must not depend on the others' side effects.
    items : iterable
        The tasks, e.g. one trace each.

    Returns
    -------
    iterator
        The results in the order of `items`, each as soon as it and those before it are done (a caller that
        folds them as they come holds a few at a time); the first exception raised, if any, is raised there.
    """
    tasks = list(items)
    pool = _pool()
    if pool is None or len(tasks) < 2:
        return (function(item) for item in tasks)
    return pool.map(function, tasks)


_POOLS: dict[int, ThreadPoolExecutor | None] = {}  # by process id: a forked child must not use its parent's threads


def _pool() -> ThreadPoolExecutor | None:
    pid = os.getpid()
    if pid not in _POOLS:
        cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
        wanted = os.environ.get("FLIGHT_SYSID_THREADS", "")
        threads = min(_MAX_THREADS, cores, int(wanted) if wanted.isdigit() and int(wanted) > 0 else cores)
        _POOLS.clear()
        _POOLS[pid] = ThreadPoolExecutor(threads, thread_name_prefix="flightlogs") if threads > 1 else None
    return _POOLS[pid]
