"""CSV and Parquet tables read through a column map (issue 32, item 1).

Each layout a tool exports (comma, semicolon, tab or spaces; header or not;
times in s, ms or µs; units in the map or in the header) reads to the same
signals in SI units; each bad table is one sentence naming the file, the
column and the line or row.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from flightlogs.errors import DataError, DataQualityWarning, LogFormatError
from flightlogs.readers import ReadOptions, TableColumn, is_table, parse_table_map, read_log, read_table

T = np.round(np.arange(0.0, 4.0, 0.02), 6)  # 50 Hz, s
P_DEG_S = 30.0 * np.sin(2.0 * np.pi * 0.7 * T)
DELTA = 0.1 * np.cos(2.0 * np.pi * 0.7 * T)


def _write(path: Path, header: str | None, rows: list[str]) -> Path:
    path.write_text(("" if header is None else header + "\n") + "\n".join(rows) + "\n", encoding="utf-8")
    return path


def _rows(delimiter: str, time_scale: float) -> list[str]:
    return [f"{t * time_scale:.6f}{delimiter}{d:.9g}{delimiter}{p:.9g}" for t, d, p in zip(T, DELTA, P_DEG_S)]


@pytest.mark.parametrize(
    ("delimiter", "header", "time_scale", "text"),
    [
        (",", "time_ms,mixer_roll,roll_rate", 1e3, "time=time_ms,delta_lat=mixer_roll,p=roll_rate:deg/s"),
        (";", "t;mixer;p [deg/s]", 1.0, "time=t:s,delta_lat=mixer,p=p"),
        ("\t", "TimeUS\tmixer\tp", 1e6, "time=TimeUS,delta_lat=1,p=2:dps"),
        (" ", None, 1e3, "time=0:ms,delta_lat=1,p=2:deg/s"),
        ("|", None, 1.0, "time=0,delta_lat=1,p=2:°/s"),
    ],
)
def test_every_layout_reads_to_the_same_si_signals(
    tmp_path: Path, delimiter: str, header: str | None, time_scale: float, text: str
) -> None:
    path = _write(tmp_path / "sweep.csv", None if header is None else header, _rows(delimiter, time_scale))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataQualityWarning)  # the time unit found, not given: tested below
        log = read_log(path, reading=ReadOptions(table_map=parse_table_map(text)))
    assert (log.log_format, log.autopilot, sorted(log.signals)) == ("table", "unknown", ["delta_lat", "p"])
    np.testing.assert_allclose(log["p"].time_s, T, atol=1e-9)
    np.testing.assert_allclose(log["p"].values, np.radians(P_DEG_S), rtol=1e-8, atol=1e-12)
    np.testing.assert_allclose(log["delta_lat"].values, DELTA, rtol=1e-8)
    assert log["p"].unit == "rad/s" and log["delta_lat"].unit == "normalised"
    assert "deg/s → rad/s" in log["p"].source


def test_a_time_unit_found_from_the_interval_is_said(tmp_path: Path) -> None:
    path = _write(tmp_path / "t.csv", "t,p", [f"{t * 1e3:.3f},{p}" for t, p in zip(T, P_DEG_S)])
    with pytest.warns(DataQualityWarning, match="read in ms"):
        log = read_table(path, parse_table_map("time=t,p=p:deg/s"))
    np.testing.assert_allclose(log["p"].time_s, T, atol=1e-9)
    assert log.warnings == (
        "t.csv: time column 't' read in ms (its median interval is 20, 50 Hz in ms); give time=t:<unit> if it is not",
    )
    given = read_table(path, parse_table_map("time=t:ms,p=p:deg/s"))
    assert given.warnings == ()


def test_empty_cells_are_missing_samples_and_unix_time_gives_utc(tmp_path: Path) -> None:
    start = 1_714_557_600.0  # 2024-05-01 10:00 UTC
    rows = [
        f"{start + t:.3f},{'' if k % 5 == 0 else p},{'nan' if k % 2 else d}"
        for k, (t, p, d) in enumerate(zip(T, P_DEG_S, DELTA))
    ]
    path = _write(tmp_path / "mocap.csv", "# exported by a rig\nunix_s,p_dps,delta", rows)
    log = read_table(path, parse_table_map("time=unix_s:s,p=p_dps:deg/s,delta_lat=delta"))
    assert log.utc_offset_s == pytest.approx(start)
    assert log["p"].samples == T.size - len(range(0, T.size, 5)) and log["delta_lat"].samples == T.size // 2
    np.testing.assert_allclose(log["p"].time_s[:2], T[[1, 2]], atol=1e-6)


def test_parquet_with_a_timestamp_column_and_percent_throttle(tmp_path: Path) -> None:
    stamps = pa.array((1_714_557_600_000_000 + (T * 1e6).astype(np.int64)), pa.timestamp("us"))
    path = tmp_path / "flight.parquet"
    pq.write_table(pa.table({"stamp": stamps, "thr_pct": 50.0 + 10.0 * DELTA, "phi_deg": P_DEG_S}), path)
    log = read_log(
        path, reading=ReadOptions(table_map=parse_table_map("time=stamp,delta_thr=thr_pct:%,phi=phi_deg:deg"))
    )
    assert log.warnings == () and log.utc_offset_s == pytest.approx(1_714_557_600.0)
    np.testing.assert_allclose(log["phi"].values, np.radians(P_DEG_S), rtol=1e-12)
    np.testing.assert_allclose(log["delta_thr"].values, 0.5 + 0.1 * DELTA, rtol=1e-12)
    assert is_table(path)


def test_a_toml_map(tmp_path: Path) -> None:
    (tmp_path / "map.toml").write_text('[columns]\ntime = "t:ms"\np = "roll [deg/s]"\ndelta_lat = 1\n')
    table_map = parse_table_map(str(tmp_path / "map.toml"))
    assert table_map.columns == {
        "time": TableColumn("t", "ms"),
        "p": TableColumn("roll [deg/s]", None),
        "delta_lat": TableColumn(1, None),
    }
    path = _write(tmp_path / "x.csv", "t,mixer,roll [deg/s]", _rows(",", 1e3))
    np.testing.assert_allclose(read_table(path, table_map)["p"].values, np.radians(P_DEG_S), rtol=1e-8)


def test_a_table_without_a_map_is_told_what_it_needs(tmp_path: Path) -> None:
    path = _write(tmp_path / "x.csv", "t,p", _rows(",", 1.0))
    with pytest.raises(LogFormatError, match=r"x.csv: a table \(CSV or Parquet\), not a flight log; it is read with"):
        read_log(path)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("p=1", "column map: no time column (give time=<column>, e.g. time=0 or time=t:ms)"),
        ("time=0,p=2:furlong/s", "column map: p is in rad/s; unknown unit 'furlong/s' for it (known: rad/s, deg/s)"),
        ("time=0,p=2:deg", "column map: p is in rad/s; unknown unit 'deg' for it (known: rad/s, deg/s)"),
        ("time=0,roll=2", "column map: 'roll' is not a canonical signal name"),
        ("time=0,p", "column map: 'p' is not name=column (e.g. p=2 or p=roll_rate:deg/s)"),
        ("time=0:fortnights,p=1", "column map: time is in s; unknown unit 'fortnights'"),
    ],
)
def test_a_bad_map_is_one_sentence(text: str, message: str) -> None:
    with pytest.raises(DataError) as caught:
        parse_table_map(text)
    assert str(caught.value).startswith(message)


@pytest.mark.parametrize(
    ("content", "text", "error", "message"),
    [
        (
            "t,p\n0,1\n0.02,2\n0.01,3\n",
            "time=t,p=p",
            DataError,
            "bad.csv, line 4: time goes back in column 't' (0.01 after 0.02)",
        ),
        ("t,p\n0,1\n0.02,x\n", "time=t,p=p", DataError, "bad.csv, line 3: column 'p' is not a number ('x')"),
        ("t,p\n0,1\n0.02,2,5\n", "time=t,p=p", LogFormatError, "bad.csv, line 3: 3 fields where the first row has 2"),
        ("t,p\n0,1\n0.02,2\n", "time=t,p=q_rate", DataError, "bad.csv: no column 'q_rate' for p (columns: t, p)"),
        ("0,1\n0.02,2\n", "time=0,p=7", DataError, "bad.csv: no column 7 for p: the table has 2 (0-1)"),
        ("0,1\n0.02,2\n", "time=0,p=rate", DataError, "bad.csv: p names column 'rate' but the table has no header row"),
        ("t,p\n0,1\n,2\n", "time=t,p=p", DataError, "bad.csv, line 3: the time column 't' has no value"),
        (
            "t,p [furlong/s]\n0,1\n0.02,2\n",
            "time=t,p=p",
            DataError,
            "column map: p is in rad/s; unknown unit 'furlong/s'",
        ),
        ("t,p\n0,\n0.02,nan\n", "time=t:s,p=p", DataError, "bad.csv: column 'p' (p) has no value in any row"),
    ],
)
def test_a_bad_table_is_one_sentence_naming_the_column_and_line(
    tmp_path: Path, content: str, text: str, error: type[Exception], message: str
) -> None:
    path = tmp_path / "bad.csv"
    path.write_text(content)
    with pytest.raises(error) as caught:
        read_table(path, parse_table_map(text))
    assert message in str(caught.value) and "\n" not in str(caught.value)


def test_a_non_numeric_parquet_column_is_named(tmp_path: Path) -> None:
    path = tmp_path / "s.parquet"
    pq.write_table(pa.table({"t": T, "label": ["a"] * T.size}), path)
    with pytest.raises(DataError, match=r"s.parquet: column 'label' \(p\) holds string, not numbers"):
        read_table(path, parse_table_map("time=t,p=label"))


def test_units_convert_exactly() -> None:
    from flightlogs.readers._units import si_factor

    assert si_factor("deg", "rad") == math.pi / 180.0 and si_factor("g", "m/s^2") == 9.80665
    assert si_factor("km/h", "m/s") == pytest.approx(1 / 3.6) and si_factor("ft", "m") == 0.3048


def test_a_quoted_header_may_hold_the_delimiter(tmp_path: Path) -> None:
    rows = [f'{t:.2f},"{d:.6f}",{p:.4f}' for t, d, p in zip(T, DELTA, P_DEG_S)]
    path = _write(tmp_path / "quoted.csv", '"time, s","mixer, roll","roll rate, deg/s"', rows)
    log = read_table(path, parse_table_map(str(_toml(tmp_path))))
    np.testing.assert_allclose(log["p"].values, np.radians(P_DEG_S), rtol=1e-4)
    np.testing.assert_allclose(log["delta_lat"].values, DELTA, atol=1e-6)


def _toml(folder: Path) -> Path:
    """A map naming columns whose names hold commas: only a TOML map can."""
    path = folder / "quoted.toml"
    path.write_text('time = "time, s:s"\ndelta_lat = "mixer, roll"\np = "roll rate, deg/s:deg/s"\n')
    return path
