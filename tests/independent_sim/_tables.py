"""Reference figures of chapter 3 of the dissertation (Tables 3.2, 3.3 and 3.5), as data."""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

__all__ = ["TABLE_3_3", "TRIM_PITCH_DEG", "MEAN_WIND"]

#: Table 3.3 (control derivatives per % of the mixer range) and Table 3.5, by wind condition.
#: N_r is 0 where the table has "—"; the delays it leaves out (tau_yaw, tau_thr) are not here.
TABLE_3_3: Mapping[str, Mapping[str, float]] = MappingProxyType(
    {
        "calm": MappingProxyType(
            {
                "X_u": -0.3172,
                "M_u": 0.7690,
                "X_lon": -0.0985,
                "M_lon": 0.5251,
                "Y_v": -0.2787,
                "L_v": -0.7406,
                "Y_lat": 0.1185,
                "L_lat": 0.6226,
                "N_r": 0.0,
                "N_yaw": 0.0744,
                "Z_thr": -0.8712,
                "T_a": 0.0458,
                "tau_lat": 0.0194,
                "tau_lon": 0.0201,
            }
        ),
        "light": MappingProxyType(
            {
                "X_u": -0.2423,
                "M_u": 0.7099,
                "X_lon": -0.0976,
                "M_lon": 0.5413,
                "Y_v": -0.3905,
                "L_v": -0.7984,
                "Y_lat": 0.1193,
                "L_lat": 0.6472,
                "N_r": 0.0,
                "N_yaw": 0.0719,
                "Z_thr": -0.8777,
                "T_a": 0.0458,
                "tau_lat": 0.0160,
                "tau_lon": 0.0220,
                "X_w_lon": -0.1486,
                "Z_w_lon": 0.8451,
                "tau_w_lon": 0.0178,
                "tau_w_thr": 0.0386,
            }
        ),
        "strong": MappingProxyType(
            {
                "X_u": -0.5008,
                "M_u": 1.267,
                "X_lon": -0.0870,
                "M_lon": 0.4523,
                "Y_v": -0.2519,
                "L_v": -0.7344,
                "Y_lat": 0.1194,
                "L_lat": 0.6597,
                "N_r": -0.2543,
                "N_yaw": 0.0631,
                "Z_thr": -0.8531,
                "T_a": 0.0458,
                "tau_lat": 0.0216,
                "tau_lon": 0.0193,
                "X_w_lon": -0.3560,
                "Z_w_lon": 1.323,
                "tau_w_lon": 0.0132,
                "tau_w_thr": 0.0203,
            }
        ),
    }
)
#: Table 3.2: trim pitch, degrees; and the mean wind of each day, m/s (section 3.3.3).
TRIM_PITCH_DEG = MappingProxyType({"calm": 0.0, "light": -2.35, "strong": -4.36})
MEAN_WIND = MappingProxyType({"calm": 0.0, "light": 2.7, "strong": 5.4})
