"""Output files that an interruption never leaves half-written: a temporary file beside the target, renamed at the end.

:func:`check_target` refuses, before any work, what an output may not replace:
a symbolic link (dangling or not: pinmob never writes through one, nor creates
its target), a folder, a device or any other non-regular file, an existing file
unless ``force``, a target in a folder that does not exist.
:class:`Replacing` writes to a hidden temporary file in the target's folder
(``.NAME.XXXX.pinmob-tmp``) and renames it over the target only on
:meth:`Replacing.commit`: until then the old file stays as it was, and on any
error, Ctrl-C or handled signal the temporary file is removed.
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path
from types import TracebackType

from pinmob.exceptions import ConfigurationError

#: Suffix of the temporary files (hidden, in the target's folder).
TEMP_SUFFIX = ".pinmob-tmp"


def check_target(option: str, path: str | Path, force: bool, switch: str = "force") -> Path:
    """The output path, if an output may be written there; else a :class:`ConfigurationError` naming ``option``.

    ``option``: how the message calls the output (``html file``; a Python parameter in backticks, such as
    ```target```, is one the command line words as its option). ``switch``: the Python parameter that allows
    overwriting (``force``), named in the refusal of an existing file.
    """
    target = Path(path).expanduser()
    shown = f"{option} {str(target)!r}"
    try:
        return _checked(target, shown, force, switch)
    except ConfigurationError as exc:
        raise exc.naming(option.strip("`"), switch) from None


def _checked(target: Path, shown: str, force: bool, switch: str) -> Path:
    if target.is_symlink():
        raise ConfigurationError(
            f"{shown} is a symbolic link (to {os.readlink(target)!r}); pinmob does not write through links: "
            "give the file's own path or a new file name"
        )
    if target.is_dir():
        raise ConfigurationError(f"{shown} is a folder; give a file name")
    if target.exists():
        if not stat.S_ISREG(target.stat().st_mode):
            raise ConfigurationError(f"{shown} is not a regular file (a device, pipe or socket); give a file name")
        if not force:
            raise ConfigurationError(
                f"{shown} exists already; choose another file name or allow overwriting (`{switch}=True`)"
            )
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise ConfigurationError(f"cannot write {shown}: folder {str(parent)!r} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise ConfigurationError(f"cannot write {shown}: folder {str(parent)!r} is not writable")
    return target


class Replacing:
    """Write ``target`` through a temporary file in its folder; :meth:`commit` renames it over the target.

    Use as a context manager: ``with Replacing(path) as tmp: write tmp; ...; r.commit()``.
    Leaving the block without :meth:`commit` (an error, Ctrl-C, a handled signal)
    removes the temporary file and leaves the target as it was.
    """

    def __init__(self, target: str | Path) -> None:
        self.target = Path(target).expanduser()
        self.path: Path | None = None
        self.committed = False

    def __enter__(self) -> Path:
        folder = self.target.parent if str(self.target.parent) else Path(".")
        try:
            fd, name = tempfile.mkstemp(dir=folder, prefix=f".{self.target.name}.", suffix=TEMP_SUFFIX)
        except OSError as exc:
            raise ConfigurationError(f"cannot write {str(self.target)!r}: {exc.strerror or exc}") from None
        os.close(fd)
        self.path = Path(name)
        return self.path

    def commit(self) -> None:
        """Rename the temporary file over the target (refused if the target became a link, folder or device meanwhile)."""
        if self.path is None or self.committed:
            return
        if self.target.is_symlink():
            raise ConfigurationError(f"{str(self.target)!r} became a symbolic link while pinmob ran; not written")
        if self.target.exists() and not stat.S_ISREG(self.target.stat().st_mode):
            raise ConfigurationError(f"{str(self.target)!r} became a folder or a device while pinmob ran; not written")
        os.chmod(self.path, 0o666 & ~_umask())
        os.replace(self.path, self.target)
        self.committed = True

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        if not self.committed and self.path is not None:
            self.path.unlink(missing_ok=True)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask
