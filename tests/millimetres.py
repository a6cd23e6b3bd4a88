"""A mechanism redrawn in millimetres, for the tests that check sizes follow the units."""

from __future__ import annotations

import pinocchio as pin

import pinmob


def in_millimetres(mech: pinmob.Mechanism) -> pinmob.Mechanism:
    """``mech`` with every joint and frame placement translation times 1000 (same limbs and platform)."""
    model = pin.Model(mech.model)
    for j in range(1, model.njoints):
        model.jointPlacements[j] = pin.SE3(
            model.jointPlacements[j].rotation, 1000 * model.jointPlacements[j].translation
        )
    for f in model.frames:
        f.placement = pin.SE3(f.placement.rotation, 1000 * f.placement.translation)
    return pinmob.Mechanism.from_model(model, {b.name: b.tip for b in mech.limbs}, platform=mech.platform)
