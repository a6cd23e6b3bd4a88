"""Names a mechanism shows on a terminal: printable characters only.

Every name of a mechanism (its own, its limbs', closures', named
configurations', and its model's joints and frames) is printed in reports and
messages. A control character in one (``ESC [2J`` clears the screen, a
carriage return overwrites the line) would act on the user's terminal:
:func:`check_names` refuses such a name, shown escaped (``repr``).
"""

from __future__ import annotations

import unicodedata
from collections.abc import Iterable

import pinocchio as pin

from pinmob.exceptions import ConfigurationError


def printable(name: str) -> bool:
    """No control or format character in ``name`` (Unicode categories Cc, Cf)."""
    if name.isprintable():  # no character of Cc, Cf (nor other non-printable ones): the usual name, at C speed
        return True
    return not any(unicodedata.category(c) in ("Cc", "Cf") for c in name)


def check_names(model: pin.Model, **named: Iterable[str]) -> None:
    """Refuse a non-printable name among ``named`` (names by what they name) and the model's joints and frames.

    Raises:
        ConfigurationError: naming what holds the name, and the name escaped.
    """
    named = {**named, "joint": list(model.names), "frame": [f.name for f in model.frames]}
    for what, names in named.items():
        for name in names:
            if not printable(name):
                raise ConfigurationError(
                    f"{what} name {name!r} holds a control character (a terminal escape or line break); "
                    "names must be printable"
                )
