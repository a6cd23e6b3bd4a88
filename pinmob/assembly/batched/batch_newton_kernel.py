"""The compiled linear algebra of :mod:`pinmob.assembly.batched.batch_solver` (numba, the optional ``fast`` extra).

The same errors, Jacobians and damped steps as that module's numpy path (its docstring), one sample at a time in
a compiled loop over the stack: :func:`pose_errors` (each frame's position and ``log3`` rotation error, and the
sample's ``max |e|``) and :func:`damped_steps` (the Jacobian per dimensionless rate, the damped normal equations
solved by Gaussian elimination with partial pivoting, the step capped) and the stopping rule
(:func:`advance`). Round-off differs from numpy's LAPACK
calls, not the iterates' limits (``tests/test_scan_batch.py`` runs both). Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pinmob.assembly.batched.batch_stopping import advance as plain_advance
from pinmob.jit_cache import njit
from pinmob.model import frames_kernel, integrate_kernel
from pinmob.screw import Array, Mask

#: Integer arrays (frame and column indices, counts).
Ints = NDArray[np.int64]

#: :func:`pinmob.assembly.batched.batch_stopping.advance`, compiled.
advance = njit(plain_advance)


@njit
def log3(r: Array, out: Array) -> None:
    """Rotation vector of the 3 x 3 rotation ``r`` into ``out``, right up to pi: by its unit quaternion.

    The quaternion by Shepperd's rule (from the largest of its four components, as Eigen's), then ``2 atan2(|v|,
    |w|)`` along ``v``, Pinocchio's ``log3`` (the angle from ``acos`` of the trace, or the axis from the
    antisymmetric part alone, lose digits near pi).
    """
    tr = r[0, 0] + r[1, 1] + r[2, 2]
    if tr > 0.0:
        s = 2.0 * np.sqrt(tr + 1.0)
        w, x, y, z = 0.25 * s, (r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s
    elif r[0, 0] >= r[1, 1] and r[0, 0] >= r[2, 2]:
        s = 2.0 * np.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2])
        w, x, y, z = (r[2, 1] - r[1, 2]) / s, 0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s
    elif r[1, 1] >= r[2, 2]:
        s = 2.0 * np.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2])
        w, x, y, z = (r[0, 2] - r[2, 0]) / s, (r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s
    else:
        s = 2.0 * np.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1])
        w, x, y, z = (r[1, 0] - r[0, 1]) / s, (r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s
    if w < 0.0:
        w, x, y, z = -w, -x, -y, -z
    n2 = x * x + y * y + z * z
    if n2 < 1e-16:  # 2 atan(n / w) / n to round-off
        k = 2.0 / w * (1.0 - n2 / (3.0 * w * w))
    else:
        n = np.sqrt(n2)
        k = 2.0 * np.arctan2(n, w) / n
    out[0], out[1], out[2] = k * x, k * y, k * z


@njit
def rpy_matrix(rpy: Array, out: Array) -> None:
    """``Rz(yaw) Ry(pitch) Rx(roll)`` (Pinocchio's rpy) of ``rpy`` (3,) into ``out`` (3, 3)."""
    cr, cp, cy = np.cos(rpy[0]), np.cos(rpy[1]), np.cos(rpy[2])
    sr, sp, sy = np.sin(rpy[0]), np.sin(rpy[1]), np.sin(rpy[2])
    out[0, 0], out[0, 1], out[0, 2] = cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr
    out[1, 0], out[1, 1], out[1, 2] = sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr
    out[2, 0], out[2, 1], out[2, 2] = -sp, cp * sr, cp * cr


@njit
def pose_errors(frames: Array, poses: Array, length: float) -> tuple[Array, Array]:
    """(B, 6F) dimensionless errors ``[(p_f - p*) / L; log3(R_f R*^T)]`` and (B,) ``max |e|`` (the larger norm).

    ``frames``: (B, F, 4, 4) homogeneous placements of the frames; ``poses``: (B, 6) targets.
    """
    n, nf = frames.shape[0], frames.shape[1]
    e = np.empty((n, 6 * nf))
    worst = np.empty(n)
    target = np.empty((3, 3))
    rel = np.empty((3, 3))
    w = np.empty(3)
    for b in range(n):
        rpy_matrix(poses[b, 3:], target)
        big = 0.0
        for f in range(nf):
            m = frames[b, f]
            pos = 0.0
            for i in range(3):
                d = (m[i, 3] - poses[b, i]) / length
                e[b, 6 * f + i] = d
                pos += d * d
            for i in range(3):  # R_f R*^T
                for j in range(3):
                    rel[i, j] = m[i, 0] * target[j, 0] + m[i, 1] * target[j, 1] + m[i, 2] * target[j, 2]
            log3(rel, w)
            rot = 0.0
            for i in range(3):
                e[b, 6 * f + 3 + i] = w[i]
                rot += w[i] * w[i]
            big = max(big, pos, rot)
        worst[b] = np.sqrt(big)
    return e, worst


@njit
def damped_steps(
    full: Array,
    frames: Array,
    poses: Array,
    e: Array,
    which: Array,
    mask: Array,
    col: Array,
    free: Array,
    length: float,
    damping: float,
    max_step: float,
    structure: tuple[Ints, Ints, Ints, Ints],
) -> Array:
    """(len(which), nv + free) capped Levenberg-Marquardt steps of the samples ``which`` (module docstring).

    ``full`` (B, 6, nv) world Jacobians, ``frames`` (B, F, 4, 4), ``poses`` (B, 6), ``e`` (B, 6F) their errors;
    ``mask`` (F, nv) the joints supporting each frame, ``col`` (nv + free,) the dimensionless column scaling,
    ``free`` the pose coordinates (0-5) that are unknowns, ``structure`` :func:`step_structure` of ``mask`` (made
    once per solve). The zeros the structure gives are skipped, not
    summed: a frame's rows in the columns that do not support it (``mask``), the pairs of columns no frame has
    both of, the rows whose entry below a pivot is zero, and each row of the elimination
    past its last non-zero column (the limbs' blocks of a mechanism without free coordinates), so the arithmetic
    on the other entries, and the steps, are those of the dense loops to the last bit, at a fraction of their
    cost (the 6-UPS: six 6 x 6 blocks of a 36 x 36 system).
    """
    nf, nv, nfree = frames.shape[1], full.shape[2], free.size
    m = nv + nfree
    out = np.empty((which.size, m))
    jac = np.empty((6 * nf, m))
    a = np.empty((m, m))
    g = np.empty(m)
    last = np.empty(m, np.int64)
    held, held_count, pairs, pair_count = structure
    for s in range(which.size):
        b = which[s]
        jac[:] = 0.0
        cy, sy = np.cos(poses[b, 5]), np.sin(poses[b, 5])
        cp, sp = np.cos(poses[b, 4]), np.sin(poses[b, 4])
        for f in range(nf):
            px, py, pz = frames[b, f, 0, 3], frames[b, f, 1, 3], frames[b, f, 2, 3]
            r = 6 * f
            for j in range(nv):
                if mask[f, j] == 0.0:
                    continue
                wx, wy, wz = full[b, 3, j], full[b, 4, j], full[b, 5, j]
                jac[r, j] = (full[b, 0, j] - (py * wz - pz * wy)) / length * col[j]
                jac[r + 1, j] = (full[b, 1, j] - (pz * wx - px * wz)) / length * col[j]
                jac[r + 2, j] = (full[b, 2, j] - (px * wy - py * wx)) / length * col[j]
                jac[r + 3, j], jac[r + 4, j], jac[r + 5, j] = wx * col[j], wy * col[j], wz * col[j]
            for c in range(nfree):
                k = free[c]
                if k < 3:
                    jac[r + k, nv + c] = -col[nv + c] / length
                elif k == 3:  # world angular velocity per roll rate: (cy cp, sy cp, -sp)
                    jac[r + 3, nv + c], jac[r + 4, nv + c], jac[r + 5, nv + c] = -cy * cp, -sy * cp, sp
                elif k == 4:  # per pitch rate: (-sy, cy, 0)
                    jac[r + 3, nv + c], jac[r + 4, nv + c] = sy, -cy
                else:  # per yaw rate: (0, 0, 1)
                    jac[r + 5, nv + c] = -1.0
        trace = 0.0
        a[:, :] = 0.0  # the pairs of columns no frame has both of: exact zeros
        for i in range(m):  # a frame's rows are zero in the columns that do not support it: skipped (exactly)
            gi = 0.0
            for t in range(held_count[i]):
                f = held[i, t]
                for r in range(6 * f, 6 * f + 6):
                    gi += jac[r, i] * e[b, r]
            g[i] = -gi
            for u in range(pair_count[i]):
                j = pairs[i, u]
                acc = 0.0
                for t in range(held_count[i]):  # the frames of both columns, in order
                    f = held[i, t]
                    if j < nv and mask[f, j] == 0.0:
                        continue
                    for r in range(6 * f, 6 * f + 6):
                        acc += jac[r, i] * jac[r, j]
                a[i, j] = acc
                a[j, i] = acc
            trace += a[i, i]
        mu = damping / m * trace
        for i in range(m):
            a[i, i] += mu
        for i in range(m):  # each row's last non-zero column: the elimination and the substitution stop there
            last[i] = i
            for j in range(m - 1, i, -1):
                if a[i, j] != 0.0:
                    last[i] = j
                    break
        for k in range(m):  # Gaussian elimination with partial pivoting on [a | g]
            p = k
            for i in range(k + 1, m):
                if abs(a[i, k]) > abs(a[p, k]):
                    p = i
            if p != k:
                for j in range(k, m):
                    a[k, j], a[p, j] = a[p, j], a[k, j]
                g[k], g[p] = g[p], g[k]
                last[k], last[p] = last[p], last[k]
            pivot = a[k, k]
            for i in range(k + 1, m):
                if a[i, k] == 0.0 and pivot == pivot:  # a factor of zero (the other blocks' rows; not a NaN pivot's)
                    continue
                factor = a[i, k] / pivot
                if factor != 0.0:
                    for j in range(k + 1, last[k] + 1):
                        a[i, j] -= factor * a[k, j]
                    g[i] -= factor * g[k]
                    last[i] = max(last[i], last[k])
        biggest = 0.0
        for i in range(m - 1, -1, -1):
            acc = g[i]
            for j in range(i + 1, last[i] + 1):
                acc -= a[i, j] * out[s, j]
            out[s, i] = acc / a[i, i]
            biggest = max(biggest, abs(out[s, i]))
        scale = min(1.0, max_step / biggest) if biggest > 0.0 else 1.0
        for i in range(m):
            out[s, i] *= scale
    return out


@njit
def step_structure(mask: Array, nv: int, nfree: int) -> tuple[Ints, Ints, Ints, Ints]:
    """:func:`damped_steps`' sparsity, the same for every sample: each column's frames and partner columns.

    Column i's frames are those whose rows it has; its partners, the columns ``j >= i`` that share one. ``mask``
    (F, nv): the joints supporting each frame; a free pose coordinate's column (``nv ..``) is in every frame's rows.
    Returns ``held`` (m, F) and ``held_count`` (m,): column i's frames ``held[i, :held_count[i]]``, in order;
    ``pairs`` (m, m) and ``pair_count`` (m,): its partners ``pairs[i, :pair_count[i]]``, in order.
    """
    nf, m = mask.shape[0], nv + nfree
    held, held_count = np.empty((m, nf), np.int64), np.zeros(m, np.int64)
    for i in range(m):
        for f in range(nf):
            if i >= nv or mask[f, i] != 0.0:
                held[i, held_count[i]] = f
                held_count[i] += 1
    pairs, pair_count = np.empty((m, m), np.int64), np.zeros(m, np.int64)
    for i in range(m):
        for j in range(i, m):
            for t in range(held_count[i]):
                if j >= nv or mask[held[i, t], j] != 0.0:
                    pairs[i, pair_count[i]] = j
                    pair_count[i] += 1
                    break
    return held, held_count, pairs, pair_count


@njit
def iterate(
    full: Array,
    frames: Array,
    q: Array,
    p: Array,
    active: Array,
    it: int,
    best: Array,
    best_q: Array,
    best_p: Array,
    history: Array,
    mask: Array,
    col: Array,
    free: Array,
    length: float,
    numbers: Array,
    stall_window: int,
    last: bool,
    vector_space: bool,
    structure: tuple[Ints, Ints, Ints, Ints],
) -> tuple[Array, Array]:
    """One iteration of :func:`pinmob.assembly.batched.batch_solver.solve_poses` on the samples ``active``, in place.

    From the kinematics at ``q[active]`` (``full``, ``frames``): the errors (:func:`pose_errors`), the stopping
    rule (:func:`advance`, which updates ``best`` and ``history``), the best iterates kept (``best_q``,
    ``best_p``) and, for the samples that go on (none when ``last``), the damped steps (:func:`damped_steps`),
    applied to ``q`` and ``p`` when ``vector_space`` (``q + dq``; else the caller integrates them). ``numbers``:
    damping, maximum step, tol, floor, stall gain, polish gain and divergence factor. ``structure``:
    :func:`step_structure` of ``mask``.

    Returns:
        the samples that go on, and their (dimensionless) steps.
    """
    damping, max_step, tol, floor = numbers[0], numbers[1], numbers[2], numbers[3]
    here = p[active]
    e, now = pose_errors(frames, here, length)
    better, keep = advance(now, active, it, best, history, tol, floor, stall_window, numbers[4], numbers[5], numbers[6])
    for s in range(active.size):
        if better[s]:
            best_q[active[s]] = q[active[s]]
            best_p[active[s]] = here[s]
    which = np.flatnonzero(keep)
    if last or which.size == 0:
        return active[:0], np.zeros((0, col.size))
    steps = damped_steps(full, frames, here, e, which, mask, col, free, length, damping, max_step, structure)
    going = active[which]
    nv = full.shape[2]
    if vector_space:
        for s in range(going.size):
            b = going[s]
            for j in range(nv):
                q[b, j] += steps[s, j] * col[j]
            for c in range(free.size):
                p[b, free[c]] += steps[s, nv + c] * col[nv + c]
    return going, steps


@njit
def solve_stack(
    q: Array,
    p: Array,
    tables: tuple[Ints, Ints, Array, Ints, Ints, Array, Array, Ints, Array, Array],
    mask: Array,
    col: Array,
    free: Array,
    length: float,
    numbers: Array,
    stall_window: int,
    max_iter: int,
    vector_space: bool,
    best: Array,
    best_q: Array,
    best_p: Array,
    history: Array,
    best_full: Array,
    best_frames: Array,
) -> None:
    """Every iteration of :func:`pinmob.assembly.batched.batch_solver.solve_poses` in one compiled call, in place.

    Per iteration, as the Python loop around :func:`iterate` does: the kinematics of the samples still going
    (:func:`pinmob.model.frames_kernel` on the model's ``tables``, :attr:`pinmob.model.FrameKinematics.tables`: the
    world joint Jacobians and the frames' placements), :func:`iterate`, the kinematics of each sample's best iterate kept
    (``best_full``, ``best_frames``) and, off a vector space, the steps applied by
    :func:`pinmob.model.integrate_kernel` (Pinocchio's ``integrate``). The tables' joint kinds must all be
    integrable there (:attr:`pinmob.model.FrameKinematics.integrable`).
    """
    parent, kind, axis, iq, iv, rot0, pos0, f_parent, f_rot, f_pos = tables
    n, nq, nf, nv = q.shape[0], q.shape[1], f_parent.shape[0], best_full.shape[2]
    active = np.arange(n)
    no_jacobians = np.empty((0, 0, 6, nv))
    moved = np.empty(nq)
    dq = np.empty(nv)
    structure = step_structure(mask, nv, free.size)  # the same for every iteration
    for it in range(max_iter + 1):
        m = active.size
        qa = np.empty((m, nq))
        before = np.empty(m)
        for s in range(m):
            qa[s] = q[active[s]]
            before[s] = best[active[s]]
        full, rot, pos = np.empty((m, 6, nv)), np.empty((m, nf, 3, 3)), np.empty((m, nf, 3))
        frames_kernel(qa, parent, kind, axis, iq, iv, rot0, pos0, f_parent, f_rot, f_pos, 0, False, rot, pos,
                      no_jacobians, full)  # fmt: skip
        frames = np.zeros((m, nf, 4, 4))
        for s in range(m):
            for f in range(nf):
                for i in range(3):
                    for j in range(3):
                        frames[s, f, i, j] = rot[s, f, i, j]
                    frames[s, f, i, 3] = pos[s, f, i]
                frames[s, f, 3, 3] = 1.0
        going, steps = iterate(full, frames, q, p, active, it, best, best_q, best_p, history, mask, col, free, length,
                               numbers, stall_window, it == max_iter, vector_space, structure)  # fmt: skip
        for s in range(m):
            if best[active[s]] < before[s]:  # the kernel's rule (batch_stopping.advance): strictly smaller
                best_full[active[s]] = full[s]
                best_frames[active[s]] = frames[s]
        if going.size == 0:
            break
        if not vector_space:
            for s in range(going.size):
                b = going[s]
                for j in range(nv):
                    dq[j] = steps[s, j] * col[j]
                integrate_kernel(q[b], dq, kind, iq, iv, moved)
                q[b] = moved
                for c in range(free.size):
                    p[b, free[c]] += steps[s, nv + c] * col[nv + c]
        active = going


@njit
def wrap_and_check(
    out: Array, angles: NDArray[np.intp], lower: Array, upper: Array, limited: Mask
) -> tuple[Mask, Mask]:
    """:meth:`pinmob.assembly.batched.batch_solver.PoseProblem.finish`'s arithmetic, in place on (N, nq) ``out``.

    Each angle (indices ``angles``) moved into (-pi, pi]; per row, whether a wrapped angle is outside its limits
    (the caller wraps that row by :func:`~pinmob.model.joints.wrap_angles` instead) and whether any coordinate is
    outside its limits by more than 1e-9 (the caller warns).
    """
    n = out.shape[0]
    special, outside = np.zeros(n, np.bool_), np.zeros(n, np.bool_)
    for i in range(n):
        for k in angles:
            x = np.pi - np.mod(np.pi - out[i, k], 2 * np.pi)
            out[i, k] = x
            if limited[k] and (x < lower[k] or x > upper[k]):
                special[i] = True
        for c in range(out.shape[1]):
            if limited[c] and (out[i, c] < lower[c] - 1e-9 or out[i, c] > upper[c] + 1e-9):
                outside[i] = True
    return special, outside
