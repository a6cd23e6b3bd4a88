"""Chunks of a scan run together: their samples assembled in lockstep and analysed in one batch.

A group of up to ``GROUP`` chunks (:func:`pinmob.scan.run.chunk_groups`) runs as one
job. Step j assembles the j-th sample of every chunk of the group, each
warm-started from the previous sample of its own chunk (the continuation of the
single-sample path, so the same assembly branch), by the batched predictor
(:func:`pinmob.assembly.batch_solver.solve_poses`: damped Newton steps over all
those samples at once, each stopped within ``PREDICT_TOL``, not polished on: a
configuration that close to closure gives the same row to far below the 1e-7 the
engines agree to). A sample it did not bring within ``PREDICT_TOL`` (out of
reach, a stall, a step that diverged) goes to the single-sample solver
(:func:`pinmob.scan.chunk.assemble_target`) from its warm start, exactly as on
the single-sample path: an unreachable verdict and its reason are that solver's. Joint targets (forward kinematics), targets that hold
joints, mechanisms without a platform or with closures besides the limb tips are
assembled by that solver alone.

The group's samples are then analysed in one batch (:mod:`pinmob.scan.batch_rows`);
a predicted sample the batch does not decide (singular or close to it) is polished
again by the single-sample solver from the predictor's configuration (its
Gauss-Newton steps end ~1e-8 from a singular solution, a double root, where the
predictor's damped steps stop earlier) and analysed on its own. Each chunk refines
and orders its rows (:meth:`pinmob.scan.chunk._Chunk.complete`, the refinements
on the single-sample path). With ``spec.engine == "single"``
the chunks run one after the other, each sample on its own.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.assembly.batch_solver import PoseProblem, solve_poses
from pinmob.assembly.reach import POSE_COORDS, pose_vector
from pinmob.blas import one_blas_thread
from pinmob.model.mechanism import Mechanism
from pinmob.scan.chunk import _Chunk, _Sample, _seed, run_chunk
from pinmob.scan.references import platform_pose
from pinmob.scan.spec import ScanSpec
from pinmob.screw.algebra import Array

#: Chunks per group (samples assembled in lockstep: up to GROUP per step).
GROUP = 16

#: A sample the predictor brought within this ``max |e|`` is closed (the predictor stops there: no polish).
PREDICT_TOL = 1e-12

#: A chunk to run: (start, stop, seed) (:func:`pinmob.scan.run.chunk_seeds`).
Job = tuple[int, int, Array]


class Predictor:
    """Starts for the single-sample solver from the batched predictor, for one scan (None: it does not apply)."""

    def __init__(self, mech: Mechanism, spec: ScanSpec) -> None:
        self.mech, self.spec = mech, spec
        self.free = tuple(POSE_COORDS.index(c) for c in spec.following)
        self.problem = PoseProblem(mech, self.free)

    @staticmethod
    def applies(mech: Mechanism, spec: ScanSpec) -> bool:
        """A platform-pose scan of a mechanism whose closures are its limb tips (module docstring)."""
        if spec.engine != "batch" or not spec.platform or not mech.has_platform or not mech.limbs:
            return False
        if mech.closures or any(limb.closures for limb in mech.limbs):  # loops besides the limb tips
            return False
        kind, value = spec.target(0)
        return kind == "pose" or (kind == "coords" and not value[1])

    def closed(
        self, targets: list[tuple[str, Any]], seeds: list[Array], starts: list[Array] | None = None
    ) -> list[Array | None]:
        """Per target (:meth:`ScanSpec.target`), the predictor's closed configuration from its seed, or None.

        Closed: :meth:`~pinmob.assembly.batch_solver.PoseProblem.finish` of a sample it converged; None where it did
        not. ``starts``: where the Newton steps start (default: the seeds; the free coordinates start at the seed's).
        """
        if not targets:
            return []
        poses = np.empty((len(targets), 6))
        for i, ((kind, value), seed) in enumerate(zip(targets, seeds)):
            if kind == "pose":
                poses[i] = pose_vector(value)
                continue
            # the free coordinates start where the seed has them
            poses[i] = pose_vector(platform_pose(self.mech, seed, self.problem.data))
            for c, v in value[0].items():
                poses[i, POSE_COORDS.index(c)] = v
        start = np.array(seeds if starts is None else starts)
        sol = solve_poses(self.problem, start, poses, tol=PREDICT_TOL, floor=PREDICT_TOL)
        out: list[Array | None] = [None] * len(targets)
        for kind in {kind for kind, _ in targets}:
            which = [i for i, (k, _) in enumerate(targets) if k == kind and sol.converged[i]]
            for i, q in zip(which, self.problem.finish(self.mech, sol.q[which], kind)):
                out[i] = q
        return out


@one_blas_thread
def run_group(mech: Mechanism, spec: ScanSpec, jobs: list[Job]) -> list[dict[str, Any]]:
    """The rows of the chunks ``jobs``, in order (module docstring)."""
    if not Predictor.applies(mech, spec):
        return [row for job in jobs for row in run_chunk(mech, spec, *job)]
    predictor = Predictor(spec.assembly_mechanism(mech), spec)  # the CAD gaps held (spec.cad): closes exactly
    chunks = [_Chunk(mech, spec) for _ in jobs]
    plans = [list(chunk.line_samples(start, stop)) for chunk, (start, stop, _) in zip(chunks, jobs)]
    pending: list[dict[int, _Sample]] = [{} for _ in jobs]
    predicted: set[tuple[int, int]] = set()
    lost: set[int] = set()  # chunks whose last sample did not assemble
    last = [seed for _, _, seed in jobs]
    before: list[Array | None] = [None] * len(jobs)  # the chunk's closed sample before its last, when that closed
    for j in range(max(len(p) for p in plans)):
        which = [c for c, plan in enumerate(plans) if j < len(plan)]
        _step(predictor, chunks, pending, predicted, lost, last, [(c, plans[c][j], last[c]) for c in which], before)
    neighbours = [c for c, (start, _, _) in enumerate(jobs) if spec.line(start)[0] < start]
    if neighbours:  # each chunk's left neighbour, warm-started from its first sample
        lost = {c for c in neighbours if pending[c][jobs[c][0]].q is None}
        _step(predictor, chunks, pending, predicted, lost, last,
              [(c, jobs[c][0] - 1, _seed(pending[c][jobs[c][0]], jobs[c][2])) for c in neighbours])  # fmt: skip
    analysed = iter(chunks[0].analysed([s for p in pending for s in p.values()]))
    rows: list[dict[str, Any]] = []
    for c, (start, stop, _) in enumerate(jobs):
        mine = [next(analysed) for _ in pending[c]]
        for (k, sample), decided in zip(list(pending[c].items()), mine):
            if decided is None and (c, k) in predicted and sample.q is not None:  # singular or close to it: the
                again = chunks[c].assemble(k, sample.q)  # single-sample solver's polish (~1e-8 from a double root)
                pending[c][k] = again if again.q is not None else sample
        rows += chunks[c].complete(start, stop, pending[c], mine)
    return rows


def _step(
    predictor: Predictor,
    chunks: list[_Chunk],
    pending: list[dict[int, _Sample]],
    predicted: set[tuple[int, int]],
    lost: set[int],
    last: list[Array],
    work: list[tuple[int, int, Array]],
    before: list[Array | None] | None = None,
) -> None:
    """Assemble sample k of chunk c from ``seed`` for each ``(c, k, seed)``: the predictor batched, else on its own.

    A chunk whose previous sample did not assemble (its seed is then the last one that did, further away: out of
    reach, most likely, again) skips the predictor: the single-sample solver from that seed, as before. With
    ``before`` (the forward pass along the chunks' lines), the predictor starts a chunk whose last two samples
    closed from their secant, extrapolated one sample on (:func:`secant_starts`), and ``before`` is kept up to date.
    """
    spec = predictor.spec
    params = {c: spec.params(k) for c, k, _ in work}
    targets = {c: spec.target(k, params[c]) for c, k, _ in work}
    tried = [w for w in work if w[0] not in lost]
    seeds = [seed for _, _, seed in tried]
    starts = None if before is None else secant_starts(predictor.problem, [before[c] for c, _, _ in tried], seeds)
    closed = predictor.closed([targets[c] for c, _, _ in tried], seeds, starts)
    if starts is not None:  # a secant start that needed a correction longer than its step: from the seed instead
        again = [
            i for i, q in enumerate(closed) if q is not None and off_secant(predictor.problem, seeds[i], starts[i], q)
        ]
        redone = predictor.closed([targets[tried[i][0]] for i in again], [seeds[i] for i in again])
        for i, q in zip(again, redone):
            closed[i] = q
    found = dict(zip([w[0] for w in tried], closed))
    for c, k, seed in work:
        q = found.get(c)
        sample = chunks[c].assemble(k, seed, closed=q, target=targets[c], params=params[c])
        pending[c][k] = sample
        if before is not None:
            previous = pending[c].get(k - 1)
            before[c] = seed if sample.q is not None and previous is not None and previous.q is not None else None
        last[c] = _seed(sample, seed)
        if q is not None:
            predicted.add((c, k))
        if sample.q is None:
            lost.add(c)
        else:
            lost.discard(c)


def short_move(problem: PoseProblem, a: Array, b: Array) -> Array:
    """``b - a`` in the tangent space (Pinocchio's ``difference``), each revolute angle's part the short way round."""
    move = b - a if problem.vector_space else pin.difference(problem.model, a, b)
    move[problem.angle_rates] = np.remainder(move[problem.angle_rates] + np.pi, 2 * np.pi) - np.pi
    return move


def secant_starts(problem: PoseProblem, before: list[Array | None], seeds: list[Array]) -> list[Array]:
    """Where the predictor starts each sample: ``seed`` moved on by ``seed - before`` (a line's secant), or ``seed``.

    ``before``: the closed sample before the one that gave ``seed`` on the same line (None: start at ``seed``).
    The move is :func:`short_move` (the closed samples' angles are wrapped into (-pi, pi]). A start only: the
    sample's verdict and branch are the Newton steps' from it (checked by :func:`off_secant`), and a sample the
    predictor does not close goes to the single-sample solver from ``seed``, as before.
    """
    starts = list(seeds)
    for i, (b, q) in enumerate(zip(before, seeds)):
        if b is not None:
            move = short_move(problem, b, q)
            starts[i] = q + move if problem.vector_space else pin.integrate(problem.model, q, move)
    return starts


def off_secant(problem: PoseProblem, seed: Array, start: Array, q: Array) -> bool:
    """True when the Newton steps from a secant ``start`` went further than the secant's own step (joint metric).

    Along a smooth line the correction is of second order in the step; a longer one means the steps left the
    continuation (on a coarse grid, the 3-UPU-wrist's U joints closed turned by pi), so the sample is closed again
    from ``seed``, as the single-sample engine's continuation does.
    """
    per_unit = problem.col[: problem.model.nv]  # slides per L, angles in rad: the same decision in any unit
    step = float(np.linalg.norm(short_move(problem, seed, start) / per_unit))
    return 0.0 < step < float(np.linalg.norm(short_move(problem, start, q) / per_unit))  # 0: the start was the seed
