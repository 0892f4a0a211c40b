"""Geodesy on the mean sphere against analytic values, a published city pair and round trips."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from flightlogs.geo import EARTH_RADIUS_M, bearing_and_distance, destination_point, lat_lon_offset, local_north_east

ONE_DEGREE_M = 111_195.08  # R1 · π / 180 (analytic)
# Ed Williams' Aviation Formulary worked example: LAX (33°57'N, 118°24'W) to JFK (40°38'N, 73°47'W).
LAX = np.radians(33 + 57 / 60), np.radians(-(118 + 24 / 60))
JFK = np.radians(40 + 38 / 60), np.radians(-(73 + 47 / 60))


def test_the_radius_is_the_iugg_mean_radius() -> None:
    """R1 = (2a + b) / 3 of GRS 80 (a = 6 378 137 m, 1/f = 298.257 222 101), to 0.1 m (Moritz 2000)."""
    a, f = 6_378_137.0, 1 / 298.257_222_101
    assert EARTH_RADIUS_M == pytest.approx((2 * a + a * (1 - f)) / 3, abs=0.05)


def test_one_degree_of_latitude_is_111_195_m() -> None:
    """R1 · π / 180, due north (analytic)."""
    bearing, distance = bearing_and_distance(np.radians(45.0), 0.3, np.radians(46.0), 0.3)
    assert distance == pytest.approx(ONE_DEGREE_M, abs=0.01)
    assert bearing == pytest.approx(0.0, abs=1e-12)


def test_bearing_and_distance_against_known_points() -> None:
    """Radians in; 4.6 m north and a step west (analytic)."""
    lat, lon = np.radians(45.0), np.radians(7.0)
    bearing, distance = bearing_and_distance(lat, lon, lat + np.radians(4.6 / ONE_DEGREE_M), lon)
    assert bearing == pytest.approx(0.0, abs=1e-9) and distance == pytest.approx(4.6, rel=1e-6)
    bearing, _ = bearing_and_distance(lat, lon, lat, np.radians(6.9999))
    assert np.degrees(bearing) == pytest.approx(270.0, abs=1e-3)


def test_lax_to_jfk() -> None:
    """Williams' example: 0.623585 rad of arc, initial course 1.150035 rad (6 digits as published);
    the WGS-84 geodesic is 3 981.6 km (Vincenty's inverse): the sphere is within 0.5 % of it."""
    bearing, distance = bearing_and_distance(*LAX, *JFK)
    assert distance / EARTH_RADIUS_M == pytest.approx(0.623585, abs=1e-6)
    assert bearing == pytest.approx(1.150035, abs=1e-6)
    assert distance == pytest.approx(3_981_600.0, rel=0.005)


@pytest.mark.parametrize("bearing_deg", [0.0, 37.0, 90.0, 211.0, 300.0])
@pytest.mark.parametrize("lat_deg, lon_deg", [(35.0, -106.9), (-35.36, 149.16), (51.9, 179.99999)])
def test_destination_point_inverts_bearing_and_distance(lat_deg: float, lon_deg: float, bearing_deg: float) -> None:
    """Out 4.6 m and back: the bearing and distance come back to 1e-7 rad and 1 µm (round trip)."""
    start = np.radians(lat_deg), np.radians(lon_deg)
    end = destination_point(*start, np.radians(bearing_deg), 4.6)
    bearing, distance = bearing_and_distance(*start, *end)
    assert distance == pytest.approx(4.6, abs=1e-6)
    assert np.angle(np.exp(1j * (bearing - np.radians(bearing_deg)))) == pytest.approx(0.0, abs=1e-7)


def test_destination_point_wraps_the_longitude() -> None:
    """East across the antimeridian lands just west of -180° + 0.001° (analytic, on the equator)."""
    lat, lon = destination_point(0.0, np.radians(179.9995), np.pi / 2, 0.001 * ONE_DEGREE_M)
    assert np.degrees(lon) == pytest.approx(-179.9995, abs=1e-9)
    assert lat == pytest.approx(0.0, abs=1e-15)


def test_local_north_east_of_one_degree() -> None:
    """A degree north is R1·π/180; a degree east at 60° is half that (cos 60° = 1/2, analytic)."""
    lat0 = np.radians(60.0)
    north, east = local_north_east(np.radians([61.0, 60.0]), np.radians([10.0, 11.0]), lat0, np.radians(10.0))
    np.testing.assert_allclose(north, [ONE_DEGREE_M, 0.0], atol=0.01)
    np.testing.assert_allclose(east, [0.0, ONE_DEGREE_M / 2], atol=0.01)


def test_local_north_east_across_the_antimeridian() -> None:
    """179.9° E to 179.9° W is 0.2° east, not 359.8° west (on the equator, analytic)."""
    _, east = local_north_east(0.0, np.radians(-179.9), 0.0, np.radians(179.9))
    assert float(east) == pytest.approx(np.radians(0.2) * EARTH_RADIUS_M, abs=1e-6)


def test_local_offsets_agree_with_the_great_circle_nearby() -> None:
    """Within a few metres the equirectangular offsets match the haversine distance to 1e-6 m."""
    lat0, lon0 = np.radians(35.0), np.radians(-106.9)
    lat, lon = destination_point(lat0, lon0, np.radians(30.0), 4.6)
    north, east = local_north_east(lat, lon, lat0, lon0)
    assert float(np.hypot(north, east)) == pytest.approx(4.6, abs=1e-6)
    assert float(np.arctan2(east, north)) == pytest.approx(np.radians(30.0), abs=1e-6)


@given(
    north=st.floats(-2000.0, 2000.0),
    east=st.floats(-2000.0, 2000.0),
    lat0_deg=st.floats(-80.0, 80.0),
    lon0_deg=st.floats(-179.0, 179.0),
)
def test_lat_lon_offset_inverts_local_north_east(north: float, east: float, lat0_deg: float, lon0_deg: float) -> None:
    """Offsets out and back come home to 1 µm (the two are exact inverses up to rounding)."""
    lat0, lon0 = np.radians(lat0_deg), np.radians(lon0_deg)
    dlat, dlon = lat_lon_offset(north, east, lat0)
    back_n, back_e = local_north_east(lat0 + dlat, lon0 + dlon, lat0, lon0)
    assert float(back_n) == pytest.approx(north, abs=1e-6)
    assert float(back_e) == pytest.approx(east, abs=1e-6)


def test_lat_lon_offset_keeps_the_shape() -> None:
    dlat, dlon = lat_lon_offset(np.zeros(5), np.ones(5), 0.0)
    assert dlat.shape == dlon.shape == (5,)
    np.testing.assert_allclose(dlon, 1.0 / EARTH_RADIUS_M)
