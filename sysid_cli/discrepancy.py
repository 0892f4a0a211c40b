"""``sysid discrepancy``: where a real flight departs from its simulation, the physics left out, and the proof."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import click

from ._common import OutputPath, SysidCommand, emit_json, json_option, staged_progress
from ._flights import conditioned_flights, reading_from, reading_options
from ._tables import print_discrepancy
from ._wind_options import wind_distance_option, wind_offset_option, wind_option

__all__ = ["discrepancy"]

_EPILOG = """\b
Examples:
  sysid discrepancy sitl.ulg real.ulg --rotor-radius 0.19
  sysid discrepancy sitl_1.ulg sitl_2.ulg --real flight_1.ulg --real flight_2.ulg -o gap.json --report gap.html
  sysid discrepancy sitl.bin --real flight.bin --wind anemometer.csv --json -
  sysid discrepancy model.json flight.ulg --report gap.html
  sysid discrepancy sitl.ulg flight_1.ulg --model-out corrected.json
  sysid discrepancy corrected.json flight_2.ulg
"""


@click.command(cls=SysidCommand, epilog=_EPILOG)
@click.argument("logs", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option(
    "--real",
    "real_logs",
    multiple=True,
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    help="A real flight log of the same vehicle (repeatable); without it, LOGS are SIM REAL.",
)
@wind_option("Anemometer CSV, or a folder of them (repeatable), for the real flights: adds the wind term.")
@wind_distance_option()
@wind_offset_option()
@reading_options()
@click.option(
    "--rotor-radius",
    "rotor_radius",
    type=click.FloatRange(min=0.0, min_open=True),
    help="Propeller radius, m, if known: where the ground effect ends is also given as Z/R.",
)
@click.option("-o", "--out", type=OutputPath(), help="Write the findings (JSON) here.")
@click.option("--report", type=OutputPath(), help="Write the HTML report here.")
@click.option(
    "--model-out",
    "model_out",
    type=OutputPath(),
    help="Write the simulation's model with what was found added (JSON); give it as SIM to check another flight.",
)
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no summary.")
def discrepancy(
    logs: tuple[Path, ...],
    real_logs: tuple[Path, ...],
    wind_paths: tuple[Path, ...],
    wind_distance: float | None,
    wind_offset: float | None,
    table_map: Any,
    vehicle: str | None,
    rotor_radius: float | None,
    out: Path | None,
    report: Path | None,
    model_out: Path | None,
    json_path: str | None,
    quiet: bool,
) -> None:
    """Compare simulated flights (LOGS: PX4 SITL, ArduPilot SITL, Gazebo or `sysid simulate`, as ULog or
    DataFlash; or one model from `sysid fit -o` or `--model-out`, evaluated along the real flights) with real flights of the same vehicle: locate where they differ, name the physics the
    simulation leaves out from a catalogue of terms (ground_effect, rotor_drag, wind, time_delay, actuator_lag,
    battery_sag, mass_change, cg_offset, control_effectiveness, parasitic_drag, inflow, translational_lift,
    thrust_saturation, sensor_scale), fit it with its uncertainty and show the residual it removes on held-out data. What no
    term explains is "unexplained": located, and modelled by a sparse combination of the flight's own states and
    inputs; terms that explain a residual equally are listed as alternatives. "none" is an answer: nothing
    beyond what noise gives on held-out simulated flight."""
    from flightlogs.conditioning.condition import ConditioningOptions
    from flightlogs.errors import DataError
    from flightlogs.writers.jsonio import write_json
    from sysid.discrepancy import DiscrepancyOptions, discover_simulation, write_corrected_model

    sim_logs: tuple[Path, ...] = logs
    if not real_logs:
        if len(logs) != 2:
            raise click.UsageError("give SIM REAL, or the simulated logs and --real for each real one")
        sim_logs, real_logs = logs[:1], logs[1:]
    models = [p for p in sim_logs if p.suffix.lower() == ".json"]
    if models and len(sim_logs) > 1:
        raise DataError(f"{models[0]}: a fitted model is the whole simulation; give it alone, or only flight logs")
    # the search needs no maneuvers; the report's frequency responses need the sweeps (2 s a log to find)
    maneuvers = None if report is not None else ()
    reading = reading_from(table_map, vehicle)
    windy = ConditioningOptions(wind_offset_s=wind_offset, wind_distance_m=wind_distance, segments=maneuvers)
    log_only = {"--wind": wind_paths, "--wind-distance": wind_distance, "--wind-offset": wind_offset}
    flown = conditioned_flights(
        list(real_logs), list(wind_paths), windy, log_only=log_only, quiet=quiet, reading=reading
    )
    simulation = (
        models[0]
        if models
        else conditioned_flights(
            list(sim_logs), [], ConditioningOptions(segments=maneuvers), log_only={}, quiet=quiet, reading=reading
        )
    )
    with staged_progress("discrepancy", quiet=quiet) as progress:
        found = discover_simulation(
            simulation, flown, options=DiscrepancyOptions(rotor_radius_m=rotor_radius), progress=progress
        )
    result = found.result
    summary = result.to_dict()
    if out is not None:
        write_json(out, summary)
    if model_out is not None and result.corrected is not None:
        write_corrected_model(model_out, result.corrected)
    if report is not None:
        from reports.discrepancy_report import write_discrepancy_report  # matplotlib: only for a report

        write_discrepancy_report(report, result, found.comparisons(flown), model=found.model_name)
    if not quiet:
        print_discrepancy(result)
        for written in (out, report, model_out):
            if written is not None:
                click.echo(f"wrote {written}")
    emit_json(summary, json_path)
