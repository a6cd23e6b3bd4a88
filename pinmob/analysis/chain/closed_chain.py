"""The closure Jacobian of the whole mechanism and the closed chain's motions.

At a closed configuration, stack the Jacobians of every closure residual
(:func:`pinmob.assembly.residual.closure_error`; limb tips welded to the
platform count as 6d closures) into ``K`` (rows, nv). Dimensionless form
``K_hat``: length rows divided by L, prismatic (linear) velocity columns
multiplied by L (``col``), so that the rank decision does not depend on units.
The closed chain's joint velocities are ``null(K)``; any frame's motions are
their image by its Jacobian.

:func:`~pinmob.analysis.chain.closure_jacobian_twists.closure_jacobian_twists` is a second, independent
computation of the platform's free twists (the tests compare it with the limb-wise method).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pinmob.analysis.chain.joint_centres import joint_centres
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.limbs import rate_scale
from pinmob.assembly import stacked_error
from pinmob.model import Mechanism, frame_id, velocity_spans
from pinmob.screw import Array, Mask, RankDecision, decide_rank, decision, svd, twist_scaling


@dataclass(frozen=True)
class ClosedChain:
    """The closure Jacobian at a configuration and the closed chain's motions (dimensionless).

    Attributes:
        col: (nv,) column scaling to dimensionless rates (L on prismatic rates, 1 elsewhere).
        k_hat: (rows, nv) dimensionless closure Jacobian.
        decision: the rank decision on ``k_hat``.
        left_null: (rows, rows - rank) orthonormal basis of ``{y : y^T K_hat = 0}``, the dependencies
            among the closure equations (the left singular vectors beyond the rank, from the same SVD).
    """

    col: Array
    k_hat: Array
    decision: RankDecision
    left_null: Array

    @property
    def null(self) -> Array:
        """(nv, m) orthonormal basis of the closed chain's dimensionless joint rates (``null(K_hat)``)."""
        return self.decision.null_space.T


def closed_chain(conf: Configuration, rtol: float) -> ClosedChain:
    """The :class:`ClosedChain` at ``conf`` (cached per tolerance).

    K_hat is dimensionless (unit axes, lever arms per L), so its natural scale is 1: the rank tolerance is
    ``rtol * max(1, sigma_1)``. A closure whose rows are all round-off (a hinge closed about its own axis, a
    ball at a point its joints cannot move) adds no constraint, wherever the mechanism stands; relative to
    sigma_1 alone, its 1e-16 rows were counted at the origin and not 10 m away.
    """

    def compute() -> ClosedChain:
        mech = conf.mechanism
        model = mech.model
        col = closed_chain_columns(conf)
        _, jac = stacked_error(mech, model, conf.data, mech.all_closures)
        k_hat = jac * col
        if not k_hat.size:
            return ClosedChain(
                col, k_hat, decide_rank(k_hat, rtol, n=model.nv, at_least=1.0), np.zeros((k_hat.shape[0], 0))
            )
        u, s, vt = svd(k_hat)  # full U and V: the null space and the left null space
        dec = decision(s, vt, rtol, at_least=1.0)  # natural scale 1: a K of round-off only has rank 0
        return ClosedChain(col, k_hat, dec, u[:, dec.rank :])

    return conf.memo(("closed_chain", rtol), compute)


def frame_rows(conf: Configuration, frame: str) -> Array:
    """(6, nv) dimensionless Jacobian of ``frame`` (twist ``[v / L; w]`` per dimensionless joint rate; cached)."""
    mech = conf.mechanism

    def compute() -> Array:
        jac = conf.frame_jacobian(frame_id(mech.model, frame))
        rows = twist_scaling(mech.length_scale)[:, None] * jac * closed_chain_columns(conf)
        rows.flags.writeable = False
        return rows

    return conf.memo(("frame rows", frame), compute)


def closed_chain_columns(conf: Configuration) -> Array:
    """(nv,) the column scaling to dimensionless rates: L on prismatic rates, 1 elsewhere (:func:`~pinmob.analysis.limbs.rate_scale`)."""
    return rate_scale(conf.mechanism)


def output_rows(conf: Configuration, frames: Sequence[str]) -> Array:
    """Dimensionless rows whose zero set defines idle motions: frame twists, joint centres, closure points.

    An idle motion moves no output frame, no joint centre and no closure point
    (e.g. a rod spinning about the line through its two ball joints). A joint
    centre's rows are ``(v_i - p_j x w_i) col_i / L`` for the joints i that
    support joint j (the linear rows of Pinocchio's ``LOCAL_WORLD_ALIGNED``
    joint Jacobian, computed here from the world Jacobian for every joint at
    once), 0 for the others. The analyses take these rows times the motions
    from :func:`output_motions` (the tests compare the two).
    """
    mech = conf.mechanism
    model, length = mech.model, mech.length_scale
    col = closed_chain_columns(conf)
    support = supported_columns(mech)  # (njoints - 1, nv)
    points = closure_points(mech)
    out = np.empty((6 * len(frames) + 3 * support.shape[0] + 3 * len(points), model.nv))
    for i, name in enumerate(frames):
        out[6 * i : 6 * i + 6] = frame_rows(conf, name)
    start = 6 * len(frames)
    if support.shape[0]:
        world = conf.world_jacobian
        v, w = world[:3], world[3:]
        p = joint_centres(conf)
        centres = out[start : start + 3 * support.shape[0]].reshape(support.shape[0], 3, model.nv)
        centres[:, 0] = v[0] - (p[:, 1:2] * w[2] - p[:, 2:3] * w[1])
        centres[:, 1] = v[1] - (p[:, 2:3] * w[0] - p[:, 0:1] * w[2])
        centres[:, 2] = v[2] - (p[:, 0:1] * w[1] - p[:, 1:2] * w[0])
        centres *= col
        centres /= length
        np.copyto(centres, 0.0, where=~support[:, None, :])  # the columns of the joints that do not support it: 0
        start += 3 * support.shape[0]
    for k, fid in enumerate(points):
        out[start + 3 * k : start + 3 * k + 3] = conf.frame_jacobian(fid)[:3] * col / length
    return out


def output_motions(conf: Configuration, frames: Sequence[str], motions: Array) -> Array:
    """(o, m) ``output_rows(conf, frames) @ motions`` without the (o, nv) rows (dimensionless).

    Joint centre j's rows times the motions: ``A_j sum_i S_ji s_i``, with ``s_i = J_i col_i motions_i``
    (6, m) the screw of velocity component i (world origin, world axes) times its rates in the motions,
    S the support mask (:func:`supported_columns`) and ``A_j = [I, -[p_j]x] / L`` (3, 6) the shift to
    the centre p_j (:func:`centre_shifts`): one product of S with the (nv, 6 m) screws and a batch of
    (3, 6) products instead of the (3 (njoints - 1), nv) rows; the same numbers up to round-off (the
    sums in another order). Tested against :func:`output_rows` on every built-in model.

    Args:
        conf: the configuration.
        frames: the output frames (their twists' rows first, as in :func:`output_rows`).
        motions: (nv, m) dimensionless joint rates (the closed chain's motions).
    """
    mech = conf.mechanism
    nv, m = motions.shape
    col = closed_chain_columns(conf)
    parts = [frame_rows(conf, name) @ motions for name in frames]
    support = supported_float(mech)  # (njoints - 1, nv)
    if support.shape[0]:
        screws = ((conf.world_jacobian * col).T[:, :, None] * motions[:, None, :]).reshape(nv, 6 * m)
        joints = support.shape[0]
        parts.append((centre_shifts(conf) @ (support @ screws).reshape(joints, 6, m)).reshape(3 * joints, m))
    parts += [conf.frame_jacobian(fid)[:3] * col / mech.length_scale @ motions for fid in closure_points(mech)]
    return np.vstack(parts) if parts else np.zeros((0, m))


def centre_shifts(conf: Configuration) -> Array:
    """(njoints - 1, 3, 6) per joint j, ``[I, -[p_j]x] / L``: a screw at the world origin to its centre's velocity per L.

    ``(v - p_j x w) / L`` for a screw ``[v; w]``; the entries are linear in p_j, so all joints' come from one
    product with a constant (3, 18) matrix (cached).
    """

    def compute() -> Array:
        length = conf.mechanism.length_scale
        out = (joint_centres(conf) @ _SKEW + _IDENTITY) / length
        out = out.reshape(-1, 3, 6)
        out.flags.writeable = False
        return out

    return conf.memo("centre shifts", compute)


# [I, -[p]x] flattened (18,): the identity part, and the (3, 18) map from p to -[p]x
_IDENTITY = np.zeros(18)
_IDENTITY[[0, 7, 14]] = 1.0
_SKEW = np.zeros((3, 18))
_SKEW[[2, 1, 2, 0, 1, 0], [4, 5, 9, 11, 15, 16]] = [1.0, -1.0, -1.0, 1.0, 1.0, -1.0]


def closure_points(mech: Mechanism) -> tuple[int, ...]:
    """The frames (indices) whose origin is a cut joint's centre: frame a of each closure but ``6d`` and couplings."""
    return mech.memo(
        "closure points", lambda: tuple(c.frame_a_id for c in mech.all_closures if c.type != "6d" and not c.is_coupling)
    )


def supported_float(mech: Mechanism) -> Array:
    """:func:`supported_columns` as 1.0 and 0.0, to multiply with (read-only, once per mechanism)."""

    def compute() -> Array:
        out = supported_columns(mech).astype(float)
        out.flags.writeable = False
        return out

    return mech.memo("supported columns, float", compute)


def supported_columns(mech: Mechanism) -> Mask:
    """(njoints - 1, nv) True where velocity component i belongs to a joint supporting joint j (1..njoints-1).

    The columns a joint's own Jacobian fills (its path to the root); read-only, computed once per mechanism.
    """

    def compute() -> Mask:
        model = mech.model
        out = np.zeros((model.njoints - 1, model.nv), dtype=bool)
        for j in range(1, model.njoints):
            for s in model.supports[j]:
                joint = model.joints[s]
                if s and joint.nv:
                    out[j - 1, joint.idx_v : joint.idx_v + joint.nv] = True
        out.flags.writeable = False
        return out

    return mech.memo("supported columns", compute)


def rates_of(motions: Array, idx: NDArray[Any]) -> Array:
    """(len(idx), m) the rates ``idx`` of closed-chain motions (nv, m), in the dimensionless coordinates: ``motions[idx]``.

    The closed chain's motions are dimensionless rates (prismatic rates per L): a rate scaled by L
    would weigh a slider's rate by the unit of length against the output rows (in nanometres it
    outweighed every output and idle motions appeared; far enough the other way it would vanish).
    Picking the rows gives the numbers a selector matrix ``S`` (one unit row per index) times ``motions`` gives,
    without the product.
    """
    return motions[np.asarray(idx, dtype=np.intp)]


def moving_joints(mech: Mechanism, basis: Array, tol: float = 1e-6) -> tuple[str, ...]:
    """Joints with a rate above ``tol`` times the largest in the motions ``basis`` (nv, k)."""
    model = mech.model
    if basis.size == 0:
        return ()
    size = np.linalg.norm(basis, axis=1)
    top = float(size.max()) or 1.0
    joints, starts = velocity_spans(model)
    largest = np.maximum.reduceat(size, starts) if starts.size else np.zeros(0)
    return tuple(model.names[int(j)] for j, big in zip(joints, largest) if big > tol * top)
