"""Tests of flightlogs.readers.tlog.

Cross-implementation reference: the real Phoenix tlog is read directly with
``pymavlink.mavutil`` and compared sample for sample. Behaviours the real file
lacks (PX4, HIGHRES_IMU, rangefinder, battery monitor, clock wrap, GCS and
companion heartbeats) are checked on small tlogs the tests write with
pymavlink's own encoder.
"""

from __future__ import annotations

import struct
import time
from pathlib import Path

import numpy as np
import pytest
from pymavlink.dialects.v20 import all as mavlink2

from flightlogs.errors import DataQualityWarning, LogCorruptionWarning, LogFormatError
from flightlogs.readers.tlog import read_tlog

from builders import read_warned

G0 = 9.80665
PHOENIX = Path("phoenix") / "2018-09-17 16-44-06.tlog"


# --------------------------------------------------------------------------- the real file


@pytest.fixture(scope="module")
def phoenix(real_data) -> Path:
    return real_data / PHOENIX


@pytest.fixture(scope="module")
def phoenix_log(phoenix):
    return read_warned(read_tlog, phoenix)


@pytest.fixture(scope="module")
def direct(phoenix) -> dict[str, dict[str, np.ndarray]]:
    """Fields of the vehicle's messages read straight through pymavlink."""
    from pymavlink import mavutil

    wanted = {
        "ATTITUDE": ("time_boot_ms", "roll", "pitch", "yaw", "rollspeed", "pitchspeed", "yawspeed"),
        "RAW_IMU": ("time_usec", "xacc", "yacc", "zacc"),
        "LOCAL_POSITION_NED": ("time_boot_ms", "vx", "vy", "vz", "z"),
        "SERVO_OUTPUT_RAW": ("time_usec", "servo1_raw", "servo2_raw", "servo3_raw", "servo4_raw"),
        "SYSTEM_TIME": ("time_boot_ms", "time_unix_usec"),
        "GLOBAL_POSITION_INT": ("time_boot_ms", "lat", "lon"),
    }
    rows: dict[str, list] = {name: [] for name in wanted}
    params: dict[str, float] = {}
    conn = mavutil.mavlink_connection(str(phoenix))
    while (msg := conn.recv_match(type=[*wanted, "PARAM_VALUE"])) is not None:
        if (msg.get_srcSystem(), msg.get_srcComponent()) != (1, 1):
            continue
        if msg.get_type() == "PARAM_VALUE":
            params.setdefault(msg.param_id, msg.param_value)
        else:
            rows[msg.get_type()].append([msg._timestamp, *(getattr(msg, f) for f in wanted[msg.get_type()])])
    conn.close()
    out = {name: dict(zip(("rx", *fields), np.array(rows[name], dtype=float).T)) for name, fields in wanted.items()}
    out["PARAM_VALUE"] = params
    return out


def _shift(time_s: np.ndarray, boot_s: np.ndarray) -> np.ndarray:
    """Log time minus the message's own boot time: 0 before the reboot, a constant after."""
    return np.round(time_s - boot_s, 6)


def test_real_tlog_metadata(phoenix_log):
    log = phoenix_log
    assert log.log_format == "tlog" and log.autopilot == "ardupilot"
    assert "APM:Copter V3.5.7" in log.vehicle and "quadrotor (MAV_TYPE 2)" in log.vehicle
    assert set(log.missing) == {"delta_lat", "delta_lon", "delta_yaw", "delta_thr", "battery_v"}
    assert any("rebooted 1 time" in w for w in log.warnings)
    assert any("no battery monitor" in w for w in log.warnings)
    assert not any("skipped" in w for w in log.warnings)
    # file name is the ground station's local time, PDT = UTC-7: 16:44:06 -> 23:44:06 UTC
    assert log.utc_start.isoformat().startswith("2018-09-17T23:44:0")


def test_real_tlog_matches_pymavlink_sample_for_sample(phoenix_log, direct):
    log = phoenix_log
    att, imu, pos, servo = (direct[k] for k in ("ATTITUDE", "RAW_IMU", "LOCAL_POSITION_NED", "SERVO_OUTPUT_RAW"))
    for name, field in (
        ("phi", "roll"),
        ("theta", "pitch"),
        ("psi", "yaw"),
        ("p", "rollspeed"),
        ("q", "pitchspeed"),
        ("r", "yawspeed"),
    ):
        np.testing.assert_array_equal(log[name].values, att[field], err_msg=name)
        assert log[name].source == f"ATTITUDE.{field}"
    for axis in "xyz":
        np.testing.assert_allclose(log[f"a{axis}"].values, imu[f"{axis}acc"] * G0 / 1000, rtol=1e-12)
        assert log[f"a{axis}"].source.startswith(f"RAW_IMU.{axis}acc (mG")
    for name, field in (("vn", "vx"), ("ve", "vy"), ("vd", "vz")):
        np.testing.assert_array_equal(log[name].values, pos[field])
    np.testing.assert_array_equal(log["height_agl"].values, -pos["z"])
    for k in range(1, 5):
        np.testing.assert_array_equal(log[f"motor_{k}"].values, servo[f"servo{k}_raw"])
        assert log[f"motor_{k}"].unit == "us"
    # one time base: each message's own autopilot time, shifted once after the reboot
    shifts = [
        _shift(log["p"].time_s, att["time_boot_ms"] * 1e-3),
        _shift(log["ax"].time_s, imu["time_usec"] * 1e-6),
        _shift(log["vn"].time_s, pos["time_boot_ms"] * 1e-3),
        _shift(log["motor_1"].time_s, servo["time_usec"] * 1e-6),
    ]
    assert np.unique(shifts[0]).size == 2 and shifts[0][0] == 0.0
    assert set(np.unique(np.concatenate(shifts))) == set(np.unique(shifts[0]))
    assert np.all(np.diff(log["p"].time_s) > 0)


def test_real_tlog_position_matches_pymavlink(phoenix_log, direct):
    """GLOBAL_POSITION_INT lat/lon (1e-7 deg) → rad, the samples at 0, 0 before the first fix left out."""
    log, gpi, att = phoenix_log, direct["GLOBAL_POSITION_INT"], direct["ATTITUDE"]
    known = (gpi["lat"] != 0) | (gpi["lon"] != 0)
    assert (~known).sum() == 10
    for name, field in (("latitude", "lat"), ("longitude", "lon")):
        np.testing.assert_array_equal(log[name].values, np.deg2rad(gpi[field][known] * 1e-7))
        assert log[name].source == f"GLOBAL_POSITION_INT.{field} (1e-7 deg→rad)" and log[name].unit == "rad"
    # on the same clock as the attitude: its own boot time, shifted once after the reboot
    shifts = np.unique(_shift(log["latitude"].time_s, gpi["time_boot_ms"][known] * 1e-3))
    assert set(shifts) <= set(np.unique(_shift(log["p"].time_s, att["time_boot_ms"] * 1e-3)))
    assert "GLOBAL_POSITION_INT.lat, lon: dropped 10 of 782 samples at 0, 0 (no position yet)" in log.warnings


def test_gps_raw_int_gives_the_position_without_global_position(tmp_path):
    items = [(0.0, VEHICLE, _heartbeat(2, 3))]
    for k in range(4):
        boot_ms = 5000 + 1000 * k
        items += [
            (1.0 + k, VEHICLE, _attitude(boot_ms)),
            (
                1.0 + k,
                VEHICLE,
                mavlink2.MAVLink_gps_raw_int_message(
                    0, 2 if k == 0 else 3, 350_000_000 + k, -1_069_000_000 - k, 0, 0, 0, 0, 0, 9
                ),
            ),
        ]
    with pytest.warns(DataQualityWarning, match="GPS_RAW_INT.lat, lon: dropped 1 of 4 samples without a 3-D fix"):
        log = read_tlog(_tlog(tmp_path / "raw.tlog", items))
    np.testing.assert_array_equal(log["latitude"].values, np.deg2rad((350_000_000 + np.arange(1, 4)) * 1e-7))
    np.testing.assert_allclose(log["longitude"].time_s, [6.0, 7.0, 8.0], atol=1e-6)  # via the receive clock
    assert log["longitude"].source == "GPS_RAW_INT.lon (1e-7 deg→rad; time from the receive clock)"
    assert any(w.startswith("GPS_RAW_INT.lat, lon: dropped 1 of 4 samples without a 3-D fix") for w in log.warnings)


def test_real_tlog_utc_offset_and_parameters(phoenix_log, direct):
    log = phoenix_log
    att = direct["ATTITUDE"]
    # log time + UTC offset lands within the telemetry latency of the receive time
    latency = att["rx"] - (log["p"].time_s + log.utc_offset_s)
    assert np.all((latency > 0.0) & (latency < 5.0))
    systime = direct["SYSTEM_TIME"]
    valid = systime["time_unix_usec"] > 0
    # SYSTEM_TIME: boot time + the session's shift + the offset is its UNIX time
    shift = np.unique(_shift(log["p"].time_s, att["time_boot_ms"] * 1e-3))[1]
    reboot_rx = att["rx"][np.flatnonzero(np.diff(att["time_boot_ms"]) < 0)[0] + 1]
    session_shift = np.where(systime["rx"] >= reboot_rx, shift, 0.0)[valid]
    unix = systime["time_boot_ms"][valid] * 1e-3 + session_shift + log.utc_offset_s
    np.testing.assert_allclose(unix, systime["time_unix_usec"][valid] * 1e-6, atol=0.02)
    assert dict(log.parameters) == pytest.approx(direct["PARAM_VALUE"])
    assert len(log.parameters) == 774 and log.parameters["SERVO3_FUNCTION"] == 35.0


def test_real_tlog_reads_fast_and_reports_progress(phoenix):
    calls: list[tuple[int, int]] = []
    start = time.perf_counter()
    read_warned(read_tlog, phoenix, progress=lambda done, total: calls.append((done, total)))
    assert time.perf_counter() - start < 3.0
    size = phoenix.stat().st_size
    assert calls[-1] == (size, size) and len(calls) > 5
    assert all(a[0] <= b[0] for a, b in zip(calls, calls[1:]))


def test_real_tlog_with_garbage_inside_is_read_with_a_warning(phoenix, tmp_path):
    data = phoenix.read_bytes()
    rng = np.random.default_rng(7)
    damaged = tmp_path / "damaged.tlog"
    damaged.write_bytes(data[:500_000] + rng.integers(0, 256, 2000, dtype=np.uint8).tobytes() + data[502_000:])
    with (
        pytest.warns(DataQualityWarning),  # the flight's own: a reboot, no battery monitor ...
        pytest.warns(LogCorruptionWarning, match="damaged.tlog: skipped"),
    ):
        log = read_tlog(damaged)
    skipped = [w for w in log.warnings if "skipped" in w]
    assert len(skipped) == 1 and "damaged.tlog" in skipped[0]
    n_skipped = int(skipped[0].split("skipped ")[1].split(" of")[0])
    assert 2000 <= n_skipped <= 2300
    assert 880 <= log["p"].samples < 902


# --------------------------------------------------------------------------- synthetic tlogs


def _tlog(path: Path, items) -> Path:
    """Write ``(rx_s, (sysid, compid), message)`` items as a tlog (MAVLink 2)."""
    links: dict = {}
    with path.open("wb") as f:
        for rx, (sysid, compid), msg in items:
            link = links.setdefault((sysid, compid), mavlink2.MAVLink(None, sysid, compid))
            f.write(struct.pack(">Q", int(round(rx * 1e6))) + msg.pack(link))
    return path


VEHICLE, GCS, COMPANION = (1, 1), (255, 190), (1, 191)


def _heartbeat(mav_type: int, autopilot: int):
    return mavlink2.MAVLink_heartbeat_message(mav_type, autopilot, 0, 0, 0, 3)


def _attitude(boot_ms: int, value: float = 0.1):
    return mavlink2.MAVLink_attitude_message(boot_ms, value, -value, 1.0, 0.01, 0.02, 0.03)


def test_px4_hexa_with_highres_imu_rangefinder_battery_and_system_time(tmp_path):
    unix0 = 1_700_000_000.0
    items = [(0.0, GCS, _heartbeat(6, 12)), (0.0, COMPANION, _heartbeat(18, 12)), (0.1, VEHICLE, _heartbeat(13, 12))]
    for k in range(5):
        rx, boot_ms = 1.0 + k, 10_000 + 1000 * k
        items += [
            (rx, VEHICLE, _attitude(boot_ms)),
            (
                rx,
                VEHICLE,
                mavlink2.MAVLink_highres_imu_message(
                    boot_ms * 1000 + 500, 0.5, -0.25, -9.8, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0
                ),
            ),
            (
                rx,
                VEHICLE,
                mavlink2.MAVLink_distance_sensor_message(boot_ms, 20, 700, 150 + k if k != 3 else 900, 0, 0, 25, 0),
            ),
            (rx, VEHICLE, mavlink2.MAVLink_servo_output_raw_message(boot_ms * 1000, 0, *range(1100, 1900, 100))),
            (
                rx + 0.2,
                VEHICLE,
                mavlink2.MAVLink_sys_status_message(0, 0, 0, 500, 15800 if k != 2 else 0, -1, -1, 0, 0, 0, 0, 0, 0),
            ),
            (rx, VEHICLE, mavlink2.MAVLink_system_time_message(int((unix0 + boot_ms / 1000) * 1e6), boot_ms)),
            (rx, COMPANION, _attitude(boot_ms + 77, value=9.0)),  # not the vehicle's
        ]
    with pytest.warns(DataQualityWarning, match="outside the sensor's range|reading 0 or 65535"):
        log = read_tlog(_tlog(tmp_path / "px4.tlog", items))
    assert log.autopilot == "px4" and "hexarotor (MAV_TYPE 13)" in log.vehicle
    np.testing.assert_allclose(log["phi"].values, 0.1, rtol=1e-6)
    np.testing.assert_allclose(log["p"].time_s, 10 + np.arange(5))
    assert log["ax"].source == "HIGHRES_IMU.xacc"
    np.testing.assert_allclose(log["ax"].time_s, 10.0005 + np.arange(5))
    np.testing.assert_allclose(log["az"].values, -9.8, rtol=1e-6)
    motors = sorted(n for n in log.signals if n.startswith("motor_"))
    assert motors == [f"motor_{k}" for k in range(1, 7)]
    np.testing.assert_array_equal(log["motor_6"].values, 1600)
    assert log["height_agl"].source.startswith("DISTANCE_SENSOR")
    np.testing.assert_allclose(log["height_agl"].values, [1.5, 1.51, 1.52, 1.54])
    assert any("outside the sensor's range" in w for w in log.warnings)
    np.testing.assert_allclose(log["battery_v"].values, 15.8)
    np.testing.assert_allclose(log["battery_v"].time_s, [10.2, 11.2, 13.2, 14.2], atol=1e-6)
    assert any("dropped 1 of 5 samples reading 0 or 65535" in w for w in log.warnings)
    assert log.utc_offset_s == pytest.approx(unix0, abs=1e-6)


def test_ardupilot_servo_functions_map_motors_and_global_position_fallback(tmp_path):
    functions = {"SERVO1_FUNCTION": 35, "SERVO2_FUNCTION": 33, "SERVO3_FUNCTION": 36, "SERVO4_FUNCTION": 34}
    items = [(0.0, VEHICLE, _heartbeat(2, 3))]
    items += [
        (0.0, VEHICLE, mavlink2.MAVLink_param_value_message(name.encode(), value, 9, 4, i))
        for i, (name, value) in enumerate(functions.items())
    ]
    items += [(0.5, VEHICLE, mavlink2.MAVLink_param_value_message(b"SERVO1_FUNCTION", 0, 9, 4, 0))]
    for k in range(3):
        boot_ms = 5000 + 200 * k
        items += [
            (
                1.0 + k,
                VEHICLE,
                mavlink2.MAVLink_servo_output_raw_message(boot_ms * 1000, 0, 1001, 1002, 1003, 1004, 0, 0, 0, 0),
            ),
            (
                1.0 + k,
                VEHICLE,
                mavlink2.MAVLink_global_position_int_message(boot_ms, 0, 0, 0, 12_345, 150, -250, 50, 0),
            ),
            (
                1.0 + k,
                VEHICLE,
                mavlink2.MAVLink_gps_raw_int_message(int((1.6e9 + boot_ms / 1000) * 1e6), 3, 0, 0, 0, 0, 0, 0, 0, 9),
            ),
        ]
    log = read_tlog(_tlog(tmp_path / "apm.tlog", items))
    assert log.parameters["SERVO1_FUNCTION"] == 35.0  # the first value seen
    assert [log[f"motor_{k}"].values[0] for k in range(1, 5)] == [1002, 1004, 1001, 1003]
    assert log["motor_1"].source == "SERVO_OUTPUT_RAW.servo2_raw"
    np.testing.assert_allclose(log["vn"].values, 1.5)
    np.testing.assert_allclose(log["ve"].values, -2.5)
    assert log["vd"].source == "GLOBAL_POSITION_INT.vz (cm/s / 100)"
    np.testing.assert_allclose(log["height_agl"].values, 12.345)
    assert log.utc_offset_s == pytest.approx(1.6e9, abs=1e-3)  # GPS_RAW_INT via receive time
    assert "latitude" not in log.signals  # every position message reads 0, 0: none known


def test_servo_clock_wrap_and_reboot_are_unwrapped(tmp_path):
    period_s = 2**32 * 1e-6
    items = [(0.0, VEHICLE, _heartbeat(2, 3))]
    boots = [4293.5, 4294.5, 4295.5, 4296.5]  # crosses the uint32 µs wrap at 4294.967 s
    for k, boot in enumerate(boots):
        items += [
            (100.0 + k, VEHICLE, _attitude(int(boot * 1000))),
            (
                100.0 + k,
                VEHICLE,
                mavlink2.MAVLink_servo_output_raw_message(
                    int(boot * 1e6) % 2**32, 0, 1500, 1500, 1500, 1500, 0, 0, 0, 0
                ),
            ),
        ]
    for k, boot in enumerate([3.0, 4.0]):  # reboot: the boot clock restarts
        items += [(110.0 + k, VEHICLE, _attitude(int(boot * 1000)))]
    with pytest.warns(DataQualityWarning, match="rebooted 1 time"):
        log = read_tlog(_tlog(tmp_path / "wrap.tlog", items))
    np.testing.assert_allclose(log["motor_1"].time_s, boots, atol=1e-6)
    assert log["motor_1"].time_s[2] > period_s
    # after the reboot, times continue on the first session's clock via the receive time
    np.testing.assert_allclose(log["p"].time_s, [*boots, 4303.5, 4304.5], atol=1e-6)
    assert any("rebooted 1 time" in w for w in log.warnings)


def test_battery_without_monitor_and_unknown_frame_are_reported(tmp_path):
    items = [(0.0, VEHICLE, _heartbeat(1, 3))]  # fixed wing: no motor count
    for k in range(3):
        items += [
            (1.0 + k, VEHICLE, _attitude(1000 * k + 1000)),
            (
                1.0 + k,
                VEHICLE,
                mavlink2.MAVLink_servo_output_raw_message(1000 * k, 0, 1500, 1500, 1500, 1500, 0, 0, 0, 0),
            ),
            (1.0 + k, VEHICLE, mavlink2.MAVLink_sys_status_message(0, 0, 0, 500, 65535, -1, -1, 0, 0, 0, 0, 0, 0)),
        ]
    with pytest.warns(DataQualityWarning, match="no battery monitor|not a known multirotor"):
        log = read_tlog(_tlog(tmp_path / "plane.tlog", items))
    assert "battery_v" not in log.signals and "motor_1..n" in log.missing
    assert any("no battery monitor" in w for w in log.warnings)
    assert any("not a known multirotor" in w for w in log.warnings)
    assert log.utc_offset_s is None


# --------------------------------------------------------------------------- bad input


def _attitude_items(n: int = 4):
    return [(0.0, VEHICLE, _heartbeat(2, 3))] + [(1.0 + k, VEHICLE, _attitude(1000 * k)) for k in range(n)]


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        (b"", "empty"),
        (b"timestamp,roll,pitch\n0,1,2\n" * 50, "no intact MAVLink message"),
        (np.random.default_rng(3).integers(0, 256, 50_000, dtype=np.uint8).tobytes(), "no intact MAVLink message"),
        (b"\x00\x05\x76\x19\xbf", "no intact MAVLink message"),
    ],
    ids=["empty", "text", "random", "truncated-header"],
)
def test_unreadable_files_raise_one_sentence_naming_the_file(tmp_path, content, fragment):
    path = tmp_path / "bad log.tlog"
    path.write_bytes(content)
    with pytest.raises(LogFormatError, match=fragment) as info:
        read_tlog(path)
    assert "bad log.tlog" in str(info.value)


def test_truncated_file_keeps_the_complete_messages(tmp_path):
    whole = _tlog(tmp_path / "whole.tlog", _attitude_items()).read_bytes()
    cut = tmp_path / "cut.tlog"
    cut.write_bytes(whole[:-15])
    with pytest.warns(LogCorruptionWarning, match="cut.tlog: skipped 33 of"):
        log = read_tlog(cut)
    assert log["p"].samples == 3
    kept = 48 - 15  # the last record (8-byte stamp + 40-byte ATTITUDE) lost 15 bytes
    assert any(f"skipped {kept} of {len(whole) - 15} bytes" in w and "cut.tlog" in w for w in log.warnings)


def test_no_vehicle_heartbeat_or_unsupported_autopilot(tmp_path):
    only_gcs = [(0.0, GCS, _heartbeat(6, 8)), (1.0, VEHICLE, _attitude(1000))]
    with pytest.raises(LogFormatError, match="no HEARTBEAT from a vehicle"):
        read_tlog(_tlog(tmp_path / "gcs.tlog", only_gcs))
    generic = [(0.0, VEHICLE, _heartbeat(2, 0)), (1.0, VEHICLE, _attitude(1000))]
    with pytest.raises(LogFormatError, match=r"autopilot \[0\].*ArduPilot \(3\) and PX4 \(12\)"):
        read_tlog(_tlog(tmp_path / "generic.tlog", generic))


def test_missing_file_raises_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError):
        read_tlog(tmp_path / "nowhere.tlog")
