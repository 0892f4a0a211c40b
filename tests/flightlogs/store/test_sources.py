"""Sources given to a command (:mod:`flightlogs.store.sources`): datasets or logs, never both, each read its way."""

from __future__ import annotations

from pathlib import Path

import pytest

from flightlogs.errors import DataError
from flightlogs.store.sources import conditioned_sources, is_dataset


def test_a_dataset_is_told_by_its_suffix_whatever_its_case() -> None:
    assert [is_dataset(p) for p in ("a.h5", "B.HDF5", "c.ulg", "d.bin", "h5")] == [True, True, False, False, False]


def test_datasets_and_logs_together_are_refused_before_anything_is_read(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="either datasets .* or logs, not both"):
        conditioned_sources([tmp_path / "absent.h5", tmp_path / "absent.ulg"])


def test_wind_files_with_a_dataset_are_refused_naming_the_field(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="`wind_paths` go with logs"):
        conditioned_sources([tmp_path / "absent.h5"], [tmp_path / "wind.csv"])
