"""Whole-mechanism mobility: closure Jacobian, redundant constraints, idle motions, actuation.

At a closed configuration q, stack the Jacobians of every closure residual
(:func:`pinmob.closure.closure_error`; limb tips welded to the platform count
as 6d closures) into ``K`` (rows, nv). Dimensionless form: length rows divided
by L, prismatic (linear) velocity columns multiplied by L, so that the rank
decision (:func:`pinmob.screw.decide_rank`, tolerance relative to sigma_max)
does not depend on units. Then

- mechanism DoF ``m = nv - rank K``: the closed chain's joint velocities are ``null K``;
- redundant (over-constraining) equations ``rows - rank K``; per closure c,
  independent of the order of declaration: ``essential_c = rank K - rank K_-c``
  (``K_-c``: K without c's rows), the constraint directions only c provides
  (removing c frees that many motions; 0 = c is not needed), and
  ``redundant_c = rows_c - essential_c``, its equations implied by the rest
  (its own other rows and the other closures). Two closures that repeat each
  other both count theirs, so these add up to at least ``rows - rank K``;
- Grubler-Kutzbach count ``sum f_joints - sum rows_closures = nv - rows``
  (``6 (n - 1 - j) + sum f`` with each closure as a joint of 6 - rows
  freedoms); it equals ``m`` only when no equation is redundant;
- idle motions: closed-chain motions that move no actuated joint, no output
  frame (the platform, else the tree's leaf bodies that carry no closure
  frame; frames named only to be reported are not outputs), no joint centre
  and no closure point; e.g. a rod spinning about the line through its two
  ball joints;
- actuation: with the actuated joints locked, the motions left
  (``locked_dof``, idle ones included) are all idle when the actuation is valid;
  actuated rates that are not independent on the closed chain over-determine it;
- the motion of any frame: the image of ``null K`` by its Jacobian, classified
  like the platform's (:func:`pinmob.screw.classify_twists`).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from .closure import (
    CLOSURE_TOL,
    closed_kinematics,
    joint_velocity_indices,
    linear_velocity_mask,
    stacked_error,
)
from .exceptions import ConfigurationError
from .mechanism import Mechanism, frame_id
from .mobility import Motion, _motions
from .screw import RTOL, Array, classify_twists, decide_rank, motion_type, twist_scaling

#: Largest number of actuator sets :func:`actuator_sets` tries (C(n, k) above it is refused).
SEARCH_LIMIT = 50_000


@dataclass(frozen=True)
class ClosureRank:
    """One closure's equations among all of them, independent of the order of declaration.

    Attributes:
        name, type: the closure.
        rows: its scalar equations.
        rank: rank of its own rows.
        essential: ``rank K - rank K_-c``: constraint directions no other closure
            provides; removing the closure frees this many motions.
    """

    name: str
    type: str
    rows: int
    rank: int
    essential: int

    @property
    def redundant(self) -> int:
        """Its equations implied by the rest (its own other rows and the other closures): ``rows - essential``."""
        return self.rows - self.essential

    @property
    def needed(self) -> bool:
        """Removing the closure changes the mechanism (``essential > 0``)."""
        return self.essential > 0

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "type": self.type,
            "rows": self.rows,
            "rank": self.rank,
            "essential": self.essential,
            "redundant": self.redundant,
            "needed": self.needed,
        }


@dataclass(frozen=True)
class FrameMobility:
    """How one frame can move on the closed chain: ``dof`` = rank of ``J_frame null(K)``."""

    frame: str
    dof: int
    motion_type: str
    motions: tuple[Motion, ...]
    free_twists: Array = field(repr=False)

    def to_dict(self) -> dict[str, Any]:
        return {
            "frame": self.frame,
            "dof": self.dof,
            "motion_type": self.motion_type,
            "motions": [m.to_dict() for m in self.motions],
        }


@dataclass(frozen=True)
class Actuation:
    """Validity of an actuator set at a configuration.

    Attributes:
        actuated: the actuated joints.
        valid: every motion left with them locked is idle, and they are independent.
        locked_dof: motions left with the actuated joints locked (idle ones included).
        idle_dof: idle motions among them.
        redundant_actuators: actuated rates implied by the others (> 0: over-determined).
        frame_dof: DoF of each end frame with the actuators locked (0 = rigid).
        remaining: the non-idle motions left, each as joint rates by name
            (largest 1, rates below 1e-6 dropped).
    """

    actuated: tuple[str, ...]
    valid: bool
    locked_dof: int
    idle_dof: int
    redundant_actuators: int
    frame_dof: dict[str, int]
    remaining: tuple[dict[str, float], ...]

    def to_dict(self) -> dict[str, Any]:
        return {
            "valid": self.valid,
            "locked_dof": self.locked_dof,
            "remaining": [dict(m) for m in self.remaining],
            "actuated": list(self.actuated),
            "idle_dof": self.idle_dof,
            "redundant_actuators": self.redundant_actuators,
            "overdetermined": self.redundant_actuators > 0,
            "frame_dof_locked": dict(self.frame_dof),
        }


@dataclass(frozen=True)
class MechanismMobility:
    """Mobility of the whole closed chain at one configuration (see the module docstring).

    ``end_frames`` are the output frames that idle motions leave at rest and
    that the actuation must control; ``frames`` the reported frame motions
    (the outputs first, then the frames named to be reported).
    """

    mechanism: str
    configuration: str | None
    nv: int
    rows: int
    rank: int
    mechanism_dof: int
    grubler: int
    closures: tuple[ClosureRank, ...]
    idle_dof: int
    idle_joints: tuple[str, ...]
    actuation: Actuation
    frames: tuple[FrameMobility, ...]
    end_frames: tuple[str, ...]
    singular_values: Array = field(repr=False)
    tolerance: float = 0.0
    length_scale: float = 1.0
    motions: Array = field(default_factory=lambda: np.zeros((0, 0)), repr=False)

    @property
    def redundant_constraints(self) -> int:
        return self.rows - self.rank

    @property
    def redundant_by_closure(self) -> dict[str, int]:
        """Per closure, its equations implied by the rest (:attr:`ClosureRank.redundant`); order-independent."""
        return {c.name: c.redundant for c in self.closures}

    def to_dict(self) -> dict[str, Any]:
        return {
            "mechanism": self.mechanism,
            "configuration": self.configuration,
            "nv": self.nv,
            "closure_rows": self.rows,
            "closure_rank": self.rank,
            "mechanism_dof": self.mechanism_dof,
            "idle_dof": self.idle_dof,
            "idle_joints": list(self.idle_joints),
            "redundant_constraints": self.redundant_constraints,
            "redundant_by_closure": self.redundant_by_closure,
            "grubler": self.grubler,
            "actuation": self.actuation.to_dict(),
            "redundant_by_closure_rule": (
                "per closure: rows minus the rank it alone adds to all the others (rank K - rank K without it); "
                "independent of the order of declaration"
            ),
            "closures": [c.to_dict() for c in self.closures],
            "end_frames": list(self.end_frames),
            "frames": [f.to_dict() for f in self.frames],
            "singular_values": [float(s) for s in self.singular_values],
            "tolerance": self.tolerance,
            "length_scale": self.length_scale,
        }

    def __str__(self) -> str:
        from .report import format_mechanism

        return format_mechanism(self)


# --------------------------------------------------------------------------- pieces


def default_end_frames(mech: Mechanism) -> tuple[str, ...]:
    """The platform if any; else the bodies at the leaves of the tree that carry no closure frame."""
    if mech.has_platform:
        return (mech.platform,)
    model = mech.model
    has_child = {int(model.parents[j]) for j in range(1, model.njoints)}
    closing = {model.frames[i].parentJoint for c in mech.all_closures for i in (c.frame_a_id, c.frame_b_id)}
    leaves = [j for j in range(1, model.njoints) if j not in has_child and j not in closing]
    out = []
    for j in leaves:
        bodies = [f.name for f in model.frames if f.parentJoint == j and f.type == pin.FrameType.BODY]
        out.append(bodies[0] if bodies else model.names[j])
    return tuple(out)


def _outputs(mech: Mechanism, data: pin.Data, frames: Sequence[str], col: Array) -> Array:
    """Dimensionless rows whose zero set defines idle motions: frame twists, joint centres, closure points."""
    model, length = mech.model, mech.length_scale
    rows = []
    for name in frames:
        rows.append(
            twist_scaling(length)[:, None]
            * pin.getFrameJacobian(model, data, frame_id(mech.model, name), pin.LOCAL_WORLD_ALIGNED)
        )
    for j in range(1, model.njoints):
        rows.append(pin.getJointJacobian(model, data, j, pin.LOCAL_WORLD_ALIGNED)[:3] / length)
    for c in mech.all_closures:  # a cut joint's centre; a 6d cut is inside one rigid body
        if c.type != "6d":
            rows.append(pin.getFrameJacobian(model, data, c.frame_a_id, pin.LOCAL_WORLD_ALIGNED)[:3] / length)
    return np.vstack(rows) * col if rows else np.zeros((0, model.nv))


def _selector(nv: int, idx: Array, col: Array) -> Array:
    sel = np.zeros((len(idx), nv))
    sel[np.arange(len(idx)), idx] = 1.0
    return sel * col  # rates in the dimensionless coordinates


def _joint_rates(mech: Mechanism, dq: Array) -> dict[str, float]:
    """Joint rates by name (largest magnitude 1, below 1e-6 dropped); multi-degree joints by their largest component."""
    model = mech.model
    big = float(np.max(np.abs(dq))) if dq.size else 0.0
    out: dict[str, float] = {}
    if big == 0:
        return out
    for j in range(1, model.njoints):
        joint = model.joints[j]
        part = dq[joint.idx_v : joint.idx_v + joint.nv] / big
        if part.size and np.max(np.abs(part)) > 1e-6:
            k = int(np.argmax(np.abs(part)))
            out[model.names[j]] = round(float(part[k]), 6)
    return dict(sorted(out.items(), key=lambda kv: -abs(kv[1])))


def _moving_joints(mech: Mechanism, basis: Array, tol: float = 1e-6) -> tuple[str, ...]:
    model = mech.model
    if basis.size == 0:
        return ()
    size = np.linalg.norm(basis, axis=1)
    top = float(size.max()) or 1.0
    return tuple(
        model.names[j]
        for j in range(1, model.njoints)
        if model.joints[j].nv
        and size[model.joints[j].idx_v : model.joints[j].idx_v + model.joints[j].nv].max() > tol * top
    )


def _split(matrix: Array, rtol: float, n: int) -> tuple[int, Array]:
    """Rank and (n, n - rank) orthonormal null-space basis of a dimensionless matrix.

    Unlike the closure Jacobian's decision, the tolerance is ``rtol * max(1, sigma_max)``:
    these matrices (joint rates and scaled twists of an orthonormal motion basis)
    are O(1) when they are not zero, and a zero one must have rank 0.
    """
    if matrix.size == 0:
        return 0, np.eye(n)
    _, s, vt = np.linalg.svd(matrix, full_matrices=True)
    rank = int(np.sum(s > rtol * max(1.0, float(s[0]))))
    return rank, vt[rank:].T


def _rank(matrix: Array, rtol: float) -> int:
    return _split(matrix, rtol, matrix.shape[1])[0] if matrix.size else 0


@dataclass(frozen=True)
class _Locked:
    """The closed-chain motions with some joints locked, and the idle ones among them (dimensionless bases)."""

    rank_a: int  # rank of the locked joints' rates on the closed chain
    locked: Array  # (m, l) motions that move no locked joint
    idle: Array  # (m, i) motions that move no locked joint and no output (a subspace of `locked`)

    def valid(self, count: int) -> bool:
        """``count`` locked joints are independent and leave only idle motions (a valid actuation)."""
        return self.rank_a == count and self.locked.shape[1] == self.idle.shape[1]


def _lock(rates: Array, outputs: Array, rtol: float, m: int) -> _Locked:
    """Split closed-chain motions by locked-joint rates ``rates`` (k, m) and output rows ``outputs`` (o, m).

    ``locked = null(rates)``, ``idle = null([rates; outputs])``: the one
    computation behind the actuation verdict, the idle joints and the
    actuator search.
    """
    rank_a, locked = _split(rates, rtol, m)
    _, idle = _split(np.vstack([rates, outputs]), rtol, m)
    return _Locked(rank_a, locked, idle)


# --------------------------------------------------------------------------- analysis


@dataclass(frozen=True)
class _Closed:
    """Kinematic data of a closed configuration shared by the analyses."""

    data: pin.Data
    col: Array  # (nv,) column scaling to dimensionless rates
    k_hat: Array  # (rows, nv) dimensionless closure Jacobian
    null: Array  # (nv, m) dimensionless basis of closed-chain motions


def _closed(mech: Mechanism, q: Array, rtol: float, closure_tol: float) -> tuple[_Closed, Any]:
    model = mech.model
    data = closed_kinematics(mech, q, closure_tol)
    col = np.where(linear_velocity_mask(model), mech.length_scale, 1.0)
    _, jac = stacked_error(mech, model, data, mech.all_closures)
    k_hat = jac * col
    dec = decide_rank(k_hat, rtol, n=model.nv)
    return _Closed(data, col, k_hat, dec.null_space.T), dec


def _actuation(
    mech: Mechanism, cl: _Closed, actuated: Sequence[str], split: _Locked, frames: Sequence[str], rtol: float
) -> Actuation:
    n = cl.null
    m = n.shape[1]
    locked, idle = split.locked, split.idle
    # non-idle remaining motions: an orthonormal basis of `locked` orthogonal to `idle`
    rest = locked - idle @ (idle.T @ locked)
    u, sv, _ = np.linalg.svd(rest, full_matrices=False) if rest.size else (np.zeros((m, 0)), np.zeros(0), None)
    remaining = [_joint_rates(mech, cl.col * (n @ u[:, i])) for i in range(int(np.sum(sv > 0.5)))]
    frame_dof = {name: _rank(_frame_rows(mech, cl, name) @ n @ locked, rtol) if locked.size else 0 for name in frames}
    locked_dof, idle_dof = locked.shape[1], idle.shape[1]
    return Actuation(
        tuple(actuated),
        split.valid(len(actuated)),
        locked_dof,
        idle_dof,
        len(actuated) - split.rank_a,
        frame_dof,
        tuple(remaining),
    )


def _frame_rows(mech: Mechanism, cl: _Closed, frame: str) -> Array:
    """(6, nv) dimensionless Jacobian of ``frame`` (twist per dimensionless joint rate)."""
    jac = pin.getFrameJacobian(mech.model, cl.data, frame_id(mech.model, frame), pin.LOCAL_WORLD_ALIGNED)
    return twist_scaling(mech.length_scale)[:, None] * jac * cl.col


def _frame_mobility(mech: Mechanism, cl: _Closed, frame: str, rtol: float) -> FrameMobility:
    length = mech.length_scale
    image = _frame_rows(mech, cl, frame) @ cl.null
    rank, _ = _split(image.T, rtol, 6)
    basis = np.linalg.svd(image, full_matrices=False)[0][:, :rank] if rank else np.zeros((6, 0))
    system = classify_twists(basis / twist_scaling(length)[:, None], length, rtol)
    motions = _motions(system)
    twists = np.column_stack([mo.twist for mo in motions]) if motions else np.zeros((6, 0))
    return FrameMobility(frame, basis.shape[1], motion_type(system), motions, twists)


def frame_mobility(
    mech: Mechanism, q: Array | str, frame: str, *, rtol: float = RTOL, closure_tol: float = CLOSURE_TOL
) -> FrameMobility:
    """Free motions of ``frame`` on the closed chain at q, at its origin with world axes.

    The image ``J_frame null(K)`` of every closed-chain motion (all closures,
    limb tips welded to the platform included), classified like the
    platform's (:func:`pinmob.screw.classify_twists`).

    Args:
        mech: the mechanism.
        q: configuration (nq,), or the name of one of ``mech.configurations``.
        frame: a frame of ``mech.model``.

    Raises:
        FrameError: no such frame (the message lists them).
        ClosureError: q does not close the loops.
    """
    q, _ = mech.resolve(q)
    frame_id(mech.model, frame)
    cl, _ = _closed(mech, q, rtol, closure_tol)
    return _frame_mobility(mech, cl, frame, rtol)


def _closure_ranks(mech: Mechanism, k_hat: Array, tolerance: float) -> tuple[ClosureRank, ...]:
    """Per closure: own rank and ``rank K - rank K_-c``, all with the absolute tolerance of K's decision."""

    def rank(rows: Array) -> int:
        return int(np.sum(np.linalg.svd(rows, compute_uv=False) > tolerance)) if rows.size and tolerance > 0 else 0

    total = rank(k_hat)
    out, start = [], 0
    for c in mech.all_closures:
        own = np.arange(start, start + c.rows)
        others = np.delete(k_hat, own, axis=0)
        out.append(ClosureRank(c.name, c.type, c.rows, rank(k_hat[own]), total - rank(others)))
        start += c.rows
    return tuple(out)


def analyze_mechanism(
    mech: Mechanism,
    q: Array | str,
    *,
    actuated: Sequence[str] | None = None,
    frames: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
    configuration: str | None = None,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
) -> MechanismMobility:
    """Mobility of the whole closed chain at a closed configuration.

    Args:
        mech: the mechanism.
        q: configuration (nq,), or the name of one of ``mech.configurations``.
        actuated: actuated joints (default: the mechanism's declared ones).
        frames: frames whose motion is reported besides the outputs; naming
            them changes no count or verdict.
        outputs: frames that idle motions must leave at rest and that the
            actuation must control (default :func:`default_end_frames`: the
            platform, else the tree's free leaf bodies).
        rtol: relative tolerance of every rank decision.

    Raises:
        ClosureError: q does not close the loops.
        FrameError: a frame does not exist.
    """
    q, configuration = mech.resolve(q, configuration)
    actuated = tuple(mech.actuated if actuated is None else actuated)
    outs = tuple(default_end_frames(mech) if outputs is None else outputs)
    reported = outs + tuple(f for f in dict.fromkeys(frames or ()) if f not in outs)
    for name in reported:
        frame_id(mech.model, name)
    cl, dec = _closed(mech, q, rtol, closure_tol)
    idx = joint_velocity_indices(mech, list(actuated))
    split = _lock(
        _selector(mech.model.nv, idx, cl.col) @ cl.null,
        _outputs(mech, cl.data, outs, cl.col) @ cl.null,
        rtol,
        cl.null.shape[1],
    )
    rows = int(cl.k_hat.shape[0])
    return MechanismMobility(
        mechanism=mech.name,
        configuration=configuration,
        nv=mech.model.nv,
        rows=rows,
        rank=dec.rank,
        mechanism_dof=mech.model.nv - dec.rank,
        grubler=mech.model.nv - rows,
        closures=_closure_ranks(mech, cl.k_hat, dec.tolerance),
        idle_dof=split.idle.shape[1],
        idle_joints=_moving_joints(mech, cl.null @ split.idle),
        actuation=_actuation(mech, cl, actuated, split, reported, rtol),
        frames=tuple(_frame_mobility(mech, cl, f, rtol) for f in reported),
        end_frames=outs,
        singular_values=dec.singular_values,
        tolerance=dec.tolerance,
        length_scale=mech.length_scale,
        motions=cl.col[:, None] * cl.null,
    )


def actuator_sets(
    mech: Mechanism,
    q: Array,
    size: int,
    *,
    candidates: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
    rtol: float = RTOL,
    limit: int = SEARCH_LIMIT,
) -> list[tuple[str, ...]]:
    """Every valid set of ``size`` actuated joints among ``candidates`` (default: all one-degree joints).

    A set is valid when its joints are independent on the closed chain and
    locking them leaves only idle motions (those that move no output frame,
    default :func:`default_end_frames`; the same split as
    :func:`analyze_mechanism`'s actuation verdict). Exhaustive: C(n, size)
    sets are tried, each with SVDs of (size, m) and (size + outputs, m)
    matrices; more than ``limit`` sets is refused (name fewer candidates).

    Raises:
        ConfigurationError: size out of range or too many combinations.
    """
    model = mech.model
    names = (
        list(candidates)
        if candidates is not None
        else [model.names[j] for j in range(1, model.njoints) if model.joints[j].nv == 1]
    )
    if not 0 < size <= len(names):
        raise ConfigurationError(f"actuator set size must be in 1..{len(names)} (the candidate joints), got {size}")
    count = math.comb(len(names), size)
    if count > limit:
        raise ConfigurationError(
            f"{count} sets of {size} among {len(names)} joints exceed the search limit {limit}; name fewer candidate joints"
        )
    outs = tuple(default_end_frames(mech) if outputs is None else outputs)
    cl, _ = _closed(mech, mech.check_q(q), rtol, CLOSURE_TOL)
    n = cl.null
    rates = _selector(model.nv, joint_velocity_indices(mech, names), cl.col) @ n  # (len(names), m)
    out = _outputs(mech, cl.data, outs, cl.col) @ n
    valid = []
    for combo in itertools.combinations(range(len(names)), size):
        split = _lock(rates[list(combo)], out, rtol, n.shape[1])
        if split.valid(size):
            valid.append(tuple(names[i] for i in combo))
    return valid
