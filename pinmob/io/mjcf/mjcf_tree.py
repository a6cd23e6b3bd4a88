"""The Pinocchio tree of a compiled MuJoCo model: one Pinocchio joint per MuJoCo joint, in MuJoCo's order.

MuJoCo moves a body with its joints one after the other (``mj_kinematics``): starting from the body
frame ``B`` placed by ``body_pos`` / ``body_quat`` in its parent, joint k (anchor ``p_k`` and axis
``a_k`` in the body frame, reference ``r_k = qpos0``) turns or slides it,

    hinge: B <- B T(p_k) R(a_k, q_k - r_k) T(-p_k),   slide: B <- B T(a_k (q_k - r_k)),
    ball:  B <- B T(p_k) R(quat_k) T(-p_k),            free:  B = (qpos position, qpos quaternion) in the world.

Each becomes a Pinocchio joint placed at ``T(p_k) R(a_k, -r_k)`` (hinge; ``T(p_k - a_k r_k)`` for a
slide) in the previous joint's frame, so that Pinocchio's q of a hinge or slide *is* MuJoCo's qpos
and the joint's limits are MuJoCo's ``range`` (radians and metres, as compiled). A ball joint is a
``JointModelSpherical`` and a free joint a ``JointModelFreeFlyer`` (world placement identity):
their quaternions are stored ``(x, y, z, w)`` by Pinocchio and ``(w, x, y, z)`` by MuJoCo
(:func:`qpos_to_q`, :func:`q_to_qpos`). A body without joints is welded to its parent. Bodies are
``BODY`` frames named as in the file, sites ``OP_FRAME`` frames (``site:<name>`` when a body or a
joint has the name already; MuJoCo keeps their names apart), each joint has a ``JOINT`` frame of its
name; unnamed elements are labelled by their MuJoCo id, ``#k`` for joint k, ``body#k``, ``site#k``
(:mod:`pinmob.io.mjcf.mjcf_names`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.io.mjcf.mjcf_names import RESERVED, add_frame, labels, site_frame
from pinmob.io.mjcf.mjcf_names import name_of as name_of  # where the MJCF modules import it from
from pinmob.screw import Array

#: MuJoCo's joint types (``mjtJoint``): free, ball, slide, hinge.
FREE, BALL, SLIDE, HINGE = 0, 1, 2, 3


@dataclass(frozen=True)
class Tree:
    """The Pinocchio model of a compiled MuJoCo model, and where MuJoCo's objects went.

    Attributes:
        model: the Pinocchio model.
        body_joint: (nbody,) Pinocchio joint carrying each MuJoCo body (0 = the world).
        body_placement: per MuJoCo body, its frame in that joint's frame.
        body_frame: per MuJoCo body, its Pinocchio frame name.
        site_frame: per MuJoCo site, its Pinocchio frame name.
        joint_names: per MuJoCo joint, its Pinocchio joint name.
    """

    model: pin.Model
    body_joint: tuple[int, ...]
    body_placement: tuple[pin.SE3, ...]
    body_frame: tuple[str, ...]
    site_frame: tuple[str, ...]
    joint_names: tuple[str, ...]


def unique(name: str, taken: set[str]) -> str:
    """``name``, or ``name_2``, ``name_3``... the first not in ``taken`` (which it is added to)."""
    out, k = name, 2
    while out in taken:
        out, k = f"{name}_{k}", k + 1
    taken.add(out)
    return out


def se3(pos: Array, quat_wxyz: Array) -> pin.SE3:
    """Placement from a position and a MuJoCo quaternion ``(w, x, y, z)`` (normalised)."""
    w, x, y, z = np.asarray(quat_wxyz, float) / np.linalg.norm(quat_wxyz)
    return pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.asarray(pos, float).copy())


def _joint_model(kind: int, axis: Array) -> pin.JointModel:
    if kind == HINGE:
        return pin.JointModelRevoluteUnaligned(axis)
    if kind == SLIDE:
        return pin.JointModelPrismaticUnaligned(axis)
    return pin.JointModelSpherical() if kind == BALL else pin.JointModelFreeFlyer()


def build_tree(m: Any, name: str) -> Tree:
    """The Pinocchio model of the compiled MuJoCo model ``m`` (see the module docstring).

    Raises:
        ValueError: a free joint below another body (MuJoCo allows it only at the top of the tree
            and the message says so), a free joint sharing its body, or a name of the file that is
            pinmob's label of another object (:mod:`pinmob.io.mjcf.mjcf_names`).
    """
    model = pin.Model()
    model.name = name
    joint_of = [0] * m.nbody
    placement = [pin.SE3.Identity()] * m.nbody
    joint_names = labels(m, "joint", m.njnt, RESERVED["joint"])
    body_frame = ("universe",) + labels(m, "body", m.nbody)[1:]  # MuJoCo's world body is Pinocchio's universe
    for b in range(1, m.nbody):
        parent = int(m.body_parentid[b])
        current = placement[parent] * se3(m.body_pos[b], m.body_quat[b])  # the body frame in joint_of[parent]
        carrier = joint_of[parent]
        first, count = int(m.body_jntadr[b]), int(m.body_jntnum[b])
        for j in range(first, first + count):
            kind, anchor = int(m.jnt_type[j]), np.array(m.jnt_pos[j], float)
            axis = np.array(m.jnt_axis[j], float)
            ref = float(m.qpos0[m.jnt_qposadr[j]]) if kind in (HINGE, SLIDE) else 0.0
            if kind == FREE:
                if count != 1 or parent != 0:
                    raise ValueError(f"body {body_frame[b]!r}: a free joint must be the only joint of a top-level body")
                at, after = pin.SE3.Identity(), pin.SE3.Identity()
            elif kind == HINGE:
                at = current * pin.SE3(pin.exp3(-ref * axis), anchor)
                after = pin.SE3(np.eye(3), -anchor)
            elif kind == SLIDE:
                at, after = current * pin.SE3(np.eye(3), anchor - ref * axis), pin.SE3(np.eye(3), -anchor)
            else:
                at, after = current * pin.SE3(np.eye(3), anchor), pin.SE3(np.eye(3), -anchor)
            carrier = model.addJoint(carrier, _joint_model(kind, axis), at, joint_names[j])
            if kind in (HINGE, SLIDE) and m.jnt_limited[j]:
                lo, hi = m.jnt_range[j]
                model.lowerPositionLimit[model.joints[carrier].idx_q] = lo
                model.upperPositionLimit[model.joints[carrier].idx_q] = hi
            current = after
        joint_of[b], placement[b] = carrier, current
    for jname in joint_names:  # a JOINT frame per joint (joint couplings name them)
        jid = model.getJointId(jname)
        add_frame(model, pin.Frame(jname, jid, pin.SE3.Identity(), pin.FrameType.JOINT), f"joint {jname!r}")
    for b in range(1, m.nbody):
        frame = pin.Frame(body_frame[b], joint_of[b], placement[b], pin.FrameType.BODY)
        add_frame(model, frame, f"body {body_frame[b]!r}")
    site_frames = []
    for s, site in enumerate(labels(m, "site", m.nsite)):
        b = int(m.site_bodyid[s])
        at = placement[b] * se3(m.site_pos[s], m.site_quat[s])
        site_frames.append(site_frame(site, model))
        add_frame(model, pin.Frame(site_frames[-1], joint_of[b], at, pin.FrameType.OP_FRAME), f"site {site!r}")
    return Tree(model, tuple(joint_of), tuple(placement), body_frame, tuple(site_frames), joint_names)


def quaternion_slices(model: pin.Model) -> list[slice]:
    """Slices of q holding a quaternion: each ball joint's q, each free joint's last four coordinates."""
    out = []
    for j in range(1, model.njoints):
        joint = model.joints[j]
        short = joint.shortname()
        if short == "JointModelSpherical":
            out.append(slice(joint.idx_q, joint.idx_q + 4))
        elif short == "JointModelFreeFlyer":
            out.append(slice(joint.idx_q + 3, joint.idx_q + 7))
    return out


def qpos_to_q(model: pin.Model, qpos: Array) -> Array:
    """MuJoCo's qpos (quaternions ``w, x, y, z``) as Pinocchio's q (``x, y, z, w``), quaternions normalised."""
    q = np.array(qpos, float)
    for s in quaternion_slices(model):
        quat = np.roll(q[s], -1)
        norm = np.linalg.norm(quat)
        q[s] = quat / norm if norm > 0 else np.array([0.0, 0.0, 0.0, 1.0])
    return q


def q_to_qpos(model: pin.Model, q: Array) -> Array:
    """Pinocchio's q as MuJoCo's qpos (the inverse of :func:`qpos_to_q`)."""
    out = np.array(q, float)
    for s in quaternion_slices(model):
        out[s] = np.roll(out[s], 1)
    return out
