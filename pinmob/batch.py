"""Many configurations at once: DoF, ranks, singular values and singularity classes, vectorised.

The same numbers as :func:`pinmob.mobility.analyze` and
:func:`pinmob.singularity.analyze_singularity` (without classifying the
motions), for N closed configurations. Pinocchio runs once per
configuration (``computeJointJacobians`` and the platform frame's placement);
all linear algebra runs on stacked arrays:

* ``A_i = D_t T_i`` (N, 6, n_i), limb joint screws made dimensionless, and
  their rank; the limb's constraint wrenches span the columns of
  ``I - Q_i Q_i^T`` (Q_i an orthonormal basis of the span of A_i); for the
  singular values, the left singular vectors beyond the rank, kept as masked
  columns so that every sample has the same array shape (zero columns do not
  change the non-zero singular values).
* ``C = [W_1 ... W_k]``: its rank d gives ``dof = 6 - d``; the same with the
  actuated columns removed gives the locked DoF.

Ranks are decided by a pivoted Gram-Schmidt vectorised over the N
configurations (:func:`orthonormalize`), singular values (optional) by
batched SVDs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from .exceptions import ConfigurationError
from .mechanism import Limb, Mechanism
from .screw import RTOL, Array, Mask, twist_scaling

#: Configurations per block of vectorised linear algebra (arrays stay in cache).
BLOCK = 128


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

    def singular(
        self, generic_rank: int, generic_twist_rank: Array, generic_locked_dof: int | None
    ) -> dict[str, Mask | None]:
        """Boolean (N,) arrays ``constraint``, ``actuation`` (None without actuators) and (N, k) ``limbs``."""
        return {
            "constraint": self.constraint_rank < generic_rank,
            "actuation": None if generic_locked_dof is None else self.locked_dof > generic_locked_dof,
            "limbs": self.limb_twist_rank < np.asarray(generic_twist_rank)[None, :],
        }


def limb_jacobians(mech: Mechanism, qs: Array, data: pin.Data | None = None) -> list[Array]:
    """Joint screws of every limb at every configuration: a list of k arrays (N, 6, n_i).

    One ``computeJointJacobians`` per configuration: its world Jacobian
    ``data.J`` holds every joint screw at the world origin; carried to the
    platform origin p by ``v += w x p`` (:func:`pinmob.screw.shift_twists`),
    these are the columns of each limb tip's ``LOCAL_WORLD_ALIGNED`` Jacobian
    carried to p, as in :func:`pinmob.mobility.limb_twists`.
    """
    model = mech.model
    data = model.createData() if data is None else data
    qs = np.atleast_2d(np.asarray(qs, float))
    n = qs.shape[0]
    full = np.empty((n, 6, model.nv))
    origin = np.empty((n, 3))
    pid = mech.platform_id
    for s in range(n):
        pin.computeJointJacobians(model, data, qs[s])
        full[s] = data.J
        origin[s] = pin.updateFramePlacement(model, data, pid).translation
    full[:, :3] += np.cross(full[:, 3:], origin[:, :, None], axis=1)
    return [full[:, :, limb.v_indices] for limb in mech.limbs]


def orthonormalize(a: Array, rtol: float = RTOL, scale: float | None = None) -> tuple[Array, Array]:
    """Orthonormal basis of the column span of each (6, m) slice of ``a`` (N, 6, m), and its rank.

    Gram-Schmidt with column pivoting, vectorised over N: at each of at most
    six steps the remaining column of largest norm is normalised and projected
    out of the others; a step whose
    largest remaining norm is below ``rtol * max_j |a_j|`` (``rtol * scale``
    when a scale is given, e.g. 1 for columns of projectors) adds nothing. This
    is the rank-revealing QR decision, which agrees with the SVD's
    ``sigma_k > rtol * sigma_1`` except within a factor ``sqrt(m)`` of the
    threshold.

    Returns:
        (N, 6, min(6, m)) basis with zero columns past the rank, and (N,) ranks.
    """
    n, _, m = a.shape
    steps = min(6, m)
    q = np.zeros((n, 6, steps))
    rank = np.zeros(n, dtype=int)
    if m == 0:
        return q, rank
    r = a.copy()
    if scale is None:
        tol = rtol * np.sqrt(np.max(np.einsum("nij,nij->nj", a, a), axis=1))
    else:
        tol = np.full(n, rtol * scale)
    rows = np.arange(n)
    for k in range(steps):
        norms = np.einsum("nij,nij->nj", r, r)
        j = np.argmax(norms, axis=1)
        best = np.sqrt(norms[rows, j])
        ok = (best > tol) & (tol > 0)
        v = r[rows, :, j] * (ok / np.where(ok, best, 1.0))[:, None]
        q[:, :, k] = v
        rank += ok
        r -= v[:, :, None] * np.einsum("ni,nij->nj", v, r)[:, None, :]
    return q, rank


def _wrench_projectors(basis: Array) -> Array:
    """``I - Q Q^T`` (N, 6, 6): columns spanning the wrenches reciprocal to the twists spanned by Q."""
    return np.eye(6)[None] - basis @ basis.transpose(0, 2, 1)


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


def _ratio(s: NDArray[np.floating], rank: int) -> Array:
    if rank <= 0:
        return np.ones(s.shape[0])
    if s.shape[1] < rank:
        return np.zeros(s.shape[0])
    return np.where(s[:, 0] > 0, s[:, rank - 1] / np.where(s[:, 0] > 0, s[:, 0], 1.0), 0.0)


def analyze_batch(
    mech: Mechanism,
    qs: Array | None,
    *,
    rtol: float = RTOL,
    singular_values: bool = False,
    jacobians: list[Array] | None = None,
) -> BatchResult:
    """Vectorised mobility and singularity numbers at N closed configurations.

    Ranks come from :func:`orthonormalize` (no per-matrix LAPACK call): the
    limb twist spans ``Q_i``, the limb wrench spaces as the columns of
    ``I - Q_i Q_i^T`` (their span is that of ``W_i``), stacked for the
    constraint rank; the same with the actuated columns removed for the locked
    DoF. With ``singular_values=True`` the singular values (as in
    :func:`pinmob.analyze`) and the limb ratios are computed too, by batched SVDs.
    Closure is not checked (the caller assembles the configurations).

    Args:
        mech: the mechanism.
        qs: (N, nq) closed configurations (unused when ``jacobians`` is given).
        rtol: relative tolerance of every rank decision.
        singular_values: also compute the singular values (slower).
        jacobians: precomputed :func:`limb_jacobians`.
    """
    if jacobians is not None:
        jacs = jacobians
    elif qs is not None:
        jacs = limb_jacobians(mech, qs)
    else:
        raise ConfigurationError("analyze_batch needs the configurations qs (N, nq) or their limb jacobians")
    n = jacs[0].shape[0]
    if n > BLOCK:  # blocks that stay in cache
        parts = [
            analyze_batch(
                mech, None, rtol=rtol, singular_values=singular_values, jacobians=[j[s : s + BLOCK] for j in jacs]
            )
            for s in range(0, n, BLOCK)
        ]
        return BatchResult(*(np.concatenate([getattr(p, f) for p in parts]) for f in BatchResult.__dataclass_fields__))
    st = twist_scaling(mech.length_scale)[None, :, None]
    projectors, locked, ranks = [], [], []
    scaled = [st * jac for jac in jacs]
    for limb, a in zip(mech.limbs, scaled):
        q, rank = orthonormalize(a, rtol)
        ranks.append(rank)
        projectors.append(_wrench_projectors(q))
        if limb.actuated:
            keep = [c for c, name in enumerate(_column_joints(mech, limb)) if name not in limb.actuated]
            locked.append(_wrench_projectors(orthonormalize(a[:, :, keep], rtol)[0]))
        else:
            locked.append(projectors[-1])
    d = orthonormalize(np.concatenate(projectors, axis=2), rtol, scale=1.0)[1]
    locked_rank = orthonormalize(np.concatenate(locked, axis=2), rtol, scale=1.0)[1]
    sv, asv = np.full((n, 6), np.nan), np.full((n, 6), np.nan)
    ratio = np.full((n, len(mech.limbs)), np.nan)
    if singular_values:
        sv, asv, ratio = _singular_values(mech, scaled, rtol)
    return BatchResult(
        dof=6 - d,
        constraint_rank=d,
        singular_values=sv,
        limb_twist_rank=np.stack(ranks, axis=1),
        limb_ratio=ratio,
        locked_dof=6 - locked_rank,
        actuation_singular_values=asv,
    )


def _singular_values(mech: Mechanism, scaled: list[Array], rtol: float) -> tuple[Array, Array, Array]:
    """Singular values of the stacked wrenches and locked wrenches, and limb ratios, by batched SVD."""
    wrench_blocks, locked_blocks, ratios = [], [], []
    for limb, a in zip(mech.limbs, scaled):
        w, _, _ = _null_columns(a, rtol)
        wrench_blocks.append(w)
        norms = np.linalg.norm(a, axis=1, keepdims=True)
        unit_s = np.linalg.svd(a / np.where(norms > 0, norms, 1.0), compute_uv=False)
        ratios.append(_ratio(unit_s, limb.generic_twist_rank))
        if limb.actuated:
            keep = [c for c, name in enumerate(_column_joints(mech, limb)) if name not in limb.actuated]
            locked_blocks.append(_null_columns(a[:, :, keep], rtol)[0])
        else:
            locked_blocks.append(w)
    pad = lambda x: np.pad(x, ((0, 0), (0, 6 - x.shape[1])))  # noqa: E731
    s = np.linalg.svd(np.concatenate(wrench_blocks, axis=2), compute_uv=False)[:, :6]
    ls = np.linalg.svd(np.concatenate(locked_blocks, axis=2), compute_uv=False)[:, :6]
    return pad(s), pad(ls), np.stack(ratios, axis=1)


def _column_joints(mech: Mechanism, limb: Limb) -> list[str]:
    """Joint name of every velocity column of the limb."""
    out: list[str] = []
    for name in limb.joints:
        out += [name] * mech.model.joints[mech.model.getJointId(name)].nv
    return out
