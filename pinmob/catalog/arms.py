"""Three UR5 arms (example-robot-data, meshes included) holding one object."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..builder import MechanismBuilder, radial, rotation
from .registry import Definition, register
from .sources import HAND, expect, limb_pairs

UR5 = "ur_description/urdf/ur5_robot.urdf"


JOINTS = ("shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint")
#: joint values [rad] starting each arm's inverse kinematics (elbow up, wrist down)
SEED_ARM = (0.0, -1.0, 1.6, -2.2, -1.57, 0.0)


def ur5_path() -> Path:
    """Path of example-robot-data's UR5 URDF (its meshes resolve through ``package://example-robot-data``)."""
    import example_robot_data

    return Path(example_robot_data.getModelPath(UR5)) / UR5


@register("3ur5")
def _three_ur5() -> Definition:
    ring, height, grip = 0.75, 0.35, 0.12
    b = MechanismBuilder(
        "3-UR5",
        f"Three UR5 arms (example-robot-data's ur5_robot.urdf, meshes included) on a circle of radius {ring} m at 0, "
        f"120, 240 deg, facing the centre, rigidly holding one object (the platform) at (0, 0, {height}) m; each tool "
        f"flange grips the object from above, {grip} m from its centre, tool axis pointing down. Each arm is a limb of six "
        "revolutes. Away from arm singularities the object has 6 DoF (3T3R); with arm A's wrist singular "
        "(wrist_2_joint = 0: its joints 2, 3, 4 and 6 parallel) the arm exerts a force along those axes.",
    )
    urdf = ur5_path()
    centre = np.array([0.0, 0.0, height])
    seed: dict[str, float] = {}
    for name, theta in limb_pairs():
        e, t = radial(theta)
        # tool flange: above the object, tool axis (z) pointing down; the tip frame is the object's frame
        # (centre, world axes) seen from the flange: rotation R^T, position R^T (centre - flange)
        tool_rot = np.column_stack([t, e, [0.0, 0.0, -1.0]])
        offset = (tool_rot.T, tool_rot.T @ (centre - (centre + grip * e)))
        b.urdf_limb(name, urdf, "base_link", "tool0", (rotation([0, 0, 1], theta + np.pi), ring * e), offset)
        seed |= {f"{name}_{j}": v for j, v in zip(JOINTS, SEED_ARM, strict=True)}
    generic = b.closed_joints(pose=(centre, np.eye(3)), seed=seed)
    # wrist-singular: arm A's wrist_2 held at 0; the object and the other arms follow (closure solve)
    singular = b.closed_joints({"A_wrist_2_joint": 0.0}, seed=generic)
    confs = {
        "generic": {
            "joints": generic,
            "expected": expect(6, "3T3R", f"{HAND} (three 6R arms away from singularities)"),
        },
        "wrist-singular": {
            "joints": singular,
            "expected": expect(5, "2T3R", f"{HAND} (arm A's four parallel axes: one constraint force)"),
        },
    }
    return b, confs, None
