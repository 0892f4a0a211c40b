"""Wind as a frozen turbulence field advected with the mean wind (Taylor's hypothesis).

A realisation is a one-dimensional field of gust velocities along the mean
wind direction, ``g(xi)`` with ``xi = (position . e) - M t`` (e the unit
vector the wind blows towards, M the mean speed): every point downstream
sees what an upstream point saw ``distance / M`` earlier. Components are
along-wind (Dryden longitudinal spectrum), cross-wind and vertical (Dryden
lateral form). Discrete 1-cosine gusts are written into the same field, so
they too reach an upstream anemometer first.

Dryden spectra (MIL-F-8785C), one-sided in spatial frequency Omega (rad/m),
each integrating to sigma^2::

    Phi_u(Omega) = sigma_u^2 2 L_u / pi / (1 + (L_u Omega)^2)
    Phi_v(Omega) = sigma_v^2 L_v / pi (1 + 3 (L_v Omega)^2) / (1 + (L_v Omega)^2)^2

and in temporal frequency omega = Omega M at a fixed point, Phi(omega) = Phi(Omega) / M.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal, cast

import numpy as np

__all__ = ["Dryden", "Gust", "Wind", "FrozenField", "dryden_psd", "realize_field", "BatchWindField"]

_FT = 0.3048


@dataclass(frozen=True, slots=True)
class Dryden:
    """Dryden turbulence intensities and scale lengths.

    Parameters
    ----------
    sigma_m_s : tuple of float
        RMS of the along-wind, cross-wind and vertical gusts, m/s.
    length_m : tuple of float
        Scale lengths L_u, L_v, L_w, m.
    """

    sigma_m_s: tuple[float, float, float]
    length_m: tuple[float, float, float]

    def __post_init__(self) -> None:
        if len(self.sigma_m_s) != 3 or len(self.length_m) != 3:
            raise ValueError("sigma_m_s and length_m need three components (u, v, w)")
        if min(self.sigma_m_s) < 0 or min(self.length_m) <= 0:
            raise ValueError("sigma_m_s must be >= 0 and length_m > 0")

    @classmethod
    def low_altitude(cls, height_m: float, wind_speed_m_s: float, *, scale: float = 1.0) -> Dryden:
        """MIL-F-8785C low-altitude model (below 1000 ft).

        Parameters
        ----------
        height_m : float
            Height above ground, m (clamped to 10 ft = 3.05 m, the model's floor).
        wind_speed_m_s : float
            Mean wind at 20 ft (6.1 m), m/s; the wind at the flight height is close enough.
        scale : float, optional
            Multiplier on the intensities.

        Returns
        -------
        Dryden

        Notes
        -----
        With h in feet: ``L_w = h``, ``L_u = L_v = h / (0.177 + 0.000823 h)^1.2``,
        ``sigma_w = 0.1 W_20``, ``sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4``.
        At 4.6 m this gives L_u = 33.9 m and sigma_u = 0.195 W_20 (below Taylor's 0.5 limit).

        Examples
        --------
        >>> d = Dryden.low_altitude(4.6, 5.4)
        >>> round(d.length_m[0], 1), round(d.sigma_m_s[0] / 5.4, 3)
        (33.9, 0.195)
        """
        h_ft = max(height_m, 10 * _FT) / _FT
        base = 0.177 + 0.000823 * h_ft
        sigma_w = 0.1 * wind_speed_m_s * scale
        sigma_u = sigma_w / base**0.4
        length_u = h_ft / base**1.2 * _FT
        return cls((sigma_u, sigma_u, sigma_w), (length_u, length_u, h_ft * _FT))


@dataclass(frozen=True, slots=True, kw_only=True)
class Gust:
    """A discrete 1-cosine gust, frozen into the field.

    Parameters
    ----------
    arrival_s : float
        Time its front reaches the vehicle's start point, s.
    duration_s : float
        Time it takes to pass a fixed point, s (length = duration * mean speed).
    amplitude_m_s : float
        Peak velocity, m/s.
    component : {"along", "across", "vertical"}
        Direction: along the mean wind, to its right, or down.
    """

    arrival_s: float
    duration_s: float
    amplitude_m_s: float
    component: Literal["along", "across", "vertical"] = "along"

    def __post_init__(self) -> None:
        if self.duration_s <= 0:
            raise ValueError(f"duration_s={self.duration_s} must be > 0")
        if self.component not in ("along", "across", "vertical"):
            raise ValueError(f"component={self.component!r} must be along, across or vertical")


@dataclass(frozen=True, slots=True, kw_only=True)
class Wind:
    """Mean wind plus optional Dryden turbulence and discrete gusts.

    Parameters
    ----------
    mean_speed_m_s : float
        Mean horizontal speed M, m/s.
    direction_from_deg : float
        Meteorological direction it comes from, deg.
    turbulence : Dryden or None
        Turbulence; None for a steady wind. Needs M >= 0.5 m/s (frozen field).
    gusts : tuple of Gust
        Discrete gusts.
    """

    mean_speed_m_s: float = 0.0
    direction_from_deg: float = 0.0
    turbulence: Dryden | None = None
    gusts: tuple[Gust, ...] = ()

    def __post_init__(self) -> None:
        if self.mean_speed_m_s < 0:
            raise ValueError(f"mean_speed_m_s={self.mean_speed_m_s} must be >= 0")
        if (self.turbulence is not None or self.gusts) and self.mean_speed_m_s < 0.5:
            raise ValueError("turbulence and gusts are advected by the mean wind: need mean_speed_m_s >= 0.5")

    @property
    def towards(self) -> np.ndarray:
        """Unit vector (north, east) the wind blows towards, shape (2,)."""
        angle = np.radians(self.direction_from_deg) + np.pi
        return np.array([np.cos(angle), np.sin(angle)])

    @property
    def mean_ned(self) -> np.ndarray:
        """Mean wind velocity, NED, m/s, shape (3,)."""
        return np.append(self.mean_speed_m_s * self.towards, 0.0)

    @classmethod
    def dissertation(
        cls,
        kind: Literal["calm", "light", "strong"],
        *,
        direction_from_deg: float = 0.0,
        height_m: float = 4.6,
        turbulence: bool = True,
    ) -> Wind:
        """The chapter 3 wind days: calm 0.9, light 2.7, strong 5.4 m/s, with low-altitude Dryden turbulence.

        Parameters
        ----------
        kind : {"calm", "light", "strong"}
            Wind day.
        direction_from_deg : float, optional
            Direction it comes from, deg.
        height_m : float, optional
            Flight height, m.
        turbulence : bool, optional
            Add Dryden turbulence.

        Returns
        -------
        Wind
        """
        speed = {"calm": 0.9, "light": 2.7, "strong": 5.4}[kind]
        return cls(
            mean_speed_m_s=speed,
            direction_from_deg=direction_from_deg,
            turbulence=Dryden.low_altitude(height_m, speed) if turbulence else None,
        )


def dryden_psd(
    omega_rad_s: np.ndarray,
    sigma_m_s: float,
    length_m: float,
    speed_m_s: float,
    component: Literal["along", "across"] = "along",
) -> np.ndarray:
    """One-sided Dryden PSD at a fixed point, (m/s)^2 per rad/s.

    Parameters
    ----------
    omega_rad_s : ndarray
        Angular frequency, rad/s.
    sigma_m_s : float
        Gust RMS, m/s.
    length_m : float
        Scale length, m.
    speed_m_s : float
        Mean speed advecting the field, m/s.
    component : {"along", "across"}
        Longitudinal form, or the lateral form (also used for vertical gusts).

    Returns
    -------
    ndarray
        PSD, same shape as `omega_rad_s`; integrates to sigma^2 over [0, inf).

    Examples
    --------
    >>> from scipy.integrate import quad
    >>> round(quad(lambda w: dryden_psd(w, 1.0, 30.0, 5.0, "across"), 0, np.inf)[0], 6)
    1.0
    """
    x = length_m * np.asarray(omega_rad_s) / speed_m_s
    if component == "along":
        shape = 2.0 / (1.0 + x * x)
    else:
        shape = (1.0 + 3.0 * x * x) / (1.0 + x * x) ** 2
    return sigma_m_s**2 * length_m / (np.pi * speed_m_s) * shape


@dataclass(frozen=True, slots=True, kw_only=True)
class FrozenField:
    """Gust velocities on a uniform grid of the along-wind coordinate xi.

    Parameters
    ----------
    xi0_m : float
        xi of the first grid point, m.
    dxi_m : float
        Grid spacing, m.
    values : ndarray, shape (n_grid, 3)
        Along-wind, cross-wind and vertical (down) gust velocity, m/s.
    """

    xi0_m: float
    dxi_m: float
    values: np.ndarray

    def __post_init__(self) -> None:
        if self.dxi_m <= 0 or np.ndim(self.values) != 2 or np.shape(self.values)[1] != 3:
            raise ValueError("dxi_m must be > 0 and values shaped (n_grid, 3)")

    def at(self, xi_m: np.ndarray) -> np.ndarray:
        """Linearly interpolated gusts at `xi_m`, shape (n, 3) (zero outside the grid).

        Parameters
        ----------
        xi_m : ndarray, shape (n,)
            Along-wind coordinates, m.

        Returns
        -------
        ndarray, shape (n, 3)
        """
        grid = self.xi0_m + self.dxi_m * np.arange(self.values.shape[0])
        return np.column_stack([np.interp(xi_m, grid, self.values[:, k], left=0.0, right=0.0) for k in range(3)])


def _spectral_synthesis(psd: np.ndarray, domega: float, n: int, rng: np.random.Generator) -> np.ndarray:
    """A real Gaussian series of `n` points with one-sided PSD `psd` on the rfft grid."""
    amplitude = n * np.sqrt(psd * domega) / 2.0
    spectrum = amplitude * (rng.standard_normal(psd.size) + 1j * rng.standard_normal(psd.size))
    spectrum[0] = 0.0
    return np.fft.irfft(spectrum, n)


def realize_field(
    wind: Wind, *, xi_min_m: float, xi_max_m: float, seed: int | np.random.SeedSequence, resolution_hz: float = 100.0
) -> FrozenField:
    """One realisation of the gust field over ``[xi_min_m, xi_max_m]``.

    Parameters
    ----------
    wind : Wind
        Mean wind, turbulence and gusts.
    xi_min_m, xi_max_m : float
        Span of along-wind coordinates that will be sampled, m.
    seed : int or SeedSequence
        Seed of the turbulence.
    resolution_hz : float, optional
        Grid spacing as a rate at a fixed point: dxi = M / resolution_hz.

    Returns
    -------
    FrozenField

    Notes
    -----
    Spectral synthesis (complex Gaussian amplitudes on an FFT grid) of a
    periodic field at least twice the span and eight longest scale lengths
    long, so wrap-around correlation stays negligible.
    """
    speed = max(wind.mean_speed_m_s, 0.5)
    dxi = speed / resolution_hz
    span = xi_max_m - xi_min_m
    turbulence = wind.turbulence
    longest = max(turbulence.length_m) if turbulence else 0.0
    n = int(2 ** np.ceil(np.log2(max(2 * span, 8 * longest, 64 * dxi) / dxi)))
    values = np.zeros((n, 3))
    if turbulence is not None:
        rng = np.random.default_rng(seed)
        omega = 2 * np.pi * np.fft.rfftfreq(n, dxi)
        forms: tuple[Literal["along", "across"], ...] = ("along", "across", "across")
        for k, form in enumerate(forms):
            sigma, length = turbulence.sigma_m_s[k], turbulence.length_m[k]
            psd = dryden_psd(omega, sigma, length, 1.0, form)  # spatial PSD: speed 1
            values[:, k] = _spectral_synthesis(psd, omega[1], n, rng)
    xi = xi_min_m + dxi * np.arange(n)
    for gust in wind.gusts:  # front at xi = -M t_a (the start point at t_a), extending upstream
        start = -wind.mean_speed_m_s * gust.arrival_s
        length = wind.mean_speed_m_s * gust.duration_s
        inside = (xi <= start) & (xi >= start - length)
        k = ("along", "across", "vertical").index(gust.component)
        values[inside, k] += gust.amplitude_m_s / 2 * (1 - np.cos(2 * np.pi * (start - xi[inside]) / length))
    return FrozenField(xi0_m=float(xi_min_m), dxi_m=float(dxi), values=values)


@dataclass(frozen=True, slots=True, kw_only=True)
class BatchWindField:
    """The frozen fields of a batch of trials, sampled at arbitrary points in one vectorised gather.

    Parameters
    ----------
    fields : ndarray, shape (n_trials, n_grid, 3)
        Gust values (padded with zeros to the longest grid).
    xi0_m : ndarray, shape (n_trials,)
        xi of the first grid point, m.
    dxi_m : ndarray, shape (n_trials,)
        Grid spacing, m.
    mean_ned : ndarray, shape (n_trials, 3)
        Mean wind, m/s.
    towards : ndarray, shape (n_trials, 2)
        Unit vector the wind blows towards.
    speed_m_s : ndarray, shape (n_trials,)
        Mean speed advecting the field, m/s.
    """

    fields: np.ndarray
    xi0_m: np.ndarray
    dxi_m: np.ndarray
    mean_ned: np.ndarray
    towards: np.ndarray
    speed_m_s: np.ndarray
    _rows: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        n = self.fields.shape[0]
        for name in ("xi0_m", "dxi_m", "speed_m_s"):
            if np.shape(getattr(self, name)) != (n,):
                raise ValueError(f"{name} must have shape ({n},)")
        object.__setattr__(self, "_rows", np.arange(n))

    @classmethod
    def stack(cls, winds: list[Wind], fields: list[FrozenField]) -> BatchWindField:
        """Batch the per-trial fields.

        Parameters
        ----------
        winds : list of Wind
            Each trial's wind.
        fields : list of FrozenField
            Each trial's realisation.

        Returns
        -------
        BatchWindField
        """
        n_grid = max(f.values.shape[0] for f in fields)
        stacked = np.zeros((len(fields), n_grid + 1, 3))  # one zero past the end
        for k, f in enumerate(fields):
            stacked[k, : f.values.shape[0]] = f.values
        return cls(
            fields=stacked,
            xi0_m=np.array([f.xi0_m for f in fields]),
            dxi_m=np.array([f.dxi_m for f in fields]),
            mean_ned=np.array([w.mean_ned for w in winds]),
            towards=np.array([w.towards for w in winds]),
            speed_m_s=np.array([w.mean_speed_m_s for w in winds]),
        )

    def gusts(self, xi_m: np.ndarray) -> np.ndarray:
        """Gust components (along, across, down) at one xi per trial, shape (n_trials, 3).

        Parameters
        ----------
        xi_m : ndarray, shape (n_trials,)
            Along-wind coordinates, m.

        Returns
        -------
        ndarray, shape (n_trials, 3)
        """
        position = (xi_m - self.xi0_m) / self.dxi_m
        limit = self.fields.shape[1] - 2
        index = np.clip(np.floor(position), 0, limit).astype(np.intp)
        frac = np.clip(position - index, 0.0, 1.0)[:, None]
        low = self.fields[self._rows, index]
        high = self.fields[self._rows, index + 1]
        return cast(np.ndarray, low + frac * (high - low))

    def at(self, position_ne: np.ndarray, time_s: float) -> np.ndarray:
        """Wind velocity (NED, m/s) at one horizontal position per trial, shape (n_trials, 3).

        Parameters
        ----------
        position_ne : ndarray, shape (n_trials, 2)
            North, east, m.
        time_s : float
            Time, s.

        Returns
        -------
        ndarray, shape (n_trials, 3)
        """
        e = self.towards
        xi = position_ne[:, 0] * e[:, 0] + position_ne[:, 1] * e[:, 1] - self.speed_m_s * time_s
        g = self.gusts(xi)
        wind = self.mean_ned.copy()
        wind[:, 0] += g[:, 0] * e[:, 0] - g[:, 1] * e[:, 1]
        wind[:, 1] += g[:, 0] * e[:, 1] + g[:, 1] * e[:, 0]
        wind[:, 2] += g[:, 2]
        return wind
