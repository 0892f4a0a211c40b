"""Ground effect (eqs. 2.1-2.5), Dryden turbulence, frozen-field advection, sensors."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal as sps

from simulator.world.environment import (
    Anemometer,
    Environment,
    GroundEffect,
    SensorNoise,
    ground_effect_function,
    thrust_ratio,
)
from simulator.world.wind_field import BatchWindField, Dryden, Gust, Wind, dryden_psd, realize_field


@pytest.mark.parametrize(
    ("model", "height_ratio", "expected"),
    [
        ("none", 1.5, 1.0),
        ("cheeseman_bennett", 1.0, 1 / (1 - (1 / 4) ** 2)),  # eq. 2.1
        ("cheeseman_bennett", 2.0, 1 / (1 - (1 / 8) ** 2)),
        ("fitted_2rotor", 2.0, 1 / (1 - 3.315 * (1 / 8) ** 2)),  # eq. 2.4: about 5 % at Z/R = 2
        ("fitted_4rotor", 3.0, -0.0373 * 3 + 1.1651),  # eq. 2.5
        ("fitted_4rotor", 4.5, 1.0),
        ("exponential", 2.0, 0.2744 * np.exp(-2 / 1.633) + 1),  # eq. 2.3
    ],
)
def test_ground_effect_ratio_against_the_formulas(model: str, height_ratio: float, expected: float) -> None:
    assert float(thrust_ratio(np.array(height_ratio), model)) == pytest.approx(expected, rel=1e-12)


def test_corrected_model_uses_rho_and_clamps_low_heights() -> None:
    x = np.array([0.2, 1.0, 3.0])
    ratio = GroundEffect(model="corrected", rho=2.788).ratio(x)
    expected = 1 / (1 - 2.788 * (1 / (4 * np.maximum(x, 1.0))) ** 2)
    np.testing.assert_allclose(ratio, expected, rtol=1e-12)
    assert ratio[0] == ratio[1]  # clamped at the landing-gear height Z/R = 1
    with pytest.raises(ValueError, match="diverges"):
        thrust_ratio(np.array(0.3), "corrected", rho=3.3, min_height_ratio=0.3)
    assert thrust_ratio(np.array(2.0), "fitted_2rotor") > 1.04  # "a 5 % increase at 2 R" (chapter 2)


def test_ground_effect_function_mixes_models_per_trial() -> None:
    assert ground_effect_function([GroundEffect(), GroundEffect()]) is None
    function = ground_effect_function(
        [GroundEffect(model="fitted_4rotor"), GroundEffect(), GroundEffect(model="fitted_4rotor")]
    )
    ratio = function(np.full((3, 4), 2.0))
    np.testing.assert_allclose(ratio[:, 0], [1.0905, 1.0, 1.0905])


def test_dryden_psd_integrates_to_the_variance() -> None:
    omega = np.linspace(0, 2000, 2_000_001)
    for component in ("along", "across"):
        area = np.trapezoid(dryden_psd(omega, 1.3, 20.0, 4.0, component), omega)
        assert area == pytest.approx(1.3**2, rel=2e-3)


def test_generated_turbulence_has_the_dryden_spectrum() -> None:
    speed, rate = 5.0, 100.0
    turbulence = Dryden((1.0, 0.8, 0.5), (30.0, 30.0, 6.0))
    wind = Wind(mean_speed_m_s=speed, direction_from_deg=0.0, turbulence=turbulence)
    field = realize_field(wind, xi_min_m=-speed * 1300.0, xi_max_m=0.0, seed=11, resolution_hz=rate)
    n = field.values.shape[0]  # the whole periodic field, seen from a fixed point at 100 Hz
    nperseg = 4096
    freq, psd = sps.welch(field.values, fs=rate, nperseg=nperseg, axis=0)  # one-sided, per Hz, Hann, 50 % overlap
    n_segments = 2 * n // nperseg - 1
    bands = np.geomspace(8 * rate / nperseg, 0.4 * rate, 9)
    for k, form in enumerate(("along", "across", "across")):
        sigma, length = turbulence.sigma_m_s[k], turbulence.length_m[k]
        analytic = 2 * np.pi * dryden_psd(2 * np.pi * freq, sigma, length, speed, form)  # per Hz
        for low, high in zip(bands[:-1], bands[1:]):
            inside = (freq >= low) & (freq < high)
            ratio = np.mean(psd[inside, k] / analytic[inside])
            # Welch: variance P^2 / K per bin (K ~ 0.95 n_segments for Hann at 50 % overlap);
            # adjacent Hann bins correlate (0.25), so m bins average to 1.5 / (m K); allow 5 sigma
            sigma = np.sqrt(1.5 / (inside.sum() * 0.95 * n_segments))
            assert abs(ratio - 1) < 5 * sigma, (k, low, high, ratio, sigma)


def test_anemometer_sees_the_vehicles_gusts_one_transport_delay_earlier() -> None:
    speed, rate = 4.6, 100.0
    wind = Wind(
        mean_speed_m_s=speed,
        direction_from_deg=300.0,
        turbulence=Dryden.low_altitude(4.6, speed),
        gusts=(Gust(arrival_s=10.0, duration_s=2.0, amplitude_m_s=1.5),),
    )
    site = Anemometer(4.6)  # upstream: delay 4.6 m / 4.6 m/s = 1 s = 100 samples
    delay = site.transport_delay_s(wind)
    assert delay == pytest.approx(1.0)
    position = site.position_ne(wind)
    field = realize_field(wind, xi_min_m=-speed * 40 - 10, xi_max_m=10.0, seed=3)
    batch = BatchWindField.stack([wind, wind], [field, field])
    time = np.arange(0, 30.0, 1 / rate)
    vehicle = np.array([batch.at(np.zeros((2, 2)), t)[0] for t in time])
    sensor = np.array([batch.at(np.array([position, position]), t)[0] for t in time])
    np.testing.assert_allclose(sensor[:-100], vehicle[100:], atol=1e-9)  # Taylor: same gusts, 1 s earlier
    # a lone 1-cosine gust peaks at the vehicle at arrival + duration / 2, at the sensor one delay before
    gust_only = realize_field(
        Wind(
            mean_speed_m_s=speed,
            direction_from_deg=300.0,
            turbulence=None,
            gusts=(Gust(arrival_s=10.0, duration_s=2.0, amplitude_m_s=1.5),),
        ),
        xi_min_m=-200,
        xi_max_m=10,
        seed=0,
    )
    lone = BatchWindField.stack([wind], [gust_only])
    peak_vehicle = time[np.argmax([lone.at(np.zeros((1, 2)), t)[0] @ np.append(wind.towards, 0) for t in time])]
    peak_sensor = time[np.argmax([lone.at(position[None], t)[0] @ np.append(wind.towards, 0) for t in time])]
    assert peak_vehicle == pytest.approx(11.0, abs=0.011)
    assert peak_vehicle - peak_sensor == pytest.approx(delay, abs=0.011)


def test_a_crosswind_anemometer_has_no_transport_delay() -> None:
    wind = Wind(mean_speed_m_s=5.0, direction_from_deg=0.0)
    assert Anemometer(4.6, bearing_deg=90.0).transport_delay_s(wind) == pytest.approx(0.0, abs=1e-12)
    assert Anemometer(4.6, bearing_deg=180.0).transport_delay_s(wind) == pytest.approx(-0.92)  # downstream


def test_low_altitude_dryden_follows_mil_f_8785c() -> None:
    d = Dryden.low_altitude(4.6, 5.4)
    h_ft = 4.6 / 0.3048
    assert d.sigma_m_s[2] == pytest.approx(0.54)
    assert d.sigma_m_s[0] == pytest.approx(0.54 / (0.177 + 0.000823 * h_ft) ** 0.4)
    assert d.length_m[2] == pytest.approx(4.6)
    assert d.sigma_m_s[0] < 0.5 * 5.4  # Taylor's hypothesis holds (sigma < 0.5 M)


def test_wind_validation() -> None:
    with pytest.raises(ValueError, match="advected"):
        Wind(mean_speed_m_s=0.2, direction_from_deg=0.0, turbulence=Dryden.low_altitude(4.6, 0.2))
    with pytest.raises(ValueError, match="duration_s"):
        Gust(arrival_s=1.0, duration_s=0.0, amplitude_m_s=1.0)
    np.testing.assert_allclose(
        Wind(mean_speed_m_s=2.0, direction_from_deg=90.0).mean_ned, [0.0, -2.0, 0.0], atol=1e-12
    )  # from the east


def test_sensor_noise_levels_and_biases() -> None:
    rng = np.random.default_rng(0)
    clean = {"p": np.zeros(200_000), "az": np.full(200_000, -9.81), "u": np.ones(200_000)}
    noisy = SensorNoise(gyro_bias_rad_s=(0.01, 0.0, 0.0)).apply(clean, rng)
    assert np.mean(noisy["p"]) == pytest.approx(0.01, abs=1e-4)
    assert np.std(noisy["p"]) == pytest.approx(0.005, rel=0.01)
    assert np.std(noisy["az"]) == pytest.approx(0.05, rel=0.01)
    assert noisy["u"] is clean["u"]
    off = SensorNoise.off().apply(clean, rng)
    assert np.array_equal(off["p"], clean["p"])
    assert Environment().rotor_drag and not Environment().thrust_sag
