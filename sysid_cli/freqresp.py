"""``sysid freqresp``: composite frequency responses of the sweeps, gated by coherence."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ._common import LibraryDefault, OutputPath, SysidCommand, emit_json, json_option
from ._flags import as_flags
from ._flights import conditioned_flights, reading_from, reading_options
from ._response_options import gating_options, windows_option
from ._wind_options import segments_from, segments_option, wind_distance_option, wind_offset_option, wind_option

_RESPONSES = ("sysid.freqresp", "ResponseOptions")  # the grid options' defaults are the library's

__all__ = ["freqresp"]

_EPILOG = """\b
Examples:
  sysid freqresp flight.h5 --json -
  sysid freqresp flight.h5 --pairs q/delta_lon,ax/delta_lon -o fr.h5 --plot fr.svg
  sysid freqresp sweeps/*.bin --wind mast.csv --wind-distance 4.6 --pairs ax/delta_lon,ax/wind_lon -o fr.h5
  sysid freqresp flight.h5 --windows 2,4,8,12,17 --overlap 0.5 --min-coherence 0.6 --omega-min 1 --omega-max 60
  sysid freqresp px4_sweeps/*.ulg --reference none --no-whole-record -o fr.h5
  sysid freqresp flight.ulg --segments maneuvers.csv --pairs q/delta_lon --json -
"""


def _pairs(_ctx: click.Context, _param: click.Parameter, value: str | None) -> tuple[tuple[str, str], ...] | None:
    from sysid.freqresp import parse_pairs

    if value is None:
        return None
    if not value.strip(" ,"):
        raise click.BadParameter("empty: give OUTPUT/INPUT pairs, e.g. q/delta_lon,theta/delta_lon")
    try:
        return parse_pairs(value)
    except ValueError as err:
        raise click.BadParameter(str(err)) from None


@click.command(cls=SysidCommand, epilog=_EPILOG)
@click.argument(
    "sources",
    metavar="DATASET|LOG...",
    nargs=-1,
    required=True,
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
)
@wind_option("Anemometer CSV or folder (with logs; aligned by UTC as in `sysid ingest`).")
@wind_distance_option("Anemometer-to-vehicle distance, m (with --wind; see `sysid ingest` for the other choices).")
@wind_offset_option("Anemometer clock minus UTC, s (with --wind).")
@segments_option("TOML or CSV of maneuvers (start_s, end_s, axis[, kind]) overriding detection (with logs).")
@reading_options()
@click.option(
    "--pairs",
    callback=_pairs,
    metavar="OUT/IN,...",
    help="Responses to compute, e.g. q/delta_lon,ax/delta_lon (default: the chapter 3 outputs of "
    "every axis with a sweep).",
)
@click.option(
    "--axis",
    type=click.Choice(["lat", "lon", "yaw", "thr"]),
    help="Use this axis's maneuvers for every pair (needed for inputs such as wind_lon alone).",
)
@click.option(
    "--kind",
    default="sweep",
    show_default=True,
    type=click.Choice(["sweep", "multisine", "3211", "doublet", "broadband"]),
    help="Maneuvers to use (broadband: a pilot's input without a frequency trend).",
)
@click.option(
    "--omega-min",
    type=click.FloatRange(min=0, min_open=True),
    cls=LibraryDefault,
    default_from=_RESPONSES + ("omega_min",),
    show_default=True,
    help="Lowest frequency, rad/s.",
)
@click.option(
    "--omega-max",
    type=click.FloatRange(min=0, min_open=True),
    cls=LibraryDefault,
    default_from=_RESPONSES + ("omega_max",),
    show_default=True,
    help="Highest frequency, rad/s.",
)
@click.option(
    "--n-freq",
    type=click.IntRange(min=2),
    cls=LibraryDefault,
    default_from=_RESPONSES + ("n_freq",),
    show_default=True,
    help="Points of the log-spaced grid.",
)
@windows_option()
@click.option(
    "--overlap",
    type=click.FloatRange(0.0, 0.95, max_open=True),
    cls=LibraryDefault,
    default_from=_RESPONSES + ("overlap",),
    show_default=True,
    help="Window overlap, fraction.",
)
@gating_options()
@click.option(
    "--reference",
    default="auto",
    show_default=True,
    metavar="auto|none|SIGNAL",
    help="Injected excitation used as the mixer input's instrument, H = G_ry/G_rx: 'auto' uses the "
    "logged `excitation` (ArduPilot SIDD) where every piece of an axis carries it, else the mixer "
    "input (PX4); 'none' never; or a signal name on every axis.",
)
@click.option(
    "--whole-record/--no-whole-record",
    default=True,
    show_default=True,
    help="Add the records' whole-length transforms to the composite (free of the windows' resolution "
    "bias; needs more maneuver pieces than inputs).",
)
@click.option(
    "-o", "--out", type=OutputPath(), help="Write the responses (fit range set on those kept) to this HDF5 file."
)
@click.option("--plot", type=OutputPath(), help="Write Bode and coherence plots to this SVG file.")
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no table.")
def freqresp(
    sources: tuple[Path, ...],
    wind_paths: tuple[Path, ...],
    wind_distance: float | None,
    wind_offset: float | None,
    segments_file: Path | None,
    table_map: Any,
    vehicle: str | None,
    pairs: tuple[tuple[str, str], ...] | None,
    axis: str | None,
    kind: str,
    omega_min: float,
    omega_max: float,
    n_freq: int,
    windows: tuple[float, ...] | None,
    overlap: float,
    min_coherence: float,
    min_decades: float,
    reference: str,
    whole_record: bool,
    out: Path | None,
    plot: Path | None,
    json_path: str | None,
    quiet: bool,
) -> None:
    """Compute composite (multi-window, chirp-z) frequency responses from the maneuvers of a DATASET
    (`sysid ingest -o`) or of LOGs ingested on the fly, gate them by coherence, and write them."""
    from sysid.freqresp import Gating, ResponseOptions, flight_responses, gate_responses, write_responses

    forced = None if reference in ("auto", "none") else reference
    if omega_min >= omega_max:
        raise click.BadParameter(
            f"{omega_min:g} rad/s must be below --omega-max ({omega_max:g} rad/s)", param_hint="'--omega-min'"
        )
    try:
        options = ResponseOptions(
            omega_min=omega_min,
            omega_max=omega_max,
            n_freq=n_freq,
            window_lengths_s=windows,
            overlap=overlap,
            reference=forced,
            whole_record=whole_record,
        )
        gating = Gating(min_coherence=min_coherence, min_decades=min_decades)
    except ValueError as err:
        raise click.UsageError(str(err)) from None
    from flightlogs.conditioning.condition import ConditioningOptions

    flights = conditioned_flights(
        sources,
        wind_paths,
        ConditioningOptions(
            wind_distance_m=wind_distance, wind_offset_s=wind_offset, segments=segments_from(segments_file)
        ),
        log_only={
            "--wind": wind_paths,
            "--wind-distance": wind_distance,
            "--wind-offset": wind_offset,
            "--segments": segments_file,
            "--map": table_map,
            "--vehicle": vehicle,
        },
        quiet=quiet,
        reading=reading_from(table_map, vehicle),
    )
    computed = flight_responses(
        flights, pairs, axis=axis, kind=kind, options=options, use_excitation=reference != "none"
    )
    gated = gate_responses(computed.responses, gating)
    kept = {response.pair: response for response in gated.kept}
    ordered = [kept.get(response.pair, response) for response in computed.responses]
    if plot is not None:
        from reports.bode import write_bode_svg

        write_bode_svg(plot, ordered, min_coherence=min_coherence)
    if out is not None:
        write_responses(out, ordered)
    summary = _summary(ordered, gated.dropped, dict(computed.pieces), options, gating, out, plot) | {
        "notes": list(computed.notes)
    }
    if not quiet:
        _print_summary(summary)
    emit_json(summary, json_path)


def _summary(
    responses: list[Any],
    dropped: tuple[Any, ...],
    pieces: dict[str, int],
    options: Any,
    gating: Any,
    out: Path | None,
    plot: Path | None,
) -> dict[str, Any]:
    import numpy as np

    reasons = {d.pair: d.reason for d in dropped}
    entries = []
    for response in responses:
        entry: dict[str, Any] = {
            "pair": response.pair,
            "input": response.input,
            "output": response.output,
            "kept": response.fit_range is not None,
            "fit_range_rad_s": None,
            "mean_coherence": None,
            "reason": reasons.get(response.pair),
            "windows_s": [round(t, 4) for t in response.windows_s],
            "conditioned_on": list(response.conditioned_on),
            "reference": response.reference,
            "whole_record": response.whole_record,
        }
        if response.fit_range is not None:
            lo, hi = response.fit_range
            inside = (response.omega >= lo) & (response.omega <= hi)
            entry["fit_range_rad_s"] = [lo, hi]
            entry["mean_coherence"] = float(np.mean(response.coherence[inside]))
        entries.append(entry)
    return {
        "responses": entries,
        "pieces": pieces,
        "options": {
            "omega_min": options.omega_min,
            "omega_max": options.omega_max,
            "n_freq": options.n_freq,
            "overlap": options.overlap,
            "min_coherence": gating.min_coherence,
            "min_decades": gating.min_decades,
            "reference": options.reference,
            "whole_record": options.whole_record,
        },
        "output": str(out) if out is not None else None,
        "plot": str(plot) if plot is not None else None,
    }


def _print_summary(summary: dict[str, Any]) -> None:
    say = click.echo
    for axis, count in summary["pieces"].items():
        say(f"{axis}: {count} maneuver piece(s)")
    for note in summary["notes"]:
        say(f"  {as_flags(note)}")
    for entry in summary["responses"]:
        if entry["kept"]:
            lo, hi = entry["fit_range_rad_s"]
            say(f"  {entry['pair']:<20} kept     {lo:7.2f}-{hi:6.2f} rad/s  mean γ² {entry['mean_coherence']:.2f}")
        else:
            say(f"  {entry['pair']:<20} dropped  {entry['reason']}")
    for key in ("output", "plot"):
        if summary[key]:
            say(f"wrote {summary[key]}")
