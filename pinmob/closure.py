"""Loop closure: residuals, closure checks, and assembly by damped least squares.

A configuration is closed when every limb tip has the platform frame's pose.
The residual of limb i is ``log6(oM_p^-1 oM_i)`` (platform frame p, tip i),
split into a position part [m] and a rotation part [rad]. Tolerances are
unit-invariant: the position part is divided by the mechanism's length scale L.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .exceptions import ClosureError
from .mechanism import Mechanism
from .screw import Array, twist_scaling

#: Default closure tolerance: position residual / L and rotation residual [rad].
CLOSURE_TOL = 1e-6


def relative_error(model: pin.Model, data: pin.Data, frame_a: int, frame_b: int) -> tuple[Array, Array]:
    """Error of frame b relative to frame a and its Jacobian; kinematics must be computed.

    ``e = log6(oM_a^-1 oM_b)`` (6,), ``J = Jlog6(M) (J_b - Ad(M^-1) J_a)`` (6, nv),
    with the frame Jacobians in their LOCAL frames.
    """
    oma, omb = data.oMf[frame_a], data.oMf[frame_b]
    m = oma.actInv(omb)
    e = pin.log6(m).vector
    ja = pin.getFrameJacobian(model, data, frame_a, pin.LOCAL)
    jb = pin.getFrameJacobian(model, data, frame_b, pin.LOCAL)
    return e, pin.Jlog6(m) @ (jb - m.inverse().action @ ja)


def pose_error(model: pin.Model, data: pin.Data, frame: int, target: pin.SE3) -> tuple[Array, Array]:
    """``e = log6(target^-1 oM_f)`` and its Jacobian (6, nv); kinematics must be computed."""
    m = target.actInv(data.oMf[frame])
    return pin.log6(m).vector, pin.Jlog6(m) @ pin.getFrameJacobian(model, data, frame, pin.LOCAL)


def compute_kinematics(model: pin.Model, data: pin.Data, q: Array) -> None:
    """Joint placements, joint Jacobians and frame placements at q (once per configuration)."""
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)


def tip_residuals(mech: Mechanism, data: pin.Data) -> dict[str, tuple[float, float]]:
    """Per limb: (position [m], rotation [rad]) residual of its tip w.r.t. the platform frame."""
    pid = mech.platform_id
    out = {}
    for limb in mech.limbs:
        e = pin.log6(data.oMf[pid].actInv(data.oMf[limb.tip_id])).vector
        out[limb.name] = (float(np.linalg.norm(e[:3])), float(np.linalg.norm(e[3:])))
    return out


def is_within(residuals: dict[str, tuple[float, float]], length: float, tol: float) -> bool:
    """True when every residual is within ``tol`` (position scaled by ``length``)."""
    return all(p / length <= tol and r <= tol for p, r in residuals.values())


def format_residuals(residuals: dict[str, tuple[float, float]]) -> str:
    """``A: 1.2e-03 m, 4.0e-04 rad; B: ...``"""
    return "; ".join(f"{k}: {p:.2e} m, {r:.2e} rad" for k, (p, r) in residuals.items())


def check_closed(
    mech: Mechanism, q: Array, tol: float = CLOSURE_TOL, what: str = "configuration", data: pin.Data | None = None
) -> dict[str, tuple[float, float]]:
    """Raise :class:`ClosureError` unless all limb tips have the platform's pose at q.

    Returns:
        the residual per limb (position [m], rotation [rad]).
    """
    q = mech.check_q(q)
    if data is None:
        data = mech.model.createData()
        compute_kinematics(mech.model, data, q)
    res = tip_residuals(mech, data)
    if not is_within(res, mech.length_scale, tol):
        raise ClosureError(
            f"{what} of {mech.name!r} does not close: limb tip residuals {format_residuals(res)} "
            f"(tolerance {tol:g} x L = {tol * mech.length_scale:.2e} m, {tol:g} rad)",
            res,
        )
    return res


@dataclass(frozen=True)
class SolverResult:
    """Outcome of :func:`solve`: the configuration, the final residual norm and iterations."""

    q: Array
    residual: float
    iterations: int
    converged: bool


ResidualFn = Callable[[Array], tuple[Array, Array]]


def solve(
    model: pin.Model, residual: ResidualFn, q0: Array, tol: float = 1e-12, max_iter: int = 200, damping: float = 1e-6
) -> SolverResult:
    """Damped least squares (Levenberg-Marquardt) with backtracking line search.

    Minimises ``|e(q)|^2`` where ``residual(q) -> (e, J)`` returns the stacked
    dimensionless residual (m,) and its Jacobian (m, nv). The step is
    ``dq = -J^T (J J^T + lambda I)^-1 e``, applied with ``pin.integrate``;
    lambda grows when a step fails and shrinks when it succeeds.

    Args:
        tol: convergence threshold on ``max |e|`` (dimensionless).
    """
    q = np.array(q0, float)
    e, jac = residual(q)
    err = float(np.max(np.abs(e))) if e.size else 0.0
    lam = damping
    it = 0
    for it in range(1, max_iter + 1):
        if err <= tol:
            return SolverResult(q, err, it - 1, True)
        jjt = jac @ jac.T
        dq = -jac.T @ np.linalg.solve(jjt + lam * np.eye(len(e)), e)
        step, accepted = 1.0, False
        cost = float(e @ e)
        while step > 1e-4:
            qn = pin.integrate(model, q, step * dq)
            en, jn = residual(qn)
            if float(en @ en) < cost:
                q, e, jac, accepted = qn, en, jn, True
                break
            step *= 0.5
        if accepted:
            lam = max(lam * 0.3, 1e-12)
        else:
            lam *= 10.0
            if lam > 1e6:
                break
        err = float(np.max(np.abs(e)))
    return SolverResult(q, err, it, err <= tol)


def assemble_pose(
    mech: Mechanism, pose: pin.SE3, seed: Array | None = None, tol: float = CLOSURE_TOL, max_iter: int = 200
) -> Array:
    """Closed configuration whose platform frame has ``pose`` (inverse kinematics of every limb).

    Residuals: the platform frame against ``pose`` and every limb tip against
    the platform frame, position parts divided by L.

    Raises:
        ClosureError: the solver did not reach ``tol``; the message gives the
            residual per limb.
    """
    model = mech.model
    data = model.createData()
    scale = twist_scaling(mech.length_scale)
    pid = mech.platform_id
    tips = [limb.tip_id for limb in mech.limbs if limb.tip_id != pid]

    def residual(q: Array) -> tuple[Array, Array]:
        compute_kinematics(model, data, q)
        blocks = [pose_error(model, data, pid, pose)] + [relative_error(model, data, pid, t) for t in tips]
        e = np.concatenate([scale * b[0] for b in blocks])
        jac = np.vstack([scale[:, None] * b[1] for b in blocks])
        return e, jac

    q0 = mech.neutral() if seed is None else mech.check_q(seed)
    result = solve(model, residual, q0, tol=min(1e-12, tol * 1e-3), max_iter=max_iter)
    compute_kinematics(model, data, result.q)
    res = tip_residuals(mech, data)
    e_pose = pin.log6(pose.actInv(data.oMf[pid])).vector
    res_pose = (float(np.linalg.norm(e_pose[:3])), float(np.linalg.norm(e_pose[3:])))
    if not is_within({**res, "pose": res_pose}, mech.length_scale, tol):
        raise ClosureError(
            f"could not assemble {mech.name!r} at platform pose xyz={np.round(pose.translation, 6).tolist()}: "
            f"after {result.iterations} iterations, platform pose residual {res_pose[0]:.2e} m, {res_pose[1]:.2e} rad; "
            f"limb tips {format_residuals(res)}. The pose may be out of reach; try another seed.",
            {**res, "pose": res_pose},
        )
    return result.q


def assemble_joints(
    mech: Mechanism, values: dict[str, float], seed: Array, tol: float = CLOSURE_TOL, max_iter: int = 200
) -> Array:
    """Closed configuration with the named one-degree joints held at ``values`` (e.g. the actuators).

    Forward kinematics when ``values`` holds the actuated joints; with no value,
    the closed configuration nearest (in the solver's sense) to ``seed``.
    Residuals: every limb tip against the platform frame (position / L) and
    ``q_j - value_j`` for each held joint (prismatic / L, revolute [rad]).

    Raises:
        ConfigurationError: a joint is unknown or has more than one coordinate.
        ClosureError: the solver did not close the loops within ``tol``.
    """
    from .exceptions import ConfigurationError, choices

    model = mech.model
    data = model.createData()
    scale = twist_scaling(mech.length_scale)
    pid = mech.platform_id
    tips = [limb.tip_id for limb in mech.limbs if limb.tip_id != pid]
    held = []
    for name, value in values.items():
        if not model.existJointName(name):
            raise ConfigurationError(
                f"unknown joint {name!r} in {mech.name!r}; valid: {choices(list(model.names)[1:])}"
            )
        joint = model.joints[model.getJointId(name)]
        if joint.nq != 1:
            raise ConfigurationError(f"joint {name!r} has {joint.nq} coordinates; only one-degree joints can be held")
        unit = 1.0 / mech.length_scale if joint.shortname().startswith("JointModelP") else 1.0
        held.append((joint.idx_q, joint.idx_v, float(value), unit))

    def residual(q: Array) -> tuple[Array, Array]:
        compute_kinematics(model, data, q)
        blocks = [relative_error(model, data, pid, t) for t in tips]
        e = [scale * b[0] for b in blocks]
        jac = [scale[:, None] * b[1] for b in blocks]
        if held:
            rows = np.zeros((len(held), model.nv))
            for r, (_, iv, _, unit) in enumerate(held):
                rows[r, iv] = unit
            e.append(np.array([unit * (q[iq] - v) for iq, _, v, unit in held]))
            jac.append(rows)
        return np.concatenate(e), np.vstack(jac)

    result = solve(model, residual, mech.check_q(seed), tol=min(1e-12, tol * 1e-3), max_iter=max_iter)
    compute_kinematics(model, data, result.q)
    res = tip_residuals(mech, data)
    off = max((abs(result.q[iq] - v) * unit for iq, _, v, unit in held), default=0.0)
    if not is_within(res, mech.length_scale, tol) or off > tol:
        raise ClosureError(
            f"could not close {mech.name!r} with joints held at {values}: after {result.iterations} iterations, "
            f"limb tips {format_residuals(res)}, held joints off by {off:.2e}. The values may be out of reach.",
            res,
        )
    return result.q
