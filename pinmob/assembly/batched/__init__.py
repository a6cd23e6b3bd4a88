"""Stacks of platform-pose assemblies closed in lockstep: the batched solver of a scan's predictor.

- :mod:`~pinmob.assembly.batched.batch_solver`: :class:`PoseProblem` (the frames and columns of a platform-pose
  assembly) and :func:`solve_poses` (damped Newton on a stack, numpy's or compiled);
- :mod:`~pinmob.assembly.batched.secant`: continuation starts of a stack and the check of their corrections
  (:func:`moved_stack`, :func:`off_secants`), and :func:`close_moved`, both with the solve in one compiled call;
- :mod:`~pinmob.assembly.batched.rotation_stacks`: stacks of rotations (rpy matrices and rates, ``matrixToRpy``,
  ``log3``);
- the compiled loops, each imported (and numba with it) only when first used:
  :mod:`~pinmob.assembly.batched.batch_newton_kernel` (the Newton iterations, on
  :mod:`~pinmob.assembly.batched.batch_stopping`'s stopping rule), :mod:`~pinmob.assembly.batched.secant_kernel`
  and :mod:`~pinmob.assembly.batched.rpy_kernel`.
"""

from pinmob.assembly.batched.batch_solver import PoseProblem, compiled_kernel, solve_poses
from pinmob.assembly.batched.rotation_stacks import matrices_rpy
from pinmob.assembly.batched.secant import (
    MovedSolution,
    close_moved,
    moved_stack,
    off_secants,
    short_moves,
)

__all__ = [
    "MovedSolution",
    "PoseProblem",
    "close_moved",
    "compiled_kernel",
    "matrices_rpy",
    "moved_stack",
    "off_secants",
    "short_moves",
    "solve_poses",
]
