"""A fleet's flight-test campaign: several vehicles, each flown on several days, one of them wearing out.

Every flight flies the demo's test card (a sweep and a doublet per axis,
:func:`~simulator.campaign.demo_flight.demo_maneuvers`) in a light, gusty
wind. The vehicles are the chapter 3 octocopter built with a scatter of a
few percent in each derivative; one vehicle's motors lose thrust
effectiveness progressively from a given flight on (its collective control
derivative ``Z_thr`` shrinks), and one log is damaged on the card. The truth
(each log's vehicle, day, parameters and thrust loss) goes to ``truth.json``;
the operator's own record of which vehicle flew which log, to ``fleet.csv``.
All the flights are integrated together (:func:`~simulator.flights.linear.simulate_hovers`),
a batch at a time, so two hundred of them take seconds, not minutes.
"""

from __future__ import annotations

import csv
from collections.abc import Callable
from dataclasses import asdict, dataclass
from datetime import UTC, date, datetime, timedelta
from pathlib import Path

import numpy as np

from flightlogs.writers.atomic import atomic_output
from flightlogs.writers.jsonio import write_json
from simulator.campaign.demo_flight import demo_maneuvers
from simulator.flights.linear import HoverSetup, WindField, simulate_hovers
from simulator.output.ardupilot import write_ardupilot_log
from simulator.vehicle.identified import CALM_HOVER

__all__ = ["FleetPlan", "FleetFiles", "write_fleet", "fleet_log_name"]

#: Derivatives that scatter from vehicle to vehicle (the time constants and delays are the same parts).
_SCATTERED = ("X_u", "M_u", "X_lon", "M_lon", "Y_v", "L_v", "Y_lat", "L_lat", "N_yaw", "Z_thr")


@dataclass(frozen=True, slots=True, kw_only=True)
class FleetPlan:
    """Who flies what in the fleet's campaign.

    Parameters
    ----------
    vehicles : int
        Number of vehicles, ``V01`` ... .
    flights : int
        Flights per vehicle, one a day, ``F01`` ... .
    degrading_vehicle : int
        The vehicle (1-based) whose motors wear out.
    degradation_starts : int
        Its first flight (1-based) with less thrust effectiveness.
    first_loss : float
        Fraction of ``Z_thr`` lost at that flight (a propeller chipped, a bearing worn) ...
    loss_per_flight : float
        ... and the fraction lost more at each flight after it (0.25 and 0.05: 75 %, 70 %, 65 %, ...
        of the healthy value).
    corrupted : tuple of (int, int) or None
        ``(vehicle, flight)`` whose log is damaged (its first 64 kB zeroed, the
        message formats lost), or None.
    scatter : float
        Relative standard deviation of each derivative across vehicles.
    first_day : date
        The day of every vehicle's first flight.
    seed : int
        Seed of the vehicles' scatter, the winds and the sensor noise.
    """

    vehicles: int = 20
    flights: int = 10
    degrading_vehicle: int = 3
    degradation_starts: int = 5
    first_loss: float = 0.25
    loss_per_flight: float = 0.05
    corrupted: tuple[int, int] | None = (12, 3)
    scatter: float = 0.04
    first_day: date = date(2024, 6, 3)
    seed: int = 0

    def thrust_loss(self, vehicle: int, flight: int) -> float:
        """Fraction of its thrust effectiveness `vehicle` has lost at `flight` (both 1-based)."""
        if vehicle != self.degrading_vehicle or flight < self.degradation_starts:
            return 0.0
        return self.first_loss + self.loss_per_flight * (flight - self.degradation_starts)


@dataclass(frozen=True, slots=True, kw_only=True)
class FleetFiles:
    """What :func:`write_fleet` wrote.

    Parameters
    ----------
    logs : tuple of Path
        Every log, vehicle by vehicle, flight by flight (the damaged one included).
    mapping_csv : Path
        ``file, vehicle, date, payload_kg`` of each log, as an operator keeps them.
    truth : Path
        JSON of the plan and, per log, its vehicle, flight, day, board id, parameters and thrust loss.
    """

    logs: tuple[Path, ...]
    mapping_csv: Path
    truth: Path


def fleet_log_name(vehicle: int, flight: int) -> str:
    """The file name of a vehicle's flight: ``V03_F05.bin``.

    Parameters
    ----------
    vehicle, flight : int
        Both 1-based.
    """
    return f"V{vehicle:02d}_F{flight:02d}.bin"


def write_fleet(
    folder: str | Path,
    plan: FleetPlan = FleetPlan(),
    *,
    batch: int = 40,
    progress: Callable[[int, int], None] | None = None,
) -> FleetFiles:
    """Fly the fleet's campaign and write its logs, the operator's mapping file and the truth.

    Parameters
    ----------
    folder : str or Path
        Destination; each vehicle's logs go to a folder of its own (``V03/V03_F05.bin``).
    plan : FleetPlan, optional
        The campaign.
    batch : int, optional
        Flights integrated together (memory grows with it: about 12 MB a flight).
    progress : callable, optional
        ``progress(done, total)`` in logs written.

    Returns
    -------
    FleetFiles
    """
    folder = Path(folder)
    rng = np.random.default_rng(plan.seed)
    vehicles = [_vehicle_parameters(rng, plan.scatter) for _ in range(plan.vehicles)]
    boards = [
        f"CubeOrange {0x00340032 + v:08X} {rng.integers(2**32):08X} {rng.integers(2**32):08X}"
        for v in range(plan.vehicles)
    ]
    payloads = [float(rng.choice([0.0, 0.5, 1.0])) for _ in range(plan.vehicles)]
    cards = [(v + 1, f + 1) for v in range(plan.vehicles) for f in range(plan.flights)]
    maneuvers = demo_maneuvers()
    duration = maneuvers[-1].end_s + 6.0
    entries: list[dict[str, object]] = []
    logs: list[Path] = []
    for lo in range(0, len(cards), batch):
        part = cards[lo : lo + batch]
        setups = [_setup(plan, vehicles[v - 1], v, f, rng) for v, f in part]
        for (v, f), setup, flight in zip(part, setups, simulate_hovers(duration, maneuvers, setups)):
            day = plan.first_day + timedelta(days=f - 1)
            utc_start = datetime(day.year, day.month, day.day, 9 + v % 8, 7 * v % 60, tzinfo=UTC)
            path = folder / f"V{v:02d}" / fleet_log_name(v, f)
            path.parent.mkdir(parents=True, exist_ok=True)
            write_ardupilot_log(flight, path, utc_start=utc_start, board_id=boards[v - 1])
            if plan.corrupted == (v, f):
                _damage(path)
            logs.append(path)
            entries.append(
                {
                    "file": str(path.relative_to(folder)),
                    "vehicle": f"V{v:02d}",
                    "flight": f,
                    "date": day.isoformat(),
                    "utc_start": utc_start.isoformat(),
                    "board_id": boards[v - 1],
                    "payload_kg": payloads[v - 1],
                    "thrust_loss": plan.thrust_loss(v, f),
                    "corrupted": plan.corrupted == (v, f),
                    "parameters": dict(setup.parameters),
                }
            )
            if progress is not None:
                progress(len(logs), len(cards))
    mapping = folder / "fleet.csv"
    with atomic_output(mapping) as tmp, tmp.open("w", newline="") as stream:
        writer = csv.writer(stream)
        writer.writerow(["file", "vehicle", "date", "payload_kg"])
        writer.writerows([e["file"], e["vehicle"], e["date"], e["payload_kg"]] for e in entries)
    plan_dict = asdict(plan) | {"first_day": plan.first_day.isoformat()}
    truth = write_json(folder / "truth.json", {"plan": plan_dict, "logs": entries})
    return FleetFiles(logs=tuple(logs), mapping_csv=mapping, truth=truth)


def _vehicle_parameters(rng: np.random.Generator, scatter: float) -> dict[str, float]:
    """The calm hover model with each derivative scattered by `scatter` (relative, 1 sigma)."""
    out = dict(CALM_HOVER)
    for name in _SCATTERED:
        out[name] *= 1.0 + scatter * float(rng.standard_normal())
    return out


def _setup(
    plan: FleetPlan, healthy: dict[str, float], vehicle: int, flight: int, rng: np.random.Generator
) -> HoverSetup:
    """One flight: the vehicle's airframe less its thrust loss, a light gusty wind from anywhere."""
    parameters = dict(healthy)
    parameters["Z_thr"] *= 1.0 - plan.thrust_loss(vehicle, flight)
    wind = WindField(
        mean_speed_m_s=float(rng.uniform(0.5, 1.5)), direction_from_deg=float(rng.uniform(0, 360)), turbulence_ratio=0.2
    )
    return HoverSetup(parameters=parameters, wind=wind, seed=int(rng.integers(2**31)))


def _damage(path: Path) -> None:
    """Zero the first 64 kB of a log (a card whose first blocks were lost): its message formats are gone."""
    data = bytearray(path.read_bytes())
    data[: 1 << 16] = bytes(min(len(data), 1 << 16))
    path.write_bytes(bytes(data))
