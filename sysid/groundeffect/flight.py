"""F/F0 from a flight log's hover steps near the ground (chapter 2's flight test, eq. 2.6).

The vehicle descends in steps and hovers at each. Over the steady second
half of a step the net vertical force is nil, so the thrust F equals the
weight, while F0 = sum of k_f PWM_i (eq. 2.6) is the thrust the same motor
commands would give out of ground effect. The steps are the plateaus of the
height trace: block means of the height (0.5 s) are split into the
piecewise-constant segments of least squared error plus a penalty per
segment (optimal partitioning with a BIC-like penalty, the noise level
estimated from successive block differences), no segment shorter than
``min_hold_s``, the first 2 s of each (the move to its level) left out of the
error.
"""

from __future__ import annotations

import math

import numpy as np

from flightlogs.errors import DataError, MissingSignalError
from flightlogs.flightlog import FlightLog, Signal
from sysid.groundeffect.records import GroundEffectDataConfig, HoverStep, HoverSteps, ThrustRatioData

__all__ = ["flight_thrust_ratio", "plateaus"]

_BLOCK_S = 0.5
_TRANSITION_S = 2.0  # the climb or descent to a new step may take this long without splitting the step
_PLAUSIBLE = (0.8, 2.0)  # F/F0 outside this band: on the ground, motors idle, or not hovering
_NOISE_FLOOR_M = 1e-6
_ROTOR_SPEEDS = ("rpm", "rad/s")  # motor signals that are rotor speeds (a motion-capture rig's rpm), not commands


def flight_thrust_ratio(log: FlightLog, config: GroundEffectDataConfig) -> ThrustRatioData:
    """F/F0 against Z/R, one point per hover step of a flight log.

    Parameters
    ----------
    log : FlightLog
        A log with ``height_agl`` (rangefinder, else local height) and
        ``motor_1..n``.
    config : GroundEffectDataConfig
        Rotor radius, k_f, PWM full scale, mass (or none: the steps above
        ``reference_height_ratio`` give the weight), shortest step.

    Returns
    -------
    ThrustRatioData
        One point per step kept, with the steps in ``steps``.

    Raises
    ------
    MissingSignalError
        If the log has no height or no motor signals.
    DataError
        If no hover step is found, or no mass is given and no step lies out
        of ground effect.
    """
    height = log["height_agl"]
    f0_time, f0_n, unit_note = _eq_2_6(log, config)
    time_s = height.time_s
    z = height.values + config.rotor_offset_m
    f0 = np.interp(time_s, f0_time, f0_n, left=np.nan, right=np.nan)
    usable = np.isfinite(z) & np.isfinite(f0)
    time_s, z, f0 = time_s[usable], z[usable], f0[usable]
    if time_s.size < 2:
        raise DataError(f"{log.path.name}: height_agl and the motor signals do not overlap in time")
    block_t, block_z, bounds = _blocks(time_s, z)
    segments = plateaus(
        block_z, min_length=max(2, math.ceil(config.min_hold_s / _BLOCK_S)), transition=round(_TRANSITION_S / _BLOCK_S)
    )
    steps, dropped = _steps(time_s, z, f0, block_t, bounds, segments, config)
    if not steps:
        raise DataError(
            f"{log.path.name}: no hover step of at least {config.min_hold_s:g} s with plausible "
            f"thrust found" + (f" ({'; '.join(dropped)})" if dropped else "")
        )
    weight, how = _weight(log, steps, config)
    steps = [_with_ratio(step, weight) for step in steps]
    kept = [s for s in steps if _PLAUSIBLE[0] <= s.thrust_ratio <= _PLAUSIBLE[1]]
    dropped += [
        f"{s.start_s:.1f}-{s.end_s:.1f} s: F/F0 = {s.thrust_ratio:.3g} implausible" for s in steps if s not in kept
    ]
    if not kept:
        raise DataError(f"{log.path.name}: no hover step with plausible F/F0 ({'; '.join(dropped)})")
    found = HoverSteps(time_s=block_t, height_m=block_z, steps=tuple(kept), dropped=tuple(dropped))
    x = np.array([s.height_m for s in kept]) / config.rotor_radius_m
    ratio = np.array([s.thrust_ratio for s in kept])
    f0_source = f"eq. 2.6 with k_f = {config.kf_n_per_count:.4g} N per count{unit_note}; F = {how}"
    return ThrustRatioData(
        height_ratio=x,
        thrust_ratio=ratio,
        rotor_radius_m=config.rotor_radius_m,
        source=log.path.name,
        f0_source=f0_source,
        f0_n=None,
        steps=found,
    )


def plateaus(
    values: np.ndarray, *, min_length: int, noise: float | None = None, transition: int = 0
) -> list[tuple[int, int]]:
    """Split a series into piecewise-constant segments (optimal partitioning, penalised least squares).

    Parameters
    ----------
    values : ndarray, shape (n,)
        The series (block means of the height).
    min_length : int
        Fewest samples in a segment (>= 1).
    noise : float, optional
        Standard deviation of the noise on `values`; default estimated from
        successive differences (median absolute deviation / sqrt 2).
    transition : int, optional
        Samples at the start of each segment left out of its cost, so that
        the move to a new level does not split the plateau it leads to
        (at most half of `min_length`).

    Returns
    -------
    list of (int, int)
        Half-open index ranges ``[start, end)`` covering ``0..n``, in order.

    Notes
    -----
    Minimises sum over segments of the squared deviations from the segment
    mean (after its first `transition` samples), plus ``2 noise^2 ln n`` per segment (the Schwarz penalty for a mean
    and a change point), by dynamic programming over segment ends: O(n^2)
    work, vectorised over segment starts.

    Examples
    --------
    >>> plateaus(np.array([0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0]), min_length=2, noise=0.01)
    [(0, 3), (3, 7)]
    """
    y = np.asarray(values, dtype=np.float64)
    n = y.size
    if n == 0 or min_length < 1:
        raise ValueError(f"need values (got {n}) and min_length >= 1 (got {min_length})")
    if n < 2 * min_length:
        return [(0, n)]
    skip = min(max(transition, 0), min_length // 2)
    sigma = _noise(y) if noise is None else noise
    penalty = 2.0 * max(sigma, _NOISE_FLOOR_M) ** 2 * math.log(n)
    s1 = np.concatenate([[0.0], np.cumsum(y)])
    s2 = np.concatenate([[0.0], np.cumsum(y * y)])
    best = np.full(n + 1, np.inf)
    best[0] = 0.0
    previous = np.zeros(n + 1, dtype=np.int64)
    for end in range(min_length, n + 1):
        starts = np.arange(0, end - min_length + 1)
        starts = starts[np.isfinite(best[starts])]
        scored = starts + skip
        cost = s2[end] - s2[scored] - (s1[end] - s1[scored]) ** 2 / (end - scored)
        total = best[starts] + cost + penalty
        pick = int(np.argmin(total))
        best[end], previous[end] = total[pick], starts[pick]
    cuts = [n]
    while cuts[-1] > 0:
        cuts.append(int(previous[cuts[-1]]))
    cuts.reverse()
    return list(zip(cuts[:-1], cuts[1:]))


def _noise(y: np.ndarray) -> float:
    """Noise standard deviation from successive differences, robust to the steps themselves."""
    if y.size < 3:
        return 0.0
    diff = np.diff(y)
    return float(1.4826 * np.median(np.abs(diff - np.median(diff))) / math.sqrt(2.0))


def _eq_2_6(log: FlightLog, config: GroundEffectDataConfig) -> tuple[np.ndarray, np.ndarray, str]:
    """Time base and F0 = sum k_f PWM_i (eq. 2.6; k_f omega_i^2 for rotor speeds), N, on the first motor's time base."""
    motors: list[Signal] = sorted(
        (s for n, s in log.signals.items() if n.startswith("motor_")), key=lambda s: int(s.name.split("_")[1])
    )
    if not motors:
        raise MissingSignalError(f"{log.path.name}: no motor signals (motor_1..n) for eq. 2.6")
    units = {m.unit for m in motors}
    if len(units) > 1:
        raise DataError(f"{log.path.name}: motor signals in mixed units {sorted(units)}")
    unit = units.pop()
    time_s = motors[0].time_s
    squared = unit in _ROTOR_SPEEDS  # thrust grows with the square of a rotor's speed, with a command's value
    total = np.zeros_like(time_s)
    for motor in motors:
        commanded = np.interp(time_s, motor.time_s, motor.values)
        total += commanded**2 if squared else commanded
    if squared:
        counts, note = total, f", rotor speeds in {unit}: k_f taken per ({unit})^2"
    elif unit == "normalised":
        counts, note = total * config.pwm_full_scale, f", motors 0..1 scaled to {config.pwm_full_scale:g} counts"
    else:
        counts, note = total, f", motors in {unit} taken as counts"
    return time_s, config.kf_n_per_count * counts, note


def _blocks(time_s: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Block-mean times and heights over 0.5 s blocks, and each block's sample range (n_blocks + 1,)."""
    index = np.floor((time_s - time_s[0]) / _BLOCK_S).astype(np.int64)
    starts = np.flatnonzero(np.diff(index, prepend=-1))
    bounds = np.append(starts, time_s.size)
    counts = np.diff(bounds)
    return (np.add.reduceat(time_s, starts) / counts, np.add.reduceat(z, starts) / counts, bounds)


def _steps(
    time_s: np.ndarray,
    z: np.ndarray,
    f0: np.ndarray,
    block_t: np.ndarray,
    bounds: np.ndarray,
    segments: list[tuple[int, int]],
    config: GroundEffectDataConfig,
) -> tuple[list[HoverStep], list[str]]:
    """Steady-half statistics of each segment; segments on the ground or too short are dropped."""
    steps, dropped = [], []
    for first, last in segments:
        lo, hi = bounds[first], bounds[last]
        start, end = float(time_s[lo]), float(time_s[hi - 1])
        if end - start < config.min_hold_s * 0.95:
            continue
        middle = 0.5 * (start + end)
        pick = slice(int(lo + np.searchsorted(time_s[lo:hi], middle)), int(hi))
        t, h, f = time_s[pick], z[pick], f0[pick]
        if t.size < 3 or np.mean(f) <= 0:
            dropped.append(f"{start:.1f}-{end:.1f} s: motors off")
            continue
        rate = float(np.polyfit(t - t.mean(), h, 1)[0])
        steps.append(
            HoverStep(
                start_s=start,
                end_s=end,
                steady_start_s=middle,
                height_m=float(np.mean(h)),
                height_std_m=float(np.std(h)),
                climb_rate_m_s=rate,
                f0_n=float(np.mean(f)),
                thrust_ratio=math.nan,
                samples=int(t.size),
            )
        )
    return steps, dropped


def _weight(log: FlightLog, steps: list[HoverStep], config: GroundEffectDataConfig) -> tuple[float, str]:
    """The thrust F that balances the weight, N, and how it was found."""
    if config.mass_kg is not None:
        return config.mass_kg * config.gravity_m_s2, f"m g with m = {config.mass_kg:g} kg"
    high = [s.f0_n for s in steps if s.height_m / config.rotor_radius_m > config.reference_height_ratio]
    if not high:
        raise DataError(
            f"{log.path.name}: no hover step above Z/R = {config.reference_height_ratio:g} to give "
            "the weight; give the mass (`mass_kg`)"
        )
    return float(
        np.mean(high)
    ), f"mean eq. 2.6 thrust of {len(high)} step(s) above Z/R = {config.reference_height_ratio:g}"


def _with_ratio(step: HoverStep, weight_n: float) -> HoverStep:
    return HoverStep(
        start_s=step.start_s,
        end_s=step.end_s,
        steady_start_s=step.steady_start_s,
        height_m=step.height_m,
        height_std_m=step.height_std_m,
        climb_rate_m_s=step.climb_rate_m_s,
        f0_n=step.f0_n,
        thrust_ratio=weight_n / step.f0_n,
        samples=step.samples,
    )
