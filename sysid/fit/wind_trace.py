"""The wind as a person checks its timing: at the anemometer, where the vehicle met it, and as the accelerometers felt it.

The wind step regresses eq. 3.14's residual on the anemometer's wind moved
to the vehicle (the transport delay, and the clock offset the residual
measured, :mod:`sysid.fit.wind_offset`). One record of it is kept for the
report: the along-nose wind the anemometer read, the same air where the
vehicle met it, and the wind the accelerometers say the vehicle met, the
along-nose residual of eq. 3.14 left without G_w divided by the gain G_w
found for it (X_w_lon), low-passed as the wind is (:data:`SMOOTHING_HZ`). When
the timing is right the second and third lie on each other, and the first
leads them by the transport delay.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np

from flightlogs.conditioning.condition import ConditionedFlight
from flightlogs.record import Record
from sysid.fit.result import WindTrace
from sysid.fit.wind import identified_outputs, prediction_residual
from sysid.fit.wind_offset import SMOOTHING_HZ, smoothed
from sysid.model.assemble import Assembler
from sysid.model.structure import ModelStructure

__all__ = ["TRACE_RATE_HZ", "wind_trace"]

#: Rate the trace is kept at, Hz: the wind regressed on is low-passed at 2 Hz.
TRACE_RATE_HZ = 10.0


def wind_trace(
    structure: ModelStructure,
    values: Mapping[str, float],
    constants: Mapping[str, float],
    records: Sequence[Record],
    flights: Sequence[ConditionedFlight],
    *,
    output: str = "ax",
) -> WindTrace | None:
    """The longest wind-step record's along-nose wind at the anemometer, at the vehicle and from `output`.

    Parameters
    ----------
    structure : ModelStructure
        A structure with wind inputs.
    values : Mapping[str, float]
        Identified values, the wind step's included (G_w gains, speed derivatives estimated again).
    constants : Mapping[str, float]
        Trim constants, SI.
    records : sequence of Record
        Records of the wind step, their wind where the vehicle met it.
    flights : sequence of ConditionedFlight
        Their flights: the record's anemometer-to-vehicle delay is its flight's.
    output : str, optional
        The accelerometer output whose residual is read as wind.

    Returns
    -------
    WindTrace or None
        None when no record carries the wind, `output` is not an output of
        the structure or reads an unidentified axis, or no estimated G_w
        gain carries the wind to it.
    """
    values, kept, _ = identified_outputs(structure, values, [output] if output in structure.outputs else [])
    if not kept or not records:
        return None
    assembler = Assembler(structure, free=(), fixed=values, constants=constants, include_wind=True)
    row = structure.outputs.index(output)
    columns = [j for j, c in enumerate(assembler.channels) if c.wind]
    gains = assembler.matrices(np.zeros(0)).d[row, columns]
    if not np.all(np.isfinite(gains)) or not np.any(gains != 0):
        return None  # no wind channel, or no G_w gain estimated on `output`
    channel = int(np.argmax(np.abs(gains)))
    signal = assembler.channels[columns[channel]].signal
    record = max((r for r in records if signal in r.signals), key=lambda r: r.time_s[-1] - r.time_s[0], default=None)
    if record is None:
        return None
    transport_delay_s = next(
        (f.wind.transport.delay_s for f in flights if f.wind is not None and f.source == record.source), math.nan
    )
    if not math.isfinite(transport_delay_s):
        return None
    residual = prediction_residual(structure, values, constants, record, output)
    t, at_vehicle = record.time_s, record[signal] - float(np.mean(record[signal]))
    felt = smoothed(residual[:, None] / float(gains[channel]), record.rate_hz)[:, 0]
    keep = t <= t[-1] - transport_delay_s  # the anemometer's reading of the air the record's last sample met
    step = max(int(record.rate_hz // TRACE_RATE_HZ), 1)
    pick = np.flatnonzero(keep)[::step]
    if pick.size < 16:
        return None
    return WindTrace(
        record=record.label,
        time_s=t[pick],
        at_anemometer_m_s=np.interp(t[pick] + transport_delay_s, t, at_vehicle),
        at_vehicle_m_s=at_vehicle[pick],
        from_accelerations_m_s=felt[pick],
        output=output,
        gain=float(gains[channel]),
        transport_delay_s=transport_delay_s,
        smoothing_hz=SMOOTHING_HZ,
    )
