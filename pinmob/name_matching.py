"""Name matching for messages: the valid name a user meant (any case), "did you mean", the valid choices listed.

Every message that names a bad value lists the valid ones (:func:`choices`); a name given in the wrong case
stands for the valid one when only one matches (:func:`match_name`), and a misspelt one gets the closest
valid names suggested (:func:`did_you_mean`).
"""

from __future__ import annotations

import difflib
from collections.abc import Callable, Iterable, Mapping, Set

from pinmob.exceptions import ConfigurationError, PinmobError


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
