"""Conditioning: wind alignment, resampling onto one time base, frames and trim, for identification.

The public names of :mod:`~flightlogs.conditioning.align`,
:mod:`~flightlogs.conditioning.condition`, :mod:`~flightlogs.conditioning.lag` and
:mod:`~flightlogs.conditioning.resample` are re-exported here: write ``from flightlogs.conditioning
import name``. Modules with a leading underscore are private.
"""

from flightlogs.conditioning.align import WindAlignment, estimate_residual_offset, overlap_s, pair_winds, wind_log_time
from flightlogs.conditioning.condition import CORE_SIGNALS, ConditionedFlight, ConditioningOptions, condition_flight
from flightlogs.conditioning.lag import (
    FROZEN_TURBULENCE_LIMIT,
    LagEstimate,
    TransportDelay,
    estimate_lag,
    transport_delay,
)
from flightlogs.conditioning.resample import (
    ContiguousSpans,
    Gap,
    Method,
    SeriesLike,
    contiguous_spans,
    find_gaps,
    resample_signal,
    resample_signals,
    uniform_time_base,
)

__all__ = [
    "WindAlignment",
    "pair_winds",
    "overlap_s",
    "wind_log_time",
    "estimate_residual_offset",
    "ConditioningOptions",
    "ConditionedFlight",
    "condition_flight",
    "CORE_SIGNALS",
    "LagEstimate",
    "estimate_lag",
    "TransportDelay",
    "transport_delay",
    "FROZEN_TURBULENCE_LIMIT",
    "Method",
    "SeriesLike",
    "Gap",
    "ContiguousSpans",
    "find_gaps",
    "uniform_time_base",
    "resample_signal",
    "resample_signals",
    "contiguous_spans",
]
