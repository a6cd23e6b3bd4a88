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
``BODY`` frames named as in the file, sites ``OP_FRAME`` frames (``site:<name>`` when a body has
the name already; MuJoCo keeps bodies and sites apart), each joint has a ``JOINT`` frame of its name;
unnamed elements get ``body<i>``,
``joint<i>``, ``site<i>`` (MuJoCo's index).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.screw.algebra import Array

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


def name_of(m: Any, kind: str, i: int) -> str:
    """The name of MuJoCo object ``i`` of ``kind`` (``body``, ``joint``, ``site``, ``equality``, ...), or ``""``."""
    import mujoco

    return mujoco.mj_id2name(m, getattr(mujoco.mjtObj, f"mjOBJ_{kind.upper()}"), i) or ""


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
            and the message says so) or a free joint sharing its body.
    """
    model = pin.Model()
    model.name = name
    joint_of = [0] * m.nbody
    placement = [pin.SE3.Identity()] * m.nbody
    taken: set[str] = set()
    joint_names: list[str] = [""] * m.njnt
    body_frame = ["universe"] * m.nbody
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
                    raise ValueError(
                        f"body {name_of(m, 'body', b) or b!r}: a free joint must be the only joint of a top-level body"
                    )
                at, after = pin.SE3.Identity(), pin.SE3.Identity()
            elif kind == HINGE:
                at = current * pin.SE3(pin.exp3(-ref * axis), anchor)
                after = pin.SE3(np.eye(3), -anchor)
            elif kind == SLIDE:
                at, after = current * pin.SE3(np.eye(3), anchor - ref * axis), pin.SE3(np.eye(3), -anchor)
            else:
                at, after = current * pin.SE3(np.eye(3), anchor), pin.SE3(np.eye(3), -anchor)
            jname = unique(name_of(m, "joint", j) or f"joint{j}", taken)
            carrier = model.addJoint(carrier, _joint_model(kind, axis), at, jname)
            joint_names[j] = jname
            if kind in (HINGE, SLIDE) and m.jnt_limited[j]:
                lo, hi = m.jnt_range[j]
                model.lowerPositionLimit[model.joints[carrier].idx_q] = lo
                model.upperPositionLimit[model.joints[carrier].idx_q] = hi
            current = after
        joint_of[b], placement[b] = carrier, current
    frames: set[str] = {"universe"}
    for jname in joint_names:  # a JOINT frame per joint (joint couplings name them)
        jid = model.getJointId(jname)
        model.addFrame(pin.Frame(unique(jname, frames), jid, pin.SE3.Identity(), pin.FrameType.JOINT), False)
    for b in range(1, m.nbody):
        fname = unique(name_of(m, "body", b) or f"body{b}", frames)
        model.addFrame(pin.Frame(fname, joint_of[b], placement[b], pin.FrameType.BODY), False)
        body_frame[b] = fname
    site_frame = []
    for s in range(m.nsite):
        b = int(m.site_bodyid[s])
        wanted = name_of(m, "site", s) or f"site{s}"
        fname = unique(wanted if wanted not in frames else f"site:{wanted}", frames)
        at = placement[b] * se3(m.site_pos[s], m.site_quat[s])
        model.addFrame(pin.Frame(fname, joint_of[b], at, pin.FrameType.OP_FRAME), False)
        site_frame.append(fname)
    return Tree(model, tuple(joint_of), tuple(placement), tuple(body_frame), tuple(site_frame), tuple(joint_names))


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
