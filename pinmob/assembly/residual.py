"""Loop-closure residuals and closure checks.

A configuration is closed when every limb tip has the platform frame's pose
and every :class:`~pinmob.model.closure.Closure` holds. The residual of limb i is
``log6(oM_p^-1 oM_i)`` (platform frame p, tip i); that of a closure between
frames a and b depends on its type (:func:`closure_error`). Each is split into
a position part [m] and a rotation part [rad]. Tolerances are unit-invariant:
the position part is divided by the mechanism's length scale L, and one
measure (:func:`worst_residual`, ``max(|p| / L, |r|)``) decides every
comparison.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from pinmob.assembly.closure_miss import CAD_GAP_MAX, format_worst, tolerance_hint
from pinmob.assembly.coupling import coupling_error, tendon_error
from pinmob.assembly.solver import ResidualFn
from pinmob.exceptions import ArgumentError, ClosureError
from pinmob.model import CLOSURE_TOL, Closure, Mechanism, acquire, borrowed, release_with
from pinmob.screw import Array, Mask

#: Valid range of a closure tolerance (dimensionless): below, round-off decides; above, nothing is closed.
#: The closure tolerance's range: round-off of one link at the bottom, a CAD gap at the top (beyond, loops that
#: do not close would be analysed as if they did: a four-bar open by 0.09 L came out with 3 DoF at 0.1)
CLOSURE_TOL_MIN, CLOSURE_TOL_MAX = 1e-14, CAD_GAP_MAX

#: Residual norms by limb or closure name: (position [m], rotation [rad]).
Residuals = dict[str, tuple[float, float]]


def check_closure_tol(tol: object, name: str = "closure_tol") -> float:
    """A validated closure tolerance: a real number in [CLOSURE_TOL_MIN, CLOSURE_TOL_MAX] (position / L, rad).

    Raises:
        ArgumentError: not a real number, not finite, or out of range (``name``: the parameter named).
    """
    if isinstance(tol, bool) or not isinstance(tol, (int, float, np.integer, np.floating)):
        raise ArgumentError(f"{name} must be a number, got {tol!r} ({type(tol).__name__})", name, tol)
    value = float(tol)
    if not (np.isfinite(value) and CLOSURE_TOL_MIN <= value <= CLOSURE_TOL_MAX):
        raise ArgumentError(
            f"{name} must be a finite number in [{CLOSURE_TOL_MIN:g}, {CLOSURE_TOL_MAX:g}] (largest residual "
            f"allowed: position / L and rotation [rad]), e.g. {CLOSURE_TOL:g}; got {tol!r}",
            name,
            tol,
        )
    return value


def frame_jacobian(model: pin.Model, data: pin.Data, frame: int, ref: pin.ReferenceFrame) -> Array:
    """``pin.getFrameJacobian`` as a (6, nv) array (Pinocchio returns a (6,) vector when nv = 1)."""
    jac: Array = pin.getFrameJacobian(model, data, frame, ref)
    return jac if jac.ndim == 2 else jac.reshape(6, model.nv)


def relative_error(model: pin.Model, data: pin.Data, frame_a: int, frame_b: int) -> tuple[Array, Array]:
    """Error of frame b relative to frame a and its Jacobian; kinematics must be computed.

    ``e = log6(oM_a^-1 oM_b)`` (6,), ``J = Jlog6(M) (J_b - Ad(M^-1) J_a)`` (6, nv),
    with the frame Jacobians in their LOCAL frames.
    """
    oma, omb = data.oMf[frame_a], data.oMf[frame_b]
    m = oma.actInv(omb)
    e = pin.log6(m).vector
    ja = frame_jacobian(model, data, frame_a, pin.LOCAL)
    jb = frame_jacobian(model, data, frame_b, pin.LOCAL)
    return e, pin.Jlog6(m) @ (jb - m.inverse().action @ ja)


def pose_error(model: pin.Model, data: pin.Data, frame: int, target: pin.SE3) -> tuple[Array, Array]:
    """``e = log6(target^-1 oM_f)`` and its Jacobian (6, nv); kinematics must be computed."""
    m = target.actInv(data.oMf[frame])
    return pin.log6(m).vector, pin.Jlog6(m) @ frame_jacobian(model, data, frame, pin.LOCAL)


def normal_rows(u: Array) -> Array:
    """(2, 3) orthonormal rows spanning the plane normal to unit u."""
    a = np.eye(3)[int(np.argmin(np.abs(u)))]
    e1 = np.cross(u, a)
    e1 /= np.linalg.norm(e1)
    return np.vstack([e1, np.cross(u, e1)])


def _selection(c: Closure) -> tuple[Array, Mask]:
    """Rows S (k, 6) of ``log6(aMb)`` forbidden by a closure of :data:`_POSE_ROWS`, and their linear mask."""
    if c.type == "orientation":
        return np.hstack([np.zeros((3, 3)), np.eye(3)]), np.zeros(3, bool)
    u = np.asarray(c.axis, float)
    p, z = normal_rows(u), np.zeros((2, 3))
    if c.type == "prismatic":  # the two translations normal to u and every rotation
        return np.vstack([np.hstack([p, z]), np.hstack([np.zeros((3, 3)), np.eye(3)])]), np.arange(5) < 2
    if c.type == "parallel_axes":
        return np.hstack([z, p]), np.zeros(2, bool)
    lin = {
        "revolute": np.vstack([np.eye(3), np.zeros((3, 3))]).T,
        "cylindrical": np.hstack([p, z]),
        "planar": np.hstack([u, np.zeros(3)])[None],
    }[c.type]
    ang = np.hstack([z, p])
    return np.vstack([lin, ang]), np.array([True] * lin.shape[0] + [False] * 2)


#: The rows of a ``6d``, ``3d`` and ``universal`` closure's residual that are lengths (read-only, shared).
_WELD_LENGTHS, _BALL_LENGTHS, _UNIVERSAL_LENGTHS = np.arange(6) < 3, np.ones(3, bool), np.arange(4) < 3
_INLINE_LENGTHS, _INPLANE_LENGTHS, _PLANAR_WELD_LENGTHS = np.ones(2, bool), np.ones(1, bool), np.arange(3) < 2
_ANGLE_LENGTHS = np.zeros(1, bool)
for _mask in (_WELD_LENGTHS, _BALL_LENGTHS, _UNIVERSAL_LENGTHS, _INLINE_LENGTHS, _INPLANE_LENGTHS):
    _mask.flags.writeable = False
_PLANAR_WELD_LENGTHS.flags.writeable = _ANGLE_LENGTHS.flags.writeable = False


#: Closure types whose rows are those of the relative pose's ``log6``, and those built from b's origin in frame a.
_POSE_ROWS = ("revolute", "cylindrical", "prismatic", "planar", "orientation", "parallel_axes")
_POINT_ROWS = ("3d", "universal", "inline", "inplane", "planar_weld", "perpendicular")


def _point_rows(c: Closure, e: Array, jac: Array, turn: tuple[Array, Array] | None) -> tuple[Array, Array, Mask]:
    """A point-based closure's rows from b's origin in frame a ``e`` (3,) with its Jacobian (3, nv).

    ``turn``: the relative rotation's ``log3`` in frame a and its Jacobian (3, nv) (``planar_weld``), or for
    ``universal`` and ``perpendicular`` the value ``u . (R_ab u_b)`` (as a (1,) array) and its rate row (1, nv).
    """
    if c.type == "3d":
        return e, jac, _BALL_LENGTHS
    u = np.asarray(c.axis, float)
    if c.type == "inline":
        p = normal_rows(u)
        return p @ e, p @ jac, _INLINE_LENGTHS
    if c.type == "inplane":
        return np.array([u @ e]), (u @ jac)[None], _INPLANE_LENGTHS
    value, rate = turn if turn is not None else (np.zeros(3), np.zeros((3, jac.shape[1])))
    if c.type == "planar_weld":
        p = normal_rows(u)
        return np.append(p @ e, u @ value), np.vstack([p @ jac, u @ rate]), _PLANAR_WELD_LENGTHS
    if c.type == "perpendicular":
        return value, rate, _ANGLE_LENGTHS
    return np.append(e, value), np.vstack([jac, rate]), _UNIVERSAL_LENGTHS  # universal


def closure_error(model: pin.Model, data: pin.Data, c: Closure) -> tuple[Array, Array, Mask]:
    """Residual of one closure, its Jacobian and which rows are lengths; kinematics must be computed.

    With ``M = oM_a^-1 oM_b`` (pose of b in a), ``p = R_a^T (p_b - p_a)`` (b's origin in frame a) and
    ``r = log3(R_a^T R_b)`` (the relative rotation in frame a):

    - ``6d``: ``e = log6(M)`` (:func:`relative_error`);
    - ``3d``: ``e = p``, ``de/dt = R_a^T (v_b - v_a) + e x w_a``
      (origin velocities in world axes, w_a in frame a);
    - ``revolute``, ``cylindrical``, ``prismatic``, ``planar``, ``orientation``, ``parallel_axes``: ``e = S log6(M)``, the rows S
      of the relative motion the closure forbids (zero exactly on the allowed
      subgroup, for relative rotations below pi); ``orientation``: ``e = r``; ``parallel_axes``: ``e = P r``
      (``P`` (2, 3) the rows normal to u);
    - ``inline``: ``e = P p``; ``inplane``: ``e = u . p``; ``planar_weld``: ``e = [P p; u . r]``;
    - ``joint``: ``e = (q1 - r1) - sum_k c_k (q2 - r2)^k`` (:func:`coupling_error`);
    - ``tendon``: ``e = (l1 - r1) - sum_k c_k (l2 - r2)^k`` on tendon lengths (:func:`tendon_error`);
    - ``universal``: the 3d residual and ``u . (R_ab u_b)`` (hinge axes
      perpendicular), whose rate is ``(R_ab u_b x u) . w_rel`` (w_rel the
      relative angular velocity in frame a); ``perpendicular``: that last row alone.

    Returns:
        e (k,), J (k, nv) and a boolean mask (k,) of the rows in metres (the
        others are in radians or dimensionless).
    """
    a, b = c.frame_a_id, c.frame_b_id
    if c.type == "joint":
        return coupling_error(model, data, c)
    if c.type == "tendon":
        return tendon_error(model, data, c)
    if c.type == "6d":
        e, jac = relative_error(model, data, a, b)
        return e, jac, _WELD_LENGTHS
    if c.type in _POSE_ROWS:
        e, jac = relative_error(model, data, a, b)
        sel, lin = _selection(c)
        return sel @ e, sel @ jac, lin
    oma, omb = data.oMf[a], data.oMf[b]
    ra = oma.rotation
    e = ra.T @ (omb.translation - oma.translation)
    ja_w = frame_jacobian(model, data, a, pin.LOCAL_WORLD_ALIGNED)
    jb_w = frame_jacobian(model, data, b, pin.LOCAL_WORLD_ALIGNED)
    wa_local = ra.T @ ja_w[3:]
    jac = ra.T @ (jb_w[:3] - ja_w[:3]) + pin.skew(e) @ wa_local
    turn = None
    if c.type == "planar_weld":
        pose, pose_jac = relative_error(model, data, a, b)
        turn = pose[3:], pose_jac[3:]
    elif c.type in ("universal", "perpendicular"):
        u = np.asarray(c.axis, float)
        w = ra.T @ omb.rotation @ np.asarray(c.axis_b, float)
        w_rel = ra.T @ (jb_w[3:] - ja_w[3:])
        turn = np.array([u @ w]), (np.cross(w, u) @ w_rel)[None]
    return _point_rows(c, e, jac, turn)


def closure_value(model: pin.Model, data: pin.Data, c: Closure) -> tuple[Array, Mask]:
    """:func:`closure_error`'s residual and length mask without the Jacobian (the same operations on e)."""
    if c.is_coupling:
        return (coupling_error if c.type == "joint" else tendon_error)(model, data, c)[::2]
    oma, omb = data.oMf[c.frame_a_id], data.oMf[c.frame_b_id]
    if c.type in _POINT_ROWS:
        e = oma.rotation.T @ (omb.translation - oma.translation)
        turn = None
        if c.type == "planar_weld":
            turn = pin.log6(oma.actInv(omb)).vector[3:], np.zeros((3, 0))  # closure_error's bits
        elif c.type in ("universal", "perpendicular"):
            w = oma.rotation.T @ omb.rotation @ np.asarray(c.axis_b, float)
            turn = np.array([np.asarray(c.axis, float) @ w]), np.zeros((1, 0))
        value, _, lin = _point_rows(c, e, np.zeros((3, 0)), turn)
        return value, lin
    e = pin.log6(oma.actInv(omb)).vector
    if c.type == "6d":
        return e, _WELD_LENGTHS
    sel, lin = _selection(c)
    return sel @ e, lin


def closure_residuals(mech: Mechanism, data: pin.Data, closures: tuple[Closure, ...] | None = None) -> Residuals:
    """Per closure (default: ``mech.closures``): (position [m], rotation [rad]) residual norms."""
    out = {}
    for c in mech.closures if closures is None else closures:
        e, lin = closure_value(mech.model, data, c)
        out[c.name] = (_norm(e[lin]), _norm(e[~lin]))
    return out


def _norm(x: Array) -> float:
    """``np.linalg.norm`` of a contiguous vector, ``sqrt(x . x)`` (its computation, without its call overhead)."""
    return math.sqrt(x.dot(x))


def stacked_error(
    mech: Mechanism, model: pin.Model, data: pin.Data, closures: tuple[Closure, ...]
) -> tuple[Array, Array]:
    """Dimensionless stacked residual (sum k_c,) and Jacobian (sum k_c, nv): length rows divided by L."""
    if not closures:
        return np.zeros(0), np.zeros((0, model.nv))
    es, js, lins = zip(*(closure_error(model, data, c) for c in closures))
    s = np.where(np.concatenate(lins), 1.0 / mech.length_scale, 1.0)  # one scaling of all rows
    return s * np.concatenate(es), s[:, None] * np.vstack(js)


def compute_kinematics(model: pin.Model, data: pin.Data, q: Array) -> None:
    """Joint placements, joint Jacobians and frame placements at q (once per configuration)."""
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)


def tip_residuals(mech: Mechanism, data: pin.Data) -> Residuals:
    """Per limb: (position [m], rotation [rad]) residual of its tip w.r.t. the platform frame."""
    if not mech.has_platform:
        return {}
    platform = data.oMf[mech.platform_id]
    out = {}
    for limb in mech.limbs:
        e = pin.log6(platform.actInv(data.oMf[limb.tip_id])).vector
        out[limb.name] = (_norm(e[:3]), _norm(e[3:]))
    return out


def worst_residual(residuals: Residuals, length: float) -> float:
    """The one residual measure: ``max over entries of max(|p| / L, |r|)`` (dimensionless; 0 when empty).

    Args:
        residuals: per name, (position [m], rotation [rad]) norms.
        length: the mechanism's length scale L [m].
    """
    return max([max(p / length, r) for p, r in residuals.values()], default=0.0)


def is_within(residuals: Residuals, length: float, tol: float) -> bool:
    """True when :func:`worst_residual` is within ``tol``."""
    return worst_residual(residuals, length) <= tol


def mechanism_residuals(mech: Mechanism, data: pin.Data) -> Residuals:
    """Every limb tip and closure residual (position [m], rotation [rad]); kinematics must be computed."""
    return tip_residuals(mech, data) | closure_residuals(mech, data)


def format_residuals(residuals: Residuals) -> str:
    """The residuals on one line: ``A: 1.2e-03 m, 4.0e-04 rad; B: ...``."""
    return "; ".join(f"{k}: {p:.2e} m, {r:.2e} rad" for k, (p, r) in residuals.items())


def check_closed(
    mech: Mechanism, q: Array, tol: float = CLOSURE_TOL, what: str = "configuration", data: pin.Data | None = None
) -> Residuals:
    """Raise :class:`ClosureError` unless every limb tip and closure holds at q (message: :mod:`~.closure_miss`).

    Args:
        mech: the mechanism.
        q: (nq,) the configuration.
        tol: largest residual allowed (position / L and rotation [rad]).
        what: how the message calls the configuration.
        data: kinematics already computed at q (then q is not checked again), or None.

    Returns:
        the residual per limb (position [m], rotation [rad]).
    """
    if data is None:
        with borrowed(mech.model) as data:
            compute_kinematics(mech.model, data, mech.check_q(q))
            res = mechanism_residuals(mech, data)
    else:
        res = mechanism_residuals(mech, data)
    length = mech.length_scale
    if not is_within(res, length, tol):
        raise ClosureError(
            f"{what} of {mech.name!r} does not close: residuals {format_worst(res, length, tol)}"
            f"{tolerance_hint(res, length)}",
            res,
        ).naming("closure_tol")
    return res


def closure_residual(mech: Mechanism) -> ResidualFn:
    """``q -> (e, J)``: every closure residual of ``mech``, stacked dimensionless (:func:`stacked_error`)."""
    model, data, closures = mech.model, acquire(mech.model), mech.all_closures

    def residual(q: Array) -> tuple[Array, Array]:
        compute_kinematics(model, data, q)
        return stacked_error(mech, model, data, closures)

    release_with(residual, model, data)  # back to the pool when the function is collected
    return residual
