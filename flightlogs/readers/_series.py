"""Shared helpers readers use to turn raw columns into canonical signals."""

from __future__ import annotations

import warnings

import numpy as np

from flightlogs.errors import DataQualityWarning
from flightlogs.flightlog import Signal

__all__: list[str] = []


def make_signal(name: str, time_s: np.ndarray, values: np.ndarray, unit: str, source: str) -> Signal | None:
    """Build a Signal, dropping non-finite samples and out-of-order timestamps.

    Drops are warned about once per signal (:class:`DataQualityWarning`); a
    signal with no sample left is omitted (it will be reported missing).
    """
    time_s = np.asarray(time_s, dtype=np.float64)
    values = np.asarray(values)  # a float32 field stays float32 in the Signal (exact, half the memory)
    if values.dtype.kind not in "fiub":
        values = values.astype(np.float64)
    keep = np.isfinite(time_s) & np.isfinite(values)
    if time_s.size:
        # keep only samples that move time forward (drop duplicates and jumps back)
        running_max = np.maximum.accumulate(np.where(np.isfinite(time_s), time_s, -np.inf))
        forward = np.ones(time_s.size, dtype=bool)
        forward[1:] = time_s[1:] > running_max[:-1]
        keep &= forward
    dropped = int(time_s.size - keep.sum())
    if dropped:
        message = (
            f"{source}: dropped {dropped} of {time_s.size} samples (non-finite values or timestamps not increasing)"
        )
        warnings.warn(DataQualityWarning(message), stacklevel=2)
    if not keep.any():
        return None
    if dropped:
        time_s, values = time_s[keep], values[keep]
    return Signal(name=name, time_s=time_s, values=values, unit=unit, source=source)  # a message's times: shared
