"""Fly a scenario: plan its trials, simulate them, write every trial's files and an index."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import Path
from typing import Any, cast

from flightlogs.errors import DataError
from flightlogs.writers.jsonio import write_json
from simulator.autopilot.excitation import Axis, Maneuver
from simulator.campaign.scenario import ManeuverSpec, Scenario, WindCondition
from simulator.flights.linear import SimulatedFlight, WindField, simulate_hover
from simulator.output.ardupilot import AnemometerSetup, write_anemometer_csv, write_ardupilot_log, write_truth
from simulator.vehicle.identified import CALM_HOVER, wind_terms_for

__all__ = ["TrialPlan", "TrialFiles", "plan_trials", "scenario_trials", "run_scenario"]

_GAP_BETWEEN_TRIALS_S = 60.0


@dataclass(frozen=True, slots=True, kw_only=True)
class TrialPlan:
    """One trial of a scenario.

    Parameters
    ----------
    index : int
        Position in the campaign, from 0.
    name : str
        File stem, e.g. ``"light-lon-sweep-3"``.
    condition : WindCondition
        Wind flown in.
    spec : ManeuverSpec
        Maneuver flown.
    maneuvers : tuple of Maneuver
        The excitation, timed on the trial's clock.
    duration_s : float
        Trial length, s.
    seed : int
        Seed of the gusts and sensor noise.
    utc_start : datetime
        UTC of the trial's first sample.
    """

    index: int
    name: str
    condition: WindCondition
    spec: ManeuverSpec
    maneuvers: tuple[Maneuver, ...]
    duration_s: float
    seed: int
    utc_start: datetime


@dataclass(frozen=True, slots=True, kw_only=True)
class TrialFiles:
    """What one trial left on disk.

    Parameters
    ----------
    plan : TrialPlan
        The trial.
    logs : tuple of Path
        One log per requested format.
    wind_csv : Path or None
        The anemometer record, if the scenario has an anemometer.
    truth : Path
        Truth JSON.
    """

    plan: TrialPlan
    logs: tuple[Path, ...]
    wind_csv: Path | None
    truth: Path


def plan_trials(scenario: Scenario) -> list[TrialPlan]:
    """Every (condition, maneuver, repeat) of a scenario as a trial, in flight order.

    Parameters
    ----------
    scenario : Scenario
        The campaign.

    Returns
    -------
    list of TrialPlan
        ``scenario.n_trials`` trials with consecutive seeds and UTC starts.
    """
    plans: list[TrialPlan] = []
    utc = scenario.utc_start
    for condition in scenario.conditions:
        for spec in scenario.maneuvers:
            for repeat in range(scenario.trials):
                maneuvers = _maneuvers(spec, scenario.margin_s)
                duration = _duration(spec, scenario.margin_s)
                name = f"{condition.name}-{spec.axis}-{spec.kind}-{repeat + 1}"
                plans.append(
                    TrialPlan(
                        index=len(plans),
                        name=name,
                        condition=condition,
                        spec=spec,
                        maneuvers=maneuvers,
                        duration_s=duration,
                        seed=scenario.seed + len(plans),
                        utc_start=utc,
                    )
                )
                utc = utc + timedelta(seconds=duration + _GAP_BETWEEN_TRIALS_S)
    return plans


def _maneuvers(spec: ManeuverSpec, margin_s: float) -> tuple[Maneuver, ...]:
    if spec.kind not in ("sweep", "doublet"):
        return ()  # height steps and 3-2-1-1 / multisine injections: see _injections
    fade = min(spec.fade_in_s, spec.duration_s / 3)
    return (
        Maneuver(
            axis=cast(Axis, spec.axis),  # validated by ManeuverSpec
            kind=spec.kind,
            start_s=margin_s,
            amplitude=spec.amplitude,
            duration_s=spec.duration_s,
            f_start_hz=spec.f_start_hz,
            f_stop_hz=spec.f_stop_hz,
            fade_in_s=fade,
            fade_out_s=min(1.0, spec.duration_s / 10),
        ),
    )


def _injections(spec: ManeuverSpec, margin_s: float) -> tuple[Any, ...]:
    if spec.kind not in ("3211", "multisine"):
        return ()
    from simulator.autopilot.control import Injection

    return (
        Injection(
            axis=cast(Axis, spec.axis),  # validated by ManeuverSpec
            kind=spec.kind,
            start_s=margin_s,
            amplitude=spec.amplitude,
            duration_s=spec.duration_s,
            f_min_hz=spec.f_start_hz,
            f_max_hz=spec.f_stop_hz,
        ),
    )


def _duration(spec: ManeuverSpec, margin_s: float) -> float:
    if spec.kind == "height_steps":
        return 2 * margin_s + spec.hold_s * len(spec.heights_m)
    return 2 * margin_s + spec.duration_s


def _nonlinear_trial(scenario: Scenario, plan: TrialPlan) -> Any:
    """The nonlinear simulator's Trial for one plan: wind, anemometer, ground effect, height steps."""
    from simulator.autopilot.control import HeightSteps
    from simulator.flights.nonlinear import Trial
    from simulator.world.environment import Anemometer, Environment, GroundEffect
    from simulator.world.wind_field import Dryden, Wind

    condition, spec = plan.condition, plan.spec
    height = spec.heights_m[0] if spec.kind == "height_steps" else 4.6
    turbulence = None
    if condition.mean_speed_m_s > 0 and condition.turbulence_ratio > 0:
        nominal = Dryden.low_altitude(height, condition.mean_speed_m_s)
        turbulence = Dryden.low_altitude(
            height,
            condition.mean_speed_m_s,
            scale=condition.turbulence_ratio * condition.mean_speed_m_s / nominal.sigma_m_s[0],
        )
    wind = Wind(
        mean_speed_m_s=condition.mean_speed_m_s, direction_from_deg=condition.direction_from_deg, turbulence=turbulence
    )
    anemometer = Anemometer(distance_m=scenario.anemometer.distance_m) if scenario.anemometer else Anemometer()
    ground = str(scenario.effects.get("ground_effect", "none")).replace("-", "_").replace("4_rotor", "4rotor")
    ground = ground.replace("2_rotor", "2rotor")
    environment = Environment(wind=wind, anemometer=anemometer, ground_effect=GroundEffect(model=ground))  # type: ignore[arg-type]
    steps = None
    if spec.kind == "height_steps":
        times = tuple(scenario.margin_s + k * spec.hold_s for k in range(len(spec.heights_m)))
        steps = HeightSteps(times, spec.heights_m)
    return Trial(
        duration_s=plan.duration_s,
        maneuvers=plan.maneuvers,
        injections=_injections(spec, scenario.margin_s),
        environment=environment,
        seed=plan.seed,
        hover_height_m=height,
        height_steps=steps,
        label=plan.name,
    )


def scenario_trials(scenario: Scenario, plans: Sequence[TrialPlan] | None = None) -> list[Any]:
    """The nonlinear simulator's trials for a scenario (all of them, or the given plans).

    Parameters
    ----------
    scenario : Scenario
        The campaign; its vehicle must be a nonlinear preset.
    plans : sequence of TrialPlan, optional
        Trials to build; default every trial of :func:`plan_trials`.

    Returns
    -------
    list of simulator.flights.nonlinear.Trial
    """
    return [_nonlinear_trial(scenario, plan) for plan in (plan_trials(scenario) if plans is None else plans)]


def _simulate(
    scenario: Scenario, plans: Sequence[TrialPlan], progress: Callable[[int, int], None] | None
) -> list[SimulatedFlight]:
    if scenario.vehicle == "linear-octo":
        unsupported = sorted({p.spec.kind for p in plans} - {"sweep", "doublet"})
        if unsupported:
            raise DataError(
                f"scenario {scenario.name!r}: the linear model flies sweeps and doublets only, "
                f"not {', '.join(unsupported)}; use vehicle octo-s1000"
            )
        return [_simulate_linear(plan) for plan in plans]
    from simulator.flights.nonlinear import simulate_flights
    from simulator.vehicle.presets import CRAZYFLIE, OCTO_S1000, QUAD_X500

    vehicle = {"octo-s1000": OCTO_S1000, "quad-x500": QUAD_X500}.get(scenario.vehicle, CRAZYFLIE)
    return list(simulate_flights(scenario_trials(scenario, plans), vehicle, progress=progress))


def _simulate_linear(plan: TrialPlan) -> SimulatedFlight:
    condition = plan.condition
    wind = WindField(
        mean_speed_m_s=condition.mean_speed_m_s,
        direction_from_deg=condition.direction_from_deg,
        turbulence_ratio=condition.turbulence_ratio,
    )
    return simulate_hover(
        plan.duration_s,
        plan.maneuvers,
        parameters=CALM_HOVER,
        wind=wind,
        wind_terms=wind_terms_for(condition.mean_speed_m_s),
        seed=plan.seed,
    )


def _write_trial(scenario: Scenario, plan: TrialPlan, flight: SimulatedFlight, folder: Path) -> TrialFiles:
    logs = []
    if "dataflash" in scenario.formats:
        logs.append(write_ardupilot_log(flight, folder / f"{plan.name}.bin", utc_start=plan.utc_start))
    if "ulog" in scenario.formats:
        from simulator.output.px4 import write_px4_log

        logs.append(write_px4_log(flight, folder / f"{plan.name}.ulg", utc_start=plan.utc_start))
    setup = None
    wind_csv = None
    if scenario.anemometer is not None and plan.condition.mean_speed_m_s > 0:
        spec = scenario.anemometer
        setup = AnemometerSetup(distance_m=spec.distance_m, rate_hz=spec.rate_hz, clock_offset_s=spec.clock_offset_s)
        wind_csv = write_anemometer_csv(
            flight, folder / f"{plan.name}-anemometer.csv", utc_start=plan.utc_start, setup=setup
        )
    truth = write_truth(flight, folder / f"{plan.name}-truth.json", utc_start=plan.utc_start, setup=setup)
    return TrialFiles(plan=plan, logs=tuple(logs), wind_csv=wind_csv, truth=truth)


def run_scenario(
    scenario: Scenario,
    out_dir: str | Path,
    *,
    progress: Callable[[int, int], None] | None = None,
    trials: Sequence[int] | None = None,
) -> list[TrialFiles]:
    """Simulate every trial of a scenario and write its files into `out_dir`.

    Parameters
    ----------
    scenario : Scenario
        The campaign.
    out_dir : str or Path
        Destination folder (created); an index ``campaign.json`` lists the trials.
    progress : callable, optional
        ``progress(done, total)`` as the simulation advances.
    trials : sequence of int, optional
        Only these trial indices (all when None).

    Returns
    -------
    list of TrialFiles
    """
    folder = Path(out_dir)
    folder.mkdir(parents=True, exist_ok=True)
    plans = [p for p in plan_trials(scenario) if trials is None or p.index in set(trials)]
    flights = _simulate(scenario, plans, progress)
    written = [_write_trial(scenario, plan, flight, folder) for plan, flight in zip(plans, flights)]
    _write_index(scenario, written, folder / "campaign.json")
    return written


def _write_index(scenario: Scenario, written: Sequence[TrialFiles], path: Path) -> None:
    index = {
        "scenario": scenario.name,
        "description": scenario.description,
        "vehicle": scenario.vehicle,
        "trials": [
            {
                "index": t.plan.index,
                "name": t.plan.name,
                "condition": t.plan.condition.name,
                "axis": t.plan.spec.axis,
                "kind": t.plan.spec.kind,
                "seed": t.plan.seed,
                "utc_start": t.plan.utc_start.isoformat(),
                "duration_s": t.plan.duration_s,
                "logs": [p.name for p in t.logs],
                "anemometer": t.wind_csv.name if t.wind_csv else None,
                "truth": t.truth.name,
            }
            for t in written
        ],
    }
    write_json(path, index, indent=2)
