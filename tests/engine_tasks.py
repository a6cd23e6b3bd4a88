"""Task functions the engine tests send to real Dask workers (importable by name on the workers)."""

from __future__ import annotations

import os
import time


def slow_square(delay: float, x: int) -> int:
    """``x * x`` after ``delay`` seconds (long enough to kill the worker running it)."""
    time.sleep(delay)
    return x * x


def exit_on(bad: int, x: int) -> int:
    """Ends the worker process running it when ``x == bad`` (as the out-of-memory killer would); else ``x``."""
    if x == bad:
        os._exit(137)
    return x
