"""Chains of revolutes: the spherical and planar 3-RRR and the Cartesian 3-PRRR."""

from __future__ import annotations

import numpy as np

from ..builder import MechanismBuilder, azimuth, polar, radial
from .registry import Definition, register
from .sources import GOSSELIN_ANGELES, HAND, KIM_TSAI, expect, limb_pairs, pose


@register("3rrr_spherical")
def _spherical_3rrr() -> Definition:
    radius, h = 0.2, 0.25
    b = MechanismBuilder(
        "3-RRR-spherical",
        f"A spherical 3-RRR: all nine revolute axes pass through the centre O = (0, 0, 0); joints drawn {radius} m from "
        f"O along their axes, limbs at 0, 120, 240 deg, platform frame {h} m above O. At the reference limb A is "
        "stretched: its three axes lie in one plane (a serial singularity); limbs B and C are not.",
    )
    for name, theta in limb_pairs():
        u1 = polar(1.0, theta, -0.6)
        u3 = polar(0.7, theta + 0.7, 0.8)
        u2 = polar(1.0, theta + 0.6, 0.0) if name != "A" else 0.5 * (u1 / np.linalg.norm(u1) + u3 / np.linalg.norm(u3))
        limb = b.limb(name)
        for label, u in (("r1", u1), ("r2", u2), ("r3", u3)):
            u = u / np.linalg.norm(u)
            limb.revolute(label, at=radius * u, axis=u, actuated=label == "r1")
        limb.tip(at=[0.0, 0.0, h])
    turned = b.closed_joints({"A_r1": 0.1, "B_r1": -0.1, "C_r1": 0.1}, seed={"A_r2": 0.3})
    confs = {
        "generic": {"joints": turned, "expected": expect(3, "3R", GOSSELIN_ANGELES)},
        "limb-A-stretched": {
            "joints": {},
            "expected": expect(2, "2R", f"{HAND}; serial (type I) singularity of {GOSSELIN_ANGELES}"),
        },
    }
    return b, confs, None


@register("3rrr_planar")
def _planar_3rrr() -> Definition:
    base_r, plat_r, arm = 0.4, 0.1, 0.2
    b = MechanismBuilder(
        "3-RRR-planar",
        f"A planar 3-RRR in the plane z = 0, all axes along z: base joints on a circle R = {base_r} m at 0, 120, 240 "
        f"deg, arms {arm} m, platform joints on a circle r = {plat_r} m. At the reference limb A is stretched (its three "
        "joints on the x axis, a serial singularity); limbs B and C are bent.",
    )
    z = [0.0, 0.0, 1.0]
    for name, theta in limb_pairs():
        base, vertex = polar(base_r, theta), polar(plat_r, theta)
        if name == "A":
            elbow = base + arm * (vertex - base) / np.linalg.norm(vertex - base)
        else:
            elbow = base + arm * radial(theta + 2.4)[0]
        limb = b.limb(name)
        limb.revolute("r1", at=base, axis=z, actuated=True)
        limb.revolute("r2", at=elbow, axis=z)
        limb.revolute("r3", at=vertex, axis=z)
        limb.tip(at=[0.0, 0.0, 0.0])
    confs = {
        "generic": {
            "pose": pose([0.03, 0.02, 0.0], [0.0, 0.0, 0.1]),
            "expected": expect(3, "2T1R", GOSSELIN_ANGELES),
        },
        "limb-A-stretched": {
            "joints": {},
            "expected": expect(2, "1T1R", f"{HAND}; serial (type I) singularity of {GOSSELIN_ANGELES}"),
        },
    }
    return b, confs, None


@register("3prrr")
def _cartesian_3prrr() -> Definition:
    b = MechanismBuilder(
        "3-PRRR",
        "Cartesian translational 3-PRRR (Kim-Tsai, Kong-Gosselin): limb A slides along x and its three revolutes are "
        "parallel to x; limbs B and C are limb A with the coordinates cycled (x -> y -> z), sliding along y and z. "
        "Each limb's revolutes form a planar chain normal to its slider, so each limb exerts two couples normal to its "
        "slider: together all three, and the platform translates, each coordinate driven by one slider.",
    )
    base_pts = {"r1": [-0.1, -0.3, 0.0], "r2": [-0.1, -0.2, 0.12], "r3": [0.0, -0.06, 0.0]}
    for k, name in enumerate("ABC"):
        perm = np.roll(np.eye(3), k, axis=0)  # x -> y -> z
        axis = perm @ [1.0, 0, 0]
        limb = b.limb(name)
        limb.prismatic("slider", at=perm @ base_pts["r1"], axis=axis, actuated=True)
        for label, p in base_pts.items():
            limb.revolute(label, at=perm @ p, axis=axis)
        limb.tip(at=[0.0, 0.0, 0.0])
    r1, r2, r3 = (np.array(base_pts[k])[1:] for k in ("r1", "r2", "r3"))
    straight = azimuth(r2 - r1) - azimuth(r3 - r2)  # limb A's knee angle (about x) that aligns its two links
    flat = b.closed_joints({"A_r2": straight})
    confs = {
        "generic": {"pose": pose([0.02, -0.01, 0.03]), "expected": expect(3, "3T", KIM_TSAI)},
        "limb-A-flat": {
            "joints": flat,
            "expected": expect(2, "2T", f"{HAND} (limb A's three revolute axes coplanar: a serial singularity)"),
        },
    }
    return b, confs, None
