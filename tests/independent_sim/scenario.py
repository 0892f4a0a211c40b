"""What a test flight is: the case, its flight plan and its sensor noise (data only)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from independent_sim.forcing import AnyEffect
from independent_sim.maneuvers import Maneuver
from independent_sim.nuisances import Nuisances
from independent_sim.wind import WindModel

__all__ = ["LogFormat", "NoiseModel", "Reposition", "HeightChange", "FlightPlan", "Case"]

LogFormat = Literal["ulog", "dataflash"]


@dataclass(frozen=True, slots=True, kw_only=True)
class NoiseModel:
    """Sensor and estimator errors, and unmeasured disturbances.

    Parameters
    ----------
    gyro_std, gyro_bias_std : float
        White noise per sample and constant bias of the gyro, rad/s.
    accel_std, accel_bias_std : float
        White noise per sample and bias of the accelerometer, m/s².
    attitude_std, attitude_drift_std : float
        White error and slowly wandering error (first order over
        `drift_tau_s`) of the attitude estimate, rad.
    velocity_std, velocity_drift_std : float
        The same for the NED velocity estimate, m/s.
    position_std, position_drift_std : float
        The same for the position estimate, m.
    drift_tau_s : float
        Correlation time of the wandering errors, s.
    force_disturbance_std, moment_disturbance_std : float
        Unmeasured gust accelerations (first order over `disturbance_tau_s`),
        m/s² on u v w and rad/s² on p q r.
    disturbance_tau_s : float
        Their correlation time, s.
    """

    gyro_std: float = 0.004
    gyro_bias_std: float = 0.002
    accel_std: float = 0.05
    accel_bias_std: float = 0.03
    attitude_std: float = 0.0005
    attitude_drift_std: float = 0.002
    velocity_std: float = 0.02
    velocity_drift_std: float = 0.02
    position_std: float = 0.01
    position_drift_std: float = 0.03
    drift_tau_s: float = 3.0
    force_disturbance_std: float = 0.03
    moment_disturbance_std: float = 0.03
    disturbance_tau_s: float = 0.5

    def __post_init__(self) -> None:
        for name in self.__dataclass_fields__:
            if getattr(self, name) < 0.0:
                raise ValueError(f"{name}={getattr(self, name)} must be ≥ 0")
        if self.drift_tau_s <= 0.0 or self.disturbance_tau_s <= 0.0:
            raise ValueError("correlation times must be > 0")

    @classmethod
    def quiet(cls) -> NoiseModel:
        """No noise and no disturbance at all (for exact checks)."""
        return cls(**{name: 0.0 for name in cls.__dataclass_fields__ if not name.endswith("tau_s")})


@dataclass(frozen=True, slots=True, kw_only=True)
class Reposition:
    """A pilot moving the position setpoint (not an excitation): a smooth step.

    Parameters
    ----------
    start_s : float
        Start, s after take-off.
    duration_s : float
        Time to reach the new setpoint, s.
    north_m, east_m : float
        Setpoint change, m.
    """

    start_s: float
    duration_s: float = 5.0
    north_m: float = 0.0
    east_m: float = 0.0


@dataclass(frozen=True, slots=True, kw_only=True)
class HeightChange:
    """A pilot moving the height setpoint during the hover: a smooth step.

    Parameters
    ----------
    start_s : float
        Start, s after take-off.
    duration_s : float
        Time to reach the new setpoint, s.
    down_m : float
        Setpoint change, m (positive: lower).
    """

    start_s: float
    down_m: float
    duration_s: float = 5.0


@dataclass(frozen=True, slots=True, kw_only=True)
class FlightPlan:
    """Timing of a flight: ground, take-off, hover, landing, ground.

    Parameters
    ----------
    duration_s : float
        Take-off to touch-down, s.
    hover_height_m : float
        Height of the hover, m (4.6 m in chapter 3).
    takeoff_s, landing_s : float
        Length of the smooth climb and descent of the height setpoint, s.
    ground_before_s, ground_after_s : float
        Time on the ground before take-off (armed after 1 s) and after
        touch-down (disarmed 1 s before the end), s.
    log_start_us : int
        Boot time of the first logged sample, µs.
    utc_at_log_start : float
        UTC of the first logged sample, UNIX s.
    repositions : tuple of Reposition
        Position setpoint moves during the hover.
    height_changes : tuple of HeightChange
        Height setpoint moves during the hover (a low hover near the ground).
    """

    duration_s: float
    hover_height_m: float = 4.6
    takeoff_s: float = 6.0
    landing_s: float = 6.0
    ground_before_s: float = 4.0
    ground_after_s: float = 3.0
    log_start_us: int = 41_250_000
    utc_at_log_start: float = 1_715_698_931.0  # 2024-05-14T15:02:11Z
    repositions: tuple[Reposition, ...] = ()
    height_changes: tuple[HeightChange, ...] = ()

    def __post_init__(self) -> None:
        if self.takeoff_s + self.landing_s + 10.0 > self.duration_s:
            raise ValueError(f"{self.duration_s=} s leaves under 10 s of hover after take-off and landing")
        if self.ground_before_s < 2.0 or self.ground_after_s < 2.0:
            raise ValueError("ground phases must be ≥ 2 s (arming and disarming happen 1 s in)")
        if self.log_start_us < 0 or self.hover_height_m <= 0.0:
            raise ValueError("log_start_us must be ≥ 0 and hover_height_m > 0")

    @property
    def hover_span_s(self) -> tuple[float, float]:
        """Time after take-off when maneuvers may run: 3 s after the climb to 3 s before the descent, s."""
        return self.takeoff_s + 3.0, self.duration_s - self.landing_s - 4.0


@dataclass(frozen=True, slots=True, kw_only=True)
class Case:
    """One log of the corpus.

    Parameters
    ----------
    name : str
        Identifier, used for file names.
    fmt : {"ulog", "dataflash"}
        Autopilot and log format: PX4 ULog (250 Hz loop) or ArduPilot ``.bin`` (400 Hz loop).
    plan : FlightPlan
        Timing.
    maneuvers : tuple of Maneuver
        What is flown, in any order (they must not overlap on one axis).
    condition : {"calm", "light", "strong"}
        Table 3.3 column of the airframe; "light"/"strong" need `wind`. A calm airframe may fly in
        `wind` too: then the wind acts only through the airframe's speed derivatives (no G_w).
    wind : WindModel or None
        Turbulent wind and the anemometer (then a CSV is written).
    noise : NoiseModel
        Sensor errors and disturbances.
    heading_deg : float
        Heading in calm air, degrees (in wind the nose faces the wind).
    px4_accel_topic : {"vehicle_acceleration", "sensor_combined"}
        Which topic carries the accelerometer in a ULog (both are written
        unless this is ``"sensor_combined"``).
    seed : int
        Seed of everything random.
    description : str
        One line on what the case is for.
    plant_changes : tuple of (str, float)
        :class:`~independent_sim.plant.HoverPlant` fields set to other values (a vehicle that differs from
        the Table 3.3 one: a longer delay, a slower actuator, more drag).
    effects : tuple of AnyEffect
        Physics outside the linear plant that acts on this vehicle (:mod:`independent_sim.effects`,
        :mod:`independent_sim.effects_more`, :mod:`independent_sim.effects_outside`), sensor scale errors
        included.
    nuisances : Nuisances or None
        Rotor vibration, gyro bias drift and logging dropouts (:mod:`independent_sim.nuisances`); None: none.
    position_hold : bool
        Whether the autopilot holds the horizontal position and velocity (False: attitude hold only, the
        vehicle drifts with what moves it).
    """

    name: str
    fmt: LogFormat
    plan: FlightPlan
    maneuvers: tuple[Maneuver, ...] = ()
    condition: Literal["calm", "light", "strong"] = "calm"
    wind: WindModel | None = None
    noise: NoiseModel = field(default_factory=NoiseModel)
    heading_deg: float = 30.0
    px4_accel_topic: Literal["vehicle_acceleration", "sensor_combined"] = "vehicle_acceleration"
    seed: int = 0
    description: str = ""
    plant_changes: tuple[tuple[str, float], ...] = ()
    effects: tuple[AnyEffect, ...] = ()
    nuisances: Nuisances | None = None
    position_hold: bool = True

    def __post_init__(self) -> None:
        if self.fmt not in ("ulog", "dataflash"):
            raise ValueError(f"{self.fmt=} must be 'ulog' or 'dataflash'")
        if self.condition != "calm" and self.wind is None:
            raise ValueError(f"{self.name}: a {self.condition} case needs wind")
        low, high = self.plan.hover_span_s
        for m in self.maneuvers:
            if m.start_s < low or m.end_s > high:
                raise ValueError(
                    f"{self.name}: {m.axis} {m.design.kind} [{m.start_s}, {m.end_s}] s leaves the hover [{low}, {high}] s"
                )
        for axis in ("lat", "lon", "yaw", "thr"):
            spans = sorted((m.start_s, m.end_s) for m in self.maneuvers if m.axis == axis)
            if any(b[0] < a[1] for a, b in zip(spans, spans[1:])):
                raise ValueError(f"{self.name}: maneuvers on {axis} overlap")

    @property
    def excited_axes(self) -> tuple[str, ...]:
        """Axes some maneuver excites, in canonical order."""
        return tuple(a for a in ("lat", "lon", "yaw", "thr") if any(m.axis == a for m in self.maneuvers))
