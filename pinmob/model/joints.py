"""Joints and frames of a Pinocchio model: velocity indices, unit masks, limits, angles, configuration vectors.

Plain functions of a ``pin.Model`` (no mechanism): what every layer above needs
to tell lengths from angles, find a joint or a frame by name, and check a
configuration vector; and a copy of a model with some joints rebuilt (:func:`with_joints`).
"""

from __future__ import annotations

import functools
from collections.abc import Iterable, Mapping, Sequence

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from pinmob.exceptions import ConfigurationError, FrameError
from pinmob.model.data_pool import borrowed
from pinmob.name_matching import choices, did_you_mean
from pinmob.screw import Array, Mask

#: Integer index array.
IndexArray = NDArray[np.intp]
#: The limit vectors of a ``pin.Model`` :func:`with_joints` copies: per coordinate (position) and per velocity
#: (effort, velocity); Pinocchio 4's others (lower effort and velocity, friction, damping, margin) are not copied.
LIMITS = ("lowerPositionLimit", "upperPositionLimit", "effortLimit", "velocityLimit")


def with_joints(
    model: pin.Model, joint_models: Mapping[int, pin.JointModel], limits: Sequence[str] = LIMITS
) -> pin.Model:
    """A copy of ``model`` with joint ``j`` rebuilt as ``joint_models[j]`` (same name, parent, placement and body).

    Joint and frame indices are kept, every frame is copied as it is, and so are the name and the gravity. The
    joints kept keep their ``limits`` (names of :data:`LIMITS`, all by default); the limits not copied, and all
    those of a rebuilt joint, are the ones ``pin.Model.addJoint`` gives (those of :data:`LIMITS`: the largest
    float, either sign).
    """
    out = pin.Model()
    out.name = model.name
    out.gravity = model.gravity
    for j in range(1, model.njoints):
        kept = j not in joint_models
        added = out.addJoint(
            int(model.parents[j]),
            model.joints[j] if kept else joint_models[j],
            model.jointPlacements[j],
            model.names[j],
        )
        out.appendBodyToJoint(added, model.inertias[j], pin.SE3.Identity())
        if kept:
            src, dst = model.joints[j], out.joints[added]
            for name in limits:
                q = name.endswith("PositionLimit")
                start, size, at = (src.idx_q, src.nq, dst.idx_q) if q else (src.idx_v, src.nv, dst.idx_v)
                getattr(out, name)[at : at + size] = getattr(model, name)[start : start + size]
    for f in list(model.frames)[1:]:
        out.addFrame(pin.Frame(f), False)
    return out


def _exists(model: pin.Model, name: str) -> bool:
    """``model.existFrame(name)``; False for a str no frame is named (a lone surrogate, which Pinocchio cannot take)."""
    try:
        return bool(model.existFrame(name))
    except UnicodeEncodeError:  # e.g. "\udcff", a command-line byte that is not UTF-8
        return False


def frame_id(model: pin.Model, name: str) -> int:
    """Index of frame ``name`` (exactly); a :class:`FrameError` suggesting close names and listing the frames otherwise.

    Several frames may share a name (a URDF link and a joint called alike): the BODY frame (the link) is meant.
    """
    if not _exists(model, name):
        names = [f.name for f in model.frames]
        raise FrameError(
            f"no frame {name!r} in model {model.name!r}{did_you_mean(name, names)}; valid frames: {choices(names)}"
        )
    try:
        return model.getFrameId(name)
    except ValueError:  # "Several frames match the filter"
        ids = [i for i, f in enumerate(model.frames) if f.name == name]
        return next((i for i in ids if model.frames[i].type == pin.FrameType.BODY), ids[0])


def frame_name(model: pin.Model, name: str) -> str:
    """The frame ``name`` stands for, matched ignoring case where that is unambiguous (a name typed by a user).

    Raises:
        FrameError: no such frame (the message suggests close names and lists the frames).
    """
    same = [f.name for f in model.frames if f.name.casefold() == name.casefold()]
    if _exists(model, name) or len(same) != 1:
        frame_id(model, name)  # the name itself, or the error
        return name
    return same[0]


def joint_names(model: pin.Model) -> list[str]:
    """The model's joint names, without ``universe``."""
    return list(model.names)[1:]


def has_joint(model: pin.Model, name: str) -> bool:
    """True when ``name`` is one of the model's :func:`joint_names` (``universe``, Pinocchio's joint 0, is not).

    ``model.existJointName`` for any str: one Pinocchio cannot take (UTF-8 only), e.g. with a lone surrogate
    (``chr(0xD800)``, or ``chr(0xDCFF)`` for a command-line byte that is not UTF-8), names no joint.
    """
    try:
        return name != "universe" and bool(model.existJointName(name))
    except UnicodeEncodeError:
        return False


def joint_id(model: pin.Model, name: str, owner: str = "") -> int:
    """Index of joint ``name`` (:func:`has_joint`); ``owner`` names what asks, in the message.

    Raises:
        FrameError: no such joint (the message suggests close names and lists the joints).
    """
    if not has_joint(model, name):
        where, names = f" in {owner!r}" if owner else "", joint_names(model)
        raise FrameError(f"unknown joint {name!r}{where}{did_you_mean(name, names)}; valid: {choices(names)}")
    return int(model.getJointId(name))


def velocity_indices(model: pin.Model, joint_ids: Iterable[int]) -> Array:
    """Velocity indices of the given joints (by index), in the given order."""
    parts = [np.arange(model.joints[j].idx_v, model.joints[j].idx_v + model.joints[j].nv) for j in joint_ids]
    return np.concatenate(parts).astype(int) if parts else np.zeros(0, int)


def one_degree_indices(model: pin.Model, names: Iterable[str], owner: str) -> Array:
    """Velocity indices of one-degree joints by name; ``owner`` names the model in messages.

    Raises:
        FrameError: an unknown joint (the message lists them).
        ConfigurationError: a joint with more than one degree of freedom.
    """
    out = []
    for name in names:
        joint = model.joints[joint_id(model, name, owner)]
        if joint.nv != 1:
            raise ConfigurationError(
                f"joint {name!r} ({joint.shortname()}) has {joint.nv} degrees of freedom; only one-degree joints "
                "can be actuated here"
            )
        out.append(joint.idx_v)
    return np.array(out, int)


def motion_subspaces(model: pin.Model) -> tuple[tuple[int, Array], ...]:
    """(joint index, motion subspace S (6, nv_j), read-only) of every joint with a velocity, at the neutral configuration.

    Pinocchio's own ``S`` of each joint (``forwardKinematics`` at ``pin.neutral``), cached per model object and
    size (a model only grows by adding joints): the file readers check the axes with it
    (:func:`pinmob.io.urdf.check_axes`), the masks below read it.
    """
    return _subspaces(model, model.njoints, model.nq, model.nv)


@functools.lru_cache(maxsize=16)
def _subspaces(model: pin.Model, njoints: int, nq: int, nv: int) -> tuple[tuple[int, Array], ...]:
    with borrowed(model) as data:  # pooled: the model's first configuration takes it next
        pin.forwardKinematics(model, data, pin.neutral(model))
        out = [(j, np.array(data.joints[j].S).reshape(6, -1)) for j in range(1, model.njoints) if model.joints[j].nv]
    for _, sub in out:
        sub.flags.writeable = False
    return tuple(out)


def _columns(model: pin.Model) -> list[tuple[int, int, Array]]:
    """(idx_q, idx_v, motion subspace S (6, nv_j)) of every joint with a velocity, at the neutral configuration."""
    out = []
    for j, sub in motion_subspaces(model):
        joint = model.joints[j]
        out.append((joint.idx_q if joint.nq == joint.nv else -1, joint.idx_v, sub))
    return out


def linear_velocity_mask(model: pin.Model) -> Mask:
    """(nv,) True where a velocity component is a translation [m/s] (prismatic, free-flyer linear part).

    Read from each joint's motion subspace at the neutral configuration: a
    column with no angular part is a translation. Cached per model (read-only).
    """
    return _masks(model, model.njoints, model.nq, model.nv)[0]


def angle_mask(model: pin.Model) -> Mask:
    """(nq,) True where a configuration coordinate is a revolute angle [rad].

    A coordinate is an angle when its joint has one coordinate per velocity
    (not a quaternion or a (cos, sin) pair) and its motion-subspace column is
    a pure rotation: revolute joints and composites of revolutes. Cached per model (read-only).
    """
    return _masks(model, model.njoints, model.nq, model.nv)[1]


@functools.lru_cache(maxsize=16)
def _masks(model: pin.Model, njoints: int, nq: int, nv: int) -> tuple[Mask, Mask]:
    """:func:`linear_velocity_mask` and :func:`angle_mask`, cached per model object and size."""
    linear, angle = np.zeros(nv, bool), np.zeros(nq, bool)
    columns = _columns(model)
    if columns:  # the norms of every joint's columns at once: a joint's are those of its slice
        stacked = np.hstack([sub for _, _, sub in columns])
        lin, ang = np.linalg.norm(stacked[:3], axis=0), np.linalg.norm(stacked[3:], axis=0)
        start = 0
        for iq, iv, sub in columns:
            k = sub.shape[1]
            linear[iv : iv + k] = ang[start : start + k] < 1e-12
            if iq >= 0:
                angle[iq : iq + k] = (lin[start : start + k] < 1e-12) & (ang[start : start + k] > 0)
            start += k
    linear.flags.writeable = angle.flags.writeable = False
    return linear, angle


def velocity_spans(model: pin.Model) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The joints with a velocity (indices in 1..njoints-1) and where each one's velocity components start.

    Cached per model (read-only); the components of joint ``joints[i]`` are
    ``starts[i] : starts[i] + nv_i``, in increasing order.
    """
    return _spans(model, model.njoints, model.nq, model.nv)


@functools.lru_cache(maxsize=16)
def _spans(model: pin.Model, njoints: int, nq: int, nv: int) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    moving = [j for j in range(1, njoints) if model.joints[j].nv]
    joints = np.array(moving, dtype=np.intp)
    starts = np.array([model.joints[j].idx_v for j in moving], dtype=np.intp)
    joints.flags.writeable = starts.flags.writeable = False
    return joints, starts


def wrap_angles(model: pin.Model, q: Array) -> Array:
    """Q with each revolute angle moved by a multiple of 2 pi into (-pi, pi], where its limits allow.

    When the (-pi, pi] value is outside the joint's position limits, the
    representative ``x + 2 pi k`` inside the limits with the smallest
    magnitude is taken; when there is none, the (-pi, pi] value. Limits with
    ``lower >= upper`` (a URDF ``<limit>`` without ``lower``/``upper`` reads
    as [0, 0]) count as no limits.
    """
    out = np.array(q, float)
    idx = _angles(model, model.njoints, model.nq, model.nv)
    if not idx.size:
        return out
    lower, upper = model.lowerPositionLimit[idx], model.upperPositionLimit[idx]
    x = np.pi - np.mod(np.pi - out[idx], 2 * np.pi)  # in (-pi, pi]
    for k in np.flatnonzero((lower < upper) & ((x < lower) | (x > upper))):
        inside = [x[k] + 2 * np.pi * n for n in range(-3, 4) if lower[k] <= x[k] + 2 * np.pi * n <= upper[k]]
        x[k] = min(inside, key=abs) if inside else x[k]
    out[idx] = x
    return out


def short_difference(model: pin.Model, q0: Array, q1: Array) -> Array:
    """(nv,) ``pin.difference(q0, q1)`` with every rotation component taken the short way, in (-pi, pi].

    Configurations whose angles were wrapped by :func:`wrap_angles` (a revolute joint near pi turned to
    -pi) differ by 2 pi in ``pin.difference``; this is the displacement that actually moved the joints.
    """
    d = pin.difference(model, q0, q1)
    turn = ~linear_velocity_mask(model)
    d[turn] = np.pi - np.mod(np.pi - d[turn], 2 * np.pi)
    return d


@functools.lru_cache(maxsize=16)
def _angles(model: pin.Model, njoints: int, nq: int, nv: int) -> NDArray[np.intp]:
    """Indices of the revolute angles (:func:`angle_mask`), cached per model object and size."""
    idx = np.flatnonzero(angle_mask(model))
    idx.flags.writeable = False
    return idx


def outside_limits(model: pin.Model, q: Array, tol: float = 1e-9) -> tuple[str, ...]:
    """``"name [lower, upper]"`` for each one-coordinate joint of q outside its position limits [rad or m].

    Limits with ``lower >= upper`` count as none (see :func:`wrap_angles`).

    Args:
        model: the Pinocchio model.
        q: (nq,) the configuration.
        tol: allowance [rad or m] beyond the limits.
    """
    idx, names = _one_coordinate(model, model.njoints, model.nq, model.nv)
    lower, upper = model.lowerPositionLimit[idx], model.upperPositionLimit[idx]
    x = np.asarray(q, float)[idx]
    bad = np.flatnonzero((lower < upper) & ((x < lower - tol) | (x > upper + tol)))
    return tuple(f"{names[k]} [{lower[k]:.6g}, {upper[k]:.6g}]" for k in bad)


@functools.lru_cache(maxsize=16)
def _one_coordinate(model: pin.Model, njoints: int, nq: int, nv: int) -> tuple[NDArray[np.intp], tuple[str, ...]]:
    """Coordinates of the joints with one coordinate per velocity, and each one's joint name (cached per model)."""
    idx: list[int] = []
    names: list[str] = []
    for j in range(1, njoints):
        joint = model.joints[j]
        if joint.nq == joint.nv:
            idx += range(joint.idx_q, joint.idx_q + joint.nq)
            names += [model.names[j]] * joint.nq
    out = np.array(idx, dtype=np.intp)
    out.flags.writeable = False
    return out, tuple(names)


def check_q(model: pin.Model, q: object, owner: str) -> Array:
    """Validate a configuration vector: shape (nq,), finite, normalised where needed; a float copy.

    Raises:
        ConfigurationError: wrong shape, non-finite values, or a quaternion or
            ``(cos, sin)`` pair off the unit sphere.
    """
    try:
        arr = np.array(q, dtype=float)
    except (TypeError, ValueError):
        raise ConfigurationError(
            f"configuration of {owner!r} must be an array of {model.nq} numbers, got {q!r}"
        ) from None
    if arr.shape != (model.nq,):
        raise ConfigurationError(
            f"configuration has shape {arr.shape}; {owner!r} needs shape ({model.nq},) "
            f"(nq = {model.nq}: joints {', '.join(joint_names(model))})"
        )
    bad = np.flatnonzero(~np.isfinite(arr))
    if bad.size:
        raise ConfigurationError(f"configuration has non-finite values (NaN or inf) at indices {bad.tolist()}")
    if not pin.isNormalized(model, arr, 1e-6):
        raise ConfigurationError(
            "configuration is not normalised (a quaternion or (cos, sin) pair is off the unit sphere)"
        )
    return arr
