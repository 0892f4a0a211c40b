"""What an effect's law sees at one control step: the plant's constants and the state the loop has reached."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["PlantContext", "Step"]


@dataclass(frozen=True, slots=True, kw_only=True)
class PlantContext:
    """Constants of the flown plant that the effects' laws use.

    Parameters
    ----------
    gravity : float
        g, m/s².
    z_thr : float
        Z_thr, m/s² per unit of the thrust input (negative: more thrust accelerates up).
    l_lat, m_lon, n_yaw : float
        L_lat, M_lon, N_yaw, rad/s² per unit of the roll, pitch and yaw inputs.
    trim_commands : ndarray, shape (4,)
        Mixer inputs at trim ``(delta_lat, delta_lon, delta_yaw, delta_thr)``, normalised.
    trim_theta_rad : float
        Trim pitch, rad.
    hover_height_m : float
        Height at which ``z_d`` is zero, m.
    period_s : float
        Control period (the step of a law's own state), s.
    """

    gravity: float
    z_thr: float
    l_lat: float
    m_lon: float
    n_yaw: float
    trim_commands: np.ndarray
    trim_theta_rad: float
    hover_height_m: float
    period_s: float

    def __post_init__(self) -> None:
        if np.shape(self.trim_commands) != (4,):
            raise ValueError(f"trim_commands has shape {np.shape(self.trim_commands)}, expected (4,)")
        if self.period_s <= 0.0:
            raise ValueError(f"{self.period_s=} s must be > 0")


@dataclass(slots=True, kw_only=True)
class Step:
    """The state the closed loop has reached at one control step (a snapshot made anew at each step).

    Not frozen: one is built at each of a flight's 60 000 control steps, and a frozen dataclass's
    ``__init__`` costs twice as much.

    Parameters
    ----------
    t_s : float
        Time after take-off, s.
    height_m : float
        Height of the logged reference point over the ground, m.
    air_m_s : ndarray, shape (3,)
        Body air-relative velocity ``(U0 + u, v, W0 + w)``, m/s (FRD).
    rates_rad_s : ndarray, shape (3,)
        Body rates ``p q r``, rad/s.
    phi, theta : float
        Roll and pitch, perturbation from trim, rad.
    d_lat, d_lon, d_thr : float
        Lagged mixer inputs of eq. 3.2 (what the rotors produce), perturbation from trim.
    commands : ndarray, shape (4,)
        What the rotors produce as mixer inputs, trim included: lagged ``lat lon thr``, the yaw input
        after its delay; order ``(lat, lon, yaw, thr)``.
    thrust : float
        Specific thrust of the plant, ``g - Z_thr d_thr``, m/s² (up).
    thrust_command : float
        Thrust command as logged now (trim included), normalised.
    accel_sim : ndarray, shape (2,)
        ``u'`` and ``v'`` of the plant alone (without the effects), m/s².
    """

    t_s: float
    height_m: float
    air_m_s: np.ndarray
    rates_rad_s: np.ndarray
    phi: float
    theta: float
    d_lat: float
    d_lon: float
    d_thr: float
    commands: np.ndarray
    thrust: float
    thrust_command: float
    accel_sim: np.ndarray
