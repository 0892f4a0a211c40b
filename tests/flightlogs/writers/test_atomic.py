"""Atomic output: all or nothing, with the permissions an ordinary write would give."""

from __future__ import annotations

import os
import stat
import threading
from pathlib import Path

import pytest

from flightlogs.errors import DataError
from flightlogs.writers.atomic import atomic_folder, atomic_output, folder_in_place


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

    with pytest.raises(DataError, match="nodir: the output folder does not exist"):
        with atomic_output(tmp_path / "nodir" / "x.h5"):
            pass  # pragma: no cover - never entered
    assert list(tmp_path.iterdir()) == []


def test_a_file_in_place_of_the_folder_is_a_data_error(tmp_path: Path) -> None:

    (tmp_path / "plain").write_text("x")
    with pytest.raises(DataError, match="plain: the output folder is a file"):
        with atomic_output(tmp_path / "plain" / "x.h5"):
            pass  # pragma: no cover - never entered


def _read_fifo_in_background(fifo: Path) -> tuple[threading.Thread, list[bytes]]:
    received: list[bytes] = []

    def read() -> None:
        with open(fifo, "rb") as stream:  # blocks until the writer opens the pipe
            received.append(stream.read())

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    return reader, received


def test_a_pipe_receives_the_output_and_stays_a_pipe(tmp_path: Path) -> None:
    """``--json >(cat)``: the output goes through the pipe; it is not replaced by a regular file."""
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    reader, received = _read_fifo_in_background(fifo)
    with atomic_output(fifo) as tmp:
        tmp.write_text('{"ok": true}')
        assert tmp.parent != tmp_path  # completed away from the pipe's folder
    reader.join(timeout=10)
    assert received == [b'{"ok": true}']
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe"]


def test_a_failure_sends_nothing_down_a_pipe(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    with pytest.raises(RuntimeError), atomic_output(fifo) as tmp:
        tmp.write_text("half")
        raise RuntimeError("failed")
    reader_fd = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)  # no writer ever opened it: reads nothing
    try:
        assert os.read(reader_fd, 100) == b""
    finally:
        os.close(reader_fd)
    assert stat.S_ISFIFO(fifo.stat().st_mode)


@pytest.mark.skipif(os.geteuid() != 0, reason="making a character device needs root (the case the bug hit)")
def test_a_character_device_is_written_through_not_replaced(tmp_path: Path) -> None:
    """``-o /dev/null`` as root replaced the device by a regular file; here on a private copy of /dev/null."""
    null = tmp_path / "null"
    os.mknod(null, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    with atomic_output(null) as tmp:
        tmp.write_text("discarded")
    assert stat.S_ISCHR(null.stat().st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["null"]


def test_a_folder_in_place_of_the_file_is_a_data_error(tmp_path: Path) -> None:
    with pytest.raises(DataError, match="is a folder"), atomic_output(tmp_path):
        pass


def test_a_new_output_folder_appears_whole_with_ordinary_permissions(tmp_path: Path) -> None:
    target = tmp_path / "campaign"
    with atomic_folder(target) as tmp:
        (tmp / "a.bin").write_bytes(b"a")
        (tmp / "sub").mkdir()
        (tmp / "sub" / "b.csv").write_text("b")
        assert not target.exists()  # nothing there until the block ends
    assert sorted(str(p.relative_to(target)) for p in target.rglob("*")) == ["a.bin", "sub", "sub/b.csv"]
    assert _mode(target) == 0o777 & ~_process_umask()
    assert [p.name for p in tmp_path.iterdir()] == ["campaign"]


def test_into_an_existing_folder_files_are_replaced_and_others_kept(tmp_path: Path) -> None:
    target = tmp_path / "campaign"
    target.mkdir()
    (target / "a.bin").write_bytes(b"old")
    (target / "keep.txt").write_text("mine")
    with atomic_folder(target) as tmp:
        (tmp / "a.bin").write_bytes(b"new")
    assert (target / "a.bin").read_bytes() == b"new" and (target / "keep.txt").read_text() == "mine"
    assert [p.name for p in tmp_path.iterdir()] == ["campaign"]


@pytest.mark.parametrize("existing", [False, True])
def test_an_interrupted_folder_leaves_nothing_and_the_old_folder_as_it_was(tmp_path: Path, existing: bool) -> None:
    target = tmp_path / "campaign"
    if existing:
        target.mkdir()
        (target / "a.bin").write_bytes(b"old")
    with pytest.raises(KeyboardInterrupt), atomic_folder(target) as tmp:
        (tmp / "a.bin").write_bytes(b"half")
        raise KeyboardInterrupt
    assert [p.name for p in tmp_path.iterdir()] == (["campaign"] if existing else [])
    if existing:
        assert [p.name for p in target.iterdir()] == ["a.bin"] and (target / "a.bin").read_bytes() == b"old"


def test_folder_in_place_keeps_the_old_files_it_did_not_rewrite(tmp_path: Path) -> None:
    folder = tmp_path / "demo"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    (folder / "report.html").write_text("old")
    (folder / "logs").mkdir()
    (folder / "logs" / "a.ulg").write_text("old log")
    with folder_in_place(folder) as inside:
        assert inside == folder and list(folder.iterdir()) == []  # the block writes into the folder itself
        (folder / "report.html").write_text("new")
    assert {p.name: p.read_text() for p in folder.iterdir() if p.is_file()} == {
        "notes.txt": "mine",
        "report.html": "new",
    }
    assert (folder / "logs" / "a.ulg").read_text() == "old log"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demo"]  # nothing set aside is left


@pytest.mark.parametrize("error", [RuntimeError("failed"), KeyboardInterrupt()])
def test_folder_in_place_puts_the_old_folder_back_when_the_block_fails(tmp_path: Path, error: BaseException) -> None:
    folder = tmp_path / "demo"
    folder.mkdir()
    (folder / "report.html").write_text("old")
    with pytest.raises(type(error)), folder_in_place(folder):
        (folder / "report.html").write_text("half")
        (folder / "dataset.h5").write_text("half")
        raise error
    assert {p.name: p.read_text() for p in folder.iterdir()} == {"report.html": "old"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demo"]
    new = tmp_path / "fresh"
    with pytest.raises(RuntimeError), folder_in_place(new):
        (new / "x").write_text("half")
        raise RuntimeError
    assert not new.exists()


def test_folder_in_place_works_on_the_current_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """``sysid demo -o .``: the folder the user stands in is not moved; its entries are set aside and put back."""
    (tmp_path / "notes.txt").write_text("mine")
    monkeypatch.chdir(tmp_path)
    with pytest.raises(RuntimeError), folder_in_place(Path(".")):
        Path("report.html").write_text("half")
        raise RuntimeError
    assert sorted(p.name for p in tmp_path.iterdir()) == ["notes.txt"]
    with folder_in_place(Path(".")):
        Path("report.html").write_text("new")
    assert {p.name: p.read_text() for p in tmp_path.iterdir()} == {"notes.txt": "mine", "report.html": "new"}
