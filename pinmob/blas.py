"""Small-matrix linear algebra on one BLAS thread.

pinmob's matrices are small (6 x n, a closure Jacobian of a few dozen rows): a
multi-threaded BLAS splits them across threads for no gain, and under load (more
runnable threads than cores) every call then waits for threads that are not
scheduled; a 6-UPS whole-mechanism analysis went from 3 ms to a 48 ms median.
:data:`one_blas_thread` (a context manager and a decorator) holds every BLAS
library loaded in the process (OpenBLAS, MKL, BLIS, ... through threadpoolctl) at
one thread while an analysis runs, and restores the user's settings when the
outermost use ends: nested uses cost a counter, and the limit is a process-wide
setting, so it holds until the last thread inside an analysis leaves it. The
libraries are looked for again when modules were imported since the last look
(a module can bring its own BLAS, as SciPy does). OpenBLAS may ignore a thread
count set from a thread other than the one that set it last: analyses run from
several threads of the user's may then not all get the limit (their results are the same).
"""

from __future__ import annotations

import sys
from typing import Any

from pinmob.held_setting import HeldSetting


class _OneBlasThread(HeldSetting):
    """Re-entrant, thread-safe ``BLAS threads = 1`` for the duration of the block (see the module docstring)."""

    def __init__(self) -> None:
        super().__init__()
        self._libraries: list[Any] = []
        self._modules = -1  # len(sys.modules) when the libraries were last looked for
        self._saved: list[tuple[Any, int]] = []

    def _blas(self) -> list[Any]:
        """The controllers (threadpoolctl) of the BLAS libraries loaded, looked for again after new imports."""
        if len(sys.modules) != self._modules:
            from threadpoolctl import ThreadpoolController

            self._libraries = list(ThreadpoolController().select(user_api="blas").lib_controllers)
            self._modules = len(sys.modules)
        return self._libraries

    def _hold(self) -> None:
        for lib in self._blas():
            threads = lib.get_num_threads()
            if threads is not None and threads != 1:
                lib.set_num_threads(1)
                self._saved.append((lib, threads))

    def _release(self) -> None:
        for lib, threads in self._saved:
            lib.set_num_threads(threads)
        self._saved.clear()


#: ``with one_blas_thread:`` or ``@one_blas_thread``: small-matrix linear algebra on one BLAS thread.
one_blas_thread = _OneBlasThread()
