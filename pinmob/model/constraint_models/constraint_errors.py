"""What goes wrong between pinmob and Pinocchio's constraint models: an error in, a warning out."""

from __future__ import annotations

from pinmob.exceptions import ConfigurationError


class ConstraintModelError(ConfigurationError):
    """A Pinocchio constraint model pinmob cannot read (the message names it and says why).

    Attributes:
        constraint: the constraint's name (or ``constraint_models[i]`` for one without a name).
    """

    def __init__(self, message: str, constraint: str = "") -> None:
        super().__init__(message)
        self.constraint = constraint

    def __reduce__(self) -> tuple[type[ConstraintModelError], tuple[str, str]]:
        return type(self), (str(self), self.constraint)


class PinocchioExportWarning(UserWarning):
    """Closures that Pinocchio has no constraint model for, and what :func:`to_pinocchio` put instead."""
