"""The built-in models: their folder and names."""

from __future__ import annotations

import functools
import importlib.util
import os
import re
from pathlib import Path

#: A top-level ``name = "..."`` line (a basic string without escapes), as pinmob's builder writes it.
_NAME = re.compile(r'^name\s*=\s*"([^"\\]*)"\s*$')


def builtin_dir() -> Path:
    """Folder of the built-in models (``pinmob/models`` installed, ``models/`` in a source checkout)."""
    spec = importlib.util.find_spec("pinmob.models")
    if spec is not None and spec.submodule_search_locations:
        return Path(next(iter(spec.submodule_search_locations)))
    return (
        Path(__file__).resolve().parents[2] / "models"
    )  # a source tree on sys.path before the install (pinmob/io/ -> ./models)


def builtin_models() -> dict[str, Path]:
    """Built-in mechanism names and their files (:func:`models_in` the built-in folder)."""
    return models_in(builtin_dir())


def models_in(folder: Path) -> dict[str, Path]:
    """The mechanism names of the ``*.toml`` files of ``folder`` (:func:`model_name`), in file name order.

    Each file's name is read again only when the file changed (its name, size and modification time are the key
    of the names cached in this process): every ``pinmob.load`` asks for the built-in ones.
    """
    stamps = []
    try:
        listed = sorted(os.scandir(folder), key=lambda e: e.name)  # as sorted(folder.glob("*.toml"))
    except OSError:  # no such folder: no model
        listed = []
    for entry in listed:
        if not entry.name.endswith(".toml"):
            continue
        try:
            stat = entry.stat()
        except OSError:  # removed since the listing: as the listing without it
            continue
        stamps.append((entry.name, stat.st_size, stat.st_mtime_ns))
    return dict(_names(folder, tuple(stamps)))


@functools.lru_cache(maxsize=4)
def _names(folder: Path, stamps: tuple[tuple[str, int, int], ...]) -> tuple[tuple[str, Path], ...]:
    """(name, file) of each built-in file of ``stamps`` (file name in ``folder``, size, modification time)."""
    paths = [folder / file for file, _, _ in stamps]
    return tuple((model_name(path), path) for path in paths)


def model_name(path: Path) -> str:
    """The ``name`` of a mechanism file (its stem when it has none).

    Read from its top-level ``name = "..."`` line when it has one before any table or multi-line string
    (the builder writes it first), without parsing the whole file; otherwise from the parsed file.
    """
    with path.open("rb") as fh:
        data = fh.read()
    for line in data.decode("utf-8", errors="replace").splitlines():
        if line.lstrip().startswith("[") or '"""' in line or "'''" in line:
            break
        match = _NAME.match(line)
        if match:
            return match.group(1)
    import tomllib  # only for a file without a plain name line

    return str(tomllib.loads(data.decode("utf-8")).get("name", path.stem))
