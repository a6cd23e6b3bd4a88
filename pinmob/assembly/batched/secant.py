"""Continuation starts of a stack: each closed sample moved on by a secant's move, and the check of its correction.

A scan's predictor (:class:`pinmob.scan.predictor.Predictor`) starts each sample of a line from the last one moved on
by the line's secant, and the seeding walk its even waypoints from the last one moved as two before moved
(:func:`moved_stack`); a start whose Newton correction is longer than its move left the continuation
(:func:`off_secants`). Moves are taken in the tangent space, each revolute angle the short way
round (:func:`short_moves`), and measured in the joint metric (:func:`move_lengths`: slides per L, angles in rad).
:mod:`pinmob.assembly.batched.secant_kernel` does the same, compiled, with the solve between.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from pinmob.assembly.batched.batch_solver import MAX_ITER, STALL_WINDOW, PoseProblem, solver_numbers
from pinmob.screw import Array, Mask


def short_moves(problem: PoseProblem, a: Array, b: Array) -> Array:
    """(B, nv) ``b - a`` of (B, nq) stacks, row by row, in the tangent space (Pinocchio's ``difference``).

    Each revolute angle's part goes the short way round.
    """
    if problem.vector_space:
        move = b - a
    else:
        move = np.array([pin.difference(problem.model, x, y) for x, y in zip(a, b)]).reshape(len(a), problem.model.nv)
    move[:, problem.angle_rates] = np.remainder(move[:, problem.angle_rates] + np.pi, 2 * np.pi) - np.pi
    return move


def moved_stack(problem: PoseProblem, a: Array, b: Array, has: Mask, seeds: Array) -> tuple[Array, Array]:
    """Each row of the (B, nq) ``seeds`` moved on by ``b - a`` where ``has``, and the moves' lengths (0: not moved).

    The moves are :func:`short_moves`, their lengths in the joint metric (:func:`move_lengths`): a line's secant
    starts when ``a`` is the closed sample before each seed and ``b`` the seeds (the closed samples' angles are
    wrapped into (-pi, pi]). A start only: the sample's verdict and branch are the Newton steps' from it (checked by
    :func:`off_secants`).
    """
    move = short_moves(problem, a, b)
    if problem.vector_space:
        starts = np.where(has[:, None], seeds + move, seeds)
    else:
        starts = seeds.copy()
        for i in np.flatnonzero(has):
            starts[i] = pin.integrate(problem.model, seeds[i], move[i])
    return starts, np.where(has, move_lengths(problem, move), 0.0)


def move_lengths(problem: PoseProblem, moves: Array) -> Array:
    """(B,) lengths of (B, nv) tangent moves in the joint metric: slides per L, angles in rad (any unit alike)."""
    x = moves / problem.col[: problem.model.nv]
    return np.sqrt(np.einsum("ij,ij->i", x, x))


def off_secants(
    problem: PoseProblem, seeds: Array, starts: Array, qs: Array, step: Array | None = None, ratio: float = 1.0
) -> Mask:
    """Per row of (B, nq) stacks: the Newton steps from a secant start went further than ``ratio`` x its step.

    The step (joint metric) is ``step`` (the moves' lengths, when known: :func:`moved_stack`), else the move from
    the seed to the start. Along a smooth line the correction is of second order in the step; a longer one means the
    steps left the continuation (on a coarse grid, the 3-UPU-wrist's U joints closed turned by pi), so the sample is
    closed again from its seed, as the single-sample engine's continuation does. False where the step is 0 (no
    secant).
    """
    step = move_lengths(problem, short_moves(problem, seeds, starts)) if step is None else step
    return (step > 0.0) & (ratio * step < move_lengths(problem, short_moves(problem, starts, qs)))  # 0: start at seed


class MovedSolution(NamedTuple):
    """What :func:`close_moved` found for B starts (:func:`pinmob.assembly.batched.secant_kernel.close_moved`'s outputs)."""

    #: (B, nq) the closed configurations: angles wrapped where converged (the rows ``special`` left to
    #: :meth:`PoseProblem.finish <pinmob.assembly.batched.batch_solver.PoseProblem.finish>`), as the solver left the others
    q: Array
    #: (B, nq) the solver's configurations (unwrapped)
    raw: Array
    #: (B, nq) the starts (before the targets' joints are held) and (B,) their moves' lengths (0: not moved)
    starts: Array
    step: Array
    #: (B,) within the tolerance
    converged: Mask
    #: (B, 6, nv) world Jacobians and (B, F, 4, 4) frame placements at ``raw``
    jacobians: Array
    frames: Array
    #: (B,) ``wrap_and_check``'s: an angle whose wrapped value is outside its limits, a coordinate outside its limits
    special: Mask
    outside: Mask
    #: (B,) a converged row whose correction was longer than the ratio times its move (:func:`off_secants`)
    off: Mask


def close_moved(
    problem: PoseProblem,
    moves: tuple[Array, Array, Mask],
    seeds: Array,
    poses: Array,
    joint_q: NDArray[np.int64],
    joints: Array,
    ratio: float,
    tol: float,
) -> MovedSolution | None:
    """:func:`moved_stack`, :func:`~pinmob.assembly.batched.batch_solver.solve_poses` and :func:`off_secants` in one compiled call.

    ``moves``: ``(a, b, has)`` of :func:`moved_stack`; ``poses`` (B, 6) the targets (none following); ``joint_q``
    and ``joints`` (B, J): the targets' joint values, held in the starts; ``ratio``: :func:`off_secants`'; ``tol``:
    the solver's tolerance and floor. None when it does not apply, where the caller runs those three: without numba,
    on Pinocchio's kinematics (``PINMOB_KINEMATICS=pinocchio``, or a joint the compiled kinematics do not model),
    or with a joint the compiled loop does not integrate (a free-flyer or planar one).
    """
    if problem.kernel is None or not problem.fast.integrable:
        return None
    from pinmob.assembly.batched.secant_kernel import close_moved as kernel

    a, b, has = moves
    lower, upper = problem.limits
    return MovedSolution(
        *kernel(
            a,
            b,
            has,
            seeds,
            poses,
            joint_q,
            joints,
            problem.fast.tables,
            problem.frame_mask,
            problem.col,
            problem.step_col,
            problem.free_array,
            problem.length,
            solver_numbers(tol, tol),
            STALL_WINDOW,
            MAX_ITER,
            problem.vector_space,
            problem.angle_rates,
            problem.angles,
            (lower, upper, problem.limited),
            ratio,
        )
    )
