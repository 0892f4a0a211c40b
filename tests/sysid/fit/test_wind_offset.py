"""The wind a model's G_w is driven with: the anemometer's, low-passed as the wind step regresses on it."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from flightlogs.conditioning.condition import ConditionedFlight, ConditioningOptions, condition_flight
from flightlogs.frames import air_velocity_body, wind_to_body_axes
from flightlogs.readers.anemometer import read_anemometer_csv
from flightlogs.readers.dispatch import read_log
from simulator.campaign.demo_flight import write_demo_flight
from sysid.fit.wind_offset import SMOOTHING_HZ, smoothed, smoothed_flights


@pytest.fixture(scope="module")
def flight(tmp_path_factory: pytest.TempPathFactory) -> ConditionedFlight:
    files = write_demo_flight(tmp_path_factory.mktemp("demo"), clock_offset_s=1.5)
    options = ConditioningOptions(wind_distance_m=4.6, wind_offset_s=1.5)
    return condition_flight(read_log(files.log), read_anemometer_csv(files.wind_csv), options)


def _noisy(flight: ConditionedFlight, seed: int) -> ConditionedFlight:
    """The flight with 0.3 m/s of white noise on the anemometer's north and east wind (u v w left as they were:
    only the smoothing's own change of them is compared)."""
    rng = np.random.default_rng(seed)
    records = []
    for record in flight.records:
        noise = {n: record[n] + 0.3 * rng.standard_normal(record.time_s.size) for n in ("wind_n", "wind_e")}
        records.append(replace(record, columns=dict(record.columns) | noise))
    return replace(flight, records=tuple(records))


def _above_cut_off(x: np.ndarray, rate_hz: float) -> float:
    """Share of `x`'s power above twice the smoothing's cut-off."""
    power = np.abs(np.fft.rfft(x - x.mean())) ** 2
    f = np.fft.rfftfreq(x.size, 1.0 / rate_hz)
    return float(power[f > 2 * SMOOTHING_HZ].sum() / power.sum())


def test_the_wind_is_low_passed_and_u_v_w_follow_it(flight: ConditionedFlight) -> None:
    noisy = _noisy(flight, seed=3)
    (smooth,) = smoothed_flights([noisy])
    assert smooth.wind == noisy.wind  # the clock offset and the alignment as they were
    assert len(smooth.records) == len(noisy.records)
    for before, after in zip(noisy.records, smooth.records):
        wind = np.column_stack([before["wind_n"], before["wind_e"]])
        change = np.column_stack([after["wind_n"], after["wind_e"]]) - wind
        np.testing.assert_allclose(change, smoothed(wind, before.rate_hz) - wind, atol=1e-12)
        assert _above_cut_off(after["wind_n"], after.rate_hz) < 0.01 < _above_cut_off(before["wind_n"], before.rate_hz)
        angles = [before.absolute(n) for n in ("phi", "theta", "psi")]
        uvw = air_velocity_body(np.zeros((change.shape[0], 3)), change, *angles)  # eq. 3.1: the ground speed kept
        for k, name in enumerate("uvw"):
            np.testing.assert_allclose(after[name] - before[name], uvw[:, k], atol=1e-12)
        body = wind_to_body_axes(change, angles[2])
        for k, name in enumerate(("wind_lon", "wind_lat")):
            np.testing.assert_allclose(after[name] - before[name], body[:, k], atol=1e-12)


def test_a_flight_without_wind_is_kept_as_it_is(flight: ConditionedFlight) -> None:
    calm = replace(flight, wind=None)
    assert smoothed_flights([calm])[0] is calm
