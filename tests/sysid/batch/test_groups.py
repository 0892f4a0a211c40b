"""Grouping logs into fits: by vehicle and day from the logs' own metadata or the operator's mapping file."""

from __future__ import annotations

from pathlib import Path

import pytest

from flightlogs.errors import DataError
from flightlogs.readers.log_mapping import read_log_mapping
from sysid.batch import LogSurvey, group_logs, log_keys


def _survey(path: Path, board: str = "", utc: str | None = None, error: str | None = None) -> LogSurvey:
    return LogSurvey(path=str(path), sha256="0" * 64, board_id=board, utc_start=utc, error=error)


def test_without_a_mapping_the_board_id_and_the_utc_day_decide(tmp_path: Path) -> None:
    logs = [
        _survey(tmp_path / "a.bin", "fmuv5 00290019 32375118 32363435", "2024-06-03T09:00:00+00:00"),
        _survey(tmp_path / "b.bin", "fmuv5 00290019 32375118 32363435", "2024-06-03T15:30:00+00:00"),
        _survey(tmp_path / "c.bin", "fmuv5 00290019 32375118 32363435", "2024-06-04T09:00:00+00:00"),
        _survey(tmp_path / "d.ulg", "001d00313235510c32393433", None),
        _survey(tmp_path / "e.bin", error="e.bin: not a log"),
    ]
    groups = group_logs(logs, ["vehicle", "day"])
    assert [(g.key, len(g.logs)) for g in groups] == [
        ("001d00313235510c32393433 unknown", 1),
        ("fmuv5 00290019 32375118 32363435 2024-06-03", 2),
        ("fmuv5 00290019 32375118 32363435 2024-06-04", 1),
    ]
    assert groups[0].date is None and groups[1].date == "2024-06-03"  # an unknown day is not a date
    assert sorted(g.key for g in group_logs(logs, ["file"])) == ["a.bin", "b.bin", "c.bin", "d.ulg"]


def test_the_mapping_file_names_vehicles_and_adds_keys(tmp_path: Path) -> None:
    (tmp_path / "V1").mkdir()
    mapping_csv = tmp_path / "fleet.csv"
    mapping_csv.write_text("file,vehicle,date,payload_kg\nV1/a.bin,V1,2024-06-03,0.5\nb.bin,V2,,1.0\n")
    mapping = read_log_mapping(mapping_csv)
    a = _survey(tmp_path / "V1" / "a.bin", "board-a", "2024-07-01T00:00:00+00:00")
    b = _survey(tmp_path / "elsewhere" / "b.bin", "board-b", "2024-07-02T00:00:00+00:00")  # found by its name
    c = _survey(tmp_path / "c.bin", "board-c", "2024-07-03T00:00:00+00:00")  # not in the mapping
    assert log_keys(a, mapping) == {
        "vehicle": "V1",
        "date": "2024-06-03",
        "payload_kg": "0.5",
        "day": "2024-06-03",
        "file": "a.bin",
    }
    assert log_keys(b, mapping)["vehicle"] == "V2" and log_keys(b, mapping)["day"] == "2024-07-02"
    assert log_keys(c, mapping)["vehicle"] == "board-c"
    by_payload = group_logs([a, b, c], ["payload_kg"], mapping)
    assert sorted(g.key for g in by_payload) == ["0.5", "1.0", "unknown"]


def test_a_day_flown_by_two_vehicles_is_one_group_of_a_mixed_vehicle(tmp_path: Path) -> None:
    logs = [_survey(tmp_path / "a.bin", "X", "2024-06-03T09:00:00+00:00")]
    (group,) = group_logs([logs[0], _survey(tmp_path / "c.bin", "Y", "2024-06-03T10:00:00+00:00")], ["day"])
    assert group.vehicle == "mixed" and group.date == "2024-06-03" and len(group.logs) == 2


@pytest.mark.parametrize(
    ("content", "phrase"),
    [
        ("vehicle,date\nV1,2024-06-03\n", "line 1 must be a header with a 'file' column"),
        ("file,vehicle\n,V1\n", "line 2: no file named"),
        ("file,vehicle\na.bin,V1\n\na.bin,V2\n", "line 4: a.bin is named twice"),
    ],
)
def test_a_bad_mapping_file_is_one_sentence_with_its_line(tmp_path: Path, content: str, phrase: str) -> None:
    path = tmp_path / "map.csv"
    path.write_text(content)
    with pytest.raises(DataError, match=phrase) as err:
        read_log_mapping(path)
    assert str(path) in str(err.value)


def test_an_unknown_key_is_refused_before_any_fit(tmp_path: Path) -> None:
    logs = [_survey(tmp_path / "a.bin", "X", None)]
    with pytest.raises(
        DataError, match="cannot group by battery: a key is one of vehicle, day, file or given by a mapping"
    ):
        group_logs(logs, ["battery"])
    mapping_csv = tmp_path / "m.csv"
    mapping_csv.write_text("file,battery\na.bin,B7\n")
    assert group_logs(logs, ["battery"], read_log_mapping(mapping_csv))[0].key == "B7"
