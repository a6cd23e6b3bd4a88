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

import hashlib
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


def called_sources(fn: Callable[..., Any]) -> set[str]:
    """The source files of ``fn`` and of the compiled functions it calls by a global name, transitively.

    numba stamps a cached function with its own file only: a compiled function it calls from another file (such as
    ``advance = njit(plain_advance)``) is compiled into it, and an edit of that file alone left the old code
    running from the cache.
    """
    files: set[str] = set()
    todo, seen = [fn], set()
    while todo:
        f = todo.pop()
        if f in seen:
            continue
        seen.add(f)
        files.add(f.__code__.co_filename)
        for name in f.__code__.co_names:
            called = getattr(f.__globals__.get(name), "py_func", None)  # a numba dispatcher's Python function
            if callable(called):
                todo.append(called)
    return files


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
        """numba's user-wide locator (disambiguator, writability check) under :func:`cache_dir`.

        Its source stamp covers the files of the compiled functions the function calls too (:func:`called_sources`).
        """

        def __init__(self, py_func: Callable[..., Any], py_file: str) -> None:
            super().__init__(py_func, py_file)
            self._py_func = py_func
            self._cache_path = str(cache_dir() / self.get_suitable_cache_subpath(py_file))

        def get_source_stamp(self) -> Any:
            others = sorted(called_sources(self._py_func) - {self._py_file})
            return (super().get_source_stamp(), *(hashlib.sha256(Path(f).read_bytes()).digest() for f in others))

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
