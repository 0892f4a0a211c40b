"""Air-relative velocities and climb rate of a flight, for the terms that need them."""

from __future__ import annotations

import numpy as np

from sysid.discrepancy.catalogue._term import averaged
from sysid.discrepancy.series import FlightSeries

__all__ = ["air_velocity", "climb_rate"]

_WIND_AVERAGE_S = 1.0  # the wind felt over the discs: the anemometer's record averaged (see the wind term)


def air_velocity(series: FlightSeries) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Body velocities relative to the air ``(u_a, v_a, w_a)``, m/s, each shape (n,); None without ``u v w``.

    The ground velocities less the logged wind (averaged over 1 s) where there is one; the ground
    velocities in a calm or where no wind is logged.

    Parameters
    ----------
    series : FlightSeries
        The flight.
    """
    if not {"u", "v", "w"} <= set(series.signals):
        return None
    u, v, w = series["u"], series["v"], series["w"]
    if "wind_lon" in series and "wind_lat" in series:
        u = u - averaged(series, series["wind_lon"], _WIND_AVERAGE_S)
        v = v - averaged(series, series["wind_lat"], _WIND_AVERAGE_S)
    return u, v, w


def climb_rate(series: FlightSeries) -> np.ndarray | None:
    """Climb rate, m/s up, shape (n,): ``-vd`` where logged, else ``-w``; None when neither is.

    Parameters
    ----------
    series : FlightSeries
        The flight.
    """
    if "vd" in series:
        return -np.asarray(series["vd"])
    if "w" in series:
        return -np.asarray(series["w"])
    return None
