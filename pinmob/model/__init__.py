"""The mechanism as plain data: a Pinocchio tree, its limbs, loop closures, platform and actuation."""

from pinmob.model.closure import CLOSURE_ROWS, CLOSURE_TYPES, Closure, ClosureGroups, ClosureType, make_closure
from pinmob.model.compiled_kinematics import FrameKinematics, frame_kinematics
from pinmob.model.constraint_models import ConstraintModelError, PinocchioExportWarning
from pinmob.model.limb import Limb
from pinmob.model.mechanism import Expectation, Mechanism, NamedConfiguration

__all__ = [
    "CLOSURE_ROWS",
    "CLOSURE_TYPES",
    "Closure",
    "ClosureGroups",
    "ClosureType",
    "ConstraintModelError",
    "Expectation",
    "FrameKinematics",
    "Limb",
    "Mechanism",
    "NamedConfiguration",
    "PinocchioExportWarning",
    "frame_kinematics",
    "make_closure",
]
