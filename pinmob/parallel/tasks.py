"""Results of Dask tasks in the order of their inputs, a bounded number in flight, watched for lost workers.

Dask recomputes the tasks of a worker that died (its nanny starts a new
worker). Two things it does not do are done here: stop waiting when the cluster
has had no worker at all for ``NO_WORKER_TIMEOUT`` seconds (a hang otherwise),
and turn a task that killed ``distributed.scheduler.allowed-failures`` workers
(Dask's ``KilledWorker``) into a :class:`Lost` result that names why, which the
caller records or reports.
"""

from __future__ import annotations

import time
import uuid
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any

from pinmob.exceptions import EngineError
from pinmob.signals import deferred_interrupts

#: Seconds without any worker after which waiting stops with an error.
NO_WORKER_TIMEOUT = 60.0

#: Seconds between two looks at the cluster's workers while waiting.
POLL = 0.5


@dataclass(frozen=True)
class Lost:
    """A task Dask gave up on: the workers running it died each time (e.g. killed for using too much memory)."""

    reason: str


#: What the tasks of the maps running on this worker share, by dataset name (a few kept, the latest last).
_SHARED: dict[str, Any] = {}
#: Shared values a worker keeps (older maps' are dropped).
KEPT_SHARED = 4


def _with_shared(name: str, fn: Callable[[Any, Any], Any], item: Any) -> Any:
    """``fn(shared, item)`` on a worker, ``shared`` fetched from the scheduler's dataset ``name`` once per worker."""
    if name not in _SHARED:
        from distributed import get_client

        _SHARED[name] = get_client().get_dataset(name)
        while len(_SHARED) > KEPT_SHARED:
            _SHARED.pop(next(iter(_SHARED)))
    return fn(_SHARED[name], item)


def ordered_results(
    client: Any,
    fn: Callable[[Any, Any], Any],
    shared: Any,
    items: Iterable[Any],
    window: int,
    watch: Watch,
) -> Iterator[Any]:
    """``fn(shared, item)`` on the cluster for each item, yielded in item order (:meth:`pinmob.parallel.Engine.map`).

    ``shared`` goes to the cluster once: it is published on the scheduler as a
    dataset, which each worker fetches once (and keeps); each task carries only
    its item and the dataset's name. The tasks have no dependency: at most
    ``window`` are submitted and not yet yielded, Dask queues them on the scheduler
    and gives each worker thread one at a time, so that when a worker dies only the
    task it was running is suspected (Dask gives a task up once it was on
    ``allowed-failures`` + 1 dead workers), and a worker that replaces it
    fetches the dataset again. ``watch`` counts the workers that disappear. Pending
    tasks are cancelled, and the dataset dropped, when the caller stops early (an
    interruption, an error) or the map ends.

    Raises:
        EngineError: no worker for ``NO_WORKER_TIMEOUT`` seconds, the scheduler gone, a task cancelled by Dask.
    """
    from distributed import wait

    token = uuid.uuid4().hex[:12]
    pending: dict[Any, int] = {}
    done: dict[int, Any] = {}
    source = iter(items)
    exhausted, submitted, yielded = False, 0, 0
    name = f"pinmob-{token}-shared"
    client.publish_dataset(**{name: shared})
    try:
        while True:
            while not exhausted and len(pending) + len(done) < window:
                try:
                    item = next(source)
                except StopIteration:
                    exhausted = True
                    break
                # a Future interrupted while it is made has no ``_cleared``; its finaliser then prints a traceback
                with deferred_interrupts():
                    future = client.submit(_with_shared, name, fn, item, key=f"pinmob-{token}-{submitted}")
                    pending[future] = submitted
                    submitted += 1
            if yielded in done:
                yield done.pop(yielded)
                yielded += 1
                continue
            if not pending:
                if exhausted:
                    watch.look(force=True)  # a worker lost and replaced within the last POLL still counts
                    return
                continue
            try:
                finished = wait(list(pending), timeout=POLL, return_when="FIRST_COMPLETED").done
            except TimeoutError:
                finished = set()
            for future in finished:
                done[pending.pop(future)] = _outcome(future)
                future.release()
            watch.look()
    finally:
        for future in pending:
            future.cancel()
        try:
            client.unpublish_dataset(name)
        except Exception:  # noqa: BLE001  (the scheduler gone: nothing left to drop)
            pass


def _outcome(future: Any) -> Any:
    """The task's result, a :class:`Lost` for Dask's ``KilledWorker``; the task's own exception is raised."""
    if future.status == "error":
        exc = future.exception()
        if type(exc).__name__ == "KilledWorker":
            tries = getattr(exc, "allowed_failures", None)  # Dask gives up after allowed-failures + 1 dead workers
            times = "" if tries is None else f" ({tries + 1} times: distributed.scheduler.allowed-failures + 1)"
            return Lost(f"the Dask workers computing it died each time it was tried{times}; out of memory?")
        future.result()  # raises the task's own exception, with its traceback
    if future.status == "cancelled":
        raise EngineError("Dask cancelled a task (was the scheduler restarted or lost?); the work stopped")
    return future.result()


class Watch:
    """Looks at the cluster's workers: counts the lost ones, stops a wait without any worker.

    Attributes:
        lost: workers that disappeared since the watch started.
    """

    def __init__(self, client: Any) -> None:
        self.client = client
        self.known = self._workers()
        self.last = time.monotonic()
        self.alone_since: float | None = None
        self.lost = 0

    def _workers(self) -> set[str]:
        try:
            return set(self.client.nthreads())
        except Exception as exc:  # noqa: BLE001  (any comm failure means the scheduler is gone)
            raise EngineError(
                f"the Dask scheduler does not answer any more ({type(exc).__name__}); the work stopped"
            ) from None

    def look(self, force: bool = False) -> None:
        """Compare the workers with the last look (``force``: now, else only after ``POLL`` seconds)."""
        now = time.monotonic()
        if not force and now - self.last < POLL:
            return
        self.last = now
        current = self._workers()
        self.lost += len(self.known - current)
        self.known = current
        if current:
            self.alone_since = None
            return
        self.alone_since = self.alone_since or now
        if now - self.alone_since > NO_WORKER_TIMEOUT:
            raise EngineError(
                f"the Dask cluster has had no worker for {NO_WORKER_TIMEOUT:.0f} s (all lost?); the work stopped"
            )
