"""A lock file beside an output, so that one run at a time writes it (``flock``, removed on release)."""

from __future__ import annotations

import contextlib
import fcntl
import os
from pathlib import Path
from typing import Any

from pinmob.exceptions import ConfigurationError


class TargetLock:
    """The lock ``path`` held for writing ``target`` (:meth:`acquire`, :meth:`release`).

    The holder removes the file, then closes it: a run that opened the old file and gets its lock
    after that sees that the path no longer names it, and takes the new one instead (a lock on a
    removed file would let two runs in).
    """

    def __init__(self, path: Path, target: Path) -> None:
        self.path, self.target = path, target
        self._fh: Any = None

    def acquire(self) -> None:
        """Hold the lock.

        Raises:
            ConfigurationError: another run holds it, or the lock file cannot be created.
        """
        busy = ConfigurationError(f"another pinmob sweep is writing {str(self.target)!r} now")
        for _ in range(3):
            try:
                fh = open(self.path, "a+")  # noqa: SIM115  (held until released)
            except OSError as exc:
                raise ConfigurationError(f"cannot create the lock file {str(self.path)!r}: {exc}") from None
            try:
                fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                fh.close()
                raise busy from None
            try:
                same = os.fstat(fh.fileno()).st_ino == os.stat(self.path).st_ino
            except FileNotFoundError:
                same = False
            if same:
                self._fh = fh
                return
            fh.close()  # the file a finishing run removed meanwhile: try the new one
        raise busy

    def release(self) -> None:
        """Remove the lock file, then let it go (nothing when not held)."""
        if self._fh is not None:
            with contextlib.suppress(OSError):
                os.unlink(self.path)
            self._fh.close()
            self._fh = None
