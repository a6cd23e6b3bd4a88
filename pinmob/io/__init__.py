"""Reading mechanisms: pinmob's TOML + URDF, Extended URDF (YAML sidecar), MJCF, and the built-in models.

Writing them again with other closures (``pinmob fix``), and TOML strings and keys as a parser reads them back.
"""

from pinmob.io.builtin import builtin_dir, builtin_models
from pinmob.io.extended_urdf import sidecar_urdf
from pinmob.io.fixed_files import fixed_mjcf, fixed_sidecar, fixed_toml
from pinmob.io.loader import LOADERS, load
from pinmob.io.mjcf import compile_mjcf
from pinmob.io.schema import toml_key, toml_string
from pinmob.io.toml_file import load_toml, read_toml
from pinmob.io.xacro_file import parse_xacro_args

__all__ = [
    "LOADERS",
    "builtin_dir",
    "builtin_models",
    "compile_mjcf",
    "fixed_mjcf",
    "fixed_sidecar",
    "fixed_toml",
    "load",
    "load_toml",
    "parse_xacro_args",
    "read_toml",
    "sidecar_urdf",
    "toml_key",
    "toml_string",
]
