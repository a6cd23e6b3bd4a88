"""Errors raised by pinmob.

Every message names the bad value and, where there is a finite set of valid
choices, lists them. The command line prints the message on one line and exits
with status 2.
"""

from __future__ import annotations

from collections.abc import Iterable


class PinmobError(Exception):
    """Base class of every error pinmob raises on purpose."""


class MechanismFileError(PinmobError):
    """A mechanism file is missing, does not parse, or holds an invalid entry."""


class FrameError(PinmobError):
    """A frame or joint name does not exist in the model."""


class ConfigurationError(PinmobError):
    """A configuration vector or a named configuration is invalid."""


class ClosureError(PinmobError):
    """A configuration does not close the loops, or the closure solver failed.

    Attributes:
        residuals: per limb (or closure) name, the residual norm (position [m],
            rotation [rad]) at the returned or rejected configuration.
    """

    def __init__(self, message: str, residuals: dict[str, tuple[float, float]] | None = None):
        super().__init__(message)
        self.residuals = dict(residuals or {})


def choices(names: Iterable[str], limit: int = 40) -> str:
    """Format valid choices for an error message: ``'a', 'b', 'c'``."""
    items = sorted(set(names))
    shown = ", ".join(repr(n) for n in items[:limit])
    if len(items) > limit:
        shown += f", ... ({len(items) - limit} more)"
    return shown or "(none)"


class ViewerError(PinmobError):
    """The viewer cannot run: meshcat missing, a port in use, no server answering, a file in the way."""


class EngineError(PinmobError):
    """Parallel work cannot go on: no Dask scheduler at an address, every worker lost, a task that kills its workers."""
