"""Reading mechanisms: pinmob's TOML + URDF, Extended URDF (YAML sidecar), MJCF, and the built-in models."""

from pinmob.io.builtin import builtin_dir, builtin_models
from pinmob.io.loader import LOADERS, load

__all__ = ["LOADERS", "builtin_dir", "builtin_models", "load"]
