"""Record: plain read-only arrays, inclusive time slices, a pandas view on demand, and pickling."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

from flightlogs.record import Record


def _record() -> Record:
    t = 10.0 + np.arange(101) * 0.01
    return Record(
        time_s=t,
        columns={"q": np.sin(t), "delta_lon": np.cos(t)},
        units={"q": "rad/s", "delta_lon": "%"},
        trim={"q": 0.1},
        source=Path("flight.ulg"),
        label="piece 1 of 1",
    )


def test_columns_are_read_only_and_trim_defaults_to_zero() -> None:
    record = _record()
    with pytest.raises(ValueError):
        record["q"][0] = 1.0
    assert dict(record.trim) == {"q": 0.1, "delta_lon": 0.0} and record.rate_hz == pytest.approx(100.0)
    np.testing.assert_allclose(record.absolute("q"), np.sin(record.time_s) + 0.1)


def test_between_keeps_both_bounds_and_samples_between_counts_them() -> None:
    record = _record()
    piece = record.between(10.2, 10.5)
    assert piece.time_s[0] == pytest.approx(10.2) and piece.time_s[-1] == pytest.approx(10.5)
    assert piece.time_s.size == record.samples_between(10.2, 10.5) == 31
    np.testing.assert_array_equal(piece["q"], record["q"][20:51])
    assert record.samples_between(11.5, 12.0) == 0


def test_a_piece_reads_the_records_memory_and_stays_read_only() -> None:
    record = _record()
    piece = record.between(10.2, 10.5)
    assert all(np.shares_memory(piece[name], record[name]) for name in record.signals)  # a view: nothing copied
    with pytest.raises(ValueError):
        piece["q"][0] = 1.0
    again = pickle.loads(pickle.dumps(piece))  # a view pickles as its own samples
    assert again["q"].size == 31 and not again["q"].flags.writeable
    np.testing.assert_array_equal(again["q"], record["q"][20:51])


def test_the_table_round_trips_through_from_table() -> None:
    record = _record()
    table = record.table
    assert table.index.name == "time_s" and table.attrs["units"] == dict(record.units)
    back = Record.from_table(table, units=record.units, trim=record.trim, source=record.source, label=record.label)
    for name in record.signals:
        np.testing.assert_array_equal(back[name], record[name])


def test_a_record_pickles_as_itself() -> None:
    record = _record()
    back = pickle.loads(pickle.dumps(record))
    assert (back.label, back.source, dict(back.units), dict(back.trim)) == (
        record.label,
        record.source,
        dict(record.units),
        dict(record.trim),
    )
    np.testing.assert_array_equal(back.time_s, record.time_s)
    np.testing.assert_array_equal(back["delta_lon"], record["delta_lon"])


def test_a_column_of_another_length_or_without_unit_is_refused() -> None:
    t = np.arange(10) * 0.1
    with pytest.raises(ValueError, match="shape"):
        Record(time_s=t, columns={"q": np.zeros(9)}, units={"q": "rad/s"}, trim={}, source=Path("a"))
    with pytest.raises(ValueError, match="no unit"):
        Record(time_s=t, columns={"q": np.zeros(10)}, units={}, trim={}, source=Path("a"))
