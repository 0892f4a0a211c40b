"""Built-in flights: the demo's sweep + doublet flight in light wind."""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

from simulator.autopilot.excitation import Axis, Maneuver
from simulator.flights.linear import WindField, simulate_hover
from simulator.output.ardupilot import AnemometerSetup, write_anemometer_csv, write_ardupilot_log, write_truth
from simulator.vehicle.identified import CALM_HOVER, LIGHT_WIND_TERMS

__all__ = ["DEMO_ANEMOMETER_DISTANCE_M", "FlightFiles", "demo_maneuvers", "write_demo_flight"]

_DEMO_UTC = datetime(2024, 5, 1, 10, 0, 0, tzinfo=UTC)

#: The demo's ground anemometer stands this far upstream of the vehicle, m (the dissertation's set-up).
DEMO_ANEMOMETER_DISTANCE_M = 4.6


@dataclass(frozen=True, slots=True, kw_only=True)
class FlightFiles:
    """The files one simulated flight leaves behind.

    Parameters
    ----------
    log : Path
        ArduPilot DataFlash log.
    wind_csv : Path
        Ground anemometer record.
    truth : Path
        JSON of what the files conceal (parameters, maneuvers, delays, offsets).
    """

    log: Path
    wind_csv: Path
    truth: Path


def demo_maneuvers() -> tuple[Maneuver, ...]:
    """One 34 s sweep (0.1-10 Hz, 5 s fade-in) and one 2 s doublet per axis, with hover between.

    Returns
    -------
    tuple of Maneuver

    Amplitudes are in % of the mixer input, as the dissertation logs it.
    """
    plan = []
    start = 6.0
    # doublets sized well above the gust-driven control activity (about 2.5 % RMS), as a test engineer would
    amplitudes: tuple[tuple[Axis, float, float], ...] = (
        ("lon", 8.0, 15.0),
        ("lat", 8.0, 15.0),
        ("yaw", 10.0, 15.0),
        ("thr", 4.0, 8.0),
    )
    for axis, sweep_pct, doublet_pct in amplitudes:
        plan.append(Maneuver(axis=axis, kind="sweep", start_s=start, amplitude=sweep_pct, duration_s=34.0))
        plan.append(Maneuver(axis=axis, kind="doublet", start_s=start + 40.0, amplitude=doublet_pct, duration_s=2.0))
        start += 50.0
    return tuple(plan)


def write_demo_flight(
    folder: str | Path, *, seed: int = 1, clock_offset_s: float = 1.5, utc_start: datetime = _DEMO_UTC
) -> FlightFiles:
    """Simulate the demo flight (calm Table 3.3 model with Table 3.5 light-wind terms) and write its files.

    Parameters
    ----------
    folder : str or Path
        Destination folder (created if needed).
    seed : int, optional
        Seed of the gusts and sensor noise.
    clock_offset_s : float, optional
        How far the anemometer's clock is ahead of UTC, s.
    utc_start : datetime, optional
        UTC of the flight's first sample.

    Returns
    -------
    FlightFiles
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    maneuvers = demo_maneuvers()
    duration = maneuvers[-1].end_s + 6.0
    flight = simulate_hover(
        duration,
        maneuvers,
        parameters=CALM_HOVER,
        wind=WindField(mean_speed_m_s=2.7, direction_from_deg=300.0, turbulence_ratio=0.2),
        wind_terms=LIGHT_WIND_TERMS,
        seed=seed,
    )
    setup = AnemometerSetup(distance_m=DEMO_ANEMOMETER_DISTANCE_M, rate_hz=20.0, clock_offset_s=clock_offset_s)
    return FlightFiles(
        log=write_ardupilot_log(flight, folder / "flight.bin", utc_start=utc_start),
        wind_csv=write_anemometer_csv(flight, folder / "anemometer.csv", utc_start=utc_start, setup=setup),
        truth=write_truth(flight, folder / "truth.json", utc_start=utc_start, setup=setup),
    )
