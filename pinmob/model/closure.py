"""Loop closures: two frames of the tree joined when the loop is closed, and how closures sit among limbs."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from typing import TYPE_CHECKING

import numpy as np
import pinocchio as pin

from pinmob.exceptions import ConfigurationError, FrameError
from pinmob.model.joints import frame_id, has_joint
from pinmob.model.tendon import Tendon
from pinmob.name_matching import choices
from pinmob.screw import Array

if TYPE_CHECKING:
    from pinmob.model.limb import Limb


class ClosureType(StrEnum):
    """The relative motion a closure allows (see :class:`Closure`); the value is the file spelling."""

    WELD = "6d"
    BALL = "3d"
    REVOLUTE = "revolute"
    UNIVERSAL = "universal"
    CYLINDRICAL = "cylindrical"
    PRISMATIC = "prismatic"
    PLANAR = "planar"
    PLANAR_WELD = "planar_weld"
    INLINE = "inline"
    INPLANE = "inplane"
    ORIENTATION = "orientation"
    PARALLEL_AXES = "parallel_axes"
    PERPENDICULAR = "perpendicular"
    JOINT = "joint"
    TENDON = "tendon"


#: Default closure tolerance: position residual / L and rotation residual [rad].
CLOSURE_TOL = 1e-6

#: Couplings: closures between coordinates (joint values, tendon lengths), not two frames meeting (from MJCF).
COUPLINGS = (ClosureType.JOINT, ClosureType.TENDON)

#: Closure types a mechanism file may declare between two frames.
CLOSURE_TYPES = tuple(t.value for t in ClosureType if t not in COUPLINGS)

#: Closure types with an axis u in frame a, and those with a second axis u_b in frame b.
AXIS_TYPES = (
    "revolute", "universal", "cylindrical", "prismatic", "planar", "planar_weld", "inline", "inplane", "parallel_axes", "perpendicular"
)  # fmt: skip
AXIS_B_TYPES = ("universal", "perpendicular")


@dataclass(frozen=True)
class Closure:
    """A loop closure: two frames of the tree that are joined when the loop is closed.

    A closure is defined by the relative motion of frame b with respect to
    frame a that it forbids, i.e. by the wrench subspace it transmits. With the
    relative twist ``[v; w]`` of b w.r.t. a expressed in frame a, and ``u`` the
    closure's axis in frame a:

    - ``6d`` (6 rows): a weld, same pose; transmits every wrench.
    - ``3d`` (3 rows): a ball joint, same origin; transmits forces through it.
    - ``revolute`` (5 rows): a hinge about u; transmits forces and couples ⊥ u.
    - ``universal`` (4 rows): hinges about u (fixed in a) and u_b (fixed in b);
      transmits forces and the couple along ``u x u_b``.
    - ``cylindrical`` (4 rows): turn about and slide along u; transmits forces
      ⊥ u and couples ⊥ u.
    - ``prismatic`` (5 rows): slide along u (an SDF loop joint of type prismatic); transmits
      forces ⊥ u and every couple.
    - ``planar`` (3 rows): slide ⊥ u and turn about u (u the plane normal);
      transmits the force along u and couples ⊥ u.
    - ``planar_weld`` (3 rows): a weld in the plane normal to u: forbids the slide ⊥ u of b's origin and the
      turn about u; the independent equations of a weld in a planar loop (its other three are implied there).
    - ``inline`` (2 rows): b's origin stays on the line through a's origin along u (slide ⊥ u forbidden);
      a ball or hinge closure in a planar loop of normal u.
    - ``inplane`` (1 row): b's origin stays in the plane through a's origin normal to u.
    - ``orientation`` (3 rows): same orientation, any translation; a weld in a spherical loop.
    - ``parallel_axes`` (2 rows): u and b's copy of it stay parallel (turns ⊥ u forbidden), any translation.
    - ``perpendicular`` (1 row): u (in a) and u_b (in b) stay perpendicular: a universal's fourth row alone.
    - ``joint`` (1 row): MuJoCo's ``<equality joint>``, a coupling of two one-degree joints,
      ``q1 - r1 = sum_k c_k (q2 - r2)^k`` (``q1 - r1 = c_0`` without a second joint); its frames
      are the two joints' frames (the world for a missing second joint).
    - ``tendon`` (1 row): MuJoCo's ``<equality tendon>``, ``l1 - r1 = sum_k c_k (l2 - r2)^k`` between
      tendon lengths (:class:`~pinmob.model.tendon.Tendon`; ``r`` the lengths at MuJoCo's ``qpos0``); its
      frames are two of the tendons' own (a joint's or a site's), so that it sits on the mechanism.

    Attributes:
        name: closure name.
        frame_a, frame_b: frame names; ``frame_a_id``, ``frame_b_id`` their indices.
        type: one of :data:`CLOSURE_TYPES`.
        axis: (3,) unit axis u in frame a (revolute, cylindrical, prismatic, universal, inline, parallel_axes, perpendicular)
            or the plane normal (planar, planar_weld, inplane); ``None`` for 6d, 3d and orientation.
        axis_b: (3,) second hinge axis of a universal closure, the axis u_b of a perpendicular one, in frame b.
        joints: the coupled joints (``joint`` closures): ``(joint1,)`` or ``(joint1, joint2)``.
        polycoef: the coupling's polynomial coefficients ``c_0, c_1, ...`` (``joint`` closures).
        reference: the joints' reference values ``r1, r2`` [rad or m] (``joint`` closures), the tendons'
            reference lengths (``tendon`` closures).
        tendons: the coupled tendons (``tendon`` closures): ``(tendon1,)`` or ``(tendon1, tendon2)``.
    """

    name: str
    frame_a: str
    frame_b: str
    type: ClosureType = ClosureType.WELD
    axis: Array | None = field(default=None, repr=False)
    axis_b: Array | None = field(default=None, repr=False)
    frame_a_id: int = -1
    frame_b_id: int = -1
    joints: tuple[str, ...] = ()
    polycoef: tuple[float, ...] = ()
    reference: tuple[float, ...] = ()
    tendons: tuple[Tendon, ...] = field(default=(), repr=False)

    @property
    def rows(self) -> int:
        """Number of scalar constraints (relative-motion components forbidden)."""
        return CLOSURE_ROWS[self.type]

    @property
    def is_coupling(self) -> bool:
        """A ``joint`` or ``tendon`` coupling: a relation between coordinates, no cut joint between its frames."""
        return self.type in COUPLINGS


#: scalar equations of each closure type
CLOSURE_ROWS = {
    ClosureType.WELD: 6,
    ClosureType.BALL: 3,
    ClosureType.REVOLUTE: 5,
    ClosureType.UNIVERSAL: 4,
    ClosureType.CYLINDRICAL: 4,
    ClosureType.PRISMATIC: 5,
    ClosureType.PLANAR: 3,
    ClosureType.PLANAR_WELD: 3,
    ClosureType.INLINE: 2,
    ClosureType.INPLANE: 1,
    ClosureType.ORIENTATION: 3,
    ClosureType.PARALLEL_AXES: 2,
    ClosureType.PERPENDICULAR: 1,
    ClosureType.JOINT: 1,
    ClosureType.TENDON: 1,
}


def closure_joints(model: pin.Model, closure: Closure) -> set[int]:
    """Indices of the joints a closure involves: those supporting either of its frames (and its tendons' joints)."""
    return {int(j) for t in closure.tendons for j in t.joint_ids(model)} | {
        int(j)
        for f in (closure.frame_a_id, closure.frame_b_id)
        for j in model.supports[model.frames[f].parentJoint]
        if j > 0
    }


@dataclass(frozen=True)
class ClosureGroups:
    """How the closures of a limb-and-platform mechanism sit among its limbs.

    Closures that share a joint of no limb form one group (one loop system).
    A group whose joints meet exactly one limb's joints is internal to that
    limb; one that meets two or more limbs couples them (the limb-wise method
    does not apply); one that meets no limb moves nothing of any limb.

    Attributes:
        internal: limb name -> names of its internal closures.
        loop_joints: limb name -> indices of the joints in no limb that they involve.
        coupling: closure name -> names of the limbs its group couples.
        detached: names of the closures that meet no limb.
    """

    internal: dict[str, tuple[str, ...]]
    loop_joints: dict[str, tuple[int, ...]]
    coupling: dict[str, tuple[str, ...]]
    detached: tuple[str, ...]


def group_closures(model: pin.Model, limbs: tuple[Limb, ...], closures: tuple[Closure, ...]) -> ClosureGroups:
    """Sort ``closures`` into internal-to-one-limb, coupling and detached groups (:class:`ClosureGroups`)."""
    owner = {model.getJointId(j): limb.name for limb in limbs for j in limb.joints}
    parent = list(range(len(closures)))  # union-find over closures sharing a joint of no limb

    def root(i: int) -> int:
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    joints = [closure_joints(model, c) for c in closures]
    first: dict[int, int] = {}
    for i, js in enumerate(joints):
        for j in js - owner.keys():
            if j in first:
                parent[root(i)] = root(first[j])
            else:
                first[j] = i
    members: dict[int, list[int]] = {}
    for i in range(len(closures)):
        members.setdefault(root(i), []).append(i)
    internal: dict[str, tuple[str, ...]] = {}
    loop: dict[str, tuple[int, ...]] = {}
    coupling: dict[str, tuple[str, ...]] = {}
    detached: list[str] = []
    order = [limb.name for limb in limbs]
    for group in members.values():
        touched = {owner[j] for i in group for j in joints[i] if j in owner}
        names = tuple(closures[i].name for i in group)
        if not touched:
            detached.extend(names)
        elif len(touched) > 1:
            coupling.update({n: tuple(x for x in order if x in touched) for n in names})
        else:
            (limb_name,) = touched
            internal[limb_name] = internal.get(limb_name, ()) + names
            free = {j for i in group for j in joints[i]} - owner.keys()
            loop[limb_name] = tuple(sorted(set(loop.get(limb_name, ())) | free))
    return ClosureGroups(internal, loop, coupling, tuple(detached))


def make_closure(
    model: pin.Model,
    name: str,
    frame_a: str,
    frame_b: str,
    type: ClosureType | str = ClosureType.WELD,
    axis: object = None,
    axis_b: object = None,
) -> Closure:
    """A validated :class:`Closure` on ``model`` (frames exist, axes present and unit).

    Raises:
        FrameError: a frame does not exist.
        ConfigurationError: unknown type, or a missing / zero axis.
    """
    if str(type).lower() not in CLOSURE_TYPES:
        raise ConfigurationError(f"closure {name!r}: unknown type {type!r}; valid: {choices(CLOSURE_TYPES)}")
    ctype = ClosureType(str(type).lower())
    ida, idb = frame_id(model, frame_a), frame_id(model, frame_b)
    if ida == idb:
        raise ConfigurationError(f"closure {name!r} joins frame {frame_a!r} to itself")

    def unit(value: object, what: str) -> Array:
        a = np.asarray(value, float) if value is not None else np.zeros(0)
        if a.shape != (3,) or not np.isfinite(a).all() or not np.abs(a).max() > 0:
            raise ConfigurationError(
                f"closure {name!r} of type {ctype.value!r} needs {what} as a non-zero 3-vector, got {value!r}"
            )
        a = a / np.abs(a).max()  # first to about 1: the norm of [1e308, 1e308, 0] overflows
        return a / np.linalg.norm(a)

    u = unit(axis, "'axis' (in frame a)") if ctype in AXIS_TYPES else None
    ub = unit(axis_b, "'axis_b' (second axis, in frame b)") if ctype in AXIS_B_TYPES else None
    return Closure(name, frame_a, frame_b, ctype, u, ub, ida, idb)


def make_coupling(
    model: pin.Model, name: str, joints: tuple[str, ...], polycoef: tuple[float, ...], reference: tuple[float, ...]
) -> Closure:
    """A ``joint`` closure: ``q1 - r1 = sum_k c_k (q2 - r2)^k`` between one-degree joints (MuJoCo's ``<equality joint>``).

    Its frames are the joints' ``JOINT`` frames (frame 0, the world, for a missing second joint).

    Raises:
        FrameError: a joint does not exist or has no ``JOINT`` frame.
        ConfigurationError: a joint is not a one-degree joint, or no coefficient is given.
    """
    frames = []
    for j in joints:
        if not has_joint(model, j):
            raise FrameError(f"closure {name!r}: no joint {j!r}; valid: {choices(list(model.names)[1:])}")
        jid = model.getJointId(j)
        if model.joints[jid].nq != 1 or model.joints[jid].nv != 1:
            raise ConfigurationError(f"closure {name!r}: joint {j!r} is not a one-degree (hinge or slide) joint")
        ids = [i for i, f in enumerate(model.frames) if f.parentJoint == jid and f.type == pin.FrameType.JOINT]
        if not ids:
            raise FrameError(f"closure {name!r}: joint {j!r} has no JOINT frame")
        frames.append(ids[0])
    if not polycoef or not np.isfinite(polycoef).all():
        raise ConfigurationError(f"closure {name!r}: a joint coupling needs finite polynomial coefficients")
    ida, idb = frames[0], frames[1] if len(frames) > 1 else 0
    return Closure(
        name,
        model.frames[ida].name,
        model.frames[idb].name,
        ClosureType.JOINT,
        frame_a_id=ida,
        frame_b_id=idb,
        joints=tuple(joints),
        polycoef=tuple(float(c) for c in polycoef),
        reference=tuple(float(r) for r in reference),
    )


def make_tendon_coupling(
    model: pin.Model,
    name: str,
    tendons: tuple[Tendon, ...],
    polycoef: tuple[float, ...],
    reference: tuple[float, ...],
    frames: tuple[int, int],
) -> Closure:
    """A ``tendon`` closure: ``l1 - r1 = sum_k c_k (l2 - r2)^k`` (``l1 - r1 = c_0`` with one tendon).

    ``frames`` are two frame indices on the tendons (they place the closure on the mechanism).

    Raises:
        ConfigurationError: no tendon or no finite coefficient.
    """
    if not tendons or not polycoef or not np.isfinite(polycoef).all():
        raise ConfigurationError(f"closure {name!r}: a tendon coupling needs a tendon and finite coefficients")
    ida, idb = frames
    return Closure(
        name,
        model.frames[ida].name,
        model.frames[idb].name,
        ClosureType.TENDON,
        frame_a_id=ida,
        frame_b_id=idb,
        polycoef=tuple(float(c) for c in polycoef),
        reference=tuple(float(r) for r in reference),
        tendons=tuple(tendons),
    )
