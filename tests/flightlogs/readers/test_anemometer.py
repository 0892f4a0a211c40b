"""Tests of flightlogs.readers.anemometer: layouts, time formats, units, bad input, round trip.

Reference values are analytic (meteorological convention: wind FROM the north
at 5 m/s moves the air south, wind_n = -5) or cross-implementation (pandas on
the real NMT file). Fixtures under tests/data/anemometer/ are hand-written.
"""

from __future__ import annotations

import contextlib
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from flightlogs.errors import DataError, DataQualityWarning, LogCorruptionWarning, LogFormatError
from flightlogs.readers.anemometer import SPEED_UNITS, WindMeasurement, read_anemometer_csv

DATA = Path(__file__).resolve().parents[2] / "data" / "anemometer"
T0 = datetime(2024, 5, 1, 10, 0, 0, tzinfo=UTC).timestamp()  # 1714557600
KNOT, KMH, MPH = 0.514444, 1 / 3.6, 0.44704

# (wind_n, wind_e) of 5 m/s FROM north, east, south, west: the air moves away from there
FROM_NESW = [(-5.0, 0.0), (0.0, -5.0), (5.0, 0.0), (0.0, 5.0)]


def _write(tmp_path: Path, text: str, name: str = "wind.csv") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


# --------------------------------------------------------------------------- layouts and formats


def test_iso_zulu_speed_and_direction_analytic():
    wind = read_anemometer_csv(DATA / "iso_utc_speed_dir.csv")
    assert wind.layout == "columns"
    assert dict(wind.columns) == {"time": "Timestamp", "speed": "Wind Speed (m/s)", "direction": "Wind Direction (deg)"}
    assert wind.unit == "m/s" and wind.warnings == ()
    np.testing.assert_allclose(wind.utc_s, T0 + np.array([0, 0.5, 1.0, 1.5, 2.0]), atol=1e-6)
    np.testing.assert_allclose(np.c_[wind.wind_n, wind.wind_e][:4], FROM_NESW, atol=1e-12)
    np.testing.assert_allclose(wind.direction_from_rad[:4], np.deg2rad([0, 90, 180, 270]))
    assert wind.direction_from_rad[4] == 0.0  # 360° is north
    assert wind.wind_d is None
    assert wind.rate_hz == pytest.approx(2.0) and wind.duration_s == pytest.approx(2.0)
    assert wind.utc_start == datetime(2024, 5, 1, 10, tzinfo=UTC)


def test_u_v_components_give_the_same_wind_as_speed_and_direction():
    polar = read_anemometer_csv(DATA / "iso_utc_speed_dir.csv")
    with pytest.warns(DataQualityWarning, match="column 'u' names no unit; m/s assumed"):  # once, not for v
        cartesian = read_anemometer_csv(DATA / "epoch_ms_uv.csv")  # epoch milliseconds
    assert cartesian.warnings == ("column 'u' names no unit; m/s assumed",)
    assert dict(cartesian.columns) == {"time": "timestamp", "u": "u", "v": "v"}
    np.testing.assert_allclose(cartesian.utc_s, polar.utc_s[:4], atol=1e-6)
    for name in ("wind_n", "wind_e", "speed_m_s", "direction_from_rad"):
        np.testing.assert_allclose(getattr(cartesian, name), getattr(polar, name)[:4], atol=1e-12, err_msg=name)


def test_naive_times_are_utc_unless_an_offset_is_given_and_knots_convert():
    wind = read_anemometer_csv(DATA / "iso_naive_knots.csv")
    np.testing.assert_allclose(wind.utc_s, T0 - 7 * 3600 + np.arange(3), atol=1e-6)
    local = read_anemometer_csv(DATA / "iso_naive_knots.csv", utc_offset_hours=-7)  # PDT
    np.testing.assert_allclose(local.utc_s, T0 + np.arange(3), atol=1e-6)
    assert wind.unit == "kn"
    np.testing.assert_allclose(wind.speed_m_s, [10 * KNOT, 10 * KNOT, 0], rtol=1e-6)
    np.testing.assert_allclose(wind.wind_n[0], -10 * KNOT, rtol=1e-6)


def test_zone_offsets_semicolons_decimal_comma_and_km_h():
    wind = read_anemometer_csv(DATA / "iso_offset_kmh_semicolon.csv", utc_offset_hours=5)
    np.testing.assert_allclose(wind.utc_s, T0 + np.arange(3), atol=1e-6)  # zone wins
    assert wind.unit == "km/h"
    np.testing.assert_allclose(wind.speed_m_s, [18 * KMH, 18 * KMH, 36 * KMH], rtol=1e-12)
    np.testing.assert_allclose(wind.speed_m_s[:2], 5.0)


def test_epoch_seconds_and_mph():
    wind = read_anemometer_csv(DATA / "epoch_mph.csv", utc_offset_hours=3)  # epoch is UTC
    np.testing.assert_allclose(wind.utc_s, T0 + np.array([0, 1.25, 2.5]))
    assert wind.unit == "mph"
    np.testing.assert_allclose(wind.speed_m_s, np.array([10, 10, 20]) * MPH, rtol=1e-12)
    np.testing.assert_allclose(wind.wind_n[2], 20 * MPH)  # from the south: towards north


def test_separate_date_and_time_columns_tab_delimited():
    wind = read_anemometer_csv(DATA / "date_time_tab.csv")
    assert wind.columns["date"] == "Date" and wind.columns["time"] == "Time"
    np.testing.assert_allclose(wind.utc_s, T0 + np.array([0, 0.2, 0.4]), atol=1e-6)
    np.testing.assert_allclose(wind.speed_m_s, 10 * KNOT, rtol=1e-6)


def test_vertical_component_is_stored_down_positive():
    wind = read_anemometer_csv(DATA / "uvw_sonic.csv")
    np.testing.assert_allclose(wind.wind_d, [-0.5, 0.5])
    np.testing.assert_allclose(wind.speed_m_s, [5.0, 5.0])
    from_deg = np.rad2deg(np.arctan2(3.0, 4.0))  # u=3, v=4 blows towards NNE: from SSW
    np.testing.assert_allclose(np.rad2deg(wind.direction_from_rad), [180 + from_deg, from_deg])


@pytest.mark.parametrize(
    ("header", "unit", "factor"),
    [
        ("speed_kn", "kn", KNOT),
        ("Speed (knots)", "kn", KNOT),
        ("WS[km/h]", "km/h", KMH),
        ("wind speed mph", "mph", MPH),
        ("ws_m/s", "m/s", 1.0),
        ("Speed [kt]", "kn", KNOT),
        ("wspd (kph)", "km/h", KMH),
        ("WS (ft/s)", "ft/s", 0.3048),
    ],
)
def test_speed_units_from_the_header(tmp_path, header, unit, factor):
    path = _write(tmp_path, f"time,{header},wd\n2024-05-01T10:00:00Z,10,0\n")
    wind = read_anemometer_csv(path)
    assert wind.unit == unit
    assert wind.speed_m_s[0] == pytest.approx(10 * factor, rel=1e-6)
    assert SPEED_UNITS[unit] == pytest.approx(factor, rel=1e-6)


def test_missing_unit_is_assumed_m_s_with_a_warning_or_taken_from_speed_unit(tmp_path):
    path = _write(tmp_path, "time,ws,wd\n2024-05-01T10:00:00Z,10,0\n")
    with pytest.warns(DataQualityWarning, match="column 'ws' names no unit; m/s assumed"):
        assert "m/s assumed" in read_anemometer_csv(path).warnings[0]
    wind = read_anemometer_csv(path, speed_unit="knots")
    assert wind.unit == "kn" and wind.warnings == ()
    assert wind.speed_m_s[0] == pytest.approx(10 * KNOT, rel=1e-6)
    with pytest.raises(ValueError, match="furlongs"):
        read_anemometer_csv(path, speed_unit="furlongs/fortnight")


def test_explicit_columns_override_detection(tmp_path):
    path = _write(tmp_path, "clock,a,b,ws,wd\n1714557600,3,0,1,1\n1714557601,4,90,1,1\n")
    with pytest.warns(DataQualityWarning, match="column 'a' names no unit"):
        wind = read_anemometer_csv(path, columns={"time": "clock", "speed": "a", "direction": "B"})
    assert dict(wind.columns) == {"time": "clock", "speed": "a", "direction": "b"}
    np.testing.assert_allclose(wind.speed_m_s, [3, 4])
    with pytest.raises(ValueError, match="unknown keys"):
        read_anemometer_csv(path, columns={"speeed": "a"})
    with pytest.raises(LogFormatError, match=r"no column 'gust'.*'clock'"):
        read_anemometer_csv(path, columns={"speed": "gust"})


def test_speed_and_direction_preferred_to_u_and_v(tmp_path):
    path = _write(tmp_path, "time,ws,wd,u,v\n1714557600,5,0,9,9\n")
    with pytest.warns(DataQualityWarning, match="column 'ws' names no unit"):
        assert set(read_anemometer_csv(path).columns) == {"time", "speed", "direction"}
    with pytest.warns(DataQualityWarning, match="column 'u' names no unit"):
        wind = read_anemometer_csv(path, columns={"u": "u", "v": "v"})
    assert set(wind.columns) == {"time", "u", "v"} and wind.wind_n[0] == 9


def test_responseone_92000_layout():
    with (
        pytest.warns(DataQualityWarning, match="with a non-zero status code|m/s assumed"),
        pytest.warns(LogCorruptionWarning, match="1 ResponseONE lines failing the checksum") as raised,
    ):
        wind = read_anemometer_csv(DATA / "responseone_92000.csv")
    assert [str(w.message) for w in raised] == list(wind.warnings)
    assert wind.layout == "responseone" and wind.columns["time"] == "logger_time_utc"
    np.testing.assert_allclose(wind.utc_s, T0 + np.array([0, 0.25, 0.5, 0.75, 1.0]), atol=1e-6)
    np.testing.assert_allclose(np.c_[wind.wind_n, wind.wind_e][:4], FROM_NESW, atol=1e-12)
    assert wind.speed_m_s[4] == 7.25
    assert wind.direction_from_rad[4] == pytest.approx(np.deg2rad(315.5))
    text = " | ".join(wind.warnings)
    assert "1 ResponseONE lines failing the checksum (first: line 4)" in text
    assert "1 ResponseONE lines with a non-zero status code (first: line 8)" in text
    assert "m/s assumed" in text


def test_responseone_91000_without_header_with_speed_unit():
    wind = read_anemometer_csv(DATA / "responseone_91000.csv", speed_unit="kn")
    assert wind.layout == "responseone" and wind.unit == "kn" and wind.warnings == ()
    np.testing.assert_allclose(wind.utc_s, T0 + np.arange(3))
    np.testing.assert_allclose(wind.speed_m_s, np.array([3.2, 3.4, 0]) * KNOT, rtol=1e-6)
    np.testing.assert_allclose(np.rad2deg(wind.direction_from_rad[:2]), [200.0, 210.5])


def test_result_is_immutable_and_checked():
    wind = read_anemometer_csv(DATA / "epoch_mph.csv")
    with pytest.raises(ValueError):
        wind.wind_n[0] = 1.0
    with pytest.raises(ValueError, match="shape"):
        WindMeasurement(
            path=Path("x"),
            utc_s=np.zeros(3),
            wind_n=np.zeros(2),
            wind_e=np.zeros(3),
            speed_m_s=np.zeros(3),
            direction_from_rad=np.zeros(3),
        )


# --------------------------------------------------------------------------- the real file

REAL_COLUMNS = {"time": "Timestamp_UTC", "u": "Um", "v": "Vm", "w": "Wm"}


@pytest.fixture(scope="module")
def nmt_csv(real_data) -> Path:
    return real_data / "nmt-uas-wind" / "level0.csv"


def test_real_nmt_file_is_refused_by_auto_detection_with_the_columns_listed(nmt_csv):
    # S/Um/Vm/MD are sensor-frame readings of an anemometer on a moving UAV (MD is the
    # compass heading, not a wind direction): no synonym matches, and guessing would be wrong.
    with pytest.raises(LogFormatError) as info:
        read_anemometer_csv(nmt_csv)
    message = str(info.value)
    assert "level0.csv" in message and "no wind columns recognised" in message
    for column in ("'Timestamp_UTC'", "'S'", "'Um'", "'Vm'", "'MD'"):
        assert column in message


@pytest.mark.filterwarnings("ignore::flightlogs.errors.DataQualityWarning")  # the NMT columns name no unit
def test_real_nmt_file_with_explicit_columns_matches_pandas(nmt_csv):
    wind = read_anemometer_csv(nmt_csv, columns=REAL_COLUMNS)
    frame = pd.read_csv(nmt_csv)
    epoch = pd.Timestamp("1970-01-01", tz="UTC")
    utc_s = pd.to_datetime(frame["Timestamp_UTC"], format="ISO8601", utc=True) - epoch
    assert wind.n_samples == len(frame) == 7303
    np.testing.assert_allclose(wind.utc_s, utc_s.dt.total_seconds().to_numpy(), rtol=0, atol=1e-6)
    np.testing.assert_array_equal(wind.wind_e, frame["Um"].to_numpy())
    np.testing.assert_array_equal(wind.wind_n, frame["Vm"].to_numpy())
    np.testing.assert_array_equal(wind.wind_d, -frame["Wm"].to_numpy())
    np.testing.assert_allclose(wind.speed_m_s, np.hypot(frame["Um"], frame["Vm"]))
    assert wind.rate_hz == pytest.approx(5.0, rel=1e-3)
    assert wind.duration_s == pytest.approx(1460.39, abs=0.01)
    # the local-time column (-07:00) gives the same instants
    local = read_anemometer_csv(nmt_csv, columns={**REAL_COLUMNS, "time": "Timestamp"})
    np.testing.assert_allclose(local.utc_s, wind.utc_s, rtol=0, atol=1e-6)


# --------------------------------------------------------------------------- bad input

GOOD = "2024-05-01T10:00:00Z,1,10\n"
BAD_CASES = [
    # (file text, error class, fragments the message must contain)
    ("time,temp,rh\n2024-05-01T10:00:00Z,20,50\n", LogFormatError, ["no wind columns", "'temp'", "'rh'"]),
    ("temp,ws,wd\n20,1,10\n", LogFormatError, ["no time column", "'temp'"]),
    ("time,ws,wd\n" + GOOD + "yesterday,1,10\n", LogFormatError, ["line 3", "'yesterday'"]),
    ("time,ws,wd\n" + GOOD + "2024-13-01T10:00:00Z,1,10\n", LogFormatError, ["line 3"]),
    ("time,ws,wd\n10:00:00,1,10\n", LogFormatError, ["line 2", "add a date column"]),
    ("time,ws,wd\n0.0,1,10\n0.2,1,10\n", LogFormatError, ["line 2", "nor UNIX time"]),
    ("time,ws,wd\n1714557600,1,10\n2024-05-01T10:00:01Z,1,10\n", LogFormatError, ["line 3", "not UNIX time in s"]),
    ("time,ws,wd\n" + GOOD + "2024-05-01T09:59:59Z,1,10\n", DataError, ["line 3", "goes backwards", "line 2"]),
    ("time,ws,wd\n" + GOOD + "2024-05-01T10:00:00Z,1,10\n", DataError, ["line 3", "repeats"]),
    ("time,ws,wd\n" + GOOD + "2024-05-01T10:00:01Z,nan,10\n", DataError, ["line 3", "'ws'"]),
    ("time,ws,wd\n" + GOOD + "2024-05-01T10:00:01Z,1,\n", DataError, ["line 3", "'wd'"]),
    ("time,ws,wd\n" + GOOD + ",1,10\n", DataError, ["line 3", "'time'", "empty"]),
    ("time,ws,wd\n" + GOOD + "2024-05-01T10:00:01Z,calm,10\n", DataError, ["line 3", "not a number"]),
    ("# station 7\ntime,ws,wd\n\n" + GOOD + "2024-05-01T10:00:01Z,-0.5,10\n", DataError, ["line 5", "negative"]),
    ("time,ws,wd\n" + GOOD + "2024-05-01T10:00:01Z,1,361\n", DataError, ["line 3", "361", "0-360"]),
    ("time,ws,wd\n" + GOOD + "2024-05-01T10:00:01Z,1,-5\n", DataError, ["line 3", "-5"]),
    ("time,ws,wd\n" + GOOD + "2024-05-01T10:00:01Z,1,10,7\n", LogFormatError, ["line 3", "4 fields", "header has 3"]),
    ("time,WS,ws,wd\n" + GOOD, LogFormatError, ["'WS'", "'ws'"]),
    ("time,ws (volts),wd\n" + GOOD, LogFormatError, ["'volts'", "not a speed unit"]),
    ("time,ws,wd\n", LogFormatError, ["no data rows"]),
    ("", LogFormatError, ["empty"]),
    ("\n  \n", LogFormatError, ["empty"]),
    ("just some words\nno delimiters here\n", LogFormatError, ["line 1", "not a CSV"]),
    (
        "t,r1\n2024-05-01T10:00:00Z,0 1.00 10.0 00*13\n2024-05-01T10:00:01Z,0 1.00\n",
        LogFormatError,
        ["line 3", "ResponseONE"],
    ),
    ("0 1.00 10.0 00*13\n", LogFormatError, ["no clock"]),
]


BAD_IDS = [
    "no-wind-columns",
    "no-time-column",
    "unparseable-time",
    "impossible-date",
    "time-of-day-only",
    "relative-seconds",
    "epoch-then-iso",
    "time-backwards",
    "time-repeats",
    "nan-speed",
    "empty-direction",
    "empty-time",
    "text-speed",
    "negative-speed-after-comment",
    "direction-361",
    "direction-negative",
    "extra-field",
    "ambiguous-columns",
    "not-a-speed-unit",
    "header-only",
    "empty-file",
    "blank-file",
    "no-delimiter",
    "bad-responseone-line",
    "responseone-without-time",
]


@pytest.mark.parametrize(("text", "error", "fragments"), BAD_CASES, ids=BAD_IDS)
def test_bad_input_names_the_file_and_the_line(tmp_path, text, error, fragments):
    path = _write(tmp_path, text, "bad wind.csv")
    with pytest.raises(error) as info:
        read_anemometer_csv(path)
    message = str(info.value)
    assert "bad wind.csv" in message
    for fragment in fragments:
        assert fragment in message, message


def test_binary_file_is_not_a_csv(tmp_path):
    path = tmp_path / "wind.csv"
    path.write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR" + bytes(range(256)))
    with pytest.raises(LogFormatError, match="not a CSV"):
        read_anemometer_csv(path)


def test_responseone_with_every_line_rejected(tmp_path):
    path = _write(tmp_path, "2024-05-01T10:00:00Z,0 1.00 10.0 00*00\n")
    with pytest.raises(DataError, match="1 failed the checksum"):
        read_anemometer_csv(path)


# --------------------------------------------------------------------------- round trip

speeds = st.floats(0.0, 80.0, allow_nan=False)
directions = st.floats(0.0, 360.0, allow_nan=False, exclude_max=True)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    rows=st.lists(st.tuples(speeds, directions), min_size=1, max_size=30),
    unit=st.sampled_from(["m/s", "kn", "km/h", "mph"]),
    start=st.floats(1e9, 2e9),
)
def test_round_trip_speed_direction_and_components(tmp_path, rows, unit, start):
    speed, direction = np.array(rows).T
    times = start + 0.2 * np.arange(len(rows))
    stamps = [datetime.fromtimestamp(t, tz=UTC).isoformat() for t in times]
    header = {"m/s": "ws (m/s)", "kn": "speed_kn", "km/h": "WS[km/h]", "mph": "Speed (mph)"}[unit]
    lines = [f"{s},{v!r},{d!r}" for s, v, d in zip(stamps, speed.tolist(), direction.tolist())]
    polar = read_anemometer_csv(_write(tmp_path, f"utc,{header},wd\n" + "\n".join(lines)))
    factor = SPEED_UNITS[unit]
    np.testing.assert_allclose(polar.utc_s, np.round(times, 6), rtol=0, atol=2e-6)
    np.testing.assert_allclose(polar.speed_m_s, speed * factor, rtol=1e-12)
    np.testing.assert_allclose(polar.direction_from_rad, np.deg2rad(direction), atol=1e-12)
    u, v = -speed * np.sin(np.deg2rad(direction)), -speed * np.cos(np.deg2rad(direction))
    lines = [f"{t!r},{a!r},{b!r}" for t, a, b in zip(times.tolist(), u.tolist(), v.tolist())]
    header = {"m/s": "u,v", "kn": "u_kn,v_kn", "km/h": "u[km/h],v[km/h]", "mph": "u mph,v mph"}[unit]
    uv_text = f"epoch,{header}\n" + "\n".join(lines)
    without_unit = unit == "m/s"
    with (
        pytest.warns(DataQualityWarning, match="column 'u' names no unit") if without_unit else contextlib.nullcontext()
    ):
        cartesian = read_anemometer_csv(_write(tmp_path, uv_text, "uv.csv"))
    np.testing.assert_allclose(cartesian.utc_s, times, rtol=0, atol=1e-6)
    for name in ("wind_n", "wind_e", "speed_m_s"):
        np.testing.assert_allclose(getattr(cartesian, name), getattr(polar, name), rtol=1e-9, atol=1e-9, err_msg=name)
    moving = polar.speed_m_s > 1e-6
    turn = np.angle(np.exp(1j * (cartesian.direction_from_rad - polar.direction_from_rad)))
    np.testing.assert_allclose(turn[moving], 0.0, atol=1e-6)


@pytest.mark.parametrize(
    "texts",
    [
        ["2024-05-01T10:00:01.500Z", "2024-05-01T10:00:01.55Z", "2024-05-01T10:00:02Z"],
        ["2024-05-01 10:00:01.123456789", "2024-05-01 10:00:01.2", "2024-05-01 10:00:59"],
        ["1969-12-31T23:59:58.25Z", "1969-12-31T23:59:59.75Z"],
    ],
)
def test_iso_times_parsed_at_once_equal_the_row_by_row_parse(texts: list[str]) -> None:
    from flightlogs.readers._anemometer_text import _iso_at_once, _iso_to_unix

    at_once = _iso_at_once(texts, 7200.0)
    assert at_once is not None
    np.testing.assert_array_equal(at_once, [_iso_to_unix(text, 7200.0) for text in texts])


@pytest.mark.parametrize(
    "texts", [["2024-05-01"], ["10:00:01"], ["2024-05-01T10:00:01+02:00"], ["2024-05-01T10:00:01,5"], ["NaT"]]
)
def test_texts_numpy_would_misread_go_row_by_row(texts: list[str]) -> None:
    from flightlogs.readers._anemometer_text import _iso_at_once

    assert _iso_at_once(texts, 0.0) is None


# --------------------------------------------------------------------------- rows without quotes

_ROW_TEXTS = [
    "utc,speed\n2024-05-01T10:00:00Z,1.0\n",
    "utc,speed\r\n\r\n# note\r\n2024-05-01T10:00:00Z , 1.0\r\n,,\r\n  # indented comment\n2024-05-01T10:00:01Z,2.0,\n",
    "date\ttime\tspeed\n2024-05-01\t10:00:00\t1\n\n\n2024-05-01\t10:00:01\t 2 \n",
    "t;v\n1714557600;1,5\n 1714557601 ;\n",
]


def _csv_rows(path: Path) -> tuple[list[list[str]], list[int]]:
    """Rows as the csv module splits them (the path :func:`load_rows` takes for quoted text)."""
    import csv
    import io

    text = path.read_bytes().decode("utf-8-sig")
    first = next(line for line in text.splitlines() if line.strip() and not line.lstrip().startswith("#"))
    reader = csv.reader(io.StringIO(text), delimiter=max(",;\t", key=first.count), skipinitialspace=True)
    rows, numbers = [], []
    for row in reader:
        if row and "".join(row).strip() and not row[0].lstrip().startswith("#"):
            rows.append([cell.strip() for cell in row])
            numbers.append(reader.line_num)
    return rows, numbers


@pytest.mark.parametrize("text", _ROW_TEXTS)
def test_text_without_quotes_is_split_into_the_csv_modules_rows_and_lines(tmp_path, text):
    from flightlogs.readers._anemometer_text import load_rows

    path = tmp_path / "wind.csv"
    path.write_bytes(text.encode())
    assert load_rows(path) == _csv_rows(path)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    cells=st.lists(
        st.lists(st.sampled_from(["", " ", "1.5", "a b", "#x", " 2 ", "-", "10:00"]), min_size=1, max_size=4),
        min_size=1,
        max_size=8,
    ),
    ending=st.sampled_from(["\n", "\r\n"]),
    delimiter=st.sampled_from([",", ";", "\t"]),
)
def test_any_unquoted_table_splits_as_the_csv_module_splits_it(tmp_path, cells, ending, delimiter):
    from flightlogs.readers._anemometer_text import load_rows

    path = tmp_path / "wind.csv"
    header = delimiter.join(["utc", "speed", "direction"])
    path.write_bytes((ending.join([header, *(delimiter.join(row) for row in cells)]) + ending).encode())
    assert load_rows(path) == _csv_rows(path)


def test_every_layout_of_the_test_data_reads_as_before():
    """The files of tests/data/anemometer (quoted or not) give the csv module's rows."""
    from flightlogs.readers._anemometer_text import load_rows

    for path in sorted(DATA.glob("*.csv")):
        assert load_rows(path) == _csv_rows(path), path.name
