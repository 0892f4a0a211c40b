"""Per-trace work spread over threads: the plain loop's results, in order, in a forked child too."""

from __future__ import annotations

import multiprocessing
import os

import numpy as np
import pytest

from flightlogs import _threads
from flightlogs._threads import map_traces


def _spectrum_peak(seed: int) -> float:
    x = np.random.default_rng(seed).normal(size=4096)
    return float(np.abs(np.fft.rfft(x)).max())


def test_results_are_the_loops_in_order() -> None:
    seeds = list(range(12))
    assert list(map_traces(_spectrum_peak, seeds)) == [_spectrum_peak(s) for s in seeds]


def test_an_exception_in_one_task_reaches_the_caller() -> None:
    def fail_on_three(k: int) -> int:
        if k == 3:
            raise ValueError("trace 3")
        return k

    with pytest.raises(ValueError, match="trace 3"):
        list(map_traces(fail_on_three, range(6)))


def test_one_thread_asked_for_means_no_pool(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("FLIGHT_SYSID_THREADS", "1")
    monkeypatch.setattr(_threads, "_POOLS", {})
    assert _threads._pool() is None
    assert list(map_traces(_spectrum_peak, [1, 2])) == [_spectrum_peak(1), _spectrum_peak(2)]


def _in_child(queue: multiprocessing.Queue) -> None:  # type: ignore[type-arg]
    queue.put(list(map_traces(_spectrum_peak, [5, 6, 7])))


@pytest.mark.skipif(not hasattr(os, "fork"), reason="fork is POSIX")
def test_a_forked_child_gets_its_own_pool() -> None:
    """The parent's pool threads do not exist in a fork: the child must not wait on them (it would hang)."""
    list(map_traces(_spectrum_peak, [1, 2]))  # the parent's pool exists before the fork
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=_in_child, args=(queue,))
    child.start()
    child.join(timeout=30)
    if child.exitcode is None:  # hung: end it, so that the failure is reported and not waited on
        child.kill()
        child.join()
    assert child.exitcode == 0
    assert queue.get(timeout=1) == [_spectrum_peak(s) for s in (5, 6, 7)]
