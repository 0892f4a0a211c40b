"""Everything that enters the closed loop from outside: sensor errors, setpoints, excitation, wind, gusts."""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from scipy.signal import lfilter

from independent_sim.control import MIXER, ClosedLoop
from independent_sim.flight import ManeuverTruth
from independent_sim.plant import PLANT_INPUTS, HoverPlant
from independent_sim.scenario import Case, FlightPlan, NoiseModel
from independent_sim.wind import WindField

__all__ = ["sensor_errors", "exogenous_inputs", "height_fraction"]


def _colored(n: int, dt: float, tau_s: float, std: float, rng: np.random.Generator) -> np.ndarray:
    """First-order (Gauss-Markov) noise of standard deviation `std` and correlation time `tau_s`."""
    if std == 0.0:
        return np.zeros(n)
    a = math.exp(-dt / tau_s)
    settle = int(5 * tau_s / dt)
    out = lfilter([math.sqrt(1 - a * a)], [1.0, -a], rng.standard_normal(n + settle))[settle:]
    return std * out


def sensor_errors(noise: NoiseModel, n: int, dt: float, rng: np.random.Generator) -> dict[str, np.ndarray]:
    """Error of each measured signal on the fine grid (bias, white and wandering parts)."""
    errors = {}
    for names, white, bias, drift in (
        (("p", "q", "r"), noise.gyro_std, noise.gyro_bias_std, 0.0),
        (("ax", "ay", "az"), noise.accel_std, noise.accel_bias_std, 0.0),
        (("phi", "theta", "psi"), noise.attitude_std, 0.0, noise.attitude_drift_std),
        (("vn", "ve", "vd"), noise.velocity_std, 0.0, noise.velocity_drift_std),
        (("x_n", "y_e", "z_d"), noise.position_std, 0.0, noise.position_drift_std),
    ):
        for name in names:
            errors[name] = (
                bias * rng.standard_normal()
                + white * rng.standard_normal(n)
                + _colored(n, dt, noise.drift_tau_s, drift, rng)
            )
    return errors


def _smoothstep(x: np.ndarray) -> np.ndarray:
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def height_fraction(plan: FlightPlan, t: np.ndarray) -> np.ndarray:
    """Height setpoint over hover height: 0 on the ground, smooth climb and descent, 1 in the hover."""
    climb = _smoothstep(t / plan.takeoff_s)
    descent = _smoothstep((t - (plan.duration_s - plan.landing_s - 1.0)) / plan.landing_s)
    return climb - descent


def exogenous_inputs(
    case: Case,
    loop: ClosedLoop,
    plant: HoverPlant,
    t: np.ndarray,
    takeoff_s: float,
    noise: Mapping[str, np.ndarray],
    n_before: int,
    field_: WindField | None,
    rng: np.random.Generator,
) -> tuple[np.ndarray, dict[str, tuple[np.ndarray, np.ndarray]], list[ManeuverTruth]]:
    """The input matrix W (n_steps, n_inputs), external plant inputs as (prev, cur), maneuvers."""
    plan, n = case.plan, t.size
    columns: dict[str, np.ndarray] = {name: np.zeros(n) for name in loop.inputs}
    at_control = n_before + loop.n_sub * np.arange(n)
    for name in ("p", "q", "r", "phi", "theta", "psi", "vn", "ve", "vd"):
        columns[f"n_{name}"] = noise[name][at_control]
    for name in ("x_n", "y_e", "z_d"):
        columns[{"x_n": "n_xn", "y_e": "n_ye", "z_d": "n_zd"}[name]] = noise[name][at_control]
    columns["sp_zd"] = plan.hover_height_m * (1.0 - height_fraction(plan, t))
    for move in plan.repositions:
        ramp = _smoothstep((t - move.start_s) / move.duration_s)
        columns["sp_xn"] += move.north_m * ramp
        columns["sp_ye"] += move.east_m * ramp
    for change in plan.height_changes:
        columns["sp_zd"] += change.down_m * _smoothstep((t - change.start_s) / change.duration_s)
    maneuvers = []
    for m in case.maneuvers:
        signal = m.design.render(t, m.start_s, m.amplitude, rng)
        columns[m.channel] += signal.values
        band = m.design.band_hz
        maneuvers.append(
            ManeuverTruth(
                axis=m.axis,
                kind=m.design.kind,
                label=m.design.label,
                injection=m.injection,
                start_s=signal.start_s,
                end_s=signal.end_s,
                amplitude=m.amplitude,
                amplitude_unit=m.amplitude_unit,
                f_min_hz=band[0] if band else None,
                f_max_hz=band[1] if band else None,
            )
        )
    external = _external_inputs(case, loop, plant, t, takeoff_s, field_, rng)
    for name, (prev, cur) in external.items():
        if name not in MIXER:
            columns[f"{name}@prev"], columns[f"{name}@cur"] = prev, cur
    return np.column_stack([columns[name] for name in loop.inputs]), external, maneuvers


def _external_inputs(
    case: Case,
    loop: ClosedLoop,
    plant: HoverPlant,
    t: np.ndarray,
    takeoff_s: float,
    field_: WindField | None,
    rng: np.random.Generator,
) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Held samples ``u[k-n-1]`` and ``u[k-n]`` of every non-mixer plant input (wind, gusts)."""
    period = loop.period_s
    lead = max(m.n_periods for m in loop.maps) + 1
    grid = np.arange(-lead, t.size) * period
    series: dict[str, np.ndarray] = {name: np.zeros(grid.size) for name in PLANT_INPUTS if name not in MIXER}
    if field_ is not None:
        # gusts fade near the ground (the surface layer), with the height setpoint; the mean wind does not
        fade = height_fraction(case.plan, grid)[:, None]
        gust = fade * (field_.at_vehicle(grid + takeoff_s) - field_.model.mean_ned)
        psi0 = plant.trim.psi0
        along = gust[:, 0] * math.cos(psi0) + gust[:, 1] * math.sin(psi0)
        series["wind_lon_x"], series["wind_lon_z"] = along, along
        series["wind_n"], series["wind_e"] = gust[:, 0], gust[:, 1]
        if not plant.has_wind_terms:
            # no G_w: a gust changes the air-relative velocity at once, the ground velocity not (eq. 3.1)
            across = -gust[:, 0] * math.sin(psi0) + gust[:, 1] * math.cos(psi0)
            series["air_accel_lon"] = np.gradient(along, period)
            series["air_accel_lat"] = np.gradient(across, period)
    noise = case.noise
    for axis in "uvwpqr":
        std = noise.force_disturbance_std if axis in "uvw" else noise.moment_disturbance_std
        series[f"dist_{axis}"][lead:] = _colored(t.size, period, noise.disturbance_tau_s, std, rng)
    out = {}
    for j, name in enumerate(PLANT_INPUTS):
        if name in MIXER:
            continue
        n = loop.maps[j].n_periods
        cur = series[name][lead - n : lead - n + t.size]
        prev = series[name][lead - n - 1 : lead - n - 1 + t.size]
        out[name] = (prev, cur)
    return out
