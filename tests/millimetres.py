"""A mechanism redrawn in other units or moved as a whole, for the tests that check answers follow (or ignore) them."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin

import pinmob
from pinmob.model.joints import linear_velocity_mask
from pinmob.model.named import NamedConfiguration


def in_millimetres(mech: pinmob.Mechanism) -> pinmob.Mechanism:
    """``mech`` with every joint and frame placement translation and prismatic joint limit times 1000.

    Same limbs, platform, closures (frame indices and axes are unchanged) and
    actuated joints; no named configuration (convert one with :func:`q_in_millimetres`).
    """
    return in_units(mech, 1000.0)


def in_units(mech: pinmob.Mechanism, factor: float, configurations: bool = False) -> pinmob.Mechanism:
    """``mech`` written in a unit of length ``1 / factor`` m: every length and prismatic limit times ``factor``.

    As :func:`in_millimetres` (``factor`` 1000); convert a configuration with :func:`q_in_units`.
    With ``configurations``, the named configurations are carried over (see :func:`_same_mechanism`).
    """
    model = pin.Model(mech.model)
    for j in range(1, model.njoints):
        model.jointPlacements[j] = pin.SE3(
            model.jointPlacements[j].rotation, factor * model.jointPlacements[j].translation
        )
    for f in model.frames:
        f.placement = pin.SE3(f.placement.rotation, factor * f.placement.translation)
    linear = linear_velocity_mask(mech.model)
    lower, upper = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
    for joint in model.joints[1:]:
        if joint.nq == joint.nv and linear[joint.idx_v : joint.idx_v + joint.nv].all():  # prismatic: limits in mm
            sl = slice(joint.idx_q, joint.idx_q + joint.nq)
            lower[sl], upper[sl] = factor * lower[sl], factor * upper[sl]
    model.lowerPositionLimit, model.upperPositionLimit = lower, upper
    return _same_mechanism(mech, model, (lambda q: q_in_units(mech, q, factor)) if configurations else None)


def placed(mech: pinmob.Mechanism, placement: pin.SE3, configurations: bool = True) -> pinmob.Mechanism:
    """``mech`` moved as a whole by ``placement`` (a rigid move of its base: every joint and frame on the world).

    The same joint values give the same configuration, moved; the named configurations are carried
    over as joint values unless ``configurations`` is False.
    """
    model = pin.Model(mech.model)
    for j in range(1, model.njoints):
        if model.parents[j] == 0:
            model.jointPlacements[j] = placement * model.jointPlacements[j]
    for f in list(model.frames)[1:]:
        if f.parentJoint == 0:
            f.placement = placement * f.placement
    return _same_mechanism(mech, model, (lambda q: q) if configurations else None)


def _same_mechanism(
    mech: pinmob.Mechanism, model: pin.Model, convert: Callable[[np.ndarray], np.ndarray] | None = None
) -> pinmob.Mechanism:
    """A mechanism on ``model`` with the limbs, platform, closures and actuated joints of ``mech``.

    With ``convert`` (q of ``mech`` to q of the copy), the copy has ``mech``'s named configurations
    too, as the joint values of each closed configuration (one-degree joints only).
    """
    configurations = {}
    if convert is not None:
        for name in mech.configurations:
            q = convert(pinmob.Configuration(mech, name).q)
            values = {model.names[j]: float(q[model.joints[j].idx_q]) for j in range(1, model.njoints)}
            configurations[name] = NamedConfiguration(name, joints=values)
    actuated = {b.name: list(b.actuated) for b in mech.limbs} | {"": list(mech.extra_actuated)}
    return pinmob.Mechanism.from_model(
        model,
        {b.name: b.tip for b in mech.limbs},
        name=mech.name,
        platform=mech.platform,
        closures=mech.closures,
        actuated=actuated,
        generic_rank=mech.generic_rank,
        configurations=configurations,
    )


def q_in_millimetres(mech: pinmob.Mechanism, q: np.ndarray) -> np.ndarray:
    """The same configuration in millimetres: prismatic joint values times 1000."""
    return q_in_units(mech, q, 1000.0)


def q_in_units(mech: pinmob.Mechanism, q: np.ndarray, factor: float) -> np.ndarray:
    """The same configuration in the unit of :func:`in_units`: prismatic joint values times ``factor``."""
    dv = pin.difference(mech.model, mech.neutral(), q)
    return pin.integrate(mech.model, mech.neutral(), np.where(linear_velocity_mask(mech.model), factor * dv, dv))


def moved(mech: pinmob.Mechanism, rotation: np.ndarray, shift: np.ndarray) -> pinmob.Mechanism:
    """``mech`` placed elsewhere: turned by ``rotation`` (3, 3) and moved by ``shift`` [m] (:func:`placed`).

    The joint values (hence every configuration vector) are unchanged; no named configuration.
    """
    move = pin.SE3(np.asarray(rotation, float), np.asarray(shift, float))
    return placed(mech, move, configurations=False)
