"""Closing the loops: residuals, the solver, projection, forward and inverse kinematics, restarts, relaxation.

- :mod:`~pinmob.assembly.residual`: closure residuals and their Jacobians, closure
  checks, the one residual measure (:func:`worst_residual`);
- :mod:`~pinmob.assembly.solver`: damped least squares with a trust region and
  polishing (:func:`solve`);
- :mod:`~pinmob.assembly.assemble`: :func:`project` (nearest closed configuration),
  :func:`solve_actuated` (forward kinematics of the closed chain),
  :func:`assemble_pose` (inverse kinematics from a platform pose);
- :mod:`~pinmob.assembly.seeds`: :func:`find_closed` (neutral, then seeded random restarts);
- :mod:`~pinmob.assembly.relaxation`: over-constraining closures relaxed to ``3d``;
- :mod:`~pinmob.assembly.named_assembly`: the named configurations of a mechanism file, closed;
- :mod:`~pinmob.assembly.batched`: a stack of platform-pose assemblies in lockstep (:func:`solve_poses`) and their
  continuation starts (:func:`moved_stack`, :func:`off_secants`, :func:`close_moved`).
"""

from pinmob.assembly.assemble import (
    Assembly,
    assemble_joints,
    assemble_pose,
    joint_velocity_indices,
    project,
    solve_actuated,
    warn_outside_limits,
)
from pinmob.assembly.batched import (
    MovedSolution,
    PoseProblem,
    close_moved,
    compiled_kernel,
    matrices_rpy,
    moved_stack,
    off_secants,
    short_moves,
    solve_poses,
)
from pinmob.assembly.cad_gaps import Gaps, frame_gaps, gaps_closed
from pinmob.assembly.closure_miss import SHOWN, format_worst, tolerance_hint, worst_first
from pinmob.assembly.named_assembly import close_joint_values, closed_configuration, named_vector
from pinmob.assembly.partial_pose import (
    POSE_COORDS,
    assemble_coordinates,
    pose_coordinate_jacobian,
    pose_from_vector,
    pose_vector,
)
from pinmob.assembly.relaxation import find_closed_relaxed, relax, relaxable, unclosable
from pinmob.assembly.residual import (
    CLOSURE_TOL,
    CLOSURE_TOL_MAX,
    Residuals,
    check_closed,
    check_closure_tol,
    closure_error,
    closure_residual,
    closure_residuals,
    compute_kinematics,
    format_residuals,
    frame_jacobian,
    is_within,
    mechanism_residuals,
    normal_rows,
    pose_error,
    relative_error,
    stacked_error,
    tip_residuals,
    worst_residual,
)
from pinmob.assembly.seeds import RESTARTS, configuration_distance, find_closed, random_configuration
from pinmob.assembly.solver import STALL_WINDOW, ResidualFn, SolverResult, solve

__all__ = [
    "Assembly",
    "CLOSURE_TOL",
    "CLOSURE_TOL_MAX",
    "Gaps",
    "MovedSolution",
    "POSE_COORDS",
    "PoseProblem",
    "RESTARTS",
    "ResidualFn",
    "Residuals",
    "SHOWN",
    "STALL_WINDOW",
    "SolverResult",
    "assemble_coordinates",
    "assemble_joints",
    "assemble_pose",
    "check_closed",
    "check_closure_tol",
    "close_joint_values",
    "close_moved",
    "closed_configuration",
    "closure_error",
    "closure_residual",
    "closure_residuals",
    "compiled_kernel",
    "compute_kinematics",
    "configuration_distance",
    "find_closed",
    "find_closed_relaxed",
    "format_residuals",
    "format_worst",
    "frame_gaps",
    "frame_jacobian",
    "gaps_closed",
    "is_within",
    "joint_velocity_indices",
    "matrices_rpy",
    "mechanism_residuals",
    "moved_stack",
    "named_vector",
    "normal_rows",
    "off_secants",
    "pose_coordinate_jacobian",
    "pose_error",
    "pose_from_vector",
    "pose_vector",
    "project",
    "random_configuration",
    "relative_error",
    "relax",
    "relaxable",
    "short_moves",
    "solve",
    "solve_actuated",
    "solve_poses",
    "stacked_error",
    "tip_residuals",
    "tolerance_hint",
    "unclosable",
    "warn_outside_limits",
    "worst_first",
    "worst_residual",
]
