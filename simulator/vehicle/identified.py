"""The chapter 3 octocopter as identified: Table 3.3 hover derivatives and Table 3.5 wind terms.

The truth the linear flights fly and the nonlinear presets are built to match.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

__all__ = ["G", "CALM_HOVER", "LIGHT_WIND_TERMS", "STRONG_WIND_TERMS", "wind_terms_for"]

#: Standard gravity, m/s².
G = 9.81

#: Table 3.3, calm wind (per % of mixer input; time constants and delays in s).
CALM_HOVER: Mapping[str, float] = MappingProxyType(
    {
        "X_u": -0.3172,
        "M_u": 0.7690,
        "X_lon": -0.0985,
        "M_lon": 0.5251,
        "Y_v": -0.2787,
        "L_v": -0.7406,
        "Y_lat": 0.1185,
        "L_lat": 0.6226,
        "N_yaw": 0.0744,
        "Z_thr": -0.8712,
        "T_a": 0.0458,
        "tau_lat": 0.0194,
        "tau_lon": 0.0201,
        "tau_yaw": 0.0133,
        "tau_thr": 0.0,
    }
)
#: Table 3.5, light wind: effect of the along-nose wind on u and w.
LIGHT_WIND_TERMS: Mapping[str, float] = MappingProxyType(
    {"X_w_lon": -0.1486, "Z_w_lon": 0.8451, "tau_w_lon": 0.0178, "tau_w_thr": 0.0386}
)
#: Table 3.5, strong wind.
STRONG_WIND_TERMS: Mapping[str, float] = MappingProxyType(
    {"X_w_lon": -0.3560, "Z_w_lon": 1.323, "tau_w_lon": 0.0132, "tau_w_thr": 0.0203}
)


def wind_terms_for(mean_speed_m_s: float) -> Mapping[str, float] | None:
    """The Table 3.5 wind terms of the nearest identified condition (none in a calm).

    Parameters
    ----------
    mean_speed_m_s : float
        Mean wind speed, m/s; the dissertation's calm, light and strong were
        0.9, 2.7 and 5.4 m/s.
    """
    if mean_speed_m_s < 1.8:
        return None
    return LIGHT_WIND_TERMS if mean_speed_m_s < 4.05 else STRONG_WIND_TERMS
