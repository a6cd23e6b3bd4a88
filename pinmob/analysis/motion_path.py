"""Following a free motion a finite amount, every step a closed configuration.

A free motion found by :func:`pinmob.analyze` is a first-order (instantaneous)
statement. To show it, :func:`follow_motion` walks along it. The motion's
screw stays fixed in the world; at each closed configuration q it

1. takes the free twist space ``F`` (6, m) at q (``analyze``, once per q) and
   projects the intended twist ``t`` onto it in the dimensionless metric
   ``W = diag(1/L, 1/L, 1/L, 1, 1, 1)``: ``t_F = F (F^T W^2 F)^-1 F^T W^2 t``;
2. predicts the joint step ``dq`` that moves the platform by ``t_F ds`` and
   keeps every closure (limb tips and the loops inside limbs, e.g. a Delta's
   parallelograms) to first order: the least-squares solution of
   ``[K; W J_p] dq = [0; W t_F ds]`` (K: :func:`pinmob.assembly.residual.stacked_error`
   of ``mech.all_closures``, J_p: platform frame Jacobian, world-aligned);
3. re-closes every loop: :func:`pinmob.assembly.assemble.assemble_pose` at the target
   ``M exp(ds t_F)`` (warm start: the prediction); where the target is off the
   motion's manifold (curved motions), :func:`pinmob.assembly.assemble.project` (all
   closures) from the prediction;
4. checks the achieved platform displacement ``d`` (twist at the platform
   origin taking the old pose to the new one) against the step asked for,
   ``t_F ds``: its share along it, ``<W d, W t_F> / (|W t_F|^2 ds)``, must be at
   least ``MIN_PROGRESS``, and its angle to ``t_F`` in the W metric at most
   ``max_deviation`` [rad] (no sideways jump while re-closing). The reference is
   ``t_F``, not ``t``: a curved motion (a Bennett coupler's screw, the parasitic
   motions of a 3-PRS) turns its free twist away from the screw it started
   with, whatever the step size, and is followed as long as ``t`` keeps a
   share ``MIN_SHARE`` of it. A step that fails 3 or 4 is halved, up to
   ``MAX_HALVINGS`` times.

It stops, and says why, when the motion leaves the free space (``|W t_F| <
MIN_SHARE |W t|``), or no step down to ``ds / 2^MAX_HALVINGS`` re-closes along
the motion: where not even the first step succeeds, the mobility found at q
is only instantaneous in that direction. Each direction's result is measured
(:class:`Displacement`). No meshcat here; :mod:`pinmob.viewer.scene` turns paths into
animation clips.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.analysis.configuration import Configuration
from pinmob.analysis.displacement import Displacement, angle_between, displacement, measure_displacement
from pinmob.analysis.mobility import platform_mobility
from pinmob.analysis.motion import Motion
from pinmob.analysis.motion_limits import describe, limiting_limbs, stop_notes
from pinmob.assembly.assemble import assemble_pose as _assemble_pose
from pinmob.assembly.assemble import project
from pinmob.assembly.residual import CLOSURE_TOL, check_closed, compute_kinematics, stacked_error
from pinmob.exceptions import ClosureError, ConfigurationError
from pinmob.frozen import ReadOnlyArrays
from pinmob.model.mechanism import Mechanism
from pinmob.screw.algebra import shift_twists, twist_scaling
from pinmob.screw.classify import MotionKind

Array = np.ndarray

#: default amplitude of translations, as a fraction of the length scale L
TRANSLATION_AMPLITUDE = 0.2
#: default amplitude of rotations and screws [rad]
ROTATION_AMPLITUDE = 0.35
#: default largest angle [rad] between a step's platform displacement and the intended motion (W metric)
MAX_DEVIATION = 0.05
#: a step is halved at most this many times before the motion is declared stopped
MAX_HALVINGS = 4
#: smallest share of the intended twist that must remain free (W metric)
MIN_SHARE = 0.5
#: smallest share of a step the platform must follow along the intended motion
MIN_PROGRESS = 0.5


@dataclass(frozen=True)
class MotionPath(ReadOnlyArrays):
    """A free motion followed forwards and backwards from q.

    Attributes:
        label: the motion's label (``T1 x``, ``R1 z``...).
        forward: closed configurations q, q_1, ..., q_n along +t.
        backward: closed configurations q, q_-1, ..., q_-m along -t.
        reached: (forward, backward) distance covered along the motion [m for T, rad for R/H].
        amplitude: distance asked for in each direction [m or rad].
        notes: why a direction stopped early (empty when both reached the amplitude).
        displacement: (forward, backward) measured displacement of the platform at each end.
    """

    label: str
    forward: tuple[Array, ...]
    backward: tuple[Array, ...]
    reached: tuple[float, float]
    amplitude: float
    notes: tuple[str, ...] = ()
    displacement: tuple[Displacement, Displacement] = (Displacement(0, 0, 0), Displacement(0, 0, 0))

    @property
    def complete(self) -> bool:
        """True when the motion was followed the full amplitude both ways."""
        return not self.notes

    def frames(self) -> list[Array]:
        """Animation frames: q -> +amplitude -> q -> -amplitude -> q (at least two frames)."""
        f, b = list(self.forward), list(self.backward)
        seq = f + f[-2::-1] + b[1:] + b[-2::-1]
        return seq if len(seq) > 1 else seq * 2

    def to_dict(self) -> dict[str, Any]:
        """The path as plain JSON: label, amplitude, distances reached, notes, displacements."""
        return {
            "label": self.label,
            "amplitude": self.amplitude,
            "reached": list(self.reached),
            "displacement": [d.to_dict() for d in self.displacement],
            "notes": list(self.notes),
        }


def default_amplitude(motion: Motion, length: float) -> float:
    """Distance shown for a motion: ``0.2 L`` [m] for translations, 0.35 rad otherwise."""
    return TRANSLATION_AMPLITUDE * length if motion.kind is MotionKind.TRANSLATION else ROTATION_AMPLITUDE


def _measure(motion: Motion) -> slice:
    """Part of a twist that measures distance: v for translations, w otherwise."""
    return slice(0, 3) if motion.kind is MotionKind.TRANSLATION else slice(3, 6)


class _Follower:
    """One motion's continuation: the mechanism's data, reused at every step."""

    def __init__(self, mech: Mechanism, motion: Motion, rtol: float, tol: float, max_deviation: float):
        self.mech, self.motion, self.rtol, self.tol, self.max_deviation = mech, motion, rtol, tol, max_deviation
        self.model, self.data = mech.model, mech.model.createData()
        self.w = twist_scaling(mech.length_scale)
        self.pid = mech.platform_id
        self.unit = "m" if motion.kind is MotionKind.TRANSLATION else "rad"

    def pose(self, q: Array) -> pin.SE3:
        compute_kinematics(self.model, self.data, q)
        return self.data.oMf[self.pid].copy()

    def project_free(self, q: Array, direction: Array) -> tuple[Array | None, str]:
        """``t_F``, the intended twist projected on the free space at q, or (None, reason)."""
        mob = platform_mobility(Configuration(self.mech, q, closure_tol=self.tol), self.rtol)
        if mob.dof == 0:
            return None, "the platform is rigid there (no free motion left)"
        free = self.w[:, None] * mob.free_twists
        target = self.w * direction
        coef, *_ = np.linalg.lstsq(free, target, rcond=None)
        share = float(np.linalg.norm(free @ coef) / np.linalg.norm(target))
        if share < MIN_SHARE:
            return None, f"the motion leaves the free space there (only {share:.0%} of it is still free)"
        return (free @ coef) / self.w, ""

    def _predict(self, q: Array, projected: Array, ds: float) -> Array:
        """Joint step keeping every closure to first order while the platform moves by ``projected ds``."""
        model, data = self.model, self.data
        compute_kinematics(model, data, q)
        _, k = stacked_error(self.mech, model, data, self.mech.all_closures)
        jp = self.w[:, None] * pin.getFrameJacobian(model, data, self.pid, pin.LOCAL_WORLD_ALIGNED)
        rhs = np.concatenate([np.zeros(k.shape[0]), self.w * projected * ds])
        dv = np.linalg.lstsq(np.vstack([k, jp]), rhs, rcond=None)[0]
        return pin.integrate(model, q, dv)

    def step(self, q: Array, om_p: pin.SE3, projected: Array, ds: float) -> tuple[Array | None, str]:
        """One step of ``ds`` along ``projected`` (``t_F``), checked against it: (q_next, "") or (None, reason)."""
        q_pred = self._predict(q, projected, ds)
        local = np.concatenate([om_p.rotation.T @ projected[:3], om_p.rotation.T @ projected[3:]]) * ds
        how = "re-closing the loops"
        try:
            q_next = _assemble_pose(self.mech, om_p * pin.exp6(local), q_pred, tol=self.tol, max_iter=60)
        except ClosureError:
            how = "the target pose cannot be assembled there, and re-closing the loops"
            try:
                q_next = project(self.mech, q_pred, tol=self.tol, max_iter=100).q
            except ClosureError:
                return None, "the loops do not close again after a step there"
        achieved = self.w * displacement(om_p, self.pose(q_next))
        wanted = self.w * projected * ds
        progress = float(achieved @ wanted / (wanted @ wanted))
        if progress < MIN_PROGRESS:
            return (
                None,
                f"{how} undoes the step there (the platform follows only {max(progress, 0):.0%} of it)",
            )
        deviation = angle_between(achieved, wanted)
        if deviation > self.max_deviation:
            return None, (
                f"{how} turns the platform off the motion ({np.degrees(deviation):.1f} deg "
                f"sideways, more than {np.degrees(self.max_deviation):.1f} deg)"
            )
        return q_next, ""

    def branch(self, q: Array, unit: Array, amp: float, ds: float) -> tuple[list[Array], float, str]:
        """Configurations from q along ``unit`` up to ``amp``, the distance covered, and why it stopped ("" if not)."""
        path, current, covered = [q], q, [0.0]
        start = self.pose(q)
        limit = int(np.ceil(amp / ds)) * 2**MAX_HALVINGS + 4  # every step covers at least ds / 2^MAX_HALVINGS
        while covered[-1] < amp * (1 - 1e-9):
            if len(path) > limit:
                return path, covered[-1], f"{limit} steps taken without reaching the amplitude"
            om_p = self.pose(current)
            # the motion's screw stays fixed in the world: re-express it at the current platform origin
            direction = shift_twists(unit, om_p.translation - start.translation)
            projected, why = self.project_free(current, direction)
            if projected is None:
                return path, covered[-1], why
            h = first = min(ds, amp - covered[-1])
            for _ in range(MAX_HALVINGS + 1):
                nxt, why = self.step(current, om_p, projected, h)
                if nxt is not None:
                    break
                h /= 2
            if nxt is None:
                why = f"{why} (also with steps down to {h * 2:.2g})"
                limits = limiting_limbs(self.mech, path, covered, first, self.rtol)
                return path, covered[-1], f"{describe(limits, self.unit)}, so {why}" if limits else why
            path.append(nxt)
            current = nxt
            covered.append(covered[-1] + h)
        return path, covered[-1], ""


def follow_motion(
    mech: Mechanism,
    q: Array,
    motion: Motion,
    *,
    amplitude: float | None = None,
    steps: int = 12,
    rtol: float = 1e-6,
    closure_tol: float = CLOSURE_TOL,
    max_deviation: float = MAX_DEVIATION,
) -> MotionPath:
    """Follow ``motion`` from the closed configuration q, both ways, by continuation.

    Args:
        mech: the mechanism.
        q: (nq,) closed configuration where ``motion`` was found.
        motion: one of ``analyze(mech, q).motions``.
        amplitude: distance in each direction [m for T, rad for R and H];
            default :func:`default_amplitude`.
        steps: continuation steps per direction (each may be halved, see the module).
        rtol: rank tolerance of the mobility analysis at each step.
        closure_tol: closure tolerance of every frame (position / L, rotation [rad]).
        max_deviation: largest angle [rad] between a step's platform displacement
            and the intended motion (W metric); a step beyond it is halved or refused.

    Returns:
        the path; every configuration in it closes within ``closure_tol``.

    Raises:
        ConfigurationError: ``steps`` < 1, a non-positive amplitude or max_deviation.
        ClosureError: q itself does not close.
    """
    if steps < 1:
        raise ConfigurationError(f"steps must be at least 1, got {steps}")
    amp = default_amplitude(motion, mech.length_scale) if amplitude is None else float(amplitude)
    if not np.isfinite(amp) or amp <= 0:
        raise ConfigurationError(
            f"amplitude must be a positive number (m for translations, rad otherwise), got {amplitude!r}"
        )
    if not np.isfinite(max_deviation) or max_deviation <= 0:
        raise ConfigurationError(f"max_deviation must be a positive angle [rad], got {max_deviation!r}")
    q = mech.check_q(q)
    check_closed(mech, q, closure_tol, what="the configuration to animate")
    unit = motion.twist / np.linalg.norm(motion.twist[_measure(motion)])
    follower = _Follower(mech, motion, rtol, closure_tol, max_deviation)
    start = follower.pose(q)
    branches, reached, reasons, moved = [], [], [], []
    for sign in (1.0, -1.0):
        path, covered, why = follower.branch(q, sign * unit, amp, amp / steps)
        branches.append(tuple(path))
        reached.append(covered)
        reasons.append(why)
        moved.append(measure_displacement(start, follower.pose(path[-1]), sign * unit, mech.length_scale))
    return MotionPath(
        motion.label,
        branches[0],
        branches[1],
        (reached[0], reached[1]),
        amp,
        stop_notes(motion.label, reasons, reached, amp, follower.unit),
        (moved[0], moved[1]),
    )
