"""The world around the vehicle: ground effect, wind, payload, CG offset, sensors; every effect switchable.

Ground-effect models give the thrust ratio F/F0 against the height ratio Z/R
(rotor plane above ground over propeller radius), eqs. 2.1-2.5. Wind is in
:mod:`simulator.world.wind_field` (frozen Dryden field advected with the mean
wind, 1-cosine gusts); :class:`Anemometer` places the ground sensor that
samples the same field.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

import numpy as np

from simulator.world.wind_field import Wind
from sysid.groundeffect import formulas as _laws

__all__ = [
    "GroundEffectModel",
    "GroundEffect",
    "thrust_ratio",
    "ground_effect_function",
    "Anemometer",
    "PayloadChange",
    "SensorNoise",
    "Environment",
]

GroundEffectModel = Literal["none", "cheeseman_bennett", "corrected", "exponential", "fitted_2rotor", "fitted_4rotor"]
_MODELS = ("none", "cheeseman_bennett", "corrected", "exponential", "fitted_2rotor", "fitted_4rotor")


def thrust_ratio(
    height_ratio: np.ndarray,
    model: GroundEffectModel,
    *,
    rho: float = 3.315,
    a: float = 0.2744,
    b: float = 1.633,
    min_height_ratio: float = 1.0,
) -> np.ndarray:
    """Thrust in ground effect over thrust out of it, F/F0, against Z/R.

    Parameters
    ----------
    height_ratio : ndarray
        Z/R: height of the rotor plane above ground over the propeller radius.
    model : {"none", "cheeseman_bennett", "corrected", "exponential", "fitted_2rotor", "fitted_4rotor"}
        Eq. 2.1 (Cheeseman-Bennett), 2.2 (corrected with `rho`), 2.3
        (exponential with `a`, `b`), 2.4 (2.2 with rho = 3.315, two rotors),
        2.5 (piecewise linear, four rotors).
    rho : float, optional
        Correction of eq. 2.2 (Table 2.2: 2.79-3.32).
    a, b : float, optional
        Eq. 2.3's amplitude and decay length (in Z/R). The defaults are the
        least-squares fit of eq. 2.3 to eq. 2.5 over 1 <= Z/R <= 6 (RMS 0.011).
    min_height_ratio : float, optional
        Z/R is clamped from below (the landing gear keeps the rotors above it;
        chapter 2's rig could not go below Z/R = 1), which also keeps eqs. 2.1-2.2 finite.

    Returns
    -------
    ndarray
        F/F0, same shape as `height_ratio`.

    Examples
    --------
    >>> float(thrust_ratio(np.array(1.0), "cheeseman_bennett"))  # 1 / (1 - 1/16)
    1.0666666666666667
    >>> float(thrust_ratio(np.array(2.0), "fitted_4rotor"))
    1.0905
    """
    x = np.maximum(np.asarray(height_ratio, dtype=np.float64), min_height_ratio)
    if model == "none":
        return np.ones_like(x)
    if model == "cheeseman_bennett":
        return _laws.cheeseman_bennett(x)
    if model in ("corrected", "fitted_2rotor"):
        factor = _laws.FITTED_2ROTOR_RHO if model == "fitted_2rotor" else rho
        if np.any(_laws.corrected_denominator(x, factor) <= 0.05):
            raise ValueError(f"eq. 2.2 with rho={factor} diverges near Z/R={min_height_ratio}: raise min_height_ratio")
        return _laws.corrected(x, factor)
    if model == "exponential":
        return _laws.exponential(x, a, b)
    if model == "fitted_4rotor":
        return _laws.piecewise_linear(
            x, _laws.FITTED_4ROTOR_SLOPE, _laws.FITTED_4ROTOR_INTERCEPT, _laws.FITTED_4ROTOR_BREAKPOINT
        )
    raise ValueError(f"unknown ground-effect model {model!r}; choose from {_MODELS}")


@dataclass(frozen=True, slots=True, kw_only=True)
class GroundEffect:
    """A ground-effect model and its constants (see :func:`thrust_ratio`).

    Parameters
    ----------
    model : str
        One of :data:`GroundEffectModel`.
    rho : float
        Eq. 2.2 correction.
    a, b : float
        Eq. 2.3 constants.
    min_height_ratio : float
        Lowest Z/R.
    """

    model: GroundEffectModel = "none"
    rho: float = 3.315
    a: float = 0.2744
    b: float = 1.633
    min_height_ratio: float = 1.0

    def __post_init__(self) -> None:
        if self.model not in _MODELS:
            raise ValueError(f"model={self.model!r} must be one of {_MODELS}")
        if self.min_height_ratio <= 0 or self.b <= 0:
            raise ValueError("min_height_ratio and b must be > 0")

    def ratio(self, height_ratio: np.ndarray) -> np.ndarray:
        """F/F0 at `height_ratio` (Z/R).

        Parameters
        ----------
        height_ratio : ndarray
            Z/R.

        Returns
        -------
        ndarray
        """
        return thrust_ratio(
            height_ratio, self.model, rho=self.rho, a=self.a, b=self.b, min_height_ratio=self.min_height_ratio
        )


def ground_effect_function(effects: list[GroundEffect]) -> Callable[[np.ndarray], np.ndarray] | None:
    """One function for a batch whose trials may use different ground-effect models.

    Parameters
    ----------
    effects : list of GroundEffect
        One per trial.

    Returns
    -------
    callable or None
        Maps Z/R, shape (n_trials, n_rotors), to F/F0; None if no trial has ground effect.
    """
    if all(e.model == "none" for e in effects):
        return None
    distinct = sorted(set(effects), key=repr)
    if len(distinct) == 1:
        return distinct[0].ratio
    masks = [np.array([e == d for e in effects])[:, None] for d in distinct]

    def ratio(height_ratio: np.ndarray) -> np.ndarray:
        out = np.ones_like(height_ratio)
        for effect, mask in zip(distinct, masks):
            out = np.where(mask, effect.ratio(height_ratio), out)
        return out

    return ratio


@dataclass(frozen=True, slots=True)
class Anemometer:
    """A ground anemometer at flight height near the vehicle's hover point.

    It samples the frozen field that reaches the vehicle: upstream it sees the
    gusts ``transport_delay_s`` earlier; off the wind line its turbulence
    decorrelates exponentially with the cross-wind offset over each
    component's scale length (chapter 3, Table 3.1: two sensors agree better
    along the wind than across it).

    Parameters
    ----------
    distance_m : float
        Horizontal distance from the hover point, m (chapter 3: 4.6 m).
    bearing_deg : float or None
        Bearing from the hover point to the sensor, deg from north; None: straight
        upstream (the direction the wind comes from), as in chapter 3.
    """

    distance_m: float = 4.6
    bearing_deg: float | None = None

    def __post_init__(self) -> None:
        if self.distance_m < 0:
            raise ValueError(f"distance_m={self.distance_m} must be >= 0")

    def position_ne(self, wind: Wind) -> np.ndarray:
        """North, east of the sensor from the hover point, m, shape (2,).

        Parameters
        ----------
        wind : Wind
            The wind (for the upstream default).

        Returns
        -------
        ndarray, shape (2,)
        """
        bearing = wind.direction_from_deg if self.bearing_deg is None else self.bearing_deg
        angle = np.radians(bearing)
        return self.distance_m * np.array([np.cos(angle), np.sin(angle)])

    def transport_delay_s(self, wind: Wind) -> float:
        """Time a frozen gust takes from the sensor to the hover point, s (negative if downstream).

        Parameters
        ----------
        wind : Wind
            The wind.

        Returns
        -------
        float
        """
        if wind.mean_speed_m_s <= 0:
            return 0.0
        return float(-self.position_ne(wind) @ wind.towards / wind.mean_speed_m_s)


@dataclass(frozen=True, slots=True)
class PayloadChange:
    """A mass picked up (positive) or dropped (negative) at a given time, at the CG.

    Parameters
    ----------
    time_s : float
        When, s.
    delta_mass_kg : float
        Mass change, kg (inertia kept).
    """

    time_s: float
    delta_mass_kg: float


@dataclass(frozen=True, slots=True, kw_only=True)
class SensorNoise:
    """White noise and constant biases on the logged signals (1 sigma; biases in body axes).

    Parameters
    ----------
    gyro_rad_s : float
        Rate noise, rad/s.
    gyro_bias_rad_s : tuple of float
        Rate biases p, q, r, rad/s.
    accel_m_s2 : float
        Specific-force noise, m/s^2 (x and y; z gets ``accel_z_factor`` times it).
    accel_bias_m_s2 : tuple of float
        Specific-force biases, m/s^2.
    attitude_rad : float
        Roll and pitch noise, rad (yaw twice it).
    velocity_m_s : float
        Earth-velocity noise, m/s.
    height_m : float
        Height noise, m.
    accel_z_factor : float
        Ratio of the z accelerometer noise to x and y.
    """

    gyro_rad_s: float = 0.005
    gyro_bias_rad_s: tuple[float, float, float] = (0.0, 0.0, 0.0)
    accel_m_s2: float = 0.03
    accel_bias_m_s2: tuple[float, float, float] = (0.0, 0.0, 0.0)
    attitude_rad: float = 0.001
    velocity_m_s: float = 0.02
    height_m: float = 0.01
    accel_z_factor: float = 5.0 / 3.0

    def __post_init__(self) -> None:
        if min(self.gyro_rad_s, self.accel_m_s2, self.attitude_rad, self.velocity_m_s, self.height_m) < 0:
            raise ValueError("noise levels must be >= 0")

    @classmethod
    def off(cls) -> SensorNoise:
        """No noise and no biases.

        Returns
        -------
        SensorNoise
        """
        return cls(
            gyro_rad_s=0.0,
            gyro_bias_rad_s=(0.0, 0.0, 0.0),
            accel_m_s2=0.0,
            accel_bias_m_s2=(0.0, 0.0, 0.0),
            attitude_rad=0.0,
            velocity_m_s=0.0,
            height_m=0.0,
        )

    def apply(self, signals: dict[str, np.ndarray], rng: np.random.Generator) -> dict[str, np.ndarray]:
        """Noisy copies of the canonical signals (others unchanged).

        Parameters
        ----------
        signals : dict of str to ndarray
            Clean signals, each shape (n_samples,).
        rng : numpy.random.Generator
            Noise source.

        Returns
        -------
        dict of str to ndarray
        """
        spec = {
            "p": (self.gyro_rad_s, self.gyro_bias_rad_s[0]),
            "q": (self.gyro_rad_s, self.gyro_bias_rad_s[1]),
            "r": (self.gyro_rad_s, self.gyro_bias_rad_s[2]),
            "ax": (self.accel_m_s2, self.accel_bias_m_s2[0]),
            "ay": (self.accel_m_s2, self.accel_bias_m_s2[1]),
            "az": (self.accel_m_s2 * self.accel_z_factor, self.accel_bias_m_s2[2]),
            "phi": (self.attitude_rad, 0.0),
            "theta": (self.attitude_rad, 0.0),
            "psi": (2 * self.attitude_rad, 0.0),
            "vn": (self.velocity_m_s, 0.0),
            "ve": (self.velocity_m_s, 0.0),
            "vd": (self.velocity_m_s, 0.0),
            "height_agl": (self.height_m, 0.0),
        }
        out = dict(signals)
        for name, (sigma, bias) in spec.items():
            if name in out:
                out[name] = out[name] + bias + rng.normal(scale=sigma, size=out[name].shape)
        return out


@dataclass(frozen=True, slots=True, kw_only=True)
class Environment:
    """Everything outside the vehicle for one trial.

    Parameters
    ----------
    wind : Wind
        Mean wind, turbulence, gusts.
    anemometer : Anemometer
        Where the ground anemometer stands.
    ground_effect : GroundEffect
        Ground-effect model ("none" to switch it off).
    rotor_drag : bool
        Rotor drag and blade flapping (X_u, Y_v, M_u, L_v) on or off.
    thrust_sag : bool
        Rotor thrust follows the sagging battery voltage.
    payload : PayloadChange or None
        A mass change during the flight.
    cg_offset_m : tuple of float
        CG displacement from its design point, FRD body axes, m.
    sensors : SensorNoise
        Noise and biases of the logged signals.
    gravity_m_s2 : float
        Gravity, m/s^2.
    """

    wind: Wind = field(default_factory=Wind)
    anemometer: Anemometer = field(default_factory=Anemometer)
    ground_effect: GroundEffect = field(default_factory=GroundEffect)
    rotor_drag: bool = True
    thrust_sag: bool = False
    payload: PayloadChange | None = None
    cg_offset_m: tuple[float, float, float] = (0.0, 0.0, 0.0)
    sensors: SensorNoise = field(default_factory=SensorNoise)
    gravity_m_s2: float = 9.81

    def __post_init__(self) -> None:
        if len(self.cg_offset_m) != 3:
            raise ValueError(f"cg_offset_m must have three components, got {self.cg_offset_m}")
        if self.gravity_m_s2 <= 0:
            raise ValueError(f"gravity_m_s2={self.gravity_m_s2} must be > 0")
