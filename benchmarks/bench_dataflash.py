"""Benchmark: flightlogs.readers.dataflash against pymavlink's DFReader, same files, same values.

Usage::

    python benchmarks/bench_dataflash.py [FILE.bin ...] [--synthetic-seconds 300]

Without files it times the real logs in ``../shared/data/real`` and a
synthetic ArduCopter 4.x log of about 30 MB written with
:mod:`flightlogs.writers.dataflash` in a temporary folder.

For each file it reports

* ``dfreader``: ``DFReader_binary(path)`` then ``_parse_next()`` until it
  returns None -- the fair full walk (``recv_msg`` is the same call); the
  message objects decode their fields lazily, so this is DFReader's lower bound;
* ``dfreader+fields``: the same walk reading every field of every message
  (what a full decode costs in DFReader), run once while checking values;
* ``ours``: :func:`flightlogs.readers.dataflash.read_messages` (best of 10 runs;
  DFReader: best of 3 on files under 5 MB, one run on larger ones);

the ratios, and whether every field of every message is identical (ints and
strings equal, floats bitwise equal).
"""

from __future__ import annotations

import argparse
import array
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from pymavlink.DFReader import DFReader_binary

from flightlogs.readers.dataflash import DataFlashMessages, read_messages
from flightlogs.writers.dataflash import MessageBlock, encode_dataflash, standard_block

REAL = Path(__file__).resolve().parents[2] / "shared" / "data" / "real"
DEFAULT_FILES = (REAL / "ardupilot-log-diagnosis" / "sample.bin", REAL / "dronekit-la-testdata" / "log171.bin")


def synthetic_log(path: Path, seconds: float, seed: int = 0, *, rate_hz: float = 400.0, system_id: bool = True) -> Path:
    """A System ID flight at `rate_hz`: two IMUs, ATT, RATE, RCOU, SIDD (≈100 kB per second at 400 Hz).

    Without `system_id`, an ordinary flight: no SIDS/SIDD (the maneuvers are then searched for).
    """
    rng = np.random.default_rng(seed)
    t400 = 10_000_000 + np.arange(int(seconds * rate_hz)) * int(round(1e6 / rate_hz))
    n, t_gps = t400.size, t400[:: max(1, int(round(rate_hz / 10)))]
    chirp = np.sin(2 * np.pi * (0.5 + 0.03 * (t400 - t400[0]) / 1e6) * (t400 - t400[0]) / 1e6)
    imu = [
        standard_block(
            "IMU",
            TimeUS=t400 + k,
            I=np.full(n, k),
            GyrX=rng.normal(0, 0.3, n),
            GyrY=rng.normal(0, 0.3, n),
            GyrZ=rng.normal(0, 0.1, n),
            AccX=rng.normal(0, 1, n),
            AccY=rng.normal(0, 1, n),
            AccZ=rng.normal(-9.81, 1, n),
            T=np.full(n, 45.5),
        )
        for k in range(2)
    ]
    imu_both = {c: np.ravel(np.column_stack([imu[0].data[c], imu[1].data[c]])) for c in imu[0].spec.columns}
    blocks = [
        MessageBlock(imu[0].spec, imu_both),
        standard_block(
            "ATT",
            TimeUS=t400 + 3,
            Roll=np.round(rng.normal(0, 10, n), 2),
            Pitch=np.round(rng.normal(0, 10, n), 2),
            Yaw=np.round(rng.uniform(0, 359.99, n), 2),
        ),
        standard_block(
            "RATE",
            TimeUS=t400 + 4,
            ROut=0.1 * chirp,
            POut=rng.normal(0, 0.05, n),
            YOut=rng.normal(0, 0.05, n),
            AOut=np.full(n, 0.42),
        ),
        standard_block("RCOU", **{"TimeUS": t400 + 5, **{f"C{k}": rng.integers(1100, 1900, n) for k in range(1, 5)}}),
    ]
    if system_id:
        blocks += [
            standard_block("SIDD", TimeUS=t400 + 6, Time=(t400 - t400[0]) / 1e6, Targ=chirp),
            standard_block("SIDS", TimeUS=t400[:1], Ax=[10], Mag=[0.1], FSt=[0.5], FSp=[20.0], TR=[seconds]),
        ]
    blocks.append(
        standard_block(
            "GPS",
            TimeUS=t_gps + 7,
            GWk=np.full(t_gps.size, 2300),
            GMS=300_000_000 + np.arange(t_gps.size) * 100,
            Status=np.full(t_gps.size, 3),
        )
    )
    params = {"FRAME_CLASS": 1, "FRAME_TYPE": 1, "SID_AXIS": 10 if system_id else 0, "SID_MAGNITUDE": 0.1}
    path.write_bytes(encode_dataflash(blocks, parameters=params, firmware="ArduCopter V4.5.7 (synthetic)"))
    return path


def time_dfreader(path: Path) -> float:
    """Seconds for DFReader_binary(path) and a _parse_next() walk to the end."""
    start = time.perf_counter()
    reader = DFReader_binary(str(path))
    while reader._parse_next() is not None:
        pass
    reader.close()
    return time.perf_counter() - start


def check_identical(path: Path, ours: DataFlashMessages) -> tuple[bool, float, int]:
    """Read every field with DFReader; (identical?, seconds, fields compared)."""
    start = time.perf_counter()
    reader = DFReader_binary(str(path))
    rows: dict[str, list[list[object]]] = {}
    while (msg := reader._parse_next()) is not None:
        rows.setdefault(msg.get_type(), []).append([getattr(msg, c) for c in msg.fmt.columns])
    seconds = time.perf_counter() - start
    reader.close()
    same, fields = set(rows) <= set(ours.tables), 0
    for name, values in rows.items():
        table = ours.tables.get(name)
        if table is None or len(table) != len(values):
            return False, seconds, fields
        for i, column in enumerate(table.format.columns[: len(values[0])]):
            ref = [v[i] for v in values]
            fields += len(ref)
            same &= _equal(table[column], ref)
    return same, seconds, fields


def _equal(ours: np.ndarray, ref: list[object]) -> bool:
    if ref and isinstance(ref[0], float):
        a = np.asarray(ours, np.float64).view(np.uint64)
        b = np.asarray(ref, np.float64).view(np.uint64)
        return bool(np.all((a == b) | (np.isnan(np.asarray(ours, np.float64)) & np.isnan(np.asarray(ref)))))
    if ref and isinstance(ref[0], array.array):
        return bool(np.array_equal(ours, np.array([r.tolist() for r in ref if isinstance(r, array.array)])))
    return ours.tolist() == ref


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--synthetic-seconds", type=float, default=300.0)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        files = list(args.files)
        if not files:
            files = [f for f in DEFAULT_FILES if f.exists()]
            files.append(synthetic_log(Path(tmp) / "synthetic_sysid.bin", args.synthetic_seconds))
        print(
            f"{'file':28s} {'MB':>6s} {'msgs':>8s} {'dfreader':>9s} {'+fields':>9s} {'ours':>8s} "
            f"{'ratio':>6s} {'ratio+f':>7s} identical"
        )
        ok = True
        for path in files:
            ours = read_messages(path)  # warm up (imports, dtype cache), then best of 10
            ours_s = min(_timed(lambda path=path: read_messages(path)) for _ in range(10))
            df_s = min(time_dfreader(path) for _ in range(3 if path.stat().st_size < 5e6 else 1))
            same, fields_s, _ = check_identical(path, ours)
            ok &= same
            print(
                f"{path.name[:28]:28s} {path.stat().st_size / 1e6:6.1f} {sum(ours.counts.values()):8d} "
                f"{df_s:8.3f}s {fields_s:8.3f}s {ours_s:7.4f}s {df_s / ours_s:5.0f}x {fields_s / ours_s:6.0f}x "
                f"{'yes' if same else 'NO'}"
            )
    return 0 if ok else 1


def _timed(fn: Callable[[], object]) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


if __name__ == "__main__":
    sys.exit(main())
