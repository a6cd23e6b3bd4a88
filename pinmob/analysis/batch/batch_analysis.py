"""Many configurations at once: DoF, ranks, singular values and singularity classes.

The same numbers as :func:`pinmob.analyze` and :func:`pinmob.analyze_singularity`
(without classifying the motions), for N closed configurations, with the same
matrices and the same rank rule (:func:`pinmob.screw.rank.rank_rule`: singular
values above ``rtol`` times the largest count). Pinocchio runs once per
configuration (``computeJointJacobians`` and the platform frame's placement);
then, per configuration:

* ``A_i = D_t T_i`` (6, n_i), limb i's joint screws per dimensionless rate (prismatic
  columns times L) made dimensionless; the rank
  of ``A_i^T`` is the limb's twist rank and its null space the limb's constraint
  wrenches ``W_i``; stacked for all limbs, ``C = [W_1, ..., W_k]^T`` has the rank
  d of the constraint space: ``dof = 6 - d``;
* the same with each actuated limb's actuated columns removed (and, for the
  other limbs, their screws with unit columns, as the singularity report does)
  gives the locked DoF.

Two engines give the same numbers: ``numpy`` (batched LAPACK SVDs, the very
calls :func:`pinmob.analyze` makes, so the same bits) and ``numba`` (a compiled
loop over the configurations with a one-sided Jacobi SVD per matrix,
:mod:`pinmob.analysis.batch.batch_kernel`; the same numbers to round-off), used when
numba is installed (``pip install "pinmob[fast]"``).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pinmob.analysis.batch.batch_numpy import numpy_engine
from pinmob.analysis.batch.batch_result import BatchResult
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.generic import generic_twist_ranks
from pinmob.analysis.limbs import column_joints, limb_decisions, limb_twists, rate_scale
from pinmob.analysis.mobility import platform_mobility
from pinmob.analysis.singularity.classification import require_platform, singularity_from_twists
from pinmob.blas import one_blas_thread
from pinmob.exceptions import ConfigurationError
from pinmob.model import Mechanism, numba_available
from pinmob.screw import RTOL, Array, label, motion_type_of_orthonormal

#: The engines of :func:`analyze_batch`.
ENGINES = ("numba", "numpy")


def world_jacobians(mech: Mechanism, qs: Array, data: pin.Data | None = None) -> tuple[Array, Array]:
    """Every joint screw at every configuration, and the platform origins.

    One ``computeJointJacobians`` per configuration: its world Jacobian
    ``data.J`` holds every joint screw ``[v; w]`` at the world origin, world axes.

    Returns:
        (N, 6, nv) world Jacobians and (N, 3) world positions of the platform frame [m].
    """
    model = mech.model
    data = pin.Data(model) if data is None else data
    jacobian, placement, pid = pin.computeJointJacobians, pin.updateFramePlacement, mech.platform_id
    full, origin = [], []
    for q in np.atleast_2d(np.asarray(qs, float)):
        full.append(jacobian(model, data, q))  # data.J
        origin.append(placement(model, data, pid).translation)
    return np.array(full).reshape(-1, 6, model.nv), np.array(origin).reshape(-1, 3)


@one_blas_thread
def analyze_batch(
    mech: Mechanism,
    qs: Array,
    *,
    rtol: float = RTOL,
    singular_values: bool = False,
    engine: str | None = None,
    twists: bool = False,
) -> BatchResult:
    """Mobility and singularity numbers at N closed configurations, fast.

    The ranks, DoF and singular values of :func:`pinmob.analyze` and
    :func:`pinmob.analyze_singularity` at each configuration (see the module
    docstring); the limb ratios and singular values only with
    ``singular_values=True``. Closure is not checked (the caller assembles the
    configurations). The first call of the numba engine in a new installation
    compiles its loop (seconds; cached on disk). A mechanism with loops inside
    its limbs (the Delta's parallelograms) is analysed one configuration at a
    time instead (loop-aware limb screws,
    :func:`pinmob.analysis.singularity.classification.singularity_from_twists`): the
    same results, at the speed of :func:`pinmob.analyze`.

    Args:
        mech: the mechanism.
        qs: (N, nq) closed configurations.
        rtol: relative tolerance of every rank decision.
        singular_values: also give the singular values and the limb ratios.
        engine: ``numba`` or ``numpy`` (default: numba when installed, else numpy).
        twists: also give the platform's free twists (:attr:`BatchResult.free_twists`: the null space of the
            stacked wrenches, from the SVD that ranks them, LAPACK's or the compiled loop's).

    Raises:
        ConfigurationError: qs has the wrong shape or non-finite values, the
            mechanism has no platform or closures that couple its limbs, or the
            engine is unknown or not installed.
    """
    qs = np.atleast_2d(np.asarray(qs, float))
    if qs.ndim != 2 or qs.shape[1] != mech.model.nq or not np.all(np.isfinite(qs)):
        raise ConfigurationError(
            f"analyze_batch needs finite configurations of shape (N, {mech.model.nq}), got shape {qs.shape}"
        )
    require_platform(mech, "analyze_batch")
    engine = check_engine(engine)
    if any(limb.closures for limb in mech.limbs):
        if twists:
            raise ConfigurationError("analyze_batch gives free twists only for limbs without loops")
        return _per_configuration(mech, qs, rtol, singular_values)
    full, origin = world_jacobians(mech, qs)
    return analyze_jacobians(mech, full, origin, rtol=rtol, singular_values=singular_values, engine=engine,
                             twists=twists)  # fmt: skip


def check_engine(engine: str | None) -> str:
    """The batch engine to use: ``engine``, or numba when installed, else numpy.

    Raises:
        ConfigurationError: an unknown engine, or numba asked for and not installed.
    """
    if engine is None:
        engine = "numba" if numba_available() else "numpy"
    if engine not in ENGINES:
        raise ConfigurationError(f"unknown batch engine {engine!r}; valid: {', '.join(ENGINES)}")
    if engine == "numba" and not numba_available():
        raise ConfigurationError("the numba engine needs numba: pip install 'pinmob[fast]'")
    return engine


@one_blas_thread
def analyze_jacobians(
    mech: Mechanism,
    full: Array,
    origin: Array,
    *,
    rtol: float = RTOL,
    singular_values: bool = False,
    engine: str | None = None,
    twists: bool = False,
) -> BatchResult:
    """:func:`analyze_batch` from the kinematics already computed: (N, 6, nv) world Jacobians, (N, 3) platform origins.

    ``full`` and ``origin`` as :func:`world_jacobians` gives them (``full`` is not changed); limbs without loops
    inside them only, and the configurations are not checked.
    """
    engine = check_engine(engine)
    if engine == "numba":  # the compiled loop scales each column as it reads it
        return _numba(mech, full, origin, rtol, singular_values, twists)
    full = full * rate_scale(mech)  # per dimensionless rate, as limb_twists (prismatic columns times L)
    return numpy_engine(mech, full, origin, rtol, singular_values, twists)


def motion_types(
    free_twists: Array, dof: ArrayLike, length: float, rtol: float, engine: str | None = None
) -> list[str]:
    """The motion type of each of N spans ``free_twists[i][:, :dof[i]]`` (:attr:`BatchResult.free_twists`).

    :func:`pinmob.screw.motion_label.motion_type_of_orthonormal` of each (``classify_twists``' label), or, with
    the numba engine, the same decisions compiled (:func:`pinmob.analysis.batch.motion_kernel.counts`) for the
    spans that its closed form (rotation rows below ``rtol``: ``kT``), taken here for all N at once, leaves.
    """
    dofs = np.asarray(dof, np.int64)
    if check_engine(engine) != "numba":
        return [motion_type_of_orthonormal(t[:, :k], length, rtol) for t, k in zip(free_twists, dofs.tolist())]
    spans = np.ascontiguousarray(free_twists, float)
    w = np.where(np.arange(6) < dofs[:, None, None], spans[:, 3:], 0.0)
    translations = (dofs > 0) & (np.sqrt((w * w).sum(axis=(1, 2))) <= rtol)
    labels = [f"{k}T" if pure else "" for k, pure in zip(dofs.tolist(), translations.tolist())]
    rest = np.flatnonzero(~translations)
    if rest.size:
        from pinmob.analysis.batch.motion_kernel import counts

        for i, c in zip(rest.tolist(), counts(spans[rest], dofs[rest], float(length), float(rtol)).tolist()):
            labels[i] = label(*c)
    return labels


def _numba(
    mech: Mechanism, full: Array, origin: Array, rtol: float, singular_values: bool, twists: bool
) -> BatchResult:
    """:func:`analyze_batch` by the compiled loop :func:`pinmob.analysis.batch.batch_kernel.ranks`.

    ``full``: the world Jacobians as computed (per joint rate: the loop scales them).
    """
    from pinmob.analysis.batch.batch_kernel import ranks

    columns = np.concatenate([np.asarray(limb.v_indices, np.int64) for limb in mech.limbs])
    offsets = np.cumsum([0] + [len(limb.v_indices) for limb in mech.limbs]).astype(np.int64)
    free, free_offsets = [], [0]
    for limb, start in zip(mech.limbs, offsets):
        free += [start + c for c, name in enumerate(column_joints(mech, limb)) if name not in limb.actuated]
        free_offsets.append(len(free))
    limb_rank, d, locked_rank, sv, asv, ratios, free_twists = ranks(
        np.ascontiguousarray(full, dtype=np.float64),  # as the loop is compiled for it (no copy when it is)
        rate_scale(mech),
        origin,
        float(mech.length_scale),
        columns,
        offsets,
        np.array(free, np.int64),
        np.array(free_offsets, np.int64),
        np.array([bool(limb.actuated) for limb in mech.limbs]),
        np.array(generic_twist_ranks(mech), np.int64),
        float(rtol),
        bool(singular_values),
    )
    if not singular_values:
        sv, asv, ratios = np.full_like(sv, np.nan), np.full_like(asv, np.nan), np.full_like(ratios, np.nan)
    return BatchResult(6 - d, d, sv, limb_rank, ratios, 6 - locked_rank, asv, "numba", free_twists if twists else None)


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
    return BatchResult(dof, rank, sv, limb_rank, ratios, locked, asv, "per configuration")
