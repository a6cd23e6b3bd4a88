"""Results frozen for real: dataclasses whose numpy arrays are made read-only when they are built."""

from __future__ import annotations

import dataclasses

import numpy as np


class ReadOnlyArrays:
    """Mixin for frozen dataclasses: every numpy array field is made read-only in ``__post_init__``.

    ``result.free_twists[0, 0] = 99`` then raises ``ValueError`` instead of silently changing a result
    (and whatever cache shares the array).
    """

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):  # type: ignore[arg-type]
            value = getattr(self, f.name)
            if isinstance(value, np.ndarray):
                value.flags.writeable = False
