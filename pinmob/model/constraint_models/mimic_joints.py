"""Mimic joints in and out: Pinocchio's ``JointModelMimic`` as pinmob's ``joint`` coupling, and back.

A mimic joint has no coordinate of its own: its value is ``q_s = scaling q_p + offset`` (``q_p`` its
primary's). pinmob reads it as a one-degree joint of its own with the coupling ``q_s - 0 = offset + scaling
(q_p - 0)`` (a ``joint`` closure, :func:`~pinmob.model.closure.make_coupling`), which has the same motions and
adds one coordinate and one closure equation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmob.model.constraint_models.constraint_errors import ConstraintModelError
from pinmob.model.joints import with_joints


@dataclass(frozen=True)
class MimicCoupling:
    """A mimic joint read as a coupling: ``secondary = offset + scaling primary`` (joint names)."""

    secondary: str
    primary: str
    scaling: float
    offset: float


def _axis_joint(model: pin.Model, joint: int) -> pin.JointModel:
    """The one-degree joint a mimic joint moves as: its motion subspace divided by its scaling."""
    mimic = model.joints[joint].extract()
    data = pin.Data(model)
    pin.forwardKinematics(model, data, pin.neutral(model))
    s = np.asarray(data.joints[joint].S).reshape(6) / mimic.scaling
    v, w = s[:3], s[3:]
    name = model.names[joint]
    if np.linalg.norm(w) > 1e-12 and np.linalg.norm(v) < 1e-12:
        return _aligned(w, pin.JointModelRX, pin.JointModelRY, pin.JointModelRZ, pin.JointModelRevoluteUnaligned)
    if np.linalg.norm(w) < 1e-12 and np.linalg.norm(v) > 1e-12:
        return _aligned(v, pin.JointModelPX, pin.JointModelPY, pin.JointModelPZ, pin.JointModelPrismaticUnaligned)
    raise ConstraintModelError(
        f"mimic joint {name!r}: only revolute and prismatic joints can be read as mimic joints", name
    )


def _aligned(axis: np.ndarray, x: type, y: type, z: type, unaligned: type) -> pin.JointModel:
    """The joint about or along ``axis`` (its own sign kept: ``-x`` is an unaligned joint, not ``x``)."""
    axis = axis / np.linalg.norm(axis)
    for k, kind in enumerate((x, y, z)):
        if abs(axis[k] - 1.0) < 1e-12:
            return kind()
    return unaligned(axis)


def unmimic(model: pin.Model) -> tuple[pin.Model, tuple[MimicCoupling, ...]]:
    """``model`` with each mimic joint made a joint of its own, and the couplings that hold them (a new model).

    Joint and frame indices are kept (:func:`~pinmob.model.joints.with_joints`), and the other joints' limits; a
    mimic joint made a joint has no limits (infinite). Each joint gets a ``JOINT`` frame named after it where it
    had none (a ``joint`` closure names its joints' frames).
    """
    mimics = dict(zip((int(j) for j in model.mimicking_joints), (int(j) for j in model.mimicked_joints)))
    if not mimics:
        return model, ()
    out = with_joints(model, {j: _axis_joint(model, j) for j in sorted(mimics)})
    couplings = []
    for j in sorted(mimics):
        mimic = model.joints[j].extract()
        couplings.append(
            MimicCoupling(model.names[j], model.names[mimics[j]], float(mimic.scaling), float(mimic.offset))
        )
        q, v = out.joints[j].idx_q, out.joints[j].idx_v  # a one-degree joint: no limits of its own
        out.lowerPositionLimit[q], out.upperPositionLimit[q] = -np.inf, np.inf
        out.effortLimit[v], out.velocityLimit[v] = np.inf, np.inf
    for j in range(1, out.njoints):
        if not any(f.parentJoint == j and f.type == pin.FrameType.JOINT for f in out.frames):
            out.addFrame(pin.Frame(out.names[j], j, 0, pin.SE3.Identity(), pin.FrameType.JOINT), False)
    return out, tuple(couplings)
