"""Damped least squares with a trust region and polishing: the one solver behind every assembly.

:func:`solve` finds q with ``e(q) = 0`` for a stacked dimensionless residual
``e`` (m,) whose Jacobian ``J = de/dv`` (m, nv) is taken w.r.t. the joint
velocities (configurations move by ``pin.integrate``).

Step. Columns are scaled to dimensionless rates, ``J' = J D`` with
``D = diag(L for a translation, 1 for a rotation)`` when a length L is given,
so that the step does not depend on the units. With the SVD ``J' = U S V^T``,
the Levenberg-Marquardt step is the minimum-norm

    dz = -V diag(s_i / (s_i^2 + lambda)) U^T e,      (s_i < RCOND s_1 dropped)

limited to ``|dz|_inf <= max_step`` (a trust region: at most ``max_step``
[rad, or L] per joint and step, so that a near-singular J cannot wind a
revolute joint by multiples of 2 pi) and applied as
``q <- integrate(q, D dz)``.

Damping (Nielsen's rule). With the gain ratio
``rho = (|e|^2 - |e_new|^2) / (|e|^2 - |e + J' dz|^2)``, a step that lowers
the cost is accepted and ``lambda <- lambda max(1/3, 1 - (2 rho - 1)^3)``;
otherwise ``lambda <- nu lambda``, ``nu <- 2 nu`` and the step is retried. The
solve stops unconverged when the cost gained less than ``STALL_GAIN`` over
the last ``STALL_WINDOW`` iterations, or after ``max_iter`` iterations.

Gauss-Newton and polish. Once ``max |e| <= NEWTON_SWITCH`` the solver is in
the basin of a solution and takes Gauss-Newton steps (lambda = 0, pseudo-
inverse), backtracking to 1/2 and 1/4 of the step, while a step lowers the
cost by at least ``1 - POLISH_GAIN``, until ``max |e| <= POLISH_FLOOR`` (near
machine precision; ``tol`` when ``polish`` is off), at most ``POLISH_STEPS``.
If they stall above ``tol``, damped steps finish. Near a singular solution
(a double root, e.g. an actuation singularity, or a limb at a serial
singularity) the residual grows with the square of the distance, the damped
steps converge slowly, and a residual of 1e-12 can leave joints 1e-6 off:
Gauss-Newton steps halve the distance at each step and polishing brings it to
~1e-8, below the rank tolerances of the analysis.

Angles. Revolute angles are finally wrapped into (-pi, pi] where the joint
limits allow it (:func:`pinmob.model.joints.wrap_angles`).

Written twice. The scans' solve at a platform pose runs these iterations in
compiled code (:func:`pinmob.assembly.compiled_solve.pose_solve_kernel.solve_pose`,
which cannot call this loop): a change to the rules above is made in both. The
kernel reads this module's constants; ``tests/test_pose_solve_kernel.py``
compares the two loops from the same starts.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from pinmob.blas import one_blas_thread
from pinmob.model import linear_velocity_mask, wrap_angles
from pinmob.screw import Array, Mask, svd

#: Integer index array.
IndexArray = NDArray[np.intp]

#: Largest step per joint [rad, or L when a length is given].
MAX_STEP = 1.0
#: Singular values below RCOND times the largest are treated as zero.
RCOND = 1e-13
#: Unconverged stop: the cost gained less than this fraction over STALL_WINDOW iterations.
STALL_GAIN, STALL_WINDOW = 1e-3, 20
#: Polishing: stop at this max |e|, after this many steps, or when a step keeps more than POLISH_GAIN of the cost.
POLISH_FLOOR, POLISH_STEPS, POLISH_GAIN = 1e-15, 60, 0.9
#: Below this max |e| the solver switches from damped to Gauss-Newton steps.
NEWTON_SWITCH = 1e-6
#: Trial steps per iteration (each raises lambda) before the solve gives up.
MAX_TRIALS = 16

ResidualFn = Callable[[Array], tuple[Array, Array]]


@dataclass(frozen=True)
class SolverResult:
    """Outcome of :func:`solve`.

    Attributes:
        q: (nq,) the last configuration (angles wrapped).
        residual: ``max |e|`` at q (dimensionless).
        iterations: damped and Gauss-Newton iterations.
        converged: ``max |e| <= tol`` was reached.
        polish: Gauss-Newton iterations among them.
    """

    q: Array
    residual: float
    iterations: int
    converged: bool
    polish: int = 0


def _max(e: Array) -> float:
    return float(np.abs(e).max()) if e.size else 0.0


@dataclass
class _State:
    """The solver's current point: configuration, residual, Jacobian, cost ``|e|^2`` and ``max |e|``."""

    q: Array
    e: Array
    jac: Array
    cost: float
    worst: float


class _Problem:
    """A residual with its column scaling and free columns: trial points and minimum-norm steps."""

    def __init__(self, model: pin.Model, residual: ResidualFn, col: Array, cols: IndexArray, max_step: float) -> None:
        self.model, self.residual, self.cols, self.max_step = model, residual, cols, max_step
        self.every = cols.size == model.nv  # every column free: no column picked out (the same numbers)
        self.col = col if self.every else col[cols]  # the free columns' scales

    def at(self, q: Array) -> _State:
        e, jac = self.residual(q)
        return _State(q, e, jac, float(e @ e), _max(e))

    def svd(self, x: _State) -> tuple[Array, Array, Array, Array]:
        """Scaled Jacobian J' (m, k) on the free columns, and U^T e, s, V^T of its SVD (s < RCOND s_1 zeroed)."""
        # in Fortran order, as numpy's pick of the free columns gives: the products (J' dz) keep their round-off
        js = np.multiply(x.jac, self.col, order="F") if self.every else x.jac[:, self.cols] * self.col
        u, s, vt = svd(js, full_matrices=False)
        return js, u.T @ x.e, np.where(s > RCOND * s[0], s, 0.0), vt

    def cap(self, dz: Array) -> Array:
        """Dz scaled down to the trust region ``|dz|_inf <= max_step``."""
        big = float(np.abs(dz).max())
        return dz * (self.max_step / big) if big > self.max_step else dz

    def step(self, x: _State, dz: Array) -> _State:
        """The point ``integrate(q, D dz)`` (scaled step dz on the free columns)."""
        if self.every:
            dq = dz * self.col
        else:
            dq = np.zeros(self.model.nv)
            dq[self.cols] = dz * self.col
        return self.at(pin.integrate(self.model, x.q, dq))


def _damped(
    p: _Problem, x: _State, tol: float, max_iter: int, damping: float, window: int = STALL_WINDOW
) -> tuple[_State, int]:
    """Levenberg-Marquardt iterations until ``max |e| <= tol``, a stall (over ``window`` iterations), or ``max_iter``."""
    history, lam, it = [x.cost], -1.0, 0
    while x.worst > tol and it < max_iter:
        if len(history) > window and x.cost > (1 - STALL_GAIN) * history[-window - 1]:
            break
        it += 1
        js, g, s, vt = p.svd(x)
        if s[0] == 0:
            break
        lam = damping * s[0] ** 2 if lam < 0 else lam
        nu = 2.0
        for _ in range(MAX_TRIALS):
            dz = p.cap(-vt.T @ (np.divide(s, s**2 + lam, out=np.zeros_like(s), where=s > 0) * g))
            trial = p.step(x, dz)
            if trial.cost < x.cost:
                lin = x.e + js @ dz  # the linear model's residual after the step
                predicted = x.cost - float(lin @ lin)
                rho = (x.cost - trial.cost) / predicted if predicted > 0 else 0.0
                lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                x = trial
                break
            lam = max(lam, 1e-30 * s[0] ** 2) * nu
            nu *= 2.0
        else:
            break
        history.append(x.cost)
    return x, it


def _gauss_newton(p: _Problem, x: _State, floor: float) -> tuple[_State, int]:
    """Gauss-Newton steps (pseudo-inverse, backtracking 1, 1/2, 1/4) until ``max |e| <= floor`` or a weak gain."""
    steps = 0
    while steps < POLISH_STEPS and x.worst > floor:
        _, g, s, vt = p.svd(x)
        if s[0] == 0:
            break
        dz = p.cap(-vt.T @ np.divide(g, s, out=np.zeros_like(s), where=s > 0))
        best = x
        for frac in (1.0, 0.5, 0.25):
            trial = p.step(x, frac * dz)
            best = trial if trial.cost < best.cost else best
            if best.cost <= POLISH_GAIN * x.cost:
                break
        if best is x:
            break
        gained = best.cost <= POLISH_GAIN * x.cost
        x, steps = best, steps + 1
        if not gained:
            break
    return x, steps


@one_blas_thread
def solve(
    model: pin.Model,
    residual: ResidualFn,
    q0: Array,
    tol: float = 1e-12,
    max_iter: int = 200,
    damping: float = 1e-3,
    *,
    length: float | None = None,
    free: Mask | None = None,
    max_step: float = MAX_STEP,
    polish: bool = True,
    stall_window: int = STALL_WINDOW,
) -> SolverResult:
    """Levenberg-Marquardt on ``residual(q) -> (e (m,), J (m, nv))`` from q0 (see the module docstring).

    Args:
        model: the Pinocchio model (configurations move by ``pin.integrate``).
        residual: ``q -> (e (m,), J (m, nv))``, dimensionless.
        q0: (nq,) the start.
        tol: convergence threshold on ``max |e|`` (dimensionless).
        max_iter: damped iterations at most (each phase); Gauss-Newton steps are bounded by ``POLISH_STEPS``.
        damping: initial lambda relative to the largest squared singular value of J'.
        length: L [m] scaling translation columns (None: columns as they are).
        free: (nv,) velocity components the solver may move (None: all); the
            others keep their values exactly.
        max_step: trust region, largest step per joint [rad, or L].
        polish: continue with Gauss-Newton steps after ``tol`` down to ``POLISH_FLOOR``.
        stall_window: damped iterations over which a cost gain below ``STALL_GAIN`` stops the solve unconverged
            (the iterates do not depend on it: only where an unconverged solve stops).
    """
    col = np.ones(model.nv) if length is None else np.where(linear_velocity_mask(model), length, 1.0)
    cols: IndexArray = np.arange(model.nv) if free is None else np.flatnonzero(free)
    p = _Problem(model, residual, col, cols, max_step)
    x = p.at(np.array(q0, float))
    floor = POLISH_FLOOR if polish else tol
    it = newton = 0
    if cols.size and x.e.size:
        x, it = _damped(p, x, max(tol, NEWTON_SWITCH), max_iter, damping, stall_window)
        if x.worst <= NEWTON_SWITCH:
            x, newton = _gauss_newton(p, x, floor)
        if tol < x.worst <= NEWTON_SWITCH:  # Gauss-Newton stalled above tol: damped steps finish
            x, k = _damped(p, x, tol, max_iter, damping, stall_window)
            it += k
            if x.worst <= tol:
                x, k = _gauss_newton(p, x, floor)
                newton += k
    q, e = x.q, x.e
    wrapped = wrap_angles(model, q)
    if not np.array_equal(wrapped, q):
        q, e = wrapped, residual(wrapped)[0]
    return SolverResult(q, _max(e), it + newton, _max(e) <= tol, newton)
