"""The built-in models: their folder and names."""

from __future__ import annotations

import tomllib
from importlib import resources
from pathlib import Path


def builtin_dir() -> Path:
    """Folder of the built-in models (``pinmob/models`` installed, ``models/`` in a source checkout)."""
    try:
        return Path(str(resources.files("pinmob.models")))
    except ModuleNotFoundError:  # running from a source tree that is not installed
        return Path(__file__).resolve().parent.parent / "models"


def builtin_models() -> dict[str, Path]:
    """Built-in mechanism names and their files."""
    out = {}
    for path in sorted(builtin_dir().glob("*.toml")):
        with path.open("rb") as fh:
            out[str(tomllib.load(fh).get("name", path.stem))] = path
    return out
