"""Running a sweep: every design's record, in design order, in this process or on Dask (:mod:`pinmob.parallel`)."""

from __future__ import annotations

from collections import deque
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.exceptions import ConfigurationError
from pinmob.parallel import Engine, Lost
from pinmob.sweeps.record import empty_record, evaluate_designs, failed
from pinmob.sweeps.spec_file import load_spec
from pinmob.sweeps.sweep_spec import SweepSpec

#: Most designs a Dask task computes (:func:`~pinmob.sweeps.record.evaluate_designs`): a task's scheduling costs
#: about as much as a small design (7-12 ms per task on 1-2 local workers, the example sweep's design 26 ms).
DESIGNS_PER_TASK = 8


class SweepRun:
    """The records of a sweep, one per design in design order (iterate over it).

    Each Dask task carries the indices and values of up to ``DESIGNS_PER_TASK`` consecutive designs (fewer when
    the run has too few designs to give each worker thread about four tasks; in process, one design at a time);
    what every design needs (the :class:`~pinmob.sweeps.sweep_spec.DesignJob`: the source, the scan, the fields)
    goes to the cluster once per run, not the design table. A task Dask gives up on (its workers died) fails each
    of its designs.

    Attributes:
        spec: the sweep.
        where: where the designs were computed (known once iteration started).
        lost_workers: Dask workers lost during the run (their designs were computed again).
    """

    def __init__(
        self,
        spec: SweepSpec,
        workers: int,
        scheduler: str | None,
        progress: bool | None,
        skip: np.ndarray | None,
    ) -> None:
        spec.check_count()
        if skip is not None and np.shape(skip) != (spec.count,):
            raise ConfigurationError(
                f"skip must hold one boolean per design ({spec.count}), got shape {np.shape(skip)}"
            )
        self.spec = spec
        self.engine = Engine(workers, scheduler)  # checks workers
        self.progress = progress
        self.skip = skip
        self.where = self.engine.describe()
        self.lost_workers = 0

    def todo(self) -> int:
        """Designs this run computes (the others are skipped)."""
        return self.spec.count - (int(np.count_nonzero(self.skip)) if self.skip is not None else 0)

    def __iter__(self) -> Iterator[dict[str, Any]]:
        from tqdm import tqdm

        todo = self.todo()
        if todo == 0:
            return
        skip = None if self.skip is None else np.array(self.skip, bool)  # as it is now: the caller may mark designs
        job = self.spec.job()
        sent: deque[list[tuple[int, dict[str, float]]]] = deque()

        def items() -> Iterator[tuple[int, dict[str, float]]]:
            for i in range(self.spec.count):
                if skip is None or not skip[i]:
                    yield i, self.spec.values(i)

        def batches(size: int) -> Iterator[list[tuple[int, dict[str, float]]]]:
            batch: list[tuple[int, dict[str, float]]] = []
            for item in items():
                batch.append(item)
                if len(batch) == size:
                    sent.append(batch)
                    yield batch
                    batch = []
            if batch:
                sent.append(batch)
                yield batch

        disable = None if self.progress is None else not self.progress
        bar = tqdm(total=todo, disable=disable, unit="design", desc=f"sweep {self.spec.name}", leave=False)
        try:
            with self.engine:
                self.where = self.engine.describe()
                if self.engine.in_process:
                    size = 1
                else:  # several designs a task, and still about four tasks per worker thread
                    size = max(1, min(DESIGNS_PER_TASK, todo // (4 * self.engine.nthreads())))
                for result in self.engine.map(evaluate_designs, job, batches(size)):
                    batch = sent.popleft()  # results come in the order of the batches
                    records = (
                        [failed(empty_record(job, *item), result.reason) for item in batch]
                        if isinstance(result, Lost)
                        else result
                    )
                    self.lost_workers = self.engine.lost_workers
                    for record in records:
                        bar.update(1)
                        yield record
                # the map's last look, once every design is in (a worker lost since the look before counts too)
                self.lost_workers = self.engine.lost_workers
        finally:
            bar.close()


def sweep(
    spec: SweepSpec | str | Path,
    workers: int = 1,
    scheduler: str | None = None,
    progress: bool | None = False,
    skip: np.ndarray | None = None,
) -> SweepRun:
    """The records of a design-space sweep, one per design, in design order.

    Args:
        spec: a :class:`~pinmob.sweeps.sweep_spec.SweepSpec` or the path of a sweep spec file
            (:func:`~pinmob.sweeps.spec_file.load_spec`).
        workers: worker processes of a Dask ``LocalCluster`` (1: this process); the records do not depend on it.
        scheduler: address of an existing Dask cluster's scheduler to compute the designs on.
        progress: a tqdm bar on stderr (None: on a terminal).
        skip: (count,) booleans, True for designs not to compute (already written).

    Returns:
        an iterable :class:`SweepRun` of records (dicts: ``design``, the parameters, then
        :data:`pinmob.sweeps.fields.FIELDS`); a design that fails is a record with its reason.

    Raises:
        ConfigurationError: a bad spec (before any design is computed), more designs than the design set's
            bound (``design.max_designs``), or a bad ``workers``.
        EngineError: the Dask cluster cannot be used or loses every worker.
    """
    if not isinstance(spec, SweepSpec):
        spec = load_spec(spec)
    return SweepRun(spec, workers, scheduler, progress, skip)
