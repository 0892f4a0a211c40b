"""The delay scans' products of the delayed winds, from their products at whole-sample lags (:class:`_LagProducts`),
and the delayed winds themselves (:meth:`_DelayedWinds.stacked`) against np.interp's.

They must be the products of the winds np.interp delays (:meth:`_DelayedWinds.stacked`) at every delay a
scan reaches: between samples, on a sample, past a record's length and past the lags computed first, in
records longer than a block; records not uniformly sampled, and delays past the lags ever tabulated, take the
delayed winds themselves.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from flightlogs.record import Record
from sysid.fit.wind import _DelayedWinds, _LagProducts


def _records(lengths: tuple[int, ...], seed: int, *, jitter: float = 0.0) -> list[Record]:
    """Records of a random low-passed wind at 100 Hz, each starting elsewhere, `jitter` s on their sample times."""
    rng = np.random.default_rng(seed)
    out = []
    for k, n in enumerate(lengths):
        time_s = 12.3 * k + 0.01 * np.arange(n) + jitter * rng.uniform(-1, 1, n)
        wind = np.convolve(rng.standard_normal(n + 30), np.ones(30) / 30, mode="valid")[:n] + 3.0
        columns = {"wind_lon": wind, "wind_lat": rng.standard_normal(n)}
        units = {"wind_lon": "m/s", "wind_lat": "m/s"}
        out.append(Record(time_s=time_s, columns=columns, units=units, trim={}, source=Path("synthetic.ulg")))
    return out


def _fixed(n: int, seed: int) -> np.ndarray:
    """Columns as the scans' (zero-mean residual, a column with a mean), shape (n, 3)."""
    rng = np.random.default_rng(seed)
    fixed = rng.standard_normal((n, 3))
    fixed[:, 2] += 0.7
    return fixed


@pytest.mark.parametrize("lengths", [(250, 517, 1000), (3387,) * 4, (17_000, 300)])  # the last: past a block
def test_the_products_are_those_of_the_delayed_winds(lengths: tuple[int, ...]) -> None:
    delayed = _DelayedWinds(_records(lengths, 1), ("wind_lon", "wind_lat"))
    fixed = _fixed(sum(lengths), 2)
    products = _LagProducts(delayed, ("wind_lon", "wind_lat", "wind_lon"), fixed, longest_s=0.5)
    taus = [0.0, 0.01, 0.0137, 0.25, 0.4999, 0.5, 0.73, 1.9, 2.5]  # on and between samples, past 0.5 s, a record
    for k in range(3):
        for tau in taus:
            direct = delayed.stacked(products.signals[k], tau) @ fixed
            scale = np.linalg.norm(delayed.stacked(products.signals[k], tau)) * np.linalg.norm(fixed, axis=0)
            np.testing.assert_allclose(products(k, tau), direct, rtol=0, atol=1e-12 * scale.max())
        assert products.tables[products.signals[k]].shape[1] == 257  # 2.5 s reached: computed again, to the most
        beyond = delayed.stacked(products.signals[k], 6.0) @ fixed  # 600 lags: not tabulated
        np.testing.assert_array_equal(products(k, 6.0), beyond)


@pytest.mark.parametrize("lengths", [(250, 517, 1000), (17_000, 300)])
def test_the_delayed_winds_are_those_np_interp_delays(lengths: tuple[int, ...]) -> None:
    """Evenly sampled records are delayed by the blend of two whole lags, not np.interp's search: the same winds,
    to rounding, on and between samples, past a record's length and before its start (a negative delay)."""
    records = _records(lengths, 5)
    delayed = _DelayedWinds(records, ("wind_lon",))
    assert delayed.steps is not None
    for tau in [0.0, 0.01, 0.0137, 0.4999, 2.5, 3.0, 6.0, 200.0, -0.013]:
        shifted = [np.interp(r.time_s - tau, r.time_s, r["wind_lon"]) for r in records]
        expected = np.concatenate([x - x.mean() for x in shifted])
        np.testing.assert_allclose(delayed.stacked("wind_lon", tau), expected, rtol=0, atol=1e-12)


def test_records_not_uniformly_sampled_take_the_delayed_winds() -> None:
    records = _records((300, 400), 3, jitter=2e-9)  # uniform enough to be a record, not for whole lags
    delayed = _DelayedWinds(records, ("wind_lon",))
    fixed = _fixed(700, 4)
    products = _LagProducts(delayed, ("wind_lon",), fixed, longest_s=0.5)
    assert delayed.steps is None
    for tau in (0.0, 0.0137, 0.31):
        np.testing.assert_array_equal(products(0, tau), delayed.stacked("wind_lon", tau) @ fixed)
    assert not products.tables
