"""The joint solution of the speed derivatives and the G_w gains by instrumental variables (:class:`_Joint`).

Its inner products are taken with the delayed winds alone (the fast path of
the delay scan): they must give what the explicit regressors give, and the
estimator must not shrink a coefficient whose regressor is measured with
noise, where least squares does by var(noise) / (var(signal) + var(noise)).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from sysid.fit.wind import _Joint, _projected


def _smooth(rng: np.random.Generator, n: int, width: int) -> np.ndarray:
    """Unit-variance noise low-passed by a moving average of `width` samples, shape (n,)."""
    out = np.convolve(rng.standard_normal(n + width), np.ones(width) / width, mode="valid")[:n]
    return out / out.std()


def _problem(seed: int) -> tuple[_Joint, np.ndarray, dict[str, np.ndarray]]:
    """Two outputs, two wind channels, two gains, one speed regressor read with noise, y built from the truth."""
    rng = np.random.default_rng(seed)
    n = 40_000
    wind = np.column_stack([_smooth(rng, n, 40), _smooth(rng, n, 25)])
    lagged = np.column_stack([np.roll(wind[:, 0], k) for k in (0, 50, 100, 150)])
    speed_true = 0.6 * np.roll(wind[:, 0], 100) + 0.3 * _smooth(rng, n, 60)  # answers the gusts, and more
    speed_read = speed_true + 0.35 * rng.standard_normal(n)  # the velocity estimate's error
    e = np.array(
        [[[1.0, 0.0], [0.0, 0.0]], [[0.0, 0.0], [0.0, 1.0]]]
    )  # gain 0: wind 0 on output 0; gain 1: wind 1 on 1
    d0 = np.array([[0.0, 0.2], [0.1, 0.0]])  # parts of the wind rows that do not scale with a gain
    truth = {"speed": -0.5, "gains": np.array([-0.36, 1.3])}
    residual = np.column_stack(
        [
            truth["speed"] * speed_true + truth["gains"][0] * wind[:, 0] + d0[0] @ wind.T,
            truth["gains"][1] * wind[:, 1] + d0[1] @ wind.T,
        ]
    )
    residual += 0.05 * rng.standard_normal(residual.shape)
    speeds = [np.column_stack([speed_read, np.zeros(n)])]
    instruments = [_projected(s, lagged) for s in speeds]
    normal = SimpleNamespace(e=e, d0=d0, residual=residual)
    data = SimpleNamespace(scale=np.array([1.0, 0.5]))
    return _Joint(normal, data, speeds, instruments), wind, truth  # type: ignore[arg-type]


def test_the_fast_inner_products_give_the_explicit_solution_and_cost() -> None:
    joint, wind, _ = _problem(1)
    cost, solution = joint.solve(wind)
    after, design = joint.explicit(wind, solution)
    assert abs(cost - np.sum(after**2)) <= 1e-9 * np.sum(after**2), (cost, np.sum(after**2))
    e, scale = joint.normal.e, joint.scale
    gains = [((wind @ e[g].T) * scale).ravel() for g in range(2)]
    regressors = np.column_stack([(joint.speeds[0] * scale).ravel(), *gains])
    instruments = np.column_stack([(joint.instruments[0] * scale).ravel(), *gains])
    target = ((joint.residual - wind @ joint.normal.d0.T) * scale).ravel()
    explicit = np.linalg.solve(instruments.T @ regressors, instruments.T @ target)
    np.testing.assert_allclose(solution, explicit, rtol=1e-9)
    # the design's information is that of the IV estimate: X^T Z (Z^T Z)^-1 Z^T X
    information = regressors.T @ instruments @ np.linalg.solve(instruments.T @ instruments, instruments.T @ regressors)
    np.testing.assert_allclose(design.T @ design, information, rtol=1e-8, atol=1e-10 * np.abs(information).max())


def test_a_speed_read_with_noise_is_not_shrunk() -> None:
    """Least squares shrinks the speed term by about var(noise) / var(read) (0.35^2 / 0.57 = 21 %); IV does not."""
    for seed in (2, 3, 4):
        joint, wind, truth = _problem(seed)
        _, solution = joint.solve(wind)
        plain = _Joint(joint.normal, SimpleNamespace(scale=joint.scale), joint.speeds, joint.speeds)  # type: ignore[arg-type]
        _, least_squares = plain.solve(wind)
        assert abs(solution[0] / truth["speed"] - 1) <= 0.05, solution
        assert least_squares[0] / truth["speed"] - 1 <= -0.15, least_squares
        np.testing.assert_allclose(solution[1:], truth["gains"], rtol=0.05)
