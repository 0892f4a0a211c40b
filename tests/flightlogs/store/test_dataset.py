"""HDF5 dataset store: round trip, provenance, atomic writes, bad files."""

from __future__ import annotations

import hashlib
from pathlib import Path

import h5py
import numpy as np
import pytest

from flightlogs.errors import LogFormatError
from flightlogs.flightlog import FlightLog, Signal
from flightlogs.store.dataset import SCHEMA_VERSION, read_dataset, write_dataset


def _log(path: Path) -> FlightLog:
    rng = np.random.default_rng(7)
    t = np.cumsum(rng.uniform(0.004, 0.006, 500))
    signals = {
        "q": Signal("q", t, rng.normal(size=500), "rad/s", "vehicle_angular_velocity[0].xyz[1]"),
        "motor_1": Signal("motor_1", t[::2], rng.uniform(1000, 2000, 250), "us", "RCOU.C1"),
    }
    return FlightLog(
        path,
        "ulog",
        "px4",
        signals,
        vehicle="quad ∅ <x>",
        parameters={"MPC_THR_HOVER": 0.42, "SYS_AUTOSTART": 4001.0},
        utc_offset_s=1.6e9 + 0.125,
        warnings=("pyulog: 3 dropouts",),
    )


def test_round_trip_keeps_every_value(tmp_path: Path) -> None:
    source = tmp_path / "flight.ulg"
    source.write_bytes(b"raw bytes")
    log = _log(source)
    out = tmp_path / "set.h5"
    write_dataset(out, [log, log])
    dataset = read_dataset(out)
    assert dataset.schema_version == SCHEMA_VERSION
    assert len(dataset.logs) == 2
    back = dataset.logs[0]
    assert (back.path, back.log_format, back.autopilot, back.vehicle) == (source, "ulog", "px4", "quad ∅ <x>")
    assert back.utc_offset_s == log.utc_offset_s
    assert dict(back.parameters) == dict(log.parameters)
    assert back.warnings == log.warnings
    for name, signal in log.signals.items():
        np.testing.assert_array_equal(back[name].time_s, signal.time_s)
        np.testing.assert_array_equal(back[name].values, signal.values)
        assert (back[name].unit, back[name].source) == (signal.unit, signal.source)
    assert dataset.sha256[str(source)] == hashlib.sha256(b"raw bytes").hexdigest()
    with h5py.File(out) as h5:
        assert sorted(h5["logs"]) == ["flight", "flight_2"]


def test_unknown_utc_round_trips_as_none(tmp_path: Path) -> None:
    log = FlightLog(tmp_path / "a.bin", "dataflash", "ardupilot", {})
    write_dataset(tmp_path / "a.h5", [log])
    assert read_dataset(tmp_path / "a.h5").logs[0].utc_offset_s is None


def test_a_failed_write_leaves_the_old_file(tmp_path: Path) -> None:
    out = tmp_path / "set.h5"
    write_dataset(out, [_log(tmp_path / "good.ulg")])
    before = out.read_bytes()

    class Broken:
        path = tmp_path / "wind.csv"

    with pytest.raises(TypeError):
        write_dataset(out, [_log(tmp_path / "other.ulg")], [Broken()])
    assert out.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".part")] == []


@pytest.mark.parametrize("content", [b"", b"not hdf5 at all"])
def test_non_hdf5_is_a_log_format_error(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "x.h5"
    path.write_bytes(content)
    with pytest.raises(LogFormatError, match="not an HDF5 dataset"):
        read_dataset(path)


def test_foreign_hdf5_and_newer_schema_are_refused(tmp_path: Path) -> None:
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as h5:
        h5["x"] = 1
    with pytest.raises(LogFormatError, match="not a flight-sysid dataset"):
        read_dataset(foreign)
    newer = tmp_path / "newer.h5"
    write_dataset(newer, [])
    with h5py.File(newer, "a") as h5:
        h5.attrs["schema_version"] = SCHEMA_VERSION + 1
    with pytest.raises(LogFormatError, match="newer than this software"):
        read_dataset(newer)


def test_wind_measurements_round_trip(tmp_path: Path) -> None:
    from flightlogs.readers.anemometer import read_anemometer_csv

    csv = Path(__file__).resolve().parents[2] / "data" / "anemometer" / "iso_utc_speed_dir.csv"
    wind = read_anemometer_csv(csv)
    out = tmp_path / "w.h5"
    write_dataset(out, [], [wind])
    back = read_dataset(out).winds[0]
    for name in ("utc_s", "wind_n", "wind_e", "speed_m_s", "direction_from_rad"):
        np.testing.assert_array_equal(getattr(back, name), getattr(wind, name))
    assert (back.path, dict(back.columns), back.unit, back.layout, back.warnings) == (
        wind.path,
        dict(wind.columns),
        wind.unit,
        wind.layout,
        wind.warnings,
    )
    assert read_dataset(out).sha256[str(csv)] == hashlib.sha256(csv.read_bytes()).hexdigest()


def test_system_id_runs_round_trip(tmp_path: Path) -> None:
    from flightlogs.flightlog import SystemIdRun

    runs = (
        SystemIdRun(25.0, 59.99, 11, "mixer pitch", 0.08, 0.1, 10.0, 5.0, 0.0, 34.0, 1.0),
        SystemIdRun(75.0, float("nan"), 10, "mixer roll", 0.08, 0.1, 10.0, 5.0, 0.0, 34.0, 1.0),
    )
    log = FlightLog(tmp_path / "sid.bin", "dataflash", "ardupilot", {}, system_id_runs=runs)
    write_dataset(tmp_path / "sid.h5", [log])
    back = read_dataset(tmp_path / "sid.h5").logs[0].system_id_runs
    assert back[0] == runs[0]
    assert back[1].axis_name == "mixer roll" and np.isnan(back[1].end_s)
