"""The predictor-corrector behind :func:`pinmob.analysis.follow.motion_path.follow_motion`: one step at a time.

:class:`Follower` follows a platform motion (a screw fixed in the world): at each closed q it
projects the intended twist on the free twists there, predicts the joint step that moves the
platform along it while keeping every closure to first order, re-closes the loops (the target
pose, else a projection) and checks the platform's achieved displacement against the step asked
for (see :mod:`pinmob.analysis.follow.motion_path` for the rules and thresholds).

:class:`RateFollower` follows a direction of joint rates instead (a motion that need not move the
platform: a limb's internal motion, a motion branch, a motion with the actuators held): it
projects the direction on the closed chain's joint rates at q (``null [K; held rows]``,
dimensionless), steps along it and re-closes every loop by the minimum-norm correction (the held
joints kept), and checks the achieved joint displacement, in the dimensionless joint metric,
against the step asked for. Distances are then dimensionless (radians for revolute joints,
metres / L for prismatic ones).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from pinmob.analysis.chain.closed_chain import closed_chain_columns
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.follow.displacement import angle_between, displacement
from pinmob.analysis.follow.motion_limits import describe, limiting_limbs
from pinmob.analysis.mobility import platform_mobility
from pinmob.analysis.motion import Motion
from pinmob.assembly import assemble_pose as _assemble_pose
from pinmob.assembly import closure_residual, compute_kinematics, frame_jacobian, project, solve, stacked_error
from pinmob.exceptions import ClosureError
from pinmob.model import Mechanism, short_difference
from pinmob.screw import Array, MotionKind, decide_rank, shift_twists, twist_scaling

#: a step is halved at most this many times before the motion is declared stopped
MAX_HALVINGS = 4
#: smallest share of the intended twist that must remain free (W metric)
MIN_SHARE = 0.5
#: smallest share of a step the platform must follow along the intended motion
MIN_PROGRESS = 0.5


def closed_rates(conf: Configuration, held: Sequence[int], rtol: float) -> Array:
    """(nv, m) orthonormal dimensionless joint rates of the closed chain at conf, the ``held`` joints still.

    ``null [K_hat; rows picking the held rates]`` (:mod:`pinmob.analysis.chain.closed_chain`'s
    dimensionless closure Jacobian), by the one rank rule.
    """
    mech = conf.mechanism
    nv = mech.model.nv
    _, k = stacked_error(mech, mech.model, conf.data, mech.all_closures)
    rows = np.vstack([k * closed_chain_columns(conf), np.eye(nv)[list(held)]])
    return decide_rank(rows, rtol, n=nv).null_space.T


class Follower:
    """One platform motion's continuation: the mechanism's data, reused at every step."""

    def __init__(
        self,
        mech: Mechanism,
        motion: Motion | None,
        rtol: float,
        tol: float,
        max_deviation: float,
        halvings: int = MAX_HALVINGS,
    ):
        self.mech, self.motion, self.rtol, self.tol, self.max_deviation = mech, motion, rtol, tol, max_deviation
        self.halvings = halvings
        self.model, self.data = mech.model, pin.Data(mech.model)
        self.w = twist_scaling(mech.length_scale)
        self.pid = mech.platform_id if mech.has_platform else 0

    def at(self, q: Array) -> Configuration:
        """The configuration q of the path, closed within the tolerance (what :meth:`project_free` reads there)."""
        return Configuration.from_checked(self.mech, q, self.tol)

    def pose(self, q: Array) -> pin.SE3:
        """The platform's pose at q."""
        compute_kinematics(self.model, self.data, q)
        return self.data.oMf[self.pid].copy()

    def direction_at(self, q: Array, unit: Array, start: pin.SE3) -> Array:
        """The intended direction at q: the motion's screw, fixed in the world, at the current platform origin."""
        return shift_twists(unit, self.pose(q).translation - start.translation)

    def free_at(self, here: Configuration) -> tuple[int, Array]:
        """The platform's DoF and (6, dof) free twists ``[v / L; w]`` at ``here``, computed once per configuration.

        Both directions of a motion start at the same configuration (its :meth:`Configuration.memo`).
        """

        def compute() -> tuple[int, Array]:
            mob = platform_mobility(here, self.rtol)
            return mob.dof, self.w[:, None] * mob.free_twists

        return here.memo(("followed free twists", self.rtol), compute)

    def project_free(self, here: Configuration, direction: Array) -> tuple[Array | None, str]:
        """``t_F``, the intended twist projected on the free space at ``here``, or (None, reason)."""
        dof, free = self.free_at(here)
        if dof == 0:
            return None, "the platform is rigid there (no free motion left)"
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
        jp = self.w[:, None] * frame_jacobian(model, data, self.pid, pin.LOCAL_WORLD_ALIGNED)
        rhs = np.concatenate([np.zeros(k.shape[0]), self.w * projected * ds])
        dv = np.linalg.lstsq(np.vstack([k, jp]), rhs, rcond=None)[0]
        return pin.integrate(model, q, dv)

    def step(self, q: Array, projected: Array, ds: float) -> tuple[Array | None, str]:
        """One step of ``ds`` along ``projected`` (``t_F``), checked against it: (q_next, "") or (None, reason)."""
        om_p = self.pose(q)
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
        return self.check(q_next, achieved, self.w * projected * ds, how)

    def check(self, q_next: Array, achieved: Array, wanted: Array, how: str) -> tuple[Array | None, str]:
        """The step accepted when ``achieved`` follows ``wanted`` (share and angle), else (None, reason)."""
        progress = float(achieved @ wanted / (wanted @ wanted))
        if progress < MIN_PROGRESS:
            return None, f"{how} undoes the step there (the {self.moving} follows only {max(progress, 0):.0%} of it)"
        deviation = angle_between(achieved, wanted)
        if deviation > self.max_deviation:
            return None, (
                f"{how} turns the {self.moving} off the motion ({np.degrees(deviation):.1f} deg "
                f"sideways, more than {np.degrees(self.max_deviation):.1f} deg)"
            )
        return q_next, ""

    moving = "platform"

    def branch(self, origin: Configuration, unit: Array, amp: float, ds: float) -> tuple[list[Array], float, str]:
        """Configurations from ``origin`` along ``unit`` up to ``amp``, the distance covered, and why it stopped ("" if not)."""
        path, here, covered, start = [origin.q], origin, [0.0], self.pose(origin.q)
        limit = int(np.ceil(amp / ds)) * 2**self.halvings + 4  # every step covers at least ds / 2^halvings
        while covered[-1] < amp * (1 - 1e-9):
            if len(path) > limit:
                return path, covered[-1], f"{limit} steps taken without reaching the amplitude"
            here = here if here.q is path[-1] else self.at(path[-1])
            current = here.q
            projected, why = self.project_free(here, self.direction_at(current, unit, start))
            if projected is None:
                return path, covered[-1], why
            h = first = min(ds, amp - covered[-1])
            for _ in range(self.halvings + 1):
                nxt, why = self.step(current, projected, h)
                if nxt is not None:
                    break
                h /= 2
            if nxt is None:
                return (
                    path,
                    covered[-1],
                    self.stopped(path, covered, first, f"{why} (also with steps down to {h * 2:.2g})"),
                )
            path.append(nxt)
            covered.append(covered[-1] + h)
        return path, covered[-1], ""

    def stopped(self, path: list[Array], covered: list[float], step: float, why: str) -> str:
        """Why a platform motion stopped: the limbs reaching the edge of their workspace there, if any, then ``why``."""
        if self.motion is None:
            return why
        limits = limiting_limbs(self.mech, path, covered, step, self.rtol)
        unit = "m" if self.motion.kind is MotionKind.TRANSLATION else "rad"
        return f"{describe(limits, unit)}, so {why}" if limits else why


class RateFollower(Follower):
    """A direction of dimensionless joint rates followed on the closed set, some joints held (see the module)."""

    moving = "mechanism"

    def __init__(
        self, mech: Mechanism, held: Sequence[int], rtol: float, tol: float, max_deviation: float, halvings: int
    ):
        super().__init__(mech, None, rtol, tol, max_deviation, halvings)
        self.held = np.asarray(held, int)
        self.free = np.ones(self.model.nv, bool)
        self.free[self.held] = False
        self.residual = closure_residual(mech)
        self.col = closed_chain_columns(Configuration.unchecked(mech, mech.neutral()))  # per mechanism

    def direction_at(self, q: Array, unit: Array, start: pin.SE3) -> Array:
        """The rates stay the same (joint space has no screw to carry along)."""
        return unit

    def at(self, q: Array) -> Configuration:
        """The kinematics at q (each step re-closes the loops within the tolerance: :meth:`step`)."""
        return Configuration.unchecked(self.mech, q)

    def project_free(self, here: Configuration, direction: Array) -> tuple[Array | None, str]:
        """The direction projected on the closed chain's rates at ``here`` (held joints still), or (None, reason)."""
        held = tuple(self.held.tolist())  # both directions start at the same configuration (its memo)
        null = here.memo(("followed closed rates", held, self.rtol), lambda: closed_rates(here, held, self.rtol))
        projected = null @ (null.T @ direction)
        share = float(np.linalg.norm(projected) / np.linalg.norm(direction))
        if share < MIN_SHARE:
            return None, f"the motion leaves the closed chain's rates there (only {share:.0%} of it is still free)"
        return projected, ""

    def step(self, q: Array, projected: Array, ds: float) -> tuple[Array | None, str]:
        """A step of ``ds`` along ``projected``, re-closed by the minimum-norm correction, checked against it."""
        q_pred = pin.integrate(self.model, q, self.col * projected * ds)
        res = solve(
            self.model,
            self.residual,
            q_pred,
            tol=min(1e-12, self.tol * 1e-3),
            max_iter=100,
            length=self.mech.length_scale,
            free=self.free,
        )
        if res.residual > self.tol:
            return None, "the loops do not close again after a step there"
        achieved = short_difference(self.model, q, res.q) / self.col
        return self.check(res.q, achieved, projected * ds, "re-closing the loops")
