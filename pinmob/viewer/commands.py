"""meshcat commands pinmob sends besides meshcat's own: the motion menu and the animation clips."""

from __future__ import annotations

import json
from typing import Any


class SetControl:
    """meshcat's ``set_control`` command: a GUI control calling ``callback`` (JavaScript).

    ``options`` are the menu's values, or a mapping of the texts shown to the values.
    """

    def __init__(self, name: str, callback: str, value: str, options: list[str] | dict[str, str]):
        self.name, self.callback, self.value, self.options = name, callback, value, options

    def lower(self) -> dict[str, Any]:
        """The command as meshcat sends it (a dictionary packed with msgpack)."""
        return {
            "type": "set_control",
            "name": self.name,
            "callback": self.callback,
            "value": self.value,
            "min": self.options,
            "path": "",
        }


class DeleteControl:
    """meshcat's ``delete_control`` command: remove the GUI control ``name`` (a scene without motions)."""

    def __init__(self, name: str):
        self.name = name

    def lower(self) -> dict[str, Any]:
        """The command as meshcat sends it (a dictionary packed with msgpack)."""
        return {"type": "delete_control", "name": self.name, "path": ""}


class SetAnimation:
    """meshcat's ``set_animation`` command from already lowered clips (``[{path, clip}]``)."""

    def __init__(self, animations: list[dict[str, Any]]):
        self.animations = animations

    def lower(self) -> dict[str, Any]:
        """The command as meshcat sends it (a dictionary packed with msgpack)."""
        options = {"play": True, "repetitions": float("inf")}
        return {"type": "set_animation", "animations": self.animations, "options": options, "path": ""}


def selector_callback(clips: dict[str, list[dict[str, Any]]], visible: str) -> str:
    """JavaScript of the motion menu: load the chosen clip (all clips move the one mechanism).

    Evaluated by meshcat when the control is created: it loads the visible clip
    at once (so a page that receives the control later still plays the right
    one) and returns the menu's callback.
    """
    return (
        "(() => { const clips = " + json.dumps(clips, separators=(",", ":")) + "; "
        "const choose = (value) => { viewer.handle_command({type: 'set_animation', "
        "animations: JSON.parse(JSON.stringify(clips[value])), options: {play: true, repetitions: Infinity}}); "
        "viewer.set_dirty(); }; "
        "choose(" + json.dumps(visible) + "); return choose; })()"
    )
