"""Joint centres: the points whose velocities define idle motions, wherever a file puts its joint frames.

An idle motion moves no output frame, no joint centre and no closure point (a rod spinning about the
line through its two ball joints). A revolute joint's frame origin may sit anywhere on its axis (a CAD
export puts it at a mate connector, a spherical mechanism's file at the sphere centre), and where it
sits decides whether a rod's spin moves it: a ball made of three revolutes is idle about its rod only
if the three are watched at the ball's centre. So a revolute's centre is taken from the axes, not
from the file: where its axis meets the axes of the revolutes next to it in the tree (parent,
children), which is the centre of a ball or the cross of a universal joint made of revolutes. When
it meets several at different points (an arm's first ball axis also meets the motor axis), the point
where most revolutes meet wins (the ball's three over the arm's two), and a tie goes to the point
nearest the frame origin. A revolute that meets none, and every other joint, keeps its frame origin.

The axes of two joints next to each other are both fixed in the body between them, so the point is
fixed on the joint's axis: an offset ``t`` along it from the frame origin, found once per mechanism
(at the neutral configuration) and applied at every configuration, ``c = p + t u`` (``u`` the unit
axis in the world).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from pinmob.analysis.configuration import Configuration
from pinmob.model import Mechanism
from pinmob.screw import Array, cross_columns

#: ``sin^2`` of the angle below which two axes are parallel (no single meeting point).
PARALLEL = 1e-6
#: Two axes closer than this times L meet, and two meeting points closer than this are one.
MEET = 1e-6


def _axes(mech: Mechanism) -> tuple[list[int], dict[int, Array], dict[int, Array]]:
    """The one-velocity revolute joints, and their frame origins and unit axes [m] at the neutral configuration."""
    model = mech.model
    neutral = Configuration.unchecked(mech, pin.neutral(model))  # its kinematics and (6, nv) world Jacobian
    revolute = [
        j
        for j in range(1, model.njoints)
        if model.joints[j].nv == 1 and model.joints[j].shortname().startswith("JointModelR")
    ]
    origin = {j: np.array(neutral.data.oMi[j].translation) for j in revolute}
    axis = {j: np.array(neutral.world_jacobian[3:, model.joints[j].idx_v]) for j in revolute}
    return revolute, origin, axis


def centre_offsets(mech: Mechanism) -> tuple[NDArray[np.intp], Array]:
    """(joints, offsets [m]): the revolute joints whose centre is off their frame origin, and ``t`` along the axis.

    Computed once per mechanism (read-only); see the module docstring for the rule.
    """

    def compute() -> tuple[NDArray[np.intp], Array]:
        model = mech.model
        tol = MEET * mech.length_scale
        revolute, origin, axis = _axes(mech)
        is_revolute = set(revolute)
        meets: dict[int, list[tuple[int, Array]]] = {j: [] for j in revolute}  # neighbour, meeting point
        for k in revolute:
            j = int(model.parents[k])
            if j not in is_revolute:
                continue
            cross = cross_columns(axis[j], axis[k])
            if cross @ cross <= PARALLEL:
                continue
            d = origin[k] - origin[j]
            if abs(d @ cross) / np.sqrt(cross @ cross) > tol:
                continue  # skew: no meeting point
            # the point of j's axis nearest k's axis: t_j = (d x u_k) . (u_j x u_k) / |u_j x u_k|^2
            point = origin[j] + axis[j] * (cross_columns(d, axis[k]) @ cross) / (cross @ cross)
            meets[j].append((k, point))
            meets[k].append((j, point))

        def cluster(j: int, point: Array) -> int:
            """How many revolutes meet at ``point``, connected to ``j`` through neighbours meeting there."""
            seen, todo = {j}, [j]
            while todo:
                for k, p in meets[todo.pop()]:
                    if k not in seen and np.linalg.norm(p - point) <= tol:
                        seen.add(k)
                        todo.append(k)
            return len(seen)

        joints, offsets = [], []
        for j in revolute:
            if not meets[j]:
                continue
            ranked = sorted(
                (-cluster(j, p), abs(float(axis[j] @ (p - origin[j]))), float(axis[j] @ (p - origin[j])))
                for _, p in meets[j]
            )
            t = ranked[0][2]
            if abs(t) > tol:
                joints.append(j)
                offsets.append(t)
        out = (np.array(joints, dtype=np.intp), np.array(offsets, dtype=float))
        for a in out:
            a.flags.writeable = False
        return out

    return mech.memo("joint centre offsets", compute)


def joint_centres(conf: Configuration) -> Array:
    """(njoints - 1, 3) every joint's centre [m] (module docstring; read-only, cached per configuration)."""

    def compute() -> Array:
        out = np.array([x.translation for x in conf.data.oMi.tolist()[1:]]).reshape(-1, 3)
        joints, offsets = centre_offsets(conf.mechanism)
        if joints.size:
            idx_v = np.array([conf.mechanism.model.joints[int(j)].idx_v for j in joints], dtype=np.intp)
            out[joints - 1] += offsets[:, None] * conf.world_jacobian[3:, idx_v].T
        out.flags.writeable = False
        return out

    return conf.memo("joint centres", compute)
