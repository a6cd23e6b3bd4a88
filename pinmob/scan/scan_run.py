"""Scans: mobility and singularities along a path or over a workspace slice.

What is scanned, in which order, is a :class:`pinmob.scan.scan_spec.ScanSpec`. Each
target is assembled warm-started (the previous sample's configuration seeds
the closure solver of the next). One coarse walk (:func:`chunk_seeds`, in this
process) goes from the reference configuration through every ``STRIDE``-th
sample of a path, or of a grid's lines up to their last chunk's first sample (a
grid row by row, in a serpentine; a line of at most ``CHUNK`` samples at its
first sample only), and gives each chunk its seed; every chunk then runs from
its seed, in this process or on a Dask worker (:mod:`pinmob.parallel`), so
``workers=N`` gives the rows of ``workers=1``, and each sample costs at most
``1 + 1/STRIDE`` assemblies plus two per chunk (its neighbours on the line, for
the refinement). The chunks run in groups (:func:`chunk_groups`: up to ``GROUP``; the first
chunk alone when its pace decides where the others run), each group as one job: with the
batched engine (``spec.engine``, the default) its chunks' samples are assembled in lockstep and analysed in one batch
(:mod:`pinmob.scan.lockstep`, :mod:`pinmob.scan.batch_rows`), the single-sample analysis
(:func:`pinmob.analysis.singularity.classification.singularity`, one kinematics computation per
sample) only where the batch cannot decide; with ``single``, each sample on its own. Both give
the same rows (``tests/test_scan_batch.py``), where the walk's continuation is unique: at a turn of the walk
across a singular region the single-sample solver may close a waypoint on another assembly branch than the
predictor (:func:`chunk_seeds`).

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

import numpy as np

import pinmob.scan.chunk as chunk
from pinmob.assembly import pose_vector
from pinmob.exceptions import EngineError, PinmobError
from pinmob.model import Mechanism
from pinmob.output_files import check_target
from pinmob.parallel import Engine, Lost
from pinmob.scan.chain_scan import CHAIN_COLUMNS, value_columns
from pinmob.scan.chunk import FINITE_COLUMNS
from pinmob.scan.lockstep import GROUP, Job, moved_stack, off_secant, run_group
from pinmob.scan.predictor import Predictor
from pinmob.scan.results.output import RowWriter
from pinmob.scan.results.scan_report import ScanReport, Summary, describe, scan_meta
from pinmob.scan.results.table import ScanTable
from pinmob.scan.scan_spec import CHUNK, POSE_COORDS, ScanSpec
from pinmob.scan.unreachable import SV_COLUMNS, VERDICT_COLUMNS
from pinmob.screw import Array

#: The columns a scan with a raised closure tolerance (``spec.cad``) adds: each assembled sample's largest closure
#: residual on the file's mechanism (position / L, rotation [rad]) and the rank tolerance of its decisions.
CAD_COLUMNS = ("residual", "rank_rtol")

#: A scan whose remaining chunks would take less than this [s] in this process stays in this process: starting a
#: ``LocalCluster`` (worker processes importing Pinocchio and pinmob) costs a few seconds.
CLUSTER_MIN_SECONDS = 10.0


def chunk_seeds(mech: Mechanism, spec: ScanSpec) -> Iterator[tuple[int, int, Array]]:
    """``(start, stop, seed)`` of every chunk, in order, from one coarse walk (:meth:`ScanSpec.waypoints`).

    The seed is the walk's configuration at the chunk's first sample (or, when that does not assemble, at the
    last waypoint that did). A waypoint one even step on from the two before it (in sample index or in the
    target's coordinates: the approach from the reference, a grid's first column, a path's every ``STRIDE``-th
    sample), both closed, is closed by the batched predictor from their secant
    (:func:`~pinmob.scan.lockstep.secant_starts`), as the chunks' samples are, and kept only when its Newton
    correction was at most ``WALK_SECANT`` of the secant's step (:func:`~pinmob.scan.lockstep.off_secant`).
    At a turn of the walk (the first waypoints of a line), where the two before are not in line with it, the
    predictor starts from the last waypoint's configuration moved as the same two samples moved on the line
    before (or after, on a three-coordinate grid's serpentine; :func:`_across_waypoint`), when both were walked
    and closed and the target moves by as much between them, with the same check of the correction against
    that move. Every other waypoint (the first, the turns of the first two lines, one the predictor did not
    close or closed off the secant) is closed by the single-sample solver from the waypoint before: the walk's
    steps can be long, and the predictor from a plain warm start could close them on other joint values (U
    joints turned by pi: the 3-UPU-wrist over yaw and pitch) and so seed the chunks on another assembly branch.
    The walk advances only as far as the chunks asked for so far need (chunks are produced lazily).
    """
    stops = dict(spec.chunks())
    order = list(stops)
    found: dict[int, Array] = {}
    q = np.array(spec.q_ref, float)
    solver = spec.assembly_mechanism(mech)  # mech, or with the reference's CAD gaps held
    predictor = Predictor(solver, spec) if Predictor.applies(mech, spec) else None
    # the last two waypoints and their closed configurations; a grid's walk starts at the reference's coordinates
    here: Walked = (
        None,
        _target_values(spec.coordinates_target(dict(spec.start))) if predictor and spec.start else None,
    )
    behind: list[tuple[Walked, Array | None]] = [((None, None), None), (here, q)]
    n = spec.line_size if spec.kind == "grid" else 0
    walked: dict[int, tuple[Walked, Array | None]] = {}  # the lines' waypoints so far, by sample index
    for target, k in spec.waypoints():
        here = (k, _target_values(target) if predictor else None)  # the moves compared only for the predictor
        closed = _secant_waypoint(predictor, target, here, behind)
        if closed is None and predictor is not None and n and k is not None and behind[1][0][0] is not None:
            closed = _across_waypoint(predictor, target, here, behind[1], walked, n)
        if closed is None:
            try:
                closed = chunk.assemble_target(solver, target, q, tol=spec.closure_tol)
            except PinmobError:
                pass
        if k is not None and n:
            walked[k] = ((None, here[1]), closed)
            if len(walked) > 8 * CHUNK:  # only the lines next to the walk's are read
                walked = {i: w for i, w in walked.items() if abs(i - k) <= 2 * n}
        if closed is not None:
            q = closed
        behind = [behind[1], (here, closed)]
        if k in stops:
            found[k] = q
        while order and order[0] in found:
            start = order.pop(0)
            yield start, stops[start], found.pop(start)


#: A walk's waypoint closed by the predictor is kept when its Newton correction is at most this fraction of the
#: secant's step (joint metric): the walk's steps can be long (a path's 8 samples, a 3-coordinate grid's turn of
#: lines), where a correction of the order of the step closed a 3-RPS's spherical joint on its other Euler triple.
#: Along the benchmark grids' first columns the correction is at most 0.17 of the step.
WALK_SECANT = 0.25

#: Where the walk is: a waypoint's sample index (None: on the approach) and its target's coordinate values.
Walked = tuple[int | None, Array | None]


def _target_values(target: tuple[str, Any]) -> Array:
    """A target's coordinates as a vector (pose coordinates, then joint values), to compare moves."""
    kind, value = target
    if kind == "pose":
        return pose_vector(value)
    if kind == "coords":
        return np.array([*value[0].values(), *value[1].values()], float)
    return np.array(list(value.values()), float)


def _even(here: Walked, mid: Walked, back: Walked) -> bool:
    """True when the move from ``mid`` to ``here`` is the move from ``back`` to ``mid`` (sample index or values)."""
    (k, v), (k2, v2), (k1, v1) = here, mid, back
    if k is not None and k1 is not None and k2 is not None and k - k2 == k2 - k1:
        return True
    return _same_move((v2, v), (v1, v2))


def _same_move(one: tuple[Array | None, Array | None], other: tuple[Array | None, Array | None]) -> bool:
    """True when the target's values move as much from ``one[0]`` to ``one[1]`` as from ``other[0]`` to ``other[1]``."""
    values = [v for v in (*one, *other) if v is not None]
    if len(values) < 4 or any(v.shape != values[0].shape for v in values):
        return False
    a0, a1, b0, b1 = values
    step = float(np.linalg.norm(b1 - b0))
    return step > 0.0 and float(np.linalg.norm((a1 - a0) - (b1 - b0))) <= 1e-9 * step


def _secant_waypoint(
    predictor: Predictor | None, target: tuple[str, Any], here: Walked, behind: list[tuple[Walked, Array | None]]
) -> Array | None:
    """A waypoint closed by the predictor from the secant of the two before it (:func:`chunk_seeds`), else None."""
    (back, q1), (mid, q2) = behind
    if predictor is None or q1 is None or q2 is None or not _even(here, mid, back):
        return None
    return _moved_waypoint(predictor, target, q2, q1, q2)


def _across_waypoint(
    predictor: Predictor,
    target: tuple[str, Any],
    here: Walked,
    last: tuple[Walked, Array | None],
    walked: dict[int, tuple[Walked, Array | None]],
    n: int,
) -> Array | None:
    """A grid's waypoint closed by the predictor from the walk's last one, moved as on a line next to them, or None.

    ``last``: the walk's last waypoint (index and values) and its configuration; ``walked``: the grid's waypoints
    so far by sample index; ``n``: the line size. When the same two samples one line before (or after) were
    walked and closed, and the target moves by as much between them (compared by their values), the start is the
    last configuration moved by their move (:func:`chunk_seeds`).
    """
    (k, v), ((kq, vq), q) = here, last
    if q is None or k is None or kq is None:
        return None
    for side in (-n, n):
        (_, v0), q0 = walked.get(kq + side, ((None, None), None))
        (_, v1), q1 = walked.get(k + side, ((None, None), None))
        if q0 is not None and q1 is not None and _same_move((vq, v), (v0, v1)):
            return _moved_waypoint(predictor, target, q, q0, q1)
    return None


def _moved_waypoint(predictor: Predictor, target: tuple[str, Any], seed: Array, a: Array, b: Array) -> Array | None:
    """``target`` closed by the predictor from ``seed`` moved by ``b - a``, else None.

    None where it did not close or its correction was longer than ``WALK_SECANT`` times that move
    (:func:`~pinmob.scan.lockstep.off_secant`).
    """
    start = moved_stack(predictor.problem, a[None], b[None], np.ones(1, bool), seed[None])[0][0]
    (closed,) = predictor.closed([target], [seed], [start])
    return None if closed is None or off_secant(predictor.problem, seed, start, closed, WALK_SECANT) else closed


def chunk_groups(mech: Mechanism, spec: ScanSpec, first_alone: bool = True) -> Iterator[list[Job]]:
    """The chunks of :func:`chunk_seeds` in groups of up to ``GROUP``, each run as one job (:func:`run_group`).

    With ``first_alone``, the first chunk is a group of its own (:class:`ScanRun` times it to decide where the
    others run). The rows do not depend on the groups.
    """
    group: list[Job] = []
    for job in chunk_seeds(mech, spec):
        group.append(job)
        if len(group) == GROUP or (first_alone and job[0] == 0):
            yield group
            group = []
    if group:
        yield group


def scan_tables(mech: Mechanism, spec: ScanSpec) -> Iterator[ScanTable]:
    """The scan's rows computed in this process, a table per group (what :func:`scan` does with one worker)."""
    names = columns(spec)
    for group in chunk_groups(mech, spec, first_alone=False):
        yield ScanTable.from_rows(names, run_group(mech, spec, group))


def scan_table(mech: Mechanism, spec: ScanSpec) -> ScanTable:
    """Every row of the scan computed in this process, as one table."""
    return ScanTable.concat(scan_tables(mech, spec), columns(spec))


def scan_in_process(mech: Mechanism, spec: ScanSpec) -> Iterator[dict[str, Any]]:
    """The scan's rows computed in this process, as dicts, one at a time (:func:`scan_tables`' rows)."""
    for table in scan_tables(mech, spec):
        yield from table.rows()


def _group_task(shared: tuple[Mechanism, ScanSpec], group: list[Job]) -> ScanTable:
    """One group of chunks on a worker (:meth:`pinmob.parallel.cluster.Engine.map`), as a table."""
    return ScanTable.from_rows(columns(shared[1]), run_group(shared[0], shared[1], group))


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
        groups = chunk_groups(self.mech, spec, first_alone=not self.engine.in_process)  # in process: no pace needed
        try:
            first = next(groups, None)
            if first is None:
                return
            t0 = time.perf_counter()
            table = ScanTable.from_rows(names, run_group(self.mech, spec, first))
            pace = (time.perf_counter() - t0) / max(1, _samples(first))
            bar.update(_samples(first))
            yield table
            left = spec.size - _samples(first)
            engine = self.engine
            if engine.in_process or (engine.scheduler is None and pace * left < CLUSTER_MIN_SECONDS):
                if not engine.in_process:
                    self.where = f"1 worker (this process: too small to pay for {engine.workers} workers)"
                for group in groups:
                    table = ScanTable.from_rows(names, run_group(self.mech, spec, group))
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
