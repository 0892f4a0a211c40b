"""A campaign keeps the flights it could condition and says why when it could condition none."""

from __future__ import annotations

from pathlib import Path

import pytest

from flightlogs.errors import DataError
from flightlogs.store.campaign import Campaign, ingest_campaign


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
