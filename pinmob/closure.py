"""Loop closure: residuals, closure checks, and assembly by damped least squares.

A configuration is closed when every limb tip has the platform frame's pose
and every :class:`~pinmob.mechanism.Closure` holds. The residual of limb i is
``log6(oM_p^-1 oM_i)`` (platform frame p, tip i); that of a closure between
frames a and b depends on its type (:func:`closure_error`). Each is split into
a position part [m] and a rotation part [rad]. Tolerances are unit-invariant:
the position part is divided by the mechanism's length scale L.

Assembly (all by :func:`solve` on the stacked dimensionless residuals):
:func:`project` (nearest closed configuration from any q),
:func:`solve_actuated` (forward kinematics of the closed chain: passive joints
from actuated joint values), :func:`assemble_pose` (inverse kinematics: every
limb from a platform pose), :func:`find_closed` (neutral first, then seeded
random restarts) and :func:`assembly_modes` (distinct solutions from several
seeds).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from .exceptions import ClosureError, ConfigurationError, FrameError, choices
from .mechanism import Closure, Mechanism
from .screw import Array, Mask, twist_scaling

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


def _perp(u: Array) -> Array:
    """(2, 3) orthonormal rows spanning the plane normal to unit u."""
    a = np.eye(3)[int(np.argmin(np.abs(u)))]
    e1 = np.cross(u, a)
    e1 /= np.linalg.norm(e1)
    return np.vstack([e1, np.cross(u, e1)])


def _selection(c: Closure) -> tuple[Array, Mask]:
    """Rows S (k, 6) of ``log6(aMb)`` forbidden by a revolute/cylindrical/planar closure, and their linear mask."""
    u = np.asarray(c.axis, float)
    p, z = _perp(u), np.zeros((2, 3))
    lin = {
        "revolute": np.vstack([np.eye(3), np.zeros((3, 3))]).T,
        "cylindrical": np.hstack([p, z]),
        "planar": np.hstack([u, np.zeros(3)])[None],
    }[c.type]
    ang = np.hstack([z, p])
    return np.vstack([lin, ang]), np.array([True] * lin.shape[0] + [False] * 2)


def closure_error(model: pin.Model, data: pin.Data, c: Closure) -> tuple[Array, Array, Mask]:
    """Residual of one closure, its Jacobian and which rows are lengths; kinematics must be computed.

    With ``M = oM_a^-1 oM_b`` (pose of b in a):

    - ``6d``: ``e = log6(M)`` (:func:`relative_error`);
    - ``3d``: ``e = R_a^T (p_b - p_a)``, ``de/dt = R_a^T (v_b - v_a) + e x w_a``
      (origin velocities in world axes, w_a in frame a);
    - ``revolute``, ``cylindrical``, ``planar``: ``e = S log6(M)``, the rows S
      of the relative motion the closure forbids (zero exactly on the allowed
      subgroup, for relative rotations below pi);
    - ``universal``: the 3d residual and ``u . (R_ab u_b)`` (hinge axes
      perpendicular), whose rate is ``(R_ab u_b x u) . w_rel`` (w_rel the
      relative angular velocity in frame a).

    Returns:
        e (k,), J (k, nv) and a boolean mask (k,) of the rows in metres (the
        others are in radians or dimensionless).
    """
    a, b = c.frame_a_id, c.frame_b_id
    if c.type == "6d":
        e, jac = relative_error(model, data, a, b)
        return e, jac, np.array([True] * 3 + [False] * 3)
    if c.type in ("revolute", "cylindrical", "planar"):
        e, jac = relative_error(model, data, a, b)
        sel, lin = _selection(c)
        return sel @ e, sel @ jac, lin
    oma, omb = data.oMf[a], data.oMf[b]
    ra = oma.rotation
    e = ra.T @ (omb.translation - oma.translation)
    ja_w = pin.getFrameJacobian(model, data, a, pin.LOCAL_WORLD_ALIGNED)
    jb_w = pin.getFrameJacobian(model, data, b, pin.LOCAL_WORLD_ALIGNED)
    wa_local = ra.T @ ja_w[3:]
    jac = ra.T @ (jb_w[:3] - ja_w[:3]) + pin.skew(e) @ wa_local
    if c.type == "3d":
        return e, jac, np.ones(3, bool)
    # universal
    u = np.asarray(c.axis, float)
    w = ra.T @ omb.rotation @ np.asarray(c.axis_b, float)
    w_rel = ra.T @ (jb_w[3:] - ja_w[3:])
    row = np.cross(w, u) @ w_rel
    return np.append(e, u @ w), np.vstack([jac, row]), np.array([True] * 3 + [False])


def closure_residuals(
    mech: Mechanism, data: pin.Data, closures: tuple[Closure, ...] | None = None
) -> dict[str, tuple[float, float]]:
    """Per closure (default: ``mech.closures``): (position [m], rotation [rad]) residual norms."""
    out = {}
    for c in mech.closures if closures is None else closures:
        e, _, lin = closure_error(mech.model, data, c)
        out[c.name] = (float(np.linalg.norm(e[lin])), float(np.linalg.norm(e[~lin])))
    return out


def stacked_error(
    mech: Mechanism, model: pin.Model, data: pin.Data, closures: tuple[Closure, ...]
) -> tuple[Array, Array]:
    """Dimensionless stacked residual (sum k_c,) and Jacobian (sum k_c, nv): length rows divided by L."""
    if not closures:
        return np.zeros(0), np.zeros((0, model.nv))
    es, js = [], []
    for c in closures:
        e, jac, lin = closure_error(model, data, c)
        s = np.where(lin, 1.0 / mech.length_scale, 1.0)
        es.append(s * e)
        js.append(s[:, None] * jac)
    return np.concatenate(es), np.vstack(js)


def compute_kinematics(model: pin.Model, data: pin.Data, q: Array) -> None:
    """Joint placements, joint Jacobians and frame placements at q (once per configuration)."""
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)


def closed_kinematics(mech: Mechanism, q: Array, tol: float = CLOSURE_TOL) -> pin.Data:
    """Fresh data with the kinematics at q (:func:`compute_kinematics`), once q is checked to close.

    Raises:
        ClosureError: q does not close within ``tol`` (:func:`check_closed`).
    """
    data = mech.model.createData()
    compute_kinematics(mech.model, data, q)
    check_closed(mech, q, tol, data=data)
    return data


def tip_residuals(mech: Mechanism, data: pin.Data) -> dict[str, tuple[float, float]]:
    """Per limb: (position [m], rotation [rad]) residual of its tip w.r.t. the platform frame."""
    if not mech.has_platform:
        return {}
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
    res = tip_residuals(mech, data) | closure_residuals(mech, data)
    if not is_within(res, mech.length_scale, tol):
        raise ClosureError(
            f"{what} of {mech.name!r} does not close: residuals {format_residuals(res)} "
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
    mark, mark_it = float(e @ e), 0  # stall detection: stop when 30 iterations gain < 0.1 %
    for it in range(1, max_iter + 1):
        if err <= tol:
            return SolverResult(q, err, it - 1, True)
        if it - mark_it >= 30:
            if float(e @ e) > 0.999 * mark:
                break
            mark, mark_it = float(e @ e), it
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
    if not mech.has_platform:
        raise ConfigurationError(f"{mech.name!r} has no platform frame: a platform pose cannot be assembled")
    closures = mech.all_closures

    def residual(q: Array) -> tuple[Array, Array]:
        compute_kinematics(model, data, q)
        e0, j0 = pose_error(model, data, pid, pose)
        e1, j1 = stacked_error(mech, model, data, closures)
        return np.concatenate([scale * e0, e1]), np.vstack([scale[:, None] * j0, j1])

    q0 = mech.neutral() if seed is None else mech.check_q(seed)
    result = solve(model, residual, q0, tol=min(1e-12, tol * 1e-3), max_iter=max_iter)
    compute_kinematics(model, data, result.q)
    res = tip_residuals(mech, data) | closure_residuals(mech, data)
    e_pose = pin.log6(pose.actInv(data.oMf[pid])).vector
    res_pose = (float(np.linalg.norm(e_pose[:3])), float(np.linalg.norm(e_pose[3:])))
    if not is_within({**res, "pose": res_pose}, mech.length_scale, tol):
        raise ClosureError(
            f"could not assemble {mech.name!r} at platform pose xyz={np.round(pose.translation, 6).tolist()}: "
            f"after {result.iterations} iterations, platform pose residual {res_pose[0]:.2e} m, {res_pose[1]:.2e} rad; "
            f"closures {format_residuals(res)}. The pose may be out of reach; try another seed.",
            {**res, "pose": res_pose},
        )
    return result.q


# --------------------------------------------------------------------------- assembly of closed chains


@dataclass(frozen=True)
class Assembly:
    """A closed configuration found by the solver.

    Attributes:
        q: (nq,) the configuration.
        residuals: per limb / closure, (position [m], rotation [rad]).
        residual: largest dimensionless residual (position / L, rotation).
        iterations: solver iterations.
        method: how it was found, e.g. ``neutral``, ``given``, ``random restart 3``.
    """

    q: Array
    residuals: dict[str, tuple[float, float]]
    residual: float
    iterations: int
    method: str

    def to_dict(self) -> dict[str, object]:
        return {
            "method": self.method,
            "residual": self.residual,
            "iterations": self.iterations,
            "q": [float(x) for x in self.q],
        }


def linear_velocity_mask(model: pin.Model) -> Mask:
    """(nv,) True where a velocity component is a translation [m/s] (prismatic, free-flyer linear part).

    Read from each joint's motion subspace at the neutral configuration: a
    column with no angular part is a translation.
    """
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    mask = np.zeros(model.nv, bool)
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nv == 0:
            continue
        sub = np.asarray(data.joints[j].S)
        mask[joint.idx_v : joint.idx_v + joint.nv] = np.linalg.norm(sub[3:], axis=0) < 1e-12
    return mask


def joint_velocity_indices(mech: Mechanism, names: tuple[str, ...] | list[str]) -> Array:
    """Velocity indices of one-degree joints by name; a :class:`FrameError` for unknown or multi-degree joints."""
    model = mech.model
    out = []
    for name in names:
        if not model.existJointName(name) or name == "universe":
            raise FrameError(f"unknown joint {name!r} in {mech.name!r}; valid: {choices(list(model.names)[1:])}")
        joint = model.joints[model.getJointId(name)]
        if joint.nv != 1:
            raise ConfigurationError(
                f"joint {name!r} ({joint.shortname()}) has {joint.nv} degrees of freedom; only one-degree joints can be actuated here"
            )
        out.append(joint.idx_v)
    return np.array(out, int)


def _finish(mech: Mechanism, q: Array, iterations: int, method: str, tol: float, what: str) -> Assembly:
    data = mech.model.createData()
    compute_kinematics(mech.model, data, q)
    res = tip_residuals(mech, data) | closure_residuals(mech, data)
    worst = max([max(p / mech.length_scale, r) for p, r in res.values()], default=0.0)
    if worst > tol:
        raise ClosureError(
            f"{what} of {mech.name!r} did not converge: after {iterations} iterations, residuals "
            f"{format_residuals(res)} (tolerance {tol:g} x L = {tol * mech.length_scale:.2e} m, {tol:g} rad)",
            res,
        )
    return Assembly(q, res, worst, iterations, method)


def project(
    mech: Mechanism, q0: Array | None = None, tol: float = CLOSURE_TOL, max_iter: int = 200, method: str = "projection"
) -> Assembly:
    """Closed configuration near ``q0`` (default neutral): damped least squares on every closure residual.

    Each step is the minimum-norm correction ``dq = -J^T (J J^T + lambda I)^-1 e``,
    so the solver moves as little as it can from q0.

    Raises:
        ClosureError: the residual did not reach ``tol``; it carries the residuals.
    """
    model = mech.model
    data = model.createData()
    closures = mech.all_closures

    def residual(q: Array) -> tuple[Array, Array]:
        compute_kinematics(model, data, q)
        return stacked_error(mech, model, data, closures)

    start = mech.neutral() if q0 is None else mech.check_q(q0)
    result = solve(model, residual, start, tol=min(1e-12, tol * 1e-3), max_iter=max_iter)
    return _finish(mech, result.q, result.iterations, method, tol, "projection onto the closed set")


def solve_actuated(
    mech: Mechanism,
    values: Mapping[str, float],
    seed: Array | None = None,
    tol: float = CLOSURE_TOL,
    max_iter: int = 200,
) -> Assembly:
    """Forward kinematics of the closed chain: passive joints from actuated joint values.

    Residuals: every closure, and ``q_j - value_j`` for each given one-degree
    joint (a length divided by L for a prismatic joint). The seed selects the
    assembly mode.

    Raises:
        ClosureError: no closed configuration with these values was reached from the seed.
    """
    model = mech.model
    data = model.createData()
    names = list(values)
    idx = joint_velocity_indices(mech, names)
    scale = np.where(linear_velocity_mask(model)[idx], 1.0 / mech.length_scale, 1.0)
    start = mech.neutral() if seed is None else mech.check_q(seed)
    target = mech.q_from_joints(values, base=start)
    closures = mech.all_closures

    def residual(q: Array) -> tuple[Array, Array]:
        compute_kinematics(model, data, q)
        e, jac = stacked_error(mech, model, data, closures)
        ea = -scale * pin.difference(model, q, target)[idx]
        ja = np.zeros((len(idx), model.nv))
        ja[np.arange(len(idx)), idx] = scale
        return np.concatenate([e, ea]), np.vstack([jac, ja])

    result = solve(model, residual, start, tol=min(1e-12, tol * 1e-3), max_iter=max_iter)
    off = np.abs(pin.difference(model, result.q, target)[idx]) * scale
    if off.size and off.max() > tol:
        bad = names[int(np.argmax(off))]
        raise ClosureError(
            f"forward kinematics of {mech.name!r}: joint {bad!r} ended {off.max():.2e} away from its value; the values may not be reachable"
        )
    return _finish(
        mech, result.q, result.iterations, "actuated values", tol, "forward kinematics (actuated joint values)"
    )


def random_configuration(mech: Mechanism, rng: np.random.Generator, spread: float = np.pi) -> Array:
    """A seed: neutral moved by uniform random joint velocities in [-spread, spread] (lengths times L)."""
    lin = linear_velocity_mask(mech.model)
    dv = rng.uniform(-spread, spread, mech.model.nv) * np.where(lin, mech.length_scale / np.pi, 1.0)
    return pin.integrate(mech.model, mech.neutral(), dv)


def find_closed(
    mech: Mechanism, q0: Array | None = None, restarts: int = 20, seed: int = 0, tol: float = CLOSURE_TOL
) -> Assembly:
    """A closed configuration: projection from q0 (default neutral), then from seeded random restarts.

    Returns the first that closes; its ``method`` says which: ``neutral`` or
    ``given`` (closed as it is), ``projection from neutral`` (or ``given``), or
    ``projection from random restart k (seed s)``.

    Raises:
        ClosureError: nothing closed; carries the best residuals seen.
        ConfigurationError: restarts is negative.
    """
    if restarts < 0:
        raise ConfigurationError(f"the number of random restarts (--restarts) must be at least 0, got {restarts}")
    rng = np.random.default_rng(seed)
    best: ClosureError | None = None
    starts = [(mech.neutral() if q0 is None else q0, "neutral" if q0 is None else "given")]
    for k in range(restarts + 1):
        q_start, label = starts[0] if k == 0 else (random_configuration(mech, rng), f"random restart {k} (seed {seed})")
        try:
            found = project(mech, q_start, tol=tol, method=f"projection from {label}")
            return found if found.iterations else replace(found, method=label)
        except ClosureError as exc:
            if best is None or _worst(exc) < _worst(best):
                best = exc
    assert best is not None
    raise ClosureError(
        f"no closed configuration of {mech.name!r} found from the neutral configuration and {restarts} random restarts; best: {best}",
        best.residuals,
    )


def _worst(exc: ClosureError) -> float:
    return max([max(p, r) for p, r in exc.residuals.values()], default=np.inf)


def configuration_distance(mech: Mechanism, q1: Array, q2: Array) -> float:
    """Largest joint difference between two configurations [rad, or m / L]; revolute angles modulo 2 pi."""
    d = pin.difference(mech.model, q1, q2)
    lin = linear_velocity_mask(mech.model)
    d = np.where(lin, d / mech.length_scale, np.angle(np.exp(1j * d)))
    return float(np.max(np.abs(d))) if d.size else 0.0


def assembly_modes(
    mech: Mechanism,
    values: Mapping[str, float] | None = None,
    seeds: int = 16,
    seed: int = 0,
    tol: float = CLOSURE_TOL,
    distinct: float = 1e-3,
) -> list[Assembly]:
    """Distinct closed configurations reached from the neutral and ``seeds`` random seeds.

    With ``values`` (actuated joint values), each is a forward-kinematics
    solution (:func:`solve_actuated`); otherwise a projection. Two solutions
    are the same mode when :func:`configuration_distance` is below ``distinct``.
    Seeds that fail to converge are skipped.
    """
    rng = np.random.default_rng(seed)
    found: list[Assembly] = []
    for k in range(seeds + 1):
        start = mech.neutral() if k == 0 else random_configuration(mech, rng)
        label = "neutral" if k == 0 else f"random seed {k} (seed {seed})"
        try:
            sol = solve_actuated(mech, values, start, tol) if values else project(mech, start, tol)
        except ClosureError:
            continue
        if all(configuration_distance(mech, sol.q, other.q) > distinct for other in found):
            found.append(Assembly(sol.q, sol.residuals, sol.residual, sol.iterations, f"{sol.method} from {label}"))
    return found


def unclosable(mech: Mechanism, restarts: int = 4, seed: int = 0) -> tuple[str, ...]:
    """Names of the closures of ``mech.closures`` that cannot be closed even on their own.

    Each closure alone (no limb, no other closure) is projected from the
    neutral configuration and ``restarts`` random seeds. A closure that never
    closes over-constrains its loop's joints: e.g. a ``6d`` weld on a loop
    whose joints cannot bring the two frames to the same orientation.
    """
    out = []
    for c in mech.closures:
        alone = replace(mech, limbs=(), platform="", closures=(c,))
        try:
            find_closed(alone, restarts=restarts, seed=seed)
        except ClosureError:
            out.append(c.name)
    return tuple(out)


def relax(mech: Mechanism, names: tuple[str, ...] | list[str]) -> Mechanism:
    """A copy of ``mech`` whose named closures become ``3d`` (the frames' origins meet; orientation is free)."""
    known = {c.name for c in mech.closures}
    for n in names:
        if n not in known:
            raise ConfigurationError(f"no closure {n!r} in {mech.name!r}; valid: {choices(known)}")
    closures = tuple(replace(c, type="3d", axis=None, axis_b=None) if c.name in names else c for c in mech.closures)
    return replace(
        mech,
        closures=closures,
        description=(mech.description + f" [closures relaxed to 3d: {', '.join(names)}]").strip(),
    )


def find_closed_relaxed(
    mech: Mechanism, restarts: int = 20, seed: int = 0, relax_restarts: int = 0
) -> tuple[Mechanism, Assembly, tuple[str, ...]]:
    """Close ``mech``, relaxing over-constraining closures to ``3d`` only where it cannot be closed as declared.

    First :func:`find_closed` as declared; if that fails, relax the closures
    that cannot close on their own (:func:`unclosable`), then, while it still
    fails, the non-3d closure with the largest residual at the best attempt.
    Returns the (possibly relaxed) mechanism, the assembly and the relaxed
    closure names, so that a report can say exactly what was changed.
    """
    try:
        return mech, find_closed(mech, restarts=restarts, seed=seed), ()
    except ClosureError:
        pass
    names = list(unclosable(mech, seed=seed))
    while True:
        current = relax(mech, names)
        try:
            return current, find_closed(current, restarts=relax_restarts, seed=seed), tuple(names)
        except ClosureError as exc:
            left = {c.name for c in current.closures if c.type != "3d"}
            worst = [(max(p / mech.length_scale, r), n) for n, (p, r) in exc.residuals.items() if n in left]
            if not worst:
                raise
            names.append(max(worst)[1])


def assemble_joints(
    mech: Mechanism, values: Mapping[str, float], seed: Array, tol: float = CLOSURE_TOL, max_iter: int = 200
) -> Array:
    """Closed configuration with the named one-degree joints held at ``values``: :func:`solve_actuated`'s ``q``.

    Raises:
        FrameError, ConfigurationError: a joint is unknown or has more than one degree of freedom.
        ClosureError: the loops did not close with these values from ``seed``.
    """
    return solve_actuated(mech, values, seed, tol, max_iter).q
