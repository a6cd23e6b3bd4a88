"""Dask worker plugins that make the tests with a killed worker or an interrupted run deterministic.

The workers cannot import the tests: a test registers this module by value
(``cloudpickle.register_pickle_by_value(worker_plugins)``) before registering a plugin.
"""

from __future__ import annotations

import os
import time
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import Any

from distributed.diagnostics.plugin import WorkerPlugin


def _first(flag: str) -> bool:
    """True for the one caller across the cluster that creates ``flag`` (an exclusive create)."""
    try:
        os.close(os.open(flag, os.O_CREAT | os.O_EXCL))
    except FileExistsError:
        return False
    return True


class KillOnFirstChunk(WorkerPlugin):
    """The worker that starts the first pinmob task kills itself with ``sig``.

    One shot across the cluster (the first to create ``flag`` does it), so the kill lands while a task is being
    computed whatever the speed of the machine (waiting for a busy worker from outside could find the work done).
    """

    name = "pinmob-test-kill-on-first-chunk"

    def __init__(self, flag: str, sig: int) -> None:
        super().__init__()
        self.flag, self.sig = flag, sig

    def transition(self, key: object, start: str, finish: str, **kwargs: object) -> None:
        if finish == "executing" and "pinmob-" in str(key) and _first(self.flag):
            os.kill(os.getpid(), self.sig)


class _GatedThreadPoolExecutor(ThreadPoolExecutor):
    """A thread pool whose tasks, past the first ``free`` across the cluster, wait for ``release`` to exist.

    The wait is in the task's thread: the worker's event loop still serves the results it holds. (Its class name
    contains ``ThreadPoolExecutor``: Dask runs tasks on it as on its own pool.)
    """

    def __init__(self, folder: str, free: int, threads: int) -> None:
        super().__init__(max_workers=threads, thread_name_prefix="gated")
        self.folder, self.free = Path(folder), free

    def _gate(self) -> None:
        n = 0
        while not _first(str(self.folder / f"started-{n}")):
            n += 1
        if n < self.free:
            return
        while not (self.folder / "release").exists():
            time.sleep(0.01)

    def submit(self, fn: Any, /, *args: Any, **kwargs: Any) -> Future:
        def gated() -> Any:
            self._gate()
            return fn(*args, **kwargs)

        return super().submit(gated)


class HoldAfter(WorkerPlugin):
    """Tasks run as usual until ``free`` have started on the cluster; the next ones wait until the file
    ``folder/release`` exists. A run cannot end before the test releases it, however fast the machine.

    Numbered files ``folder/started-N`` count the tasks started; the plugin's teardown gives the worker back
    its own thread pool.
    """

    name = "pinmob-test-hold-after"

    def __init__(self, folder: str, free: int) -> None:
        super().__init__()
        self.folder, self.free = folder, free
        self._own: Any = None

    def setup(self, worker: Any) -> None:
        self._own = worker.executors["default"]
        worker.executors["default"] = _GatedThreadPoolExecutor(self.folder, self.free, worker.state.nthreads)

    def teardown(self, worker: Any) -> None:
        gated = worker.executors["default"]
        worker.executors["default"] = self._own
        gated.shutdown(wait=False)
