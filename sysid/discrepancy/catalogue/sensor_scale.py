"""Sensor scale: a gyro reads its rates ``(1 + error)`` times the true ones, per axis.

No model of the vehicle tells a gyro's scale from the physics it measures: a roll rate logged 4 % high
gives a roll acceleration 4 % high, which is a roll moment 4 % stronger per command to any equation of
motion. The attitude does: its rate of change is the body rate by kinematics alone
(:func:`~flightlogs.frames.euler_rates_to_body`), whatever the vehicle's physics. So the scale is measured
before any model, as the slope of the attitude's rates on the logged ones in the band the flight's
manoeuvres excite (0.3-3 Hz: above the gyros' drifting biases and the attitude's slow corrections, below
where a differentiated attitude is noise), its uncertainty by leaving out one of 20 folds of interleaved
4 s blocks at a time (jackknife). The real flight's scale is taken relative to the simulated one's, which holds
whatever both estimators share; an axis off by more than 3 standard deviations and 2 % is corrected
(``p`` and ``p_dot`` divided by ``1 + error``) before the search looks for physics. The 2 % is a real
PX4 flight's: its two halves, one gyro, read 0.9 % apart at 3.4 standard deviations (the jackknife
does not see what changes between flights, an estimator's slow corrections), so a smaller error is
not told from none.

The accelerometers are not measured: against the derivative of the logged velocity their scale came
out within ±4 % on flights without any error (the velocity's noise, differentiated, swamps the small
specific forces of a hovering vehicle in x and y), so a claim on them would be a guess.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from flightlogs.frames import euler_rates_to_body
from sysid._filters import butterworth_zero_phase, savgol_slope
from sysid.discrepancy._folds import folds
from sysid.discrepancy.catalogue._term import Calibration, Coefficient, Term, pm
from sysid.discrepancy.result import Finding, FittedParameter
from sysid.discrepancy.series import FlightSeries

__all__ = ["TERM", "gyro_scale_errors"]

_AXES = (  # (logged rate, its derivative, key, reported name)
    ("p", "p_dot", "gyro_p", "gyro_p_scale_error"),
    ("q", "q_dot", "gyro_q", "gyro_q_scale_error"),
    ("r", "r_dot", "gyro_r", "gyro_r_scale_error"),
)
_ATTITUDE = ("phi", "theta", "psi")
_BAND_HZ = (0.3, 3.0)  # where the slope is read: above bias drift and attitude corrections, below differentiated noise
_FOLDS = 20  # folds the jackknife leaves out one at a time ...
_BLOCK_S = 4.0  # ... each of interleaved blocks this long (the band-passed residual's correlation is shorter)
_SIGMAS = 3.0  # an axis whose relative error is beyond this many standard deviations ...
_MIN_ERROR = 0.02  # ... and this share is corrected (a real flight's two halves: 0.9 % apart at 3.4 σ)
_SLOPE_WINDOW_S = 0.1  # Savitzky-Golay window of the attitude's derivative (as the rates')


def _band_passed(x: np.ndarray, rate_hz: float) -> np.ndarray:
    """`x` band-passed to :data:`_BAND_HZ` (zero-phase Butterworth, 2nd order each side), shape (n,)."""
    pad = min(x.size - 1, int(3 * rate_hz / _BAND_HZ[0]))
    below_top = butterworth_zero_phase(x, _BAND_HZ[1], rate_hz, order=2, pad=pad)
    below_bottom = butterworth_zero_phase(x, _BAND_HZ[0], rate_hz, order=2, pad=pad)
    return np.asarray(below_top - below_bottom)


def _kinematic_pairs(series: FlightSeries) -> dict[str, tuple[np.ndarray, np.ndarray]] | None:
    """Per gyro axis, (logged rate, the attitude's rate), band-passed and joined over the pieces long enough."""
    if not all(a in series for a in _ATTITUDE):
        return None
    shortest = int(2 * series.rate_hz / _BAND_HZ[0])
    window = max(5, int(round(_SLOPE_WINDOW_S * series.rate_hz)) | 1)
    logged: dict[str, list[np.ndarray]] = {rate: [] for rate, _, _, _ in _AXES}
    kinematic: dict[str, list[np.ndarray]] = {rate: [] for rate, _, _, _ in _AXES}
    for rows in series.spans():
        phi, theta, psi = (series[a][rows] for a in _ATTITUDE)
        if rows.stop - rows.start < shortest or not np.all(np.isfinite(phi + theta + psi)):
            continue
        slopes = [savgol_slope(a, window, 2, 1.0 / series.rate_hz) for a in (phi, theta, np.unwrap(psi))]
        body = euler_rates_to_body(phi, theta, *slopes)
        for k, (rate, _, _, _) in enumerate(_AXES):
            logged[rate].append(_band_passed(series[rate][rows], series.rate_hz))
            kinematic[rate].append(_band_passed(body[:, k], series.rate_hz))
    if not logged["p"]:
        return None
    return {rate: (np.concatenate(logged[rate]), np.concatenate(kinematic[rate])) for rate in logged}


def _scale_error(logged: np.ndarray, kinematic: np.ndarray, rate_hz: float) -> tuple[float, float] | None:
    """A gyro's scale error (logged over the attitude's rate, minus 1) and its jackknife standard deviation.

    None where the axis is not measured: a slope on some fold that is not positive (no motion in the band).

    The jackknife leaves out one of :data:`_FOLDS` folds of interleaved :data:`_BLOCK_S` blocks at a time:
    a flight's roll or pitch sweep holds 75-80 % of its axis' band energy in 12 s, so contiguous stretches
    left out would make the spread the sweep's alone (0.8-2.3 % on the tuning flights, against 0.6-0.9 %).
    """
    fold = np.empty(logged.size, int)
    for j, rows in enumerate(folds(logged.size, int(_BLOCK_S * rate_hz), _FOLDS)):
        fold[rows] = j
    products = np.bincount(fold, logged * kinematic, _FOLDS)  # each fold's sums: one pass over the samples
    squares = np.bincount(fold, logged * logged, _FOLDS)
    numerators = np.concatenate([[products.sum()], products.sum() - products])  # all, then each fold left out
    denominators = np.concatenate([[squares.sum()], squares.sum() - squares])
    slopes = numerators / np.maximum(denominators, 1e-300)
    if not np.all(slopes > 0.0):
        return None
    errors = 1.0 / slopes - 1.0
    left_out = errors[1:]
    sigma = float(np.sqrt((_FOLDS - 1) / _FOLDS * np.sum((left_out - left_out.mean()) ** 2)))
    return float(errors[0]), sigma


def gyro_scale_errors(sim: FlightSeries, real: FlightSeries) -> tuple[FittedParameter, ...]:
    """Each gyro axis' scale error of REAL relative to SIM, measured against each flight's attitude.

    Parameters
    ----------
    sim, real : FlightSeries
        The flights (each needs ``phi theta psi`` and ``p q r``).

    Returns
    -------
    tuple of FittedParameter
        ``gyro_p_scale_error`` … (ratio, ``+0.04``: REAL's gyro reads 4 % higher than SIM's), empty when
        either flight lacks the attitude or a piece of flight long enough to read the band.
    """
    simulated, flown = _kinematic_pairs(sim), _kinematic_pairs(real)
    if simulated is None or flown is None:
        return ()
    found = []
    for rate, _, _, name in _AXES:
        measured_sim = _scale_error(*simulated[rate], sim.rate_hz)
        measured_real = _scale_error(*flown[rate], real.rate_hz)
        if measured_sim is None or measured_real is None:
            continue
        (e_sim, s_sim), (e_real, s_real) = measured_sim, measured_real
        ratio = (1.0 + e_real) / (1.0 + e_sim)
        sigma = ratio * float(np.hypot(s_real / (1.0 + e_real), s_sim / (1.0 + e_sim)))
        found.append(FittedParameter(name=name, value=ratio - 1.0, uncertainty=sigma, unit="1"))
    return tuple(found)


def _off(error: FittedParameter) -> bool:
    """Whether an axis' error is measured apart from none: beyond :data:`_SIGMAS` and :data:`_MIN_ERROR`."""
    return abs(error.value) > max(_SIGMAS * error.uncertainty, _MIN_ERROR)


def _calibrate(sim: FlightSeries, real: FlightSeries) -> Calibration | None:
    """REAL with each gyro axis off beyond :data:`_SIGMAS` corrected, or None when every axis agrees."""
    measured = gyro_scale_errors(sim, real)
    off = {p.name: p.value for p in measured if _off(p)}
    if not off:
        return None
    signals = dict(real.signals)
    outputs = []
    for rate, derivative, _, name in _AXES:
        if name in off:
            signals[rate] = real[rate] / (1.0 + off[name])
            signals[derivative] = real[derivative] / (1.0 + off[name])
            outputs.append(derivative)
    return Calibration(parameters=measured, outputs=tuple(outputs), corrected=replace(real, signals=signals))


def _what(finding: Finding) -> str:
    errors = [
        f"{p.name.split('_')[1]} {pm(p.value, p.uncertainty, 100.0, sign=True)} %"
        for p in finding.parameters
        if _off(p)
    ]
    return (
        f"The real vehicle's gyro reads another scale than the simulation's against its own attitude "
        f"({', '.join(errors)}): a sensor's calibration, not the vehicle's physics"
    )


TERM = Term(
    effect="sensor_scale",
    summary="a gyro's scale-factor error (the logged rates against the attitude's kinematics)",
    outputs=tuple(derivative for _, derivative, _, _ in _AXES),
    regime=None,
    make=lambda _context: None,
    what=_what,
    coefficients=tuple(Coefficient(key=key, name=name, unit="1") for _, _, key, name in _AXES),
    separated_by="a flight whose attitude is logged apart from its gyros (an external attitude reference)",
    calibrate=_calibrate,
)
