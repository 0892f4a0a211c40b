"""Physics the linear plant leaves out, flown into a REAL vehicle of a discrepancy pair (issue 15).

The plant (:mod:`.plant`) is linear and knows nothing of the ground, the battery or a payload. A
discrepancy pair needs a REAL vehicle that differs from the simulated one by such physics, here with
laws and constants that neither our own simulator (``simulator.world``) nor the search's terms
(``sysid.discrepancy.terms``) use: an exponential cushion where they have the chapter 2 laws and an
inverse square, a fade of the control moments with the voltage that the search does not model.

Each effect is a force or moment that the closed loop feels at every control step, computed from
the state the loop has reached (height, thrust, time) and added to the plant's unmeasured
disturbance inputs ``dist_w``, ``dist_p``, ``dist_q`` (m/s², rad/s²) by :mod:`.forcing`. The
accelerometers read the state derivative (eq. 3.7), so they feel it as a real force would be felt.
More effects: :mod:`.effects_more` (the search's newer catalogue entries, our own laws) and
:mod:`.effects_outside` (physics outside the search's catalogue).

The specific thrust of the linear plant, ``T = g - Z_thr d_thr`` (m/s², up; ``d_thr`` the lagged
thrust command about trim), scales every effect on thrust:

=================  ===================================================================================
effect             law (``z`` rotor height over the ground, m; ``t`` s after take-off; ``V`` volts)
=================  ===================================================================================
GroundCushion      ``T (1 + a exp(-z / L)) ``: an exponential cushion, not the chapter 2 laws
BatteryFade        ``T (V / V_full)^n`` on thrust and the roll and pitch moments, ``V`` the pack's voltage
PayloadPickUp      mass ``m (1 + r)`` from ``t0`` on: every specific force ``/ (1 + r)``
OffsetCentre       rolling and pitching moments ``(k_roll, k_pitch) T``
=================  ===================================================================================
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = [
    "GroundCushion",
    "BatteryFade",
    "PayloadPickUp",
    "OffsetCentre",
    "Effect",
    "pack_voltage",
    "pack_current",
]


@dataclass(frozen=True, slots=True, kw_only=True)
class GroundCushion:
    """Thrust ratio ``1 + gain exp(-z / decay_m)``, z the rotor plane's height over the ground.

    Parameters
    ----------
    gain : float
        Thrust ratio minus one with the rotors at the ground.
    decay_m : float
        Height over which the cushion falls by e, m.
    rotor_above_m : float
        Rotor plane over the logged height (the landing gear), m.
    """

    gain: float = 0.25
    decay_m: float = 0.15
    rotor_above_m: float = 0.12


@dataclass(frozen=True, slots=True, kw_only=True)
class BatteryFade:
    """Thrust and control moments ``∝ (V / full_v)^exponent``, V the logged pack voltage.

    Parameters
    ----------
    exponent : float
        Power of the voltage (2: rotor speed ∝ V, thrust ∝ speed²).
    full_v : float
        Voltage the simulated vehicle assumes, V.
    """

    exponent: float = 2.0
    full_v: float = 25.1


@dataclass(frozen=True, slots=True, kw_only=True)
class PayloadPickUp:
    """The mass grows by `ratio` at `at_s` (s after take-off): a winch picks up a load.

    Parameters
    ----------
    at_s : float
        Time after take-off, s.
    ratio : float
        Added mass over the vehicle's mass.
    """

    at_s: float
    ratio: float = 0.06


@dataclass(frozen=True, slots=True, kw_only=True)
class OffsetCentre:
    """The centre of gravity off the thrust axis: moments per specific thrust, rad/m.

    Parameters
    ----------
    roll_rad_m, pitch_rad_m : float
        Angular acceleration per m/s² of specific thrust, rad/m (``m g dy / I_xx`` over ``g``).
    """

    roll_rad_m: float = 0.02
    pitch_rad_m: float = -0.05


Effect = GroundCushion | BatteryFade | PayloadPickUp | OffsetCentre


def pack_voltage(thrust: np.ndarray, airborne_s: np.ndarray) -> np.ndarray:
    """Voltage of the 6S pack, V: it discharges over the flight and sags with the current.

    Parameters
    ----------
    thrust : ndarray, shape (n,)
        Thrust command, normalised (0..1).
    airborne_s : ndarray, shape (n,)
        Time flown so far, s.

    Returns
    -------
    ndarray, shape (n,)

    Examples
    --------
    >>> round(float(pack_voltage(np.array([0.45]), np.array([100.0]))[0]), 3)
    24.235
    """
    return 25.1 - 0.006 * airborne_s - 0.009 * pack_current(thrust)


def pack_current(thrust: np.ndarray) -> np.ndarray:
    """Current drawn by the motors at a thrust command (0..1), A."""
    return 0.8 + 95.0 * np.abs(thrust) ** 1.5
