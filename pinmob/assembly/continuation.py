"""Continuation (homotopy) for forward kinematics: the held joints moved to their targets in steps."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmob.assembly.residual import closure_residual
from pinmob.assembly.solver import SolverResult, solve
from pinmob.model import Mechanism, linear_velocity_mask
from pinmob.screw import Array

#: Continuation: first step (fraction of the way) and the smallest before giving up.
HOMOTOPY_STEP, HOMOTOPY_MIN_STEP = 0.25, 1.0 / 64
#: Corrector iterations per continuation step.
HOMOTOPY_ITER = 30


def held_coordinates(mech: Mechanism, idx: Array) -> Array:
    """Configuration indices of the one-degree joints with velocity indices ``idx`` (two for a continuous joint)."""
    model = mech.model
    out: list[int] = []
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nv == 1 and joint.idx_v in idx:
            out += range(joint.idx_q, joint.idx_q + joint.nq)
    return np.array(out, int)


def continuation(
    mech: Mechanism, start: Array, target: Array, idx: Array, tol: float, max_iter: int
) -> SolverResult | None:
    """Homotopy: project ``start``, then move the held joints (velocity indices ``idx``) to ``target`` in steps.

    A step advances the held joints by a fraction h of the way (revolutes the
    short way round); the free joints are predicted along the tangent
    ``dv_free = -J_free^+ J_held dv_held`` and corrected by :func:`solve` with
    the held joints fixed. A failed step halves h, a good one doubles it (at
    most 1/2). None when the projection fails or h falls below
    ``HOMOTOPY_MIN_STEP``.
    """
    model, residual = mech.model, closure_residual(mech)
    free = np.ones(model.nv, bool)
    free[idx] = False
    held = held_coordinates(mech, idx)
    closed = solve(model, residual, start, tol=tol, max_iter=max_iter, length=mech.length_scale, polish=False)
    if not closed.converged:
        return None
    way = pin.difference(model, closed.q, target)[idx]
    way = np.where(linear_velocity_mask(model)[idx], way, np.angle(np.exp(1j * way)))
    q, t, h, total, last = closed.q, 0.0, HOMOTOPY_STEP, closed.iterations, closed
    while t < 1.0:
        step = min(h, 1.0 - t)
        jac = residual(q)[1]
        dv = np.zeros(model.nv)
        dv[idx] = step * way
        dv[free] = -np.linalg.lstsq(jac[:, free], jac[:, idx] @ dv[idx], rcond=None)[0]
        guess = pin.integrate(model, q, dv)
        final = t + step >= 1.0
        if final:
            guess[held] = target[held]
        iters = max_iter if final else HOMOTOPY_ITER
        last = solve(model, residual, guess, tol=tol, max_iter=iters, length=mech.length_scale, free=free, polish=final)
        total += last.iterations
        if last.converged:
            q, t, h = last.q, t + step, min(2 * h, 0.5)
        else:
            h /= 2
            if h < HOMOTOPY_MIN_STEP:
                return None
    return SolverResult(q, last.residual, total, True, last.polish)
