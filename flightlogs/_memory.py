"""Giving freed memory back to the system between the phases of reading a log.

glibc keeps the blocks a phase freed (the decoded tables, the resampler's
working arrays) and maps new pages for the next phase's larger arrays; the
process's resident size then counts both. ``malloc_trim`` returns the free
pages at once (a few milliseconds). Elsewhere (another C library) it does nothing.
"""

from __future__ import annotations

import ctypes
import ctypes.util
from functools import lru_cache
from typing import Any

__all__ = ["give_back_freed_memory"]


def give_back_freed_memory() -> None:
    """Return the pages of freed heap blocks to the system (glibc's ``malloc_trim(0)``); elsewhere nothing."""
    trim = _malloc_trim()
    if trim is not None:
        trim(0)


@lru_cache(maxsize=1)
def _malloc_trim() -> Any:
    """glibc's ``malloc_trim``, or None where the C library has none."""
    try:
        return ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").malloc_trim
    except (OSError, AttributeError):
        return None
