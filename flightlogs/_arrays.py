"""Values keyed by an array's contents: signals of one message share equal time arrays (not always one object)."""

from __future__ import annotations

from typing import Generic, TypeVar

import numpy as np

__all__ = ["ByContents"]

_T = TypeVar("_T")


class ByContents(Generic[_T]):
    """A small map from 1-D arrays, compared by value (the same object found at once), to values."""

    def __init__(self) -> None:
        self._stored: dict[tuple[int, float, float], list[tuple[np.ndarray, _T]]] = {}

    @staticmethod
    def _key(array: np.ndarray) -> tuple[int, float, float]:
        return (array.size, float(array[0]), float(array[-1])) if array.size else (0, 0.0, 0.0)

    def get(self, array: np.ndarray) -> _T | None:
        """The value stored under an array equal to `array`, or None."""
        for stored, value in self._stored.get(self._key(array), ()):
            if stored is array or np.array_equal(stored, array):
                return value
        return None

    def put(self, array: np.ndarray, value: _T) -> None:
        """Store `value` under `array` (kept by reference)."""
        self._stored.setdefault(self._key(array), []).append((array, value))
