"""Joint values by name and configuration vectors: from one to the other."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pinocchio as pin

from pinmob.exceptions import ConfigurationError
from pinmob.model.joints import joint_id
from pinmob.screw import Array


def q_from_values(model: pin.Model, values: Mapping[str, float], base: Array, owner: str) -> Array:
    """A copy of ``base`` (nq,) with the named joints set: a value [m or rad] per one-degree joint.

    A continuous joint takes an angle (stored as its ``(cos, sin)`` pair).

    Raises:
        FrameError: an unknown joint (the message lists them).
        ConfigurationError: a value that is not a finite number, or a joint of several coordinates.
    """
    q = np.array(base, float)
    for jname, value in values.items():
        jid = joint_id(model, jname, owner)
        try:
            x = float(value)
        except (TypeError, ValueError):
            raise ConfigurationError(f"joint {jname!r}: value {value!r} is not a number") from None
        if not np.isfinite(x):
            raise ConfigurationError(f"joint {jname!r}: value {value!r} is not finite")
        joint = model.joints[jid]
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


def _kind(joint: pin.JointModel) -> str:
    """How a joint's value is read from q, one rule for every reader.

    ``value`` (one coordinate), ``angle`` (a continuous joint's (cos, sin)), ``quaternion`` (spherical or
    free: a quaternion last) or ``coordinates``.
    """
    if joint.nq == 1:
        return "value"
    if joint.nq == 2 and joint.nv == 1:  # continuous (unbounded revolute)
        return "angle"
    return "quaternion" if joint.shortname() in ("JointModelSpherical", "JointModelFreeFlyer") else "coordinates"


def _read(x: list[float], first: int, count: int, kind: str, quaternion_wxyz: bool = False) -> float | list[float]:
    """A joint's value from the coordinates x of q (:func:`_kind`): a number [m or rad], or its coordinates."""
    if kind == "value":
        return x[first]
    if kind == "angle":
        return float(np.arctan2(x[first + 1], x[first]))
    coords = x[first : first + count]
    if quaternion_wxyz and kind == "quaternion":
        coords[-4:] = coords[-1:] + coords[-4:-1]
    return coords


def joint_value(model: pin.Model, q: Array, name: str, near: float | None = None) -> float:
    """The value at q [m or rad] of the one-degree joint ``name``.

    Its coordinate, or a continuous joint's angle ``atan2(sin, cos)`` in (-pi, pi], or, with ``near``, the
    one of its values ``angle + 2 pi k`` nearest ``near`` (a path interpolated towards 4 rad reads 4, not -2.28).

    Raises:
        FrameError: no such joint (the message lists them).
        ConfigurationError: a joint of several degrees (spherical, free, planar).
    """
    joint = model.joints[joint_id(model, name)]
    kind = _kind(joint)
    if kind not in ("value", "angle"):
        raise ConfigurationError(f"joint {name!r} ({joint.shortname()}) has {joint.nv} degrees: no single value")
    value = _read(np.asarray(q, float)[joint.idx_q : joint.idx_q + joint.nq].tolist(), 0, joint.nq, kind)
    assert isinstance(value, float)  # a one-degree joint reads as a number
    if near is not None and kind == "angle":  # the turn nearest the value asked for
        value += 2.0 * np.pi * round((near - value) / (2.0 * np.pi))
    return value


#: Per joint: name, first coordinate, number of coordinates, and how its value is read (:func:`_kind`).
JointLayout = tuple[tuple[str, int, int, str], ...]


def joint_layout(model: pin.Model) -> JointLayout:
    """How :func:`values_by_name` reads each joint's value from q (computed once, kept per mechanism)."""
    return tuple(
        (str(model.names[j]), int(model.joints[j].idx_q), int(model.joints[j].nq), _kind(model.joints[j]))
        for j in range(1, model.njoints)
    )


def values_by_name(
    model: pin.Model, q: Array, quaternion_wxyz: bool = False, layout: JointLayout | None = None
) -> dict[str, float | list[float]]:
    """The joint values of q by joint name: a number per one-degree joint [m or rad], a list per other joint.

    A continuous joint gives its angle (from its ``(cos, sin)`` pair); a spherical or free joint its
    coordinates, quaternions ``(x, y, z, w)`` (Pinocchio) or ``(w, x, y, z)`` (``quaternion_wxyz``:
    MuJoCo's ``qpos`` order). ``layout``: the model's :func:`joint_layout`, when already at hand.
    """
    x = np.asarray(q, float).tolist()
    return {
        name: _read(x, first, count, kind, quaternion_wxyz)
        for name, first, count, kind in (joint_layout(model) if layout is None else layout)
    }


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
