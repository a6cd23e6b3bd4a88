"""The compiled loop behind :func:`pinmob.analysis.batch.batch_analysis.analyze_batch` (numba, the optional ``fast`` extra).

Per configuration, the same matrices and the same rank rule as
:func:`pinmob.analyze` (:func:`pinmob.screw.rank.rank_rule`: singular values above
``rtol`` times the largest count), with the singular values from one-sided Jacobi
rotations instead of LAPACK's SVD (:mod:`pinmob.screw.jacobi`): the
same numbers to round-off (the tests compare them with the numpy path, which calls
LAPACK). A limb's screws and the stacked wrenches (at most six) are orthogonalised
as columns (:func:`~pinmob.screw.jacobi.orthogonalize`, 6 long), the
wrenches reciprocal to them (the complement of their span) by Householder reflections
(:func:`~pinmob.screw.jacobi.complete`); more than six stacked wrenches are
first reduced to six (the R of their QR factorisation:
:func:`stack_columns`). Per limb, of the eleven
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

from pinmob.jit_cache import njit
from pinmob.screw import Array, column_rank, complete, orthogonalize

#: Integer array (ranks, DoF).
Ints = NDArray[np.int64]

#: A limb's screws have full column rank without their own SVD when their unit columns' ``sigma_n / sigma_1``,
#: times their shortest over their longest column (a lower bound of their own ratio), exceeds this many ``rtol``:
#: far beyond the round-off of either SVD, so the rank rule would count every column.
CERTAIN = 1.01


@njit
def ranks(
    full: Array,
    rates: Array,
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
        rates: (nv,) each column's scale (:func:`pinmob.analysis.limbs.rate_scale`: L on prismatic rates, 1
            elsewhere): the screws per dimensionless rate are ``full[:, :, j] * rates[j]``, multiplied here as
            each column is read (the same products as ``full * rates`` over the stack, without that copy).
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
            sj = rates[j]
            wx, wy, wz = full[s, 3, j] * sj, full[s, 4, j] * sj, full[s, 5, j] * sj
            a[0, c] = (full[s, 0, j] * sj + (wy * pz - wz * py)) / length
            a[1, c] = (full[s, 1, j] * sj + (wz * px - wx * pz)) / length
            a[2, c] = (full[s, 2, j] * sj + (wx * py - wy * px)) / length
            a[3, c], a[4, c], a[5, c] = wx, wy, wz
        used = locked_used = 0
        for i in range(k):
            lo, hi = offsets[i], offsets[i + 1]
            size = hi - lo
            certain = False
            unactuated = 0
            for task in range(3):  # one call site each below: numba compiles what a site calls once more per site
                if task == 0:  # the screws with unit columns: the limb ratio, an unactuated limb's locked wrenches
                    if actuated[i] and not ratios:
                        continue
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
                    begin, end = 0, size
                elif task == 1:  # an actuated limb's unactuated screws: its locked wrenches
                    if not actuated[i]:
                        continue
                    for c in range(lo, hi):
                        if is_free[c]:
                            g[:, unactuated] = a[:, c]
                            unactuated += 1
                    begin, end = 0, unactuated
                else:  # the screws: the actuated ones added to the unactuated ones orthogonalised
                    end = unactuated
                    for c in range(lo, hi):
                        if not (actuated[i] and is_free[c]):
                            g[:, end] = a[:, c]
                            end += 1
                    begin = unactuated
                if certain and task > 0:  # full column rank, as are its columns: the complement by Householder QR
                    r, ordered = end, identity
                else:
                    orthogonalize(g, begin, end)
                    r, ordered = column_rank(g, end, rtol, sv, order), order
                if task == 0:
                    if ratios:  # sigma_g / sigma_1
                        ratio[s, i] = 1.0 if generic[i] <= 0 else (sv[generic[i] - 1] / sv[0] if sv[0] > 0.0 else 0.0)
                    # sigma_n / sigma_1 of the screws is at least the unit columns' times shortest / longest
                    certain = size <= 6 and sv[0] > 0.0 and sv[size - 1] / sv[0] * (shortest / longest) > CERTAIN * rtol
                    if actuated[i]:
                        continue
                target = wrenches if task == 2 else locked
                written = complete(g, ordered, r, target, used if task == 2 else locked_used, True)
                if task == 2:
                    limb_rank[s, i] = r
                    used += written
                else:
                    locked_used += written
        for which in range(2):  # the stacked wrenches (and their null space), then the stacked locked wrenches
            count = stack_columns(wrenches if which == 0 else locked, used if which == 0 else locked_used, g)
            orthogonalize(g, 0, count)
            r = column_rank(g, count, rtol, sv, order)
            if which == 0:
                rank[s], sv_out[s] = r, sv[:6]
                complete(g, order, r, free_twists[s], 0, False)
            else:
                locked_rank[s], asv_out[s] = r, sv[:6]
    return limb_rank, rank, locked_rank, sv_out, asv_out, ratio, free_twists


@njit
def stack_columns(rows: Array, used: int, g: Array) -> int:
    """The stacked wrenches ``rows[:used]`` (used, 6) as columns of ``g``: the same singular values and null space.

    Up to six: the rows themselves. More: the rows of R of their QR factorisation (Householder reflections
    of ``rows``, which is overwritten), six of them: ``rows = Q R`` has R's singular values and null space.

    Returns:
        the number of columns written (``min(used, 6)``).
    """
    if used > 6:
        for c in range(6):
            norm = 0.0
            for i in range(c, used):
                norm += rows[i, c] * rows[i, c]
            norm = np.sqrt(norm)
            if norm == 0.0:
                continue
            alpha = -norm if rows[c, c] >= 0.0 else norm  # the new diagonal entry
            rows[c, c] -= alpha  # the reflector h = x - alpha e_c, stored in place of x
            hh = 0.0
            for i in range(c, used):
                hh += rows[i, c] * rows[i, c]
            for d in range(c + 1, 6):
                dot = 0.0
                for i in range(c, used):
                    dot += rows[i, c] * rows[i, d]
                dot *= 2.0 / hh
                for i in range(c, used):
                    rows[i, d] -= dot * rows[i, c]
            rows[c, c] = alpha
            for i in range(c + 1, used):
                rows[i, c] = 0.0
        used = 6
    for c in range(used):
        for i in range(6):
            g[i, c] = rows[c, i]
    return used
