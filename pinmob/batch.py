"""Many configurations at once: DoF, ranks, singular values and singularity classes.

The same numbers as :func:`pinmob.mobility.analyze` and
:func:`pinmob.singularity.analyze_singularity` (without classifying the
motions), for N closed configurations. Pinocchio runs once per
configuration (``computeJointJacobians`` and the platform frame's placement);
the linear algebra runs in one compiled loop over the configurations
(:func:`_ranks`, numba, cached by :mod:`pinmob.jit_cache`):

* ``A_i = D_t T_i`` (6, n_i), limb i's joint screws made dimensionless, an
  orthonormal basis ``Q_i`` of their span and its rank (the limb's twist
  rank), by Gram-Schmidt with column pivoting (:func:`_span`);
* the limb's constraint wrenches ``W_i``: an orthonormal basis of the
  complement of ``span(Q_i)`` (:func:`_complement`); stacked for all limbs,
  ``C = [W_1, ..., W_k]`` has the rank d of the constraint space: ``dof = 6 - d``;
* the same with the actuated columns removed gives the locked DoF.

Singular values (optional) come from batched LAPACK SVDs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from .closure import compute_kinematics
from .exceptions import ConfigurationError
from .jit_cache import njit
from .mechanism import Mechanism
from .screw import RTOL, Array, twist_scaling
from .singularity import analyze_both, column_joints, ratio, require_platform, unit_columns

#: Integer array (ranks, DoF).
Ints = NDArray[np.int64]


@dataclass(frozen=True)
class BatchResult:
    """Per-configuration results of :func:`analyze_batch` (N configurations, k limbs).

    Attributes:
        dof: (N,) platform DoF, ``6 - constraint_rank``.
        constraint_rank: (N,) rank of the stacked limb wrenches.
        singular_values: (N, 6) of the stacked dimensionless limb wrenches.
        limb_twist_rank: (N, k) rank of each limb's joint screws.
        limb_ratio: (N, k) ``sigma_r / sigma_1`` of each limb's unit-normalised dimensionless joint screws, r
            its generic rank: the limb distances of :func:`pinmob.singularity.analyze_singularity`.
        locked_dof: (N,) platform DoF with the actuated joints locked.
        actuation_singular_values: (N, 6) of the stacked dimensionless locked-limb wrenches.
    """

    dof: Ints
    constraint_rank: Ints
    singular_values: Array
    limb_twist_rank: Ints
    limb_ratio: Array
    locked_dof: Ints
    actuation_singular_values: Array


def world_jacobians(mech: Mechanism, qs: Array, data: pin.Data | None = None) -> tuple[Array, Array]:
    """Every joint screw at every configuration, and the platform origins.

    One ``computeJointJacobians`` per configuration: its world Jacobian
    ``data.J`` holds every joint screw ``[v; w]`` at the world origin, world axes.

    Returns:
        (N, 6, nv) world Jacobians and (N, 3) world positions of the platform frame [m].
    """
    model = mech.model
    data = model.createData() if data is None else data
    jacobian, placement, pid = pin.computeJointJacobians, pin.updateFramePlacement, mech.platform_id
    full, origin = [], []
    for q in np.atleast_2d(np.asarray(qs, float)):
        full.append(jacobian(model, data, q))  # data.J
        origin.append(placement(model, data, pid).translation)
    return np.array(full).reshape(-1, 6, model.nv), np.array(origin).reshape(-1, 3)


def limb_jacobians(mech: Mechanism, full: Array, origin: Array) -> list[Array]:
    """Joint screws of every limb at every configuration: a list of k arrays (N, 6, n_i).

    The world screws of :func:`world_jacobians` carried to the platform origin p
    by ``v += w x p`` (:func:`pinmob.screw.shift_twists`): the columns of each
    limb tip's ``LOCAL_WORLD_ALIGNED`` Jacobian carried to p, as in
    :func:`pinmob.mobility.limb_twists`.
    """
    shifted = full.copy()
    shifted[:, :3] += np.cross(full[:, 3:], origin[:, :, None], axis=1)
    return [shifted[:, :, limb.v_indices] for limb in mech.limbs]


@njit
def _span(a: Array, cols: Ints, tol: float, r: Array, q: Array, first: int) -> int:
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
def _complement(q: Array, rank: int, proj: Array, r: Array, out: Array, first: int) -> int:
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
    return _span(proj, np.arange(6), 0.1, r, out, first)


@njit
def _ranks(
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
    orthonormal complement (the limb's wrenches) are found by :func:`_span` and
    :func:`_complement`; the stacked wrenches (orthonormal per limb) are ranked.

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
            twist_rank = _span(a, cols, tol, r, q, 0) if largest > 0 else 0
            limb_rank[s, i] = twist_rank
            used += _complement(q, twist_rank, proj, r, wrenches, used)
            kept = free[free_offsets[i] : free_offsets[i + 1]]
            if kept.size < cols.size:
                twist_rank = _span(a, kept, tol, r, q, 0) if largest > 0 else 0
            locked_used += _complement(q, twist_rank, proj, r, locked_wrenches, locked_used)
        rank[s] = _span(wrenches, every[:used], rtol, r, q, 0)
        locked_rank[s] = _span(locked_wrenches, every[:locked_used], rtol, r, q, 0)
    return limb_rank, rank, locked_rank


def _null_columns(a: Array, rtol: float) -> tuple[Array, Array, Array]:
    """Left null space of each (6, m) slice of ``a`` (N, 6, m), as masked columns.

    Returns:
        (N, 6, 6) left singular vectors with the columns of the row space zeroed,
        (N,) ranks, (N, min(6, m)) singular values.
    """
    n = a.shape[0]
    if a.shape[2] == 0:
        return np.broadcast_to(np.eye(6), (n, 6, 6)).copy(), np.zeros(n, int), np.zeros((n, 0))
    u, s, _ = np.linalg.svd(a, full_matrices=True)
    rank = np.sum(s > rtol * s[:, :1], axis=1) * (s[:, 0] > 0)
    mask = np.arange(6)[None, :] >= rank[:, None]
    return u * mask[:, None, :], rank, s


def analyze_batch(
    mech: Mechanism,
    qs: Array,
    *,
    rtol: float = RTOL,
    singular_values: bool = False,
) -> BatchResult:
    """Mobility and singularity numbers at N closed configurations, fast.

    Ranks come from the compiled loop :func:`_ranks` (no per-matrix LAPACK
    call): the limb twist spans ``Q_i``, the limb wrenches ``W_i`` as their
    orthonormal complements, stacked for the constraint rank; the same with
    the actuated columns removed for the locked DoF. With ``singular_values=True`` the singular values (as in
    :func:`pinmob.analyze`) and the limb ratios are computed too, by batched SVDs.
    Closure is not checked (the caller assembles the configurations). The first
    call in a new installation compiles the loop (seconds; cached on disk in a per-user folder,
    :func:`pinmob.jit_cache.cache_dir`, never in the installed package).
    A mechanism with loops inside its limbs (the Delta's parallelograms) is
    analysed one configuration at a time instead (loop-aware limb screws,
    :func:`pinmob.singularity.analyze_both`): the same results, at the speed
    of :func:`pinmob.analyze`.

    Args:
        mech: the mechanism.
        qs: (N, nq) closed configurations.
        rtol: relative tolerance of every rank decision.
        singular_values: also compute the singular values (slower).

    Raises:
        ConfigurationError: qs has the wrong shape or non-finite values, or the
            mechanism has no platform or closures that couple its limbs.
    """
    qs = np.atleast_2d(np.asarray(qs, float))
    if qs.ndim != 2 or qs.shape[1] != mech.model.nq or not np.all(np.isfinite(qs)):
        raise ConfigurationError(
            f"analyze_batch needs finite configurations of shape (N, {mech.model.nq}), got shape {qs.shape}"
        )
    require_platform(mech, "analyze_batch")
    if any(limb.closures for limb in mech.limbs):
        return _per_configuration(mech, qs, rtol, singular_values)
    n = qs.shape[0]
    full, origin = world_jacobians(mech, qs)
    columns = np.concatenate([np.asarray(limb.v_indices, np.int64) for limb in mech.limbs])
    offsets = np.cumsum([0] + [len(limb.v_indices) for limb in mech.limbs]).astype(np.int64)
    free, free_offsets = [], [0]
    for limb, start in zip(mech.limbs, offsets):
        free += [start + c for c, name in enumerate(column_joints(mech, limb)) if name not in limb.actuated]
        free_offsets.append(len(free))
    limb_rank, d, locked_rank = _ranks(
        full,
        origin,
        float(mech.length_scale),
        columns,
        offsets,
        np.array(free, np.int64),
        np.array(free_offsets, np.int64),
        float(rtol),
    )
    sv, asv = np.full((n, 6), np.nan), np.full((n, 6), np.nan)
    ratio = np.full((n, len(mech.limbs)), np.nan)
    if singular_values:
        st = twist_scaling(mech.length_scale)[None, :, None]
        sv, asv, ratio = _singular_values(mech, [st * jac for jac in limb_jacobians(mech, full, origin)], rtol)
    return BatchResult(
        dof=6 - d,
        constraint_rank=d,
        singular_values=sv,
        limb_twist_rank=limb_rank,
        limb_ratio=ratio,
        locked_dof=6 - locked_rank,
        actuation_singular_values=asv,
    )


def _per_configuration(mech: Mechanism, qs: Array, rtol: float, singular_values: bool) -> BatchResult:
    """:func:`analyze_batch` by :func:`pinmob.singularity.analyze_both`, one configuration at a time."""
    model = mech.model
    data = model.createData()
    n, k = qs.shape[0], len(mech.limbs)
    dof, rank, locked = (np.zeros(n, np.int64) for _ in range(3))
    limb_rank = np.zeros((n, k), np.int64)
    sv, asv, ratios = np.full((n, 6), np.nan), np.full((n, 6), np.nan), np.full((n, k), np.nan)
    for i, q in enumerate(qs):
        compute_kinematics(model, data, q)
        mob, sing = analyze_both(mech, data, 0, rtol=rtol)  # no generic rank needed for these numbers
        dof[i], rank[i], locked[i] = mob.dof, 6 - mob.dof, sing.locked_dof
        limb_rank[i] = [limb.twist_rank for limb in mob.limbs]
        if singular_values:
            sv[i], asv[i] = mob.singular_values, np.nan_to_num(sing.actuation_singular_values)
            ratios[i] = [sing.distances[f"limb {limb.name}"] for limb in mech.limbs]
    return BatchResult(dof, rank, sv, limb_rank, ratios, locked, asv)


def _singular_values(mech: Mechanism, scaled: list[Array], rtol: float) -> tuple[Array, Array, Array]:
    """Singular values of the stacked wrenches and locked wrenches, and limb ratios, by batched SVD."""
    wrench_blocks, locked_blocks, ratios = [], [], []
    for limb, a in zip(mech.limbs, scaled):
        w, _, _ = _null_columns(a, rtol)
        wrench_blocks.append(w)
        ratios.append(ratio(np.linalg.svd(unit_columns(a), compute_uv=False), limb.generic_twist_rank))
        if limb.actuated:
            keep = [c for c, name in enumerate(column_joints(mech, limb)) if name not in limb.actuated]
            locked_blocks.append(_null_columns(a[:, :, keep], rtol)[0])
        else:
            locked_blocks.append(w)
    pad = lambda x: np.pad(x, ((0, 0), (0, 6 - x.shape[1])))  # noqa: E731
    s = np.linalg.svd(np.concatenate(wrench_blocks, axis=2), compute_uv=False)[:, :6]
    ls = np.linalg.svd(np.concatenate(locked_blocks, axis=2), compute_uv=False)[:, :6]
    return pad(s), pad(ls), np.stack(ratios, axis=1)
