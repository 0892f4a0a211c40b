"""Which other mixer inputs move with a maneuver's input: the secondary inputs its responses are conditioned on.

In closed loop a sweep on one axis can drive another axis's controller
through the airframe: in wind, a longitudinal sweep pitches the vehicle,
the air-relative heave follows (``w' = ... + U0 q``) and the altitude loop
answers with the thrust. ``w / delta_lon`` computed from ``delta_lon`` alone
then holds ``Z_thr delta_thr / delta_lon`` as well (8 dB at 3-12 rad/s on
the independent corpus's strong-wind logs). Tischler's practice is to
condition a response on a secondary input when that input is correlated
with the primary one and carries power: :func:`coupled_inputs` finds those
among the candidates; which outputs each one drives is the model
structure's to say (``sysid.fit.identify``).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from flightlogs.record import Record
from sysid.freqresp._conditioning import coherence
from sysid.freqresp.estimate import ChannelWindows, _channels, _common_step, _grid, _window_samples
from sysid.freqresp.options import ResponseOptions

__all__ = ["coupled_inputs"]


def coupled_inputs(
    records: Sequence[Record],
    control: str,
    candidates: Sequence[str],
    options: ResponseOptions,
    *,
    min_coherence: float = 0.5,
    min_share: float = 0.1,
    significance: float = 0.01,
    windows: ChannelWindows | None = None,
) -> tuple[str, ...]:
    """The `candidates` that move with `control` over the maneuvers: coherent with it over part of the grid.

    Parameters
    ----------
    records : sequence of Record
        The maneuver pieces of `control`'s axis.
    control : str
        The maneuver's input (``delta_lon``).
    candidates : sequence of str
        Other inputs the records carry (``delta_thr`` ...).
    options : ResponseOptions
        Grid, windows, overlap and taper (the reference is not used: the question is about the inputs).
    min_coherence : float, optional
        Ordinary coherence gamma^2 between `control` and a candidate that counts as correlated.
    min_share : float, optional
        Share of the frequencies a window length reaches where it must be reached, for some window length.
    significance : float, optional
        Chance that unrelated signals pass at a frequency: the coherence must also exceed
        ``1 - significance^(1 / (n_d - 1))`` for the window's ``n_d`` averages.
    windows : ChannelWindows, optional
        The records' windowed transforms (with the same `options`), shared with the axis's responses:
        `control` is then transformed once for both.

    Returns
    -------
    tuple of str
        The candidates correlated with `control`, in the order given. A
        candidate that never varies is left out.

    Raises
    ------
    MissingSignalError
        If a record lacks `control` or a candidate.

    Notes
    -----
    With ``n_d`` averages unrelated signals reach ``gamma^2 >= x`` with
    probability ``(1 - x)^(n_d - 1)``; the longest windows average three or
    four, so 0.5 alone would pass a noise input at a tenth of their
    frequencies. Each window length is judged on its own coherence.

    The candidates not yet found are transformed together with `control`
    at each window length, so its transform is made once per length, not
    once per candidate; each is judged on its own coherence with it, as if
    alone (the picks the same as one at a time on the chapter 3 campaign and
    eleven of the independent corpus's cases, 32 calls).

    A candidate driven by `control` through the loop alone (no noise, no
    disturbance) is fully coherent with it: conditioning on it then leaves
    nothing of `control` (partial coherence near zero) and gating drops the
    response, as it should, since the data cannot tell the two paths apart.
    """
    dt = _common_step(records)
    names = [n for n in dict.fromkeys(candidates) if n != control]
    blocks = [_channels(r, (control, *names)) for r in records]  # row 0 the control, then each candidate
    lengths = _window_samples(blocks, dt, options)
    omega = _grid(options, dt, max(lengths))
    left = [k for k in range(len(names)) if not all(np.ptp(block[k + 1]) == 0 for block in blocks)]
    windows = ChannelWindows(records, options) if windows is None else windows
    found: set[str] = set()
    for n_window in lengths:  # every candidate still unfound at once: the control's transform made once
        if not left:
            break
        spectra = windows.spectra((control, *(names[k] for k in left)), n_window, omega, keep=(control,))
        if spectra is None or spectra.n_effective <= 1.0:
            continue
        reached = omega >= spectra.omega_low * (1.0 - 1e-12)
        g = spectra.spectra[reached]
        chance = 1.0 - significance ** (1.0 / (spectra.n_effective - 1.0))
        for j, k in enumerate(list(left), start=1):
            gamma2 = coherence(np.real(g[:, 0, 0]), np.real(g[:, j, j]), g[:, 0, j])
            if reached.any() and np.mean(gamma2 >= max(min_coherence, chance)) >= min_share:
                found.add(names[k])
                left.remove(k)
    return tuple(n for n in names if n in found)
