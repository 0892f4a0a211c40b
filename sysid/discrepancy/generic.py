"""A model of the unknown: a sparse combination of physically meaningful regressors, chosen on held-out blocks.

When the residual the catalogue leaves stays above the noise floor, the search fits this generic model
before it gives any catalogue name, and after the last one: a catalogue term is named only when it
explains about as much as this model does; what no term explains is reported as ``unexplained``, in
the words of the regressors chosen ("az residual ∝ thrust × climb rate").

The library (pysindy's polynomial-and-custom library, with names and units): the body velocities and
rates, the attitude, the climb rate, the specific thrust ``T`` and its products with each velocity and
rate, the squares and signed squares of the velocities, the products of the rates, and each axis'
command as the simulation's model makes it a moment or thrust (:meth:`BaselineModel.command_part`: a
roll command's moment may act on pitch). Each output's regressors are chosen by orthogonal matching
pursuit (scikit-learn's ``orthogonal_mp_gram``, ported in :mod:`sysid.discrepancy._omp`: forward
selection with least-squares refits, on the columns centred and scaled to unit variance), at most
:data:`MAX_REGRESSORS`; how many is chosen per output on held-out time blocks (:func:`~sysid.discrepancy.selection.folds`), and the held-out prediction of each block comes from the regressors and
coefficients chosen without it (each fold's Gram matrix is summed once; a training set's is the total less its own).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from sysid.discrepancy._omp import omp_gram_path
from sysid.discrepancy.catalogue import Candidate, Coefficient, FlightContext, Term
from sysid.discrepancy.catalogue._air import climb_rate
from sysid.discrepancy.catalogue._term import pm
from sysid.discrepancy.result import Finding
from sysid.discrepancy.selection import folds
from sysid.discrepancy.series import OUTPUTS

__all__ = ["MAX_REGRESSORS", "GenericFit", "Regressor", "fit_generic", "generic_library", "generic_term"]

#: Most regressors the model of the unknown keeps per output.
MAX_REGRESSORS = 4
_MIN_OUTPUT_GAIN = 0.02  # an output whose held-out residual the model cuts by less is left out of it
_COMMAND_OUTPUTS = {"delta_lat": "p_dot", "delta_lon": "q_dot", "delta_yaw": "r_dot", "delta_thr": "az"}
_COMMAND_WORDS = {"delta_lat": "roll", "delta_lon": "pitch", "delta_yaw": "yaw", "delta_thr": "thrust"}
_OUTPUT_UNITS = {"ax": "m/s²", "ay": "m/s²", "az": "m/s²", "p_dot": "rad/s²", "q_dot": "rad/s²", "r_dot": "rad/s²"}


@dataclass(frozen=True, slots=True, kw_only=True)
class Regressor:
    """One column of the library.

    Parameters
    ----------
    key : str
        Short name (``T*w``).
    words : str
        What it is, for a person (``thrust × climb rate``).
    unit : str
        Its unit (``m²/s³``).
    values : ndarray, shape (n,)
        Its samples.
    """

    key: str
    words: str
    unit: str
    values: np.ndarray


@dataclass(frozen=True, slots=True, kw_only=True)
class GenericFit:
    """The model of the unknown fitted on a residual.

    Parameters
    ----------
    chosen : Mapping[str, tuple of Regressor]
        Per output it acts on, the regressors kept (fitted on all samples).
    score : float
        Held-out share of the noise-weighted residual of all outputs it removes (0-1, can be negative).
    output_scores : Mapping[str, float]
        The same per output.
    predicted : Mapping[str, ndarray]
        Each output's held-out prediction with the model (current prediction plus the model), shape (n,).
    """

    chosen: Mapping[str, tuple[Regressor, ...]]
    score: float
    output_scores: Mapping[str, float]
    predicted: Mapping[str, np.ndarray]

    @property
    def outputs(self) -> tuple[str, ...]:
        """The outputs it acts on."""
        return tuple(self.chosen)

    def candidate(self, outputs: tuple[str, ...] = ()) -> Candidate:
        """A linear candidate of the kept regressors (to fit on all samples with uncertainties).

        Parameters
        ----------
        outputs : tuple of str, optional
            Outputs it is located on besides those it models (a residual no regressor explains).
        """
        # centred: a constant is a sensor's bias, left to the residual (see fit_generic)
        regressors = {o: np.column_stack([r.values - r.values.mean() for r in rs]) for o, rs in self.chosen.items()}
        keys = tuple(f"{o}:{r.key}" for o, rs in self.chosen.items() for r in rs)
        return Candidate(
            effect="unexplained",
            outputs=tuple(dict.fromkeys(self.outputs + outputs)),
            kind="linear",
            grid=(float("nan"),),
            grid_parameter="",
            build=lambda _value: regressors,
            coefficients=keys,
            regime=None,
        )


def generic_library(context: FlightContext) -> list[Regressor]:
    """The candidate regressors of a flight, each shape (n,).

    Parameters
    ----------
    context : FlightContext
        The flight, the simulation's model and its specific thrust.
    """
    s, thrust = context.series, context.thrust
    out: list[Regressor] = []

    def add(key: str, words: str, unit: str, values: np.ndarray) -> None:
        if np.all(np.isfinite(values)) and np.std(values) > 0:
            out.append(Regressor(key=key, words=words, unit=unit, values=np.asarray(values, dtype=float)))

    speeds = {k: s[k] for k in ("u", "v", "w") if k in s}
    rates = {k: s[k] for k in ("p", "q", "r")}
    climb = climb_rate(s)
    for k, x in speeds.items():
        add(k, f"{k} (body speed)", "m/s", x)
        add(f"T*{k}", f"thrust × {k}", "m²/s³", thrust * x)
        add(f"{k}|{k}|", f"{k} × |{k}|", "m²/s²", x * np.abs(x))
    for k, x in rates.items():
        add(k, f"{k} (body rate)", "rad/s", x)
        add(f"T*{k}", f"thrust × {k}", "m rad/s³", thrust * x)
    for a, b in (("p", "q"), ("q", "r"), ("p", "r")):
        add(f"{a}*{b}", f"{a} × {b}", "rad²/s²", rates[a] * rates[b])
    if "u" in speeds and "v" in speeds:
        add("u*v", "u × v", "m²/s²", speeds["u"] * speeds["v"])
    for k in ("phi", "theta"):
        if k in s:
            add(k, {"phi": "roll angle", "theta": "pitch angle"}[k], "rad", s[k])
    if climb is not None:
        add("climb", "climb rate", "m/s", climb)
        add("T*climb", "thrust × climb rate", "m²/s³", thrust * climb)
    add("T", "thrust", "m/s²", thrust)
    for command, own in _COMMAND_OUTPUTS.items():
        part = context.command_parts[command][own]
        add(f"P_{command}", f"the {_COMMAND_WORDS[command]} command's {own}", _OUTPUT_UNITS[own], part - part.mean())
    return out


def fit_generic(
    context: FlightContext,
    y: Mapping[str, np.ndarray],
    current: Mapping[str, np.ndarray],
    scale: Mapping[str, float],
    *,
    outputs: tuple[str, ...] = OUTPUTS,
    library: list[Regressor] | None = None,
) -> GenericFit:
    """The sparse model of the residual ``y - current`` of each of `outputs`, judged on held-out blocks.

    Parameters
    ----------
    context : FlightContext
        The flight (the library's source).
    y, current : Mapping[str, ndarray]
        Each output as flown and as currently predicted, shape (n,).
    scale : Mapping[str, float]
        Each output's noise-floor variance.
    outputs : tuple of str, optional
        The outputs to model.
    library : list of Regressor, optional
        The regressors (default :func:`generic_library`).

    Returns
    -------
    GenericFit
    """
    columns = library if library is not None else generic_library(context)
    theta = np.column_stack([c.values for c in columns])
    parts = folds(theta.shape[0])
    sums = _BlockSums.of(theta, parts)
    predicted = {o: np.array(current[o], dtype=float) for o in current}
    chosen: dict[str, tuple[Regressor, ...]] = {}
    output_scores: dict[str, float] = {}
    for o in outputs:
        residual = np.asarray(y[o] - current[o], dtype=float)
        held = sums.held_out(theta, residual, parts)  # (MAX_REGRESSORS + 1, n): 0 .. MAX_REGRESSORS regressors
        errors = [float(np.sum((residual - h) ** 2)) for h in held]
        best = int(np.argmin(errors))
        # a constant is a sensor's bias, a nuisance: the model is what the regressors add to it, judged on the residual
        contribution = held[best] - held[0]
        before = float(np.sum(residual**2))
        gain = 1.0 - float(np.sum((residual - contribution) ** 2)) / before if before > 0 else 0.0
        if best == 0 or gain < _MIN_OUTPUT_GAIN:
            continue
        chosen[o] = tuple(columns[k] for k in sums.support(theta, residual, best))
        output_scores[o] = round(gain, 4)
        predicted[o] = current[o] + contribution
    total_before = sum(float(np.sum((y[o] - current[o]) ** 2)) / scale[o] for o in outputs)
    total_after = sum(float(np.sum((y[o] - predicted[o]) ** 2)) / scale[o] for o in outputs)
    score = 1.0 - total_after / total_before if total_before > 0 else 0.0
    return GenericFit(chosen=chosen, score=float(score), output_scores=output_scores, predicted=predicted)


@dataclass(frozen=True, slots=True)
class _BlockSums:
    """Each time block's sums of the library (count, column sums, Gram matrix): a fold's are the total less its own."""

    count: np.ndarray  # (n_blocks,)
    column: np.ndarray  # (n_blocks, m)
    gram: np.ndarray  # (n_blocks, m, m)

    @classmethod
    def of(cls, theta: np.ndarray, folds: list[np.ndarray]) -> _BlockSums:
        return cls(
            count=np.array([f.size for f in folds], dtype=float),
            column=np.stack([theta[f].sum(axis=0) for f in folds]),
            gram=np.stack([theta[f].T @ theta[f] for f in folds]),
        )

    def _path(self, keep: np.ndarray, xy: np.ndarray, y_sum: float) -> tuple[list[np.ndarray], np.ndarray, float]:
        """Orthogonal matching pursuit on the blocks `keep`: supports and coefficients of 1.. regressors."""
        n = float(self.count[keep].sum())
        mean = self.column[keep].sum(axis=0) / n
        centred = self.gram[keep].sum(axis=0) - n * np.outer(mean, mean)
        spread = np.sqrt(np.maximum(np.diag(centred), 1e-300))
        gram = centred / np.outer(spread, spread)
        covariance = (xy - mean * y_sum) / spread
        path = omp_gram_path(gram, covariance, n_nonzero_coefs=MAX_REGRESSORS)  # shorter where it ends early
        coefficients = [path[:, k] / spread for k in range(path.shape[1])]
        return coefficients, mean, y_sum / n

    def held_out(self, theta: np.ndarray, residual: np.ndarray, folds: list[np.ndarray]) -> np.ndarray:
        """Each block's prediction of `residual` from the others', with 0 .. MAX_REGRESSORS regressors, (k, n)."""
        out = np.zeros((MAX_REGRESSORS + 1, residual.size))
        xy = np.stack([theta[f].T @ residual[f] for f in folds])
        y_sums = np.array([residual[f].sum() for f in folds])
        for b, test in enumerate(folds):
            keep = np.arange(len(folds)) != b
            coefficients, mean, level = self._path(keep, xy[keep].sum(axis=0), float(y_sums[keep].sum()))
            out[:, test] = level
            centred = theta[test] - mean
            for k, c in enumerate(coefficients[:MAX_REGRESSORS]):
                out[k + 1, test] += centred @ c
            for k in range(len(coefficients) + 1, MAX_REGRESSORS + 1):  # the path ended early: no more to add
                out[k, test] = out[len(coefficients), test]
        return out

    def support(self, theta: np.ndarray, residual: np.ndarray, size: int) -> np.ndarray:
        """The `size` regressors the pursuit picks on all samples."""
        every = np.ones(self.count.size, dtype=bool)
        coefficients, _, _ = self._path(every, theta.T @ residual, float(residual.sum()))
        return np.flatnonzero(coefficients[min(size, len(coefficients)) - 1])


def generic_term(fit: GenericFit, outputs: tuple[str, ...] = ()) -> Term:
    """The catalogue-like entry of a fitted model of the unknown: its coefficients' names and units, its sentence.

    Parameters
    ----------
    fit : GenericFit
        The model.
    outputs : tuple of str, optional
        Outputs it is located on besides those it models.
    """
    coefficients = tuple(
        Coefficient(key=f"{o}:{r.key}", name=f"{o} per {r.words}", unit=_per(_OUTPUT_UNITS[o], r.unit))
        for o, rs in fit.chosen.items()
        for r in rs
    )

    def what(finding: Finding) -> str:
        if not finding.parameters:
            return (
                f"Something the catalogue does not hold acts on the real vehicle's {', '.join(finding.outputs)}, "
                "and no sparse model of the flight's own states and inputs explains it either: dynamics of their "
                "own (a load swinging under the vehicle, a flexible structure, a sensor's) are likely"
            )
        parts = [
            f"{p.name.replace(' per ', ' residual ∝ ', 1)}: {pm(p.value, p.uncertainty)} {p.unit}"
            for p in finding.parameters
        ]
        return (
            "Something the catalogue does not hold acts on the real vehicle ("
            + "; ".join(parts)
            + "): none of its terms explains this residual as well as this sparse model of the flight's own states "
            "and inputs does"
        )

    return Term(
        effect="unexplained",
        summary="a residual no catalogue term explains, modelled by a sparse combination of the flight's states and inputs",
        outputs=tuple(dict.fromkeys(fit.outputs + outputs)),
        regime=None,
        make=lambda _context: fit.candidate(outputs),
        what=what,
        coefficients=coefficients,
    )


def _per(numerator: str, denominator: str) -> str:
    """The unit of a coefficient: output unit over regressor unit (``1`` when they are the same)."""
    return "1" if numerator == denominator else f"({numerator})/({denominator})"
