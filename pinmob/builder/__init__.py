"""Sketch parallel and closed-chain mechanisms in code and write them as URDF + pinmob TOML.

Every joint is placed at a *reference configuration* (all joint values zero)
by its world position [m] and world axis; universal (U) and spherical (S)
joints are consecutive revolutes at one point. Each limb ends at a tip frame
given by its world pose; at the reference configuration the tips of the limbs
placed this way coincide (the platform frame). Loops inside limbs or between
free chains are closed by closures between named frames.

Example (a planar 2-RRR, then a Delta limb whose parallelogram is a real loop)::

    b = MechanismBuilder("2-RR", "planar two-limb sketch")
    a = b.limb("A")
    a.revolute("r1", at=[0.3, 0, 0], axis=[0, 0, 1], actuated=True)
    a.tip(at=[0, 0.2, 0])
    ...
    limb = b.limb("A")
    limb.revolute("motor", at=base, axis=t, actuated=True)
    rod_b = limb.branch("b")                 # second rod, hanging from the arm
    rod_b.spherical("top", at=top_b)
    rod_b.frame("end", at=bottom_b)          # frame A_b_end on that rod
    limb.spherical("a_top", at=top_a)
    limb.spherical("a_bottom", at=bottom_a)
    limb.frame("b_pf", at=bottom_b)          # frame A_b_pf on the platform side
    limb.tip(at=centre)
    b.closure("A_b", "A_b_pf", "A_b_end", "3d")
    b.write("models", "my_delta", configurations={...})

Layout helpers: :func:`radial`, :func:`polar`, :func:`symmetric_angles`,
:func:`rotation`, :func:`rpy`. Limbs taken from an existing robot URDF (with
its meshes) are added by :meth:`MechanismBuilder.urdf_limb`; free chains (not
limbs) by :meth:`MechanismBuilder.chain`.
"""

from pinmob.builder.text import is_generated

from .chain_builder import JOINT_TYPES, ChainBuilder, ClosureSpec, FrameSpec, JointSpec, LimbBuilder
from .closed_joints import closed_joints, joint_values
from .layout import azimuth, check_rotation, cross, polar, radial, rotation, rpy, symmetric_angles
from .mechanism_builder import MechanismBuilder
from .text import ZERO_RTOL, toml_value
from .urdf_limb import UrdfLimb

#: former private name of :func:`rpy`, still used by tests/data/make_models.py
_rpy = rpy

__all__ = [
    "ChainBuilder",
    "ClosureSpec",
    "FrameSpec",
    "JOINT_TYPES",
    "JointSpec",
    "LimbBuilder",
    "MechanismBuilder",
    "UrdfLimb",
    "ZERO_RTOL",
    "azimuth",
    "check_rotation",
    "closed_joints",
    "cross",
    "is_generated",
    "joint_values",
    "polar",
    "radial",
    "rotation",
    "rpy",
    "symmetric_angles",
    "toml_value",
]
