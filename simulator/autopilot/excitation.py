"""Computer-generated excitation signals, as autopilots inject them at the mixer input."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, cast

import numpy as np

__all__ = ["Axis", "Maneuver", "sweep", "doublet", "excitation_signal", "three_two_one_one", "multisine"]

Axis = Literal["lat", "lon", "yaw", "thr"]


@dataclass(frozen=True, slots=True, kw_only=True)
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


def three_two_one_one(time_s: np.ndarray, start_s: float, amplitude: float, pulse_s: float) -> np.ndarray:
    """3-2-1-1 multistep: +A for 3 pulses, -A for 2, +A for 1, -A for 1.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Times, s.
    start_s : float
        Start, s.
    amplitude : float
        Step height, in the mixer input's unit.
    pulse_s : float
        Length of the shortest step, s (the whole input lasts 7 pulses).

    Returns
    -------
    ndarray, shape (n_samples,)
        Excitation, zero outside.

    Examples
    --------
    >>> three_two_one_one(np.arange(8.0) + 0.5, 0.0, 1.0, 1.0)
    array([ 1.,  1.,  1., -1., -1.,  1., -1.,  0.])
    """
    if pulse_s <= 0:
        raise ValueError(f"{pulse_s=} must be > 0")
    k = np.floor((np.asarray(time_s, dtype=np.float64) - start_s) / pulse_s)
    pattern = np.array([1.0, 1.0, 1.0, -1.0, -1.0, 1.0, -1.0])
    inside = (k >= 0) & (k < 7)
    return np.where(inside, amplitude * pattern[np.clip(k, 0, 6).astype(np.intp)], 0.0)


def multisine(
    time_s: np.ndarray,
    start_s: float,
    duration_s: float,
    amplitude: float,
    *,
    f_min_hz: float = 0.1,
    f_max_hz: float = 10.0,
    n_tones: int = 30,
    fade_s: float = 1.0,
) -> np.ndarray:
    """Schroeder-phased multisine: log-spaced harmonics of 1/duration, peak `amplitude`.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Times, s.
    start_s : float
        Start, s.
    duration_s : float
        Length, s (the tones are harmonics of 1/duration_s).
    amplitude : float
        Peak value (before the fades), in the mixer input's unit.
    f_min_hz, f_max_hz : float, optional
        Frequency band, Hz.
    n_tones : int, optional
        Number of tones (fewer if the band holds fewer harmonics).
    fade_s : float, optional
        Linear fade in and out, s.

    Returns
    -------
    ndarray, shape (n_samples,)
        Excitation, zero outside.

    Notes
    -----
    Schroeder phases ``-pi k (k - 1) / n`` keep the crest factor low; the
    peak is normalised on a grid of 64 samples per period of the top tone
    (within 0.2 % of the true peak).
    """
    if duration_s <= 2 * fade_s or not 0 < f_min_hz < f_max_hz:
        raise ValueError("need duration_s > 2 fade_s and 0 < f_min_hz < f_max_hz")
    base = 1.0 / duration_s
    harmonics = np.unique(np.round(np.geomspace(max(f_min_hz / base, 1.0), f_max_hz / base, n_tones)))
    k = np.arange(1, harmonics.size + 1)
    phases = -np.pi * k * (k - 1) / harmonics.size

    def shape(t: np.ndarray) -> np.ndarray:
        return cast(
            np.ndarray, np.sum(np.cos(2 * np.pi * base * harmonics[:, None] * t[None, :] + phases[:, None]), axis=0)
        )

    grid = np.arange(0.0, duration_s, 1.0 / (64 * f_max_hz))
    peak = float(np.max(np.abs(shape(grid))))
    t = np.asarray(time_s, dtype=np.float64) - start_s
    inside = (t >= 0) & (t < duration_s)
    envelope = np.clip(t / fade_s, 0, 1) * np.clip((duration_s - t) / fade_s, 0, 1) if fade_s > 0 else 1.0
    return np.where(inside, amplitude * envelope * shape(t) / peak, 0.0)
