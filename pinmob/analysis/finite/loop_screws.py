"""The mechanism's instantaneous joint screws as loops: the input of the higher-order analysis.

Every closure (limb tips welded to the platform included) closes a loop of the kinematic tree.
A closure that is not a weld lets its two frames move relative to each other: it is written
as a *cut joint*, a serial chain of elementary screws attached to frame a's body, at the
closed configuration (world axes, frame a's origin p, its axis ``u`` turned to the world):

- ``6d``: none; ``3d`` (ball): rotations about x, y, z through p;
- ``revolute``: the rotation about u through p; ``cylindrical``: it and the translation along u;
- ``universal``: the rotation about u, then about the second axis (frame b's ``axis_b``), through p;
- ``planar``: the translations along two directions normal to u, then the rotation about u.

A coupling (a polynomial between joint values or fixed-tendon lengths) closes no loop: it is a
scalar row of its own, differentiated exactly (:mod:`pinmob.analysis.finite.coupling_rows`).

The loop twist of a closure is then ``V_b - V_e`` (frame b's body, the cut chain's last body),
and the closed configurations near q are exactly the curves keeping every loop twist zero
(:mod:`pinmob.screw.lie`). The cut coordinates are extra unknowns; each cut chain is a local
parametrisation of the relative motions its closure allows, so the instantaneous DoF is the same
as that of the closure Jacobian (``nullity A = nv - rank K``), and the first ``nv`` coordinates of
any solution are joint rates.

Units: twists ``[v / L; w]`` at one reference point (the platform origin, else the centroid of the
closure frames), translation rates per L, as in :mod:`pinmob.analysis.chain.closed_chain`.
Joints must have a motion subspace constant in their child frame (revolute, prismatic, helical,
spherical, planar, translation, free-flyer); others are refused with the list.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinmob.analysis.chain.closed_chain import closed_chain_columns
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.finite.coupling_rows import CoupledSystem, CouplingRow, coupling_rows
from pinmob.exceptions import ConfigurationError
from pinmob.model import Closure, ClosureType
from pinmob.name_matching import choices
from pinmob.screw import Array, LoopSystem, shift_twists, twist_scaling

#: Pinocchio joints whose motion subspace is constant in the child frame (``dS/dt = [V_child, S]`` holds).
SUPPORTED_JOINTS = (
    "JointModelRX",
    "JointModelRY",
    "JointModelRZ",
    "JointModelRevoluteUnaligned",
    "JointModelRUBX",
    "JointModelRUBY",
    "JointModelRUBZ",
    "JointModelRevoluteUnboundedUnaligned",
    "JointModelPX",
    "JointModelPY",
    "JointModelPZ",
    "JointModelPrismaticUnaligned",
    "JointModelHX",
    "JointModelHY",
    "JointModelHZ",
    "JointModelHelicalUnaligned",
    "JointModelSpherical",
    "JointModelPlanar",
    "JointModelTranslation",
    "JointModelFreeFlyer",
)


@dataclass(frozen=True)
class MechanismLoops:
    """The loops of a mechanism at a closed configuration.

    Attributes:
        system: the screws, bodies and loops (:class:`~pinmob.screw.lie.LoopSystem`).
        nv: the tree's joint rates (the first ``nv`` columns); the rest are cut-joint rates.
        columns: (nv,) the tree columns' scaling to dimensionless rates (L on translations).
        reference: (3,) the reference point of every twist [m].
    """

    system: LoopSystem
    nv: int
    columns: Array
    reference: Array
    couplings: tuple[CouplingRow, ...] = ()

    @property
    def equations(self) -> CoupledSystem:
        """The closure equations near q: the loops', then the couplings' rows (:mod:`pinmob.analysis.finite.coupling_rows`)."""
        return CoupledSystem(self.system, self.couplings)


def _cut_screws(conf: Configuration, c: Closure) -> list[Array]:
    """World twists ``[v; w]`` (at the world origin, SI) of closure c's cut chain, in chain order."""
    oma = conf.frame_placement(c.frame_a_id)
    p, rot = np.array(oma.translation), np.array(oma.rotation)

    def turn(axis: Array) -> Array:
        return np.concatenate([np.cross(p, axis), axis])

    def slide(axis: Array) -> Array:
        return np.concatenate([axis, np.zeros(3)])

    if c.type is ClosureType.WELD:
        return []
    if c.type is ClosureType.BALL:
        return [turn(e) for e in np.eye(3)]
    if c.type is ClosureType.ORIENTATION:
        return [slide(e) for e in np.eye(3)]
    u = rot @ np.asarray(c.axis, float)
    if c.type is ClosureType.REVOLUTE:
        return [turn(u)]
    if c.type is ClosureType.CYLINDRICAL:
        return [turn(u), slide(u)]
    if c.type is ClosureType.PRISMATIC:
        return [slide(u)]
    if c.type in (ClosureType.UNIVERSAL, ClosureType.PERPENDICULAR):
        u_b = np.array(conf.frame_placement(c.frame_b_id).rotation) @ np.asarray(c.axis_b, float)
        slides = [slide(e) for e in np.eye(3)] if c.type is ClosureType.PERPENDICULAR else []
        return slides + [turn(u), turn(u_b)]
    e1 = np.cross(u, np.eye(3)[int(np.argmin(np.abs(u)))])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(u, e1)
    if c.type is ClosureType.PLANAR_WELD:
        return [slide(u), turn(e1), turn(e2)]
    if c.type is ClosureType.INLINE:
        return [slide(u)] + [turn(e) for e in np.eye(3)]
    if c.type is ClosureType.INPLANE:
        return [slide(e1), slide(e2)] + [turn(e) for e in np.eye(3)]
    if c.type is ClosureType.PARALLEL_AXES:
        return [slide(e) for e in np.eye(3)] + [turn(u)]
    return [slide(e1), slide(e2), turn(u)]  # planar


def check_joints(conf: Configuration) -> None:
    """Refuse a joint whose motion subspace changes in its child frame (the bracket rule does not hold).

    Raises:
        ConfigurationError: naming the joint, its type and the supported types.
    """
    model = conf.mechanism.model
    for j in range(1, model.njoints):
        kind = model.joints[j].shortname()
        if model.joints[j].nv and kind not in SUPPORTED_JOINTS:
            raise ConfigurationError(
                f"the higher-order (finite mobility) analysis cannot treat joint {model.names[j]!r} of type {kind}; "
                f"supported: {choices(SUPPORTED_JOINTS)}"
            )


def mechanism_loops(conf: Configuration) -> MechanismLoops:
    """The :class:`MechanismLoops` at ``conf`` (cached on it).

    Raises:
        ConfigurationError: an unsupported joint type (:func:`check_joints`).
    """

    def compute() -> MechanismLoops:
        check_joints(conf)
        mech = conf.mechanism
        model, length = mech.model, mech.length_scale
        closures = mech.all_closures
        points = [conf.frame_placement(i).translation for c in closures for i in (c.frame_a_id, c.frame_b_id)]
        reference = conf.platform_origin if mech.has_platform else np.mean(points, axis=0) if points else np.zeros(3)
        col = closed_chain_columns(conf)
        tree = conf.world_jacobian * col  # (6, nv) joint screws per dimensionless rate, world origin
        body = np.zeros(model.nv, int)
        parent = list(model.parents)
        for j in range(1, model.njoints):
            joint = model.joints[j]
            body[joint.idx_v : joint.idx_v + joint.nv] = j
        screws, bodies, ends = [tree], [body], []
        for c in (c for c in closures if not c.is_coupling):  # couplings: rows of their own, below
            cut = _cut_screws(conf, c)
            end = model.frames[c.frame_a_id].parentJoint
            for s in cut:
                parent.append(end)
                end = len(parent) - 1
                scale = length if np.linalg.norm(s[3:]) == 0 else 1.0
                screws.append((s * scale)[:, None])
                bodies.append(np.array([end]))
            ends.append((model.frames[c.frame_b_id].parentJoint, end))
        s_all = shift_twists(np.hstack(screws), reference) * twist_scaling(length)[:, None]
        body_all = np.concatenate(bodies)
        n, nb = body_all.size, len(parent)
        support = np.zeros((nb, n))
        for b in range(1, nb):  # parents come before their children
            support[b] = support[parent[b]]
            support[b, body_all == b] = 1.0
        loops = np.array([support[b] - support[e] for b, e in ends]).reshape(len(ends), n)
        system = LoopSystem(s_all.T.copy(), body_all, support, loops)
        return MechanismLoops(system, model.nv, col, reference, coupling_rows(conf, closures, col, n, reference))

    return conf.memo("mechanism_loops", compute)
