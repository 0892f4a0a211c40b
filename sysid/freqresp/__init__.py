"""Frequency responses: chirp-z spectra, composite windows, conditioning and gating."""

from .response import FrequencyResponse

__all__ = ["FrequencyResponse"]
