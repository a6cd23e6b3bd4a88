"""pinmob: how the platform of a parallel or closed-chain robot can move, from its URDF.

>>> import pinmob
>>> mech = pinmob.load("3-PUU")
>>> mob = pinmob.analyze(mech, mech.configuration("generic"))
>>> mob.motion_type
'3T'
"""

from .closure import assemble_pose, check_closed
from .exceptions import ClosureError, ConfigurationError, FrameError, MechanismFileError, PinmobError
from .mechanism import Expectation, Limb, Mechanism, NamedConfiguration
from .mechanism_file import builtin_models, load
from .mobility import Constraint, LimbMobility, Mobility, Motion, analyze, closure_jacobian_twists, paper_view
from .screw import MotionKind, WrenchKind

__version__ = "0.1.0"

__all__ = [
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
