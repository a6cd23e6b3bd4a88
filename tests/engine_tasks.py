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


def exit_on_counting(shared: tuple[int, str], x: int) -> int:
    """As :func:`exit_on` with ``shared = (bad, path)``, adding a line to the file ``path`` each time it exits."""
    bad, path = shared
    if x == bad:
        with open(path, "a") as f:
            f.write("ran\n")
        os._exit(137)
    return x


_UNPICKLED = [0]


class Counted:
    """A payload that counts, per process, how many times it was unpickled."""

    def __init__(self, payload: bytes) -> None:
        self.payload = payload

    def __setstate__(self, state: dict) -> None:
        _UNPICKLED[0] += 1
        self.__dict__.update(state)


def size_plus(shared: Counted, x: int) -> int:
    """``len(shared.payload) + x``."""
    return len(shared.payload) + x


def unpickled() -> int:
    """How many times a :class:`Counted` was unpickled in this process."""
    return _UNPICKLED[0]
