"""Batch simulator: many closed-loop trials of the nonlinear vehicle at once.

All trials of equal length advance together: the state is one array
``(n_trials, n_states)``, integrated by fixed-step RK4 (400 Hz by default)
with the rotor commands and the wind held over a step; per-axis transport
delays are ring buffers of mixer inputs with linear interpolation between
steps. Every operation is element-wise per trial, so a trial gives the same
numbers alone as in a batch. Signals are logged at 100 Hz as
:class:`NonlinearFlight` (a :class:`~simulator.flights.linear.SimulatedFlight`
with the anemometer's record and the clean truth added), which the log
writers of :mod:`simulator.output.ardupilot` accept.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from types import MappingProxyType
from typing import Literal

import numpy as np

from simulator.autopilot.control import ControllerGains, design_gains
from simulator.flights._batch import NonlinearFlight, run_batch
from simulator.flights.trial import Trial
from simulator.vehicle.linearize import hover_derivatives, linearize_hover
from simulator.vehicle.multirotor import Vehicle
from simulator.vehicle.presets import OCTO_S1000

__all__ = ["Trial", "NonlinearFlight", "simulate_flights", "truth_parameters"]


_TRUTH_CACHE: dict[int, tuple[Vehicle, dict[str, float]]] = {}  # the vehicle is kept so its id stays its own


def truth_parameters(vehicle: Vehicle) -> dict[str, float]:
    """Hover derivatives of `vehicle` (Table 3.3 names) from its linearisation: the truth of its flights.

    Parameters
    ----------
    vehicle : Vehicle
        The vehicle.

    Returns
    -------
    dict of str to float
    """
    key = id(vehicle)
    if key not in _TRUTH_CACHE:
        _TRUTH_CACHE[key] = (vehicle, hover_derivatives(linearize_hover(vehicle)) | {"mass_kg": vehicle.mass_kg})
    return dict(_TRUTH_CACHE[key][1])


def simulate_flights(
    trials: list[Trial],
    vehicle: Vehicle = OCTO_S1000,
    *,
    rate_hz: float = 400.0,
    log_rate_hz: float = 100.0,
    gains: ControllerGains | None = None,
    method: Literal["rk4", "euler"] = "rk4",
    progress: Callable[[int, int], None] | None = None,
) -> list[NonlinearFlight]:
    """Fly every trial closed loop and return what the autopilot logs.

    Parameters
    ----------
    trials : list of Trial
        The flights; those with the same number of steps run as one batch.
    vehicle : Vehicle, optional
        The vehicle (all trials).
    rate_hz : float, optional
        Integration and control rate, Hz (a multiple of `log_rate_hz`).
    log_rate_hz : float, optional
        Log rate, Hz.
    gains : ControllerGains, optional
        Controller; default :func:`~simulator.autopilot.control.design_gains` on the vehicle's hover model.
    method : {"rk4", "euler"}, optional
        Fixed-step RK4, or semi-implicit Euler (velocities first), four times cheaper.
    progress : callable, optional
        Called as ``progress(steps_done, steps_total)`` every 100 log samples of each batch.

    Returns
    -------
    list of NonlinearFlight
        In the order of `trials`.

    Examples
    --------
    >>> from simulator.world.environment import Environment
    >>> flight = simulate_flights([Trial(duration_s=1.0, environment=Environment())])[0]
    >>> flight.signals["az"].size, round(float(np.mean(flight.truth["az"])), 2)
    (100, -9.81)
    """
    decimation = rate_hz / log_rate_hz
    if abs(decimation - round(decimation)) > 1e-9 or decimation < 1:
        raise ValueError(f"rate_hz={rate_hz} must be a whole multiple of log_rate_hz={log_rate_hz}")
    if not trials:
        return []
    truth = truth_parameters(vehicle)
    gains = gains or design_gains(truth)
    groups: dict[int, list[int]] = {}
    for index, trial in enumerate(trials):
        groups.setdefault(int(round(trial.duration_s * log_rate_hz)), []).append(index)
    flights: list[NonlinearFlight | None] = [None] * len(trials)
    for n_log, members in sorted(groups.items()):
        batch = run_batch(
            [trials[i] for i in members],
            vehicle,
            gains,
            n_log=n_log,
            rate_hz=rate_hz,
            decimation=int(round(decimation)),
            method=method,
            progress=progress,
        )
        for i, flight in zip(members, batch):
            flights[i] = _with_truth(flight, truth, trials[i])
    return [f for f in flights if f is not None]


def _with_truth(flight: NonlinearFlight, truth: Mapping[str, float], trial: Trial) -> NonlinearFlight:
    env = trial.environment
    settings = {
        "wind_speed_m_s": env.wind.mean_speed_m_s,
        "wind_from_deg": env.wind.direction_from_deg,
        "hover_height_m": trial.hover_height_m,
        "heading_deg": float(np.degrees(trial.heading_rad)),
        "anemometer_distance_m": env.anemometer.distance_m,
        "transport_delay_s": flight.transport_delay_s,
        "rotor_drag": float(env.rotor_drag),
        "thrust_sag": float(env.thrust_sag),
        "payload_kg": env.payload.delta_mass_kg if env.payload else 0.0,
        "payload_time_s": env.payload.time_s if env.payload else 0.0,
        "cg_x_m": env.cg_offset_m[0],
        "cg_y_m": env.cg_offset_m[1],
        "cg_z_m": env.cg_offset_m[2],
        "seed": float(trial.seed),
    }
    return NonlinearFlight(
        time_s=flight.time_s,
        signals=flight.signals,
        wind_at_vehicle=flight.wind_at_vehicle,
        maneuvers=flight.maneuvers,
        parameters=MappingProxyType(dict(truth) | settings),
        wind_at_anemometer=flight.wind_at_anemometer,
        anemometer_ne_m=flight.anemometer_ne_m,
        transport_delay_s=flight.transport_delay_s,
        truth=flight.truth,
        injections=flight.injections,
        label=flight.label,
    )
