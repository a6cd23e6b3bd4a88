"""Damped Newton steps on many platform-pose assemblies at once, in lockstep: the predictor of a batched scan.

B targets (platform pose coordinates ``[x, y, z, roll, pitch, yaw]``, some of them
*free*: unknowns that follow the mechanism) and B warm starts. Every limb tip
(and the platform frame) is driven to the target pose, as
:func:`pinmob.assembly.assemble.assemble_pose` does; per frame f, dimensionless
and in world axes,

    e_f = [ (p_f - p*) / L ;  log3(R_f R*^T) ],

with the Jacobian per joint rate taken from the world joint Jacobian
(Pinocchio's ``data.J``: one call of the compiled kinematics per iteration over
the stack, :mod:`pinmob.model.compiled_kinematics`, where numba is installed and
the joints are of the types it compiles, else one ``computeJointJacobians`` per
sample and iteration) on the frame's supporting joints, ``[(J_v - [p_f]x J_w) / L ; J_w]``, and, per free
coordinate, ``-[e_k / L ; 0]`` (x, y, z) or ``-[0 ; E(rpy) e_k]`` (angles,
``E`` the world angular velocity per rpy rate). The rotation rows take the
angular velocity for the rate of ``log3`` (no ``Jlog3``): exact at a solution,
so the steps converge quadratically near one. The errors,
Jacobians and steps are computed by a compiled loop over the samples still
running when numba is installed (:mod:`pinmob.assembly.batched.batch_newton_kernel`), else
as numpy stacks (the same iterates to round-off).

Step: Levenberg-Marquardt on the dimensionless columns ``J' = J D`` (D = L on a
translation, 1 on a rotation), ``dz = -(J'^T J' + mu I)^-1 J'^T e`` with
``mu = DAMPING * trace(J'^T J') / n``, capped at ``MAX_STEP`` per column (the
trust region of :mod:`pinmob.assembly.solver`), and applied by
``pin.integrate``. A sample stops when its ``max |e|`` is at most ``tol``
(converged), or unconverged when it gained less than 0.1% over
``stall_window`` iterations (:data:`~pinmob.assembly.solver.STALL_GAIN`), when a
step makes it grow tenfold, or after ``max_iter`` iterations.

With ``floor`` below ``tol``, a sample within ``tol`` goes on while a step keeps at
most ``POLISH_GAIN`` of its ``max |e|^2``, down to ``floor`` (the single-sample
solver's polish rule, :mod:`pinmob.assembly.solver`; a scan stops at ``tol``,
:mod:`pinmob.scan.lockstep`), and is closed (:meth:`PoseProblem.finish`). A scan
gives every sample the predictor did not converge to the single-sample solver.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from types import ModuleType

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from pinmob.assembly.assemble import warn_outside_limits
from pinmob.assembly.batched.batch_stopping import advance as plain_advance
from pinmob.assembly.batched.rotation_stacks import log3_stack, rpy_matrices, rpy_rates, skew_stack
from pinmob.assembly.solver import MAX_STEP, POLISH_FLOOR, POLISH_GAIN, STALL_GAIN
from pinmob.blas import one_blas_thread
from pinmob.model import (
    Mechanism,
    acquire,
    angle_mask,
    frame_kinematics,
    linear_velocity_mask,
    mechanism_kinematics,
    release_with,
    wrap_angles,
)
from pinmob.screw import Array, Mask

#: Pinocchio joints whose ``integrate`` is ``q + v`` (one coordinate per velocity, no rotation group).
VECTOR_JOINTS = frozenset(
    f"JointModel{k}" for k in ("RX", "RY", "RZ", "PX", "PY", "PZ", "RevoluteUnaligned", "PrismaticUnaligned")
)

#: Damping of the normal equations, relative to their mean diagonal.
DAMPING = 1e-12
#: A step that makes ``max |e|`` grow by this factor stops the sample (it left the basin of its warm start).
DIVERGED = 10.0
#: Iterations at most, and the stall window: a sample that gained less than ``STALL_GAIN`` over it stops.
MAX_ITER, STALL_WINDOW = 40, 5


@dataclass(frozen=True)
class BatchSolution:
    """Outcome of :func:`solve_poses`: per sample, the best configuration, its ``max |e|`` and whether it converged.

    ``jacobians`` (N, 6, nv) and ``frames`` (N, F, 4, 4): the kinematics at each best configuration
    (:meth:`PoseProblem.kinematics`, computed there to measure its errors; a scan's analysis reads them instead
    of computing them again).
    """

    q: Array
    residual: Array
    converged: Mask
    jacobians: Array
    frames: Array


def compiled_kernel() -> ModuleType | None:
    """:mod:`pinmob.assembly.batched.batch_newton_kernel` when numba is installed (the ``fast`` extra), else None (numpy)."""
    try:
        import numba  # noqa: F401
    except ImportError:
        return None
    import pinmob.assembly.batched.batch_newton_kernel as batch_newton_kernel

    return batch_newton_kernel


class PoseProblem:
    """The frames of a platform-pose assembly and their supporting columns (see the module docstring).

    ``compiled=False``: numpy steps and Pinocchio's kinematics, whether numba is installed or not (numba is not
    imported: the same iterates to round-off, whatever the installation).
    """

    def __init__(
        self, mech: Mechanism, free: tuple[int, ...] = (), compiled: bool = True, fixed: tuple[int, ...] = ()
    ) -> None:
        model = self.model = mech.model
        self.length, self.free = mech.length_scale, tuple(free)
        # what depends only on the mechanism and the kinematics engine asked for: computed
        # once per mechanism (a scan makes one problem for its seeding walk and one per group of chunks)
        shape = mech.memo("pose problem", lambda: _Shape(mech), transient=True)
        self.frames, self.mask, self.frame_mask = shape.frames, shape.mask, shape.frame_mask
        self.col = np.concatenate([shape.col_q, [self.length if f < 3 else 1.0 for f in self.free]])
        self.free_array = np.array(self.free, np.int64)
        #: The columns of the steps: ``col`` with the joints ``fixed`` (velocity indices: a target's joint values,
        #: held at their values in the starts) at zero, so no step moves them.
        self.step_col = self.col.copy()
        self.step_col[list(fixed)] = 0.0
        #: Every joint's configuration space is its velocity space: ``pin.integrate`` is ``q + dq``.
        self.vector_space = shape.vector_space
        #: The frames' kinematics for a stack: compiled (numba) when it can be and ``compiled`` (shared per mechanism
        #: and engine asked for with the compiled single-sample solve, :func:`~pinmob.model.mechanism_kinematics`: it
        #: keeps no state between calls), else Pinocchio's calls (:meth:`kinematics`, in the problem's own
        #: :attr:`data`).
        self.fast = (
            mechanism_kinematics(mech, self.frames) if compiled else frame_kinematics(model, self.frames, "pinocchio")
        )
        self.kernel = compiled_kernel() if compiled else None
        self.angles, self.angle_rates = shape.angles, shape.angle_rates
        self.limits, self.limited = shape.limits, shape.limited

    @cached_property
    def data(self) -> pin.Data:
        """The ``pin.Data`` of Pinocchio's kinematics, taken from the model's pool when first used.

        Read by :meth:`kinematics` without the compiled ones and by the predictor's following coordinates; given
        back when the problem is collected. The compiled kinematics need none, and a 6-UPS's takes 0.5 ms to make.
        """
        data = acquire(self.model)
        release_with(self, self.model, data)
        return data

    @staticmethod
    def covers(mech: Mechanism) -> bool:
        """The problem closes ``mech``'s loops: a platform and limbs, and no closure besides the limb tips."""
        return bool(
            mech.has_platform and mech.limbs and not mech.closures and not any(limb.closures for limb in mech.limbs)
        )

    def finish(self, mech: Mechanism, qs: Array, kind: str, checked: tuple[Array, Mask, Mask] | None = None) -> Array:
        """(N, nq) configurations the predictor closed, as the single-sample assembly returns each.

        Revolute angles wrapped (:func:`~pinmob.model.joints.wrap_angles`, the same arithmetic over the whole
        stack; that function itself for a row with an angle whose wrapped value is outside its limits) and the
        warning for joints outside their limits of :func:`~pinmob.assembly.assemble.assemble_pose` (``kind``
        ``pose``), of :func:`~pinmob.assembly.partial_pose.assemble_coordinates` (``coords``) or of
        :func:`~pinmob.assembly.assemble.solve_actuated` (``joints``), checked where any coordinate is outside its
        limits. ``checked``: the wrapped stack and its two masks of ``wrap_and_check``, already computed (the compiled
        predictor's, :mod:`pinmob.assembly.batched.secant_kernel`; ``qs`` then its stack before wrapping).
        """
        lower, upper = self.limits
        if checked is None:
            out = np.array(qs, float).reshape(-1, self.model.nq)
            check = _wrap_and_check if self.kernel is None else self.kernel.wrap_and_check
            special, outside = check(out, self.angles, lower, upper, self.limited)
        else:
            out, special, outside = checked
        for i in np.flatnonzero(special):
            out[i] = wrap_angles(self.model, qs[i])
            outside[i] = bool((self.limited & ((out[i] < lower - 1e-9) | (out[i] > upper + 1e-9))).any())
        what = {"pose": "assembly at a platform pose", "joints": "forward kinematics (actuated joint values)"}.get(
            kind, "assembly at platform pose coordinates"
        )
        for i in np.flatnonzero(outside):
            warn_outside_limits(mech, out[i], what)
        return out

    def kinematics(self, qs: Array) -> tuple[Array, Array]:
        """(B, 6, nv) world Jacobians and (B, F, 4, 4) frame placements at (B, nq).

        The compiled kinematics in one call (:mod:`pinmob.model.compiled_kinematics`), else Pinocchio one sample
        at a time.
        """
        if self.fast.engine == "compiled":
            full, rot, pos = self.fast.world_jacobians(qs)
            frames = np.zeros((len(qs), len(self.frames), 4, 4))
            frames[:, :, :3, :3], frames[:, :, :3, 3], frames[:, :, 3, 3] = rot, pos, 1.0
            return full, frames
        model, data = self.model, self.data
        full, frames = np.empty((len(qs), 6, model.nv)), np.empty((len(qs), len(self.frames), 4, 4))
        jacobians, placement = pin.computeJointJacobians, pin.updateFramePlacement
        for b, q in enumerate(qs):
            full[b] = jacobians(model, data, q)
            for i, frame in enumerate(self.frames):
                frames[b, i] = placement(model, data, frame).homogeneous
        return full, frames

    def empty_kinematics(self, n: int) -> tuple[Array, Array]:
        """(n, 6, nv) Jacobians and (n, F, 4, 4) placements of :meth:`kinematics`, NaN until computed."""
        return np.full((n, 6, self.model.nv), np.nan), np.full((n, len(self.frames), 4, 4), np.nan)

    def residual_of(self, full: Array, frames: Array, poses: Array) -> tuple[Array, Array]:
        """(B, 6F) dimensionless errors and (B, 6F, nv + free) Jacobians per dimensionless rate, in numpy.

        From the kinematics at (B, nq) configurations (:meth:`kinematics`) and (B, 6) target poses.
        """
        n, nf, nv = len(full), len(self.frames), self.model.nv
        pos, rot = frames[:, :, :3, 3], frames[:, :, :3, :3]
        jac = full[:, None] * self.mask  # (B, F, 6, nv): each frame's supporting columns
        lin = jac[:, :, :3] - skew_stack(pos.reshape(-1, 3)).reshape(n, nf, 3, 3) @ jac[:, :, 3:]
        target = rpy_matrices(poses[:, 3:])
        rel = (rot @ target[:, None].transpose(0, 1, 3, 2)).reshape(-1, 3, 3)
        errors = np.empty((n, nf, 6))
        np.divide(pos - poses[:, None, :3], self.length, out=errors[:, :, :3])
        errors[:, :, 3:] = log3_stack(rel).reshape(n, nf, 3)
        rows = np.zeros((n, nf, 6, nv + len(self.free)))  # (B, F, 6, nv + free)
        np.divide(lin, self.length, out=rows[:, :, :3, :nv])
        rows[:, :, 3:, :nv] = jac[:, :, 3:]
        if self.free:
            rates = rpy_rates(poses[:, 3:])
            for c, f in enumerate(self.free, nv):
                if f < 3:
                    rows[:, :, f, c] = -1.0 / self.length
                else:
                    rows[:, :, 3:, c] = -rates[:, None, :, f - 3]
        rows *= self.step_col
        return errors.reshape(n, 6 * nf), rows.reshape(n, 6 * nf, -1)

    def integrate(self, qs: Array, poses: Array, steps: Array) -> tuple[Array, Array]:
        """Configurations and poses moved by (B, nv + free) dimensionless steps."""
        nv, dq = self.model.nv, steps * self.step_col
        if self.vector_space:
            out = qs + dq[:, :nv]
        else:
            out = np.array([pin.integrate(self.model, q, d) for q, d in zip(qs, dq[:, :nv])])
        moved = poses.copy()
        moved[:, list(self.free)] += dq[:, nv:]
        return out, moved


class _Shape:
    """The parts of a :class:`PoseProblem` that depend only on the mechanism (read only)."""

    def __init__(self, mech: Mechanism) -> None:
        model = mech.model
        joints = [model.joints[j] for j in range(model.njoints)]  # Pinocchio's wrappers, made once
        pid = mech.platform_id
        body = model.frames[pid].parentJoint
        self.frames = [pid] + [b.tip_id for b in mech.limbs if model.frames[b.tip_id].parentJoint != body]
        self.mask = np.zeros((len(self.frames), 1, model.nv))  # (F, 1, nv): the joints supporting each frame
        for i, frame in enumerate(self.frames):
            for j in list(model.supports[model.frames[frame].parentJoint])[1:]:
                self.mask[i, 0, joints[j].idx_v : joints[j].idx_v + joints[j].nv] = 1.0
        self.frame_mask = np.ascontiguousarray(self.mask[:, 0])  # (F, nv), as the compiled kernels take it
        self.col_q = np.where(linear_velocity_mask(model), mech.length_scale, 1.0)
        self.vector_space = all(joint.shortname() in VECTOR_JOINTS for joint in joints[1:])
        self.angles = np.flatnonzero(angle_mask(model))
        #: The revolute angles' velocity indices (a joint with an angle has one coordinate per velocity).
        rate = {j.idx_q + i: j.idx_v + i for j in joints[1:] for i in range(j.nq)}
        self.angle_rates = np.array([rate[int(i)] for i in self.angles], np.int64)
        self.limits = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
        self.limited = self.limits[0] < self.limits[1]  # lower >= upper: no limits (wrap_angles' rule)


def _wrap_and_check(
    out: Array, angles: NDArray[np.intp], lower: Array, upper: Array, limited: Mask
) -> tuple[Mask, Mask]:
    """``batch_newton_kernel.wrap_and_check`` in numpy (the same arithmetic over the whole stack)."""
    x = np.pi - np.mod(np.pi - out[:, angles], 2 * np.pi)  # in (-pi, pi]
    special = np.any(limited[angles] & ((x < lower[angles]) | (x > upper[angles])), axis=1)
    out[:, angles] = x
    outside = np.any(limited & ((out < lower - 1e-9) | (out > upper + 1e-9)), axis=1)
    return np.asarray(special, np.bool_), np.asarray(outside, np.bool_)


def _worst(e: Array, frames: int) -> Array:
    """(B,) ``max |e|`` per sample: the largest position or rotation norm over the frames."""
    parts = e.reshape(len(e), frames * 2, 3)
    return np.sqrt(np.max(np.einsum("bij,bij->bi", parts, parts), axis=1))


def solve_poses(
    problem: PoseProblem,
    qs: Array,
    poses: Array,
    tol: float = 1e-12,
    max_iter: int = MAX_ITER,
    stall_window: int = STALL_WINDOW,
    floor: float = POLISH_FLOOR,
) -> BatchSolution:
    """Damped Newton on B pose assemblies in lockstep (module docstring) from (B, nq) starts to (B, 6) poses.

    ``poses`` holds the given coordinates and the free ones' starting values (the warm starts' own). A sample
    within ``tol`` goes on while its steps keep at most ``POLISH_GAIN`` of ``max |e|^2``, down to ``floor``
    (the single-sample solver's polish); the best iterate of each sample is returned.
    """
    if problem.kernel is None:  # numpy's LAPACK calls on one BLAS thread (the compiled loop calls no BLAS)
        with one_blas_thread:
            return _solve(problem, qs, poses, tol, max_iter, stall_window, floor)
    return _solve_compiled(problem, qs, poses, tol, max_iter, stall_window, floor)


def solver_numbers(tol: float, floor: float) -> Array:
    """The compiled iterations' numbers: damping, maximum step, tol, floor, stall gain, polish gain, divergence factor."""
    return np.array([DAMPING, MAX_STEP, tol, floor, STALL_GAIN, POLISH_GAIN, DIVERGED])


def _solve_compiled(
    problem: PoseProblem, qs: Array, poses: Array, tol: float, max_iter: int, stall_window: int, floor: float
) -> BatchSolution:
    """:func:`solve_poses`'s iterations, each one compiled call (``batch_newton_kernel.iterate``) after Pinocchio's."""
    kernel = problem.kernel
    assert kernel is not None
    q, p = np.array(qs, float), np.array(poses, float)
    n = len(q)
    history = np.full((n, max_iter + 1), np.inf)
    best_q, best_p, best = q.copy(), p.copy(), np.full(n, np.inf)
    best_full, best_frames = problem.empty_kinematics(n)
    numbers = solver_numbers(tol, floor)
    active, mask = np.arange(n), problem.frame_mask
    if problem.fast.integrable:  # the whole loop in one compiled call (no Python per iteration)
        kernel.solve_stack(q, p, problem.fast.tables, mask, problem.step_col, problem.free_array, problem.length,
                           numbers, stall_window, max_iter, problem.vector_space, best, best_q, best_p, history,
                           best_full, best_frames)  # fmt: skip
        return BatchSolution(best_q, best, best <= tol, best_full, best_frames)
    structure = kernel.step_structure(mask, problem.model.nv, len(problem.free))  # the same for every iteration
    for it in range(max_iter + 1):
        full, placements = problem.kinematics(q[active])
        before = best[active]
        going, dz = kernel.iterate(full, placements, q, p, active, it, best, best_q, best_p, history, mask,
                                   problem.step_col, problem.free_array, problem.length, numbers, stall_window,
                                   it == max_iter, problem.vector_space, structure)  # fmt: skip
        better = best[active] < before  # the kernel's rule (batch_stopping.advance): strictly smaller
        best_full[active[better]], best_frames[active[better]] = full[better], placements[better]
        if not going.size:
            break
        if not problem.vector_space:
            q[going], p[going] = problem.integrate(q[going], p[going], dz)
        active = going
    return BatchSolution(best_q, best, best <= tol, best_full, best_frames)


def _solve(
    problem: PoseProblem, qs: Array, poses: Array, tol: float, max_iter: int, stall_window: int, floor: float
) -> BatchSolution:
    """:func:`solve_poses`'s iterations with numpy stacks (without numba; the compiled ones: :func:`_solve_compiled`)."""
    q, p = np.array(qs, float), np.array(poses, float)
    n, frames = len(q), len(problem.frames)
    history = np.full((n, max_iter + 1), np.inf)
    best_q, best_p, best = q.copy(), p.copy(), np.full(n, np.inf)
    best_full, best_frames = problem.empty_kinematics(n)
    active = np.arange(n)
    for it in range(max_iter + 1):
        now_q, here = q[active], p[active]
        full, placements = problem.kinematics(now_q)
        e, jac = problem.residual_of(full, placements, here)
        now = _worst(e, frames)
        better, keep = plain_advance(now, active, it, best, history, tol, floor, stall_window, STALL_GAIN, POLISH_GAIN,
                               DIVERGED)  # fmt: skip
        best_q[active[better]], best_p[active[better]] = now_q[better], here[better]
        best_full[active[better]], best_frames[active[better]] = full[better], placements[better]
        if not keep.any() or it == max_iter:
            break
        e, jac = e[keep], jac[keep]
        jtj = jac.transpose(0, 2, 1) @ jac
        k = np.arange(jtj.shape[1])
        jtj[:, k, k] += (DAMPING / k.size) * np.einsum("bii->b", jtj)[:, None]  # + mu I
        dz = np.asarray(-np.linalg.solve(jtj, (jac.transpose(0, 2, 1) @ e[..., None]))[..., 0], float)
        dz *= np.minimum(1.0, MAX_STEP / np.max(np.abs(dz), axis=1))[:, None]
        active = active[keep]
        q[active], p[active] = problem.integrate(now_q[keep], here[keep], dz)
    return BatchSolution(best_q, best, best <= tol, best_full, best_frames)
