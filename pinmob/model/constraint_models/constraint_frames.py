"""The frame a constraint's (joint, placement) stands for: an existing frame of the model, or a new one."""

from __future__ import annotations

import pinocchio as pin

from pinmob.model.joints import frame_id

#: Frame types looked up first when several frames sit at a constraint's point (a named operational frame first).
_PREFERRED = (pin.FrameType.OP_FRAME, pin.FrameType.BODY, pin.FrameType.JOINT, pin.FrameType.FIXED_JOINT)

#: Largest difference of two placements read as the same [m, rad] (relative to 1 m).
SAME_PLACEMENT = 1e-9


def same_placement(a: pin.SE3, b: pin.SE3, tol: float = SAME_PLACEMENT) -> bool:
    """True when the two placements differ by at most ``tol`` in every entry."""
    return bool(abs(a.homogeneous - b.homogeneous).max() <= tol)


def matching_frame(model: pin.Model, joint: int, placement: pin.SE3) -> int | None:
    """The index of a frame on ``joint`` at ``placement`` (one its name finds, a named operational frame first)."""
    found = [
        i
        for i, f in enumerate(model.frames)
        if f.parentJoint == joint and same_placement(f.placement, placement) and frame_id(model, f.name) == i
    ]
    for kind in _PREFERRED:
        for i in found:
            if model.frames[i].type == kind:
                return i
    return found[0] if found else None


def constraint_frame(model: pin.Model, joint: int, placement: pin.SE3, name: str) -> int:
    """The frame at (``joint``, ``placement``): an existing one, else a new operational frame ``name`` (unique).

    ``model`` is changed when a frame is added (the caller's copy).
    """
    found = matching_frame(model, joint, placement)
    if found is not None:
        return found
    unique, k = name, 1
    while model.existFrame(unique):
        k += 1
        unique = f"{name}_{k}"
    parent = next(
        (i for i, f in enumerate(model.frames) if f.parentJoint == joint and f.type == pin.FrameType.JOINT), 0
    )
    return int(model.addFrame(pin.Frame(unique, joint, parent, placement, pin.FrameType.OP_FRAME)))
