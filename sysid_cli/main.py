"""The ``sysid`` command group: options shared by all commands, error mapping, warnings printed once."""

from __future__ import annotations

import logging
import signal
import sys
import types

import click

from flightlogs.errors import SysidError, SysidWarning

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


class _SysidGroup(click.Group):
    """Turn project errors into one sentence and exit code 1 (traceback only with --debug).

    The project's warnings raised while the command runs are printed after
    it, once each, as ``warning: <message>`` (see :mod:`sysid_cli._warnings`);
    one made an error by ``-W error`` ends the command like an error.
    SIGINT (Ctrl-C) and SIGTERM end it with one line and exit 130 or 143:
    outputs are written through temporary files that are then removed, so
    nothing half-written is left and an earlier output stays as it was.
    """

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
            click.secho(f"error: {err}", fg="red", err=True)
            ctx.exit(1)
        except SysidWarning as err:  # -W error
            if ctx.meta.get("sysid.debug"):
                raise
            click.secho(f"error: {err} ({type(err).__name__}, an error under -W error)", fg="red", err=True)
            ctx.exit(1)
        except BrokenPipeError:
            raise
        except Exception as err:  # a bug or an unwrapped library failure
            if ctx.meta.get("sysid.debug"):
                raise
            click.secho(
                f"error: unexpected {type(err).__name__}: {err} (run with --debug for the traceback)",
                fg="red",
                err=True,
            )
            ctx.exit(1)
        finally:
            signal.signal(signal.SIGTERM, previous)


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


def _register() -> None:
    from . import demo, freqresp, ingest, simulate

    cli.add_command(ingest.ingest)
    cli.add_command(simulate.simulate)
    cli.add_command(demo.demo)
    cli.add_command(freqresp.freqresp)
    cli.add_command(__import__("sysid_cli.groundeffect", fromlist=["ground_effect"]).ground_effect)
    cli.add_command(__import__("sysid_cli.validate", fromlist=["validate"]).validate)
    cli.add_command(__import__("sysid_cli.mrac", fromlist=["mrac"]).mrac)
    cli.add_command(__import__("sysid_cli.fit", fromlist=["fit"]).fit)
    cli.add_command(__import__("sysid_cli.modes", fromlist=["modes"]).modes)
    cli.add_command(__import__("sysid_cli.report", fromlist=["report"]).report)
    cli.add_command(__import__("sysid_cli.discrepancy", fromlist=["discrepancy"]).discrepancy)


_register()
