"""The Mechanism: one Pinocchio model (a tree), its limbs, platform and actuation.

A limb is the serial chain of joints that supports its tip frame. At a closed
configuration every limb tip has the same pose: the platform's. Loading from
files lives in :mod:`pinmob.mechanism_file`; closing configurations in
:mod:`pinmob.closure`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
import pinocchio as pin

from .exceptions import ConfigurationError, FrameError, choices
from .screw import RTOL, Array


@dataclass(frozen=True)
class Limb:
    """A serial chain from the base to the platform.

    Attributes:
        name: limb name.
        tip: name of the frame at the end of the chain.
        tip_id: Pinocchio frame index of ``tip``.
        joints: names of the joints supporting ``tip``, base to tip.
        v_indices: (nv_limb,) velocity indices of those joints in the model.
        actuated: names of this limb's actuated joints.
        generic_twist_rank: rank of the limb's joint screws at generic
            (random) joint values, with its internal loops closed; a lower
            rank at a configuration is a serial singularity.
        closures: names of the closures internal to this limb (loops such as
            a parallelogram that involve its joints and no other limb's).
        loop_joints: joints in no limb that those closures involve (e.g. the
            second rod of a parallelogram), in model order.
        loop_v_indices: velocity indices of ``loop_joints``.
    """

    name: str
    tip: str
    tip_id: int
    joints: tuple[str, ...]
    v_indices: Array = field(repr=False)
    actuated: tuple[str, ...] = ()
    generic_twist_rank: int = 0
    closures: tuple[str, ...] = ()
    loop_joints: tuple[str, ...] = ()
    loop_v_indices: Array = field(default_factory=lambda: np.zeros(0, int), repr=False)

    @property
    def screw_v_indices(self) -> Array:
        """Velocity indices of the joints whose rates move the limb: ``v_indices`` then ``loop_v_indices``."""
        return np.concatenate([self.v_indices, self.loop_v_indices]).astype(int)


CLOSURE_TYPES = ("6d", "3d", "revolute", "universal", "cylindrical", "planar")


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
    - ``planar`` (3 rows): slide ⊥ u and turn about u (u the plane normal);
      transmits the force along u and couples ⊥ u.

    Attributes:
        name: closure name.
        frame_a, frame_b: frame names; ``frame_a_id``, ``frame_b_id`` their indices.
        type: one of :data:`CLOSURE_TYPES`.
        axis: (3,) unit axis u in frame a (revolute, cylindrical, universal) or
            the plane normal (planar); ``None`` for 6d and 3d.
        axis_b: (3,) second hinge axis of a universal closure, in frame b.
    """

    name: str
    frame_a: str
    frame_b: str
    type: str = "6d"
    axis: Array | None = field(default=None, repr=False)
    axis_b: Array | None = field(default=None, repr=False)
    frame_a_id: int = -1
    frame_b_id: int = -1

    @property
    def rows(self) -> int:
        """Number of scalar constraints (relative-motion components forbidden)."""
        return CLOSURE_ROWS[self.type]


CLOSURE_ROWS = {"6d": 6, "3d": 3, "revolute": 5, "universal": 4, "cylindrical": 4, "planar": 3}


def closure_joints(model: pin.Model, closure: Closure) -> set[int]:
    """Indices of the joints a closure involves: those supporting either of its frames."""
    return {
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
    type: str = "6d",
    axis: object = None,
    axis_b: object = None,
) -> Closure:
    """A validated :class:`Closure` on ``model`` (frames exist, axes present and unit).

    Raises:
        FrameError: a frame does not exist.
        ConfigurationError: unknown type, or a missing / zero axis.
    """
    ctype = str(type).lower()
    if ctype not in CLOSURE_TYPES:
        raise ConfigurationError(f"closure {name!r}: unknown type {type!r}; valid: {choices(CLOSURE_TYPES)}")
    ida, idb = frame_id(model, frame_a), frame_id(model, frame_b)
    if ida == idb:
        raise ConfigurationError(f"closure {name!r} joins frame {frame_a!r} to itself")

    def unit(value: object, what: str) -> Array:
        a = np.asarray(value, float) if value is not None else np.zeros(0)
        if a.shape != (3,) or not np.isfinite(a).all() or np.linalg.norm(a) < 1e-12:
            raise ConfigurationError(
                f"closure {name!r} of type {ctype!r} needs {what} as a non-zero 3-vector, got {value!r}"
            )
        return a / np.linalg.norm(a)

    u = unit(axis, "'axis' (in frame a)") if ctype in ("revolute", "universal", "cylindrical", "planar") else None
    ub = unit(axis_b, "'axis_b' (second hinge axis, in frame b)") if ctype == "universal" else None
    return Closure(name, frame_a, frame_b, ctype, u, ub, ida, idb)


@dataclass(frozen=True)
class NamedConfiguration:
    """A named configuration: joint values, or a platform pose to assemble.

    Attributes:
        name: configuration name.
        joints: joint values by joint name [m or rad]; omitted joints are neutral.
        pose: platform pose (``pin.SE3``) to be assembled, or ``None``.
        seed: joint values that start the closure solver (select the assembly mode).
        approach: joint-space direction by joint name used by the paper's view
            (:func:`pinmob.mobility.paper_view`); empty when not declared.
    """

    name: str
    joints: Mapping[str, float] = field(default_factory=dict)
    pose: pin.SE3 | None = None
    seed: Mapping[str, float] = field(default_factory=dict)
    approach: Mapping[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class Expectation:
    """Mobility stated by the literature for a named configuration."""

    dof: int
    motion_type: str
    source: str = ""


@dataclass(frozen=True)
class Mechanism:
    """A closed-chain mechanism: a Pinocchio tree plus limbs meeting at a platform.

    Build one with :func:`pinmob.load` or :func:`Mechanism.from_model`.

    Attributes:
        name: mechanism name.
        model: the Pinocchio model holding every limb as a branch.
        limbs: the limbs; their tips coincide at a closed configuration (may be
            empty for a mechanism described by closures only).
        platform: name of the frame reported as platform; ``""`` when the
            mechanism has none (e.g. an Extended URDF robot).
        length_scale: characteristic length L [m] used to make ranks unit-invariant.
        configurations: named configurations.
        expected: literature mobility per configuration name.
        description: free text.
        source: the file it was loaded from, if any.
        visual_model: Pinocchio visual geometry, if loaded.
        collision_model: Pinocchio collision geometry, if loaded.
        generic_rank: constraint rank at generic configurations, when declared
            (else :mod:`pinmob.singularity` estimates it from random closed
            configurations).
        closures: loop closures besides the limb tips meeting at the platform
            (see :attr:`all_closures`).
        extra_actuated: actuated joints not attached to a limb (mechanisms
            described by closures only).
    """

    name: str
    model: pin.Model = field(repr=False)
    limbs: tuple[Limb, ...]
    platform: str
    length_scale: float
    configurations: Mapping[str, NamedConfiguration] = field(default_factory=dict, repr=False)
    expected: Mapping[str, Expectation] = field(default_factory=dict, repr=False)
    description: str = ""
    source: Path | None = None
    visual_model: pin.GeometryModel | None = field(default=None, repr=False)
    collision_model: pin.GeometryModel | None = field(default=None, repr=False)
    generic_rank: int | None = None
    closures: tuple[Closure, ...] = ()
    extra_actuated: tuple[str, ...] = ()

    # ------------------------------------------------------------------ build

    @classmethod
    def from_model(
        cls,
        model: pin.Model,
        limbs: Mapping[str, str] | list[tuple[str, str]],
        *,
        name: str = "mechanism",
        platform: str | None = None,
        actuated: Mapping[str, list[str]] | None = None,
        length_scale: float | None = None,
        configurations: Mapping[str, NamedConfiguration] | None = None,
        expected: Mapping[str, Expectation] | None = None,
        description: str = "",
        source: Path | None = None,
        visual_model: pin.GeometryModel | None = None,
        collision_model: pin.GeometryModel | None = None,
        generic_rank: int | None = None,
        closures: list[Closure] | tuple[Closure, ...] = (),
    ) -> Mechanism:
        """Build a mechanism from a model and ``{limb name: tip frame}``.

        Without limbs the mechanism is described by ``closures`` alone; its
        actuated joints are then given under the key ``""`` of ``actuated``
        (joints anywhere in the model), and it has a platform only if
        ``platform`` names one.

        Raises:
            FrameError: a tip, platform or actuated joint does not exist.
            ConfigurationError: two limbs share a joint, a limb has no joint, or
                there is neither a limb nor a closure.
        """
        pairs = list(limbs.items()) if isinstance(limbs, Mapping) else list(limbs)
        if not pairs and not closures:
            raise ConfigurationError(f"mechanism {name!r} has neither a limb nor a closure; give at least one")
        actuated = dict(actuated or {})
        extra = tuple(actuated.pop("", ()))
        for a in extra:
            if not model.existJointName(a) or a == "universe":
                raise FrameError(
                    f"actuated joint {a!r} does not exist in {name!r}; valid: {choices(list(model.names)[1:])}"
                )
        names = [c.name for c in closures]
        if len(set(names)) != len(names):
            raise ConfigurationError(f"closure names must be unique in {name!r}, got {names}")
        built: list[Limb] = []
        owner: dict[str, str] = {}
        for limb_name, tip in pairs:
            tip_id = frame_id(model, tip)
            joint_ids = [j for j in model.supports[model.frames[tip_id].parentJoint] if j > 0]
            if not joint_ids:
                raise ConfigurationError(f"limb {limb_name!r}: tip frame {tip!r} is fixed to the base (no joint)")
            joints = tuple(model.names[j] for j in joint_ids)
            for j in joints:
                if j in owner:
                    raise ConfigurationError(
                        f"limbs {owner[j]!r} and {limb_name!r} share joint {j!r}: each limb must be its own "
                        "branch from the base (close shared parts with closures instead)"
                    )
                owner[j] = limb_name
            acts = tuple(actuated.get(limb_name, ()))
            for a in acts:
                if a not in joints:
                    raise FrameError(
                        f"limb {limb_name!r}: actuated joint {a!r} is not in its chain; valid: {choices(joints)}"
                    )
            built.append(Limb(limb_name, tip, tip_id, joints, _velocity_indices(model, joint_ids), acts))
        groups = group_closures(model, tuple(built), tuple(closures))
        built = [
            replace(
                b,
                closures=groups.internal.get(b.name, ()),
                loop_joints=tuple(model.names[j] for j in groups.loop_joints.get(b.name, ())),
                loop_v_indices=_velocity_indices(model, groups.loop_joints.get(b.name, ())),
            )
            for b in built
        ]
        platform = platform or (pairs[0][1] if pairs else "")
        if platform:
            frame_id(model, platform)
        frames = [b.tip_id for b in built] + [i for c in closures for i in (c.frame_a_id, c.frame_b_id)]
        scale = float(length_scale) if length_scale else characteristic_length(model, frames)
        if not np.isfinite(scale) or scale <= 0:
            raise ConfigurationError(f"length_scale must be a positive number of metres, got {length_scale!r}")
        if generic_rank is not None and (
            not isinstance(generic_rank, int) or isinstance(generic_rank, bool) or not 0 <= generic_rank <= 6
        ):
            raise ConfigurationError(f"generic_rank must be an integer from 0 to 6, got {generic_rank!r}")
        mech = cls(
            name=name,
            model=model,
            limbs=tuple(built),
            platform=platform,
            length_scale=scale,
            configurations=dict(configurations or {}),
            expected=dict(expected or {}),
            description=description,
            source=source,
            visual_model=visual_model,
            collision_model=collision_model,
            generic_rank=generic_rank,
            closures=tuple(closures),
            extra_actuated=extra,
        )
        return replace(mech, limbs=tuple(replace(b, generic_twist_rank=_generic_twist_rank(mech, b)) for b in built))

    # ------------------------------------------------------------------ queries

    @property
    def has_platform(self) -> bool:
        """True when a platform frame is named."""
        return bool(self.platform)

    @property
    def all_closures(self) -> tuple[Closure, ...]:
        """Every loop closure: each limb tip welded (6d) to the platform frame, then :attr:`closures`.

        A limb whose tip is fixed to the platform frame's body (same parent
        joint) closes nothing and is left out.
        """
        if not self.platform:
            return self.closures
        pid = self.platform_id
        body = self.model.frames[pid].parentJoint
        implicit = tuple(
            Closure(f"limb {b.name}", self.platform, b.tip, "6d", None, None, pid, b.tip_id)
            for b in self.limbs
            if self.model.frames[b.tip_id].parentJoint != body
        )
        return implicit + self.closures

    @property
    def coupling_closures(self) -> dict[str, tuple[str, ...]]:
        """Closures whose loops involve the joints of two or more limbs: closure name -> those limbs.

        The limb-wise method cannot treat them (:func:`pinmob.mobility.analyze`
        then uses the closure Jacobian of the whole mechanism).
        """
        return group_closures(self.model, self.limbs, self.closures).coupling

    @property
    def platform_id(self) -> int:
        """Pinocchio frame index of the platform frame."""
        return self.model.getFrameId(self.platform)

    @property
    def actuated(self) -> tuple[str, ...]:
        """All actuated joint names, limb by limb, then those outside limbs."""
        return tuple(a for limb in self.limbs for a in limb.actuated) + self.extra_actuated

    def limb(self, name: str) -> Limb:
        """The limb called ``name``."""
        for limb in self.limbs:
            if limb.name == name:
                return limb
        raise ConfigurationError(f"no limb {name!r} in {self.name!r}; valid: {choices(b.name for b in self.limbs)}")

    def neutral(self) -> Array:
        """Pinocchio's neutral configuration, shape (nq,)."""
        return pin.neutral(self.model)

    def q_from_joints(self, values: Mapping[str, float], base: Array | None = None) -> Array:
        """Configuration vector from joint values by name; others from ``base`` (default neutral).

        One-degree joints take a value [m or rad]; continuous joints take an angle.
        """
        q = np.array(self.neutral() if base is None else base, float)
        for jname, value in values.items():
            if not self.model.existJointName(jname):
                raise FrameError(
                    f"unknown joint {jname!r} in {self.name!r}; valid: {choices(list(self.model.names)[1:])}"
                )
            try:
                x = float(value)
            except (TypeError, ValueError):
                raise ConfigurationError(f"joint {jname!r}: value {value!r} is not a number") from None
            if not np.isfinite(x):
                raise ConfigurationError(f"joint {jname!r}: value {value!r} is not finite")
            joint = self.model.joints[self.model.getJointId(jname)]
            if joint.nq == 1:
                q[joint.idx_q] = x
            elif joint.nq == 2 and joint.nv == 1:  # continuous (unbounded revolute): (cos, sin)
                q[joint.idx_q : joint.idx_q + 2] = (np.cos(x), np.sin(x))
            else:
                raise ConfigurationError(
                    f"joint {jname!r} ({joint.shortname()}) has {joint.nq} coordinates: give the whole "
                    "configuration vector instead of a value by name"
                )
        return q

    def configuration(self, name: str, tol: float = 1e-6) -> Array:
        """A named configuration as a closed configuration vector, shape (nq,).

        Joint values are checked for closure; a pose is assembled by
        :func:`pinmob.closure.assemble_pose`. Raises :class:`ClosureError` when
        the configuration does not close within ``tol`` (position / L and
        rotation [rad]; the default is ``pinmob.closure.CLOSURE_TOL``).
        """
        from .closure import assemble_pose, check_closed

        if name not in self.configurations:
            raise ConfigurationError(
                f"no configuration {name!r} in {self.name!r}; valid: {choices(self.configurations)}"
            )
        conf = self.configurations[name]
        if conf.pose is not None:
            seed = self.q_from_joints(conf.seed)
            return assemble_pose(self, conf.pose, seed, tol)
        q = self.q_from_joints(conf.joints)
        check_closed(self, q, tol, f"configuration {name!r}")
        return q

    def resolve(self, q: Array | str, configuration: str | None = None) -> tuple[Array, str | None]:
        """A checked configuration vector and the name to report with it.

        A name is looked up (:meth:`configuration`) and becomes the reported
        name unless ``configuration`` is given; a vector is checked (:meth:`check_q`).
        """
        if isinstance(q, str):
            return self.check_q(self.configuration(q)), configuration or q
        return self.check_q(q), configuration

    def check_q(self, q: object) -> Array:
        """Validate a configuration vector: shape (nq,), finite, normalised where needed."""
        arr = np.asarray(q, dtype=float) if not isinstance(q, np.ndarray) else q.astype(float)
        if arr.shape != (self.model.nq,):
            raise ConfigurationError(
                f"configuration has shape {arr.shape}; {self.name!r} needs shape ({self.model.nq},) "
                f"(nq = {self.model.nq}: joints {', '.join(list(self.model.names)[1:])})"
            )
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            raise ConfigurationError(f"configuration has non-finite values (NaN or inf) at indices {bad.tolist()}")
        if not pin.isNormalized(self.model, arr, 1e-6):
            raise ConfigurationError(
                "configuration is not normalised (a quaternion or (cos, sin) pair is off the unit sphere)"
            )
        return arr


def frame_id(model: pin.Model, name: str) -> int:
    """Index of frame ``name``; a :class:`FrameError` listing the frames otherwise."""
    if not model.existFrame(name):
        raise FrameError(
            f"no frame {name!r} in model {model.name!r}; valid frames: {choices(f.name for f in model.frames)}"
        )
    return model.getFrameId(name)


def characteristic_length(model: pin.Model, frame_ids: list[int]) -> float:
    """Default L [m]: root mean square of the model's non-zero link offsets.

    Uses the joint placements (link vectors) and the given frames' placements;
    it scales with the model's units and does not depend on the configuration.
    Falls back to 1 m for a model with no offset at all.
    """
    offsets = [np.linalg.norm(model.jointPlacements[j].translation) for j in range(1, model.njoints)]
    offsets += [np.linalg.norm(model.frames[f].placement.translation) for f in frame_ids]
    nonzero = np.array([o for o in offsets if o > 1e-12])
    return float(np.sqrt(np.mean(nonzero**2))) if nonzero.size else 1.0


def _velocity_indices(model: pin.Model, joint_ids: list[int] | tuple[int, ...]) -> Array:
    """Velocity indices of the given joints, in the given order."""
    parts = [np.arange(model.joints[j].idx_v, model.joints[j].idx_v + model.joints[j].nv) for j in joint_ids]
    return np.concatenate(parts).astype(int) if parts else np.zeros(0, int)


def _generic_twist_rank(mech: Mechanism, limb: Limb, samples: int = 3) -> int:
    """Largest rank of a limb's joint screws over seeded random configurations (its generic rank).

    The screws are :func:`pinmob.mobility.limb_screws` (with the limb's
    internal loops closed: each sample is first projected onto them, and used
    as it is only where that fails), scaled by ``mech.length_scale`` as in
    every rank decision of the analysis.
    """
    from .closure import ClosureError, compute_kinematics, project, random_configuration
    from .mobility import limb_screws
    from .screw import decide_rank, twist_scaling

    model = mech.model
    data = model.createData()
    rng = np.random.default_rng(0)
    loops = tuple(c for c in mech.closures if c.name in limb.closures)
    alone = replace(mech, limbs=(), platform="", closures=loops)
    best = 0
    for _ in range(samples):
        q = random_configuration(mech, rng, spread=1.0)
        if loops:
            try:
                q = project(alone, q).q
            except ClosureError:
                pass
        compute_kinematics(model, data, q)
        t = twist_scaling(mech.length_scale)[:, None] * limb_screws(mech, data, limb)
        best = max(best, decide_rank(t.T, RTOL).rank)
    return best
