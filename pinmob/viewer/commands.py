"""meshcat commands pinmob sends besides meshcat's own: the animation clips (pinmob's panel: :mod:`.panel`)."""

from __future__ import annotations

from typing import Any


class SetAnimation:
    """meshcat's ``set_animation`` command from already lowered clips (``[{path, clip}]``)."""

    def __init__(self, animations: list[dict[str, Any]]):
        self.animations = animations

    def lower(self) -> dict[str, Any]:
        """The command as meshcat sends it (a dictionary packed with msgpack)."""
        options = {"play": True, "repetitions": float("inf")}
        return {"type": "set_animation", "animations": self.animations, "options": options, "path": ""}
