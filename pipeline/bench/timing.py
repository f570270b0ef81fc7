"""Timing shared by the benchmarks."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

__all__ = ["best_time"]


def best_time(fn: Callable[[], Any], *, repeat: int = 3, min_time: float = 0.0) -> float:
    """Best wall time of ``repeat`` calls (after one warm-up call), in seconds.

    With ``min_time``, stops early once at least two calls have taken that long in all.

    >>> best_time(lambda: None, repeat=2) >= 0.0
    True
    """
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
        if min_time and sum(times) > min_time and len(times) >= 2:
            break
    return min(times)
