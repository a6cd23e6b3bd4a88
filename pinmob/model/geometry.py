"""A mechanism's visual and collision geometry, loaded when something first draws it.

Loading meshes costs far more than an analysis (the 3-UR5's 21 UR5 meshes take
about a second), and no analysis uses them: a :class:`Geometry` holds either the
geometry models themselves or a picklable loader that builds them from the
mechanism's Pinocchio model on first use (the file readers in :mod:`pinmob.io`
check at load time that the mesh files exist, and warn when they do not).
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

import pinocchio as pin

#: ``model -> (visual, collision)`` geometry models (None where there is none).
GeometryLoader = Callable[[pin.Model], tuple[pin.GeometryModel | None, pin.GeometryModel | None]]


class Geometry:
    """Visual and collision geometry models, given or loaded on first use.

    Args:
        loader: builds ``(visual, collision)`` from the mechanism's model when first asked
            (a module-level function, a :func:`functools.partial` of one, or an object that pickles).
        visual: the visual geometry, when already built (then no loader).
        collision: the collision geometry, when already built.
    """

    def __init__(
        self,
        loader: GeometryLoader | None = None,
        visual: pin.GeometryModel | None = None,
        collision: pin.GeometryModel | None = None,
    ) -> None:
        self._loader = loader
        self._models: tuple[pin.GeometryModel | None, pin.GeometryModel | None] | None = (
            None if loader is not None else (visual, collision)
        )
        self._lock = threading.Lock()

    @property
    def loaded(self) -> bool:
        """The geometry models exist (given, or loaded by a first use)."""
        return self._models is not None

    def models(self, model: pin.Model) -> tuple[pin.GeometryModel | None, pin.GeometryModel | None]:
        """``(visual, collision)`` for ``model``, loaded once (the loader warns about what it cannot load)."""
        with self._lock:
            if self._models is None:
                assert self._loader is not None
                self._models = self._loader(model)
            return self._models

    def __getstate__(self) -> dict[str, Any]:
        """Pickled as its loader when it has one (geometry models are rebuilt on first use)."""
        return {"loader": self._loader, "models": None if self._loader is not None else self._models}

    def __setstate__(self, state: dict[str, Any]) -> None:
        self._loader, self._models, self._lock = state["loader"], state["models"], threading.Lock()

    def __repr__(self) -> str:
        return f"Geometry({'loaded' if self.loaded else 'not loaded yet'})"
