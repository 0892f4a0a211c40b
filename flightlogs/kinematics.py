"""The specific force an accelerometer would have felt, from the velocities and the attitude.

A motion-capture rig logs velocities, not specific forces; the discrepancy
search compares specific forces. ``f = R_ib (dv/dt - g)`` gives them, with
the derivative a Savitzky–Golay slope (quadratic over
:data:`SPECIFIC_FORCE_WINDOW_S`) inside each stretch without a gap. Sampled
at 50 Hz, a velocity with 2 cm/s of noise gives a slope with about 0.1 m/s²
over 0.2 s (0.3 m/s² over 0.1 s); everything slower than about 2 Hz passes
unchanged. A flight compared with one whose specific forces were derived
has its own derived the same way: like is compared with like.
"""

from __future__ import annotations

import numpy as np

from flightlogs.frames import earth_to_body

__all__ = ["SPECIFIC_FORCE_WINDOW_S", "specific_force", "slope"]

#: Savitzky-Golay window of a velocity's derivative, s.
SPECIFIC_FORCE_WINDOW_S = 0.2
_G = 9.80665  # standard gravity, m/s^2
_GAP_FACTOR = 5.0  # an interval this many times the median splits the samples


def slope(time_s: np.ndarray, values: np.ndarray, window_s: float = SPECIFIC_FORCE_WINDOW_S) -> np.ndarray:
    """The time derivative of `values`: a quadratic's slope over `window_s`, never across a gap.

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Increasing sample times, s; an interval over five times the median is a gap.
    values : ndarray, shape (n,)
        Samples, any unit.
    window_s : float, optional
        Savitzky-Golay window, s (at least 5 samples).

    Returns
    -------
    ndarray, shape (n,)
        Unit of `values` per second; central differences in a stretch shorter than the window, 0 in one
        of a single sample.

    Examples
    --------
    >>> t = np.arange(0.0, 2.0, 0.02)
    >>> bool(np.allclose(slope(t, 3.0 * t**2), 6.0 * t))
    True
    """
    from scipy.signal import savgol_filter  # only derived signals need it

    time_s = np.asarray(time_s, dtype=np.float64)
    values = np.asarray(values, dtype=np.float64)
    out = np.zeros_like(values)
    if time_s.size < 2:
        return out
    interval = np.diff(time_s)
    breaks = np.flatnonzero(interval > _GAP_FACTOR * np.median(interval)) + 1
    edges = [0, *breaks.tolist(), time_s.size]
    for start, stop in zip(edges[:-1], edges[1:]):
        t, v = time_s[start:stop], values[start:stop]
        if t.size < 2:
            continue
        step = float(np.median(np.diff(t)))
        window = max(5, int(round(window_s / step)) | 1)
        if t.size < window:
            out[start:stop] = np.gradient(v, t)
        else:
            out[start:stop] = savgol_filter(v, window, 2, deriv=1, delta=step)
    return out


def specific_force(
    time_s: np.ndarray,
    velocity_ned: np.ndarray,
    phi: np.ndarray,
    theta: np.ndarray,
    psi: np.ndarray,
    window_s: float = SPECIFIC_FORCE_WINDOW_S,
) -> np.ndarray:
    """Body-axis specific force ``R_ib (dv/dt - g)`` from NED velocities and the attitude.

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Sample times, s.
    velocity_ned : ndarray, shape (n, 3)
        Ground velocity north, east, down, m/s.
    phi, theta, psi : ndarray, shape (n,)
        Roll, pitch and yaw, rad.
    window_s : float, optional
        Window of the derivative, s (:func:`slope`).

    Returns
    -------
    ndarray, shape (n, 3)
        ``ax ay az``, m/s² (at rest and level, ``(0, 0, -g)``).

    Examples
    --------
    >>> t = np.arange(0.0, 1.0, 0.02)
    >>> level = np.zeros(t.size)
    >>> np.round(specific_force(t, np.zeros((t.size, 3)), level, level, level)[0], 5)
    array([ 0.     ,  0.     , -9.80665])
    """
    velocity_ned = np.asarray(velocity_ned, dtype=np.float64)
    acceleration = np.column_stack([slope(time_s, velocity_ned[:, k], window_s) for k in range(3)])
    acceleration[:, 2] -= _G
    return earth_to_body(acceleration, phi, theta, psi)
