"""Ground-effect families by name, their parameters, and the results of fitting them.

See :mod:`sysid.groundeffect.fitting` for how they are fitted and chosen.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Literal

import numpy as np

from sysid.groundeffect import formulas
from sysid.groundeffect.records import ThrustRatioData

__all__ = [
    "ModelName",
    "MODEL_NAMES",
    "PARAMETER_NAMES",
    "Criterion",
    "ModelFit",
    "GroundEffectFit",
    "evaluate_model",
]

ModelName = Literal["cheeseman_bennett", "corrected", "exponential", "piecewise_linear"]
MODEL_NAMES: tuple[ModelName, ...] = ("cheeseman_bennett", "corrected", "exponential", "piecewise_linear")
#: Reported parameters of each family, in order (the piecewise intercept is derived).
PARAMETER_NAMES: dict[str, tuple[str, ...]] = {
    "cheeseman_bennett": (),
    "corrected": ("rho",),
    "exponential": ("a", "b"),
    "piecewise_linear": ("slope", "intercept", "breakpoint"),
}
Criterion = Literal["aicc", "bic"]
#: The formula of each family, called as ``law(height_ratio, *values)``.
_LAWS: dict[str, Callable[..., np.ndarray]] = {
    "cheeseman_bennett": formulas.cheeseman_bennett,
    "corrected": formulas.corrected,
    "exponential": formulas.exponential,
    "piecewise_linear": formulas.piecewise_linear,
}


def evaluate_model(name: str, values: Sequence[float] | np.ndarray, height_ratio: np.ndarray) -> np.ndarray:
    """F/F0 of a family at given parameter values.

    Parameters
    ----------
    name : {"cheeseman_bennett", "corrected", "exponential", "piecewise_linear"}
        The family.
    values : sequence of float, shape (n_params,)
        Parameters in the order of ``PARAMETER_NAMES[name]``.
    height_ratio : ndarray, any shape
        Z/R.

    Returns
    -------
    ndarray
        F/F0, same shape as `height_ratio`.

    Examples
    --------
    >>> float(evaluate_model("piecewise_linear", [-0.0373, 1.1651, 4.42], np.array(3.0)))
    1.0532
    """
    p = [float(v) for v in values]
    if name not in PARAMETER_NAMES:
        raise ValueError(f"unknown ground-effect model {name!r}; choose from {MODEL_NAMES}")
    if len(p) != len(PARAMETER_NAMES[name]):
        raise ValueError(f"{name} takes {len(PARAMETER_NAMES[name])} parameters {PARAMETER_NAMES[name]}, got {len(p)}")
    return _LAWS[name](np.asarray(height_ratio, dtype=np.float64), *p)


@dataclass(frozen=True, slots=True, kw_only=True)
class ModelFit:
    """One family fitted to F/F0 against Z/R.

    Parameters
    ----------
    name : str
        Family name.
    param_names : tuple of str
        Names of `values`, as ``PARAMETER_NAMES[name]``.
    values : ndarray, shape (n_params,)
        Estimates.
    stderr : ndarray, shape (n_params,)
        Standard errors (inf when not identifiable).
    ci_low, ci_high : ndarray, shape (n_params,)
        Confidence interval at the fit's level.
    n_free : int
        Free parameters p (the piecewise intercept is not free).
    residuals : ndarray, shape (n_points,)
        Data minus model.
    rss : float
        Residual sum of squares.
    rmse : float
        sqrt(RSS / (n - p)).
    r2 : float
        1 - RSS / TSS (negative when worse than the mean).
    aicc, bic : float
        n ln(RSS/n) + 2k + 2k(k+1)/(n-k-1), and n ln(RSS/n) + k ln n, with k = p + 1.
    notes : tuple of str
        Caveats (parameter at a bound, singular covariance).
    """

    name: str
    param_names: tuple[str, ...]
    values: np.ndarray
    stderr: np.ndarray
    ci_low: np.ndarray
    ci_high: np.ndarray
    n_free: int
    residuals: np.ndarray
    rss: float
    rmse: float
    r2: float
    aicc: float
    bic: float
    notes: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        shape = (len(self.param_names),)
        for field_name in ("values", "stderr", "ci_low", "ci_high"):
            array = np.asarray(getattr(self, field_name), dtype=np.float64)
            if array.shape != shape:
                raise ValueError(f"{self.name}: {field_name} has shape {array.shape}, expected {shape}")
            object.__setattr__(self, field_name, array)
        object.__setattr__(self, "residuals", np.asarray(self.residuals, dtype=np.float64))

    @property
    def params(self) -> dict[str, float]:
        """Parameter name to estimate."""
        return {n: float(v) for n, v in zip(self.param_names, self.values)}

    @property
    def intervals(self) -> dict[str, list[float]]:
        """Parameter name to its confidence interval ``[low, high]``, in the parameter's unit."""
        return {n: [float(lo), float(hi)] for n, lo, hi in zip(self.param_names, self.ci_low, self.ci_high)}

    def ratio(self, height_ratio: np.ndarray) -> np.ndarray:
        """F/F0 of this fit at `height_ratio`.

        Parameters
        ----------
        height_ratio : ndarray, any shape
            Z/R.

        Returns
        -------
        ndarray
            F/F0, same shape.
        """
        return evaluate_model(self.name, self.values, height_ratio)

    def criterion(self, which: Criterion) -> float:
        """The value of an information criterion.

        Parameters
        ----------
        which : {"aicc", "bic"}
            Criterion.

        Returns
        -------
        float
        """
        return self.aicc if which == "aicc" else self.bic


@dataclass(frozen=True, slots=True, kw_only=True)
class GroundEffectFit:
    """Every family fitted to one data set, and the one chosen.

    Parameters
    ----------
    data : ThrustRatioData
        The points fitted.
    models : tuple of ModelFit
        One per family, in the order fitted.
    best : str
        Name of the family with the lowest criterion.
    criterion : {"aicc", "bic"}
        Criterion used.
    confidence : float
        Level of the confidence intervals.
    """

    data: ThrustRatioData
    models: tuple[ModelFit, ...]
    best: str
    criterion: Criterion = "aicc"
    confidence: float = 0.95

    def __post_init__(self) -> None:
        object.__setattr__(self, "models", tuple(self.models))
        if self.best not in [m.name for m in self.models]:
            raise ValueError(f"best={self.best!r} is not among the fitted models")

    def model(self, name: str) -> ModelFit:
        """The fit of one family.

        Parameters
        ----------
        name : str
            Family name.

        Returns
        -------
        ModelFit
        """
        for fit in self.models:
            if fit.name == name:
                return fit
        raise KeyError(f"{name!r} was not fitted; fitted: {[m.name for m in self.models]}")

    def ratio(self, height_ratio: np.ndarray) -> np.ndarray:
        """F/F0 of the chosen model at `height_ratio`, Z/R clamped to the smallest fitted.

        Parameters
        ----------
        height_ratio : ndarray, any shape
            Z/R.

        Returns
        -------
        ndarray
            F/F0, same shape.
        """
        x = np.maximum(np.asarray(height_ratio, dtype=np.float64), float(self.data.height_ratio.min()))
        return self.model(self.best).ratio(x)

    def delta(self, name: str) -> float:
        """Criterion of a family minus the lowest (0 for the chosen one).

        Parameters
        ----------
        name : str
            Family name.

        Returns
        -------
        float
        """
        lowest = min(m.criterion(self.criterion) for m in self.models)
        return self.model(name).criterion(self.criterion) - lowest
