"""The frequency-response object every later step is fitted to."""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np

__all__ = ["FrequencyResponse"]

_ANCHOR_COHERENCE = 0.6  # the phase's branch is fixed at the first frequency this coherent


@dataclass(frozen=True, slots=True, kw_only=True)
class FrequencyResponse:
    """One input-to-output frequency response with its quality measures.

    Parameters
    ----------
    input : str
        Canonical input name (``delta_lon``, ``wind_lon`` ...).
    output : str
        Canonical output name (``q``, ``ax`` ...).
    omega : ndarray, shape (n_freq,)
        Angular frequency, rad/s, increasing.
    response : ndarray of complex, shape (n_freq,)
        Output per unit input (output unit / input unit).
    coherence : ndarray, shape (n_freq,)
        Coherence gamma^2 in [0, 1] (partial coherence when conditioned).
    random_error : ndarray, shape (n_freq,)
        Normalised random error of the magnitude, a fraction (Bendat & Piersol:
        sqrt(1 - gamma^2) / (|gamma| sqrt(2 n_d))).
    input_autospectrum, output_autospectrum : ndarray, shape (n_freq,)
        G_xx and G_yy (one-sided), unit^2 / (rad/s).
    cross_spectrum : ndarray of complex, shape (n_freq,)
        G_xy; with a `reference`, ``response * G_xx`` (``response = cross /
        input`` always holds, ``coherence = |cross|^2 / (input output)`` only
        without a reference).
    windows_s : tuple of float
        Window lengths combined into this response, s.
    conditioned_on : tuple of str, optional
        Other inputs whose correlated part was removed (empty: single input).
    input_unit, output_unit : str, optional
        Units as logged / SI.
    fit_range : tuple of float or None, optional
        ``(omega_min, omega_max)``, rad/s, where the response passed gating;
        ``None`` before gating.
    reference : str or None, optional
        The injected excitation used as instrument for the input (``H = G_ry /
        G_rx``), or None when the response is ``G_xy / G_xx``.
    whole_record : bool, optional
        Whether the records' whole-length transforms contributed to the composite.
    """

    input: str
    output: str
    omega: np.ndarray
    response: np.ndarray
    coherence: np.ndarray
    random_error: np.ndarray
    input_autospectrum: np.ndarray
    output_autospectrum: np.ndarray
    cross_spectrum: np.ndarray
    windows_s: tuple[float, ...]
    conditioned_on: tuple[str, ...] = ()
    input_unit: str = ""
    output_unit: str = ""
    fit_range: tuple[float, float] | None = None
    reference: str | None = None
    whole_record: bool = False

    def __post_init__(self) -> None:
        n_freq = np.shape(self.omega)
        if len(n_freq) != 1 or n_freq[0] < 2:
            raise ValueError(f"omega must be 1-D with at least 2 points, got shape {n_freq}")
        if np.any(np.diff(self.omega) <= 0):
            raise ValueError("omega must be strictly increasing")
        for name in (
            "response",
            "coherence",
            "random_error",
            "input_autospectrum",
            "output_autospectrum",
            "cross_spectrum",
        ):
            shape = np.shape(getattr(self, name))
            if shape != n_freq:
                raise ValueError(f"{name} has shape {shape}, expected {n_freq} like omega")
        if self.fit_range is not None and not self.fit_range[0] < self.fit_range[1]:
            raise ValueError(f"fit_range={self.fit_range} must be (low, high) with low < high")

    @property
    def pair(self) -> str:
        """``output/input``, the name of the pair used on the command line (``q/delta_lon``)."""
        return f"{self.output}/{self.input}"

    @property
    def magnitude_db(self) -> np.ndarray:
        """Magnitude, dB, shape (n_freq,)."""
        return cast(np.ndarray, 20.0 * np.log10(np.maximum(np.abs(self.response), 1e-300)))

    @property
    def phase_deg(self) -> np.ndarray:
        """Phase, deg, unwrapped along frequency, shape (n_freq,).

        The branch is that of the lowest frequency with coherence gamma^2 of
        0.6 or more (the most coherent one if none reaches it), taken in
        (-180, 180] deg: noise at the incoherent low end of the grid would
        otherwise shift the whole curve by whole turns.
        """
        unwrapped = np.unwrap(np.angle(self.response))
        coherent = np.flatnonzero(self.coherence >= _ANCHOR_COHERENCE)
        anchor = int(coherent[0]) if coherent.size else int(np.argmax(np.nan_to_num(self.coherence)))
        turns = np.round((unwrapped[anchor] - np.angle(self.response[anchor])) / (2 * np.pi))
        return cast(np.ndarray, np.degrees(unwrapped - 2 * np.pi * turns))
