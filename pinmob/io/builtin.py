"""The built-in models: their folder and names."""

from __future__ import annotations

import importlib.util
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
    """Built-in mechanism names and their files."""
    return {model_name(path): path for path in sorted(builtin_dir().glob("*.toml"))}


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
