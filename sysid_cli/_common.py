"""Options and output helpers shared by the commands."""

from __future__ import annotations

import dataclasses
import functools
import importlib
import inspect
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager, redirect_stdout
from contextvars import ContextVar
from pathlib import Path
from typing import Any, Literal, TextIO

import click

from flightlogs.errors import DataError
from flightlogs.writers.jsonio import json_text, write_json

from ._flags import RUNNING, as_flags
from ._warnings import QUIET

__all__ = [
    "LibraryDefault",
    "OutputPath",
    "SysidCommand",
    "json_option",
    "JSON_ON_STDOUT",
    "json_owns_stdout",
    "emit_json",
    "progress_bar",
    "staged_progress",
]


class LibraryDefault(click.Option):
    """An option whose default is the library's own: a field of a dataclass's defaults, or of a constant.

    ``default_from=("sysid.freqresp", "Gating", "min_coherence")`` reads the default ``Gating`` declares;
    ``("sysid.fit", "DEFAULT_GUIDELINES", "max_cr_percent")`` reads the constant's field, and
    ``("sysid.verify", "doublet_records", "before_s")`` the function's keyword default. The value has
    one owner, the library; the module is imported when the default is needed (a run, or ``--help``),
    not with the command line.
    """

    def __init__(self, *args: Any, default_from: tuple[str, str, str], **kwargs: Any) -> None:
        super().__init__(*args, default=None, **kwargs)
        self.default_from = default_from

    def get_default(self, ctx: click.Context, call: bool = True) -> Any:
        value = super().get_default(ctx, call=call)
        if value is None:
            module, name, field = self.default_from
            owner = getattr(importlib.import_module(module), name)
            if isinstance(owner, type):  # a dataclass: the field's declared default
                (declared,) = [f for f in dataclasses.fields(owner) if f.name == field]
                assert declared.default is not dataclasses.MISSING, f"{name}.{field} declares no default"
                value = declared.default
            elif callable(owner):  # a function: its keyword's default
                value = inspect.signature(owner).parameters[field].default
            else:
                value = getattr(owner, field)
        return value


class OutputPath(click.Path):
    """Click type of a path a command writes: its folder must exist, checked before any work (exit 2).

    A file output must not be an existing folder; a folder output (which the
    command creates) must not be an existing file. Either way its parent
    folder must exist and be writable, so a typo fails at once instead of
    after the work, and no other output of the command is written.

    Parameters
    ----------
    folder : bool
        The output is a folder rather than a file.
    allow_dash : bool
        Accept ``-`` (standard output) as it is.
    path_type : type
        What the value converts to: `Path` or `str`.
    within : str or None
        The parameter name of a folder output of the same command: a path inside that folder (which the
        command creates) may have a folder that does not exist yet (checked by :class:`SysidCommand`).

    Examples
    --------
    >>> import click
    >>> OutputPath().convert("x.json", None, None).name
    'x.json'
    >>> try:
    ...     OutputPath().convert("nodir/x.json", None, None)
    ... except click.BadParameter as err:
    ...     print(err.message)
    nodir/x.json: folder nodir does not exist
    """

    def __init__(
        self, *, folder: bool = False, allow_dash: bool = False, path_type: type = Path, within: str | None = None
    ) -> None:
        super().__init__(file_okay=not folder, dir_okay=folder, allow_dash=allow_dash, path_type=path_type)
        self.folder = folder
        self.within = within

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """The path, once its folder is known to exist (click.BadParameter otherwise)."""
        converted = super().convert(value, param, ctx)
        if self.allow_dash and value in ("-", b"-"):
            return converted
        path = Path(os.fsdecode(converted))
        parent = path.parent
        if not parent.exists() and self.within is None:
            self.fail(f"{path}: folder {parent} does not exist", param, ctx)
        if not parent.exists():
            return converted  # inside the folder output `within`, or not: SysidCommand.invoke tells
        if not parent.is_dir():
            self.fail(f"{path}: {parent} is a file, not a folder", param, ctx)
        if not os.access(parent, os.W_OK | os.X_OK):
            self.fail(f"{path}: folder {parent} is not writable", param, ctx)
        return converted


class SysidCommand(click.Command):
    """A command whose file outputs are checked before it runs, and whose ``--json -`` owns stdout.

    An output that is one of the command's input files is refused (it would
    be destroyed); with ``--no-clobber``, added to every command that writes
    a file, an output that exists already is refused too. Either is one
    sentence and exit code 1, before any work. Otherwise an existing output
    is replaced only once the new one is complete (see
    :func:`flightlogs.writers.atomic.atomic_output`).

    With ``--json -`` the command runs with ``sys.stdout`` pointing at
    stderr, so its human lines (``click.echo``, ``print``) go there and
    stdout carries the JSON of :func:`emit_json` alone (see
    :func:`json_owns_stdout`).
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        if self.callback is not None and any(isinstance(p.type, OutputPath) for p in self.params):
            self.params.append(
                click.Option(
                    ["--no-clobber"],
                    is_flag=True,
                    help="Refuse to replace an output file that exists (exit 1) instead of replacing it.",
                )
            )
            command = self.callback

            @functools.wraps(command)
            def without_the_flag(*args: Any, no_clobber: bool = False, **kwargs: Any) -> Any:  # the flag is ours
                return command(*args, **kwargs)

            self.callback = without_the_flag

    def invoke(self, ctx: click.Context) -> Any:
        """Check the outputs, then run the command."""
        no_clobber = bool(ctx.params.get("no_clobber", False))
        inputs = [Path(os.fsdecode(v)) for p in self.params if _is_input(p) for v in _values(ctx.params.get(p.name))]
        for param in self.params:
            if isinstance(param.type, OutputPath) and param.type.within is not None:
                _inside_folder_output(ctx, param, param.type.within)
            if not isinstance(param.type, OutputPath) or param.type.folder:
                continue
            for value in _values(ctx.params.get(param.name)):
                out = Path(os.fsdecode(value))
                if str(value) == "-" or not out.exists():
                    continue
                same = next((i for i in inputs if i.exists() and os.path.samefile(i, out)), None)
                if same is not None:
                    raise DataError(
                        f"{out}: is also an input ({same}); writing {param.opts[-1]} there would destroy it"
                    )
                if no_clobber and out.is_file():
                    raise DataError(
                        f"{out}: exists, and --no-clobber leaves it as it is; give another {param.opts[-1]}"
                    )
        ctx.meta[RUNNING] = ctx  # library messages then name its flags (sysid_cli._flags)
        if ctx.params.get("quiet"):
            ctx.meta[QUIET] = True  # its warnings counted, not listed (sysid_cli._warnings)
        if ctx.params.get("json_path") == "-":
            ctx.meta[JSON_ON_STDOUT] = True  # a failure then prints {"error": ...} there (sysid_cli.main)
        with json_owns_stdout(ctx.params.get("json_path")):
            return super().invoke(ctx)


def _inside_folder_output(ctx: click.Context, param: click.Parameter, within: str) -> None:
    """A path whose folder does not exist must lie inside the folder output `within` (exit 2 otherwise)."""
    for value in _values(ctx.params.get(param.name)):
        path = Path(os.fsdecode(value))
        folder = ctx.params.get(within)
        if path.parent.exists():
            continue
        if folder is None or Path(os.fsdecode(folder)).resolve() not in (
            path.parent.resolve(),
            *path.parent.resolve().parents,
        ):
            raise click.BadParameter(
                f"{path}: folder {path.parent} does not exist (and is not inside the results folder)", ctx, param
            )


def _is_input(param: click.Parameter) -> bool:
    return isinstance(param.type, click.Path) and not isinstance(param.type, OutputPath) and param.type.exists


def _values(value: Any) -> list[Any]:
    if value is None:
        return []
    return list(value) if isinstance(value, (tuple, list)) else [value]


json_option = click.option(
    "--json",
    "json_path",
    type=OutputPath(allow_dash=True, path_type=str),
    default=None,
    help="Write a machine-readable summary to PATH ('-' for stdout).",
)


#: ``ctx.meta`` key set when the command's ``--json`` is ``-``: its stdout is JSON, even on failure.
JSON_ON_STDOUT = "sysid.json_on_stdout"

#: The real stdout while a command runs under :func:`json_owns_stdout` (``sys.stdout`` is then stderr).
_JSON_STDOUT: ContextVar[TextIO | None] = ContextVar("sysid_json_stdout", default=None)


@contextmanager
def json_owns_stdout(json_path: str | None) -> Iterator[None]:
    """With `json_path` ``-``, send every human line of the block to stderr: stdout is kept for the JSON.

    ``sys.stdout`` is stderr inside the block, so ``click.echo``, ``print``
    and anything else that writes to ``sys.stdout`` lands on stderr; only
    :func:`emit_json` writes to the real stdout. Any other `json_path`
    changes nothing. :class:`SysidCommand` runs every command in this block.

    Parameters
    ----------
    json_path : str or None
        The command's ``--json`` value.

    Examples
    --------
    >>> with json_owns_stdout("-"):
    ...     print("1 log, 2 segments")  # on stderr
    ...     emit_json({"segments": 2}, "-")
    {
      "segments": 2
    }
    """
    if json_path != "-":
        yield
        return
    token = _JSON_STDOUT.set(sys.stdout)
    try:
        with redirect_stdout(sys.stderr):
            yield
    finally:
        _JSON_STDOUT.reset(token)


def emit_json(summary: dict[str, Any], json_path: str | None) -> None:
    """Write `summary` as JSON (NaN as null) to a file (atomically) or, for ``-``, to the real stdout.

    Its ``notes``, library sentences, name the command's flags as the printed lines do (:func:`as_flags`).
    """
    if json_path is None:
        return
    if isinstance(summary.get("notes"), list):
        summary = summary | {"notes": [as_flags(n) if isinstance(n, str) else n for n in summary["notes"]]}
    if json_path == "-":
        stdout = _JSON_STDOUT.get() or sys.stdout
        stdout.write(json_text(summary, indent=2))
        stdout.flush()
        return
    write_json(json_path, summary, indent=2)


@contextmanager
def progress_bar(
    label: str, *, unit: Literal["bytes", "steps"] = "steps", quiet: bool = False
) -> Iterator[Callable[[int, int], None]]:
    """Yield a ``progress(done, total)`` callback that drives a tqdm bar on stderr.

    `unit` ``"bytes"`` counts bytes (scaled: kB, MB); ``"steps"`` counts
    whole steps (trials, stages, files). The bar appears only on a terminal
    and only once work has lasted about a second.
    """
    if quiet or not sys.stderr.isatty():  # no bar to draw: tqdm is not even loaded
        yield lambda _done, _total: None
        return
    from tqdm import tqdm

    bytes_ = unit == "bytes"
    bar = tqdm(
        desc=label,
        total=0,
        unit="B" if bytes_ else " steps",
        unit_scale=bytes_,
        delay=1.0,
        leave=False,
        disable=True if quiet else None,
        file=sys.stderr,
    )

    def update(done: int, total: int) -> None:
        if bar.total != total:
            bar.total = total
        bar.n = done
        bar.refresh() if bar.n >= total else bar.update(0)

    try:
        yield update
    finally:
        bar.close()


@contextmanager
def staged_progress(label: str, *, quiet: bool = False) -> Iterator[Callable[[str, int, int], None]]:
    """Yield ``progress(stage, done, total)``: ``reading …`` stages on a bar of bytes, the rest on a bar of steps.

    Each bar runs once from 0 to its total; the steps bar names the stage.
    """
    with ExitStack() as stack:
        bars: dict[str, Callable[[int, int], None]] = {}

        def update(stage: str, done: int, total: int) -> None:
            unit: Literal["bytes", "steps"] = "bytes" if stage.startswith("reading") else "steps"
            if unit not in bars:
                bars[unit] = stack.enter_context(
                    progress_bar("reading" if unit == "bytes" else label, unit=unit, quiet=quiet)
                )
            bars[unit](done, total)

        yield update
