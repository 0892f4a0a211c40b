"""Exact zero-order-hold discretisation of a delayed state space, and its simulation.

A delay of ``(m + f)`` samples (``m`` whole, ``0 <= f < 1``) is handled by the
modified z-transform: over one sample interval the delayed, held input is
``u[k-m-1]`` for the first ``f`` of the interval and ``u[k-m]`` for the rest, so

    x[k+1] = Φ(T) x[k] + Γ((1-f)T) u[k-m] + Φ((1-f)T) Γ(fT) u[k-m-1]

with ``Φ(h) = e^{Ah}`` and ``Γ(h) = ∫_0^h e^{Av} dv B``, both taken from one
matrix exponential of ``[[A, B], [0, 0]] h``. This is exact for inputs held
between samples, as a mixer input is between autopilot loop updates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import cast

import numpy as np
from scipy import linalg

from sysid.model.statespace import DelayedStateSpace

__all__ = [
    "DiscreteModel",
    "discretize",
    "shifted",
    "delayed_inputs",
    "output_feedthrough",
    "simulate",
    "predict_one_step",
]


@dataclass(frozen=True, slots=True, kw_only=True)
class DiscreteModel:
    """A delayed state space discretised at one sample interval (ZOH, modified z-transform).

    Parameters
    ----------
    ad : ndarray, shape (n_states, n_states)
        State transition over one sample.
    gamma_now : ndarray, shape (n_states, n_inputs)
        Input matrix of ``u[k - m]``.
    gamma_prev : ndarray, shape (n_states, n_inputs)
        Input matrix of ``u[k - m - 1]`` (zero where the delay is whole samples).
    c : ndarray, shape (n_outputs, n_states)
    d : ndarray, shape (n_outputs, n_inputs)
    whole : ndarray of int, shape (n_inputs,)
        Whole samples ``m`` of each input's delay.
    fraction : ndarray, shape (n_inputs,)
        Fractional part ``f`` of each input's delay, samples, in [0, 1).
    dt_s : float
        Sample interval, s.
    """

    ad: np.ndarray
    gamma_now: np.ndarray
    gamma_prev: np.ndarray
    c: np.ndarray
    d: np.ndarray
    whole: np.ndarray
    fraction: np.ndarray
    dt_s: float


def _phi_gamma(a: np.ndarray, b: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """``e^{Ah}`` and ``∫_0^h e^{Av} dv B`` from one matrix exponential."""
    n_x, n_u = b.shape
    block = np.zeros((n_x + n_u, n_x + n_u))
    block[:n_x, :n_x], block[:n_x, n_x:] = a, b
    exponential = linalg.expm(block * h)
    return exponential[:n_x, :n_x], exponential[:n_x, n_x:]


def discretize(model: DelayedStateSpace, dt_s: float) -> DiscreteModel:
    """Discretise `model` at `dt_s` with its delays as whole plus fractional samples.

    Parameters
    ----------
    model : DelayedStateSpace
        The continuous model.
    dt_s : float
        Sample interval, s.

    Returns
    -------
    DiscreteModel
    """
    a, b = np.asarray(model.a, dtype=float), np.asarray(model.b, dtype=float)
    samples = np.asarray(model.input_delays_s, dtype=float) / dt_s
    whole = np.floor(samples + 1e-9).astype(int)
    fraction = np.clip(samples - whole, 0.0, None)
    fraction[fraction < 1e-9] = 0.0
    ad, _ = _phi_gamma(a, b, dt_s)
    gamma_now = np.empty_like(b)
    gamma_prev = np.zeros_like(b)
    for j, f in enumerate(fraction):
        phi_rest, gamma_rest = _phi_gamma(a, b[:, [j]], (1.0 - f) * dt_s)
        gamma_now[:, j] = gamma_rest[:, 0]
        if f > 0:
            _, gamma_first = _phi_gamma(a, b[:, [j]], f * dt_s)
            gamma_prev[:, j] = (phi_rest @ gamma_first)[:, 0]
    return DiscreteModel(
        ad=ad,
        gamma_now=gamma_now,
        gamma_prev=gamma_prev,
        c=np.asarray(model.c, dtype=float),
        d=np.asarray(model.d, dtype=float),
        whole=whole,
        fraction=fraction,
        dt_s=float(dt_s),
    )


def shifted(inputs: np.ndarray, lag: np.ndarray) -> np.ndarray:
    """Column j of `inputs` delayed by ``lag[j]`` samples, the first value held before the start.

    Parameters
    ----------
    inputs : ndarray, shape (n_samples, n_inputs)
    lag : ndarray of int, shape (n_inputs,)
    """
    n = inputs.shape[0]
    index = np.clip(np.arange(n)[:, None] - lag[None, :], 0, n - 1)
    return np.take_along_axis(inputs, index, axis=0)


def delayed_inputs(model: DiscreteModel, inputs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``u[k - m]`` and ``u[k - m - 1]`` for every input, each shape (n_samples, n_inputs).

    Parameters
    ----------
    model : DiscreteModel
        Its whole-sample delays.
    inputs : ndarray, shape (n_samples, n_inputs)
        Inputs at the sample times.
    """
    return shifted(inputs, model.whole), shifted(inputs, model.whole + 1)


def output_feedthrough(model: DiscreteModel, now: np.ndarray, prev: np.ndarray) -> np.ndarray:
    """``D u(t_k - tau)``: the held value at the delayed instant, shape (n_samples, n_outputs).

    Parameters
    ----------
    model : DiscreteModel
        Its feedthrough and fractional delays.
    now, prev : ndarray, shape (n_samples, n_inputs)
        ``u[k - m]`` and ``u[k - m - 1]`` (:func:`delayed_inputs`).
    """
    held = np.where(model.fraction[None, :] > 0, prev, now)
    return cast(np.ndarray, held @ model.d.T)


def simulate(model: DiscreteModel, inputs: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """Outputs of the discretised model from `x0` driven by `inputs`.

    Parameters
    ----------
    model : DiscreteModel
    inputs : ndarray, shape (n_samples, n_inputs)
        Inputs at the sample times (held in between).
    x0 : ndarray, shape (n_states,)
        State at the first sample.

    Returns
    -------
    ndarray, shape (n_samples, n_outputs)
    """
    now, prev = delayed_inputs(model, inputs)
    drive = now @ model.gamma_now.T + prev @ model.gamma_prev.T
    states = np.empty((inputs.shape[0], model.ad.shape[0]))
    x = np.asarray(x0, dtype=float).copy()
    for k in range(inputs.shape[0]):
        states[k] = x
        x = model.ad @ x + drive[k]
    return cast(np.ndarray, states @ model.c.T + output_feedthrough(model, now, prev))


def predict_one_step(model: DiscreteModel, inputs: np.ndarray, measured: np.ndarray, x0: np.ndarray) -> np.ndarray:
    """One-step-ahead outputs: each step starts from the measured states, the rest from the model.

    Parameters
    ----------
    model : DiscreteModel
    inputs : ndarray, shape (n_samples, n_inputs)
    measured : ndarray, shape (n_samples, n_states)
        Measured state values, NaN where a state is not measured.
    x0 : ndarray, shape (n_states,)
        State at the first sample (its unmeasured part seeds the model's own).

    Returns
    -------
    ndarray, shape (n_samples, n_outputs)
        Row 0 is the output at `x0`; row k+1 is predicted from step k.
    """
    now, prev = delayed_inputs(model, inputs)
    drive = now @ model.gamma_now.T + prev @ model.gamma_prev.T
    known = np.isfinite(measured)
    states = np.empty((inputs.shape[0], model.ad.shape[0]))
    x = np.asarray(x0, dtype=float).copy()
    for k in range(inputs.shape[0]):
        states[k] = x
        start = np.where(known[k], measured[k], x)
        x = model.ad @ start + drive[k]
    return cast(np.ndarray, states @ model.c.T + output_feedthrough(model, now, prev))
