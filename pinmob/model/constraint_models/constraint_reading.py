"""Pinocchio's constraint models read as pinmob closures (:meth:`pinmob.Mechanism.from_pinocchio`).

Both of Pinocchio's APIs are read: the legacy ``RigidConstraintModel`` (``CONTACT_3D``: the two points
coincide, a ``3d`` closure; ``CONTACT_6D``: the two frames coincide, a ``6d`` closure) and the new
``PointAnchorConstraintModel`` (``3d``) and ``FrameAnchorConstraintModel`` (``6d``), bare or wrapped in a
``ConstraintModel``. Each joins ``joint1`` at ``joint1_placement`` to ``joint2`` at ``joint2_placement``; a
closure's frames are the model's frames at those placements where it has them, else new operational frames
named after the constraint (``<name>_a``, ``<name>_b``). The legacy ``reference_frame`` says in which frame
Pinocchio writes the rows: it changes no allowed motion, so it is not kept.

Two point anchors joining the same two joints at two different points allow exactly the rotation about the
line through them. :meth:`pinmob.Mechanism.to_pinocchio` writes a ``revolute`` closure so, naming them
``<name>`` and ``<name>/axis``: such a pair is read back as the one ``revolute`` closure about that line (its
5 equations instead of the anchors' 6, whose sixth is always redundant). ``hinges=True`` reads every such
pair so, whatever its names; ``hinges=False`` none (two ``3d`` closures, their redundant row counted: what a
constrained solver is given). Its frames (``<name>_a``, ``<name>_b``)
sit at the first anchor's points with their z axis, the hinge axis, towards the second's.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import pinocchio as pin

from pinmob.model.closure import Closure, ClosureType, make_closure, make_coupling
from pinmob.model.constraint_models.anchors import Anchor
from pinmob.model.constraint_models.constraint_errors import ConstraintModelError
from pinmob.model.constraint_models.constraint_frames import constraint_frame, same_placement
from pinmob.model.constraint_models.mimic_joints import unmimic
from pinmob.model.joints import frame_id, has_joint

#: Two anchor points closer than this (relative to the model's size) are one point, not a hinge axis.
_SAME_POINT = 1e-9


def _label(cm: object, index: int) -> str:
    name = str(getattr(cm, "name", "") or "")
    return name or f"constraint_models[{index}]"


def _anchor(model: pin.Model, cm: object, index: int) -> Anchor:
    """One constraint model checked and read (:class:`ConstraintModelError` naming it otherwise)."""
    label = _label(cm, index)
    if isinstance(cm, pin.ConstraintModel):
        inner = cm.extract()
        name = str(cm.name or getattr(inner, "name", "") or "") or f"constraint_models[{index}]"
        cm, label = inner, name
    if isinstance(cm, pin.RigidConstraintModel):
        if cm.type == pin.ContactType.CONTACT_3D:
            kind = ClosureType.BALL
        elif cm.type == pin.ContactType.CONTACT_6D:
            kind = ClosureType.WELD
        else:
            raise ConstraintModelError(
                f"constraint {label!r}: contact type {cm.type.name} has no meaning as a loop closure; "
                "valid: CONTACT_3D, CONTACT_6D",
                label,
            )
    elif isinstance(cm, pin.PointAnchorConstraintModel):
        kind = ClosureType.BALL
    elif isinstance(cm, pin.FrameAnchorConstraintModel):
        kind = ClosureType.WELD
    else:
        raise ConstraintModelError(
            f"constraint {label!r}: {type(cm).__name__} is not a loop closure pinmob reads (a contact, a joint "
            "limit or friction constrains no loop); valid: RigidConstraintModel (CONTACT_3D, CONTACT_6D), "
            "PointAnchorConstraintModel, FrameAnchorConstraintModel, or a ConstraintModel holding one",
            label,
        )
    j1, j2 = int(cm.joint1_id), int(cm.joint2_id)
    for j in (j1, j2):
        if not 0 <= j < model.njoints:
            raise ConstraintModelError(
                f"constraint {label!r}: joint index {j} is not in the model (it has joints 0 to {model.njoints - 1})",
                label,
            )
    if j1 == j2:
        what = "joint 0 (the world) at both ends" if j1 == 0 else f"joint {model.names[j1]!r} to itself"
        raise ConstraintModelError(
            f"constraint {label!r} joins {what}: it closes no loop; a closure joins two different joints", label
        )
    for which, m in (("joint1_placement", cm.joint1_placement), ("joint2_placement", cm.joint2_placement)):
        h = np.asarray(m.homogeneous)
        rotation = h[:3, :3]
        if not np.isfinite(h).all():
            raise ConstraintModelError(f"constraint {label!r}: {which} is not finite (NaN or inf): {h.tolist()}", label)
        if not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-9) or np.linalg.det(rotation) < 0:
            raise ConstraintModelError(
                f"constraint {label!r}: {which} has no rotation matrix: {rotation.tolist()}", label
            )
    offset = (
        np.asarray(cm.desired_contact_placement.homogeneous) - np.eye(4)
        if isinstance(cm, pin.RigidConstraintModel)
        else np.asarray(cm.desired_constraint_offset)
    )
    if not (np.isfinite(offset).all() and np.abs(offset).max() <= 1e-12):
        which = "desired_contact_placement" if isinstance(cm, pin.RigidConstraintModel) else "desired_constraint_offset"
        raise ConstraintModelError(
            f"constraint {label!r} holds its ends apart ({which} is not the identity): a closure is read as its "
            "two ends meeting; move the offset into joint2_placement",
            label,
        )
    return Anchor(label, kind, j1, pin.SE3(cm.joint1_placement), j2, pin.SE3(cm.joint2_placement))


def _hinges(anchors: list[Anchor], scale: float, named: bool) -> list[Anchor | tuple[Anchor, Anchor]]:
    """The anchors with each pair of point anchors on the same two joints at two points made one hinge.

    ``named``: only pairs named ``X`` and ``X/axis`` (as :mod:`.anchors` writes them), in either order.
    """
    paired: dict[int, int] = {}  # first anchor -> second

    def partner(i: int, a: Anchor) -> int | None:
        for k, b in enumerate(anchors):
            if k == i or k in paired or k in paired.values() or b.kind != ClosureType.BALL:
                continue
            if named and b.name != f"{a.name}/axis":
                continue
            if b.joint1 == a.joint2 and b.joint2 == a.joint1:
                b = _flipped(b)
            elif (b.joint1, b.joint2) != (a.joint1, a.joint2):
                continue
            d1 = float(np.linalg.norm(b.placement1.translation - a.placement1.translation))
            d2 = float(np.linalg.norm(b.placement2.translation - a.placement2.translation))
            if min(d1, d2) > _SAME_POINT * scale and abs(d1 - d2) <= _SAME_POINT * scale:  # the same axis segment
                return k
        return None

    for i, a in enumerate(anchors):
        if a.kind == ClosureType.BALL and i not in paired.values() and not (named and a.name.endswith("/axis")):
            k = partner(i, a)
            if k is not None:
                paired[i] = k
    out: list[Anchor | tuple[Anchor, Anchor]] = []
    for i, a in enumerate(anchors):
        if i in paired:
            b = anchors[paired[i]]
            out.append((a, b if b.joint1 == a.joint1 else _flipped(b)))
        elif i not in paired.values():
            out.append(a)
    return out


def _flipped(b: Anchor) -> Anchor:
    """The same anchor with its two ends swapped."""
    return Anchor(b.name, b.kind, b.joint2, b.placement2, b.joint1, b.placement1)


_Z = np.array([0.0, 0.0, 1.0])


def _on_axis(first: pin.SE3, second: pin.SE3) -> pin.SE3:
    """A placement at ``first``'s point whose z axis points to ``second``'s (a hinge's frame on one body)."""
    z = second.translation - first.translation
    z = z / np.linalg.norm(z)
    x = np.cross(z, np.eye(3)[int(np.argmin(np.abs(z)))])
    x /= np.linalg.norm(x)
    return pin.SE3(np.column_stack([x, np.cross(z, x), z]), first.translation.copy())


def read_constraint_models(
    model: pin.Model, constraint_models: Sequence[object], *, hinges: bool | None = None
) -> tuple[pin.Model, list[Closure]]:
    """A copy of ``model`` holding the closures' frames, and the closures the constraint models stand for.

    Mimic joints become joints of their own held by ``joint`` couplings (:mod:`.mimic_joints`), named
    ``mimic_<joint>`` as a URDF's mimic joints are (:mod:`pinmob.io.mimic`).

    Args:
        model: the Pinocchio model (a tree; mimic joints allowed).
        constraint_models: Pinocchio constraint models (see the module docstring).
        hinges: read two point anchors on the same two joints as one ``revolute`` closure: None, those named
            ``X`` and ``X/axis`` (a revolute closure written by pinmob); True, every such pair; False, none.

    Raises:
        ConstraintModelError: a constraint pinmob cannot read, named (its kind, joints or placements).
    """
    if not isinstance(model, pin.Model):
        raise ConstraintModelError(f"model must be a pinocchio.Model, got {type(model).__name__}")
    if not hasattr(constraint_models, "__iter__") or hasattr(constraint_models, "joint1_id"):
        raise ConstraintModelError(
            "constraint_models must be a list (or a Pinocchio StdVec) of constraint models, got "
            f"{type(constraint_models).__name__}"
        )
    model, mimics = unmimic(model)
    model = pin.Model(model)  # the closures' new frames go into a copy
    anchors = [_anchor(model, cm, i) for i, cm in enumerate(constraint_models)]
    names = [a.name for a in anchors]
    if len(set(names)) != len(names):
        doubled = sorted({n for n in names if names.count(n) > 1})
        raise ConstraintModelError(f"constraint names must be unique, got {doubled} more than once", doubled[0])
    scale = max(1.0, max((float(np.linalg.norm(p.translation)) for p in model.jointPlacements), default=1.0))
    closures: list[Closure] = []
    for item in _hinges(anchors, scale, named=hinges is None) if hinges is not False else anchors:
        if isinstance(item, tuple):
            a, b = item
            fa = constraint_frame(model, a.joint1, _on_axis(a.placement1, b.placement1), f"{a.name}_a")
            fb = constraint_frame(model, a.joint2, _on_axis(a.placement2, b.placement2), f"{a.name}_b")
            closures.append(
                make_closure(model, a.name, model.frames[fa].name, model.frames[fb].name, ClosureType.REVOLUTE, _Z)
            )
            continue
        fa = constraint_frame(model, item.joint1, item.placement1, f"{item.name}_a")
        fb = constraint_frame(model, item.joint2, item.placement2, f"{item.name}_b")
        closures.append(make_closure(model, item.name, model.frames[fa].name, model.frames[fb].name, item.kind))
    for m in mimics:
        closures.append(
            make_coupling(model, f"mimic_{m.secondary}", (m.secondary, m.primary), (m.offset, m.scaling), (0.0, 0.0))
        )
    return model, closures


def limb_welds(model: pin.Model, closures: Sequence[Closure], platform: str, tips: Sequence[str]) -> set[str]:
    """Names of the ``6d`` closures that weld a limb's tip to the platform frame (a limb says so already).

    A closure's frame is the tip (or the platform) when it sits on the same joint at the same placement.
    """

    def end(frame: int) -> tuple[int, pin.SE3]:
        return int(model.frames[frame].parentJoint), model.frames[frame].placement

    def same(a: tuple[int, pin.SE3], b: tuple[int, pin.SE3]) -> bool:
        return a[0] == b[0] and same_placement(a[1], b[1])

    if not platform:
        return set()
    p = end(frame_id(model, platform))
    ends = [end(frame_id(model, t)) for t in tips]
    found = set()
    for c in closures:
        if c.type != ClosureType.WELD:
            continue
        a, b = end(c.frame_a_id), end(c.frame_b_id)
        if any((same(a, p) and same(b, t)) or (same(b, p) and same(a, t)) for t in ends):
            found.add(c.name)
    return found


def mechanism_parts(
    model: pin.Model,
    constraint_models: Sequence[object],
    limbs: Mapping[str, str],
    platform: str | None,
    actuated: Sequence[str] | Mapping[str, list[str]],
    hinges: bool | None,
) -> tuple[pin.Model, list[Closure], str | None, dict[str, list[str]]]:
    """What :meth:`pinmob.Mechanism.from_pinocchio` gives :meth:`~pinmob.Mechanism.from_model`.

    The model and closures (:func:`read_constraint_models`) without the limbs' own welds to the platform
    (:func:`limb_welds`; the platform defaults to the first limb's tip), and the actuated joints by limb
    (``""``: joints in no limb), from a list of joint names or such a mapping.
    """
    model, closures = read_constraint_models(model, constraint_models, hinges=hinges)
    if limbs and platform is None:
        platform = next(iter(limbs.values()))
    welds = limb_welds(model, closures, platform or "", list(limbs.values()))
    if isinstance(actuated, Mapping):
        return model, [c for c in closures if c.name not in welds], platform, {k: list(v) for k, v in actuated.items()}
    by_limb: dict[str, list[str]] = {}
    for joint in actuated:
        holder = next((n for n, tip in limbs.items() if _supports(model, tip, joint)), "")
        by_limb.setdefault(holder, []).append(joint)
    return model, [c for c in closures if c.name not in welds], platform, by_limb


def _supports(model: pin.Model, tip: str, joint: str) -> bool:
    """True when ``joint`` is in the chain supporting frame ``tip``."""
    if not has_joint(model, joint):
        return False
    return model.getJointId(joint) in model.supports[model.frames[frame_id(model, tip)].parentJoint]
