"""pinmob: how the platform of a parallel or closed-chain robot can move, from its URDF.

>>> import pinmob
>>> mech = pinmob.load("3-PUU")
>>> mob = pinmob.analyze(mech, mech.configuration("generic"))
>>> mob.motion_type
'3T'
"""

from . import extended_urdf, mjcf  # noqa: F401  (register the .yaml and .xml loaders)
from .closure import Assembly, assemble_pose, assembly_modes, check_closed, find_closed, project, solve_actuated
from .constraints import MechanismMobility, actuator_sets, analyze_mechanism
from .exceptions import ClosureError, ConfigurationError, FrameError, MechanismFileError, PinmobError
from .mechanism import Closure, Expectation, Limb, Mechanism, NamedConfiguration
from .mechanism_file import builtin_models, load
from .mobility import Constraint, LimbMobility, Mobility, Motion, analyze, closure_jacobian_twists, paper_view
from .screw import MotionKind, WrenchKind

__version__ = "0.1.0"

__all__ = [
    "Assembly",
    "Closure",
    "MechanismMobility",
    "actuator_sets",
    "analyze_mechanism",
    "assembly_modes",
    "find_closed",
    "project",
    "solve_actuated",
    "ClosureError",
    "ConfigurationError",
    "Constraint",
    "Expectation",
    "FrameError",
    "Limb",
    "LimbMobility",
    "Mechanism",
    "MechanismFileError",
    "Mobility",
    "Motion",
    "MotionKind",
    "NamedConfiguration",
    "PinmobError",
    "WrenchKind",
    "analyze",
    "assemble_pose",
    "builtin_models",
    "check_closed",
    "closure_jacobian_twists",
    "load",
    "paper_view",
]
