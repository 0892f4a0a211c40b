"""A logging dropout (every topic silent for 0.1-0.3 s, as a real SD card's stall) cuts a piece; it drops no signal.

The core signals resume a sample after the gap, a 10 Hz estimate up to a tenth of a second later: the
slower signal's first value is held over those few samples (1.5 of its periods at most), as at the
log's own edges. Before, the velocity was left out of the whole piece around each dropout ("vn: not
logged through piece 4 of 5"), and with it every term of the discrepancy search that needs a speed.
The log comes from the independent generator (``independent_sim``), whose writer removes the samples.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from independent_sim import simulate
from independent_sim.pairs import open_pair_case
from independent_sim.px4_log import write_px4

from flightlogs.conditioning.condition import ConditioningOptions, condition_flight
from flightlogs.readers import read_log

pytestmark = pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")


def test_every_piece_between_dropouts_keeps_the_slow_estimates(tmp_path: Path) -> None:
    flight = simulate(open_pair_case("dropouts", 17))
    assert len(flight.dropouts_s) >= 1 and all(0.1 <= b - a <= 0.3 for a, b in flight.dropouts_s)
    log = tmp_path / "dropouts.ulg"
    write_px4(flight, log)
    conditioned = condition_flight(read_log(log), options=ConditioningOptions(segments=()))
    assert len(conditioned.records) >= len(flight.dropouts_s) + 1  # cut at each gap
    for record in conditioned.records:
        if record.time_s[-1] - record.time_s[0] >= 2.0:
            assert {"vn", "ve", "vd"} <= set(record.signals), record.label
