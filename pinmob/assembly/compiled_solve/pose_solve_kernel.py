"""The single-sample solver's iterations at a platform pose, compiled (numba, the optional ``fast`` extra).

:func:`solve_pose` runs the iterations of :func:`pinmob.assembly.solver.solve` (that module's docstring: damped
steps by the SVD of the column-scaled Jacobian, Nielsen's damping, the trust region, the stall rule, then the
Gauss-Newton polish with its backtracking, and damped steps again where it stalls above ``tol``) on the residual of
:func:`pinmob.assembly.assemble.assemble_pose` for a mechanism without closures other than its limb tips: per frame
``f`` (the platform's and the tips on other bodies), ``log6(target^-1 oM_f)`` and ``Jlog6 J_f`` (the frame Jacobian
in its LOCAL axes), position rows divided by L. The kinematics are
:func:`~pinmob.model.kinematics_kernel.frames_kernel`'s, the moves
:func:`~pinmob.model.kinematics_kernel.integrate_kernel`'s (Pinocchio's ``integrate``), ``log6`` and
``Jlog6`` :func:`~pinmob.assembly.compiled_solve.se3_log.log6_jlog6`'s (Pinocchio's formulas), the SVD by
blocks where the Jacobian has them (:mod:`~pinmob.assembly.compiled_solve.block_svd`). Round-off differs from
the Python loop's (Pinocchio's calls, numpy's LAPACK and BLAS), not the iterates' limits
(``tests/test_pose_solve_kernel.py``).
Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np

from pinmob.assembly.compiled_solve.block_svd import block_svd
from pinmob.assembly.compiled_solve.se3_log import log6_jlog6
from pinmob.jit_cache import njit
from pinmob.model import frames_kernel, integrate_kernel
from pinmob.screw import Array

#: The frame Jacobians' reference: Pinocchio's LOCAL (the code of :data:`pinmob.model.kinematics_kernel.LOCAL`).
LOCAL = 0


@njit
def _residual(
    q: Array, tables: tuple, rt: Array, pt: Array, scale: Array, e: Array, jac: Array, work: tuple
) -> tuple[float, float]:
    """The residual ``e`` (6F,) and Jacobian ``jac`` (6F, nv) at q, and its cost ``|e|^2`` and ``max |e|``."""
    parent, kind, axis, iq, iv, rot0, pos0, f_parent, f_rot, f_pos = tables
    rot, pos, fj, world, rm, pm, ef, jl = work
    frames_kernel(q.reshape((1, q.shape[0])), parent, kind, axis, iq, iv, rot0, pos0, f_parent, f_rot, f_pos, LOCAL,
                  True, rot, pos, fj, world)  # fmt: skip
    nv = jac.shape[1]
    for f in range(rot.shape[1]):
        d0, d1, d2 = pos[0, f, 0] - pt[0], pos[0, f, 1] - pt[1], pos[0, f, 2] - pt[2]
        for i in range(3):  # target^-1 oM_f: (rt^T r, rt^T (p - pt))
            pm[i] = rt[0, i] * d0 + rt[1, i] * d1 + rt[2, i] * d2
            for j in range(3):
                rm[i, j] = rt[0, i] * rot[0, f, 0, j] + rt[1, i] * rot[0, f, 1, j] + rt[2, i] * rot[0, f, 2, j]
        log6_jlog6(rm, pm, ef, jl)
        for i in range(6):
            e[6 * f + i] = scale[i] * ef[i]
            for c in range(nv):
                acc = 0.0
                for k in range(6):
                    acc += jl[i, k] * fj[0, f, k, c]
                jac[6 * f + i, c] = scale[i] * acc
    cost, worst = 0.0, 0.0
    for i in range(e.shape[0]):
        cost += e[i] * e[i]
        worst = max(worst, abs(e[i]))
    return cost, worst


@njit
def solve_pose(
    q0: Array,
    tables: tuple,
    rt: Array,
    pt: Array,
    scale: Array,
    col: Array,
    settings: Array,
    blocks: tuple,
) -> tuple[Array, float, int, int]:
    """The solver's last configuration from ``q0``, its ``max |e|``, its damped and its Gauss-Newton iterations.

    ``tables``: :attr:`pinmob.model.compiled_kinematics.FrameKinematics.tables` of the residual's frames (every
    joint integrable); the target's rotation ``rt`` and position ``pt``; ``scale`` (6,) of each frame's rows;
    ``col`` (nv,) the column scales D. ``settings``: tol, max_iter, damping, max_step, floor (the polish's),
    stall window, and the solver's constants NEWTON_SWITCH, STALL_GAIN, RCOND, MAX_TRIALS, POLISH_STEPS, POLISH_GAIN.
    ``blocks``: :func:`~pinmob.assembly.compiled_solve.block_svd.frame_blocks`'s of the frames (the SVD by blocks;
    none: LAPACK's of the whole).
    """
    tol, max_iter, damping, max_step, floor = settings[0], int(settings[1]), settings[2], settings[3], settings[4]
    window, switch, gain, rcond = int(settings[5]), settings[6], settings[7], settings[8]
    trials, polish_steps, polish_gain = int(settings[9]), int(settings[10]), settings[11]
    nf, nv, nq = tables[7].shape[0], col.shape[0], q0.shape[0]
    m = 6 * nf
    work = _work(nf, nv)
    q, e, jac = q0.copy(), np.empty(m), np.empty((m, nv))
    tq, te, tj = np.empty(nq), np.empty(m), np.empty((m, nv))  # a trial point
    bq, be, bj = np.empty(nq), np.empty(m), np.empty((m, nv))  # the polish's best trial
    cost, worst = _residual(q, tables, rt, pt, scale, e, jac, work)
    js = np.empty((m, nv))
    dz, dq, y = np.empty(nv), np.empty(nv), np.empty(nv)
    count = blocks[2].shape[0] if blocks[1].shape[0] > 1 else min(m, nv)  # singular values
    s, vt, g = np.empty(count), np.empty((count, nv)), np.empty(count)
    history = np.empty(max_iter + 1)
    iterations, newton = 0, 0
    if m == 0 or nv == 0:
        return q, worst, 0, 0
    for phase in range(4):  # damped to the switch, polish, then (stalled above tol) damped to tol and polish
        if phase == 2 and not (tol < worst <= switch):
            break
        if phase == 3 and worst > tol:
            break
        if phase == 1 and worst > switch:
            continue
        if phase == 0 or phase == 2:
            target = max(tol, switch) if phase == 0 else tol
            lam, it, kept = -1.0, 0, 1
            history[0] = cost
            while worst > target and it < max_iter:
                if kept > window and cost > (1.0 - gain) * history[kept - window - 1]:
                    break
                it += 1
                s0 = _scaled_svd(jac, col, e, js, blocks, s, vt, g)
                if s0 == 0.0:
                    break
                for k in range(s.shape[0]):
                    if not s[k] > rcond * s0:
                        s[k] = 0.0
                lam = damping * s0**2 if lam < 0 else lam
                nu = 2.0
                accepted = False
                for _ in range(trials):
                    for k in range(s.shape[0]):
                        y[k] = s[k] / (s[k] ** 2 + lam) * g[k] if s[k] > 0 else 0.0
                    _step_direction(vt, y, s.shape[0], max_step, dz)
                    tcost, tworst = _trial(q, dz, 1.0, col, dq, tq, te, tj, tables, rt, pt, scale, work)
                    if tcost < cost:
                        predicted = cost
                        for i in range(m):  # the linear model's residual after the step
                            acc = e[i]
                            for c in range(nv):
                                acc += js[i, c] * dz[c]
                            predicted -= acc * acc
                        rho = (cost - tcost) / predicted if predicted > 0 else 0.0
                        lam *= max(1.0 / 3.0, 1.0 - (2.0 * rho - 1.0) ** 3)
                        _keep(tq, te, tj, q, e, jac)
                        cost, worst = tcost, tworst
                        accepted = True
                        break
                    lam = max(lam, 1e-30 * s0**2) * nu
                    nu *= 2.0
                if not accepted:
                    break
                history[kept] = cost
                kept += 1
            iterations += it
        else:  # Gauss-Newton steps, backtracking 1, 1/2, 1/4, while a step lowers the cost by 1 - polish_gain
            steps = 0
            while steps < polish_steps and worst > floor:
                s0 = _scaled_svd(jac, col, e, js, blocks, s, vt, g)
                if s0 == 0.0:
                    break
                for k in range(s.shape[0]):
                    y[k] = g[k] / s[k] if s[k] > rcond * s0 else 0.0
                _step_direction(vt, y, s.shape[0], max_step, dz)
                best_cost, best_worst, found = cost, worst, False
                for frac in (1.0, 0.5, 0.25):
                    tcost, tworst = _trial(q, dz, frac, col, dq, tq, te, tj, tables, rt, pt, scale, work)
                    if tcost < best_cost:
                        _keep(tq, te, tj, bq, be, bj)
                        best_cost, best_worst, found = tcost, tworst, True
                    if best_cost <= polish_gain * cost:
                        break
                if not found:
                    break
                gained = best_cost <= polish_gain * cost
                _keep(bq, be, bj, q, e, jac)
                cost, worst = best_cost, best_worst
                steps += 1
                if not gained:
                    break
            newton += steps
    return q, worst, iterations, newton


@njit
def _work(nf: int, nv: int) -> tuple:
    """:func:`_residual`'s work arrays for ``nf`` frames and ``nv`` velocities."""
    return (np.empty((1, nf, 3, 3)), np.empty((1, nf, 3)), np.empty((1, nf, 6, nv)), np.empty((0, 6, nv)),
            np.empty((3, 3)), np.empty(3), np.empty(6), np.empty((6, 6)))  # fmt: skip


@njit
def worst_at(q: Array, tables: tuple, rt: Array, pt: Array, scale: Array, nv: int) -> float:
    """``max |e|`` of :func:`solve_pose`'s residual at q (the solve's last configuration, its angles wrapped)."""
    nf = tables[7].shape[0]
    return _residual(q, tables, rt, pt, scale, np.empty(6 * nf), np.empty((6 * nf, nv)), _work(nf, nv))[1]


@njit
def _step_direction(vt: Array, y: Array, k: int, max_step: float, dz: Array) -> None:
    """``dz = -V y`` (y on the first k right singular vectors), scaled down to ``|dz|_inf <= max_step``."""
    big = 0.0
    for c in range(dz.shape[0]):
        acc = 0.0
        for j in range(k):
            acc += vt[j, c] * y[j]
        dz[c] = -acc
        big = max(big, abs(dz[c]))
    if big > max_step:
        for c in range(dz.shape[0]):
            dz[c] *= max_step / big


@njit
def _keep(q: Array, e: Array, jac: Array, to_q: Array, to_e: Array, to_jac: Array) -> None:
    """Copy a point (q, e, jac) into another's arrays."""
    to_q[:] = q
    to_e[:] = e
    to_jac[:, :] = jac


@njit
def _scaled_svd(jac: Array, col: Array, e: Array, js: Array, blocks: tuple, s: Array, vt: Array, g: Array) -> float:
    """The scaled Jacobian ``J D`` into ``js`` and its SVD; returns the largest singular value.

    The singular values into ``s``, ``V^T`` into ``vt`` and ``U^T e`` into ``g``: by blocks where there are
    (:func:`~pinmob.assembly.compiled_solve.block_svd.block_svd`, the values in block order), else LAPACK's.
    """
    for i in range(jac.shape[0]):
        for c in range(jac.shape[1]):
            js[i, c] = jac[i, c] * col[c]
    if blocks[1].shape[0] > 1:
        return block_svd(js, e, blocks, s, vt, g)
    u, sl, vl = np.linalg.svd(js, full_matrices=False)
    s[:] = sl
    vt[:, :] = vl
    for k in range(u.shape[1]):
        acc = 0.0
        for i in range(u.shape[0]):
            acc += u[i, k] * e[i]
        g[k] = acc
    return s[0]


@njit
def _trial(
    q: Array, dz: Array, frac: float, col: Array, dq: Array, tq: Array, te: Array, tj: Array, tables: tuple,
    rt: Array, pt: Array, scale: Array, work: tuple,
) -> tuple[float, float]:  # fmt: skip
    """The point ``integrate(q, D (frac dz))`` into ``tq`` with its residual (``te``, ``tj``), cost and ``max |e|``."""
    for c in range(dz.shape[0]):
        dq[c] = frac * dz[c] * col[c]
    integrate_kernel(q, dq, tables[1], tables[3], tables[4], tq)
    return _residual(tq, tables, rt, pt, scale, te, tj, work)
