"""Computer-generated excitation signals, as autopilots inject them at the mixer input."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

__all__ = ["Axis", "Maneuver", "sweep", "doublet", "excitation_signal"]

Axis = Literal["lat", "lon", "yaw", "thr"]


@dataclass(frozen=True, slots=True)
class Maneuver:
    """One excitation on one mixer axis.

    Parameters
    ----------
    axis : {"lat", "lon", "yaw", "thr"}
        Mixer input it is summed into.
    kind : {"sweep", "doublet"}
        Log-swept chirp with fade-in/out, or a two-sided pulse.
    start_s : float
        Start time, s.
    amplitude : float
        Peak value, in the mixer input's unit.
    duration_s : float
        Whole length, s (sweep: fade-in + sweep + fade-out; doublet: both pulses).
    f_start_hz, f_stop_hz : float
        Sweep frequency range, Hz (ignored by doublets).
    fade_in_s, fade_out_s : float
        Sweep amplitude ramps, s.
    """

    axis: Axis
    kind: Literal["sweep", "doublet"]
    start_s: float
    amplitude: float
    duration_s: float
    f_start_hz: float = 0.1
    f_stop_hz: float = 10.0
    fade_in_s: float = 5.0
    fade_out_s: float = 1.0

    def __post_init__(self) -> None:
        if self.duration_s <= 0:
            raise ValueError(f"duration_s={self.duration_s} must be > 0")
        if self.kind == "sweep" and self.duration_s <= self.fade_in_s + self.fade_out_s:
            raise ValueError("a sweep must last longer than its fades")

    @property
    def end_s(self) -> float:
        """End time, s."""
        return self.start_s + self.duration_s

    @property
    def record_s(self) -> float:
        """Time spent sweeping (between the fades), s."""
        return self.duration_s - self.fade_in_s - self.fade_out_s


def sweep(time_s: np.ndarray, maneuver: Maneuver) -> tuple[np.ndarray, np.ndarray]:
    """Log-swept chirp with constant-frequency fade-in and fade-out.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Times, s.
    maneuver : Maneuver
        A maneuver of kind "sweep".

    Returns
    -------
    value : ndarray, shape (n_samples,)
        Excitation, zero outside the maneuver.
    freq_hz : ndarray, shape (n_samples,)
        Instantaneous frequency, Hz (zero outside).

    Notes
    -----
    The frequency holds at ``f_start_hz`` while the amplitude fades in, rises
    exponentially to ``f_stop_hz`` over the record, and holds while it fades
    out, the shape of ArduPilot's System ID chirp.
    """
    t = np.asarray(time_s, dtype=np.float64) - maneuver.start_s
    inside = (t >= 0.0) & (t < maneuver.duration_s)
    t_in, t_rec = maneuver.fade_in_s, maneuver.record_s
    f0, f1 = maneuver.f_start_hz, maneuver.f_stop_hz
    rate = np.log(f1 / f0) / t_rec
    tau = np.clip(t - t_in, 0.0, t_rec)
    phase = 2 * np.pi * f0 * np.minimum(t, t_in)
    phase += 2 * np.pi * f0 * np.expm1(rate * tau) / rate
    phase += 2 * np.pi * f1 * np.clip(t - t_in - t_rec, 0.0, None)
    freq = np.where(t < t_in, f0, np.where(t < t_in + t_rec, f0 * np.exp(rate * tau), f1))
    envelope = np.clip(t / t_in, 0.0, 1.0) * np.clip((maneuver.duration_s - t) / maneuver.fade_out_s, 0.0, 1.0)
    value = np.where(inside, maneuver.amplitude * envelope * np.sin(phase), 0.0)
    return value, np.where(inside, freq, 0.0)


def doublet(time_s: np.ndarray, maneuver: Maneuver) -> np.ndarray:
    """Two-sided pulse: +amplitude for the first half, -amplitude for the second.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Times, s.
    maneuver : Maneuver
        A maneuver of kind "doublet".

    Returns
    -------
    ndarray, shape (n_samples,)
        Excitation, zero outside the maneuver.
    """
    t = np.asarray(time_s, dtype=np.float64) - maneuver.start_s
    half = maneuver.duration_s / 2
    return np.where((t >= 0) & (t < half), maneuver.amplitude, 0.0) - np.where(
        (t >= half) & (t < maneuver.duration_s), maneuver.amplitude, 0.0
    )


def excitation_signal(time_s: np.ndarray, maneuvers: tuple[Maneuver, ...], axis: Axis) -> np.ndarray:
    """Sum of all maneuvers on one axis.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Times, s.
    maneuvers : tuple of Maneuver
        The flight's excitation plan.
    axis : {"lat", "lon", "yaw", "thr"}
        Mixer axis.

    Returns
    -------
    ndarray, shape (n_samples,)
        Excitation on `axis`.
    """
    total = np.zeros(np.shape(time_s))
    for maneuver in maneuvers:
        if maneuver.axis != axis:
            continue
        total += sweep(time_s, maneuver)[0] if maneuver.kind == "sweep" else doublet(time_s, maneuver)
    return total
