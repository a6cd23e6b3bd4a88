"""Generated visual geometry for models without visuals: a stick figure of the mechanism.

Most built-in models are kinematic URDFs without ``<visual>`` elements (3-UR5 has
UR5 meshes). So that
it still looks like a mechanism in the viewer, :func:`skeleton_geometry` builds
a Pinocchio ``GeometryModel`` of simple shapes attached to the joints:

- links: a cylinder from each joint origin to the origin of each child joint
  and to each frame attached to it (e.g. a limb's tip), so consecutive joint
  origins are joined;
- revolute joints: a short cylinder along the joint axis (a U joint shows as
  two crossed cylinders); prismatic joints: a block that slides on a rail
  fixed to the parent body; other joints: a sphere;
- the base: bars joining the roots of the limbs; the platform: a thin disc at
  the platform frame reaching the limbs' last joints.

Sizes scale with the mechanism's length L [m], so a model in millimetres looks
the same as one in metres. Pure Pinocchio/coal; no meshcat.
"""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

from pinmob.model import Mechanism
from pinmob.screw import Array

#: RGBA colours: limbs cycle through LIMB_COLORS.
LIMB_COLORS = (
    (0.12, 0.47, 0.71, 1.0),
    (0.17, 0.63, 0.17, 1.0),
    (0.58, 0.40, 0.74, 1.0),
    (0.55, 0.34, 0.29, 1.0),
    (0.09, 0.75, 0.81, 1.0),
    (0.50, 0.50, 0.10, 1.0),
)
JOINT_COLOR = (0.25, 0.25, 0.25, 1.0)
BASE_COLOR = (0.45, 0.45, 0.45, 1.0)
PLATFORM_COLOR = (0.95, 0.60, 0.10, 0.55)


def _rotation_z_to(axis: Array) -> Array:
    """Rotation (3, 3) taking the z axis onto the unit vector ``axis``."""
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    return pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), a).toRotationMatrix()


def _segment(name: str, joint: int, a: Array, b: Array, radius: float, color: tuple) -> pin.GeometryObject:
    """Cylinder from a to b (both in the joint frame) attached to ``joint``."""
    d = np.asarray(b, float) - np.asarray(a, float)
    length = float(np.linalg.norm(d))
    placement = pin.SE3(_rotation_z_to(d), 0.5 * (np.asarray(a) + np.asarray(b)))
    return _object(name, joint, placement, coal.Cylinder(radius, length), color)


def _object(name: str, joint: int, placement: pin.SE3, shape: coal.ShapeBase, color: tuple) -> pin.GeometryObject:
    obj = pin.GeometryObject(name, joint, placement, shape)
    obj.meshColor = np.array(color, float)
    return obj


def _joint_axes(model: pin.Model, q: Array) -> dict[int, Array]:
    """Motion subspace (6, nv_j) of every joint in its own frame at q."""
    data = pin.Data(model)
    pin.forwardKinematics(model, data, q)
    return {j: np.array(data.joints[j].S).reshape(6, -1) for j in range(1, model.njoints)}


def skeleton_geometry(mech: Mechanism, q: Array) -> pin.GeometryModel:
    """A visual ``GeometryModel`` drawing the mechanism as links and joints.

    Args:
        mech: the mechanism.
        q: (nq,) configuration used for the sizes that depend on it (rails are
            centred on the sliders' values, the platform disc reaches the
            limbs' last joints there).

    Returns:
        geometry attached to ``mech.model``'s joints; draw it with
        ``pin.visualize.MeshcatVisualizer`` like URDF visuals.
    """
    model = mech.model
    length = mech.length_scale
    link_r, joint_r, joint_len = 0.03 * length, 0.05 * length, 0.22 * length
    geom = pin.GeometryModel()
    limb_of = {name: i for i, limb in enumerate(mech.limbs) for name in limb.joints}
    axes = _joint_axes(model, q)
    eps = 1e-9 * length

    for j in range(1, model.njoints):
        name = model.names[j]
        color = LIMB_COLORS[limb_of.get(name, 0) % len(LIMB_COLORS)]
        # links to child joints and attached frames
        targets = [model.jointPlacements[c].translation for c in range(j + 1, model.njoints) if model.parents[c] == j]
        targets += [f.placement.translation for f in model.frames if f.parentJoint == j]
        seen: list[Array] = []
        for k, t in enumerate(targets):
            if np.linalg.norm(t) < eps or any(np.linalg.norm(t - s) < eps for s in seen):
                continue
            seen.append(np.array(t))
            geom.addGeometryObject(_segment(f"{name}/link{k}", j, np.zeros(3), t, link_r, color))
        # the joint itself
        s = axes[j]
        if s.shape[1] == 1 and np.linalg.norm(s[3:, 0]) > 1e-12 and np.linalg.norm(s[:3, 0]) < 1e-12:
            w = s[3:, 0]
            geom.addGeometryObject(
                _segment(f"{name}/joint", j, -0.5 * joint_len * w, 0.5 * joint_len * w, joint_r, JOINT_COLOR)
            )
        elif s.shape[1] == 1 and np.linalg.norm(s[3:, 0]) < 1e-12:
            v = s[:3, 0] / np.linalg.norm(s[:3, 0])
            block = pin.SE3(_rotation_z_to(v), np.zeros(3))
            size = 1.6 * joint_r
            geom.addGeometryObject(_object(f"{name}/slider", j, block, coal.Box(size, size, 1.5 * size), JOINT_COLOR))
            # rail on the parent, centred on the slider's value at q
            parent = int(model.parents[j])
            value = float(q[model.joints[j].idx_q])
            m0 = model.jointPlacements[j]
            centre = m0.translation + m0.rotation @ (v * value)
            d = m0.rotation @ v
            geom.addGeometryObject(
                _segment(
                    f"{name}/rail",
                    parent,
                    centre - 0.8 * length * d,
                    centre + 0.8 * length * d,
                    0.4 * link_r,
                    BASE_COLOR,
                )
            )
        else:
            geom.addGeometryObject(
                _object(f"{name}/joint", j, pin.SE3.Identity(), coal.Sphere(1.2 * joint_r), JOINT_COLOR)
            )

    # base: bars between consecutive limb roots
    roots = [model.jointPlacements[j].translation for j in range(1, model.njoints) if model.parents[j] == 0]
    if len(roots) >= 3:
        for k, (a, b) in enumerate(zip(roots, roots[1:] + roots[:1], strict=True)):
            if np.linalg.norm(b - a) > eps:
                geom.addGeometryObject(_segment(f"base/bar{k}", 0, a, b, 0.6 * link_r, BASE_COLOR))

    # platform disc reaching the limbs' last joints
    data = pin.Data(model)
    pin.framesForwardKinematics(model, data, q)
    pid = mech.platform_id
    frame = model.frames[pid]
    om_p = data.oMf[pid]
    reach = [
        np.linalg.norm(om_p.actInv(data.oMi[model.frames[limb.tip_id].parentJoint]).translation[:2])
        for limb in mech.limbs
    ]
    radius = max([r for r in reach if r > eps], default=0.3 * length)
    geom.addGeometryObject(
        _object(
            "platform/disc", frame.parentJoint, frame.placement, coal.Cylinder(radius, 0.025 * length), PLATFORM_COLOR
        )
    )
    return geom


def visual_geometry(mech: Mechanism, q: Array) -> tuple[pin.GeometryModel, bool]:
    """The URDF visuals when the model has some, else :func:`skeleton_geometry`.

    Returns:
        (geometry, generated): ``generated`` is True for the stick figure.
    """
    if mech.visual_model is not None and mech.visual_model.ngeoms > 0:
        return mech.visual_model, False
    return skeleton_geometry(mech, q), True
