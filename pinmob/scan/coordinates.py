"""Grid coordinates: which a grid varies, which it holds, and which follow the mechanism.

A grid varies one to three *coordinates*, each a platform pose coordinate
(``x y z`` [m], ``roll pitch yaw`` [rad], :data:`POSE_COORDS`) or a one-degree
joint (actuated or not) [rad or m]. At each sample the gridded coordinates take
their grid values; of the others (the rule, :func:`held_coordinates`):

* pose coordinates along which the mechanism can still move at the reference
  configuration (``--at``) once the gridded ones are held are *held* at their
  values there; the remaining pose coordinates (a lower-mobility platform's
  constrained, parasitic ones) *follow*: they are solved for with the closures
  (:func:`pinmob.assembly.partial_pose.assemble_coordinates`);
* a grid over joints only is forward kinematics: the actuated joints that can
  still move once the gridded joints are held are held at ``--at``; every other
  joint follows (closures solved from the warm start, with continuation).

Which can still move, in a basis-independent way: with ``N`` an orthonormal basis
of the closed chain's dimensionless motions at ``--at`` (``null K_hat``,
:func:`pinmob.analysis.chain.closed_chain.closed_chain`, whose image by the
platform's Jacobian is the platform's free motion space), each coordinate has a
rate row ``c_i`` on it (x, y, z and prismatic joints in units of L). The gridded
coordinates must vary independently there (``C_G N`` of full row rank, else a
:class:`ConfigurationError` listing the free coordinates); the motions left are
``N' = N null(C_G N)``. Then, one at a time, the candidate coordinate along which
``N'`` has the largest component ``|c_i N'|`` (ties: the first in the order
``x y z roll pitch yaw``, or the declared order of the actuated joints) is held
and ``N'`` is reduced to the motions that keep it still, until no candidate has a
component above ``rtol``. A pose coordinate that no motion changes, at ``--at``
nor at the generic configurations, is held too (:func:`constant_coordinates`: it
could not follow anyway). A full-mobility platform (6 DoF) gridded over two pose
coordinates thus holds the four others, as a plain pose grid, and so does a
translational one over two positions (its rotations are constant); the 3-RPS
gridded over roll and pitch holds z, and x, y and yaw follow.
"""

from __future__ import annotations

from contextlib import closing

import numpy as np

from pinmob.analysis import Configuration, closed_chain, frame_rows, generic_states, parked
from pinmob.assembly import POSE_COORDS, pose_coordinate_jacobian, pose_vector
from pinmob.exceptions import ConfigurationError, PinmobError
from pinmob.model import Mechanism, joint_value, linear_velocity_mask
from pinmob.name_matching import choices
from pinmob.scan.chain_scan import value_joints
from pinmob.scan.references import platform_pose
from pinmob.screw import RTOL, Array

#: Ties between candidates' components within this relative amount go to the first in order.
TIE = 1e-9


def coordinate_names(mech: Mechanism) -> tuple[str, ...]:
    """Every coordinate a grid may vary: the pose coordinates (with a platform), then the one-degree joints."""
    return (POSE_COORDS if mech.has_platform else ()) + value_joints(mech)


def check_coordinates(mech: Mechanism, names: list[str], option: str = "`axes`") -> tuple[str, ...]:
    """The grid's coordinate names, checked: known, one to three, all different.

    Raises:
        ConfigurationError: an unknown coordinate (the message lists the pose coordinates and the joints), a
            repeated one, or not one to three.
    """
    valid = coordinate_names(mech)
    for name in names:
        if name not in valid:
            pose = f"pose coordinates {', '.join(POSE_COORDS)}; " if mech.has_platform else ""
            raise ConfigurationError(
                f"unknown grid coordinate {name!r} of {mech.name!r}; valid: {pose}joints {choices(value_joints(mech))}"
            )
    if not 1 <= len(names) <= 3 or len(set(names)) != len(names):
        raise ConfigurationError(f"{option} needs one to three different coordinates, got {list(names)}").naming("axes")
    return tuple(names)


def coordinate_unit(mech: Mechanism, name: str) -> str:
    """The unit of a coordinate: ``m`` for x, y, z and a prismatic joint, ``rad`` for the angles and other joints."""
    if name in POSE_COORDS:
        return "m" if name in POSE_COORDS[:3] else "rad"
    joint = mech.model.joints[mech.model.getJointId(name)]
    return "m" if linear_velocity_mask(mech.model)[joint.idx_v] else "rad"


def coordinate_values(mech: Mechanism, q: Array, names: tuple[str, ...] | list[str]) -> dict[str, float]:
    """Values of coordinates at q: pose coordinates of the platform [m, rad], joint values [rad or m]."""
    out: dict[str, float] = {}
    pose = np.zeros(6)
    if any(n in POSE_COORDS for n in names):
        pose = pose_vector(platform_pose(mech, q))
    for n in names:
        out[n] = float(pose[POSE_COORDS.index(n)]) if n in POSE_COORDS else joint_value(mech.model, q, n)
    return out


def coordinate_rates(conf: Configuration, names: tuple[str, ...] | list[str], rtol: float = RTOL) -> Array:
    """(k, m) dimensionless rates of the coordinates on the closed chain's motions ``N`` (module docstring)."""
    mech = conf.mechanism
    null = closed_chain(conf, rtol).null
    rows = np.zeros((len(names), mech.model.nv))
    if any(n in POSE_COORDS for n in names):
        twist = frame_rows(conf, mech.platform)  # [v / L; w] per dimensionless joint rate
        pose_rows = pose_coordinate_jacobian(conf.frame_placement(mech.platform_id), twist)
    for i, n in enumerate(names):
        if n in POSE_COORDS:
            rows[i] = pose_rows[POSE_COORDS.index(n)]
        else:  # a joint's value in units of L (prismatic) or rad changes at its dimensionless rate
            rows[i, mech.model.joints[mech.model.getJointId(n)].idx_v] = 1.0
    return rows @ null


def held_coordinates(
    mech: Mechanism, q: Array, gridded: tuple[str, ...], at: str = "the reference", rtol: float = RTOL
) -> tuple[str, ...]:
    """The coordinates a grid holds at their values at q (module docstring); the other ones follow.

    Raises:
        ConfigurationError: the gridded coordinates cannot vary independently at q (the message lists the
            coordinates that are free there and the DoF).
    """
    conf = Configuration(mech, q)
    pose_grid = any(n in POSE_COORDS for n in gridded)
    candidates = [n for n in (POSE_COORDS if pose_grid else mech.actuated) if n not in gridded]
    rates = coordinate_rates(conf, list(gridded) + candidates, rtol)
    grid_rates, cand = rates[: len(gridded)], rates[len(gridded) :]
    s = np.linalg.svd(grid_rates, compute_uv=False)
    if s.size < len(gridded) or s[-1] <= rtol * max(1.0, float(s[0])):
        raise ConfigurationError(_not_free(mech, conf, gridded, at, rtol))
    # the motions left once the gridded coordinates are held: N' = null(C_G N), as coefficients on N
    _, _, vt = np.linalg.svd(grid_rates)
    left = vt[len(gridded) :].T
    held: list[str] = []
    while left.shape[1] and candidates:
        norms = np.linalg.norm(cand @ left, axis=1)
        top = float(norms.max(initial=0.0))
        if top <= rtol:
            break
        i = next(k for k, v in enumerate(norms) if v >= top * (1 - TIE))
        held.append(candidates[i])
        _, _, vt = np.linalg.svd((cand[i] @ left)[None, :])
        left = left @ vt[1:].T
        cand = np.delete(cand, i, axis=0)
        candidates.pop(i)
    if pose_grid:  # coordinates no motion changes, here nor at generic configurations, are held: they cannot follow
        rest = [n for n in POSE_COORDS if n not in gridded and n not in held]
        held += constant_coordinates(mech, conf, rest, rtol)
    order = POSE_COORDS if pose_grid else mech.actuated
    return tuple(n for n in order if n in held)


def constant_coordinates(mech: Mechanism, conf: Configuration, names: list[str], rtol: float = RTOL) -> list[str]:
    """The coordinates among ``names`` that no motion of the closed chain changes, here and at generic configurations.

    Their rate rows (:func:`coordinate_rates`) have norm at most ``rtol`` at ``conf`` and at every configuration of
    :func:`pinmob.analysis.generic.generic_configurations` (:func:`~pinmob.analysis.generic.generic_states`). E.g.
    the rotations of a translational platform (3-PUU, Delta): held at their values, a grid over its position is a
    plain pose grid. None (``[]``) when no generic configuration can be built. The generic states are read only while
    a coordinate may still be constant (the 3-RPS's parasitic x, y, yaw move at the first one).
    """
    if not names:
        return []
    still = np.linalg.norm(coordinate_rates(conf, names, rtol), axis=1) <= rtol
    if not still.any():
        return []
    try:
        states = generic_states(mech)
    except PinmobError:
        return []
    with closing(parked(states)) as each:  # the state the loop stops at parked too
        for c in each:
            still &= np.linalg.norm(coordinate_rates(c, names, rtol), axis=1) <= rtol
            if not still.any():  # each coordinate left moves at some configuration: none is constant
                break
    return [n for n, s in zip(names, still) if s]


def _not_free(mech: Mechanism, conf: Configuration, gridded: tuple[str, ...], at: str, rtol: float) -> str:
    """The message for a grid whose coordinates cannot vary independently: the free coordinates and the DoF."""
    pose_grid = any(n in POSE_COORDS for n in gridded)
    names = list(POSE_COORDS if pose_grid else value_joints(mech))
    rates = coordinate_rates(conf, names, rtol)
    free = [n for n, r in zip(names, np.linalg.norm(rates, axis=1)) if r > rtol]
    s = np.linalg.svd(rates, compute_uv=False) if rates.size else np.zeros(0)
    dof = int(np.sum(s > rtol * max(1.0, float(s[0]) if s.size else 0.0)))
    what = "pose coordinates" if pose_grid else "joints"
    return (
        f"coordinates {', '.join(gridded)} cannot vary independently at {at!r} of {mech.name!r}: "
        f"its {what} vary there with {dof} DoF; the free {what} (moved by some motion): "
        f"{', '.join(free) or 'none'}"
    )
