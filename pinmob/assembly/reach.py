"""Why a platform pose could not be assembled: the pose coordinates the mechanism does not reach.

When :func:`~pinmob.assembly.assemble.assemble_pose` fails, the closed configuration nearest the target is
sought from the failed attempt: damped least squares on the platform's pose error and every closure, the
closures weighted :data:`WEIGHT` times more, then projected onto the closed set. Its platform pose differs
from the target along the coordinates the mechanism cannot reach, ``x y z`` (world [m]) and ``roll pitch
yaw`` (Pinocchio's rpy [rad]): those whose difference exceeds the tolerance (position / L, rad) and is at
least :data:`SHARE` of the largest are named. When that configuration reaches the target, the pose is
within reach and another seed may find it.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmob.assembly.residual import (
    closure_residual,
    compute_kinematics,
    mechanism_residuals,
    pose_error,
    stacked_error,
    worst_residual,
)
from pinmob.assembly.solver import solve
from pinmob.model import Mechanism, borrowed
from pinmob.screw import Array, twist_scaling

#: Weight of the closures against the platform's pose error in the search for the nearest closed configuration.
WEIGHT = 1e3
#: A coordinate is named when its difference is at least this share of the largest (position / L, rad).
SHARE = 0.1
#: The platform pose coordinates, in order: position [m], then Pinocchio's roll, pitch, yaw [rad]
#: (``R = Rz(yaw) Ry(pitch) Rx(roll)``).
POSE_COORDS = ("x", "y", "z", "roll", "pitch", "yaw")


def nearest_closed(mech: Mechanism, pose: pin.SE3, q0: Array, tol: float) -> Array | None:
    """A closed configuration (within ``tol``) whose platform pose is nearest ``pose``, searched from ``q0``.

    None when none was found from there (the projection onto the closed set failed).
    """
    model, pid, length = mech.model, mech.platform_id, mech.length_scale
    scale = twist_scaling(mech.length_scale)
    with borrowed(model) as data:

        def residual(q: Array) -> tuple[Array, Array]:
            compute_kinematics(model, data, q)
            e_pose, j_pose = pose_error(model, data, pid, pose)
            e_closed, j_closed = stacked_error(mech, model, data, mech.all_closures)
            return (
                np.concatenate([scale * e_pose, WEIGHT * e_closed]),
                np.vstack([scale[:, None] * j_pose, WEIGHT * j_closed]),
            )

        weighted = solve(model, residual, q0, tol=1e-12, length=length, polish=False)
        closed = solve(model, closure_residual(mech), weighted.q, tol=min(1e-12, tol * 1e-3), length=length)
        compute_kinematics(model, data, closed.q)
        within = worst_residual(mechanism_residuals(mech, data), length) <= tol
    return closed.q if within else None


def pose_vector(placement: pin.SE3) -> Array:
    """(6,) ``[x, y, z, roll, pitch, yaw]`` [m, rad] of a placement (:data:`POSE_COORDS`)."""
    return np.concatenate([placement.translation, pin.rpy.matrixToRpy(placement.rotation)])


def reach_note(mech: Mechanism, pose: pin.SE3, q0: Array, tol: float) -> str:
    """What the failure of ``assemble_pose(mech, pose)`` from the attempt ``q0`` says about the pose, one sentence.

    ``the platform pose is out of reach along z (residual 2.29 m; the nearest closed configuration found has
    z = -0.709 m)``; or that a closed configuration reaches it (another seed may find it); or that none near
    the attempt was found.
    """
    q = nearest_closed(mech, pose, q0, tol)
    if q is None:
        return "No closed configuration near the attempt was found; try another seed."
    with borrowed(mech.model) as data:
        compute_kinematics(mech.model, data, q)
        reached = pose_vector(data.oMf[mech.platform_id])
    asked = pose_vector(pose)
    diff = reached - asked
    diff[3:] = np.angle(np.exp(1j * diff[3:]))  # angles modulo 2 pi
    size = np.abs(diff) / np.where(np.arange(6) < 3, mech.length_scale, 1.0)
    if size.max() <= tol:
        return "A closed configuration reaches it: the solver did not converge from this seed; try another seed."
    out = [k for k in range(6) if size[k] > tol and size[k] >= SHARE * size.max()]
    unit = ["m"] * 3 + ["rad"] * 3
    along = ", ".join(f"{POSE_COORDS[k]} (residual {abs(diff[k]):.3g} {unit[k]})" for k in out)
    has = ", ".join(
        f"{POSE_COORDS[k]} = {np.round(reached[k], 6) + 0.0:.4g} {unit[k]}" for k in out
    )  # no round-off figures
    return f"The platform pose is out of reach along {along}: the nearest closed configuration found has {has}."
