"""Anemometer CSV column hints read as the command-line option ``--columns KEY=COL``, not as Python."""

from __future__ import annotations

from pathlib import Path

import pytest

from flightlogs.errors import LogFormatError
from flightlogs.readers.anemometer import read_anemometer_csv

_ROWS = "2024-05-01T10:00:00.000Z,2.3,1.0,90\n2024-05-01T10:00:00.050Z,2.4,1.1,91\n"


@pytest.mark.parametrize(
    ("header", "hint"),
    [
        ("utc,speed_m_s,temp,rh", "name them in `columns` (speed=COL,direction=COL or u=COL,v=COL)"),
        ("when,speed,direction,rh", "name it in `columns` (time=COL)"),
        ("time,speed [m/s],speed [km/h],direction", "name one in `columns` (speed=COL)"),
    ],
)
def test_a_missing_or_ambiguous_column_names_the_file_and_the_columns_argument(
    tmp_path: Path, header: str, hint: str
) -> None:
    path = tmp_path / "w_missingcol.csv"
    path.write_text(header + "\n" + _ROWS)
    with pytest.raises(LogFormatError) as info:
        read_anemometer_csv(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and hint in message, message
    assert "columns={" not in message and "..." not in message
