"""HDF5 dataset store: round trip, provenance, atomic writes, bad files."""

from __future__ import annotations

import dataclasses
import hashlib
from pathlib import Path

import h5py
import numpy as np
import pytest

from flightlogs.errors import LogFormatError
from flightlogs.flightlog import FlightLog, Signal
from flightlogs.store.dataset import SCHEMA_VERSION, read_dataset, write_dataset


def _log(path: Path) -> FlightLog:
    rng = np.random.default_rng(7)
    t = np.cumsum(rng.uniform(0.004, 0.006, 500))
    signals = {
        "q": Signal(
            name="q", time_s=t, values=rng.normal(size=500), unit="rad/s", source="vehicle_angular_velocity[0].xyz[1]"
        ),
        "motor_1": Signal(
            name="motor_1", time_s=t[::2], values=rng.uniform(1000, 2000, 250), unit="us", source="RCOU.C1"
        ),
    }
    return FlightLog(
        path=path,
        log_format="ulog",
        autopilot="px4",
        signals=signals,
        vehicle="quad ∅ <x>",
        parameters={"MPC_THR_HOVER": 0.42, "SYS_AUTOSTART": 4001.0},
        utc_offset_s=1.6e9 + 0.125,
        warnings=("pyulog: 3 dropouts",),
    )


def test_round_trip_keeps_every_value(tmp_path: Path) -> None:
    source = tmp_path / "flight.ulg"
    source.write_bytes(b"raw bytes")
    log = dataclasses.replace(_log(source), board_id="fmuv5 00290019 32375118 32363435")
    out = tmp_path / "set.h5"
    write_dataset(out, [log, log])
    dataset = read_dataset(out)
    assert dataset.schema_version == SCHEMA_VERSION
    assert len(dataset.logs) == 2
    back = dataset.logs[0]
    assert (back.path, back.log_format, back.autopilot, back.vehicle) == (source, "ulog", "px4", "quad ∅ <x>")
    assert back.board_id == "fmuv5 00290019 32375118 32363435"
    assert back.utc_offset_s == log.utc_offset_s
    assert dict(back.parameters) == dict(log.parameters)
    assert back.warnings == log.warnings
    for name, signal in log.signals.items():
        np.testing.assert_array_equal(back[name].time_s, signal.time_s)
        np.testing.assert_array_equal(back[name].values, signal.values)
        assert (back[name].unit, back[name].source) == (signal.unit, signal.source)
    assert dataset.sha256[str(source)] == hashlib.sha256(b"raw bytes").hexdigest()
    with h5py.File(out, "r+") as h5:
        assert sorted(h5["logs"]) == ["flight", "flight_2"]
        del h5["logs/flight"].attrs["board_id"]  # as a file written before board ids were kept
    assert read_dataset(out).logs[0].board_id == ""


def test_values_a_log_held_in_float32_are_stored_and_held_in_float32_and_given_in_float64(tmp_path: Path) -> None:
    log = _log(tmp_path / "flight.ulg")
    single = np.float32(np.random.default_rng(3).normal(size=250)).astype(np.float64)  # float32 values, in float64
    signals = dict(log.signals) | {
        "p": Signal(name="p", time_s=log["motor_1"].time_s, values=single, unit="rad/s", source="x")
    }
    out = tmp_path / "set.h5"
    write_dataset(out, [dataclasses.replace(log, signals=signals)])
    with h5py.File(out) as h5:
        stored = {name: h5[f"logs/flight/signals/{name}/values"].dtype for name in ("p", "q", "motor_1")}
    assert stored == {"p": np.float32, "q": np.float64, "motor_1": np.float64}  # q and motor_1 need float64
    back = read_dataset(out).logs[0]
    assert back["p"].stored_values.dtype == np.float32 and back["q"].stored_values.dtype == np.float64
    for name, signal in signals.items():
        assert back[name].values.dtype == np.float64
        np.testing.assert_array_equal(back[name].values, signal.values)


def test_unknown_utc_round_trips_as_none(tmp_path: Path) -> None:
    log = FlightLog(path=tmp_path / "a.bin", log_format="dataflash", autopilot="ardupilot", signals={})
    write_dataset(tmp_path / "a.h5", [log])
    assert read_dataset(tmp_path / "a.h5").logs[0].utc_offset_s is None


def test_a_failed_write_leaves_the_old_file(tmp_path: Path) -> None:
    out = tmp_path / "set.h5"
    write_dataset(out, [_log(tmp_path / "good.ulg")])
    before = out.read_bytes()

    class Broken:
        path = tmp_path / "wind.csv"

    with pytest.raises(TypeError):
        write_dataset(out, [_log(tmp_path / "other.ulg")], [Broken()])
    assert out.read_bytes() == before
    assert [p.name for p in tmp_path.iterdir() if p.name.endswith(".part")] == []


@pytest.mark.parametrize("content", [b"", b"not hdf5 at all"])
def test_non_hdf5_is_a_log_format_error(tmp_path: Path, content: bytes) -> None:
    path = tmp_path / "x.h5"
    path.write_bytes(content)
    with pytest.raises(LogFormatError, match="not an HDF5 dataset"):
        read_dataset(path)


def test_foreign_hdf5_and_newer_schema_are_refused(tmp_path: Path) -> None:
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as h5:
        h5["x"] = 1
    with pytest.raises(LogFormatError, match="not a flight-sysid dataset"):
        read_dataset(foreign)
    newer = tmp_path / "newer.h5"
    write_dataset(newer, [])
    with h5py.File(newer, "a") as h5:
        h5.attrs["schema_version"] = SCHEMA_VERSION + 1
    with pytest.raises(LogFormatError, match="newer than this software"):
        read_dataset(newer)


def test_wind_measurements_round_trip(tmp_path: Path) -> None:
    from flightlogs.readers.anemometer import read_anemometer_csv

    csv = Path(__file__).resolve().parents[2] / "data" / "anemometer" / "iso_utc_speed_dir.csv"
    wind = read_anemometer_csv(csv)
    out = tmp_path / "w.h5"
    write_dataset(out, [], [wind])
    back = read_dataset(out).winds[0]
    for name in ("utc_s", "wind_n", "wind_e", "speed_m_s", "direction_from_rad"):
        np.testing.assert_array_equal(getattr(back, name), getattr(wind, name))
    assert (back.path, dict(back.columns), back.unit, back.layout, back.warnings) == (
        wind.path,
        dict(wind.columns),
        wind.unit,
        wind.layout,
        wind.warnings,
    )
    assert read_dataset(out).sha256[str(csv)] == hashlib.sha256(csv.read_bytes()).hexdigest()


def test_system_id_runs_round_trip(tmp_path: Path) -> None:
    from flightlogs.flightlog import SystemIdRun

    runs = (
        SystemIdRun(
            start_s=25.0,
            end_s=59.99,
            axis=11,
            axis_name="mixer pitch",
            magnitude=0.08,
            f_start_hz=0.1,
            f_stop_hz=10.0,
            fade_in_s=5.0,
            const_s=0.0,
            record_s=34.0,
            fade_out_s=1.0,
        ),
        SystemIdRun(
            start_s=75.0,
            end_s=float("nan"),
            axis=10,
            axis_name="mixer roll",
            magnitude=0.08,
            f_start_hz=0.1,
            f_stop_hz=10.0,
            fade_in_s=5.0,
            const_s=0.0,
            record_s=34.0,
            fade_out_s=1.0,
        ),
    )
    log = FlightLog(
        path=tmp_path / "sid.bin", log_format="dataflash", autopilot="ardupilot", signals={}, system_id_runs=runs
    )
    write_dataset(tmp_path / "sid.h5", [log])
    back = read_dataset(tmp_path / "sid.h5").logs[0].system_id_runs
    assert back[0] == runs[0]
    assert back[1].axis_name == "mixer roll" and np.isnan(back[1].end_s)


def _every_dataset(out: Path) -> None:
    """Write a dataset with every kind of text one holds: a log with a SIDS run, a wind measurement, a conditioned
    flight (its segments and records) of a simulated hover."""
    import warnings
    from datetime import UTC, datetime

    from flightlogs.flightlog import SystemIdRun
    from flightlogs.readers.anemometer import read_anemometer_csv
    from flightlogs.store.campaign import ingest_campaign
    from simulator.autopilot.excitation import Maneuver
    from simulator.flights.linear import simulate_hover
    from simulator.output.px4 import write_px4_log

    run = SystemIdRun(
        start_s=25.0, end_s=59.99, axis=11, axis_name="mixer pitch", magnitude=0.08, f_start_hz=0.1,
        f_stop_hz=10.0, fade_in_s=5.0, const_s=0.0, record_s=34.0, fade_out_s=1.0,
    )  # fmt: skip
    log = dataclasses.replace(_log(out.parent / "flight.ulg"), system_id_runs=(run,))
    wind = read_anemometer_csv(Path(__file__).resolve().parents[2] / "data" / "anemometer" / "iso_utc_speed_dir.csv")
    doublet = Maneuver(axis="lon", kind="doublet", start_s=8.0, amplitude=8.0, duration_s=2.0)
    flight = simulate_hover(16.0, (doublet,), rate_hz=25.0, substeps=2, seed=3)
    hover = write_px4_log(flight, out.parent / "hover.ulg", utc_start=datetime(2025, 5, 1, 10, tzinfo=UTC))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        campaign = ingest_campaign([hover], [])
    write_dataset(out, [log, *campaign.logs], [wind], list(campaign.flights))


def _texts(h5: h5py.File) -> list[np.dtype]:
    """The dtype of every attribute and dataset in `h5` (compound ones by their fields)."""
    dtypes: list[np.dtype] = []

    def visit(_: str, item: h5py.Group | h5py.Dataset) -> None:
        dtypes.extend(item.attrs.get_id(name).dtype for name in item.attrs)
        if isinstance(item, h5py.Dataset):
            dtypes.extend([item.dtype] if item.dtype.names is None else [item.dtype[n] for n in item.dtype.names])

    dtypes.extend(h5.attrs.get_id(name).dtype for name in h5.attrs)
    h5.visititems(visit)
    return dtypes


def test_a_dataset_has_no_variable_length_text_and_checksummed_structure(tmp_path: Path) -> None:
    """Variable-length text lives in HDF5's global heap, which has no checksum and whose damage can hang libhdf5
    (found by fuzzing); the 1.10 format checksums the superblock and every object header."""
    out = tmp_path / "set.h5"
    _every_dataset(out)
    data = out.read_bytes()
    assert b"GCOL" not in data and data[8] >= 2  # no global heap; superblock version 2 or 3 (checksummed)
    with h5py.File(out) as h5:
        dtypes = _texts(h5)
    assert all(h5py.check_vlen_dtype(d) is None for d in dtypes)
    assert all(d.kind != "O" for d in dtypes)
    assert sum(d.kind == "S" for d in dtypes) > 20  # the text is there, in fixed-length strings


def test_damage_to_any_object_header_is_one_sentence_or_harmless(tmp_path: Path) -> None:
    """A damaged header of an object the reader opens is a checksum error, said in one sentence; never a group
    read as absent (the wind and conditioned groups were, through ``h5.get``). The headers the reader never
    opens are the shared time arrays' folders (their datasets are reached by the signals' hard links)."""
    out = tmp_path / "set.h5"
    _every_dataset(out)
    data = out.read_bytes()
    whole = read_dataset(out)
    headers = [k for k in range(len(data)) if data.startswith(b"OHDR", k)]
    harmless = []
    for at in headers:
        damaged = bytearray(data)
        damaged[at + 6] ^= 0x55  # the size of the header's first chunk: what the checksum covers moves
        path = tmp_path / f"damaged-{at}.h5"
        path.write_bytes(bytes(damaged))
        try:
            back = read_dataset(path)
        except LogFormatError as err:
            assert path.name in str(err) and "damaged" in str(err)
            continue
        counts = [len(back.logs), len(back.winds), len(back.conditioned), *(len(g.signals) for g in back.logs)]
        assert counts == [
            len(whole.logs),
            len(whole.winds),
            len(whole.conditioned),
            *(len(g.signals) for g in whole.logs),
        ]
        harmless.append(at)
    assert len(headers) > 100 and len(harmless) == len(whole.logs)  # one time folder per log


def _as_version_1(path: Path) -> None:
    """Rewrite `path` as version 1 wrote it: every text in variable-length strings (h5py's ``str``)."""
    with h5py.File(path, "a") as h5:

        def visit(_: str, item: h5py.Group | h5py.Dataset) -> None:
            for name, value in list(item.attrs.items()):
                if isinstance(value, bytes):
                    item.attrs[name] = value.decode()
            if isinstance(item, h5py.Dataset) and item.dtype.names is not None:
                vlen = np.dtype(
                    [(n, h5py.string_dtype() if item.dtype[n].kind == "S" else item.dtype[n]) for n in item.dtype.names]
                )
                rows = item[()]
                table = np.array(
                    [tuple(v.decode() if isinstance(v, bytes) else v for v in row) for row in rows], dtype=vlen
                )
                parent, key = item.parent, item.name.rsplit("/", 1)[1]
                del parent[key]
                parent.create_dataset(key, data=table)

        items: list[tuple[str, h5py.Group | h5py.Dataset]] = []
        h5.visititems(lambda name, item: items.append((name, item)))
        for name, item in items:
            visit(name, item)
        for name, value in list(h5.attrs.items()):
            if isinstance(value, bytes):
                h5.attrs[name] = value.decode()
        h5.attrs["schema_version"] = 1


def test_a_version_1_dataset_reads_as_it_was_written(tmp_path: Path) -> None:
    new, old = tmp_path / "new.h5", tmp_path / "old.h5"
    _every_dataset(new)
    old.write_bytes(new.read_bytes())
    _as_version_1(old)
    with h5py.File(old) as h5:
        assert any(h5py.check_string_dtype(d) is not None and d.kind == "O" for d in _texts(h5))
    a, b = read_dataset(new), read_dataset(old)
    assert (a.schema_version, b.schema_version) == (SCHEMA_VERSION, 1)
    assert a.sha256 == b.sha256
    assert len(a.conditioned) == len(b.conditioned) == 1
    assert a.conditioned[0].segments == b.conditioned[0].segments and len(a.conditioned[0].segments) > 0
    assert [(r.label, dict(r.units), dict(r.trim)) for r in a.conditioned[0].records] == [
        (r.label, dict(r.units), dict(r.trim)) for r in b.conditioned[0].records
    ]
    for x, y in ((a.logs[0], b.logs[0]), (a.winds[0], b.winds[0])):
        for field in dataclasses.fields(x):
            u, v = getattr(x, field.name), getattr(y, field.name)
            if field.name == "signals":
                assert {k: (s.unit, s.source) for k, s in u.items()} == {k: (s.unit, s.source) for k, s in v.items()}
            elif isinstance(u, np.ndarray):
                np.testing.assert_array_equal(u, v)
            else:
                assert u == v, field.name
