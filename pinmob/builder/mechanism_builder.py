"""The MechanismBuilder: limbs, free chains and closures, written as URDF + pinmob TOML."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pinmob.exceptions import ConfigurationError
from pinmob.io import toml_key, unicode_text
from pinmob.model import NO_LENGTH, SHORTEST
from pinmob.name_matching import choices

from .chain_builder import ChainBuilder, ClosureSpec, LimbBuilder
from .closed_joints import canonical_joints, closed_joints, write_files
from .layout import check_rotation, point
from .text import MARKER, check_name, toml_value, xml_attribute
from .urdf_limb import UrdfLimb

if TYPE_CHECKING:
    import pinocchio as pin

    from pinmob.model import Mechanism

#: limb tips placed by the builder must coincide at the reference within this fraction of the model's size
COINCIDENCE_RTOL = 1e-9


class MechanismBuilder:
    """Build a mechanism from limbs meeting at a platform, free chains and closures; write URDF and TOML.

    - :meth:`limb`: a chain from the base to a tip frame; all limb tips meet the
      platform frame (fixed to the first limb's tip). Limb tips placed by the
      builder must coincide at the reference configuration.
    - :meth:`urdf_limb`: a limb copied from a robot URDF.
    - :meth:`chain`: a free chain from the base or any link (not a limb), e.g. the
      rocker of a four-bar; ``ChainBuilder.branch`` starts one from a chain's link.
    - :meth:`closure`: two frames joined when the loops are closed (``[[closures]]``).

    With no limb the mechanism is described by its closures; it then has a
    platform only when a frame called ``platform`` (the constructor argument) exists.
    """

    def __init__(self, name: str, description: str = "", platform: str = "platform"):
        if not isinstance(name, str) or not name.strip():
            raise ConfigurationError(f"mechanism name must be a non-empty string, got {name!r}")
        self.name = unicode_text("mechanism name", name)  # the URDF's and the TOML file's: UTF-8 text
        self.description = unicode_text("description", description) if isinstance(description, str) else description
        self.platform = check_name("platform frame", platform)
        self.limbs: list[LimbBuilder | UrdfLimb] = []
        self.chains: list[ChainBuilder] = []
        self.closures: list[ClosureSpec] = []

    # ------------------------------------------------------------------ parts

    def _new_name(self, kind: str, name: str) -> str:
        check_name(f"{kind} name", name)
        if any(b.name == name for b in [*self.limbs, *self.chains]):
            raise ConfigurationError(f"a limb or chain {name!r} exists already")
        return name

    def limb(self, name: str) -> LimbBuilder:
        """Start a new limb; its joints are named ``{name}_{label}``."""
        limb = LimbBuilder(self._new_name("limb", name))
        self.limbs.append(limb)
        return limb

    def chain(self, name: str, parent: str = "base") -> ChainBuilder:
        """Start a free chain (not a limb) at link ``parent``: ``base`` or the ``.link`` of another chain."""
        origins = {"base": (0.0, 0.0, 0.0)} | {j.link: j.position for c in self._builder_chains() for j in c.joints}
        if parent not in origins:
            raise ConfigurationError(f"chain {name!r}: no link {parent!r}; valid: {choices(origins)}")
        chain = ChainBuilder(self._new_name("chain", name), parent, origins[parent])
        self.chains.append(chain)
        return chain

    def urdf_limb(
        self,
        name: str,
        urdf: str | Path,
        root_link: str,
        tip_link: str,
        base_pose: tuple[ArrayLike, ArrayLike],
        tip_offset: tuple[ArrayLike, ArrayLike] = (np.eye(3), (0.0, 0.0, 0.0)),
        actuated: Sequence[str] | None = None,
    ) -> UrdfLimb:
        """Add a limb copied from a robot URDF (e.g. an arm of example-robot-data).

        Args:
            name: limb name; the arm's links and joints become ``{name}_{original}``.
            urdf: path of the robot's URDF.
            root_link: first link of the chain kept (e.g. ``base_link``).
            tip_link: last link of the chain kept (e.g. ``tool0``).
            base_pose: (rotation (3, 3), position (3,) [m]) of ``root_link`` in the world.
            tip_offset: pose of the limb tip frame in ``tip_link`` (rotation, position [m]).
            actuated: original names of the actuated joints (default: every movable joint).
        """
        self._new_name("limb", name)
        pose = (check_rotation(f"limb {name!r} base_pose", base_pose[0]), np.array(point("base_pose", base_pose[1])))
        offset = (
            check_rotation(f"limb {name!r} tip_offset", tip_offset[0]),
            np.array(point("tip_offset", tip_offset[1])),
        )
        limb = UrdfLimb.read(name, urdf, root_link, tip_link, pose, offset)
        if actuated is not None:
            limb.actuated = [f"{name}_{a}" for a in actuated]
            unknown = set(limb.actuated) - set(limb.joints)
            if unknown:
                raise ConfigurationError(
                    f"limb {name!r}: actuated joint(s) {sorted(unknown)} not in the chain; valid: {limb.joints}"
                )
        self.limbs.append(limb)
        return limb

    def closure(
        self,
        name: str,
        frame_a: str,
        frame_b: str,
        type: str = "6d",
        axis: ArrayLike | None = None,
        axis_b: ArrayLike | None = None,
    ) -> ClosureSpec:
        """Join ``frame_a`` and ``frame_b`` when the loops are closed (written to ``[[closures]]``).

        Args:
            name: the closure's name.
            frame_a: the first frame (its axes carry ``axis``).
            frame_b: the second frame.
            type: ``6d`` (weld), ``3d`` (ball: same origin), ``revolute``, ``universal``,
                ``cylindrical`` or ``planar`` (see :class:`pinmob.model.closure.Closure`).
            axis: the closure's axis in frame a (revolute, universal, cylindrical; planar: normal).
            axis_b: second hinge axis of a universal closure, in frame b.

        Frames are checked when the mechanism is built (:meth:`mechanism`, :meth:`write`).
        """
        from pinmob.model import CLOSURE_TYPES

        check_name("closure name", name)
        if any(c.name == name for c in self.closures):
            raise ConfigurationError(f"closure {name!r} exists already")
        if type not in CLOSURE_TYPES:
            raise ConfigurationError(f"closure {name!r}: unknown type {type!r}; valid: {choices(CLOSURE_TYPES)}")
        axes = [
            None if a is None else point(f"closure {name!r} {k}", a) for k, a in (("axis", axis), ("axis_b", axis_b))
        ]
        spec = ClosureSpec(name, check_name("frame", frame_a), check_name("frame", frame_b), type, axes[0], axes[1])
        self.closures.append(spec)
        return spec

    # ------------------------------------------------------------------ checks

    def _builder_chains(self) -> list[ChainBuilder]:
        """Every chain placed by the builder (limbs, free chains, their branches)."""
        roots = [b for b in self.limbs if isinstance(b, ChainBuilder)] + self.chains
        return [c for r in roots for c in r.walk()]

    def _names(self) -> list[str]:
        """Every link, joint and frame name the URDF will hold."""
        names = ["base"] + ([self.platform, f"{self.platform}_fixed"] if self.limbs else [])
        for c in self._builder_chains():
            names += [n for j in c.joints for n in (j.name, j.link)]
            names += [n for f in c.frames for n in (f.name, f"{f.name}_fixed")]
        for limb in self.limbs:
            names += limb.names() if isinstance(limb, UrdfLimb) else [limb.tip_name, f"{limb.tip_name}_fixed"]
        return names

    def check(self) -> None:
        """Refuse an empty mechanism, a name used twice, or limb tips that do not coincide.

        Raises:
            ConfigurationError: for each of those; builder-placed limb tips must coincide at the reference
                configuration within ``COINCIDENCE_RTOL`` of its size.
        """
        chains = self._builder_chains()
        if not self.limbs and not any(c.joints for c in chains):
            raise ConfigurationError(f"mechanism {self.name!r} is empty: add a limb (.limb) or a chain (.chain)")
        names = self._names()
        twice = {n for n in names if names.count(n) > 1}
        if twice:
            raise ConfigurationError(f"mechanism {self.name!r}: name(s) used twice: {choices(twice)}")
        placed = [b for b in self.limbs if isinstance(b, LimbBuilder)]
        if len(placed) < 2:
            return
        tips = [b.tip_position for b in placed if b.tip_position is not None]
        coordinates = [float(np.linalg.norm(p)) for p in [j.position for c in chains for j in c.joints] + tips]
        size = max(coordinates)  # the tips' gap is round-off of these; none above round-off at the origin: 1 m
        size = size if size > SHORTEST else NO_LENGTH
        first = placed[0]
        for limb in placed[1:]:
            if limb.tip_position is None or limb.tip_rotation is None or first.tip_position is None:
                raise ConfigurationError(f"limb {(limb if limb.tip_position is None else first).name!r} has no tip")
            gap = float(np.linalg.norm(np.subtract(limb.tip_position, first.tip_position)))
            turn = float(np.abs(limb.tip_rotation - first.tip_rotation).max())
            if gap > COINCIDENCE_RTOL * size or turn > COINCIDENCE_RTOL:
                raise ConfigurationError(
                    f"limb tips must coincide at the reference configuration: limb {limb.name!r} tip is "
                    f"{gap:.3g} m and {turn:.3g} (rotation matrix entries) away from limb {first.name!r} tip"
                )

    # ------------------------------------------------------------------ URDF and TOML

    def urdf(self) -> str:
        """URDF text: limbs and chains from link ``base``; the platform frame on the first limb's tip."""
        self.check()
        lines = ['<?xml version="1.0"?>', f"<!-- {MARKER}; edit the builder, not this file -->"]
        lines += [f"<robot name={xml_attribute(self.name.replace(' ', '_'))}>", '  <link name="base"/>']
        for limb in self.limbs:
            lines += limb.urdf_lines()
        for chain in self.chains:
            lines += chain.urdf_lines()
        if self.limbs:
            lines.append(f'  <link name="{self.platform}"/>')
            lines.append(f'  <joint name="{self.platform}_fixed" type="fixed">')
            lines.append(f'    <parent link="{self.limbs[0].tip_name}"/>\n    <child link="{self.platform}"/>')
            lines.append('    <origin xyz="0 0 0" rpy="0 0 0"/>\n  </joint>')
        return "\n".join(lines + ["</robot>"]) + "\n"

    def _platform(self) -> str | None:
        """The platform frame: on the first limb's tip, or a chain frame of that name, or none."""
        frames = {f.name for c in self._builder_chains() for f in c.frames}
        return self.platform if self.limbs or self.platform in frames else None

    def _extra_actuated(self) -> list[str]:
        """Actuated joints outside limbs (free chains and limb branches): the file's top-level ``actuated``."""
        limb_chains = [b for b in self.limbs if isinstance(b, LimbBuilder)]
        inner = [c for limb in limb_chains for c in limb.walk() if c is not limb]
        return [a for c in inner + [c for r in self.chains for c in r.walk()] for a in c.actuated]

    def toml(
        self,
        urdf: str,
        configurations: Mapping[str, Mapping[str, Any]] | None = None,
        length_scale: float | None = None,
        urdf_text: str | None = None,
        model: pin.Model | None = None,
    ) -> str:
        """Pinmob mechanism file text referring to ``urdf`` (a path relative to the file).

        Revolute angles of the configurations' ``joints`` and ``seed`` tables are written in (-pi, pi]
        (:func:`pinmob.builder.closed_joints.canonical_joints`), so the same configuration gives the same
        text whichever multiple of 2 pi it was computed with. The angles are read from the model of :meth:`urdf`'s
        text: ``model`` when the caller has it already (:meth:`model`; only read here), else that of ``urdf_text``
        when given, else of the text built again.
        """
        out = [f"# {MARKER}; edit the builder, not this file", f"name = {toml_value(self.name)}"]
        if self.description:
            out.append(f"description = {toml_value(self.description)}")
        out.append(f"urdf = {toml_value(urdf)}")
        platform = self._platform()
        if platform:
            out.append(f"platform = {toml_value(platform)}")
        if length_scale:
            out.append(f"length_scale = {toml_value(float(length_scale))}")
        extra = self._extra_actuated()
        if extra:
            out.append(f"actuated = {toml_value(extra)}")
        for limb in self.limbs:
            out += ["", "[[limbs]]", f"name = {toml_value(limb.name)}", f"tip = {toml_value(limb.tip_name)}"]
            if limb.actuated:
                out.append(f"actuated = {toml_value(limb.actuated)}")
        for c in self.closures:
            out += c.toml_lines()
        for cname, conf in (configurations or {}).items():
            out += ["", f"[configurations.{toml_key(unicode_text('configuration name', cname))}]"]
            for k, v in conf.items():
                if k in ("joints", "seed") and isinstance(v, Mapping):
                    for joint in v:  # before Pinocchio looks them up (it takes UTF-8 text only)
                        if isinstance(joint, str):
                            unicode_text(f"configuration {cname!r}: joint name", joint)
                    model = model if model is not None else self.model(urdf_text)
                    v = canonical_joints(model, v)
                out.append(f"{toml_key(k)} = {toml_value(v)}")
        return "\n".join(out) + "\n"

    # ------------------------------------------------------------------ mechanism

    def model(self, text: str | None = None) -> pin.Model:
        """The Pinocchio model of :meth:`urdf` (kinematics only), or of its ``text`` when given; parsed on each call."""
        import pinocchio as pin

        return pin.buildModelFromXML(self.urdf() if text is None else text)

    def mechanism(self) -> Mechanism:
        """The mechanism as it would load from the written files (kinematics only, no files).

        Lets a user sketch a mechanism and analyse it at once::

            mech = b.mechanism()
            pinmob.analyze(mech, mech.neutral())  # the reference configuration
        """
        from pinmob.model import Mechanism, make_closure

        model = self.model()
        closures = [make_closure(model, c.name, c.frame_a, c.frame_b, c.type, c.axis, c.axis_b) for c in self.closures]
        actuated = {limb.name: list(limb.actuated) for limb in self.limbs} | {"": self._extra_actuated()}
        tips = [(limb.name, limb.tip_name) for limb in self.limbs]
        return Mechanism.from_model(
            model,
            tips,
            name=self.name,
            platform=self._platform(),
            actuated=actuated,
            description=self.description,
            closures=closures,
        )

    def closed_joints(
        self,
        fixed: Mapping[str, float] | None = None,
        pose: tuple[ArrayLike, ArrayLike] | None = None,
        seed: Mapping[str, float] | None = None,
    ) -> dict[str, float]:
        """Joint values [rad or m] of a closed configuration, for a ``joints`` table of :meth:`write`.

        See :func:`pinmob.builder.closed_joints.closed_joints` (``fixed`` joints held, or the
        platform put at ``pose = (xyz [m], rotation (3, 3))``; ``seed`` selects the assembly mode).
        """
        return closed_joints(self.mechanism(), fixed, pose, seed)

    def write(
        self,
        directory: str | Path,
        stem: str,
        configurations: Mapping[str, Mapping[str, Any]] | None = None,
        length_scale: float | None = None,
        check: bool = True,
    ) -> Path:
        """Write ``{stem}.urdf`` and ``{stem}.toml`` into ``directory``; returns the TOML path.

        With ``check`` every named configuration must close first (:func:`pinmob.builder.closed_joints.write_files`);
        files of that name are replaced only if the builder wrote them.

        Raises:
            ConfigurationError: a bad stem, a configuration that does not close,
                or a file in the way that the builder did not write.
        """
        check_name("file stem", stem)
        texts = {f"{stem}.urdf": self.urdf(), f"{stem}.toml": self.toml(f"{stem}.urdf", configurations, length_scale)}
        return write_files(self.name, Path(directory), texts, f"{stem}.toml", check)
