"""Parametrize lists of the built-in models, read from their TOML files (tomllib): no model is loaded at collection.

Loading a model parses its URDF and meshes (50 ms each, 54 loads made collection take 4-12 s); the tests load
the models they run, lazily.
"""

from __future__ import annotations

import tomllib

import pinmob


def _documents() -> dict[str, dict]:
    return {name: tomllib.loads(path.read_text()) for name, path in pinmob.builtin_models().items()}


def model_configurations() -> list[tuple[str, str]]:
    """(model name, configuration name) of every built-in model and named configuration, models sorted by name."""
    return [(name, c) for name, doc in sorted(_documents().items()) for c in doc.get("configurations", {})]


def models_with_closures() -> set[str]:
    """Names of the built-in models whose file declares ``[[closures]]`` (loops inside limbs or between chains)."""
    return {name for name, doc in _documents().items() if doc.get("closures")}
