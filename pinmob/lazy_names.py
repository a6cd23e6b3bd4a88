"""Names a package's face exports without importing their modules until one is read (PEP 562)."""

from __future__ import annotations

import importlib
from collections.abc import Callable
from typing import Any


def lazy_getattr(package: str, names: dict[str, str]) -> Callable[[str], Any]:
    """The module ``__getattr__`` of ``package``'s face: each of ``names`` (name -> module) imported when first read.

    A face assigns it (``__getattr__ = lazy_getattr(__name__, _LAZY)``) and imports the names under
    ``TYPE_CHECKING`` for the type checker; any other name raises ``AttributeError``, as a module does.
    """

    def __getattr__(name: str) -> Any:
        if name in names:
            return getattr(importlib.import_module(names[name]), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__
