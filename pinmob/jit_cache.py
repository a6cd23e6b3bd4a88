"""numba-compiled functions whose on-disk cache is a per-user folder, never the installed package.

``numba.njit(cache=True)`` writes its cache next to the source file when that
folder is writable: into ``site-packages/pinmob/__pycache__`` of a regular
install, files pip does not know about (they survive ``pip uninstall``, and the
left-over ``site-packages/pinmob`` folder then shadows a later editable install
of the same environment). :func:`njit` compiles the same way, with the cache in
:func:`cache_dir` instead:

* ``$NUMBA_CACHE_DIR`` when the user set numba's own setting;
* else ``$XDG_CACHE_HOME/pinmob/numba`` (default ``~/.cache/pinmob/numba``;
  ``%LOCALAPPDATA%/pinmob/numba`` on Windows, ``~/Library/Caches/pinmob/numba``
  on macOS), one sub-folder per installation (numba names it after the source
  folder's path, so two environments never share compiled code).

When that folder cannot be created or written, or this numba version lays out
its cache classes differently, the functions are compiled in every process (a
few seconds each time) instead of cached. No environment variable and no
numba setting is changed: other numba users in the same process are not affected.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba


def cache_dir() -> Path:
    """The folder of pinmob's numba cache (without numba's per-installation sub-folder); see the module docstring."""
    configured = getattr(numba.config, "CACHE_DIR", "")  # NUMBA_CACHE_DIR, read by numba at import
    if configured:
        return Path(configured)
    xdg = os.environ.get("XDG_CACHE_HOME", "")
    if xdg and os.path.isabs(xdg):
        base = Path(xdg)
    elif os.name == "nt":
        base = Path(os.environ.get("LOCALAPPDATA") or Path.home() / "AppData" / "Local")
    elif sys.platform == "darwin":
        base = Path.home() / "Library" / "Caches"
    else:
        base = Path.home() / ".cache"
    return base / "pinmob" / "numba"


def _cache_class() -> type | None:
    """A numba ``FunctionCache`` whose only locator is :func:`cache_dir`, or None if numba's layout differs."""
    try:
        from numba.core import caching

        names = vars(caching)  # the locator lost its leading underscore in numba 0.61
        user_wide = names.get("UserWideCacheLocator") or names["_UserWideCacheLocator"]
        results = caching.CompileResultCacheImpl
        functions = caching.FunctionCache
    except (ImportError, AttributeError, KeyError):
        return None

    class Locator(user_wide):  # type: ignore[misc, valid-type]
        """numba's user-wide locator (source stamp, disambiguator, writability check) under :func:`cache_dir`."""

        def __init__(self, py_func: Callable[..., Any], py_file: str) -> None:
            super().__init__(py_func, py_file)
            self._cache_path = str(cache_dir() / self.get_suitable_cache_subpath(py_file))

    class Impl(results):  # type: ignore[misc, valid-type]
        _locator_classes = [Locator]

    class Cache(functions):  # type: ignore[misc, valid-type]
        _impl_class = Impl

    return Cache


_CACHE = _cache_class()


def njit(fn: Callable[..., Any]) -> Any:
    """``numba.njit(fn)`` with its compiled code cached in :func:`cache_dir` (or not at all: module docstring)."""
    dispatcher = numba.njit(fn)  # not cache=True: numba would choose the package's own __pycache__
    if _CACHE is not None:
        try:
            dispatcher._cache = _CACHE(dispatcher.py_func)  # type: ignore[attr-defined]
        except (RuntimeError, OSError):  # no writable cache folder: compile in each process
            pass
    return dispatcher
