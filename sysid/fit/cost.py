"""The frequency-response cost of eq. 3.9 and its residual vector.

For each response pair l, on n_omega = 20 log-spaced points of its fit range
(the response's own frequencies nearest to them)::

    J_l = 20/n_omega * sum W_gamma [W_g (|T_hat| - |T|)^2 + W_p (<T_hat - <T)^2]

magnitudes in dB, phases in degrees, W_g = 1, W_p = 0.01745 and
W_gamma = [1.58 (1 - exp(-gamma^2))]^2 (Tischler & Remple, ch. 11). The
residual vector stacks ``sqrt(20/n_omega W_gamma W_g) dB error`` and
``sqrt(20/n_omega W_gamma W_p) phase error`` so that its sum of squares is
``J = sum_l J_l``. The model response is exact: ``C (sI - A)^-1 B + D`` times
``exp(-s tau)`` per input, evaluated directly, so an unstable bare airframe
is no obstacle. Its derivatives with respect to the parameters are analytic.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import cast

import numpy as np

from flightlogs.errors import FitError
from sysid.freqresp import FrequencyResponse
from sysid.model.assemble import Assembler, SystemMatrices

__all__ = ["CostWeights", "CostSummary", "FitPoints", "fit_points", "LogResponseCost", "ResponseModel"]

_DB = 20.0 / np.log(10.0)  # dB per neper
_DEG = 180.0 / np.pi


@dataclass(frozen=True, slots=True, kw_only=True)
class CostWeights:
    """Weights of eq. 3.9 (Tischler's standard values).

    Parameters
    ----------
    magnitude : float
        W_g, per dB^2.
    phase : float
        W_p, per deg^2 (0.01745: 1 dB weighs like 7.57 deg).
    coherence_gain : float
        The 1.58 of W_gamma = [1.58 (1 - exp(-gamma^2))]^2.
    n_points : int
        n_omega, frequency points per response.
    """

    magnitude: float = 1.0
    phase: float = 0.01745
    coherence_gain: float = 1.58
    n_points: int = 20

    def __post_init__(self) -> None:
        if self.n_points < 2:
            raise ValueError(f"n_points={self.n_points} must be at least 2")
        if self.magnitude < 0 or self.phase < 0 or self.magnitude + self.phase == 0:
            raise ValueError(f"weights magnitude={self.magnitude}, phase={self.phase} must be >= 0, not both 0")


@dataclass(frozen=True, slots=True, kw_only=True)
class CostSummary:
    """Cost of a fit: J_ave and the cost of each response pair.

    Parameters
    ----------
    average : float
        J_ave, the mean of the per-pair costs (guideline: <= 100 good, <= 150 acceptable).
    responses : Mapping[str, float]
        J_l by pair name (``q/delta_lon``); guideline <= 200 each.
    """

    average: float
    responses: Mapping[str, float] = field(default_factory=lambda: MappingProxyType({}))

    def __post_init__(self) -> None:
        object.__setattr__(self, "responses", MappingProxyType({str(k): float(v) for k, v in self.responses.items()}))

    @property
    def total(self) -> float:
        """J, the sum over pairs."""
        return float(sum(self.responses.values()))


@dataclass(frozen=True, slots=True, kw_only=True)
class FitPoints:
    """The measured responses sampled at the cost's frequency points, stacked.

    Parameters
    ----------
    pairs : tuple of str
        Pair name of each response (``output/input``), unique.
    inputs : tuple of str
        Input signal of each response.
    outputs : tuple of str
        Output signal of each response.
    omega : ndarray, shape (n_points_total,)
        Frequencies, rad/s.
    response : ndarray of int, shape (n_points_total,)
        Index of the response each point belongs to.
    log_measured : ndarray of complex, shape (n_points_total,)
        ``ln|T| + i angle(T)`` of the measured response (angle unwrapped, rad).
    weight : ndarray, shape (n_points_total,)
        ``20/n_omega W_gamma``.
    """

    pairs: tuple[str, ...]
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    omega: np.ndarray
    response: np.ndarray
    log_measured: np.ndarray
    weight: np.ndarray

    def __post_init__(self) -> None:
        n = np.shape(self.omega)
        for name in ("response", "log_measured", "weight"):
            if np.shape(getattr(self, name)) != n:
                raise ValueError(f"{name} has shape {np.shape(getattr(self, name))}, expected {n} like omega")
        if not len(self.pairs) == len(self.inputs) == len(self.outputs):
            raise ValueError("pairs, inputs and outputs must have one entry per response")


def fit_points(responses: Sequence[FrequencyResponse], *, weights: CostWeights = CostWeights()) -> FitPoints:
    """Pick each gated response's n_omega points, log-spaced over its fit range.

    The points are the response's own frequencies nearest to n_omega
    log-spaced targets (repeats removed), so that nothing is interpolated:
    near a lightly damped zero the magnitude and phase change too fast
    between grid points for interpolation to be trusted.

    Parameters
    ----------
    responses : sequence of FrequencyResponse
        Gated responses (``fit_range`` set).
    weights : CostWeights, optional
        Weights and the number of points.

    Returns
    -------
    FitPoints
        With weight ``20/n W_gamma``, n the number of distinct points (at
        most n_omega).

    Raises
    ------
    FitError
        If a response has no fit range or no frequency inside it.
    """
    if not responses:
        raise FitError("no frequency response to fit")
    pairs: list[str] = []
    omega, index, log_meas, weight = [], [], [], []
    for k, fr in enumerate(responses):
        if fr.fit_range is None:
            raise FitError(f"response {fr.pair} has no fit range: gate the responses before fitting")
        lo, hi = fr.fit_range
        inside = np.flatnonzero((fr.omega >= lo * (1 - 1e-9)) & (fr.omega <= hi * (1 + 1e-9)))
        if inside.size == 0:
            raise FitError(f"response {fr.pair}: no frequency inside its fit range {fr.fit_range}")
        targets = np.log(np.geomspace(max(lo, fr.omega[inside[0]]), min(hi, fr.omega[inside[-1]]), weights.n_points))
        nearest = np.abs(np.log(fr.omega[inside])[None, :] - targets[:, None]).argmin(axis=1)
        chosen = inside[np.unique(nearest)]
        phase = np.unwrap(np.angle(fr.response))[chosen]
        w_gamma = (weights.coherence_gain * (1.0 - np.exp(-np.clip(fr.coherence[chosen], 0.0, 1.0)))) ** 2
        omega.append(fr.omega[chosen])
        index.append(np.full(chosen.size, k))
        log_meas.append(np.log(np.maximum(np.abs(fr.response[chosen]), 1e-300)) + 1j * phase)
        weight.append(20.0 / chosen.size * w_gamma)
        name = fr.pair
        pairs.append(name if name not in pairs else f"{name}#{pairs.count(name) + 1}")
    return FitPoints(
        pairs=tuple(pairs),
        inputs=tuple(fr.input for fr in responses),
        outputs=tuple(fr.output for fr in responses),
        omega=np.concatenate(omega),
        response=np.concatenate(index),
        log_measured=np.concatenate(log_meas),
        weight=np.concatenate(weight),
    )


def _times_real(left: np.ndarray, right: np.ndarray) -> np.ndarray:
    """``left @ right`` for complex `left` and real `right` without converting `right` to complex."""
    return cast(np.ndarray, (left.real @ right) + 1j * (left.imag @ right))


class LogResponseCost:
    """Eq. 3.9 on a set of fit points for any model that gives ``ln T`` and its derivatives.

    Subclasses provide :meth:`log_response`; the weighted residuals (dB and
    deg), their Jacobian and the cost follow from it here, the same for a
    state-space structure (:class:`ResponseModel`) and a transfer function
    (:mod:`sysid.fit.transfer`).

    Parameters
    ----------
    points : FitPoints
        The measured data.
    weights : CostWeights, optional
        The weights W_g, W_p.
    """

    def __init__(self, points: FitPoints, *, weights: CostWeights = CostWeights()) -> None:
        self.points, self.weights = points, weights
        root = np.sqrt(points.weight)
        self._scale = np.concatenate([root * np.sqrt(weights.magnitude) * _DB, root * np.sqrt(weights.phase) * _DEG])

    def log_response(
        self, theta: np.ndarray, *, with_derivatives: bool = False
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """``ln T`` of the model at each point, and optionally ``d ln T / d theta`` (see subclasses).

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.
        with_derivatives : bool, optional
            Also return the derivatives, shape (n_points_total, n_free).
        """
        raise NotImplementedError

    def residuals(self, theta: np.ndarray) -> np.ndarray:
        """Weighted residual vector; its sum of squares is J.

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.

        Returns
        -------
        ndarray, shape (2 n_points_total,)
            Magnitude residuals (dB, weighted) then phase residuals (deg, weighted).
        """
        log_t, _ = self.log_response(theta)
        return self._residuals(log_t)

    def jacobian(self, theta: np.ndarray) -> np.ndarray:
        """Jacobian of :meth:`residuals`, shape (2 n_points_total, n_free).

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.
        """
        if np.size(theta) == 0:  # structure reduction has removed every parameter
            return np.zeros((2 * self.points.omega.size, 0))
        _, d_log_t = self.log_response(theta, with_derivatives=True)
        assert d_log_t is not None
        jac = np.concatenate([d_log_t.real, d_log_t.imag]) * self._scale[:, None]
        return np.where(np.isfinite(jac), jac, 0.0)

    def _residuals(self, log_t: np.ndarray) -> np.ndarray:
        error = log_t - self.points.log_measured
        phase = np.angle(np.exp(1j * error.imag))  # wrapped to (-pi, pi]
        r = np.concatenate([error.real, phase]) * self._scale
        return np.where(np.isfinite(r), r, 1e3)

    def cost(self, theta: np.ndarray) -> CostSummary:
        """J_ave and the cost of each pair at `theta`.

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.
        """
        r = self.residuals(theta)
        n = self.points.omega.size
        per_point = r[:n] ** 2 + r[n:] ** 2
        per_pair = np.bincount(self.points.response, weights=per_point, minlength=len(self.points.pairs))
        return CostSummary(average=float(per_pair.mean()), responses=dict(zip(self.points.pairs, per_pair.tolist())))


class ResponseModel(LogResponseCost):
    """Residuals of eq. 3.9 and their Jacobian for a structure on a set of fit points.

    Parameters
    ----------
    assembler : Assembler
        Builds the matrices from the free parameters.
    points : FitPoints
        The measured data.
    weights : CostWeights, optional
        The weights W_g, W_p.

    Raises
    ------
    FitError
        If a response's input or output is not in the model.
    """

    def __init__(self, assembler: Assembler, points: FitPoints, *, weights: CostWeights = CostWeights()) -> None:
        super().__init__(points, weights=weights)
        self.assembler = assembler
        outputs = assembler.structure.outputs
        signals = [c.signal for c in assembler.channels]
        for pair, i, o in zip(points.pairs, points.inputs, points.outputs):
            if o not in outputs or i not in signals:
                raise FitError(
                    f"response {pair}: the model {assembler.structure.name} has no "
                    + (f"output {o}" if o not in outputs else f"input {i}")
                )
        self._row = np.array([outputs.index(points.outputs[r]) for r in points.response])
        self._select = np.array(
            [[float(signals[c] == points.inputs[r]) for c in range(len(signals))] for r in points.response]
        )
        self._s = 1j * points.omega

    def log_response(
        self, theta: np.ndarray, *, with_derivatives: bool = False
    ) -> tuple[np.ndarray, np.ndarray | None]:
        """``ln T`` of the model at each point, and optionally ``d ln T / d theta``.

        Parameters
        ----------
        theta : ndarray, shape (n_free,)
            Free-parameter values.
        with_derivatives : bool, optional
            Also return the derivatives, shape (n_points_total, n_free).

        Returns
        -------
        log_t : ndarray of complex, shape (n_points_total,)
        d_log_t : ndarray of complex, shape (n_points_total, n_free), or None
        """
        m = self.assembler.matrices(theta)
        n = m.a.shape[0]
        shifted = self._s[:, None, None] * np.eye(n) - m.a
        c_rows = m.c[self._row]
        try:
            x = np.linalg.solve(shifted, np.broadcast_to(m.b, (self._s.size, *m.b.shape)))
            z = np.linalg.solve(np.swapaxes(shifted, 1, 2), c_rows[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            bad = np.full(self._s.size, np.nan + 0j)
            return bad, (np.full((self._s.size, theta.size), np.nan + 0j) if with_derivatives else None)
        g = np.einsum("pn,pnc->pc", c_rows, x) + m.d[self._row]
        delay = self._select * np.exp(-self._s[:, None] * m.delays[None, :])
        t = np.sum(g * delay, axis=1)
        with np.errstate(divide="ignore", invalid="ignore"):
            log_t = np.log(t)
        if not with_derivatives:
            return log_t, None
        return log_t, self._derivatives(theta, m, x, z, g, delay, t)

    def _derivatives(
        self,
        theta: np.ndarray,
        m: SystemMatrices,
        x: np.ndarray,
        z: np.ndarray,
        g: np.ndarray,
        delay: np.ndarray,
        t: np.ndarray,
    ) -> np.ndarray:
        dm = self.assembler.derivatives(theta, m)
        n_p, n, n_c = theta.size, m.a.shape[0], m.b.shape[1]
        z_da = _times_real(z, np.moveaxis(dm.a, 0, 1).reshape(n, n_p * n)).reshape(-1, n_p, n)  # z^T dA_k
        dg = (z_da + np.moveaxis(dm.c[:, self._row, :], 0, 1)) @ x  # (z^T dA_k + dC_k) x
        dg += _times_real(z, np.moveaxis(dm.b, 0, 1).reshape(n, n_p * n_c)).reshape(-1, n_p, n_c)
        dg += np.moveaxis(dm.d[:, self._row, :], 0, 1)
        dg -= self._s[:, None, None] * dm.delays[None, :, :] * g[:, None, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            return cast(np.ndarray, (dg @ delay[:, :, None])[:, :, 0] / t[:, None])
