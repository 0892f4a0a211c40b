"""Atomic output: all or nothing, with the permissions an ordinary write would give."""

from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from flightlogs.writers.atomic import atomic_output


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


def _process_umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def test_a_new_file_is_readable_as_an_ordinary_write_would_be(tmp_path: Path) -> None:
    """The report a colleague opens must not stay 0o600 like the temporary file (mkstemp)."""
    plain = tmp_path / "plain.html"
    plain.write_text("x")
    target = tmp_path / "report.html"
    with atomic_output(target) as tmp:
        assert _mode(tmp) == 0o600
        tmp.write_text("done")
    assert _mode(target) == _mode(plain) == 0o666 & ~_process_umask()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plain.html", "report.html"]


def test_a_replaced_file_keeps_its_permissions(tmp_path: Path) -> None:
    target = tmp_path / "model.json"
    target.write_text("old")
    target.chmod(0o640)
    with atomic_output(target) as tmp:
        tmp.write_text("new")
    assert target.read_text() == "new"
    assert _mode(target) == 0o640


def test_a_failure_leaves_the_old_file_and_no_temporary(tmp_path: Path) -> None:
    target = tmp_path / "model.json"
    target.write_text("old")
    with pytest.raises(RuntimeError, match="boom"):
        with atomic_output(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("boom")
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["model.json"]


def test_a_missing_folder_is_a_data_error_naming_it(tmp_path: Path) -> None:
    from flightlogs.errors import DataError

    with pytest.raises(DataError, match="nodir: the output folder does not exist"):
        with atomic_output(tmp_path / "nodir" / "x.h5"):
            pass  # pragma: no cover - never entered
    assert list(tmp_path.iterdir()) == []


def test_a_file_in_place_of_the_folder_is_a_data_error(tmp_path: Path) -> None:
    from flightlogs.errors import DataError

    (tmp_path / "plain").write_text("x")
    with pytest.raises(DataError, match="plain: the output folder is a file"):
        with atomic_output(tmp_path / "plain" / "x.h5"):
            pass  # pragma: no cover - never entered
