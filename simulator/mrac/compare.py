"""Take-off and landing steps flown by PID and both MRACs, as in Tables 2.6-2.8 and Fig. 2.12.

For a height ratio inside ground effect (Z/R below ``out_of_ground_ratio``)
the vehicle rests on the ground, takes off and lands again. For the
Crazyflie at Z/R = 4, 3, 2 it takes off to the heights section 2.7 flew,
"6.2cm (Z/R ≈ 4), 4.2cm (Z/R ≈ 3) and 2.2cm (Z/R ≈ 2) above the ground";
at any other ratio (or vehicle) to the height that puts its rotors at that
Z/R. Out of ground effect it hovers at that Z/R and steps 6.2 cm up and
back (Fig. 2.12: 0.5 m, Z/R = 22). Each controller engages at rest at the
start (Theta_hat = 0; the integrator holds the trim, as Crazyflie's ROS
controller seeds it with the lift-off thrust). Each phase lasts 40 s for the
PID and 20 s for the MRACs, as in section 2.7. Trials differ by their noise
seed; every controller sees the same seeds.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from flightlogs.errors import DataError
from simulator.flights.altitude import (
    CRAZYFLIE_ALTITUDE,
    MOCAP_NOISE,
    AltitudeRun,
    AltitudeVehicle,
    ThrustRatioModel,
    simulate_altitude,
)
from simulator.mrac.analysis import LoopAnalysis, loop_analysis
from simulator.mrac.controllers import AdaptiveHistory, MracAltitude, PidAltitude
from simulator.mrac.metrics import MetricStatistics, StepMetrics, statistics, step_metrics
from simulator.mrac.reference import REFERENCE_EQ_2_20
from simulator.world.environment import GroundEffect, SensorNoise

__all__ = [
    "CONTROLLERS",
    "StepCase",
    "step_case",
    "CompareConfig",
    "ControllerResult",
    "MracComparison",
    "compare_controllers",
]

ControllerName = Literal["pid", "mrac_linear", "mrac_rbf"]
Phase = Literal["takeoff", "landing"]
#: Controller names, in report order.
CONTROLLERS: tuple[ControllerName, ...] = ("pid", "mrac_linear", "mrac_rbf")
#: Take-off heights of Tables 2.6-2.8 above the landed vehicle, m, by the Z/R that names them (section 2.7).
_TABLE_HEIGHTS_M: tuple[tuple[float, float], ...] = ((4.0, 0.062), (3.0, 0.042), (2.0, 0.022))


@dataclass(frozen=True, slots=True, kw_only=True)
class StepCase:
    """The two commanded heights of one take-off/landing experiment.

    Parameters
    ----------
    height_ratio : float
        Z/R that names the case.
    low_m : float
        Height before take-off and after landing, m (0: resting on the ground).
    high_m : float
        Height after take-off, m.
    in_ground_effect : bool
        Whether the case is inside ground effect (steps to and from the ground).
    """

    height_ratio: float
    low_m: float
    high_m: float
    in_ground_effect: bool

    def __post_init__(self) -> None:
        if not 0 <= self.low_m < self.high_m:
            raise DataError(f"Z/R = {self.height_ratio}: need 0 <= low_m={self.low_m} < high_m={self.high_m}")


def step_case(
    height_ratio: float,
    *,
    vehicle: AltitudeVehicle = CRAZYFLIE_ALTITUDE,
    out_of_ground_ratio: float = 10.0,
    step_m: float = 0.062,
    table_heights: bool = True,
) -> StepCase:
    """The experiment chapter 2 flew at `height_ratio`.

    Parameters
    ----------
    height_ratio : float
        Z/R of the rotors: at the top of the step in ground effect, at its bottom out of it.
    vehicle : AltitudeVehicle, optional
        Gives R and the gear height.
    out_of_ground_ratio : float, optional
        Z/R from which the vehicle is out of ground effect (chapter 2's descent starts at 10).
    step_m : float, optional
        Step out of ground effect, m (Fig. 2.12: 6.2 cm).
    table_heights : bool, optional
        At Z/R = 4, 3, 2 take off to the heights section 2.7 states, 6.2, 4.2,
        2.2 cm (the Crazyflie's rotors then sit at Z/R = 3.89, 3.0, 2.11),
        rather than to ``Z/R R - gear`` (6.45, 4.2, 1.95 cm). Only meaningful
        for the chapter 2 Crazyflie.

    Returns
    -------
    StepCase

    Raises
    ------
    DataError
        If the height ratio puts the rotors at or below their height on the ground.

    Examples
    --------
    >>> case = step_case(4.0)
    >>> case.low_m, case.high_m, case.in_ground_effect
    (0.0, 0.062, True)
    >>> round(step_case(4.0, table_heights=False).high_m, 4)
    0.0645
    >>> round(step_case(22.0).high_m - step_case(22.0).low_m, 3)
    0.062
    """
    height = vehicle.height_for_ratio(height_ratio)
    if not np.isfinite(height) or height <= 0:
        lowest = vehicle.gear_height_m / vehicle.rotor_radius_m
        raise DataError(
            f"height ratio Z/R = {height_ratio} is at or below the rotors' height on the ground "
            f"(Z/R = {lowest:.2f}); choose a larger one"
        )
    if height_ratio < out_of_ground_ratio:
        table = dict(_TABLE_HEIGHTS_M)
        if table_heights and height_ratio in table:
            height = table[height_ratio]
        return StepCase(height_ratio=float(height_ratio), low_m=0.0, high_m=height, in_ground_effect=True)
    return StepCase(height_ratio=float(height_ratio), low_m=height, high_m=height + step_m, in_ground_effect=False)


@dataclass(frozen=True, slots=True, kw_only=True)
class CompareConfig:
    """What to fly in :func:`compare_controllers`.

    Parameters
    ----------
    height_ratios : tuple of float
        Cases, Z/R (chapter 2: 4, 3, 2; 22 out of ground effect).
    trials : int
        Trials per case and controller (chapter 2: 3).
    seed : int
        Seed of the trials' noise seeds.
    pid_phase_s : float
        Length of the PID's take-off and of its landing, s (chapter 2: 40).
    mrac_phase_s : float
        Length of each MRAC phase, s (chapter 2: 20).
    rate_hz : float
        Control rate, Hz (chapter 2: 200).
    gamma : float
        MRAC adaptation rate (chapter 2: 1e-3).
    sensors : SensorNoise
        Errors of the measured height and climb rate.
    controllers : tuple of str
        Which of ``pid``, ``mrac_linear``, ``mrac_rbf`` to fly.
    """

    height_ratios: tuple[float, ...] = (4.0, 3.0, 2.0)
    trials: int = 3
    seed: int = 0
    pid_phase_s: float = 40.0
    mrac_phase_s: float = 20.0
    rate_hz: float = 200.0
    gamma: float = 1e-3
    sensors: SensorNoise = field(default_factory=lambda: MOCAP_NOISE)
    controllers: tuple[ControllerName, ...] = CONTROLLERS

    def __post_init__(self) -> None:
        if not self.height_ratios or any(not np.isfinite(r) or r <= 0 for r in self.height_ratios):
            raise DataError(f"height_ratios={self.height_ratios} must be positive numbers")
        if self.trials < 1 or min(self.pid_phase_s, self.mrac_phase_s) < 2.0 or self.rate_hz <= 0 or self.gamma <= 0:
            raise DataError(f"need trials >= 1 (got {self.trials}), phases >= 2 s, rate_hz > 0 and gamma > 0")
        unknown = [c for c in self.controllers if c not in CONTROLLERS]
        if unknown or not self.controllers:
            raise DataError(f"unknown controllers {unknown}; choose from {CONTROLLERS}")

    def seeds(self) -> tuple[int, ...]:
        """Noise seed of each trial (shared by all controllers and cases).

        Returns
        -------
        tuple of int
        """
        return tuple(int(s) for s in np.random.SeedSequence(self.seed).generate_state(self.trials))


@dataclass(frozen=True, slots=True, kw_only=True)
class ControllerResult:
    """One controller flying one case.

    Parameters
    ----------
    controller : str
        ``pid``, ``mrac_linear`` or ``mrac_rbf``.
    case : StepCase
        The experiment.
    phase_s : float
        Length of each phase, s; take-off from 0, landing from `phase_s`.
    run : AltitudeRun
        The simulation (all trials).
    reference_m : ndarray, shape (n_steps,)
        Reference model's height for the command, m.
    adaptive : AdaptiveHistory or None
        Theta_hat and friends for an MRAC.
    takeoff, landing : tuple of StepMetrics
        Indices per trial.
    """

    controller: str
    case: StepCase
    phase_s: float
    run: AltitudeRun
    reference_m: np.ndarray
    adaptive: AdaptiveHistory | None
    takeoff: tuple[StepMetrics, ...]
    landing: tuple[StepMetrics, ...]

    def __post_init__(self) -> None:
        if np.shape(self.reference_m) != np.shape(self.run.time_s):
            expected = np.shape(self.run.time_s)
            raise ValueError(f"reference_m has shape {np.shape(self.reference_m)}, expected {expected}")
        if len(self.takeoff) != self.run.n_trials or len(self.landing) != self.run.n_trials:
            raise ValueError("takeoff and landing need one StepMetrics per trial")

    def metrics(self, phase: Phase) -> tuple[StepMetrics, ...]:
        """Indices of `phase` per trial.

        Parameters
        ----------
        phase : {"takeoff", "landing"}
            Which step.

        Returns
        -------
        tuple of StepMetrics
        """
        return self.takeoff if phase == "takeoff" else self.landing


@dataclass(frozen=True, slots=True, kw_only=True)
class MracComparison:
    """All controllers on all cases.

    Parameters
    ----------
    config : CompareConfig
        What was flown.
    vehicle : AltitudeVehicle
        The vehicle.
    ground_effect : str
        Label of the ground-effect law.
    results : tuple of ControllerResult
        Case-major, controllers in `config` order.
    analyses : tuple of LoopAnalysis
        The PID loop linearised at the top of each case's step, in case order.
    """

    config: CompareConfig
    vehicle: AltitudeVehicle
    ground_effect: str
    results: tuple[ControllerResult, ...]
    analyses: tuple[LoopAnalysis, ...]

    def __post_init__(self) -> None:
        if len(self.results) != len(self.config.height_ratios) * len(self.config.controllers):
            raise ValueError("results must hold one ControllerResult per case and controller")
        if len(self.analyses) != len(self.config.height_ratios):
            raise ValueError("analyses must hold one LoopAnalysis per case")

    @property
    def cases(self) -> tuple[StepCase, ...]:
        """The cases, in order."""
        n = len(self.config.controllers)
        return tuple(self.results[k * n].case for k in range(len(self.config.height_ratios)))

    def result(self, height_ratio: float, controller: str) -> ControllerResult:
        """The result of `controller` at `height_ratio`.

        Parameters
        ----------
        height_ratio : float
            A case's Z/R.
        controller : str
            A controller name.

        Returns
        -------
        ControllerResult
        """
        for r in self.results:
            if r.case.height_ratio == height_ratio and r.controller == controller:
                return r
        raise KeyError(f"no result for {controller} at Z/R = {height_ratio}")

    def statistics(
        self, controller: str, *, height_ratio: float | None = None, phase: Phase | None = None
    ) -> MetricStatistics:
        """Mean and spread of the indices of `controller`, over trials and the cases and phases selected.

        Parameters
        ----------
        controller : str
            A controller name.
        height_ratio : float, optional
            One case (default all).
        phase : {"takeoff", "landing"}, optional
            One phase (default both).

        Returns
        -------
        MetricStatistics
        """
        picked: list[StepMetrics] = []
        for r in self.results:
            if r.controller == controller and (height_ratio is None or r.case.height_ratio == height_ratio):
                for p in ("takeoff", "landing") if phase is None else (phase,):
                    picked.extend(r.metrics(p))
        if not picked:
            raise KeyError(f"no result for {controller} at Z/R = {height_ratio}")
        return statistics(picked)


def _controller(name: str, config: CompareConfig, vehicle: AltitudeVehicle) -> PidAltitude | MracAltitude:
    if name == "pid":
        return PidAltitude(vehicle=vehicle)
    return MracAltitude("linear" if name == "mrac_linear" else "rbf", vehicle=vehicle, gamma=config.gamma)


def _columns(run: AltitudeRun, cols: slice) -> AltitudeRun:
    return AltitudeRun(
        time_s=run.time_s,
        command_m=run.command_m[:, cols],
        height_m=run.height_m[:, cols],
        climb_rate_m_s=run.climb_rate_m_s[:, cols],
        measured_height_m=run.measured_height_m[:, cols],
        pwm=run.pwm[:, cols],
        thrust_ratio=run.thrust_ratio[:, cols],
        seeds=run.seeds[cols],
    )


def _fly(
    name: str,
    cases: list[StepCase],
    config: CompareConfig,
    vehicle: AltitudeVehicle,
    law: ThrustRatioModel,
    progress: Callable[[int, int], None] | None,
) -> list[ControllerResult]:
    """All cases for one controller in one batch (columns: case-major, then trials)."""
    phase_s = config.pid_phase_s if name == "pid" else config.mrac_phase_s
    n_phase = int(round(phase_s * config.rate_hz))
    seeds = config.seeds()
    n_t = len(seeds)
    low = np.repeat([c.low_m for c in cases], n_t)
    high = np.repeat([c.high_m for c in cases], n_t)
    command = np.concatenate([np.tile(high, (n_phase, 1)), np.tile(low, (n_phase, 1))])
    controller = _controller(name, config, vehicle)
    run = simulate_altitude(
        controller,
        command,
        vehicle=vehicle,
        ground_effect=law,
        rate_hz=config.rate_hz,
        seeds=seeds * len(cases),
        sensors=config.sensors,
        initial_height_m=low,
        progress=progress,
    )
    history = controller.history() if isinstance(controller, MracAltitude) else None
    t = run.time_s[:n_phase]
    results = []
    for j, case in enumerate(cases):
        cols = slice(j * n_t, (j + 1) * n_t)
        height = run.height_m[:, cols]
        reference = REFERENCE_EQ_2_20.response(run.time_s, command[:, j * n_t] - case.low_m)[:, 0] + case.low_m
        takeoff, landing = (
            tuple(step_metrics(t, height[rows, i], reference[rows], before_m=before, after_m=after) for i in range(n_t))
            for rows, before, after in (
                (slice(None, n_phase), case.low_m, case.high_m),
                (slice(n_phase, None), case.high_m, case.low_m),
            )
        )
        adaptive = (
            None
            if history is None
            else AdaptiveHistory(
                theta=history.theta[:, cols],
                reference_height_m=history.reference_height_m[:, cols],
                adaptive_thrust_n=history.adaptive_thrust_n[:, cols],
                labels=history.labels,
            )
        )
        results.append(
            ControllerResult(
                controller=name,
                case=case,
                phase_s=float(phase_s),
                run=_columns(run, cols),
                reference_m=reference,
                adaptive=adaptive,
                takeoff=takeoff,
                landing=landing,
            )
        )
    return results


def compare_controllers(
    config: CompareConfig = CompareConfig(),
    *,
    vehicle: AltitudeVehicle = CRAZYFLIE_ALTITUDE,
    ground_effect: ThrustRatioModel | None = None,
    ground_effect_label: str | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> MracComparison:
    """Fly every case with every controller and score the steps (Tables 2.6-2.8).

    Parameters
    ----------
    config : CompareConfig, optional
        Cases, trials, phase lengths.
    vehicle : AltitudeVehicle, optional
        Default the chapter 2 Crazyflie.
    ground_effect : ThrustRatioModel or None, optional
        F/F0 against Z/R acting on the vehicle; default eq. 2.5. A model fitted
        by :mod:`sysid.groundeffect` closes the loop from data to controller.
    ground_effect_label : str, optional
        Its name in the report.
    progress : callable, optional
        ``progress(done, total)`` in control steps over the whole comparison.

    Returns
    -------
    MracComparison

    Examples
    --------
    >>> config = CompareConfig(height_ratios=(3.0,), trials=1, pid_phase_s=4.0, mrac_phase_s=4.0)
    >>> comparison = compare_controllers(config)
    >>> [r.controller for r in comparison.results]
    ['pid', 'mrac_linear', 'mrac_rbf']
    """
    law: ThrustRatioModel = ground_effect if ground_effect is not None else GroundEffect(model="fitted_4rotor")
    label = ground_effect_label or ("eq. 2.5 (fitted, 4 rotors)" if ground_effect is None else type(law).__name__)
    cases = [step_case(r, vehicle=vehicle, table_heights=vehicle == CRAZYFLIE_ALTITUDE) for r in config.height_ratios]
    lengths = [
        2 * int(round((config.pid_phase_s if c == "pid" else config.mrac_phase_s) * config.rate_hz))
        for c in config.controllers
    ]
    total, done = sum(lengths), 0
    by_controller = []
    for name, length in zip(config.controllers, lengths):
        offset = done
        report = None if progress is None else (lambda k, _n, o=offset: progress(o + k, total))
        by_controller.append(_fly(name, cases, config, vehicle, law, report))
        done += length
    results = tuple(by_controller[i][j] for j in range(len(cases)) for i in range(len(config.controllers)))
    analyses = tuple(
        loop_analysis(case.high_m, vehicle=vehicle, ground_effect=law, gamma=config.gamma) for case in cases
    )
    return MracComparison(config=config, vehicle=vehicle, ground_effect=label, results=results, analyses=analyses)
