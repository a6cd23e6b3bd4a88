"""Literature sources of the built-in models' expected mobility, and small helpers for their tables."""

from __future__ import annotations

from typing import Any

from ..builder import symmetric_angles

PAPER = "Zhao et al., The free mobility of a parallel manipulator (seed paper)"
HAND = "derived by hand in the pinmob test suite"
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
KAROUIA = "Karouia & Herve, A three-dof tripod for generating spherical rotation, ARK 2000"
CLAVEL = "R. Clavel, Delta, a fast robot with parallel geometry, 18th Int. Symp. on Industrial Robots, 1988; R. Clavel, Conception d'un robot parallele rapide a 4 degres de liberte, PhD thesis, EPFL, 1991"
FICHTER = (
    "Fichter (1986), A Stewart platform-based manipulator: general theory and practical construction, IJRR 5(2): "
    "the platform turned by +-90 deg about the vertical from the home pose is singular at every height; "
    "checked by hand-coded Pluecker line geometry in the pinmob test suite"
)
VIRTUAL_CHAIN = (
    "Campos, Guenther & Martins, Differential kinematics of serial manipulators using virtual chains, "
    "J. Braz. Soc. Mech. Sci. Eng. 27(4), 2005"
)


def pose(xyz: Any, rpy: Any = (0.0, 0.0, 0.0)) -> dict[str, list[float]]:
    """A ``pose`` table: position [m] and roll, pitch, yaw [rad]."""
    return {"xyz": [float(x) for x in xyz], "rpy": [float(x) for x in rpy]}


def expect(dof: int, motion: str, source: str) -> dict[str, Any]:
    """An ``expected`` table: DoF, motion type and where they come from."""
    return {"dof": dof, "motion_type": motion, "source": source}


def limb_pairs(names: str = "ABC") -> list[tuple[str, float]]:
    """Limb names with their angles about z, evenly spread from 0 [rad]."""
    return list(zip(names, symmetric_angles(len(names)), strict=True))
