"""Per-log work in forked workers: the plain loop's results, warnings and first exception, in order."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from flightlogs.errors import DataQualityWarning
from flightlogs.parallel import map_forked, worker_count
from flightlogs.store.campaign import ingest_campaign

forking = pytest.mark.skipif(worker_count(2) < 2, reason="one core, or no fork: map_forked is a plain loop here")


def _peaks(n: int) -> list[float]:
    """A task per seed that warns and returns: its result depends only on memory the workers inherit."""
    data = [np.random.default_rng(seed).normal(size=4096) for seed in range(n)]

    def peak(k: int) -> float:
        warnings.warn(DataQualityWarning(f"task {k} of {n}"), stacklevel=1)
        return float(np.abs(np.fft.rfft(data[k])).max())

    return list(map_forked(peak, n))


@forking
def test_results_and_warnings_are_the_loops_in_order(monkeypatch: pytest.MonkeyPatch) -> None:
    with pytest.warns(DataQualityWarning) as forked:
        results = _peaks(7)
    monkeypatch.setenv("FLIGHT_SYSID_THREADS", "1")
    assert worker_count(7) == 1
    with pytest.warns(DataQualityWarning) as looped:
        expected = _peaks(7)
    assert results == expected
    assert [str(w.message) for w in forked] == [str(w.message) for w in looped] == [f"task {k} of 7" for k in range(7)]


@forking
def test_a_tasks_exception_is_raised_in_its_turn_with_the_workers_traceback() -> None:
    def fail_on_three(k: int) -> int:
        if k == 3:
            raise ValueError("log 3 has no attitude")
        return 10 * k

    got: list[int] = []
    with pytest.raises(ValueError, match="^log 3 has no attitude") as raised:
        for value in map_forked(fail_on_three, 6):
            got.append(value)
    assert got == [0, 10, 20]  # those before it, as a loop gives them
    assert str(raised.value) == "log 3 has no attitude"  # the one sentence a user reads: the note is for --debug
    (note,) = raised.value.__notes__
    assert note.startswith("raised in a worker process:") and "in fail_on_three" in note


def test_one_task_or_one_thread_asked_for_means_a_plain_loop(monkeypatch: pytest.MonkeyPatch) -> None:
    assert worker_count(1) == 1
    monkeypatch.setenv("FLIGHT_SYSID_THREADS", "1")
    assert worker_count(50) == 1
    monkeypatch.setenv("FLIGHT_SYSID_THREADS", "2")
    assert worker_count(50) <= 2


@forking
def test_a_campaign_conditioned_in_workers_equals_one_conditioned_in_a_loop(
    real_data: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    logs = [real_data / "pyulog" / "sample_appended_multiple.ulg", real_data / "dronekit-la-testdata" / "log171.bin"]
    with warnings.catch_warnings(record=True) as forked_warnings:
        warnings.simplefilter("always")
        forked = ingest_campaign(logs)
    monkeypatch.setenv("FLIGHT_SYSID_THREADS", "1")
    with warnings.catch_warnings(record=True) as looped_warnings:
        warnings.simplefilter("always")
        looped = ingest_campaign(logs)
    assert [str(w.message) for w in forked_warnings] == [str(w.message) for w in looped_warnings]
    assert forked.notes == looped.notes
    assert len(forked.flights) == len(looped.flights) == 2
    for a, b in zip(forked.flights, looped.flights):
        assert a.segments == b.segments and a.warnings == b.warnings
        assert [r.label for r in a.records] == [r.label for r in b.records]
        for ra, rb in zip(a.records, b.records):
            np.testing.assert_array_equal(ra.time_s, rb.time_s)
            assert ra.columns.keys() == rb.columns.keys()
            for name in ra.columns:
                np.testing.assert_array_equal(ra.columns[name], rb.columns[name])
