"""What a simulation returns: the flown case on one fine time grid, and its maneuvers' truth."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from independent_sim.control import CascadeGains, ClosedLoop
from independent_sim.plant import HoverPlant
from independent_sim.scenario import Case, LogFormat
from independent_sim.wind import WindField

__all__ = ["ManeuverTruth", "Flight"]


@dataclass(frozen=True, slots=True, kw_only=True)
class ManeuverTruth:
    """Where and what a maneuver really was, on the log's clock.

    Parameters
    ----------
    axis : {"lat", "lon", "yaw", "thr"}
        Mixer axis excited.
    kind : {"sweep", "doublet", "3211", "multisine"}
        Kind, in the workbench's segment vocabulary.
    label : str
        Design, e.g. ``"log chirp up 0.1-10 Hz"``.
    injection : str
        Where it entered the loop.
    start_s, end_s : float
        True bounds on the log clock (the readers' ``time_s``), s.
    amplitude : float
        Peak, in `amplitude_unit`.
    amplitude_unit : str
        ``normalised``, ``rad``, ``rad/s`` or ``m/s``.
    f_min_hz, f_max_hz : float or None
        Band of a sweep or multisine, Hz.
    """

    axis: str
    kind: str
    label: str
    injection: str
    start_s: float
    end_s: float
    amplitude: float
    amplitude_unit: str
    f_min_hz: float | None = None
    f_max_hz: float | None = None


@dataclass(frozen=True, slots=True, kw_only=True)
class Flight:
    """A flown case: every logged quantity on one fine time grid.

    Parameters
    ----------
    case : Case
        What was flown.
    fmt : {"ulog", "dataflash"}
        Autopilot profile used.
    time_s : ndarray, shape (n,)
        Fine grid on the log clock (boot time), s.
    step_us : int
        Fine grid step, µs.
    sub_steps : int
        Fine steps per control period.
    truth : Mapping[str, ndarray]
        True values (trim included), each shape (n,): ``p q r`` rad/s,
        ``phi theta psi`` rad, ``u v w`` (air-relative) and ``vn ve vd`` m/s,
        ``x_n y_e`` m, ``height`` m, ``ax ay az`` m/s², ``delta_*`` (as
        logged), ``p_sp q_sp r_sp``, ``phi_sp theta_sp psi_sp``,
        ``vn_sp ve_sp vd_sp``, ``height_sp`` m, ``stick_lat stick_lon stick_yaw
        stick_thr`` (-1..1: right, back, right, climb; centred unless a pilot
        flies the maneuver), ``wind_n wind_e`` m/s,
        ``exc_mixer_<axis>``, the excitation injected at the mixer, and ``effect_u effect_v effect_w
        effect_p effect_q effect_r``, the accelerations the case's effects added (m/s², rad/s²), and ``actuator_lat actuator_lon
        actuator_thr``, the lagged mixer inputs of eq. 3.2 (what the rotors produce; never logged).
    measured : Mapping[str, ndarray]
        Sensor and estimator outputs: ``p q r ax ay az phi theta psi vn ve vd x_n y_e height``.
    armed, airborne : ndarray of bool, shape (n,)
        Arming and flight state.
    maneuvers : tuple of ManeuverTruth
        Maneuvers in time order.
    plant : HoverPlant
        The truth airframe.
    gains : CascadeGains
        The controller.
    loop : ClosedLoop
        The closed loop flown.
    wind : WindField or None
        The wind at the anemometer.
    utc_offset_s : float
        UTC minus log clock, s.
    dropouts_s : tuple of (float, float)
        Logging gaps ``[start_s, end_s)`` on the log clock: the writers leave out every sample inside them.
    """

    case: Case
    fmt: LogFormat
    time_s: np.ndarray
    step_us: int
    sub_steps: int
    truth: Mapping[str, np.ndarray]
    measured: Mapping[str, np.ndarray]
    armed: np.ndarray
    airborne: np.ndarray
    maneuvers: tuple[ManeuverTruth, ...]
    plant: HoverPlant
    gains: CascadeGains
    loop: ClosedLoop = field(repr=False)
    wind: WindField | None = field(repr=False)
    utc_offset_s: float
    dropouts_s: tuple[tuple[float, float], ...] = ()

    @property
    def time_us(self) -> np.ndarray:
        """The fine grid as integer µs since boot."""
        return self.case.plan.log_start_us + self.step_us * np.arange(self.time_s.size, dtype=np.int64)

    def control_indices(self) -> np.ndarray:
        """Indices of the fine grid at the control instants."""
        return np.arange(0, self.time_s.size, self.sub_steps)
