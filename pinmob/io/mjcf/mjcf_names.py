"""The names pinmob shows for a compiled MuJoCo model's objects: the file's own, and ``#`` labels for unnamed ones.

MuJoCo keeps one namespace per kind of object (a body and a joint may share a name) and lets most
objects go unnamed, known by their id. pinmob shows each object by the name the file gives it, and
an unnamed one by a label that says which MuJoCo object it is (:func:`label`):

- a joint: ``#k``, k its MuJoCo joint id. The keys of ``joint_values`` are so usable with MuJoCo:
  ``mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)`` finds a named joint, and ``#k`` is joint
  id k (``data.joint(k)``);
- any other kind: ``<kind>#k``: ``body#3``, ``site#0``, ``equality#1`` (an equality's closure),
  ``key#0`` (a keyframe's configuration), ``actuator#2``, ``tendon#0``.

Pinocchio's frames share one namespace across kinds (:func:`add_frame`): a body's ``BODY`` frame and a
joint's ``JOINT`` frame may share their name (a frame asked for by name is then the body's, as with a
URDF link and joint called alike); a site's frame is its name, or ``site:<name>`` when a body or a
joint has that name; the closure of equality ``c`` adds the frames ``c#a`` and ``c#b``
(:func:`closure_frames`). A file whose own name is a label pinmob gives another object (a joint named
``#2`` beside unnamed joint 2, a site named ``loop#a`` beside equality ``loop``) is refused with one
line naming both, rather than shown with two things under one name.
"""

from __future__ import annotations

from typing import Any

import pinocchio as pin


def name_of(m: Any, kind: str, i: int) -> str:
    """The name of MuJoCo object ``i`` of ``kind`` (``body``, ``joint``, ``site``, ``equality``, ...), or ``""``."""
    import mujoco

    return mujoco.mj_id2name(m, getattr(mujoco.mjtObj, f"mjOBJ_{kind.upper()}"), i) or ""


def label(m: Any, kind: str, i: int) -> str:
    """The name of MuJoCo object ``i`` of ``kind``, or its label when unnamed: ``#i`` for a joint, ``<kind>#i`` else."""
    return name_of(m, kind, i) or f"{'' if kind == 'joint' else kind}#{i}"


def labels(m: Any, kind: str, count: int, reserved: tuple[str, ...] = ()) -> tuple[str, ...]:
    """:func:`label` of each of the ``count`` objects of ``kind``, checked to be distinct.

    Raises:
        ValueError: an object named as pinmob labels another unnamed one, or with a ``reserved`` name
            (``universe``: Pinocchio's world joint); the message names both.
    """
    out = tuple(label(m, kind, i) for i in range(count))
    seen: dict[str, int] = {}
    for i, name in enumerate(out):
        if name in reserved:
            raise ValueError(f"{kind} {i} is named {name!r}, a name pinmob keeps for its own use; rename it")
        if name in seen:
            first, second = (seen[name], i) if name_of(m, kind, i) == "" else (i, seen[name])
            raise ValueError(
                f"{kind} {first} is named {name!r}, the name pinmob gives unnamed {kind} {second}; rename it"
            )
        seen[name] = i
    return out


#: The kinds of MuJoCo objects pinmob shows, with the ``MjModel`` attribute counting them.
KINDS = {
    "joint": "njnt",
    "body": "nbody",
    "site": "nsite",
    "equality": "neq",
    "key": "nkey",
    "actuator": "nu",
    "tendon": "ntendon",
}
#: Names pinmob keeps for its own use, per kind (Pinocchio's world joint; MuJoCo's qpos0 beside a key named reference).
RESERVED = {"joint": ("universe",), "key": ("#reference",)}


def check_labels(m: Any) -> None:
    """Check that the :func:`labels` of every kind of object pinmob shows are distinct.

    Raises:
        ValueError: as :func:`labels`.
    """
    for kind, count in KINDS.items():
        labels(m, kind, int(getattr(m, count)), RESERVED.get(kind, ()))


#: What holds a frame of each type, for messages.
HOLDERS = {
    pin.FrameType.BODY: "a body",
    pin.FrameType.JOINT: "a joint",
    pin.FrameType.OP_FRAME: "a site or a closure",
    pin.FrameType.FIXED_JOINT: "the world (Pinocchio's 'universe')",
}


def add_frame(model: pin.Model, frame: pin.Frame, what: str) -> int:
    """Add ``frame`` to ``model`` (its index), its name checked against the frames already there.

    Pinocchio keeps one frame per name and type (adding a second returns the first, silently) and a
    frame asked for by name is the ``BODY`` one where several share it: so a name may be shared only by
    one body and one joint.

    Args:
        model: the model (changed in place).
        frame: the frame to add.
        what: the object the frame stands for, for the message (``site 'tip'``).

    Raises:
        ValueError: the name is taken (the message names the frame and ``what``).
    """
    kinds = {f.type for f in model.frames if f.name == frame.name}
    shared = {pin.FrameType.BODY, pin.FrameType.JOINT}
    if kinds and (frame.type in kinds or not kinds | {frame.type} <= shared):
        holders = " or ".join(sorted({HOLDERS.get(k, str(k)) for k in kinds}))
        raise ValueError(f"{what}: its frame name {frame.name!r} is already the frame of {holders}; rename it")
    return int(model.addFrame(frame, False))


def site_frame(name: str, model: pin.Model) -> str:
    """The frame name of a site: its own, or ``site:<name>`` when a body or joint frame has it."""
    taken = any(f.name == name and f.type in (pin.FrameType.BODY, pin.FrameType.JOINT) for f in model.frames)
    return f"site:{name}" if taken else name


def closure_frames(name: str) -> tuple[str, str]:
    """The names of the two frames of closure ``name``: ``name#a`` and ``name#b``."""
    return f"{name}#a", f"{name}#b"
