"""Scans: mobility and singularities along a path or over a workspace slice.

What is scanned, in which order, is a :class:`pinmob.scan.scan_spec.ScanSpec`. Each
target is assembled warm-started (the previous sample's configuration seeds
the closure solver of the next). One coarse walk (:func:`~pinmob.scan.seeding_walk.chunk_seeds`, in this
process) goes from the reference configuration through every ``STRIDE``-th
sample of a path, or of a grid's lines up to their last chunk's first sample (a
grid row by row, in a serpentine; a line of at most ``LINE_CHUNK`` samples, one chunk, at its
first sample only), and gives each chunk its seed; every chunk then runs from
its seed, in this process or on a Dask worker (:mod:`pinmob.parallel`), so
``workers=N`` gives the rows of ``workers=1``, and each sample costs at most
``1 + 1/STRIDE`` assemblies plus two per chunk (its neighbours on the line, for
the refinement). The chunks run in groups (:func:`chunk_groups`: up to ``GROUP`` on a Dask worker,
``LOCAL_GROUP`` in this process; the first chunk alone when its pace decides where the others run), each group as
one job: with the
batched engine (``spec.engine``, the default) its chunks' samples are assembled in lockstep and analysed in one batch
(:mod:`pinmob.scan.lockstep`, :mod:`pinmob.scan.batch_rows`), the single-sample analysis
(:func:`pinmob.analysis.singularity.classification.singularity`, one kinematics computation per
sample) only where the batch cannot decide; with ``single``, each sample on its own. Both give
the same rows (``tests/test_scan_batch.py``), where the walk's continuation is unique: at a turn of the walk
across a singular region the single-sample solver may close a waypoint on another assembly branch than the
predictor (:func:`~pinmob.scan.seeding_walk.chunk_seeds`).

Refinement (:mod:`pinmob.scan.refine`): a singularity between samples is looked for
where, along a line, a distance to singularity has a local minimum above
``rtol`` (each question on its own: constraint, actuation, each limb) that is
below the near-singular band or that the V through the three samples puts
below half its value, and where a sample borders one that cannot be assembled
(the edge of the reachable set, where a limb's inverse kinematics is singular).
A sample that is already singular is not refined. The line parameter is refined
(re-assembling warm-started at each trial, up to ``REFINE_ITER`` solver
iterations) and the best point is reported as an extra row (``refined`` True,
``index`` the sample before it) when its distance is below the near-singular
band ``NEAR_FACTOR * rtol``; it may then be singular or only near-singular.

Rows come a group of chunks at a time, as a table (:class:`~pinmob.scan.results.table.ScanTable`: one array per
column), in order of the line parameter (memory flat in the number of samples: :meth:`ScanRun.tables`); targets
that cannot be assembled give a row with ``reachable = False``. :func:`scan` writes them to the output files as
they come and returns the :class:`~pinmob.scan.results.scan_report.ScanReport`.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

from pinmob.exceptions import EngineError
from pinmob.model import Mechanism
from pinmob.output_files import check_target
from pinmob.parallel import Engine, Lost
from pinmob.scan.chain_scan import CHAIN_COLUMNS, value_columns
from pinmob.scan.chunk import FINITE_COLUMNS
from pinmob.scan.lockstep import GROUP, LOCAL_GROUP, Job, run_group
from pinmob.scan.results.output import RowWriter
from pinmob.scan.results.scan_report import ScanReport, Summary, describe, scan_meta
from pinmob.scan.results.table import ScanTable
from pinmob.scan.scan_spec import POSE_COORDS, ScanSpec
from pinmob.scan.seeding_walk import chunk_seeds
from pinmob.scan.unreachable import SV_COLUMNS, VERDICT_COLUMNS

#: The columns a scan with a raised closure tolerance (``spec.cad``) adds: each assembled sample's largest closure
#: residual on the file's mechanism (position / L, rotation [rad]) and the rank tolerance of its decisions.
CAD_COLUMNS = ("residual", "rank_rtol")

#: A scan whose remaining chunks would take less than this [s] in this process stays in this process: starting a
#: ``LocalCluster`` (worker processes importing Pinocchio and pinmob) costs a few seconds.
CLUSTER_MIN_SECONDS = 10.0


def chunk_groups(mech: Mechanism, spec: ScanSpec, first_alone: bool = True, size: int = GROUP) -> Iterator[list[Job]]:
    """The chunks of :func:`~pinmob.scan.seeding_walk.chunk_seeds` in groups of up to ``size``, each run as one job (:func:`run_group`).

    With ``first_alone``, the first chunk is a group of its own (:class:`ScanRun` times it to decide where the
    others run). ``size``: ``GROUP`` for Dask workers, ``LOCAL_GROUP`` in this process. The rows do not depend on
    the groups.
    """
    group: list[Job] = []
    for job in chunk_seeds(mech, spec):
        group.append(job)
        if len(group) == size or (first_alone and job[0] == 0):
            yield group
            group = []
    if group:
        yield group


def scan_tables(mech: Mechanism, spec: ScanSpec) -> Iterator[ScanTable]:
    """The scan's rows computed in this process, a table per group (what :func:`scan` does with one worker)."""
    names = columns(spec)
    for group in chunk_groups(mech, spec, first_alone=False, size=LOCAL_GROUP):
        yield run_group(mech, spec, group).table(names)


def scan_table(mech: Mechanism, spec: ScanSpec) -> ScanTable:
    """Every row of the scan computed in this process, as one table."""
    return ScanTable.concat(scan_tables(mech, spec), columns(spec))


def scan_in_process(mech: Mechanism, spec: ScanSpec) -> Iterator[dict[str, Any]]:
    """The scan's rows computed in this process, as dicts, one at a time (:func:`scan_tables`' rows)."""
    for table in scan_tables(mech, spec):
        yield from table.rows()


def _group_task(shared: tuple[Mechanism, ScanSpec], group: list[Job]) -> ScanTable:
    """One group of chunks on a worker (:meth:`pinmob.parallel.cluster.Engine.map`), as a table."""
    return run_group(shared[0], shared[1], group).table(columns(shared[1]))


def _samples(group: list[Job]) -> int:
    return sum(stop - start for start, stop, _ in group)


class ScanRun:
    """The rows of a scan, a table at a time (:meth:`tables`; or iterate over its rows).

    :attr:`where` says where the chunks ran.

    The first group of chunks runs in this process (with ``workers > 1`` or a ``scheduler``, the first chunk
    alone, to time it). With ``workers > 1`` the others go to a
    Dask ``LocalCluster`` only when, at the first chunk's pace, they would take
    more than ``CLUSTER_MIN_SECONDS`` here; with a ``scheduler`` they go to that
    cluster. The rows do not depend on where they were computed.
    """

    def __init__(
        self, mech: Mechanism, spec: ScanSpec, workers: int, progress: bool | None, scheduler: str | None
    ) -> None:
        self.mech, self.spec = mech, spec
        self.engine = Engine(workers, scheduler)  # checks workers
        self.progress = progress
        self.where = "1 worker (this process)"

    def __iter__(self) -> Iterator[dict[str, Any]]:
        for table in self.tables():
            yield from table.rows()

    def tables(self) -> Iterator[ScanTable]:
        """The rows, a group of chunks at a time (in order of the line parameter)."""
        from tqdm import tqdm

        spec = self.spec
        names = columns(spec)
        disable = (None if spec.size >= 50 else True) if self.progress is None else not self.progress
        bar = tqdm(total=spec.size, disable=disable, unit="sample", desc=f"scan {self.mech.name}", leave=False)
        local = self.engine.in_process  # in process: no pace needed, and the larger groups
        groups = chunk_groups(self.mech, spec, first_alone=not local, size=LOCAL_GROUP if local else GROUP)
        try:
            first = next(groups, None)
            if first is None:
                return
            t0 = time.perf_counter()
            table = run_group(self.mech, spec, first).table(names)
            pace = (time.perf_counter() - t0) / max(1, _samples(first))
            bar.update(_samples(first))
            yield table
            left = spec.size - _samples(first)
            engine = self.engine
            if engine.in_process or (engine.scheduler is None and pace * left < CLUSTER_MIN_SECONDS):
                if not engine.in_process:
                    self.where = f"1 worker (this process: too small to pay for {engine.workers} workers)"
                for group in groups:
                    table = run_group(self.mech, spec, group).table(names)
                    bar.update(_samples(group))
                    yield table
                return
            with engine:
                self.where = engine.describe()
                for result in engine.map(_group_task, (self.mech, spec), groups):
                    if isinstance(result, Lost):
                        raise EngineError(f"a scan chunk could not be computed: {result.reason}; the scan stopped")
                    bar.update(int((~result["refined"]).sum()))
                    yield result
                if engine.lost_workers:
                    self.where += f"; {engine.lost_workers} worker(s) lost and replaced, their chunks computed again"
        finally:
            bar.close()


def scan(
    mech: Mechanism,
    spec: ScanSpec,
    workers: int = 1,
    progress: bool | None = None,
    scheduler: str | None = None,
    *,
    csv: str | None = None,
    json: str | None = None,
    parquet: str | None = None,
    overwrite: bool = False,
    keep_rows: bool = True,
) -> ScanReport:
    """Scan ``mech``: its rows (samples and refined points) written to the files as they come, and its report.

    Args:
        mech: the mechanism.
        spec: what to scan (:mod:`pinmob.scan.scan_spec`).
        workers: worker processes of a Dask ``LocalCluster`` (1: this process); the rows do not depend on it.
        progress: show a tqdm bar on stderr (None: only for scans of 50 samples or more on a terminal).
        scheduler: address of an existing Dask cluster's scheduler to run the chunks on.
        csv: a CSV file to write the rows to, a table at a time (:class:`~pinmob.scan.results.output.RowWriter`; an
            interruption leaves the files as they were).
        json: a JSON file to write them to.
        parquet: a Parquet file to write them to.
        overwrite: replace files that exist.
        keep_rows: keep every row in the report (``report.table``; iterate over the report for the rows as
            dicts); False keeps memory flat in the number of samples (the summary needs no row kept).

    Returns:
        the :class:`~pinmob.scan.results.scan_report.ScanReport`: ``str(report)`` is the summary ``pinmob scan`` prints.

    Raises:
        ConfigurationError: ``workers`` is not a positive whole number; an output file may not be written.
        EngineError: the cluster cannot be used, loses every worker, or a chunk kills its workers each time.
    """
    files = {k: str(check_target(f"`{k}`", p, overwrite, "overwrite")) for k, p in
             (("csv", csv), ("json", json), ("parquet", parquet)) if p is not None}  # fmt: skip
    run = ScanRun(mech, spec, workers, progress, scheduler)
    rank_rtol = spec.reference_rtol(mech)
    what = describe(spec, rank_rtol)
    summary = Summary(spec.platform, spec.finite_order is not None)
    kept: list[ScanTable] = []
    t0 = time.perf_counter()
    with RowWriter(columns(spec), scan_meta(mech, spec, what, rank_rtol), files.get("csv"), files.get("json"),
                   files.get("parquet")) as writer:  # fmt: skip
        for table in run.tables():
            writer.write_table(table)
            summary.add(table)
            if keep_rows:
                kept.append(table)
    seconds = time.perf_counter() - t0
    rows = ScanTable.concat(kept, columns(spec)) if keep_rows else None
    return ScanReport(mech.name, spec, what, summary, seconds, run.where, rank_rtol, tuple(mech.actuated), files,
                      rows)  # fmt: skip


def columns(spec: ScanSpec) -> list[str]:
    """CSV columns of a scan's rows, in order."""
    params = list(spec.params(0))
    finite = list(FINITE_COLUMNS) if spec.finite_order is not None else []
    cad = list(CAD_COLUMNS) if spec.cad else []
    if not spec.platform:
        return ["index", *params, "refined", *value_columns(spec.values), *CHAIN_COLUMNS, *finite, *cad]
    return ["index", *params, "refined", *POSE_COORDS, *VERDICT_COLUMNS, *SV_COLUMNS, *finite, "reason",
            *value_columns(spec.values), *cad]  # fmt: skip
