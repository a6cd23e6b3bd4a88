"""The SVD of a block-diagonal Jacobian block by block: the compiled pose solve's factorisation.

At a platform pose each frame's residual (the platform's, a limb's tip) depends on the joints that carry it only:
the stacked Jacobian of :func:`pinmob.assembly.compiled_solve.pose_solve_kernel.solve_pose` is block-diagonal, a
block per group of frames that share joints (:func:`frame_blocks`; a limb each for the 3-PUU, the 6-UPS, the
3-RPS). Its SVD is the union of its blocks' SVDs, each by one-sided Jacobi rotations (:func:`block_svd`, by
:func:`pinmob.screw.span`): the same singular values and vectors, round-off aside, at a fraction of the cost of
LAPACK's call on the whole matrix, which a few microseconds of small-matrix work cannot amortise (35 to 45 us
for the 3-PUU's 18 x 15 on this project's benchmark machine). Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from pinmob.jit_cache import njit
from pinmob.screw import Array, span

#: Integer arrays (row and column indices, and where each block's start).
Ints = NDArray[np.int64]


def frame_blocks(model: pin.Model, frames: list[int]) -> tuple[Ints, Ints, Ints, Ints]:
    """The diagonal blocks of the frames' stacked Jacobians (6 rows a frame, ``model.nv`` columns).

    Frames whose supports (the joints from the world to the frame) share a joint are one block. Returns
    ``rows, rows_at, cols, cols_at``: block b's rows are ``rows[rows_at[b]:rows_at[b + 1]]``, its columns
    alike, each sorted; a column no frame depends on is in no block. No block (``rows_at == [0]``) when the
    frames make one block only: the whole matrix is then factorised at once.
    """
    groups: list[tuple[list[int], set[int]]] = []  # (frame positions, columns)
    for i, f in enumerate(frames):
        joints = [model.joints[j] for j in model.supports[model.frames[f].parentJoint] if j > 0]
        columns = {c for joint in joints for c in range(joint.idx_v, joint.idx_v + joint.nv)}
        members = [i]
        for k in [k for k, (_, cols) in enumerate(groups) if cols & columns][::-1]:  # joined by a shared joint
            members += groups[k][0]
            columns |= groups.pop(k)[1]
        groups.append((members, columns))
    groups = [g for g in groups if g[1]]  # frames fixed to the world: rows of zeros, no singular value
    if len(groups) < 2:
        empty = np.zeros(0, np.int64)
        return empty, np.zeros(1, np.int64), empty, np.zeros(1, np.int64)
    rows = [[6 * i + r for i in sorted(members) for r in range(6)] for members, _ in groups]
    cols = [sorted(columns) for _, columns in groups]
    return (
        np.array([r for block in rows for r in block], np.int64),
        np.cumsum([0] + [len(block) for block in rows]).astype(np.int64),
        np.array([c for block in cols for c in block], np.int64),
        np.cumsum([0] + [len(block) for block in cols]).astype(np.int64),
    )


@njit
def block_svd(js: Array, e: Array, blocks: tuple, s: Array, vt: Array, g: Array) -> float:
    """The SVD of the block-diagonal ``js`` (m, nv) by its ``blocks`` (:func:`frame_blocks`); its largest value.

    Into ``s`` (K,) the singular values (K: the blocks' columns, in block order, each block's descending),
    ``vt`` (K, nv) the right singular vectors as rows (zero off their block's columns), ``g`` (K,) ``U^T e``.
    """
    rows, rows_at, cols, cols_at = blocks
    vt[:, :] = 0.0
    k, top = 0, 0.0
    for b in range(rows_at.shape[0] - 1):
        r0, nr = rows_at[b], rows_at[b + 1] - rows_at[b]
        c0, p = cols_at[b], cols_at[b + 1] - cols_at[b]
        a, v, sv = np.empty((nr, p)), np.empty((p, p)), np.empty(p)
        for i in range(nr):
            for c in range(p):
                a[i, c] = js[rows[r0 + i], cols[c0 + c]]
        span(a, nr, 0.0, sv, v)  # a: U diag(sv)
        for j in range(p):
            s[k] = sv[j]
            top = max(top, sv[j])
            acc = 0.0
            for i in range(nr):
                acc += a[i, j] * e[rows[r0 + i]]
            g[k] = acc / sv[j] if sv[j] > 0.0 else 0.0
            for c in range(p):
                vt[k, cols[c0 + c]] = v[c, j]
            k += 1
    return top
