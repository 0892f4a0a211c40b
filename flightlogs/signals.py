"""The canonical signal vocabulary shared by every layer.

All signals after ingest are named and scaled as in ``DESIGN.md``: SI units,
radians, FRD body axes and NED earth axes (PX4 conventions). Mixer inputs,
motor commands and the excitation keep the unit they were logged in, and the
unit is recorded with them.

The references the autopilot logs (:data:`REFERENCE_SIGNALS`) are optional:
rate and attitude setpoints in SI units and radians, and the pilot's sticks
normalised (unit ``"1"``), each positive in the sense of the positive body
rate it asks for (``stick_lat`` right → ``+p``, ``stick_lon`` back, nose up →
``+q``, ``stick_yaw`` right → ``+r``, ``stick_thr`` up → more thrust).
``stick_lat stick_lon stick_yaw`` span -1..1; ``stick_thr`` spans 0..1, or
-1..1 where the autopilot logs it so (PX4 ``manual_control_setpoint.throttle``,
v1.14 on).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

__all__ = [
    "SignalSpec",
    "CANONICAL_SIGNALS",
    "LOGGED_SIGNALS",
    "ESTIMATOR_SIGNALS",
    "REFERENCE_SIGNALS",
    "STATE_SIGNALS",
    "COMMAND_AXES",
    "is_canonical",
    "describe",
]


@dataclass(frozen=True, slots=True)
class SignalSpec:
    """Meaning and SI unit of one canonical signal.

    Parameters
    ----------
    name : str
        Canonical name, e.g. ``"q"``.
    meaning : str
        Plain-language description.
    unit : str
        SI unit, or ``"as logged"`` when the autopilot's own unit is kept.
    """

    name: str
    meaning: str
    unit: str


_SPECS = (
    SignalSpec("p", "body roll rate", "rad/s"),
    SignalSpec("q", "body pitch rate", "rad/s"),
    SignalSpec("r", "body yaw rate", "rad/s"),
    SignalSpec("phi", "roll angle", "rad"),
    SignalSpec("theta", "pitch angle", "rad"),
    SignalSpec("psi", "yaw angle (heading)", "rad"),
    SignalSpec("vn", "north velocity", "m/s"),
    SignalSpec("ve", "east velocity", "m/s"),
    SignalSpec("vd", "down velocity", "m/s"),
    SignalSpec("u", "body-x air-relative velocity (eq. 3.1)", "m/s"),
    SignalSpec("v", "body-y air-relative velocity (eq. 3.1)", "m/s"),
    SignalSpec("w", "body-z air-relative velocity (eq. 3.1)", "m/s"),
    SignalSpec("ax", "body-x specific force", "m/s^2"),
    SignalSpec("ay", "body-y specific force", "m/s^2"),
    SignalSpec("az", "body-z specific force", "m/s^2"),
    SignalSpec("delta_lat", "roll mixer input", "as logged"),
    SignalSpec("delta_lon", "pitch mixer input", "as logged"),
    SignalSpec("delta_yaw", "yaw mixer input", "as logged"),
    SignalSpec("delta_thr", "thrust mixer input", "as logged"),
    SignalSpec("wind_n", "north wind at the vehicle (blowing towards)", "m/s"),
    SignalSpec("wind_e", "east wind at the vehicle (blowing towards)", "m/s"),
    SignalSpec("wind_lon", "wind along body x", "m/s"),
    SignalSpec("wind_lat", "wind along body y", "m/s"),
    SignalSpec("height_agl", "height above ground", "m"),
    SignalSpec("battery_v", "battery voltage", "V"),
    SignalSpec("excitation", "injected excitation signal", "as logged"),
    SignalSpec("est_wind_n", "autopilot's own north wind estimate", "m/s"),
    SignalSpec("est_wind_e", "autopilot's own east wind estimate", "m/s"),
    SignalSpec("latitude", "WGS-84 latitude of the vehicle (GNSS receiver or estimator)", "rad"),
    SignalSpec("longitude", "WGS-84 longitude of the vehicle (GNSS receiver or estimator)", "rad"),
    SignalSpec("p_ref", "body roll rate setpoint", "rad/s"),
    SignalSpec("q_ref", "body pitch rate setpoint", "rad/s"),
    SignalSpec("r_ref", "body yaw rate setpoint", "rad/s"),
    SignalSpec("phi_ref", "roll angle setpoint", "rad"),
    SignalSpec("theta_ref", "pitch angle setpoint", "rad"),
    SignalSpec("psi_ref", "yaw angle (heading) setpoint", "rad"),
    SignalSpec("stick_lat", "pilot's roll stick, right positive (-1..1)", "1"),
    SignalSpec("stick_lon", "pilot's pitch stick, back (nose up) positive (-1..1)", "1"),
    SignalSpec("stick_yaw", "pilot's yaw stick, right positive (-1..1)", "1"),
    SignalSpec("stick_thr", "pilot's throttle stick, up positive (0..1, or -1..1 as logged)", "1"),
    SignalSpec("armed", "motors armed (1) or not (0), as the autopilot says", "1"),
    SignalSpec("landed", "on the ground (1) or airborne (0), by the autopilot's land detector", "1"),
)

#: Every canonical signal with a fixed name, by name.
CANONICAL_SIGNALS: dict[str, SignalSpec] = {spec.name: spec for spec in _SPECS}

#: Signals a reader is expected to find in a flight log (``motor_1..n`` aside).
#: The ones it cannot find are reported as missing, by name.
LOGGED_SIGNALS: tuple[str, ...] = (
    "p",
    "q",
    "r",
    "phi",
    "theta",
    "psi",
    "vn",
    "ve",
    "vd",
    "ax",
    "ay",
    "az",
    "delta_lat",
    "delta_lon",
    "delta_yaw",
    "delta_thr",
    "height_agl",
    "battery_v",
)

#: Optional signals a reader adds when the autopilot logs them. ``latitude``
#: and ``longitude`` locate the vehicle for the anemometer's transport delay;
#: they are not dynamic signals and stay out of conditioned records.
ESTIMATOR_SIGNALS: tuple[str, ...] = ("excitation", "est_wind_n", "est_wind_e", "latitude", "longitude")

#: Optional references a reader adds when the autopilot logs them (the inputs
#: a piloted or injected maneuver gives the feedback loops); like the
#: estimator's signals they are never reported missing.
REFERENCE_SIGNALS: tuple[str, ...] = (
    "p_ref",
    "q_ref",
    "r_ref",
    "phi_ref",
    "theta_ref",
    "psi_ref",
    "stick_lat",
    "stick_lon",
    "stick_yaw",
    "stick_thr",
)

#: Optional flight states a reader adds when the autopilot logs them: whether it is armed and whether its land
#: detector says it is on the ground. They tell hover from a bench or the time before take-off; like the
#: position they are not dynamic signals and stay out of conditioned records.
STATE_SIGNALS: tuple[str, ...] = ("armed", "landed")

#: The control axis each command moves: the mixer inputs and the references.
COMMAND_AXES: Mapping[str, str] = MappingProxyType(
    {
        **{f"delta_{axis}": axis for axis in ("lat", "lon", "yaw", "thr")},
        **{f"stick_{axis}": axis for axis in ("lat", "lon", "yaw", "thr")},
        **dict.fromkeys(("p_ref", "phi_ref"), "lat"),
        **dict.fromkeys(("q_ref", "theta_ref"), "lon"),
        **dict.fromkeys(("r_ref", "psi_ref"), "yaw"),
    }
)

_MOTOR = re.compile(r"motor_([1-9][0-9]?)")


def is_canonical(name: str) -> bool:
    """Return True if `name` is a canonical signal name (``motor_N`` included).

    Parameters
    ----------
    name : str
        Name to check.
    """
    return name in CANONICAL_SIGNALS or _MOTOR.fullmatch(name) is not None


def describe(name: str) -> SignalSpec:
    """Return the :class:`SignalSpec` of a canonical name.

    Parameters
    ----------
    name : str
        Canonical name, ``motor_N`` included.

    Raises
    ------
    KeyError
        If `name` is not canonical.

    Examples
    --------
    >>> describe("q").unit
    'rad/s'
    >>> describe("motor_3").meaning
    'motor 3 command'
    """
    if name in CANONICAL_SIGNALS:
        return CANONICAL_SIGNALS[name]
    match = _MOTOR.fullmatch(name)
    if match is None:
        raise KeyError(f"{name!r} is not a canonical signal name")
    return SignalSpec(name, f"motor {match.group(1)} command", "as logged")
