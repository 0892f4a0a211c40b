"""Excitation signals: chirps, piloted sweeps, doublets, 3-2-1-1s and multisines.

Each signal is a function of a time grid returning an :class:`Excitation`:
the values (zero outside the maneuver) and the maneuver's true bounds. The
designs that fly them are in :mod:`.maneuvers`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from scipy.signal import lfilter

__all__ = ["Excitation", "chirp", "piloted_sweep", "doublet", "three_two_one_one", "multisine"]


@dataclass(frozen=True, slots=True)
class Excitation:
    """A rendered excitation.

    Parameters
    ----------
    values : ndarray, shape (n_samples,)
        Signal on the time grid, zero outside ``[start_s, end_s)``.
    start_s, end_s : float
        True bounds of the maneuver (fades included), s, on the grid's clock.
    """

    values: np.ndarray
    start_s: float
    end_s: float

    def __post_init__(self) -> None:
        if not self.end_s > self.start_s:
            raise ValueError(f"end_s={self.end_s} must be after start_s={self.start_s}")


def _inside(time_s: np.ndarray, start_s: float, duration_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Mask of samples in ``[start, start + duration)`` and their time since start, s."""
    if duration_s <= 0.0:
        raise ValueError(f"{duration_s=} s must be > 0")
    relative = np.asarray(time_s, dtype=np.float64) - start_s
    return (relative >= 0.0) & (relative < duration_s), relative


def _fade(relative: np.ndarray, duration_s: float, fade_in_s: float, fade_out_s: float) -> np.ndarray:
    """Raised-cosine envelope rising over `fade_in_s` and falling over the last `fade_out_s`."""
    envelope = np.ones_like(relative)
    if fade_in_s > 0.0:
        rising = relative < fade_in_s
        envelope[rising] = 0.5 - 0.5 * np.cos(np.pi * relative[rising] / fade_in_s)
    if fade_out_s > 0.0:
        left = duration_s - relative
        falling = left < fade_out_s
        envelope[falling] *= 0.5 - 0.5 * np.cos(np.pi * np.clip(left[falling], 0.0, None) / fade_out_s)
    return envelope


def chirp(
    time_s: np.ndarray,
    *,
    start_s: float,
    amplitude: float,
    duration_s: float = 34.0,
    f_min_hz: float = 0.1,
    f_max_hz: float = 10.0,
    law: Literal["linear", "log"] = "log",
    direction: Literal["up", "down"] = "up",
    fade_in_s: float = 3.0,
    fade_out_s: float = 1.0,
    dwell_s: float = 0.0,
) -> Excitation:
    """A frequency sweep with a raised-cosine fade-in and fade-out.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Time grid, s.
    start_s : float
        Start of the fade-in, s.
    amplitude : float
        Peak value, in the units of the injection point.
    duration_s : float
        Length including the fades, s.
    f_min_hz, f_max_hz : float
        Band, Hz.
    law : {"linear", "log"}
        Instantaneous frequency linear or exponential in time.
    direction : {"up", "down"}
        Rising or falling frequency.
    fade_in_s, fade_out_s : float
        Fade lengths, s.
    dwell_s : float, optional
        Time spent at `f_min_hz` before the sweep (a rising one only), s; part of `duration_s`.

    Returns
    -------
    Excitation

    Examples
    --------
    >>> t = np.arange(0.0, 40.0, 0.01)
    >>> sweep = chirp(t, start_s=2.0, amplitude=0.06, duration_s=30.0)
    >>> (sweep.start_s, sweep.end_s), bool(np.abs(sweep.values).max() <= 0.06)
    ((2.0, 32.0), True)
    """
    if not 0.0 < f_min_hz < f_max_hz:
        raise ValueError(f"need 0 < {f_min_hz=} < {f_max_hz=}")
    if fade_in_s + fade_out_s > duration_s:
        raise ValueError(f"fades {fade_in_s} + {fade_out_s} s are longer than {duration_s=} s")
    if dwell_s and (direction != "up" or not 0.0 < dwell_s < duration_s):
        raise ValueError(f"a dwell of {dwell_s} s needs a rising sweep longer than it ({duration_s=} s)")
    mask, relative = _inside(time_s, start_s, duration_s)
    tau = relative[mask] if direction == "up" else duration_s - relative[mask]
    f0, f1 = f_min_hz, f_max_hz
    sweep_s, swept = duration_s - dwell_s, np.maximum(tau - dwell_s, 0.0)
    if law == "linear":
        phase = 2 * np.pi * (f0 * swept + (f1 - f0) * swept**2 / (2 * sweep_s))
    else:
        ratio = math.log(f1 / f0)
        phase = 2 * np.pi * f0 * sweep_s / ratio * (np.exp(ratio * swept / sweep_s) - 1.0)
    phase = phase + 2 * np.pi * f0 * np.minimum(tau, dwell_s)
    values = np.zeros(np.shape(time_s))
    values[mask] = amplitude * _fade(relative[mask], duration_s, fade_in_s, fade_out_s) * np.sin(phase)
    return Excitation(values, start_s, start_s + duration_s)


def _smooth_noise(n: int, dt: float, correlation_s: float, rng: np.random.Generator) -> np.ndarray:
    """Unit-variance noise low-passed over `correlation_s` (first order, forwards and backwards)."""
    a = math.exp(-dt / correlation_s)
    raw = rng.standard_normal(n + 400)
    smooth = lfilter([1.0 - a], [1.0, -a], lfilter([1.0 - a], [1.0, -a], raw)[::-1])[::-1][200:-200]
    return smooth / max(float(np.std(smooth)), 1e-12)


def piloted_sweep(
    time_s: np.ndarray,
    *,
    start_s: float,
    amplitude: float,
    rng: np.random.Generator,
    duration_s: float = 45.0,
    f_min_hz: float = 0.2,
    f_max_hz: float = 3.0,
    irregularity: float = 0.25,
) -> Excitation:
    """A pilot's frequency sweep: irregular amplitude and frequency, rising on average.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Uniform time grid, s.
    start_s : float
        First stick motion, s.
    amplitude : float
        Typical peak, in the units of the injection point (stick deflection
        times the stick's scale).
    rng : numpy.random.Generator
        Source of the pilot's irregularity.
    duration_s : float
        Length, s.
    f_min_hz, f_max_hz : float
        Band the pilot covers (exponential on average), Hz.
    irregularity : float
        Relative spread of frequency and amplitude (0 for a clean log chirp).

    Returns
    -------
    Excitation
        Amplitude wanders by ±`irregularity` (low-passed over 3 s), frequency
        by ``exp(±irregularity)``; the first cycle is eased in, the last half
        second eased out.
    """
    mask, relative = _inside(time_s, start_s, duration_s)
    values = np.zeros(np.shape(time_s))
    n = int(mask.sum())
    if n < 2:
        return Excitation(values, start_s, start_s + duration_s)
    dt = float(np.median(np.diff(time_s)))
    tau = relative[mask]
    nominal = f_min_hz * (f_max_hz / f_min_hz) ** (tau / duration_s)
    frequency = nominal * np.exp(irregularity * _smooth_noise(n, dt, 2.0, rng))
    gain = np.clip(1.0 + irregularity * _smooth_noise(n, dt, 3.0, rng), 0.3, None)
    phase = 2 * np.pi * np.cumsum(frequency) * dt
    ease_in = min(1.0 / f_min_hz, duration_s / 4)
    values[mask] = amplitude * gain * _fade(tau, duration_s, ease_in, 0.5) * np.sin(phase)
    return Excitation(values, start_s, start_s + duration_s)


def _pulses(time_s: np.ndarray, start_s: float, amplitude: float, widths: tuple[float, ...]) -> Excitation:
    """Consecutive rectangular pulses of alternating sign, the first positive for `amplitude` > 0."""
    values = np.zeros(np.shape(time_s))
    edge = start_s
    for k, width in enumerate(widths):
        mask, _ = _inside(time_s, edge, width)
        values[mask] = amplitude * (1 if k % 2 == 0 else -1)
        edge += width
    return Excitation(values, start_s, edge)


def doublet(time_s: np.ndarray, *, start_s: float, amplitude: float, width_s: float = 1.0) -> Excitation:
    """Two opposite pulses of one width.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Time grid, s.
    start_s : float
        Start of the first pulse, s.
    amplitude : float
        Pulse height (sign of the first pulse), units of the injection point.
    width_s : float
        Width of each pulse, s.

    Returns
    -------
    Excitation
        Bounds ``[start_s, start_s + 2 width_s]``.

    Examples
    --------
    >>> pulse = doublet(np.arange(0.0, 5.0, 0.5), start_s=1.0, amplitude=1.0, width_s=1.0)
    >>> pulse.values.tolist(), pulse.end_s
    ([0.0, 0.0, 1.0, 1.0, -1.0, -1.0, 0.0, 0.0, 0.0, 0.0], 3.0)
    """
    return _pulses(time_s, start_s, amplitude, (width_s, width_s))


def three_two_one_one(time_s: np.ndarray, *, start_s: float, amplitude: float, unit_s: float = 0.4) -> Excitation:
    """A 3-2-1-1: pulses of 3, 2, 1 and 1 units, alternating in sign.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Time grid, s.
    start_s : float
        Start, s.
    amplitude : float
        Pulse height, units of the injection point.
    unit_s : float
        The time unit, s.

    Returns
    -------
    Excitation
        Bounds ``[start_s, start_s + 7 unit_s]``.
    """
    return _pulses(time_s, start_s, amplitude, (3 * unit_s, 2 * unit_s, unit_s, unit_s))


def multisine(
    time_s: np.ndarray,
    *,
    start_s: float,
    amplitude: float,
    duration_s: float = 30.0,
    f_min_hz: float = 0.2,
    f_max_hz: float = 8.0,
    period_s: float = 10.0,
    fade_s: float = 1.0,
) -> Excitation:
    """A Schroeder-phased multisine over the harmonics of ``1/period_s`` in a band.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Time grid, s.
    start_s : float
        Start, s.
    amplitude : float
        Peak value, units of the injection point.
    duration_s : float
        Length, s.
    f_min_hz, f_max_hz : float
        Band of the tones, Hz.
    period_s : float
        Period of the sum (the frequency resolution), s.
    fade_s : float
        Raised-cosine fade in and out, s.

    Returns
    -------
    Excitation
    """
    harmonics = np.arange(max(1, math.ceil(f_min_hz * period_s)), math.floor(f_max_hz * period_s) + 1)
    if harmonics.size < 2:
        raise ValueError(f"band {f_min_hz}-{f_max_hz} Hz holds fewer than 2 harmonics of 1/{period_s} s")
    count = harmonics.size
    phases = -np.pi * np.arange(1, count + 1) * np.arange(count) / count  # Schroeder (low crest factor)
    base = np.arange(0.0, period_s, 1e-3)
    peak = np.abs(np.sin(2 * np.pi * np.outer(base, harmonics) / period_s + phases).sum(axis=1)).max()
    mask, relative = _inside(time_s, start_s, duration_s)
    tau = relative[mask]
    total = np.sin(2 * np.pi * np.outer(tau, harmonics) / period_s + phases).sum(axis=1)
    values = np.zeros(np.shape(time_s))
    values[mask] = amplitude / peak * _fade(tau, duration_s, fade_s, fade_s) * total
    return Excitation(values, start_s, start_s + duration_s)
