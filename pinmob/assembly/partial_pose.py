"""Assembly at some platform pose coordinates and joint values, the other coordinates following the mechanism.

A platform pose as six coordinates ``p = [x, y, z, roll, pitch, yaw]`` [m, rad]
(:data:`POSE_COORDS`; roll, pitch, yaw are Pinocchio's ``rpy``:
``R = Rz(yaw) Ry(pitch) Rx(roll)``). :func:`assemble_coordinates` finds a closed
configuration where the *given* pose coordinates and one-degree joints take
given values and everything else follows: the other pose coordinates are
unknowns, solved with the closures (for a lower-mobility platform they are
its parasitic motions, e.g. the 3-RPS's x, y and yaw once z, roll and pitch
are given). One :func:`~pinmob.assembly.solver.solve` on the stacked
dimensionless residual

    e(q) = [ closures (lengths / L) ;  D (p_S(q) - p*_S) ]

(``S`` the given pose coordinates, ``D`` = 1/L on x, y, z and 1 on the
angles, angle differences wrapped into (-pi, pi]) whose Jacobian rows are
``dp/dq = [J_v ; E(rpy)^-1 J_w]`` (``J`` the platform frame's
``LOCAL_WORLD_ALIGNED`` Jacobian, ``E`` Pinocchio's ``computeRpyJacobian``
in the world frame, ``w = E rpy_dot``); the given joints are held exactly
(the solver does not move them). With joint values only, it is forward
kinematics (:func:`~pinmob.assembly.assemble.solve_actuated`, with its
continuation) from a warm start predicted along the closed set
(:func:`predicted_seed`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
import pinocchio as pin

from pinmob.assembly.assemble import _solver_tol, joint_velocity_indices, solve_actuated, warn_outside_limits
from pinmob.assembly.closure_miss import format_worst, tolerance_hint
from pinmob.assembly.continuation import held_coordinates
from pinmob.assembly.reach import POSE_COORDS, pose_vector
from pinmob.assembly.residual import (
    CLOSURE_TOL,
    closure_residual,
    compute_kinematics,
    mechanism_residuals,
    stacked_error,
    worst_residual,
)
from pinmob.assembly.solver import STALL_WINDOW, solve
from pinmob.exceptions import ClosureError, ConfigurationError
from pinmob.model import Mechanism, borrowed, linear_velocity_mask
from pinmob.name_matching import choices
from pinmob.screw import Array

#: Largest step of the given joints [rad, or L for a prismatic joint] per predicted forward-kinematics step.
JOINT_STEP = 0.2


def pose_from_vector(v: Array) -> pin.SE3:
    """Pose from ``[x, y, z, roll, pitch, yaw]`` [m, rad]."""
    v = np.asarray(v, float)
    return pin.SE3(pin.rpy.rpyToMatrix(v[3:]), v[:3])


def pose_coordinate_jacobian(pose: pin.SE3, jacobian: Array) -> Array:
    """(6, nv) rates of ``[x, y, z, roll, pitch, yaw]`` from the frame's (6, nv) ``LOCAL_WORLD_ALIGNED`` Jacobian.

    ``[J_v ; E^-1 J_w]`` with ``w = E(rpy) rpy_dot`` (world-frame angular velocity); singular at pitch = +-pi/2.
    """
    e = pin.rpy.computeRpyJacobian(pin.rpy.matrixToRpy(pose.rotation), pin.WORLD)
    return np.vstack([jacobian[:3], np.linalg.solve(e, jacobian[3:])])


def predicted_seed(mech: Mechanism, joints: Mapping[str, float], seed: Array, tol: float = CLOSURE_TOL) -> Array:
    """A warm start for forward kinematics to ``joints`` from the closed ``seed``, predicted along the closed set.

    The given joints move to their values in ``ceil(max |step| / JOINT_STEP)`` equal steps (revolutes the short
    way round; prismatic steps in units of L); at each, the other joints are predicted along the tangent
    ``dv_free = -K_free^+ K_held dv_held`` (K the closure Jacobian) and, before the last step, corrected with
    the given joints held. The last prediction is returned (:func:`solve_actuated` corrects it): a big step
    does not leave the seed's assembly branch as a jump from the seed with only the given joints changed can.
    ``seed`` itself when a correction fails.
    """
    model = mech.model
    idx = joint_velocity_indices(mech, list(joints))
    if not idx.size:
        return seed
    target = mech.q_from_joints(joints, base=seed)
    linear = linear_velocity_mask(model)[idx]
    way = pin.difference(model, seed, target)[idx]
    way = np.where(linear, way, np.angle(np.exp(1j * way)))
    size = float(np.max(np.abs(np.where(linear, way / mech.length_scale, way))))
    steps = max(1, math.ceil(size / JOINT_STEP - 1e-9))  # a step of exactly JOINT_STEP is one step
    free = np.ones(model.nv, bool)
    free[idx] = False
    residual = closure_residual(mech)
    q = seed
    for k in range(steps):
        jac = residual(q)[1]
        dv = np.zeros(model.nv)
        dv[idx] = way / steps
        dv[free] = -np.linalg.lstsq(jac[:, free], jac[:, idx] @ dv[idx], rcond=None)[0]
        q = pin.integrate(model, q, dv)
        if k < steps - 1:
            result = solve(model, residual, q, tol=_solver_tol(tol), length=mech.length_scale, free=free, polish=False)
            if not result.converged:
                return seed
            q = result.q
    return q


def assemble_coordinates(
    mech: Mechanism,
    pose: Mapping[str, float],
    joints: Mapping[str, float] | None = None,
    seed: Array | None = None,
    tol: float = CLOSURE_TOL,
    max_iter: int = 200,
    stall_window: int = STALL_WINDOW,
) -> Array:
    """A closed configuration with the given pose coordinates and joint values, the rest following (module docstring).

    Args:
        mech: the mechanism (a platform frame is needed when ``pose`` is not empty).
        pose: values of some of :data:`POSE_COORDS` [m, rad].
        joints: values of one-degree joints [m or rad], held exactly.
        seed: (nq,) warm start (selects the assembly branch); None: neutral.
        tol: largest closure residual and pose-coordinate miss (position / L, rotation [rad]).
        max_iter: solver iterations.
        stall_window: the solver's (:func:`~pinmob.assembly.solver.solve`), with pose coordinates given.

    Raises:
        ConfigurationError: an unknown pose coordinate, a non-finite value, or no platform frame.
        FrameError: an unknown joint (the message lists them).
        ClosureError: not assembled from ``seed``; the message names the largest misses (the residuals carry
            every closure and, as ``coordinate <name>``, each given pose coordinate's miss).
    """
    joints = dict(joints or {})
    if not pose:
        start = mech.neutral() if seed is None else mech.check_q(seed)
        return solve_actuated(mech, joints, predicted_seed(mech, joints, start, tol), tol, max_iter).q
    if not mech.has_platform:
        raise ConfigurationError(f"{mech.name!r} has no platform frame: pose coordinates cannot be assembled")
    unknown = [c for c in pose if c not in POSE_COORDS]
    if unknown:
        raise ConfigurationError(f"unknown pose coordinate {unknown[0]!r}; valid: {choices(POSE_COORDS)}")
    if not np.all(np.isfinite(list(pose.values()))):
        raise ConfigurationError(f"pose coordinates must be finite numbers, got {dict(pose)}")
    model, length, pid = mech.model, mech.length_scale, mech.platform_id
    rows = np.array([POSE_COORDS.index(c) for c in pose], int)
    target = np.array(list(pose.values()), float)
    angle = rows >= 3
    scale = np.where(angle, 1.0, 1.0 / length)
    idx = joint_velocity_indices(mech, list(joints))
    start = mech.neutral() if seed is None else mech.check_q(seed)
    q0 = mech.q_from_joints(joints, base=start) if joints else start
    free = np.ones(model.nv, bool)
    free[idx] = False

    def misses(data: pin.Data) -> Array:
        d = pose_vector(data.oMf[pid])[rows] - target
        return np.where(angle, np.angle(np.exp(1j * d)), d)

    with borrowed(model) as data:

        def residual(q: Array) -> tuple[Array, Array]:
            compute_kinematics(model, data, q)
            e_c, j_c = stacked_error(mech, model, data, mech.all_closures)
            jac = pin.getFrameJacobian(model, data, pid, pin.LOCAL_WORLD_ALIGNED)
            j_p = pose_coordinate_jacobian(data.oMf[pid], jac)[rows]
            return np.concatenate([e_c, scale * misses(data)]), np.vstack([j_c, scale[:, None] * j_p])

        result = solve(model, residual, q0, tol=_solver_tol(tol), max_iter=max_iter, length=length, free=free,
                       stall_window=stall_window)  # fmt: skip
        q = result.q.copy()
        held = held_coordinates(mech, idx)
        q[held] = q0[held]
        compute_kinematics(model, data, q)
        closures = mechanism_residuals(mech, data)
        miss = misses(data)
    res = closures | {
        f"coordinate {c}": (0.0, abs(float(m))) if a else (abs(float(m)), 0.0) for c, m, a in zip(pose, miss, angle)
    }
    if worst_residual(res, length) > tol:
        given = ", ".join(f"{c} = {v:.6g}" for c, v in pose.items())
        raise ClosureError(
            f"could not assemble {mech.name!r} at {given}{' with ' + str(joints) if joints else ''}: residuals "
            f"{format_worst(res, length, tol)}{tolerance_hint(res, length)}",
            res,
        ).naming("closure_tol")
    warn_outside_limits(mech, q, "assembly at platform pose coordinates")
    return q
