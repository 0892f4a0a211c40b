"""Recover the injected excitation from closed-loop mixer inputs.

In closed loop the mixer input is the excitation plus the controller's
feedback, ``delta = e + c``, and a fast rate loop cancels most of a
mixer-level doublet within a fraction of a second, so its shape is lost in
``delta``. Near hover the feedback is close to linear in the measured states
of the same axis (rate, attitude, velocity), ``c ≈ K x + c0``. Fitting K by
least squares where no excitation runs and subtracting ``K x`` leaves ``e``,
whose doublets, 3211s and sweeps have their true shape again.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

__all__ = ["FEEDBACK_STATES", "estimate_excitation"]

#: States each axis's controller feeds back (FRD/NED canonical names).
FEEDBACK_STATES: Mapping[str, tuple[str, ...]] = {
    "lat": ("p", "phi", "ve"),
    "lon": ("q", "theta", "vn"),
    "yaw": ("r", "psi"),
    "thr": ("vd", "height_agl"),
}
_MIN_FIT_SAMPLES = 200


def estimate_excitation(
    inputs: Mapping[str, np.ndarray],
    states: Mapping[str, np.ndarray],
    quiet: np.ndarray,
) -> dict[str, np.ndarray]:
    """Mixer inputs with the linear state feedback removed.

    Parameters
    ----------
    inputs : Mapping[str, ndarray], each shape (n_samples,)
        Mixer input by axis (``"lat"``, ``"lon"``, ``"yaw"``, ``"thr"``).
    states : Mapping[str, ndarray], each shape (n_samples,)
        Canonical signals on the same time base (see :data:`FEEDBACK_STATES`).
    quiet : ndarray of bool, shape (n_samples,)
        Samples with no excitation, where the feedback law is fitted.

    Returns
    -------
    dict of ndarray
        For each axis, the input minus its fitted feedback; the input itself
        (NaN as 0) when the axis's states are not all logged or too few quiet
        samples remain.

    Examples
    --------
    A doublet hidden by a feedback that cancels it is recovered exactly.

    >>> rng = np.random.default_rng(0)
    >>> q = rng.normal(size=2000)
    >>> e = np.zeros(2000); e[1000:1100], e[1100:1200] = 1.0, -1.0
    >>> states = {"q": q, "theta": np.cumsum(q) * 0.01, "vn": np.zeros(2000)}
    >>> quiet = np.ones(2000, dtype=bool); quiet[990:1210] = False
    >>> out = estimate_excitation({"lon": e - 2.0 * q}, states, quiet)["lon"]
    >>> bool(np.allclose(out, e, atol=1e-9))
    True
    """
    estimated = {}
    for axis, values in inputs.items():
        u = np.asarray(values, dtype=np.float64)
        names = FEEDBACK_STATES.get(axis, ())
        if not names or not all(name in states for name in names):
            estimated[axis] = np.nan_to_num(u)
            continue
        regressors = np.column_stack([states[name] for name in names] + [np.ones(u.size)])
        usable = quiet & np.isfinite(u) & np.all(np.isfinite(regressors), axis=1)
        if usable.sum() < _MIN_FIT_SAMPLES:
            estimated[axis] = np.nan_to_num(u)
            continue
        gains, *_ = np.linalg.lstsq(regressors[usable], u[usable], rcond=None)
        estimated[axis] = np.nan_to_num(u - regressors @ gains)
    return estimated
