"""The integration loop of :func:`simulator.flights.nonlinear.simulate_flights`: setup, stepping, logging.

The flight it returns, :class:`NonlinearFlight`, is defined here and re-exported by
:mod:`simulator.flights.nonlinear`, so the loop needs nothing from the module that calls it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, cast

import numpy as np

from flightlogs.frames import air_velocity_body, quaternion_to_euler
from simulator.autopilot.control import (
    ControllerGains,
    Injection,
    controller_step,
    excitation_table,
    initial_controller_state,
)
from simulator.flights.linear import SimulatedFlight
from simulator.flights.trial import Trial
from simulator.vehicle.dynamics import Conditions, vehicle_derivative
from simulator.vehicle.linearize import Trim, trim_hover
from simulator.vehicle.multirotor import Vehicle, mixer_commands
from simulator.world.environment import ground_effect_function
from simulator.world.wind_field import BatchWindField, FrozenField, realize_field

__all__ = ["NonlinearFlight", "run_batch"]

_MARGIN_M = 30.0  # along-wind room for the vehicle's excursions


@dataclass(frozen=True, slots=True, kw_only=True)
class NonlinearFlight(SimulatedFlight):
    """A simulated flight with the anemometer's record and the noise-free truth.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Log times, s.
    signals : Mapping[str, ndarray]
        Canonical signals as logged (noise and biases applied): ``p q r phi
        theta psi u v w ax ay az vn ve vd height_agl delta_lat delta_lon
        delta_yaw delta_thr`` (mixer inputs in %, thrust from hover trim),
        ``motor_1..n`` (rotor command, % of full scale) and ``battery_v`` (V).
    wind_at_vehicle : ndarray, shape (n_samples, 2)
        ``wind_n, wind_e`` at the vehicle, m/s.
    maneuvers : tuple of Maneuver
        Sweeps and doublets flown.
    parameters : Mapping[str, float]
        The truth: hover derivatives of the vehicle (Table 3.3 names) and the trial's settings.
    wind_at_anemometer : ndarray, shape (n_samples, 2)
        ``wind_n, wind_e`` at the anemometer on the log clock, m/s.
    anemometer_ne_m : ndarray, shape (2,)
        Anemometer position from the hover point, north and east, m.
    transport_delay_s : float
        Distance along the wind over mean speed, s (Taylor's hypothesis).
    truth : Mapping[str, ndarray]
        The same signals without noise or biases, plus ``pn pe`` (position from the hover point, m),
        ``wind_d`` (m/s) and ``mass_kg``.
    injections : tuple of Injection
        3-2-1-1s and multisines flown.
    label : str
        The trial's label.
    """

    wind_at_anemometer: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    anemometer_ne_m: np.ndarray = field(default_factory=lambda: np.zeros(2))
    transport_delay_s: float = 0.0
    truth: Mapping[str, np.ndarray] = field(default_factory=dict)
    injections: tuple[Injection, ...] = ()
    label: str = ""

    def __post_init__(self) -> None:
        n = np.shape(self.time_s)[0]
        if np.shape(self.wind_at_vehicle) != (n, 2) or np.shape(self.wind_at_anemometer) != (n, 2):
            raise ValueError(f"wind_at_vehicle and wind_at_anemometer must have shape ({n}, 2)")
        for name, values in self.signals.items():
            if np.shape(values) != (n,):
                raise ValueError(f"signal {name!r} must have shape ({n},), got {np.shape(values)}")


@dataclass(frozen=True, slots=True, kw_only=True)
class _Setup:
    """Everything fixed before the first step (arrays over trials, and over steps where they vary)."""

    dt_s: float
    n_steps: int
    decimation: int
    conditions: Conditions
    mass_kg: np.ndarray  # (n,)
    payload_kg: np.ndarray  # (n,)
    payload_time_s: np.ndarray  # (n,)
    state0: np.ndarray  # (n, n_states)
    integrators0: np.ndarray  # (n, 6)
    mixer_trim: np.ndarray  # (n, 4)
    reference: np.ndarray  # (n, 4): north, east, height, heading
    height_ref: np.ndarray  # (n_steps, n)
    position_ref: np.ndarray | None  # (n_steps, n, 2): north, east; None: hold the origin
    excitation: np.ndarray  # (n_steps, n, 4)
    wind: BatchWindField
    fields: list[FrozenField]
    anemometer_ne: np.ndarray  # (n, 2)
    delay_whole: np.ndarray  # (4,) int
    delay_frac: np.ndarray  # (4,)
    buffer_len: int
    seen_noise: np.ndarray  # (n_log, n, 10): rates, attitude, velocity, height errors the controller sees


def _trim_for(trial: Trial, vehicle: Vehicle, conditions: Conditions, cache: dict[tuple[Any, ...], Trim]) -> Trim:
    env = trial.environment
    key = (
        tuple(env.wind.mean_ned),
        trial.heading_rad,
        env.cg_offset_m,
        env.rotor_drag,
        env.thrust_sag,
        env.ground_effect,
        trial.hover_height_m,
        env.gravity_m_s2,
    )
    if key not in cache:
        cache[key] = trim_hover(
            vehicle,
            wind_ned=tuple(env.wind.mean_ned),
            heading_rad=trial.heading_rad,
            conditions=conditions,
            height_m=_start_height(trial),
        )
    return cache[key]


def _position_reference(trials: list[Trial], time: np.ndarray) -> np.ndarray | None:
    if all(t.legs is None for t in trials):
        return None
    origin = np.zeros((time.size, 2))
    return np.stack([t.legs.reference(time) if t.legs is not None else origin for t in trials], axis=1)


def _start_height(trial: Trial) -> float:
    return float(trial.height_steps.heights_m[0]) if trial.height_steps is not None else trial.hover_height_m


def _setup(
    trials: list[Trial], vehicle: Vehicle, gains: ControllerGains, n_log: int, rate_hz: float, decimation: int
) -> _Setup:
    n = len(trials)
    envs = [t.environment for t in trials]
    gravity = envs[0].gravity_m_s2
    if any(e.gravity_m_s2 != gravity for e in envs):
        raise ValueError("all trials of a batch must share gravity_m_s2")
    dt = 1.0 / rate_hz
    n_steps = n_log * decimation
    time = np.arange(n_steps) * dt
    cg = np.array([e.cg_offset_m for e in envs], dtype=np.float64)
    drag = np.array([float(e.rotor_drag) for e in envs])
    sag = np.array([float(e.thrust_sag) for e in envs])
    conditions = Conditions(
        cg_offset_m=cg,
        rotor_drag=drag,
        thrust_sag=sag,
        ground_effect=ground_effect_function([e.ground_effect for e in envs]),
        gravity_m_s2=gravity,
    )
    cache: dict[tuple[Any, ...], Trim] = {}
    trims = []
    for k, trial in enumerate(trials):
        single = Conditions(
            cg_offset_m=cg[k : k + 1],
            rotor_drag=drag[k : k + 1],
            thrust_sag=sag[k : k + 1],
            ground_effect=ground_effect_function([envs[k].ground_effect]),
            gravity_m_s2=gravity,
        )
        trims.append(_trim_for(trial, vehicle, single, cache))
    state0 = np.array([t.state for t in trims])
    state0[:, -2] = [3600.0 * t.battery_used_ah for t in trials]
    euler = np.array([t.euler for t in trims])
    mixer_trim = np.array([t.mixer_input for t in trims])
    heights = np.column_stack(
        [
            t.height_steps.reference(time) if t.height_steps is not None else np.full(n_steps, t.hover_height_m)
            for t in trials
        ]
    )
    reference = np.column_stack([np.zeros(n), np.zeros(n), heights[0], [t.heading_rad for t in trials]])
    excitation = np.stack([excitation_table(time, t.maneuvers, t.injections) for t in trials], axis=1)
    fields, anemometers = [], []
    for trial in trials:
        wind, site = trial.environment.wind, trial.environment.anemometer
        position = site.position_ne(wind)
        along = float(position @ wind.towards)
        span = wind.mean_speed_m_s * trial.duration_s
        seed = np.random.SeedSequence(trial.seed).spawn(3)[0]
        fields.append(
            realize_field(
                wind, xi_min_m=min(0.0, along) - span - _MARGIN_M, xi_max_m=max(0.0, along) + _MARGIN_M, seed=seed
            )
        )
        anemometers.append(position)
    delays = np.maximum(vehicle.delays_s / dt - 0.5, 0.0)  # the zero-order hold adds half a step
    whole = np.floor(delays).astype(np.intp)
    return _Setup(
        dt_s=dt,
        n_steps=n_steps,
        decimation=decimation,
        conditions=conditions,
        mass_kg=np.full(n, vehicle.mass_kg),
        payload_kg=np.array([e.payload.delta_mass_kg if e.payload else 0.0 for e in envs]),
        payload_time_s=np.array([e.payload.time_s if e.payload else np.inf for e in envs]),
        state0=state0,
        integrators0=initial_controller_state(gains, euler, mixer_trim, gravity),
        mixer_trim=mixer_trim,
        reference=reference,
        height_ref=heights,
        position_ref=_position_reference(trials, time),
        excitation=excitation,
        wind=BatchWindField.stack([t.environment.wind for t in trials], fields),
        fields=fields,
        anemometer_ne=np.array(anemometers),
        delay_whole=whole,
        delay_frac=delays - whole,
        buffer_len=int(whole.max()) + 2,
        seen_noise=np.stack([_seen_noise(t, n_steps // decimation + 1) for t in trials], axis=1),
    )


def _seen_noise(trial: Any, n_log: int) -> np.ndarray:
    """Estimation errors the controller acts on, (n_log, 10), drawn per trial (batching cannot change them).

    A real autopilot flies on noisy estimates, which is why its mixer inputs are never
    noise-free; the errors are white at the log rate and held between log samples.
    """
    sensors = trial.environment.sensors
    sigma = np.array(
        [sensors.gyro_rad_s] * 3 + [sensors.attitude_rad] * 3 + [sensors.velocity_m_s] * 3 + [sensors.height_m]
    )
    rng = np.random.default_rng(np.random.SeedSequence(trial.seed).spawn(4)[3])
    return cast(np.ndarray, rng.standard_normal((n_log, sigma.size)) * sigma)


def _as_seen(state: np.ndarray, noise: np.ndarray) -> np.ndarray:
    """The state as the controller's estimator reports it: rates, attitude, velocity and height with errors."""
    seen = state.copy()
    seen[:, 10:13] += noise[:, 0:3]
    half = 0.5 * noise[:, 3:6]  # small rotation, body axes
    w, x, y, z = state[:, 6], state[:, 7], state[:, 8], state[:, 9]
    a, b, c = half[:, 0], half[:, 1], half[:, 2]
    quat = np.column_stack(
        [w - x * a - y * b - z * c, x + w * a + y * c - z * b, y + w * b + z * a - x * c, z + w * c + x * b - y * a]
    )
    seen[:, 6:10] = quat / np.linalg.norm(quat, axis=1, keepdims=True)
    seen[:, 3:6] += noise[:, 6:9]
    seen[:, 2] += noise[:, 9]
    return seen


def _step(
    vehicle: Vehicle,
    state: np.ndarray,
    command: np.ndarray,
    wind: np.ndarray,
    mass: np.ndarray,
    setup: _Setup,
    method: str,
) -> tuple[np.ndarray, np.ndarray]:
    """Advance one step; returns the new state and the specific force at the step's start."""
    dt, cond = setup.dt_s, setup.conditions
    k1, specific = vehicle_derivative(vehicle, state, command, wind, mass, cond)
    if method == "euler":
        new = state + dt * k1
        new[:, 0:3] = state[:, 0:3] + dt * new[:, 3:6]  # semi-implicit: positions from new velocities
    else:
        k2, _ = vehicle_derivative(vehicle, state + 0.5 * dt * k1, command, wind, mass, cond)
        k3, _ = vehicle_derivative(vehicle, state + 0.5 * dt * k2, command, wind, mass, cond)
        k4, _ = vehicle_derivative(vehicle, state + dt * k3, command, wind, mass, cond)
        new = state + (dt / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
    quat = new[:, 6:10]
    norm = np.sqrt(quat[:, 0] ** 2 + quat[:, 1] ** 2 + quat[:, 2] ** 2 + quat[:, 3] ** 2)
    new[:, 6:10] = quat / norm[:, None]
    return new, specific


def _integrate(
    setup: _Setup, vehicle: Vehicle, gains: ControllerGains, method: str, progress: Callable[[int, int], None] | None
) -> dict[str, np.ndarray]:
    n = setup.state0.shape[0]
    n_log = setup.n_steps // setup.decimation
    logs = {
        "state": np.empty((n_log, n, setup.state0.shape[1])),
        "specific": np.empty((n_log, n, 3)),
        "mixer": np.empty((n_log, n, 4)),
        "command": np.empty((n_log, n, vehicle.n_rotors)),
        "wind": np.empty((n_log, n, 3)),
        "mass": np.empty((n_log, n)),
        "seen": np.empty((n_log, n, 13)),
    }
    state, integrators = setup.state0.copy(), setup.integrators0.copy()
    length = setup.buffer_len
    buffer = np.repeat(setup.mixer_trim[None], length, axis=0)
    axes = np.arange(4)
    frac = setup.delay_frac[:, None]
    reference = setup.reference.copy()
    gravity = setup.conditions.gravity_m_s2
    for k in range(setup.n_steps):
        t = k * setup.dt_s
        wind = setup.wind.at(state[:, 0:2], t)
        reference[:, 2] = setup.height_ref[k]
        if setup.position_ref is not None:
            reference[:, :2] = setup.position_ref[k]
        seen = _as_seen(state, setup.seen_noise[k // setup.decimation])
        mixer, integrators = controller_step(gains, integrators, seen, reference, setup.dt_s, gravity)
        mixer = mixer + setup.excitation[k]
        buffer[k % length] = mixer
        newer = buffer[(k - setup.delay_whole) % length, :, axes]  # (4, n)
        older = buffer[(k - setup.delay_whole - 1) % length, :, axes]
        command = mixer_commands(vehicle, (newer + frac * (older - newer)).T)
        mass = setup.mass_kg + np.where(t >= setup.payload_time_s, setup.payload_kg, 0.0)
        previous = state
        state, specific = _step(vehicle, state, command, wind, mass, setup, method)
        if k % setup.decimation == 0:
            j = k // setup.decimation
            logs["state"][j], logs["specific"][j], logs["mixer"][j] = previous, specific, mixer
            logs["command"][j], logs["wind"][j], logs["mass"][j] = command, wind, mass
            logs["seen"][j] = seen[:, :13]
            if progress is not None and j % 100 == 0:
                progress(k, setup.n_steps)
    return logs


def _anemometer_wind(field: FrozenField, trial: Trial, position_ne: np.ndarray, time_s: np.ndarray) -> np.ndarray:
    """Wind at the fixed anemometer, NED north and east, shape (n_samples, 2).

    Along the wind the sensor samples the vehicle's frozen field. Off the wind
    line, its turbulence decorrelates from the vehicle's as ``rho = exp(-|c| / L)``
    (c the cross-wind offset, L each component's scale length): the sensor sees
    ``rho g + sqrt(1 - rho^2) g'`` with g' an independent realisation; discrete
    gusts are taken as wide enough to reach both.
    """
    wind = trial.environment.wind
    e = wind.towards
    xi = float(position_ne @ e) - wind.mean_speed_m_s * time_s
    g = field.at(xi)
    cross = float(position_ne @ np.array([-e[1], e[0]]))
    if wind.turbulence is not None and abs(cross) > 1e-9:
        lo, hi = field.xi0_m, field.xi0_m + field.dxi_m * (field.values.shape[0] - 1)
        seed = np.random.SeedSequence(trial.seed).spawn(3)[2]
        other = realize_field(replace(wind, gusts=()), xi_min_m=lo, xi_max_m=hi, seed=seed).at(xi)
        gusts = realize_field(replace(wind, turbulence=None), xi_min_m=lo, xi_max_m=hi, seed=0).at(xi)
        rho = np.exp(-abs(cross) / np.asarray(wind.turbulence.length_m))
        g = gusts + rho * (g - gusts) + np.sqrt(1.0 - rho**2) * other
    mean = wind.mean_ned
    return np.column_stack([mean[0] + g[:, 0] * e[0] - g[:, 1] * e[1], mean[1] + g[:, 0] * e[1] + g[:, 1] * e[0]])


def _estimates(logs: dict[str, np.ndarray], i: int, sensors: Any) -> dict[str, np.ndarray]:
    """The rates, attitude, velocity and height the controller flew on: what an autopilot logs.

    The gyro bias is added here (the controller's estimate carries white errors only).
    """
    seen = logs["seen"][:, i]
    euler = quaternion_to_euler(seen[:, 6:10])
    bias = sensors.gyro_bias_rad_s
    return {
        "p": seen[:, 10] + bias[0],
        "q": seen[:, 11] + bias[1],
        "r": seen[:, 12] + bias[2],
        "phi": euler[:, 0],
        "theta": euler[:, 1],
        "psi": euler[:, 2],
        "vn": seen[:, 3],
        "ve": seen[:, 4],
        "vd": seen[:, 5],
        "height_agl": -seen[:, 2],
    }


def _flight_signals(vehicle: Vehicle, logs: dict[str, np.ndarray], i: int) -> dict[str, np.ndarray]:
    """Clean canonical signals of trial `i`."""
    state = logs["state"][:, i]
    euler = quaternion_to_euler(state[:, 6:10])
    wind = logs["wind"][:, i]
    uvw = air_velocity_body(state[:, 3:6], wind[:, :2], euler[:, 0], euler[:, 1], euler[:, 2])
    n_r = vehicle.n_rotors
    signals = {
        "p": state[:, 10],
        "q": state[:, 11],
        "r": state[:, 12],
        "phi": euler[:, 0],
        "theta": euler[:, 1],
        "psi": euler[:, 2],
        "u": uvw[:, 0],
        "v": uvw[:, 1],
        "w": uvw[:, 2],
        "ax": logs["specific"][:, i, 0],
        "ay": logs["specific"][:, i, 1],
        "az": logs["specific"][:, i, 2],
        "vn": state[:, 3],
        "ve": state[:, 4],
        "vd": state[:, 5],
        "height_agl": -state[:, 2],
        "battery_v": vehicle.battery.open_circuit_v(state[:, 13 + n_r]) - state[:, 14 + n_r],
    }
    for k, axis in enumerate(("lat", "lon", "yaw", "thr")):
        signals[f"delta_{axis}"] = logs["mixer"][:, i, k]
    for k in range(n_r):
        signals[f"motor_{k + 1}"] = 100.0 * logs["command"][:, i, k]
    return {name: np.ascontiguousarray(values) for name, values in signals.items()}


def run_batch(
    trials: list[Trial],
    vehicle: Vehicle,
    gains: ControllerGains,
    *,
    n_log: int,
    rate_hz: float,
    decimation: int,
    method: str,
    progress: Callable[[int, int], None] | None,
) -> list[NonlinearFlight]:
    """Simulate trials of equal length together.

    Parameters
    ----------
    trials : list of Trial
        The trials (:class:`simulator.flights.nonlinear.Trial`), all of `n_log` log samples.
    vehicle : Vehicle
        The vehicle.
    gains : ControllerGains
        The controller.
    n_log : int
        Log samples per trial.
    rate_hz : float
        Integration and control rate, Hz.
    decimation : int
        Integration steps per log sample.
    method : str
        ``"euler"`` for semi-implicit Euler, anything else for RK4.
    progress : callable or None
        Called as ``progress(steps_done, steps_total)``.

    Returns
    -------
    list of NonlinearFlight
        In the order of `trials`, without the truth parameters (the caller adds them).
    """
    setup = _setup(trials, vehicle, gains, n_log, rate_hz, decimation)
    logs = _integrate(setup, vehicle, gains, "euler" if method == "euler" else "rk4", progress)
    time = np.arange(n_log) / (rate_hz / decimation)
    flights: list[NonlinearFlight] = []
    for i, trial in enumerate(trials):
        clean = _flight_signals(vehicle, logs, i)
        noise_rng = np.random.default_rng(np.random.SeedSequence(trial.seed).spawn(3)[1])
        noisy = trial.environment.sensors.apply(clean, noise_rng) | _estimates(logs, i, trial.environment.sensors)
        wind = trial.environment.wind
        truth = dict(clean) | {
            "wind_d": logs["wind"][:, i, 2].copy(),
            "mass_kg": logs["mass"][:, i].copy(),
            "pn": logs["state"][:, i, 0].copy(),
            "pe": logs["state"][:, i, 1].copy(),
        }
        flights.append(
            NonlinearFlight(
                time_s=time,
                signals=MappingProxyType(noisy),
                wind_at_vehicle=np.ascontiguousarray(logs["wind"][:, i, :2]),
                maneuvers=tuple(trial.maneuvers),
                parameters={},
                wind_at_anemometer=_anemometer_wind(setup.fields[i], trial, setup.anemometer_ne[i], time),
                anemometer_ne_m=setup.anemometer_ne[i].copy(),
                transport_delay_s=trial.environment.anemometer.transport_delay_s(wind),
                truth=MappingProxyType(truth),
                injections=tuple(trial.injections),
                label=trial.label,
            )
        )
    return flights
