"""Errors raised by pinmob.

Every message names the bad value and, where there is a finite set of valid
choices, lists them. The command line prints the message on one line and exits
with status 2.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Self


class PinmobError(Exception):
    """Base class of every error pinmob raises on purpose.

    Attributes:
        parameters: the Python parameters (e.g. ``closure_tol``) the message names, as ``closure_tol`` or
            ``closure_tol=2e-05``; the command line words them as its options (``--closure-tol 2e-05``).
    """

    parameters: tuple[str, ...] = ()

    def naming(self, *parameters: str) -> Self:
        """This error, saying that its message names these Python parameters (see ``parameters``)."""
        self.parameters = self.parameters + parameters
        return self


class MechanismFileError(PinmobError):
    """A mechanism file is missing, does not parse, or holds an invalid entry."""


class FrameError(PinmobError):
    """A frame or joint name does not exist in the model."""


class ConfigurationError(PinmobError):
    """A configuration vector or a named configuration is invalid, or an argument is (the subclasses tell which)."""


class ArgumentError(ConfigurationError):
    """An argument out of its domain: a tolerance, a count or an order out of range, a value of the wrong type.

    Attributes:
        parameter: the Python parameter given the bad value (e.g. ``"rtol"``), also in ``parameters``.
        value: the value given.
    """

    def __init__(self, message: str, parameter: str, value: object = None) -> None:
        super().__init__(message)
        self.parameter, self.value = parameter, value
        self.parameters = (parameter,)

    def __reduce__(self) -> tuple[type[ArgumentError], tuple[str, str, object]]:
        return type(self), (str(self), self.parameter, self.value)


class UnknownConfigurationError(ConfigurationError):
    """A configuration name that the mechanism does not declare (``name``: the name given)."""

    def __init__(self, message: str, name: str) -> None:
        super().__init__(message)
        self.name = name

    def __reduce__(self) -> tuple[type[UnknownConfigurationError], tuple[str, str]]:
        return type(self), (str(self), self.name)


def unknown(name: str) -> Callable[[str], UnknownConfigurationError]:
    """The error of a message about the unknown configuration ``name`` (as ``match_name``'s ``error``)."""
    return lambda message: UnknownConfigurationError(message, name)


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

    def __reduce__(self) -> tuple[type[ClosureError], tuple[str, dict[str, tuple[float, float]]], dict[str, object]]:
        # the note resolved: pickled as plain text, with the parameters it names
        return type(self), (str(self), self.residuals), {"parameters": self.parameters}


class GlossaryError(PinmobError):
    """A term the glossary does not explain (``pinmob glossary TERM``)."""


class ViewerError(PinmobError):
    """The viewer cannot run: meshcat missing, a port in use, no server answering, a file in the way."""


class EngineError(PinmobError):
    """Parallel work cannot go on: no Dask scheduler at an address, every worker lost, a task that kills its workers."""
