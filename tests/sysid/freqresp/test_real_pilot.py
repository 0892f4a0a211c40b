"""Closed-loop responses from a real log with pilot excitation only (issue 14): kd0aij's 250 racer, PX4 2016.

The log has no mixer input, no stick and no attitude estimate: the gyro, and
the rate and attitude setpoints the pilot's roll and pitch stick oscillations
drive. The maneuvers are those the detector finds (tested in
``tests/flightlogs/maneuvers/test_detection_independent.py``); the pairs name
the setpoints, whose axis is their own (no ``--axis`` needed).

What is known without our code: a rate loop with integral action follows
its setpoint at low frequency (0 dB, no phase) and falls behind as the
frequency rises, by its delays and lags.

Measured: p/p_ref -0.9 dB, -16 deg at 4 rad/s; +0.9 dB, -32 deg at 15 rad/s;
a +5 to +9 dB resonance at 30-40 rad/s; gamma^2 0.99-1.0 over 6-20 rad/s.
q/q_ref -0.6 dB, -11 deg at 4 rad/s; +1.0 dB, -34 deg at 15 rad/s.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from flightlogs.conditioning.condition import condition_flight
from flightlogs.readers import read_log
from sysid.freqresp import ResponseOptions
from sysid.freqresp.records import flight_responses

pytestmark = pytest.mark.filterwarnings("ignore::flightlogs.errors.SysidWarning")  # its dropouts, tested elsewhere

KD0AIJ = "kd0aij-impulse-response/log1.ulg"
TRACKING_RAD_S = (4.0, 15.0)  # below the loop's resonance, above where the pilot's input thins out
DB = 3.0  # a rate loop with integral action tracks within this of 0 dB there


@pytest.fixture(scope="module", name="responses")
def responses_fixture(real_data: Path):  # type: ignore[no-untyped-def]
    flight = condition_flight(read_log(real_data / KD0AIJ))
    found = flight_responses([flight], [("p", "p_ref"), ("q", "q_ref")], kind="broadband", options=ResponseOptions())
    return {r.pair: r for r in found.responses}


@pytest.mark.parametrize("pair", ["p/p_ref", "q/q_ref"])
def test_the_rate_loop_tracks_its_setpoint_and_falls_behind_with_frequency(responses, pair: str) -> None:  # type: ignore[no-untyped-def]
    response = responses[pair]
    w = response.omega
    tracking = (w >= TRACKING_RAD_S[0]) & (w <= TRACKING_RAD_S[1])
    assert np.all(response.coherence[tracking] >= 0.85), response.coherence[tracking].min()
    assert np.all(np.abs(response.magnitude_db[tracking]) <= DB), response.magnitude_db[tracking]
    phase = np.unwrap(np.radians(response.phase_deg[tracking]))
    assert np.all(phase < 0.0)  # it lags
    # the lag grows with frequency: the phase at the top of the band is at least twice that at the bottom
    assert phase[-1] < 1.5 * phase[0] < 0.0
