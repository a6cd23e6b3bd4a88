"""The compiled loop behind :func:`pinmob.analysis.batch.batch_analysis.analyze_batch` (numba, the optional ``fast`` extra).

Per configuration, the same matrices and the same rank rule as
:func:`pinmob.analyze` (:func:`pinmob.screw.rank.rank_rule`: singular values above
``rtol`` times the largest count), with the singular values and right singular
vectors of each small matrix from a one-sided Jacobi SVD (:func:`span`)
instead of LAPACK's: the same numbers to round-off (the tests compare them with
the numpy path, which calls LAPACK). Importing this module imports numba; the
compiled code is cached by :mod:`pinmob.jit_cache` (outside the installed package).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pinmob.jit_cache import njit
from pinmob.screw.algebra import Array

#: Integer array (ranks, DoF).
Ints = NDArray[np.int64]

#: Columns count as orthogonal when ``|g_j . g_l| <= ORTHOGONAL * rows * |g_j| |g_l|`` (round-off of the dot product).
ORTHOGONAL = 2.0**-52


@njit
def span(g: Array, rows: int, rtol: float, sv: Array, v: Array) -> int:
    """Rank of ``g[:rows]`` (rows, p) by a one-sided Jacobi SVD, in place: singular values ``sv`` (p,), vectors ``v``.

    Plane rotations of pairs of columns (Hestenes) until every pair is
    orthogonal to round-off: ``g V = U diag(sv)``; ``sv`` sorted descending, the
    columns of ``v`` (the right singular vectors) sorted alike: the first ``rank``
    span the row space, the others its complement. Columns shorter than
    round-off of the whole matrix are zero and left alone. ``g`` is overwritten.
    The rank is :func:`pinmob.screw.rank.rank_rule`'s: the singular values above
    ``rtol`` times the largest (0 when they are all zero).
    """
    p = g.shape[1]
    for i in range(p):
        for j in range(p):
            v[i, j] = 1.0 if i == j else 0.0
    total = 0.0
    for i in range(rows):
        for j in range(p):
            total += g[i, j] * g[i, j]
    negligible = (ORTHOGONAL * ORTHOGONAL) * total  # a column this short is zero to round-off: not rotated
    for _ in range(60):
        rotated = False
        for j in range(p - 1):
            for k in range(j + 1, p):
                alpha = beta = gamma = 0.0
                for i in range(rows):
                    alpha += g[i, j] * g[i, j]
                    beta += g[i, k] * g[i, k]
                    gamma += g[i, j] * g[i, k]
                if gamma == 0.0 or min(alpha, beta) <= negligible:
                    continue
                if abs(gamma) <= ORTHOGONAL * max(rows, 1) * np.sqrt(alpha * beta):
                    continue
                zeta = (beta - alpha) / (2.0 * gamma)
                if abs(zeta) > 1e150:
                    t = 0.5 / zeta
                else:
                    t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
                c = 1.0 / np.sqrt(1.0 + t * t)
                s = c * t
                if s == 0.0:
                    continue
                rotated = True
                for i in range(rows):
                    a, b = g[i, j], g[i, k]
                    g[i, j], g[i, k] = c * a - s * b, s * a + c * b
                for i in range(p):
                    a, b = v[i, j], v[i, k]
                    v[i, j], v[i, k] = c * a - s * b, s * a + c * b
        if not rotated:
            break
    for j in range(p):
        norm = 0.0
        for i in range(rows):
            norm += g[i, j] * g[i, j]
        sv[j] = np.sqrt(norm)
    for j in range(1, p):  # insertion sort, descending, columns of v alike
        k = j
        while k > 0 and sv[k - 1] < sv[k]:
            sv[k - 1], sv[k] = sv[k], sv[k - 1]
            for i in range(p):
                v[i, k - 1], v[i, k] = v[i, k], v[i, k - 1]
            k -= 1
    if rows == 0 or sv[0] <= 0.0:
        return 0
    rank = 0
    for x in sv:
        if x > rtol * sv[0]:
            rank += 1
    return rank


@njit
def complement(
    a: Array, cols: Ints, unit: bool, rtol: float, g: Array, sv: Array, v: Array, out: Array, first: int
) -> tuple[int, int]:
    """The complement of the span of ``a[:, cols]`` (6, n) (its columns unit length when ``unit``), as rows of ``out``.

    The null space of ``M = a[:, cols]^T`` (:func:`span`), written to ``out[first:]``: the wrenches reciprocal
    to those screws.

    Returns:
        M's rank and the number of rows written (6 - rank).
    """
    n = cols.size
    for r in range(n):
        norm = 0.0
        for i in range(6):
            norm += a[i, cols[r]] * a[i, cols[r]]
        scale = 1.0 / np.sqrt(norm) if unit and norm > 0.0 else 1.0
        for i in range(6):
            g[r, i] = a[i, cols[r]] * scale
    rank = span(g, n, rtol, sv, v)
    for k in range(rank, 6):
        for i in range(6):
            out[first + k - rank, i] = v[i, k]
    return rank, 6 - rank


@njit
def ranks(
    full: Array,
    origin: Array,
    length: float,
    columns: Ints,
    offsets: Ints,
    free: Ints,
    free_offsets: Ints,
    actuated: NDArray[np.bool_],
    generic: Ints,
    rtol: float,
    ratios: bool,
) -> tuple[Ints, Ints, Ints, Array, Array, Array, Array]:
    """Limb twist ranks, constraint ranks, locked ranks, their singular values, the limb ratios and the free twists.

    Per configuration, the limbs' joint screws are carried to the platform origin
    p and made dimensionless, ``[(v + w x p) / L; w]``; per limb, the null space of
    its transposed screws (the limb's wrenches; with unit rows for an unactuated
    limb's locked wrenches and the limb ratios, as the singularity report does)
    and, for an actuated limb, of its unactuated screws; the stacked wrenches
    and locked wrenches are ranked (:func:`span`, :func:`complement`).

    Args:
        full: (N, 6, nv) world Jacobians.
        origin: (N, 3) platform origins [m].
        length: length scale L [m].
        columns: (m,) velocity indices of every limb's joints, limb i's at
            ``columns[offsets[i]:offsets[i + 1]]``.
        offsets: (k + 1,) offsets of the limbs in ``columns``.
        free: positions in ``columns`` of the joints that are not actuated, limb i's at
            ``free[free_offsets[i]:free_offsets[i + 1]]``.
        free_offsets: (k + 1,) offsets into ``free``.
        actuated: (k,) the limb has actuated joints.
        generic: (k,) each limb's generic twist rank (for the limb ratios).
        rtol: relative tolerance of every rank decision.
        ratios: compute the limb ratios (else they are left 0).

    Returns:
        (N, k) limb twist ranks, (N,) constraint ranks, (N,) locked ranks, (N, 6) singular values of the
        stacked wrenches and of the stacked locked wrenches, (N, k) limb ratios ``sigma_g / sigma_1``, and (N, 6, 6)
        an orthonormal basis of the null space of the stacked wrenches (the platform's free dimensionless twists)
        in the first ``6 - rank`` columns, NaN in the others (its right singular vectors beyond the rank).
    """
    n, k, m = full.shape[0], offsets.size - 1, columns.size
    limb_rank = np.zeros((n, k), np.int64)
    rank = np.zeros(n, np.int64)
    locked_rank = np.zeros(n, np.int64)
    sv_out, asv_out = np.zeros((n, 6)), np.zeros((n, 6))
    ratio = np.zeros((n, k))
    free_twists = np.full((n, 6, 6), np.nan)
    a = np.zeros((6, m))
    rows = max(6 * k, max(m, 6))
    g = np.zeros((rows, 6))
    sv = np.zeros(6)
    v = np.zeros((6, 6))
    wrenches = np.zeros((6 * k, 6))
    locked = np.zeros((6 * k, 6))
    scratch = np.zeros((6, 6))
    every = np.arange(m)
    for s in range(n):
        px, py, pz = origin[s, 0], origin[s, 1], origin[s, 2]
        for c in range(m):
            j = columns[c]
            wx, wy, wz = full[s, 3, j], full[s, 4, j], full[s, 5, j]
            a[0, c] = (full[s, 0, j] + (wy * pz - wz * py)) / length
            a[1, c] = (full[s, 1, j] + (wz * px - wx * pz)) / length
            a[2, c] = (full[s, 2, j] + (wx * py - wy * px)) / length
            a[3, c], a[4, c], a[5, c] = wx, wy, wz
        used = locked_used = 0
        for i in range(k):
            cols = every[offsets[i] : offsets[i + 1]]
            r, added = complement(a, cols, False, rtol, g, sv, v, wrenches, used)
            limb_rank[s, i] = r
            used += added
            if actuated[i]:
                kept = free[free_offsets[i] : free_offsets[i + 1]]
                _, added = complement(a, kept, False, rtol, g, sv, v, locked, locked_used)
            else:
                _, added = complement(a, cols, True, rtol, g, sv, v, locked, locked_used)
            locked_used += added
            if ratios:  # sigma_g / sigma_1 of the limb's screws with unit rows
                complement(a, cols, True, rtol, g, sv, v, scratch, 0)
                ratio[s, i] = 1.0 if generic[i] <= 0 else (sv[generic[i] - 1] / sv[0] if sv[0] > 0.0 else 0.0)
        rank[s] = span(wrenches, used, rtol, sv, v)  # the stacked wrenches (rebuilt for each configuration)
        sv_out[s] = sv
        for c in range(rank[s], 6):
            for i in range(6):
                free_twists[s, i, c - rank[s]] = v[i, c]
        locked_rank[s] = span(locked, locked_used, rtol, sv, v)
        asv_out[s] = sv
    return limb_rank, rank, locked_rank, sv_out, asv_out, ratio, free_twists
