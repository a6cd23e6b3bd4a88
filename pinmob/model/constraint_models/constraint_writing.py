"""pinmob closures written as Pinocchio constraint models (:meth:`pinmob.Mechanism.to_pinocchio`).

``api="new"`` gives ``ConstraintModel`` objects holding ``PointAnchorConstraintModel`` /
``FrameAnchorConstraintModel``, ``api="legacy"`` ``RigidConstraintModel`` objects (``CONTACT_3D`` /
``CONTACT_6D``, rows in the ``LOCAL`` frame of joint 1's end), both in the vector type Pinocchio's algorithms
take (``getConstraintsJacobian``, ``constraintDynamics``, ...). Which closure becomes what is said in
:mod:`.anchors`; whatever is not exact is named in one :class:`PinocchioExportWarning`.

Joint couplings: Pinocchio's constrained algorithms refuse mimic joints, so couplings are left out by
default; with ``mimic=True`` each linear coupling of two joints, ``q1 - r1 = c0 + c1 (q2 - r2)``, becomes
joint 1 mimicking joint 2 (``q1 = c1 q2 + (r1 + c0 - c1 r2)``) where Pinocchio accepts it.
"""

from __future__ import annotations

import warnings
from collections.abc import Sequence

import pinocchio as pin

from pinmob.exceptions import ArgumentError
from pinmob.model.closure import Closure, ClosureType
from pinmob.model.constraint_models.anchors import Anchor, closure_anchors
from pinmob.model.constraint_models.constraint_errors import PinocchioExportWarning

#: The two APIs: the new anchors in ``ConstraintModel``, the legacy ``RigidConstraintModel``.
APIS = ("new", "legacy")

#: The legacy contact type of each anchor kind.
_LEGACY_KIND = {ClosureType.BALL: pin.ContactType.CONTACT_3D, ClosureType.WELD: pin.ContactType.CONTACT_6D}


def _build(model: pin.Model, anchor: Anchor, api: str) -> object:
    """One Pinocchio constraint model for ``anchor``."""
    ends = (anchor.joint1, anchor.placement1, anchor.joint2, anchor.placement2)
    if api == "legacy":
        built = pin.RigidConstraintModel(_LEGACY_KIND[anchor.kind], model, *ends, pin.LOCAL)
        built.name = anchor.name
        return built
    cls = pin.PointAnchorConstraintModel if anchor.kind == ClosureType.BALL else pin.FrameAnchorConstraintModel
    inner = cls(model, *ends)
    inner.name = anchor.name
    wrapped = pin.ConstraintModel(inner)
    wrapped.name = anchor.name
    return wrapped


def _linear(closure: Closure) -> tuple[float, float] | None:
    """``(scaling, offset)`` of a linear coupling of two joints, ``q1 = scaling q2 + offset``, or None."""
    coefficients = list(closure.polycoef)
    while len(coefficients) > 2 and coefficients[-1] == 0.0:  # MuJoCo's polycoef has five entries
        coefficients.pop()
    if len(closure.joints) != 2 or len(coefficients) > 2:
        return None
    c0, c1 = (tuple(coefficients) + (0.0,))[:2]
    r1, r2 = closure.reference
    return c1, r1 + c0 - c1 * r2


def _mimics(model: pin.Model, couplings: Sequence[Closure]) -> tuple[pin.Model, list[str]]:
    """``model`` with a mimic joint for each linear coupling of two joints, and a note per coupling left out.

    Pinocchio's mimic joint comes after the joint it mimics, and mimics a joint with a coordinate. So the
    couplings are taken as a graph on the joints: in each connected group, every joint mimics the group's
    first joint in the model, its scaling and offset composed along the couplings that lead there
    (``q1 = s q2 + o`` read backwards is ``q2 = q1 / s - o / s``). A coupling that closes a cycle in the
    graph is left out (its joints are coupled already), as is one with a zero scaling (a joint held at a value).
    """
    notes: list[str] = []
    edges: dict[int, list[tuple[int, float, float, str]]] = {}  # joint -> (other, s, o, coupling): q_j = s q_o + o
    for c in couplings:
        linear = _linear(c)
        if linear is None or linear[0] == 0.0:
            what = "a joint held at a value" if len(c.joints) == 1 or linear is not None else "a polynomial coupling"
            notes.append(f"{c.name!r} (joint coupling): left out ({what}: no Pinocchio model)")
            continue
        (i1, i2), (scaling, offset) = (model.getJointId(j) for j in c.joints), linear
        edges.setdefault(i1, []).append((i2, scaling, offset, c.name))
        edges.setdefault(i2, []).append((i1, 1.0 / scaling, -offset / scaling, c.name))
    # each joint as (root, s, o): q_joint = s q_root + o, by a breadth-first walk from each group's first joint
    found: dict[int, tuple[int, float, float]] = {}
    used: set[str] = set()
    for root in sorted(edges):
        if root in found:
            continue
        found[root] = (root, 1.0, 0.0)
        queue = [root]
        while queue:
            joint = queue.pop(0)
            _, s_j, o_j = found[joint]
            for other, s, o, name in edges[joint]:  # q_joint = s q_other + o, so q_other = (q_joint - o) / s
                if other not in found:
                    found[other] = (root, s_j / s, (o_j - o) / s)
                    used.add(name)
                    queue.append(other)
    for c in couplings:
        if c.name not in used and any(c.name == e[3] for es in edges.values() for e in es):
            notes.append(
                f"{c.name!r} (joint coupling): left out (it closes a cycle of couplings: Pinocchio's mimic joints "
                "form a tree)"
            )
    out = model
    for joint, (root, scaling, offset) in sorted(found.items()):
        if joint == root:
            continue
        try:
            out = pin.transformJointIntoMimic(out, root, joint, scaling, offset)
        except (RuntimeError, ValueError) as error:
            why = str(error).split("message:")[-1].strip().splitlines()[0]
            notes.append(
                f"joint {model.names[joint]!r} (joint coupling): left out (Pinocchio refuses it as a mimic of "
                f"{model.names[root]!r}: {why})"
            )
    return out, notes


def write_constraint_models(
    model: pin.Model, closures: Sequence[Closure], *, length: float, api: str = "new", mimic: bool = False
) -> tuple[pin.Model, object]:
    """A copy of ``model`` and the Pinocchio constraint models of ``closures`` (see the module docstring).

    Args:
        model: the mechanism's model.
        closures: every closure (the limbs' welds included: :attr:`pinmob.Mechanism.all_closures`).
        length: the length scale L [m] (a revolute closure's two anchors are L apart).
        api: ``"new"`` or ``"legacy"``.
        mimic: write linear joint couplings as mimic joints.

    Returns:
        the model and a ``StdVec_ConstraintModel`` (new) or ``StdVec_RigidConstraintModel`` (legacy).

    Warns:
        PinocchioExportWarning: one, naming each closure not written exactly and what was put instead.
    """
    if api not in APIS:
        raise ArgumentError(f"api must be one of {', '.join(map(repr, APIS))}, got {api!r}", "api", api)
    anchors: list[Anchor] = []
    notes: list[str] = []
    for closure in closures:
        if closure.type != ClosureType.JOINT or not mimic:
            found, note = closure_anchors(model, closure, length)
            anchors.extend(found)
            notes += [note] if note else []
    out = pin.Model(model)
    if mimic:
        out, mimic_notes = _mimics(out, [c for c in closures if c.type == ClosureType.JOINT])
        notes += mimic_notes
    if notes:
        linear = not mimic and any(c.type == ClosureType.JOINT and _linear(c) is not None for c in closures)
        hint = " (`mimic=True` writes linear joint couplings as mimic joints)" if linear else ""
        warnings.warn(
            f"{len(notes)} closure(s) have no exact Pinocchio constraint model: {'; '.join(notes)}{hint}",
            PinocchioExportWarning,
            stacklevel=3,
        )
    vector = pin.StdVec_RigidConstraintModel() if api == "legacy" else pin.StdVec_ConstraintModel()
    for anchor in anchors:
        vector.append(_build(out, anchor, api))
    return out, vector
