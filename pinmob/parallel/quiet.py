"""Silence one message of Dask's: the ``NameError`` its ``sync`` logs when a call is interrupted at a bad time.

``distributed.utils.sync`` runs a call on the client's event loop and waits for it;
a ``KeyboardInterrupt`` in the wait (Ctrl-C, or SIGTERM/SIGHUP that pinmob turns
into one) schedules ``cancel()`` of the call's future on the loop. When the call
failed before its future existed (a connection already closing, as during an
interruption), ``cancel()`` meets an unassigned variable and the event loop logs
``NameError: cannot access free variable 'future'`` with a traceback on stderr,
after pinmob has said it was interrupted. The call has ended either way, so
nothing is lost; :func:`install` drops exactly that record (the ``NameError``
raised by ``cancel`` in ``distributed/utils.py``), nothing else.
"""

from __future__ import annotations

import logging
from pathlib import PurePath

#: The loggers an event loop's failing callback is reported on (tornado's, and asyncio's).
LOGGERS = ("tornado.application", "asyncio")


class CancelBeforeStart(logging.Filter):
    """Drops the record of ``distributed.utils.sync``'s ``cancel()`` failing with a ``NameError``."""

    def filter(self, record: logging.LogRecord) -> bool:
        """False for that one record (its exception raised in ``cancel`` of ``distributed/utils.py``)."""
        exc = record.exc_info[1] if record.exc_info else None
        if not isinstance(exc, NameError) or exc.__traceback__ is None:
            return True
        tb = exc.__traceback__
        while tb.tb_next is not None:
            tb = tb.tb_next
        code = tb.tb_frame.f_code
        return not (code.co_name == "cancel" and PurePath(code.co_filename).parts[-2:] == ("distributed", "utils.py"))


def install() -> None:
    """Add the filter to the event loops' loggers (once per process)."""
    for name in LOGGERS:
        logger = logging.getLogger(name)
        if not any(isinstance(f, CancelBeforeStart) for f in logger.filters):
            logger.addFilter(CancelBeforeStart())
