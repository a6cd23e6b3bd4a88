"""A stack of continuation starts closed in one compiled call (numba, the optional ``fast`` extra).

:func:`close_moved` is what :meth:`pinmob.scan.predictor.Predictor.close` does over numpy for a stack of samples
of a scan, in one call: each seed moved on by a secant's move (:func:`pinmob.assembly.batched.secant.moved_stack`), the
target's joint values held, :func:`pinmob.assembly.batched.batch_newton_kernel.solve_stack`, the closed configurations'
angles wrapped (:func:`~pinmob.assembly.batched.batch_newton_kernel.wrap_and_check`, the arithmetic of
:meth:`pinmob.assembly.batched.batch_solver.PoseProblem.finish`) and the check of each correction against its move
(:func:`pinmob.assembly.batched.secant.off_secants`). The same operations on the same numbers as that Python: on a
vector space (revolute and prismatic joints) the moves, starts and configurations to the last bit, the corrections'
lengths to round-off (compared with the moves' only); with unbounded revolute or spherical joints the moves are
Pinocchio's ``difference`` and ``integrate`` compiled (:func:`~pinmob.model.difference_kernel`,
:func:`~pinmob.model.integrate_kernel`, equal to 1e-13), so the starts and the closed configurations differ in
round-off (``tests/test_scan_lockstep.py``). The seeding walk closes one sample at a time on it: a dozen numpy calls
of a few microseconds each, per sample, are one call here. Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pinmob.assembly.batched.batch_newton_kernel import solve_stack, wrap_and_check
from pinmob.jit_cache import njit
from pinmob.model import difference_kernel, integrate_kernel
from pinmob.screw import Array, Mask

#: Integer arrays (indices).
Ints = NDArray[np.int64]


@njit
def short_move(
    a: Array, b: Array, kind: Ints, iq: Ints, iv: Ints, vector_space: bool, angle_rates: Ints, out: Array
) -> None:
    """``b - a`` in the tangent space into ``out`` (nv,), each revolute angle's part the short way round.

    :func:`pinmob.assembly.batched.secant.short_moves` of one row: ``b - a`` on a vector space, else Pinocchio's
    ``difference`` (:func:`~pinmob.model.difference_kernel`); then ``remainder(x + pi, 2 pi) - pi`` at
    ``angle_rates``.
    """
    if vector_space:
        for j in range(out.size):
            out[j] = b[j] - a[j]
    else:
        difference_kernel(a, b, kind, iq, iv, out)
    for r in angle_rates:
        out[r] = np.remainder(out[r] + np.pi, 2 * np.pi) - np.pi


@njit
def move_length(move: Array, col: Array) -> float:
    """Length of a tangent move in the joint metric (slides per L, angles in rad): :func:`~pinmob.assembly.batched.secant.move_lengths`."""
    total = 0.0
    for j in range(move.size):
        x = move[j] / col[j]
        total += x * x
    return float(np.sqrt(total))


@njit
def close_moved(
    a: Array,
    b: Array,
    has: Mask,
    seeds: Array,
    poses: Array,
    joint_q: Ints,
    joints: Array,
    tables: tuple[Ints, Ints, Array, Ints, Ints, Array, Array, Ints, Array, Array],
    mask: Array,
    col: Array,
    step_col: Array,
    free: Ints,
    length: float,
    numbers: Array,
    stall_window: int,
    max_iter: int,
    vector_space: bool,
    angle_rates: Ints,
    angles: Ints,
    limits: tuple[Array, Array, Mask],
    ratio: float,
) -> tuple[Array, Array, Array, Array, Mask, Array, Array, Mask, Mask, Mask]:
    """B starts moved, closed, finished and checked (module docstring), in one call.

    Args:
        a: (B, nq) where each row's move starts (the rows not ``has`` unread).
        b: (B, nq) where it ends: each seed where ``has`` moves on by the short move from ``a`` to ``b``.
        has: (B,) the rows that move (the others start at their seed).
        seeds: (B, nq) the seeds.
        poses: (B, 6) the target pose coordinates (the following ones already at the seeds').
        joint_q: (J,) configuration indices of the joints the targets give.
        joints: (B, J) their values: held in the starts (the caller sets them exactly in the closed configurations,
            where an angle may be wrapped; the corrections are measured to those).
        tables: the compiled kinematics' tables (:attr:`pinmob.model.FrameKinematics.tables`).
        mask: (F, nv) the joints supporting each frame.
        col: (nv + free,) the problem's columns: the joint metric's scales (L on slides, 1 on angles).
        step_col: the steps' columns (0 on the joints the targets give).
        free: (free,) the pose coordinates that are unknowns.
        length: the length scale L [m].
        numbers: :func:`~pinmob.assembly.batched.batch_solver.solver_numbers`.
        stall_window: the solver's stall window.
        max_iter: its iterations at most.
        vector_space: every joint's configuration is its velocity (``q + v``).
        angle_rates: the revolute angles' velocity indices.
        angles: their configuration indices.
        limits: the lower and upper position limits and which coordinates have them.
        ratio: a converged row whose correction (start to closed, joint metric) is longer than ``ratio`` times its
            move is off its secant.

    Returns:
        the closed configurations (angles wrapped where converged; the others as the solver left them), the
        solver's (unwrapped), the starts (before the joints are held) and their moves' lengths (0: not moved), the
        converged rows, the world Jacobians (B, 6, nv) and frame placements (B, F, 4, 4) at them, the rows
        ``wrap_and_check`` leaves to :func:`~pinmob.model.joints.wrap_angles` and those outside their limits, and
        the rows off their secants.
    """
    n, nq, nv = seeds.shape[0], seeds.shape[1], mask.shape[1]
    kind, iq, iv, frames = tables[1], tables[3], tables[4], tables[7].size  # the joints (the moves) and the frame count
    lower, upper, limited = limits
    move, moved = np.empty(nv), np.empty(nq)
    starts, step = seeds.copy(), np.zeros(n)
    for i in range(n):
        if not has[i]:
            continue
        short_move(a[i], b[i], kind, iq, iv, vector_space, angle_rates, move)
        step[i] = move_length(move, col)
        if vector_space:
            for j in range(nq):
                starts[i, j] = seeds[i, j] + move[j]
        else:
            integrate_kernel(seeds[i], move, kind, iq, iv, moved)
            starts[i] = moved
    q, p = starts.copy(), poses.copy()
    for i in range(n):
        for c in range(joint_q.size):
            q[i, joint_q[c]] = joints[i, c]
    history = np.full((n, max_iter + 1), np.inf)
    best_q, best_p, best = q.copy(), p.copy(), np.full(n, np.inf)
    best_full, best_frames = np.full((n, 6, nv), np.nan), np.full((n, frames, 4, 4), np.nan)
    solve_stack(q, p, tables, mask, step_col, free, length, numbers, stall_window, max_iter, vector_space, best, best_q,
                best_p, history, best_full, best_frames)  # fmt: skip
    converged = best <= numbers[2]
    out = best_q.copy()
    special, outside, off = np.zeros(n, np.bool_), np.zeros(n, np.bool_), np.zeros(n, np.bool_)
    rows = np.flatnonzero(converged)
    if rows.size:
        done = np.empty((rows.size, nq))
        for r in range(rows.size):
            done[r] = best_q[rows[r]]
        wrapped, beyond = wrap_and_check(done, angles, lower, upper, limited)
        for r in range(rows.size):
            i = rows[r]
            out[i], special[i], outside[i] = done[r], wrapped[r], beyond[r]
            if step[i] > 0.0:  # the correction to the configuration with the given joints exactly at their values
                for j in range(nq):
                    moved[j] = out[i, j]
                for c in range(joint_q.size):
                    moved[joint_q[c]] = joints[i, c]
                short_move(starts[i], moved, kind, iq, iv, vector_space, angle_rates, move)
                off[i] = ratio * step[i] < move_length(move, col)
    return out, best_q, starts, step, converged, best_full, best_frames, special, outside, off
