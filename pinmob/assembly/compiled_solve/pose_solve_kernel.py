"""The single-sample solver's iterations at a platform pose, compiled (numba, the optional ``fast`` extra).

:func:`solve_pose` runs the iterations of :func:`pinmob.assembly.solver.solve` (that module's docstring: damped
steps by the SVD of the column-scaled Jacobian, Nielsen's damping, the trust region, the stall rule, then the
Gauss-Newton polish with its backtracking, and damped steps again where it stalls above ``tol``) on the residual of
:func:`pinmob.assembly.assemble.assemble_pose` for a mechanism without closures other than its limb tips: per frame
``f`` (the platform's and the tips on other bodies), ``log6(target^-1 oM_f)`` and ``Jlog6 J_f`` (the frame Jacobian
in its LOCAL axes), position rows divided by L. The kinematics are
:func:`~pinmob.model.kinematics_kernel.frames_kernel`'s, the moves
:func:`~pinmob.model.kinematics_kernel.integrate_kernel`'s (Pinocchio's ``integrate``), the rotation
vector :func:`~pinmob.assembly.batch_newton_kernel.log3`'s; ``log6`` and ``Jlog6`` are Pinocchio's formulas
(:func:`log6_jlog6`), their coefficients by their series below 0.1 rad. Round-off differs from the Python loop's
(Pinocchio's calls, numpy's LAPACK and BLAS), not the iterates' limits (``tests/test_pose_solve_kernel.py``).
Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np

from pinmob.assembly.batch_newton_kernel import log3
from pinmob.jit_cache import njit
from pinmob.model import frames_kernel, integrate_kernel
from pinmob.screw import Array

#: Below this angle [rad] the coefficients of log6 and Jlog6 are their series (the closed forms lose digits).
SERIES_BELOW = 0.1
#: The frame Jacobians' reference: Pinocchio's LOCAL (the code of :data:`pinmob.model.kinematics_kernel.LOCAL`).
LOCAL = 0


@njit
def log6_jlog6(r: Array, p: Array, e: Array, jlog: Array) -> None:
    """``log6`` of the placement (r, p) into ``e`` (6,) ([v; w]) and its ``Jlog6`` into ``jlog`` (6, 6).

    With w the rotation vector (angle t) and ``a = (t/2) cot(t/2)``, ``b = (1 - a) / t^2``,
    ``c = b'(t) / t``: ``v = a p - w x p / 2 + b (w.p) w``; ``Jlog6 = [J3, (C J3); 0, J3]`` with
    ``J3 = b w w^T + a I + [w]x / 2`` and ``C = (c (w.p) w - (t^2 c + 2 b) p) w^T + b w p^T + b (w.p) I + [p]x / 2``.
    """
    w = np.empty(3)
    log3(r, w)
    t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
    t = np.sqrt(t2)
    if t < SERIES_BELOW:  # b = 1/12 + t^2/720 + t^4/30240 + t^6/1209600 + ..., c = b' / t
        b = 1.0 / 12.0 + t2 * (1.0 / 720.0 + t2 * (1.0 / 30240.0 + t2 * (1.0 / 1209600.0 + t2 / 47900160.0)))
        c = 1.0 / 360.0 + t2 * (1.0 / 7560.0 + t2 * (1.0 / 201600.0 + t2 / 5987520.0))
    else:
        half = 0.5 * t
        sh = np.sin(half)
        b = 1.0 / t2 - np.cos(half) / (2.0 * t * sh)
        c = -2.0 / (t2 * t2) + (1.0 + np.sin(t) / t) / (t2 * 4.0 * sh * sh)
    a = 1.0 - t2 * b
    wp = w[0] * p[0] + w[1] * p[1] + w[2] * p[2]
    cross = np.empty(3)  # w x p
    cross[0], cross[1], cross[2] = w[1] * p[2] - w[2] * p[1], w[2] * p[0] - w[0] * p[2], w[0] * p[1] - w[1] * p[0]
    for i in range(3):
        e[i] = a * p[i] - 0.5 * cross[i] + b * wp * w[i]
        e[3 + i] = w[i]
    j3 = np.empty((3, 3))
    cm = np.empty((3, 3))
    k1, k2 = c * wp, t2 * c + 2.0 * b
    for i in range(3):
        v3 = k1 * w[i] - k2 * p[i]
        for j in range(3):
            j3[i, j] = b * w[i] * w[j]
            cm[i, j] = v3 * w[j] + b * w[i] * p[j]
        j3[i, i] += a
        cm[i, i] += wp * b
    _add_half_skew(w, j3)
    _add_half_skew(p, cm)
    for i in range(3):
        for j in range(3):
            jlog[i, j] = j3[i, j]
            jlog[3 + i, 3 + j] = j3[i, j]
            jlog[3 + i, j] = 0.0
            jlog[i, 3 + j] = cm[i, 0] * j3[0, j] + cm[i, 1] * j3[1, j] + cm[i, 2] * j3[2, j]


@njit
def _add_half_skew(v: Array, out: Array) -> None:
    """``out += [v]x / 2`` (the cross-product matrix of ``v``, halved)."""
    out[0, 1] -= 0.5 * v[2]
    out[0, 2] += 0.5 * v[1]
    out[1, 0] += 0.5 * v[2]
    out[1, 2] -= 0.5 * v[0]
    out[2, 0] -= 0.5 * v[1]
    out[2, 1] += 0.5 * v[0]


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
) -> tuple[Array, float, int, int]:
    """The solver's last configuration from ``q0``, its ``max |e|``, its damped and its Gauss-Newton iterations.

    ``tables``: :attr:`pinmob.model.compiled_kinematics.FrameKinematics.tables` of the residual's frames (every
    joint integrable); the target's rotation ``rt`` and position ``pt``; ``scale`` (6,) of each frame's rows;
    ``col`` (nv,) the column scales D. ``settings``: tol, max_iter, damping, max_step, floor (the polish's),
    stall window, and the solver's constants NEWTON_SWITCH, STALL_GAIN, RCOND, MAX_TRIALS, POLISH_STEPS, POLISH_GAIN.
    """
    tol, max_iter, damping, max_step, floor = settings[0], int(settings[1]), settings[2], settings[3], settings[4]
    window, switch, gain, rcond = int(settings[5]), settings[6], settings[7], settings[8]
    trials, polish_steps, polish_gain = int(settings[9]), int(settings[10]), settings[11]
    nf, nv, nq = tables[7].shape[0], col.shape[0], q0.shape[0]
    m = 6 * nf
    work = (np.empty((1, nf, 3, 3)), np.empty((1, nf, 3)), np.empty((1, nf, 6, nv)), np.empty((0, 6, nv)),
            np.empty((3, 3)), np.empty(3), np.empty(6), np.empty((6, 6)))  # fmt: skip
    q, e, jac = q0.copy(), np.empty(m), np.empty((m, nv))
    tq, te, tj = np.empty(nq), np.empty(m), np.empty((m, nv))  # a trial point
    bq, be, bj = np.empty(nq), np.empty(m), np.empty((m, nv))  # the polish's best trial
    cost, worst = _residual(q, tables, rt, pt, scale, e, jac, work)
    js = np.empty((m, nv))
    dz, dq, y, g = np.empty(nv), np.empty(nv), np.empty(nv), np.empty(nv)
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
                s, vt = _scaled_svd(jac, col, e, js, g)
                if s[0] == 0.0:
                    break
                s0 = s[0]
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
                s, vt = _scaled_svd(jac, col, e, js, g)
                if s[0] == 0.0:
                    break
                s0 = s[0]
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
def _scaled_svd(jac: Array, col: Array, e: Array, js: Array, g: Array) -> tuple[Array, Array]:
    """The scaled Jacobian ``J D`` into ``js``, its singular values and ``V^T``, and ``U^T e`` into ``g``."""
    for i in range(jac.shape[0]):
        for c in range(jac.shape[1]):
            js[i, c] = jac[i, c] * col[c]
    u, s, vt = np.linalg.svd(js, full_matrices=False)
    for k in range(u.shape[1]):
        acc = 0.0
        for i in range(u.shape[0]):
            acc += u[i, k] * e[i]
        g[k] = acc
    return s, vt


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
