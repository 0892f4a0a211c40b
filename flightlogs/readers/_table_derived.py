"""What a motion-capture table does not record, derived from what it does: specific forces and mixer inputs.

A motion-capture rig logs where the vehicle is and how it is oriented, not
what its accelerometer felt nor what its mixer was asked. Both follow from
the rest, and the discrepancy search and the fits need both:

* ``ax ay az`` (m/s², body axes): the specific force
  ``f = R_ib (dv/dt - g)`` from the NED velocities ``vn ve vd`` and the
  attitude ``phi theta psi`` (:func:`flightlogs.kinematics.specific_force`);
* ``delta_lat delta_lon delta_yaw delta_thr`` (normalised): the mixer
  inputs whose mix gives each rotor's share of full thrust, from the rotor
  speeds (thrust grows with the speed squared: ``(omega / full_scale)^2``) or
  normalised rotor commands, by the least-squares inverse of the layout's
  mixer (rotor k at angle ``a_k`` from the nose, spin ``s_k``, command
  ``delta_thr + g_r (-sin a_k) delta_lat + g_p cos(a_k) delta_lon + g_y s_k delta_yaw``;
  PX4's gains ``g`` are 1).

A signal the table maps itself is never replaced.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

import numpy as np

from flightlogs.errors import DataError
from flightlogs.flightlog import Signal
from flightlogs.kinematics import SPECIFIC_FORCE_WINDOW_S, specific_force

__all__ = ["RotorLayout", "FRAMES", "derived_signals"]

_VELOCITY = ("vn", "ve", "vd")
_ATTITUDE = ("phi", "theta", "psi")
_SPECIFIC_FORCE = ("ax", "ay", "az")
_MIXER_INPUTS = ("delta_lat", "delta_lon", "delta_yaw", "delta_thr")
_ROTOR_SPEEDS = ("rpm", "rad/s")


@dataclass(frozen=True, slots=True)
class RotorLayout:
    """Where each rotor is and how it spins: what turns rotor speeds into mixer inputs.

    Parameters
    ----------
    angles_deg : tuple of float, shape (n_rotors,)
        Angle of rotor k (signal ``motor_{k+1}``) from the nose, positive to the right, deg.
    spins : tuple of int, shape (n_rotors,)
        +1 for a rotor whose drag torque yaws the body right under a positive yaw input, else -1 (PX4's sign).
    full_scale : float or None
        Rotor speed at full thrust, in the motor columns' unit (rpm or rad/s); None when the motors are
        normalised commands.
    gains : tuple of float, shape (3,)
        The mixer's roll, pitch and yaw gains (PX4: 1, 1, 1).

    Raises
    ------
    DataError
        If the layout has fewer than four rotors, a spin is not ±1, or the full scale is not positive.
    """

    angles_deg: tuple[float, ...]
    spins: tuple[int, ...]
    full_scale: float | None = None
    gains: tuple[float, float, float] = (1.0, 1.0, 1.0)

    def __post_init__(self) -> None:
        if len(self.angles_deg) < 4 or len(self.angles_deg) != len(self.spins):
            raise DataError("column map: [rotors] needs one angle and one spin (+1 or -1) for each of 4 or more rotors")
        if any(spin not in (1, -1) for spin in self.spins):
            raise DataError(f"column map: [rotors] spins {list(self.spins)} must each be +1 or -1")
        if self.full_scale is not None and not self.full_scale > 0:
            raise DataError(f"column map: [rotors] full_scale {self.full_scale} must be a positive rotor speed")
        if len(self.gains) != 3 or not all(g > 0 for g in self.gains):
            raise DataError(
                f"column map: [rotors] gains {list(self.gains)} must be three positive numbers (roll, pitch, yaw)"
            )

    @property
    def mixer(self) -> np.ndarray:
        """Rotor commands per mixer input, shape (n_rotors, 4): columns lat, lon, yaw, thr."""
        angles = np.radians(self.angles_deg)
        roll, pitch, yaw = self.gains
        spins = np.asarray(self.spins, float)
        return np.column_stack([-roll * np.sin(angles), pitch * np.cos(angles), yaw * spins, np.ones(angles.size)])


#: Named layouts: PX4's quadrotor X (4001: front-right, rear-left, front-left, rear-right) and an
#: octorotor X (a rotor every 45° from 22.5°, alternating spin).
FRAMES: Mapping[str, tuple[tuple[float, ...], tuple[int, ...]]] = MappingProxyType(
    {
        "quad_x": ((45.0, 225.0, 315.0, 135.0), (1, 1, -1, -1)),
        "octo_x": (tuple(22.5 + 45.0 * k for k in range(8)), (1, -1, 1, -1, 1, -1, 1, -1)),
    }
)


def derived_signals(signals: Mapping[str, Signal], rotors: RotorLayout | None) -> dict[str, Signal]:
    """The specific forces and mixer inputs a table lacks, derived from what it has.

    Parameters
    ----------
    signals : Mapping[str, Signal]
        The table's signals, SI.
    rotors : RotorLayout or None
        The rotor layout, for mixer inputs from ``motor_N``; None derives none.

    Returns
    -------
    dict of str to Signal
        ``ax ay az`` where the velocities and attitude are mapped and they are not; ``delta_*`` where
        the motors and a layout are given and no mixer input is mapped.

    Raises
    ------
    DataError
        If the layout's rotor count differs from the table's motor columns, or rotor speeds come without
        a full scale.
    """
    out: dict[str, Signal] = {}
    if set(_VELOCITY + _ATTITUDE) <= signals.keys() and not set(_SPECIFIC_FORCE) & signals.keys():
        out.update(_specific_force(signals))
    if rotors is not None and not set(_MIXER_INPUTS) & signals.keys():
        out.update(_mixer_inputs(signals, rotors))
    return out


def _specific_force(signals: Mapping[str, Signal]) -> dict[str, Signal]:
    time_s = signals["vn"].time_s
    velocity = np.column_stack([np.interp(time_s, signals[n].time_s, signals[n].values) for n in _VELOCITY])
    attitude = [np.interp(time_s, signals[n].time_s, np.unwrap(signals[n].values)) for n in _ATTITUDE]
    force = specific_force(time_s, velocity, *attitude)
    source = f"derived: d(vn ve vd)/dt - g in body axes (Savitzky-Golay, {SPECIFIC_FORCE_WINDOW_S:g} s)"
    return {
        name: Signal(name=name, time_s=time_s, values=force[:, k], unit="m/s^2", source=source, derived=True)
        for k, name in enumerate(_SPECIFIC_FORCE)
    }


def _mixer_inputs(signals: Mapping[str, Signal], rotors: RotorLayout) -> dict[str, Signal]:
    n_rotors = len(rotors.spins)
    motors = [f"motor_{k}" for k in range(1, n_rotors + 1)]
    mapped = sorted((n for n in signals if n.startswith("motor_")), key=lambda n: int(n[6:]))
    if mapped != motors:
        raise DataError(
            f"column map: [rotors] lays out {n_rotors} rotors but the table maps {', '.join(mapped) or 'no motor'}; "
            f"map {motors[0]}..{motors[-1]}"
        )
    units = {signals[n].unit for n in motors}
    speeds = units <= set(_ROTOR_SPEEDS)
    if len(units) > 1 or not (speeds or units == {"normalised"}):
        raise DataError(
            f"column map: the motors are in {', '.join(sorted(units))}; mixer inputs are derived from rotor "
            "speeds (rpm, rad/s) or normalised commands, all in one unit"
        )
    if speeds and rotors.full_scale is None:
        raise DataError(
            "column map: the motors are rotor speeds; give [rotors] full_scale (the speed at full thrust, "
            f"{units.pop()}) to derive the mixer inputs"
        )
    time_s = signals[motors[0]].time_s
    command = np.column_stack([np.interp(time_s, signals[n].time_s, signals[n].values) for n in motors])
    if speeds:
        assert rotors.full_scale is not None
        command = (command / rotors.full_scale) ** 2
    inputs = np.linalg.lstsq(rotors.mixer, command.T, rcond=None)[0].T
    shown = f"rotor speeds / {rotors.full_scale:g}, squared" if speeds else "rotor commands"
    source = f"derived: the mixer's least-squares inverse of the {shown} ({n_rotors} rotors)"
    return {
        name: Signal(name=name, time_s=time_s, values=inputs[:, k], unit="normalised", source=source, derived=True)
        for k, name in enumerate(_MIXER_INPUTS)
    }
