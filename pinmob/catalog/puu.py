"""The seed paper's 3-PUU in three geometries (Zhao et al.): generic, beta = 0 (flat) and beta = pi/2 (vertical)."""

from __future__ import annotations

import numpy as np

from pinmob.exceptions import ConfigurationError

from ..builder import MechanismBuilder, cross, radial
from .registry import Definition, register
from .sources import PAPER, limb_pairs


def three_puu(
    name: str, description: str, big_r: float, small_r: float, drop: float, stroke: float = 1.0
) -> MechanismBuilder:
    """The seed paper's 3-PUU at its reference configuration (all joints zero).

    Limb i (A, B, C at theta = 0, 120, 240 deg): a slider on the vertical guide
    through ``R e_i``, a U joint at the slider (first axis t_i = z x e_i, fixed to
    the slider; second axis n_i normal to t_i and to the link), a link to the
    platform vertex ``r e_i - drop z``, and a U joint there (axes n_i then t_i,
    the last one fixed to the platform). Intermediate axes parallel and outer
    axes parallel: the translational arrangement of the paper's Fig. 3, whose
    only generic limb constraint is a couple along t_i x n_i (eq. 19). The
    sliders travel ``[-stroke, stroke]`` [m] from there.
    """
    b = MechanismBuilder(name, description)
    z = np.array([0.0, 0.0, 1.0])
    for limb_name, theta in limb_pairs():
        e, t = radial(theta)
        slider, vertex = big_r * e, small_r * e - drop * z
        link = vertex - slider
        n = cross(t, link)
        limb = b.limb(limb_name)
        limb.prismatic("slider", at=slider, axis=z, lower=-stroke, upper=stroke, actuated=True)
        limb.universal("u1", at=slider, axis1=t, axis2=n)
        limb.universal("u2", at=vertex, axis1=n, axis2=t)
        limb.tip(at=-drop * z)
    return b


def _sliders(value: float) -> dict[str, float]:
    return {f"{x}_slider": value for x in "ABC"}


def three_puu_design(big_r: float = 0.3, small_r: float = 0.15, link: float = 0.25, stroke: float = 1.0) -> Definition:
    """The 3-PUU of the seed paper with the platform hanging below the sliders, for any dimensions [m].

    ``drop = sqrt(link^2 - (R - r)^2)`` puts the platform below the sliders; configurations ``generic`` (all
    joints zero) and ``offset`` (the platform moved by (0.03, -0.02, 0.03) m).

    Raises:
        ConfigurationError: a dimension that is not positive, or links not longer than ``R - r`` (beta = 0 or
            no assembly: see 3-PUU-flat).
    """
    for name, value in (("big_r", big_r), ("small_r", small_r), ("link", link), ("stroke", stroke)):
        if not value > 0:
            raise ConfigurationError(f"3-PUU: {name} must be a positive length [m], got {value}")
    if not link > abs(big_r - small_r):
        raise ConfigurationError(
            f"3-PUU: the links ({link} m) must be longer than |R - r| = {abs(big_r - small_r):.6g} m for the platform "
            "to hang below the sliders"
        )
    drop = float(np.sqrt(link**2 - (big_r - small_r) ** 2))
    b = three_puu(
        "3-PUU",
        f"The seed paper's 3-PUU: three vertical guides at R = {big_r} m, platform circumradius r = {small_r} m, "
        f"links {link} m, platform hanging below the sliders. Links longer than R - r, so beta = 0 cannot be "
        "assembled here (see 3-PUU-flat) and beta = pi/2 neither (see 3-PUU-vertical).",
        big_r,
        small_r,
        drop,
        stroke,
    )
    confs = {
        "generic": {"joints": _sliders(0.0), "expected": {"dof": 3, "motion_type": "3T", "source": PAPER + ", eq. 38"}},
        "offset": {
            "pose": {"xyz": [0.03, -0.02, -drop + 0.03], "rpy": [0.0, 0.0, 0.0]},
            "expected": {"dof": 3, "motion_type": "3T", "source": PAPER + ", eq. 38"},
        },
    }
    return b, confs, None


@register("3puu")
def _three_puu() -> Definition:
    return three_puu_design()


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
    hand = "derived by hand in the pinmob test suite (each limb twist rank 4 at beta = 0)"
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
    hand = "derived by hand in the pinmob test suite (three parallel couples along z)"
    confs = {
        "vertical": {"joints": _sliders(0.0), "expected": {"dof": 5, "motion_type": "3T2R", "source": hand}},
        "generic": {
            "pose": {"xyz": [0.05, 0.03, -0.23], "rpy": [0.0, 0.0, 0.0]},
            "expected": {"dof": 3, "motion_type": "3T", "source": PAPER + ", eq. 38"},
        },
    }
    return b, confs, None
