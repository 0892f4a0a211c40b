"""``sysid fit``: identify a model structure from sweep logs (frequency responses, eq. 3.9; wind, eq. 3.14)."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from ._common import LibraryDefault, OutputPath, SysidCommand, emit_json, json_option, staged_progress
from ._flights import check_sources, conditioned_flights, reading_from, reading_options
from ._response_options import gating_options, windows_option
from ._tables import print_fit
from ._transfer import fit_transfer, parse_band
from ._wind_options import (
    anemometer_at_option,
    segments_from,
    segments_option,
    transport_delay_option,
    wind_distance_option,
    wind_offset_option,
    wind_option,
)

if TYPE_CHECKING:
    pass

__all__ = ["fit", "parse_assignments"]

_EPILOG = """\b
Examples:
  sysid fit sweeps/*.bin --model hover -o model.json
  sysid fit sweeps/*.bin --wind anemometer/ --wind-distance 4.6 --model hover-wind -o model.json --json -
  sysid fit dataset.h5 --model my-structure.toml --starts 5 --set T_a=0.05 -o model.json --mat model.mat
  sysid fit flight.ulg --segments maneuvers.toml --partial -o model.json    # the axes flown only
  sysid fit roll.csv --map time=t:ms,delta_lat=1,p=2:deg/s --delay --report tf.html \
      --tf "p/delta_lat = b2*s^2/(s^4 + a3*s^3 + a2*s^2 + a1*s + a0)"
"""


def parse_assignments(_ctx: click.Context, _param: click.Parameter, value: tuple[str, ...]) -> dict[str, float]:
    """Parse repeated ``NAME=VALUE`` options into a mapping (click callback)."""
    found: dict[str, float] = {}
    for item in value:
        for part in item.split(","):
            name, sep, number = part.partition("=")
            try:
                found[name.strip()] = float(number)
            except ValueError:
                raise click.BadParameter(f"{part!r} is not NAME=VALUE (e.g. X_u=-0.3172)") from None
            if not sep or not name.strip() or not math.isfinite(found[name.strip()]):
                raise click.BadParameter(f"{part!r} is not NAME=VALUE with a finite value")
    return found


@click.command(cls=SysidCommand, epilog=_EPILOG)
@click.argument("logs", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option(
    "--model",
    "model_name",
    default="hover",
    show_default=True,
    metavar="NAME|FILE",
    help="Built-in structure (hover, hover-wind) or a structure TOML file.",
)
@wind_option("Anemometer CSV or folder (repeatable): air-relative u v w and the wind input.")
@wind_distance_option()
@anemometer_at_option("Anemometer position, deg, for the distance to the vehicle's GPS position.")
@transport_delay_option("Transport delay of the wind, s.")
@wind_offset_option("Anemometer clock minus UTC, s.")
@click.option("--estimate-wind-offset", is_flag=True, help="Refine the clock offset by cross-correlation.")
@segments_option("TOML or CSV of maneuvers (start_s, end_s, axis[, kind]) overriding detection.")
@reading_options()
@click.option(
    "--kind",
    default="sweep",
    show_default=True,
    type=click.Choice(["sweep", "multisine", "3211", "doublet", "broadband"]),
    help="Maneuvers to fit (broadband: a pilot's input without a frequency trend, only when asked for).",
)
@click.option(
    "--set",
    "initial",
    multiple=True,
    callback=parse_assignments,
    metavar="NAME=VALUE",
    help="Starting value of a parameter (repeatable).",
)
@click.option(
    "--trim",
    "constants",
    multiple=True,
    callback=parse_assignments,
    metavar="NAME=VALUE",
    help="Trim constant instead of the flights' trim, e.g. U0=0 (repeatable).",
)
@click.option(
    "--starts",
    type=click.IntRange(min=1),
    cls=LibraryDefault,
    default_from=("sysid.fit", "FitOptions", "starts"),
    show_default=True,
    help="Starting points of the search (more guard against local minima).",
)
@click.option("--no-reduce", is_flag=True, help="Keep every parameter (no structure reduction).")
@click.option(
    "--max-cr",
    cls=LibraryDefault,
    default_from=("sysid.fit", "DEFAULT_GUIDELINES", "max_cr_percent"),
    type=click.FloatRange(min=0, min_open=True),
    show_default=True,
    help="Cramér–Rao bound guideline, % of the value (reduction and the report's verdict).",
)
@click.option(
    "--max-insensitivity",
    cls=LibraryDefault,
    default_from=("sysid.fit", "DEFAULT_GUIDELINES", "max_insensitivity_percent"),
    type=click.FloatRange(min=0, min_open=True),
    show_default=True,
    help="Insensitivity guideline, % of the value (reduction and the report's verdict).",
)
@click.option(
    "--max-correlation",
    type=click.FloatRange(0, 1, min_open=True),
    default=None,
    metavar="R",
    help="Also remove one of two parameters correlated beyond |R| (default: correlation not used).",
)
@gating_options()
@click.option(
    "--partial",
    is_flag=True,
    help="Write a model of the axes that can be identified, the others marked unidentified "
    "(default: an axis without a usable maneuver is an error).",
)
@click.option(
    "--tf",
    "tf_texts",
    multiple=True,
    metavar="EXPR",
    help="Fit a transfer function instead of the structure (repeatable), e.g. "
    '"p/delta_lat = b2*s^2/(s^4 + a3*s^3 + a2*s^2 + a1*s + a0)".',
)
@click.option("--delay", is_flag=True, help="With --tf: fit a transport delay exp(-tau s) too.")
@windows_option()
@click.option("--band", callback=parse_band, metavar="LO,HI", help="With --tf: fit only within LO-HI rad/s.")
@click.option("-o", "--out", type=OutputPath(), help="Write the identified model (versioned JSON).")
@click.option("--mat", type=OutputPath(), help="Also write the model for MATLAB (.mat).")
@click.option("--report", type=OutputPath(), help="Write the HTML fit report.")
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no tables.")
def fit(
    logs: tuple[Path, ...],
    model_name: str,
    wind_paths: tuple[Path, ...],
    wind_distance: float | None,
    anemometer_at: tuple[float, float] | None,
    transport_delay: float | None,
    wind_offset: float | None,
    estimate_wind_offset: bool,
    segments_file: Path | None,
    table_map: Any,
    vehicle: str | None,
    kind: str,
    initial: dict[str, float],
    constants: dict[str, float],
    starts: int,
    no_reduce: bool,
    max_cr: float,
    max_insensitivity: float,
    max_correlation: float | None,
    min_coherence: float,
    min_decades: float,
    partial: bool,
    tf_texts: tuple[str, ...],
    delay: bool,
    windows: tuple[float, ...] | None,
    band: tuple[float, float] | None,
    out: Path | None,
    mat: Path | None,
    report: Path | None,
    json_path: str | None,
    quiet: bool,
) -> None:
    """Identify a state-space model from the sweeps in LOGS (flight logs, or HDF5 datasets written by
    ``sysid ingest -o``): frequency responses, gating, the cost of eq. 3.9 with Cramér–Rao and
    insensitivity accuracy, structure reduction, then the wind terms on the residual of eq. 3.14.
    Control derivatives are per unit of the logged mixer input (the unit is printed). Every axis of the
    structure needs a maneuver whose responses pass gating (exit 1 naming each that has none), unless
    --partial: a parameter no response informs is unidentified, never given a value."""
    from flightlogs.conditioning.condition import ConditioningOptions
    from sysid.fit import (
        DEFAULT_GUIDELINES,
        FitOptions,
        IdentifyOptions,
        fit_summary,
        identify_logs,
        write_mat,
        write_model,
    )
    from sysid.freqresp import Gating, ResponseOptions
    from sysid.model import load_structure

    gating = Gating(min_coherence=min_coherence, min_decades=min_decades)
    guidelines = replace(DEFAULT_GUIDELINES, max_cr_percent=max_cr, max_insensitivity_percent=max_insensitivity)

    log_only = {
        "--wind": wind_paths,
        "--wind-distance": wind_distance,
        "--anemometer-at": anemometer_at,
        "--transport-delay": transport_delay,
        "--wind-offset": wind_offset,
        "--estimate-wind-offset": estimate_wind_offset,
        "--segments": segments_file,
        "--map": table_map,
        "--vehicle": vehicle,
    }
    conditioning = ConditioningOptions(
        wind_distance_m=wind_distance,
        anemometer_position_rad=anemometer_at,
        transport_delay_s=transport_delay,
        wind_offset_s=wind_offset,
        estimate_wind_offset=estimate_wind_offset,
        segments=segments_from(segments_file),
    )
    reading = reading_from(table_map, vehicle)
    if tf_texts:
        if mat is not None:
            raise click.UsageError("--mat writes a state-space model; --tf fits transfer functions")
        flights = conditioned_flights(logs, wind_paths, conditioning, log_only=log_only, quiet=quiet, reading=reading)
        fit_transfer(
            flights,
            tf_texts,
            delay=delay,
            band=band,
            windows=windows,
            kind=kind,
            gating=gating,
            guidelines=guidelines,
            sources=list(logs),
            out=out,
            report=report,
            json_path=json_path,
            quiet=quiet,
        )
        return
    if delay or band is not None:
        raise click.UsageError("--delay and --band go with --tf")
    structure = load_structure(model_name)
    structure.values(initial)  # a --set that names no parameter is an error before any work
    options = IdentifyOptions(
        fit=FitOptions(
            starts=starts,
            reduce=not no_reduce,
            guidelines=guidelines,
            max_correlation=max_correlation,
        ),
        kind=kind,
        gating=gating,
        constants=constants or None,
        initial=initial or None,
        partial=partial,
        responses=ResponseOptions(window_lengths_s=windows),
    )
    check_sources(logs, log_only)
    with staged_progress("identifying", quiet=quiet) as progress:
        model = identify_logs(
            list(logs),
            structure,
            wind_paths=list(wind_paths),
            conditioning=conditioning,
            options=options,
            progress=progress,
            reading=reading,
        )
    if out is not None:
        write_model(out, model)
    if mat is not None:
        write_mat(mat, model)
    if report is not None:
        from reports.model_report import write_model_report

        write_model_report(report, model)
    summary = fit_summary(model) | {
        "output": str(out) if out else None,
        "mat": str(mat) if mat else None,
        "report": str(report) if report else None,
    }
    if not quiet:
        print_fit(summary, model.guidelines)
    emit_json(summary, json_path)
