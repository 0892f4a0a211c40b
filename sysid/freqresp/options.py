"""Choices for frequency-response identification (grid, windows, taper, gating thresholds)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from sysid.freqresp._tapers import taper

__all__ = ["ResponseOptions"]


@dataclass(frozen=True, slots=True, kw_only=True)
class ResponseOptions:
    """How :func:`~sysid.freqresp.frequency_responses` computes and gates responses.

    The defaults follow Tischler & Remple (CIFER's FRESPID / COMPOSITE) for
    the dissertation's 34 s, 0.1-10 Hz sweeps logged at 100 Hz.

    Parameters
    ----------
    omega_min, omega_max : float
        Frequency range of the grid, rad/s (default 0.5-70 rad/s, about
        0.08-11 Hz). Points below what the longest window resolves (see
        `min_cycles`) are left out of the result.
    n_freq : int
        Number of grid points over ``[omega_min, omega_max]``.
    window_lengths_s : tuple of float or None
        Window lengths, s; None for five lengths spaced geometrically from
        ``2 pi / (5 omega_min)`` (``1 / (5 f_min)``) up to half the longest record.
    overlap : float
        Fraction of a window shared with the next one, in [0, 0.95) (CIFER: 0.8).
    taper : str
        Window taper, any name :func:`scipy.signal.get_window` knows (``"hann"``).
    min_cycles : float
        A window's estimate is used only at frequencies with at least this
        many periods inside it (``omega >= 2 pi min_cycles / T_window``).
        Three: with two, the Hann window's main lobe (four bins wide) still
        mixes in the sweep's fade-in tone and the 34 s sweeps of the
        dissertation gave up to 20° phase bias at the lowest points.
    spacing : {"log", "linear"}
        Grid spacing. ``"log"`` (default) evaluates the windows' Fourier
        transforms by one matrix product per window length; ``"linear"`` uses
        the chirp-z transform (:class:`scipy.signal.CZT`), the fast one for a
        dense, evenly spaced zoom grid.
    reference : str or None
        Record column holding the injected excitation (``"excitation"``,
        ArduPilot's SIDD), or None. When given it stands in for the first
        input as an instrumental variable: ``H = G_ry / G_rx`` (conditioned
        on the other inputs, which are their own instruments). In closed
        loop the mixer input carries the feedback of the output noise and
        turbulence, which biases ``G_xy / G_xx`` towards ``-1 / K``; the
        injected signal is uncorrelated with both. The coherence is then the
        one matching the estimate's random error (see
        :mod:`sysid.freqresp._conditioning`). None: the inputs themselves.
    whole_record : bool
        Add the records' whole-length transforms to the composite where they
        are significant (:mod:`sysid.freqresp._whole`; from as many records
        as inputs or fewer, without a reference unless there is one input,
        its noise comes from neighbouring bins: :mod:`sysid.freqresp._local`).
        A record holding a whole maneuver from trim to trim
        gives ``Y = H X`` exactly, free of the windows' resolution bias near
        a closed loop's notch, an unstable pair and the sweep's fade-in
        tone; the grid then reaches down to ``min_cycles`` periods of the
        longest record. False: windows only (CIFER's composite).
    min_excitation_ratio : float
        With quiet records given (flight without the excitation, see
        :func:`~sysid.freqresp.frequency_responses`): the least ratio of the
        input's autospectrum in the maneuvers to its feedback floor for a
        frequency to count; below it the coherence is set to zero. The
        floor is subtracted above it, so the ratio bounds the correction's
        share of the estimate: 4 (6 dB) keeps it to a quarter, which an
        error of a quarter of the floor's own estimate turns into under 0.5 dB.

    Examples
    --------
    >>> ResponseOptions(window_lengths_s=(2.0, 4.0, 8.0), overlap=0.5).window_lengths_s
    (2.0, 4.0, 8.0)
    >>> ResponseOptions(reference="excitation").reference
    'excitation'
    """

    omega_min: float = 0.5
    omega_max: float = 70.0
    n_freq: int = 150
    window_lengths_s: tuple[float, ...] | None = None
    overlap: float = 0.8
    taper: str = "hann"
    min_cycles: float = 3.0
    spacing: Literal["log", "linear"] = "log"
    reference: str | None = None
    whole_record: bool = True
    min_excitation_ratio: float = 4.0

    def __post_init__(self) -> None:
        if not 0.0 < self.omega_min < self.omega_max or not np.isfinite(self.omega_max):
            raise ValueError(f"need 0 < omega_min < omega_max, got {self.omega_min=}, {self.omega_max=} (rad/s)")
        if int(self.n_freq) != self.n_freq or self.n_freq < 2:
            raise ValueError(f"{self.n_freq=} must be an integer >= 2")
        if self.window_lengths_s is not None:
            lengths = tuple(float(t) for t in self.window_lengths_s)
            if not lengths or any(not (t > 0 and np.isfinite(t)) for t in lengths):
                raise ValueError(f"window_lengths_s={self.window_lengths_s} must be positive lengths, s")
            object.__setattr__(self, "window_lengths_s", tuple(sorted(set(lengths))))
        if not 0.0 <= self.overlap < 0.95:
            raise ValueError(f"{self.overlap=} must lie in [0, 0.95)")
        try:
            taper(self.taper, 16)
        except ValueError as err:
            raise ValueError(f"taper={self.taper!r} is not a window scipy.signal.get_window knows") from err
        if not self.min_cycles > 0:
            raise ValueError(f"{self.min_cycles=} must be > 0")
        if self.spacing not in ("log", "linear"):
            raise ValueError(f"spacing={self.spacing!r} must be 'log' or 'linear'")
        if not (self.min_excitation_ratio > 1.0 and np.isfinite(self.min_excitation_ratio)):
            raise ValueError(f"{self.min_excitation_ratio=} must be a finite ratio > 1")
        if self.reference is not None and (not isinstance(self.reference, str) or not self.reference):
            raise ValueError(f"reference={self.reference!r} must be a signal name or None")

    def grid(self) -> np.ndarray:
        """The requested frequency grid, rad/s, shape (n_freq,)."""
        if self.spacing == "log":
            return np.geomspace(self.omega_min, self.omega_max, int(self.n_freq))
        return np.linspace(self.omega_min, self.omega_max, int(self.n_freq))
