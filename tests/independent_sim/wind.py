"""Wind: Dryden turbulence carried past a ground anemometer to the vehicle.

The turbulence is frozen (Taylor's hypothesis): the air the anemometer
measures at time ``t`` reaches the vehicle, ``distance_m`` downstream, at
``t + distance_m / mean_speed_m_s``. The anemometer samples it at 20 Hz with
bounded noise (±0.3 m/s, ±2°) and its record is written as a CSV the
workbench's :func:`flightlogs.readers.read_anemometer_csv` accepts: ISO-8601
UTC time, speed and the direction the wind comes FROM. The anemometer's logger
may keep its own clock (``clock_offset_s``): each sample is stamped with the
logger's time, not UTC.

The autopilot may log its own wind estimate (``estimate_time_constant_s``):
the true wind at the vehicle through a first-order low-pass
(:func:`lagged_estimate`), what an EKF's slowly wandering wind states give.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
from scipy.signal import bilinear, butter, lfilter, sosfiltfilt

from flightlogs.writers import atomic_output

__all__ = [
    "WindModel",
    "WindField",
    "wind_field",
    "write_anemometer_csv",
    "lagged_estimate",
    "MAX_CLOCK_OFFSET_S",
    "ESTIMATE_NOISE_M_S",
]

#: Largest anemometer clock error a case may have, s.
MAX_CLOCK_OFFSET_S = 30.0
#: Standard deviation of the white noise on each logged sample of the autopilot's wind estimate, m/s.
ESTIMATE_NOISE_M_S = 0.05


@dataclass(frozen=True, slots=True, kw_only=True)
class WindModel:
    """A steady wind with Dryden turbulence, and the anemometer that measures it.

    Parameters
    ----------
    mean_speed_m_s : float
        Mean horizontal speed, m/s (5.4: the dissertation's strong-wind day).
    from_deg : float
        Direction the wind comes from, degrees clockwise from north; the
        vehicle holds its nose into it.
    sigma_m_s : float
        Standard deviation of the along- and across-wind turbulence, m/s
        (0.6: an intensity of 11 % at 5.4 m/s).
    scale_m : float
        Dryden length scale, m (MIL-F-8785C low altitude: 33.7 m at 4.6 m).
    cutoff_hz : float
        Low-pass of the turbulence (averaging over the rotor disc), Hz.
    distance_m : float
        Anemometer upstream of the vehicle, m.
    anemometer_rate_hz : float
        Anemometer sample rate, Hz.
    speed_noise_m_s : float
        Bound of the anemometer's uniform speed error, m/s.
    direction_noise_deg : float
        Bound of its uniform direction error, degrees.
    clock_offset_s : float
        The anemometer logger's clock minus UTC, s (positive: the logger runs
        ahead); the air measured at UTC ``t`` is stamped ``t + clock_offset_s``.
        At most :data:`MAX_CLOCK_OFFSET_S` in magnitude.
    estimate_time_constant_s : float or None
        When given, the log carries the autopilot's wind estimate: the true
        wind at the vehicle through a first-order low-pass of this time
        constant, s (PX4 ``wind``, ArduPilot ``XKF2``), plus white noise of
        :data:`ESTIMATE_NOISE_M_S` on each logged sample; None: no estimate
        logged.
    """

    mean_speed_m_s: float = 5.4
    from_deg: float = 0.0
    sigma_m_s: float = 0.6
    scale_m: float = 33.7
    cutoff_hz: float = 1.5
    distance_m: float = 4.6
    anemometer_rate_hz: float = 20.0
    speed_noise_m_s: float = 0.3
    direction_noise_deg: float = 2.0
    clock_offset_s: float = 0.0
    estimate_time_constant_s: float | None = None

    def __post_init__(self) -> None:
        if self.mean_speed_m_s <= 0.5:
            raise ValueError(f"{self.mean_speed_m_s=} m/s must be > 0.5 (a transport delay needs wind)")
        if not 0.0 <= self.sigma_m_s < 0.5 * self.mean_speed_m_s:
            raise ValueError(f"{self.sigma_m_s=} must be < 0.5 × mean speed (Taylor's hypothesis)")
        if self.distance_m <= 0.0 or self.anemometer_rate_hz <= 0.0 or self.scale_m <= 0.0:
            raise ValueError("distance_m, anemometer_rate_hz and scale_m must be > 0")
        if not abs(self.clock_offset_s) <= MAX_CLOCK_OFFSET_S:
            raise ValueError(f"{self.clock_offset_s=} s must be within ±{MAX_CLOCK_OFFSET_S:g} s")
        tau = self.estimate_time_constant_s
        if tau is not None and not (math.isfinite(tau) and tau > 0.0):
            raise ValueError(f"{self.estimate_time_constant_s=} s must be > 0 (or None: no estimate logged)")

    @property
    def transport_delay_s(self) -> float:
        """Anemometer-to-vehicle delay, distance / mean speed, s."""
        return self.distance_m / self.mean_speed_m_s

    @property
    def mean_ned(self) -> np.ndarray:
        """Mean wind as the velocity of the air, north and east, m/s."""
        heading = math.radians(self.from_deg)
        return -self.mean_speed_m_s * np.array([math.cos(heading), math.sin(heading)])


@dataclass(frozen=True, slots=True)
class WindField:
    """Turbulent wind on one time grid, felt at the anemometer.

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Uniform grid on the log's clock, s.
    wind_ne : ndarray, shape (n, 2)
        Air velocity north and east at the anemometer, m/s (mean included).
    model : WindModel
        The model it was drawn from.
    """

    time_s: np.ndarray
    wind_ne: np.ndarray
    model: WindModel

    def at_vehicle(self, time_s: np.ndarray) -> np.ndarray:
        """Wind at the vehicle: the anemometer's, one transport delay later.

        Parameters
        ----------
        time_s : ndarray, shape (m,)
            Times on the log's clock, s.

        Returns
        -------
        ndarray, shape (m, 2)
            North and east air velocity, m/s.
        """
        earlier = np.asarray(time_s) - self.model.transport_delay_s
        return np.column_stack([np.interp(earlier, self.time_s, self.wind_ne[:, k]) for k in range(2)])


def _dryden(n: int, dt: float, speed: float, scale: float, lateral: bool, rng: np.random.Generator) -> np.ndarray:
    """Unit-variance Dryden turbulence, longitudinal (first order) or lateral (second order)."""
    tau = scale / speed
    if lateral:
        numerator, denominator = [math.sqrt(3.0) * tau, 1.0], [tau**2, 2 * tau, 1.0]
    else:
        numerator, denominator = [1.0], [tau, 1.0]
    b, a = bilinear(numerator, denominator, fs=1.0 / dt)
    settle = int(10 * tau / dt)
    out = lfilter(b, a, rng.standard_normal(n + settle))[settle:]
    return out / max(float(np.std(out)), 1e-12)


def wind_field(
    model: WindModel,
    start_s: float,
    end_s: float,
    dt: float,
    rng: np.random.Generator,
    *,
    zero_mean_over: tuple[float, float],
) -> WindField:
    """Draw a turbulent wind at the anemometer over ``[start_s, end_s]``.

    Parameters
    ----------
    model : WindModel
        Mean wind, turbulence and anemometer.
    start_s, end_s : float
        Span on the log's clock, s.
    dt : float
        Grid step, s.
    rng : numpy.random.Generator
        Source of the turbulence.
    zero_mean_over : tuple of float
        Span (anemometer clock, s) over which the turbulence is made exactly
        zero-mean and of standard deviation `sigma_m_s`: the air that passes
        the vehicle during the flight, so that the measured mean over the
        flight is the model's mean and distance / mean is the true delay.

    Returns
    -------
    WindField
    """
    time_s = np.arange(start_s, end_s + dt, dt)
    n = time_s.size
    along = _dryden(n, dt, model.mean_speed_m_s, model.scale_m, False, rng)
    across = _dryden(n, dt, model.mean_speed_m_s, model.scale_m, True, rng)
    sos = butter(2, model.cutoff_hz, fs=1.0 / dt, output="sos")
    inside = (time_s >= zero_mean_over[0]) & (time_s <= zero_mean_over[1])
    turbulence = []
    for series in (along, across):
        smooth = sosfiltfilt(sos, series)
        smooth -= smooth[inside].mean()
        turbulence.append(model.sigma_m_s * smooth / max(float(smooth[inside].std()), 1e-12))
    heading = math.radians(model.from_deg)
    downwind = -np.array([math.cos(heading), math.sin(heading)])  # unit vector the air moves along
    right = np.array([-downwind[1], downwind[0]])
    wind_ne = (model.mean_speed_m_s + turbulence[0])[:, None] * downwind + turbulence[1][:, None] * right
    return WindField(time_s=time_s, wind_ne=wind_ne, model=model)


def write_anemometer_csv(
    path: Path, field: WindField, *, log_start_s: float, log_end_s: float, utc_offset_s: float, rng: np.random.Generator
) -> tuple[np.ndarray, np.ndarray]:
    """Sample the anemometer over a log and write its CSV, stamped by the logger's clock.

    Parameters
    ----------
    path : Path
        Destination ``.csv``.
    field : WindField
        The wind at the anemometer; ``field.model.clock_offset_s`` is the
        logger's clock error.
    log_start_s, log_end_s : float
        Log span on the log's clock, s; the record covers, in true time, from
        a transport delay plus 5 s before the start to 5 s after the end,
        whatever the logger's clock error.
    utc_offset_s : float
        UTC minus log clock, s.
    rng : numpy.random.Generator
        Source of the sensor noise.

    Returns
    -------
    tuple of ndarray
        Each sample's stamp on the logger's clock, i.e. its true UTC plus
        ``clock_offset_s`` (UNIX s, shape (n,)), and the measured ``wind_ne``
        (shape (n, 2), m/s).

    Notes
    -----
    Columns ``time_utc`` (ISO-8601 with milliseconds and ``Z``),
    ``speed_m_s`` and ``direction_deg`` (meteorological, FROM). The stamps
    start on a whole second of the logger's clock.
    """
    model = field.model
    step = 1.0 / model.anemometer_rate_hz
    ahead = model.clock_offset_s
    first_utc = math.floor(log_start_s + utc_offset_s - model.transport_delay_s - 5.0 + ahead)
    utc = first_utc + step * np.arange(int((log_end_s + utc_offset_s + 5.0 + ahead - first_utc) / step))
    utc = np.round(utc, 3)
    true = np.column_stack([np.interp(utc - ahead - utc_offset_s, field.time_s, field.wind_ne[:, k]) for k in range(2)])
    speed = np.hypot(true[:, 0], true[:, 1]) + rng.uniform(-1, 1, utc.size) * model.speed_noise_m_s
    speed = np.round(np.clip(speed, 0.0, None), 3)
    toward = np.degrees(np.arctan2(true[:, 1], true[:, 0]))
    direction = np.round((toward + 180.0 + rng.uniform(-1, 1, utc.size) * model.direction_noise_deg) % 360.0, 2)
    direction[direction >= 360.0] -= 360.0
    measured = -speed[:, None] * np.column_stack([np.cos(np.radians(direction)), np.sin(np.radians(direction))])
    lines = ["time_utc,speed_m_s,direction_deg"]
    for stamp, s, d in zip(utc, speed, direction):
        text = datetime.fromtimestamp(round(float(stamp) * 1000) / 1000, tz=UTC).isoformat(timespec="milliseconds")
        lines.append(f"{text.replace('+00:00', 'Z')},{s:.3f},{d:.2f}")
    with atomic_output(path) as tmp:
        tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return utc, measured


def lagged_estimate(time_s: np.ndarray, wind_ne: np.ndarray, time_constant_s: float) -> np.ndarray:
    """An estimator's view of the wind: a causal first-order low-pass started at the first sample.

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Uniform grid, s.
    wind_ne : ndarray, shape (n, 2)
        True wind at the vehicle, north and east, m/s.
    time_constant_s : float
        Time constant of the low-pass, s.

    Returns
    -------
    ndarray, shape (n, 2)
        ``y[k] = y[k-1] + (1 - exp(-dt / tau)) (x[k] - y[k-1])``, ``y[0] = x[0]``, m/s.

    Examples
    --------
    >>> t = np.arange(0.0, 10.0, 0.01)
    >>> step = np.column_stack([np.r_[0.0, np.ones(t.size - 1)], np.zeros(t.size)])
    >>> round(float(lagged_estimate(t, step, 2.0)[200, 0]), 3)  # one time constant after the step
    0.632
    """
    dt = float(time_s[1] - time_s[0])
    alpha = -math.expm1(-dt / time_constant_s)
    x = np.asarray(wind_ne, dtype=np.float64)
    return np.column_stack(
        [lfilter([alpha], [1.0, alpha - 1.0], x[:, k], zi=[(1.0 - alpha) * x[0, k]])[0] for k in range(x.shape[1])]
    )
