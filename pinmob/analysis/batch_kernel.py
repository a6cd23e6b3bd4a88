"""The compiled loop behind :func:`pinmob.analysis.batch.analyze_batch`: ranks of N configurations at once.

Pivoted Gram-Schmidt on 6-row matrices, compiled with numba (cached by :mod:`pinmob.jit_cache`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pinmob.jit_cache import njit
from pinmob.screw.algebra import Array

#: Integer array (ranks, DoF).
Ints = NDArray[np.int64]


@njit
def span(a: Array, cols: Ints, tol: float, r: Array, q: Array, first: int) -> int:
    """Orthonormal basis of the span of the columns ``cols`` of a (6, m) matrix; returns the rank.

    Gram-Schmidt with column pivoting on a copy ``r`` (6, len(cols)): at each of
    at most six steps the remaining column of largest norm is normalised into
    ``q[:, first + rank]`` and projected out of the others; the steps stop when
    the largest remaining norm is at most ``tol``. This is the rank-revealing QR
    decision, which agrees with the SVD's ``sigma_k > tol`` except within a
    factor ``sqrt(m)`` of the threshold.
    """
    m = cols.size
    for c in range(m):
        for i in range(6):
            r[i, c] = a[i, cols[c]]
    rank = 0
    for _ in range(min(6, m)):
        best, j = 0.0, -1
        for c in range(m):
            norm = 0.0
            for i in range(6):
                norm += r[i, c] * r[i, c]
            if norm > best:
                best, j = norm, c
        best = np.sqrt(best)
        if j < 0 or best <= tol:
            break
        col = first + rank
        for i in range(6):
            q[i, col] = r[i, j] / best
        for c in range(m):
            dot = 0.0
            for i in range(6):
                dot += q[i, col] * r[i, c]
            for i in range(6):
                r[i, c] -= dot * q[i, col]
        rank += 1
    return rank


@njit
def complement(q: Array, rank: int, proj: Array, r: Array, out: Array, first: int) -> int:
    """Orthonormal basis of the complement of ``span(q[:, :rank])``, written to ``out[:, first:]``; returns 6 - rank.

    The wrenches reciprocal to the twists Q: pivoted Gram-Schmidt on the
    columns of the projector ``I - Q Q^T`` (6, 6), whose rank is 6 - rank. The
    column norms of a projector of rank p sum to p, so while vectors are left
    the largest norm is at least ``sqrt(1/6)``; 0.1 separates them from round-off.
    """
    for i in range(6):
        for j in range(6):
            dot = 0.0
            for k in range(rank):
                dot += q[i, k] * q[j, k]
            proj[i, j] = (1.0 if i == j else 0.0) - dot
    return span(proj, np.arange(6), 0.1, r, out, first)


@njit
def ranks(
    full: Array,
    origin: Array,
    length: float,
    columns: Ints,
    offsets: Ints,
    free: Ints,
    free_offsets: Ints,
    rtol: float,
) -> tuple[Ints, Ints, Ints]:
    """Limb twist ranks, constraint rank and locked constraint rank of N configurations.

    Per configuration, the limbs' joint screws are carried to the platform origin
    p and made dimensionless, ``[(v + w x p) / L; w]``; each limb's span and its
    orthonormal complement (the limb's wrenches) are found by :func:`span` and
    :func:`complement`; the stacked wrenches (orthonormal per limb) are ranked.

    Args:
        full: (N, 6, nv) world Jacobians (:func:`world_jacobians`).
        origin: (N, 3) platform origins [m].
        length: length scale L [m].
        columns: (m,) velocity indices of every limb's joints, limb i's at
            ``columns[offsets[i]:offsets[i + 1]]``.
        offsets: (k + 1,) offsets of the limbs in ``columns``.
        free: positions in ``columns`` of the joints that are not actuated, limb i's at
            ``free[free_offsets[i]:free_offsets[i + 1]]``.
        free_offsets: (k + 1,) offsets into ``free``.
        rtol: a limb's columns count while above ``rtol`` times its largest
            column norm; the stacked unit wrenches while above ``rtol``.

    Returns:
        (N, k) limb twist ranks, (N,) constraint ranks, (N,) locked constraint ranks.
    """
    n, k, m = full.shape[0], offsets.size - 1, columns.size
    limb_rank = np.zeros((n, k), np.int64)
    rank = np.zeros(n, np.int64)
    locked_rank = np.zeros(n, np.int64)
    a = np.zeros((6, m))
    q = np.zeros((6, 6))
    proj = np.zeros((6, 6))
    r = np.zeros((6, max(m, 6 * k)))
    wrenches = np.zeros((6, 6 * k))
    locked_wrenches = np.zeros((6, 6 * k))
    every = np.arange(max(m, 6 * k))
    for s in range(n):
        px, py, pz = origin[s, 0], origin[s, 1], origin[s, 2]
        for c in range(m):
            j = columns[c]
            wx, wy, wz = full[s, 3, j], full[s, 4, j], full[s, 5, j]
            a[0, c] = (full[s, 0, j] + wy * pz - wz * py) / length
            a[1, c] = (full[s, 1, j] + wz * px - wx * pz) / length
            a[2, c] = (full[s, 2, j] + wx * py - wy * px) / length
            a[3, c], a[4, c], a[5, c] = wx, wy, wz
        used = locked_used = 0
        for i in range(k):
            cols = every[offsets[i] : offsets[i + 1]]
            largest = 0.0
            for c in cols:
                norm = 0.0
                for row in range(6):
                    norm += a[row, c] * a[row, c]
                largest = max(largest, np.sqrt(norm))
            tol = rtol * largest
            twist_rank = span(a, cols, tol, r, q, 0) if largest > 0 else 0
            limb_rank[s, i] = twist_rank
            used += complement(q, twist_rank, proj, r, wrenches, used)
            kept = free[free_offsets[i] : free_offsets[i + 1]]
            if kept.size < cols.size:
                twist_rank = span(a, kept, tol, r, q, 0) if largest > 0 else 0
            locked_used += complement(q, twist_rank, proj, r, locked_wrenches, locked_used)
        rank[s] = span(wrenches, every[:used], rtol, r, q, 0)
        locked_rank[s] = span(locked_wrenches, every[:locked_used], rtol, r, q, 0)
    return limb_rank, rank, locked_rank
