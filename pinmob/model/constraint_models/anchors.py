"""Each pinmob closure as the anchors Pinocchio has: a frame anchor (``6d``), point anchors (``3d``), or none.

Pinocchio's constraint models join two (joint, placement) ends either at a point (``CONTACT_3D``, a point
anchor: 3 rows) or as a whole frame (``CONTACT_6D``, a frame anchor: 6 rows); neither API selects rows. So:

- ``6d`` is one frame anchor and ``3d`` one point anchor (exact);
- ``revolute`` (5 equations) is two point anchors on its axis, at the closure's origin and one length scale
  L along u (exact: the same allowed motion, written with 6 rows of rank 5; the second is named
  ``<name>/axis``);
- ``universal`` is one point anchor (its fourth equation, hinge axes perpendicular, has no Pinocchio model);
- ``cylindrical``, ``planar``, ``tendon`` couplings and ``joint`` couplings have none and are left out (a
  linear ``joint`` coupling can be a mimic joint instead, :mod:`.constraint_writing`); so is any other closure type.

Every closure not written exactly comes with a note saying what was put instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmob.model.closure import Closure, ClosureType


@dataclass(frozen=True)
class Anchor:
    """One Pinocchio constraint, built or read: ``kind`` ``3d`` (a point) or ``6d`` (a frame) between two joint ends."""

    name: str
    kind: ClosureType
    joint1: int
    placement1: pin.SE3
    joint2: int
    placement2: pin.SE3


def closure_anchors(model: pin.Model, closure: Closure, length: float) -> tuple[list[Anchor], str]:
    """The anchors standing for ``closure`` and a note when they are not exact (``""`` when they are).

    Args:
        model: the model holding the closure's frames.
        closure: the closure.
        length: the mechanism's length scale L [m] (the distance between a hinge's two anchors).
    """
    name, kind = closure.name, closure.type
    if closure.is_coupling:
        return [], f"{name!r} ({kind.value} coupling): left out"
    fa, fb = model.frames[closure.frame_a_id], model.frames[closure.frame_b_id]
    ja, jb = int(fa.parentJoint), int(fb.parentJoint)
    ma, mb = pin.SE3(fa.placement), pin.SE3(fb.placement)
    if ja == jb:
        return [], f"{name!r} ({kind.value}): left out (both its frames are on joint {model.names[ja]!r})"
    if kind in (ClosureType.WELD, ClosureType.BALL):
        return [Anchor(name, kind, ja, ma, jb, mb)], ""
    if kind == ClosureType.REVOLUTE:
        step = pin.SE3(np.eye(3), length * np.asarray(closure.axis, float))
        return [
            Anchor(name, ClosureType.BALL, ja, ma, jb, mb),
            Anchor(f"{name}/axis", ClosureType.BALL, ja, ma * step, jb, mb * step),
        ], ""
    if kind == ClosureType.UNIVERSAL:
        return [Anchor(name, ClosureType.BALL, ja, ma, jb, mb)], (
            f"{name!r} (universal): a point anchor (its fourth equation, hinge axes perpendicular, left out)"
        )
    if kind in (ClosureType.CYLINDRICAL, ClosureType.PLANAR):
        return [], f"{name!r} ({kind.value}): left out (no anchor allows its sliding)"
    return [], f"{name!r} ({kind.value}): left out (no Pinocchio constraint model writes it)"
