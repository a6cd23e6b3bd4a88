"""Parallel work on Dask: where tasks run, and results in order however and wherever they were computed.

:class:`~pinmob.parallel.cluster.Engine` runs tasks in this process, on a Dask
``LocalCluster`` of N worker processes started here, or on an existing Dask
cluster given by its scheduler address (for instance one that dask-jobqueue
started on PBS or SLURM nodes). :meth:`Engine.map` gives the results in the
order of the items, with a bounded number of tasks in flight (memory flat in the
number of items). A worker that dies (killed, out of memory) is replaced by its
nanny and Dask computes its tasks again; a task that kills
``distributed.scheduler.allowed-failures`` workers in a row comes back as a
:class:`~pinmob.parallel.tasks.Lost` result naming why; a cluster left with no
worker at all is an :class:`~pinmob.exceptions.EngineError` after
``NO_WORKER_TIMEOUT`` seconds, never a hang.

Dask is imported only when a cluster is used: ``import pinmob`` does not import it.
"""

from pinmob.parallel.cluster import Engine
from pinmob.parallel.tasks import NO_WORKER_TIMEOUT, Lost

__all__ = ["NO_WORKER_TIMEOUT", "Engine", "Lost"]
