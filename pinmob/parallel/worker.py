"""Set-up of the worker processes of a ``LocalCluster`` pinmob starts (a Dask preload module).

A Ctrl-C in a terminal, or a hang-up, reaches every process of the foreground
process group, Dask's worker processes included, which would each print a
``KeyboardInterrupt`` traceback while pinmob itself stops cleanly. The workers
ignore SIGINT and SIGHUP: pinmob, which does handle them, closes the cluster.
A worker that receives one while it still starts (before this hook) prints its
traceback to the standard error it was given: /dev/null
(:meth:`pinmob.parallel.Engine.start`).
SIGTERM and SIGKILL still end a worker (as the out-of-memory killer would); its
nanny starts a new one and Dask computes its tasks again.
"""

from __future__ import annotations

import signal
from typing import Any


def dask_setup(worker: Any) -> None:
    """Dask preload hook, run in each worker process: ignore SIGINT and SIGHUP (pinmob ends the cluster)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "SIGHUP"):
        signal.signal(signal.SIGHUP, signal.SIG_IGN)
