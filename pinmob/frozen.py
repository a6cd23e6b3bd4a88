"""Results frozen for real: dataclasses whose numpy arrays are made read-only when they are built."""

from __future__ import annotations

import dataclasses
from typing import Any

import numpy as np

_FIELDS: dict[type, tuple[str, ...]] = {}

#: Names of the array types in field annotations (``Array`` and ``Mask`` of :mod:`pinmob.screw.algebra`, ``Ints``).
ARRAY_TYPES = ("Array", "Ints", "Mask", "NDArray", "ndarray")


class ReadOnlyArrays:
    """Mixin for frozen dataclasses: every numpy array field is made read-only in ``__post_init__``.

    ``result.free_twists[0, 0] = 99`` then raises ``ValueError`` instead of silently changing a result
    (and whatever cache shares the array). The fields are those annotated as arrays (``Array``,
    ``Ints``, ``NDArray[...]``, optional or not), looked up once per class.
    """

    def __post_init__(self) -> None:
        cls = type(self)
        names = _FIELDS.get(cls)
        if names is None:
            names = _FIELDS[cls] = tuple(
                f.name
                for f in dataclasses.fields(self)  # type: ignore[arg-type]
                if any(kind in str(f.type) for kind in ARRAY_TYPES)
            )
        for name in names:
            value = getattr(self, name)
            if isinstance(value, np.ndarray):
                value.flags.writeable = False


def read_only(value: Any) -> None:
    """Every numpy array in ``value`` (nested in dicts, lists and tuples) made read-only (e.g. after unpickling)."""
    if isinstance(value, np.ndarray):
        value.flags.writeable = False
    elif isinstance(value, dict):
        for item in value.values():
            read_only(item)
    elif isinstance(value, (list, tuple)):
        for item in value:
            read_only(item)
