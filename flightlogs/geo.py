"""Geodesy on the mean Earth sphere: the radius, great-circle bearing and distance, local north/east offsets.

One sphere for every layer: the anemometer-to-vehicle geometry of the
conditioning, the GPS tracks the simulator logs, and the tests that read
them back. Latitudes and longitudes are WGS-84, in radians; distances and
offsets in metres.

Over the few hundred metres between an anemometer and a vehicle the sphere
of mean radius is within 0.5 % of the ellipsoid's distances (millimetres),
and the local equirectangular offsets of :func:`local_north_east` are
within (offset / R)·tan(latitude) of the sphere's (micrometres).
"""

from __future__ import annotations

from typing import Final

import numpy as np
import numpy.typing as npt

__all__ = ["EARTH_RADIUS_M", "bearing_and_distance", "destination_point", "local_north_east", "lat_lon_offset"]

#: Mean radius of the Earth, m: IUGG R1 = (2a + b) / 3 of the GRS 80 ellipsoid, 6 371 008.7714 m
#: (H. Moritz, "Geodetic Reference System 1980", Journal of Geodesy 74 (2000), p. 131), to 0.1 m.
EARTH_RADIUS_M: Final = 6_371_008.8


def bearing_and_distance(lat_from: float, lon_from: float, lat_to: float, lon_to: float) -> tuple[float, float]:
    """Initial bearing and great-circle distance between two positions (haversine, spherical Earth).

    Parameters
    ----------
    lat_from, lon_from : float
        Start (the anemometer), WGS-84 latitude and longitude, rad.
    lat_to, lon_to : float
        End (the vehicle), rad.

    Returns
    -------
    tuple of float
        Bearing, rad clockwise from north in [0, 2π), and distance, m.

    Notes
    -----
    Haversine distance ``2 R asin √(sin²(Δφ/2) + cos φ1 cos φ2 sin²(Δλ/2))``
    (R. W. Sinnott, "Virtues of the haversine", Sky and Telescope 68, 1984),
    well conditioned down to millimetres; bearing
    ``atan2(sin Δλ cos φ2, cos φ1 sin φ2 − sin φ1 cos φ2 cos Δλ)``, on the
    sphere of radius :data:`EARTH_RADIUS_M`.

    Examples
    --------
    >>> bearing, distance = bearing_and_distance(0.0, 0.0, 0.0, np.radians(0.001))
    >>> round(float(np.degrees(bearing)), 6), round(distance, 2)
    (90.0, 111.2)
    """
    phi1, phi2 = lat_from, lat_to
    dlon = lon_to - lon_from
    dphi = phi2 - phi1
    hav = np.sin(dphi / 2) ** 2 + np.cos(phi1) * np.cos(phi2) * np.sin(dlon / 2) ** 2
    distance = 2 * EARTH_RADIUS_M * np.arcsin(np.sqrt(hav))
    bearing = np.arctan2(
        np.sin(dlon) * np.cos(phi2), np.cos(phi1) * np.sin(phi2) - np.sin(phi1) * np.cos(phi2) * np.cos(dlon)
    )
    return float(np.mod(bearing, 2 * np.pi)), float(distance)


def destination_point(lat_rad: float, lon_rad: float, bearing_rad: float, distance_m: float) -> tuple[float, float]:
    """Position reached from a start along a great circle, the inverse of :func:`bearing_and_distance`.

    Parameters
    ----------
    lat_rad, lon_rad : float
        Start, WGS-84 latitude and longitude, rad.
    bearing_rad : float
        Initial direction, rad clockwise from north.
    distance_m : float
        Distance travelled, m.

    Returns
    -------
    tuple of float
        Latitude and longitude of the end, rad (longitude in [-π, π)).

    Examples
    --------
    >>> lat, lon = destination_point(0.0, 0.0, np.pi / 2, 111.195)
    >>> round(float(np.degrees(lon)), 6), round(float(lat), 12)
    (0.001, 0.0)
    """
    angle = distance_m / EARTH_RADIUS_M
    lat = np.arcsin(np.sin(lat_rad) * np.cos(angle) + np.cos(lat_rad) * np.sin(angle) * np.cos(bearing_rad))
    lon = lon_rad + np.arctan2(
        np.sin(bearing_rad) * np.sin(angle) * np.cos(lat_rad), np.cos(angle) - np.sin(lat_rad) * np.sin(lat)
    )
    return float(lat), float(np.mod(lon + np.pi, 2 * np.pi) - np.pi)


def local_north_east(
    lat_rad: npt.ArrayLike, lon_rad: npt.ArrayLike, lat0_rad: float, lon0_rad: float
) -> tuple[np.ndarray, np.ndarray]:
    """North and east offsets of positions from a reference point (equirectangular about its latitude).

    Parameters
    ----------
    lat_rad, lon_rad : float or array_like, shape (n_samples,)
        Positions, WGS-84 latitude and longitude, rad.
    lat0_rad, lon0_rad : float
        The reference point (a mean position, or the origin of a track), rad.

    Returns
    -------
    north_m, east_m : ndarray, shape like `lat_rad`
        Offsets from the reference point, m.

    Notes
    -----
    ``north = R (φ − φ0)``, ``east = R cos φ0 · wrap(λ − λ0)`` with the
    longitude difference wrapped into (−π, π], so a track across ±180°
    stays whole; :func:`lat_lon_offset` is the inverse.

    Examples
    --------
    >>> north, east = local_north_east(np.radians([1.0, 0.0]), np.radians([0.0, 1.0]), 0.0, 0.0)
    >>> north.round(1).tolist(), east.round(1).tolist()
    ([111195.1, 0.0], [0.0, 111195.1])
    >>> _, east = local_north_east(0.0, np.radians(-179.9), 0.0, np.radians(179.9))
    >>> round(float(east), 1)
    22239.0
    """
    north = (np.asarray(lat_rad) - lat0_rad) * EARTH_RADIUS_M
    east = np.angle(np.exp(1j * (np.asarray(lon_rad) - lon0_rad))) * EARTH_RADIUS_M * np.cos(lat0_rad)
    return np.asarray(north), np.asarray(east)


def lat_lon_offset(north_m: npt.ArrayLike, east_m: npt.ArrayLike, lat0_rad: float) -> tuple[np.ndarray, np.ndarray]:
    """Latitude and longitude differences of north/east offsets from a point at latitude `lat0_rad`.

    Parameters
    ----------
    north_m, east_m : float or array_like, shape (n_samples,)
        Offsets from the reference point, m.
    lat0_rad : float
        Latitude of the reference point, rad.

    Returns
    -------
    dlat_rad, dlon_rad : ndarray, shape like `north_m`
        To add to the reference point's latitude and longitude, rad: the
        inverse of :func:`local_north_east`.

    Examples
    --------
    >>> dlat, dlon = lat_lon_offset(111_195.08, 55_597.54, np.radians(60.0))
    >>> round(float(np.degrees(dlat)), 6), round(float(np.degrees(dlon)), 6)
    (1.0, 1.0)
    """
    return np.asarray(np.asarray(north_m) / EARTH_RADIUS_M), np.asarray(
        np.asarray(east_m) / (EARTH_RADIUS_M * np.cos(lat0_rad))
    )
