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
- :mod:`~pinmob.assembly.named_assembly`: the named configurations of a mechanism file, closed.
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
from pinmob.assembly.named_assembly import closed_configuration
from pinmob.assembly.relaxation import find_closed_relaxed, relax, unclosable
from pinmob.assembly.residual import (
    CLOSURE_TOL,
    CLOSURE_TOL_MAX,
    Residuals,
    check_closed,
    check_closure_tol,
    closure_error,
    closure_residuals,
    compute_kinematics,
    format_residuals,
    is_within,
    mechanism_residuals,
    pose_error,
    relative_error,
    stacked_error,
    tip_residuals,
    worst_residual,
)
from pinmob.assembly.seeds import RESTARTS, configuration_distance, find_closed, random_configuration
from pinmob.assembly.solver import ResidualFn, SolverResult, solve

__all__ = [
    "RESTARTS",
    "CLOSURE_TOL",
    "CLOSURE_TOL_MAX",
    "Assembly",
    "ResidualFn",
    "Residuals",
    "SolverResult",
    "assemble_joints",
    "assemble_pose",
    "check_closed",
    "check_closure_tol",
    "closed_configuration",
    "closure_error",
    "closure_residuals",
    "compute_kinematics",
    "configuration_distance",
    "find_closed",
    "find_closed_relaxed",
    "format_residuals",
    "is_within",
    "joint_velocity_indices",
    "mechanism_residuals",
    "pose_error",
    "project",
    "random_configuration",
    "relative_error",
    "relax",
    "solve",
    "solve_actuated",
    "stacked_error",
    "tip_residuals",
    "unclosable",
    "warn_outside_limits",
    "worst_residual",
]
