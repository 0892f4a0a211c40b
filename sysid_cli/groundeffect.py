"""``sysid ground-effect``: fit F/F0 against Z/R (eqs. 2.1-2.5) from a rig CSV or a flight log; spacing studies."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click

from ._common import LibraryDefault, OutputPath, SysidCommand, emit_json, json_option, progress_bar
from ._flights import reading_from, reading_options
from .ingest import parse_columns

_CONFIG = ("sysid.groundeffect.records", "GroundEffectDataConfig")  # the flight options' defaults are the library's

__all__ = ["ground_effect"]

_GROUP_EPILOG = """\b
Examples:
  sysid ground-effect fit rig.csv --rotor-radius 0.0225 --report ge.html --json -
  sysid ground-effect fit hover-steps.ulg --rotor-radius 0.0225 --mass 0.03812 -o ge-model.json
  sysid ground-effect spacing rig_0mm.csv rig_10mm.csv rig_20mm.csv --spacing 0,10,20 --rotor-radius 0.0225
"""

_FIT_EPILOG = """\b
Examples:
  sysid ground-effect fit rig.csv --rotor-radius 0.0225 --report ge.html --json -
  sysid ground-effect fit rig.csv --rotor-radius 0.0225 --f0 0.402 --columns height=Z_cm,thrust=scale_g
  sysid ground-effect fit hover-steps.ulg --rotor-radius 0.0225 --kf 2.083e-6 --mass 0.03812 -o ge-model.json
  sysid ground-effect fit flight.ulg --rotor-radius 0.0225 --models corrected,piecewise_linear --criterion bic
"""

_SPACING_EPILOG = """\b
Examples:
  sysid ground-effect spacing rig_0mm.csv rig_10mm.csv rig_20mm.csv rig_30mm.csv rig_40mm.csv rig_50mm.csv \\
      --spacing 0,10,20,30,40,50 --rotors 4 --rotor-radius 0.0225 --report spacing.html
  sysid ground-effect spacing two_0mm.csv two_25mm.csv --spacing 0,25 --rotors 2 --rotor-radius 0.0225 --json -
"""


def _float_list(_ctx: click.Context, _param: click.Parameter, value: str | None) -> list[float] | None:
    if value is None:
        return None
    try:
        return [float(part) for part in value.split(",") if part.strip()]
    except ValueError:
        raise click.BadParameter(f"{value!r} is not a comma-separated list of numbers (e.g. 0,10,20)") from None


def _models(_ctx: click.Context, _param: click.Parameter, value: str | None) -> tuple[str, ...] | None:
    from sysid.groundeffect import MODEL_NAMES

    if value is None:
        return None
    names = tuple(part.strip() for part in value.split(",") if part.strip())
    if not names:
        raise click.BadParameter(f"empty: choose one or more of {', '.join(MODEL_NAMES)}")
    unknown = [n for n in names if n not in MODEL_NAMES]
    if unknown:
        raise click.BadParameter(f"{', '.join(unknown)}: choose from {', '.join(MODEL_NAMES)}")
    return names


def _data_options(command: Callable[..., Any]) -> Callable[..., Any]:
    """Options turning a rig CSV or a flight log into F/F0 against Z/R (shared by fit and spacing)."""
    options = [
        reading_options(
            "Flight table (motion capture, CSV or Parquet): its column map, e.g. time=t:ms,height_agl=z:mm,"
            "motor_1=rpm1:rpm,... (rotor speeds in rpm or rad/s give F0 = k_f sum omega^2), or a .toml file."
        ),
        click.option(
            "--rotor-radius",
            "rotor_radius",
            type=click.FloatRange(min=0, min_open=True),
            required=True,
            metavar="M",
            help="Propeller radius R, m (Crazyflie: 0.0225).",
        ),
        click.option(
            "--f0",
            type=click.FloatRange(min=0, min_open=True),
            metavar="N",
            help="Rig: thrust out of ground effect, N (default: mean of the rows with Z/R > 8).",
        ),
        click.option(
            "--columns",
            callback=parse_columns,
            metavar="height=COL,thrust=COL",
            help="Rig CSV column names (default height_m, thrust_n).",
        ),
        click.option(
            "--units",
            callback=parse_columns,
            metavar="height=U,thrust=U",
            help="Rig CSV units (m, cm, mm, in; N, mN, g, kg) when the column names do not say.",
        ),
        click.option(
            "--kf",
            type=click.FloatRange(min=0, min_open=True),
            cls=LibraryDefault,
            default_from=_CONFIG + ("kf_n_per_count",),
            show_default=True,
            metavar="N",
            help="Flight: k_f of eq. 2.6, N per PWM count (Table 2.1).",
        ),
        click.option(
            "--mass",
            type=click.FloatRange(min=0, min_open=True),
            metavar="KG",
            help="Flight: vehicle mass, kg (default: the weight is the eq. 2.6 thrust of steps above Z/R 8).",
        ),
        click.option(
            "--pwm-full-scale",
            type=click.FloatRange(min=0, min_open=True),
            cls=LibraryDefault,
            default_from=_CONFIG + ("pwm_full_scale",),
            show_default=True,
            help="Flight: PWM counts of a full command, for motors logged as 0..1.",
        ),
        click.option(
            "--rotor-offset",
            type=float,
            cls=LibraryDefault,
            default_from=_CONFIG + ("rotor_offset_m",),
            show_default=True,
            metavar="M",
            help="Flight: rotor plane above the height sensor's reference, m.",
        ),
        click.option(
            "--min-hold",
            type=click.FloatRange(min=0, min_open=True),
            cls=LibraryDefault,
            default_from=_CONFIG + ("min_hold_s",),
            show_default=True,
            metavar="S",
            help="Flight: shortest hover step, s (its second half is used).",
        ),
        click.option(
            "--models",
            callback=_models,
            metavar="NAME,...",
            help="Families to fit (default all: cheeseman_bennett,corrected,exponential,piecewise_linear).",
        ),
        click.option(
            "--criterion",
            type=click.Choice(["aicc", "bic"]),
            cls=LibraryDefault,
            default_from=("sysid.groundeffect.fitting", "FitConfig", "criterion"),
            show_default=True,
            help="Model selection: corrected Akaike or Bayesian information criterion.",
        ),
        click.option(
            "--confidence",
            type=click.FloatRange(0, 1, min_open=True, max_open=True),
            cls=LibraryDefault,
            default_from=("sysid.groundeffect.fitting", "FitConfig", "confidence"),
            show_default=True,
            help="Level of the parameter confidence intervals.",
        ),
    ]
    for option in reversed(options):
        command = option(command)
    return command


def _configs(kw: dict[str, Any]) -> tuple[Any, Any]:
    from sysid.groundeffect import MODEL_NAMES, FitConfig, GroundEffectDataConfig

    columns, units = kw["columns"] or {}, kw["units"] or {}
    for mapping, what in ((columns, "--columns"), (units, "--units")):
        extra = set(mapping) - {"height", "thrust"}
        if extra:
            raise click.BadParameter(f"{', '.join(sorted(extra))}: only height= and thrust= are known", param_hint=what)
    data = GroundEffectDataConfig(
        rotor_radius_m=kw["rotor_radius"],
        f0_n=kw["f0"],
        height_column=columns.get("height", "height_m"),
        thrust_column=columns.get("thrust", "thrust_n"),
        height_unit=units.get("height"),
        thrust_unit=units.get("thrust"),
        kf_n_per_count=kw["kf"],
        mass_kg=kw["mass"],
        pwm_full_scale=kw["pwm_full_scale"],
        rotor_offset_m=kw["rotor_offset"],
        min_hold_s=kw["min_hold"],
    )
    return data, FitConfig(models=kw["models"] or MODEL_NAMES, criterion=kw["criterion"], confidence=kw["confidence"])


@click.group("ground-effect", epilog=_GROUP_EPILOG)
def ground_effect() -> None:
    """Ground-effect models of chapter 2: thrust ratio F/F0 against height ratio Z/R."""


@ground_effect.command("fit", cls=SysidCommand, epilog=_FIT_EPILOG)
@click.argument("data", type=click.Path(exists=True, dir_okay=False, path_type=Path))
@_data_options
@click.option(
    "-o",
    "--out",
    type=OutputPath(),
    help="Write the chosen model (and the fit summary) as JSON, for `sysid mrac compare --ground-effect`.",
)
@click.option("--report", type=OutputPath(), help="Write an HTML report.")
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no table.")
def fit(data: Path, out: Path | None, report: Path | None, json_path: str | None, quiet: bool, **kw: Any) -> None:
    """Fit the ground-effect laws to DATA and choose one by AICc or BIC.

    DATA is a rig CSV (height_m, thrust_n) or a flight log with hover steps near the ground
    (F = weight, F0 = sum k_f PWM, eq. 2.6). The laws: Cheeseman-Bennett (eq. 2.1), corrected with
    rho (2.2), exponential (2.3) and piecewise linear (the form of 2.5)."""
    from sysid.groundeffect import fit_ground_effect, fit_summary, load_thrust_ratio, write_ground_effect_model

    data_config, fit_config = _configs(kw)
    with progress_bar("reading", unit="bytes", quiet=quiet) as bar:
        points = load_thrust_ratio(
            data, data_config, progress=bar, reading=reading_from(kw["table_map"], kw["vehicle"])
        )
    result = fit_ground_effect(points, fit_config)
    if out is not None:
        write_ground_effect_model(result, out)
    if report is not None:
        from reports.groundeffect_report import write_groundeffect_report

        write_groundeffect_report(result, report)
    summary = fit_summary(result)
    summary["outputs"] = {"model": str(out) if out else None, "report": str(report) if report else None}
    if not quiet:
        _print_fit(summary)
    emit_json(summary, json_path)


@ground_effect.command("spacing", cls=SysidCommand, epilog=_SPACING_EPILOG)
@click.argument("data", nargs=-1, required=True, type=click.Path(exists=True, dir_okay=False, path_type=Path))
@click.option(
    "--spacing",
    "spacing_mm",
    callback=_float_list,
    required=True,
    metavar="MM,...",
    help="Rotor-spacing increment of each DATA file, mm, in the same order.",
)
@click.option(
    "--rotors",
    type=click.IntRange(min=2),
    cls=LibraryDefault,
    default_from=("sysid.groundeffect.spacing", "spacing_study", "rotors"),
    show_default=True,
    help="Rotors running: 2 reports rho of eq. 2.2; more compares piecewise linear with eq. 2.2.",
)
@_data_options
@click.option("--report", type=OutputPath(), help="Write an HTML report.")
@json_option
@click.option("-q", "--quiet", is_flag=True, help="No progress bar and no table.")
def spacing(
    data: tuple[Path, ...],
    spacing_mm: list[float],
    rotors: int,
    report: Path | None,
    json_path: str | None,
    quiet: bool,
    **kw: Any,
) -> None:
    """Compare rotor spacings: fit each DATA file and find where piecewise linear gives way to eq. 2.2.

    One DATA file per spacing (--spacing, mm, same order); with 2 rotors rho of eq. 2.2 is reported
    per spacing (Table 2.2), with more the two families are compared (Table 2.3)."""
    from sysid.groundeffect import load_thrust_ratio, spacing_study, spacing_summary

    _check_spacings(spacing_mm, data)
    data_config, fit_config = _configs(kw)
    with progress_bar("fitting", quiet=quiet) as bar:
        datasets = [
            load_thrust_ratio(path, data_config, reading=reading_from(kw["table_map"], kw["vehicle"])) for path in data
        ]
        study = spacing_study(datasets, [s * 1e-3 for s in spacing_mm], rotors=rotors, config=fit_config, progress=bar)
    if report is not None:
        from reports.groundeffect_report import write_spacing_report

        write_spacing_report(study, report)
    summary = spacing_summary(study)
    summary["outputs"] = {"report": str(report) if report else None}
    if not quiet:
        _print_spacing(summary)
    emit_json(summary, json_path)


def _check_spacings(spacing_mm: list[float], data: tuple[Path, ...]) -> None:
    """Usage error (naming --spacing, in mm) unless there is one distinct, non-negative spacing per file."""
    if len(data) < 2:
        raise click.UsageError("a spacing study compares at least two DATA files, one per spacing")
    if len(spacing_mm) != len(data):
        raise click.BadParameter(f"{len(data)} files but {len(spacing_mm)} spacings", param_hint="'--spacing'")
    bad = [s for s in spacing_mm if not (math.isfinite(s) and s >= 0)]
    if bad:
        raise click.BadParameter(f"{bad[0]:g} mm: spacings must be finite and not negative", param_hint="'--spacing'")
    repeated = sorted({s for s in spacing_mm if spacing_mm.count(s) > 1})
    if repeated:
        raise click.BadParameter(
            f"{', '.join(f'{s:g}' for s in repeated)} mm given twice: each DATA file needs its own spacing",
            param_hint="'--spacing'",
        )


def _print_fit(summary: dict[str, Any]) -> None:
    say = click.echo
    say(f"{summary['source']}: {summary['n_points']} points, F0 {summary['f0_source']}")
    criterion = {"aicc": "AICc", "bic": "BIC"}[summary["criterion"]]
    say(f"  {'model':<18} {'RMSE T/T∞':>9} {'R2':>8} {'d' + criterion:>8}  parameters (of z/R, T/T∞: unitless)")
    for name, model in summary["models"].items():
        params = ", ".join(
            f"{n} {v:.5g} [{lo:.4g}, {hi:.4g}]"
            for (n, v), (lo, hi) in zip(model["params"].items(), model["ci"].values())
        )
        mark = "*" if name == summary["best"] else " "
        say(f"{mark} {name:<18} {model['rmse']:>9.4f} {model['r2']:>8.4f} {model['delta']:>8.2f}  {params or '-'}")
    say(f"chosen: {summary['best']} (lowest {criterion})")
    for key, path in summary["outputs"].items():
        if path:
            say(f"wrote {key} {path}")


def _print_spacing(summary: dict[str, Any]) -> None:
    say = click.echo
    families = summary["families"]
    say(f"{'spacing mm':>10}  " + "  ".join(f"{'R2 ' + f:>20}" for f in families) + "  chosen")
    for entry in summary["sets"]:
        r2 = "  ".join(f"{entry['models'][f]['r2']:>20.4f}" for f in families)
        say(f"{entry['spacing_mm']:>10g}  {r2}  {entry['chosen']}")
    if len(families) > 1:
        transition = summary["transition_mm"]
        say(
            f"transition {families[0]} -> {families[-1]}: "
            + (f"at {transition:g} mm" if transition is not None else "none found")
        )
    if summary["outputs"]["report"]:
        say(f"wrote report {summary['outputs']['report']}")
