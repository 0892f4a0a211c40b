"""Tests of flightlogs.readers.ardupilot: canonical signals from DataFlash logs.

Reference values are cross-implementation: the same fields read with
pymavlink's DFReader, with the unit conversion applied here.
"""

from __future__ import annotations

import calendar
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest
from pymavlink.DFReader import DFReader_binary

from flightlogs.errors import DataQualityWarning
from flightlogs.readers.ardupilot import gps_leap_seconds, read_dataflash, system_id_runs
from flightlogs.readers.dataflash import decode_messages, read_messages
from flightlogs.readers.dispatch import read_log
from flightlogs.writers.dataflash import encode_dataflash, standard_block

from builders import read_warned

SAMPLE = ("ardupilot-log-diagnosis", "sample.bin")  # ArduCopter 3.6.4
LOG171 = ("dronekit-la-testdata", "log171.bin")  # ArduCopter 3.3-dev
GPS_EPOCH = 315964800


def dfreader_field(path: Path, message: str, field: str) -> tuple[np.ndarray, np.ndarray]:
    """(time s, values) of one field read with DFReader; time from TimeUS or TimeMS."""
    reader = DFReader_binary(str(path))
    times, values = [], []
    while (msg := reader.recv_match(type=message)) is not None:
        stamp = msg.TimeUS / 1e6 if "TimeUS" in msg.fmt.columns else msg.TimeMS / 1e3
        times.append(stamp)
        values.append(getattr(msg, field))
    reader.close()
    return np.array(times), np.array(values, dtype=np.float64)


@pytest.mark.parametrize(
    ("where", "name", "message", "field", "convert"),
    [
        (SAMPLE, "phi", "ATT", "Roll", np.deg2rad),
        (SAMPLE, "p", "IMU", "GyrX", None),
        (SAMPLE, "az", "IMU", "AccZ", None),
        (SAMPLE, "motor_3", "RCOU", "C3", None),
        (SAMPLE, "vn", "NKF1", "VN", None),
        (SAMPLE, "delta_lat", "RATE", "ROut", None),
        (LOG171, "theta", "ATT", "Pitch", np.deg2rad),
        (LOG171, "q", "IMU", "GyrY", None),
        (LOG171, "motor_1", "RCOU", "Ch1", None),
        (LOG171, "battery_v", "CURR", "Volt", lambda v: v / 100.0),
        (LOG171, "vd", "EKF1", "VD", None),
        (LOG171, "delta_thr", "RATE", "AOut", None),
    ],
    ids=lambda v: v if isinstance(v, str) else None,
)
def test_signal_equals_dfreader_field_sample_for_sample(real_data: Path, where, name, message, field, convert) -> None:
    path = real_data.joinpath(*where)
    log = read_warned(read_dataflash, path)
    time_s, values = dfreader_field(path, message, field)
    np.testing.assert_array_equal(log[name].time_s, time_s)
    np.testing.assert_array_equal(log[name].values, convert(values) if convert else values)


def test_float32_and_pwm_fields_are_held_in_float32_converted_ones_in_float64(real_data: Path) -> None:
    log = read_warned(read_dataflash, real_data.joinpath(*SAMPLE))
    held = {name: log[name].stored_values.dtype for name in ("p", "az", "delta_lat", "motor_3", "phi", "psi")}
    # IMU and RATE fields are float32, RCOU uint16; the angles are converted from degrees
    assert held == {"p": np.float32, "az": np.float32, "delta_lat": np.float32, "motor_3": np.float32} | {
        "phi": np.float64,
        "psi": np.float64,
    }
    signals = log.signals.values()
    held_bytes = sum(s.stored_values.nbytes for s in signals)
    assert held_bytes < 0.7 * sum(s.values.nbytes for s in signals)  # what float64 would hold


@pytest.mark.parametrize("where", [SAMPLE, LOG171], ids=lambda w: w[1])
def test_yaw_is_wrapped_to_minus_pi_pi(real_data: Path, where) -> None:
    path = real_data.joinpath(*where)
    psi = read_warned(read_dataflash, path)["psi"]
    _, yaw_deg = dfreader_field(path, "ATT", "Yaw")
    assert np.all((psi.values > -np.pi) & (psi.values <= np.pi))
    # np.angle is an independent (-π, π] wrap; the two agree to float rounding (a few ulp of π)
    np.testing.assert_allclose(psi.values, np.angle(np.exp(1j * np.deg2rad(yaw_deg))), rtol=0, atol=1e-15)
    assert psi.source == "ATT.Yaw (deg→rad, wrapped to (-π, π])"


def test_copter_36_log_metadata_and_sources(real_data: Path) -> None:
    log = read_warned(read_dataflash, real_data.joinpath(*SAMPLE))
    assert (log.log_format, log.autopilot) == ("dataflash", "ardupilot")
    assert log.vehicle.startswith("ArduCopter V3.6.4 (6c4da9e3); frame QUAD") and "4 motors" in log.vehicle
    assert log.parameters["FRAME_CLASS"] == 1.0
    assert log.parameters["MOT_THST_HOVER"] == float(np.float32(0.14000675082206726))  # first of three values
    assert log.missing == ("battery_v",)  # no BAT message in this log: absent, not filled
    assert sorted(n for n in log.signals if n.startswith("motor_")) == ["motor_1", "motor_2", "motor_3", "motor_4"]
    assert log["p"].source == "IMU[0].GyrX" and log["phi"].source == "ATT.Roll (deg→rad)"
    assert log["height_agl"].source == "CTUN.Alt (altitude above home; no rangefinder)"
    assert log["delta_thr"].unit == "normalised (0..1)" and log["motor_1"].unit == "us"
    assert "excitation" not in log.signals


def test_copter_33_log_metadata_and_units(real_data: Path) -> None:
    log = read_warned(read_dataflash, real_data.joinpath(*LOG171))
    assert log.vehicle.startswith("APM:Copter V3.3-dev (ae3192b8); frame QUAD")
    assert log.missing == ()
    assert log["battery_v"].source == "CURR.Volt (cV→V)" and log["battery_v"].unit == "V"
    assert log["delta_lat"].unit.startswith("servo units") and log["delta_thr"].unit.startswith("per mille")
    assert log["vn"].source == "EKF1[0].VN" and log["est_wind_n"].source == "EKF2[0].VWN"


@pytest.mark.parametrize(
    ("where", "leap", "day"), [(SAMPLE, 18, "2019-03-27"), (LOG171, 17, "2015-11-21")], ids=["2019", "2015"]
)
def test_utc_offset_from_gps_week_and_ms(real_data: Path, where, leap: int, day: str) -> None:
    path = real_data.joinpath(*where)
    log = read_warned(read_dataflash, path)
    reader = DFReader_binary(str(path))
    gps = []
    while (msg := reader.recv_match(type="GPS")) is not None:
        if "GWk" in msg.fmt.columns:
            gps.append((msg.GWk, msg.GMS, msg.TimeUS / 1e6))
        else:  # Copter 3.3: TimeMS is GPS time of week, T the boot time
            gps.append((msg.Week, msg.TimeMS, msg.T / 1e3))
    week, week_ms, boot_s = np.array([g for g in gps if g[0] > 0], dtype=np.float64).T
    expected = np.median(GPS_EPOCH + week * 604800.0 + week_ms / 1e3 - leap - boot_s)
    assert log.utc_offset_s == expected
    assert log.utc_start is not None and log.utc_start.date().isoformat() == day
    # DFReader's clock starts at the first fix and always subtracts 18 s; GPS messages are
    # logged up to one 5 Hz GPS period (0.2 s) after their fix, so the two agree within that.
    assert abs(log.utc_offset_s - (reader.clock.timebase + 18 - leap)) < 0.2
    reader.close()


@pytest.mark.parametrize(
    ("where", "dropped"), [(SAMPLE, 0), (LOG171, 161)], ids=lambda v: v[1] if isinstance(v, tuple) else None
)
def test_gps_position_equals_dfreader_where_the_fix_is_3d(real_data: Path, where, dropped: int) -> None:
    """GPS Lat/Lng (deg as DFReader gives them) → rad, samples with Status ≥ 3 only."""
    path = real_data.joinpath(*where)
    log = read_warned(read_dataflash, path)
    reader = DFReader_binary(str(path))
    rows = []
    while (msg := reader.recv_match(type="GPS")) is not None:
        boot_s = msg.TimeUS / 1e6 if "TimeUS" in msg.fmt.columns else msg.T / 1e3  # Copter 3.3: T is boot time
        rows.append((boot_s, msg.Status, msg.Lat, msg.Lng))
    reader.close()
    boot_s, status, lat, lng = np.array(rows, dtype=np.float64).T
    fixed = status >= 3
    assert int((~fixed).sum()) == dropped
    for name, values, column in (("latitude", lat, "Lat"), ("longitude", lng, "Lng")):
        np.testing.assert_array_equal(log[name].time_s, boot_s[fixed])
        np.testing.assert_array_equal(log[name].values, np.deg2rad(values[fixed]))
        assert log[name].source == f"GPS[0].{column} (deg→rad, Status ≥ 3)" and log[name].unit == "rad"
    assert any(f"dropped {dropped} of" in w for w in log.warnings if w.startswith("GPS[0].Lat")) == bool(dropped)


def test_gps_position_from_instance_0_and_none_without_a_fix(tmp_path: Path) -> None:
    stamps = [1_000_000, 1_200_000, 1_400_000]
    gps = standard_block(
        "GPS",
        TimeUS=stamps * 2,
        I=[0, 0, 0, 1, 1, 1],
        Status=[1, 3, 6, 3, 3, 3],
        Lat=[0.0, 35.0, 35.0000001, 1.0, 1.0, 1.0],
        Lng=[0.0, -106.9, -106.9, 2.0, 2.0, 2.0],
    )
    path = tmp_path / "gps.bin"
    path.write_bytes(encode_dataflash([gps]))
    with pytest.warns(DataQualityWarning, match=r"GPS\[0\].Lat, Lng: dropped 1 of 3 samples without a 3-D fix"):
        log = read_dataflash(path)
    np.testing.assert_array_equal(log["latitude"].values, np.deg2rad([35.0, 35.0000001]))
    np.testing.assert_array_equal(log["longitude"].time_s, [1.2, 1.4])
    assert "GPS[0].Lat, Lng: dropped 1 of 3 samples without a 3-D fix (Status < 3)." in log.warnings
    nofix = standard_block("GPS", TimeUS=stamps, Status=[1, 2, 1], Lat=[35.0] * 3, Lng=[-106.9] * 3)
    path.write_bytes(encode_dataflash([nofix]))
    with pytest.warns(DataQualityWarning, match="never had a 3-D fix"):
        log = read_dataflash(path)
    assert "latitude" not in log.signals and any("never had a 3-D fix" in w for w in log.warnings)


def _gps_block(utc: datetime, leap: int, boot_s: float) -> object:
    """Three GPS fixes at `utc` (+0.2 s steps) logged at boot time `boot_s`."""
    gps_s = calendar.timegm(utc.timetuple()) + leap - GPS_EPOCH + np.array([0.0, 0.2, 0.4])
    week = (gps_s // 604800).astype(int)
    return standard_block(
        "GPS",
        TimeUS=np.round((boot_s + np.array([0.0, 0.2, 0.4])) * 1e6).astype(np.int64),
        GWk=week,
        GMS=np.round((gps_s - week * 604800) * 1e3).astype(np.int64),
        Status=[3, 3, 3],
    )


@pytest.mark.parametrize(
    ("utc", "leap"),
    [(datetime(2015, 6, 30, 12), 16), (datetime(2016, 12, 31, 23, 59, 50), 17), (datetime(2017, 1, 1, 0, 0, 10), 18)],
    ids=str,
)
def test_leap_seconds_follow_the_date(tmp_path: Path, utc: datetime, leap: int) -> None:
    path = tmp_path / "gps.bin"
    path.write_bytes(encode_dataflash([_gps_block(utc, leap, boot_s=100.0)]))
    log = read_dataflash(path)
    assert log.utc_offset_s == calendar.timegm(utc.timetuple()) - 100.0  # exact: whole ms, whole µs


def test_gps_leap_seconds_table() -> None:
    when = [
        datetime(y, m, d, tzinfo=UTC).timestamp()
        for y, m, d in [(2012, 6, 30), (2012, 7, 2), (2015, 7, 2), (2017, 1, 2)]
    ]
    assert gps_leap_seconds(np.array(when)).tolist() == [15, 16, 17, 18]


def test_no_gps_fix_gives_no_utc(tmp_path: Path) -> None:
    gps = standard_block("GPS", TimeUS=[1_000_000, 1_200_000], GWk=[0, 0], GMS=[0, 0], Status=[1, 1])
    path = tmp_path / "nofix.bin"
    path.write_bytes(encode_dataflash([gps]))
    with pytest.warns(DataQualityWarning, match="never had a 3-D fix"):
        assert read_dataflash(path).utc_offset_s is None


def test_sidd_gives_the_excitation_and_sids_the_maneuver(tmp_path: Path) -> None:
    t = 30_000_000 + 2500 * np.arange(800)
    targ = np.sin(np.arange(800) / 20.0).astype(np.float32)
    blocks = [
        standard_block(
            "SIDS",
            TimeUS=[t[0] - 10],
            Ax=[10],
            Mag=[0.05],
            FSt=[0.5],
            FSp=[8.0],
            TFin=[1.0],
            TC=[4.0],
            TR=[2.0],
            TFout=[0.5],
        ),
        standard_block("SIDD", TimeUS=t, Time=(t - t[0]) / 1e6, Targ=targ),
        standard_block("RATE", TimeUS=t + 1, ROut=targ + 0.01),
    ]
    path = tmp_path / "sysid.bin"
    path.write_bytes(encode_dataflash(blocks, parameters={"SID_AXIS": 10.0}, firmware="ArduCopter V4.5.7 (sim)"))
    log = read_dataflash(path)
    np.testing.assert_array_equal(log["excitation"].values, targ)
    np.testing.assert_array_equal(log["excitation"].time_s, t / 1e6)
    assert log["excitation"].source == "SIDD.Targ" and "10 (mixer roll)" in log["excitation"].unit
    (run,) = system_id_runs(read_messages(path))
    assert (run.axis, run.axis_name, run.f_start_hz, run.f_stop_hz) == (10, "mixer roll", 0.5, 8.0)
    assert run.start_s == (t[0] - 10) / 1e6 and run.end_s == t[-1] / 1e6
    assert log.vehicle.startswith("ArduCopter V4.5.7 (sim)")


def test_the_flightlog_carries_the_system_id_runs(tmp_path: Path) -> None:
    t = 10_000_000 + 2500 * np.arange(400)
    sids = standard_block(
        "SIDS",
        TimeUS=[t[0] - 5, t[250] - 5],
        Ax=[7, 11],
        Mag=[10.0, 0.1],
        FSt=[0.5, 1.0],
        FSp=[20.0, 8.0],
        TFin=[1.0, 0.5],
        TC=[4.0, 2.0],
        TR=[2.0, 1.0],
        TFout=[0.5, 0.5],
    )
    sidd = standard_block("SIDD", TimeUS=t, Time=(t - t[0]) / 1e6, Targ=np.zeros(400, dtype=np.float32))
    path = tmp_path / "runs.bin"
    path.write_bytes(encode_dataflash([sids, sidd]))
    runs = read_dataflash(path).system_id_runs
    assert isinstance(runs, tuple) and [run.end_s for run in runs] == [t[249] / 1e6, t[-1] / 1e6]
    assert runs == system_id_runs(read_messages(path))


def test_newer_layouts_instances_and_estimator_choice(tmp_path: Path) -> None:
    t = 5_000_000 + 10_000 * np.arange(100)
    two = np.repeat(t, 2)
    blocks = [
        standard_block("XKF1", TimeUS=two, C=np.tile([0, 1], 100), VN=np.tile([1.5, -7.0], 100)),
        standard_block("XKF2", TimeUS=two + 1, C=np.tile([0, 1], 100), VWN=np.tile([2.0, 9.0], 100)),
        standard_block("BAT", TimeUS=two + 2, Instance=np.tile([0, 1], 100), Volt=np.tile([15.5, 3.3], 100)),
        standard_block("RFND", TimeUS=two + 3, Instance=np.tile([0, 1], 100), Dist=np.tile([1.25, 40.0], 100)),
        standard_block("CTUN", TimeUS=t + 4, ThO=np.full(100, 0.4), Alt=np.full(100, 7.0)),
    ]
    path = tmp_path / "new.bin"
    path.write_bytes(encode_dataflash(blocks, parameters={"AHRS_EKF_TYPE": 3.0}))
    log = read_dataflash(path)
    assert log["vn"].source == "XKF1[0].VN" and np.all(log["vn"].values == 1.5)
    assert log["est_wind_n"].source == "XKF2[0].VWN" and np.all(log["est_wind_n"].values == 2.0)
    assert log["battery_v"].source == "BAT[0].Volt" and np.all(log["battery_v"].values == np.float32(15.5))
    assert log["height_agl"].source == "RFND[0].Dist" and np.all(log["height_agl"].values == 1.25)
    assert log["delta_thr"].source == "CTUN.ThO" and log["delta_thr"].unit == "normalised (0..1)"
    assert {"p", "phi", "delta_lat", "motor_1..n"} <= set(log.missing)


def test_motor_count_from_moving_channels_without_frame_information(tmp_path: Path) -> None:
    n = 50
    pwm = {f"C{k}": 1100 + (np.arange(n) % 7) * 10 * (k <= 6) for k in range(1, 15)}
    path = tmp_path / "hexa.bin"
    path.write_bytes(encode_dataflash([standard_block("RCOU", TimeUS=1000 + 2500 * np.arange(n), **pwm)]))
    log = read_dataflash(path)
    assert sorted(s for s in log.signals if s.startswith("motor_")) == [f"motor_{k}" for k in range(1, 7)]
    assert log["motor_6"].source == "RCOU.C6 (PWM)"


def test_read_log_dispatches_and_reports_progress(real_data: Path) -> None:
    path = real_data.joinpath(*SAMPLE)
    calls: list[tuple[int, int]] = []
    log = read_warned(read_log, path, progress=lambda done, total: calls.append((done, total)))
    assert log.autopilot == "ardupilot" and calls[-1] == (path.stat().st_size,) * 2


def test_appended_logs_with_other_layouts_map_the_first_only(real_data: Path, tmp_path: Path) -> None:
    path = tmp_path / "both.bin"
    path.write_bytes(real_data.joinpath(*SAMPLE).read_bytes() + real_data.joinpath(*LOG171).read_bytes())
    with pytest.warns(DataQualityWarning, match="only the first log|is redefined|clock goes back|EKF wind estimate"):
        log = read_dataflash(path)
    first = read_warned(read_dataflash, real_data.joinpath(*SAMPLE))
    np.testing.assert_array_equal(log["phi"].values, first["phi"].values)
    assert any("only the first log" in w for w in log.warnings)
    assert read_warned(decode_messages, path.read_bytes()).get("ATT@1") is not None
