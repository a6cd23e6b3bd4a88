"""A mechanism redrawn in millimetres, for the tests that check sizes follow the units."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import pinmob
from pinmob.model.joints import linear_velocity_mask


def in_millimetres(mech: pinmob.Mechanism) -> pinmob.Mechanism:
    """``mech`` with every joint and frame placement translation and prismatic joint limit times 1000.

    Same limbs, platform, closures (frame indices and axes are unchanged) and
    actuated joints; no named configuration (convert one with :func:`q_in_millimetres`).
    """
    model = pin.Model(mech.model)
    for j in range(1, model.njoints):
        model.jointPlacements[j] = pin.SE3(
            model.jointPlacements[j].rotation, 1000 * model.jointPlacements[j].translation
        )
    for f in model.frames:
        f.placement = pin.SE3(f.placement.rotation, 1000 * f.placement.translation)
    linear = linear_velocity_mask(mech.model)
    lower, upper = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
    for joint in model.joints[1:]:
        if joint.nq == joint.nv and linear[joint.idx_v : joint.idx_v + joint.nv].all():  # prismatic: limits in mm
            sl = slice(joint.idx_q, joint.idx_q + joint.nq)
            lower[sl], upper[sl] = 1000 * lower[sl], 1000 * upper[sl]
    model.lowerPositionLimit, model.upperPositionLimit = lower, upper
    return _with_model(mech, model)


def q_in_millimetres(mech: pinmob.Mechanism, q: np.ndarray) -> np.ndarray:
    """The same configuration in millimetres: prismatic joint values times 1000."""
    dv = pin.difference(mech.model, mech.neutral(), q)
    return pin.integrate(mech.model, mech.neutral(), np.where(linear_velocity_mask(mech.model), 1000 * dv, dv))


def moved(mech: pinmob.Mechanism, rotation: np.ndarray, shift: np.ndarray) -> pinmob.Mechanism:
    """``mech`` placed elsewhere: the whole mechanism turned by ``rotation`` (3, 3) and moved by ``shift`` [m].

    The joints on the ground and the frames fixed to it are placed by the rigid move; everything else rides
    along. The joint values (hence every configuration vector) are unchanged.
    """
    model = pin.Model(mech.model)
    move = pin.SE3(np.asarray(rotation, float), np.asarray(shift, float))
    for j in range(1, model.njoints):
        if model.parents[j] == 0:
            model.jointPlacements[j] = move * model.jointPlacements[j]
    for f in model.frames:
        if f.parentJoint == 0:
            f.placement = move * f.placement
    return _with_model(mech, model)


def _with_model(mech: pinmob.Mechanism, model: pin.Model) -> pinmob.Mechanism:
    """``mech``'s limbs, platform, closures and actuated joints on another (rescaled or moved) model."""
    actuated = {b.name: list(b.actuated) for b in mech.limbs} | {"": list(mech.extra_actuated)}
    return pinmob.Mechanism.from_model(
        model,
        {b.name: b.tip for b in mech.limbs},
        name=mech.name,
        platform=mech.platform,
        closures=mech.closures,
        actuated=actuated,
    )
