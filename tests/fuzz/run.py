"""Fuzz one reader with atheris (libFuzzer, coverage-guided): ``python tests/fuzz/run.py TARGET [libFuzzer flags]``.

    python tests/fuzz/run.py dataflash -runs=100000 -timeout=10 -rss_limit_mb=2048
    python tests/fuzz/run.py --list

TARGET is a name of :data:`targets.TARGETS`. The seeds are written to a temporary corpus folder
(or to ``-corpus DIR``, kept between runs); libFuzzer grows it with the inputs that reach new code in
flightlogs, sysid, simulator, pyulog, pymavlink and h5py's Python side. An input that breaks the
rule of :mod:`targets` stops the run with exit code 1 and is written as ``crash-<sha1>`` (in
``-artifact_prefix``); keep it under ``tests/fuzz/regressions/TARGET/`` once fixed, where
``test_fuzz.py`` replays it. Timeouts and memory: libFuzzer's ``-timeout`` and ``-rss_limit_mb``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import atheris

sys.path[:0] = [str(Path(__file__).resolve().parents[1])]  # tests/, for builders and this package

with atheris.instrument_imports(include=["flightlogs", "sysid", "simulator", "pyulog", "pymavlink"]):
    from fuzz.targets import TARGETS, check, load_readers, seeds

    load_readers()


def main(argv: list[str]) -> None:
    if len(argv) < 2 or argv[1] not in TARGETS:
        print(f"usage: {argv[0]} TARGET [libFuzzer flags]; TARGET one of {', '.join(TARGETS)}", file=sys.stderr)
        raise SystemExit(0 if "--list" in argv else 2)
    target = TARGETS[argv[1]]
    flags = [a for a in argv[2:] if not a.startswith("-corpus=")]
    corpus = next((Path(a.split("=", 1)[1]) for a in argv[2:] if a.startswith("-corpus=")), None)
    corpus = corpus or Path(tempfile.mkdtemp(prefix=f"fuzz-{target.name}-"))
    corpus.mkdir(parents=True, exist_ok=True)
    for k, data in enumerate(seeds(target)):
        (corpus / f"seed-{k:03d}").write_bytes(data)
    work = Path(tempfile.mkdtemp(prefix="fuzz-input-"))
    path = work / f"input{target.suffix}"

    def one_input(data: bytes) -> None:
        check(target, data, path)

    atheris.Setup([argv[0], *flags, str(corpus)], one_input)
    atheris.Fuzz()


if __name__ == "__main__":
    main(sys.argv)
