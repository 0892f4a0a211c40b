"""Heave-only simulation of a multirotor near the ground, for altitude controllers (chapter 2, section 2.5).

The altitude loop of chapter 2 only needs the vertical axis: height ``z`` of
the vehicle above its resting position on the ground, climb rate ``v_z``,
the first-order motor lag and transport delay of the throttle input, and
the thrust ``n k_f PWM F/F0(Z/R)`` with the rotor plane ``Z = z + gear``
above the ground (eqs. 2.5-2.6). The parameters come from the simulator's
own vehicle (:func:`AltitudeVehicle.from_vehicle`, by default the
:func:`~simulator.vehicle.presets.crazyflie` preset) and the ground-effect law from
anything with ``ratio(height_ratio)``, such as
:class:`~simulator.world.environment.GroundEffect` or a model fitted by
:mod:`sysid.groundeffect`; sensor errors use
:class:`~simulator.world.environment.SensorNoise`. The ground holds the vehicle:
it never goes below ``z = 0``.

A controller is any object with ``reset(height_m, trim_pwm)`` and
``step(height_m, climb_rate_m_s, command_m, dt_s) -> pwm`` (see
:class:`AltitudeController`); one call serves a batch of trials that differ
by their noise seed.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from simulator.vehicle.multirotor import Vehicle
from simulator.vehicle.presets import CRAZYFLIE
from simulator.world.environment import GroundEffect, SensorNoise

__all__ = [
    "ThrustRatioModel",
    "AltitudeController",
    "AltitudeVehicle",
    "CRAZYFLIE_GEAR_HEIGHT_M",
    "CRAZYFLIE_ALTITUDE",
    "MOCAP_NOISE",
    "AltitudeRun",
    "simulate_altitude",
]

#: Rotor plane above the ground when the chapter 2 Crazyflie rests on its gear, m: the
#: least-squares offset that maps Tables 2.6-2.8's heights 6.2, 4.2, 2.2 cm to Z/R = 4, 3, 2
#: with R = 22.5 mm (Z/R = 1.13 on the ground: "slightly higher than 1", section 2.4.1).
CRAZYFLIE_GEAR_HEIGHT_M = 0.0255

#: Motion-capture errors the altitude controller sees (assumed: 1 mm height, 1 cm/s climb rate, 1 sigma).
MOCAP_NOISE = SensorNoise(gyro_rad_s=0.0, accel_m_s2=0.0, attitude_rad=0.0, velocity_m_s=0.01, height_m=0.001)


class ThrustRatioModel(Protocol):
    """Anything that gives F/F0 against Z/R (eqs. 2.1-2.5 or a fitted model)."""

    def ratio(self, height_ratio: np.ndarray) -> np.ndarray:
        """F/F0 at Z/R, same shape."""


class AltitudeController(Protocol):
    """A height controller for a batch of trials: rotor PWM from the measured height and climb rate."""

    def reset(self, height_m: np.ndarray, trim_pwm: np.ndarray) -> None:
        """Start at rest at `height_m` (n_trials,), holding it with `trim_pwm` (n_trials,) per rotor."""

    def step(self, height_m: np.ndarray, climb_rate_m_s: np.ndarray, command_m: np.ndarray, dt_s: float) -> np.ndarray:
        """PWM per rotor, counts, shape (n_trials,), for the next `dt_s` (`command_m` shape (n_trials,))."""


@dataclass(frozen=True, slots=True, kw_only=True)
class AltitudeVehicle:
    """The heave axis of a multirotor with thrust linear in PWM (eq. 2.6).

    Parameters
    ----------
    mass_kg : float
        Mass, kg.
    n_rotors : int
        Number of rotors (all receive the same PWM in the altitude loop).
    thrust_per_count_n : float
        k_f: thrust of one rotor per PWM count out of ground effect, N.
    pwm_max : float
        Full-scale PWM, counts.
    idle_fraction : float
        Lowest PWM as a fraction of `pwm_max` (the motors keep spinning).
    motor_time_constant_s : float
        First-order lag of the rotor thrust, s.
    delay_s : float
        Transport delay of the throttle command, s (rounded to whole control steps).
    rotor_radius_m : float
        Propeller radius R, m.
    gear_height_m : float
        Rotor plane above the ground when the vehicle rests on it, m.
    gravity_m_s2 : float
        Gravity, m/s^2.
    """

    mass_kg: float
    n_rotors: int
    thrust_per_count_n: float
    pwm_max: float
    idle_fraction: float
    motor_time_constant_s: float
    delay_s: float
    rotor_radius_m: float
    gear_height_m: float
    gravity_m_s2: float = 9.81

    def __post_init__(self) -> None:
        positive = (
            self.mass_kg,
            self.thrust_per_count_n,
            self.pwm_max,
            self.motor_time_constant_s,
            self.rotor_radius_m,
            self.gravity_m_s2,
        )
        if min(positive) <= 0 or self.n_rotors < 1 or self.delay_s < 0 or self.gear_height_m < 0:
            raise ValueError(
                f"{self} needs positive mass, k_f, PWM range, lag, radius, gravity and rotors, "
                "and delay_s, gear_height_m >= 0"
            )
        if not 0 <= self.idle_fraction < 1:
            raise ValueError(f"idle_fraction={self.idle_fraction} must be in [0, 1)")
        if self.hover_pwm >= self.pwm_max:
            raise ValueError(
                f"{self.mass_kg} kg needs {self.hover_pwm:.0f} counts per rotor to hover, "
                f"more than pwm_max={self.pwm_max}"
            )

    @property
    def thrust_per_pwm_n(self) -> float:
        """Total thrust per PWM count applied to every rotor, n k_f, N."""
        return self.n_rotors * self.thrust_per_count_n

    @property
    def hover_pwm(self) -> float:
        """PWM per rotor that holds the weight out of ground effect, counts."""
        return self.mass_kg * self.gravity_m_s2 / self.thrust_per_pwm_n

    @property
    def idle_pwm(self) -> float:
        """Lowest PWM, counts."""
        return self.idle_fraction * self.pwm_max

    def height_for_ratio(self, height_ratio: float) -> float:
        """Height of the vehicle above its resting position that puts its rotors at Z/R, m.

        Parameters
        ----------
        height_ratio : float
            Z/R.

        Returns
        -------
        float
            ``height_ratio * R - gear_height_m``, m.
        """
        return height_ratio * self.rotor_radius_m - self.gear_height_m

    def height_ratio(self, height_m: np.ndarray | float) -> np.ndarray:
        """Z/R of the rotor plane at vehicle height `height_m`.

        Parameters
        ----------
        height_m : ndarray or float
            Height above the resting position, m.

        Returns
        -------
        ndarray
            ``(height_m + gear_height_m) / R``, same shape.
        """
        return (np.asarray(height_m) + self.gear_height_m) / self.rotor_radius_m

    @classmethod
    def from_vehicle(
        cls, vehicle: Vehicle, *, gear_height_m: float, pwm_max: float = 65535.0, gravity_m_s2: float = 9.81
    ) -> AltitudeVehicle:
        """The heave axis of a simulator :class:`~simulator.vehicle.multirotor.Vehicle` with a linear thrust curve.

        Parameters
        ----------
        vehicle : Vehicle
            The vehicle (``thrust_expo`` must be 0: thrust linear in command, eq. 2.6).
        gear_height_m : float
            Rotor plane above the ground when landed, m.
        pwm_max : float, optional
            Full-scale PWM, counts (k_f = max_thrust / pwm_max).
        gravity_m_s2 : float, optional
            Gravity, m/s^2.

        Returns
        -------
        AltitudeVehicle

        Examples
        --------
        >>> from simulator.vehicle.presets import CRAZYFLIE
        >>> heave = AltitudeVehicle.from_vehicle(CRAZYFLIE, gear_height_m=0.0255)
        >>> round(heave.thrust_per_count_n * 1e6, 3), round(heave.hover_pwm)
        (2.083, 44882)
        """
        if vehicle.thrust_expo != 0:
            raise ValueError(
                f"{vehicle.name}: thrust_expo={vehicle.thrust_expo}; the PWM loop needs thrust linear "
                "in command (eq. 2.6)"
            )
        return cls(
            mass_kg=vehicle.mass_kg,
            n_rotors=vehicle.n_rotors,
            thrust_per_count_n=vehicle.max_thrust_n / pwm_max,
            pwm_max=pwm_max,
            idle_fraction=vehicle.idle_command,
            motor_time_constant_s=vehicle.motor_time_constant_s,
            delay_s=float(vehicle.delays_s[3]),
            rotor_radius_m=vehicle.rotor_radius_m,
            gear_height_m=gear_height_m,
            gravity_m_s2=gravity_m_s2,
        )


#: The chapter 2 Crazyflie (Table 2.1 with the simulator's preset) resting on its gear.
CRAZYFLIE_ALTITUDE: AltitudeVehicle = AltitudeVehicle.from_vehicle(CRAZYFLIE, gear_height_m=CRAZYFLIE_GEAR_HEIGHT_M)


@dataclass(frozen=True, slots=True, kw_only=True)
class AltitudeRun:
    """A batch of heave simulations sampled at the control rate.

    Parameters
    ----------
    time_s : ndarray, shape (n_steps,)
        Time of each control step, s.
    command_m : ndarray, shape (n_steps, n_trials)
        Commanded height, m.
    height_m : ndarray, shape (n_steps, n_trials)
        True height above the resting position at each step, m.
    climb_rate_m_s : ndarray, shape (n_steps, n_trials)
        True climb rate, m/s (up positive).
    measured_height_m : ndarray, shape (n_steps, n_trials)
        Height the controller saw, m.
    pwm : ndarray, shape (n_steps, n_trials)
        PWM per rotor sent by the controller (after the limits), counts.
    thrust_ratio : ndarray, shape (n_steps, n_trials)
        F/F0 of the ground effect at each step.
    seeds : tuple of int
        Noise seed of each trial.
    """

    time_s: np.ndarray
    command_m: np.ndarray
    height_m: np.ndarray
    climb_rate_m_s: np.ndarray
    measured_height_m: np.ndarray
    pwm: np.ndarray
    thrust_ratio: np.ndarray
    seeds: tuple[int, ...] = field(default=())

    def __post_init__(self) -> None:
        n_steps = np.shape(self.time_s)[0]
        for name in ("command_m", "height_m", "climb_rate_m_s", "measured_height_m", "pwm", "thrust_ratio"):
            shape = np.shape(getattr(self, name))
            if shape != (n_steps, len(self.seeds)):
                raise ValueError(f"{name} has shape {shape}, expected ({n_steps}, {len(self.seeds)})")

    @property
    def n_trials(self) -> int:
        """Number of trials."""
        return len(self.seeds)


def _noise(seeds: Sequence[int], n_steps: int, sensors: SensorNoise) -> tuple[np.ndarray, np.ndarray]:
    """Height and climb-rate errors, each (n_steps, n_trials), one generator per trial (batch invariant)."""
    height = np.empty((n_steps, len(seeds)))
    rate = np.empty((n_steps, len(seeds)))
    for i, seed in enumerate(seeds):
        draws = np.random.default_rng(seed).standard_normal((2, n_steps))
        height[:, i] = sensors.height_m * draws[0]
        rate[:, i] = sensors.velocity_m_s * draws[1]
    return height, rate


def simulate_altitude(
    controller: AltitudeController,
    command_m: np.ndarray,
    *,
    vehicle: AltitudeVehicle = CRAZYFLIE_ALTITUDE,
    ground_effect: ThrustRatioModel | None = None,
    rate_hz: float = 200.0,
    seeds: Sequence[int] = (0,),
    sensors: SensorNoise = MOCAP_NOISE,
    initial_height_m: float | np.ndarray | None = None,
    substeps: int = 4,
    progress: Callable[[int, int], None] | None = None,
) -> AltitudeRun:
    """Fly a height command with `controller` in the loop, one trial per noise seed.

    Parameters
    ----------
    controller : AltitudeController
        Reset here, then stepped once per control period.
    command_m : ndarray, shape (n_steps,) or (n_steps, n_trials)
        Commanded height above the resting position at each control step, m
        (one column per trial, or one for all).
    vehicle : AltitudeVehicle, optional
        Heave parameters; default the chapter 2 Crazyflie.
    ground_effect : ThrustRatioModel or None, optional
        F/F0 against Z/R; default eq. 2.5 (``GroundEffect("fitted_4rotor")``).
    rate_hz : float, optional
        Control rate, Hz (chapter 2's position controller: 200 Hz).
    seeds : sequence of int, optional
        One trial per seed; a trial's noise depends only on its seed.
    sensors : SensorNoise, optional
        ``height_m`` and ``velocity_m_s`` are the 1-sigma errors of the measured height and climb rate.
    initial_height_m : float or ndarray, shape (n_trials,), optional
        The vehicle starts at rest here, held by the PWM that balances its weight
        there (default the first command), m.
    substeps : int, optional
        Integration steps per control step (motor lag exact, semi-implicit Euler for the body).
    progress : callable, optional
        ``progress(done, total)`` in control steps.

    Returns
    -------
    AltitudeRun

    Notes
    -----
    ``m dv/dt = n k_f s F/F0((z + gear)/R) - m g`` with the lagged PWM ``s``
    (``ds/dt = (u(t - delay) - s) / T``); at ``z = 0`` the ground carries the
    vehicle (no bounce). The PWM is limited to ``[idle, pwm_max]``. F/F0 is
    held over a control step (at 0.1 m/s it changes by under 0.1 % in 5 ms).

    Examples
    --------
    >>> class Hold:
    ...     def reset(self, height_m, trim_pwm): self.pwm = trim_pwm
    ...     def step(self, height_m, climb_rate_m_s, command_m, dt_s): return self.pwm
    >>> run = simulate_altitude(Hold(), np.full(200, 0.05), sensors=SensorNoise.off())
    >>> float(np.ptp(run.height_m)) < 1e-9
    True
    """
    n = len(seeds)
    command = np.asarray(command_m, dtype=np.float64)
    command = np.repeat(command[:, None], n, axis=1) if command.ndim == 1 else command
    if command.ndim != 2 or command.shape[0] < 1 or command.shape[1] != n:
        raise ValueError(f"command_m has shape {np.shape(command_m)}: need (n_steps,) or (n_steps, {n}) for {n} seeds")
    z = (
        command[0].copy()
        if initial_height_m is None
        else np.broadcast_to(np.asarray(initial_height_m, dtype=np.float64), (n,)).copy()
    )
    if not (np.all(np.isfinite(command)) and np.all(command >= 0) and np.all(np.isfinite(z)) and np.all(z >= 0)):
        raise ValueError("commanded and initial heights must be finite and >= 0")
    if rate_hz <= 0 or substeps < 1:
        raise ValueError(f"{rate_hz=} must be > 0 and {substeps=} >= 1")
    law: ThrustRatioModel = ground_effect if ground_effect is not None else GroundEffect(model="fitted_4rotor")
    n_steps, dt = command.shape[0], 1.0 / rate_hz
    v = np.zeros(n)
    trim = vehicle.hover_pwm / np.asarray(law.ratio(vehicle.height_ratio(z)), dtype=np.float64)
    lagged = trim.copy()
    controller.reset(z.copy(), trim.copy())
    delay = int(round(vehicle.delay_s * rate_hz))
    queue = [trim.copy() for _ in range(delay)]
    noise_z, noise_v = _noise(seeds, n_steps, sensors)
    out = {name: np.empty((n_steps, n)) for name in ("z", "v", "zm", "pwm", "ratio")}
    h = dt / substeps
    decay = np.exp(-h / vehicle.motor_time_constant_s)
    gain = vehicle.thrust_per_pwm_n / vehicle.mass_kg
    for k in range(n_steps):
        measured = z + noise_z[k]
        pwm = np.clip(controller.step(measured, v + noise_v[k], command[k], dt), vehicle.idle_pwm, vehicle.pwm_max)
        out["z"][k], out["v"][k], out["zm"][k], out["pwm"][k] = z, v, measured, pwm
        queue.append(pwm)
        applied = queue.pop(0)
        ratio = law.ratio(vehicle.height_ratio(z))
        out["ratio"][k] = ratio
        for _ in range(substeps):
            lagged = applied + (lagged - applied) * decay
            v = v + h * (gain * lagged * ratio - vehicle.gravity_m_s2)
            z = z + h * v
            grounded = z <= 0.0
            if grounded.any():
                z = np.where(grounded, 0.0, z)
                v = np.where(grounded, 0.0, v)
        if progress is not None and (k % 1000 == 0 or k == n_steps - 1):
            progress(k + 1, n_steps)
    return AltitudeRun(
        time_s=np.arange(n_steps) * dt,
        command_m=command,
        height_m=out["z"],
        climb_rate_m_s=out["v"],
        measured_height_m=out["zm"],
        pwm=out["pwm"],
        thrust_ratio=out["ratio"],
        seeds=tuple(int(s) for s in seeds),
    )
