"""The octocopter X mixer: how the four mixer inputs become eight motor commands (logs and motor saturation)."""

from __future__ import annotations

import numpy as np

__all__ = ["MOTOR_ANGLES_RAD", "ROLL_ARM", "PITCH_ARM", "YAW_SPIN", "MOTOR_MIX", "UNMIX"]

#: Motor k at 22.5° + 45° k clockwise from the nose, rad.
MOTOR_ANGLES_RAD = np.radians(22.5 + 45.0 * np.arange(8))
#: Share of the roll, pitch and yaw inputs each motor takes (before the mixer's gains), alternating spin.
ROLL_ARM = -np.sin(MOTOR_ANGLES_RAD)
PITCH_ARM = np.cos(MOTOR_ANGLES_RAD)
YAW_SPIN = np.array([1.0, -1.0] * 4)

#: Motor commands from the mixer inputs ``(delta_lat, delta_lon, delta_yaw, delta_thr)``, shape (8, 4):
#: ``thrust + 0.5 (roll, pitch) + 0.3 yaw`` per motor.
MOTOR_MIX = np.column_stack([0.5 * ROLL_ARM, 0.5 * PITCH_ARM, 0.3 * YAW_SPIN, np.ones(8)])
#: Least-squares inverse of :data:`MOTOR_MIX`, shape (4, 8): the mixer inputs eight motor outputs amount to.
UNMIX = np.linalg.pinv(MOTOR_MIX)
