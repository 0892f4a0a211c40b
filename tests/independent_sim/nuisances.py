"""Nuisances of real sensors and loggers: rotor vibration on the accelerometers, drifting gyro biases, SD-card stalls.

A :class:`Nuisances` on a :class:`~independent_sim.scenario.Case` adds, to both flights of a pair alike:

* **vibration**: the blade-passing line and its second harmonic on each accelerometer axis, at a frequency
  that follows the rotor speed (``f = f_hover sqrt(δ_thr / δ_hover)``) and an amplitude that follows the
  thrust (``∝ δ_thr / δ_hover``), evaluated at each sample's instant: a log sampled below twice the line
  holds it aliased (140 Hz in a 200 Hz topic reads as 60 Hz), as a real log does;
* **gyro bias drift**: a random walk per axis (``σ sqrt(t / T)``, σ reached over T = 240 s), seen by the
  rate loop and logged;
* **dropouts**: 1-3 gaps of 0.1-0.3 s at random times in flight, where every topic of the log misses its
  samples (:func:`keep_mask`, applied by the log writers).

All of it is drawn from its own generator (``(seed, 0x6e75)``): a case without nuisances flies and logs exactly
as before, and two flights of one seed with and without an effect carry the same nuisances.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = [
    "Nuisances",
    "DEFAULT_NUISANCES",
    "nuisance_rng",
    "vibration",
    "gyro_drift",
    "dropout_spans",
    "keep_mask",
]


@dataclass(frozen=True, slots=True, kw_only=True)
class Nuisances:
    """What a real vehicle's sensors and logger add to every log.

    Parameters
    ----------
    vibration_hz : float
        Blade-passing frequency at the hover thrust, Hz (0: no vibration).
    vibration_m_s2 : tuple of float
        Amplitude of the line on ``ax ay az`` at the hover thrust, m/s².
    harmonic_ratio : float
        Amplitude of the second harmonic over the first.
    gyro_drift_rad_s : float
        Standard deviation the gyro biases' random walk reaches after 240 s, rad/s.
    dropouts : tuple of int
        Least and most number of logging gaps in flight (inclusive).
    dropout_s : tuple of float
        Shortest and longest gap, s.
    """

    vibration_hz: float = 140.0
    vibration_m_s2: tuple[float, float, float] = (1.0, 1.2, 2.0)
    harmonic_ratio: float = 0.4
    gyro_drift_rad_s: float = 0.003
    dropouts: tuple[int, int] = (1, 3)
    dropout_s: tuple[float, float] = (0.1, 0.3)

    def __post_init__(self) -> None:
        if self.vibration_hz < 0.0 or min(self.vibration_m_s2) < 0.0 or len(self.vibration_m_s2) != 3:
            raise ValueError(f"{self.vibration_hz=} and {self.vibration_m_s2=} must be ≥ 0 (three amplitudes)")
        if self.harmonic_ratio < 0.0 or self.gyro_drift_rad_s < 0.0:
            raise ValueError(f"{self.harmonic_ratio=} and {self.gyro_drift_rad_s=} must be ≥ 0")
        if not 0 <= self.dropouts[0] <= self.dropouts[1] <= 10:
            raise ValueError(f"{self.dropouts=} must be (least, most) within 0..10")
        if not 0.0 < self.dropout_s[0] <= self.dropout_s[1] <= 2.0:
            raise ValueError(f"{self.dropout_s=} must be (shortest, longest) within (0, 2] s")


#: The nuisances of the open pair plan (:func:`~independent_sim.pairs.open_pair_case`).
DEFAULT_NUISANCES = Nuisances()


def nuisance_rng(seed: int) -> np.random.Generator:
    """The generator of a case's nuisances, apart from the one of its noise."""
    return np.random.default_rng((seed, 0x6E75))


def vibration(
    nuisances: Nuisances, time_s: np.ndarray, thrust: np.ndarray, hover_thrust: float, rng: np.random.Generator
) -> np.ndarray:
    """Rotor vibration felt by the accelerometers at each instant, shape (n, 3), m/s².

    Parameters
    ----------
    nuisances : Nuisances
        Frequency and amplitudes.
    time_s : ndarray, shape (n,)
        Instants, s (a fine grid: the phase is integrated along it).
    thrust : ndarray, shape (n,)
        Thrust command, normalised (0 with the motors stopped).
    hover_thrust : float
        Thrust command at hover, normalised.
    rng : numpy.random.Generator
        Draws each axis's phase.

    Returns
    -------
    ndarray, shape (n, 3)
        ``ax ay az`` vibration.
    """
    level = np.clip(thrust / hover_thrust, 0.0, None)
    frequency_hz = nuisances.vibration_hz * np.sqrt(level)
    phase = 2.0 * np.pi * np.concatenate([[0.0], np.cumsum(frequency_hz[:-1] * np.diff(time_s))])
    out = np.zeros((time_s.size, 3))
    for k, amplitude in enumerate(nuisances.vibration_m_s2):
        first, second = rng.uniform(0.0, 2.0 * np.pi, 2)
        line = np.sin(phase + first) + nuisances.harmonic_ratio * np.sin(2.0 * phase + second)
        out[:, k] = amplitude * level * line
    return out


def gyro_drift(nuisances: Nuisances, n: int, dt_s: float, rng: np.random.Generator) -> np.ndarray:
    """Random-walk gyro biases, shape (n, 3), rad/s, starting at zero.

    Parameters
    ----------
    nuisances : Nuisances
        The walk's size (`gyro_drift_rad_s` after 240 s).
    n : int
        Samples.
    dt_s : float
        Sample step, s.
    rng : numpy.random.Generator
        Draws the walk.

    Returns
    -------
    ndarray, shape (n, 3)
    """
    density = nuisances.gyro_drift_rad_s / math.sqrt(240.0)  # rad/s per sqrt(s)
    steps = density * math.sqrt(dt_s) * rng.standard_normal((n, 3))
    steps[0] = 0.0
    return np.cumsum(steps, axis=0)


def dropout_spans(
    nuisances: Nuisances, takeoff_s: float, touchdown_s: float, rng: np.random.Generator
) -> tuple[tuple[float, float], ...]:
    """Logging gaps ``(start_s, end_s)`` on the log clock, in time order, apart from each other and in flight.

    Parameters
    ----------
    nuisances : Nuisances
        How many gaps and how long.
    takeoff_s, touchdown_s : float
        Airborne span on the log clock, s (gaps fall 10 s or more inside it).
    rng : numpy.random.Generator
        Draws the gaps.

    Returns
    -------
    tuple of (float, float)
    """
    low, high = nuisances.dropouts
    count = int(rng.integers(low, high + 1))
    spans: list[tuple[float, float]] = []
    while len(spans) < count:
        length = float(rng.uniform(*nuisances.dropout_s))
        start = float(rng.uniform(takeoff_s + 10.0, touchdown_s - 10.0 - length))
        if all(start > end + 5.0 or start + length < begin - 5.0 for begin, end in spans):
            spans.append((start, start + length))
    return tuple(sorted(spans))


def keep_mask(time_us: np.ndarray, spans_s: tuple[tuple[float, float], ...]) -> np.ndarray:
    """True for the samples a logger writes: those outside every gap.

    Parameters
    ----------
    time_us : ndarray of int, shape (n,)
        Sample times, µs on the log clock.
    spans_s : tuple of (float, float)
        Gaps ``[start_s, end_s)``, s.

    Returns
    -------
    ndarray of bool, shape (n,)

    Examples
    --------
    >>> keep_mask(np.array([0, 100_000, 200_000, 300_000]), ((0.05, 0.25),)).tolist()
    [True, False, False, True]
    """
    keep = np.ones(np.shape(time_us), bool)
    seconds = np.asarray(time_us) / 1e6
    for start, end in spans_s:
        keep &= (seconds < start) | (seconds >= end)
    return keep
