"""Loop closure: residuals, closure checks and assembly, in one namespace.

The work lives in smaller modules; every name is importable from here:

- :mod:`pinmob.residual`: closure residuals and their Jacobians, closure
  checks, the one residual measure (:func:`worst_residual`);
- :mod:`pinmob.solver`: damped least squares with a trust region and
  polishing (:func:`solve`), revolute angle wrapping, joint limits;
- :mod:`pinmob.assembly`: :func:`project` (nearest closed configuration),
  :func:`solve_actuated` (forward kinematics of the closed chain),
  :func:`assemble_pose` (inverse kinematics from a platform pose);
- :mod:`pinmob.seeds`: :func:`find_closed` (neutral, then seeded random
  restarts) and :func:`assembly_modes` (distinct solutions modulo idle motions);
- :mod:`pinmob.relaxation`: over-constraining closures relaxed to ``3d``.
"""

from __future__ import annotations

from .assembly import (
    Assembly,
    assemble_joints,
    assemble_pose,
    joint_velocity_indices,
    project,
    solve_actuated,
    warn_outside_limits,
)
from .exceptions import ClosureError
from .relaxation import find_closed_relaxed, relax, unclosable
from .residual import (
    CLOSURE_TOL,
    Residuals,
    check_closed,
    closed_kinematics,
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
from .seeds import (
    ModeSignature,
    assembly_modes,
    configuration_distance,
    find_closed,
    mode_distance,
    mode_signature,
    random_configuration,
)
from .solver import (
    ResidualFn,
    SolverResult,
    angle_mask,
    linear_velocity_mask,
    outside_limits,
    solve,
    wrap_angles,
)

__all__ = [
    "CLOSURE_TOL",
    "Assembly",
    "ClosureError",
    "ModeSignature",
    "ResidualFn",
    "Residuals",
    "SolverResult",
    "angle_mask",
    "assemble_joints",
    "assemble_pose",
    "assembly_modes",
    "check_closed",
    "closed_kinematics",
    "closure_error",
    "closure_residuals",
    "compute_kinematics",
    "configuration_distance",
    "find_closed",
    "find_closed_relaxed",
    "format_residuals",
    "is_within",
    "joint_velocity_indices",
    "linear_velocity_mask",
    "mechanism_residuals",
    "mode_distance",
    "mode_signature",
    "outside_limits",
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
    "wrap_angles",
]
