"""A roll sweep as a flight-test table: a known fourth-order-plus-delay roll response, written as CSV and Parquet.

Issue 32: what a MATLAB or web-tool export of one sweep looks like — time
in ms from boot, the roll mixer input (normalised) and the roll rate in
deg/s, at 100 Hz. The response is a transfer function of our choosing,
integrated here (exact zero-order hold of the 400 Hz mixer input, the delay a
whole number of 0.5 ms steps), so a transfer-function fit must recover it:

    p/delta_lat = b2 s^2 / (s^4 + a3 s^3 + a2 s^2 + a1 s + a0) e^(-tau s)

with the poles of a multirotor's roll: the actuator at 20 rad/s, a roll
mode at 7 rad/s (damping 0.55) and a slow pole at 1.2 rad/s. A logarithmic
chirp 0.08-8 Hz over 70 s with 4 s fades, a gust torque (low-passed white
noise) and a gyro's white noise and 0.01 deg/s quantisation make it real.
Nothing here is shared with ``simulator`` or ``sysid``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from scipy.linalg import expm
from scipy.signal import lfilter, tf2ss

__all__ = ["RollTable", "write_roll_table", "ROLL_TRUTH"]

_B2 = 1360.0  # L_lat / T_a: a roll acceleration of 62 rad/s^2 per unit input through a 46 ms actuator
_POLES = (20.0, 1.2)  # real poles, rad/s
_MODE = (7.0, 0.55)  # natural frequency, rad/s, and damping of the roll mode
_TAU_S = 0.0215
_DEN = np.polymul(np.polymul([1.0, _POLES[0]], [1.0, _POLES[1]]), [1.0, 2 * _MODE[1] * _MODE[0], _MODE[0] ** 2])

#: The truth: the structure's parameters by name, and the delay.
ROLL_TRUTH = {"b2": _B2, "a3": _DEN[1], "a2": _DEN[2], "a1": _DEN[3], "a0": _DEN[4], "tau": _TAU_S}

_STEP_S = 0.0005  # integration step; the delay is 43 of them
_MIXER_HZ = 400
_LOG_HZ = 100
_BOOT_S = 187.42  # the log starts 187.42 s after boot, as an exported table would


@dataclass(frozen=True, slots=True)
class RollTable:
    """The files written and where the sweep is.

    Parameters
    ----------
    csv, parquet : Path
        The same table in both formats.
    sweep_s : tuple of (float, float)
        The chirp's start and end, s on the table's clock.
    """

    csv: Path
    parquet: Path
    sweep_s: tuple[float, float]


def _chirp(t: np.ndarray, start_s: float, length_s: float) -> np.ndarray:
    """A logarithmic chirp 0.08-8 Hz, amplitude 0.08, with 4 s cosine fades; zero outside."""
    f0, f1, fade = 0.08, 8.0, 4.0
    local = t - start_s
    inside = (local >= 0) & (local <= length_s)
    k = math.log(f1 / f0) / length_s
    phase = 2 * math.pi * f0 * (np.exp(k * np.clip(local, 0, length_s)) - 1) / k
    envelope = np.clip(np.minimum(local, length_s - local) / fade, 0, 1)
    return np.where(inside, 0.08 * (0.5 - 0.5 * np.cos(math.pi * envelope)) * np.sin(phase), 0.0)


def write_roll_table(folder: Path, *, seed: int = 0) -> RollTable:
    """Fly the known roll response through a sweep and write it as ``roll.csv`` and ``roll.parquet``.

    Parameters
    ----------
    folder : Path
        Where the files go.
    seed : int
        Noise seed.

    Returns
    -------
    RollTable
    """
    rng = np.random.default_rng(seed)
    length_s, start_s, total_s = 70.0, 6.0, 82.0
    t = np.arange(0.0, total_s, _STEP_S)
    mixer_t = t[:: int(round(1 / (_MIXER_HZ * _STEP_S)))]
    mixer = _chirp(mixer_t, start_s, length_s)
    held = np.repeat(mixer, int(round(1 / (_MIXER_HZ * _STEP_S))))[: t.size]  # zero-order hold at 400 Hz
    delayed = np.concatenate([np.zeros(int(round(_TAU_S / _STEP_S))), held])[: t.size]
    # a gust torque enters as a disturbance input of the same plant (white noise low-passed at 3 rad/s)
    gust = lfilter([1 - math.exp(-3.0 * _STEP_S)], [1, -math.exp(-3.0 * _STEP_S)], rng.standard_normal(t.size)) * 0.6
    a, b, c, d = tf2ss([_B2, 0.0, 0.0], _DEN)
    n = a.shape[0]
    block = np.zeros((n + 1, n + 1))
    block[:n, :n], block[:n, n:] = a * _STEP_S, b * _STEP_S
    phi = expm(block)
    ad, bd = phi[:n, :n], phi[:n, n:]
    x = np.zeros(n)
    rate = np.empty(t.size)
    drive = delayed + 0.02 * gust
    for k in range(t.size):
        rate[k] = (c @ x + d[:, 0] * drive[k])[0]
        x = ad @ x + bd[:, 0] * drive[k]
    every = int(round(1 / (_LOG_HZ * _STEP_S)))
    logged_t, logged_mixer = t[::every], held[::every]
    gyro_deg_s = np.round(np.degrees(rate[::every]) + rng.normal(0.0, 0.4, logged_t.size), 2)
    time_ms = np.round((logged_t + _BOOT_S) * 1000.0, 3)
    csv = folder / "roll.csv"
    csv.write_text(
        "time_ms,mixer_roll,roll_rate_dps\n"
        + "".join(f"{a:.3f},{b:.6f},{c:.2f}\n" for a, b, c in zip(time_ms, logged_mixer, gyro_deg_s))
    )
    parquet = folder / "roll.parquet"
    pq.write_table(pa.table({"time_ms": time_ms, "mixer_roll": logged_mixer, "roll_rate_dps": gyro_deg_s}), parquet)
    return RollTable(csv=csv, parquet=parquet, sweep_s=(_BOOT_S + start_s, _BOOT_S + start_s + length_s))
