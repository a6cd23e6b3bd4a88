"""Chunks of a scan run together: their samples assembled in lockstep and analysed in one batch.

A group of up to ``GROUP`` chunks (:func:`pinmob.scan.run.chunk_groups`) runs as one
job. Step j assembles the j-th sample of every chunk of the group, each
warm-started from the previous sample of its own chunk (the continuation of the
single-sample path, so the same assembly branch): first the batched predictor
(:func:`pinmob.assembly.batch_solver.solve_poses`, damped Newton steps over all
those samples at once) brings each platform-pose target close to its solution,
then the single-sample solver (:func:`pinmob.scan.chunk.assemble_target`) polishes
it from there (a Gauss-Newton step or two) and decides whether it closed. A sample
the predictor did not converge (out of reach, a stall, a step that diverged) is
given to that solver from its warm start, exactly as the single-sample path does:
the reachable / unreachable verdicts and the reasons are that solver's. Joint
targets (forward kinematics), targets that hold joints, mechanisms without a
platform or with closures besides the limb tips are assembled by that solver alone.

The group's samples are then analysed in one batch (:mod:`pinmob.scan.batch_rows`)
and each chunk refines and orders its rows (:meth:`pinmob.scan.chunk._Chunk.complete`,
the refinements on the single-sample path). With ``spec.engine == "single"``
the chunks run one after the other, each sample on its own.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.assembly.batch_solver import PoseProblem, solve_poses
from pinmob.assembly.reach import POSE_COORDS, pose_vector
from pinmob.model.mechanism import Mechanism
from pinmob.scan.chunk import _Chunk, _Sample, _seed, run_chunk
from pinmob.scan.spec import ScanSpec
from pinmob.screw.algebra import Array

#: Chunks per group (samples assembled in lockstep: up to GROUP per step).
GROUP = 8

#: The predictor stops a sample at this ``max |e|``: the single-sample solver's polish then takes one step.
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
        if spec.engine != "batch" or not spec.platform or not mech.has_platform or not mech.limbs or mech.closures:
            return False
        kind, value = spec.target(0)
        return kind == "pose" or (kind == "coords" and not value[1])

    def starts(self, ts: list[float], seeds: list[Array]) -> list[Array]:
        """Per target t, the predictor's configuration when it converged, else the seed."""
        model, data, pid = self.mech.model, self.problem.data, self.mech.platform_id
        poses = np.empty((len(ts), 6))
        for i, (t, seed) in enumerate(zip(ts, seeds)):
            kind, value = self.spec.target(t)
            if kind == "pose":
                poses[i] = pose_vector(value)
                continue
            pin.framesForwardKinematics(model, data, seed)
            poses[i] = pose_vector(data.oMf[pid])  # the free coordinates start where the seed has them
            for c, v in value[0].items():
                poses[i, POSE_COORDS.index(c)] = v
        sol = solve_poses(self.problem, np.array(seeds), poses, tol=PREDICT_TOL)
        return [q if ok else seed for q, ok, seed in zip(sol.q, sol.converged, seeds)]


def run_group(mech: Mechanism, spec: ScanSpec, jobs: list[Job]) -> list[dict[str, Any]]:
    """The rows of the chunks ``jobs``, in order (module docstring)."""
    if not Predictor.applies(mech, spec):
        return [row for job in jobs for row in run_chunk(mech, spec, *job)]
    predictor = Predictor(mech, spec)
    chunks = [_Chunk(mech, spec) for _ in jobs]
    plans = [list(chunk.line_samples(start, stop)) for chunk, (start, stop, _) in zip(chunks, jobs)]
    pending: list[dict[int, _Sample]] = [{} for _ in jobs]
    last = [seed for _, _, seed in jobs]
    for j in range(max(len(p) for p in plans)):
        which = [c for c, plan in enumerate(plans) if j < len(plan)]
        _step(predictor, chunks, pending, last, [(c, float(plans[c][j]), last[c]) for c in which])
    neighbours = [c for c, (start, _, _) in enumerate(jobs) if spec.line(start)[0] < start]
    if neighbours:  # each chunk's left neighbour, warm-started from its first sample
        _step(predictor, chunks, pending, last,
              [(c, float(jobs[c][0] - 1), _seed(pending[c][jobs[c][0]], jobs[c][2])) for c in neighbours])  # fmt: skip
    analysed = iter(chunks[0].analysed([s for p in pending for s in p.values()]))
    rows: list[dict[str, Any]] = []
    for c, (start, stop, _) in enumerate(jobs):
        mine = [next(analysed) for _ in pending[c]]
        rows += chunks[c].complete(start, stop, pending[c], mine)
    return rows


def _step(
    predictor: Predictor,
    chunks: list[_Chunk],
    pending: list[dict[int, _Sample]],
    last: list[Array],
    work: list[tuple[int, float, Array]],
) -> None:
    """Assemble sample t of chunk c from ``seed`` for each ``(c, t, seed)``, the predictor's starts batched."""
    starts = predictor.starts([t for _, t, _ in work], [seed for _, _, seed in work])
    for (c, t, seed), start in zip(work, starts):
        sample = chunks[c].assemble(t, start)
        pending[c][int(t)] = sample
        last[c] = _seed(sample, seed)
