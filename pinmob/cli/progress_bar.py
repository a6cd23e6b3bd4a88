"""The command line's progress bars: tqdm on stderr, only on a terminal, only for steps longer than two seconds.

tqdm is imported when a step has lasted that long, not before: its import (about 13 ms, most of it
``importlib.metadata``) would otherwise be part of every ``pinmob analyze``, whose steps are short.
"""

from __future__ import annotations

import math
import os
import sys
import time
from typing import Any, TextIO

from pinmob.exceptions import ConfigurationError
from pinmob.progress import Bar, BarFactory

#: seconds a step runs before its bar appears (``PINMOB_PROGRESS_DELAY`` sets another)
DELAY = 2.0


def delay() -> float:
    """Seconds a step runs before its bar appears: ``PINMOB_PROGRESS_DELAY`` when set, else :data:`DELAY`.

    Raises:
        ConfigurationError: the variable is not a finite number of seconds >= 0.
    """
    text = os.environ.get("PINMOB_PROGRESS_DELAY", "").strip()
    if not text:
        return DELAY
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise ConfigurationError(f"PINMOB_PROGRESS_DELAY must be a number of seconds >= 0 (e.g. 2), got {text[:40]!r}")
    return value


class LateBar:
    """A :class:`pinmob.progress.Bar` that opens a tqdm bar once its step has lasted ``delay`` seconds.

    The units done and the last note before that are carried into the tqdm bar when it opens; on a
    stream that is not a terminal it never opens.

    Args:
        description: what the step does (after ``pinmob: `` in the bar).
        total: how many units (None when unknown).
        delay: seconds before the bar appears.
        stream: where the bar is drawn (``sys.stderr`` when None).
    """

    def __init__(self, description: str, total: int | None, delay: float = DELAY, stream: TextIO | None = None):
        self._description, self._total, self._delay = description, total, delay
        self._stream = sys.stderr if stream is None else stream
        self._start = time.monotonic()
        self._done = 0
        self._note = ""
        self._bar: Any = None

    def _opened(self) -> bool:
        """True when the tqdm bar is open, opening it when the delay has passed on a terminal."""
        if self._bar is None and time.monotonic() - self._start >= self._delay and self._stream.isatty():
            from tqdm import tqdm

            self._bar = tqdm(
                total=self._total,
                initial=self._done,
                desc=f"pinmob: {self._description}",
                leave=False,
                file=self._stream,
            )
            if self._note:
                self._bar.set_postfix_str(self._note)
            return False  # opened with what is done so far
        return self._bar is not None

    def update(self, n: int = 1) -> None:
        """``n`` more units done."""
        self._done += n
        if self._opened():
            self._bar.update(n)

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        """A short note on the current unit."""
        self._note = s
        if self._opened():
            self._bar.set_postfix_str(s, refresh=refresh)

    def close(self) -> None:
        """The step is over: the bar, if it opened, is cleared."""
        if self._bar is not None:
            self._bar.close()


def terminal_bars() -> BarFactory:
    """The command line's bar factory (:func:`pinmob.progress.reporting`): a :class:`LateBar` on stderr per step.

    The delay is read once, here (:func:`delay`), so that a wrong ``PINMOB_PROGRESS_DELAY`` is reported
    before the command starts.
    """
    seconds = delay()

    def bar(description: str, total: int | None) -> Bar:
        return LateBar(description, total, seconds)

    return bar
