"""Errors raised by pinmob.

Every message names the bad value and, where there is a finite set of valid
choices, lists them. The command line prints the message on one line and exits
with status 2.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable, Iterable, Mapping, Set


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


def choices(names: Iterable[str], limit: int = 40) -> str:
    """Format valid choices for an error message: ``'a', 'b', 'c'``."""
    items = sorted(set(names))
    shown = ", ".join(repr(n) for n in items[:limit])
    if len(items) > limit:
        shown += f", ... ({len(items) - limit} more)"
    return shown or "(none)"


def did_you_mean(name: str, valid: Iterable[str]) -> str:
    """`` (did you mean 'Delta'?)`` naming the valid names closest to ``name`` (ignoring case); "" when none is close."""
    items = list(dict.fromkeys(valid))
    same = [v for v in items if v.casefold() == name.casefold()]
    by_case = {v.casefold(): v for v in items}
    close = same or [by_case[c] for c in difflib.get_close_matches(name.casefold(), list(by_case), n=3, cutoff=0.6)]
    return f" (did you mean {' or '.join(repr(v) for v in close)}?)" if close else ""


def match_name(
    name: str, valid: Iterable[str], what: str, where: str = "", error: Callable[[str], PinmobError] | None = None
) -> str:
    """The valid name that ``name`` stands for: itself, else the only one equal to it ignoring case.

    Args:
        name: the name given.
        valid: the valid names.
        what: what they name, for the message (``configuration``, ``frame``...).
        where: where they were looked for, for the message (e.g. ``" in '3-PUU'"``).
        error: the exception class raised, called with the message (default :class:`ConfigurationError`).

    Raises:
        PinmobError: no valid name matches (none, or several differing only in case); the message
            suggests the closest ones ("did you mean") and lists every valid name.
    """
    if isinstance(valid, (Mapping, Set)) and name in valid:
        return name  # looked up, not searched: a file with 20,000 configurations names each in constant time
    items = list(dict.fromkeys(valid))
    if name in items:
        return name
    same = [v for v in items if v.casefold() == name.casefold()]
    if len(same) == 1:
        return same[0]
    raise (error or ConfigurationError)(
        f"no {what} {name!r}{where}{did_you_mean(name, items)}; valid: {choices(items)}"
    )


class GlossaryError(PinmobError):
    """A term the glossary does not explain (``pinmob glossary TERM``)."""


class ViewerError(PinmobError):
    """The viewer cannot run: meshcat missing, a port in use, no server answering, a file in the way."""


class EngineError(PinmobError):
    """Parallel work cannot go on: no Dask scheduler at an address, every worker lost, a task that kills its workers."""
