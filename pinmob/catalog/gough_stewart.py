"""The 6-UPS Gough-Stewart platform and Fichter's actuation (Type II) singular pose."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..builder import MechanismBuilder
from .registry import Definition, register
from .sources import FICHTER


def gough_stewart(
    name: str, description: str, base_r: float, plat_r: float, half_angle: float, height: float
) -> MechanismBuilder:
    """A 6-UPS Gough-Stewart platform at its home pose (all joints zero).

    Leg i (i = 0..5, k = i // 2, sign s = -1 for even i, +1 for odd i) runs from
    the base point at angle ``120 k deg + s * half_angle`` on the circle of radius
    ``base_r`` to the platform point at angle ``120 k deg + s * (60 deg -
    half_angle)`` on the circle of radius ``plat_r``, ``height`` above the base:
    both hexagons have the same layout (joints in pairs ``2 * half_angle``
    apart), the platform's turned by 60 deg. U at the base (first axis
    horizontal, normal to the leg's horizontal projection; second normal to the
    first and to the leg), an actuated prismatic along the leg, S at the
    platform as three revolutes about world z, x, y at the home pose (the first
    takes the platform's yaw, so a yaw of 90 deg is far from the joint's own
    gimbal lock). The platform frame is at the platform centre.
    """
    b = MechanismBuilder(name, description)
    z = np.array([0.0, 0.0, 1.0])
    for i in range(6):
        k, s = i // 2, (-1.0 if i % 2 == 0 else 1.0)
        base_angle = 2 * np.pi / 3 * k + s * half_angle
        plat_angle = 2 * np.pi / 3 * k + s * (np.pi / 3 - half_angle)
        a = base_r * np.array([np.cos(base_angle), np.sin(base_angle), 0.0])
        p = plat_r * np.array([np.cos(plat_angle), np.sin(plat_angle), 0.0]) + height * z
        leg = (p - a) / np.linalg.norm(p - a)
        u1 = np.cross(z, leg)
        u1 /= np.linalg.norm(u1)
        limb = b.limb("ABCDEF"[i])
        limb.universal("u", at=a, axis1=u1, axis2=np.cross(u1, leg))
        limb.prismatic("leg", at=a, axis=leg, actuated=True)
        limb.spherical("s", at=p, axes=((0, 0, 1), (1, 0, 0), (0, 1, 0)))
        limb.tip(at=height * z)
    return b


@register("6ups")
def _six_ups() -> Definition:
    base_r, plat_r, half, height = 0.5, 0.3, float(np.deg2rad(10.0)), 0.4
    b = gough_stewart(
        "6-UPS",
        f"Gough-Stewart platform (6-UPS): base joints on a circle of radius {base_r} m, platform joints on a circle of "
        f"radius {plat_r} m, joints in pairs 20 deg apart on both (the same hexagon layout, the platform's turned by "
        f"60 deg), platform {height} m above the base at home. Six actuated legs; no constraint wrench (3T3R). "
        "Turned by 90 deg about the vertical it is at an actuation (Type II) singularity.",
        base_r,
        plat_r,
        half,
        height,
    )
    twist = {f"{x}_sa": 1.5 for x in "ABCDEF"}
    confs: dict[str, dict[str, Any]] = {
        "generic": {
            "pose": {"xyz": [0.03, -0.02, height + 0.02], "rpy": [0.05, -0.04, 0.1]},
            "expected": {
                "dof": 6,
                "motion_type": "3T3R",
                "source": "Gruebler-Kutzbach: 6 legs of 6 joints, no constraint",
            },
        },
        "home": {
            "joints": {},
            "expected": {
                "dof": 6,
                "motion_type": "3T3R",
                "source": "Gruebler-Kutzbach: 6 legs of 6 joints, no constraint",
            },
        },
        "type2": {
            "pose": {"xyz": [0.0, 0.0, height], "rpy": [0.0, 0.0, float(np.pi / 2)]},
            "seed": twist,
            "expected": {
                "dof": 6,
                "motion_type": "3T3R",
                "source": "free mobility unchanged (no constraint); actuation singular: " + FICHTER,
            },
        },
    }
    return b, confs, None
