"""A process-wide setting held while any block of it runs: :class:`HeldSetting`.

The base of :data:`pinmob.blas.one_blas_thread` and :data:`pinmob.collector.collector_paused`: a context manager and
decorator, re-entrant and thread-safe, that changes a setting of the whole process when the first block begins
(:meth:`HeldSetting._hold`, which saves what it changed) and puts it back when the last one ends
(:meth:`HeldSetting._release`); nested or concurrent blocks cost a counter.
"""

from __future__ import annotations

import threading
from contextlib import ContextDecorator
from typing import Self


class HeldSetting(ContextDecorator):
    """Holds a process-wide setting from the first block's start to the last block's end (module docstring)."""

    def __init__(self) -> None:
        self._depth = 0
        self._lock = threading.Lock()

    def _hold(self) -> None:
        """Change the setting, saving what it was (the first block begins)."""
        raise NotImplementedError

    def _release(self) -> None:
        """Put the setting back as :meth:`_hold` found it (the last block ends)."""
        raise NotImplementedError

    def __enter__(self) -> Self:
        with self._lock:
            self._depth += 1
            if self._depth == 1:
                self._hold()
        return self

    def __exit__(self, *exc: object) -> None:
        with self._lock:
            self._depth -= 1
            if self._depth == 0:
                self._release()

    @property
    def active(self) -> bool:
        """True inside a block (the setting is held)."""
        return self._depth > 0
