"""Joint values by name and configuration vectors: from one to the other."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pinocchio as pin

from pinmob.exceptions import ConfigurationError, FrameError, choices
from pinmob.model.joints import joint_names
from pinmob.screw.algebra import Array


def q_from_values(model: pin.Model, values: Mapping[str, float], base: Array, owner: str) -> Array:
    """A copy of ``base`` (nq,) with the named joints set: a value [m or rad] per one-degree joint.

    A continuous joint takes an angle (stored as its ``(cos, sin)`` pair).

    Raises:
        FrameError: an unknown joint (the message lists them).
        ConfigurationError: a value that is not a finite number, or a joint of several coordinates.
    """
    q = np.array(base, float)
    for jname, value in values.items():
        if not model.existJointName(jname):
            raise FrameError(f"unknown joint {jname!r} in {owner!r}; valid: {choices(joint_names(model))}")
        try:
            x = float(value)
        except (TypeError, ValueError):
            raise ConfigurationError(f"joint {jname!r}: value {value!r} is not a number") from None
        if not np.isfinite(x):
            raise ConfigurationError(f"joint {jname!r}: value {value!r} is not finite")
        joint = model.joints[model.getJointId(jname)]
        if joint.nq == 1:
            q[joint.idx_q] = x
        elif joint.nq == 2 and joint.nv == 1:  # continuous (unbounded revolute): (cos, sin)
            q[joint.idx_q : joint.idx_q + 2] = (np.cos(x), np.sin(x))
        else:
            raise ConfigurationError(
                f"joint {jname!r} ({joint.shortname()}) has {joint.nq} coordinates: give the whole "
                "configuration vector instead of a value by name"
            )
    return q


def one_value(joint: pin.JointModel, q: Array) -> float | None:
    """A one-degree joint's value at q [m or rad], None for a joint of several degrees.

    Its coordinate, or a continuous joint's angle ``atan2(sin, cos)`` in (-pi, pi].
    """
    if joint.nq == 1:
        return float(q[joint.idx_q])
    if joint.nq == 2 and joint.nv == 1:  # continuous (unbounded revolute): (cos, sin)
        return float(np.arctan2(q[joint.idx_q + 1], q[joint.idx_q]))
    return None


def joint_value(model: pin.Model, q: Array, name: str, near: float | None = None) -> float:
    """The value at q [m or rad] of the one-degree joint ``name`` (:func:`one_value`).

    A continuous joint's angle is in (-pi, pi], or, with ``near``, the one of its values ``angle + 2 pi k``
    nearest ``near`` (a path interpolated towards 4 rad reads 4, not -2.28).

    Raises:
        FrameError: no such joint (the message lists them).
        ConfigurationError: a joint of several degrees (spherical, free, planar).
    """
    if not model.existJointName(name):
        raise FrameError(f"unknown joint {name!r}; valid: {choices(joint_names(model))}")
    joint = model.joints[model.getJointId(name)]
    value = one_value(joint, q)
    if value is None:
        raise ConfigurationError(f"joint {name!r} ({joint.shortname()}) has {joint.nv} degrees: no single value")
    if near is not None and joint.nq == 2:  # continuous: the turn nearest the value asked for
        value += 2.0 * np.pi * round((near - value) / (2.0 * np.pi))
    return value


#: Per joint: name, first coordinate, number of coordinates, and how its value is read: ``value`` (one
#: coordinate), ``angle`` (a continuous joint's (cos, sin)), ``quaternion`` (spherical or free: a quaternion
#: last) or ``coordinates``.
JointLayout = tuple[tuple[str, int, int, str], ...]


def joint_layout(model: pin.Model) -> JointLayout:
    """How :func:`values_by_name` reads each joint's value from q (computed once, kept per mechanism)."""
    out = []
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nq == 1:
            kind = "value"
        elif joint.nq == 2 and joint.nv == 1:
            kind = "angle"
        elif joint.shortname() in ("JointModelSpherical", "JointModelFreeFlyer"):
            kind = "quaternion"
        else:
            kind = "coordinates"
        out.append((str(model.names[j]), int(joint.idx_q), int(joint.nq), kind))
    return tuple(out)


def values_by_name(
    model: pin.Model, q: Array, quaternion_wxyz: bool = False, layout: JointLayout | None = None
) -> dict[str, float | list[float]]:
    """The joint values of q by joint name: a number per one-degree joint [m or rad], a list per other joint.

    A continuous joint gives its angle (from its ``(cos, sin)`` pair); a spherical or free joint its
    coordinates, quaternions ``(x, y, z, w)`` (Pinocchio) or ``(w, x, y, z)`` (``quaternion_wxyz``:
    MuJoCo's ``qpos`` order). ``layout``: the model's :func:`joint_layout`, when already at hand.
    """
    x = np.asarray(q, float).tolist()
    out: dict[str, float | list[float]] = {}
    for name, i, n, kind in joint_layout(model) if layout is None else layout:
        if kind == "value":
            out[name] = x[i]
        elif kind == "angle":
            out[name] = float(np.arctan2(x[i + 1], x[i]))
        else:
            coords = x[i : i + n]
            if quaternion_wxyz and kind == "quaternion":
                coords[-4:] = coords[-1:] + coords[-4:-1]
            out[name] = coords
    return out


def parse_joint_values(text: str, option: str = "joint values") -> dict[str, float]:
    """``"a=0.1,b=-2"`` -> ``{"a": 0.1, "b": -2.0}`` (``--joints``, and the ends of a joint path).

    Args:
        text: ``name=value`` items [rad or m] separated by commas.
        option: how the message calls the text (e.g. ``--joints``).

    Raises:
        ConfigurationError: an item that is not ``name=number``.
    """
    out: dict[str, float] = {}
    for item in (t.strip() for t in text.split(",")):
        name, sep, value = item.partition("=")
        try:
            number = float(value)
        except ValueError:
            number = float("nan")
        if not item or not sep or not name.strip() or not np.isfinite(number):
            raise ConfigurationError(
                f"{option} {text!r}: {item!r} is not name=value (a finite number [rad or m]); e.g. a=0.1,b=-0.2"
            )
        out[name.strip()] = number
    return out
