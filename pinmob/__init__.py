"""pinmob: how a parallel or closed-chain robot can move at a configuration, from its URDF, with Pinocchio.

>>> import pinmob
>>> mech = pinmob.load("3-PUU")
>>> report = pinmob.analyze(mech, "generic")
>>> report.motion_type
'3T'

The package is layered; imports only go down:

- :mod:`pinmob.screw`: screw algebra, the one rank decision rule, classification (numpy only);
- :mod:`pinmob.model`: the mechanism as plain data (Pinocchio model, limbs, closures, platform);
- :mod:`pinmob.io`: reading files (TOML + URDF, Extended URDF, MJCF) and the built-in models;
- :mod:`pinmob.assembly`: closing the loops (residuals, solver, projection, forward and inverse kinematics);
- :mod:`pinmob.analysis`: :class:`Configuration` (the state object), the analyses, :class:`Report` and
  :func:`analyze` (the one entry point);
- :mod:`pinmob.scan`, :mod:`pinmob.viewer`, :mod:`pinmob.cli`: scans, the meshcat viewer, the command line;
- :mod:`pinmob.builder`, :mod:`pinmob.catalog`: authoring the built-in models; :mod:`pinmob.testing`: assertions;
- :mod:`pinmob.parallel`, :mod:`pinmob.sweeps`: parallel work on Dask, and design-space sweeps (:func:`sweep`).
- :mod:`pinmob.progress`: progress of long steps, shown by whoever listens (the command line).
"""

from typing import TYPE_CHECKING, Any

from pinmob.analysis import (
    Actuation,
    ClosureRank,
    Configuration,
    Constraint,
    FixCheck,
    FrameMobility,
    LimbMobility,
    MechanismMobility,
    Method,
    MinimalClosure,
    MinimalClosures,
    Mobility,
    Motion,
    Report,
    Singularity,
    View,
    actuator_sets,
    analyze,
    analyze_mechanism,
    analyze_singularity,
    check_fixed,
    closure_jacobian_twists,
    fix_closures,
    frame_mobility,
    minimal_closures,
    paper_view,
)
from pinmob.assembly import (
    CLOSURE_TOL,
    Assembly,
    assemble_pose,
    check_closed,
    closed_configuration,
    find_closed,
    project,
    solve_actuated,
)
from pinmob.exceptions import (
    ArgumentError,
    ClosureError,
    ConfigurationError,
    FrameError,
    MechanismFileError,
    PinmobError,
    UnknownConfigurationError,
)
from pinmob.io import builtin_models, load
from pinmob.model import (
    Closure,
    ClosureType,
    ConstraintModelError,
    Expectation,
    Limb,
    Mechanism,
    NamedConfiguration,
    PinocchioExportWarning,
)
from pinmob.screw import RTOL, MotionKind, WrenchKind

__version__ = "0.1.0"

if TYPE_CHECKING:
    from pinmob.analysis import assembly_modes
    from pinmob.sweeps import SweepSpec, load_spec, sweep


def __getattr__(name: str) -> Any:
    """The rarely used parts of the API, imported when first asked for (``import pinmob`` stays light).

    ``assembly_modes``, and the design-space sweeps (``sweep``, ``SweepSpec``, ``load_spec``: their
    package brings the model builder, the catalog and the Dask engine).
    """
    if name == "assembly_modes":
        from pinmob.analysis import assembly_modes

        return assembly_modes
    if name in ("sweep", "SweepSpec", "load_spec"):
        import pinmob.sweeps

        return getattr(pinmob.sweeps, name)
    raise AttributeError(f"module 'pinmob' has no attribute {name!r}")


__all__ = [
    "CLOSURE_TOL",
    "RTOL",
    "SweepSpec",
    "Actuation",
    "ArgumentError",
    "Assembly",
    "Closure",
    "ClosureError",
    "ClosureRank",
    "ClosureType",
    "Configuration",
    "ConfigurationError",
    "Constraint",
    "ConstraintModelError",
    "Expectation",
    "FixCheck",
    "FrameError",
    "FrameMobility",
    "Limb",
    "LimbMobility",
    "Mechanism",
    "MechanismFileError",
    "MechanismMobility",
    "MinimalClosure",
    "MinimalClosures",
    "Method",
    "Mobility",
    "Motion",
    "MotionKind",
    "NamedConfiguration",
    "PinmobError",
    "PinocchioExportWarning",
    "Report",
    "Singularity",
    "UnknownConfigurationError",
    "View",
    "WrenchKind",
    "actuator_sets",
    "analyze",
    "analyze_mechanism",
    "analyze_singularity",
    "assemble_pose",
    "assembly_modes",
    "builtin_models",
    "check_closed",
    "check_fixed",
    "closed_configuration",
    "closure_jacobian_twists",
    "find_closed",
    "fix_closures",
    "frame_mobility",
    "load",
    "load_spec",
    "minimal_closures",
    "paper_view",
    "project",
    "solve_actuated",
    "sweep",
]
