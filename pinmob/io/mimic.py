"""URDF ``<mimic>`` joints as couplings: ``q_j = multiplier * q_m + offset``, one closure row each.

A URDF joint ``j`` with ``<mimic joint="m" multiplier="k" offset="c"/>`` (defaults ``k = 1``, ``c = 0``)
moves with joint ``m``. pinmob builds the Pinocchio model without Pinocchio's mimic joints (every joint
keeps its own coordinate, so ``nv`` counts every joint as MuJoCo does) and adds one ``joint`` coupling per
mimic, ``q_j - 0 = c + k (q_m - 0)`` (:func:`pinmob.model.closure.make_coupling`, MuJoCo's ``<equality
joint>`` with ``polycoef = (c, k)``): a closure row like any other, in the DoF, the redundancy, the
actuation (an actuated driver moves its mimics; an actuated mimic holds its driver) and the finite
analysis (a linear coupling holds exactly at every order).

:func:`mimic_couplings` is used wherever pinmob reads a URDF: a plain URDF (with or without
onshape-to-robot's closing frames), an Extended URDF and the URDF a pinmob TOML file names.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import pinocchio as pin

from pinmob.exceptions import MechanismFileError, PinmobError
from pinmob.model import Closure, make_coupling
from pinmob.name_matching import choices

#: The name of the coupling of mimic joint ``j``: ``mimic_<j>``.
PREFIX = "mimic_"


def mimic_joints(urdf: Path, source: str | None = None) -> list[tuple[str, str, float, float]]:
    """``(joint, driver, multiplier, offset)`` of each ``<joint>`` of the URDF with a ``<mimic>`` element, in file order.

    Raises:
        MechanismFileError: a mimic without a ``joint`` attribute, or a multiplier or offset that is not a finite
            number (naming the file and the joint).
    """
    text = urdf.read_bytes() if source is None else source.encode()  # source: the URDF a xacro file expanded to
    if b"mimic" not in text:
        return []
    import xml.etree.ElementTree as ET  # only for URDFs that mention mimic (urdfdom parsed the file already)

    found = []
    for joint in ET.fromstring(text).findall("joint"):  # the robot's joints (a <transmission> has <joint> too)
        mimic = joint.find("mimic")
        if mimic is None:
            continue
        name = joint.get("name", "")
        driver = mimic.get("joint", "")
        if not driver:
            raise MechanismFileError(f'{urdf}: joint {name!r}: <mimic> needs a joint="..." attribute (the driver)')
        values = []
        for key, default in (("multiplier", 1.0), ("offset", 0.0)):
            raw = mimic.get(key)
            try:
                value = default if raw is None else float(raw)
            except ValueError:
                value = math.nan
            if not math.isfinite(value):
                raise MechanismFileError(f"{urdf}: joint {name!r}: <mimic {key}={raw!r}> must be a finite number")
            values.append(value)
        found.append((name, driver, values[0], values[1]))
    return found


def mimic_couplings(urdf: Path, model: pin.Model, source: str | None = None) -> list[Closure]:
    """One ``joint`` coupling ``mimic_<j>``: ``q_j = multiplier * q_m + offset`` per mimic joint of ``urdf`` in ``model``.

    ``model`` is the URDF's model built without Pinocchio's mimic joints (its joints may have been rebuilt, as
    an Extended URDF's ``joint_type`` does). A mimic on a fixed joint, or driven by one, couples no coordinate
    (a fixed joint has none, and is not a joint of the model): it is left out, as MuJoCo's URDF importer
    leaves it, with one warning naming every such mimic.

    Raises:
        MechanismFileError: a mimic or driver that is no joint of the URDF at all, or not a one-degree
            (revolute or prismatic) joint (a continuous joint's coordinate is a point on a circle).
    """
    out, fixed = [], []
    joints = list(model.names)[1:]
    declared = None
    for joint, driver, multiplier, offset in mimic_joints(urdf, source):
        if joint == driver:
            raise MechanismFileError(f"{urdf}: joint {joint!r} mimics itself; name another joint as its driver")
        if joint not in joints or driver not in joints:
            declared = urdf_joints(urdf, source) if declared is None else declared
            missing = [(role, n) for role, n in (("joint", joint), ("driver", driver)) if n not in declared]
            if missing:
                role, name = missing[0]
                raise MechanismFileError(
                    f"{urdf}: mimic joint {joint!r}: its {role} {name!r} is not a joint of the URDF; "
                    f"moving joints: {choices(joints)}"
                )
            fixed.append(joint)
            continue
        for role, name in (("joint", joint), ("driver", driver)):
            jm = model.joints[model.getJointId(name)]
            if jm.nq != 1 or jm.nv != 1:
                raise MechanismFileError(
                    f"{urdf}: mimic joint {joint!r}: its {role} {name!r} ({jm.shortname()}) is not a revolute or "
                    "prismatic joint; a mimic couples one-coordinate joints (a continuous joint's coordinate is an "
                    "angle on a circle: give it limits and type revolute)"
                )
        try:
            out.append(make_coupling(model, PREFIX + joint, (joint, driver), (offset, multiplier), (0.0, 0.0)))
        except PinmobError as exc:
            raise MechanismFileError(f"{urdf}: mimic joint {joint!r}: {exc}") from None
    if fixed:
        warnings.warn(
            f"{urdf.name}: <mimic> of {len(fixed)} joint(s) left out, the joint or its driver being fixed (no "
            f"coordinate to couple): {', '.join(fixed)}",
            stacklevel=4,
        )
    return out


def urdf_joints(urdf: Path, source: str | None = None) -> set[str]:
    """The names of every ``<joint>`` of the URDF (or of its text ``source``), fixed ones included."""
    import xml.etree.ElementTree as ET

    text = urdf.read_bytes() if source is None else source.encode()
    return {j.get("name", "") for j in ET.fromstring(text).findall("joint")}


def unique(path: Path, closures: list[Closure]) -> list[Closure]:
    """``closures`` when their names are unique; else a :class:`MechanismFileError` naming the repeated one.

    A mimic coupling is named ``mimic_<joint>``: a loop of the file with that name would hide it.
    """
    seen: set[str] = set()
    for c in closures:
        if c.name in seen:
            raise MechanismFileError(
                f"{path}: two closures named {c.name!r} (mimic joint couplings are named {PREFIX}<joint>); rename "
                "the file's loop"
            )
        seen.add(c.name)
    return closures
