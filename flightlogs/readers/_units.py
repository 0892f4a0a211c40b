"""Units a table's column may be given in, and their size in the canonical signal's SI unit.

Mixer inputs, motor commands and the excitation keep the unit they were
logged in (:mod:`flightlogs.signals`): for them a unit is a label, checked
against :data:`AS_LOGGED` (a percentage is scaled to the normalised 0..1).
"""

from __future__ import annotations

import math
import re
from types import MappingProxyType

__all__ = ["SI_SIZES", "AS_LOGGED", "canonical_unit", "si_factor"]

_G = 9.80665  # standard gravity, m/s^2
_DEG = math.pi / 180.0

#: Size of each known unit in the SI unit it converts to, by SI unit (``"s"`` for time).
SI_SIZES = MappingProxyType(
    {
        "s": {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9},
        "rad": {"rad": 1.0, "deg": _DEG},
        "rad/s": {"rad/s": 1.0, "deg/s": _DEG},
        "m/s": {"m/s": 1.0, "cm/s": 0.01, "mm/s": 0.001, "km/h": 1.0 / 3.6, "kn": 1852.0 / 3600.0, "ft/s": 0.3048},
        "m/s^2": {"m/s^2": 1.0, "g": _G, "mg": _G * 1e-3, "ft/s^2": 0.3048},
        "m": {"m": 1.0, "cm": 0.01, "mm": 0.001, "km": 1000.0, "ft": 0.3048},
        "V": {"V": 1.0, "mV": 1e-3},
        "1": {"1": 1.0, "%": 0.01},
    }
)

#: Labels a mixer input, motor command or excitation may carry (kept, not converted), by alias:
#: ``normalised`` (0..1 or -1..1, the default), ``us`` (PWM pulse width), ``rpm`` and ``rad/s`` (rotor speed).
AS_LOGGED = MappingProxyType(
    {"normalised": "normalised", "1": "normalised", "us": "us", "rpm": "rpm", "rad/s": "rad/s"}
)

_ALIASES = {
    "sec": "s",
    "second": "s",
    "seconds": "s",
    "msec": "ms",
    "µs": "us",
    "μs": "us",
    "usec": "us",
    "nsec": "ns",
    "degree": "deg",
    "degrees": "deg",
    "°": "deg",
    "radian": "rad",
    "radians": "rad",
    "deg/sec": "deg/s",
    "°/s": "deg/s",
    "dps": "deg/s",
    "rad/sec": "rad/s",
    "rps": "rad/s",
    "mps": "m/s",
    "kph": "km/h",
    "kmh": "km/h",
    "kt": "kn",
    "kts": "kn",
    "knots": "kn",
    "fps": "ft/s",
    "m/s2": "m/s^2",
    "m/s²": "m/s^2",
    "m/s/s": "m/s^2",
    "ft/s2": "ft/s^2",
    "ft/s²": "ft/s^2",
    "v": "V",
    "mv": "mV",
    "pwm": "us",
    "percent": "%",
    "norm": "normalised",
    "normalized": "normalised",
    "rev/min": "rpm",
}


def canonical_unit(text: str) -> str:
    """The unit's canonical spelling (``"deg/sec"`` → ``"deg/s"``), or `text` stripped when it has no alias.

    Parameters
    ----------
    text : str
        A unit as a user or a header writes it.

    Examples
    --------
    >>> canonical_unit(" Deg/Sec ")
    'deg/s'
    >>> canonical_unit("m/s²")
    'm/s^2'
    """
    spelled = re.sub(r"\s", "", text)
    lowered = spelled.lower()
    known = {u for sizes in SI_SIZES.values() for u in sizes} | set(AS_LOGGED)
    for candidate in (spelled, lowered):
        if candidate in known:
            return candidate
    return _ALIASES.get(lowered, spelled)


def si_factor(unit: str, si_unit: str) -> float | None:
    """The factor that takes a value in `unit` to `si_unit`, or None when `unit` is not one of its units.

    Parameters
    ----------
    unit : str
        Canonical spelling (:func:`canonical_unit`).
    si_unit : str
        The SI unit wanted, a key of :data:`SI_SIZES`.

    Examples
    --------
    >>> round(si_factor("deg/s", "rad/s"), 6)
    0.017453
    >>> si_factor("deg", "m") is None
    True
    """
    return SI_SIZES.get(si_unit, {}).get(unit)
