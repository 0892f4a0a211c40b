"""The fitted ground-effect model as a JSON file, and the summary the CLI prints.

A controller study (``sysid mrac compare --ground-effect FILE``) reads the
file back with :func:`read_ground_effect_model` and calls ``ratio(Z/R)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from flightlogs.errors import ModelError
from sysid._json import read_json_object, write_json
from sysid._json import value_text as _show
from sysid.groundeffect.models import PARAMETER_NAMES, GroundEffectFit, evaluate_model

__all__ = [
    "FittedGroundEffect",
    "fit_summary",
    "write_ground_effect_model",
    "read_ground_effect_model",
    "MODEL_FILE_FORMAT",
]

#: Value of the file's ``format`` key.
MODEL_FILE_FORMAT = "flight-sysid ground-effect model"
_VERSION = 1


@dataclass(frozen=True, slots=True, kw_only=True)
class FittedGroundEffect:
    """A ground-effect law with fitted values: F/F0 as a function of Z/R.

    Parameters
    ----------
    model : str
        Family (``"cheeseman_bennett"``, ``"corrected"``, ``"exponential"``, ``"piecewise_linear"``).
    param_names : tuple of str
        Parameter names, as ``PARAMETER_NAMES[model]``.
    values : ndarray, shape (n_params,)
        Parameter values.
    rotor_radius_m : float
        Propeller radius R of the vehicle fitted, m.
    min_height_ratio : float
        Lowest Z/R of the data; lower Z/R is clamped to it (no extrapolation
        toward the ground, where eq. 2.2 diverges).
    source : str
        Data the model was fitted to.
    """

    model: str
    param_names: tuple[str, ...]
    values: np.ndarray
    rotor_radius_m: float
    min_height_ratio: float = 0.0
    source: str = ""

    def __post_init__(self) -> None:
        if self.model not in PARAMETER_NAMES:
            raise ModelError(f"unknown ground-effect model {self.model!r}; choose from {tuple(PARAMETER_NAMES)}")
        if tuple(self.param_names) != PARAMETER_NAMES[self.model]:
            raise ModelError(f"{self.model} takes parameters {PARAMETER_NAMES[self.model]}, got {self.param_names}")
        values = np.asarray(self.values, dtype=np.float64)
        if values.shape != (len(self.param_names),) or not np.all(np.isfinite(values)):
            raise ModelError(
                f"{self.model}: parameter values {values.tolist()} must be {len(self.param_names)} finite numbers"
            )
        if not (self.rotor_radius_m > 0 and self.min_height_ratio >= 0):
            raise ModelError(f"rotor_radius_m={self.rotor_radius_m} must be > 0 and min_height_ratio >= 0")
        object.__setattr__(self, "param_names", tuple(self.param_names))
        object.__setattr__(self, "values", values)

    @property
    def params(self) -> dict[str, float]:
        """Parameter name to value."""
        return {n: float(v) for n, v in zip(self.param_names, self.values)}

    def ratio(self, height_ratio: np.ndarray) -> np.ndarray:
        """F/F0 at `height_ratio` (Z/R), clamped from below at `min_height_ratio`.

        Parameters
        ----------
        height_ratio : ndarray, any shape
            Z/R.

        Returns
        -------
        ndarray
            F/F0, same shape.
        """
        x = np.maximum(np.asarray(height_ratio, dtype=np.float64), self.min_height_ratio)
        return evaluate_model(self.model, self.values, x)

    @classmethod
    def from_fit(cls, fit: GroundEffectFit) -> FittedGroundEffect:
        """The chosen model of a fit.

        Parameters
        ----------
        fit : GroundEffectFit
            The fit.

        Returns
        -------
        FittedGroundEffect
        """
        best = fit.model(fit.best)
        return cls(
            model=best.name,
            param_names=best.param_names,
            values=best.values,
            rotor_radius_m=fit.data.rotor_radius_m,
            min_height_ratio=float(fit.data.height_ratio.min()),
            source=fit.data.source,
        )


def fit_summary(fit: GroundEffectFit) -> dict[str, Any]:
    """A JSON-ready summary of a fit: ``best``, ``models.NAME.params|ci|rmse|r2|...``, the data.

    Parameters
    ----------
    fit : GroundEffectFit
        The fit.

    Returns
    -------
    dict
        Plain numbers, strings, lists and dicts (NaN stays NaN; the CLI writes null).
    """
    data = fit.data
    models = {}
    for m in fit.models:
        models[m.name] = {
            "params": m.params,
            "stderr": {n: float(v) for n, v in zip(m.param_names, m.stderr)},
            "ci": m.intervals,
            "n_free": m.n_free,
            "rmse": m.rmse,
            "r2": m.r2,
            "aicc": m.aicc,
            "bic": m.bic,
            "delta": fit.delta(m.name),
            "notes": list(m.notes),
        }
    summary: dict[str, Any] = {
        "best": fit.best,
        "criterion": fit.criterion,
        "confidence": fit.confidence,
        "models": models,
        "source": data.source,
        "f0_source": data.f0_source,
        "f0_n": data.f0_n,
        "rotor_radius_m": data.rotor_radius_m,
        "n_points": data.n_points,
        "height_ratio": data.height_ratio.tolist(),
        "thrust_ratio": data.thrust_ratio.tolist(),
    }
    if data.steps is not None:
        summary["steps"] = [
            {
                "start_s": s.start_s,
                "end_s": s.end_s,
                "steady_start_s": s.steady_start_s,
                "height_m": s.height_m,
                "height_ratio": s.height_m / data.rotor_radius_m,
                "climb_rate_m_s": s.climb_rate_m_s,
                "f0_n": s.f0_n,
                "thrust_ratio": s.thrust_ratio,
            }
            for s in data.steps.steps
        ]
        summary["dropped_steps"] = list(data.steps.dropped)
    return summary


def write_ground_effect_model(fit: GroundEffectFit, path: str | Path) -> Path:
    """Write the chosen model (and the full fit summary) as JSON, atomically.

    Parameters
    ----------
    fit : GroundEffectFit
        The fit.
    path : str or Path
        Destination; its folder must exist.

    Returns
    -------
    Path
        The path written.
    """
    chosen = FittedGroundEffect.from_fit(fit)
    document = {
        "format": MODEL_FILE_FORMAT,
        "version": _VERSION,
        "model": chosen.model,
        "params": chosen.params,
        "rotor_radius_m": chosen.rotor_radius_m,
        "min_height_ratio": chosen.min_height_ratio,
        "source": chosen.source,
        "fit": fit_summary(fit),  # NaN written null
    }
    return write_json(path, document)


def read_ground_effect_model(path: str | Path) -> FittedGroundEffect:
    """Read a model written by :func:`write_ground_effect_model`.

    Parameters
    ----------
    path : str or Path
        The JSON file.

    Returns
    -------
    FittedGroundEffect
        Has ``ratio(height_ratio)``.

    Raises
    ------
    ModelError
        If the file is not such a model, or its model or values are invalid.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from sysid.groundeffect import ThrustRatioData, fit_ground_effect
    >>> x = np.linspace(1.2, 9.0, 20)
    >>> data = ThrustRatioData(height_ratio=x, thrust_ratio=evaluate_model("corrected", [3.0], x), rotor_radius_m=0.0225)
    >>> fit = fit_ground_effect(data)
    >>> target = write_ground_effect_model(fit, pathlib.Path(tempfile.mkdtemp()) / "ge.json")
    >>> model = read_ground_effect_model(target)
    >>> model.model, round(float(model.ratio(np.array(2.0))), 4)
    ('corrected', 1.0492)
    """
    path = Path(path)
    document = read_json_object(path, ModelError, "ground-effect model")
    if document.get("format") != MODEL_FILE_FORMAT:
        raise ModelError(f'{path}: not a ground-effect model (no "format": {MODEL_FILE_FORMAT!r})')
    if document.get("version") != _VERSION:
        raise ModelError(f"{path}: ground-effect model version {document.get('version')!r}; this tool reads {_VERSION}")
    model = document.get("model")
    if not isinstance(model, str):
        raise ModelError(f'{path}: no ground-effect model named ("model" is {_show(model)})')
    if model not in PARAMETER_NAMES:
        raise ModelError(f"{path}: unknown ground-effect model {model!r}; choose from {', '.join(PARAMETER_NAMES)}")
    params = document.get("params")
    if not isinstance(params, dict):
        raise ModelError(f'{path}: the {model} model has no parameters ("params" is {_show(params)})')
    values = [
        _number(
            path,
            params,
            name,
            f"the {model} model needs parameter {name}",
            label=f"parameter {name} of the {model} model",
        )
        for name in PARAMETER_NAMES[model]
    ]
    extra = sorted(set(params) - set(PARAMETER_NAMES[model]))
    if extra:
        raise ModelError(
            f"{path}: {', '.join(extra)} is not a parameter of the {model} model "
            f"(it takes {', '.join(PARAMETER_NAMES[model]) or 'none'})"
        )
    radius = _number(path, document, "rotor_radius_m", "the rotor radius (rotor_radius_m) is missing")
    lowest = _number(path, document, "min_height_ratio", "", default=0.0)
    try:
        return FittedGroundEffect(
            model=model,
            param_names=PARAMETER_NAMES[model],
            values=np.array(values),
            rotor_radius_m=radius,
            min_height_ratio=lowest,
            source=str(document.get("source", "")),
        )
    except ModelError as err:
        raise ModelError(f"{path}: {err}") from None


def _number(
    path: Path, table: dict[str, Any], key: str, missing: str, *, default: float | None = None, label: str = ""
) -> float:
    """A finite number from a JSON object, or a ModelError naming the file and the key."""
    if key not in table and default is not None:
        return default
    if key not in table:
        raise ModelError(f"{path}: {missing}")
    value = table[key]
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ModelError(f"{path}: {label or key} is {_show(value)}, not a finite number")
    return float(value)
