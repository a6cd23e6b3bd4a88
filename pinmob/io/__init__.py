"""Reading mechanisms: pinmob's TOML + URDF, Extended URDF (YAML sidecar), MJCF, and the built-in models.

Writing them again with other closures (``pinmob fix``), and TOML strings and keys as a parser reads them back
(:func:`unicode_text` refuses a str that no UTF-8 file can hold).

``pinmob.load`` of a built-in model or a TOML file needs only the TOML reader: the other formats' readers and
writers (Extended URDF, MJCF, xacro, the fixed files of ``pinmob fix``) load when one of their names is first
read (:data:`_LAZY`), as :func:`pinmob.io.loader.load` imports them for a file of their format.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pinmob.io.builtin import builtin_dir, builtin_models
from pinmob.io.loader import LOADERS, load
from pinmob.io.schema import toml_key, toml_string, unicode_text
from pinmob.io.toml_file import load_toml, read_toml
from pinmob.lazy_names import lazy_getattr

if TYPE_CHECKING:  # the other formats' modules load when first used (see _LAZY)
    from pinmob.io.extended_urdf import read_sidecar, sidecar_urdf
    from pinmob.io.fixed_files import fixed_mjcf, fixed_sidecar, fixed_toml
    from pinmob.io.mjcf import compile_mjcf
    from pinmob.io.xacro_file import parse_xacro_args

#: the names whose modules load when first read: every reader but the TOML one's is left out of ``import pinmob``
#: and of loading a built-in model
_LAZY = {
    "read_sidecar": "pinmob.io.extended_urdf",
    "sidecar_urdf": "pinmob.io.extended_urdf",
    "fixed_mjcf": "pinmob.io.fixed_files",
    "fixed_sidecar": "pinmob.io.fixed_files",
    "fixed_toml": "pinmob.io.fixed_files",
    "compile_mjcf": "pinmob.io.mjcf",
    "parse_xacro_args": "pinmob.io.xacro_file",
}


#: A name of :data:`_LAZY`, its module imported when it is first read (PEP 562).
__getattr__ = lazy_getattr(__name__, _LAZY)


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
    "read_sidecar",
    "read_toml",
    "sidecar_urdf",
    "toml_key",
    "toml_string",
    "unicode_text",
]
