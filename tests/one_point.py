"""Built-in mechanisms redrawn with their joint frames at one point: the same kinematics, lengths that vanish.

A spherical mechanism's revolute axes meet at its centre; a file may place every joint frame there
(and the platform frame too), so that no link offset is left but round-off. :func:`slid` slides
every revolute joint frame along its own axis (the kinematics are unchanged), :func:`tips_at` puts
the limb tips and the platform frame at one point of the platform (the platform moves as before).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from millimetres import _same_mechanism
from numpy.typing import ArrayLike

import pinmob


def slid(mech: pinmob.Mechanism, centre: ArrayLike = (0.0, 0.0, 0.0)) -> pinmob.Mechanism:
    """``mech`` with every revolute joint frame slid along its own axis to the axis point nearest ``centre`` [m].

    The same kinematics written otherwise: a revolute's motion commutes with a translation along
    its axis, so the joint frame moves by ``d`` along the axis (at the neutral configuration) and
    everything the joint carries (child joints, frames) by ``-d``: every joint value gives the same
    world pose of every link frame. Those of a spherical mechanism whose axes meet at ``centre``
    all land on it. The named configurations are carried over as joint values.
    """
    model = pin.Model(mech.model)
    data = model.createData()
    q = pin.neutral(model)
    pin.forwardKinematics(model, data, q)
    shifts: dict[int, pin.SE3] = {}
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nv != 1:
            continue
        s = pin.computeJointJacobian(model, data, q, j)[:, joint.idx_v]  # motion subspace, joint frame
        if np.linalg.norm(s[:3]) > 1e-12:
            continue  # prismatic or helical
        axis = s[3:] / np.linalg.norm(s[3:])
        world = data.oMi[j]
        d = float((np.asarray(centre, float) - world.translation) @ (world.rotation @ axis))
        shifts[j] = pin.SE3(np.eye(3), d * axis)
    for j, shift in shifts.items():
        model.jointPlacements[j] = model.jointPlacements[j] * shift
    for k in range(1, model.njoints):
        parent = model.parents[k]
        if parent in shifts:
            model.jointPlacements[k] = shifts[parent].inverse() * model.jointPlacements[k]
    for f in model.frames:
        if f.parentJoint in shifts and not (f.type == pin.FrameType.JOINT and f.name == model.names[f.parentJoint]):
            f.placement = shifts[f.parentJoint].inverse() * f.placement
    return _same_mechanism(mech, model, lambda x: x)


def tips_at(mech: pinmob.Mechanism, point: ArrayLike, configuration: str) -> pinmob.Mechanism:
    """``mech`` with its limb tips and platform frame moved on their links to world ``point`` [m] at ``configuration``.

    At a closed configuration the limb tips coincide with the platform frame, so their links move as
    one rigid platform: moving every tip by the same offset on that platform keeps every closure
    closed and the platform's motions the same (its twists are only referred to another point).
    Frames that close a loop (``[[closures]]``) stay where they are.
    """
    model = pin.Model(mech.model)
    data = model.createData()
    pin.forwardKinematics(model, data, pinmob.Configuration(mech, configuration).q)
    names = ({b.tip for b in mech.limbs} | {mech.platform}) - {n for c in mech.closures for n in (c.frame_a, c.frame_b)}
    for f in model.frames:
        if f.name in names:
            f.placement = pin.SE3(f.placement.rotation, data.oMi[f.parentJoint].actInv(np.asarray(point, float)))
    return _same_mechanism(mech, model, lambda q: q)


def axes_meet(mech: pinmob.Mechanism) -> np.ndarray:
    """(3,) the point [m] nearest all revolute axes at the neutral configuration (least squares; their centre if they meet).

    Minimises the sum of squared distances to the axes: ``sum (I - u u^T) x = sum (I - u u^T) p`` over
    the axes (point p, unit direction u); the minimum-norm solution when that has many (parallel axes).
    """
    model = mech.model
    data = model.createData()
    q = pin.neutral(model)
    pin.forwardKinematics(model, data, q)
    lhs, rhs = np.zeros((3, 3)), np.zeros(3)
    for j in range(1, model.njoints):
        joint = model.joints[j]
        s = pin.computeJointJacobian(model, data, q, j)[:, joint.idx_v] if joint.nv == 1 else None
        if s is None or np.linalg.norm(s[:3]) > 1e-12:
            continue
        u = data.oMi[j].rotation @ (s[3:] / np.linalg.norm(s[3:]))
        proj = np.eye(3) - np.outer(u, u)
        lhs, rhs = lhs + proj, rhs + proj @ data.oMi[j].translation
    return np.linalg.lstsq(lhs, rhs, rcond=None)[0]
