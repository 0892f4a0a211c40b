"""Write output files so that a failure never leaves half a file behind."""

from __future__ import annotations

import contextlib
import functools
import os
import shutil
import stat
import tempfile
from collections.abc import Iterator
from pathlib import Path

from flightlogs.errors import DataError

__all__ = ["atomic_folder", "atomic_output", "folder_in_place"]


@contextlib.contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside `path`; rename it over `path` on success.

    If the block raises, the temporary file is removed and an existing file at
    `path` is left untouched. The result has the permissions an ordinary
    ``open(path, "w")`` would give: those of the file it replaces, else
    0o666 less the umask (the temporary file itself is private, 0o600).
    A `path` that is not a regular file (``/dev/null``, a pipe such as
    ``>(cat)``, a terminal) is never replaced: the output is completed in a
    private temporary folder and then written to it in one pass, so nothing
    reaches it when the block fails.

    Parameters
    ----------
    path : str or Path
        Final destination. Its folder must exist.

    Raises
    ------
    DataError
        If the folder of `path` does not exist or is not a folder, or
        `path` is a folder.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "out.txt"
    >>> with atomic_output(target) as tmp:
    ...     _ = tmp.write_text("done")
    >>> target.read_text()
    'done'
    """
    path = Path(path)
    if path.is_dir():
        raise DataError(f"{path}: is a folder, not a file to write")
    if path.exists() and not path.is_file():
        with _through_private_copy(path) as tmp:
            yield tmp
        return
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise DataError(
            f"{folder}: the output folder does not exist"
            if not folder.exists()
            else f"{folder}: the output folder is a file"
        )
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=folder)
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        os.chmod(tmp, _mode_for(path))
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def atomic_folder(path: str | Path) -> Iterator[Path]:
    """Yield a temporary folder beside `path`; on success its files become `path`'s.

    A new `path` is the temporary folder renamed; into an existing folder
    each file is moved in turn (replacing one of the same name, as
    :func:`atomic_output` would). If the block raises (an error, Ctrl-C,
    SIGTERM), the temporary folder is removed and `path` is left as it was.

    Parameters
    ----------
    path : str or Path
        The output folder. Its parent must exist.

    Raises
    ------
    DataError
        If `path` is a file, or its parent folder does not exist.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "campaign"
    >>> with atomic_folder(target) as tmp:
    ...     _ = (tmp / "a.txt").write_text("done")
    >>> sorted(p.name for p in target.iterdir())
    ['a.txt']
    """
    path, parent = _output_folder(path)
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".part", dir=parent))
    os.chmod(tmp, 0o777 & ~_umask())  # as a folder made by mkdir (mkdtemp's is private)
    try:
        yield tmp
        if not path.exists():
            os.replace(tmp, path)
            return
        for entry in sorted(tmp.rglob("*")):
            target = path / entry.relative_to(tmp)
            if entry.is_dir():
                target.mkdir(exist_ok=True)
            else:
                os.replace(entry, target)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


@contextlib.contextmanager
def folder_in_place(path: str | Path) -> Iterator[Path]:
    """Yield `path` itself, emptied, to write into; whatever it held comes back if the block fails.

    For outputs that record their own paths (a dataset names its logs, a report its files), so
    cannot be written under a temporary name as in :func:`atomic_folder`. The folder's entries are
    set aside in a folder beside it first (the folder itself stays, so ``.`` works); if the block
    raises (an error, Ctrl-C, SIGTERM), what was written is removed and the old entries are put back
    (a folder created for the block is removed); on success, the old entries the block did not
    write again are put back beside the new ones.

    Parameters
    ----------
    path : str or Path
        The output folder. Its parent must exist.

    Raises
    ------
    DataError
        If `path` is a file, or its parent folder does not exist.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> target = pathlib.Path(tempfile.mkdtemp()) / "demo"
    >>> target.mkdir(); _ = (target / "notes.txt").write_text("mine")
    >>> with folder_in_place(target) as folder:
    ...     _ = (folder / "report.html").write_text("new")
    >>> sorted(p.name for p in target.iterdir())
    ['notes.txt', 'report.html']
    """
    path, _ = _output_folder(path)
    created = not path.exists()
    path.mkdir(exist_ok=True)
    # beside the folder (inside it for the root folder), never in its place: "." and the like stay where they are
    aside = Path(tempfile.mkdtemp(prefix=f".{path.resolve().name}.", suffix=".old", dir=path.resolve().parent))
    for entry in [e for e in path.iterdir() if e.resolve() != aside]:
        os.replace(entry, aside / entry.name)
    try:
        yield path
    except BaseException:
        for entry in [e for e in path.iterdir() if e.resolve() != aside]:
            if entry.is_dir() and not entry.is_symlink():
                shutil.rmtree(entry)
            else:
                entry.unlink()
        for entry in aside.iterdir():
            os.replace(entry, path / entry.name)
        if created:
            path.rmdir()
        raise
    else:
        for entry in aside.iterdir():
            if not (path / entry.name).exists():
                os.replace(entry, path / entry.name)
    finally:
        shutil.rmtree(aside, ignore_errors=True)


def _output_folder(path: str | Path) -> tuple[Path, Path]:
    """`path` as an output folder and its parent; DataError if it is a file or its parent is missing."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise DataError(f"{path}: is a file, not a folder to write into")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise DataError(f"{parent}: the output folder's parent does not exist")
    return path, parent


@contextlib.contextmanager
def _through_private_copy(path: Path) -> Iterator[Path]:
    """Yield a temporary path in a private folder; copy it into the device or pipe `path` on success."""
    with tempfile.TemporaryDirectory(prefix="sysid-") as folder:
        tmp = Path(folder) / (path.name or "output")
        yield tmp
        with open(tmp, "rb") as source, open(path, "wb") as target:
            shutil.copyfileobj(source, target)


def _mode_for(path: Path) -> int:
    """Permission bits for a new `path`: those of the file there, else 0o666 less the umask."""
    try:
        return stat.S_IMODE(path.stat().st_mode)
    except FileNotFoundError:
        return 0o666 & ~_umask()


@functools.cache
def _umask() -> int:
    """The process umask (read once: setting it to read it is not thread-safe)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask
