"""Tests of simulator.output.px4: a simulated flight written as a PX4 ULog reads back as simulated."""

from __future__ import annotations

from dataclasses import replace
from datetime import UTC, datetime, timedelta
from pathlib import Path

import numpy as np
import pytest
from pyulog import ULog

from flightlogs.flightlog import FlightLog
from flightlogs.readers.dispatch import read_log
from flightlogs.readers.px4_topics import rotor_count
from simulator.autopilot.excitation import Maneuver
from simulator.flights.linear import SimulatedFlight, WindField, simulate_hover
from simulator.output.px4 import AIRFRAMES, write_px4_log
from simulator.vehicle.identified import LIGHT_WIND_TERMS

UTC_START = datetime(2024, 5, 1, 10, 0, 0, 123_456, tzinfo=UTC)
LOG_START_S = 20.0
HOVER = 0.5
F32 = float(np.finfo(np.float32).eps)  # relative precision of the logged floats


@pytest.fixture(scope="module")
def flight() -> SimulatedFlight:
    """12 s of hover in light wind with a pitch sweep, a roll doublet and a yaw doublet."""
    maneuvers = (
        Maneuver(axis="lon", kind="sweep", start_s=1.0, amplitude=8.0, duration_s=7.0, fade_in_s=1.0, f_stop_hz=5.0),
        Maneuver(axis="lat", kind="doublet", start_s=8.5, amplitude=15.0, duration_s=1.0),
        Maneuver(axis="yaw", kind="doublet", start_s=10.0, amplitude=10.0, duration_s=1.0),
    )
    return simulate_hover(12.0, maneuvers, wind=WindField(), wind_terms=LIGHT_WIND_TERMS, seed=4)


@pytest.fixture(scope="module")
def with_motors(flight: SimulatedFlight) -> SimulatedFlight:
    """The flight with motor commands (%) and a battery voltage of its own, as a richer simulator logs."""
    rng = np.random.default_rng(5)
    extra = {f"motor_{k + 1}": 50.0 + rng.normal(scale=5.0, size=flight.time_s.size) for k in range(8)}
    extra["battery_v"] = 24.9 - 0.01 * flight.time_s + rng.normal(scale=0.02, size=flight.time_s.size)
    return replace(flight, signals=dict(flight.signals) | extra)


@pytest.fixture(scope="module")
def read_back(with_motors: SimulatedFlight, tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, FlightLog]:
    path = tmp_path_factory.mktemp("px4") / "flight.ulg"
    assert write_px4_log(with_motors, path, utc_start=UTC_START) == path
    return path, read_log(path)


def assert_float32_equal(got: np.ndarray, expected: np.ndarray, name: str) -> None:
    """Values equal to the float32 rounding of `expected` (exactly what the file can hold)."""
    np.testing.assert_array_equal(got, np.asarray(expected, np.float32).astype(np.float64), err_msg=name)


def test_every_canonical_signal_reads_back(read_back: tuple[Path, FlightLog], with_motors: SimulatedFlight) -> None:
    _, log = read_back
    s = with_motors.signals
    expected = {
        name: s[name] for name in ("p", "q", "r", "vn", "ve", "vd", "ax", "ay", "az", "height_agl", "battery_v")
    }
    expected |= {f"delta_{axis}": s[f"delta_{axis}"] / 100.0 for axis in ("lat", "lon", "yaw")}
    expected["delta_thr"] = HOVER + s["delta_thr"] / 100.0
    expected |= {f"motor_{k}": s[f"motor_{k}"] / 100.0 for k in range(1, 9)}
    assert log.missing == ()
    assert log.warnings == ()
    for name, values in expected.items():
        signal = log[name]
        step = 10 if name == "battery_v" else 1  # battery_status at 10 Hz, the rest at the flight's 100 Hz
        np.testing.assert_allclose(signal.time_s, with_motors.time_s[::step] + LOG_START_S, rtol=0, atol=1e-6)
        assert_float32_equal(signal.values, values[::step], name)
    assert log["delta_thr"].source == "-vehicle_thrust_setpoint[0].xyz[2]"
    assert log["height_agl"].source == "vehicle_local_position[0].dist_bottom"


def test_attitude_reads_back_through_the_quaternion(
    read_back: tuple[Path, FlightLog], with_motors: SimulatedFlight
) -> None:
    _, log = read_back
    for name in ("phi", "theta", "psi"):
        error = np.angle(np.exp(1j * (log[name].values - with_motors.signals[name])))
        # a float32 quaternion holds each angle to a few float32 ulps of 1
        np.testing.assert_allclose(error, 0.0, atol=8 * F32, err_msg=name)


def test_estimated_wind_is_the_wind_at_the_vehicle(
    read_back: tuple[Path, FlightLog], with_motors: SimulatedFlight
) -> None:
    _, log = read_back
    for k, name in enumerate(("est_wind_n", "est_wind_e")):
        np.testing.assert_allclose(log[name].time_s, with_motors.time_s[::4] + LOG_START_S, rtol=0, atol=1e-6)
        assert_float32_equal(log[name].values, with_motors.wind_at_vehicle[::4, k], name)


def test_utc_start_reads_back(read_back: tuple[Path, FlightLog]) -> None:
    _, log = read_back
    assert log.utc_start is not None
    assert abs(log.utc_start - UTC_START) < timedelta(milliseconds=1)
    assert log.utc_offset_s == pytest.approx(UTC_START.timestamp() - LOG_START_S, abs=1e-6)


def test_airframe_and_topics_are_px4s(read_back: tuple[Path, FlightLog]) -> None:
    path, log = read_back
    assert rotor_count(log.parameters) == 8
    assert log.parameters["MAV_TYPE"] == 14 and log.parameters["SYS_AUTOSTART"] == 8001
    assert "octorotor" in log.vehicle
    ulog = ULog(str(path))
    assert {d.name for d in ulog.data_list} == {
        "vehicle_angular_velocity",
        "vehicle_attitude",
        "vehicle_local_position",
        "vehicle_acceleration",
        "vehicle_torque_setpoint",
        "vehicle_thrust_setpoint",
        "actuator_motors",
        "battery_status",
        "sensor_gps",
        "wind",
    }
    local = ulog.get_dataset("vehicle_local_position").data
    assert all(local[flag].all() for flag in ("xy_valid", "z_valid", "v_xy_valid", "v_z_valid", "dist_bottom_valid"))
    np.testing.assert_array_equal(local["z"], -local["dist_bottom"])
    motors = ulog.get_dataset("actuator_motors").data
    assert np.isnan(motors["control[8]"]).all() and np.isfinite(motors["control[7]"]).all()
    thrust = ulog.get_dataset("vehicle_thrust_setpoint").data
    assert (thrust["xyz[2]"] < 0).all()  # thrust points up: negative body z
    gps = ulog.get_dataset("sensor_gps").data
    assert (gps["fix_type"] == 3).all()
    assert ulog.message_formats["vehicle_attitude"].fields[:3] == [
        ("uint64_t", 0, "timestamp"),
        ("uint64_t", 0, "timestamp_sample"),
        ("float", 4, "q"),
    ]


def test_motors_come_from_the_mixer_without_motor_signals(flight: SimulatedFlight, tmp_path: Path) -> None:
    path = write_px4_log(flight, tmp_path / "quad.ulg", utc_start=UTC_START, airframe="quad")
    log = read_log(path)
    assert sorted(n for n in log.signals if n.startswith("motor_")) == [f"motor_{k}" for k in range(1, 5)]
    assert log.parameters["CA_ROTOR_COUNT"] == 4 and log.parameters["MAV_TYPE"] == 2
    torque = np.column_stack([log["delta_lat"].values, log["delta_lon"].values, log["delta_yaw"].values])
    motors = np.column_stack([log[f"motor_{k}"].values for k in range(1, 5)])
    mixed = AIRFRAMES["quad"].mix(log["delta_thr"].values, torque)
    np.testing.assert_allclose(motors, mixed, rtol=0, atol=4 * F32)
    # quad X: the motors average to the thrust; rolling right (positive) speeds up the left motors 2 and 3
    np.testing.assert_allclose(motors.mean(axis=1), log["delta_thr"].values, atol=4 * F32)
    roll = (motors[:, 1] + motors[:, 2] - motors[:, 0] - motors[:, 3]) / 4
    np.testing.assert_allclose(roll, np.sqrt(0.5) * torque[:, 0], atol=4 * F32)
    volts = log["battery_v"].values
    assert 16.0 < volts.min() and volts.max() <= 16.8 and (np.diff(volts) <= 0).all()


def test_a_flight_without_the_needed_signals_is_refused(flight: SimulatedFlight, tmp_path: Path) -> None:
    signals = {k: v for k, v in flight.signals.items() if k != "height_agl"}
    with pytest.raises(ValueError, match="height_agl"):
        write_px4_log(replace(flight, signals=signals), tmp_path / "x.ulg", utc_start=UTC_START)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"utc_start": datetime(2024, 5, 1, 10)}, "timezone-aware"),
        ({"utc_start": UTC_START, "airframe": "quad"}, "8 motors"),
    ],
)
def test_bad_options_are_refused(with_motors: SimulatedFlight, tmp_path: Path, kwargs: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        write_px4_log(with_motors, tmp_path / "x.ulg", **kwargs)
    assert not list(tmp_path.iterdir())
