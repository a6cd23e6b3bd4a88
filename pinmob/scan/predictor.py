"""The batched predictor of a scan: a stack of platform-pose targets closed from their seeds in lockstep.

:class:`Predictor` wraps :func:`pinmob.assembly.batched.batch_solver.solve_poses` for one scan: the targets as pose
coordinates (NaN where a coordinate follows: it starts where the seed has it), each sample stopped within
``PREDICT_TOL``, the converged ones finished as the single-sample assembly returns them, with the kinematics the
solver computed at them (:class:`Closed`). Where the targets give joint values (a grid or a path over the
motors), those joints start at the target's values and no step moves them (the problem's ``fixed`` columns),
and every pose coordinate not given is an unknown: the frames meet where the joints put them.
:mod:`pinmob.scan.lockstep` runs a group's chunks on it, and the seeding walk
(:func:`pinmob.scan.seeding_walk.chunk_seeds`) its even steps.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np
import pinocchio as pin

from pinmob.assembly import (
    POSE_COORDS,
    PoseProblem,
    close_moved,
    moved_stack,
    off_secants,
    pose_vector,
    solve_poses,
)
from pinmob.model import Mechanism
from pinmob.scan.scan_spec import ScanSpec
from pinmob.screw import Array, Mask

#: A sample the predictor brought within this ``max |e|`` is closed (the predictor stops there: no polish).
PREDICT_TOL = 1e-12


class Closed(NamedTuple):
    """What :meth:`Predictor.close` found for a stack of B targets."""

    #: (B, nq) closed configurations (finished; the rows not converged as the solver left them).
    q: Array
    #: (B,) the predictor converged.
    converged: Mask
    #: (B, 6, nv) world joint Jacobians and (B, 4, 4) platform placements at ``q``: the kinematics the
    #: predictor computed there (the analysis of the sample reads them, :func:`pinmob.scan.batch_rows.analyse`).
    jacobians: Array
    platform: Array


class Predictor:
    """Starts for the single-sample solver from the batched predictor, for one scan (None: it does not apply)."""

    def __init__(self, mech: Mechanism, spec: ScanSpec) -> None:
        self.mech, self.spec = mech, spec
        #: The joints the targets give (:attr:`ScanSpec.target_joints`) and their configuration indices: each
        #: start holds them at the target's values and no step moves them.
        self.joints = spec.target_joints
        model = mech.model
        self.joint_q = [model.joints[model.getJointId(n)].idx_q for n in self.joints]
        self.joint_array = np.array(self.joint_q, np.int64)
        fixed = tuple(model.joints[model.getJointId(n)].idx_v for n in self.joints)
        # the pose coordinates that are unknowns: the following ones; with joints given, every one not given
        given = {*spec.varied, *(c for c, _ in spec.held)}
        names = [c for c in POSE_COORDS if c not in given] if self.joints else spec.following
        self.free = tuple(POSE_COORDS.index(c) for c in names)
        self.problem = PoseProblem(mech, self.free, fixed=fixed)

    @staticmethod
    def applies(mech: Mechanism, spec: ScanSpec) -> bool:
        """A scan the predictor runs (module docstring).

        A platform-pose scan of a mechanism whose closures are its limb tips, or a grid or a path that gives
        values of one-coordinate joints.
        """
        if spec.engine != "batch" or not spec.platform or not PoseProblem.covers(mech):
            return False
        kind, _ = spec.target(0)
        if kind == "pose":
            return True
        model = mech.model
        joints = [model.joints[model.getJointId(n)] for n in spec.target_joints]
        return kind in ("coords", "joints") and all(j.nq == 1 and j.nv == 1 for j in joints)

    def closed(
        self,
        targets: list[tuple[str, Any]],
        seeds: list[Array],
        moves: tuple[Array, Array, Mask] | None = None,
        ratio: float = 1.0,
    ) -> list[Array | None]:
        """Per target (:meth:`ScanSpec.target`), the predictor's closed configuration from its seed, or None.

        Closed: :meth:`~pinmob.assembly.batched.batch_solver.PoseProblem.finish` of a sample it converged; None where it did
        not, or where its start was moved (``moves``, :meth:`close`'s) and its correction was longer than ``ratio``
        times its move.
        """
        if not targets:
            return []
        poses = np.full((len(targets), 6), np.nan)
        joints = np.empty((len(targets), len(self.joints)))
        for i, (kind, value) in enumerate(targets):
            if kind == "pose":
                poses[i] = pose_vector(value)
            elif kind == "joints":
                joints[i] = [value[n] for n in self.joints]
            else:
                poses[i, [POSE_COORDS.index(c) for c in value[0]]] = list(value[0].values())
                joints[i] = [value[1][n] for n in self.joints]
        kinds = [kind for kind, _ in targets]
        q, ok, _, _ = self.close(
            poses, np.array(seeds, float), kinds, joints=joints, moves=moves, ratio=ratio, redo=False
        )
        return [q[i] if ok[i] else None for i in range(len(targets))]

    def close(
        self,
        poses: Array,
        seeds: Array,
        kinds: str | list[str],
        *,
        joints: Array | None = None,
        moves: tuple[Array, Array, Mask] | None = None,
        ratio: float = 1.0,
        redo: bool = True,
    ) -> Closed:
        """:meth:`closed` on stacks: (B, 6) target pose coordinates (NaN: following), (B, nq) seeds.

        Returns the closed configurations (finished, :meth:`closed`), which converged, and the kinematics there
        (:class:`Closed`). ``kinds``: the targets' kind (``pose``, ``coords`` or ``joints``), one for all or one
        each. The following coordinates start where each seed has them. ``joints``: (B, J) the values of :attr:`joints`
        (the starts hold them; none: the targets give no joint). ``moves``: ``(a, b, has)``, the rows ``has`` start at
        their seed moved on by the move from ``a`` to ``b`` (:func:`~pinmob.assembly.moved_stack`: a line's secant),
        the others at their seed; a moved row whose Newton correction was longer than ``ratio`` times its move
        (:func:`~pinmob.assembly.off_secants`) is closed again from its seed (``redo``), or is not closed. With
        numba, moves, solve, finish and check are one compiled call (:func:`~pinmob.assembly.batched.secant.close_moved`).
        """
        if self.free:  # no NaN otherwise: every coordinate is given
            poses = self.seed_poses(poses, seeds)
        if not isinstance(kinds, str) and len(set(kinds)) == 1:  # one kind for all (the same rows)
            kinds = kinds[0]
        if self.joints:
            assert joints is not None, "the targets give joint values"
        held = joints if joints is not None and self.joints else np.empty((len(seeds), 0))
        if moves is None:
            moves = (seeds, seeds, np.zeros(len(seeds), bool))
        closed, off = self._close(poses, seeds, kinds, held, moves, ratio)
        if not off.any():
            return closed
        again = np.flatnonzero(off)
        if redo:  # from the seed instead
            redone, _ = self._close(poses[again], seeds[again], kinds if isinstance(kinds, str) else
                                    [kinds[i] for i in again], held[again], (seeds[again], seeds[again],
                                    np.zeros(again.size, bool)), ratio)  # fmt: skip
            for part, new in zip(closed, redone):
                part[again] = new
        else:
            closed.converged[again] = False
        return closed

    def _close(
        self, poses: Array, seeds: Array, kinds: str | list[str], held: Array, moves: tuple[Array, Array, Mask],
        ratio: float
    ) -> tuple[Closed, Mask]:  # fmt: skip
        """:meth:`close` without the second try: the closed stack, and its rows off their moves."""
        problem, joint_q = self.problem, self.joint_q
        got = close_moved(problem, moves, seeds, poses, self.joint_array, held, ratio, PREDICT_TOL)
        if got is not None:
            q, converged, jacobians, frames = got.q, got.converged, got.jacobians, got.frames
            starts, step, off = got.starts, got.step, got.off
            checked = (got.q, got.special, got.outside)
        else:
            has = moves[2]
            starts, step = moved_stack(problem, *moves[:2], has, seeds) if has.any() else (seeds, np.zeros(len(seeds)))
            held_starts = np.array(starts, float)
            held_starts[:, joint_q] = held
            sol = solve_poses(problem, held_starts, poses, tol=PREDICT_TOL, floor=PREDICT_TOL)
            q, converged, jacobians, frames, checked, off = sol.q, sol.converged, sol.jacobians, sol.frames, None, None
        # angles wrapped (the same kinematics): all but the compiled call's rows it left to finish, or to warn of
        finish = got is None or bool((converged & (got.special | got.outside)).any())
        for kind in ({kinds} if isinstance(kinds, str) else set(kinds)) if finish else ():
            which = converged if isinstance(kinds, str) else converged & (np.array(kinds) == kind)
            if which.any():
                part = None if checked is None else (checked[0][which], checked[1][which], checked[2][which])
                q[which] = problem.finish(self.mech, q[which] if got is None else got.raw[which], kind, part)
        if joint_q:  # the given joints exactly at their values (an angle may be wrapped)
            q[np.ix_(converged, joint_q)] = held[converged]
        if off is None:
            off = converged & off_secants(problem, seeds, starts, q, step, ratio) if moves[2].any() else step > 0.0
        elif got is not None and (converged & got.special).any():  # finished again above: their corrections again
            again = np.flatnonzero(converged & got.special & (step > 0.0))
            off[again] = off_secants(problem, seeds[again], starts[again], q[again], step[again], ratio)
        return Closed(q, converged, jacobians, frames[:, 0]), off  # frames[0]: the platform's

    def seed_poses(self, poses: Array, seeds: Array) -> Array:
        """``poses`` with each following coordinate (NaN) at its value at the sample's seed (its platform pose)."""
        missing = np.isnan(poses)
        rows = np.flatnonzero(missing.any(axis=1))
        if not rows.size:
            return poses
        at, model, data, pid = np.empty((len(poses), 6)), self.problem.model, self.problem.data, self.mech.platform_id
        for i in rows:  # platform_pose's placement, without the other frames
            pin.forwardKinematics(model, data, seeds[i])
            at[i] = pose_vector(pin.updateFramePlacement(model, data, pid))
        return np.where(missing, at, poses)
