"""Which responses, over which frequencies, a model may be fitted to (dissertation eq. 3.8)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from flightlogs.masks import true_runs
from sysid.freqresp.response import FrequencyResponse

__all__ = ["DroppedResponse", "Gating", "GatingResult", "gate_responses", "fit_range"]

#: Dips below the threshold spanning at most this are bridged, decades (a few noisy points do not split a range).
BRIDGE_DECADES = 0.05


@dataclass(frozen=True, slots=True, kw_only=True)
class Gating:
    """The rule of eq. 3.8 a response must pass to be fitted, for every command that gates.

    Parameters
    ----------
    min_coherence : float
        Threshold on gamma^2, in (0, 1) (dissertation eq. 3.8: 0.5; 0.6 is the stricter choice for noisy data).
    min_decades : float
        Shortest acceptable fit range ``log10(omega_max / omega_min)``, decades (eq. 3.8: 0.3).

    Raises
    ------
    ValueError
        If either is out of range.
    """

    min_coherence: float = 0.5
    min_decades: float = 0.3

    def __post_init__(self) -> None:
        if not 0.0 < self.min_coherence < 1.0:
            raise ValueError(f"min_coherence={self.min_coherence!r} must lie in (0, 1)")
        if not self.min_decades > 0:
            raise ValueError(f"min_decades={self.min_decades!r} must be > 0")


@dataclass(frozen=True, slots=True, kw_only=True)
class DroppedResponse:
    """A response left out of the fit, and why.

    Parameters
    ----------
    input : str
        Input name.
    output : str
        Output name.
    reason : str
        One sentence.
    """

    input: str
    output: str
    reason: str

    @property
    def pair(self) -> str:
        """``output/input``."""
        return f"{self.output}/{self.input}"


@dataclass(frozen=True, slots=True, kw_only=True)
class GatingResult:
    """Responses kept (with their fit range set) and those dropped.

    Parameters
    ----------
    kept : tuple of FrequencyResponse
        Responses passing the coherence and span rules, ``fit_range`` set, in the order given.
    dropped : tuple of DroppedResponse
        The others, with the reason, in the order given.
    """

    kept: tuple[FrequencyResponse, ...]
    dropped: tuple[DroppedResponse, ...]


def fit_range(omega: np.ndarray, coherence: np.ndarray, min_coherence: float) -> tuple[float, float] | None:
    """Widest frequency range (in decades) over which the coherence stays at or above `min_coherence`.

    Dips narrower than :data:`BRIDGE_DECADES` are bridged, except at the top
    of the range, where the coherence must come back for more points than the
    dip held.

    Parameters
    ----------
    omega : ndarray, shape (n_freq,)
        Frequency, rad/s, increasing.
    coherence : ndarray, shape (n_freq,)
        gamma^2.
    min_coherence : float
        Threshold on gamma^2.

    Returns
    -------
    tuple of float or None
        ``(omega_lo, omega_hi)``, rad/s, or None if no point passes.

    Examples
    --------
    >>> omega = np.geomspace(1, 100, 9)
    >>> lo, hi = fit_range(omega, np.array([0.2, 0.9, 0.9, 0.9, 0.3, 0.1, 0.8, 0.9, 0.2]), 0.5)
    >>> round(lo, 3), round(hi, 3)
    (1.778, 5.623)
    """
    good = np.asarray(coherence) >= min_coherence
    if not good.any():
        return None
    index = np.flatnonzero(good)
    log_omega = np.log10(np.asarray(omega, dtype=float))
    runs: list[list[int]] = [[int(index[0]), int(index[0])]]
    for k in index[1:]:
        last = runs[-1][1]
        if k == last + 1 or log_omega[k - 1] - log_omega[last + 1] <= BRIDGE_DECADES:  # the dip's own width
            runs[-1][1] = int(k)
        else:
            runs.append([int(k), int(k)])
    runs = [[lo, _without_a_lone_top(good, lo, hi)] for lo, hi in runs]
    lo, hi = max(runs, key=lambda run: log_omega[run[1]] - log_omega[run[0]])
    return float(omega[lo]), float(omega[hi])


def _without_a_lone_top(good: np.ndarray, lo: int, hi: int) -> int:
    """The last index of a bridged run less the stretches at its top that hold no more points than the dip below.

    A dip is bridged where the coherence comes back. Past the top of a sweep
    the input carries only the autopilot's feedback, and a point or two
    above the threshold there is chance, not the coherence coming back (on a
    fleet log, one point at 70 rad/s with gamma^2 = 0.51 after two at 0.36
    and 0.13, its gain a hundred times the response's, made J 687 of an
    otherwise clean yaw response). The bottom is left as it is: a sweep
    dwells there, and a short stretch below a dip carries the speed
    derivatives (ax/delta_lon from 2.6 rad/s on an independent windy log).
    """
    stretches = [(lo + start, lo + stop - 1) for start, stop in true_runs(good[lo : hi + 1])]  # inclusive
    while len(stretches) > 1 and stretches[-1][1] - stretches[-1][0] < stretches[-1][0] - stretches[-2][1] - 1:
        stretches.pop()
    return stretches[-1][1]


def gate_responses(responses: Sequence[FrequencyResponse], gating: Gating = Gating()) -> GatingResult:
    """Keep the responses with a fit range of gamma^2 >= ``gating.min_coherence`` spanning ``gating.min_decades``.

    Parameters
    ----------
    responses : sequence of FrequencyResponse
        Responses to gate.
    gating : Gating, optional
        The rule (eq. 3.8's by default).

    Returns
    -------
    GatingResult
        Kept responses with ``fit_range`` set (via :func:`dataclasses.replace`), dropped ones with a reason.

    Examples
    --------
    >>> omega = np.geomspace(1.0, 10.0, 11)
    >>> gamma2 = np.where(omega < 4.0, 0.9, 0.2)
    >>> h = FrequencyResponse(input="delta_lon", output="q", omega=omega, response=np.ones(11, complex),
    ...                       coherence=gamma2, random_error=np.zeros(11),
    ...                       input_autospectrum=np.ones(11), output_autospectrum=np.ones(11),
    ...                       cross_spectrum=np.ones(11, complex), windows_s=(2.0,))
    >>> result = gate_responses([h])
    >>> result.kept[0].fit_range
    (1.0, 3.981071705534973)
    >>> print(gate_responses([h], Gating(min_decades=0.7)).dropped[0].reason)
    q/delta_lon: coherence reaches 0.5 over only 0.60 decade (1-3.98 rad/s), less than the 0.7 decade required.
    """
    min_coherence, min_decades = gating.min_coherence, gating.min_decades
    kept: list[FrequencyResponse] = []
    dropped: list[DroppedResponse] = []
    for response in responses:
        span = fit_range(response.omega, response.coherence, min_coherence)
        if span is None:
            best = float(np.nanmax(response.coherence)) if np.any(np.isfinite(response.coherence)) else 0.0
            dropped.append(
                DroppedResponse(
                    input=response.input,
                    output=response.output,
                    reason=f"{response.pair}: coherence never reaches {min_coherence:g} (at most {best:.2f}).",
                )
            )
            continue
        decades = float(np.log10(span[1] / span[0]))
        if decades < min_decades:
            dropped.append(
                DroppedResponse(
                    input=response.input,
                    output=response.output,
                    reason=f"{response.pair}: coherence reaches {min_coherence:g} over only "
                    f"{decades:.2f} decade ({span[0]:.3g}-{span[1]:.3g} rad/s), less than "
                    f"the {min_decades:g} decade required.",
                )
            )
            continue
        kept.append(replace(response, fit_range=span))
    return GatingResult(kept=tuple(kept), dropped=tuple(dropped))
