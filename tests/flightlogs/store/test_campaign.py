"""A campaign keeps the flights it could condition and says why when it could condition none."""

from __future__ import annotations

import os
import warnings
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest

from flightlogs.conditioning.condition import ConditionedFlight, ConditioningOptions
from flightlogs.errors import DataError, DataQualityWarning, LogFormatError
from flightlogs.flightlog import FlightLog
from flightlogs.parallel import worker_count
from flightlogs.store.campaign import Campaign, conditioned_campaign, ingest_campaign
from simulator.campaign.fly import plan_trials, run_scenario
from simulator.campaign.scenario import load_builtin
from simulator.flights.linear import simulate_hover
from simulator.output.px4 import write_px4_log


def test_no_conditioned_flight_names_each_logs_reason() -> None:
    campaign = Campaign(
        logs=(),
        winds=(),
        conditioned=(None, None),
        notes=(("not conditioned: a.ulg has no attitude",), ("not conditioned: b.bin is 2 s long",)),
    )
    assert campaign.flights == ()
    with pytest.raises(
        DataError,
        match=r"^no log could be conditioned \(not conditioned: a.ulg has no attitude; "
        r"not conditioned: b.bin is 2 s long\)$",
    ):
        campaign.require_flights()


@pytest.mark.filterwarnings("ignore::flightlogs.errors.DataQualityWarning")  # the logs' own (no wind, invalid vn ve)
def test_real_logs_are_kept_in_order(real_data: Path) -> None:
    logs = [real_data / "pyulog" / "sample_appended_multiple.ulg", real_data / "dronekit-la-testdata" / "log171.bin"]
    campaign = ingest_campaign(logs)
    assert campaign.require_flights() == campaign.flights
    assert [f.source.name for f in campaign.flights] == [p.name for p in logs]


@pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")  # the logs' own, not tested here
def test_progress_counts_the_bytes_of_all_logs_once(real_data: Path) -> None:
    """Issue 14: the bar counted each file's bytes and reset between files. Now one count over all logs."""
    logs = [real_data / "pyulog" / "sample_appended_multiple.ulg", real_data / "dronekit-la-testdata" / "log171.bin"]
    calls: list[tuple[str, int, int]] = []
    ingest_campaign(logs, progress=lambda name, done, total: calls.append((name, done, total)))
    total = sum(p.stat().st_size for p in logs)
    assert {c[2] for c in calls} == {total}
    done = [c[1] for c in calls]
    assert done == sorted(done) and done[0] == 0 and done[-1] == total
    assert [c[0] for c in calls if c[1] == logs[0].stat().st_size][0] == logs[
        0
    ].name  # the first file ends where the second starts


@pytest.fixture(scope="module")
def windy_trials(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Three sweeps of the chapter 3 campaign, one in each wind, with their anemometer files."""
    scenario = load_builtin("chapter3-campaign")
    wanted = ("strong-lon-sweep-1", "light-thr-sweep-2", "calm-lat-sweep-1")
    out = tmp_path_factory.mktemp("campaign")
    run_scenario(scenario, out, trials=[p.index for p in plan_trials(scenario) if p.name in wanted])
    return out


def _same_flights(found: tuple[ConditionedFlight, ...], expected: tuple[ConditionedFlight, ...]) -> None:
    assert [f.source for f in found] == [f.source for f in expected]
    for flight, other in zip(found, expected):
        assert flight.wind == other.wind and flight.segments == other.segments and flight.rate_hz == other.rate_hz
        assert len(flight.records) == len(other.records)
        for record, again in zip(flight.records, other.records):
            np.testing.assert_array_equal(record.time_s, again.time_s)
            assert record.signals == again.signals and dict(record.trim) == dict(again.trim)
            for name in record.signals:
                np.testing.assert_array_equal(record[name], again[name])


@pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")  # the logs' own, not tested here
def test_logs_read_where_they_are_conditioned_give_the_ingests_flights(real_data: Path, windy_trials: Path) -> None:
    """Real logs without wind, and simulated ones paired with their anemometer files by UTC."""
    real = [real_data / "pyulog" / "sample_appended_multiple.ulg", real_data / "dronekit-la-testdata" / "log171.bin"]
    _same_flights(conditioned_campaign(real), ingest_campaign(real).require_flights())
    logs = sorted(windy_trials.glob("*.bin"))
    options = ConditioningOptions(wind_distance_m=4.6)
    found = conditioned_campaign(logs, [windy_trials], options=options)
    _same_flights(found, ingest_campaign(logs, [windy_trials], options=options).require_flights())
    assert len(found) == 3 and all(f.wind is not None for f in found)


def test_the_logs_are_read_in_the_workers_and_the_progress_counts_each_once(
    real_data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    if worker_count(2) < 2:
        pytest.skip("one core: the logs are read here, in a loop")
    import flightlogs.store.campaign as campaign

    read = campaign.read_log

    def noted(path: Path, **kwargs: object) -> FlightLog:  # each reading process leaves its id in a file
        (tmp_path / f"{os.getpid()}-{Path(path).name}").touch()
        return read(path, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(campaign, "read_log", noted)
    logs = [real_data / "pyulog" / "sample_appended_multiple.ulg", real_data / "dronekit-la-testdata" / "log171.bin"]
    calls: list[tuple[str, int, int]] = []
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the logs' own
        conditioned_campaign(logs, progress=lambda name, done, total: calls.append((name, done, total)))
    readers = {int(p.name.split("-")[0]) for p in tmp_path.iterdir()}
    assert len(list(tmp_path.iterdir())) == 2 and os.getpid() not in readers  # each log once, none here
    sizes = [p.stat().st_size for p in logs]
    assert calls == [
        (logs[0].name, 0, sum(sizes)),
        (logs[0].name, sizes[0], sum(sizes)),
        (logs[1].name, sum(sizes), sum(sizes)),
    ]


def test_a_log_that_cannot_be_read_is_named(tmp_path: Path) -> None:
    broken = tmp_path / "broken.ulg"
    broken.write_bytes(b"not a log at all" * 64)
    with pytest.raises(LogFormatError, match="broken.ulg"):
        conditioned_campaign([broken])


def test_a_log_too_short_to_condition_is_left_out_with_its_reason(real_data: Path, tmp_path: Path) -> None:
    """Read in a worker but not conditioned (1.5 s of flight, under the 2 s a record needs): a warning and the
    others kept; alone, the one sentence that gives its reason."""
    flight = simulate_hover(1.5, (), rate_hz=25.0, substeps=2, seed=3)
    short = write_px4_log(flight, tmp_path / "short.ulg", utc_start=datetime(2025, 5, 1, 10, tzinfo=UTC))
    good = real_data / "dronekit-la-testdata" / "log171.bin"
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        kept = conditioned_campaign([short, good])
    assert [f.source.name for f in kept] == [good.name]
    assert any(
        isinstance(w.message, DataQualityWarning) and str(w.message).startswith(f"not conditioned: {short}")
        for w in seen
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(DataError, match=r"^no log could be conditioned \(not conditioned: .*short\.ulg"):
            conditioned_campaign([short])
