"""Write a case's files: the log, the anemometer CSV, the truth (JSON) and the true segments (CSV)."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any, Literal

import numpy as np

from flightlogs.writers import atomic_output
from independent_sim.ardupilot_log import write_ardupilot
from independent_sim.flight import Flight, ManeuverTruth
from independent_sim.px4_log import write_px4
from independent_sim.scenario import Case, LogFormat
from independent_sim.simulate import simulate
from independent_sim.wind import write_anemometer_csv

__all__ = ["PARAMETER_UNITS", "Truth", "CaseFiles", "write_case", "truth_of"]

#: Unit of each parameter of ``hover`` / ``hover-wind`` (control derivatives per logged mixer unit).
PARAMETER_UNITS: Mapping[str, str] = MappingProxyType(
    {
        "X_u": "1/s",
        "M_u": "rad/(m s)",
        "X_lon": "m/s^2 per delta_lon (normalised)",
        "M_lon": "rad/s^2 per delta_lon (normalised)",
        "Y_v": "1/s",
        "L_v": "rad/(m s)",
        "Y_lat": "m/s^2 per delta_lat (normalised)",
        "L_lat": "rad/s^2 per delta_lat (normalised)",
        "N_r": "1/s",
        "N_yaw": "rad/s^2 per delta_yaw (normalised)",
        "Z_w": "1/s",
        "Z_thr": "m/s^2 per delta_thr (normalised)",
        "T_a": "s",
        "tau_lat": "s",
        "tau_lon": "s",
        "tau_yaw": "s",
        "tau_thr": "s",
        "X_w_lon": "1/s",
        "Z_w_lon": "1/s",
        "tau_w_lon": "s",
        "tau_w_thr": "s",
    }
)


@dataclass(frozen=True, slots=True, kw_only=True)
class Truth:
    """What a correct tool must find in a case's log.

    Parameters
    ----------
    case : str
        Case name.
    fmt : {"ulog", "dataflash"}
        Log format.
    seed : int
        Seed the case was drawn with.
    structure : {"hover", "hover-wind"}
        The workbench structure the truth is expressed in.
    parameters : Mapping[str, float]
        True value of every parameter of `structure`, units in
        :data:`PARAMETER_UNITS` (control derivatives per unit of the logged
        mixer input: Table 3.3 × 100).
    hover_parameters : Mapping[str, float]
        The same restricted to ``hover`` (what a fit without wind should
        approach in calm air).
    trim : Mapping[str, float]
        ``U0 W0`` m/s, ``theta0 psi0`` rad, mixer trims as logged.
    maneuvers : tuple of ManeuverTruth
        Every maneuver, bounds on the log clock (the readers' ``time_s``).
    unexcited_axes : tuple of str
        Mixer axes no maneuver excites.
    takeoff_s, touchdown_s : float
        Airborne span on the log clock, s.
    controller : Mapping[str, float]
        Gains and rate of the closed loop (not logged as such).
    wind : Mapping[str, float or None] or None
        When the case has wind: ``mean_speed_m_s``, ``from_deg``,
        ``sigma_m_s``, ``distance_m``, ``transport_delay_s`` (s),
        ``anemometer_rate_hz``, ``speed_noise_m_s``, ``direction_noise_deg``;
        ``clock_offset_s``, the anemometer logger's clock minus UTC, s
        (positive: it runs ahead; its stamps are true UTC plus this); and
        ``estimate_time_constant_s``, the time constant of the first-order lag
        of the autopilot's logged wind estimate behind the true wind at the
        vehicle, s (None, JSON null: the log has no estimate).
    utc_offset_s : float
        UTC minus log clock, s.
    """

    case: str
    fmt: LogFormat
    seed: int
    structure: str
    parameters: Mapping[str, float]
    hover_parameters: Mapping[str, float]
    trim: Mapping[str, float]
    maneuvers: tuple[ManeuverTruth, ...]
    unexcited_axes: tuple[str, ...]
    takeoff_s: float
    touchdown_s: float
    controller: Mapping[str, float]
    wind: Mapping[str, float | None] | None
    utc_offset_s: float

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (units alongside the parameters)."""
        return {
            "case": self.case,
            "format": self.fmt,
            "seed": self.seed,
            "structure": self.structure,
            "parameters": dict(self.parameters),
            "hover_parameters": dict(self.hover_parameters),
            "units": {name: PARAMETER_UNITS[name] for name in self.parameters},
            "mixer_units": "PX4 torque setpoint / ArduPilot RATE out: -1..1; thrust 0..1; "
            "control derivatives = Table 3.3 (per %) x 100",
            "trim": dict(self.trim),
            "maneuvers": [asdict(m) for m in self.maneuvers],
            "unexcited_axes": list(self.unexcited_axes),
            "takeoff_s": self.takeoff_s,
            "touchdown_s": self.touchdown_s,
            "controller": dict(self.controller),
            "wind": None if self.wind is None else dict(self.wind),
            "utc_offset_s": self.utc_offset_s,
        }


@dataclass(frozen=True, slots=True, kw_only=True)
class CaseFiles:
    """The files written for a case.

    Parameters
    ----------
    log : Path
        The ``.ulg`` or ``.bin``.
    truth_json : Path
        :class:`Truth` as JSON.
    segments_csv : Path
        True maneuvers as a ``--segments`` file (``start_s,end_s,axis,kind,f_min_hz,f_max_hz``).
    anemometer_csv : Path or None
        The anemometer record, when the case has wind.
    truth : Truth
        The truth itself.
    expected : Mapping[str, tuple[ndarray, ndarray]]
        For each canonical signal in the log, the ``(time_s, values)`` the
        workbench's reader must return.
    """

    log: Path
    truth_json: Path
    segments_csv: Path
    anemometer_csv: Path | None
    truth: Truth
    expected: Mapping[str, tuple[np.ndarray, np.ndarray]] = field(repr=False)


def truth_of(flight: Flight) -> Truth:
    """The :class:`Truth` of a flown case.

    Parameters
    ----------
    flight : Flight
        The flown case.

    Returns
    -------
    Truth
    """
    case, plant = flight.case, flight.plant
    structure: Literal["hover", "hover-wind"] = "hover-wind" if plant.has_wind_terms else "hover"
    trim = plant.trim
    wind: dict[str, float | None] | None = None
    if case.wind is not None:
        model = case.wind
        wind = {
            "mean_speed_m_s": model.mean_speed_m_s,
            "from_deg": model.from_deg,
            "sigma_m_s": model.sigma_m_s,
            "distance_m": model.distance_m,
            "transport_delay_s": model.transport_delay_s,
            "anemometer_rate_hz": model.anemometer_rate_hz,
            "speed_noise_m_s": model.speed_noise_m_s,
            "direction_noise_deg": model.direction_noise_deg,
            "clock_offset_s": model.clock_offset_s,
            "estimate_time_constant_s": model.estimate_time_constant_s,
        }
    airborne = np.flatnonzero(flight.airborne)
    return Truth(
        case=case.name,
        fmt=flight.fmt,
        seed=case.seed,
        structure=structure,
        parameters=MappingProxyType(plant.parameters(structure)),
        hover_parameters=MappingProxyType(plant.parameters("hover")),
        trim=MappingProxyType(
            {
                "U0": trim.U0,
                "W0": trim.W0,
                "theta0": trim.theta0,
                "psi0": float(math.remainder(trim.psi0, 2 * math.pi)),
                "delta_lat": trim.delta_lat,
                "delta_lon": trim.delta_lon,
                "delta_yaw": trim.delta_yaw,
                "delta_thr": trim.delta_thr,
            }
        ),
        maneuvers=flight.maneuvers,
        unexcited_axes=tuple(a for a in ("lat", "lon", "yaw", "thr") if a not in case.excited_axes),
        takeoff_s=float(flight.time_s[airborne[0]]),
        touchdown_s=float(flight.time_s[airborne[-1]]),
        controller=MappingProxyType(dict(asdict(flight.gains))),
        wind=None if wind is None else MappingProxyType(wind),
        utc_offset_s=flight.utc_offset_s,
    )


def _segments_text(maneuvers: tuple[ManeuverTruth, ...]) -> str:
    lines = ["start_s,end_s,axis,kind,f_min_hz,f_max_hz"]
    for m in maneuvers:
        band = f"{m.f_min_hz:g},{m.f_max_hz:g}" if m.f_min_hz is not None else ","
        lines.append(f"{m.start_s:.4f},{m.end_s:.4f},{m.axis},{m.kind},{band}")
    return "\n".join(lines) + "\n"


def write_case(case: Case, out_dir: Path, fmt: LogFormat | None = None) -> CaseFiles:
    """Fly `case` and write its log, truth, segments and (with wind) anemometer files.

    Parameters
    ----------
    case : Case
        The case.
    out_dir : Path
        Existing folder; files are named after the case
        (``<name>.ulg`` or ``<name>.bin``, ``<name>.truth.json``,
        ``<name>.segments.csv``, ``<name>.anemometer.csv``).
    fmt : {"ulog", "dataflash"}, optional
        Format (and autopilot profile); the case's own by default.

    Returns
    -------
    CaseFiles

    Examples
    --------
    >>> import tempfile
    >>> from independent_sim.catalogue import case_named
    >>> files = write_case(case_named("heldout-ap-hover"), Path(tempfile.mkdtemp()))
    >>> files.log.suffix, files.truth.maneuvers, files.truth.unexcited_axes
    ('.bin', (), ('lat', 'lon', 'yaw', 'thr'))
    """
    fmt = fmt or case.fmt
    out_dir = Path(out_dir)
    flight = simulate(case, fmt)
    stem = out_dir / case.name
    log = stem.with_suffix(".ulg" if fmt == "ulog" else ".bin")
    expected = write_px4(flight, log) if fmt == "ulog" else write_ardupilot(flight, log)
    truth = truth_of(flight)
    truth_json = out_dir / f"{case.name}.truth.json"
    with atomic_output(truth_json) as tmp:
        tmp.write_text(json.dumps(truth.to_json(), indent=2) + "\n", encoding="utf-8")
    segments_csv = out_dir / f"{case.name}.segments.csv"
    with atomic_output(segments_csv) as tmp:
        tmp.write_text(_segments_text(truth.maneuvers), encoding="utf-8")
    anemometer = None
    if flight.wind is not None:
        anemometer = out_dir / f"{case.name}.anemometer.csv"
        write_anemometer_csv(
            anemometer,
            flight.wind,
            log_start_s=float(flight.time_s[0]),
            log_end_s=float(flight.time_s[-1]),
            utc_offset_s=flight.utc_offset_s,
            rng=np.random.default_rng(case.seed + 1),
        )
    return CaseFiles(
        log=log,
        truth_json=truth_json,
        segments_csv=segments_csv,
        anemometer_csv=anemometer,
        truth=truth,
        expected=MappingProxyType(expected),
    )
