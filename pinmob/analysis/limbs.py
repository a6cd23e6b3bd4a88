"""Each limb's joint screws at a configuration, and the rank decisions on them.

A limb's joint screws are the columns of the world Jacobian ``data.J`` (every
joint screw ``[v; w]`` at the world origin, world axes) for its joints, carried to
the platform origin p by ``v += w x p``: the columns of its tip frame's
``LOCAL_WORLD_ALIGNED`` Jacobian carried to p. A limb with loops inside it (a
parallelogram closed by a ``3d`` closure) moves only along the joint rates that
keep those loops closed (:func:`limb_rates`). The same function serves one
configuration and a batch of them (:func:`limb_screws_at`).

Every screw is per unit *dimensionless* rate: a prismatic joint's rate [m/s] is
counted in L per second (its column times L, :func:`rate_scale`), a revolute's
in rad/s. So the columns ``[v / L; w]`` that every rank decision sees are the
same numbers whatever the unit of length (a prismatic column per metre would be
``1 / L`` against a revolute's ``1``: in micrometres the sliders would vanish
below the tolerance, in kilometres the revolutes).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pinmob.analysis.configuration import Configuration
from pinmob.assembly import stacked_error
from pinmob.frozen import ReadOnlyArrays
from pinmob.model import Limb, Mechanism, linear_velocity_mask
from pinmob.screw import Array, RankDecision, decide_rank, decide_ranks, twist_scaling, wrench_scaling

#: Integer index array.
Indices = NDArray[np.intp]


def rate_scale(mech: Mechanism) -> Array:
    """(nv,) per velocity component: L [m] on translations (prismatic rates), 1 on rotations (read-only, per mechanism).

    A joint screw times its entry is the screw per unit dimensionless rate (see the module docstring).
    """

    def compute() -> Array:
        out = np.where(linear_velocity_mask(mech.model), mech.length_scale, 1.0)
        out.flags.writeable = False
        return out

    return mech.memo("rate scale", compute)


def limb_screws_at(world: Array, origin: Array, columns: NDArray[Any], rates: Array | None = None) -> Array:
    """Joint screws carried to a point: ``[v + w x p; w]`` of the chosen world Jacobian columns, times ``rates``.

    Args:
        world: (..., 6, nv) world Jacobians (screws at the world origin, world axes).
        origin: (..., 3) the point p [m] (the platform origin).
        columns: (k,) velocity indices.
        rates: (k, m) joint-rate directions (None: the identity).

    Returns:
        (..., 6, m) the screws at p [m/s, rad/s per unit rate].
    """
    cols = world[..., columns]
    w = cols[..., 3:, :]
    p = origin[..., :, None]
    v = cols[..., :3, :] + np.stack(
        [w[..., 1, :] * p[..., 2, :] - w[..., 2, :] * p[..., 1, :],
         w[..., 2, :] * p[..., 0, :] - w[..., 0, :] * p[..., 2, :],
         w[..., 0, :] * p[..., 1, :] - w[..., 1, :] * p[..., 0, :]],
        axis=-2,
    )  # fmt: skip
    screws = np.concatenate([v, w], axis=-2)
    return screws if rates is None else screws @ rates


def limb_rates(conf: Configuration, limb: Limb, rtol: float, locked: tuple[str, ...] = ()) -> tuple[Array, Array]:
    """Joint-rate directions behind a limb's screws: velocity indices E (e,) and rates D (e, k).

    Without internal loops, E are the limb's velocity indices minus those of
    the ``locked`` joints and D = diag(col), one dimensionless rate per joint. With internal closures, E are its
    joints and loop joints (:attr:`Limb.screw_v_indices`) and
    ``D = diag(col) N``, N an orthonormal basis of
    ``null([K_hat[:, E]; S_locked])`` (closure rows per L, prismatic rates
    times L, so ``col`` is L on prismatic rates and 1 elsewhere; rank decided
    with ``rtol``): the rates that keep the loops closed to first order.
    """
    mech = conf.mechanism
    model = mech.model
    held = {model.joints[model.getJointId(j)].idx_v for j in locked}
    if not limb.closures:
        idx = np.array([int(v) for v in limb.v_indices if v not in held], dtype=int)
        return idx, np.diag(rate_scale(mech)[idx])
    idx = limb.screw_v_indices
    col = rate_scale(mech)[idx]
    loops = tuple(c for c in mech.closures if c.name in limb.closures)
    _, k = stacked_error(mech, model, conf.data, loops)
    rows = np.vstack([k[:, idx] * col, np.eye(idx.size)[[i for i, v in enumerate(idx) if v in held]]])
    return idx, col[:, None] * decide_rank(rows, rtol, n=idx.size).null_space.T


def limb_screws(
    conf: Configuration,
    limb: Limb,
    rtol: float,
    point: Array,
    locked: tuple[str, ...] = (),
    world: Array | None = None,
) -> Array:
    """A limb's joint screws at ``point`` [m], (6, k): per dimensionless joint rate, or loop-closing rate (:func:`limb_rates`).

    Only the joints that support the tip move it: a loop joint (e.g. a parallelogram's second rod) acts
    through the rates that keep the loops closed, not through a screw of its own.
    """
    world = conf.world_jacobian if world is None else world
    idx, rates = limb_rates(conf, limb, rtol, locked)
    if not limb.closures:
        return limb_screws_at(world, point, idx) * rate_scale(conf.mechanism)[idx]
    own = limb.v_indices.size  # the rates' first rows are the limb's own joints (Limb.screw_v_indices)
    return limb_screws_at(world, point, limb.v_indices, rates[:own])


def limb_twists(conf: Configuration, rtol: float, lock_actuated: bool = False) -> tuple[Array, ...]:
    """Joint screws of each limb, (6, n_i) each, per unit dimensionless rate, at the platform origin, world axes.

    Each limb's world Jacobian columns carried to the platform origin
    (:func:`limb_screws_at`), restricted to the rates that keep its internal
    loops closed (:func:`limb_rates`); with ``lock_actuated``, also its
    actuated joints still. Limbs with loops give screws per unit
    dimensionless rate. The limbs without loops are carried in one call (the
    screws are computed column by column: the same as one limb at a time), and
    their locked screws are the columns of the unlocked ones. Cached per configuration.
    """

    def compute() -> tuple[Array, ...]:
        mech = conf.mechanism
        world, origin = conf.world_jacobian, conf.platform_origin
        columns, bounds, kept = open_limb_columns(mech)
        every = limb_screws_at(world, origin, columns) * rate_scale(mech)[columns]
        every.flags.writeable = False
        out = []
        for limb, (start, stop), keep in zip(mech.limbs, bounds, kept):
            if limb.closures:
                out.append(
                    limb_screws(conf, limb, rtol, origin, mech.limb_actuators(limb) if lock_actuated else (), world)
                )
            else:
                out.append(every[:, keep] if lock_actuated else every[:, start:stop])
        return tuple(out)

    return conf.memo(("limb_twists", rtol, lock_actuated), compute)


def open_limb_columns(mech: Mechanism) -> tuple[Indices, list[tuple[int, int]], list[Indices]]:
    """Velocity indices of the limbs without loops, end to end; each limb's slice of them; its unactuated positions.

    Computed once per mechanism (limbs with loops get an empty slice).
    """

    def compute() -> tuple[Indices, list[tuple[int, int]], list[Indices]]:
        model = mech.model
        columns: list[int] = []
        bounds, kept = [], []
        for limb in mech.limbs:
            start = len(columns)
            if not limb.closures:
                held = {model.joints[model.getJointId(j)].idx_v for j in limb.actuated}
                columns += [int(v) for v in limb.v_indices]
                kept.append(np.array([start + k for k, v in enumerate(limb.v_indices) if v not in held], dtype=np.intp))
            else:
                kept.append(np.zeros(0, dtype=np.intp))
            bounds.append((start, len(columns)))
        return np.array(columns, dtype=np.intp), bounds, kept

    return mech.memo("open limb columns", compute)


def unit_columns(matrix: Array) -> Array:
    """The columns scaled to unit length (zero columns kept): ``A_i`` free of the joints' rate units."""
    norms = np.linalg.norm(matrix, axis=-2, keepdims=True)
    return matrix / np.where(norms > 0, norms, 1.0)


def limb_decisions(mech: Mechanism, twists: tuple[Array, ...] | list[Array], rtol: float) -> list[RankDecision]:
    """Rank decision on each limb's joint screws ``U_i`` (dimensionless, unit columns), transposed.

    Its rank is the limb's twist rank, its null space the limb's wrench basis
    ``W_i`` (dimensionless, orthonormal). A limb with loops inside it: its
    screws are ``[v / L; w]`` per orthonormal basis of the dimensionless
    loop-closing rates (:func:`limb_rates`), taken as they are: their singular
    values do not depend on which basis, while unit columns would.
    """
    st = twist_scaling(mech.length_scale)[:, None]
    return decide_ranks(
        [(st * t if limb.closures else unit_columns(st * t)).T for limb, t in zip(mech.limbs, twists)], rtol, n=6
    )


def wrench_blocks(decisions: list[RankDecision]) -> list[Array]:
    """Dimensionless orthonormal wrench bases ``W_i`` (6, 6 - r_i)."""
    return [d.null_space.T for d in decisions]


def column_joints(mech: Mechanism, limb: Limb) -> list[str]:
    """Joint name of every velocity column of the limb."""
    out: list[str] = []
    for name in limb.joints:
        out += [name] * mech.model.joints[mech.model.getJointId(name)].nv
    return out


@dataclass(frozen=True)
class LimbMobility(ReadOnlyArrays):
    """What one limb contributes at the configuration.

    Attributes:
        name, joints: the limb.
        twist_rank: rank of its joint screws here (with its internal loops closed).
        generic_twist_rank: rank at generic joint values; lower here = serial singularity.
        wrenches: (6, 6 - twist_rank) its constraint wrenches ``[f; tau]``.
        closures: its internal closures (:attr:`pinmob.model.limb.Limb.closures`).
        loop_joints: the joints in no limb that they involve.
    """

    name: str
    joints: tuple[str, ...]
    twist_rank: int
    generic_twist_rank: int
    wrenches: Array = field(repr=False)
    closures: tuple[str, ...] = ()
    loop_joints: tuple[str, ...] = ()

    @property
    def wrench_count(self) -> int:
        """Number of constraint wrenches the limb exerts here."""
        return int(self.wrenches.shape[1])

    @property
    def serially_singular(self) -> bool:
        """Its twist rank is below the generic one (a serial singularity)."""
        return self.twist_rank < self.generic_twist_rank

    def to_dict(self) -> dict[str, Any]:
        """One entry of ``limbs`` in the JSON document."""
        return {
            "name": self.name,
            "joints": list(self.joints),
            "twist_rank": self.twist_rank,
            "generic_twist_rank": self.generic_twist_rank,
            "wrench_count": self.wrench_count,
            "serially_singular": self.serially_singular,
            "closures": list(self.closures),
            "loop_joints": list(self.loop_joints),
        }

    def line(self) -> str:
        """``  A: 5 joints, twist rank 5 (generic 5), 1 constraint wrench(es)`` (+ loops, singular flag)."""
        flag = "  <- serial singularity" if self.serially_singular else ""
        loops = (
            f" + {len(self.loop_joints)} loop joint(s), closed by {', '.join(self.closures)}" if self.closures else ""
        )
        return (
            f"  {self.name}: {len(self.joints)} joints{loops}, twist rank {self.twist_rank} "
            f"(generic {self.generic_twist_rank}), {self.wrench_count} constraint wrench(es){flag}"
        )


def limbwise_obstacle(mech: Mechanism) -> str:
    """Why the limb-wise method cannot be used on ``mech`` ("" when it can)."""
    if not mech.limbs:
        return f"{mech.name!r} is described by closures only (no limbs)"
    coupling = mech.coupling_closures
    if not coupling:
        return ""
    return "; ".join(f"closure {c!r} couples limbs {', '.join(limbs)}" for c, limbs in coupling.items())


def limb_wrenches(conf: Configuration, rtol: float) -> list[tuple[Array, int]]:
    """Per limb: its constraint wrenches (6, 6 - r_i), reciprocal to its joint screws, and its twist rank r_i.

    :func:`~pinmob.screw.rank.reciprocal_wrenches` of each limb's screws, the limbs' rank decisions in one
    batched SVD per shape (:func:`~pinmob.screw.rank.decide_ranks`).
    """
    length = conf.mechanism.length_scale

    def compute() -> list[tuple[Array, int]]:
        st, sw = twist_scaling(length)[:, None], wrench_scaling(length)[:, None]
        decisions = decide_ranks([(st * t).T for t in limb_twists(conf, rtol)], rtol, n=6)
        return [(dec.null_space.T / sw, dec.rank) for dec in decisions]

    return conf.memo(("limb_wrenches", rtol), compute)
