"""Frequency responses: chirp-z spectra, composite windows, conditioning and gating.

The public names live in small modules and are re-exported here:
:mod:`~sysid.freqresp.options` (:class:`ResponseOptions`),
:mod:`~sysid.freqresp.estimate` (:func:`frequency_responses`),
:mod:`~sysid.freqresp.gating` (:func:`gate_responses`),
:mod:`~sysid.freqresp.records` (:func:`maneuver_records`, :data:`DEFAULT_PAIRS`,
:func:`flight_responses`) and :mod:`~sysid.freqresp.io` (HDF5). Private
modules hold the numerics: ``_spectra`` (windowed spectra), ``_whole`` (the
records' whole-length transforms, the composite's bias-free member),
``_conditioning`` (conditioned and instrumental-variable estimates) and
``_composite``.
"""

from sysid.freqresp.estimate import automatic_window_lengths, frequency_responses
from sysid.freqresp.gating import DroppedResponse, GatingResult, fit_range, gate_responses
from sysid.freqresp.io import RESPONSES_SCHEMA_VERSION, read_responses, write_responses
from sysid.freqresp.options import ResponseOptions
from sysid.freqresp.records import (
    DEFAULT_PAIRS,
    EXCITATION,
    FlightResponses,
    default_pairs,
    flight_responses,
    maneuver_records,
    parse_pairs,
    reference_options,
)
from sysid.freqresp.response import FrequencyResponse

__all__ = [
    "FrequencyResponse",
    "ResponseOptions",
    "frequency_responses",
    "automatic_window_lengths",
    "DroppedResponse",
    "GatingResult",
    "gate_responses",
    "fit_range",
    "write_responses",
    "read_responses",
    "RESPONSES_SCHEMA_VERSION",
    "DEFAULT_PAIRS",
    "EXCITATION",
    "maneuver_records",
    "parse_pairs",
    "default_pairs",
    "reference_options",
    "FlightResponses",
    "flight_responses",
]
