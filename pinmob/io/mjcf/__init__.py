"""MJCF, read through MuJoCo's own compiler: the kinematic tree, equalities as closures, tendons and actuators.

:mod:`~pinmob.io.mjcf.mjcf_reader` (:func:`load_mjcf`, :func:`compile_mjcf`: the mechanism from the compiled
model), :mod:`~pinmob.io.mjcf.mjcf_tree` (MuJoCo's bodies and joints as a Pinocchio tree, ``qpos`` to ``q``),
:mod:`~pinmob.io.mjcf.mjcf_names` (labels of MuJoCo's objects), :mod:`~pinmob.io.mjcf.mjcf_tendons` (tendons and
actuators), :mod:`~pinmob.io.mjcf.actuator_lengths` and :mod:`~pinmob.io.mjcf.mujoco_kinematics` (lengths MuJoCo
computes, asked at a configuration), :mod:`~pinmob.io.mjcf.mjcf_includes` and :mod:`~pinmob.io.mjcf.mjcf_assets`
(the files an MJCF names, kept inside its folder), :mod:`~pinmob.io.mjcf.mjcf_geometry` (the visual geoms).
"""

from pinmob.io.mjcf.mjcf_reader import compile_mjcf, load_mjcf
from pinmob.io.mjcf.mjcf_tendons import MomentActuator, SpatialTendon
from pinmob.io.mjcf.mjcf_tree import q_to_qpos, qpos_to_q

__all__ = ["MomentActuator", "SpatialTendon", "compile_mjcf", "load_mjcf", "q_to_qpos", "qpos_to_q"]
