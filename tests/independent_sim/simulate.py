"""Fly a :class:`~independent_sim.scenario.Case`: the closed loop at the control rate, states on a fine grid.

1. The closed loop (:func:`~independent_sim.control.closed_loop`) runs as one
   discrete LTI recursion at the control rate (250 Hz PX4, 400 Hz ArduPilot).
2. The plant states between control instants, on a fine grid (1 kHz PX4,
   400 Hz ArduPilot), follow exactly from the held, delayed inputs
   (:mod:`._zoh`); the accelerometers from the state derivative (eq. 3.7).
3. Trim is added, the ground phases before take-off and after touch-down are
   appended, and the sensors add their errors (scale errors of the case's
   effects, and its nuisances: rotor vibration, a drifting gyro bias). The logs
   are samples of these arrays (:mod:`.px4_log`, :mod:`.ardupilot_log`),
   less the nuisances' logging gaps.

Physics outside the plant (:mod:`.forcing`) is computed at each control step
from the state reached and enters the plant's disturbance inputs.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, replace
from types import MappingProxyType

import numpy as np

from independent_sim._inputs import exogenous_inputs, sensor_errors
from independent_sim._zoh import propagator
from independent_sim.control import (
    MIXER,
    ClosedLoop,
    ardupilot_gains,
    closed_loop,
    px4_gains,
)
from independent_sim.effects_more import AccelScale, GyroScale
from independent_sim.flight import Flight, ManeuverTruth
from independent_sim.forcing import FORCED, EffectForcing, PlantContext, Step, effect_forcing
from independent_sim.nuisances import dropout_spans, gyro_drift, nuisance_rng, vibration
from independent_sim.plant import AIR_INPUTS, PLANT_INPUTS, STATES, G, HoverPlant, hover_plant, in_wind
from independent_sim.scenario import Case, LogFormat
from independent_sim.wind import WindField, wind_field

__all__ = ["simulate", "MAX_TILT_RAD", "MAX_YAW_RATE_RAD_S", "MAX_CLIMB_M_S"]

#: Stick scaling of a piloted maneuver: full roll/pitch stick, full yaw stick, full throttle stick.
MAX_TILT_RAD = math.radians(35.0)
MAX_YAW_RATE_RAD_S = math.radians(150.0)
MAX_CLIMB_M_S = 3.0
_SUB_STEPS = {"ulog": 4, "dataflash": 1}  # fine grid: 1 kHz (PX4), 400 Hz (ArduPilot)


def simulate(case: Case, fmt: LogFormat | None = None) -> Flight:
    """Fly `case` with the autopilot profile of `fmt` (default: the case's).

    Parameters
    ----------
    case : Case
        The flight.
    fmt : {"ulog", "dataflash"}, optional
        PX4 (250 Hz loop, 1 kHz grid) or ArduPilot (400 Hz loop and grid).

    Returns
    -------
    Flight
    """
    fmt = fmt or case.fmt
    plan, rng = case.plan, np.random.default_rng(case.seed)
    psi0 = math.radians(case.wind.from_deg if case.wind is not None else case.heading_deg)
    plant = replace(hover_plant(case.condition, psi0=psi0), **dict(case.plant_changes))
    if case.wind is not None and not plant.has_wind_terms:  # the calm airframe flown in wind
        plant = in_wind(plant, case.wind.mean_speed_m_s, psi0)
    gains = px4_gains(plant) if fmt == "ulog" else ardupilot_gains(plant)
    if not case.position_hold:  # attitude hold only: no horizontal position or velocity loop
        gains = replace(gains, pos_xy_p=0.0, vel_xy_p=0.0, vel_xy_i=0.0)
    loop = closed_loop(plant, gains, n_sub=_SUB_STEPS[fmt])
    grid = _Grid.of(case, gains.rate_hz, loop.n_sub)
    field_ = None
    if case.wind is not None:
        delay = case.wind.transport_delay_s
        span = (grid.takeoff_s - delay, grid.takeoff_s + plan.duration_s - delay)  # air passing the vehicle in flight
        field_ = wind_field(
            case.wind, grid.time_s[0] - delay - 10.0, grid.time_s[-1] + 10.0, 0.01, rng, zero_mean_over=span
        )
    noise = sensor_errors(case.noise, grid.time_s.size, grid.step_us * 1e-6, rng)
    spare = nuisance_rng(case.seed)
    if case.nuisances is not None:  # the rate loop flies on the drifting gyro too
        drift = gyro_drift(case.nuisances, grid.time_s.size, grid.step_us * 1e-6, spare)
        for k, name in enumerate(("p", "q", "r")):
            noise[name] = noise[name] + drift[:, k]
    control_t = np.arange(grid.n_steps) / gains.rate_hz
    W, external, maneuvers = exogenous_inputs(
        case, loop, plant, control_t, grid.takeoff_s, noise, grid.n_before, field_, rng
    )
    trim = plant.trim
    context = PlantContext(
        gravity=G,
        z_thr=plant.Z_thr,
        l_lat=plant.L_lat,
        m_lon=plant.M_lon,
        n_yaw=plant.N_yaw,
        trim_commands=np.array([trim.delta_lat, trim.delta_lon, trim.delta_yaw, trim.delta_thr]),
        trim_theta_rad=trim.theta0,
        hover_height_m=plan.hover_height_m,
        period_s=loop.period_s,
    )
    forcing = effect_forcing(case.effects, context)
    added = np.zeros((grid.n_steps, len(FORCED)))
    if forcing is None:
        X = _run(loop, W, _initial_state(loop, plant, case))
    else:
        X = _run_forced(loop, W, _initial_state(loop, plant, case), forcing, added)
        for name in FORCED:  # what the effects added, for the fine grid
            column = {c: k for k, c in enumerate(loop.inputs)}
            external[name] = (W[:, column[f"{name}@prev"]], W[:, column[f"{name}@cur"]])
    Y = X[:-1] @ loop.C.T + W @ loop.D.T
    outputs = {name: Y[:, k] for k, name in enumerate(loop.outputs)}
    x_fine, xdot_fine = _lift(loop, X[:-1, : len(STATES)], outputs, external)
    flight = _compose(plant, loop, x_fine, xdot_fine, outputs, W, case)
    for k, name in enumerate(FORCED):  # for tests only: never written to a log
        flight[f"effect_{name[5:]}"] = np.repeat(added[:, k], loop.n_sub)
    truth = _with_ground(flight, plant, grid, field_)
    felt: dict[str, np.ndarray] = {}
    dropouts: tuple[tuple[float, float], ...] = ()
    if case.nuisances is not None:
        shaking = vibration(case.nuisances, grid.time_s, truth["delta_thr"], plant.trim.delta_thr, spare)
        felt = {name: shaking[:, k] for k, name in enumerate(("ax", "ay", "az"))}
        touchdown_s = float(grid.time_s[grid.time_s.size - grid.n_after - 1])
        dropouts = dropout_spans(case.nuisances, grid.takeoff_s, touchdown_s, spare)
    return Flight(
        case=case,
        fmt=fmt,
        time_s=grid.time_s,
        step_us=grid.step_us,
        sub_steps=loop.n_sub,
        truth=MappingProxyType(truth),
        measured=MappingProxyType(_measure(truth, noise, case, felt)),
        armed=grid.armed(),
        airborne=grid.airborne(),
        maneuvers=tuple(sorted((_shift(m, grid.takeoff_s) for m in maneuvers), key=lambda m: m.start_s)),
        plant=plant,
        gains=gains,
        loop=loop,
        wind=field_,
        utc_offset_s=plan.utc_at_log_start - float(grid.time_s[0]),
        dropouts_s=dropouts,
    )


@dataclass(frozen=True, slots=True)
class _Grid:
    """The fine time grid of a flight: ground, airborne (``n_steps`` control periods), ground."""

    time_s: np.ndarray
    step_us: int
    n_steps: int
    n_before: int
    n_after: int

    @classmethod
    def of(cls, case: Case, rate_hz: float, n_sub: int) -> _Grid:
        plan = case.plan
        step_us = round(1e6 / rate_hz) // n_sub
        n_steps = round(plan.duration_s * rate_hz)
        n_before = round(plan.ground_before_s * rate_hz) * n_sub
        n_after = round(plan.ground_after_s * rate_hz) * n_sub
        n_total = n_before + n_steps * n_sub + n_after
        time_s = (plan.log_start_us + step_us * np.arange(n_total, dtype=np.int64)) / 1e6
        return cls(time_s=time_s, step_us=step_us, n_steps=n_steps, n_before=n_before, n_after=n_after)

    @property
    def takeoff_s(self) -> float:
        return float(self.time_s[self.n_before])

    def airborne(self) -> np.ndarray:
        flying = np.zeros(self.time_s.size, bool)
        flying[self.n_before : self.time_s.size - self.n_after] = True
        return flying

    def armed(self) -> np.ndarray:
        """Armed 1 s after the log starts until 1 s before it ends."""
        second = int(1.0e6 / self.step_us)
        armed = np.zeros(self.time_s.size, bool)
        armed[second : self.time_s.size - second] = True
        return armed


def _shift(m: ManeuverTruth, takeoff_s: float) -> ManeuverTruth:
    """The maneuver with bounds moved from flight time to the log clock."""
    return replace(m, start_s=m.start_s + takeoff_s, end_s=m.end_s + takeoff_s)


def _initial_state(loop: ClosedLoop, plant: HoverPlant, case: Case) -> np.ndarray:
    """On the ground, level, at rest over the ground: the plant's perturbation from hover trim."""
    x0 = np.zeros(len(loop.states))
    index = {name: k for k, name in enumerate(loop.states)}
    x0[index["z_d"]] = case.plan.hover_height_m
    x0[index["theta"]] = -plant.trim.theta0
    if case.wind is not None:
        x0[index["u"]] = case.wind.mean_speed_m_s - plant.trim.U0
        x0[index["w"]] = -plant.trim.W0
    return x0


def _run(loop: ClosedLoop, W: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """States X[0..n] of ``X[k+1] = A X[k] + B W[k]``."""
    forcing = W @ loop.B.T
    X = np.empty((W.shape[0] + 1, x0.size))
    X[0] = x0
    A = loop.A
    x = x0
    for k in range(W.shape[0]):
        x = A @ x + forcing[k]
        X[k + 1] = x
    return X


def _run_forced(
    loop: ClosedLoop, W: np.ndarray, x0: np.ndarray, forcing: EffectForcing, added_out: np.ndarray
) -> np.ndarray:
    """States X[0..n] with the effects' disturbances computed from each step's state (W updated in place).

    A disturbance input without delay enters step k as ``name@cur`` and step k + 1 as ``name@prev``.
    The effects' accelerations of each step are written to `added_out`, shape (n, 6).
    """
    column = {name: k for k, name in enumerate(loop.inputs)}
    for name in FORCED:
        if loop.maps[PLANT_INPUTS.index(name)].n_periods != 0:
            raise ValueError(f"{name} must enter without delay")
    cur = [column[f"{name}@cur"] for name in FORCED]
    prev = [column[f"{name}@prev"] for name in FORCED]
    thrust_row = loop.outputs.index("delta_thr")
    context, laws = forcing.context, forcing.laws()
    A, B, C_thr, D_thr = loop.A, loop.B, loop.C[thrust_row], loop.D[thrust_row]
    s = {name: k for k, name in enumerate(STATES)}
    yaw_input = loop.states.index(f"buf_delta_yaw_{loop.maps[PLANT_INPUTS.index('delta_yaw')].n_periods}")
    if STATES[:6] != ("u", "v", "w", "p", "q", "r") or STATES[9:12] != ("d_lat", "d_lon", "d_thr"):
        raise ValueError("the plant's states are out of the order the effects read them in")
    own = loop.plant.A[[s["u"], s["v"]]]  # u' and v' of the plant alone
    air_trim, trim = loop.plant.air_velocity_trim, context.trim_commands
    commands = np.empty(4)
    X = np.empty((W.shape[0] + 1, x0.size))
    X[0] = x = x0
    for k in range(W.shape[0]):
        commands[:2], commands[2], commands[3] = x[9:11], x[yaw_input], x[11]
        step = Step(
            t_s=k * loop.period_s,
            height_m=context.hover_height_m - x[s["z_d"]],
            air_m_s=x[:3] + air_trim,
            rates_rad_s=x[3:6],
            phi=x[s["phi"]],
            theta=x[s["theta"]],
            d_lat=x[9],
            d_lon=x[10],
            d_thr=x[11],
            commands=commands + trim,
            thrust=context.gravity - context.z_thr * x[11],
            thrust_command=float(trim[3] + C_thr @ x + D_thr @ W[k]),
            accel_sim=own @ x[: len(STATES)],
        )
        added = laws[0](step)
        for law in laws[1:]:
            added = added + law(step)
        W[k, cur] += added
        added_out[k] = added
        if k + 1 < W.shape[0]:
            W[k + 1, prev] += added
        x = A @ x + B @ W[k]
        X[k + 1] = x
    return X


def _lift(
    loop: ClosedLoop,
    x: np.ndarray,
    outputs: Mapping[str, np.ndarray],
    external: Mapping[str, tuple[np.ndarray, np.ndarray]],
) -> tuple[np.ndarray, np.ndarray]:
    """Plant states and the derivatives the accelerometers feel on the fine grid, shape (n_steps * n_sub, 15) each."""
    n_steps, m_sub = x.shape[0], loop.n_sub
    A, B = loop.plant.A, loop.plant.B
    prev = np.zeros((n_steps, len(PLANT_INPUTS)))
    cur = np.zeros_like(prev)
    for j, name in enumerate(PLANT_INPUTS):
        if name in MIXER:
            n = loop.maps[j].n_periods
            delta = np.concatenate([np.zeros(n + 1), outputs[name]])
            prev[:, j], cur[:, j] = delta[:n_steps], delta[1 : n_steps + 1]
        else:
            prev[:, j], cur[:, j] = external[name]
    h = loop.period_s / m_sub
    phis = np.array([propagator(A, B[:, :1], m * h)[0] for m in range(m_sub)])
    before = np.zeros((len(PLANT_INPUTS), m_sub, len(STATES)))
    after = np.zeros_like(before)
    active = np.zeros((m_sub, len(PLANT_INPUTS)), bool)
    for j, maps in enumerate(loop.maps):
        before[j, 1:], after[j, 1:] = maps.before[:-1], maps.after[:-1]
        active[:, j] = maps.active_after[:m_sub]
    fine = np.einsum("mij,kj->kmi", phis, x)
    fine += np.einsum("kj,jmi->kmi", prev, before) + np.einsum("kj,jmi->kmi", cur, after)
    acting = np.where(active[None, :, :], cur[:, None, :], prev[:, None, :])
    felt = B.copy()  # the air's own acceleration changes u and v, but no accelerometer feels it
    felt[:, [PLANT_INPUTS.index(name) for name in AIR_INPUTS]] = 0.0
    derivative = fine @ A.T + acting @ felt.T
    return fine.reshape(-1, len(STATES)), derivative.reshape(-1, len(STATES))


def _rotation(phi: np.ndarray, theta: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Body (FRD) → NED rotation matrices, shape (n, 3, 3)."""
    cf, sf, ct, st, cp, sp = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta), np.cos(psi), np.sin(psi)
    return np.stack(
        [
            np.stack([ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp], -1),
            np.stack([ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp], -1),
            np.stack([-st, sf * ct, cf * ct], -1),
        ],
        -2,
    )


def _wrap(angle: np.ndarray) -> np.ndarray:
    return np.pi - np.mod(np.pi - angle, 2 * np.pi)


def _compose(
    plant: HoverPlant,
    loop: ClosedLoop,
    x: np.ndarray,
    xdot: np.ndarray,
    outputs: Mapping[str, np.ndarray],
    W: np.ndarray,
    case: Case,
) -> dict[str, np.ndarray]:
    """Airborne signals on the fine grid with trim added (ground velocities from eq. 3.1 inverted)."""
    trim, s = plant.trim, {name: k for k, name in enumerate(STATES)}

    def hold(values: np.ndarray) -> np.ndarray:
        """Control-rate values held on the fine grid."""
        return np.repeat(values, loop.n_sub)

    out = {name: x[:, s[name]].copy() for name in ("p", "q", "r", "x_n", "y_e")}
    out["phi"], out["theta"] = x[:, s["phi"]], trim.theta0 + x[:, s["theta"]]
    out["psi"] = _wrap(trim.psi0 + x[:, s["psi"]])
    out["height"] = case.plan.hover_height_m - x[:, s["z_d"]]
    accel = np.hstack([x, xdot]) @ loop.plant.accel_rows.T + loop.plant.accel_trim
    out["ax"], out["ay"], out["az"] = accel.T
    air = x[:, [s["u"], s["v"], s["w"]]] + loop.plant.air_velocity_trim
    wind = np.zeros((x.shape[0], 3))
    if case.wind is not None:
        column = {name: k for k, name in enumerate(loop.inputs)}
        gust = W[:, [column["wind_n@cur"], column["wind_e@cur"]]] + case.wind.mean_ned
        wind[:, :2] = np.repeat(gust, loop.n_sub, axis=0)
    velocity = np.einsum("kij,kj->ki", _rotation(out["phi"], out["theta"], out["psi"]), air) + wind
    out["vn"], out["ve"], out["vd"] = velocity.T
    out["wind_n"], out["wind_e"] = wind[:, 0], wind[:, 1]
    for name in MIXER:
        out[name] = hold(outputs[name]) + getattr(trim, name)
    for axis in ("lat", "lon", "thr"):  # for tests only: the lagged inputs of eq. 3.2, trim included
        out[f"actuator_{axis}"] = x[:, s[f"d_{axis}"]] + getattr(trim, f"delta_{axis}")
    for name in ("p_sp", "q_sp", "r_sp", "phi_sp", "vn_sp", "ve_sp", "vd_sp"):
        out[name] = hold(outputs[name])
    out["theta_sp"] = hold(outputs["theta_sp"]) + trim.theta0
    out["psi_sp"] = np.full(x.shape[0], _wrap(np.array(trim.psi0)))
    column = {name: k for k, name in enumerate(loop.inputs)}
    stick = {  # canonical senses: right, back (nose up), right, up
        "stick_lat": W[:, column["exc_attitude_lat"]] / MAX_TILT_RAD,
        "stick_lon": W[:, column["exc_attitude_lon"]] / MAX_TILT_RAD,
        "stick_yaw": W[:, column["exc_rate_yaw"]] / MAX_YAW_RATE_RAD_S,
        "stick_thr": W[:, column["exc_climb_thr"]] / MAX_CLIMB_M_S,
    }
    for name, values in stick.items():
        out[name] = hold(values)
    out["height_sp"] = hold(case.plan.hover_height_m - W[:, column["sp_zd"]])
    for axis in ("lat", "lon", "yaw", "thr"):  # for tests only: never written to a log
        out[f"exc_mixer_{axis}"] = hold(W[:, column[f"exc_mixer_{axis}"]])
    return out


def _with_ground(
    flight: Mapping[str, np.ndarray], plant: HoverPlant, grid: _Grid, field_: WindField | None
) -> dict[str, np.ndarray]:
    """Prepend and append the vehicle standing level on the ground, motors idle."""
    n_before, n_after, time_s = grid.n_before, grid.n_after, grid.time_s
    out = {}
    level = {
        "az": -G,
        "psi": float(_wrap(np.array(plant.trim.psi0))),
        "psi_sp": float(_wrap(np.array(plant.trim.psi0))),
    }
    for name, values in flight.items():
        before = np.full(n_before, level.get(name, 0.0))
        after = np.full(n_after, level.get(name, 0.0))
        if name in ("x_n", "y_e"):
            after[:] = values[-1]
        out[name] = np.concatenate([before, values, after])
    if field_ is not None:
        wind = field_.at_vehicle(time_s)
        ground = np.ones(time_s.size, bool)
        ground[n_before : time_s.size - n_after] = False
        out["wind_n"][ground], out["wind_e"][ground] = wind[ground, 0], wind[ground, 1]
    rotation = _rotation(out["phi"], out["theta"], out["psi"])
    relative = np.column_stack([out["vn"] - out["wind_n"], out["ve"] - out["wind_e"], out["vd"]])
    out["u"], out["v"], out["w"] = np.einsum("kji,kj->ki", rotation, relative).T  # eq. 3.1
    return out


def _measure(
    truth: Mapping[str, np.ndarray], errors: Mapping[str, np.ndarray], case: Case, felt: Mapping[str, np.ndarray]
) -> dict[str, np.ndarray]:
    """Sensor outputs: truth (and what only the sensor `felt`, e.g. vibration) scaled, plus the errors the controller also saw."""
    scales: dict[str, float] = {}
    for effect in case.effects:
        if isinstance(effect, GyroScale | AccelScale):
            scales.update(effect.scales)
    measured = {
        name: scales.get(name, 1.0) * (truth[name] + felt.get(name, 0.0)) + errors[name]
        for name in ("p", "q", "r", "ax", "ay", "az")
    }
    measured.update({name: truth[name] + errors[name] for name in ("phi", "theta")})
    measured["psi"] = _wrap(truth["psi"] + errors["psi"])
    for name in ("vn", "ve", "vd", "x_n", "y_e"):
        measured[name] = truth[name] + errors[name]
    measured["height"] = truth["height"] - errors["z_d"]
    return measured
