"""Progress of long steps: the core says what it is doing, a listener (the command line) shows it.

The analyses, the closure solver's restarts and relaxation, and the viewer's
motion following run :func:`step` around their loops::

    with step("closing the loops: random restarts", total=restarts + 1) as bar:
        for k in range(restarts + 1):
            ...
            bar.update()

Nothing is shown unless a listener is installed with :func:`reporting` (a
context variable, so threads and library users are unaffected): ``pinmob``'s
command line installs one that draws a bar on stderr when stderr is a terminal
and the step has lasted more than two seconds (:mod:`pinmob.cli.progress_bar`).
This module imports nothing: every layer may use it.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from typing import Protocol


class Bar(Protocol):
    """What a step reports to: a tqdm bar has these methods."""

    def update(self, n: int = 1) -> object:
        """``n`` more units done."""

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        """A short note on the current unit (e.g. the motion being followed)."""

    def close(self) -> None:
        """The step is over."""


#: makes a :class:`Bar` for a step: ``(description, total or None)``
BarFactory = Callable[[str, "int | None"], Bar]


class _Silent:
    """The bar used when nobody listens."""

    def update(self, n: int = 1) -> None:
        """Nothing."""

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        """Nothing."""

    def close(self) -> None:
        """Nothing."""


_FACTORY: ContextVar[BarFactory | None] = ContextVar("pinmob_progress", default=None)


@contextlib.contextmanager
def reporting(factory: BarFactory | None) -> Iterator[None]:
    """Within the block, every :func:`step` reports to a bar made by ``factory`` (None: silence)."""
    token = _FACTORY.set(factory)
    try:
        yield
    finally:
        _FACTORY.reset(token)


@contextlib.contextmanager
def step(description: str, total: int | None = None) -> Iterator[Bar]:
    """A step that may take long: yields a :class:`Bar` to ``update()`` as units get done.

    Args:
        description: what is being done, e.g. ``"following the free motions"``.
        total: how many units (None when unknown).
    """
    factory = _FACTORY.get()
    bar: Bar = _Silent() if factory is None else factory(description, total)
    try:
        yield bar
    finally:
        bar.close()
