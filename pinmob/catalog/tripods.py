"""Tripods: Tsai's 3-UPU, the 3-UPU wrist, Hunt's 3-RPS and the 3-PRS."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..builder import MechanismBuilder, polar, radial, rotation, rpy
from .registry import Definition, register
from .sources import CARRETERO, HAND, HUNT, KAROUIA, LEE_SHAH, TSAI, ZBG, expect, limb_pairs, pose


@register("3upu")
def _tsai_3upu() -> Definition:
    big_r, small_r, h = 0.3, 0.15, 0.3
    b = MechanismBuilder(
        "3-UPU",
        f"Tsai's translational 3-UPU: base U centres on a circle R = {big_r} m, platform U centres on a circle "
        f"r = {small_r} m at height {h} m (reference), limbs at 0, 120, 240 deg. Each limb: U (first axis t = tangent "
        "of the base circle, second axis n normal to t and to the leg), prismatic leg (actuated), U (axes n then t, "
        "the last one fixed to the platform): the two inner axes are parallel and the two outer axes are parallel, "
        "Tsai's condition for pure translation. Each limb exerts one constraint couple along t x n.",
    )
    for name, theta in limb_pairs():
        e, t = radial(theta)
        base, vertex = polar(big_r, theta), polar(small_r, theta, h)
        leg = vertex - base
        n = np.cross(t, leg)
        limb = b.limb(name)
        limb.universal("u1", at=base, axis1=t, axis2=n)
        limb.prismatic("leg", at=base, axis=leg, actuated=True)
        limb.universal("u2", at=vertex, axis1=n, axis2=t)
        limb.tip(at=[0.0, 0.0, h])
    confs: dict[str, dict[str, Any]] = {
        "generic": {"pose": pose([0.04, -0.03, 0.33]), "expected": expect(3, "3T", TSAI)},
        "constraint-singular": {
            "pose": pose([0.0, 0.0, 0.0]),
            "seed": {f"{x}_u1a": 1.0 for x in "ABC"},
            "expected": expect(4, "3T1R", f"{HAND} (the three limb couples lie in the base plane); {ZBG}"),
        },
    }
    return b, confs, None


@register("3upu_wrist")
def _upu_wrist() -> Definition:
    big_r, small_r, h, centre_h = 0.3, 0.12, 0.25, 0.5
    centre = np.array([0.0, 0.0, centre_h])
    b = MechanismBuilder(
        "3-UPU-wrist",
        f"A spherical 3-UPU (Karouia-Herve type wrist): base U centres on a circle R = {big_r} m, platform U centres "
        f"on a circle r = {small_r} m at height {h} m turned by 60 deg, limbs at 0, 120, 240 deg. In each limb the "
        f"first base axis and the last platform axis pass through the fixed centre O = (0, 0, {centre_h}) m and the two "
        "inner axes are parallel (normal to the plane of O and the leg). Each limb exerts a constraint force through O "
        "along its inner axes, so the platform can only turn about O.",
    )
    for name, theta in limb_pairs():
        base, vertex = polar(big_r, theta), polar(small_r, theta + np.pi / 3, h)
        n = np.cross(centre - base, centre - vertex)
        limb = b.limb(name)
        limb.universal("u1", at=base, axis1=centre - base, axis2=n)
        limb.prismatic("leg", at=base, axis=vertex - base, actuated=True)
        limb.universal("u2", at=vertex, axis1=n, axis2=centre - vertex)
        limb.tip(at=[0.0, 0.0, h])
    rot = rotation([1.0, 0.5, 0.2], 0.25)
    origin = centre + rot @ (np.array([0.0, 0.0, h]) - centre)
    confs = {
        "generic": {"pose": pose(origin, rpy(rot)), "expected": expect(3, "3R", KAROUIA)},
        "home": {"joints": {}, "expected": expect(3, "3R", KAROUIA)},
    }
    return b, confs, None


def _rps_like(b: MechanismBuilder, big_r: float, small_r: float, h: float, slider: bool) -> None:
    for name, theta in limb_pairs():
        e, t = radial(theta)
        base, vertex = polar(big_r, theta), polar(small_r, theta, h)
        limb = b.limb(name)
        if slider:
            limb.prismatic("slider", at=base, axis=[0, 0, 1], actuated=True)
            limb.revolute("r", at=base, axis=t)
        else:
            limb.revolute("r", at=base, axis=t)
            limb.prismatic("leg", at=base, axis=vertex - base, actuated=True)
        limb.spherical("s", at=vertex, axes=(e, t, (0, 0, 1)))
        limb.tip(at=[0.0, 0.0, h])


#: tilt about x of the ``tilted-x`` configurations [rad]
TILT = float(np.deg2rad(20.0))


def _rps_confs(b: MechanismBuilder, fixed: dict[str, float], small_r: float, h: float, source: str) -> dict[str, Any]:
    """Generic (actuators moved, passive joints solved), home, and the tilted-x pose of the 3-RPS / 3-PRS.

    tilted-x: the platform turned by TILT about x with its centre at (r (1 - cos TILT) / 2, 0, h):
    every sphere centre then lies in the vertical plane of its limb (t_i . s_i = 0), the only
    condition both mechanisms put on the platform pose (derived in tests/test_models.py).
    """
    principal = (
        "principal screws (pinmob's convention): T along z, one free twist with horizontal angular velocity, a "
        "screw whose pitch (the parasitic motion) no free translation cancels, and one rotation; the same twist "
        f"space also has a basis of T z and two pure rotations with tilted axes, the 1T2R of {source}"
    )
    return {
        "generic": {"joints": b.closed_joints(fixed), "expected": expect(3, "1T1R1H", f"{HAND}: {principal}")},
        "home": {"joints": {}, "expected": expect(3, "1T2R", source)},
        "tilted-x": {
            "pose": pose([small_r * (1.0 - np.cos(TILT)) / 2.0, 0.0, h], [TILT, 0.0, 0.0]),
            "expected": expect(
                3, "1T1R1H", f"{HAND}: the screw is about x through the centre, pitch r sin(20 deg) / 2; {principal}"
            ),
        },
    }


@register("3rps")
def _three_rps() -> Definition:
    big_r, small_r, h = 0.25, 0.12, 0.3
    b = MechanismBuilder(
        "3-RPS",
        f"Hunt's 3-RPS: base revolutes tangent to a circle R = {big_r} m at 0, 120, 240 deg, actuated prismatic legs, "
        f"spherical joints (three revolutes) at the platform vertices on a circle r = {small_r} m; reference with the "
        f"platform parallel to the base at height {h} m. Each limb exerts a force through its sphere centre parallel "
        "to its base revolute axis: the platform heaves along z and tilts, while x, y and the turn about z follow as "
        "parasitic motions. tilted-x: turned by 20 deg about x, centre shifted by r (1 - cos 20 deg) / 2 along x.",
    )
    _rps_like(b, big_r, small_r, h, slider=False)
    confs = _rps_confs(b, {"A_leg": 0.04, "B_leg": -0.02, "C_leg": 0.01}, small_r, h, f"{HUNT}; {LEE_SHAH}")
    return b, confs, None


@register("3prs")
def _three_prs() -> Definition:
    big_r, small_r, h = 0.3, 0.12, 0.25
    b = MechanismBuilder(
        "3-PRS",
        f"3-PRS: actuated vertical sliders on a circle R = {big_r} m at 0, 120, 240 deg, revolutes tangent to that "
        f"circle, fixed-length links to spherical joints at the platform vertices on a circle r = {small_r} m, "
        f"{h} m above the sliders at the reference. Each limb exerts a force through its sphere centre parallel to its "
        "revolute axis: 1T2R with parasitic motions, as the 3-RPS. tilted-x: turned by 20 deg about x, centre "
        "shifted by r (1 - cos 20 deg) / 2 along x.",
    )
    _rps_like(b, big_r, small_r, h, slider=True)
    confs = _rps_confs(b, {"A_slider": 0.05, "B_slider": -0.03, "C_slider": 0.0}, small_r, h, CARRETERO)
    return b, confs, None
