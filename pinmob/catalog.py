"""Definitions of the built-in models, written to ``models/`` by the builder.

Regenerate every built-in model with::

    python -m pinmob.catalog models

A test fails when a file in ``models/`` differs from what this module writes.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from .builder import MechanismBuilder, _rpy, polar, radial, rotation, symmetric_angles

Definition = tuple[MechanismBuilder, dict[str, dict[str, Any]], float | None]

#: stem of the files -> function building (builder, configurations, length_scale)
CATALOG: dict[str, Callable[[], Definition]] = {}


def register(stem: str) -> Callable[[Callable[[], Definition]], Callable[[], Definition]]:
    def deco(fn: Callable[[], Definition]) -> Callable[[], Definition]:
        CATALOG[stem] = fn
        return fn

    return deco


def _radial(theta: float) -> tuple[np.ndarray, np.ndarray]:
    """Radial unit vector e and tangent t = z x e at angle theta."""
    e = np.array([np.cos(theta), np.sin(theta), 0.0])
    return e, np.array([-e[1], e[0], 0.0])


def three_puu(name: str, description: str, big_r: float, small_r: float, drop: float) -> MechanismBuilder:
    """The seed paper's 3-PUU at its reference configuration (all joints zero).

    Limb i (A, B, C at theta = 0, 120, 240 deg): a slider on the vertical guide
    through ``R e_i``, a U joint at the slider (first axis t_i = z x e_i, fixed to
    the slider; second axis n_i normal to t_i and to the link), a link to the
    platform vertex ``r e_i - drop z``, and a U joint there (axes n_i then t_i,
    the last one fixed to the platform). Intermediate axes parallel and outer
    axes parallel: the translational arrangement of the paper's Fig. 3, whose
    only generic limb constraint is a couple along t_i x n_i (eq. 19).
    """
    b = MechanismBuilder(name, description)
    z = np.array([0.0, 0.0, 1.0])
    for limb_name, theta in zip("ABC", (0.0, 2 * np.pi / 3, 4 * np.pi / 3)):
        e, t = _radial(theta)
        slider, vertex = big_r * e, small_r * e - drop * z
        link = vertex - slider
        n = np.cross(t, link)
        limb = b.limb(limb_name)
        limb.prismatic("slider", at=slider, axis=z, actuated=True)
        limb.universal("u1", at=slider, axis1=t, axis2=n)
        limb.universal("u2", at=vertex, axis1=n, axis2=t)
        limb.tip(at=-drop * z)
    return b


def _sliders(value: float) -> dict[str, float]:
    return {f"{x}_slider": value for x in "ABC"}


PAPER = "Zhao et al., The free mobility of a parallel manipulator (seed paper)"


@register("3puu")
def _three_puu() -> Definition:
    big_r, small_r, link = 0.3, 0.15, 0.25
    drop = float(np.sqrt(link**2 - (big_r - small_r) ** 2))
    b = three_puu(
        "3-PUU",
        f"The seed paper's 3-PUU: three vertical guides at R = {big_r} m, platform circumradius r = {small_r} m, "
        f"links {link} m, platform hanging below the sliders. Links longer than R - r, so beta = 0 cannot be "
        "assembled here (see 3-PUU-flat) and beta = pi/2 neither (see 3-PUU-vertical).",
        big_r,
        small_r,
        drop,
    )
    confs = {
        "generic": {"joints": _sliders(0.0), "expected": {"dof": 3, "motion_type": "3T", "source": PAPER + ", eq. 38"}},
        "offset": {
            "pose": {"xyz": [0.03, -0.02, -drop + 0.03], "rpy": [0.0, 0.0, 0.0]},
            "expected": {"dof": 3, "motion_type": "3T", "source": PAPER + ", eq. 38"},
        },
    }
    return b, confs, None


@register("3puu_flat")
def _three_puu_flat() -> Definition:
    big_r, small_r = 0.3, 0.15
    b = three_puu(
        "3-PUU-flat",
        f"The seed paper's 3-PUU with link length R - r = {big_r - small_r} m (R = {big_r} m, r = {small_r} m): "
        "the only geometry where beta = 0 (links horizontal, platform coplanar with the sliders) can be assembled, "
        "and then it is the only assembly there is. Each limb is at a serial singularity there.",
        big_r,
        small_r,
        0.0,
    )
    tilt = {f"{x}_u1a": 1.0 for x in "ABC"} | {f"{x}_u2b": -1.0 for x in "ABC"}
    hand = "derived by hand in tests/test_three_puu.py (each limb twist rank 4 at beta = 0)"
    confs = {
        "flat": {
            "joints": _sliders(0.0),
            "approach": tilt,
            "expected": {"dof": 2, "motion_type": "1T1R", "source": hand},
        },
        "flat-raised": {
            "joints": _sliders(0.1),
            "approach": tilt,
            "expected": {"dof": 2, "motion_type": "1T1R", "source": hand},
        },
    }
    return b, confs, None


@register("3puu_vertical")
def _three_puu_vertical() -> Definition:
    radius, link = 0.2, 0.25
    b = three_puu(
        "3-PUU-vertical",
        f"The seed paper's 3-PUU with equal radii R = r = {radius} m and links {link} m, so that beta = pi/2 "
        "(links vertical, normal to the platform) can be assembled.",
        radius,
        radius,
        link,
    )
    hand = "derived by hand in tests/test_three_puu.py (three parallel couples along z)"
    confs = {
        "vertical": {"joints": _sliders(0.0), "expected": {"dof": 5, "motion_type": "3T2R", "source": hand}},
        "generic": {
            "pose": {"xyz": [0.05, 0.03, -0.23], "rpy": [0.0, 0.0, 0.0]},
            "expected": {"dof": 3, "motion_type": "3T", "source": PAPER + ", eq. 38"},
        },
    }
    return b, confs, None


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


FICHTER = (
    "Fichter (1986), A Stewart platform-based manipulator: general theory and practical construction, IJRR 5(2): "
    "the platform turned by +-90 deg about the vertical from the home pose is singular at every height; "
    "checked by hand-coded Pluecker line geometry in tests/test_six_ups.py"
)


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


# --------------------------------------------------------------------------- classic parallel mechanisms (issue 3)

HAND = "derived by hand in tests/test_models.py"
TSAI = "L.-W. Tsai, Kinematics of a three-dof platform with three extensible limbs, Recent Advances in Robot Kinematics, 1996"
ZBG = "Zlatanov, Bonev & Gosselin, Constraint singularities of parallel mechanisms, ICRA 2002"
HUNT = "K. H. Hunt, Structural kinematics of in-parallel-actuated robot-arms, J. Mech. Trans. Autom. Des. 105, 1983"
LEE_SHAH = "Lee & Shah, Kinematic analysis of a three-degrees-of-freedom in-parallel actuated manipulator, IEEE J. Robot. Autom. 4(3), 1988"
CARRETERO = "Carretero, Podhorodeski, Nahon & Gosselin, Kinematic analysis and optimization of a new three degree-of-freedom spatial parallel manipulator, J. Mech. Des. 122, 2000"
KONG = "X. Kong & C. M. Gosselin, Type Synthesis of Parallel Mechanisms, Springer, 2007"
GOSSELIN_ANGELES = (
    "Gosselin & Angeles, Singularity analysis of closed-loop kinematic chains, IEEE Trans. Robot. Autom. 6(3), 1990"
)
BENNETT = "G. T. Bennett, A new mechanism, Engineering 76, 1903; J. E. Baker, The Bennett linkage and its associated quadric surfaces, Mech. Mach. Theory 23, 1988"
KIM_TSAI = (
    "Kim & Tsai, Design optimization of a Cartesian parallel manipulator, J. Mech. Des. 125, 2003; Kong & Gosselin 2002"
)


def _pose(xyz: Any, rpy: Any = (0.0, 0.0, 0.0)) -> dict[str, list[float]]:
    return {"xyz": [float(x) for x in xyz], "rpy": [float(x) for x in rpy]}


def _expect(dof: int, motion: str, source: str) -> dict[str, Any]:
    return {"dof": dof, "motion_type": motion, "source": source}


def close(builder: MechanismBuilder, fixed: dict[str, float], seed: dict[str, float] | None = None) -> dict[str, float]:
    """Joint values closing ``builder``'s mechanism with the ``fixed`` joint values held.

    Damped least squares (:func:`pinmob.closure.solve`) on the limb tip residuals
    (position / L, rotation) and the rows ``q_j - fixed_j``, started at ``seed``.
    Used to write closed ``joints`` configurations; returns every non-zero joint value.
    """
    from .closure import compute_kinematics, relative_error, solve
    from .screw import twist_scaling

    mech = builder.mechanism()
    model, data = mech.model, mech.model.createData()
    scale = twist_scaling(mech.length_scale)
    pid = mech.platform_id
    idx = {n: model.joints[model.getJointId(n)].idx_q for n in fixed}

    def residual(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        compute_kinematics(model, data, q)
        blocks = [relative_error(model, data, pid, limb.tip_id) for limb in mech.limbs if limb.tip_id != pid]
        e = np.concatenate([scale * b[0] for b in blocks] + [np.array([q[idx[n]] - v for n, v in fixed.items()])])
        rows = np.zeros((len(fixed), model.nv))
        for i, n in enumerate(fixed):
            rows[i, model.joints[model.getJointId(n)].idx_v] = 1.0
        return e, np.vstack([scale[:, None] * b[1] for b in blocks] + [rows])

    result = solve(model, residual, mech.q_from_joints({**(seed or {}), **fixed}), tol=1e-10, max_iter=500)
    if not result.converged:
        raise RuntimeError(f"{builder.name}: closure with {fixed} did not converge (residual {result.residual:.2e})")
    q = result.q
    out = {}
    for j in range(1, model.njoints):
        x = float(q[model.joints[j].idx_q])
        if abs(x) > 1e-13:
            out[model.names[j]] = round(x, 12)
    return out


def _limb_pairs(names: str = "ABC") -> list[tuple[str, float]]:
    return list(zip(names, symmetric_angles(len(names)), strict=True))


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
    for name, theta in _limb_pairs():
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
        "generic": {"pose": _pose([0.04, -0.03, 0.33]), "expected": _expect(3, "3T", TSAI)},
        "constraint-singular": {
            "pose": _pose([0.0, 0.0, 0.0]),
            "seed": {f"{x}_u1a": 1.0 for x in "ABC"},
            "expected": _expect(4, "3T1R", f"{HAND} (the three limb couples lie in the base plane); {ZBG}"),
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
    for name, theta in _limb_pairs():
        base, vertex = polar(big_r, theta), polar(small_r, theta + np.pi / 3, h)
        n = np.cross(centre - base, centre - vertex)
        limb = b.limb(name)
        limb.universal("u1", at=base, axis1=centre - base, axis2=n)
        limb.prismatic("leg", at=base, axis=vertex - base, actuated=True)
        limb.universal("u2", at=vertex, axis1=n, axis2=centre - vertex)
        limb.tip(at=[0.0, 0.0, h])
    rot = rotation([1.0, 0.5, 0.2], 0.25)
    origin = centre + rot @ (np.array([0.0, 0.0, h]) - centre)
    rpy = _rpy(rot)
    confs = {
        "generic": {
            "pose": _pose(origin, rpy),
            "expected": _expect(
                3, "3R", "Karouia & Herve, A three-dof tripod for generating spherical rotation, ARK 2000"
            ),
        },
        "home": {
            "joints": {},
            "expected": _expect(
                3, "3R", "Karouia & Herve, A three-dof tripod for generating spherical rotation, ARK 2000"
            ),
        },
    }
    return b, confs, None


def _rps_like(b: MechanismBuilder, big_r: float, small_r: float, h: float, slider: bool) -> None:
    for name, theta in _limb_pairs():
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


@register("3rps")
def _three_rps() -> Definition:
    big_r, small_r, h = 0.25, 0.12, 0.3
    b = MechanismBuilder(
        "3-RPS",
        f"Hunt's 3-RPS: base revolutes tangent to a circle R = {big_r} m at 0, 120, 240 deg, actuated prismatic legs, "
        f"spherical joints (three revolutes) at the platform vertices on a circle r = {small_r} m; reference with the "
        f"platform parallel to the base at height {h} m. Each limb exerts a force through its sphere centre parallel "
        "to its base revolute axis: the platform heaves along z and tilts, while x, y and the turn about z follow as "
        "parasitic motions.",
    )
    _rps_like(b, big_r, small_r, h, slider=False)
    tilted = close(b, {"A_leg": 0.04, "B_leg": -0.02, "C_leg": 0.01})
    confs = {
        "generic": {
            "joints": tilted,
            "expected": _expect(
                3,
                "1T1R1H",
                f"{HAND}: the horizontal-axis motion is a screw (parasitic); 1T2R counted as independent outputs in {HUNT}, {LEE_SHAH}",
            ),
        },
        "home": {"joints": {}, "expected": _expect(3, "1T2R", f"{HUNT}; {LEE_SHAH}")},
    }
    return b, confs, None


@register("3prs")
def _three_prs() -> Definition:
    big_r, small_r, h = 0.3, 0.12, 0.25
    b = MechanismBuilder(
        "3-PRS",
        f"3-PRS: actuated vertical sliders on a circle R = {big_r} m at 0, 120, 240 deg, revolutes tangent to that "
        f"circle, fixed-length links to spherical joints at the platform vertices on a circle r = {small_r} m, "
        f"{h} m above the sliders at the reference. Each limb exerts a force through its sphere centre parallel to its "
        "revolute axis: 1T2R with parasitic motions, as the 3-RPS.",
    )
    _rps_like(b, big_r, small_r, h, slider=True)
    tilted = close(b, {"A_slider": 0.05, "B_slider": -0.03, "C_slider": 0.0})
    confs = {
        "generic": {
            "joints": tilted,
            "expected": _expect(
                3,
                "1T1R1H",
                f"{HAND}: the horizontal-axis motion is a screw (parasitic); 1T2R counted as independent outputs in {CARRETERO}",
            ),
        },
        "home": {"joints": {}, "expected": _expect(3, "1T2R", CARRETERO)},
    }
    return b, confs, None


@register("delta_3ruu")
def _delta() -> Definition:
    base_r, plat_r, arm, rod = 0.2, 0.05, 0.25, 0.3
    arm_angle = np.pi / 3
    elbow_r, elbow_z = base_r + arm * np.cos(arm_angle), -arm * np.sin(arm_angle)
    drop = elbow_z - np.sqrt(rod**2 - (elbow_r - plat_r) ** 2)
    b = MechanismBuilder(
        "Delta-3RUU",
        f"The Delta robot with each parallelogram replaced by the equivalent U-U rod (3-RUU): actuated revolutes "
        f"tangent to a circle R = {base_r} m at 0, 120, 240 deg, arms {arm} m (60 deg below horizontal at the "
        f"reference), rods {rod} m, platform circumradius {plat_r} m. The actuator axis and the first axis of each U "
        "are parallel (tangent t), the two middle axes are parallel (n), the last axis (t) is fixed to the platform: "
        "the translational 3-RUU. Each limb exerts one couple along t x n; unlike the parallelogram Delta it has "
        "constraint singularities, e.g. with the rods horizontal.",
    )
    for name, theta in _limb_pairs():
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
            "pose": _pose([0.03, -0.02, drop + 0.02]),
            "expected": _expect(3, "3T", "R. Clavel, Delta, a fast robot with parallel geometry, 1988; " + TSAI),
        },
        "constraint-singular": {
            "pose": _pose([0.0, 0.0, level]),
            "expected": _expect(4, "3T1R", f"{HAND} (rods horizontal: the three couples lie in one plane); {ZBG}"),
        },
    }
    return b, confs, None


@register("4ruu")
def _four_ruu() -> Definition:
    base_r, plat_r, arm, h = 0.3, 0.1, 0.15, 0.25
    b = MechanismBuilder(
        "4-RUU",
        f"A 4-RUU Schoenflies mechanism: actuated revolutes with vertical axes at (+-{base_r}, 0, 0), (0, +-{base_r}, 0), "
        f"horizontal arms {arm} m along the tangent, U joints (vertical axis, then a horizontal axis n) at the elbows, "
        f"U joints (n, then vertical, fixed to the platform) at the platform vertices on a circle r = {plat_r} m, "
        f"{h} m up. Each limb exerts one horizontal couple along z x n. At the reference all four n are parallel "
        "to x (a constraint singularity with one extra rotation about x).",
    )
    z = np.array([0.0, 0.0, 1.0])
    for name, theta in _limb_pairs("ABCD"):
        e, t = radial(theta)
        base = polar(base_r, theta)
        elbow = base + arm * t
        vertex = polar(plat_r, theta, h)
        limb = b.limb(name)
        limb.revolute("r", at=base, axis=z, actuated=True)
        limb.universal("u1", at=elbow, axis1=z, axis2=[1, 0, 0])
        limb.universal("u2", at=vertex, axis1=[1, 0, 0], axis2=z)
        limb.tip(at=[0.0, 0.0, h])
    confs = {
        "generic": {
            "pose": _pose([0.02, 0.01, h + 0.02], [0.0, 0.0, 0.3]),
            "expected": _expect(4, "3T1R", f"{KONG}; {HAND}"),
        },
        "parallel-axes": {
            "joints": {},
            "expected": _expect(5, "3T2R", f"{HAND} (four parallel middle axes: the couples are parallel)"),
        },
    }
    return b, confs, None


@register("3rrr_spherical")
def _spherical_3rrr() -> Definition:
    radius, h = 0.2, 0.25
    b = MechanismBuilder(
        "3-RRR-spherical",
        f"A spherical 3-RRR: all nine revolute axes pass through the centre O = (0, 0, 0); joints drawn {radius} m from "
        f"O along their axes, limbs at 0, 120, 240 deg, platform frame {h} m above O. At the reference limb A is "
        "stretched: its three axes lie in one plane (a serial singularity); limbs B and C are not.",
    )
    for name, theta in _limb_pairs():
        u1 = polar(1.0, theta, -0.6)
        u3 = polar(0.7, theta + 0.7, 0.8)
        u2 = polar(1.0, theta + 0.6, 0.0) if name != "A" else 0.5 * (u1 / np.linalg.norm(u1) + u3 / np.linalg.norm(u3))
        limb = b.limb(name)
        for label, u in (("r1", u1), ("r2", u2), ("r3", u3)):
            u = u / np.linalg.norm(u)
            limb.revolute(label, at=radius * u, axis=u, actuated=label == "r1")
        limb.tip(at=[0.0, 0.0, h])
    turned = close(b, {"A_r1": 0.1, "B_r1": -0.1, "C_r1": 0.1}, seed={"A_r2": 0.3})
    confs = {
        "generic": {"joints": turned, "expected": _expect(3, "3R", GOSSELIN_ANGELES)},
        "limb-A-stretched": {
            "joints": {},
            "expected": _expect(2, "2R", f"{HAND}; serial (type I) singularity of {GOSSELIN_ANGELES}"),
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
    for name, theta in _limb_pairs():
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
            "pose": _pose([0.03, 0.02, 0.0], [0.0, 0.0, 0.1]),
            "expected": _expect(3, "2T1R", GOSSELIN_ANGELES),
        },
        "limb-A-stretched": {
            "joints": {},
            "expected": _expect(2, "1T1R", f"{HAND}; serial (type I) singularity of {GOSSELIN_ANGELES}"),
        },
    }
    return b, confs, None


def _angle(v: np.ndarray) -> float:
    return float(np.arctan2(v[1], v[0]))


def _elbow(a: np.ndarray, e: np.ndarray, la: float, lb: float, side: float) -> np.ndarray:
    """Planar elbow point at distance la from a and lb from e, on the ``side`` (+1 left, -1 right) of a->e."""
    d = float(np.linalg.norm(e - a))
    x = (la**2 - lb**2 + d**2) / (2 * d)
    u = (e - a) / d
    return a + x * u + side * np.sqrt(max(0.0, la**2 - x**2)) * np.array([-u[1], u[0], 0.0])


@register("five_bar")
def _five_bar() -> Definition:
    half, arm, rod = 0.1, 0.2, 0.25
    a1, b1, end = np.array([-half, 0.0, 0.0]), np.array([half, 0.0, 0.0]), np.array([0.0, 0.3, 0.0])
    b = MechanismBuilder(
        "five-bar",
        f"Planar five-bar (2-RR), plane z = 0, axes along z: base joints at (-+{half}, 0, 0), proximal links {arm} m, "
        f"distal links {rod} m, end point at (0, 0.3, 0) at the reference. pinmob needs every limb tip to have the "
        "platform's pose (position and orientation), and an end point has no orientation; so the platform is the "
        "distal link of limb A (tip frame at the end point) and limb B is R-R-R, its last revolute being the end-point "
        "joint. The platform (that link) has the five-bar's 2 DoF; its end point moves in 2T.",
    )
    z = [0.0, 0.0, 1.0]
    a2, b2 = _elbow(a1, end, arm, rod, +1.0), _elbow(b1, end, arm, rod, -1.0)
    la = b.limb("A")
    la.revolute("r1", at=a1, axis=z, actuated=True)
    la.revolute("r2", at=a2, axis=z)
    la.tip(at=end)
    lb = b.limb("B")
    lb.revolute("r1", at=b1, axis=z, actuated=True)
    lb.revolute("r2", at=b2, axis=z)
    lb.revolute("r3", at=end, axis=z)
    lb.tip(at=end)

    def joints(e2: np.ndarray) -> dict[str, float]:
        """Joint values (relative to the reference) putting the end point at e2, by planar trigonometry."""
        a2n, b2n = _elbow(a1, e2, arm, rod, +1.0), _elbow(b1, e2, arm, rod, -1.0)
        alpha = [_angle(a2n - a1) - _angle(a2 - a1), _angle(e2 - a2n) - _angle(end - a2)]
        beta = [_angle(b2n - b1) - _angle(b2 - b1), _angle(e2 - b2n) - _angle(end - b2)]
        return {
            "A_r1": alpha[0],
            "A_r2": alpha[1] - alpha[0],
            "B_r1": beta[0],
            "B_r2": beta[1] - beta[0],
            "B_r3": alpha[1] - beta[1],
        }

    phi = np.deg2rad(110.0)
    stretched = b1 + (arm + rod) * np.array([np.cos(phi), np.sin(phi), 0.0])
    vals = {k: round(float(np.angle(np.exp(1j * v))), 12) for k, v in joints(stretched).items()}
    gk = "Grubler-Kutzbach: 3 (5 - 1) - 2 x 5 = 2"
    confs = {
        "generic": {"joints": {}, "expected": _expect(2, "1T1R", f"{gk}; the link's motion type {HAND}")},
        "limb-B-stretched": {
            "joints": vals,
            "expected": _expect(1, "1R", f"{HAND}; serial (type I) singularity of {GOSSELIN_ANGELES}"),
        },
    }
    return b, confs, None


def _dh(theta: float, a: float, alpha: float) -> np.ndarray:
    """Denavit-Hartenberg transform Rz(theta) Tx(a) Rx(alpha), (4, 4)."""
    out = np.eye(4)
    out[:3, :3] = rotation([0, 0, 1], theta) @ rotation([1, 0, 0], alpha)
    out[:3, 3] = rotation([0, 0, 1], theta) @ [a, 0.0, 0.0]
    return out


def bennett_theta2(theta1: float, alpha1: float, alpha2: float) -> float:
    """Bennett's closure: tan(theta1/2) tan(theta2/2) = sin((alpha2 + alpha1)/2) / sin((alpha2 - alpha1)/2)."""
    return float(2 * np.arctan(np.sin((alpha2 + alpha1) / 2) / np.sin((alpha2 - alpha1) / 2) / np.tan(theta1 / 2)))


def bennett_frames(theta1: float, a1: float, alpha1: float, alpha2: float) -> list[np.ndarray]:
    """World frames (4, 4) of the four joints (z = joint axis) of a Bennett loop, frame 1 = identity.

    Frame i+1 = frame i Rz(theta_i) Tx(a_i) Rx(alpha_i) with (theta_i, a_i, alpha_i) =
    (theta1, a1, alpha1), (theta2, a2, alpha2), (-theta1, a1, alpha1), (-theta2, a2, alpha2), the last one
    closing the loop back to frame 1 (checked in the tests).
    """
    a2 = a1 * np.sin(alpha2) / np.sin(alpha1)
    theta2 = bennett_theta2(theta1, alpha1, alpha2)
    frames = [np.eye(4)]
    for theta, a, alpha in ((theta1, a1, alpha1), (theta2, a2, alpha2), (-theta1, a1, alpha1)):
        frames.append(frames[-1] @ _dh(theta, a, alpha))
    return frames


@register("bennett")
def _bennett() -> Definition:
    a1, alpha1, alpha2, theta1 = 0.2, np.deg2rad(40.0), np.deg2rad(70.0), np.deg2rad(100.0)
    a2 = a1 * np.sin(alpha2) / np.sin(alpha1)
    frames = bennett_frames(theta1, a1, alpha1, alpha2)
    b = MechanismBuilder(
        "Bennett",
        f"Bennett's overconstrained spatial 4R linkage: opposite links equal, lengths a1 = {a1} m, a2 = {a2:.6g} m, "
        f"twists alpha1 = 40 deg, alpha2 = 70 deg, so that a1 / sin(alpha1) = a2 / sin(alpha2). The ground link is "
        "joints 4-1, the coupler (platform) joints 2-3; limb X is joint 1 then joint 2, limb Y joint 4 then joint 3. "
        "Reference: theta1 = 100 deg and theta2 from Bennett's closure equation "
        "tan(theta1/2) tan(theta2/2) = sin((alpha2 + alpha1)/2) / sin((alpha2 - alpha1)/2). Grubler-Kutzbach gives "
        "6 (4 - 4 - 1) + 4 = -2; the linkage moves with 1 DoF.",
    )
    origin = [f[:3, 3] for f in frames]
    axis = [f[:3, 2] for f in frames]
    tip = 0.5 * (origin[1] + origin[2])
    x = b.limb("X")
    x.revolute("j1", at=origin[0], axis=axis[0], actuated=True)
    x.revolute("j2", at=origin[1], axis=axis[1])
    x.tip(at=tip)
    y = b.limb("Y")
    y.revolute("j4", at=origin[3], axis=axis[3])
    y.revolute("j3", at=origin[2], axis=axis[2])
    y.tip(at=tip)
    theta1b = np.deg2rad(140.0)
    d1 = theta1b - theta1
    d2 = bennett_theta2(theta1b, alpha1, alpha2) - bennett_theta2(theta1, alpha1, alpha2)
    source = f"{BENNETT}; Grubler-Kutzbach gives -2"
    confs = {
        "generic": {"joints": {}, "expected": _expect(1, "1H", source)},
        "theta1-140deg": {
            "joints": {"X_j1": round(d1, 12), "X_j2": round(d2, 12), "Y_j4": round(d2, 12), "Y_j3": round(d1, 12)},
            "expected": _expect(1, "1H", source),
        },
    }
    return b, confs, None


@register("sarrus")
def _sarrus() -> Definition:
    off, bend, h = 0.1, 0.08, 0.2
    b = MechanismBuilder(
        "Sarrus",
        f"Sarrus linkage: two limbs of three parallel revolutes each (6R loop), limb A with axes along x in the plane "
        f"y = -{off}..., limb B with axes along y; hinges at the base (z = 0), the knee ({bend} m outwards, z = {h / 2}) "
        f"and the platform (z = {h}). Grubler-Kutzbach gives 6 (6 - 6 - 1) + 6 = 0; it moves with 1 DoF, a translation "
        "along z.",
    )
    for name, axis, out in (("A", [1.0, 0, 0], np.array([0.0, -1.0, 0])), ("B", [0, 1.0, 0], np.array([1.0, 0, 0]))):
        limb = b.limb(name)
        limb.revolute("r1", at=off * out, axis=axis, actuated=name == "A")
        limb.revolute("r2", at=(off + bend) * out + [0, 0, h / 2], axis=axis)
        limb.revolute("r3", at=off * out + [0, 0, h], axis=axis)
        limb.tip(at=[0.0, 0.0, h])
    phi = float(np.arctan2(bend, h / 2))
    straight = {f"{x}_{j}": round(v, 12) for x in "AB" for j, v in (("r1", -phi), ("r2", 2 * phi), ("r3", -phi))}
    confs = {
        "generic": {"joints": {}, "expected": _expect(1, "1T", "P. F. Sarrus, Comptes Rendus 36, 1853; " + HAND)},
        "stretched": {
            "joints": straight,
            "expected": _expect(0, "rigid", f"{HAND} (both limbs straight: first-order rigid at the top dead centre)"),
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
    straight = _angle(r2 - r1) - _angle(r3 - r2)  # limb A's knee angle (about x) that aligns its two links
    flat = close(b, {"A_r2": straight})
    confs = {
        "generic": {"pose": _pose([0.02, -0.01, 0.03]), "expected": _expect(3, "3T", KIM_TSAI)},
        "limb-A-flat": {
            "joints": flat,
            "expected": _expect(2, "2T", f"{HAND} (limb A's three revolute axes coplanar: a serial singularity)"),
        },
    }
    return b, confs, None


UR5 = "ur_description/urdf/ur5_robot.urdf"


def _ur5_path() -> Path:
    import example_robot_data

    return Path(example_robot_data.getModelPath(UR5)) / UR5


def _ik(mech: Any, limb_name: str, target: np.ndarray, seed: np.ndarray) -> np.ndarray:
    """Joint values of one limb of ``mech`` putting its tip at ``target`` (4, 4), by damped least squares."""
    import pinocchio as pin

    from .closure import compute_kinematics, pose_error, solve
    from .screw import twist_scaling

    model, data = mech.model, mech.model.createData()
    limb = mech.limb(limb_name)
    scale = twist_scaling(mech.length_scale)
    goal = pin.SE3(target[:3, :3], target[:3, 3])

    def residual(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        compute_kinematics(model, data, q)
        e, jac = pose_error(model, data, limb.tip_id, goal)
        return scale * e, scale[:, None] * jac

    result = solve(model, residual, seed, tol=1e-13, max_iter=500)
    if not result.converged:
        raise RuntimeError(f"IK of limb {limb_name} did not converge ({result.residual:.2e})")
    return result.q


@register("3ur5")
def _three_ur5() -> Definition:
    ring, height, grip = 0.75, 0.35, 0.12
    b = MechanismBuilder(
        "3-UR5",
        f"Three UR5 arms (example-robot-data's ur5_robot.urdf, meshes included) on a circle of radius {ring} m at 0, "
        f"120, 240 deg, facing the centre, rigidly holding one object (the platform) at (0, 0, {height}) m; each tool "
        f"flange grips the object from above, {grip} m from its centre, tool axis pointing down. Each arm is a limb of six "
        "revolutes. Away from arm singularities the object has 6 DoF (3T3R); with arm A's wrist singular "
        "(wrist_2_joint = 0: its joints 2, 3, 4 and 6 parallel) the arm exerts a force along those axes.",
    )
    urdf = _ur5_path()
    centre = np.array([0.0, 0.0, height])
    tool_frames, arms = {}, []
    for name, theta in _limb_pairs():
        e, _ = radial(theta)
        arms.append(b.urdf_limb(name, urdf, "base_link", "tool0", (rotation([0, 0, 1], theta + np.pi), ring * e)))
        tool = np.eye(4)
        tool[:3, :3] = np.column_stack([radial(theta)[1], e, [0.0, 0.0, -1.0]])
        tool[:3, 3] = centre + grip * e
        tool_frames[name] = tool
    # tips at the tool flanges first, to solve each arm's inverse kinematics
    mech = b.mechanism()
    seed_arm = np.array([0.0, -1.0, 1.6, -2.2, -1.57, 0.0])
    q = mech.neutral()
    for limb in mech.limbs:
        q[limb.v_indices] = seed_arm
        q = _ik(mech, limb.name, tool_frames[limb.name], q)
    # each tip frame: the object's frame (centre, world axes) seen from its tool flange
    for arm in arms:
        offset = np.linalg.inv(tool_frames[arm.name])
        obj = np.eye(4)
        obj[:3, 3] = centre
        rel = offset @ obj
        arm.tip_offset = (rel[:3, :3], rel[:3, 3])
    mech = b.mechanism()

    def values(qv: np.ndarray) -> dict[str, float]:
        return {
            mech.model.names[j]: round(float(qv[mech.model.joints[j].idx_q]), 12) for j in range(1, mech.model.njoints)
        }

    # wrist-singular: arm A's wrist_2 held at 0; the object and the other arms follow (closure solve)
    singular = close(b, {"A_wrist_2_joint": 0.0}, seed=values(q))
    confs = {
        "generic": {
            "joints": values(q),
            "expected": _expect(6, "3T3R", f"{HAND} (three 6R arms away from singularities)"),
        },
        "wrist-singular": {
            "joints": singular,
            "expected": _expect(5, "2T3R", f"{HAND} (arm A's four parallel axes: one constraint force)"),
        },
    }
    return b, confs, None


def write_all(directory: str | Path) -> list[Path]:
    """Write every catalogued model into ``directory``; returns the TOML paths."""
    out = []
    for stem, fn in CATALOG.items():
        builder, confs, length = fn()
        out.append(builder.write(directory, stem, confs, length))
    return out


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    target = Path(args[0]) if args else Path(__file__).resolve().parent.parent / "models"
    for path in write_all(target):
        print(path)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
