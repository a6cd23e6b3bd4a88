"""Chunks of a scan run together: their samples assembled in lockstep and analysed in one batch.

A group of up to ``GROUP`` chunks (:func:`pinmob.scan.scan_run.chunk_groups`) runs as one
job. Step j assembles the j-th sample of every chunk of the group, each
warm-started from the previous sample of its own chunk (the continuation of the
single-sample path, so the same assembly branch), by the batched predictor
(:func:`pinmob.assembly.batched.batch_solver.solve_poses`: damped Newton steps over all
those samples at once, each stopped within :data:`~pinmob.scan.predictor.PREDICT_TOL`, not polished on: a
configuration that close to closure gives the same row to far below the 1e-7 the
engines agree to). A sample it did not bring within that tolerance (out of
reach, a stall, a step that diverged) goes to the single-sample solver
(:func:`pinmob.scan.chunk.assemble_target`) from its warm start, exactly as on
the single-sample path: an unreachable verdict and its reason are that solver's. A step works on the stack of
its samples: their targets are rows of pose-coordinate vectors built for the whole group at once
(:meth:`pinmob.scan.scan_spec.ScanSpec.pose_targets`), their secant starts and the check of them are computed over the stack
(:func:`~pinmob.assembly.moved_stack`, :func:`~pinmob.assembly.off_secants`; with numba, one compiled call with
the solve: :func:`~pinmob.assembly.close_moved`). A grid or a path that gives joint values (the designer's
motors) runs on the predictor too: those joints are held at their values in each start and no step moves them,
the pose coordinates not given are unknowns (:class:`~pinmob.scan.predictor.Predictor`). Joints with more than
one coordinate, mechanisms without a platform or with closures besides the limb tips are assembled by the
single-sample solver alone.

The group's samples are then analysed in one batch (:mod:`pinmob.scan.batch_rows`);
a predicted sample the batch does not decide (singular or close to it) is polished
again by the single-sample solver from the predictor's configuration (its
Gauss-Newton steps end ~1e-8 from a singular solution, a double root, where the
predictor's damped steps stop earlier; where the targets give joint values, from the sample's seed, as on the
single-sample path: where the actuators leave a motion uncontrolled, the configuration is one of a continuum)
and analysed on its own. The samples a refinement may refine are screened for all the group's chunks at once
(:func:`pinmob.scan.chunk.to_refine`); each chunk refines
and orders its rows (:meth:`pinmob.scan.chunk._Chunk.complete`, the refinements
on the single-sample path). The rows the batch decided keep their verdicts in its columns
(:class:`~pinmob.scan.group_rows.GroupRows`) until the group's table is made: no row dict is built for them.
With ``spec.engine == "single"`` the chunks run one after the other, each sample on its own.
"""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import nullcontext
from typing import Any

import numpy as np

from pinmob.blas import one_blas_thread
from pinmob.collector import collector_paused
from pinmob.model import Mechanism
from pinmob.scan.batch_rows import Analysed
from pinmob.scan.chunk import _Chunk, _Sample, _seed, run_chunk, to_refine
from pinmob.scan.group_rows import BatchRow, GroupRows, Head
from pinmob.scan.predictor import Predictor
from pinmob.scan.row_columns import values_and_limits
from pinmob.scan.scan_spec import ScanSpec
from pinmob.screw import Array

#: Chunks per group sent to a Dask worker (samples assembled in lockstep: up to GROUP per step), its unit of work.
#: Each step has a cost of its own (its Python and compiled calls): a 21 x 21 grid in process runs 21 steps with 32,
#: 42 with 16 (about a tenth of the 3-PUU's time).
GROUP = 32

#: Chunks per group in the process that runs the scan (:func:`pinmob.scan.scan_run.chunk_groups`): more lines per step
#: than a worker's group, where no other worker waits for the groups. A 41 x 41 grid runs 41 steps in one group,
#: not 82 in a group of 32 lines and one of 9 (the 3-PUU's, in process: about a tenth less time). A group holds its
#: samples until its table is made: up to 64 lines of at most 128 samples.
LOCAL_GROUP = 64

#: A chunk to run: (start, stop, seed) (:func:`pinmob.scan.seeding_walk.chunk_seeds`).
Job = tuple[int, int, Array]


@one_blas_thread
def run_group(mech: Mechanism, spec: ScanSpec, jobs: list[Job]) -> GroupRows:
    """The rows of the chunks ``jobs``, in order (module docstring); those the batch decided kept as its columns.

    :meth:`GroupRows.table <pinmob.scan.group_rows.GroupRows.table>` makes their table. The garbage collector's
    automatic passes are paused meanwhile (:data:`~pinmob.collector.collector_paused`: the group's objects make hardly
    a reference cycle, 5 objects in a 41 x 41 scan), except with ``spec.finite_order``: each sample's finite analysis
    refers back to its configuration, a cycle a sample that only the collector frees (a 21 x 21 6-UPS grid held
    0.9 GB more paused).
    """
    with collector_paused if spec.finite_order is None else nullcontext():
        return _run_group(mech, spec, jobs)


def _run_group(mech: Mechanism, spec: ScanSpec, jobs: list[Job]) -> GroupRows:
    """:func:`run_group`'s rows."""
    if not Predictor.applies(mech, spec):
        return GroupRows([row for job in jobs for row in run_chunk(mech, spec, *job)])
    predictor = Predictor(spec.assembly_mechanism(mech), spec)  # the CAD gaps held (spec.cad): closes exactly
    chunks = [_Chunk(mech, spec) for _ in jobs]
    plans = [list(chunk.line_samples(start, stop)) for chunk, (start, stop, _) in zip(chunks, jobs)]
    neighbours = [c for c, (start, _, _) in enumerate(jobs) if spec.line(start)[0] < start]
    group = _Lockstep(predictor, chunks, [seed for _, _, seed in jobs],
                      [k for plan in plans for k in plan] + [jobs[c][0] - 1 for c in neighbours])  # fmt: skip
    for j in range(max(len(p) for p in plans)):
        group.step([(c, plan[j], group.last[c]) for c, plan in enumerate(plans) if j < len(plan)], secant=True)
    if neighbours:  # each chunk's left neighbour, warm-started from its first sample
        group.lost = {c for c in neighbours if group.pending[c][jobs[c][0]].q is None}
        for c in neighbours:
            group.last_k[c] = jobs[c][0] if group.pending[c][jobs[c][0]].q is not None else None
        group.step([(c, jobs[c][0] - 1, _seed(group.pending[c][jobs[c][0]], jobs[c][2])) for c in neighbours])
    pending = group.pending
    batch, where = chunks[0].batch_analysis([s for p in pending for s in p.values()])
    entries = iter(where)  # per sample, its entry in the batch where the batch decided it
    mine: list[list[int | None]] = [[next(entries) for _ in p] for p in pending]
    again_q: dict[tuple[int, int | None], Array] = {}  # (chunk, sample): its configuration solved again
    for c, chunk in enumerate(chunks):
        for (k, sample), decided in zip(list(pending[c].items()), mine[c]):  # in the order they were assembled
            if decided is None and (c, k) in group.predicted and sample.q is not None:  # singular or close to it:
                # the single-sample solver's polish (~1e-8 from a double root); where the targets give joint values,
                # from the sample's seed, as the single-sample path: with motions the actuators do not control, the
                # configuration is one of a continuum, and the solver's own choice is the row's (its seed: the
                # sample before, as solved again when it was, as on the single-sample path)
                seed = again_q.get((c, group.origin[c, k]), group.seeds[c, k]) if group.joints is not None else sample.q
                again = chunk.assemble(k, seed)
                pending[c][k] = again if again.q is not None else sample
                if again.q is not None:
                    again_q[c, k] = again.q
    columns = iter(values_and_limits(mech, spec.values, [s for p in pending for s in p.values()]))  # at once
    rows: list[dict[str, Any] | BatchRow] = []
    columnar = batch is not None and spec.finite_order is None  # the finite DoF are added to row dicts
    done = []
    for c, chunk in enumerate(chunks):
        analysed: Sequence[Analysed | int | None] = mine[c] if columnar or batch is None else batch.analysed(mine[c])
        done.append(chunk.done(pending[c], analysed, [next(columns) for _ in pending[c]], batch if columnar else None))
    refine = to_refine([(start, stop, *spec.line(start), d.entries) for (start, stop, _), d in zip(jobs, done)],
                       batch if columnar else None, chunks[0].rtol)  # fmt: skip
    for c, (start, stop, _) in enumerate(jobs):
        rows += chunks[c].complete(start, stop, done[c], refine[c])
    return GroupRows(rows, batch)


class _Lockstep:
    """A group's chunks assembled in lockstep (:func:`run_group`): their samples so far and the state of each line.

    The targets of all the samples the group assembles (``samples``) are built at once, as vectors
    (:meth:`ScanSpec.pose_targets`, with their :meth:`ScanSpec.param_columns`).
    """

    def __init__(self, predictor: Predictor, chunks: list[_Chunk], seeds: list[Array], samples: list[int]) -> None:
        spec = predictor.spec
        self.predictor, self.chunks, self.kind = predictor, chunks, spec.target_kind
        ks = list(dict.fromkeys(samples))
        self.row = {k: i for i, k in enumerate(ks)}
        #: the samples' line parameters, a row per sample (as ``poses``): their heads are rows of them (:class:`Head`)
        self.params = spec.param_columns(ks)
        self.poses = spec.pose_targets(ks, self.params)
        #: the joint values the targets give (:attr:`Predictor.joints`), a row per sample as ``poses``
        self.joints = spec.joint_targets(ks, self.params) if predictor.joints else None
        self.pending: list[dict[int, _Sample]] = [{} for _ in chunks]
        self.predicted: set[tuple[int, int]] = set()  # (chunk, sample) closed by the predictor
        self.seeds: dict[tuple[int, int], Array] = {}  # (chunk, sample): its warm start, where the predictor closed it
        #: (chunk, sample): the sample whose configuration was its warm start (None: the chunk's seed)
        self.origin: dict[tuple[int, int], int | None] = {}
        self.last_k: list[int | None] = [None] * len(chunks)  # the sample that gave each chunk's ``last``
        self.lost: set[int] = set()  # chunks whose last sample did not assemble
        self.last = list(seeds)  # each chunk's last closed configuration (its seed at first)
        self.before: list[Array | None] = [None] * len(chunks)  # the closed sample before the last, when it closed

    def step(self, work: list[tuple[int, int, Array]], secant: bool = False) -> None:
        """Assemble sample k of chunk c from ``seed`` for each ``(c, k, seed)``: the predictor batched, else on its own.

        A chunk whose previous sample did not assemble (its seed is then the last one that did, further away: out
        of reach, most likely, again) skips the predictor: the single-sample solver from that seed, as before. With
        ``secant`` (the forward pass along the chunks' lines), the predictor starts a chunk whose last two samples
        closed from their secant, extrapolated one sample on (:func:`~pinmob.assembly.moved_stack`; from the seed again where
        the steps went off it, :func:`~pinmob.assembly.off_secants`), and ``before`` is kept up to date. A sample the predictor did not
        close gets its target (:meth:`ScanSpec.target`) for the single-sample solver.
        """
        predictor, kind = self.predictor, self.kind
        tried = [i for i, (c, _, _) in enumerate(work) if c not in self.lost]
        found: list[tuple[Array, Array, Array] | None] = [None] * len(work)
        if tried:
            seeds = np.array([work[i][2] for i in tried], float)
            rows = [self.row[work[i][1]] for i in tried]
            poses = self.poses[rows]  # NaN where following: close seeds them
            joints = None if self.joints is None else self.joints[rows]
            behind = [self.before[work[i][0]] for i in tried] if secant else []
            has = np.array([b is not None for b in behind], bool)
            moves = None
            if has.any():  # a secant start that needs a correction longer than its step: from the seed instead
                moves = (np.array([seeds[j] if b is None else b for j, b in enumerate(behind)]), seeds, has)
            closed = predictor.close(poses, seeds, kind, joints=joints, moves=moves)
            for j in np.flatnonzero(closed.converged):
                found[tried[j]] = (closed.q[j], closed.jacobians[j], closed.platform[j])
        first = self.chunks[0]  # a predicted sample as _Chunk.assemble makes it, with the predictor's kinematics
        plain = self.joints is None and first.takes_closed and predictor.mech is first.mech
        for (c, k, seed), got in zip(work, found):
            chunk, pending = self.chunks[c], self.pending[c]
            head = Head(k, self.params, self.row[k])
            if got is not None and plain:
                sample = _Sample(head, got[0], {}, {}, got[1:])
            elif got is not None:  # the target built where it gives joint values: the sample's known values
                target = chunk.spec.target(k, head.line_params()) if self.joints is not None else None
                sample = chunk.assemble(k, got[0], closed=got[0], target=target, params=head)
                if predictor.mech is chunk.mech:  # not on a model with CAD gaps held (spec.cad)
                    sample.kinematics = got[1:]
            else:
                sample = chunk.assemble(k, seed, params=head)
            pending[k] = sample
            if secant:
                previous = pending.get(k - 1)
                self.before[c] = (
                    seed if sample.q is not None and previous is not None and previous.q is not None else None
                )
            self.last[c] = _seed(sample, seed)
            if got is not None:
                self.predicted.add((c, k))
                self.seeds[c, k], self.origin[c, k] = seed, self.last_k[c]
            if sample.q is not None:
                self.last_k[c] = k
            if sample.q is None:
                self.lost.add(c)
            else:
                self.lost.discard(c)
