"""The ``sysid`` command group: options shared by all commands, error mapping, warnings printed once."""

from __future__ import annotations

import importlib
import logging
import signal
import sys
import types
from typing import NoReturn

import click

from flightlogs.errors import SysidError, SysidWarning

from ._flags import as_flags
from ._warnings import warnings_printed_once

__all__ = ["cli"]

_EPILOG = """\b
Examples:
  sysid demo
  sysid ingest flight.ulg --wind anemometer.csv -o flight.h5 --json -
"""


class _Terminated(BaseException):
    """SIGTERM, raised where the program is so that every output in progress is cleaned up as on Ctrl-C."""


def _terminate(_signum: int, _frame: types.FrameType | None) -> None:
    raise _Terminated


#: Exit codes of a command ended by a signal, as a shell reports one: 128 + the signal's number.
_INTERRUPTED = {KeyboardInterrupt: (130, "SIGINT"), _Terminated: (143, "SIGTERM")}


#: Each command's module and object, imported when the command runs (``sysid --help`` imports them all): a
#: command loads only what it uses (20 ms of a 0.4 s ingest of a small log went to the other commands' imports).
_COMMANDS = {
    "batch": ("sysid_cli.batch", "batch"),
    "demo": ("sysid_cli.demo", "demo"),
    "discrepancy": ("sysid_cli.discrepancy", "discrepancy"),
    "fit": ("sysid_cli.fit", "fit"),
    "freqresp": ("sysid_cli.freqresp", "freqresp"),
    "ground-effect": ("sysid_cli.groundeffect", "ground_effect"),
    "ingest": ("sysid_cli.ingest", "ingest"),
    "modes": ("sysid_cli.modes", "modes"),
    "mrac": ("sysid_cli.mrac", "mrac"),
    "report": ("sysid_cli.report", "report"),
    "simulate": ("sysid_cli.simulate", "simulate"),
    "validate": ("sysid_cli.validate", "validate"),
}


class _SysidGroup(click.Group):
    """Turn project errors into one sentence and exit code 1 (traceback only with --debug).

    The project's warnings raised while the command runs are printed after
    it, once each, as ``warning: <message>`` (see :mod:`sysid_cli._warnings`);
    one made an error by ``-W error`` ends the command like an error.
    SIGINT (Ctrl-C) and SIGTERM end it with one line and exit 130 or 143:
    outputs are written through temporary files that are then removed, so
    nothing half-written is left and an earlier output stays as it was.
    """

    def list_commands(self, ctx: click.Context) -> list[str]:
        """Every command's name, sorted."""
        return sorted({*super().list_commands(ctx), *_COMMANDS})

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        """The command called `cmd_name`, its module imported now."""
        if cmd_name in _COMMANDS and cmd_name not in self.commands:
            module, name = _COMMANDS[cmd_name]
            self.add_command(getattr(importlib.import_module(module), name), cmd_name)
        return super().get_command(ctx, cmd_name)

    def invoke(self, ctx: click.Context) -> object:
        previous = signal.signal(signal.SIGTERM, _terminate)
        try:
            with warnings_printed_once(ctx.meta):
                return super().invoke(ctx)
        except (click.exceptions.Exit, click.ClickException, click.Abort):
            raise
        except (KeyboardInterrupt, _Terminated) as err:
            if ctx.meta.get("sysid.debug"):
                raise
            code, name = _INTERRUPTED[type(err)]
            fresh_line = "\n" if sys.stderr.isatty() else ""  # past a progress bar's line
            click.secho(f"{fresh_line}interrupted ({name}): no file was left half-written", fg="red", err=True)
            ctx.exit(code)
        except SysidError as err:
            if ctx.meta.get("sysid.debug"):
                raise
            _failed(ctx, str(err))
        except SysidWarning as err:  # -W error
            if ctx.meta.get("sysid.debug"):
                raise
            _failed(ctx, f"{err} ({type(err).__name__}, an error under -W error)")
        except BrokenPipeError:
            raise
        except Exception as err:  # a bug or an unwrapped library failure
            if ctx.meta.get("sysid.debug"):
                raise
            _failed(ctx, f"unexpected {type(err).__name__}: {err} (run with --debug for the traceback)")
        finally:
            signal.signal(signal.SIGTERM, previous)


def _failed(ctx: click.Context, message: str) -> NoReturn:
    """End the command with `message` on stderr and exit 1; with ``--json -`` also ``{"error": message}`` on stdout.

    The fields a library message names are the running command's flags (:func:`~sysid_cli._flags.as_flags`).
    """
    message = as_flags(message, ctx)
    click.secho(f"error: {message}", fg="red", err=True)
    from ._common import JSON_ON_STDOUT  # numpy and the writers: only once a command ran

    if ctx.meta.get(JSON_ON_STDOUT):
        from flightlogs.writers.jsonio import json_text

        click.echo(json_text({"error": message, "exit_code": 1}, indent=2), nl=False)
    ctx.exit(1)


@click.group(cls=_SysidGroup, epilog=_EPILOG, context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(package_name="flight-sysid", prog_name="sysid")
@click.option("--debug", is_flag=True, help="Show full tracebacks and debug logging.")
@click.pass_context
def cli(ctx: click.Context, debug: bool) -> None:
    """flight-sysid: turn multirotor flight logs into validated dynamic models."""
    ctx.meta["sysid.debug"] = debug
    logging.basicConfig(
        level=logging.DEBUG if debug else logging.WARNING,
        format="%(levelname)s %(name)s: %(message)s",
        stream=sys.stderr,
    )
