"""Many configurations at once: DoF, ranks, singular values and singularity classes, vectorised.

The same numbers as :func:`pinmob.mobility.analyze` and
:func:`pinmob.singularity.analyze_singularity` (without classifying the
motions), for N closed configurations. The Pinocchio calls run once per
configuration (``computeJointJacobians``, ``updateFramePlacements``, one
``getFrameJacobian`` per limb); all linear algebra runs on stacked arrays:

* ``A_i = D_t T_i`` (N, 6, n_i), limb joint screws made dimensionless;
  ``rank_i`` = number of singular values above ``rtol * sigma_1``; the limb's
  constraint wrenches are the left singular vectors beyond ``rank_i``, kept as
  masked columns so that every sample has the same array shape (zero columns
  do not change the non-zero singular values).
* ``C = [W_1 ... W_k]`` (N, 6, 6k): its singular values give the constraint
  rank d and ``dof = 6 - d``; the same with the actuated columns removed gives
  the locked DoF.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from .mechanism import Mechanism
from .screw import RTOL, Array, twist_scaling


@dataclass(frozen=True)
class BatchResult:
    """Per-configuration results of :func:`analyze_batch` (N configurations, k limbs).

    Attributes:
        dof: (N,) platform DoF, ``6 - constraint_rank``.
        constraint_rank: (N,) rank of the stacked limb wrenches.
        singular_values: (N, 6) of the stacked dimensionless limb wrenches.
        limb_twist_rank: (N, k) rank of each limb's joint screws.
        limb_ratio: (N, k) ``sigma_r / sigma_1`` of each limb's unit-normalised joint screws, r its generic rank.
        locked_dof: (N,) platform DoF with the actuated joints locked.
        actuation_singular_values: (N, 6) of the stacked dimensionless locked-limb wrenches.
    """

    dof: Array
    constraint_rank: Array
    singular_values: Array
    limb_twist_rank: Array
    limb_ratio: Array
    locked_dof: Array
    actuation_singular_values: Array

    def singular(self, generic_rank: int, generic_twist_rank: Array, generic_locked_dof: int | None) -> dict[str, Array]:
        """Boolean (N,) arrays ``constraint``, ``actuation`` (None without actuators) and (N, k) ``limbs``."""
        return {
            "constraint": self.constraint_rank < generic_rank,
            "actuation": None if generic_locked_dof is None else self.locked_dof > generic_locked_dof,
            "limbs": self.limb_twist_rank < np.asarray(generic_twist_rank)[None, :],
        }


def limb_jacobians(mech: Mechanism, qs: Array, data: pin.Data | None = None) -> list[Array]:
    """Joint screws of every limb at every configuration: a list of k arrays (N, 6, n_i).

    Columns of ``getFrameJacobian(tip, LOCAL_WORLD_ALIGNED)``, carried from the
    tip origin to the platform origin (``v += w x (p - tip)``).
    """
    model = mech.model
    data = model.createData() if data is None else data
    qs = np.atleast_2d(np.asarray(qs, float))
    n, k = qs.shape[0], len(mech.limbs)
    full = np.empty((n, k, 6, model.nv))
    offset = np.empty((n, k, 3))
    pid = mech.platform_id
    tips = [limb.tip_id for limb in mech.limbs]
    frame = pin.LOCAL_WORLD_ALIGNED
    for s in range(n):
        pin.computeJointJacobians(model, data, qs[s])
        pin.updateFramePlacements(model, data)
        p = data.oMf[pid].translation
        for i, tip in enumerate(tips):
            full[s, i] = pin.getFrameJacobian(model, data, tip, frame)
            offset[s, i] = p - data.oMf[tip].translation
    out = []
    for i, limb in enumerate(mech.limbs):
        jac = full[:, i][:, :, limb.v_indices]
        jac[:, :3] += np.cross(jac[:, 3:], offset[:, i, :, None], axis=1)
        out.append(jac)
    return out


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


def _ratio(s: Array, rank: int) -> Array:
    if rank <= 0:
        return np.ones(s.shape[0])
    if s.shape[1] < rank:
        return np.zeros(s.shape[0])
    return np.where(s[:, 0] > 0, s[:, rank - 1] / np.where(s[:, 0] > 0, s[:, 0], 1.0), 0.0)


def _stack_rank(blocks: list[Array], rtol: float) -> tuple[Array, Array]:
    c = np.concatenate(blocks, axis=2)
    s = np.linalg.svd(c, compute_uv=False)[:, :6]
    rank = np.sum(s > rtol * s[:, :1], axis=1) * (s[:, 0] > 0)
    return rank, s


def analyze_batch(mech: Mechanism, qs: Array, *, rtol: float = RTOL, jacobians: list[Array] | None = None) -> BatchResult:
    """Vectorised mobility and singularity numbers at N closed configurations.

    Closure is not checked (the caller assembles the configurations).

    Args:
        mech: the mechanism.
        qs: (N, nq) closed configurations.
        rtol: relative tolerance of every rank decision.
        jacobians: precomputed :func:`limb_jacobians` (to time the linear algebra alone).
    """
    jacs = limb_jacobians(mech, qs) if jacobians is None else jacobians
    st = twist_scaling(mech.length_scale)[None, :, None]
    wrench_blocks, locked_blocks, ranks, ratios = [], [], [], []
    for limb, jac in zip(mech.limbs, jacs):
        a = st * jac
        w, rank, _ = _null_columns(a, rtol)
        wrench_blocks.append(w)
        ranks.append(rank)
        norms = np.linalg.norm(a, axis=1, keepdims=True)
        unit_s = np.linalg.svd(a / np.where(norms > 0, norms, 1.0), compute_uv=False)
        ratios.append(_ratio(unit_s, limb.generic_twist_rank))
        if limb.actuated:
            names = [limb.joints[k] for k, _ in _columns(mech, limb)]
            keep = [c for c, name in enumerate(names) if name not in limb.actuated]
            locked_blocks.append(_null_columns(a[:, :, keep], rtol)[0])
        else:
            locked_blocks.append(w)
    d, s = _stack_rank(wrench_blocks, rtol)
    locked_rank, ls = _stack_rank(locked_blocks, rtol)
    pad = lambda x: np.pad(x, ((0, 0), (0, 6 - x.shape[1])))  # noqa: E731
    return BatchResult(
        dof=6 - d,
        constraint_rank=d,
        singular_values=pad(s),
        limb_twist_rank=np.stack(ranks, axis=1),
        limb_ratio=np.stack(ratios, axis=1),
        locked_dof=6 - locked_rank,
        actuation_singular_values=pad(ls),
    )


def _columns(mech: Mechanism, limb) -> list[tuple[int, int]]:  # type: ignore[no-untyped-def]
    """(joint position in the limb, velocity column) for every velocity column of the limb."""
    out = []
    for k, name in enumerate(limb.joints):
        out += [(k, c) for c in range(mech.model.joints[mech.model.getJointId(name)].nv)]
    return out
