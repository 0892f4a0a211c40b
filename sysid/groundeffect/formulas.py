"""Thrust ratio F/F0 against height ratio Z/R: the ground-effect laws of chapter 2 (eqs. 2.1-2.5).

Pure formulas, shared by the fitting code (:mod:`sysid.groundeffect`) and the
simulator (:func:`simulator.world.environment.thrust_ratio`, which clamps Z/R from
below before calling them). Z is the height of the rotor plane above the
ground and R the propeller radius, so both ratios are dimensionless.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "cheeseman_bennett",
    "corrected",
    "corrected_denominator",
    "exponential",
    "piecewise_linear",
    "FITTED_2ROTOR_RHO",
    "FITTED_4ROTOR_SLOPE",
    "FITTED_4ROTOR_INTERCEPT",
    "FITTED_4ROTOR_BREAKPOINT",
]

#: Eq. 2.4: the correction of eq. 2.2 fitted to the two-rotor rig data.
FITTED_2ROTOR_RHO = 3.315
#: Eq. 2.5: slope of F/F0 against Z/R fitted to the four-rotor rig data.
FITTED_4ROTOR_SLOPE = -0.0373
#: Eq. 2.5: intercept at Z/R = 0.
FITTED_4ROTOR_INTERCEPT = 1.1651
#: Eq. 2.5: Z/R beyond which F/F0 = 1.
FITTED_4ROTOR_BREAKPOINT = 4.42


def cheeseman_bennett(height_ratio: np.ndarray) -> np.ndarray:
    """Eq. 2.1, the single-rotor law of Cheeseman and Bennett: F/F0 = 1 / (1 - (R/4Z)^2).

    Parameters
    ----------
    height_ratio : ndarray, any shape
        Z/R, rotor-plane height over propeller radius (> 1/4).

    Returns
    -------
    ndarray
        F/F0, same shape.

    Examples
    --------
    >>> float(cheeseman_bennett(np.array(1.0)))
    1.0666666666666667
    """
    return corrected(height_ratio, 1.0)


def corrected(height_ratio: np.ndarray, rho: float) -> np.ndarray:
    """Eq. 2.2, Cheeseman-Bennett with a rotor-interaction correction: F/F0 = 1 / (1 - rho (R/4Z)^2).

    Parameters
    ----------
    height_ratio : ndarray, any shape
        Z/R (greater than sqrt(rho)/4, where the law diverges).
    rho : float
        Correction coefficient (1 is eq. 2.1; eq. 2.4 fits 3.315 for two rotors).

    Returns
    -------
    ndarray
        F/F0, same shape.

    Examples
    --------
    >>> round(float(corrected(np.array(2.0), FITTED_2ROTOR_RHO)), 4)  # "5 % at twice the radius"
    1.0546
    """
    return 1.0 / corrected_denominator(height_ratio, rho)


def corrected_denominator(height_ratio: np.ndarray, rho: float) -> np.ndarray:
    """The denominator of eq. 2.2, 1 - rho (R/4Z)^2: F0/F, which reaches 0 where the law diverges.

    Parameters
    ----------
    height_ratio : ndarray, any shape
        Z/R.
    rho : float
        Correction coefficient (1 for eq. 2.1).

    Returns
    -------
    ndarray
        F0/F under eq. 2.2, same shape (<= 0 below Z/R = sqrt(rho)/4).

    Examples
    --------
    >>> float(corrected_denominator(np.array(1.0), 1.0))  # 1 - 1/16
    0.9375
    """
    x = np.asarray(height_ratio, dtype=np.float64)
    return 1.0 - rho * (1.0 / (4.0 * x)) ** 2


def exponential(height_ratio: np.ndarray, a: float, b: float) -> np.ndarray:
    """Eq. 2.3: F/F0 = a exp(-(Z/R)/b) + 1.

    Parameters
    ----------
    height_ratio : ndarray, any shape
        Z/R.
    a : float
        Amplitude: F/F0 - 1 at Z = 0.
    b : float
        Decay length in units of R (> 0).

    Returns
    -------
    ndarray
        F/F0, same shape.

    Examples
    --------
    >>> float(exponential(np.array(0.0), 0.7, 1.5))
    1.7
    """
    x = np.asarray(height_ratio, dtype=np.float64)
    return a * np.exp(-x / b) + 1.0


def piecewise_linear(height_ratio: np.ndarray, slope: float, intercept: float, breakpoint: float) -> np.ndarray:
    """Eq. 2.5's form: F/F0 = intercept + slope Z/R below the breakpoint, 1 from it on.

    Parameters
    ----------
    height_ratio : ndarray, any shape
        Z/R.
    slope : float
        Change of F/F0 per unit Z/R below the breakpoint (negative in ground effect).
    intercept : float
        F/F0 extrapolated to Z = 0. The law is continuous when
        ``intercept + slope * breakpoint == 1`` (eq. 2.5 misses by 2e-4).
    breakpoint : float
        Z/R where ground effect ends.

    Returns
    -------
    ndarray
        F/F0, same shape.

    Examples
    --------
    >>> x = np.array([2.0, 5.0])
    >>> piecewise_linear(x, FITTED_4ROTOR_SLOPE, FITTED_4ROTOR_INTERCEPT, FITTED_4ROTOR_BREAKPOINT).round(4)
    array([1.0905, 1.    ])
    """
    x = np.asarray(height_ratio, dtype=np.float64)
    return np.where(x < breakpoint, slope * x + intercept, 1.0)
