"""The numpy engine of :func:`pinmob.analysis.batch.batch_analysis.analyze_batch`: batched LAPACK SVDs, the single analyses' calls.

Per limb, the matrices :func:`pinmob.analyze` and :func:`pinmob.analyze_singularity` decide (the same calls,
stacked over the configurations: the same bits); the stacked limb wrenches of configurations with the same
limb ranks decomposed together; with ``spans``, the null space of the stacked wrenches (the platform's free
twists).
"""

from __future__ import annotations

import numpy as np

from pinmob.analysis.batch.batch_result import BatchResult, Ints
from pinmob.analysis.generic import generic_twist_ranks
from pinmob.analysis.limbs import column_joints, limb_screws_at, unit_columns
from pinmob.analysis.singularity.result import ratio
from pinmob.model import Mechanism
from pinmob.screw import Array, rank_rule_rows, svd, twist_scaling, wrench_scaling


def limb_jacobians(mech: Mechanism, full: Array, origin: Array) -> list[Array]:
    """Joint screws of every limb at every configuration: a list of k arrays (N, 6, n_i).

    :func:`pinmob.analysis.limbs.limb_screws_at` on the world screws of
    :func:`pinmob.analysis.batch.batch_analysis.world_jacobians` per dimensionless rate (times
    :func:`~pinmob.analysis.limbs.rate_scale`), as for one configuration.
    """
    return [limb_screws_at(full, origin, limb.v_indices) for limb in mech.limbs]


def null_rows(a: Array, rtol: float) -> tuple[Ints, Array, Array]:
    """Ranks, singular values and ``V^T`` of each (m, 6) matrix of a stack (N, m, 6): decide_rank's SVD, batched."""
    _, s, vt = svd(a, full_matrices=a.shape[1] < a.shape[2])
    return rank_rule_rows(s, rtol), s, vt


def stacked_ranks(
    blocks: list[tuple[Ints, Array]], rtol: float, scale: Array | None, twists: bool = False
) -> tuple[Ints, Array, Array | None]:
    """Rank and (N, 6) singular values of the null rows of every limb stacked, per configuration.

    ``blocks``: per limb, (N,) ranks and (N, 6, 6) ``V^T`` (its null rows are those beyond the rank). The
    configurations with the same ranks are stacked and decomposed together. With ``scale`` (the wrench
    scaling), each block goes to SI and back, as :func:`pinmob.analysis.mobility.mobility_from_wrenches` takes it.
    With ``twists``, also the (N, 6, 6) null spaces of the stacked matrices (the reciprocal dimensionless twists)
    as columns, NaN beyond each one's dimension.
    """
    n = blocks[0][0].shape[0]
    ranks, values = np.zeros(n, np.int64), np.zeros((n, 6))
    null = np.full((n, 6, 6), np.nan) if twists else None
    pattern = np.stack([r for r, _ in blocks], axis=1)
    for key in np.unique(pattern, axis=0):
        where = np.flatnonzero((pattern == key).all(axis=1))
        rows = [vt[where, r:, :] for r, (_, vt) in zip(key, blocks)]
        if scale is not None:
            si = np.concatenate([np.swapaxes(w, 1, 2) / scale for w in rows], axis=2)
            stacked = np.swapaxes(scale * si, 1, 2)
        else:
            stacked = np.concatenate(rows, axis=1)
        if stacked.shape[1] == 0:
            if null is not None:
                null[where] = np.eye(6)  # no wrench: every twist is free (decide_rank of an empty matrix)
            continue
        r, s, vt = null_rows(stacked, rtol)
        ranks[where], values[where, : s.shape[1]] = r, s[:, :6]
        if null is not None:
            for i, (w, rank) in enumerate(zip(where, r)):
                null[w, :, : 6 - rank] = vt[i, rank:].T
    return ranks, values, null


def numpy_engine(
    mech: Mechanism, full: Array, origin: Array, rtol: float, singular_values: bool, spans: bool = False
) -> BatchResult:
    """:func:`analyze_batch` with batched LAPACK SVDs: the matrices and calls of the single analyses, per limb."""
    st, sw = twist_scaling(mech.length_scale)[:, None], wrench_scaling(mech.length_scale)[:, None]
    generic = generic_twist_ranks(mech)
    wrenches, locked, ratios = [], [], []
    for limb, g, twists in zip(mech.limbs, generic, limb_jacobians(mech, full, origin)):
        a = st * twists  # (N, 6, n_i)
        rank, _, vt = null_rows(np.swapaxes(a, 1, 2), rtol)
        wrenches.append((rank, vt))
        unit = None
        if singular_values or not limb.actuated:
            unit = null_rows(np.swapaxes(unit_columns(a), 1, 2), rtol)
            ratios.append(ratio(unit[1], g))
        if limb.actuated:
            keep = [c for c, name in enumerate(column_joints(mech, limb)) if name not in limb.actuated]
            lr, _, lvt = null_rows(np.swapaxes(a[:, :, keep], 1, 2), rtol)
            locked.append((lr, lvt))
        elif unit is not None:
            locked.append((unit[0], unit[2]))
    d, sv, free = stacked_ranks(wrenches, rtol, sw, spans)
    locked_rank, asv, _ = stacked_ranks(locked, rtol, None)
    n = full.shape[0]
    if not singular_values:
        sv, asv, ratio_array = np.full((n, 6), np.nan), np.full((n, 6), np.nan), np.full((n, len(mech.limbs)), np.nan)
    else:
        ratio_array = np.stack(ratios, axis=1)
    limb_rank = np.stack([r for r, _ in wrenches], axis=1)
    return BatchResult(6 - d, d, sv, limb_rank, ratio_array, 6 - locked_rank, asv, "numpy", free)
