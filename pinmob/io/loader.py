"""Loading a mechanism: a built-in model name, or a file of any supported format."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

from pinmob.exceptions import MechanismFileError
from pinmob.io.builtin import builtin_models
from pinmob.io.toml_file import load_toml
from pinmob.model import Mechanism
from pinmob.name_matching import choices, did_you_mean


def load_extended_urdf(path: Path) -> Mechanism:
    """:func:`pinmob.io.extended_urdf.load_extended_urdf` (its module, and YAML, imported when first used)."""
    from pinmob.io.extended_urdf import load_extended_urdf

    return load_extended_urdf(path)


def load_mjcf(path: Path) -> Mechanism:
    """:func:`pinmob.io.mjcf.load_mjcf` (its module, and the XML parser, imported when first used)."""
    from pinmob.io.mjcf import load_mjcf

    return load_mjcf(path)


def load_sdf(path: Path) -> Mechanism:
    """:func:`pinmob.io.sdf.load_sdf` (its module imported when first used)."""
    from pinmob.io.sdf import load_sdf

    return load_sdf(path)


def load_urdf(path: Path) -> Mechanism:
    """A URDF: the Extended URDF of its same-named YAML sidecar, else a plain URDF.

    The sidecar is :func:`pinmob.io.extended_urdf.sidecar`'s; a plain URDF is read by
    :func:`pinmob.io.closing_frames.load_closing_urdf` (closing frames and mimic joints).
    """
    from pinmob.io.extended_urdf import sidecar

    found = sidecar(path)
    if found is not None:
        from pinmob.io.extended_urdf import load_extended_urdf

        return load_extended_urdf(*found)  # the sidecar found and its document: the file is read once
    from pinmob.io.closing_frames import load_closing_urdf

    return load_closing_urdf(path)


#: Loaders by file suffix.
LOADERS: dict[str, Callable[[Path], Mechanism]] = {
    ".toml": load_toml,
    ".yaml": load_extended_urdf,
    ".yml": load_extended_urdf,
    ".xml": load_mjcf,
    ".mjcf": load_mjcf,
    ".urdf": load_urdf,
    ".sdf": load_sdf,
    ".world": load_sdf,
}


def load_xacro(
    path: Path, xacro_args: Mapping[str, str] | None = None, package_dirs: Sequence[str | Path] = ()
) -> Mechanism:
    """A xacro file expanded (:func:`pinmob.io.xacro_file.expand_xacro`), read as a plain URDF."""
    from pinmob.io.closing_frames import load_closing_urdf
    from pinmob.io.xacro_file import expand_xacro

    return load_closing_urdf(path, text=expand_xacro(path, xacro_args, package_dirs))


def load(
    name_or_path: str | Path,
    *,
    xacro_args: Mapping[str, str] | None = None,
    package_dirs: Sequence[str | Path] = (),
) -> Mechanism:
    """Load a mechanism: a built-in model name (matched ignoring case where unambiguous), or a path to a mechanism file.

    A ``.xacro`` file is expanded first, with its arguments ``xacro_args`` (``{"prefix": "left_"}``) and the
    folders ``$(find pkg)`` searches (``package_dirs``, then ``ROS_PACKAGE_PATH``): :mod:`pinmob.io.xacro_file`.

    Raises:
        MechanismFileError: the file is missing, does not parse, or is invalid;
            the message lists the built-in names when neither matches.
    """
    text = str(name_or_path)
    path = Path(text).expanduser()
    builtins = builtin_models()
    if not path.exists():
        same = [name for name in builtins if name.casefold() == text.casefold()]
        if text in builtins or len(same) == 1:
            return load_toml(builtins[text if text in builtins else same[0]])
        raise MechanismFileError(
            f"{text!r} is neither a built-in model nor an existing file{did_you_mean(text, builtins)}; "
            f"built-in models: {choices(builtins)}"
        )
    suffix = path.suffix.lower()
    if suffix == ".xacro":
        return load_xacro(path, xacro_args, package_dirs)
    if suffix in LOADERS:
        return LOADERS[suffix](path)
    raise MechanismFileError(
        f"{text!r}: unknown mechanism file type {suffix!r}; valid: {choices([*LOADERS, '.xacro'])}"
    )
