"""The batched predictor of a scan: a stack of platform-pose targets closed from their seeds in lockstep.

:class:`Predictor` wraps :func:`pinmob.assembly.batch_solver.solve_poses` for one scan: the targets as pose
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

from pinmob.assembly import POSE_COORDS, PoseProblem, pose_vector, solve_poses
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
        self, targets: list[tuple[str, Any]], seeds: list[Array], starts: list[Array] | None = None
    ) -> list[Array | None]:
        """Per target (:meth:`ScanSpec.target`), the predictor's closed configuration from its seed, or None.

        Closed: :meth:`~pinmob.assembly.batch_solver.PoseProblem.finish` of a sample it converged; None where it did
        not. ``starts``: where the Newton steps start (default: the seeds; the free coordinates start at the seed's).
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
        seed_stack = np.array(seeds, float)
        kinds = [kind for kind, _ in targets]
        q, ok, _, _ = self.close(poses, seed_stack, kinds, seed_stack if starts is None else np.array(starts, float),
                                 joints)  # fmt: skip
        return [q[i] if ok[i] else None for i in range(len(targets))]

    def close(
        self,
        poses: Array,
        seeds: Array,
        kinds: str | list[str],
        starts: Array | None = None,
        joints: Array | None = None,
    ) -> Closed:
        """:meth:`closed` on stacks: (B, 6) target pose coordinates (NaN: following), (B, nq) seeds.

        Returns the closed configurations (finished, :meth:`closed`), which converged, and the kinematics there
        (:class:`Closed`). ``kinds``: the targets' kind (``pose``, ``coords`` or ``joints``), one for all or one
        each. The following coordinates start where each seed has them. ``joints``: (B, J) the values of :attr:`joints`
        (the starts hold them; none: the targets give no joint).
        """
        poses = self.seed_poses(poses, seeds)
        starts = seeds if starts is None else starts
        if not isinstance(kinds, str) and len(set(kinds)) == 1:  # one kind for all (the same rows)
            kinds = kinds[0]
        if self.joints:
            assert joints is not None, "the targets give joint values"
            starts = np.array(starts, float)
            starts[:, self.joint_q] = joints
        sol = solve_poses(self.problem, starts, poses, tol=PREDICT_TOL, floor=PREDICT_TOL)
        q = sol.q
        for kind in {kinds} if isinstance(kinds, str) else set(kinds):
            which = sol.converged if isinstance(kinds, str) else sol.converged & (np.array(kinds) == kind)
            if which.any():
                q[which] = self.problem.finish(self.mech, q[which], kind)  # angles wrapped: the same kinematics
        if joints is not None and self.joints:  # the given joints exactly at their values (an angle may be wrapped)
            q[np.ix_(sol.converged, self.joint_q)] = joints[sol.converged]
        return Closed(q, sol.converged, sol.jacobians, sol.frames[:, 0])  # frames[0]: the platform's

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
