"""Many configurations at once: DoF, ranks, singular values and singularity classes.

The same numbers as :func:`pinmob.analyze` and
:func:`pinmob.analyze_singularity` (without classifying the
motions), for N closed configurations. Pinocchio runs once per
configuration (``computeJointJacobians`` and the platform frame's placement);
the linear algebra runs in one compiled loop over the configurations
(:func:`pinmob.analysis.batch_kernel.ranks`, numba):

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

from pinmob.analysis.batch_kernel import ranks
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.generic import generic_twist_ranks
from pinmob.analysis.limbs import column_joints, limb_decisions, limb_screws_at, limb_twists, unit_columns
from pinmob.analysis.mobility import platform_mobility
from pinmob.analysis.singularity import ratio
from pinmob.analysis.singularity_analysis import require_platform, singularity_from_twists
from pinmob.blas import one_blas_thread
from pinmob.exceptions import ConfigurationError
from pinmob.frozen import ReadOnlyArrays
from pinmob.model.mechanism import Mechanism
from pinmob.screw.algebra import Array, twist_scaling
from pinmob.screw.rank import RTOL

#: Integer array (ranks, DoF).
Ints = NDArray[np.int64]


@dataclass(frozen=True)
class BatchResult(ReadOnlyArrays):
    """Per-configuration results of :func:`analyze_batch` (N configurations, k limbs).

    Attributes:
        dof: (N,) platform DoF, ``6 - constraint_rank``.
        constraint_rank: (N,) rank of the stacked limb wrenches.
        singular_values: (N, 6) of the stacked dimensionless limb wrenches.
        limb_twist_rank: (N, k) rank of each limb's joint screws.
        limb_ratio: (N, k) ``sigma_r / sigma_1`` of each limb's unit-normalised dimensionless joint screws, r
            its generic rank: the limb distances of :func:`pinmob.analyze_singularity`.
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

    :func:`pinmob.analysis.limbs.limb_screws_at` on the world screws of
    :func:`world_jacobians`, as for one configuration.
    """
    return [limb_screws_at(full, origin, limb.v_indices) for limb in mech.limbs]


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


@one_blas_thread
def analyze_batch(
    mech: Mechanism,
    qs: Array,
    *,
    rtol: float = RTOL,
    singular_values: bool = False,
) -> BatchResult:
    """Mobility and singularity numbers at N closed configurations, fast.

    Ranks come from the compiled loop :func:`pinmob.analysis.batch_kernel.ranks` (no per-matrix LAPACK
    call): the limb twist spans ``Q_i``, the limb wrenches ``W_i`` as their
    orthonormal complements, stacked for the constraint rank; the same with
    the actuated columns removed for the locked DoF. With ``singular_values=True`` the singular values (as in
    :func:`pinmob.analyze`) and the limb ratios are computed too, by batched SVDs.
    Closure is not checked (the caller assembles the configurations). The first
    call in a new installation compiles the loop (seconds; cached on disk).
    A mechanism with loops inside its limbs (the Delta's parallelograms) is
    analysed one configuration at a time instead (loop-aware limb screws,
    :func:`pinmob.analysis.singularity_analysis.singularity_from_twists`): the same results, at the speed
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
    limb_rank, d, locked_rank = ranks(
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
    """:func:`analyze_batch` by the single-configuration analyses, one configuration at a time."""
    n, k = qs.shape[0], len(mech.limbs)
    dof, rank, locked = (np.zeros(n, np.int64) for _ in range(3))
    limb_rank = np.zeros((n, k), np.int64)
    sv, asv, ratios = np.full((n, 6), np.nan), np.full((n, 6), np.nan), np.full((n, k), np.nan)
    for i, q in enumerate(qs):
        conf = Configuration.unchecked(mech, q)
        mob = platform_mobility(conf, rtol)
        twists, locked_twists = limb_twists(conf, rtol), limb_twists(conf, rtol, lock_actuated=True)
        decisions = limb_decisions(mech, twists, rtol)
        sing = singularity_from_twists(mech, twists, locked_twists, decisions, 0, rtol=rtol)  # generic rank unused here
        dof[i], rank[i], locked[i] = mob.dof, 6 - mob.dof, sing.locked_dof
        limb_rank[i] = [limb.twist_rank for limb in mob.limbs]
        if singular_values:
            sv[i], asv[i] = mob.singular_values, np.nan_to_num(sing.actuation_singular_values)
            ratios[i] = [sing.distances[f"limb {limb.name}"] for limb in mech.limbs]
    return BatchResult(dof, rank, sv, limb_rank, ratios, locked, asv)


def _singular_values(mech: Mechanism, scaled: list[Array], rtol: float) -> tuple[Array, Array, Array]:
    """Singular values of the stacked wrenches and locked wrenches, and limb ratios, by batched SVD."""
    wrench_blocks, locked_blocks, ratios = [], [], []
    for limb, generic, a in zip(mech.limbs, generic_twist_ranks(mech), scaled):
        w, _, _ = _null_columns(a, rtol)
        wrench_blocks.append(w)
        ratios.append(ratio(np.linalg.svd(unit_columns(a), compute_uv=False), generic))
        if limb.actuated:
            keep = [c for c, name in enumerate(column_joints(mech, limb)) if name not in limb.actuated]
            locked_blocks.append(_null_columns(a[:, :, keep], rtol)[0])
        else:
            locked_blocks.append(w)
    pad = lambda x: np.pad(x, ((0, 0), (0, 6 - x.shape[1])))  # noqa: E731
    s = np.linalg.svd(np.concatenate(wrench_blocks, axis=2), compute_uv=False)[:, :6]
    ls = np.linalg.svd(np.concatenate(locked_blocks, axis=2), compute_uv=False)[:, :6]
    return pad(s), pad(ls), np.stack(ratios, axis=1)
