"""The matching pursuit of the model of the unknown (``sysid.discrepancy._omp``) against scikit-learn's.

Reference values are cross-implementation: ``sklearn.linear_model.orthogonal_mp_gram(gram, xy,
n_nonzero_coefs=k, return_path=True)``, of which the port is a translation making the same BLAS and LAPACK calls
in the same order. Paths are compared to rounding (``atol`` 1e-12 of the path's largest coefficient; they agree
bitwise today), their length exactly, and a shorter path must be where scikit-learn warns that the pursuit "ended
prematurely". Cases: random well-conditioned designs (centred and scaled as the search's, and raw), a near
duplicate that stops the pursuit on its Cholesky pivot, exact linear dependence, a target fitted before the last
step, a column chosen twice, no correlation at all, the arguments both refuse, and every call the search makes on
a simulated flight (with the whole fit compared with scikit-learn in the port's place).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping

import numpy as np
import pytest
from sklearn.linear_model import orthogonal_mp_gram

import sysid.discrepancy.generic as generic
from sysid.discrepancy._omp import omp_gram_path
from sysid.discrepancy.baseline import fit_baseline
from sysid.discrepancy.catalogue import FlightContext
from sysid.discrepancy.series import OUTPUTS

from builders import synthetic_series

PREMATURE = "ended prematurely due to linear dependence"


def _sklearn(gram: np.ndarray, xy: np.ndarray, k: int) -> tuple[np.ndarray, bool]:
    """scikit-learn's path, shape (n_features, n_steps), and whether it warned that the pursuit ended early."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuntimeWarning)
        path = orthogonal_mp_gram(gram, xy, n_nonzero_coefs=k, return_path=True)
    premature = any(PREMATURE in str(w.message) for w in caught)
    return np.reshape(path, (gram.shape[0], -1)), premature


def _assert_as_sklearn(gram: np.ndarray, xy: np.ndarray, k: int) -> np.ndarray:
    """The port's path, checked against scikit-learn's: same length, same support, equal to rounding."""
    ours = omp_gram_path(gram, xy, n_nonzero_coefs=k)
    reference, premature = _sklearn(gram, xy, k)
    assert ours.shape == reference.shape
    assert (ours.shape[1] < k) == premature
    np.testing.assert_array_equal(ours != 0, reference != 0)
    np.testing.assert_allclose(ours, reference, rtol=0, atol=1e-12 * np.abs(reference).max(initial=0.0))
    return ours


def _standardised(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Gram matrix and covariance of columns centred and scaled to unit variance, as the search forms them."""
    x = (x - x.mean(axis=0)) / x.std(axis=0)
    return x.T @ x, x.T @ (y - y.mean())


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize(("n_features", "k"), [(5, 1), (5, 5), (12, 4), (30, 4), (30, 30)])
@pytest.mark.parametrize("standardised", [True, False])
def test_well_conditioned_designs_give_sklearns_path(seed: int, n_features: int, k: int, standardised: bool) -> None:
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(400, n_features)) @ (np.eye(n_features) + 0.3 * rng.normal(size=(n_features, n_features)))
    x += rng.normal(size=n_features)  # columns off zero: centring matters
    y = x[:, :3] @ rng.normal(size=3) + rng.normal(size=400)
    gram, xy = _standardised(x, y) if standardised else (x.T @ x, x.T @ y)
    path = _assert_as_sklearn(gram, xy, k)
    assert path.shape == (n_features, k)
    assert [np.count_nonzero(path[:, j]) for j in range(k)] == list(range(1, k + 1))


def test_a_near_duplicate_stops_the_path_on_its_cholesky_pivot() -> None:
    """x1 = x0 + 1e-9 z, y ∝ z: x1 is chosen, then x0 (correlation about 1) whose pivot 1 - 1/(1 + 1e-18) ≤ eps."""
    q, _ = np.linalg.qr(np.random.default_rng(1).normal(size=(200, 6)))
    x = np.column_stack([q[:, :5], q[:, 0] + 1e-9 * q[:, 5]])
    path = _assert_as_sklearn(x.T @ x, x.T @ (q[:, 5] * 1e9 + 0.3 * q[:, 2]), 4)
    assert path.shape[1] == 1 and np.flatnonzero(path[:, 0]).tolist() == [5]


@pytest.mark.parametrize(("below_one", "n_steps"), [(2.0**-53, 1), (2.0**-52, 2)])
def test_the_path_ends_where_the_cholesky_pivot_is_at_most_eps(below_one: float, n_steps: int) -> None:
    """Two unit columns of correlation c = 1 - 2⁻⁵³ (pivot 1 - c² = eps: the end) or 1 - 2⁻⁵² (2 eps: one more step)."""
    c = 1.0 - below_one
    path = _assert_as_sklearn(np.array([[1.0, c], [c, 1.0]]), np.array([1.0, 0.5]), 2)
    assert path.shape[1] == n_steps


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("offset", [1e-9, 1e-6, 1e-3])
def test_nearly_collinear_columns_give_sklearns_path(seed: int, offset: float) -> None:
    """A column 1e-9 .. 1e-3 (standard deviations) from another: ends early at 1e-9, refits ill-conditioned above."""
    rng = np.random.default_rng(seed)
    x = rng.normal(size=(300, 8))
    x[:, 7] = x[:, 2] + offset * rng.normal(size=300)
    path = _assert_as_sklearn(*_standardised(x, x @ rng.normal(size=8) + rng.normal(size=300)), 8)
    assert path.shape[1] == (7 if offset == 1e-9 else 8)


def test_exactly_dependent_columns_end_the_path_at_their_rank() -> None:
    """Six columns of rank four (a duplicate and a difference): no more than four steps."""
    rng = np.random.default_rng(2)
    z = rng.normal(size=(200, 4))
    x = np.column_stack([z, z[:, 0], z[:, 1] - 2.0 * z[:, 2]])
    path = _assert_as_sklearn(x.T @ x, x.T @ rng.normal(size=200), 6)
    assert path.shape[1] == 4


def test_a_target_in_the_span_of_two_columns_ends_the_path_after_two_steps() -> None:
    rng = np.random.default_rng(1)
    x = rng.normal(size=(200, 6))
    path = _assert_as_sklearn(x.T @ x, x.T @ (x[:, 1] - 2.0 * x[:, 4]), 4)
    assert path.shape[1] == 2
    np.testing.assert_allclose(path[:, 1], [0.0, 1.0, 0.0, 0.0, -2.0, 0.0], atol=1e-12)


@pytest.mark.parametrize(("correlation", "n_steps"), [(1.4e-8, 1), (1.5e-8, 2)])
def test_the_path_ends_where_the_next_correlation_squared_is_below_eps(correlation: float, n_steps: int) -> None:
    """Orthonormal columns: the second's correlation 1.4e-8 (square 1.96e-16 < eps, the end) or 1.5e-8 (2.25e-16)."""
    assert _assert_as_sklearn(np.eye(2), np.array([1.0, correlation]), 2).shape[1] == n_steps


def test_a_column_chosen_twice_ends_the_path() -> None:
    """Two columns fitted at scale 1e12 (rounding left on them), the others exactly uncorrelated: one of the two
    is chosen again."""
    gram = np.eye(5)
    gram[:2, :2] = [[2.0, 0.3], [0.3, 1.0]]
    xy = np.array([0.7e12, -1.3e12, 0.0, 0.0, 0.0])
    assert _assert_as_sklearn(gram, xy, 4).shape == (5, 2)


def test_no_correlation_gives_an_empty_path() -> None:
    assert _assert_as_sklearn(np.eye(3), np.zeros(3), 2).shape == (3, 0)


def test_the_inputs_are_left_as_they_were() -> None:
    rng = np.random.default_rng(3)
    x = rng.normal(size=(50, 6))
    gram, xy = x.T @ x, x.T @ rng.normal(size=50)
    kept = gram.copy(), xy.copy()
    omp_gram_path(gram, xy, n_nonzero_coefs=4)
    np.testing.assert_array_equal(gram, kept[0])
    np.testing.assert_array_equal(xy, kept[1])


@pytest.mark.parametrize("k", [0, 4])
def test_more_coefficients_than_columns_or_none_are_refused_as_by_sklearn(k: int) -> None:
    gram, xy = np.eye(3), np.ones(3)
    with pytest.raises(ValueError, match="n_nonzero_coefs"):
        omp_gram_path(gram, xy, n_nonzero_coefs=k)
    with pytest.raises(ValueError):
        orthogonal_mp_gram(gram, xy, n_nonzero_coefs=k, return_path=True)


@pytest.mark.parametrize(
    ("gram", "xy"),
    [(np.ones((2, 3)), np.ones(2)), (np.eye(3), np.ones(2)), (np.diag([1.0, np.nan, 1.0]), np.ones(3))],
    ids=["not square", "xy of another length", "not finite"],
)
def test_malformed_arguments_are_refused(gram: np.ndarray, xy: np.ndarray) -> None:
    with pytest.raises(ValueError):
        omp_gram_path(gram, xy, n_nonzero_coefs=1)


@pytest.fixture(scope="module", name="context")
def context_fixture() -> FlightContext:
    flight = synthetic_series(n=4000, seed=4)
    baseline = fit_baseline(flight)
    return FlightContext(series=flight, baseline=baseline, thrust=-baseline.predict(flight)["az"])


def _residuals(context: FlightContext) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray], dict[str, float]]:
    """A residual on each output (a speed's moment, a drag, a command's cross-coupling, noise), the current zero."""
    s, n = context.series, context.series.n
    rng = np.random.default_rng(9)
    part = context.command_parts["delta_lat"]["p_dot"]
    extra = {"q_dot": 0.2 * s["u"], "ax": -0.3 * s["u"] * np.abs(s["u"]), "p_dot": 0.15 * (part - part.mean())}
    y = {o: extra.get(o, np.zeros(n)) + rng.normal(0.0, 0.05, n) for o in OUTPUTS}
    return y, {o: np.zeros(n) for o in OUTPUTS}, {o: 0.05**2 for o in OUTPUTS}


def test_every_pursuit_of_the_search_gives_sklearns_path(
    context: FlightContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The Gram matrices and covariances ``fit_generic`` forms on held-out blocks and on all samples."""
    calls: list[tuple[np.ndarray, np.ndarray, int]] = []

    def recorded(gram: np.ndarray, xy: np.ndarray, *, n_nonzero_coefs: int) -> np.ndarray:
        calls.append((gram.copy(), xy.copy(), n_nonzero_coefs))
        return omp_gram_path(gram, xy, n_nonzero_coefs=n_nonzero_coefs)

    monkeypatch.setattr(generic, "omp_gram_path", recorded)
    generic.fit_generic(context, *_residuals(context))
    assert len(calls) > len(OUTPUTS) and {c[0].shape[0] for c in calls} == {len(generic.generic_library(context))}
    for gram, xy, k in calls:
        _assert_as_sklearn(gram, xy, k)


def test_the_model_of_the_unknown_is_the_same_with_sklearn(
    context: FlightContext, monkeypatch: pytest.MonkeyPatch
) -> None:
    y, current, scale = _residuals(context)
    ours = generic.fit_generic(context, y, current, scale)
    monkeypatch.setattr(
        generic, "omp_gram_path", lambda gram, xy, *, n_nonzero_coefs: _sklearn(gram, xy, n_nonzero_coefs)[0]
    )
    theirs = generic.fit_generic(context, y, current, scale)
    assert {o: [r.key for r in rs] for o, rs in ours.chosen.items()} == {
        o: [r.key for r in rs] for o, rs in theirs.chosen.items()
    }
    assert set(ours.chosen) >= {"q_dot", "ax", "p_dot"}
    assert ours.score == theirs.score and ours.output_scores == theirs.output_scores
    _assert_same_arrays(ours.predicted, theirs.predicted)


def _assert_same_arrays(ours: Mapping[str, np.ndarray], theirs: Mapping[str, np.ndarray]) -> None:
    assert ours.keys() == theirs.keys()
    for key in ours:
        np.testing.assert_allclose(ours[key], theirs[key], rtol=0, atol=1e-12 * np.abs(theirs[key]).max())
