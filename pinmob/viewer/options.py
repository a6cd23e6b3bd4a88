"""What a scene shows and how its motions are followed: the options every viewer function takes, declared once.

:func:`pinmob.viewer.show`, :func:`~pinmob.viewer.export_html`, :func:`~pinmob.viewer.scene_html` and
:func:`~pinmob.viewer.notebook` take these as keywords (``motion="T1 x", steps=20``); :func:`view_options`
turns the keywords into a :class:`ViewOptions`, naming any unknown one.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

from pinmob.analysis import FOLLOW_STEPS
from pinmob.exceptions import ArgumentError
from pinmob.name_matching import choices, did_you_mean


@dataclass(frozen=True)
class ViewOptions:
    """The options of a scene (keywords of every viewer function).

    Attributes:
        motion: label of the motion shown first (``T1 x``, matched ignoring case; default: the first).
        wrenches: show the constraint wrenches on opening (they are in the scene, hidden, otherwise).
        amplitude: distance of each motion [m for T, rad for R/H]; default 0.2 L or 0.35 rad.
        steps: continuation steps per direction.
        animate: follow the motions; False shows them as still glyphs only.
        finite: tell each motion's finite verdict (:mod:`pinmob.analysis.finite.finite_mobility`); a motion that
            exists only to first order is drawn as such (grey glyph pulsing in its clip, the panel says so).
    """

    motion: str | None = None
    wrenches: bool = False
    amplitude: float | None = None
    steps: int = FOLLOW_STEPS
    animate: bool = True
    finite: bool = True


#: the option names, in their declaration order
VIEW_OPTIONS = tuple(f.name for f in fields(ViewOptions))


def view_options(**options: Any) -> ViewOptions:
    """The :class:`ViewOptions` of keywords given to a viewer function (the defaults for the others).

    Raises:
        ArgumentError: a keyword that is not an option (the message lists them).
    """
    for name in options:
        if name not in VIEW_OPTIONS:
            raise ArgumentError(
                f"unknown viewer option {name!r}{did_you_mean(name, VIEW_OPTIONS)}; valid: {choices(VIEW_OPTIONS)}",
                name,
                options[name],
            )
    return ViewOptions(**options)
