"""The Delta robot: with real parallelograms (closures inside the limbs) and as the equivalent 3-RUU; the 4-RUU.

Delta limb i (at theta_i = 0, 120, 240 deg, radial unit vector e, tangent t = z x e):
an actuated revolute about t at B = R e, an arm of length a to the elbow E, and a
parallelogram of two rods of length l, S-S (three revolutes at each end), from
E +- w t on the arm to V +- w t on the platform, V = p + r e. Angles in the limb
plane are measured about t from e, positive downwards: a direction at angle psi
is ``cos(psi) e - sin(psi) z`` (the rotation about t by psi applied to e).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from pinmob.exceptions import ConfigurationError

from ..builder import MechanismBuilder, polar, radial
from .registry import Definition, register
from .sources import CLAVEL, HAND, KONG, TSAI, ZBG, expect, limb_pairs, pose

#: Delta (parallelograms): base radius R, platform radius r, arm a, rods l, half width w [m]; arm angle at reference
BASE_R, PLAT_R, ARM, ROD, HALF_WIDTH = 0.2, 0.05, 0.3, 0.4, 0.04
ARM_ANGLE = float(np.deg2rad(60.0))


def delta_limb_angles(pz: float) -> tuple[float, float]:
    """Arm angle alpha and rod angle psi [rad] of every limb with the platform centre at (0, 0, pz) [m].

    Inverse kinematics (Clavel) in the limb plane, with V - B = u e + w z (u = r - R, w = pz):
    ``|V - E|^2 = l^2`` with ``E - B = a (cos(alpha) e - sin(alpha) z)`` gives
    ``u cos(alpha) - w sin(alpha) = (u^2 + w^2 + a^2 - l^2) / (2 a) = K``, i.e.
    ``rho cos(alpha + phi) = K`` with ``rho = |(u, w)|``, ``phi = atan2(w, u)``;
    the elbow-out branch is ``alpha = -acos(K / rho) - phi``. The rod direction is V - E.

    psi is returned in [0, 2 pi): the rods point inwards (psi from about 100 deg at the bottom of the
    workspace to 180 deg with the rods horizontal, ``rods-horizontal``), so atan2's cut at +-pi would fall
    exactly on a named configuration and round-off would pick either side (values 2 pi apart on two
    machines); the cut at 0 is far from every pose used.
    """
    u, w = PLAT_R - BASE_R, pz
    k = (u**2 + w**2 + ARM**2 - ROD**2) / (2 * ARM)
    rho, phi = float(np.hypot(u, w)), float(np.arctan2(w, u))
    alpha = -float(np.arccos(np.clip(k / rho, -1.0, 1.0))) - phi
    d = np.array([u - ARM * np.cos(alpha), w + ARM * np.sin(alpha)])  # rod V - E: (e, z) components
    return alpha, float(np.mod(np.arctan2(-d[1], d[0]), 2 * np.pi))


def delta_height(alpha: float) -> float:
    """Platform height pz [m] of the symmetric pose with arm angle alpha (elbow out, V below E)."""
    elbow_r, elbow_z = BASE_R + ARM * np.cos(alpha), -ARM * np.sin(alpha)
    return float(elbow_z - np.sqrt(ROD**2 - (elbow_r - PLAT_R) ** 2))


def _symmetric_joints(pz: float) -> dict[str, float]:
    """Joint values of the symmetric pose (0, 0, pz), by hand: everything turns about t in the limb planes.

    Motor: alpha - alpha0; top S (first axis t, fixed in the arm): the rod's turn relative to the arm,
    (psi - psi0) - (alpha - alpha0); bottom S (rod to platform, which does not turn): -(psi - psi0).
    """
    alpha0, psi0 = delta_limb_angles(delta_height(ARM_ANGLE))
    alpha, psi = delta_limb_angles(pz)
    out = {}
    for name, _ in limb_pairs():
        out[f"{name}_motor"] = alpha - alpha0
        for top in (f"{name}_a_topa", f"{name}_b_topa"):
            out[top] = (psi - psi0) - (alpha - alpha0)
        out[f"{name}_a_bota"] = -(psi - psi0)
    return out


@register("delta")
def _delta() -> Definition:
    p0 = np.array([0.0, 0.0, delta_height(ARM_ANGLE)])
    b = MechanismBuilder(
        "Delta",
        f"Clavel's Delta robot with its parallelograms modelled as real loops: actuated revolutes tangent to a "
        f"circle R = {BASE_R} m at 0, 120, 240 deg, arms {ARM} m (60 deg below horizontal at the reference), "
        f"parallelograms of two S-S rods {ROD} m long, {2 * HALF_WIDTH} m apart along the motor axis, platform "
        f"circumradius {PLAT_R} m. Limb X: motor X_motor, arm, rod a (S X_a_top, S X_a_bot) to the platform; rod b "
        "is a branch from the arm (S X_b_top) whose lower end X_b_end is joined to the platform point X_b_pf by a 3d "
        "(ball) closure inside the limb. Each parallelogram transmits a force along its rods and a couple normal "
        "to its plane, n = t x d (d the rod direction); the arm's revolute leaves the couple: three couples, 3T. "
        "Each rod also spins idly about its own axis (6 idle motions).",
    )
    for name, theta in limb_pairs():
        e, t = radial(theta)
        elbow = polar(BASE_R + ARM * np.cos(ARM_ANGLE), theta, -ARM * np.sin(ARM_ANGLE))
        vertex = p0 + PLAT_R * e
        d = (vertex - elbow) / np.linalg.norm(vertex - elbow)
        axes = (t, np.cross(t, d), d)  # first S axis t: the parallelogram's own swing, far from gimbal lock
        limb = b.limb(name)
        limb.revolute("motor", at=polar(BASE_R, theta), axis=t, actuated=True)
        rod_b = limb.branch("b")
        rod_b.spherical("top", at=elbow - HALF_WIDTH * t, axes=axes)
        end = rod_b.frame("end", at=vertex - HALF_WIDTH * t)
        limb.spherical("a_top", at=elbow + HALF_WIDTH * t, axes=axes)
        limb.spherical("a_bot", at=vertex + HALF_WIDTH * t, axes=axes)
        pf = limb.frame("b_pf", at=vertex - HALF_WIDTH * t)
        limb.tip(at=p0)
        b.closure(f"{name}_b", pf, end, "3d")
    bottom = -float(np.sqrt((ARM + ROD) ** 2 - (BASE_R - PLAT_R) ** 2))
    level = -ARM * float(np.sqrt(1 - ((ROD + PLAT_R - BASE_R) / ARM) ** 2))
    confs: dict[str, dict[str, Any]] = {
        "generic": {
            "pose": pose([0.04, -0.03, p0[2] + 0.05]),
            "expected": expect(3, "3T", f"{CLAVEL}; {HAND} (three couples n_i = t_i x d_i)"),
        },
        "arms-stretched": {
            "joints": _symmetric_joints(bottom),
            "expected": expect(
                0,
                "rigid",
                f"{HAND}: every arm aligned with its rods (the bottom of the workspace, a serial singularity of each "
                "limb): each limb also exerts the force along its rods, three concurrent forces and three couples",
            ),
        },
        "rods-horizontal": {
            "joints": _symmetric_joints(level),
            "expected": expect(
                5,
                "3T2R",
                f"{HAND}: every parallelogram in the platform's plane, so every couple n_i = t_i x d_i is vertical "
                f"(rank 1): a constraint singularity ({ZBG}) with the rotations about x and y",
            ),
        },
    }
    return b, confs, None


def delta_3ruu_design(
    base_r: float = 0.2, plat_r: float = 0.05, arm: float = 0.25, rod: float = 0.3, arm_angle: float = float(np.pi / 3)
) -> Definition:
    """The Delta's U-U equivalent (3-RUU) for any dimensions [m] and arm angle at the reference [rad].

    Configurations ``generic`` (the platform moved by (0.03, -0.02, 0.02) m) and ``constraint-singular``
    (rods horizontal).

    Raises:
        ConfigurationError: a length that is not positive, or rods too short to reach the platform.
    """
    for name, value in (("base_r", base_r), ("plat_r", plat_r), ("arm", arm), ("rod", rod)):
        if not value > 0:
            raise ConfigurationError(f"Delta-3RUU: {name} must be a positive length [m], got {value}")
    elbow_r, elbow_z = base_r + arm * np.cos(arm_angle), -arm * np.sin(arm_angle)
    if not rod > abs(elbow_r - plat_r):
        raise ConfigurationError(
            f"Delta-3RUU: the rods ({rod} m) do not reach the platform: the elbows are {abs(elbow_r - plat_r):.6g} m "
            "from it horizontally"
        )
    if not arm > abs(rod + plat_r - base_r):
        raise ConfigurationError(
            f"Delta-3RUU: the arms ({arm} m) must be longer than |rod + r - R| = {abs(rod + plat_r - base_r):.6g} m "
            "for the rods to lie horizontal somewhere (configuration constraint-singular)"
        )
    drop = elbow_z - np.sqrt(rod**2 - (elbow_r - plat_r) ** 2)
    b = MechanismBuilder(
        "Delta-3RUU",
        f"The Delta robot with each parallelogram replaced by the equivalent U-U rod (3-RUU): actuated revolutes "
        f"tangent to a circle R = {base_r} m at 0, 120, 240 deg, arms {arm} m (60 deg below horizontal at the "
        f"reference), rods {rod} m, platform circumradius {plat_r} m. The actuator axis and the first axis of each U "
        "are parallel (tangent t), the two middle axes are parallel (n), the last axis (t) is fixed to the platform: "
        "the translational 3-RUU. Each limb exerts one couple along t x n = -d (d the rod direction, normal to t "
        "here), where a parallelogram exerts n = t x d (model Delta): the two have different constraint "
        "singularities. With the rods horizontal and radial the 3-RUU's couples are radial (3T1R), the Delta's "
        "are vertical (3T2R).",
    )
    for name, theta in limb_pairs():
        e, t = radial(theta)
        base = polar(base_r, theta)
        elbow = polar(elbow_r, theta, elbow_z)
        vertex = polar(plat_r, theta, drop)
        n = np.cross(t, vertex - elbow)
        limb = b.limb(name)
        limb.revolute("r", at=base, axis=t, actuated=True)
        limb.universal("u1", at=elbow, axis1=t, axis2=n)
        limb.universal("u2", at=vertex, axis1=n, axis2=t)
        limb.tip(at=[0.0, 0.0, drop])
    level = -arm * np.sqrt(1 - ((rod + plat_r - base_r) / arm) ** 2)  # elbows and platform at one height
    confs = {
        "generic": {
            "pose": pose([0.03, -0.02, drop + 0.02]),
            "expected": expect(3, "3T", f"{CLAVEL}; {TSAI}"),
        },
        "constraint-singular": {
            "pose": pose([0.0, 0.0, level]),
            "expected": expect(4, "3T1R", f"{HAND} (rods horizontal: the three couples lie in one plane); {ZBG}"),
        },
    }
    return b, confs, None


@register("delta_3ruu")
def _delta_3ruu() -> Definition:
    return delta_3ruu_design()


@register("4ruu")
def _four_ruu() -> Definition:
    base_r, plat_r, arm, h = 0.3, 0.1, 0.15, 0.25
    b = MechanismBuilder(
        "4-RUU",
        f"A 4-RUU Schoenflies mechanism: actuated revolutes with vertical axes at (+-{base_r}, 0, 0), (0, +-{base_r}, 0), "
        f"horizontal arms {arm} m along the tangent (limbs A and C along +t, B and D along -t), U joints (vertical "
        f"axis, then a horizontal axis n) at the elbows, U joints (n, then vertical, fixed to the platform) at the "
        f"platform vertices on a circle r = {plat_r} m, {h} m up. Each limb exerts one horizontal couple along z x n "
        "and is driven through the force along its rod. The arms alternate because four rods that are images of "
        "one another under the quarter turns about z lie on one regulus of a hyperboloid, whose lines span only 3 "
        "forces: with all arms along +t the actuation would be singular at every 4-fold symmetric pose and nearly "
        "so around it. At the reference all four n are parallel to x (a constraint singularity with one extra "
        "rotation about x).",
    )
    z = np.array([0.0, 0.0, 1.0])
    for (name, theta), side in zip(limb_pairs("ABCD"), (1.0, -1.0, 1.0, -1.0), strict=True):
        e, t = radial(theta)
        base = polar(base_r, theta)
        elbow = base + side * arm * t
        vertex = polar(plat_r, theta, h)
        limb = b.limb(name)
        limb.revolute("r", at=base, axis=z, actuated=True)
        limb.universal("u1", at=elbow, axis1=z, axis2=[1, 0, 0])
        limb.universal("u2", at=vertex, axis1=[1, 0, 0], axis2=z)
        limb.tip(at=[0.0, 0.0, h])
    confs = {
        "generic": {
            "pose": pose([0.02, -0.01, 0.21], [0.0, 0.0, 0.35]),
            "expected": expect(4, "3T1R", f"{KONG}; {HAND}"),
        },
        "parallel-axes": {
            "joints": {},
            "expected": expect(5, "3T2R", f"{HAND} (four parallel middle axes: the couples are parallel)"),
        },
    }
    return b, confs, None
