"""Sketch parallel mechanisms in code and write them as URDF + pinmob TOML.

Every joint is placed at a *reference configuration* (all joint values zero)
by its world position [m] and world axis; universal (U) and spherical (S)
joints are consecutive revolutes at one point. Each limb ends at a tip frame
given by its world pose; at the reference configuration, tips that should
coincide must coincide.

Example::

    b = MechanismBuilder("2-RR", "planar two-limb sketch")
    a = b.limb("A")
    a.revolute("r1", at=[0.3, 0, 0], axis=[0, 0, 1])
    a.tip(at=[0, 0.2, 0])
    ...
    b.write("models", configurations={...})

Layout helpers: :func:`radial` (radial and tangential unit vectors at an
angle), :func:`polar` (a point on a circle), :func:`symmetric_angles` (n
angles evenly spread) and :func:`rotation` (axis-angle). Limbs taken from an
existing robot URDF (with its meshes) are added by
:meth:`MechanismBuilder.urdf_limb`.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any
from xml.etree import ElementTree

import numpy as np
from numpy.typing import ArrayLike

from .exceptions import ConfigurationError

if TYPE_CHECKING:
    from .mechanism import Mechanism

JOINT_TYPES = ("revolute", "prismatic", "continuous")


# --------------------------------------------------------------------------- layout helpers


def radial(theta: float) -> tuple[np.ndarray, np.ndarray]:
    """Radial unit vector ``e = (cos theta, sin theta, 0)`` and tangent ``t = z x e``.

    Args:
        theta: angle about the world z axis [rad].
    """
    e = np.array([np.cos(theta), np.sin(theta), 0.0])
    return e, np.array([-e[1], e[0], 0.0])


def polar(radius: float, theta: float, z: float = 0.0) -> np.ndarray:
    """Point ``radius * e(theta) + z * z_hat`` [m], shape (3,)."""
    return radius * radial(theta)[0] + np.array([0.0, 0.0, z])


def symmetric_angles(n: int, offset: float = 0.0) -> list[float]:
    """``n`` angles ``offset + 2 pi k / n`` [rad], k = 0..n-1 (limbs spread evenly about z)."""
    return [offset + 2.0 * np.pi * k / n for k in range(n)]


def rotation(axis: Sequence[float], angle: float) -> np.ndarray:
    """Rotation matrix (3, 3) of ``angle`` [rad] about ``axis`` (Rodrigues' formula).

    ``R = I + sin(a) [u]x + (1 - cos(a)) [u]x^2`` with ``u = axis / |axis|``.
    """
    u = np.asarray(axis, float)
    u = u / np.linalg.norm(u)
    k = np.array([[0.0, -u[2], u[1]], [u[2], 0.0, -u[0]], [-u[1], u[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * k @ k


def _triple(v: ArrayLike) -> tuple[float, float, float]:
    """A 3-vector as a tuple of Python floats."""
    x, y, z = np.asarray(v, float)
    return float(x), float(y), float(z)


def _link_of(joint: ElementTree.Element, tag: str) -> str:
    """The ``link`` attribute of a URDF joint's ``<parent>`` or ``<child>`` ("" when missing)."""
    el = joint.find(tag)
    return "" if el is None else el.get("link", "")


@dataclass(frozen=True)
class JointSpec:
    """One joint at the reference configuration (world coordinates)."""

    name: str
    type: str
    position: tuple[float, float, float]
    axis: tuple[float, float, float]
    lower: float
    upper: float


@dataclass
class LimbBuilder:
    """Joints of one limb, base to tip; see :class:`MechanismBuilder`."""

    name: str
    joints: list[JointSpec] = field(default_factory=list)
    tip_position: tuple[float, float, float] | None = None
    tip_rotation: np.ndarray | None = None
    actuated: list[str] = field(default_factory=list)

    def _add(
        self,
        label: str,
        jtype: str,
        at: ArrayLike,
        axis: ArrayLike,
        lower: float,
        upper: float,
        actuated: bool,
    ) -> str:
        if jtype not in JOINT_TYPES:
            raise ConfigurationError(f"joint type {jtype!r}; valid: {', '.join(JOINT_TYPES)}")
        a = np.asarray(axis, float)
        if a.shape != (3,) or not np.isfinite(a).all() or np.linalg.norm(a) < 1e-12:
            raise ConfigurationError(
                f"limb {self.name!r} joint {label!r}: axis must be a non-zero 3-vector, got {axis!r}"
            )
        p = np.asarray(at, float)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise ConfigurationError(f"limb {self.name!r} joint {label!r}: position must be a 3-vector, got {at!r}")
        name = f"{self.name}_{label}"
        if any(j.name == name for j in self.joints):
            raise ConfigurationError(f"limb {self.name!r} already has a joint {label!r}")
        a = a / np.linalg.norm(a)
        self.joints.append(JointSpec(name, jtype, _triple(p), _triple(a), lower, upper))
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
        """Add a revolute joint about ``axis`` through ``at``; returns its full name."""
        return self._add(label, "revolute", at, axis, lower, upper, actuated)

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
        """Two revolutes at one point: ``{label}a`` about axis1, then ``{label}b`` about axis2."""
        return self.revolute(label + "a", at, axis1), self.revolute(label + "b", at, axis2)

    def spherical(
        self, label: str, at: ArrayLike, axes: Sequence[ArrayLike] = ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    ) -> tuple[str, ...]:
        """Three revolutes at one point: ``{label}a``, ``{label}b``, ``{label}c``."""
        return tuple(self.revolute(label + s, at, ax) for s, ax in zip("abc", axes))

    def tip(self, at: ArrayLike, rotation: Sequence[ArrayLike] | None = None) -> None:
        """End the limb at a tip frame with world pose (at, rotation) at the reference configuration."""
        self.tip_position = _triple(at)
        self.tip_rotation = np.eye(3) if rotation is None else np.asarray(rotation, float)


@dataclass
class UrdfLimb:
    """A limb copied from an existing robot URDF: its chain from ``root_link`` to ``tip_link``.

    Links and joints are renamed ``{limb}_{original name}``; each link keeps its
    visual, collision and inertial elements (meshes keep their ``package://``
    paths, so a viewer shows the robot when the package folder is known to
    :func:`pinmob.mechanism_file.package_dirs`). The root link is fixed to the
    builder's ``base`` at ``base_pose``; the tip frame ``{limb}_tip`` is fixed to
    the tip link at ``tip_offset`` (both ``(rotation (3, 3), position (3,) [m])``).
    Create it with :meth:`MechanismBuilder.urdf_limb`.
    """

    name: str
    source: Path
    root_link: str
    tip_link: str
    base_pose: tuple[np.ndarray, np.ndarray]
    tip_offset: tuple[np.ndarray, np.ndarray]
    actuated: list[str] = field(default_factory=list)
    links: list[ElementTree.Element] = field(default_factory=list, repr=False)
    chain: list[ElementTree.Element] = field(default_factory=list, repr=False)

    @classmethod
    def read(
        cls,
        name: str,
        source: str | Path,
        root_link: str,
        tip_link: str,
        base_pose: tuple[np.ndarray, np.ndarray],
        tip_offset: tuple[np.ndarray, np.ndarray],
    ) -> UrdfLimb:
        """Parse ``source`` and keep the links and joints from ``root_link`` to ``tip_link``."""
        path = Path(source)
        try:
            robot = ElementTree.parse(path).getroot()
        except (OSError, ElementTree.ParseError) as exc:
            raise ConfigurationError(f"limb {name!r}: cannot read URDF {str(path)!r}: {exc}") from None
        links = {el.get("name", ""): el for el in robot.findall("link")}
        by_child = {_link_of(el, "child"): el for el in robot.findall("joint")}
        for link in (root_link, tip_link):
            if link not in links:
                raise ConfigurationError(
                    f"limb {name!r}: no link {link!r} in {path.name}; valid: {', '.join(sorted(links))}"
                )
        chain, link = [], tip_link
        while link != root_link:
            if link not in by_child:
                raise ConfigurationError(
                    f"limb {name!r}: link {tip_link!r} does not descend from {root_link!r} in {path.name}"
                )
            chain.append(by_child[link])
            link = _link_of(by_child[link], "parent")
        chain.reverse()
        kept = [root_link] + [_link_of(j, "child") for j in chain]
        limb = cls(name, path, root_link, tip_link, base_pose, tip_offset)
        limb.links = [_renamed(links[n], name) for n in kept]
        limb.chain = [_renamed(j, name) for j in chain]
        limb.actuated = limb.joints
        return limb

    @property
    def joints(self) -> list[str]:
        """Names of the limb's movable joints (renamed), base to tip."""
        return [j.get("name", "") for j in self.chain if j.get("type") != "fixed"]

    def urdf_lines(self) -> list[str]:
        """URDF elements of this limb, indented for inclusion in a ``<robot>``."""
        out = []
        rot, pos = self.base_pose
        root = f"{self.name}_{self.root_link}"
        out.append(f'  <joint name="{self.name}_mount" type="fixed">')
        out.append(f'    <parent link="base"/>\n    <child link="{root}"/>')
        out.append(f'    <origin xyz="{_v(pos)}" rpy="{_v(_rpy(np.asarray(rot)))}"/>\n  </joint>')
        for el in self.links + self.chain:
            el = _copy(el)
            ElementTree.indent(el, space="  ", level=1)
            out.append("  " + ElementTree.tostring(el, encoding="unicode").rstrip())
        rot, pos = self.tip_offset
        tip = f"{self.name}_tip"
        out.append(f'  <link name="{tip}"/>')
        out.append(f'  <joint name="{tip}_fixed" type="fixed">')
        out.append(f'    <parent link="{self.name}_{self.tip_link}"/>\n    <child link="{tip}"/>')
        out.append(f'    <origin xyz="{_v(pos)}" rpy="{_v(_rpy(np.asarray(rot)))}"/>\n  </joint>')
        return out


def _copy(el: ElementTree.Element) -> ElementTree.Element:
    return ElementTree.fromstring(ElementTree.tostring(el))


def _renamed(el: ElementTree.Element, prefix: str) -> ElementTree.Element:
    """Copy of a URDF link or joint with its name and link references prefixed."""
    out = _copy(el)
    out.tail = None
    out.set("name", f"{prefix}_{out.get('name')}")
    for tag in ("parent", "child"):
        ref = out.find(tag)
        if ref is not None:
            ref.set("link", f"{prefix}_{ref.get('link')}")
    return out


def _rpy(rot: np.ndarray) -> tuple[float, float, float]:
    """URDF roll-pitch-yaw of a rotation matrix (R = Rz(y) Ry(p) Rx(r))."""
    pitch = float(np.arcsin(-np.clip(rot[2, 0], -1, 1)))
    if abs(np.cos(pitch)) > 1e-9:
        roll = float(np.arctan2(rot[2, 1], rot[2, 2]))
        yaw = float(np.arctan2(rot[1, 0], rot[0, 0]))
    else:
        roll, yaw = float(np.arctan2(-rot[1, 2], rot[1, 1])), 0.0
    return roll, pitch, yaw


def _f(x: float) -> str:
    s = f"{x:.12g}"
    return "0" if s == "-0" else s


def _v(xs: ArrayLike) -> str:
    return " ".join(_f(float(x)) for x in np.asarray(xs, float).ravel())


def toml_value(value: Any) -> str:
    """A TOML literal for str, bool, int, float, sequences and mappings (inline)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return (
            _f(float(value)) if float(value) != int(float(value)) or abs(float(value)) > 1e15 else f"{float(value):.1f}"
        )
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, Mapping):
        return "{ " + ", ".join(f"{_key(k)} = {toml_value(v)}" for k, v in value.items()) + " }"
    if isinstance(value, (list, tuple, np.ndarray)):
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {type(value).__name__} as TOML")


def _key(k: str) -> str:
    return k if k.replace("_", "").replace("-", "").isalnum() else toml_value(k)


class MechanismBuilder:
    """Build a limbs-meeting-at-a-platform mechanism and write its URDF and TOML."""

    def __init__(self, name: str, description: str = "", platform: str = "platform"):
        self.name = name
        self.description = description
        self.platform = platform
        self.limbs: list[LimbBuilder | UrdfLimb] = []

    def limb(self, name: str) -> LimbBuilder:
        """Start a new limb; its joints are named ``{name}_{label}``."""
        if any(b.name == name for b in self.limbs):
            raise ConfigurationError(f"limb {name!r} exists already")
        limb = LimbBuilder(name)
        self.limbs.append(limb)
        return limb

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
            root_link, tip_link: the chain kept (e.g. ``base_link`` to ``tool0``).
            base_pose: (rotation (3, 3), position (3,) [m]) of ``root_link`` in the world.
            tip_offset: pose of the limb tip frame in ``tip_link`` (rotation, position [m]).
            actuated: original names of the actuated joints (default: every movable joint).
        """
        if any(b.name == name for b in self.limbs):
            raise ConfigurationError(f"limb {name!r} exists already")
        pose = (np.asarray(base_pose[0], float), np.asarray(base_pose[1], float))
        offset = (np.asarray(tip_offset[0], float), np.asarray(tip_offset[1], float))
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

    # ------------------------------------------------------------------ URDF

    def urdf(self) -> str:
        """URDF text: one branch per limb from link ``base``; the platform frame on the first tip."""
        robot = self.name.replace(" ", "_")
        lines = [
            '<?xml version="1.0"?>',
            "<!-- generated by pinmob.builder; edit the builder, not this file -->",
            f'<robot name="{robot}">',
            '  <link name="base"/>',
        ]
        for limb in self.limbs:
            if isinstance(limb, UrdfLimb):
                lines += limb.urdf_lines()
                continue
            if limb.tip_position is None or limb.tip_rotation is None:
                raise ConfigurationError(f"limb {limb.name!r} has no tip: call .tip(...)")
            if not limb.joints:
                raise ConfigurationError(f"limb {limb.name!r} has no joint")
            parent, prev = "base", np.zeros(3)
            for j in limb.joints:
                child = f"{j.name}_link"
                lines.append(f'  <link name="{child}"/>')
                lines.append(f'  <joint name="{j.name}" type="{j.type}">')
                lines.append(f'    <parent link="{parent}"/>\n    <child link="{child}"/>')
                lines.append(f'    <origin xyz="{_v(np.asarray(j.position) - prev)}" rpy="0 0 0"/>')
                lines.append(f'    <axis xyz="{_v(j.axis)}"/>')
                if j.type != "continuous":
                    lines.append(f'    <limit lower="{_f(j.lower)}" upper="{_f(j.upper)}" effort="100" velocity="10"/>')
                lines.append("  </joint>")
                parent, prev = child, np.asarray(j.position)
            tip = f"{limb.name}_tip"
            lines.append(f'  <link name="{tip}"/>')
            lines.append(f'  <joint name="{tip}_fixed" type="fixed">')
            lines.append(f'    <parent link="{parent}"/>\n    <child link="{tip}"/>')
            lines.append(
                f'    <origin xyz="{_v(np.asarray(limb.tip_position) - prev)}" rpy="{_v(_rpy(limb.tip_rotation))}"/>'
            )
            lines.append("  </joint>")
        first = f"{self.limbs[0].name}_tip"
        lines.append(f'  <link name="{self.platform}"/>')
        lines.append(f'  <joint name="{self.platform}_fixed" type="fixed">')
        lines.append(f'    <parent link="{first}"/>\n    <child link="{self.platform}"/>')
        lines.append('    <origin xyz="0 0 0" rpy="0 0 0"/>\n  </joint>')
        lines.append("</robot>")
        return "\n".join(lines) + "\n"

    # ------------------------------------------------------------------ TOML

    def toml(
        self,
        urdf: str,
        configurations: Mapping[str, Mapping[str, Any]] | None = None,
        length_scale: float | None = None,
    ) -> str:
        """pinmob mechanism file text referring to ``urdf`` (a path relative to the file)."""
        out = ["# generated by pinmob.builder; edit the builder, not this file", f"name = {toml_value(self.name)}"]
        if self.description:
            out.append(f"description = {toml_value(self.description)}")
        out.append(f"urdf = {toml_value(urdf)}")
        out.append(f"platform = {toml_value(self.platform)}")
        if length_scale:
            out.append(f"length_scale = {toml_value(float(length_scale))}")
        for limb in self.limbs:
            out += ["", "[[limbs]]", f"name = {toml_value(limb.name)}", f"tip = {toml_value(limb.name + '_tip')}"]
            if limb.actuated:
                out.append(f"actuated = {toml_value(limb.actuated)}")
        for cname, conf in (configurations or {}).items():
            out += ["", f"[configurations.{_key(cname)}]"]
            out += [f"{_key(k)} = {toml_value(v)}" for k, v in conf.items()]
        return "\n".join(out) + "\n"

    def mechanism(self) -> Mechanism:
        """The mechanism as it would load from the written files (kinematics only, no files).

        Lets a user sketch a mechanism and analyse it at once::

            mech = b.mechanism()
            pinmob.analyze(mech, mech.neutral())  # the reference configuration
        """
        import pinocchio as pin

        from .mechanism import Mechanism

        model = pin.buildModelFromXML(self.urdf())
        actuated = {limb.name: list(limb.actuated) for limb in self.limbs}
        tips = [(limb.name, f"{limb.name}_tip") for limb in self.limbs]
        return Mechanism.from_model(
            model, tips, name=self.name, platform=self.platform, actuated=actuated, description=self.description
        )

    def write(
        self,
        directory: str | Path,
        stem: str,
        configurations: Mapping[str, Mapping[str, Any]] | None = None,
        length_scale: float | None = None,
    ) -> Path:
        """Write ``{stem}.urdf`` and ``{stem}.toml`` into ``directory``; returns the TOML path."""
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        (d / f"{stem}.urdf").write_text(self.urdf())
        path = d / f"{stem}.toml"
        path.write_text(self.toml(f"{stem}.urdf", configurations, length_scale))
        return path
