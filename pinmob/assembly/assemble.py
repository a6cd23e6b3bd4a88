"""Assembly: closed configurations from any configuration, from actuated joint values, from a platform pose.

Each is one :func:`~pinmob.assembly.solver.solve` on stacked dimensionless residuals
(lengths divided by L), polished to near machine precision:

- :func:`project`: the nearest closed configuration (every closure residual);
- :func:`solve_actuated`: forward kinematics of the closed chain: the given
  joints are held at their values exactly and the others solve the closures;
  from a seed that does not converge, a continuation (homotopy) moves the
  given joints from their values at the seed's projection to the targets;
- :func:`assemble_pose`: inverse kinematics: the platform frame and every limb
  tip against the target pose, and the other closures.

Failure is a :class:`ClosureError` carrying the residual of every limb,
closure and target; a joint that ends outside its position limits is a
warning (and listed in :attr:`Assembly.outside_limits`).
"""

from __future__ import annotations

import warnings
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmob.assembly.closure_miss import format_worst, tolerance_hint
from pinmob.assembly.compiled_solve import compiled_pose_solver
from pinmob.assembly.continuation import continuation, held_coordinates
from pinmob.assembly.reach import reach_note
from pinmob.assembly.residual import (
    CLOSURE_TOL,
    Residuals,
    closure_residual,
    compute_kinematics,
    format_residuals,
    mechanism_residuals,
    pose_error,
    stacked_error,
    worst_residual,
)
from pinmob.assembly.solver import STALL_WINDOW, SolverResult, solve
from pinmob.exceptions import ClosureError, ConfigurationError
from pinmob.frozen import ReadOnlyArrays
from pinmob.model import Mechanism, borrowed, linear_velocity_mask, one_degree_indices, outside_limits
from pinmob.screw import Array, twist_scaling


@dataclass(frozen=True)
class Assembly(ReadOnlyArrays):
    """A closed configuration found by the solver.

    Attributes:
        q: (nq,) the configuration.
        residuals: per limb / closure (and, from actuated values, ``joint <name>``: the held
            joint's miss), (position [m], rotation [rad]).
        residual: largest dimensionless residual (position / L, rotation).
        iterations: solver iterations.
        method: how it was found, e.g. ``neutral``, ``given``, ``random restart 3``.
        outside_limits: joints that ended outside their position limits (``name [lower, upper]``).
    """

    q: Array
    residuals: Residuals
    residual: float
    iterations: int
    method: str
    outside_limits: tuple[str, ...] = ()

    def to_dict(self) -> dict[str, object]:
        """``{method, residual, iterations, q, outside_limits}`` (plain JSON)."""
        return {
            "method": self.method,
            "residual": self.residual,
            "iterations": self.iterations,
            "q": [float(x) for x in self.q],
            "outside_limits": list(self.outside_limits),
        }


def joint_velocity_indices(mech: Mechanism, names: tuple[str, ...] | list[str]) -> Array:
    """Velocity indices of one-degree joints by name (:func:`pinmob.model.joints.one_degree_indices`).

    Raises:
        FrameError: an unknown joint (the message lists them).
        ConfigurationError: a joint with more than one degree of freedom.
    """
    return one_degree_indices(mech.model, names, mech.name)


def warn_outside_limits(mech: Mechanism, q: Array, what: str) -> tuple[str, ...]:
    """Warn (and return them, :func:`outside_limits`) when joints of ``q`` are outside their position limits.

    The message names the joints and their limits, not the values, so that a
    scan or an animation leaving the limits warns once, not at every sample.
    """
    out = outside_limits(mech.model, q)
    if out:
        warnings.warn(f"{what} of {mech.name!r}: joints outside their position limits: {', '.join(out)}", stacklevel=3)
    return out


def _finish(
    mech: Mechanism, result: SolverResult, method: str, tol: float, what: str, extra: Residuals | None = None
) -> Assembly:
    """The :class:`Assembly` at ``result.q``, or a :class:`ClosureError` when a residual exceeds ``tol``.

    The error gives the worst residuals, not the solver's iteration count: where a solve stalls is decided
    by round-off (the five-bar's failed solve took 26 to 28 iterations under different BLAS kernels); a
    miss of CAD size names the ``--closure-tol`` that accepts it (:mod:`pinmob.assembly.closure_miss`).
    """
    with borrowed(mech.model) as data:
        compute_kinematics(mech.model, data, result.q)
        res = mechanism_residuals(mech, data) | (extra or {})
    worst = worst_residual(res, mech.length_scale)
    if worst > tol:
        length = mech.length_scale  # the worst residuals, and the closure_tol that accepts a CAD-sized miss
        raise ClosureError(
            f"{what} of {mech.name!r} did not converge: residuals {format_worst(res, length, tol)}"
            f"{tolerance_hint(res, length)}",
            res,
        ).naming("closure_tol")
    limits = warn_outside_limits(mech, result.q, what)
    return Assembly(result.q, res, worst, result.iterations, method, limits)


def _solver_tol(tol: float) -> float:
    return min(1e-12, tol * 1e-3)


def project(
    mech: Mechanism, q0: Array | None = None, tol: float = CLOSURE_TOL, max_iter: int = 200, method: str = "projection"
) -> Assembly:
    """Closed configuration near ``q0`` (default neutral): damped least squares on every closure residual.

    Each step is the minimum-norm correction (prismatic rates in units of L),
    so the solver moves as little as it can from q0.

    Raises:
        ClosureError: the residual did not reach ``tol``; it carries the residuals.
    """
    start = mech.neutral() if q0 is None else mech.check_q(q0)
    result = solve(
        mech.model, closure_residual(mech), start, tol=_solver_tol(tol), max_iter=max_iter, length=mech.length_scale
    )
    return _finish(mech, result, method, tol, "projection onto the closed set")


def solve_actuated(
    mech: Mechanism,
    values: Mapping[str, float],
    seed: Array | None = None,
    tol: float = CLOSURE_TOL,
    max_iter: int = 200,
) -> Assembly:
    """Forward kinematics of the closed chain: passive joints from actuated joint values.

    The given one-degree joints are held exactly at ``values`` [m or rad]; the
    other joints solve every closure residual from ``seed`` (which selects the
    assembly mode). When that does not converge, a continuation from the
    seed's projection onto the closed set moves the given joints to their
    values (:func:`continuation`).

    Raises:
        FrameError, ConfigurationError: an unknown or multi-degree joint, or a
            value that is not a finite number.
        ClosureError: no closed configuration with these values was reached
            from the seed; its residuals hold every closure residual and, as
            ``joint <name>``, each given joint's miss (zero: they are held).
    """
    model = mech.model
    idx = joint_velocity_indices(mech, list(values))
    start = mech.neutral() if seed is None else mech.check_q(seed)
    target = mech.q_from_joints(values, base=start)
    free = np.ones(model.nv, bool)
    free[idx] = False
    stol = _solver_tol(tol)
    residual = closure_residual(mech)
    result = solve(model, residual, target, tol=stol, max_iter=max_iter, length=mech.length_scale, free=free)
    if not result.converged and idx.size:
        homotopy = continuation(mech, start, target, idx, stol, max_iter)
        if homotopy is not None:
            result = homotopy
    held = held_coordinates(mech, idx)
    q = result.q.copy()
    q[held] = target[held]  # exactly the given values (the solver may have wrapped an angle by 2 pi)
    result = SolverResult(q, result.residual, result.iterations, result.converged, result.polish)
    miss = np.abs(pin.difference(model, q, target)[idx])
    lin = linear_velocity_mask(model)[idx]
    misses = {f"joint {n}": (float(d), 0.0) if t else (0.0, float(d)) for n, d, t in zip(values, miss, lin)}
    return _finish(mech, result, "actuated values", tol, "forward kinematics (actuated joint values)", misses)


def assemble_pose(
    mech: Mechanism,
    pose: pin.SE3,
    seed: Array | None = None,
    tol: float = CLOSURE_TOL,
    max_iter: int = 200,
    stall_window: int = STALL_WINDOW,
    compiled: bool = False,
) -> Array:
    """Closed configuration whose platform frame has ``pose`` (inverse kinematics of every limb).

    Residuals (position parts divided by L): the platform frame and every limb
    tip against ``pose`` (``log6(pose^-1 oM_f)``: each limb is solved for the
    target on its own, so a symmetric seed of a symmetric mechanism gives a
    symmetric solution), then the closures that are not limb tips. ``stall_window``: the solver's
    (:func:`~pinmob.assembly.solver.solve`). ``compiled``: its iterations in one compiled call where the mechanism
    allows it (:func:`~pinmob.assembly.compiled_solve.compiled_pose_solver`: no closure besides the limb tips,
    numba installed; the same iterations, round-off aside), as a scan's samples are.

    Raises:
        ConfigurationError: ``mech`` has no platform, or ``pose`` is not finite.
        ClosureError: the solver did not reach ``tol``; the message and the
            residuals give every limb, closure and the platform pose (``pose``), and the message
            the pose coordinates the mechanism does not reach (:func:`~pinmob.assembly.reach.reach_note`).
    """
    if not mech.has_platform:
        raise ConfigurationError(f"{mech.name!r} has no platform frame: a platform pose cannot be assembled")
    if not isinstance(pose, pin.SE3) or not np.isfinite(pose.homogeneous).all():
        raise ConfigurationError(f"the platform pose must be a finite pin.SE3, got {pose!r}")
    model = mech.model
    scale = twist_scaling(mech.length_scale)
    pid = mech.platform_id
    body = model.frames[pid].parentJoint
    frames = [pid] + [b.tip_id for b in mech.limbs if model.frames[b.tip_id].parentJoint != body]
    q0 = mech.neutral() if seed is None else mech.check_q(seed)
    size = 6 * len(frames)  # the tips' rows (the closures' follow)
    with borrowed(model) as data:
        rows = scale[:, None]

        def residual(q: Array) -> tuple[Array, Array]:
            compute_kinematics(model, data, q)
            errors, jacobians = np.empty(size), np.empty((size, model.nv))
            for i, f in enumerate(frames):
                e, j = pose_error(model, data, f, pose)
                np.multiply(scale, e, out=errors[6 * i : 6 * i + 6])
                np.multiply(rows, j, out=jacobians[6 * i : 6 * i + 6])
            if mech.closures:
                e1, j1 = stacked_error(mech, model, data, mech.closures)
                return np.concatenate([errors, e1]), np.vstack([jacobians, j1])
            return errors, jacobians

        fast = compiled_pose_solver(mech, frames) if compiled else None
        if fast is not None:
            result = fast.solve(pose, q0, _solver_tol(tol), max_iter, stall_window=stall_window)
        else:
            result = solve(model, residual, q0, tol=_solver_tol(tol), max_iter=max_iter, length=mech.length_scale,
                           stall_window=stall_window)  # fmt: skip
        compute_kinematics(model, data, result.q)
        e_pose = pin.log6(pose.actInv(data.oMf[pid])).vector
        res_pose = (float(np.linalg.norm(e_pose[:3])), float(np.linalg.norm(e_pose[3:])))
        closures = mechanism_residuals(mech, data)
    res = closures | {"pose": res_pose}
    if worst_residual(res, mech.length_scale) > tol:
        raise ClosureError(
            f"could not assemble {mech.name!r} at platform pose xyz={np.round(pose.translation, 6).tolist()}: "
            f"platform pose residual {res_pose[0]:.2e} m, {res_pose[1]:.2e} rad; "
            f"closures {format_residuals(closures)}.",
            res,
            note=lambda: reach_note(mech, pose, result.q, tol),
        )
    warn_outside_limits(mech, result.q, "assembly at a platform pose")
    return result.q


def assemble_joints(
    mech: Mechanism, values: Mapping[str, float], seed: Array, tol: float = CLOSURE_TOL, max_iter: int = 200
) -> Array:
    """Closed configuration with the named one-degree joints held at ``values``: :func:`solve_actuated`'s ``q``.

    Raises:
        FrameError, ConfigurationError: a joint is unknown or has more than one degree of freedom.
        ClosureError: the loops did not close with these values from ``seed``.
    """
    return solve_actuated(mech, values, seed, tol, max_iter).q
