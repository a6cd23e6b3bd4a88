"""Interruptions held back while a short step must finish whole: a file published, a Dask cluster started.

Python raises ``KeyboardInterrupt`` (Ctrl-C, or SIGTERM and SIGHUP under
:func:`pinmob.cli.common.signals_interrupt`) between any two bytecodes of the
main thread, also inside a finaliser or a library's callback, where it is
printed as "Exception ignored" and lost. :func:`deferred_interrupts` records
SIGINT, SIGTERM and SIGHUP instead, runs the step, then raises one
``KeyboardInterrupt`` if any came. Outside the main thread (where handlers
cannot be installed) it changes nothing.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator

#: The signals held back: Ctrl-C, and the two a terminal or a job scheduler sends to stop a program.
HELD = tuple(getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name))


@contextlib.contextmanager
def deferred_interrupts() -> Iterator[list[int]]:
    """Hold back SIGINT, SIGTERM and SIGHUP for the block; then raise ``KeyboardInterrupt`` if one came.

    Yields:
        the list of the signals received so far (empty while none came).

    Raises:
        KeyboardInterrupt: on leaving the block normally when a signal came (an exception leaving the
            block goes on as it is).
    """
    received: list[int] = []
    if threading.current_thread() is not threading.main_thread():
        yield received
        return

    def record(signum: int, frame: object) -> None:
        received.append(signum)

    previous = {sig: signal.signal(sig, record) for sig in HELD}
    try:
        yield received
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, signal.SIG_DFL if handler is None else handler)  # None: a handler set from C
    if received:
        raise KeyboardInterrupt
