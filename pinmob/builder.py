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
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .exceptions import ConfigurationError

JOINT_TYPES = ("revolute", "prismatic", "continuous")


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

    def _add(self, label: str, jtype: str, at: Sequence[float], axis: Sequence[float], lower: float, upper: float, actuated: bool) -> str:
        if jtype not in JOINT_TYPES:
            raise ConfigurationError(f"joint type {jtype!r}; valid: {', '.join(JOINT_TYPES)}")
        a = np.asarray(axis, float)
        if a.shape != (3,) or not np.isfinite(a).all() or np.linalg.norm(a) < 1e-12:
            raise ConfigurationError(f"limb {self.name!r} joint {label!r}: axis must be a non-zero 3-vector, got {axis!r}")
        p = np.asarray(at, float)
        if p.shape != (3,) or not np.isfinite(p).all():
            raise ConfigurationError(f"limb {self.name!r} joint {label!r}: position must be a 3-vector, got {at!r}")
        name = f"{self.name}_{label}"
        if any(j.name == name for j in self.joints):
            raise ConfigurationError(f"limb {self.name!r} already has a joint {label!r}")
        a = a / np.linalg.norm(a)
        self.joints.append(JointSpec(name, jtype, tuple(p.tolist()), tuple(a.tolist()), lower, upper))  # type: ignore[arg-type]
        if actuated:
            self.actuated.append(name)
        return name

    def revolute(self, label: str, at: Sequence[float], axis: Sequence[float], lower: float = -np.pi, upper: float = np.pi, actuated: bool = False) -> str:
        """Add a revolute joint about ``axis`` through ``at``; returns its full name."""
        return self._add(label, "revolute", at, axis, lower, upper, actuated)

    def prismatic(self, label: str, at: Sequence[float], axis: Sequence[float], lower: float = -1.0, upper: float = 1.0, actuated: bool = False) -> str:
        """Add a prismatic joint along ``axis`` [m]; returns its full name."""
        return self._add(label, "prismatic", at, axis, lower, upper, actuated)

    def universal(self, label: str, at: Sequence[float], axis1: Sequence[float], axis2: Sequence[float]) -> tuple[str, str]:
        """Two revolutes at one point: ``{label}a`` about axis1, then ``{label}b`` about axis2."""
        return self.revolute(label + "a", at, axis1), self.revolute(label + "b", at, axis2)

    def spherical(self, label: str, at: Sequence[float], axes: Sequence[Sequence[float]] = ((1, 0, 0), (0, 1, 0), (0, 0, 1))) -> tuple[str, ...]:
        """Three revolutes at one point: ``{label}a``, ``{label}b``, ``{label}c``."""
        return tuple(self.revolute(label + s, at, ax) for s, ax in zip("abc", axes))

    def tip(self, at: Sequence[float], rotation: Sequence[Sequence[float]] | None = None) -> None:
        """End the limb at a tip frame with world pose (at, rotation) at the reference configuration."""
        self.tip_position = tuple(np.asarray(at, float).tolist())  # type: ignore[assignment]
        self.tip_rotation = np.eye(3) if rotation is None else np.asarray(rotation, float)


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


def _v(xs: Sequence[float]) -> str:
    return " ".join(_f(x) for x in xs)


def toml_value(value: Any) -> str:
    """A TOML literal for str, bool, int, float, sequences and mappings (inline)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, np.integer)):
        return str(int(value))
    if isinstance(value, (float, np.floating)):
        return _f(float(value)) if float(value) != int(float(value)) or abs(float(value)) > 1e15 else f"{float(value):.1f}"
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
        self.limbs: list[LimbBuilder] = []

    def limb(self, name: str) -> LimbBuilder:
        """Start a new limb; its joints are named ``{name}_{label}``."""
        if any(b.name == name for b in self.limbs):
            raise ConfigurationError(f"limb {name!r} exists already")
        limb = LimbBuilder(name)
        self.limbs.append(limb)
        return limb

    # ------------------------------------------------------------------ URDF

    def urdf(self) -> str:
        """URDF text: one branch per limb from link ``base``; the platform frame on the first tip."""
        robot = self.name.replace(" ", "_")
        lines = ['<?xml version="1.0"?>', '<!-- generated by pinmob.builder; edit the builder, not this file -->', f'<robot name="{robot}">', '  <link name="base"/>']
        for limb in self.limbs:
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
            lines.append(f'    <origin xyz="{_v(np.asarray(limb.tip_position) - prev)}" rpy="{_v(_rpy(limb.tip_rotation))}"/>')
            lines.append("  </joint>")
        first = f"{self.limbs[0].name}_tip"
        lines.append(f'  <link name="{self.platform}"/>')
        lines.append(f'  <joint name="{self.platform}_fixed" type="fixed">\n    <parent link="{first}"/>\n    <child link="{self.platform}"/>')
        lines.append('    <origin xyz="0 0 0" rpy="0 0 0"/>\n  </joint>')
        lines.append("</robot>")
        return "\n".join(lines) + "\n"

    # ------------------------------------------------------------------ TOML

    def toml(self, urdf: str, configurations: Mapping[str, Mapping[str, Any]] | None = None, length_scale: float | None = None) -> str:
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

    def write(self, directory: str | Path, stem: str, configurations: Mapping[str, Mapping[str, Any]] | None = None, length_scale: float | None = None) -> Path:
        """Write ``{stem}.urdf`` and ``{stem}.toml`` into ``directory``; returns the TOML path."""
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        (d / f"{stem}.urdf").write_text(self.urdf())
        path = d / f"{stem}.toml"
        path.write_text(self.toml(f"{stem}.urdf", configurations, length_scale))
        return path
