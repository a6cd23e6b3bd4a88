"""Errors raised by pinmob.

Every message names the bad value and, where there is a finite set of valid
choices, lists them. The command line prints the message on one line and exits
with status 2.
"""

from __future__ import annotations

from collections.abc import Callable


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

    ``note``: a sentence computed when the message is first read (not where nothing reads it: a scan's
    unreachable samples), e.g. which pose coordinates are out of reach.
    """

    def __init__(
        self,
        message: str,
        residuals: dict[str, tuple[float, float]] | None = None,
        note: Callable[[], str] | None = None,
    ):
        super().__init__(message)
        self.residuals = dict(residuals or {})
        self._note = note  # a diagnosis that costs solves, appended when the message is first read

    def __str__(self) -> str:
        if self._note is not None:
            note, self._note = self._note, None
            self.args = (f"{self.args[0]} {note()}",)
        return super().__str__()

    def __reduce__(self) -> tuple[type[ClosureError], tuple[str, dict[str, tuple[float, float]]]]:
        return type(self), (str(self), self.residuals)  # the note resolved: pickled as plain text


class GlossaryError(PinmobError):
    """A term the glossary does not explain (``pinmob glossary TERM``)."""


class ViewerError(PinmobError):
    """The viewer cannot run: meshcat missing, a port in use, no server answering, a file in the way."""


class EngineError(PinmobError):
    """Parallel work cannot go on: no Dask scheduler at an address, every worker lost, a task that kills its workers."""
