"""Frequency responses: chirp-z spectra, composite windows, conditioning and gating.

The public names live in small modules and are re-exported here:
:mod:`~sysid.freqresp.options` (:class:`ResponseOptions`),
:mod:`~sysid.freqresp.estimate` (:func:`frequency_responses`, :func:`frequency_response_sets`,
:class:`ChannelWindows`),
:mod:`~sysid.freqresp.gating` (:func:`gate_responses`),
:mod:`~sysid.freqresp.records` (:func:`maneuver_records`, :func:`maneuver_band`,
:func:`quiet_records`, :func:`within_band`, :data:`DEFAULT_PAIRS`, :func:`flight_responses`),
:mod:`~sysid.freqresp.coupling` (:func:`coupled_inputs`) and :mod:`~sysid.freqresp.io` (HDF5, loaded with
h5py on first use: a fit that writes no responses does not load it).
Private modules hold the numerics: ``_spectra`` (windowed spectra), ``_whole``
(the records' whole-length transforms, the composite's bias-free member),
``_local`` (that member from one record: its neighbouring bins),
``_conditioning`` (conditioned and instrumental-variable estimates) and
``_composite``.
"""

from typing import TYPE_CHECKING

from flightlogs._lazy import lazy_names
from sysid.freqresp.coupling import coupled_inputs
from sysid.freqresp.estimate import (
    ChannelWindows,
    automatic_window_lengths,
    frequency_response_sets,
    frequency_responses,
)
from sysid.freqresp.gating import DroppedResponse, Gating, GatingResult, fit_range, gate_responses
from sysid.freqresp.options import ResponseOptions
from sysid.freqresp.records import (
    DEFAULT_PAIRS,
    EXCITATION,
    FlightResponses,
    default_pairs,
    flight_responses,
    maneuver_band,
    maneuver_records,
    parse_pairs,
    quiet_records,
    reference_options,
    within_band,
)
from sysid.freqresp.response import FrequencyResponse

if TYPE_CHECKING:
    from sysid.freqresp.io import RESPONSES_SCHEMA_VERSION, read_responses, write_responses

__all__ = [
    "ChannelWindows",
    "FrequencyResponse",
    "ResponseOptions",
    "frequency_responses",
    "frequency_response_sets",
    "automatic_window_lengths",
    "coupled_inputs",
    "DroppedResponse",
    "Gating",
    "GatingResult",
    "gate_responses",
    "fit_range",
    "write_responses",
    "read_responses",
    "RESPONSES_SCHEMA_VERSION",
    "DEFAULT_PAIRS",
    "EXCITATION",
    "maneuver_records",
    "maneuver_band",
    "quiet_records",
    "within_band",
    "parse_pairs",
    "default_pairs",
    "reference_options",
    "FlightResponses",
    "flight_responses",
]

__getattr__, __dir__ = lazy_names(
    __name__, dict.fromkeys(("RESPONSES_SCHEMA_VERSION", "read_responses", "write_responses"), "io")
)
