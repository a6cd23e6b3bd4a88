"""The mechanism as plain data: a Pinocchio tree, its limbs, loop closures, platform and actuation."""

from typing import TYPE_CHECKING

from pinmob.lazy_names import lazy_getattr
from pinmob.model.actuated_joints import with_actuated
from pinmob.model.closure import (
    CLOSURE_ROWS,
    CLOSURE_TOL,
    CLOSURE_TYPES,
    Closure,
    ClosureGroups,
    ClosureType,
    make_closure,
    make_coupling,
    make_tendon_coupling,
)
from pinmob.model.compiled_kinematics import (
    ENGINE_VARIABLE,
    FrameKinematics,
    frame_kinematics,
    mechanism_kinematics,
    numba_available,
)
from pinmob.model.constraint_models import ConstraintModelError, PinocchioExportWarning
from pinmob.model.data_pool import acquire, borrowed, release_with
from pinmob.model.geometry import Geometry
from pinmob.model.joint_values import joint_layout, joint_value, parse_joint_values, q_from_values, values_by_name
from pinmob.model.joints import (
    angle_mask,
    frame_id,
    frame_name,
    has_joint,
    joint_id,
    joint_names,
    linear_velocity_mask,
    motion_subspaces,
    one_degree_indices,
    outside_limits,
    short_difference,
    velocity_spans,
    with_joints,
    wrap_angles,
)
from pinmob.model.length_scale import NO_LENGTH, SHORTEST
from pinmob.model.limb import Limb
from pinmob.model.mechanism import Expectation, Mechanism, NamedConfiguration
from pinmob.model.tendon import FixedTendon, Tendon, TendonActuator, Transmission, joint_configuration, tendon_rows

if TYPE_CHECKING:
    from pinmob.model.kinematics_kernel import difference_kernel, frames_kernel, integrate_kernel

#: the compiled kernels load (and import numba) when first read: ``import pinmob`` imports no numba
#: (tests/test_fast_paths.py)
_LAZY = {
    "difference_kernel": "pinmob.model.kinematics_kernel",
    "frames_kernel": "pinmob.model.kinematics_kernel",
    "integrate_kernel": "pinmob.model.kinematics_kernel",
}


#: A name of :data:`_LAZY`, its module imported when it is first read (PEP 562).
__getattr__ = lazy_getattr(__name__, _LAZY)


__all__ = [
    "difference_kernel",
    "frames_kernel",
    "integrate_kernel",
    "numba_available",
    "CLOSURE_ROWS",
    "CLOSURE_TOL",
    "CLOSURE_TYPES",
    "Closure",
    "ClosureGroups",
    "ClosureType",
    "ConstraintModelError",
    "ENGINE_VARIABLE",
    "Expectation",
    "FixedTendon",
    "FrameKinematics",
    "Geometry",
    "Limb",
    "Mechanism",
    "NO_LENGTH",
    "NamedConfiguration",
    "PinocchioExportWarning",
    "SHORTEST",
    "Tendon",
    "TendonActuator",
    "Transmission",
    "acquire",
    "angle_mask",
    "borrowed",
    "frame_id",
    "frame_kinematics",
    "frame_name",
    "has_joint",
    "joint_id",
    "joint_configuration",
    "joint_layout",
    "joint_names",
    "joint_value",
    "linear_velocity_mask",
    "mechanism_kinematics",
    "motion_subspaces",
    "make_closure",
    "make_coupling",
    "make_tendon_coupling",
    "one_degree_indices",
    "outside_limits",
    "parse_joint_values",
    "q_from_values",
    "release_with",
    "short_difference",
    "tendon_rows",
    "values_by_name",
    "velocity_spans",
    "with_actuated",
    "with_joints",
    "wrap_angles",
]
