"""Serial chains of the builder: joints placed in world coordinates, frames, branches, limb tips.

A chain starts at a parent link (the base, or a link of another chain) and
adds joints one after the other, each moving the link it creates. Every joint
is given at the *reference configuration* (all joint values zero) by its world
position [m] and world axis; links are world-aligned with their origin at
their joint. A frame is fixed to the chain's current (last) link; a branch is
a new chain starting at that link. A :class:`LimbBuilder` is a chain from the
base that ends at a tip frame meeting the platform. A :class:`ClosureSpec` joins
two frames when the loops are closed.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from pinmob.exceptions import ConfigurationError

from .layout import check_rotation, cross, point, rpy, unit
from .text import check_name, number, toml_value, vector

JOINT_TYPES = ("revolute", "prismatic", "continuous")
#: smallest sine between the two axes of a U joint, and smallest |det| of the three unit axes of an S joint
AXIS_INDEPENDENCE = 1e-6


@dataclass(frozen=True)
class JointSpec:
    """One joint at the reference configuration (world coordinates).

    Attributes:
        name: full joint name; its moving link is ``{name}_link``.
        type: one of :data:`JOINT_TYPES`.
        position: world position of the joint [m]; origin of its link.
        axis: unit world axis.
        lower, upper: joint limits [rad or m] (unused for ``continuous``).
        parent: link the joint is attached to; ``parent_origin`` its world origin [m].
    """

    name: str
    type: str
    position: tuple[float, float, float]
    axis: tuple[float, float, float]
    lower: float
    upper: float
    parent: str = "base"
    parent_origin: tuple[float, float, float] = (0.0, 0.0, 0.0)

    @property
    def link(self) -> str:
        """Name of the link this chain element adds."""
        return f"{self.name}_link"


@dataclass(frozen=True)
class FrameSpec:
    """A frame fixed to ``parent`` (world origin ``parent_origin``) at a world pose at the reference configuration."""

    name: str
    parent: str
    parent_origin: tuple[float, float, float]
    position: tuple[float, float, float]
    rotation: tuple[tuple[float, ...], ...] = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


def joint_lines(j: JointSpec) -> list[str]:
    """URDF ``<link>`` and ``<joint>`` elements of a joint."""
    out = [
        f'  <link name="{j.link}"/>',
        f'  <joint name="{j.name}" type="{j.type}">',
        f'    <parent link="{j.parent}"/>\n    <child link="{j.link}"/>',
        f'    <origin xyz="{vector(np.subtract(j.position, j.parent_origin))}" rpy="0 0 0"/>',
        f'    <axis xyz="{vector(j.axis)}"/>',
    ]
    if j.type != "continuous":
        out.append(f'    <limit lower="{number(j.lower)}" upper="{number(j.upper)}" effort="100" velocity="10"/>')
    return out + ["  </joint>"]


def frame_lines(f: FrameSpec) -> list[str]:
    """URDF elements of a frame: a link fixed to its parent."""
    xyz = vector(np.subtract(f.position, f.parent_origin))
    return [
        f'  <link name="{f.name}"/>',
        f'  <joint name="{f.name}_fixed" type="fixed">',
        f'    <parent link="{f.parent}"/>\n    <child link="{f.name}"/>',
        f'    <origin xyz="{xyz}" rpy="{vector(rpy(np.array(f.rotation)))}"/>\n  </joint>',
    ]


@dataclass
class ChainBuilder:
    """Joints of one serial chain from ``parent``, base to end; see the module docstring.

    Joints are named ``{chain name}_{label}``, frames ``{chain name}_{label}``,
    branches ``{chain name}_{label}``. Actuated joints of a chain that is not a
    limb are written to the mechanism file's top-level ``actuated`` list.
    """

    name: str
    parent: str = "base"
    parent_origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    joints: list[JointSpec] = field(default_factory=list)
    frames: list[FrameSpec] = field(default_factory=list)
    branches: list[ChainBuilder] = field(default_factory=list)
    actuated: list[str] = field(default_factory=list)

    @property
    def link(self) -> str:
        """The chain's current last link (its parent while it has no joint)."""
        return self.joints[-1].link if self.joints else self.parent

    @property
    def origin(self) -> tuple[float, float, float]:
        """World origin [m] of :attr:`link` at the reference configuration."""
        return self.joints[-1].position if self.joints else self.parent_origin

    def _check_open(self, label: str) -> None:
        """Hook: a limb refuses joints after its tip."""

    def _add(
        self, label: str, jtype: str, at: ArrayLike, axis: ArrayLike, lower: float, upper: float, actuated: bool
    ) -> str:
        where = f"chain {self.name!r} joint {label!r}"
        check_name("joint label", label)
        self._check_open(label)
        if jtype not in JOINT_TYPES:
            raise ConfigurationError(f"{where}: joint type {jtype!r}; valid: {', '.join(JOINT_TYPES)}")
        a = unit(f"{where}: axis", axis)
        p = point(f"{where}: position", at)
        lo, hi = float(lower), float(upper)
        if not (np.isfinite(lo) and np.isfinite(hi)) or lo > hi:
            raise ConfigurationError(f"{where}: limits must be finite with lower <= upper, got [{lower}, {upper}]")
        name = f"{self.name}_{label}"
        if any(j.name == name for j in self.joints):
            raise ConfigurationError(f"chain {self.name!r} already has a joint {label!r}")
        spec = JointSpec(name, jtype, p, (float(a[0]), float(a[1]), float(a[2])), lo, hi, self.link, self.origin)
        self.joints.append(spec)
        if actuated:
            self.actuated.append(name)
        return name

    def revolute(
        self,
        label: str,
        at: ArrayLike,
        axis: ArrayLike,
        lower: float = -np.pi,
        upper: float = np.pi,
        actuated: bool = False,
    ) -> str:
        """Add a revolute joint about ``axis`` through ``at`` [m], limits in rad; returns its full name."""
        return self._add(label, "revolute", at, axis, lower, upper, actuated)

    def continuous(self, label: str, at: ArrayLike, axis: ArrayLike, actuated: bool = False) -> str:
        """Add an unbounded revolute (URDF ``continuous``) about ``axis`` through ``at``; returns its full name."""
        return self._add(label, "continuous", at, axis, -np.pi, np.pi, actuated)

    def prismatic(
        self,
        label: str,
        at: ArrayLike,
        axis: ArrayLike,
        lower: float = -1.0,
        upper: float = 1.0,
        actuated: bool = False,
    ) -> str:
        """Add a prismatic joint along ``axis`` [m]; returns its full name."""
        return self._add(label, "prismatic", at, axis, lower, upper, actuated)

    def universal(self, label: str, at: ArrayLike, axis1: ArrayLike, axis2: ArrayLike) -> tuple[str, str]:
        """Two revolutes at one point: ``{label}a`` about axis1, then ``{label}b`` about axis2 (not parallel)."""
        u1, u2 = unit(f"U joint {label!r}: axis1", axis1), unit(f"U joint {label!r}: axis2", axis2)
        n = cross(u1, u2)
        sine = math.sqrt(n.dot(n))
        if sine < AXIS_INDEPENDENCE:
            raise ConfigurationError(
                f"chain {self.name!r} U joint {label!r}: axes {u1.round(6).tolist()} and {u2.round(6).tolist()} are "
                f"parallel (sine {sine:.1e} < {AXIS_INDEPENDENCE:g}); a U joint needs two independent axes"
            )
        return self.revolute(label + "a", at, u1), self.revolute(label + "b", at, u2)

    def spherical(
        self, label: str, at: ArrayLike, axes: Sequence[ArrayLike] = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    ) -> tuple[str, ...]:
        """Three revolutes at one point: ``{label}a``, ``{label}b``, ``{label}c`` about independent axes."""
        if len(axes) != 3:
            raise ConfigurationError(f"chain {self.name!r} S joint {label!r}: needs three axes, got {len(axes)}")
        units = [unit(f"S joint {label!r}: axis {k}", a) for k, a in enumerate(axes)]
        det = float(abs(np.linalg.det(np.array(units))))
        if det < AXIS_INDEPENDENCE:
            raise ConfigurationError(
                f"chain {self.name!r} S joint {label!r}: the three axes are dependent (|det| {det:.1e} < "
                f"{AXIS_INDEPENDENCE:g}); an S joint needs three independent axes"
            )
        return tuple(self.revolute(label + s, at, ax) for s, ax in zip("abc", units))

    def frame(self, label: str, at: ArrayLike, rotation: ArrayLike | None = None) -> str:
        """Fix a frame ``{chain}_{label}`` to the current link at world pose (at, rotation); returns its name.

        Frames name the two sides of a closure (:meth:`MechanismBuilder.closure`).
        """
        name = f"{self.name}_{check_name('frame label', label)}"
        where = f"chain {self.name!r} frame {label!r}"
        rot = np.eye(3) if rotation is None else check_rotation(where, rotation)
        self.frames.append(
            FrameSpec(name, self.link, self.origin, point(f"{where}: position", at), tuple(map(tuple, rot)))
        )
        return name

    def branch(self, label: str) -> ChainBuilder:
        """Start a side chain ``{chain}_{label}`` at the current link (e.g. the second rod of a parallelogram)."""
        chain = ChainBuilder(f"{self.name}_{check_name('branch label', label)}", self.link, self.origin)
        self.branches.append(chain)
        return chain

    def walk(self) -> Iterator[ChainBuilder]:
        """This chain and all its branches, depth first."""
        yield self
        for b in self.branches:
            yield from b.walk()

    def urdf_lines(self) -> list[str]:
        """The limb's URDF elements (links, joints and frames), one per line."""
        """URDF elements of this chain and its branches."""
        out: list[str] = []
        for chain in self.walk():
            for j in chain.joints:
                out += joint_lines(j)
            for f in chain.frames:
                out += frame_lines(f)
        return out


@dataclass
class LimbBuilder(ChainBuilder):
    """A chain from the base ending at a tip frame ``{name}_tip``; see :class:`MechanismBuilder`.

    Its own joints form the limb; joints of its branches are internal to the limb
    (closed by closures inside it).
    """

    tip_position: tuple[float, float, float] | None = None
    tip_rotation: np.ndarray | None = None

    def _check_open(self, label: str) -> None:
        if self.tip_position is not None:
            raise ConfigurationError(
                f"limb {self.name!r} ends at its tip: joint {label!r} cannot follow it (start a branch instead)"
            )

    def tip(self, at: ArrayLike, rotation: ArrayLike | None = None) -> None:
        """End the limb at a tip frame with world pose (at, rotation) at the reference configuration."""
        if not self.joints:
            raise ConfigurationError(f"limb {self.name!r} has no joint: add joints before its tip")
        where = f"limb {self.name!r} tip"
        self.tip_position = point(f"{where} position", at)
        self.tip_rotation = np.eye(3) if rotation is None else check_rotation(where, rotation)

    @property
    def tip_name(self) -> str:
        """Name of the limb's tip frame."""
        return f"{self.name}_tip"

    def urdf_lines(self) -> list[str]:
        """The limb's URDF elements, its tip frame last, one per line."""
        if self.tip_position is None or self.tip_rotation is None:
            raise ConfigurationError(f"limb {self.name!r} has no tip: call .tip(...)")
        tip = FrameSpec(self.tip_name, self.link, self.origin, self.tip_position, tuple(map(tuple, self.tip_rotation)))
        return super().urdf_lines() + frame_lines(tip)


@dataclass(frozen=True)
class ClosureSpec:
    """A closure written to ``[[closures]]``: see :class:`pinmob.model.closure.Closure` for the types."""

    name: str
    frame_a: str
    frame_b: str
    type: str = "6d"
    axis: tuple[float, float, float] | None = None
    axis_b: tuple[float, float, float] | None = None

    def toml_lines(self) -> list[str]:
        """The closure's ``[[closures]]`` table, one line per key."""
        out = ["", "[[closures]]", f"name = {toml_value(self.name)}"]
        out += [f"frames = {toml_value([self.frame_a, self.frame_b])}", f"type = {toml_value(self.type)}"]
        for key, value in (("axis", self.axis), ("axis_b", self.axis_b)):
            if value is not None:
                out.append(f"{key} = {toml_value(list(value))}")
        return out
