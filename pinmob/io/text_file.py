"""Reading a small text file of a mechanism (TOML, YAML) so that no file can cost a traceback, a hang or the memory.

A mechanism file is a few kilobytes. :func:`check_regular` is the one check of every file a model is
read from (TOML, YAML, URDF, MJCF and its includes), one ``stat`` per file per load: it refuses a missing
file, a folder, what is not a regular file and a file over 4 MB (``PINMOB_MAX_FILE_BYTES`` raises the
bound: :mod:`pinmob.bounds`); :func:`read_text` also text that is not UTF-8; :func:`parsing` turns what a parser
raises on hostile input (nesting thousands of levels deep: ``RecursionError``;
an integer of thousands of digits: ``ValueError``) into one
:class:`~pinmob.exceptions.MechanismFileError` naming the file; :func:`shown`
writes a parsed value into a message with bounded work (a YAML alias bomb
expands to billions of items when printed whole).
"""

from __future__ import annotations

import reprlib
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from pinmob.bounds import BOUNDS, bound
from pinmob.exceptions import MechanismFileError

_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxlist, _SHORT.maxdict, _SHORT.maxstring, _SHORT.maxother = 3, 6, 6, 60, 60
_SHORT.maxlong = 40


def check_regular(path: Path, label: str, kind: str = "", *, missing_ok: bool = False) -> int:
    """Refuse ``path`` (named ``label`` in the message) unless it is a regular file within the file bound.

    Opening a named pipe blocks until a writer comes, and a device or a huge file exhausts the memory: every
    file a model is read from goes through this first, once (one ``stat``).

    Args:
        path: the file.
        label: how the message names it, e.g. ``urdf file '/x/robot.urdf'``.
        kind: what it should be (``TOML``, ``URDF``): a folder is "a folder, not a <kind> file".
        missing_ok: a missing file passes (its reader says so: MuJoCo names a missing include).

    Returns:
        The bound, in bytes (read no more than one byte over it).

    Raises:
        MechanismFileError: missing, cannot be looked at (no permission), a folder, device, pipe or socket, or
            larger than the bound (``PINMOB_MAX_FILE_BYTES``).
    """
    try:
        info = path.stat()
    except FileNotFoundError:
        if missing_ok:
            return bound("bytes")
        raise MechanismFileError(f"{label} does not exist") from None
    except OSError as exc:
        raise MechanismFileError(f"{label} cannot be read: {exc.strerror or exc}") from None
    if stat.S_ISDIR(info.st_mode):
        raise MechanismFileError(f"{label} is a folder" + (f", not a {kind} file" if kind else ""))
    if not stat.S_ISREG(info.st_mode):
        raise MechanismFileError(f"{label} is not a regular file (a device, pipe or socket)")
    limit = bound("bytes")
    if info.st_size > limit:
        raise MechanismFileError(
            f"{label} has {info.st_size} bytes, over the {limit}-byte bound on a mechanism file; "
            f"set {BOUNDS['bytes'][1]} to raise it"
        )
    return limit


def read_text(path: Path, kind: str) -> str:
    """The UTF-8 text of the mechanism file ``path`` (a ``kind`` file: ``TOML``, ``YAML``).

    Raises:
        MechanismFileError: missing, a folder or not a regular file, larger than its bound,
            unreadable, or not UTF-8.
    """
    limit = check_regular(path, f"mechanism file {str(path)!r}", kind)
    try:
        data = path.read_bytes()[: limit + 1]
    except OSError as exc:
        raise MechanismFileError(f"{path}: cannot be read: {exc.strerror or exc}") from None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise MechanismFileError(
            f"{path}: not a UTF-8 text file ({kind} must be UTF-8): byte {exc.start} is invalid"
        ) from None


@contextmanager
def parsing(path: Path, kind: str) -> Iterator[None]:
    """Turn what a parser raises on hostile input inside the block into one :class:`MechanismFileError`."""
    try:
        yield
    except RecursionError:
        raise MechanismFileError(f"{path}: {kind} nested too deeply to read (thousands of levels)") from None
    except MemoryError:
        raise MechanismFileError(f"{path}: {kind} too large to hold in memory") from None
    except ValueError as exc:  # e.g. an integer over Python's 4300-digit conversion limit
        said = " ".join(str(exc).split(";")[0].split())[:200]
        raise MechanismFileError(f"{path}: {kind} value cannot be read: {said}") from None


def shown(value: object) -> str:
    """``value`` for an error message: its repr, few items per level, few levels, 200 characters (bounded work)."""
    try:
        text = _SHORT.repr(value)
    except (RecursionError, ValueError):
        return f"<a {type(value).__name__}>"
    return text if len(text) <= 200 else text[:197] + "..."
