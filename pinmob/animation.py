"""Following a free motion a finite amount, every step a closed configuration.

A free motion found by :func:`pinmob.analyze` is a first-order (instantaneous)
statement. To show it, :func:`follow_motion` walks along it: at each step it

1. takes the free twist space ``F`` (6, m) at the current closed q
   (``analyze`` again) and projects the motion's unit twist ``t`` onto it in
   the dimensionless metric ``W = diag(1/L, 1/L, 1/L, 1, 1, 1)``:
   ``t_F = F (F^T W^2 F)^-1 F^T W^2 t``;
2. predicts the joint step of each limb, ``dq_i = J_i^+ t_F ds`` (limb tip
   Jacobian, world-aligned), and the platform target ``M exp(ds t_F)``;
3. re-closes the loops: :func:`pinmob.closure.assemble_pose` at the target
   (warm start: the prediction); where the target is off the motion's
   manifold (curved motions), :func:`pinmob.closure.solve` on the closure
   residuals alone from the prediction;
4. checks the platform really moved: the step achieved along ``t``,
   ``<W d, W t_F ds> / |W t_F ds|^2``, must be at least ``min_progress``.

It stops, and says why, when the motion leaves the free space (``|W t_F| <
min_projection |W t|``), the loops do not re-close, or the platform does not
follow: then the mobility found at q is only instantaneous in that direction.
No meshcat here; :mod:`pinmob.viewer` turns paths into animation clips.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .closure import CLOSURE_TOL, check_closed, compute_kinematics, relative_error, solve
from .closure import assemble_pose as _assemble_pose
from .exceptions import ClosureError, ConfigurationError
from .mechanism import Mechanism
from .mobility import Motion, analyze
from .screw import MotionKind, shift_twists, twist_scaling

Array = np.ndarray

#: default amplitude of translations, as a fraction of the length scale L
TRANSLATION_AMPLITUDE = 0.2
#: default amplitude of rotations and screws [rad]
ROTATION_AMPLITUDE = 0.35


@dataclass(frozen=True)
class MotionPath:
    """A free motion followed forwards and backwards from q.

    Attributes:
        label: the motion's label (``T1 x``, ``R1 z``...).
        forward: closed configurations q, q_1, ..., q_n along +t.
        backward: closed configurations q, q_-1, ..., q_-m along -t.
        reached: (forward, backward) distance covered [m for T, rad for R/H].
        amplitude: distance asked for in each direction [m or rad].
        notes: why a direction stopped early (empty when both reached the amplitude).
    """

    label: str
    forward: tuple[Array, ...]
    backward: tuple[Array, ...]
    reached: tuple[float, float]
    amplitude: float
    notes: tuple[str, ...] = ()

    @property
    def complete(self) -> bool:
        """True when the motion was followed the full amplitude both ways."""
        return not self.notes

    def frames(self) -> list[Array]:
        """Animation frames: q -> +amplitude -> q -> -amplitude -> q (at least two frames)."""
        f, b = list(self.forward), list(self.backward)
        seq = f + f[-2::-1] + b[1:] + b[-2::-1]
        return seq if len(seq) > 1 else seq * 2


def default_amplitude(motion: Motion, length: float) -> float:
    """Distance shown for a motion: ``0.2 L`` [m] for translations, 0.35 rad otherwise."""
    return TRANSLATION_AMPLITUDE * length if motion.kind is MotionKind.TRANSLATION else ROTATION_AMPLITUDE


def _measure(motion: Motion) -> slice:
    """Part of a twist that measures distance: v for translations, w otherwise."""
    return slice(0, 3) if motion.kind is MotionKind.TRANSLATION else slice(3, 6)


def _close_loops(mech: Mechanism, q0: Array, tol: float) -> Array | None:
    """Closed configuration near q0 (closure residuals only), or None."""
    model, data = mech.model, mech.model.createData()
    scale = twist_scaling(mech.length_scale)
    pid = mech.platform_id
    tips = [limb.tip_id for limb in mech.limbs if limb.tip_id != pid]

    def residual(q: Array) -> tuple[Array, Array]:
        compute_kinematics(model, data, q)
        blocks = [relative_error(model, data, pid, t) for t in tips]
        return np.concatenate([scale * b[0] for b in blocks]), np.vstack([scale[:, None] * b[1] for b in blocks])

    result = solve(model, residual, q0, tol=min(1e-12, tol * 1e-3), max_iter=100)
    try:
        check_closed(mech, result.q, tol)
    except ClosureError:
        return None
    return result.q


def _displacement(a: pin.SE3, b: pin.SE3) -> Array:
    """Twist [v; w] at a's origin, world axes, that carries pose a to pose b in unit time."""
    local = pin.log6(a.actInv(b)).vector
    rot = a.rotation
    return np.concatenate([rot @ local[:3], rot @ local[3:]])


def _step(
    mech: Mechanism, q: Array, direction: Array, ds: float, motion: Motion, rtol: float, tol: float
) -> tuple[Array | None, str]:
    """One continuation step of ``ds`` along ``direction``; (q_next, "") or (None, reason)."""
    model, data = mech.model, mech.model.createData()
    w = twist_scaling(mech.length_scale)
    mob = analyze(mech, q, rtol=rtol, closure_tol=tol)
    if mob.dof == 0:
        return None, "the platform is rigid there (no free motion left)"
    free = w[:, None] * mob.free_twists
    target_dir = w * direction
    coef, *_ = np.linalg.lstsq(free, target_dir, rcond=None)
    projected = (free @ coef) / w
    share = float(np.linalg.norm(w * projected) / np.linalg.norm(target_dir))
    if share < 0.5:
        return None, f"the motion leaves the free space there (only {share:.0%} of it is still free)"
    compute_kinematics(model, data, q)
    pid = mech.platform_id
    om_p = data.oMf[pid].copy()
    # predictor: each limb's joint step for the platform twist, carried to its tip
    dv = np.zeros(model.nv)
    for limb in mech.limbs:
        jac = pin.getFrameJacobian(model, data, limb.tip_id, pin.LOCAL_WORLD_ALIGNED)[:, limb.v_indices]
        tip_twist = shift_twists(projected, data.oMf[limb.tip_id].translation - om_p.translation)
        dv[limb.v_indices] = np.linalg.lstsq(jac, tip_twist, rcond=None)[0]
    q_pred = pin.integrate(model, q, dv * ds)
    local = np.concatenate([om_p.rotation.T @ projected[:3], om_p.rotation.T @ projected[3:]]) * ds
    target = om_p * pin.exp6(local)
    try:
        q_next = _assemble_pose(mech, target, q_pred, tol=tol, max_iter=60)
    except ClosureError:
        reclosed = _close_loops(mech, q_pred, tol)
        if reclosed is None:
            return None, "the loops do not close again after a step there"
        q_next = reclosed
    compute_kinematics(model, data, q_next)
    achieved = w * _displacement(om_p, data.oMf[pid])
    wanted = w * projected * ds
    progress = float(achieved @ wanted / (wanted @ wanted))
    if progress < 0.5:
        return (
            None,
            f"re-closing the loops undoes the step there (the platform follows only {max(progress, 0):.0%} of it)",
        )
    return q_next, ""


def follow_motion(
    mech: Mechanism,
    q: Array,
    motion: Motion,
    *,
    amplitude: float | None = None,
    steps: int = 12,
    rtol: float = 1e-6,
    closure_tol: float = CLOSURE_TOL,
) -> MotionPath:
    """Follow ``motion`` from the closed configuration q, both ways, by continuation.

    Args:
        mech: the mechanism.
        q: (nq,) closed configuration where ``motion`` was found.
        motion: one of ``analyze(mech, q).motions``.
        amplitude: distance in each direction [m for T, rad for R and H];
            default :func:`default_amplitude`.
        steps: continuation steps per direction.
        rtol: rank tolerance of the mobility analysis at each step.
        closure_tol: closure tolerance of every frame (position / L, rotation [rad]).

    Returns:
        the path; every configuration in it closes within ``closure_tol``.

    Raises:
        ConfigurationError: ``steps`` < 1 or a non-positive amplitude.
        ClosureError: q itself does not close.
    """
    if steps < 1:
        raise ConfigurationError(f"steps must be at least 1, got {steps}")
    amp = default_amplitude(motion, mech.length_scale) if amplitude is None else float(amplitude)
    if not np.isfinite(amp) or amp <= 0:
        raise ConfigurationError(
            f"amplitude must be a positive number (m for translations, rad otherwise), got {amplitude!r}"
        )
    q = mech.check_q(q)
    check_closed(mech, q, closure_tol, what="the configuration to animate")
    meas = _measure(motion)
    unit = motion.twist / np.linalg.norm(motion.twist[meas])
    ds = amp / steps
    branches, reached, notes = [], [], []
    for sign, word in ((1.0, "forwards"), (-1.0, "backwards")):
        path, current = [q], q
        model, data = mech.model, mech.model.createData()
        compute_kinematics(model, data, q)
        origin0 = data.oMf[mech.platform_id].translation.copy()
        for k in range(steps):
            compute_kinematics(model, data, current)
            # the motion's screw stays fixed in the world: re-express it at the current platform origin
            direction = sign * shift_twists(unit, data.oMf[mech.platform_id].translation - origin0)
            nxt, why = _step(mech, current, direction, ds, motion, rtol, closure_tol)
            if nxt is None:
                unit_name = "m" if motion.kind is MotionKind.TRANSLATION else "rad"
                hint = "; the mobility found there is only instantaneous in this direction" if k == 0 else ""
                notes.append(f"{motion.label}: stopped {word} after {k * ds:.3g} {unit_name} of {amp:.3g}: {why}{hint}")
                break
            path.append(nxt)
            current = nxt
        branches.append(tuple(path))
        reached.append((len(path) - 1) * ds)
    if len(notes) == 2 and reached == [0.0, 0.0] and notes[0].split(": ", 2)[2] == notes[1].split(": ", 2)[2]:
        notes = [f"{motion.label}: cannot be followed either way from here: {notes[0].split(': ', 2)[2]}"]
    return MotionPath(motion.label, branches[0], branches[1], (reached[0], reached[1]), amp, tuple(notes))
