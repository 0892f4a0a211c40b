"""``read_ulog``: real logs against pyulog read directly, fallbacks on synthetic logs, bad input.

Reference values are cross-implementation: pyulog's own arrays (exact), scipy's
rotation for the Euler angles (float64 round-off), and the facts the data
README states for each real file (topics present, voltage range, GPS).
"""

from __future__ import annotations

import contextlib
import io
import re
import struct
import warnings
from datetime import UTC, datetime
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pyulog import ULog
from scipy.spatial.transform import Rotation

from flightlogs.errors import DataQualityWarning, LogCorruptionWarning, LogFormatError, SysidError
from flightlogs.flightlog import FlightLog
from flightlogs.readers import read_log
from flightlogs.readers.ulog import read_ulog
from flightlogs.signals import LOGGED_SIGNALS

from builders import read_warned

QUAD = "px4-ulog-rs/quadrotor_local.ulg"
OLD = "pyulog/sample.ulg"
GPS_LOG = "px4-ulog-rs/corrupt_unregistered_msg_id.ulg"
MOTORS_4 = {f"motor_{i}" for i in range(1, 5)}
DELTAS = {"delta_lat", "delta_lon", "delta_yaw", "delta_thr"}
ATTITUDE = {"phi", "theta", "psi"}
RATES_ACCEL = {"p", "q", "r", "ax", "ay", "az"}
POSITION = {"latitude", "longitude"}
# references (optional, never missing): vehicle_rates_setpoint, vehicle_attitude_setpoint, manual_control_setpoint
REFERENCES = {"p_ref", "q_ref", "r_ref", "phi_ref", "theta_ref", "psi_ref"}
STICKS = {"stick_lat", "stick_lon", "stick_yaw", "stick_thr"}
# flight states (optional, never missing): actuator_armed or vehicle_status, vehicle_land_detected (data README)
ARMED = {"armed"}
STATES = {"armed", "landed"}

# file -> (signals present, exactly; sources of some of them), from the data README
REAL_ULOGS = {
    "kd0aij-impulse-response/log1.ulg": (
        RATES_ACCEL | REFERENCES | ARMED,
        {"p": "sensor_gyro[0].x", "az": "sensor_accel[0].z", "armed": "vehicle_status[0].arming_state (2: armed)"},
    ),
    QUAD: (
        RATES_ACCEL | ATTITUDE | DELTAS | MOTORS_4 | REFERENCES | STICKS | STATES | {"vd", "height_agl", "battery_v"},
        {
            "landed": "vehicle_land_detected[0].landed",
            "armed": "actuator_armed[0].armed",
            "p": "vehicle_angular_velocity[0].xyz[0]",
            "phi": "vehicle_attitude[0].q[0..3] (quaternion→Euler)",
            "ax": "vehicle_acceleration[0].xyz[0]",
            "delta_thr": "-vehicle_thrust_setpoint[0].xyz[2]",
            "motor_4": "actuator_motors[0].control[3]",
            "height_agl": "-vehicle_local_position[0].z",
            "battery_v": "battery_status[0].voltage_v",
        },
    ),
    GPS_LOG: (
        set(LOGGED_SIGNALS) | MOTORS_4 | POSITION | REFERENCES | STICKS | STATES,
        {
            "vn": "vehicle_local_position[0].vx",
            "delta_lat": "vehicle_torque_setpoint[0].xyz[0]",
            "motor_1": "actuator_motors[0].control[0]",
            "latitude": "vehicle_global_position[0].lat (deg→rad)",
            "longitude": "vehicle_global_position[0].lon (deg→rad)",
        },
    ),
    "px4-ulog-rs/corrupt_actuator_armed_wrong_size.ulg": (
        RATES_ACCEL | ATTITUDE | ARMED | {"vd", "height_agl", "battery_v"},
        {"r": "vehicle_angular_velocity[0].xyz[2]", "battery_v": "battery_status[0].voltage_v"},
    ),
    OLD: (
        RATES_ACCEL | ATTITUDE | DELTAS | MOTORS_4 | REFERENCES | ARMED | {"vd", "height_agl"},
        {
            "p": "vehicle_attitude[0].rollspeed",
            "ax": "sensor_combined[0].accelerometer_m_s2[0]",
            "delta_thr": "actuator_controls_0[0].control[3]",
            "motor_1": "actuator_outputs[0].output[0]",
            "height_agl": "vehicle_local_position[0].dist_bottom",
        },
    ),
    "pyulog/sample_appended_multiple.ulg": (
        RATES_ACCEL
        | ATTITUDE
        | DELTAS
        | MOTORS_4
        | REFERENCES
        | ARMED
        | {"vd", "height_agl", "est_wind_n", "est_wind_e"},
        {
            "q": "vehicle_attitude[0].pitchspeed",
            "est_wind_n": "wind_estimate[0].windspeed_north",
            "motor_2": "actuator_outputs[0].output[1]",
            "height_agl": "-vehicle_local_position[0].z",
        },
    ),
}


@cache
def _read(path: Path) -> FlightLog:
    return read_warned(read_ulog, path)


@cache
def _pyulog(path: Path) -> dict[str, dict[str, np.ndarray]]:
    """Instance 0 of every topic, read by pyulog directly (the reference)."""
    with contextlib.redirect_stdout(io.StringIO()):
        ulog = ULog(str(path))
    return {d.name: d.data for d in ulog.data_list if d.multi_id == 0}


def _initial_parameters(path: Path) -> dict[str, float]:
    with contextlib.redirect_stdout(io.StringIO()):
        return dict(ULog(str(path), parse_header_only=True).initial_parameters)


def _seconds(stamps: np.ndarray) -> np.ndarray:
    return stamps.astype(np.float64) / 1e6


# --------------------------------------------------------------------------- real logs


def test_the_table_covers_every_real_ulog(real_data: Path) -> None:
    assert {str(p.relative_to(real_data)) for p in real_data.rglob("*.ulg")} == set(REAL_ULOGS)


@pytest.mark.parametrize("relative", sorted(REAL_ULOGS))
def test_every_real_ulog_reads_with_the_signals_its_readme_lists(real_data: Path, relative: str) -> None:
    present, sources = REAL_ULOGS[relative]
    log = _read(real_data / relative)
    assert (log.log_format, log.autopilot, log.path) == ("ulog", "px4", real_data / relative)
    assert set(log.signals) == present
    expected_missing = [n for n in LOGGED_SIGNALS if n not in present]
    assert list(log.missing) == expected_missing + ([] if MOTORS_4 <= present else ["motor_1..n"])
    assert {name: log[name].source for name in sources} == sources
    for signal in log.signals.values():
        assert signal.samples >= 2 and np.all(np.diff(signal.time_s) > 0)
        assert np.all(np.isfinite(signal.values))
    assert log.vehicle.startswith("PX4 on ") and "MAV_TYPE" in log.vehicle
    assert log.parameters == {k: float(v) for k, v in _initial_parameters(real_data / relative).items()}


def test_modern_log_matches_pyulog_sample_for_sample(real_data: Path) -> None:
    log, raw = _read(real_data / QUAD), _pyulog(real_data / QUAD)
    pairs = {
        "p": ("vehicle_angular_velocity", "xyz[0]", 1),
        "r": ("vehicle_angular_velocity", "xyz[2]", 1),
        "ay": ("vehicle_acceleration", "xyz[1]", 1),
        "delta_lon": ("vehicle_torque_setpoint", "xyz[1]", 1),
        "delta_thr": ("vehicle_thrust_setpoint", "xyz[2]", -1),
        "motor_3": ("actuator_motors", "control[2]", 1),
        "battery_v": ("battery_status", "voltage_v", 1),
        "vd": ("vehicle_local_position", "vz", 1),
        "height_agl": ("vehicle_local_position", "z", -1),
    }
    for name, (topic, field, sign) in pairs.items():
        np.testing.assert_array_equal(log[name].time_s, _seconds(raw[topic]["timestamp"]), err_msg=name)
        np.testing.assert_array_equal(log[name].values, sign * raw[topic][field].astype(np.float64), err_msg=name)
    held = {name: log[name].stored_values.dtype for name in ("p", "vd", "height_agl", "phi")}
    assert held == {"p": np.float32, "vd": np.float32, "height_agl": np.float32, "phi": np.float64}  # phi: from q
    # facts of the flight (README): 28.5-31.0 V pack, hover thrust ~0.62-0.66 (positive = more thrust)
    assert 28.0 < log["battery_v"].values.min() and log["battery_v"].values.max() < 31.5
    airborne = (log["delta_thr"].time_s > 110) & (log["delta_thr"].time_s < 190)
    assert 0.55 < np.median(log["delta_thr"].values[airborne]) < 0.75
    # hovering, the accelerometer reads about -g along body z (FRD)
    assert abs(np.median(log["az"].values) + 9.81) < 0.3
    assert "motor_5" not in log.signals and log.parameters["CA_ROTOR_COUNT"] == 4


def test_horizontal_velocity_flagged_invalid_is_missing_not_filled(real_data: Path) -> None:
    log, raw = _read(real_data / QUAD), _pyulog(real_data / QUAD)
    assert not raw["vehicle_local_position"]["v_xy_valid"].any()  # README: vxy invalid
    assert {"vn", "ve"} <= set(log.missing)
    assert "vehicle_local_position[0].vx: no usable samples (926 with v_xy_valid not set); vn missing" in log.warnings


@pytest.mark.parametrize("relative", [QUAD, OLD])
def test_euler_angles_match_scipy(real_data: Path, relative: str) -> None:
    log, raw = _read(real_data / relative), _pyulog(real_data / relative)
    attitude = raw["vehicle_attitude"]
    wxyz = np.column_stack([attitude[f"q[{i}]"] for i in range(4)]).astype(np.float64)
    yaw_pitch_roll = Rotation.from_quat(wxyz[:, [1, 2, 3, 0]]).as_euler("ZYX")  # scalar-last
    for k, name in enumerate(["psi", "theta", "phi"]):
        np.testing.assert_array_equal(log[name].time_s, _seconds(attitude["timestamp"]))
        np.testing.assert_allclose(log[name].values, yaw_pitch_roll[:, k], atol=1e-9, err_msg=name)


def test_old_log_matches_pyulog_sample_for_sample(real_data: Path) -> None:
    log, raw = _read(real_data / OLD), _pyulog(real_data / OLD)
    pairs = {
        "delta_lat": ("actuator_controls_0", "control[0]"),
        "delta_thr": ("actuator_controls_0", "control[3]"),
        "motor_1": ("actuator_outputs", "output[0]"),
        "motor_4": ("actuator_outputs", "output[3]"),
        "ax": ("sensor_combined", "accelerometer_m_s2[0]"),
        "az": ("sensor_combined", "accelerometer_m_s2[2]"),
        "q": ("vehicle_attitude", "pitchspeed"),
        "height_agl": ("vehicle_local_position", "dist_bottom"),
    }
    for name, (topic, field) in pairs.items():
        np.testing.assert_array_equal(log[name].time_s, _seconds(raw[topic]["timestamp"]), err_msg=name)
        np.testing.assert_array_equal(log[name].values, raw[topic][field].astype(np.float64), err_msg=name)
    # never armed: every motor output at the 900 us disarmed PWM; noutputs is 8 but MAV_TYPE 2 has 4 motors
    assert log["motor_1"].unit == "PWM us" and set(log["motor_1"].values) == {900.0}
    assert set(raw["actuator_outputs"]["noutputs"]) == {8} and "motor_5" not in log.signals
    assert any("4 logging dropout(s)" in w for w in log.warnings)


def test_appended_data_log_reads_every_sample(real_data: Path) -> None:
    path = real_data / "pyulog/sample_appended_multiple.ulg"
    with contextlib.redirect_stdout(io.StringIO()):
        assert ULog(str(path)).has_data_appended
    log = _read(path)
    assert log["ax"].samples == _pyulog(path)["sensor_combined"]["timestamp"].size == 2373
    assert log.duration_s == pytest.approx(9.8, abs=0.2)


# --------------------------------------------------------------------------- UTC


def test_utc_offset_from_gps_gives_the_flight_date(real_data: Path) -> None:
    log, gps = _read(real_data / GPS_LOG), _pyulog(real_data / GPS_LOG)["sensor_gps"]
    per_sample = (gps["time_utc_usec"].astype(np.int64) - gps["timestamp"].astype(np.int64)) / 1e6
    assert log.utc_offset_s is not None
    # time_utc_usec is the fix time, timestamp its publication: within 0.1 s of each other
    assert np.all(np.abs(per_sample - log.utc_offset_s) < 0.1)
    assert datetime(2020, 1, 1, tzinfo=UTC) < log.utc_start < datetime(2030, 1, 1, tzinfo=UTC)


def test_gps_position_matches_pyulog_sample_for_sample(real_data: Path) -> None:
    """The estimator's global position, deg → rad, where lat_lon_valid is set (pyulog read directly)."""
    log, raw = _read(real_data / GPS_LOG), _pyulog(real_data / GPS_LOG)["vehicle_global_position"]
    valid = (raw["lat_lon_valid"] != 0) & (raw["timestamp"] > 0)
    assert 0 < (~valid).sum() < 10  # the few samples before the estimator had a position
    for name, field in (("latitude", "lat"), ("longitude", "lon")):
        np.testing.assert_array_equal(log[name].time_s, _seconds(raw["timestamp"][valid]))
        np.testing.assert_array_equal(log[name].values, np.deg2rad(raw[field][valid]))
        assert log[name].unit == "rad"
    assert (
        f"vehicle_global_position[0].lat (deg→rad): dropped {(~valid).sum()} of {valid.size} samples "
        f"({(~valid).sum()} with lat_lon_valid not set)" in log.warnings
    )


def test_gps_without_a_fix_gives_no_position(real_data: Path) -> None:
    """quadrotor_local logs sensor_gps and vehicle_gps_position, but with fix_type 0 throughout."""
    raw = _pyulog(real_data / QUAD)
    assert not np.any(raw["sensor_gps"]["fix_type"]) and not np.any(raw["vehicle_gps_position"]["fix_type"])
    log = _read(real_data / QUAD)
    assert not POSITION & set(log.signals)
    assert not any("latitude" in w or "fix_type" in w for w in log.warnings)


@pytest.mark.parametrize("relative", [QUAD, "kd0aij-impulse-response/log1.ulg"])
def test_no_gps_time_gives_none(real_data: Path, relative: str) -> None:
    # quadrotor_local logs sensor_gps, but never with a time (no fix); log1 has no GPS topic
    assert _read(real_data / relative).utc_offset_s is None


# --------------------------------------------------------------------------- damage


def test_corrupt_message_id_reads_with_warnings_and_prints_nothing(
    real_data: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    with (
        pytest.warns(DataQualityWarning, match=r"\((5|10) with (lat_lon|v_xy)_valid not set\)"),
        pytest.warns(LogCorruptionWarning, match="message id 32812|unreadable bytes|pyulog: Warning") as raised,
    ):
        log = read_ulog(real_data / GPS_LOG)
    assert capsys.readouterr() == ("", "")
    assert [str(w.message) for w in raised] == list(log.warnings)  # raised to the caller and kept, in order
    assert any("message id 32812" in w and "skipped 1" in w for w in log.warnings)
    assert any(re.search(r"skipped about \d+ unreadable bytes \(2 resynchronisation", w) for w in log.warnings)
    assert any(w.startswith("pyulog: Warning: no subscription found") for w in log.warnings)  # its print, captured


def test_under_warnings_as_errors_a_corrupt_log_raises_its_first_warning(real_data: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # as python -W error
        with pytest.raises(LogCorruptionWarning, match="skipped 1 data message.* message id 32812"):
            read_log(real_data / GPS_LOG)


def test_wrong_size_message_and_zero_tail_are_reported(real_data: Path) -> None:
    log = _read(real_data / "px4-ulog-rs/corrupt_actuator_armed_wrong_size.ulg")
    assert "skipped 1 'actuator_armed' message(s) whose size does not match its format" in log.warnings
    assert any("last 711029 bytes of the file are zeros" in w for w in log.warnings)
    assert not any("truncated" in w for w in log.warnings)  # zero padding is not a cut message
    assert any("actuator_outputs[0]: cannot tell which outputs drive motors" in w for w in log.warnings)


def test_truncated_copy_reads_the_intact_part(real_data: Path, tmp_path: Path) -> None:
    full = _read(real_data / QUAD)
    data = (real_data / QUAD).read_bytes()
    cut = tmp_path / "cut.ulg"
    cut.write_bytes(data[: len(data) * 6 // 10])
    with (
        pytest.warns(DataQualityWarning, match="v_xy_valid not set"),
        pytest.warns(LogCorruptionWarning, match="cut.ulg: the file is truncated") as raised,
    ):
        log = read_ulog(cut)
    assert [str(w.message) for w in raised] == list(log.warnings)
    assert any(
        re.fullmatch(
            rf"cut\.ulg: the file is truncated: it ends inside a message at byte \d+ of "
            rf"{len(data) * 6 // 10}; that last message was skipped",
            w,
        )
        for w in log.warnings
    )
    n = log["p"].samples
    assert 0.4 * full["p"].samples < n < 0.8 * full["p"].samples
    np.testing.assert_array_equal(log["p"].values, full["p"].values[:n])


def _bad_files(real_data: Path) -> dict[str, tuple[bytes, str]]:
    good, modern = (real_data / OLD).read_bytes(), (real_data / QUAD).read_bytes()
    rng = np.random.default_rng(7)
    return {
        "empty": (b"", "the file is empty"),
        "random bytes": (rng.integers(0, 256, 5000, dtype=np.uint8).tobytes(), "not a PX4 ULog"),
        "dataflash": (bytes.fromhex("a3 95 80 80 59") + bytes(200), "ArduPilot DataFlash"),
        "cut in the header": (good[:10], "truncated inside the ULog header at byte 10"),
        "header only": (good[:16], "holds no readable data message"),
        "cut in the definitions": (good[:200], "holds no readable data message (200 bytes)"),
        "magic then garbage": (
            good[:16] + rng.integers(0, 256, 20000, dtype=np.uint8).tobytes(),
            "holds no readable data message",
        ),
        # the flag-bits message opens quadrotor_local at byte 16; byte 27 is incompat_flags[0]
        "unknown incompatible flag": (
            modern[:27] + b"\x02" + modern[28:100_000],
            "uses a ULog extension pyulog cannot read",
        ),
    }


@pytest.mark.parametrize(
    "case",
    [
        "empty",
        "random bytes",
        "dataflash",
        "cut in the header",
        "header only",
        "cut in the definitions",
        "magic then garbage",
        "unknown incompatible flag",
    ],
)
def test_bad_input_raises_one_sentence_naming_the_file(
    real_data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], case: str
) -> None:
    content, fragment = _bad_files(real_data)[case]
    path = tmp_path / f"{case.replace(' ', '_')}.ulg"
    path.write_bytes(content)
    with pytest.raises(LogFormatError) as caught:
        read_ulog(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: ") and fragment in message
    assert "\n" not in message and message.endswith(".")
    assert isinstance(caught.value, SysidError) and isinstance(caught.value, ValueError)
    assert capsys.readouterr() == ("", "")


def test_missing_file_is_a_log_format_error(tmp_path: Path) -> None:
    with pytest.raises(LogFormatError, match="absent.ulg: cannot be read"):
        read_ulog(tmp_path / "absent.ulg")


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    flips=st.lists(st.tuples(st.integers(16, 59_999), st.integers(0, 255)), min_size=1, max_size=40),
    keep=st.integers(16, 60_000),
)
def test_any_damage_reads_or_raises_log_format_error(
    real_data: Path, tmp_path: Path, flips: list[tuple[int, int]], keep: int
) -> None:
    data = bytearray((real_data / "pyulog/sample_appended_multiple.ulg").read_bytes()[:60_000])
    for offset, value in flips:
        data[offset] = value
    path = tmp_path / "damaged.ulg"
    path.write_bytes(bytes(data[:keep]))
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        try:
            log = read_warned(read_ulog, path)  # whatever damage it reads past is warned about and kept
        except LogFormatError as err:
            assert str(err).startswith(f"{path}: ")
        else:
            assert all(np.all(np.diff(s.time_s) > 0) for s in log.signals.values())
    assert out.getvalue() == ""


def test_progress_runs_from_zero_to_the_file_size(real_data: Path) -> None:
    calls: list[tuple[int, int]] = []
    read_warned(read_ulog, real_data / OLD, progress=lambda done, total: calls.append((done, total)))
    size = (real_data / OLD).stat().st_size
    assert calls[0] == (0, size) and calls[-1] == (size, size) and len(calls) > 3
    assert all(b[0] >= a[0] and b[1] == size for a, b in zip(calls, calls[1:]))


# --------------------------------------------------------------------------- fallbacks (pyulog's writer)


def _rewrite(real: Path, target: Path, topics: list[str]) -> Path:
    """The real log with only `topics` kept, written by pyulog's own writer."""
    with contextlib.redirect_stdout(io.StringIO()):
        ULog(str(real), message_name_filter_list=topics).write_ulog(str(target))
    return target


def test_without_vehicle_angular_velocity_rates_fall_back_to_sensor_combined(real_data: Path, tmp_path: Path) -> None:
    path = _rewrite(real_data / QUAD, tmp_path / "no_vav.ulg", ["sensor_combined", "sensor_gyro", "vehicle_attitude"])
    log, raw = read_ulog(path), _pyulog(real_data / QUAD)["sensor_combined"]
    for k, name in enumerate(["p", "q", "r"]):
        assert log[name].source == f"sensor_combined[0].gyro_rad[{k}]"
        np.testing.assert_array_equal(log[name].values, raw[f"gyro_rad[{k}]"].astype(np.float64))
    assert log["ax"].source == "sensor_combined[0].accelerometer_m_s2[0]"  # no vehicle_acceleration either
    assert log["phi"].source.startswith("vehicle_attitude[0].q")


def test_without_sensor_combined_rates_fall_back_to_sensor_gyro(real_data: Path, tmp_path: Path) -> None:
    path = _rewrite(real_data / QUAD, tmp_path / "gyro_only.ulg", ["sensor_gyro", "sensor_accel"])
    log = read_ulog(path)
    assert log["q"].source == "sensor_gyro[0].y" and log["az"].source == "sensor_accel[0].z"
    assert set(log.signals) == RATES_ACCEL


_TYPES = {
    "uint64": "uint64_t",
    "float32": "float",
    "uint8": "uint8_t",
    "int8": "int8_t",
    "uint32": "uint32_t",
    "int32": "int32_t",
    "float64": "double",
}


def _synthetic(path: Path, topics: dict[tuple[str, int], dict[str, np.ndarray]], parameters: dict[str, int]) -> Path:
    """A ULog built from arrays and written by ``ULog.write_ulog`` (formats inferred from dtypes)."""
    ulog = ULog(None)
    ulog._start_timestamp, ulog._file_version = 1_000_000, 1
    ulog._msg_info_dict.update(sys_name="PX4", ver_hw="SYNTHETIC")
    ulog._msg_info_dict_types.update(sys_name="char[3]", ver_hw="char[9]")
    ulog._initial_parameters.update(parameters)
    for msg_id, ((name, multi_id), fields) in enumerate(topics.items()):
        declared: dict[str, str] = {}
        for field, values in fields.items():
            base, index = re.fullmatch(r"(\w+)(?:\[(\d+)\])?", field).groups()
            size = sum(f.startswith(f"{base}[") for f in fields)
            declared[base] = f"{_TYPES[np.asarray(values).dtype.name]}{f'[{size}]' if index else ''} {base};"
        ulog._message_formats[name] = ULog.MessageFormat(f"{name}:{''.join(declared.values())}".encode(), None)
        added = ULog._MessageAddLogged(
            struct.pack("<BH", multi_id, msg_id) + name.encode(), None, ulog._message_formats
        )
        rows = np.zeros(len(fields["timestamp"]), dtype=added.dtype)
        for field, values in fields.items():
            rows[field] = values
        added.buffer = bytearray(rows.tobytes())
        ulog._data_list.append(ULog.Data(added))
    ulog.write_ulog(str(path))
    return path


N = 200
STAMPS = (2_000_000 + 10_000 * np.arange(N)).astype(np.uint64)  # 100 Hz from t = 2 s


def _f(values: object) -> np.ndarray:
    return np.broadcast_to(np.asarray(values, dtype=np.float32), (N,)).copy()


def test_synthetic_log_exercises_the_rest_of_the_table(tmp_path: Path) -> None:
    bumpy = STAMPS.copy()
    bumpy[0], bumpy[50] = 0, bumpy[49]  # a zero and a repeated timestamp
    distance = _f(np.linspace(0.05, 3.0, N))  # the first samples below min_distance 0.1 m
    motors = {f"control[{i}]": _f(0.5 if i < 6 else np.nan) for i in range(12)}
    gps_utc = np.where(np.arange(N) < 20, 0, STAMPS.astype(np.int64) + 1_700_000_000_000_000).astype(np.uint64)
    topics = {
        ("vehicle_angular_velocity", 0): {"timestamp": bumpy, **{f"xyz[{i}]": _f(0.1 * i) for i in range(3)}},
        ("vehicle_thrust_setpoint", 0): {"timestamp": STAMPS, **{f"xyz[{i}]": _f([0, 0, -0.6][i]) for i in range(3)}},
        ("distance_sensor", 0): {
            "timestamp": STAMPS,
            "current_distance": _f(9.0),
            "min_distance": _f(0.1),
            "max_distance": _f(10.0),
            "orientation": np.zeros(N, np.uint8),
        },  # forward
        ("distance_sensor", 1): {
            "timestamp": STAMPS,
            "current_distance": distance,
            "min_distance": _f(0.1),
            "max_distance": _f(10.0),
            "orientation": np.full(N, 25, np.uint8),
        },
        ("vehicle_local_position", 0): {"timestamp": STAMPS, "z": _f(-1.0), "z_valid": np.ones(N, np.uint8)},
        ("wind", 0): {"timestamp": STAMPS, "windspeed_north": _f(3.0), "windspeed_east": _f(-1.0)},
        ("sensor_gps", 0): {"timestamp": STAMPS, "time_utc_usec": gps_utc},
        ("actuator_motors", 0): {"timestamp": STAMPS, **motors},
    }
    with pytest.warns(DataQualityWarning, match=r"dropped \d+ of \d+ samples|\[0\] is empty or invalid") as raised:
        log = read_ulog(_synthetic(tmp_path / "synthetic.ulg", topics, {"MAV_TYPE": 13}))
    assert [str(w.message) for w in raised] == list(log.warnings)
    assert log["p"].samples == N - 2
    assert "vehicle_angular_velocity[0].xyz[0]: dropped 1 of 200 samples (1 with timestamp 0)" in log.warnings
    assert any(w.startswith("vehicle_angular_velocity[0].xyz[0]: dropped 1 of 199 samples") for w in log.warnings)
    assert log["delta_thr"].source == "-vehicle_thrust_setpoint[0].xyz[2]"
    np.testing.assert_allclose(log["delta_thr"].values, 0.6, rtol=1e-6)  # more thrust is positive
    assert log["height_agl"].source == "distance_sensor[1].current_distance"  # instance 0 faces forward
    assert log["height_agl"].values.min() >= 0.1 and log["height_agl"].samples < N
    assert any("distance_sensor[0] is empty or invalid" in w for w in log.warnings)
    assert (log["est_wind_n"].source, log["est_wind_e"].values[0]) == ("wind[0].windspeed_north", -1.0)
    assert log.utc_offset_s == 1_700_000_000.0  # the 20 samples without a GPS time are ignored
    assert {n for n in log.signals if n.startswith("motor_")} == {f"motor_{i}" for i in range(1, 7)}
    assert log.vehicle == "PX4 on SYNTHETIC, MAV_TYPE 13 (hexarotor)"


@pytest.mark.parametrize(
    ("parameters", "noutputs", "motors"),
    [
        ({"MAV_TYPE": 13}, 8, 6),  # hexarotor: 6 of the 8 outputs
        ({"SYS_AUTOSTART": 6001}, 8, 6),  # hexa x airframe number, no MAV_TYPE
        ({"MAV_TYPE": 14}, 4, 4),  # an octorotor, but only 4 outputs logged
        ({"CA_ROTOR_COUNT": 3, "MAV_TYPE": 2}, 8, 3),  # the allocator's count wins
        ({"MAV_TYPE": 1}, 8, 0),  # fixed wing: which outputs are motors is unknown
    ],
)
def test_motor_count_from_actuator_outputs(
    tmp_path: Path, parameters: dict[str, int], noutputs: int, motors: int
) -> None:
    outputs = {f"output[{i}]": _f(1500 + i) for i in range(16)}
    topics = {("actuator_outputs", 0): {"timestamp": STAMPS, "noutputs": np.full(N, noutputs, np.uint32), **outputs}}
    unknown = pytest.warns(DataQualityWarning, match="cannot tell which outputs drive motors")
    with unknown if not motors else contextlib.nullcontext():
        log = read_ulog(_synthetic(tmp_path / "outputs.ulg", topics, parameters))
    assert {n for n in log.signals if n.startswith("motor_")} == {f"motor_{i}" for i in range(1, motors + 1)}
    if motors:
        assert log[f"motor_{motors}"].source == f"actuator_outputs[0].output[{motors - 1}]"
        assert log["motor_1"].unit == "PWM us"


@pytest.mark.parametrize(
    ("valid", "source"),
    [
        (np.ones(N, np.uint8), "vehicle_local_position[0].dist_bottom"),
        (np.r_[np.zeros(5), np.ones(N - 5)].astype(np.uint8), "-vehicle_local_position[0].z"),  # not valid throughout
    ],
)
def test_height_prefers_dist_bottom_only_when_valid_throughout(tmp_path: Path, valid: np.ndarray, source: str) -> None:
    topics = {
        ("vehicle_local_position", 0): {
            "timestamp": STAMPS,
            "z": _f(-1.5),
            "dist_bottom": _f(1.2),
            "z_valid": np.ones(N, np.uint8),
            "dist_bottom_valid": valid,
        }
    }
    log = read_ulog(_synthetic(tmp_path / "height.ulg", topics, {}))
    assert log["height_agl"].source == source and log["height_agl"].samples == N


@pytest.mark.parametrize("topic", ["sensor_gps", "vehicle_gps_position"])
def test_receiver_position_keeps_3d_fixes_in_either_layout(tmp_path: Path, topic: str) -> None:
    """Before PX4 v1.14 lat/lon are int32 in 1e-7 deg; from v1.14 latitude_deg/longitude_deg are double deg."""
    fix = np.where(np.arange(N) < 30, 2, 3).astype(np.uint8)  # a 2-D fix first
    lat_deg, lon_deg = 35.0 + 1e-6 * np.arange(N), -106.9 - 1e-6 * np.arange(N)
    old = {
        "timestamp": STAMPS,
        "lat": np.round(lat_deg * 1e7).astype(np.int32),
        "lon": np.round(lon_deg * 1e7).astype(np.int32),
        "fix_type": fix,
    }
    new = {"timestamp": STAMPS, "latitude_deg": lat_deg, "longitude_deg": lon_deg, "fix_type": fix}
    for layout, fields in (("old", old), ("new", new)):
        with pytest.warns(DataQualityWarning, match=r"dropped 30 of 200 samples \(30 with fix_type < 3\)"):
            log = read_ulog(_synthetic(tmp_path / f"{layout}.ulg", {(topic, 0): fields}, {}))
        np.testing.assert_array_equal(log["latitude"].time_s, _seconds(STAMPS[30:]))
        if layout == "old":
            assert log["latitude"].source == f"{topic}[0].lat (1e-7 deg→rad)"
            np.testing.assert_array_equal(log["longitude"].values, np.deg2rad(old["lon"][30:] * 1e-7))
        else:
            assert log["latitude"].source == f"{topic}[0].latitude_deg (deg→rad)"
            np.testing.assert_array_equal(log["longitude"].values, np.deg2rad(lon_deg[30:]))
        np.testing.assert_allclose(log["latitude"].values, np.deg2rad(lat_deg[30:]), rtol=0, atol=1e-9)
        assert any("dropped 30 of 200 samples (30 with fix_type < 3)" in w for w in log.warnings)


def test_the_estimator_position_wins_over_the_receiver(tmp_path: Path) -> None:
    topics = {
        ("sensor_gps", 0): {
            "timestamp": STAMPS,
            "latitude_deg": np.full(N, 10.0),
            "longitude_deg": np.full(N, 20.0),
            "fix_type": np.full(N, 3, np.uint8),
        },
        ("vehicle_global_position", 0): {"timestamp": STAMPS, "lat": np.full(N, 10.5), "lon": np.full(N, 20.5)},
    }
    log = read_ulog(_synthetic(tmp_path / "both.ulg", topics, {}))
    assert log["longitude"].source == "vehicle_global_position[0].lon (deg→rad)"  # no lat_lon_valid: all valid
    np.testing.assert_array_equal(log["longitude"].values, np.deg2rad(20.5))


@pytest.mark.parametrize("name", [QUAD, OLD])
def test_a_clean_file_read_in_memory_equals_the_tracked_read(
    real_data: Path, name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    import flightlogs.readers.ulog as ulog_module

    path = real_data / name
    assert ulog_module.scan_clean(path, path.stat().st_size, None) is not None  # the fast path is taken
    fast = read_warned(read_ulog, path)
    monkeypatch.setattr(ulog_module, "scan_clean", lambda *_: None)
    tracked = read_warned(read_ulog, path)
    assert fast.warnings == tracked.warnings and fast.vehicle == tracked.vehicle
    assert dict(fast.parameters) == dict(tracked.parameters) and list(fast.signals) == list(tracked.signals)
    for signal_name, signal in tracked.signals.items():
        np.testing.assert_array_equal(fast.signals[signal_name].time_s, signal.time_s)
        np.testing.assert_array_equal(fast.signals[signal_name].values, signal.values)


@pytest.mark.parametrize("name", [QUAD, "kd0aij-impulse-response/log1.ulg"])
def test_reading_the_mapped_topics_only_gives_the_same_log(
    real_data: Path, name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """What a log over 256 MB gets (pyulog keeps only the topics signals come from), on real logs: the same
    signals, bit for bit, parameters, vehicle and UTC offset."""
    import flightlogs.readers.ulog as ulog_module

    every = _read(real_data / name)
    monkeypatch.setattr(ulog_module, "_EVERY_TOPIC_UP_TO", 0)
    mapped = _read(real_data / name)
    assert mapped.signals.keys() == every.signals.keys() and len(every.signals) > 10
    for key, signal in every.signals.items():
        np.testing.assert_array_equal(mapped[key].time_s, signal.time_s)
        np.testing.assert_array_equal(mapped[key].values, signal.values)
        assert (mapped[key].unit, mapped[key].source) == (signal.unit, signal.source)
    assert (mapped.parameters, mapped.vehicle, mapped.utc_offset_s) == (
        every.parameters,
        every.vehicle,
        every.utc_offset_s,
    )


def test_a_large_log_of_other_topics_only_is_read_whole_to_say_so(
    real_data: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """No mapped topic in a large log: every topic is read again, so that a log of other topics is not called
    empty (the error a file with no data message gets)."""
    import flightlogs.readers.ulog as ulog_module
    from flightlogs.readers import px4_topics

    monkeypatch.setattr(ulog_module, "_EVERY_TOPIC_UP_TO", 0)
    monkeypatch.setattr(ulog_module, "MAPPED_TOPICS", frozenset({"no_such_topic"}))
    log = _read(real_data / QUAD)
    assert log.signals  # read on the second pass, with every topic
    assert px4_topics.MAPPED_TOPICS >= {"vehicle_angular_velocity", "actuator_outputs", "sensor_gps"}
