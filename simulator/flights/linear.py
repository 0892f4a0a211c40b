"""Closed-loop hover flights of the chapter 3 linear model (eqs. 3.10-3.13), with wind.

A small, exact-truth flight generator: the identified octocopter model of
Table 3.3 (calm), optionally with the wind terms of Table 3.5, flown by an LQR
hover controller with excitation summed at the mixer input. The full
nonlinear simulator builds on the same outputs.

The model's axes are the body's: ``u`` along the nose, ``v`` to the right. The
wind (north, east) reaches them turned by the yaw state ``psi``, and the ground
velocity is logged turned back, so a log read with its own heading gives the
airspeeds the dynamics used. (The yaw sweep turns the vehicle by up to 30 deg.
The airframe used to feel the wind as if it kept heading north while the logged
heading turned: in a fleet flight's 1.4 m/s wind the lateral airspeed read from
the log carried about 0.07 m/s RMS the airframe never felt, a model fitted on
that log had its ``L_v`` and ``Y_v`` 6.5 % short, and the same vehicle in another
wind was named a CG offset.)

The states are linear perturbations in the heading frame: ``vd`` is ``w``, and
pitch and roll do not turn the logged velocity. Turning it by the whole
attitude (``R_b^i [u v w]``) looks more exact but is not, for this model: its
dynamics have no ``q u - p v`` terms, so the mean airspeed a wind puts into
``u`` would, turned by the pitch, make the vehicle climb at ``theta * W`` that
its heave never felt. Tried on a 40-log fleet (issue 33): 30 of 40 fits
beyond J_ave 100 (median 147) against 5 as written. Ingest still turns the
logged velocity by the whole attitude, as it must for a real log; the
``theta * u`` left in body ``w`` is second order, and
:mod:`sysid.fit.trim_paths` does not fit the response it makes.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import cast

import numpy as np
from scipy import linalg
from scipy import signal as sps

from flightlogs.frames import wind_to_body_axes
from simulator.autopilot.excitation import Axis, Maneuver, excitation_signal, sweep
from simulator.vehicle.identified import CALM_HOVER, G

__all__ = ["WindField", "SimulatedFlight", "HoverSetup", "simulate_hover", "simulate_hovers"]

_AXES: tuple[Axis, ...] = ("lat", "lon", "yaw", "thr")


@dataclass(frozen=True, slots=True, kw_only=True)
class WindField:
    """Horizontal wind: a mean plus frozen turbulence.

    Parameters
    ----------
    mean_speed_m_s : float
        Mean speed M, m/s.
    direction_from_deg : float
        Meteorological direction the wind comes from, deg.
    turbulence_ratio : float
        sigma_M / M of the gusts (below 0.5 for frozen turbulence).
    corner_hz : float
        Corner frequency of the second-order gust spectrum, Hz.
    """

    mean_speed_m_s: float = 2.7
    direction_from_deg: float = 0.0
    turbulence_ratio: float = 0.2
    corner_hz: float = 0.3

    def sample(self, time_s: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Wind ``(wind_n, wind_e)`` at a fixed point, m/s, shape (n_samples, 2).

        Parameters
        ----------
        time_s : ndarray, shape (n_samples,)
            Uniform times, s.
        rng : numpy.random.Generator
            Noise source.
        """
        rate = 1.0 / float(np.median(np.diff(time_s)))
        # second-order roll-off: gusts carry little power above a few Hz, so the 20 Hz
        # anemometer and the 25 Hz EKF estimate sample them without aliasing
        sos = sps.butter(2, self.corner_hz, fs=rate, output="sos")
        gusts = sps.sosfilt(sos, rng.normal(size=(time_s.size, 2)), axis=0)
        gusts *= self.turbulence_ratio * self.mean_speed_m_s / gusts[time_s.size // 10 :].std(axis=0)
        towards = np.radians(self.direction_from_deg) + np.pi
        mean = self.mean_speed_m_s * np.array([np.cos(towards), np.sin(towards)])
        return cast(np.ndarray, mean + gusts)


@dataclass(frozen=True, slots=True, kw_only=True)
class SimulatedFlight:
    """Truth and measurements of one simulated flight on its 100 Hz log clock.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Log times, s.
    signals : Mapping[str, ndarray]
        Canonical signals as the autopilot logs them (SI; mixer inputs in %).
    wind_at_vehicle : ndarray, shape (n_samples, 2)
        ``wind_n, wind_e`` at the vehicle, m/s.
    maneuvers : tuple of Maneuver
        The excitation flown.
    parameters : Mapping[str, float]
        Model parameters used (the truth).
    """

    time_s: np.ndarray
    signals: Mapping[str, np.ndarray]
    wind_at_vehicle: np.ndarray
    maneuvers: tuple[Maneuver, ...]
    parameters: Mapping[str, float] = field(default_factory=dict)


def _axis_models(p: Mapping[str, float]) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Continuous (A, B) per axis; states lat [v, p, phi, d], lon [u, q, theta, d], yaw [r, psi], thr [w, z, d]."""
    inv = 1.0 / p["T_a"]
    lat = np.array([[p["Y_v"], 0, G, p["Y_lat"]], [p["L_v"], 0, 0, p["L_lat"]], [0, 1, 0, 0], [0, 0, 0, -inv]])
    lon = np.array([[p["X_u"], 0, -G, p["X_lon"]], [p["M_u"], 0, 0, p["M_lon"]], [0, 1, 0, 0], [0, 0, 0, -inv]])
    yaw = np.array([[0.0, 0], [1, 0]])
    thr = np.array([[0, 0, p["Z_thr"]], [-1.0, 0, 0], [0, 0, -inv]])  # z is height (up), w is down
    return {
        "lat": (lat, np.array([[0], [0], [0], [inv]])),
        "lon": (lon, np.array([[0], [0], [0], [inv]])),
        "yaw": (yaw, np.array([[p["N_yaw"]], [0]])),
        "thr": (thr, np.array([[0], [0], [inv]])),
    }


def _trim_states(
    models: Mapping[str, tuple[np.ndarray, np.ndarray]], gains: Mapping[str, np.ndarray], wind_ne: np.ndarray
) -> dict[str, np.ndarray]:
    """Equilibrium of each loop in a steady wind, so a flight starts in trim rather than in a transient.

    The controller feeds back ground velocity (airspeed + wind): x' = (A - B K) x - B K d = 0 with
    d the wind on the velocity state.
    """
    states = {}
    for axis, (a, b) in models.items():
        disturbance = np.zeros(a.shape[0])
        if axis in ("lon", "lat"):
            disturbance[0] = wind_ne[0] if axis == "lon" else wind_ne[1]
        k = gains[axis][None, :]
        states[axis] = np.linalg.solve(a - b @ k, b @ k @ disturbance)
    return states


def _lqr(a: np.ndarray, b: np.ndarray, weights: np.ndarray) -> np.ndarray:
    x = linalg.solve_continuous_are(a, b, np.diag(weights), np.eye(1) * 0.02)
    return cast(np.ndarray, (b.T @ x / 0.02).ravel())


_WEIGHTS = {"lat": [2.0, 1.0, 20.0, 0.0], "lon": [2.0, 1.0, 20.0, 0.0], "yaw": [1.0, 5.0], "thr": [1.0, 2.0, 0.0]}


@dataclass(frozen=True, slots=True, kw_only=True)
class HoverSetup:
    """What differs between flights flown together by :func:`simulate_hovers`.

    Parameters
    ----------
    parameters : Mapping[str, float], optional
        Bare-airframe model (Table 3.3 names); default the calm model.
    wind : WindField, optional
        Wind at the vehicle; none for still air.
    wind_terms : Mapping[str, float], optional
        ``X_w_lon, Z_w_lon, tau_w_lon, tau_w_thr`` (Table 3.5); none: wind only
        moves the air the vehicle flies in.
    seed : int, optional
        Seed of the gusts and the sensor noise.
    """

    parameters: Mapping[str, float] = field(default_factory=lambda: CALM_HOVER)
    wind: WindField | None = None
    wind_terms: Mapping[str, float] | None = None
    seed: int = 0


def simulate_hover(
    duration_s: float,
    maneuvers: tuple[Maneuver, ...],
    *,
    parameters: Mapping[str, float] = CALM_HOVER,
    wind: WindField | None = None,
    wind_terms: Mapping[str, float] | None = None,
    rate_hz: float = 100.0,
    substeps: int = 5,
    hover_height_m: float = 4.6,
    seed: int = 0,
) -> SimulatedFlight:
    """Fly a hover with excitation, closed loop, and return what the autopilot logs.

    Parameters
    ----------
    duration_s : float
        Flight length, s.
    maneuvers : tuple of Maneuver
        Excitation summed at the mixer input.
    parameters, wind, wind_terms, seed
        As in :class:`HoverSetup`.
    rate_hz : float, optional
        Log rate, Hz.
    substeps : int, optional
        Integration and control steps per log sample (delays are whole integration
        steps); the logged mixer input is the command averaged over the log interval.
    hover_height_m : float, optional
        Trim height above ground, m (the dissertation's 4.6 m, out of ground effect).

    Returns
    -------
    SimulatedFlight
    """
    setup = HoverSetup(parameters=parameters, wind=wind, wind_terms=wind_terms, seed=seed)
    return simulate_hovers(
        duration_s, maneuvers, [setup], rate_hz=rate_hz, substeps=substeps, hover_height_m=hover_height_m
    )[0]


#: Where each axis's states sit in the stacked state of all four loops (:func:`_axis_models`' order).
_SLICES = {"lat": slice(0, 4), "lon": slice(4, 8), "yaw": slice(8, 10), "thr": slice(10, 13)}
_N_STATES = 13
_U, _V, _W = _SLICES["lon"].start, _SLICES["lat"].start, _SLICES["thr"].start  # the velocity states
_PSI = _SLICES["yaw"].start + 1  # the heading from the trim, rad


def simulate_hovers(
    duration_s: float,
    maneuvers: tuple[Maneuver, ...],
    setups: Sequence[HoverSetup],
    *,
    rate_hz: float = 100.0,
    substeps: int = 5,
    hover_height_m: float = 4.6,
) -> list[SimulatedFlight]:
    """Fly several hovers with the same excitation at once: one integration loop for all of them.

    Each flight is what :func:`simulate_hover` flies with its setup; flying
    them together costs about what one costs (the loop's steps, not its
    arithmetic, take the time), which makes a fleet of hundreds of flights cheap.

    Parameters
    ----------
    duration_s : float
        Flight length, s.
    maneuvers : tuple of Maneuver
        Excitation summed at the mixer input, the same in every flight.
    setups : sequence of HoverSetup
        One per flight: its airframe, wind and seed.
    rate_hz, substeps, hover_height_m
        As in :func:`simulate_hover`.

    Returns
    -------
    list of SimulatedFlight
        In the order of `setups`.
    """
    n_flights = len(setups)
    rngs = [np.random.default_rng(setup.seed) for setup in setups]
    dt = 1.0 / (rate_hz * substeps)
    n_fine = int(round(duration_s / dt))
    t_fine = np.arange(n_fine) * dt
    wind_ne = np.stack(
        [s.wind.sample(t_fine, rng) if s.wind is not None else np.zeros((n_fine, 2)) for s, rng in zip(setups, rngs)]
    )
    terms = [dict(s.wind_terms or {}) for s in setups]
    wind_terms = any(terms)
    x_w, z_w = (np.array([t.get(name, 0.0) for t in terms]) for name in ("X_w_lon", "Z_w_lon"))
    w_lon_delay, w_thr_delay = (
        np.array([int(round(t.get(name, 0.0) / dt)) for t in terms]) for name in ("tau_w_lon", "tau_w_thr")
    )
    shapes = ((_N_STATES, _N_STATES), (_N_STATES, len(_AXES)), (len(_AXES), _N_STATES), (3, _N_STATES))
    a_d, b_d, gains, rows = (np.zeros((n_flights, *shape)) for shape in shapes)
    states = np.zeros((n_flights, _N_STATES))
    delays = np.zeros((n_flights, len(_AXES)), dtype=np.intp)
    for f, setup in enumerate(setups):
        models = _axis_models(setup.parameters)
        axis_gains: dict[str, np.ndarray] = {axis: _lqr(*models[axis], np.array(_WEIGHTS[axis])) for axis in _AXES}
        trim = _trim_states(models, axis_gains, wind_ne[f, : max(1, int(round(1.0 / dt)))].mean(axis=0))
        for j, axis in enumerate(_AXES):
            at = _SLICES[axis]
            a, b = models[axis]
            ad, bd = sps.cont2discrete((a, b, np.eye(a.shape[0]), 0), dt)[:2]
            a_d[f, at, at], b_d[f, at, j], gains[f, j, at] = ad, bd.ravel(), axis_gains[axis]
            states[f, at] = trim[axis]
            delays[f, j] = int(round(setup.parameters.get(f"tau_{axis}", 0.0) / dt))
        for r, moved in enumerate(("lon", "lat", "thr")):  # the continuous rows of u', v', w' (logged accelerations)
            rows[f, r, _SLICES[moved]] = models[moved][0][0]
    excitation = np.stack([excitation_signal(t_fine, maneuvers, axis) for axis in _AXES], axis=1)  # (n_fine, 4)
    history = np.zeros((n_fine, n_flights, len(_AXES)))
    n_logged = -(-n_fine // substeps)  # the log's instants: every `substeps`-th step
    logged = np.zeros((n_logged, n_flights, _N_STATES))
    accel = np.zeros((n_logged, n_flights, 3))
    flight, axis_index = np.arange(n_flights)[:, None], np.arange(len(_AXES))[None, :]
    everyone, still = np.arange(n_flights), np.zeros(n_flights)  # still: no wind terms, no wind along the nose
    for k in range(n_fine):
        # the controller holds ground velocity: airspeed plus the wind along each axis
        psi = states[:, _PSI]
        feedback = states.copy()
        feedback[:, [_U, _V]] += wind_to_body_axes(wind_ne[:, k], psi)
        history[k] = excitation[k] - np.matmul(gains, feedback[:, :, None])[:, :, 0]
        wind_lon_u = wind_lon_w = still
        if wind_terms:  # Table 3.5's terms on the wind along the nose, each its own delay earlier
            wind_lon_u = wind_to_body_axes(wind_ne[everyone, np.maximum(k - w_lon_delay, 0)], psi)[:, 0]
            wind_lon_w = wind_to_body_axes(wind_ne[everyone, np.maximum(k - w_thr_delay, 0)], psi)[:, 0]
        if k % substeps == 0:
            j = k // substeps
            logged[j] = states
            accel[j] = np.matmul(rows, states[:, :, None])[:, :, 0]
            accel[j, :, 0] += x_w * wind_lon_u
            accel[j, :, 2] += z_w * wind_lon_w
        command = history[np.maximum(k - delays, 0), flight, axis_index]
        states = np.matmul(a_d, states[:, :, None])[:, :, 0] + np.matmul(b_d, command[:, :, None])[:, :, 0]
        states[:, _U] += dt * x_w * wind_lon_u
        states[:, _W] += dt * z_w * wind_lon_w
    return [
        _flight(
            t_fine,
            logged[:, f],
            accel[:, f],
            history[:, f],
            wind_ne[f],
            maneuvers,
            dict(setups[f].parameters) | terms[f],
            substeps,
            hover_height_m,
            rngs[f],
        )
        for f in range(n_flights)
    ]


def _flight(
    t_fine: np.ndarray,
    states: np.ndarray,
    accel: np.ndarray,
    history: np.ndarray,
    wind_ne: np.ndarray,
    maneuvers: tuple[Maneuver, ...],
    truth: dict[str, float],
    substeps: int,
    hover_height_m: float,
    rng: np.random.Generator,
) -> SimulatedFlight:
    """One flight's log from its states (n_logged, 13) and accelerations (n_logged, 3) at the log's instants
    and its commands at every integration step (n_fine, 4)."""
    pick = slice(0, t_fine.size, substeps)
    lat, lon, yaw, thr = (states[:, _SLICES[axis]] for axis in _AXES)
    signals = {
        "u": lon[:, 0], "v": lat[:, 0], "w": thr[:, 0],
        "p": lat[:, 1], "q": lon[:, 1], "r": yaw[:, 0],
        "phi": lat[:, 2], "theta": lon[:, 2], "psi": yaw[:, 1],
        "ax": accel[:, 0] + G * lon[:, 2],  # eq. 3.7 at zero trim
        "ay": accel[:, 1] - G * lat[:, 2],
        "az": accel[:, 2] - G,
        "height_agl": hover_height_m + thr[:, 1],
    }  # fmt: skip
    # the logger averages the fast command over each log interval, centred on the log instant (a boxcar
    # anti-alias filter, zero phase): picking every `substeps`-th command instead would log the
    # feedback's within-interval change as a timing error of a few ms, which the unstable open-loop
    # pitch and roll modes amplify in any time-domain check
    boxcar = np.ones(substeps) / substeps
    for j, axis in enumerate(_AXES):
        signals[f"delta_{axis}"] = np.convolve(history[:, j], boxcar, mode="same")[pick]
    signals = {name: np.ascontiguousarray(values) for name, values in signals.items()}
    # the body-axis airspeeds turned back to north and east by the heading, plus the wind
    ground_ne = wind_to_body_axes(np.column_stack([signals["u"], signals["v"]]), -signals["psi"])
    signals["vn"] = ground_ne[:, 0] + wind_ne[pick, 0]
    signals["ve"] = ground_ne[:, 1] + wind_ne[pick, 1]
    signals["vd"] = signals["w"]
    _add_sensor_noise(signals, rng)
    return SimulatedFlight(
        time_s=t_fine[pick],
        signals=MappingProxyType(signals),
        wind_at_vehicle=np.ascontiguousarray(wind_ne[pick]),
        maneuvers=tuple(maneuvers),
        parameters=MappingProxyType(truth),
    )


_NOISE = {
    "p": 0.005,
    "q": 0.005,
    "r": 0.005,
    "ax": 0.03,
    "ay": 0.03,
    "az": 0.05,
    "phi": 0.001,
    "theta": 0.001,
    "psi": 0.002,
    "vn": 0.02,
    "ve": 0.02,
    "vd": 0.02,
}


def _add_sensor_noise(signals: dict[str, np.ndarray], rng: np.random.Generator) -> None:
    for name, sigma in _NOISE.items():
        signals[name] = signals[name] + rng.normal(scale=sigma, size=signals[name].size)


def sweep_frequency(time_s: np.ndarray, maneuver: Maneuver) -> np.ndarray:
    """Instantaneous sweep frequency, Hz, shape (n_samples,) (zero outside the sweep)."""
    return sweep(time_s, maneuver)[1]
