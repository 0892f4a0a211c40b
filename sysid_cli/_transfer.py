"""``sysid fit --tf``: transfer-function fits of single responses, printed, written and reported."""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import click

from ._common import emit_json
from ._flags import as_flags

__all__ = ["parse_band", "fit_transfer", "print_transfer"]


def parse_band(_ctx: click.Context, _param: click.Parameter, value: str | None) -> tuple[float, float] | None:
    """``LO,HI`` in rad/s (click callback)."""
    if value is None:
        return None
    try:
        low, high = (float(part) for part in value.split(","))
    except ValueError:
        raise click.BadParameter(f"{value!r} is not LO,HI in rad/s (e.g. 2,20)") from None
    if not (math.isfinite(low) and math.isfinite(high) and 0 < low < high):
        raise click.BadParameter(f"{value!r}: two increasing positive frequencies, rad/s")
    return low, high


def fit_transfer(
    flights: Sequence[Any],
    texts: Sequence[str],
    *,
    delay: bool,
    band: tuple[float, float] | None,
    windows: tuple[float, ...] | None,
    kind: str,
    gating: Any,
    guidelines: Any,
    sources: Sequence[Path],
    out: Path | None,
    report: Path | None,
    json_path: str | None,
    quiet: bool,
) -> None:
    """Fit each ``--tf`` to its pair's response on `flights`; print, write (``-o``, ``--report``) and emit JSON.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        The flights.
    texts : sequence of str
        The ``--tf`` expressions.
    delay : bool
        Fit a transport delay.
    band : tuple of (float, float) or None
        ``--band``, rad/s.
    windows : tuple of float or None
        ``--windows``: the composite's window lengths, s.
    kind : str
        Maneuvers used.
    gating : Gating
        The gating rule (``--min-coherence``, ``--min-decades``).
    guidelines : Guidelines
        The guidelines the fits are judged by (``--max-cr``, ``--max-insensitivity``).
    sources : sequence of Path
        The files read.
    out, report : Path or None
        JSON and HTML outputs.
    json_path : str or None
        ``--json``.
    quiet : bool
        No table.
    """
    from flightlogs.writers.jsonio import write_json
    from sysid.fit.transfer import TransferOptions, fit_transfer_functions
    from sysid.freqresp import ResponseOptions
    from sysid.model.transfer import parse_transfer_function

    structures = [parse_transfer_function(text) for text in texts]
    fits = fit_transfer_functions(
        flights,
        structures,
        options=TransferOptions(
            delay=delay,
            band_rad_s=band,
            guidelines=guidelines,
        ),
        responses=ResponseOptions(window_lengths_s=windows),
        kind=kind,
        gating=gating,
    )
    summary: dict[str, Any] = {
        "tf": [fit.to_dict() for fit in fits],
        "sources": [str(p) for p in sources],
        "output": str(out) if out else None,
        "report": str(report) if report else None,
    }
    if out is not None:
        write_json(out, summary, indent=2)
    if report is not None:
        from reports.transfer_report import write_transfer_report

        write_transfer_report(report, fits, sources=[p.name for p in sources])
    if not quiet:
        print_transfer(summary)
    emit_json(summary, json_path)


def print_transfer(summary: dict[str, Any]) -> None:
    """The fits as tables on stdout (stderr under ``--json -``).

    Parameters
    ----------
    summary : dict
        ``{"tf": [TransferFunctionFit.to_dict(), ...], ...}``.
    """
    say = click.echo
    for tf in summary["tf"]:
        low, high = tf["band_rad_s"]
        say(f"{tf['expression']}: J = {tf['J']:.2f} over {low:.3g}-{high:.3g} rad/s")
        say(f"  {'parameter':<10} {'value':>12} {'CR%':>8} {'I%':>8}  unit")
        for name, p in tf["parameters"].items():
            say(
                f"  {name:<10} {p['value']:>12.5g} {p['cr_percent']:>8.3g} {p['insensitivity_percent']:>8.3g}  "
                f"{p['unit']}"
            )
        say("  poles (rad/s): " + ", ".join(f"{complex(*p):.4g}" for p in tf["poles"]))
        for note in tf["notes"]:
            say(f"  note: {as_flags(note)}")
    for key in ("output", "report"):
        if summary.get(key):
            say(f"wrote {summary[key]}")
