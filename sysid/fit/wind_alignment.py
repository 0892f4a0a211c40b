"""Whether the anemometer's wind lines up with the flight closely enough for the wind step (eq. 3.14).

The conditioning measures each flight's residual anemometer clock offset by
cross-correlation with the autopilot's wind estimate (or attitude), and
applies it only when asked (``--estimate-wind-offset``). A clear offset of
seconds, found but not applied, puts the wind out of line with the
residual the G_w terms are fitted to: the chapter 3 campaign's anemometer
runs 1.5 s off UTC, and the wind step then dropped all four terms as if the
wind did nothing (issue 14).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from flightlogs.conditioning.condition import ConditionedFlight
from sysid.model.structure import ModelStructure

__all__ = ["wind_misalignment"]

#: Smallest cross-correlation peak (anemometer against the autopilot's wind estimate) trusted as a clock offset.
MIN_OFFSET_CORRELATION = 0.8


def wind_misalignment(flights: Sequence[ConditionedFlight], structure: ModelStructure) -> str:
    """Why the flights' wind cannot be regressed on: its clock is off by more than the wind delays take up; or "".

    The conditioning measures the residual clock offset of each flight's
    anemometer against the autopilot's wind estimate (or attitude) and
    applies it only when asked (``--estimate-wind-offset``). An offset
    found with a clear correlation peak and larger than the largest delay
    the structure allows a wind input (``tau_w`` bounds, 0.5 s for
    ``hover-wind``) leaves the wind and the residual of eq. 3.14 apart by
    more than the wind step can align.

    Parameters
    ----------
    flights : sequence of ConditionedFlight
        The flights, with their wind alignment.
    structure : ModelStructure
        The structure, with wind inputs.

    Returns
    -------
    str
        The logs, the offset found and the option that corrects it; "" when the wind is aligned (or not measured).
    """
    bound = max(
        (structure.parameter(n).upper for c in structure.wind_inputs for n in c.delay.names),
        default=0.0,
    )
    bound = bound if math.isfinite(bound) else 0.5
    off = [
        f
        for f in flights
        if f.wind is not None
        and f.wind.clock_offset_source != "estimated"
        and f.wind.residual is not None
        and abs(f.wind.residual.correlation) >= MIN_OFFSET_CORRELATION
        and abs(f.wind.residual.lag_s) > bound
    ]
    if not off:
        return ""
    lags = [f.wind.residual.lag_s for f in off if f.wind is not None and f.wind.residual is not None]
    offsets = [f.wind.clock_offset_s - lag for f, lag in zip(off, lags) if f.wind is not None]
    against = off[0].wind.residual_against if off[0].wind is not None else None
    names = ", ".join(f.source.name for f in off[:3]) + (" ..." if len(off) > 3 else "")
    return (
        f"the anemometer's clock is off by {-float(np.median(lags)):+.2f} s in {len(off)} of {len(flights)} logs "
        f"({names}): the wind correlates best with the {against or 'vehicle'} {float(np.median(lags)):+.2f} s from "
        f"where it was placed, more than the {bound:g} s the wind delays can take up, so the wind does not line up "
        f"with the residual of eq. 3.14 (nor u v w with the flight); give --estimate-wind-offset, or "
        f"--wind-offset {float(np.median(offsets)):.2f}"
    )
