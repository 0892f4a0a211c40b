"""Signal and FlightLog containers: shapes, immutability, missing signals."""

from __future__ import annotations

from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest

from flightlogs.errors import MissingSignalError
from flightlogs.flightlog import FlightLog, Signal, SystemIdRun
from flightlogs.signals import LOGGED_SIGNALS, describe, is_canonical


def _signal(name: str, n: int = 101, rate: float = 100.0) -> Signal:
    t = np.arange(n) / rate
    return Signal(name=name, time_s=t, values=np.sin(t), unit=describe(name).unit, source=f"test.{name}")


def test_signal_rate_and_duration() -> None:
    signal = _signal("q", n=201, rate=200.0)
    assert signal.samples == 201
    assert signal.duration_s == pytest.approx(1.0)
    assert signal.rate_hz == pytest.approx(200.0)


def test_signal_arrays_are_read_only() -> None:
    signal = _signal("p")
    with pytest.raises(ValueError):
        signal.values[0] = 1.0


@pytest.mark.parametrize(
    ("given", "held"),
    [
        (np.float32, np.float32),  # a log's float32 field: half the memory, every value exact
        (np.uint16, np.float32),  # a PWM: exact in float32
        (np.int16, np.float32),
        (np.bool_, np.float32),
        (np.int32, np.float64),  # 2**24 + 1 is not a float32
        (np.float64, np.float64),
    ],
)
def test_signal_holds_a_narrow_field_narrow_and_gives_float64(given: type, held: type) -> None:
    raw = np.array([0, 1, 7, 100], dtype=given) if given is not np.bool_ else np.array([0, 1, 1, 0], dtype=bool)
    if given is np.float32:
        raw = np.array([0.1, -2.5e-7, 3.4e38, 1 / 3], dtype=np.float32)
    if given is np.int32:
        raw = np.array([0, 2**24 + 1, -(2**31), 2**31 - 1], dtype=np.int32)
    signal = Signal(name="q", time_s=np.arange(4.0), values=raw, unit="rad/s", source="test")
    assert signal.stored_values.dtype == held
    assert signal.values.dtype == np.float64
    assert np.array_equal(signal.values, raw.astype(np.float64))  # exact: nothing rounded either way
    assert not signal.values.flags.writeable and not signal.stored_values.flags.writeable


def test_a_signal_replaced_with_new_values_holds_them() -> None:
    signal = Signal(name="psi", time_s=np.arange(3.0), values=np.float32([3.0, -3.0, 3.0]), unit="rad", source="t")
    unwrapped = replace(signal, values=np.unwrap(signal.values), source="t, unwrapped")
    assert unwrapped.stored_values.dtype == np.float64 and unwrapped.source == "t, unwrapped"
    assert np.allclose(unwrapped.values, [3.0, 2 * np.pi - 3.0, 3.0])


@pytest.mark.parametrize(
    ("name", "time_s", "values"),
    [("q", np.zeros(3), np.zeros(4)), ("q", np.zeros((3, 2)), np.zeros((3, 2))), ("pitch", np.zeros(3), np.zeros(3))],
)
def test_signal_rejects_bad_shapes_and_names(name: str, time_s: np.ndarray, values: np.ndarray) -> None:
    with pytest.raises(ValueError):
        Signal(name=name, time_s=time_s, values=values, unit="rad/s", source="test")


def test_canonical_names() -> None:
    assert is_canonical("motor_8") and is_canonical("delta_thr")
    assert not is_canonical("motor_0") and not is_canonical("roll")


def test_flightlog_reports_missing_and_utc() -> None:
    signals = {name: _signal(name) for name in ("p", "q", "r", "motor_1")}
    log = FlightLog(
        path=Path("x.ulg"), log_format="ulog", autopilot="px4", signals=signals, utc_offset_s=1_700_000_000.0
    )
    assert "p" not in log.missing and "phi" in log.missing
    assert "motor_1..n" not in log.missing
    assert set(log.missing) == set(LOGGED_SIGNALS) - {"p", "q", "r"}
    assert log.utc_start == datetime.fromtimestamp(1_700_000_000.0, tz=UTC)
    assert log.duration_s == pytest.approx(1.0)


def test_flightlog_getitem_names_the_missing_signal() -> None:
    log = FlightLog(path=Path("flight.bin"), log_format="dataflash", autopilot="ardupilot", signals={"p": _signal("p")})
    with pytest.raises(MissingSignalError, match=r"flight.bin: no signal 'theta'"):
        log["theta"]
    assert log["p"].name == "p"


def test_flightlog_signals_are_immutable() -> None:
    log = FlightLog(path=Path("a.ulg"), log_format="ulog", autopilot="px4", signals={"p": _signal("p")})
    with pytest.raises(TypeError):
        log.signals["q"] = _signal("q")  # type: ignore[index]


def test_flightlog_keeps_system_id_runs_as_a_tuple() -> None:
    run = SystemIdRun(
        start_s=5.0,
        end_s=40.0,
        axis=7,
        axis_name="rate roll",
        magnitude=10.0,
        f_start_hz=0.5,
        f_stop_hz=20.0,
        fade_in_s=1.0,
        const_s=4.0,
        record_s=30.0,
        fade_out_s=0.5,
    )
    log = FlightLog(
        path=Path("sysid.bin"),
        log_format="dataflash",
        autopilot="ardupilot",
        signals={"p": _signal("p")},
        system_id_runs=[run],
    )
    assert log.system_id_runs == (run,)
    assert (
        FlightLog(path=Path("a.ulg"), log_format="ulog", autopilot="px4", signals={"p": _signal("p")}).system_id_runs
        == ()
    )
