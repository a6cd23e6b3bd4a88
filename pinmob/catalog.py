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

from .builder import MechanismBuilder

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
    confs = {
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
