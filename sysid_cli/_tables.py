"""The terminal tables of the commands, one owner each: ingest, fit (and modes), validate; the demo prints them too."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import click

from ._flags import as_flags
from ._warnings import grouped, mark_reported

if TYPE_CHECKING:
    from sysid.fit import Guidelines

__all__ = ["print_ingest", "print_fit", "print_modes", "print_validation", "print_discrepancy"]


def print_ingest(summary: dict[str, Any]) -> None:
    """The ingest's table (`summary` as from :func:`flightlogs.store.campaign_summary`): each log's signals
    with rate and unit, the wind alignment, records and maneuvers, then its warnings grouped."""
    say = click.echo
    for entry in summary["logs"]:
        say(
            f"{entry['path']}: {entry['autopilot']} {entry['log_format']}, "
            f"{entry['vehicle'] or 'vehicle unknown'}, {entry['duration_s']:.1f} s"
            + (f", starts {entry['utc_start']}" if entry["utc_start"] else ", no GPS time")
        )
        say(f"  {'signal':<11} {'samples':>8} {'rate Hz':>8}  {'unit':<20} source")
        for name, info in entry["signals"].items():
            say(f"  {name:<11} {info['samples']:>8} {info['rate_hz']:>8.1f}  {info['unit']:<20} {info['source']}")
        if entry["missing"]:
            say(f"  missing: {', '.join(entry['missing'])}")
        alignment = entry.get("wind_alignment")
        if alignment:
            say(
                f"  wind {alignment['wind_file']}: clock offset {alignment['clock_offset_s']:+.3f} s "
                f"({alignment['clock_offset_source']}), transport delay {alignment['transport_delay_s']:.3f} s "
                f"({alignment['transport_delay_source']}"
                + (f", {alignment['distance_m']:.2f} m" if alignment["distance_m"] is not None else "")
                + f"), mean {alignment['mean_speed_m_s']:.2f} m/s"
            )
            if alignment["residual_offset_s"] is not None:
                say(
                    f"    residual clock offset {alignment['residual_offset_s']:+.3f} s against "
                    f"{alignment['residual_against']}, modelled as lagging the air by a first-order "
                    f"{alignment['residual_lag_modelled_s']:g} s (correlation {alignment['residual_correlation']:.2f})"
                )
        for record in entry.get("records", []):
            say(
                f"  record {record['label']}: {record['start_s']:.2f}-{record['end_s']:.2f} s, "
                f"{record['samples']} samples at {entry['rate_hz']:.0f} Hz"
            )
        for segment in entry.get("segments", []):
            axis = segment["axis"] or "-"
            say(
                f"  {segment['kind']:<8} {axis:<4} {segment['start_s']:8.2f}-{segment['end_s']:8.2f} s  ({segment['source']})"
            )
        if "segments" in entry and all(s["kind"] == "hover" for s in entry["segments"]):
            hovers = len(entry["segments"])
            say(
                "  no maneuver found (no sweep, doublet, 3-2-1-1, multisine or pilot's broadband input)"
                + (f"; {hovers} hover stretch{'es' if hovers > 1 else ''}" if hovers else "")
            )
        for warning in grouped(entry["warnings"]):
            say(f"  warning: {as_flags(warning)}")
        mark_reported(entry["warnings"])
    if summary["output"]:
        say(f"wrote {summary['output']}")


def _fmt(value: float | None, spec: str = ".3g") -> str:
    return "-" if value is None else format(value, spec)


def _value(value: float | None) -> str:
    """A parameter value for the table: "—" when it has none (unidentified)."""
    return "—" if value is None or not math.isfinite(value) else format(value, ".5g")


def print_modes(rows: list[dict[str, Any]], say: Any) -> None:
    """Print a modes table (rows as from :func:`sysid.fit.mode_summary`) through `say`."""
    say(f"  {'mode':<9} {'eigenvalue 1/s':>22} {'damping':>8} {'omega_n rad/s':>13} {'t2 / t1/2 s':>11}  stability")
    for m in rows:
        pair = f"{m['real']:.4g} ± {m['imag']:.4g}i" if m["imag"] > 0 else f"{m['real']:.4g}"
        time = m["time_to_double_s"] if m["time_to_double_s"] is not None else m["time_to_half_s"]
        say(
            f"  {m['mode']:<9} {pair:>22} {_fmt(m['damping']):>8} {m['natural_frequency_rad_s']:>13.4g} "
            f"{_fmt(time):>11}  {m['stability']}"
        )


def print_fit(summary: dict[str, Any], guidelines: Guidelines) -> None:
    """The fit's table (`summary` as from :func:`sysid.fit.fit_summary`): parameters with their units, costs,
    reduction, the wind step, the modes, notes and the verdict."""
    say = click.echo
    say(
        f"model {summary['model']}: J_ave = {summary['cost']['average']:.2f} (guideline <= {guidelines.j_average_good:g})"
    )
    say(f"  {'parameter':<11} {'value':>11} {'CR%':>7} {'I%':>7}  {'status':<12} unit")
    for name, p in summary["parameters"].items():
        misses = guidelines.misses_cr(p["cr_percent"] or 0) or guidelines.misses_insensitivity(
            p["insensitivity_percent"] or 0
        )
        flag = " !" if misses else ""
        say(
            f"  {name:<11} {_value(p['value']):>11} {_fmt(p['cr_percent'], '.2f'):>7} "
            f"{_fmt(p['insensitivity_percent'], '.2f'):>7}  {p['status'] + flag:<12} {p['unit']}"
        )
    for axis in summary["axes"]:
        if axis["status"] != "identified":
            say(f"  axis {axis['axis']} unidentified: {axis['reason']}; its parameters have no value")
    say("  response costs: " + ", ".join(f"{k} {v:.1f}" for k, v in summary["cost"]["responses"].items()))
    for step in summary["reduction"]:
        say(f"  reduction {step['step']}: {step['parameter']} {step['action']} ({step['reason']})")
    if summary["wind"]:
        w = summary["wind"]
        say(
            "  wind step residual RMS: "
            + ", ".join(
                f"{o} {b:.3g} -> {a:.3g} {u}".rstrip()
                for o, b, a, u in zip(w["outputs"], w["rms_before"], w["rms_after"], w["units"])
            )
        )
    print_modes(summary["eigenvalues"], say)
    for note in summary["notes"]:
        say(f"  note: {as_flags(note)}")
    say(f"verdict: {summary['verdict']['sentence']}")
    for key in ("output", "mat", "report"):
        if summary.get(key):
            say(f"wrote {summary[key]}")


def print_validation(summary: dict[str, Any]) -> None:
    """The verification's table (`summary` as ``sysid validate --json`` gives it): each output's RMS error
    in its unit and TIC, with the wind term's change, then the notes."""
    say = click.echo
    say(f"{summary['model']}: {len(summary['records'])} records, each judged on the outputs of its axis")
    wind = summary.get("wind_correction", {})
    header = f"  {'output':<8} {'unit':<8} {'RMS error':>10} {'TIC':>6}"
    band = next((c["band_hz"] for c in wind.values() if c["band_hz"] is not None), None)
    in_band = f"< {band:g} Hz" if band is not None else ""
    say(header + (f" {'without G_w':>12} {'reduction':>9}" + (f" {in_band:>9}" if in_band else "") if wind else ""))
    for name, row in summary["summary"].items():
        line = f"  {name:<8} {row['unit']:<8} {row['rmse']:>10.4g} {row['tic']:>6.2f}"
        if name in wind and wind[name]["reduction_percent"] is not None:
            line += f" {wind[name]['rmse_without']:>12.4g} {wind[name]['reduction_percent']:>8.1f}%"
            if in_band and wind[name]["reduction_in_band_percent"] is not None:
                line += f" {wind[name]['reduction_in_band_percent']:>8.1f}%"
        say(line)
    for note in summary["notes"]:
        say(f"  note: {as_flags(note)}")
    if summary["off_axis"]:
        say(
            "  off-axis (not judged): "
            + ", ".join(f"{name} TIC {row['tic']:.2f}" for name, row in summary["off_axis"].items())
        )
    for path in (summary["output"], summary["report"]):
        if path:
            say(f"wrote {path}")


def print_discrepancy(result: Any) -> None:
    """The discrepancy search's verdict and findings (`result` a :class:`sysid.discrepancy.DiscrepancyResult`):
    each effect with the held-out cut of the residual it removes, in %, and its evidence."""
    click.echo(f"verdict: {result.verdict}")
    for finding in result.findings:
        cut = f"{finding.improvement_percent:5.1f} % held-out" if finding.modelled else "located only    "
        click.echo(f"  {finding.effect:14s} {cut}  {finding.evidence}")
    if not result.findings:
        click.echo(f"  {result.summary}")
