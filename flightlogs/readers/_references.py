"""References the autopilot logs outside the PX4 table: ArduPilot DataFlash, MAVLink telemetry, RC sticks.

The canonical references (:data:`flightlogs.signals.REFERENCE_SIGNALS`) are
optional: a log without them is not short of anything. PX4 ULog topics map
through :data:`flightlogs.readers.px4_topics.PX4_GROUPS`; this module serves
:mod:`flightlogs.readers.ardupilot` and :mod:`flightlogs.readers.tlog`.

=====================================  ==========================================================
canonical                              source
=====================================  ==========================================================
``p_ref q_ref r_ref``                  DataFlash ``RATE.RDes/PDes/YDes`` (deg/s; centideg/s in
                                       Copter ≤3.3, the logs without ``TimeUS``); tlog
                                       ``ATTITUDE_TARGET.body_roll_rate..`` (rad/s)
``phi_ref theta_ref psi_ref``          DataFlash ``ATT.DesRoll/DesPitch/DesYaw`` (deg, yaw
                                       wrapped to (-π, π] like ``ATT.Yaw``); tlog
                                       ``ATTITUDE_TARGET.q`` (quaternion → Euler)
``stick_lat stick_lon stick_yaw``      DataFlash ``RCIN.Cn``; tlog ``RC_CHANNELS.chann_raw``;
``stick_thr``                          channels and ranges from the parameters
                                       (:func:`stick_channels`)
=====================================  ==========================================================

A DataFlash group whose fields are zero in every sample is taken as not
logged (a writer that fills only some columns) and left out. ATTITUDE_TARGET
samples whose ``type_mask`` says a field is to be ignored are dropped for it.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Literal

import numpy as np

from flightlogs.errors import DataQualityWarning
from flightlogs.frames import quaternion_to_euler
from flightlogs.readers.dataflash import DataFlashMessages, MessageTable

__all__ = ["StickChannel", "stick_channels", "dataflash_references", "tlog_references"]

_STICKS = ("stick_lat", "stick_lon", "stick_yaw", "stick_thr")
_AXIS = {"stick_lat": "ROLL", "stick_lon": "PITCH", "stick_yaw": "YAW", "stick_thr": "THROTTLE"}
_ARDUPILOT_MAP = {"stick_lat": 1, "stick_lon": 2, "stick_yaw": 4, "stick_thr": 3}  # RCMAP_* defaults
_PWM_DEFAULTS = {"ardupilot": (1100.0, 1500.0, 1900.0), "px4": (1000.0, 1500.0, 2000.0)}  # RCn_MIN/TRIM/MAX
_TARGET_IGNORE_ATTITUDE = 128  # ATTITUDE_TARGET_TYPEMASK_ATTITUDE_IGNORE; 1, 2, 4 ignore the body rates
_NO_RC = (0.0, 65535.0)  # no pulse; RC_CHANNELS: channel unused


@dataclass(frozen=True, slots=True, kw_only=True)
class StickChannel:
    """One pilot stick: the RC input channel that carries it and the calibration that normalises it.

    Parameters
    ----------
    name : str
        Canonical stick name, ``"stick_lat"`` ... ``"stick_thr"``.
    channel : int
        RC input channel, from 1.
    low, trim, high : float
        Calibrated PWM at the stick's ends and centre (``RCn_MIN``,
        ``RCn_TRIM``, ``RCn_MAX``), µs.
    reversed : bool
        Whether the channel is reversed (``RCn_REVERSED`` = 1, or ``RCn_REV`` = -1).
    note : str
        Where each number came from, for the signal's source string.
    """

    name: str
    channel: int
    low: float
    trim: float
    high: float
    reversed: bool
    note: str

    def __post_init__(self) -> None:
        if self.name not in _STICKS:
            raise ValueError(f"{self.name=} must be one of {_STICKS}")
        if self.channel < 1:
            raise ValueError(f"{self.channel=} must be ≥ 1")
        if not self.low < self.high:
            raise ValueError(f"{self.low=} must be below {self.high=} (µs)")

    def normalise(self, pwm: np.ndarray) -> np.ndarray:
        """PWM (µs) → the stick's position, positive as the canonical stick is.

        Roll, pitch and yaw: piecewise linear through ``trim``, -1 at ``low``,
        +1 at ``high``; throttle: 0 at ``low``, 1 at ``high``. Clipped to
        the range; the dead zone (``RCn_DZ``) is not applied.

        Parameters
        ----------
        pwm : ndarray, shape (n_samples,)
            Pulse widths, µs.

        Returns
        -------
        ndarray, shape (n_samples,)
            Stick positions, 1.

        Examples
        --------
        >>> roll = StickChannel(name="stick_lat", channel=1, low=1100, trim=1500, high=1900, reversed=False, note="")
        >>> roll.normalise(np.array([1100.0, 1300.0, 1500.0, 1700.0, 2000.0])).tolist()
        [-1.0, -0.5, 0.0, 0.5, 1.0]
        """
        pwm = np.asarray(pwm, dtype=np.float64)
        if self.name == "stick_thr":
            level = np.clip((pwm - self.low) / (self.high - self.low), 0.0, 1.0)
            return 1.0 - level if self.reversed else level
        span = np.where(pwm >= self.trim, self.high - self.trim, self.trim - self.low)
        position = np.clip((pwm - self.trim) / span, -1.0, 1.0)
        return -position if self.reversed else position


def stick_channels(parameters: Mapping[str, float], autopilot: Literal["ardupilot", "px4"]) -> tuple[StickChannel, ...]:
    """The RC channels of the pilot's sticks and their calibration, from the autopilot's parameters.

    Parameters
    ----------
    parameters : Mapping[str, float]
        Autopilot parameters as logged.
    autopilot : {"ardupilot", "px4"}
        Whose parameter names to read.

    Returns
    -------
    tuple of StickChannel
        ``stick_lat stick_lon stick_yaw stick_thr`` in that order, those
        whose channel is known and calibration consistent.

    Warns
    -----
    DataQualityWarning
        For a stick left out because its calibration is inconsistent.

    Notes
    -----
    ArduPilot: channels ``RCMAP_ROLL/PITCH/YAW/THROTTLE`` (defaults 1, 2, 4,
    3), calibration ``RCn_MIN/TRIM/MAX`` (defaults 1100/1500/1900 µs),
    reversal ``RCn_REVERSED`` = 1 (Copter 3.5 on) or ``RCn_REV`` = -1
    (before). PX4: channels ``RC_MAP_ROLL...`` (no default: 0 is
    unassigned), calibration ``RCn_MIN/TRIM/MAX`` (defaults 1000/1500/2000
    µs), reversal ``RCn_REV`` = -1. Both autopilots read a higher pitch PWM
    as stick back (nose up), so no sign is flipped beyond the reversal.
    Defaults used are named in :attr:`StickChannel.note`.

    Examples
    --------
    >>> pitch = stick_channels({"RCMAP_PITCH": 2.0, "RC2_MIN": 1000.0, "RC2_MAX": 2000.0}, "ardupilot")[1]
    >>> pitch.channel, pitch.trim, pitch.note
    (2, 1500.0, 'RCMAP_PITCH=2; RC2_MIN/TRIM/MAX 1000/1500/2000 µs (TRIM the default)')
    """
    found = []
    for name in _STICKS:
        channel = _channel(parameters, name, autopilot)
        if channel is None:
            continue
        stick = _calibrated(parameters, name, channel, autopilot)
        if stick is not None:
            found.append(stick)
    return tuple(found)


def _channel(parameters: Mapping[str, float], name: str, autopilot: str) -> tuple[int, str] | None:
    """RC channel of a stick and the parameter (or default) naming it."""
    key = f"RCMAP_{_AXIS[name]}" if autopilot == "ardupilot" else f"RC_MAP_{_AXIS[name]}"
    value = parameters.get(key)
    if value is None or not np.isfinite(value):
        if autopilot != "ardupilot":
            return None
        return _ARDUPILOT_MAP[name], f"{key} default {_ARDUPILOT_MAP[name]}"
    return (int(value), f"{key}={int(value)}") if int(value) >= 1 else None


def _calibrated(
    parameters: Mapping[str, float], name: str, channel: tuple[int, str], autopilot: str
) -> StickChannel | None:
    number, mapped = channel
    prefix = f"RC{number}_"
    defaults = dict(zip(("MIN", "TRIM", "MAX"), _PWM_DEFAULTS[autopilot]))
    values = {key: float(parameters.get(prefix + key, default)) for key, default in defaults.items()}
    assumed = [key for key in defaults if prefix + key not in parameters]
    low, trim, high = values["MIN"], values["TRIM"], values["MAX"]
    if name == "stick_thr":
        consistent = low < high  # throttle is scaled min..max; its trim is not used
    else:
        consistent = low < trim < high
    if not consistent:
        message = (
            f"{prefix}MIN/TRIM/MAX {low:g}/{trim:g}/{high:g} µs are inconsistent; "
            f"{name} not read from RC channel {number}"
        )
        warnings.warn(DataQualityWarning(message), stacklevel=3)
        return None
    if autopilot == "ardupilot" and prefix + "REVERSED" in parameters:
        reversed_ = parameters[prefix + "REVERSED"] == 1
    else:
        reversed_ = parameters.get(prefix + "REV", 1.0) == -1
    note = f"{mapped}; {prefix}MIN/TRIM/MAX {low:g}/{trim:g}/{high:g} µs"
    if assumed:
        note += f" ({'/'.join(assumed)} the default)"
    if reversed_:
        note += ", reversed"
    return StickChannel(name=name, channel=number, low=low, trim=trim, high=high, reversed=reversed_, note=note)


# --------------------------------------------------------------------------- DataFlash


def dataflash_references(
    messages: DataFlashMessages,
    parameters: Mapping[str, float],
    add: Callable[..., None],
    *,
    wrap_yaw: Callable[[np.ndarray], np.ndarray],
) -> None:
    """Add the rate and attitude setpoints and the sticks of an ArduPilot log.

    Parameters
    ----------
    messages : DataFlashMessages
        The decoded log (``RATE``, ``ATT``, ``RCIN``).
    parameters : Mapping[str, float]
        Its parameters (``RCMAP_*``, ``RCn_*``).
    add : callable
        ``add(name, table, column, unit, source, convert)`` of
        :func:`flightlogs.readers.ardupilot.flightlog_from_messages`.
    wrap_yaw : callable
        Degrees → radians in (-π, π], the conversion ``ATT.Yaw`` gets.
    """
    rate = messages.get("RATE")
    columns = ("RDes", "PDes", "YDes")
    if rate is not None and _logged(rate, columns):
        legacy = "TimeUS" not in rate  # Copter ≤3.3 logs the rate targets in centidegrees/s
        scale, note = (np.deg2rad(0.01), "cdeg/s→rad/s, Copter ≤3.3") if legacy else (np.deg2rad(1.0), "deg/s→rad/s")
        for name, column in zip(("p_ref", "q_ref", "r_ref"), columns):
            add(name, rate, column, "rad/s", f"RATE.{column} ({note})", lambda v: v * scale)
    att = messages.get("ATT")
    if att is not None and _logged(att, ("DesRoll", "DesPitch", "DesYaw")):
        add("phi_ref", att, "DesRoll", "rad", "ATT.DesRoll (deg→rad)", np.deg2rad)
        add("theta_ref", att, "DesPitch", "rad", "ATT.DesPitch (deg→rad)", np.deg2rad)
        add("psi_ref", att, "DesYaw", "rad", "ATT.DesYaw (deg→rad, wrapped to (-π, π])", wrap_yaw)
    rcin = messages.get("RCIN")
    if rcin is None:
        return
    sticks = [stick for stick in stick_channels(parameters, "ardupilot") if f"C{stick.channel}" in rcin]
    live = _receiving(rcin, [f"C{stick.channel}" for stick in sticks], "RCIN")
    if live is None:
        return
    table = rcin.select(live)
    for stick in sticks:
        add(stick.name, table, f"C{stick.channel}", "1", f"RCIN.C{stick.channel} ({stick.note})", stick.normalise)


def _logged(table: MessageTable, columns: tuple[str, ...]) -> bool:
    """Whether every column is there and one of them is not zero throughout."""
    return all(column in table for column in columns) and any(np.any(table[column] != 0) for column in columns)


def _receiving(table: MessageTable | Mapping[str, np.ndarray], columns: list[str], label: str) -> np.ndarray | None:
    """Rows where every stick channel carries a pulse (not 0, not 65535); None if there is none."""
    if not columns:
        return None
    live = np.ones(len(table[columns[0]]), dtype=bool)
    for column in columns:
        live &= ~np.isin(np.asarray(table[column], dtype=np.float64), _NO_RC)
    if not live.any():
        message = f"{label}: the stick channels carry no pulse in any sample (no RC receiver); sticks not read"
        warnings.warn(DataQualityWarning(message), stacklevel=3)
        return None
    if not live.all():
        message = (
            f"{label}.{', '.join(columns)}: dropped {int((~live).sum())} of {live.size} samples "
            "without a pulse on a stick channel (no RC signal)"
        )
        warnings.warn(DataQualityWarning(message), stacklevel=3)
    return live


# --------------------------------------------------------------------------- MAVLink telemetry


def tlog_references(
    tables: Mapping[str, Mapping[str, np.ndarray]],
    time_s: Callable[[Mapping[str, np.ndarray]], np.ndarray],
    autopilot: Literal["ardupilot", "px4"],
    parameters: Mapping[str, float],
    add: Callable[[str, np.ndarray, np.ndarray, str, str], None],
) -> None:
    """Add the setpoints (``ATTITUDE_TARGET``) and the sticks (``RC_CHANNELS``) of a telemetry log.

    Parameters
    ----------
    tables : Mapping[str, Mapping[str, ndarray]]
        Message type → field → column, as :mod:`flightlogs.readers.tlog` keeps them.
    time_s : callable
        Log time, s, of each row of a table stamped with ``time_boot_ms``.
    autopilot : {"ardupilot", "px4"}
        Whose parameter names give the RC calibration.
    parameters : Mapping[str, float]
        The parameters seen in the log.
    add : callable
        ``add(name, time_s, values, unit, source)``.
    """
    target = tables.get("ATTITUDE_TARGET")
    if target is not None and target["rx"].size:
        stamps = time_s(target)
        mask = target["type_mask"].astype(np.int64)
        for bit, (name, field) in enumerate(
            (("p_ref", "body_roll_rate"), ("q_ref", "body_pitch_rate"), ("r_ref", "body_yaw_rate"))
        ):
            used = (mask & (1 << bit)) == 0
            if used.sum() >= 2:
                add(name, stamps[used], target[field][used], "rad/s", f"ATTITUDE_TARGET.{field}")
        quaternion = np.column_stack([target[f"q[{i}]"] for i in range(4)])
        used = ((mask & _TARGET_IGNORE_ATTITUDE) == 0) & (np.linalg.norm(quaternion, axis=1) > 0.5)
        if used.sum() >= 2:
            euler = quaternion_to_euler(quaternion[used])
            for k, name in enumerate(("phi_ref", "theta_ref", "psi_ref")):
                add(name, stamps[used], euler[:, k], "rad", "ATTITUDE_TARGET.q[0..3] (quaternion→Euler)")
    table = tables.get("RC_CHANNELS")
    if table is None or not table["rx"].size:
        return
    sticks = [s for s in stick_channels(parameters, autopilot) if f"chan{s.channel}_raw" in table]
    live = _receiving(table, [f"chan{s.channel}_raw" for s in sticks], "RC_CHANNELS")
    if live is None:
        return
    stamps = time_s(table)[live]
    for stick in sticks:
        field = f"chan{stick.channel}_raw"
        add(stick.name, stamps, stick.normalise(table[field][live]), "1", f"RC_CHANNELS.{field} ({stick.note})")
