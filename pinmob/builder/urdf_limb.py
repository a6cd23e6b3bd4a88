"""Limbs copied from an existing robot URDF (e.g. an arm of example-robot-data), meshes included."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree

import numpy as np

from pinmob.exceptions import ConfigurationError

from .chain_builder import FrameSpec, frame_lines
from .layout import rpy
from .text import vector


def _link_of(joint: ElementTree.Element, tag: str) -> str:
    """The ``link`` attribute of a URDF joint's ``<parent>`` or ``<child>`` ("" when missing)."""
    el = joint.find(tag)
    return "" if el is None else el.get("link", "")


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


@dataclass
class UrdfLimb:
    """A limb copied from an existing robot URDF: its chain from ``root_link`` to ``tip_link``.

    Links and joints are renamed ``{limb}_{original name}``; each link keeps its
    visual, collision and inertial elements (meshes keep their ``package://``
    paths, so a viewer shows the robot when the package folder is known to
    :func:`pinmob.io.urdf.package_dirs`). The root link is fixed to the
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

    @property
    def tip_name(self) -> str:
        """Name of the limb's tip frame."""
        return f"{self.name}_tip"

    def names(self) -> list[str]:
        """Every link and joint name this limb writes."""
        return [el.get("name", "") for el in self.links + self.chain] + [f"{self.name}_mount", self.tip_name]

    def urdf_lines(self) -> list[str]:
        """URDF elements of this limb, indented for inclusion in a ``<robot>``."""
        out = []
        rot, pos = self.base_pose
        root = f"{self.name}_{self.root_link}"
        out.append(f'  <joint name="{self.name}_mount" type="fixed">')
        out.append(f'    <parent link="base"/>\n    <child link="{root}"/>')
        out.append(f'    <origin xyz="{vector(pos)}" rpy="{vector(rpy(rot))}"/>\n  </joint>')
        for el in self.links + self.chain:
            el = _copy(el)
            ElementTree.indent(el, space="  ", level=1)
            out.append("  " + ElementTree.tostring(el, encoding="unicode").rstrip())
        rot, pos = self.tip_offset
        tip = FrameSpec(
            self.tip_name, f"{self.name}_{self.tip_link}", (0.0, 0.0, 0.0), tuple(pos), tuple(map(tuple, rot))
        )
        return out + frame_lines(tip)
