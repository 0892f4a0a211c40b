"""Ground-effect rig CSV: layouts, units, and errors that name the file and line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flightlogs.errors import DataError, SysidError
from flightlogs.readers.rig import HEIGHT_UNITS, THRUST_UNITS, read_rig_csv

G0 = 9.80665  # standard gravity: grams and kilograms of force


def _write(tmp_path: Path, text: str, name: str = "rig.csv") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_default_layout_reads_si_values_and_line_numbers(tmp_path: Path) -> None:
    path = _write(tmp_path, "# rig run 3\nheight_m,thrust_n\n0.025,0.4412\n\n0.035,0.4254\n")
    rig = read_rig_csv(path)
    np.testing.assert_array_equal(rig.height_m, [0.025, 0.035])
    np.testing.assert_array_equal(rig.thrust_n, [0.4412, 0.4254])
    assert rig.lines.tolist() == [3, 5]
    assert (rig.height_source, rig.thrust_source) == ("height_m", "thrust_n")


@pytest.mark.parametrize(
    ("header", "height_scale", "thrust_scale"),
    [
        ("height_cm,thrust_g", 0.01, G0 / 1000),  # a digital scale reads grams (chapter 2's rig)
        ("Height (mm);Thrust [kg]", 0.001, G0),
        ("height_in\tthrust_mN", 0.0254, 0.001),
    ],
)
def test_units_come_from_the_column_suffix(
    tmp_path: Path, header: str, height_scale: float, thrust_scale: float
) -> None:
    delimiter = ";" if ";" in header else ("\t" if "\t" in header else ",")
    path = _write(tmp_path, f"{header}\n2.5{delimiter}45\n20{delimiter}39.1\n")
    rig = read_rig_csv(path)
    np.testing.assert_allclose(rig.height_m, np.array([2.5, 20.0]) * height_scale, rtol=1e-15)
    np.testing.assert_allclose(rig.thrust_n, np.array([45.0, 39.1]) * thrust_scale, rtol=1e-15)
    assert "→" in rig.height_source and "→" in rig.thrust_source


def test_columns_and_units_can_be_named(tmp_path: Path) -> None:
    path = _write(tmp_path, "time,Z,F,temp\n1,2.5,45,20\n2,3.5,44,20\n")
    rig = read_rig_csv(path, height_column="z", thrust_column="F", height_unit="cm", thrust_unit="g")
    np.testing.assert_allclose(rig.height_m, [0.025, 0.035])
    np.testing.assert_allclose(rig.thrust_n, np.array([45.0, 44.0]) * G0 / 1000)


@pytest.mark.parametrize(
    ("text", "kwargs", "message"),
    [
        ("height_m,thrust_n\n0.02,0.4\n0.03,abc\n", {}, r"rig\.csv, line 3: column 'thrust_n' is not a number"),
        ("height_m,thrust_n\n0.02,0.4\n-0.03,0.4\n", {}, r"line 3: column 'height_m' must be > 0"),
        ("height_m,thrust_n\n0.02,0.4\n0.03,0\n", {}, r"line 3: column 'thrust_n' must be > 0"),
        ("height_m,thrust_n\n0.02,\n", {}, r"line 2: column 'thrust_n' has no value"),
        ("h,f\n0.02,0.4\n", {}, r"line 1: no column 'height_m'; the header has 'h', 'f'"),
        ("Z,F\n0.02,0.4\n", {"height_column": "Z", "thrust_column": "F"}, r"cannot tell the unit of height column 'Z'"),
        ("height_m,thrust_n\n0.02,0.4\n", {"thrust_unit": "lbf"}, r"thrust unit 'lbf' is not one of"),
        ("height_m,thrust_n\n", {}, r"line 1: a header but no readings"),
        ("", {}, r"rig\.csv: the file is empty"),
        ("height_m thrust_n\n0.02 0.4\n", {}, r"line 1: no comma, semicolon or tab"),
        ("height_m,thrust_n\n0.02,0.4,7\n", {}, r"line 2: 3 fields but the header has 2"),
    ],
)
def test_bad_input_is_a_data_error_naming_file_and_line(
    tmp_path: Path, text: str, kwargs: dict[str, str], message: str
) -> None:
    path = _write(tmp_path, text)
    with pytest.raises(DataError, match=message):
        read_rig_csv(path, **kwargs)


def test_binary_and_missing_files_are_data_errors(tmp_path: Path) -> None:
    binary = tmp_path / "rig.csv"
    binary.write_bytes(b"\x00\x01\x02height")
    with pytest.raises(DataError, match="binary content"):
        read_rig_csv(binary)
    with pytest.raises(SysidError):
        read_rig_csv(tmp_path / "absent.csv")


@settings(max_examples=40, deadline=None)
@given(
    st.sampled_from(sorted(HEIGHT_UNITS)),
    st.sampled_from(sorted(THRUST_UNITS)),
    st.lists(st.tuples(st.floats(1e-3, 1e3), st.floats(1e-3, 1e3)), min_size=1, max_size=20),
)
def test_any_unit_round_trips_to_si(height_unit: str, thrust_unit: str, rows: list[tuple[float, float]]) -> None:
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "rig.csv"
        lines = [f"height_{height_unit},thrust_{thrust_unit}"] + [f"{h!r},{f!r}" for h, f in rows]
        path.write_text("\n".join(lines) + "\n")
        rig = read_rig_csv(path)
    heights, thrusts = np.array(rows).T
    np.testing.assert_allclose(rig.height_m, heights * HEIGHT_UNITS[height_unit], rtol=1e-15)
    np.testing.assert_allclose(rig.thrust_n, thrusts * THRUST_UNITS[thrust_unit], rtol=1e-15)
