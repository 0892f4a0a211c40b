"""A log of a vehicle that is not a multirotor is refused in one sentence (issue 32, item 3).

PX4 says what it flies in ``MAV_TYPE`` and ``CA_AIRFRAME``, ArduPilot in its
firmware's name (ArduCopter, ArduPlane, ArduRover) and a telemetry log in
the HEARTBEAT's ``type``. Every real log in ``../shared/data/real`` is a
multirotor (or a generic ``MAV_TYPE 0``, which says nothing) and is read.
"""

from __future__ import annotations

import warnings
from datetime import UTC, datetime
from pathlib import Path

import pytest
from click.testing import CliRunner
from pyulog import ULog

from flightlogs.errors import SysidWarning
from flightlogs.readers import read_log
from simulator.autopilot.excitation import Maneuver
from simulator.flights.linear import simulate_hover
from simulator.output.ardupilot import write_ardupilot_log
from simulator.output.px4 import write_px4_log
from simulator.vehicle.identified import CALM_HOVER
from sysid_cli.main import cli

REAL = Path(__file__).resolve().parents[3] / "shared" / "data" / "real"
START = datetime(2024, 5, 1, 10, tzinfo=UTC)


@pytest.fixture(scope="module", name="flight")
def flight_fixture():  # type: ignore[no-untyped-def]
    return simulate_hover(
        30.0,
        (Maneuver(axis="lat", kind="sweep", start_s=5.0, amplitude=8.0, duration_s=20.0),),
        parameters=CALM_HOVER,
        seed=1,
    )


def _fixed_wing_ulog(flight, folder: Path) -> Path:  # type: ignore[no-untyped-def]
    """Our simulator's PX4 log with the parameters of a fixed wing (MAV_TYPE 1, CA_AIRFRAME 1)."""
    ulog = ULog(str(write_px4_log(flight, folder / "quad.ulg", utc_start=START)))
    ulog._initial_parameters.update({"MAV_TYPE": 1, "CA_AIRFRAME": 1})  # what write_ulog writes
    ulog.write_ulog(str(folder / "plane.ulg"))
    return folder / "plane.ulg"


def test_a_px4_fixed_wing_is_refused_and_can_be_forced(flight, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    plane, out = _fixed_wing_ulog(flight, tmp_path), tmp_path / "out.h5"
    refused = CliRunner().invoke(cli, ["ingest", str(plane), "-o", str(out), "-q"])
    assert refused.exit_code == 1 and not out.exists()
    assert refused.stderr == (
        f"error: {plane}: a fixed-wing (CA_AIRFRAME 1), not a multirotor; the models here are a multirotor's "
        "(read it as one with --vehicle multirotor)\n"  # the library names `force_multirotor`: the CLI its flag
    )
    forced = CliRunner().invoke(cli, ["ingest", str(plane), "--vehicle", "multirotor", "--json", "-", "-q"])
    assert forced.exit_code == 0, forced.output
    assert "plane.ulg: a fixed-wing (CA_AIRFRAME 1), read as a multirotor as asked" in forced.stdout


def test_an_arduplane_log_is_refused(flight, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    copter = write_ardupilot_log(flight, tmp_path / "copter.bin", utc_start=START)
    raw = copter.read_bytes()
    assert raw.count(b"ArduCopter V4.5.7") == 1  # the MSG text is a fixed 64-byte field: same length, same log
    plane = tmp_path / "plane.bin"
    plane.write_bytes(raw.replace(b"ArduCopter V4.5.7", b"ArduPlane V4.5.7 "))
    result = CliRunner().invoke(cli, ["fit", str(plane), "--partial", "-q"])
    assert result.exit_code == 1
    assert "plane.bin: a fixed wing (ArduPlane), not a multirotor" in result.stderr
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidWarning)  # the simulator's EKF wind is zero: said, and beside the point
        assert read_log(copter).vehicle_type == "multirotor"


@pytest.mark.parametrize(
    ("name", "vehicle_type"),
    [
        ("ardupilot-log-diagnosis/sample.bin", "multirotor"),
        ("dronekit-la-testdata/log171.bin", "multirotor"),
        ("kd0aij-impulse-response/log1.ulg", "multirotor"),
        ("phoenix/2018-09-17 16-44-06.tlog", "multirotor"),
        ("px4-ulog-rs/quadrotor_local.ulg", "multirotor"),
        ("px4-ulog-rs/corrupt_actuator_armed_wrong_size.ulg", ""),  # MAV_TYPE 0, generic: it does not say
        ("pyulog/sample.ulg", "multirotor"),
    ],
)
def test_every_real_multirotor_log_is_read(name: str, vehicle_type: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SysidWarning)
        assert read_log(REAL / name).vehicle_type == vehicle_type
