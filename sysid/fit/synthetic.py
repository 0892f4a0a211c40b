"""Synthetic measured responses: an exact model response with a known perturbation.

For testing the identification engine on its own, and for examples: what a
perfect spectral estimator would return, plus multiplicative noise of a
chosen size (dB and deg), with a coherence array you choose.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from sysid.freqresp import FrequencyResponse
from sysid.model.statespace import DelayedStateSpace

__all__ = ["synthetic_responses"]


def synthetic_responses(
    model: DelayedStateSpace,
    pairs: Sequence[str],
    *,
    omega: np.ndarray | None = None,
    fit_range: tuple[float, float] | Mapping[str, tuple[float, float]] = (1.0, 40.0),
    noise_db: float = 0.0,
    noise_deg: float = 0.0,
    coherence: float | np.ndarray = 0.95,
    seed: int = 0,
) -> tuple[FrequencyResponse, ...]:
    """Responses of `model` for the given pairs, perturbed by log-normal noise.

    Parameters
    ----------
    model : DelayedStateSpace
        The truth; a pair's input may name several model inputs (all with that
        signal name are summed, as for a wind signal entering with two delays).
    pairs : sequence of str
        ``"output/input"`` names, e.g. ``"q/delta_lon"``.
    omega : ndarray, shape (n_freq,), optional
        Frequencies, rad/s; default 200 log-spaced points over 0.3-80 rad/s.
    fit_range : tuple of float, or Mapping[str, tuple of float], optional
        ``(omega_min, omega_max)``, rad/s, set on every response, or by pair
        name (pairs not named get ``(1.0, 40.0)``); real gating stops short of
        lightly damped zeros, where the coherence falls.
    noise_db : float, optional
        Standard deviation of the magnitude error, dB.
    noise_deg : float, optional
        Standard deviation of the phase error, deg.
    coherence : float or ndarray, shape (n_freq,), optional
        Coherence gamma^2 given to every response.
    seed : int, optional
        Seed of the noise.

    Returns
    -------
    tuple of FrequencyResponse

    Examples
    --------
    >>> m = DelayedStateSpace(a=np.array([[-2.0]]), b=np.array([[2.0]]), c=np.array([[1.0]]), d=np.zeros((1, 1)),
    ...                       states=("p",), inputs=("delta_lat",), outputs=("p",), input_delays_s=np.array([0.0]))
    >>> fr, = synthetic_responses(m, ["p/delta_lat"], omega=np.array([0.5, 2.0]))
    >>> np.round(np.abs(fr.response), 3)
    array([0.97 , 0.707])
    """
    omega = np.geomspace(0.3, 80.0, 200) if omega is None else np.asarray(omega, dtype=float)
    full = model.frequency_response(omega)
    rng = np.random.default_rng(seed)
    gamma2 = np.broadcast_to(np.asarray(coherence, dtype=float), omega.shape).copy()
    found = []
    for pair in pairs:
        output, _, signal = pair.partition("/")
        if output not in model.outputs or signal not in model.inputs:
            raise ValueError(f"pair {pair!r}: the model has no output {output!r} or input {signal!r}")
        columns = [k for k, name in enumerate(model.inputs) if name == signal]
        exact = full[:, model.outputs.index(output), columns].sum(axis=1)
        perturbation = rng.normal(scale=noise_db / 20.0 * np.log(10.0), size=omega.size) + 1j * rng.normal(
            scale=np.radians(noise_deg), size=omega.size
        )
        response = exact * np.exp(perturbation)
        auto = np.ones(omega.size)
        error = np.sqrt(1.0 - gamma2) / np.sqrt(np.maximum(gamma2, 1e-12) * 2.0 * 20.0)
        span = fit_range.get(pair, (1.0, 40.0)) if isinstance(fit_range, Mapping) else fit_range
        found.append(
            FrequencyResponse(
                input=signal,
                output=output,
                omega=omega,
                response=response,
                coherence=gamma2,
                random_error=error,
                input_autospectrum=auto,
                output_autospectrum=np.abs(response) ** 2,
                cross_spectrum=response,
                windows_s=(10.0,),
                fit_range=(float(span[0]), float(span[1])),
            )
        )
    return tuple(found)
