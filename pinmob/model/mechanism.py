"""The Mechanism: one Pinocchio model (a tree), its limbs, closures, platform and actuation (plain data).

A limb is the serial chain of joints that supports its tip frame. At a closed
configuration every limb tip has the same pose: the platform's. Loading from
files lives in :mod:`pinmob.io`; closing configurations in :mod:`pinmob.assembly`;
the closed configuration and what is computed from it in
:class:`pinmob.analysis.configuration.Configuration`.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property
from pathlib import Path
from typing import Any, TypeVar

import pinocchio as pin

from pinmob.exceptions import ConfigurationError, FrameError, unknown
from pinmob.frozen import read_only
from pinmob.model.closure import Closure, ClosureType, group_closures
from pinmob.model.constraint_models import mechanism_parts, write_constraint_models
from pinmob.model.geometry import Geometry
from pinmob.model.joint_values import q_from_values
from pinmob.model.joints import check_q, frame_id, has_joint, joint_names, velocity_indices
from pinmob.model.length_scale import characteristic_length, check_length_scale
from pinmob.model.limb import Limb
from pinmob.model.named import Expectation, NamedConfiguration
from pinmob.model.names import check_names
from pinmob.model.tendon import Transmission
from pinmob.name_matching import choices, did_you_mean, match_name
from pinmob.screw import Array

T = TypeVar("T")


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
        geometry: the visual and collision geometry (:class:`~pinmob.model.geometry.Geometry`; meshes
            are loaded when first drawn), read as :attr:`visual_model` and :attr:`collision_model`.
        generic_rank: constraint rank at generic configurations, when declared
            (else :mod:`pinmob.analysis.singularity.result` estimates it from random closed
            configurations).
        closures: loop closures besides the limb tips meeting at the platform
            (see :attr:`all_closures`).
        extra_actuated: actuated joints not attached to a limb (mechanisms
            described by closures only).
        actuated_tendons: actuators held as their moment arms (MJCF; :class:`~pinmob.model.tendon.Transmission`).
        joint_actuators: the file's actuators on joints, ``(actuator, joint)`` (MJCF names them apart from joints).
        quaternion_wxyz: joint values give quaternions ``(w, x, y, z)``, MuJoCo's ``qpos`` order (MJCF
            files), instead of Pinocchio's ``(x, y, z, w)``.
        ignored: the file's loop and coupling elements pinmob does not read, one phrase each (a URDF
            ``<constraint>``, an SDF ``<mimic>`` or included model, an MJCF equality it cannot use): the
            loader warns once, and the mechanism DoF is printed as ignoring them.
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
    geometry: Geometry | None = field(default=None, repr=False, compare=False)
    generic_rank: int | None = None
    closures: tuple[Closure, ...] = ()
    extra_actuated: tuple[str, ...] = ()
    actuated_tendons: tuple[Transmission, ...] = ()
    joint_actuators: tuple[tuple[str, str], ...] = ()
    quaternion_wxyz: bool = False
    ignored: tuple[str, ...] = ()

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
        geometry: Geometry | None = None,
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
            ConfigurationError: two limbs share a joint, a limb has no joint, there is
                neither a limb nor a closure, or ``length_scale`` is outside
                :data:`~pinmob.model.length_scale.LENGTH_RANGE` times the geometry's own length (where round-off decides).
        """
        pairs = list(limbs.items()) if isinstance(limbs, Mapping) else list(limbs)
        if not pairs and not closures:
            raise ConfigurationError(f"mechanism {name!r} has neither a limb nor a closure; give at least one")
        actuated = dict(actuated or {})
        extra = tuple(actuated.pop("", ()))
        for a in extra:
            if not has_joint(model, a):
                raise FrameError(
                    f"actuated joint {a!r} does not exist in {name!r}{did_you_mean(a, joint_names(model))}; "
                    f"valid: {choices(joint_names(model))}"
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
            built.append(Limb(limb_name, tip, tip_id, joints, velocity_indices(model, joint_ids), acts))
        groups = group_closures(model, tuple(built), tuple(closures))
        built = [
            replace(
                b,
                closures=groups.internal.get(b.name, ()),
                loop_joints=tuple(model.names[j] for j in groups.loop_joints.get(b.name, ())),
                loop_v_indices=velocity_indices(model, groups.loop_joints.get(b.name, ())),
            )
            for b in built
        ]
        platform = platform or (pairs[0][1] if pairs else "")
        if platform:
            frame_id(model, platform)
        frames = [b.tip_id for b in built] + [i for c in closures for i in (c.frame_a_id, c.frame_b_id)]
        scale = check_length_scale(length_scale, characteristic_length(model, frames))
        if generic_rank is not None and (
            not isinstance(generic_rank, int) or isinstance(generic_rank, bool) or not 0 <= generic_rank <= 6
        ):
            raise ConfigurationError(f"generic_rank must be an integer from 0 to 6, got {generic_rank!r}")
        check_names(model, mechanism=[name], limb=dict(pairs), closure=names, configuration=configurations or {})
        return cls(
            name=name,
            model=model,
            limbs=tuple(built),
            platform=platform,
            length_scale=scale,
            configurations=dict(configurations or {}),
            expected=dict(expected or {}),
            description=description,
            source=source,
            geometry=geometry if geometry is not None else Geometry(visual=visual_model, collision=collision_model),
            generic_rank=generic_rank,
            closures=tuple(closures),
            extra_actuated=extra,
        )

    @classmethod
    def from_pinocchio(
        cls,
        model: pin.Model,
        constraint_models: Sequence[object],
        *,
        platform: str | None = None,
        limbs: Mapping[str, str] | None = None,
        actuated: Sequence[str] | Mapping[str, list[str]] = (),
        hinges: bool | None = None,
        **options: Any,
    ) -> Mechanism:
        """A mechanism from a Pinocchio model and its constraint models (either API; mimic joints allowed).

        Each constraint becomes a closure (:mod:`pinmob.model.constraint_models.constraint_reading`):
        ``CONTACT_3D`` and point anchors ``3d``, ``CONTACT_6D`` and frame anchors ``6d``; the two point anchors
        :meth:`to_pinocchio` writes for a revolute closure, ``X`` and ``X/axis``, one ``revolute`` again (any two
        point anchors on the same two joints with ``hinges=True``, none with ``hinges=False``). Each mimic
        joint becomes a joint of its own and a coupling ``mimic_<joint>``. With ``limbs`` (``{limb: tip
        frame}``) and ``platform``, a ``6d`` constraint welding a limb's tip to the platform is the limb's own
        closure and is not repeated. ``actuated`` names the actuated joints (or maps limb names to them, as
        :meth:`from_model`); ``options`` go to :meth:`from_model` (``name``, ``configurations``,
        ``length_scale``, ...).

        Raises:
            ConstraintModelError: a constraint pinmob cannot read (the message names it).
            FrameError, ConfigurationError: as :meth:`from_model`.
        """
        tips = dict(limbs or {})
        model, closures, platform, by_limb = mechanism_parts(model, constraint_models, tips, platform, actuated, hinges)
        return cls.from_model(model, tips, platform=platform, actuated=by_limb, closures=closures, **options)

    def to_pinocchio(self, api: str = "new", *, mimic: bool = False) -> tuple[pin.Model, Any]:
        """The mechanism as a Pinocchio model and constraint models: every closure, the limbs' welds included.

        Args:
            api: ``"new"`` (``ConstraintModel`` holding point and frame anchors) or ``"legacy"``
                (``RigidConstraintModel``, ``CONTACT_3D`` / ``CONTACT_6D``).
            mimic: write linear joint couplings as mimic joints (Pinocchio's constrained algorithms refuse
                them, so they are left out by default).

        Returns:
            ``(model, constraint_models)``: a copy of the model and a ``StdVec_ConstraintModel`` or
            ``StdVec_RigidConstraintModel`` (:mod:`pinmob.model.constraint_models.constraint_writing`).

        Warns:
            PinocchioExportWarning: closures Pinocchio has no exact model for, each named with what was put
                instead (a universal's point anchor, a cylindrical closure left out, ...).
        """
        return write_constraint_models(self.model, self.all_closures, length=self.length_scale, api=api, mimic=mimic)

    # ------------------------------------------------------------------ queries

    @property
    def visual_model(self) -> pin.GeometryModel | None:
        """Pinocchio visual geometry (None without one); its meshes are loaded the first time it is asked for."""
        return self.geometry.models(self.model)[0] if self.geometry is not None else None

    @property
    def collision_model(self) -> pin.GeometryModel | None:
        """Pinocchio collision geometry (None without one), loaded the first time it is asked for."""
        return self.geometry.models(self.model)[1] if self.geometry is not None else None

    @property
    def has_platform(self) -> bool:
        """True when a platform frame is named."""
        return bool(self.platform)

    def memo(self, key: Hashable, compute: Callable[[], T], transient: bool = False) -> T:
        """The value cached under ``key``, computed once by ``compute()`` (per mechanism object).

        What depends only on the mechanism (index arrays, generic ranks, ...)
        is computed once this way; :func:`dataclasses.replace` makes a new
        mechanism with an empty cache. A ``transient`` value (objects of this process: configurations with
        their kinematics, solver set-ups) is not pickled with the mechanism: a copy computes its own.
        """
        cache = self._transient if transient else self._memo
        try:
            return cache[key]
        except KeyError:
            value = cache[key] = compute()
            return value

    @cached_property
    def _memo(self) -> dict[Hashable, Any]:
        return {}

    @cached_property
    def _transient(self) -> dict[Hashable, Any]:
        return {}

    def __getstate__(self) -> dict[str, Any]:
        """The mechanism's state for pickling, without its transient cache (:meth:`memo`)."""
        state = dict(self.__dict__)
        state.pop("_transient", None)
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        """An unpickled copy (a Dask worker's): its cached arrays made read-only again, as they were."""
        self.__dict__.update(state)
        read_only(state.get("_memo", {}))

    @cached_property
    def all_closures(self) -> tuple[Closure, ...]:
        """Every loop closure: each limb tip welded (6d) to the platform frame, then :attr:`closures`.

        A limb whose tip is fixed to the platform frame's body (same parent
        joint) closes nothing and is left out. Computed once per mechanism, as
        the other constants below.
        """
        if not self.platform:
            return self.closures
        pid = self.platform_id
        body = self.model.frames[pid].parentJoint
        implicit = tuple(
            Closure(f"limb {b.name}", self.platform, b.tip, ClosureType.WELD, None, None, pid, b.tip_id)
            for b in self.limbs
            if self.model.frames[b.tip_id].parentJoint != body
        )
        return implicit + self.closures

    @property
    def coupling_closures(self) -> dict[str, tuple[str, ...]]:
        """Closures whose loops involve the joints of two or more limbs: closure name -> those limbs.

        The limb-wise method cannot treat them (:func:`pinmob.analyze` then uses the whole closure Jacobian).
        """
        return dict(self._coupling)

    @cached_property
    def _coupling(self) -> dict[str, tuple[str, ...]]:
        return group_closures(self.model, self.limbs, self.closures).coupling

    @cached_property
    def platform_id(self) -> int:
        """Pinocchio frame index of the platform frame."""
        return frame_id(self.model, self.platform)

    @cached_property
    def actuated(self) -> tuple[str, ...]:
        """All actuated joint names, limb by limb, then those outside limbs."""
        return tuple(a for limb in self.limbs for a in limb.actuated) + self.extra_actuated

    def limb_actuators(self, limb: Limb) -> tuple[str, ...]:
        """The actuated joints that lock ``limb``: its own, then those outside limbs among its loop joints."""
        return limb.actuated + tuple(a for a in self.extra_actuated if a in limb.loop_joints)

    def configuration_name(self, name: str) -> str:
        """The named configuration ``name`` stands for, matched ignoring case where that is unambiguous.

        Raises:
            UnknownConfigurationError: no such configuration (the message suggests close names and lists them).
        """
        return match_name(name, self.configurations, "configuration", f" in {self.name!r}", error=unknown(name))

    def limb(self, name: str) -> Limb:
        """The limb called ``name``."""
        if name not in (found := {limb.name: limb for limb in self.limbs}):
            raise ConfigurationError(f"no limb {name!r} in {self.name!r}; valid: {choices(found)}")
        return found[name]

    def with_ignored(self, ignored: Sequence[str]) -> Mechanism:
        """This mechanism naming the file's elements pinmob does not read (:attr:`ignored`)."""
        return replace(self, ignored=tuple(ignored)) if ignored else self

    def neutral(self) -> Array:
        """Pinocchio's neutral configuration, shape (nq,)."""
        return pin.neutral(self.model)

    def q_from_joints(self, values: Mapping[str, float], base: Array | None = None) -> Array:
        """Configuration vector from joint values by name; others from ``base`` (default neutral).

        One-degree joints take a value [m or rad]; continuous joints take an angle (:func:`q_from_values`).
        """
        return q_from_values(self.model, values, self.neutral() if base is None else base, self.name)

    def check_q(self, q: object) -> Array:
        """Validate a configuration vector: shape (nq,), finite, normalised where needed (a float copy)."""
        return check_q(self.model, q, self.name)
