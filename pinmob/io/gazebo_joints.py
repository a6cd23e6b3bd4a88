"""Loop joints a URDF gives Gazebo in SDFormat (``<gazebo><joint>``), and the URDF elements pinmob does not read.

URDF describes a tree; ROS description packages close their loops for Gazebo by writing the loop joint in SDFormat
inside a ``<gazebo>`` element (the Gazebo tutorial "kinematic loop", 2b-t/closed_loop, grippers' ``close_loop``
macros). Gazebo converts the URDF to SDFormat and adds the joint. pinmob reads it as :mod:`pinmob.io.sdf` reads an
SDF loop joint: ``<parent>`` and ``<child>`` are links, the joint frame is the child link's frame moved by
``<pose>`` (SDFormat up to 1.6: relative to the child link), its axis ``<xyz>`` is in the joint frame (in the model
frame with ``<use_parent_model_frame>1``), and the joint becomes a closure of its type (revolute 5 rows, prismatic
5, ball 3, universal 4, fixed 6) between the joint frame fixed in the parent (``<joint>#a``) and in the child
(``<joint>#b``), at the URDF's zero configuration (where Gazebo places it).

A URDF ``<constraint>`` element (the loop closures proposed in ros/urdfdom#264) is not read: it is named in
:attr:`~pinmob.model.mechanism.Mechanism.ignored`.
"""

from __future__ import annotations

import warnings
from functools import partial
from pathlib import Path
from xml.etree import ElementTree

import numpy as np
import pinocchio as pin

from pinmob.bounds import bound
from pinmob.model import Closure


def _axis(el: ElementTree.Element, joint: str, tag: str, joint_world: pin.SE3) -> np.ndarray:
    """The joint's unit axis (``<axis>`` or ``<axis2>``) in the joint frame."""
    axis = el.find(tag)
    xyz = None if axis is None else axis.findtext("xyz")
    try:
        u = np.array([float(v) for v in (xyz or "").split()])
    except ValueError:
        raise ValueError(f"<gazebo> joint {joint!r}: <{tag}><xyz> {xyz!r} is not numbers") from None
    if u.shape != (3,) or not np.isfinite(u).all() or not np.linalg.norm(u) > 0:
        raise ValueError(f"<gazebo> joint {joint!r} needs <{tag}><xyz> as a non-zero 3-vector, got {xyz!r}")
    if axis is not None and (axis.findtext("use_parent_model_frame") or "").strip().lower() in ("1", "true"):
        u = joint_world.rotation.T @ u
    return u / np.linalg.norm(u)


def urdf_loop_joints(model: pin.Model, text: str) -> tuple[list[Closure], list[str]]:
    """The closures of the URDF's ``<gazebo><joint>`` loop joints (frames added to ``model``), and what is ignored.

    Raises:
        ValueError: a joint of a type pinmob does not read, an unknown link, or a bad pose or axis (one line).
    """
    if "<gazebo" not in text and "<constraint" not in text:
        return [], []
    root = ElementTree.fromstring(text)
    ignored = [f"<constraint> {el.get('name', '')!r}" for el in root.iter("constraint")]
    joints = [j for g in root.findall("gazebo") if not g.get("reference") for j in g.findall("joint")]
    if not joints:
        return [], ignored
    from pinmob.io.sdf import LOOP_CLOSURES, loop_closure, parse_pose  # the SDFormat reader, when there are some

    data = pin.Data(model)
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    closures = []
    for el in joints:
        name, kind = el.get("name", ""), el.get("type", "")
        if kind not in LOOP_CLOSURES:
            raise ValueError(f"<gazebo> joint {name!r} of type {kind!r} is not read; valid: {', '.join(LOOP_CLOSURES)}")
        links = []
        for tag in ("parent", "child"):
            link = (el.findtext(tag) or "").strip()
            if not model.existFrame(link, pin.FrameType.BODY):
                raise ValueError(f"<gazebo> joint {name!r}: its <{tag}> {link!r} is not a link of the URDF")
            links.append(model.getFrameId(link, pin.FrameType.BODY))
        pose, relative = parse_pose(el.find("pose"), f"<gazebo> joint {name!r}")
        if relative:
            raise ValueError(f"<gazebo> joint {name!r}: a pose relative to {relative!r} is not read (only its child)")
        at = data.oMf[links[1]] * pose
        ends = [(j, data.oMi[j]) for j in (model.frames[frame].parentJoint for frame in links)]
        closures.append(loop_closure(model, name, kind, at, ends, partial(_axis, el, name, joint_world=at)))
    return closures, ignored


def unread_elements(urdf: Path, loader: str) -> list[str]:
    """The URDF's loop elements a loader that reads the loops elsewhere (a YAML sidecar, a TOML file) leaves out.

    ``<constraint>`` elements and ``<gazebo>`` loop joints, one phrase each, with one warning naming them.
    """
    text = urdf_text(urdf, bound("bytes"))
    if "<constraint" not in text and "<gazebo" not in text:
        return []
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError:  # Pinocchio read it: a prolog or entity expat refuses; nothing more to name
        return []
    out = [f"<constraint> {el.get('name', '')!r}" for el in root.iter("constraint")]
    out += [
        f"<gazebo> loop joint {j.get('name', '')!r}"
        for g in root.findall("gazebo")
        if not g.get("reference")
        for j in g.findall("joint")
    ]
    if out:
        warnings.warn(f"{urdf.name}: not read ({loader} gives the loops): {'; '.join(out)}", stacklevel=4)
    return out


def urdf_text(path: Path, limit: int) -> str:
    """The URDF file's text (within ``limit`` bytes, checked by the caller), for its ``<gazebo>`` joints."""
    return path.read_bytes()[: limit + 1].decode("utf-8", errors="replace")
