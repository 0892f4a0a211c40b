"""Every reader of flight-sysid as a fuzz target: what it reads, from which seeds, and the rule it keeps.

The rule (issue 17): whatever the bytes, a reader returns (a partial read may warn), or raises a
:class:`~flightlogs.errors.SysidError` whose message names the file. Any other exception, a hang
(libFuzzer's ``-timeout``) or memory beyond ``-rss_limit_mb`` is a defect.

Seeds come from the real logs under ``../shared/data/real`` (their first kilobytes: a DataFlash,
ULog or MAVLink stream's prefix is itself a log), the test data and the project's own writers.
"""

from __future__ import annotations

import importlib
import os
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from flightlogs.errors import SysidError

__all__ = ["TARGETS", "Target", "UnnamedFileError", "check", "load_readers", "seeds"]

_ROOT = Path(__file__).resolve().parents[2]
REAL = Path(os.environ.get("SYSID_REAL_DATA", _ROOT.parent / "shared" / "data" / "real"))
_TEST_DATA = _ROOT / "tests" / "data"
_PREFIXES = (2048, 16384, 65536)  # bytes of each real log taken as a seed


class UnnamedFileError(AssertionError):
    """A reader's error that does not name the file it read."""


@dataclass(frozen=True, slots=True)
class Target:
    """One reader: the file suffix it is given, how it is called, and its seed inputs."""

    name: str
    suffix: str
    read: Callable[[Path], object]
    seed_files: Callable[[], list[bytes]]


def check(target: Target, data: bytes, path: Path) -> None:
    """Read `data` as `path` with `target`'s reader; raise if the rule is broken."""
    path.write_bytes(data)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            target.read(path)
        except SysidError as err:
            if path.name not in str(err):
                raise UnnamedFileError(f"{type(err).__name__} does not name {path.name}: {err}") from err


def seeds(target: Target) -> list[bytes]:
    """The seed inputs of `target`, deduplicated, in a fixed order."""
    return list(dict.fromkeys(target.seed_files()))


#: The modules of every reader (and what they read through), imported by :func:`load_readers`.
_READER_MODULES = (
    "flightlogs.readers.ardupilot",
    "flightlogs.readers.dataflash",
    "flightlogs.readers.tlog",
    "flightlogs.readers.ulog",
    "flightlogs.readers.anemometer",
    "flightlogs.readers.segments_file",
    "flightlogs.store.dataset",
    "simulator.campaign.scenario",
    "sysid.fit.model_file",
    "pyulog",
    "pymavlink.DFReader",
)


def load_readers() -> None:
    """Import every reader's module now (under atheris' instrumentation, so that its code is traced)."""
    for name in _READER_MODULES:
        importlib.import_module(name)


def _prefixes(*names: str) -> list[bytes]:
    out = []
    for name in names:
        data = (REAL / name).read_bytes()
        out += [data[:n] for n in _PREFIXES]
    return out


def _reader(module: str, function: str) -> Callable[[Path], object]:
    """``module.function(path)``, the module imported at the first call (after the fuzzer's instrumentation)."""

    def read(path: Path) -> object:
        return getattr(importlib.import_module(module), function)(path)

    return read


_log = _reader("flightlogs.readers", "read_log")
_anemometer = _reader("flightlogs.readers.anemometer", "read_anemometer_csv")
_segments = _reader("flightlogs.readers.segments_file", "read_segments_file")
_model = _reader("sysid.fit.model_file", "read_model")
_scenario = _reader("simulator.campaign.scenario", "read_scenario")
_dataset = _reader("flightlogs.store.dataset", "read_dataset")


def _anemometer_seeds() -> list[bytes]:
    files = sorted(_TEST_DATA.glob("anemometer/*.csv"))
    return [f.read_bytes()[:8192] for f in files] + [(REAL / "nmt-uas-wind" / "level0.csv").read_bytes()[:8192]]


def _segments_csv() -> list[bytes]:
    return [
        b"start_s,end_s,axis,kind\n10.0,44.0,lon,sweep\n54.0,56.0,lat,doublet\n",
        b"# maneuvers\n12.5,40,yaw\n50,52,thr,doublet\n60,90,lat,sweep,0.1,8\n",
    ]


def _segments_toml() -> list[bytes]:
    return [
        b'[[segment]]\nstart_s = 10.0\nend_s = 44.0\naxis = "lon"\nkind = "sweep"\nf_min_hz = 0.1\nf_max_hz = 8.0\n'
        b'\n[[segment]]\nstart_s = 54.0\nend_s = 56.0\naxis = "lat"\nkind = "doublet"\n'
    ]


def _model_seeds() -> list[bytes]:
    import tempfile

    from sysid.fit.model_file import write_model

    from builders import small_model

    with tempfile.TemporaryDirectory() as folder:
        return [write_model(Path(folder) / "model.json", small_model()).read_bytes()]


def _scenario_seeds() -> list[bytes]:
    folder = _ROOT / "simulator" / "campaign" / "builtin"
    return [f.read_bytes() for f in sorted(folder.glob("*.toml"))]


def _dataset_seeds() -> list[bytes]:
    """A dataset of a 16 s simulated hover with a pitch doublet (our simulator's log: no real data in the seeds
    of a target whose defects are kept as files)."""
    import tempfile
    from datetime import UTC, datetime

    from flightlogs.store.campaign import ingest_campaign
    from flightlogs.store.dataset import write_dataset
    from simulator.autopilot.excitation import Maneuver
    from simulator.flights.linear import simulate_hover
    from simulator.output.px4 import write_px4_log

    with tempfile.TemporaryDirectory() as folder:
        doublet = Maneuver(axis="lon", kind="doublet", start_s=8.0, amplitude=8.0, duration_s=2.0)
        flight = simulate_hover(16.0, (doublet,), rate_hz=25.0, substeps=2, seed=3)
        log = write_px4_log(flight, Path(folder) / "hover.ulg", utc_start=datetime(2025, 5, 1, 10, tzinfo=UTC))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            campaign = ingest_campaign([log], [])
            path = Path(folder) / "d.h5"
            write_dataset(path, campaign.logs, campaign.winds, list(campaign.flights))
        return [path.read_bytes()]


TARGETS: dict[str, Target] = {
    t.name: t
    for t in (
        Target(
            "dataflash",
            ".bin",
            _log,
            lambda: _prefixes("ardupilot-log-diagnosis/sample.bin", "dronekit-la-testdata/log171.bin"),
        ),
        Target(
            "ulog",
            ".ulg",
            _log,
            lambda: _prefixes("kd0aij-impulse-response/log1.ulg", "px4-ulog-rs/quadrotor_local.ulg"),
        ),
        Target("tlog", ".tlog", _log, lambda: _prefixes("phoenix/2018-09-17 16-44-06.tlog")),
        Target("anemometer", ".csv", _anemometer, _anemometer_seeds),
        Target("segments_csv", ".csv", _segments, _segments_csv),
        Target("segments_toml", ".toml", _segments, _segments_toml),
        Target("model", ".json", _model, _model_seeds),
        Target("scenario", ".toml", _scenario, _scenario_seeds),
        Target("dataset", ".h5", _dataset, _dataset_seeds),
    )
}
