"""The single-sample solver at a platform pose in one compiled call, where the mechanism allows it.

:func:`compiled_pose_solver` gives a :class:`CompiledPoseSolve` for a mechanism whose loops are its limb tips on
the platform (no other closure) and whose joints the compiled kinematics computes and integrates
(:func:`pinmob.model.compiled_kinematics.frame_kinematics`: numba installed, and ``PINMOB_KINEMATICS`` not
``pinocchio``); else None, and :func:`pinmob.assembly.assemble.assemble_pose` iterates in Python with Pinocchio's
calls. Both run :func:`pinmob.assembly.solver.solve`'s iterations on the same residual
(:mod:`pinmob.assembly.compiled_solve.pose_solve_kernel`); the last configuration's angles are wrapped as
``solve`` does.
"""

from __future__ import annotations

import os

import numpy as np
import pinocchio as pin

from pinmob.assembly.solver import (
    MAX_STEP,
    MAX_TRIALS,
    NEWTON_SWITCH,
    POLISH_FLOOR,
    POLISH_GAIN,
    POLISH_STEPS,
    RCOND,
    STALL_GAIN,
    STALL_WINDOW,
    SolverResult,
)
from pinmob.model import ENGINE_VARIABLE, Mechanism, linear_velocity_mask, mechanism_kinematics, wrap_angles
from pinmob.screw import Array, twist_scaling


class CompiledPoseSolve:
    """:func:`~pinmob.assembly.solver.solve` on a platform-pose residual of ``frames``, in one compiled call."""

    def __init__(self, mech: Mechanism, tables: tuple[Array, ...], frames: list[int]) -> None:
        from pinmob.assembly.compiled_solve.block_svd import frame_blocks  # imports numba: only where it runs
        from pinmob.assembly.compiled_solve.pose_solve_kernel import solve_pose, worst_at

        self.model, self.tables, self.kernel, self.worst_at = mech.model, tables, solve_pose, worst_at
        self.blocks = frame_blocks(mech.model, frames)  # the Jacobian's diagonal blocks: its SVD by blocks
        self.scale = twist_scaling(mech.length_scale)
        self.col = np.where(linear_velocity_mask(mech.model), mech.length_scale, 1.0)
        # the kernel's settings: tol, max_iter, damping and the stall window are set per call
        self.settings = np.array([0.0, 0.0, 0.0, MAX_STEP, POLISH_FLOOR, 0.0, NEWTON_SWITCH, STALL_GAIN, RCOND,
                                  MAX_TRIALS, POLISH_STEPS, POLISH_GAIN], float)  # fmt: skip

    def solve(
        self,
        pose: pin.SE3,
        q0: Array,
        tol: float,
        max_iter: int,
        damping: float = 1e-3,
        stall_window: int = STALL_WINDOW,
    ) -> SolverResult:
        """``solve(model, residual, q0, tol, max_iter, damping, length=L, stall_window=...)``'s result, compiled.

        The residual is :func:`~pinmob.assembly.assemble.assemble_pose`'s at ``pose``; the wrapped configuration's
        ``max |e|`` is the kernel's too.
        """
        settings = self.settings.copy()
        settings[0], settings[1], settings[2], settings[5] = tol, max_iter, damping, stall_window
        rt, pt = np.ascontiguousarray(pose.rotation), np.ascontiguousarray(pose.translation)
        q, worst, it, newton = self.kernel(np.array(q0, float), self.tables, rt, pt, self.scale, self.col, settings,
                                           self.blocks)  # fmt: skip
        wrapped = wrap_angles(self.model, q)
        if not np.array_equal(wrapped, q):
            q, worst = wrapped, self.worst_at(wrapped, self.tables, rt, pt, self.scale, self.col.shape[0])
        return SolverResult(q, float(worst), int(it + newton), bool(worst <= tol), int(newton))


def compiled_pose_solver(mech: Mechanism, frames: list[int]) -> CompiledPoseSolve | None:
    """The compiled solve of ``mech`` at a pose of ``frames`` (module docstring), or None where it cannot run."""
    if mech.closures:
        return None
    engine = os.environ.get(ENGINE_VARIABLE)

    def build() -> CompiledPoseSolve | None:
        fast = mechanism_kinematics(mech, frames)  # shared with the batched predictor's problems
        return CompiledPoseSolve(mech, fast.tables, frames) if fast.engine == "compiled" and fast.integrable else None

    return mech.memo(("compiled pose solve", tuple(frames), engine), build, transient=True)
