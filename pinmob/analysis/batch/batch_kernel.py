"""The compiled loop behind :func:`pinmob.analysis.batch.batch_analysis.analyze_batch` (numba, the optional ``fast`` extra).

Per configuration, the same matrices and the same rank rule as
:func:`pinmob.analyze` (:func:`pinmob.screw.rank.rank_rule`: singular values above
``rtol`` times the largest count), with the singular values from one-sided Jacobi
rotations instead of LAPACK's SVD (:mod:`pinmob.analysis.batch.jacobi`): the
same numbers to round-off (the tests compare them with the numpy path, which calls
LAPACK). A limb's screws and the stacked wrenches (at most six) are orthogonalised
as columns (:func:`~pinmob.analysis.batch.jacobi.orthogonalize`, 6 long), the
wrenches reciprocal to them (the complement of their span) by Householder reflections
(:func:`~pinmob.analysis.batch.jacobi.complete`); more than six wrenches by
rows (:func:`~pinmob.analysis.batch.jacobi.span`). Per limb, of the eleven
SVDs a 3-PUU sample took before, only the one of the unit columns is left where it
proves the limb's rank (:data:`CERTAIN`): then the screws and the unactuated screws
have full column rank and their complements need no SVD; an actuated limb that is
not proven continues its unactuated screws' rotations with the actuated ones added.
Importing this module imports numba; the compiled code is cached by
:mod:`pinmob.jit_cache` (outside the installed package).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pinmob.analysis.batch.jacobi import column_rank, complete, orthogonalize, span
from pinmob.jit_cache import njit
from pinmob.screw.algebra import Array

#: Integer array (ranks, DoF).
Ints = NDArray[np.int64]

#: A limb's screws have full column rank without their own SVD when their unit columns' ``sigma_n / sigma_1``,
#: times their shortest over their longest column (a lower bound of their own ratio), exceeds this many ``rtol``:
#: far beyond the round-off of either SVD, so the rank rule would count every column.
CERTAIN = 1.01


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
    and locked wrenches are ranked (module docstring).

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
        in the first ``6 - rank`` columns (the complement of the wrenches' span), NaN in the others.
    """
    n, k, m = full.shape[0], offsets.size - 1, columns.size
    limb_rank = np.zeros((n, k), np.int64)
    rank = np.zeros(n, np.int64)
    locked_rank = np.zeros(n, np.int64)
    sv_out, asv_out = np.zeros((n, 6)), np.zeros((n, 6))
    ratio = np.zeros((n, k))
    free_twists = np.full((n, 6, 6), np.nan)
    a = np.zeros((6, m))
    width = 6
    for i in range(k):
        width = max(width, offsets[i + 1] - offsets[i])
    g = np.zeros((6, width))  # a limb's screws or the stacked wrenches, as columns
    sv = np.zeros(width)
    order = np.zeros(width, np.int64)
    v = np.zeros((6, 6))
    no_twists = np.zeros((6, 0))
    wrenches = np.zeros((6 * k, 6))
    locked = np.zeros((6 * k, 6))
    identity = np.arange(width)
    is_free = np.zeros(m, np.bool_)
    for f in free:
        is_free[f] = True
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
            lo, hi = offsets[i], offsets[i + 1]
            size = hi - lo
            certain = False
            if ratios or not actuated[i]:  # the screws with unit columns
                shortest, longest = np.inf, 0.0
                for c in range(lo, hi):
                    norm = 0.0
                    for e in range(6):
                        norm += a[e, c] * a[e, c]
                    norm = np.sqrt(norm)
                    shortest, longest = min(shortest, norm), max(longest, norm)
                    scale = 1.0 / norm if norm > 0.0 else 1.0
                    for e in range(6):
                        g[e, c - lo] = a[e, c] * scale
                orthogonalize(g, 0, size)
                r = column_rank(g, size, rtol, sv, order)
                if not actuated[i]:
                    locked_used += complete(g, order, r, locked, locked_used, True)
                if ratios:  # sigma_g / sigma_1
                    ratio[s, i] = 1.0 if generic[i] <= 0 else (sv[generic[i] - 1] / sv[0] if sv[0] > 0.0 else 0.0)
                # sigma_n / sigma_1 of the screws themselves is at least the unit columns' times shortest / longest
                certain = size <= 6 and sv[0] > 0.0 and sv[size - 1] / sv[0] * (shortest / longest) > CERTAIN * rtol
            start = 0
            if actuated[i]:  # the unactuated screws first (locked wrenches), then the actuated ones added
                for c in range(lo, hi):
                    if is_free[c]:
                        g[:, start] = a[:, c]
                        start += 1
                if certain:  # full column rank, as are its columns: the complement by Householder QR
                    locked_used += complete(g, identity, start, locked, locked_used, True)
                else:
                    orthogonalize(g, 0, start)
                    r = column_rank(g, start, rtol, sv, order)
                    locked_used += complete(g, order, r, locked, locked_used, True)
                filled = start
                for c in range(lo, hi):
                    if not is_free[c]:
                        g[:, filled] = a[:, c]
                        filled += 1
            else:
                g[:, :size] = a[:, lo:hi]
            if certain:
                r = size
                used += complete(g, identity, r, wrenches, used, True)
            else:
                orthogonalize(g, start, size)
                r = column_rank(g, size, rtol, sv, order)
                used += complete(g, order, r, wrenches, used, True)
            limb_rank[s, i] = r
        rank[s] = _stacked(wrenches, used, rtol, g, sv, order, v, free_twists[s])
        sv_out[s] = sv[:6]
        locked_rank[s] = _stacked(locked, locked_used, rtol, g, sv, order, v, no_twists)
        asv_out[s] = sv[:6]
    return limb_rank, rank, locked_rank, sv_out, asv_out, ratio, free_twists


@njit
def _stacked(rows: Array, used: int, rtol: float, g: Array, sv: Array, order: Ints, v: Array, null: Array) -> int:
    """Rank and singular values (``sv[:6]``) of the stacked wrenches ``rows[:used]``; their null space into ``null``.

    Up to six wrenches: as columns (:func:`orthogonalize`; the null space by :func:`complete`); more: by
    :func:`span` on the rows. ``null`` (6, 6) gets an orthonormal basis of the twists reciprocal to every wrench
    in its first ``6 - rank`` columns (none when it has no columns).
    """
    if used > 6:
        sv6 = np.zeros(6)
        r = span(rows, used, rtol, sv6, v)
        sv[:6] = sv6
        if null.shape[1]:
            for c in range(r, 6):
                for i in range(6):
                    null[i, c - r] = v[i, c]
        return r
    for c in range(used):
        for i in range(6):
            g[i, c] = rows[c, i]
    orthogonalize(g, 0, used)
    r = column_rank(g, used, rtol, sv, order)
    if null.shape[1]:
        complete(g, order, r, null, 0, False)
    return r
