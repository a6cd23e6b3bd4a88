"""Where tasks run: this process, a Dask ``LocalCluster`` started here, or an existing Dask cluster."""

from __future__ import annotations

import contextlib
import os
from collections.abc import Callable, Iterable, Iterator
from typing import Any, TypeVar

from pinmob.exceptions import ArgumentError, EngineError
from pinmob.parallel.quiet import install as quiet_logs
from pinmob.parallel.tasks import Lost, Watch, ordered_results
from pinmob.signals import deferred_interrupts

T = TypeVar("T")
R = TypeVar("R")

#: Seconds to wait for the scheduler of an existing cluster to answer.
CONNECT_TIMEOUT = 20.0

#: The only interface a LocalCluster pinmob starts listens on (scheduler, workers, their HTTP servers).
LOOPBACK = "127.0.0.1"

#: The preload module of the workers pinmob starts (:mod:`pinmob.parallel.worker`).
WORKER_SETUP = "pinmob.parallel.worker"


def check_workers(workers: object) -> int:
    """``workers`` as a positive integer; anything else is an :class:`ArgumentError` naming the parameter."""
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise ArgumentError(
            f"workers must be a whole number of worker processes, at least 1, got {workers!r}", "workers", workers
        )
    return workers


@contextlib.contextmanager
def _stderr_of_children_to_devnull() -> Iterator[None]:
    """File descriptor 2, which child processes inherit, on /dev/null; this process's ``sys.stderr`` kept as it was.

    When ``sys.stderr`` writes to descriptor 2 it is replaced, for the block, by a stream on a copy of the
    original descriptor (Python's warnings and messages still reach the terminal).
    """
    import io
    import sys

    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    os.close(devnull)
    previous = sys.stderr
    try:
        uses_fd2 = previous is not None and previous.fileno() == 2
    except (AttributeError, OSError, ValueError):  # captured (pytest), or no file behind it
        uses_fd2 = False
    own = None
    if uses_fd2:
        previous.flush()
        own = io.TextIOWrapper(  # its own copy of the descriptor: closed with it, whoever keeps it
            io.FileIO(os.dup(saved), "w"), encoding=previous.encoding, errors=previous.errors, line_buffering=True
        )
        sys.stderr = own
    try:
        yield
    finally:
        if own is not None:
            own.flush()
            sys.stderr = previous
        os.dup2(saved, 2)
        os.close(saved)


def _close_quietly(clusters: set[Any]) -> None:
    """Close clusters left half-started (else Dask closes them at exit, printing their errors)."""
    import gc
    import logging

    # the event loop's start-up tasks that failed report themselves when collected, maybe only at exit
    logging.getLogger("asyncio").setLevel(logging.CRITICAL)
    for cluster in clusters:
        try:
            cluster.close(timeout=10)
        except BaseException:  # noqa: BLE001  (a half-started cluster fails to close in many ways)
            pass
    gc.collect()


class Engine:
    """Where tasks run (a context manager: the cluster it starts is closed on leaving, whatever happened).

    Args:
        workers: worker processes of a ``LocalCluster`` started here; 1 (and no
            ``scheduler``): tasks run one after the other in this process.
        scheduler: address of the scheduler of an existing Dask cluster
            (e.g. ``tcp://10.0.0.5:8786``); ``workers`` is then ignored.

    Attributes:
        lost_workers: workers that disappeared since the engine started, as of the last look (:meth:`count_lost`
            looks now); their tasks were computed again.
    """

    def __init__(self, workers: int = 1, scheduler: str | None = None) -> None:
        self.workers = check_workers(workers)
        if scheduler is not None and (not isinstance(scheduler, str) or not scheduler.strip()):
            raise ArgumentError(
                f"scheduler must be the address of a Dask scheduler, got {scheduler!r}", "scheduler", scheduler
            )
        self.scheduler = scheduler
        self._client: Any = None
        self._cluster: Any = None
        self._watch: Watch | None = None

    @property
    def lost_workers(self) -> int:
        """Workers lost since the engine started, as of the last look at the cluster."""
        return self._watch.lost if self._watch is not None else 0

    def count_lost(self) -> int:
        """Workers lost since the engine started, looking at the cluster now (0 in process)."""
        if self._watch is not None and self._client is not None:
            self._watch.look(force=True)
        return self.lost_workers

    @property
    def in_process(self) -> bool:
        """Tasks run in this process (one worker, no scheduler)."""
        return self.scheduler is None and self.workers == 1

    def describe(self) -> str:
        """Where the tasks run, for the summary line (e.g. ``2 worker(s), Dask LocalCluster``)."""
        if self.in_process:
            return "1 worker (this process)"
        if self.scheduler is not None:
            return f"{self.nthreads()} worker thread(s), Dask cluster at {self.scheduler}"
        return f"{self.workers} worker(s), Dask LocalCluster"

    def nthreads(self) -> int:
        """Worker threads of the cluster now (1 in process)."""
        if self._client is None:
            return 1
        return max(1, sum(self._client.nthreads().values()))

    def __enter__(self) -> Engine:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def start(self) -> None:
        """Start the ``LocalCluster`` or connect to the scheduler (nothing in process).

        Raises:
            EngineError: the scheduler does not answer, or the cluster cannot start.
        """
        if self.in_process or self._client is not None:
            return
        import logging

        from dask.distributed import Client, LocalCluster
        from distributed.deploy.spec import SpecCluster

        quiet_logs()

        before = set(SpecCluster._instances)
        # A Ctrl-C or a hang-up reaches the whole process group. Here it is held back while the cluster starts
        # (not lost in a library's callback; raised once started, the cluster then closed). The worker processes
        # inherit a standard error on /dev/null: one that receives it while it still starts, before it ignores
        # it (pinmob.parallel.worker), would print a KeyboardInterrupt traceback. This process keeps its own.
        try:
            with deferred_interrupts() as received, _stderr_of_children_to_devnull():
                try:
                    if self.scheduler is not None:
                        self._client = Client(self.scheduler, timeout=CONNECT_TIMEOUT)
                    else:
                        self._cluster = LocalCluster(
                            n_workers=self.workers,
                            threads_per_worker=1,
                            processes=True,
                            host=LOOPBACK,
                            dashboard_address=f"{LOOPBACK}:0",
                            worker_dashboard_address=f"{LOOPBACK}:0",
                            silence_logs=logging.CRITICAL,
                            preload=[WORKER_SETUP],
                        )
                        self._client = Client(self._cluster)
                except (OSError, TimeoutError, ValueError, RuntimeError) as exc:
                    if received:  # the workers stopped by the same Ctrl-C: an interruption, not an error
                        raise KeyboardInterrupt from None
                    self.close()
                    _close_quietly(set(SpecCluster._instances) - before)
                    where = f"the Dask scheduler at {self.scheduler!r}" if self.scheduler else "a Dask LocalCluster"
                    raise EngineError(
                        f"cannot use {where}: {' '.join(str(exc).split()) or type(exc).__name__}"
                    ) from None
        except KeyboardInterrupt:  # Ctrl-C or a handled signal while starting: stop what started, say nothing more
            self.close()
            _close_quietly(set(SpecCluster._instances) - before)
            raise
        self._watch = Watch(self._client)

    def close(self) -> None:
        """Disconnect, and stop the ``LocalCluster`` this engine started (its worker processes end)."""
        client, cluster = self._client, self._cluster
        self._client = self._cluster = None
        if self._watch is not None:
            self._watch.client = None
        for thing in (client, cluster):
            if thing is not None:
                try:
                    thing.close()
                except Exception:  # noqa: BLE001  (closing after a failure must not hide it)
                    pass

    def map(
        self, fn: Callable[[Any, T], R], shared: Any, items: Iterable[T], window: int | None = None
    ) -> Iterator[R | Lost]:
        """``fn(shared, item)`` for each item, yielded in the order of the items.

        Args:
            fn: a module-level function (workers import it by name).
            shared: what every task needs (sent to the cluster once per map, as a task every task depends on).
            items: the task inputs, read lazily as tasks complete.
            window: most tasks submitted and not yet yielded (default: four per worker thread, at least 8).

        Yields:
            each result, or a :class:`Lost` for a task Dask gave up on (it killed its workers).
        """
        if self.in_process:
            for item in items:
                yield fn(shared, item)
            return
        self.start()
        size = window or max(8, 4 * self.nthreads())
        assert self._watch is not None  # started
        try:
            yield from ordered_results(self._client, fn, shared, items, size, self._watch)
        finally:
            if self._client is not None:
                try:
                    self._watch.look(force=True)  # a worker lost near the end counts too
                except Exception:  # noqa: BLE001  (the scheduler gone: nothing more to count)
                    pass
