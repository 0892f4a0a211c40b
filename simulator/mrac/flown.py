"""The rise times chapter 2 flew (Tables 2.6-2.8), to show beside the simulation's."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

__all__ = ["FlownRiseTime", "FLOWN_RISE_TIMES", "flown_rise_time"]


@dataclass(frozen=True, slots=True, kw_only=True)
class FlownRiseTime:
    """Mean rise times of one case of the chapter's flight tests, s.

    Parameters
    ----------
    height_ratio : float
        Z/R of the case (4, 3 or 2).
    phase : {"takeoff", "landing"}
        The step.
    pid_s, linear_s, rbf_s : float or None
        PID, MRAC with the linear regressor, MRAC with RBFs; None where the table has no figure (the PID
        did not touch down within its 40 s at Z/R 2).
    """

    height_ratio: float
    phase: Literal["takeoff", "landing"]
    pid_s: float | None
    linear_s: float | None
    rbf_s: float | None

    def cut(self, controller: str) -> float | None:
        """The MRAC's (``"mrac_linear"`` or ``"mrac_rbf"``) rise time over the PID's, or None where either is missing."""
        mrac = {"mrac_linear": self.linear_s, "mrac_rbf": self.rbf_s}[controller]
        return None if mrac is None or self.pid_s is None else mrac / self.pid_s


#: Tables 2.6 (Z/R = 4), 2.7 (3) and 2.8 (2), "Rise time (sec)" rows, means over the trials.
FLOWN_RISE_TIMES: tuple[FlownRiseTime, ...] = (
    FlownRiseTime(height_ratio=4.0, phase="takeoff", pid_s=22.40, linear_s=4.53, rbf_s=2.99),
    FlownRiseTime(height_ratio=4.0, phase="landing", pid_s=25.72, linear_s=4.99, rbf_s=3.86),
    FlownRiseTime(height_ratio=3.0, phase="takeoff", pid_s=25.86, linear_s=4.58, rbf_s=3.15),
    FlownRiseTime(height_ratio=3.0, phase="landing", pid_s=27.62, linear_s=5.23, rbf_s=3.53),
    FlownRiseTime(height_ratio=2.0, phase="takeoff", pid_s=31.07, linear_s=4.90, rbf_s=3.50),
    FlownRiseTime(height_ratio=2.0, phase="landing", pid_s=None, linear_s=4.11, rbf_s=3.51),
)


def flown_rise_time(height_ratio: float, phase: str) -> FlownRiseTime | None:
    """The chapter's figures for a case, or None for a case it did not fly (Z/R 22).

    Parameters
    ----------
    height_ratio : float
        Z/R of the case.
    phase : {"takeoff", "landing"}
        The step.

    Returns
    -------
    FlownRiseTime or None

    Examples
    --------
    >>> round(flown_rise_time(4.0, "takeoff").cut("mrac_rbf"), 3)
    0.133
    """
    return next((f for f in FLOWN_RISE_TIMES if f.height_ratio == height_ratio and f.phase == phase), None)
