"""SDFormat models with loops, read with the standard XML parser: links, joints, frames, poses ``relative_to``.

Pinocchio's pip wheel is built without libsdformat, and the kinematic part of SDFormat is small, so pinmob
reads it itself, by the specification (sdformat.org, "pose frame semantics", as libsdformat and Drake's
parser resolve it):

- the model is the file's one ``<model>`` (in ``<sdf>`` or a ``<world>``) that has joints; a world's other
  models without joints (a ground plane) are left out, named in :attr:`Mechanism.ignored`. A nested
  ``<model>`` or an ``<include>`` inside the model is refused in one line (pinmob reads one flat model).
- a pose is ``x y z roll pitch yaw`` (fixed axes, ``R = Rz(yaw) Ry(pitch) Rx(roll)``; ``degrees="true"``
  for degrees) or ``x y z qx qy qz qw`` (``rotation_format="quat_xyzw"``), relative to the frame its
  ``relative_to`` names; without it a link's pose is relative to the model frame, a ``<frame>``'s to the
  frame it is ``attached_to`` (default the model frame), a joint's to its child frame. ``world`` is the
  world frame, ``__model__`` the model frame (placed by the model's own pose).
- a joint's ``<parent>`` and ``<child>`` name links or frames (a frame stands for the link it is attached
  to); its axis ``<xyz>`` is in the joint frame, or in the frame ``expressed_in`` names (SDFormat 1.7+),
  or in the model frame with ``<use_parent_model_frame>true`` (up to 1.6).
- joints are read in file order: a joint whose child link has a parent joint already (or whose parent is
  carried by its child) closes a loop, and becomes a closure of its own type between the joint frame
  fixed in the parent link (frame ``<joint>#a``) and the joint frame fixed in the child link
  (``<joint>#b``): ``revolute`` and ``continuous``: a revolute closure about the axis (5 rows);
  ``prismatic``: a prismatic closure along it (5); ``ball``: a ``3d`` closure (3); ``universal``: a
  universal closure about ``axis`` (in the parent) and ``axis2`` (in the child) (4); ``fixed``: ``6d`` (6).
  The joint frame is one frame, so the file's poses close every loop as they are: they are the
  configuration ``initial`` (every joint value 0).
- the other joints build the tree: ``revolute`` (limits from ``<limit>``), ``continuous``, ``prismatic``,
  ``ball``, ``universal`` (two hinges, ``<joint>`` then ``<joint>#2``) and ``fixed`` (the child welded to
  its parent). A link no joint carries floats (a free-flyer joint named after it, ``<link>#free``), unless
  the model is ``<static>``. Other joint types (``revolute2``, ``screw``, ``gearbox``) are refused in one
  line; an ``<axis><mimic>`` (SDFormat 1.11) is a coupling pinmob does not read: named in
  :attr:`Mechanism.ignored`, with one warning.

Frames of the Pinocchio model: a body frame per link, a joint frame per tree joint, an operational frame
per ``<frame>``. A joint whose ``<parent>`` is a ``<frame>`` away from the joint (which sits at its child
frame, as the specification says; the parent frame only names the parent link) is named in a warning: a
file that means the joint to be at that frame (Drake's ``four_bar_loop.sdf``, "aspirational" by its own
comment) is not read as it means.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from functools import partial
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pinocchio as pin

from pinmob.bounds import check_bound
from pinmob.io.schema import errors_at, file_error
from pinmob.io.text_file import parsing, read_text
from pinmob.model import Closure, Mechanism, NamedConfiguration, make_closure
from pinmob.screw import Array

#: Joint types pinmob reads, and the closure type a loop joint of each becomes.
LOOP_CLOSURES = {
    "revolute": "revolute",
    "continuous": "revolute",
    "prismatic": "prismatic",
    "ball": "3d",
    "universal": "universal",
    "fixed": "6d",
}
#: The frames every model has.
WORLD, MODEL = "world", "__model__"
#: An XML comment (non-greedy: to its first ``-->``).
COMMENT = re.compile(r"<!--.*?-->", re.DOTALL)
#: Distance between a joint and the ``<frame>`` its ``<parent>`` names that the warning names (relative, or [m]).
APART = 1e-9


@dataclass
class Sdf:
    """The model's elements by name, and their resolved world poses (filled as they are resolved)."""

    path: Path
    model: ElementTree.Element
    links: dict[str, ElementTree.Element] = field(default_factory=dict)
    frames: dict[str, ElementTree.Element] = field(default_factory=dict)
    joints: dict[str, ElementTree.Element] = field(default_factory=dict)
    world: dict[str, pin.SE3] = field(default_factory=dict)
    resolving: set[str] = field(default_factory=set)

    def error(self, msg: str) -> Exception:
        """A one-line error naming the file and the model."""
        return file_error(self.path, f"SDF model {self.model.get('name', '')!r}: {msg}")


def parse_pose(el: ElementTree.Element | None, where: str) -> tuple[pin.SE3, str | None]:
    """A ``<pose>`` element as (pose, the frame it is relative to or None); identity when absent or empty.

    Raises:
        ValueError: not 6 numbers (7 with ``rotation_format="quat_xyzw"``).
    """
    if el is None:
        return pin.SE3.Identity(), None
    relative = el.get("relative_to") or el.get("frame") or None  # ``frame``: SDFormat 1.5-1.6
    text = (el.text or "").split()
    if not text:
        return pin.SE3.Identity(), relative
    try:
        values = np.array([float(v) for v in text])
    except ValueError:
        raise ValueError(f"{where}: <pose> {' '.join(text)[:80]!r} is not numbers") from None
    quat = el.get("rotation_format", "euler_rpy") == "quat_xyzw"
    if values.size != (7 if quat else 6) or not np.isfinite(values).all():
        raise ValueError(f"{where}: <pose> needs {7 if quat else 6} finite numbers, got {' '.join(text)[:80]!r}")
    if quat:
        q = values[3:]
        if not np.linalg.norm(q) > 0:
            raise ValueError(f"{where}: <pose> quaternion is zero")
        rot = pin.Quaternion(q[3], q[0], q[1], q[2]).normalized().matrix()
    else:
        rpy = np.radians(values[3:]) if el.get("degrees", "false").strip().lower() in ("true", "1") else values[3:]
        rot = pin.rpy.rpyToMatrix(*rpy)
    return pin.SE3(rot, values[:3]), relative


def world_pose(sdf: Sdf, name: str) -> pin.SE3:
    """The world pose of frame ``name`` (link, frame, joint, ``world`` or ``__model__``) in the file's poses.

    Raises:
        ValueError: an unknown frame, or poses relative to each other in a cycle.
    """
    if name in sdf.world:
        return sdf.world[name]
    if name in sdf.resolving:
        raise ValueError(f"the poses of {', '.join(sorted(sdf.resolving))} are relative to each other in a cycle")
    sdf.resolving.add(name)
    if name in sdf.links:
        pose, relative = parse_pose(sdf.links[name].find("pose"), f"link {name!r}")
        base = relative or MODEL
    elif name in sdf.frames:
        pose, relative = parse_pose(sdf.frames[name].find("pose"), f"frame {name!r}")
        base = relative or sdf.frames[name].get("attached_to") or MODEL
    elif name in sdf.joints:
        pose, relative = parse_pose(sdf.joints[name].find("pose"), f"joint {name!r}")
        base = relative or joint_end(sdf, name, "child")
    else:
        valid = sorted([*sdf.links, *sdf.frames, *sdf.joints])
        raise ValueError(f"unknown frame {name!r}; valid: {', '.join([WORLD, MODEL, *valid][:40])}")
    result = world_pose(sdf, base) * pose
    sdf.resolving.discard(name)
    sdf.world[name] = result
    return result


def joint_end(sdf: Sdf, joint: str, tag: str) -> str:
    """The frame a joint's ``<parent>`` or ``<child>`` names (SDFormat 1.4's ``<parent link=..>`` too)."""
    el = sdf.joints[joint].find(tag)
    name = "" if el is None else (el.text or el.get("link") or "").strip()
    if not name:
        raise ValueError(f"joint {joint!r} has no <{tag}>")
    return name


def link_of(sdf: Sdf, name: str, seen: frozenset[str] = frozenset()) -> str:
    """The link frame ``name`` is fixed to (``world`` for the world); ``__model__`` is the canonical link.

    Raises:
        ValueError: an unknown name, or frames attached to each other in a cycle.
    """
    if name == WORLD or name in sdf.links:
        return name
    if name in seen:
        raise ValueError(f"frames {', '.join(sorted(seen))} are attached to each other in a cycle")
    if name == MODEL:
        canonical = sdf.model.get("canonical_link") or next(iter(sdf.links), WORLD)
        return link_of(sdf, canonical, seen | {name})
    if name in sdf.frames:
        return link_of(sdf, sdf.frames[name].get("attached_to") or MODEL, seen | {name})
    if name in sdf.joints:
        return link_of(sdf, joint_end(sdf, name, "child"), seen | {name})
    raise ValueError(f"unknown frame {name!r}; valid: {', '.join([WORLD, *sdf.links, *sdf.frames][:40])}")


def joint_axis(sdf: Sdf, joint: str, tag: str = "axis") -> Array:
    """A joint's unit axis (``<axis>`` or ``<axis2>``) in the joint frame.

    Raises:
        ValueError: missing or zero.
    """
    axis_el = sdf.joints[joint].find(tag)
    if axis_el is None or (xyz := axis_el.find("xyz")) is None or not (xyz.text or "").split():
        raise ValueError(f"joint {joint!r} needs <{tag}><xyz>")
    try:
        u = np.array([float(v) for v in (xyz.text or "").split()])
    except ValueError:
        raise ValueError(f"joint {joint!r}: <{tag}><xyz> {xyz.text!r} is not numbers") from None
    if u.shape != (3,) or not np.isfinite(u).all() or not np.linalg.norm(u) > 0:
        raise ValueError(f"joint {joint!r}: <{tag}><xyz> must be a non-zero 3-vector, got {xyz.text!r}")
    expressed = xyz.get("expressed_in")
    parent_model = (axis_el.findtext("use_parent_model_frame") or "").strip().lower() in ("true", "1")
    if expressed or parent_model:
        frame = world_pose(sdf, expressed or MODEL).rotation
        u = world_pose(sdf, joint).rotation.T @ frame @ u
    return u / np.linalg.norm(u)


def joint_limits(el: ElementTree.Element) -> tuple[float, float] | None:
    """``<axis><limit>``'s (lower, upper) when both are finite numbers, lower <= upper; else None."""
    limit = el.find("axis/limit")
    try:
        lo, hi = float(limit.findtext("lower", "")), float(limit.findtext("upper", ""))  # type: ignore[union-attr]
    except (AttributeError, ValueError):
        return None
    return (lo, hi) if np.isfinite([lo, hi]).all() and lo <= hi else None


def loop_closure(
    model: pin.Model,
    name: str,
    kind: str,
    at: pin.SE3,
    ends: Sequence[tuple[int, pin.SE3]],
    axis_of: Callable[[str], Array],
) -> Closure:
    """The closure loop joint ``name`` of type ``kind`` (a key of :data:`LOOP_CLOSURES`) becomes; its frames added.

    The joint frame, at world pose ``at``, is fixed once in the parent's and once in the child's Pinocchio joint
    (``ends``: each its joint id and that joint's world pose, parent first), as frames ``<name>#a`` and
    ``<name>#b``; the closure joins them, about or along ``axis_of("axis")`` (and ``axis_of("axis2")`` for a
    universal joint), a unit axis in the joint frame, read only for the types that have it.
    """
    for (joint, joint_world), suffix in zip(ends, "ab", strict=True):
        model.addFrame(pin.Frame(f"{name}#{suffix}", joint, joint_world.actInv(at), pin.FrameType.OP_FRAME), False)
    axis = axis_of("axis") if kind not in ("ball", "fixed") else None
    axis_b = axis_of("axis2") if kind == "universal" else None
    return make_closure(model, name, f"{name}#a", f"{name}#b", LOOP_CLOSURES[kind], axis, axis_b)


def _add_joint(model: pin.Model, sdf: Sdf, name: str, kind: str, carrier: int, at: pin.SE3) -> int:
    """Add tree joint ``name`` (its Pinocchio joints) on ``carrier`` at placement ``at``; the last joint's id."""
    el = sdf.joints[name]
    if kind in ("revolute", "continuous"):
        u = joint_axis(sdf, name)
        jm = pin.JointModelRevoluteUnaligned(u) if kind == "revolute" else pin.JointModelRevoluteUnboundedUnaligned(u)
        jid = model.addJoint(carrier, jm, at, name)
        if kind == "revolute" and (limits := joint_limits(el)):
            model.lowerPositionLimit[model.joints[jid].idx_q] = limits[0]
            model.upperPositionLimit[model.joints[jid].idx_q] = limits[1]
    elif kind == "prismatic":
        jid = model.addJoint(carrier, pin.JointModelPrismaticUnaligned(joint_axis(sdf, name)), at, name)
        if limits := joint_limits(el):
            model.lowerPositionLimit[model.joints[jid].idx_q] = limits[0]
            model.upperPositionLimit[model.joints[jid].idx_q] = limits[1]
    elif kind == "ball":
        jid = model.addJoint(carrier, pin.JointModelSpherical(), at, name)
    else:  # universal: two hinges at the joint frame
        first = model.addJoint(carrier, pin.JointModelRevoluteUnaligned(joint_axis(sdf, name)), at, name)
        model.addJointFrame(first)
        u2 = joint_axis(sdf, name, "axis2")
        jid = model.addJoint(first, pin.JointModelRevoluteUnaligned(u2), pin.SE3.Identity(), f"{name}#2")
    model.addJointFrame(jid)
    return int(jid)


def _tree_joints(sdf: Sdf) -> tuple[dict[str, str], list[str]]:
    """(the joint carrying each link, in file order; the loop joints): see the module docstring."""
    carried: dict[str, str] = {}
    loops: list[str] = []

    def ancestors(link: str) -> set[str]:
        out = set()
        while link in carried:
            out.add(link)
            link = link_of(sdf, joint_end(sdf, carried[link], "parent"))
        return out | {link}

    for name in sdf.joints:
        parent, child = (link_of(sdf, joint_end(sdf, name, t)) for t in ("parent", "child"))
        if child == WORLD:
            raise ValueError(f"joint {name!r}: its child is the world; valid children: the model's links")
        if parent == child:
            raise ValueError(f"joint {name!r} joins link {child!r} to itself")
        if child in carried or child in ancestors(parent):
            loops.append(name)
        else:
            carried[child] = name
    return carried, loops


def _models(root: ElementTree.Element, path: Path) -> tuple[ElementTree.Element, list[str]]:
    """The model to read and the world's other elements left out (models without joints, includes)."""
    if root.tag != "sdf":
        raise file_error(path, f"not an SDFormat file: its root element is <{root.tag}>, not <sdf>")
    candidates = list(root.findall("model"))
    left: list[str] = []
    for world in root.findall("world"):
        candidates += world.findall("model")
        left += [f"<include> {(inc.findtext('uri') or '').strip()!r}" for inc in world.findall("include")]
    with_joints = [m for m in candidates if m.find("joint") is not None or m.find("model") is not None]
    left += [f"model {m.get('name', '')!r} (no joint)" for m in candidates if m not in with_joints]
    if not with_joints:
        if root.find("world/include") is not None:
            raise file_error(path, f"no <model> with joints in the file; included models are not read: {left}")
        raise file_error(path, "no <model> with joints: no mechanism to read")
    if len(with_joints) > 1:
        names = ", ".join(repr(m.get("name", "")) for m in with_joints)
        raise file_error(path, f"several models with joints ({names}): pinmob reads one; give it a file with one")
    return with_joints[0], left


def _check_flat(sdf: Sdf) -> None:
    """Refuse what pinmob does not read inside the model (nested and included models), and duplicate names."""
    for tag in ("model", "include"):
        inner = sdf.model.find(tag)
        if inner is not None:
            what = inner.get("name") or (inner.findtext("uri") or "").strip()
            raise sdf.error(
                f"{'a nested <model>' if tag == 'model' else 'an <include>'} ({what!r}) is not read: pinmob reads one "
                "model's own links, joints and frames; write them into the model"
            )
    seen: dict[str, str] = {}
    for tag, table in (("link", sdf.links), ("frame", sdf.frames), ("joint", sdf.joints)):
        for el in sdf.model.findall(tag):
            name = el.get("name", "")
            if not name or name in (WORLD, MODEL) or name in seen:
                why = f"is also a {seen[name]}" if name in seen else "is reserved" if name else "is missing"
                raise sdf.error(f"the name of {tag} {name!r} {why}: names of links, joints and frames are unique")
            seen[name] = tag
            table[name] = el
    check_bound("joints", len(sdf.joints), f"sdf {str(sdf.path)!r}")


def _mimics(sdf: Sdf) -> list[str]:
    """The joints whose ``<axis>`` or ``<axis2>`` has a ``<mimic>`` (a coupling pinmob does not read)."""
    return [f"<mimic> of joint {n!r}" for n, el in sdf.joints.items() if el.find("axis/mimic") is not None] + [
        f"<mimic> of joint {n!r} (axis2)" for n, el in sdf.joints.items() if el.find("axis2/mimic") is not None
    ]


def build(sdf: Sdf) -> tuple[pin.Model, list[Closure], list[str]]:
    """The Pinocchio model at the file's poses, the loop joints' closures, and the joints whose ends are apart."""
    model = pin.Model()
    model.name = sdf.model.get("name", "") or sdf.path.stem
    for name, el in sdf.joints.items():
        if el.get("type", "") not in LOOP_CLOSURES:
            raise ValueError(
                f"joint {name!r} of type {el.get('type', '')!r} is not read; valid: {', '.join(LOOP_CLOSURES)}"
            )
    carried, loops = _tree_joints(sdf)
    static = (sdf.model.findtext("static") or "").strip().lower() in ("true", "1")
    carrier: dict[str, int] = {WORLD: 0}
    joint_world = {0: pin.SE3.Identity()}

    def place(link: str) -> int:
        """The Pinocchio joint carrying ``link`` (its joints added first)."""
        if link in carrier:
            return carrier[link]
        if link not in carried:
            if static:
                carrier[link] = 0
                return 0
            at = world_pose(sdf, link)
            jid = model.addJoint(0, pin.JointModelFreeFlyer(), at, f"{link}#free")
            model.addJointFrame(jid)
            joint_world[jid] = at
            carrier[link] = int(jid)
            return int(jid)
        joint = carried[link]
        parent = place(link_of(sdf, joint_end(sdf, joint, "parent")))
        kind = sdf.joints[joint].get("type", "")
        at_world = world_pose(sdf, joint)
        if kind == "fixed":
            carrier[link] = parent
            return parent
        jid = _add_joint(model, sdf, joint, kind, parent, joint_world[parent].actInv(at_world))
        joint_world[jid] = at_world
        carrier[link] = jid
        return jid

    for link in sdf.links:
        place(link)
    for link in sdf.links:
        j = carrier[link]
        model.addFrame(pin.Frame(link, j, joint_world[j].actInv(world_pose(sdf, link)), pin.FrameType.BODY), False)
    for name in sdf.frames:
        j = carrier[link_of(sdf, name)]
        frame = pin.Frame(name, j, joint_world[j].actInv(world_pose(sdf, name)), pin.FrameType.OP_FRAME)
        model.addFrame(frame, False)
    closures = []
    for name in loops:
        at = world_pose(sdf, name)
        ends = [carrier[link_of(sdf, joint_end(sdf, name, t))] for t in ("parent", "child")]
        kind = sdf.joints[name].get("type", "")
        placed = [(end, joint_world[end]) for end in ends]
        closures.append(loop_closure(model, name, kind, at, placed, partial(joint_axis, sdf, name)))
    apart = []
    for name in sdf.joints:  # a <frame> named as the parent, away from the joint: the file may mean it as the joint
        parent = joint_end(sdf, name, "parent")
        if parent in sdf.frames:
            miss = float(np.linalg.norm(world_pose(sdf, parent).actInv(world_pose(sdf, name)).translation))
            if miss > APART * max(1.0, float(np.linalg.norm(world_pose(sdf, name).translation))):
                apart.append(f"{name} (at its child frame, {miss:.3g} m from its parent frame {parent!r})")
    return model, closures, apart


def load_sdf(path: str | Path) -> Mechanism:
    """Load an SDFormat file's model: its tree, its loop joints as closures, the configuration ``initial``.

    Raises:
        MechanismFileError: the file is not SDFormat XML, has no model with joints or several, a nested or
            included model, a joint type pinmob does not read, an unknown frame, a pose cycle, or no loop
            joint (the message says which).
    """
    path = Path(path)
    text = read_text(path, "SDF")
    if "<!ENTITY" in text:
        raise file_error(
            path, "an SDF file with <!ENTITY> declarations is not read (entities can expand without bound)"
        )
    with parsing(path, "SDF"):
        try:  # comments dropped first (lines kept): libsdformat's tinyxml2 reads a "--" in one, expat does not
            root = ElementTree.fromstring(COMMENT.sub(lambda m: "\n" * m.group(0).count("\n"), text))
        except ElementTree.ParseError as exc:
            raise file_error(path, f"not well-formed XML: {exc}") from None
        chosen, left = _models(root, path)
        sdf = Sdf(path, chosen)
        _check_flat(sdf)
        try:
            placed, relative = parse_pose(chosen.find("pose"), "the model")
        except ValueError as exc:
            raise sdf.error(str(exc)) from None
        if relative not in (None, WORLD):
            raise sdf.error(f"its pose is relative to {relative!r}: a model's pose is read relative to the world only")
        sdf.world.update({WORLD: pin.SE3.Identity(), MODEL: placed})
        try:
            model, closures, apart = build(sdf)
        except ValueError as exc:
            raise sdf.error(str(exc)) from None
    if not closures:
        raise sdf.error(
            "no joint closes a loop (each link has one parent joint): a tree, with nothing for pinmob to analyse"
        )
    ignored = _mimics(sdf) + [x for x in left if x.startswith("<include>")]
    if apart:
        warnings.warn(
            f"{path.name}: joint(s) {'; '.join(apart)}: SDFormat places a joint at its child frame (its pose is "
            "relative to it; the parent frame names the parent link only), as libsdformat and Drake read it, and "
            "pinmob reads it so",
            stacklevel=2,
        )
    with errors_at(path):
        mech = Mechanism.from_model(
            model,
            [],
            name=model.name,
            description=f"SDFormat {path.name} (model {model.name!r})",
            source=path,
            closures=closures,
            configurations={"initial": NamedConfiguration("initial")},
        )
    if ignored:
        warnings.warn(f"{path.name}: not read: {'; '.join(ignored)}", stacklevel=2)
    return mech.with_ignored(ignored)
