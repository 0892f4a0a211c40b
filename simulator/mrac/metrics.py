"""Step-response indices of Tables 2.6-2.8: rise time, steady-state error, MSE to the reference, overshoot, settling."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, fields

import numpy as np

__all__ = ["StepMetrics", "step_metrics", "Statistic", "MetricStatistics", "statistics"]


@dataclass(frozen=True, slots=True, kw_only=True)
class StepMetrics:
    """Indices of one step response (NaN where an index is undefined).

    Parameters
    ----------
    rise_time_s : float
        From 10 % to 90 % of the commanded change, s; NaN if 90 % is never reached.
    steady_state_error_m : float
        ``|final - command|`` with the final value the mean over the last second, m.
    mse_m2 : float
        Mean squared difference between the height and the reference model's, m^2.
    overshoot_percent : float
        Largest excursion beyond the command, % of the commanded change (0 if none).
    settling_time_s : float
        Time after which the height stays within 2 % of the change around its final
        value, s; NaN if it leaves that band in the last quarter of the record.
    """

    rise_time_s: float
    steady_state_error_m: float
    mse_m2: float
    overshoot_percent: float
    settling_time_s: float

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if not isinstance(value, float):
                raise TypeError(f"{f.name}={value!r} must be a float")
            if value < 0:
                raise ValueError(f"{f.name}={value} must be >= 0 or NaN")


def _first_crossing(time_s: np.ndarray, fraction: np.ndarray, level: float) -> float:
    """First time `fraction` reaches `level`, interpolated between samples; NaN if never."""
    above = np.flatnonzero(fraction >= level)
    if above.size == 0:
        return float("nan")
    k = int(above[0])
    if k == 0:
        return float(time_s[0])
    f0, f1 = fraction[k - 1], fraction[k]
    return float(time_s[k - 1] + (level - f0) / (f1 - f0) * (time_s[k] - time_s[k - 1]))


def _smooth(time_s: np.ndarray, values: np.ndarray, window_s: float) -> np.ndarray:
    """Centred moving average over `window_s` (shorter at the ends); the values for a window under two samples."""
    dt = float(time_s[1] - time_s[0])
    n = int(round(window_s / dt))
    if n < 2:
        return values
    kernel = np.ones(n)
    return np.convolve(values, kernel, mode="same") / np.convolve(np.ones_like(values), kernel, mode="same")


def step_metrics(
    time_s: np.ndarray,
    height_m: np.ndarray,
    reference_m: np.ndarray,
    *,
    before_m: float,
    after_m: float,
    final_window_s: float = 1.0,
    band: float = 0.02,
    smoothing_s: float = 0.5,
) -> StepMetrics:
    """Indices of a step from `before_m` to `after_m` commanded at ``time_s[0]``.

    Parameters
    ----------
    time_s : ndarray, shape (n_samples,)
        Times from the step, s (increasing).
    height_m : ndarray, shape (n_samples,)
        Height, m.
    reference_m : ndarray, shape (n_samples,)
        Reference model's height for the same command, m.
    before_m, after_m : float
        Commanded height before and after the step, m.
    final_window_s : float, optional
        Averaging window of the final value, s.
    band : float, optional
        Settling band as a fraction of the change (2 %).
    smoothing_s : float, optional
        Overshoot and settling are read from the height averaged over this centred
        window, s, so that millimetre hover jitter does not decide them (0: raw);
        rise time, final value and MSE use the raw height.

    Returns
    -------
    StepMetrics

    Examples
    --------
    >>> t = np.arange(0.0, 20.0, 0.01)
    >>> m = step_metrics(t, 1 - np.exp(-t), 1 - np.exp(-t), before_m=0.0, after_m=1.0)
    >>> round(m.rise_time_s, 3), round(m.settling_time_s, 2), m.overshoot_percent, m.mse_m2
    (2.197, 3.93, 0.0, 0.0)
    """
    time_s = np.asarray(time_s, dtype=np.float64)
    height = np.asarray(height_m, dtype=np.float64)
    reference = np.asarray(reference_m, dtype=np.float64)
    if time_s.ndim != 1 or height.shape != time_s.shape or reference.shape != time_s.shape or time_s.size < 2:
        raise ValueError("time_s, height_m and reference_m must be equal 1-D arrays of at least two samples")
    change = after_m - before_m
    if change == 0:
        raise ValueError(f"before_m = after_m = {after_m}: not a step")
    fraction = (height - before_m) / change
    rise = _first_crossing(time_s, fraction, 0.9) - _first_crossing(time_s, fraction, 0.1)
    final = float(np.mean(height[time_s >= time_s[-1] - final_window_s]))
    smooth = _smooth(time_s, height, smoothing_s)
    outside = np.flatnonzero(np.abs(smooth - final) > band * abs(change))
    if outside.size == 0:
        settling = 0.0
    else:
        last = int(outside[-1])
        settling = float(time_s[min(last + 1, time_s.size - 1)] - time_s[0])
        if time_s[last] - time_s[0] > 0.75 * (time_s[-1] - time_s[0]):
            settling = float("nan")
    return StepMetrics(
        rise_time_s=float(rise),
        steady_state_error_m=abs(final - after_m),
        mse_m2=float(np.mean((height - reference) ** 2)),
        overshoot_percent=float(max(0.0, 100.0 * (float(np.max((smooth - before_m) / change)) - 1.0))),
        settling_time_s=settling,
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class Statistic:
    """Mean and sample standard deviation over the finite values of a set.

    Parameters
    ----------
    mean : float
        Mean, NaN if no value is finite.
    std : float
        Standard deviation (ddof = 1; 0 for one value), NaN if none.
    n : int
        Number of finite values.
    total : int
        Number of values, finite or not.
    """

    mean: float
    std: float
    n: int
    total: int

    def __post_init__(self) -> None:
        if not 0 <= self.n <= self.total:
            raise ValueError(f"need 0 <= n={self.n} <= total={self.total}")

    @classmethod
    def of(cls, values: Sequence[float] | np.ndarray) -> Statistic:
        """Statistic of `values`.

        Parameters
        ----------
        values : sequence of float
            Values (NaN allowed).

        Returns
        -------
        Statistic

        Examples
        --------
        >>> Statistic.of([1.0, 3.0, float("nan")])
        Statistic(mean=2.0, std=1.4142135623730951, n=2, total=3)
        """
        array = np.asarray(values, dtype=np.float64)
        finite = array[np.isfinite(array)]
        if finite.size == 0:
            return cls(mean=float("nan"), std=float("nan"), n=0, total=array.size)
        std = float(np.std(finite, ddof=1)) if finite.size > 1 else 0.0
        return cls(mean=float(np.mean(finite)), std=std, n=int(finite.size), total=int(array.size))


@dataclass(frozen=True, slots=True, kw_only=True)
class MetricStatistics:
    """Mean and spread of each index of Tables 2.6-2.8 over a set of step responses.

    Parameters
    ----------
    rise_time_s, steady_state_error_m, mse_m2, overshoot_percent, settling_time_s : Statistic
        One per :class:`StepMetrics` field.
    """

    rise_time_s: Statistic
    steady_state_error_m: Statistic
    mse_m2: Statistic
    overshoot_percent: Statistic
    settling_time_s: Statistic

    def as_dict(self) -> dict[str, dict[str, float | int]]:
        """``{index: {"mean", "std", "n"}}`` for JSON.

        Returns
        -------
        dict
        """
        return {
            f.name: {"mean": getattr(self, f.name).mean, "std": getattr(self, f.name).std, "n": getattr(self, f.name).n}
            for f in fields(self)
        }


def statistics(metrics: Sequence[StepMetrics]) -> MetricStatistics:
    """Statistics of each index over `metrics`.

    Parameters
    ----------
    metrics : sequence of StepMetrics
        Step responses (trials, heights, phases).

    Returns
    -------
    MetricStatistics
    """
    return MetricStatistics(
        **{f.name: Statistic.of([getattr(m, f.name) for m in metrics]) for f in fields(StepMetrics)}
    )
