"""The references autopilots log (rate and attitude setpoints, pilot sticks) as canonical signals.

PX4 maps them through :data:`flightlogs.readers.px4_topics.PX4_GROUPS`;
ArduPilot DataFlash and MAVLink tlogs through
:mod:`flightlogs.readers._references`. Reference values: the fields read by
pyulog, pymavlink's DFReader or its MAVLink decoder directly (exact, with the
unit conversion applied here), scipy's rotation for the Euler angles, and
measured facts of the real logs with a stated margin.
"""

from __future__ import annotations

import contextlib
import io
import struct
import warnings
from functools import cache
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from pymavlink.dialects.v20 import all as mavlink2
from pyulog import ULog
from scipy.spatial.transform import Rotation

from flightlogs.conditioning.condition import condition_flight
from flightlogs.errors import SysidWarning
from flightlogs.flightlog import FlightLog, Signal
from flightlogs.readers._references import StickChannel, stick_channels
from flightlogs.readers.ardupilot import read_dataflash
from flightlogs.readers.dataflash import read_messages
from flightlogs.readers.tlog import read_tlog
from flightlogs.readers.ulog import read_ulog
from flightlogs.signals import LOGGED_SIGNALS, REFERENCE_SIGNALS, describe
from flightlogs.store.dataset import read_dataset, write_dataset
from flightlogs.writers.dataflash import MessageBlock, MessageSpec, encode_dataflash, standard_block
from flightlogs.writers.ulog import TopicData, write_ulog

from builders import read_warned

KD0AIJ = "kd0aij-impulse-response/log1.ulg"
QUAD = "px4-ulog-rs/quadrotor_local.ulg"
LOG171 = "dronekit-la-testdata/log171.bin"  # ArduCopter 3.3-dev
SAMPLE = "ardupilot-log-diagnosis/sample.bin"  # ArduCopter 3.6.4
PHOENIX = "phoenix/2018-09-17 16-44-06.tlog"  # ArduCopter 3.5.7
RATE_REFS = ("p_ref", "q_ref", "r_ref")
ATTITUDE_REFS = ("phi_ref", "theta_ref", "psi_ref")
STICKS = ("stick_lat", "stick_lon", "stick_yaw", "stick_thr")


@cache
def _ulog(path: Path) -> FlightLog:
    return read_warned(read_ulog, path)


@cache
def _raw(path: Path) -> tuple[dict[str, dict[str, np.ndarray]], float]:
    """Instance 0 of every topic, read by pyulog directly, and the log's start, s."""
    with contextlib.redirect_stdout(io.StringIO()):
        ulog = ULog(str(path))
    return {d.name: d.data for d in ulog.data_list if d.multi_id == 0}, ulog.start_timestamp / 1e6


def _at(signal: Signal, time_s: np.ndarray) -> np.ndarray:
    return np.interp(time_s, signal.time_s, signal.values)


def _correlation(a: Signal, b: Signal) -> float:
    return float(np.corrcoef(a.values, _at(b, a.time_s))[0, 1])


def _euler(wxyz: np.ndarray) -> np.ndarray:
    """(phi, theta, psi) per row of scalar-first quaternions, by scipy."""
    return Rotation.from_quat(wxyz[:, [1, 2, 3, 0]]).as_euler("ZYX")[:, ::-1]


# --------------------------------------------------------------------------- the registry


def test_references_are_canonical_optional_and_never_missing() -> None:
    assert {describe(n).unit for n in RATE_REFS} == {"rad/s"} and {describe(n).unit for n in ATTITUDE_REFS} == {"rad"}
    assert {describe(n).unit for n in STICKS} == {"1"}
    assert set(REFERENCE_SIGNALS) == {*RATE_REFS, *ATTITUDE_REFS, *STICKS}
    assert not set(REFERENCE_SIGNALS) & set(LOGGED_SIGNALS)
    gyro_only = FlightLog(
        path=Path("x.ulg"),
        log_format="ulog",
        autopilot="px4",
        signals={"p": Signal(name="p", time_s=np.arange(3.0), values=np.zeros(3), unit="rad/s", source="t")},
    )
    assert not set(REFERENCE_SIGNALS) & set(gyro_only.missing)


# --------------------------------------------------------------------------- PX4


def test_kd0aij_rate_setpoints_at_204_hz_follow_the_pilots_oscillations(real_data: Path) -> None:
    """The pilot's 1-3 Hz stick oscillations, 15-38 s into the log, reach the gyro through the rate loop.

    Measured: the peak correlation of the setpoint with the gyro over lags of
    0-0.2 s is 0.968 (roll) and 0.967 (pitch), at 40 and 45 ms; 0.90 leaves a
    margin of 0.07. The pilot did not excite yaw there (r_ref std 0.04 rad/s
    against 0.5 in roll), so r is not judged.
    """
    path = real_data / KD0AIJ
    log, (raw, start_s) = _ulog(path), _raw(path)
    setpoint = raw["vehicle_rates_setpoint"]
    for name, field in zip(RATE_REFS, ("roll", "pitch", "yaw")):
        assert log[name].source == f"vehicle_rates_setpoint[0].{field}" and log[name].unit == "rad/s"
        np.testing.assert_array_equal(log[name].values, setpoint[field].astype(np.float64))
        np.testing.assert_array_equal(log[name].time_s, setpoint["timestamp"] / 1e6)
        assert 200.0 < log[name].rate_hz < 208.0  # 203.7 Hz
    for reference, response in (("p_ref", "p"), ("q_ref", "q")):
        ref = log[reference]
        inside = (ref.time_s >= start_s + 15.0) & (ref.time_s <= start_s + 38.0)
        lags = np.arange(0.0, 0.2, 0.005)
        peaks = [np.corrcoef(ref.values[inside], _at(log[response], ref.time_s[inside] + lag))[0, 1] for lag in lags]
        assert max(peaks) > 0.90, reference
        assert 0.02 <= lags[int(np.argmax(peaks))] <= 0.08, reference  # the response lags the setpoint


def test_kd0aij_attitude_setpoints_from_the_euler_fields_agree_with_its_quaternion(real_data: Path) -> None:
    path = real_data / KD0AIJ
    log, (raw, _) = _ulog(path), _raw(path)
    setpoint = raw["vehicle_attitude_setpoint"]
    from_quaternion = _euler(np.column_stack([setpoint[f"q_d[{i}]"] for i in range(4)]).astype(np.float64))
    for k, (name, field) in enumerate(zip(ATTITUDE_REFS, ("roll_body", "pitch_body", "yaw_body"))):
        assert log[name].source == f"vehicle_attitude_setpoint[0].{field}"
        np.testing.assert_array_equal(log[name].values, setpoint[field].astype(np.float64))
        # two float32 copies of one setpoint: measured 1.2e-7 rad apart at most
        np.testing.assert_allclose(log[name].values, from_quaternion[:, k], rtol=0, atol=1e-6)
        assert 40.0 < log[name].rate_hz < 47.0  # 43.5 Hz


def test_modern_px4_log_gives_quaternion_setpoints_and_the_sticks(real_data: Path) -> None:
    path = real_data / QUAD
    log, (raw, _) = _ulog(path), _raw(path)
    assert log["p_ref"].source == "vehicle_rates_setpoint[0].roll" and 49.0 < log["p_ref"].rate_hz < 51.0
    setpoint = raw["vehicle_attitude_setpoint"]
    expected = _euler(np.column_stack([setpoint[f"q_d[{i}]"] for i in range(4)]).astype(np.float64))
    for k, name in enumerate(ATTITUDE_REFS):
        assert log[name].source == "vehicle_attitude_setpoint[0].q_d[0..3] (quaternion→Euler)"
        np.testing.assert_allclose(log[name].values, expected[:, k], atol=1e-9, err_msg=name)
    manual = raw["manual_control_setpoint"]
    for name, field, sign in (("stick_lat", "roll", 1), ("stick_lon", "pitch", -1), ("stick_yaw", "yaw", 1)):
        assert log[name].source == f"{'-' if sign < 0 else ''}manual_control_setpoint[0].{field}"
        np.testing.assert_array_equal(log[name].values, sign * manual[field].astype(np.float64))
    assert log["stick_thr"].source == "manual_control_setpoint[0].throttle"
    assert log["stick_thr"].values.min() == -1.0  # v1.14 logs throttle in -1..1; kept as logged
    # sticks positive as the rotation they ask for: measured 0.996 (roll) and 0.998 (pitch)
    assert _correlation(log["stick_lat"], log["phi_ref"]) > 0.95
    assert _correlation(log["stick_lon"], log["theta_ref"]) > 0.95
    assert {"vn", "ve"} == set(log.missing)


def _stamps(n: int) -> np.ndarray:
    return (1_000_000 + 20_000 * np.arange(n)).astype(np.uint64)  # 50 Hz from 1 s


def test_old_px4_names_and_validity_flags(tmp_path: Path) -> None:
    n = 50
    x, y, z, r = (np.linspace(-0.5, 0.5, n, dtype=np.float32) * k for k in (1, 2, 0.5, -1))
    valid = np.ones(n, dtype=bool)
    valid[:5] = False
    yaw = np.linspace(3.0, 3.2, n)  # q_d turning through ±π
    q_d = np.column_stack([np.cos(yaw / 2), np.zeros(n), np.zeros(n), np.sin(yaw / 2)]).astype(np.float32)
    topics = [
        TopicData("manual_control_setpoint", {"timestamp": _stamps(n), "x": x, "y": y, "z": z + 0.5, "r": r}),
        TopicData("vehicle_attitude_setpoint", {"timestamp": _stamps(n), "q_d": q_d, "q_d_valid": valid}),
    ]
    log = read_warned(read_ulog, write_ulog(tmp_path / "old.ulg", topics, info={"sys_name": "PX4"}))
    assert log["stick_lat"].source == "manual_control_setpoint[0].y"
    assert log["stick_lon"].source == "-manual_control_setpoint[0].x"
    assert log["stick_yaw"].source == "manual_control_setpoint[0].r"
    np.testing.assert_array_equal(log["stick_lon"].values, -x.astype(np.float64))
    np.testing.assert_array_equal(log["stick_thr"].values, (z + 0.5).astype(np.float64))  # 0..1 as logged
    psi_ref = log["psi_ref"]
    assert psi_ref.samples == n - 5 and any("5 with q_d_valid not set" in w for w in log.warnings)
    np.testing.assert_allclose(np.unwrap(psi_ref.values), yaw[5:], atol=1e-6)
    assert "p_ref" not in log.signals and not set(REFERENCE_SIGNALS) & set(log.missing)


def test_new_px4_sticks_drop_samples_flagged_invalid(tmp_path: Path) -> None:
    n = 40
    columns = {f: np.full(n, 0.25, dtype=np.float32) for f in ("roll", "pitch", "yaw", "throttle")}
    valid = np.arange(n) >= 10
    topic = TopicData("manual_control_setpoint", {"timestamp": _stamps(n), **columns, "valid": valid})
    log = read_warned(read_ulog, write_ulog(tmp_path / "new.ulg", [topic], info={"sys_name": "PX4"}))
    for name in STICKS:
        assert log[name].samples == 30 and log[name].unit == "1"
    assert log["stick_lon"].values[0] == -0.25 and log["stick_thr"].values[0] == 0.25


# --------------------------------------------------------------------------- ArduPilot DataFlash


def _dfreader(path: Path, message: str, field: str) -> np.ndarray:
    table = read_warned(read_messages, path, types=(message,))[message]
    return np.asarray(table[field], dtype=np.float64)


@pytest.mark.parametrize("relative", [LOG171, SAMPLE])
def test_rate_and_attitude_setpoints_of_real_copter_logs(real_data: Path, relative: str) -> None:
    path = real_data / relative
    log = read_warned(read_dataflash, path)
    legacy = relative == LOG171  # Copter ≤3.3 logs RATE in centidegrees/s
    scale, note = (np.pi / 18000.0, "cdeg/s→rad/s, Copter ≤3.3") if legacy else (np.pi / 180.0, "deg/s→rad/s")
    for name, column in zip(RATE_REFS, ("RDes", "PDes", "YDes")):
        assert log[name].source == f"RATE.{column} ({note})" and log[name].unit == "rad/s"
        np.testing.assert_allclose(log[name].values, _dfreader(path, "RATE", column) * scale, rtol=1e-15, atol=0)
    for name, column in (("phi_ref", "DesRoll"), ("theta_ref", "DesPitch")):
        assert log[name].source == f"ATT.{column} (deg→rad)"
        np.testing.assert_array_equal(log[name].values, np.deg2rad(_dfreader(path, "ATT", column)))
    des_yaw = np.deg2rad(_dfreader(path, "ATT", "DesYaw"))
    np.testing.assert_allclose(log["psi_ref"].values, np.angle(np.exp(1j * des_yaw)), rtol=0, atol=1e-15)
    assert np.all((log["psi_ref"].values > -np.pi) & (log["psi_ref"].values <= np.pi))


@pytest.mark.parametrize(("relative", "scale"), [(LOG171, np.pi / 18000.0), (SAMPLE, np.pi / 180.0)])
def test_the_rate_unit_matches_the_gyro(real_data: Path, relative: str, scale: float) -> None:
    """RATE.R/P, the achieved rates, share RDes/PDes's unit: scaled alike they match the gyro.

    Measured slopes 0.98 and 0.99 (log171, ~10 Hz), 0.98 and 1.00 (sample, 1 Hz);
    a wrong unit would be off by a factor of 100 or 57.
    """
    path = real_data / relative
    log, rate = read_warned(read_dataflash, path), read_warned(read_messages, path, types=("RATE",))["RATE"]
    for achieved, gyro in (("R", "p"), ("P", "q")):
        slope = np.polyfit(_at(log[gyro], rate.time_s), rate[achieved] * scale, 1)[0]
        assert 0.9 < slope < 1.1, (achieved, slope)


def test_copter_33_sticks_from_rcin_and_the_rc_parameters(real_data: Path) -> None:
    path = real_data / LOG171
    log, messages = (
        read_warned(read_dataflash, path),
        read_warned(read_messages, real_data / LOG171, types=("RCIN", "CTUN")),
    )
    assert log["stick_lon"].source == "RCIN.C2 (RCMAP_PITCH=2; RC2_MIN/TRIM/MAX 1000/1500/2000 µs)"
    assert log["stick_thr"].source == "RCIN.C3 (RCMAP_THROTTLE=3; RC3_MIN/TRIM/MAX 1000/1500/1900 µs)"
    live = messages["RCIN"]["C1"] > 0  # before the receiver is bound every channel reads 0
    assert "RCIN.C1, C2, C4, C3: dropped 468 of 2383 samples without a pulse on a stick channel (no RC signal)" in (
        log.warnings
    )
    np.testing.assert_allclose(log["stick_thr"].values, np.clip((messages["RCIN"]["C3"][live] - 1000) / 900, 0, 1))
    # measured: 0.999 with the throttle the autopilot took in, 0.67 and 0.64 with the pitch and yaw setpoints
    assert np.corrcoef(log["stick_thr"].values, messages["CTUN"]["ThrIn"][live])[0, 1] > 0.99
    assert _correlation(log["stick_lon"], log["theta_ref"]) > 0.5
    assert _correlation(log["stick_yaw"], log["r_ref"]) > 0.5
    assert log.missing == ()


def test_copter_36_sticks_use_its_calibration(real_data: Path) -> None:
    log = read_warned(read_dataflash, real_data / SAMPLE)
    np.testing.assert_allclose(log["stick_lat"].values, (1511 - 1512) / (1512 - 1094))  # held still, 1 Hz
    np.testing.assert_allclose(log["stick_thr"].values, 0.0)
    assert log.missing == ("battery_v",)


RCIN = MessageSpec(name="RCIN", format="QHHHHHH", columns=("TimeUS", "C1", "C2", "C3", "C4", "C5", "C6"))


def _rcin(time_us: np.ndarray, **channels: np.ndarray) -> MessageBlock:
    data = {column: np.full(time_us.size, 1500) for column in RCIN.columns[1:]}
    return MessageBlock(RCIN, {"TimeUS": time_us, **data, **channels})


def test_synthetic_dataflash_round_trips_the_references_exactly(tmp_path: Path) -> None:
    n = 400
    t = 10_000_000 + 2500 * np.arange(n)  # 400 Hz
    rdes = (40.0 * np.sin(np.arange(n) / 10.0)).astype(np.float32)  # deg/s
    des_yaw = np.mod(170.0 + 0.05 * np.arange(n), 360.0)  # through 180°
    pitch_pwm = (1500 + 300 * np.sin(np.arange(n) / 7.0)).astype(int)
    blocks = [
        standard_block("RATE", TimeUS=t, RDes=rdes, PDes=-rdes, YDes=0.5 * rdes),
        standard_block("ATT", TimeUS=t, DesRoll=np.full(n, 12.5), DesYaw=des_yaw),
        _rcin(t, C3=pitch_pwm, C6=np.full(n, 1300)),
    ]
    parameters = {"RCMAP_PITCH": 3.0, "RCMAP_THROTTLE": 6.0, "RC3_REVERSED": 1.0, "RC6_MIN": 1000.0, "RC6_MAX": 2000.0}
    path = tmp_path / "refs.bin"
    path.write_bytes(encode_dataflash(blocks, parameters=parameters, firmware="ArduCopter V4.5.7 (sim)"))
    log = read_warned(read_dataflash, path)
    np.testing.assert_array_equal(log["p_ref"].values, np.deg2rad(rdes.astype(np.float64)))
    np.testing.assert_array_equal(log["q_ref"].values, -np.deg2rad(rdes.astype(np.float64)))
    np.testing.assert_array_equal(log["p_ref"].time_s, t / 1e6)
    assert log["p_ref"].source == "RATE.RDes (deg/s→rad/s)"
    np.testing.assert_allclose(log["phi_ref"].values, np.deg2rad(12.5))
    wrapped = np.angle(np.exp(1j * np.deg2rad(des_yaw)))
    np.testing.assert_allclose(log["psi_ref"].values, wrapped, rtol=0, atol=1e-9)  # 'C' stores centidegrees
    # RC3 reversed: a higher PWM is stick forward, nose down; defaults for what the log does not set
    assert log["stick_lon"].source == (
        "RCIN.C3 (RCMAP_PITCH=3; RC3_MIN/TRIM/MAX 1100/1500/1900 µs (MIN/TRIM/MAX the default), reversed)"
    )
    np.testing.assert_allclose(log["stick_lon"].values, -np.clip((pitch_pwm - 1500) / 400, -1, 1))
    np.testing.assert_allclose(log["stick_thr"].values, 0.3)  # RC6: (1300 - 1000) / (2000 - 1000)
    assert log["stick_lat"].source.startswith("RCIN.C1 (RCMAP_ROLL default 1;")


def test_setpoints_zero_throughout_are_not_logged(tmp_path: Path) -> None:
    """The simulator fills only ROut..AOut and Roll..Yaw: its zero RDes/DesRoll are no setpoints."""
    t = 10_000_000 + 2500 * np.arange(100)
    blocks = [standard_block("RATE", TimeUS=t, ROut=np.full(100, 0.1)), standard_block("ATT", TimeUS=t, Roll=t * 0.0)]
    path = tmp_path / "sim.bin"
    path.write_bytes(encode_dataflash(blocks))
    log = read_warned(read_dataflash, path)
    assert "delta_lat" in log.signals and not set(REFERENCE_SIGNALS) & set(log.signals)
    assert not set(REFERENCE_SIGNALS) & set(log.missing)


# --------------------------------------------------------------------------- RC calibration


@pytest.mark.parametrize(
    ("name", "pwm", "reversed_", "expected"),
    [
        ("stick_lat", [1100, 1300, 1500, 1700, 1900], False, [-1.0, -0.5, 0.0, 0.5, 1.0]),
        ("stick_lon", [1000, 1500, 2100], True, [1.0, 0.0, -1.0]),  # clipped beyond MIN/MAX
        ("stick_thr", [1100, 1500, 1900, 2000], False, [0.0, 0.5, 1.0, 1.0]),
        ("stick_thr", [1100, 1500, 1900], True, [1.0, 0.5, 0.0]),
    ],
)
def test_pwm_normalisation_table(name: str, pwm: list[int], reversed_: bool, expected: list[float]) -> None:
    stick = StickChannel(name=name, channel=1, low=1100, trim=1500, high=1900, reversed=reversed_, note="")
    np.testing.assert_allclose(stick.normalise(np.array(pwm, dtype=float)), expected)


@given(
    trim_fraction=st.floats(0.1, 0.9),
    pwm=st.lists(st.floats(800, 2200), min_size=2, max_size=20),
    axis=st.sampled_from(STICKS),
)
def test_normalised_sticks_are_monotone_bounded_and_reversal_flips_them(
    trim_fraction: float, pwm: list[float], axis: str
) -> None:
    low, high = 1000.0, 2000.0
    common = dict(name=axis, channel=1, low=low, trim=low + trim_fraction * (high - low), high=high, note="")
    normal, flipped = StickChannel(**common, reversed=False), StickChannel(**common, reversed=True)
    ordered = np.sort(np.array(pwm))
    values = normal.normalise(ordered)
    assert np.all(np.diff(values) >= 0)
    assert np.all(values >= (0.0 if axis == "stick_thr" else -1.0)) and np.all(values <= 1.0)
    mirror = 1.0 - values if axis == "stick_thr" else -values
    np.testing.assert_allclose(flipped.normalise(ordered), mirror)


@pytest.mark.parametrize(
    ("name", "channel", "low", "match"),
    [("roll", 1, 1000.0, "name="), ("stick_lat", 0, 1000.0, "channel="), ("stick_thr", 3, 2000.0, "low=")],
)
def test_a_stick_channel_checks_its_fields(name: str, channel: int, low: float, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        StickChannel(name=name, channel=channel, low=low, trim=1500.0, high=2000.0, reversed=False, note="")


def test_rc_parameters_of_each_autopilot() -> None:
    old = stick_channels({"RC2_REV": -1.0}, "ardupilot")  # Copter ≤3.4 reverses with RCn_REV = -1
    assert [s.name for s in old] == list(STICKS) and [s.channel for s in old] == [1, 2, 4, 3]
    assert [s.reversed for s in old] == [False, True, False, False]
    px4 = stick_channels({"RC_MAP_ROLL": 2.0, "RC_MAP_PITCH": 0.0, "RC2_REV": -1.0}, "px4")
    assert [(s.name, s.channel, s.low, s.high, s.reversed) for s in px4] == [("stick_lat", 2, 1000, 2000, True)]
    with pytest.warns(match="RC1_MIN/TRIM/MAX 1500/1500/1900 µs are inconsistent; stick_lat not read"):
        assert [s.name for s in stick_channels({"RC1_MIN": 1500.0}, "ardupilot")] == list(STICKS[1:])


# --------------------------------------------------------------------------- MAVLink tlog


def _tlog(path: Path, items: list[tuple[float, object]]) -> Path:
    """``(rx_s, message)`` from the vehicle (1, 1) as a MAVLink 2 tlog."""
    link = mavlink2.MAVLink(None, 1, 1)
    path.write_bytes(b"".join(struct.pack(">Q", int(round(rx * 1e6))) + msg.pack(link) for rx, msg in items))
    return path


def test_px4_tlog_attitude_target_and_rc_channels(tmp_path: Path) -> None:
    items: list[tuple[float, object]] = [(0.0, mavlink2.MAVLink_heartbeat_message(2, 12, 0, 0, 0, 3))]
    for name, value in {"RC_MAP_ROLL": 1.0, "RC_MAP_PITCH": 2.0, "RC_MAP_THROTTLE": 3.0, "RC2_REV": -1.0}.items():
        items.append((0.0, mavlink2.MAVLink_param_value_message(name.encode(), value, 9, 100, 0)))
    quaternion = [np.cos(0.1), 0.0, 0.0, np.sin(0.1)]  # yaw 0.2 rad
    for k in range(6):
        boot_ms, mask = 5000 + 100 * k, 4 if k == 0 else 0  # the first sample ignores the yaw rate
        items.append(
            (1.0 + k, mavlink2.MAVLink_attitude_target_message(boot_ms, mask, quaternion, 0.1 * k, -0.2, 0.3, 0.5))
        )
        pwm = [1500 + 50 * k, 1700, 1000 + 100 * k, *([0] * 15)]
        items.append((1.0 + k, mavlink2.MAVLink_rc_channels_message(boot_ms, 3, *pwm, 255)))
    log = read_warned(read_tlog, _tlog(tmp_path / "px4.tlog", items))
    np.testing.assert_allclose(log["p_ref"].values, 0.1 * np.arange(6), rtol=1e-6)
    np.testing.assert_allclose(log["p_ref"].time_s, 5.0 + 0.1 * np.arange(6))
    assert log["r_ref"].samples == 5 and log["r_ref"].source == "ATTITUDE_TARGET.body_yaw_rate"
    np.testing.assert_allclose(log["psi_ref"].values, 0.2, rtol=1e-6)
    assert log["psi_ref"].source == "ATTITUDE_TARGET.q[0..3] (quaternion→Euler)"
    np.testing.assert_allclose(log["stick_lat"].values, 0.1 * np.arange(6))  # (PWM - 1500) / 500
    np.testing.assert_allclose(log["stick_lon"].values, -0.4)  # RC2 reversed
    np.testing.assert_allclose(log["stick_thr"].values, 0.1 * np.arange(6))
    assert log["stick_thr"].source == (
        "RC_CHANNELS.chan3_raw (RC_MAP_THROTTLE=3; RC3_MIN/TRIM/MAX 1000/1500/2000 µs (MIN/TRIM/MAX the default))"
    )
    assert "stick_yaw" not in log.signals  # PX4 has no default channel: RC_MAP_YAW not set


def test_phoenix_tlog_sticks_from_rc_channels(real_data: Path) -> None:
    from pymavlink import mavutil

    log = read_warned(read_tlog, real_data / PHOENIX)
    rows = []
    conn = mavutil.mavlink_connection(str(real_data / PHOENIX))
    while (msg := conn.recv_match(type="RC_CHANNELS")) is not None:
        if (msg.get_srcSystem(), msg.get_srcComponent()) == (1, 1):
            rows.append([msg.chan3_raw, msg.chan1_raw, msg.chan2_raw, msg.chan4_raw])
    conn.close()
    pwm = np.array(rows, dtype=float)
    live = np.all(pwm > 0, axis=1)
    assert log["stick_thr"].source == "RC_CHANNELS.chan3_raw (RCMAP_THROTTLE=3; RC3_MIN/TRIM/MAX 982/2006/2006 µs)"
    np.testing.assert_allclose(log["stick_thr"].values, np.clip((pwm[live, 0] - 982) / (2006 - 982), 0, 1))
    assert log["stick_thr"].samples == 628 and not set(RATE_REFS) & set(log.signals)  # ArduPilot sends no target
    assert set(log.missing) == {"delta_lat", "delta_lon", "delta_yaw", "delta_thr", "battery_v"}


# --------------------------------------------------------------------------- into records and the store


def test_references_reach_the_records_and_the_store_round_trips_them(tmp_path: Path) -> None:
    rate_hz, n = 100.0, 3001  # the slower references end with the core signals
    t = np.arange(n) / rate_hz
    rng = np.random.default_rng(14)
    heading = 3.0 + 0.01 * t  # through +π at 14 s
    signals = {
        name: Signal(name=name, time_s=t, values=rng.normal(0.0, 0.1, n), unit="rad/s", source=f"test.{name}")
        for name in ("p", "q", "r")
    }
    signals["p_ref"] = Signal(name="p_ref", time_s=t[::2], values=np.sin(t[::2]), unit="rad/s", source="test.p_ref")
    signals["psi_ref"] = Signal(
        name="psi_ref", time_s=t[::5], values=np.angle(np.exp(1j * heading[::5])), unit="rad", source="test.psi_ref"
    )
    log = FlightLog(path=tmp_path / "refs.ulg", log_format="ulog", autopilot="px4", signals=signals)
    with warnings.catch_warnings():  # what conditioning says of this bare log is not tested here
        warnings.simplefilter("ignore", SysidWarning)
        flight = condition_flight(log)
    (record,) = flight.records
    assert {"p_ref", "psi_ref"} <= set(record.table.columns) and record.units["psi_ref"] == "rad"
    time_s = record.table.index.to_numpy()
    np.testing.assert_allclose(record.table["p_ref"] + record.trim["p_ref"], np.sin(time_s), atol=1e-3)
    # unwrapped like psi before it is resampled: no jump of 2π where the heading passes ±π
    np.testing.assert_allclose(record.table["psi_ref"] + record.trim["psi_ref"], 3.0 + 0.01 * time_s, atol=1e-6)
    path = tmp_path / "refs.h5"
    write_dataset(path, [log], conditioned=[flight])
    back = read_dataset(path)
    (stored,) = back.conditioned[0].records
    for name in ("p_ref", "psi_ref"):
        np.testing.assert_array_equal(stored.table[name].to_numpy(), record.table[name].to_numpy())
        np.testing.assert_array_equal(back.logs[0][name].values, log[name].values)
        assert back.logs[0][name].source == log[name].source
