"""A fitted model in the simulation's place: each real flight as the model would have flown it.

``sysid discrepancy model.json REAL`` compares REAL with a model from ``sysid fit -o`` rather than
with a simulated log. The model is evaluated along each real flight by equation error: the states
the log measures (``u v w p q r phi theta``) and the mixer inputs, delayed as the model delays them,
give the angular accelerations (the rows ``A x + B u(t - tau)`` of ``p q r``, smoothed as the logged
ones are: :func:`~sysid.discrepancy.series.smoothed_as_derivative`) and the specific forces
(``C x + D u(t - tau)`` of ``ax ay az``); the states no log measures (the actuators' lag) are the
model's own, simulated from the inputs one step at a time, from rest. The logged inputs are
samples of a signal that moves between them, so they are read between samples by linear
interpolation (a held sample would add half a sample of delay: 10 ms at 50 Hz). The model is linear about
the trim it was fitted at (its inputs, states and specific forces, as in the model file): a real
flight trimmed elsewhere (a heavier vehicle, an offset centre of gravity) departs from it. Where
the model has no trim of a signal, the flight's median stands in.

To that the noise REAL leaves is added: the residual of the best linear model of REAL itself
(:func:`~sysid.discrepancy.baseline.fit_baseline`), moved by half of each piece in time so that it
follows no regime of the flight. The result is a simulated flight: the search then runs as on a
log, its noise floor and null scores those of noise of REAL's size.

A corrected simulation (:class:`~.corrected.CorrectedModel`, the search's own model of SIM with what it
found) takes the same place: :func:`corrected_outputs` evaluates it along a flight, :func:`corrected_flight`
adds REAL's noise, and :func:`simulated_flight` flies whichever a model file held.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

import numpy as np

from flightlogs.errors import ModelError
from sysid.discrepancy.baseline import fit_baseline
from sysid.discrepancy.catalogue import FlightContext, term_of
from sysid.discrepancy.corrected import UNEXPLAINED, CorrectedModel, ModelTerm
from sysid.discrepancy.generic import generic_library
from sysid.discrepancy.series import OUTPUTS, FlightSeries, smoothed_as_derivative, smoothed_specific_forces
from sysid.model.discrete import discretize, predict_one_step
from sysid.model.statespace import DelayedStateSpace

__all__ = [
    "corrected_flight",
    "corrected_outputs",
    "model_flight",
    "model_outputs",
    "simulated_flight",
    "with_real_noise",
]

_RATES = {"p_dot": "p", "q_dot": "q", "r_dot": "r"}  # an angular acceleration is its rate's row of A x + B u
_FORCES = ("ax", "ay", "az")


def model_outputs(model: DelayedStateSpace, flight: FlightSeries, *, source: str = "model") -> dict[str, np.ndarray]:
    """The six outputs the model gives along `flight`, perturbations from its trim, each shape (n,).

    Parameters
    ----------
    model : DelayedStateSpace
        The model (states, inputs and outputs by canonical name; ``ax ay az`` among the outputs).
    flight : FlightSeries
        A flight that logs every input of the model.
    source : str, optional
        The model's name, for messages.

    Returns
    -------
    dict of str to ndarray
        ``ax ay az`` (m/s²) and ``p_dot q_dot r_dot`` (rad/s²), each shape (n,), perturbations from the
        model's trim.

    Raises
    ------
    ModelError
        If the model lacks a rate or specific force, or has an input the flight did not log.
    """
    lacking = [s for s in _RATES.values() if s not in model.states] + [o for o in _FORCES if o not in model.outputs]
    if lacking:
        raise ModelError(
            f"{source}: no {', '.join(lacking)} in the model (an unidentified axis?); "
            "the discrepancy search compares all three rates and specific forces"
        )
    unlogged = [i for i in model.inputs if i not in flight]
    if unlogged:
        raise ModelError(f"{source}: input {', '.join(unlogged)} is not logged by {flight.name}")
    a, b, c, d = (np.asarray(m, dtype=float) for m in (model.a, model.b, model.c, model.d))
    rows = np.vstack(
        [a[[model.states.index(s) for s in _RATES.values()]], c[[model.outputs.index(o) for o in _FORCES]]]
    )
    through = np.vstack(
        [b[[model.states.index(s) for s in _RATES.values()]], d[[model.outputs.index(o) for o in _FORCES]]]
    )
    n_x = len(model.states)
    own = DelayedStateSpace(  # the states themselves as outputs; the delays are applied to the inputs here
        a=a,
        b=b,
        c=np.eye(n_x),
        d=np.zeros((n_x, len(model.inputs))),
        states=model.states,
        inputs=model.inputs,
        outputs=model.states,
        input_delays_s=np.zeros(len(model.inputs)),
    )
    step_s = 1.0 / flight.rate_hz
    discrete = discretize(own, step_s)
    inputs = _about_trim(flight, model.inputs, model.trim)
    measured = _about_trim(flight, model.states, model.trim)
    delays = np.asarray(model.input_delays_s, dtype=float)
    out = np.empty((flight.n, rows.shape[0]))
    for piece in flight.pieces():
        t, x = flight.time_s[piece], measured[piece]
        delayed = _shifted(t, inputs[piece], delays)  # u(t_k - tau)
        midway = _shifted(t, inputs[piece], delays - step_s / 2.0)  # across each step: its middle, not its start
        states = predict_one_step(discrete, midway, x, _at_rest(a, b, x[0], delayed[0]))
        out[piece] = np.where(np.isfinite(x), x, states) @ rows.T + delayed @ through.T
    named = {o: out[:, k] for k, o in enumerate((*_RATES, *_FORCES))}
    return named | {o: smoothed_as_derivative(flight, named[o]) for o in _RATES}


def model_flight(model: DelayedStateSpace, flight: FlightSeries, *, source: str = "model") -> FlightSeries:
    """`flight` with its six outputs the model's, plus noise of REAL's size: a simulated flight.

    Parameters
    ----------
    model : DelayedStateSpace
        The model (see :func:`model_outputs`).
    flight : FlightSeries
        A real flight.
    source : str, optional
        The model's name, for messages and the flight's name.

    Returns
    -------
    FlightSeries
        The same samples and signals; ``ax ay az p_dot q_dot r_dot`` replaced.

    Raises
    ------
    ModelError
        As :func:`model_outputs`.
    """
    outputs = model_outputs(model, flight, source=source)
    # an angular acceleration's trim is 0
    levels = {o: (_trim(flight, o, model.trim) if o in _FORCES else 0.0) + outputs[o] for o in OUTPUTS}
    return with_real_noise(flight, levels, name=f"{source} on {flight.name}")


def with_real_noise(flight: FlightSeries, outputs: Mapping[str, np.ndarray], *, name: str) -> FlightSeries:
    """`flight` with its six outputs a model's plus the noise the flight itself leaves: a simulated flight.

    The noise is the residual of the best linear model of the flight itself
    (:func:`~sysid.discrepancy.baseline.fit_baseline`), moved by half of each piece in time so that it
    follows no regime of the flight.

    Parameters
    ----------
    flight : FlightSeries
        A real flight.
    outputs : Mapping[str, ndarray]
        ``ax ay az`` (m/s²) and ``p_dot q_dot r_dot`` (rad/s²) as the model gives them, shape (n,) each.
    name : str
        The simulated flight's name.

    Returns
    -------
    FlightSeries
        The same samples and signals; the six outputs replaced.
    """
    own = fit_baseline(flight).predict(flight)  # the best linear model of REAL: its residual is REAL's noise
    outputs = smoothed_specific_forces(flight, outputs)  # as REAL's own derivative smooths them, if it does
    signals = dict(flight.signals)
    for o in OUTPUTS:
        noise = flight[o] - own[o]
        for piece in flight.pieces():
            noise[piece] = np.roll(noise[piece], piece.size // 2)
        signals[o] = np.asarray(outputs[o]) + noise
    return replace(flight, name=name, signals=signals)


def corrected_outputs(model: CorrectedModel, flight: FlightSeries) -> dict[str, np.ndarray]:
    """The six outputs the corrected simulation gives along `flight`, shape (n,) each.

    Parameters
    ----------
    model : CorrectedModel
        The corrected simulation.
    flight : FlightSeries
        A flight logging every signal the terms read (the wind, for a wind term).

    Returns
    -------
    dict of str to ndarray
        ``ax ay az`` (m/s²) and ``p_dot q_dot r_dot`` (rad/s²).

    Raises
    ------
    ModelError
        If the flight lacks a signal a term reads.
    """
    if missing := [s for s in model.baseline.signals if s not in flight]:
        raise ModelError(f"{flight.name}: the corrected simulation reads {missing[0]}, which this flight does not log")
    base = model.baseline.predict(flight)
    trim = model.thrust_trim * base["az"]  # -trim × thrust, the thrust being -az
    additions = {o: np.zeros(flight.n) for o in OUTPUTS}
    additions["az"] = trim
    library: dict[str, np.ndarray] | None = None
    for term in model.terms:
        context = FlightContext(series=flight, baseline=model.baseline, thrust=-(base["az"] + trim))
        try:
            if term.effect == UNEXPLAINED:
                if library is None:  # the search's library: built once, on the model before any term
                    first = FlightContext(series=flight, baseline=model.baseline, thrust=-(base["az"] + trim))
                    library = {r.key: r.values for r in generic_library(first)}
                columns = {o: _centred(library, keys, term) for o, keys in term.regressors.items()}
            else:
                candidate = term_of(term.effect).make(context)
                if candidate is None:  # a wind term without the wind, a ground effect without the height
                    raise KeyError(f"what its {term.effect} term needs")
                built = candidate.build(term.value)
                if candidate.kind == "transform":
                    base = dict(built)
                    continue
                columns = dict(built)
        except KeyError as err:
            raise ModelError(
                f"{flight.name}: the corrected simulation's {term.effect} term reads {err.args[0]}, "
                "which this flight does not log"
            ) from None
        for o, coefficients in term.coefficients.items():
            if columns[o].shape[1] != coefficients.size:
                raise ModelError(
                    f"{flight.name}: the corrected simulation's {term.effect} term has {coefficients.size} "
                    f"coefficients on {o}, its regressors {columns[o].shape[1]}"
                )
            additions[o] = additions[o] + columns[o] @ coefficients
    return {o: base[o] + additions[o] for o in OUTPUTS}


def corrected_flight(model: CorrectedModel, flight: FlightSeries, *, source: str = "corrected") -> FlightSeries:
    """`flight` with its six outputs the corrected simulation's, plus the noise the flight leaves.

    Parameters
    ----------
    model : CorrectedModel
        The corrected simulation.
    flight : FlightSeries
        A real flight.
    source : str, optional
        The model's name, for the flight's name.

    Returns
    -------
    FlightSeries
        A simulated flight (:func:`~sysid.discrepancy.fitted_model.with_real_noise`).
    """
    return with_real_noise(flight, corrected_outputs(model, flight), name=f"{source} on {flight.name}")


def _centred(library: Mapping[str, np.ndarray], keys: tuple[str, ...], term: ModelTerm) -> np.ndarray:
    """The named library columns, each less its mean, shape (n, len(keys))."""
    missing = [k for k in keys if k not in library]
    if missing:
        raise KeyError(f"the regressor {missing[0]}")
    return np.column_stack([library[k] - library[k].mean() for k in keys])


def simulated_flight(
    model: DelayedStateSpace | CorrectedModel, flight: FlightSeries, *, source: str = "model"
) -> FlightSeries:
    """`flight` as a model file's model would have flown it, with the noise the flight leaves: a simulated flight.

    Parameters
    ----------
    model : DelayedStateSpace or CorrectedModel
        From ``sysid fit -o`` or ``sysid discrepancy --model-out``.
    flight : FlightSeries
        A real flight.
    source : str, optional
        The model's name, for messages and the flight's name.

    Raises
    ------
    ModelError
        If the flight lacks what the model reads.
    """
    if isinstance(model, CorrectedModel):
        return corrected_flight(model, flight, source=source)
    return model_flight(model, flight, source=source)


def _shifted(t: np.ndarray, columns: np.ndarray, delays_s: np.ndarray) -> np.ndarray:
    """Column j at ``t - delays_s[j]``, linear between samples, the end values held beyond; shape of `columns`."""
    return np.column_stack([np.interp(t - d, t, c) for c, d in zip(columns.T, delays_s)])


def _at_rest(a: np.ndarray, b: np.ndarray, measured: np.ndarray, inputs: np.ndarray) -> np.ndarray:
    """The state at the first sample: the measured part as measured, the rest at rest with it and the inputs."""
    x: np.ndarray = np.nan_to_num(measured)
    free = ~np.isfinite(measured)
    if np.any(free):  # A_ff x_f + A_fm x_m + B_f u = 0
        rest = a[np.ix_(free, ~free)] @ x[~free] + b[free] @ inputs
        x[free] = np.linalg.lstsq(a[np.ix_(free, free)], -rest, rcond=None)[0]
    return x


def _about_trim(flight: FlightSeries, names: tuple[str, ...], trim: Mapping[str, float]) -> np.ndarray:
    """Columns of `names` less the model's trim (the flight's median where it has none), shape (n, len(names)).

    NaN where the flight has no such signal.
    """
    columns = [flight[s] - _trim(flight, s, trim) if s in flight else np.full(flight.n, np.nan) for s in names]
    return np.column_stack(columns)


def _trim(flight: FlightSeries, name: str, trim: Mapping[str, float]) -> float:
    value = trim.get(name)
    return float(np.median(flight[name])) if value is None or not np.isfinite(value) else float(value)
