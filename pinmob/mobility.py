"""Platform mobility at a closed configuration (the seed paper's method, done right).

For each limb i with joint screws ``T_i`` (6, n_i) -- the columns of its tip
frame's ``LOCAL_WORLD_ALIGNED`` Jacobian, carried to the platform origin -- the
constraint wrenches are a basis ``W_i`` of ``{w : w^T T_i = 0}``. Stacking them,
``C = [W_1 ... W_k]^T``, an SVD gives the constraint space (rank d) and the free
twists ``{t : C t = 0}`` (dimension 6 - d). All on dimensionless matrices
(:mod:`pinmob.screw`), so the answer does not depend on units.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np
import pinocchio as pin

from .closure import CLOSURE_TOL, closed_kinematics, compute_kinematics, linear_velocity_mask, stacked_error
from .exceptions import ConfigurationError, choices
from .mechanism import Limb, Mechanism
from .screw import (
    RTOL,
    Array,
    MotionKind,
    ScrewSystem,
    WrenchKind,
    axis_label,
    classify_twists,
    classify_wrenches,
    clean,
    decide_rank,
    motion_type,
    reciprocal_twists,
    reciprocal_wrenches,
    shift_twists,
    twist_scaling,
    wrench_scaling,
)

VIEWS = ("configuration", "paper")


class Method(StrEnum):
    """How the platform's constraint space was obtained."""

    LIMB_WISE = "limb-wise"  # stacked limb wrenches (the seed paper's method)
    CLOSURE_JACOBIAN = "closure Jacobian"  # image of the whole closed chain's motions


#: name of the configuration the paper view comes from when none is declared
GENERIC = "generic"


def _vec(a: Array | None) -> list[float] | None:
    return None if a is None else [float(x) for x in a]


def check_rtol(rtol: object, name: str = "rtol") -> float:
    """A validated relative rank tolerance: a finite real number with ``0 < rtol < 1``.

    Singular values below ``rtol * sigma_max`` count as zero, so ``rtol <= 0``
    would call round-off a motion and ``rtol >= 1`` would drop real ones.

    Args:
        rtol: the tolerance to check (dimensionless).
        name: how the caller calls it in the message (``--rtol`` for the CLI).

    Raises:
        ConfigurationError: not a real number, not finite, or outside (0, 1).
    """
    if isinstance(rtol, bool) or not isinstance(rtol, (int, float, np.integer, np.floating)):
        raise ConfigurationError(f"{name} must be a number in (0, 1), got {rtol!r} ({type(rtol).__name__})")
    value = float(rtol)
    if not (np.isfinite(value) and 0.0 < value < 1.0):
        raise ConfigurationError(f"{name} must be a finite number in (0, 1), e.g. {RTOL:g}; got {rtol!r}")
    return value


def resolve(
    mech: Mechanism, q: Array | str, configuration: str | None, closure_tol: float = CLOSURE_TOL
) -> tuple[Array, str | None]:
    """:meth:`Mechanism.resolve` that assembles or checks a named configuration with ``closure_tol``."""
    if isinstance(q, str):
        return mech.resolve(mech.configuration(q, closure_tol), configuration or q)
    return mech.resolve(q, configuration)


@dataclass(frozen=True)
class Motion:
    """One free motion of the platform (SI units, Pinocchio order).

    Attributes:
        kind: T (translation), R (rotation) or H (screw).
        direction: (3,) unit direction (of translation, or of the axis).
        point: (3,) axis point closest to the platform origin [m] (None for T).
        pitch: [m/rad] (None for T, 0 for R).
        twist: (6,) unit twist ``[v; w]`` at the platform origin.
        label: short name such as ``T1 x`` or ``R1 z``.
    """

    kind: MotionKind
    direction: Array
    point: Array | None
    pitch: float | None
    twist: Array
    label: str

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind.value,
            "label": self.label,
            "direction": _vec(self.direction),
            "point": _vec(self.point),
            "pitch": self.pitch,
        }


@dataclass(frozen=True)
class Constraint:
    """One canonical constraint wrench: a couple, a force (pitch 0) or a wrench (SI units, Pinocchio order).

    Attributes:
        kind: couple, force or wrench.
        direction: (3,) unit direction (of the couple's moment, or of the force).
        point: (3,) point of the force's line closest to the platform origin [m] (None for a couple).
        pitch: [m/rad] (None for a couple, 0 for a force).
        wrench: (6,) unit wrench ``[f; tau]`` at the platform origin.
    """

    kind: WrenchKind
    direction: Array
    point: Array | None
    pitch: float | None
    wrench: Array

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind.value,
            "direction": _vec(self.direction),
            "point": _vec(self.point),
            "pitch": self.pitch,
            "wrench": _vec(self.wrench),
        }


@dataclass(frozen=True)
class LimbMobility:
    """What one limb contributes at the configuration.

    Attributes:
        name, joints: the limb.
        twist_rank: rank of its joint screws here (with its internal loops closed).
        generic_twist_rank: rank at generic joint values; lower here = serial singularity.
        wrenches: (6, 6 - twist_rank) its constraint wrenches ``[f; tau]``.
        closures: its internal closures (:attr:`pinmob.mechanism.Limb.closures`).
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
        return int(self.wrenches.shape[1])

    @property
    def serially_singular(self) -> bool:
        return self.twist_rank < self.generic_twist_rank

    def to_dict(self) -> dict[str, Any]:
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


@dataclass(frozen=True)
class Mobility:
    """Mobility of the platform at one configuration.

    Attributes:
        mechanism, configuration: names (configuration may be None).
        dof: number of independent free motions, ``6 - constraint_rank``.
        motion_type: label such as ``3T``, ``3T1R``, ``1T1R1H`` or ``rigid``.
        motions: canonical free motions (translations, rotations, screws by pitch).
        free_twists: (6, dof) the motions' unit twists as columns.
        constraints: canonical constraint wrenches.
        constraint_wrenches: (6, d) their wrenches ``[f; tau]`` as columns.
        constraint_rank: d.
        singular_values: (6,) of the stacked dimensionless limb wrenches (zero-padded);
            with the closure-Jacobian method, of an orthonormal basis of the
            constraint space (ones, then zeros).
        tolerance: absolute threshold applied to ``singular_values``.
        length_scale: L [m].
        platform_origin: (3,) world position of the platform frame [m].
        limbs: per-limb details.
        view: ``configuration`` (wrenches at q) or ``paper`` (generic limb wrenches carried to q).
        method: :class:`Method` used; ``closure Jacobian`` when a closure couples
            limbs or there is no limb (``limbs`` is then empty).
        method_note: why that method was used (empty for the limb-wise method).
    """

    mechanism: str
    configuration: str | None
    dof: int
    motion_type: str
    motions: tuple[Motion, ...]
    free_twists: Array = field(repr=False)
    constraints: tuple[Constraint, ...] = field(repr=False)
    constraint_wrenches: Array = field(repr=False)
    constraint_rank: int = 0
    singular_values: Array = field(default_factory=lambda: np.zeros(6), repr=False)
    tolerance: float = 0.0
    length_scale: float = 1.0
    platform: str = ""
    platform_origin: Array = field(default_factory=lambda: np.zeros(3), repr=False)
    limbs: tuple[LimbMobility, ...] = field(default=(), repr=False)
    view: str = "configuration"
    method: Method = Method.LIMB_WISE
    method_note: str = ""

    @property
    def translations(self) -> int:
        return sum(m.kind is MotionKind.TRANSLATION for m in self.motions)

    @property
    def rotations(self) -> int:
        return sum(m.kind is MotionKind.ROTATION for m in self.motions)

    @property
    def screws(self) -> int:
        return sum(m.kind is MotionKind.SCREW for m in self.motions)

    @property
    def serially_singular_limbs(self) -> tuple[str, ...]:
        return tuple(limb.name for limb in self.limbs if limb.serially_singular)

    @property
    def frame(self) -> str:
        p = ", ".join(f"{x:.6g}" for x in clean(self.platform_origin, self.length_scale))
        return (
            f"twists [v; w] and wrenches [f; tau] at the origin of frame {self.platform!r} "
            f"(world position [{p}] m), world-aligned axes (pin.LOCAL_WORLD_ALIGNED)"
        )

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON dictionary (no NaN), keys as documented in the README."""
        return {
            "mechanism": self.mechanism,
            "configuration": self.configuration,
            "view": self.view,
            "method": self.method.value,
            "method_note": self.method_note,
            "dof": self.dof,
            "motion_type": self.motion_type,
            "translations": self.translations,
            "rotations": self.rotations,
            "screws": self.screws,
            "motions": [m.to_dict() for m in self.motions],
            "free_twists": [_vec(c) for c in self.free_twists.T],
            "constraints": [c.to_dict() for c in self.constraints],
            "constraint_wrenches": [_vec(c) for c in self.constraint_wrenches.T],
            "constraint_rank": self.constraint_rank,
            "singular_values": _vec(self.singular_values),
            "tolerance": self.tolerance,
            "length_scale": self.length_scale,
            "frame": self.frame,
            "limbs": [limb.to_dict() for limb in self.limbs],
        }

    def __str__(self) -> str:
        from .report import format_mobility

        return format_mobility(self)


# --------------------------------------------------------------------------- kinematics


def limb_rates(
    mech: Mechanism, data: pin.Data, limb: Limb, rtol: float = RTOL, locked: tuple[str, ...] = ()
) -> tuple[Array, Array]:
    """Joint-rate directions behind :func:`limb_screws`: velocity indices E (e,) and rates D (e, k).

    Without internal loops, E are the limb's velocity indices minus those of
    the ``locked`` joints and D the identity. With internal closures, E are its
    joints and loop joints (:attr:`Limb.screw_v_indices`) and
    ``D = diag(col) N``, N an orthonormal basis of
    ``null([K_hat[:, E]; S_locked])`` (closure rows per L, prismatic rates
    times L, so ``col`` is L on prismatic rates and 1 elsewhere; rank decided
    with ``rtol``): the rates that keep the loops closed to first order.
    Kinematics must be computed.
    """
    model = mech.model
    held = {model.joints[model.getJointId(j)].idx_v for j in locked}
    if not limb.closures:
        idx = np.array([int(v) for v in limb.v_indices if v not in held], dtype=int)
        return idx, np.eye(idx.size)
    idx = limb.screw_v_indices
    col = np.where(linear_velocity_mask(model)[idx], mech.length_scale, 1.0)
    loops = tuple(c for c in mech.closures if c.name in limb.closures)
    _, k = stacked_error(mech, model, data, loops)
    rows = np.vstack([k[:, idx] * col, np.eye(idx.size)[[i for i, v in enumerate(idx) if v in held]]])
    return idx, col[:, None] * decide_rank(rows, rtol, n=idx.size).null_space.T


def limb_screws(mech: Mechanism, data: pin.Data, limb: Limb, rtol: float = RTOL, locked: tuple[str, ...] = ()) -> Array:
    """Twists the limb can give its tip, (6, k), at the tip origin, world axes. Kinematics must be computed.

    A limb without internal loops: the columns of
    ``getFrameJacobian(tip, LOCAL_WORLD_ALIGNED)`` for its joints (one per
    joint velocity, per unit rate), without those of the ``locked`` joints. A
    limb with internal closures (e.g. a parallelogram closed by a ``3d``
    closure): ``T = J_tip[:, E] D`` with the rates D of :func:`limb_rates`
    that keep those loops closed and the ``locked`` (one-degree) joints
    still; the columns are then per unit dimensionless rate.
    """
    idx, rates = limb_rates(mech, data, limb, rtol, locked)
    jac = pin.getFrameJacobian(mech.model, data, limb.tip_id, pin.LOCAL_WORLD_ALIGNED)
    return jac[:, idx] @ rates


def limb_twists(mech: Mechanism, data: pin.Data, rtol: float = RTOL, lock_actuated: bool = False) -> list[Array]:
    """Joint screws of each limb, (6, n_i) each, at the platform origin, world axes.

    :func:`limb_screws` of each limb (its tip Jacobian's columns for its
    joints, restricted to the rates that keep its internal loops closed; with
    ``lock_actuated``, also its actuated joints still), shifted from the tip
    origin to the platform origin (they coincide at a closed configuration up
    to the residual). Kinematics must be computed.
    """
    p = data.oMf[mech.platform_id].translation
    return [
        shift_twists(
            limb_screws(mech, data, limb, rtol, limb.actuated if lock_actuated else ()),
            p - data.oMf[limb.tip_id].translation,
        )
        for limb in mech.limbs
    ]


def _motions(system: ScrewSystem) -> tuple[Motion, ...]:
    out = []
    counters = {k: 0 for k in MotionKind}
    for s in system.all:
        kind = MotionKind(s.kind)
        counters[kind] += 1
        out.append(
            Motion(
                kind, s.direction, s.point, s.pitch, s.vector, f"{kind.value}{counters[kind]} {axis_label(s.direction)}"
            )
        )
    return tuple(out)


def _constraints(system: ScrewSystem) -> tuple[Constraint, ...]:
    return tuple(Constraint(WrenchKind(s.kind), s.direction, s.point, s.pitch, s.vector) for s in system.all)


def _assemble(
    mech: Mechanism,
    configuration: str | None,
    limb_rows: list[tuple[Array, int]],
    platform_origin: Array,
    rtol: float,
    view: str,
    *,
    method: Method = Method.LIMB_WISE,
    note: str = "",
    wrenches: Array | None = None,
) -> Mobility:
    """Stack limb wrenches (or take ``wrenches``, (6, d)), decide the constraint rank and classify both spaces."""
    length = mech.length_scale
    if wrenches is None:
        blocks = [w for w, _ in limb_rows]
        stacked = np.hstack(blocks) if blocks else np.zeros((6, 0))
    else:
        stacked = wrenches
    free, dec = reciprocal_twists(stacked, length, rtol)
    constraint_basis = dec.row_space.T / wrench_scaling(length)[:, None]
    system = classify_twists(free, length, rtol)
    motions = _motions(system)
    cons = _constraints(classify_wrenches(constraint_basis, length, rtol))
    sv = np.zeros(6)
    sv[: min(6, dec.singular_values.size)] = dec.singular_values[:6]
    limbs = tuple(
        LimbMobility(limb.name, limb.joints, rank, limb.generic_twist_rank, w, limb.closures, limb.loop_joints)
        for limb, (w, rank) in zip(mech.limbs, limb_rows)
    )
    return Mobility(
        mechanism=mech.name,
        configuration=configuration,
        dof=6 - dec.rank,
        motion_type=motion_type(system),
        motions=motions,
        free_twists=np.column_stack([m.twist for m in motions]) if motions else np.zeros((6, 0)),
        constraints=cons,
        constraint_wrenches=np.column_stack([c.wrench for c in cons]) if cons else np.zeros((6, 0)),
        constraint_rank=dec.rank,
        singular_values=sv,
        tolerance=dec.tolerance,
        length_scale=length,
        platform=mech.platform,
        platform_origin=np.array(platform_origin, float),
        limbs=limbs,
        view=view,
        method=method,
        method_note=note,
    )


def _limbwise_obstacle(mech: Mechanism) -> str:
    """Why the limb-wise method cannot be used on ``mech`` ("" when it can)."""
    if not mech.limbs:
        return f"{mech.name!r} is described by closures only (no limbs)"
    coupling = mech.coupling_closures
    if not coupling:
        return ""
    return "; ".join(f"closure {c!r} couples limbs {', '.join(limbs)}" for c, limbs in coupling.items())


def analyze(
    mech: Mechanism,
    q: Array | str,
    *,
    configuration: str | None = None,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
) -> Mobility:
    """Mobility of the platform at a closed configuration.

    The limb-wise method: each limb's wrenches are reciprocal to its
    :func:`limb_twists` (internal loops closed), stacked and ranked. When a
    closure couples two or more limbs (its loop involves the joints of
    several limbs), or the mechanism has no limbs, no limb has wrenches of
    its own: the platform's free twists are then the image of the whole
    closed chain's motions, ``J_platform null(K)``
    (:func:`pinmob.constraints.frame_mobility`), its constraint wrenches their
    reciprocal, and the result says so (``method``, ``method_note``).

    Args:
        mech: the mechanism.
        q: configuration (nq,), or the name of one of ``mech.configurations``.
        configuration: name reported with the result (set automatically when q is a name).
        rtol: relative tolerance of every rank decision (singular values below
            ``rtol * sigma_max`` count as zero).
        closure_tol: closure tolerance (position / L and rotation [rad]).

    Raises:
        ConfigurationError: q has the wrong shape or non-finite values, rtol is not
            in (0, 1), or the mechanism has no platform frame.
        ClosureError: q does not close the loops.
    """
    rtol = check_rtol(rtol)
    q, configuration = resolve(mech, q, configuration, closure_tol)
    if not mech.has_platform:
        raise ConfigurationError(
            f"{mech.name!r} has no platform frame: use pinmob.analyze_mechanism(mech, q, frames=[...]) "
            "(or pinmob analyze --frame NAME) for the motion of any frame"
        )
    data = closed_kinematics(mech, q, closure_tol)
    origin = data.oMf[mech.platform_id].translation
    obstacle = _limbwise_obstacle(mech)
    if obstacle:
        from .constraints import frame_mobility

        free = frame_mobility(mech, q, mech.platform, rtol=rtol, closure_tol=closure_tol).free_twists
        wrenches, _ = reciprocal_wrenches(free, mech.length_scale, rtol)
        note = (
            f"{obstacle}: the limb-wise method does not apply; the platform's motion is the image of the "
            "closed chain's motions (closure Jacobian of the whole mechanism)"
        )
        return _assemble(
            mech,
            configuration,
            [],
            origin,
            rtol,
            "configuration",
            method=Method.CLOSURE_JACOBIAN,
            note=note,
            wrenches=wrenches,
        )
    rows = []
    for twists in limb_twists(mech, data, rtol):
        w, dec = reciprocal_wrenches(twists, mech.length_scale, rtol)
        rows.append((w, dec.rank))
    return _assemble(mech, configuration, rows, origin, rtol, "configuration")


# --------------------------------------------------------------------------- second method


def closure_jacobian_twists(
    mech: Mechanism, q: Array | str, rtol: float = RTOL, *, closure_tol: float = CLOSURE_TOL
) -> Array:
    """Free platform twists from the global loop-closure Jacobian (an independent method).

    Closure rows ``K = [J_2 - J_1; ...; J_k - J_1]`` (tip Jacobians over all
    joints, carried to the platform origin), followed by the rows of the
    mechanism's own closures (loops inside limbs, lengths divided by L, see
    :func:`~pinmob.residual.stacked_error`); the closed chain's joint velocities
    are ``null(K)``; the platform twists are their image ``J_1 null(K)``.
    Joint columns are scaled to comparable units before the rank decision.

    Args:
        mech: the mechanism.
        q: closed configuration (nq,), or the name of one of ``mech.configurations``.
        rtol: relative tolerance of the rank decisions, in (0, 1).
        closure_tol: closure tolerance (position / L and rotation [rad]).

    Returns:
        (6, m) orthonormal (dimensionless) basis, in SI, of the platform's free twists.

    Raises:
        ConfigurationError: q has the wrong shape or non-finite values, or rtol is not in (0, 1).
        ClosureError: q does not close the loops.
    """
    rtol = check_rtol(rtol)
    q, _ = resolve(mech, q, None, closure_tol)
    model = mech.model
    data = closed_kinematics(mech, q, closure_tol)
    p = data.oMf[mech.platform_id].translation
    scale = twist_scaling(mech.length_scale)[:, None]
    full = [
        scale
        * shift_twists(
            pin.getFrameJacobian(model, data, limb.tip_id, pin.LOCAL_WORLD_ALIGNED),
            p - data.oMf[limb.tip_id].translation,
        )
        for limb in mech.limbs
    ]
    col = np.linalg.norm(np.sum(np.abs(np.stack(full)), axis=0), axis=0)
    col = np.where(col > 0, 1.0 / np.where(col > 0, col, 1.0), 1.0)
    rows = [f - full[0] for f in full[1:]]
    if mech.closures:  # loops inside limbs (e.g. parallelograms): their rows, dimensionless like the tip rows
        rows.append(stacked_error(mech, model, data, mech.closures)[1])
    if rows:
        k = np.vstack(rows) * col
        dq = decide_rank(k, rtol, n=model.nv).null_space.T * col[:, None]
    else:
        dq = np.diag(col)
    # rank of the image against the size of the platform Jacobian itself: when every closed-chain motion
    # leaves the platform still (e.g. limbs folding at a dead centre) the image is round-off only
    image = full[0] @ dq
    reference = float(np.linalg.norm(full[0] * col, 2))
    if image.size == 0 or float(np.linalg.norm(image, 2)) <= rtol * reference:
        return np.zeros((6, 0))
    _, s_img, vt = np.linalg.svd(image.T, full_matrices=True)
    return vt[: int(np.sum(s_img > rtol * reference))].T / scale


# --------------------------------------------------------------------------- paper view


def _direction(mech: Mechanism, approach: Array | Mapping[str, float]) -> Array:
    """Joint-space direction (nv,) from an array or from rates by joint name (one-dof joints)."""
    model = mech.model
    if isinstance(approach, Mapping):
        dv = np.zeros(model.nv)
        for name, value in approach.items():
            if not model.existJointName(name) or name == "universe":
                raise ConfigurationError(
                    f"approach names unknown joint {name!r}; valid: {choices(list(model.names)[1:])}"
                )
            joint = model.joints[model.getJointId(name)]
            if joint.nv != 1:
                raise ConfigurationError(
                    f"approach: joint {name!r} has {joint.nv} velocity coordinates; give the whole (nv,) direction"
                )
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
                raise ConfigurationError(f"approach: rate of joint {name!r} must be a number, got {value!r}")
            dv[joint.idx_v] = float(value)
    else:
        try:
            dv = np.array(approach, dtype=float)
        except (TypeError, ValueError):
            raise ConfigurationError(
                f"approach direction must be an array of {model.nv} numbers, got {approach!r}"
            ) from None
        if dv.shape != (model.nv,):
            raise ConfigurationError(f"approach direction must have shape ({model.nv},), got {dv.shape}")
    if not np.all(np.isfinite(dv)):
        raise ConfigurationError(
            f"approach direction must be finite, got non-finite values at {np.flatnonzero(~np.isfinite(dv)).tolist()}"
        )
    return dv


def paper_view(
    mech: Mechanism,
    q: Array | str,
    approach: Array | Mapping[str, float] | None = None,
    *,
    configuration: str | None = None,
    eps: float = 1e-3,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
) -> Mobility:
    """Mobility allowed by each limb's *generic* constraint wrenches, carried to q.

    Where no limb is serially singular at q, the generic wrenches are the
    wrenches at q and this equals :func:`analyze`. Otherwise it reproduces the
    seed paper's procedure: it derives each limb's
    reciprocal screws at a generic configuration and substitutes the special
    configuration into that formula (e.g. beta = 0 in its eq. 20). A limb at a
    serial singularity has more wrenches at q than that limit; :func:`analyze`
    counts them, this view does not.

    Each limb's wrench space is followed along ``q(s) = integrate(q, s * dv)``
    (limbs are serial chains, so q(s) need not close) and its limit for
    s -> 0+ is taken by Richardson extrapolation of the projectors:
    ``P0 = 2 P(eps/2) - P(eps)``, keeping as many wrenches as the limb has at
    ``q(eps)``.

    Args:
        mech: the mechanism.
        q: closed configuration (nq,), or the name of one of ``mech.configurations``.
        approach: joint-space direction (nv,) or joint values by name; default
            (None or an empty mapping): the named configuration's declared
            ``approach``, else the direction from q toward the mechanism's
            ``generic`` configuration (``pin.difference(model, q, q_generic)``).
        configuration: name reported with the result (set automatically when q is a name).
        eps: step along the approach direction (the direction is normalised).
        rtol: relative tolerance of every rank decision, in (0, 1).
        closure_tol: closure tolerance (position / L and rotation [rad]).

    Raises:
        ConfigurationError: q or the approach direction is invalid, rtol is not in (0, 1),
            or no approach direction is available where one is needed.
        ClosureError: q does not close the loops.
    """
    rtol = check_rtol(rtol)
    if not (np.isfinite(eps) and eps > 0):
        raise ConfigurationError(f"eps must be a positive step, got {eps!r}")
    if isinstance(approach, Mapping) and not approach:
        approach = None
    if isinstance(q, str) and approach is None:
        declared = mech.configurations[q].approach if q in mech.configurations else None
        approach = declared or None
    given = approach is not None  # by the caller or declared by the configuration
    q, configuration = resolve(mech, q, configuration, closure_tol)
    model = mech.model
    length = mech.length_scale
    data = closed_kinematics(mech, q, closure_tol)
    here = [(w, dec.rank) for w, dec in (reciprocal_wrenches(t, length, rtol) for t in limb_twists(mech, data))]
    if all(rank >= limb.generic_twist_rank for (_, rank), limb in zip(here, mech.limbs)):
        # no limb is serially singular: its generic wrenches are its wrenches here
        return _assemble(mech, configuration, here, data.oMf[mech.platform_id].translation, rtol, "paper")
    if approach is None and configuration != GENERIC and GENERIC in mech.configurations:
        approach = pin.difference(model, q, mech.configuration(GENERIC, closure_tol))  # from the generic one
    dv = np.zeros(0) if approach is None else _direction(mech, approach)
    norm = float(np.linalg.norm(dv)) if dv.size else 0.0
    if given and norm == 0.0:
        raise ConfigurationError("the approach direction is zero; give a non-zero joint-space direction")
    if norm == 0.0:
        declared_in = [name for name, c in mech.configurations.items() if c.approach]
        where = f"configuration {configuration!r}" if configuration else "this configuration"
        raise ConfigurationError(
            f"the paper's view needs an approach direction and {where} of {mech.name!r} has none (no declared "
            f"'approach' and no distinct '{GENERIC}' configuration to come from): add "
            f"'approach = {{ <joint> = <rate>, ... }}' to [configurations.<name>] in the mechanism file (in Python: "
            f"paper_view(..., approach=...)); configurations of {mech.name!r} that declare one: {choices(declared_in)}"
        )
    dv /= norm
    sw = wrench_scaling(length)[:, None]

    def limb_spaces(s: float) -> list[tuple[Array, int]]:
        compute_kinematics(model, data, pin.integrate(model, q, s * dv))
        out = []
        for twists in limb_twists(mech, data):
            w, dec = reciprocal_wrenches(twists, length, rtol)
            out.append((sw * w, dec.rank))
        return out

    at_eps, at_half = limb_spaces(eps), limb_spaces(eps / 2)
    rows = []
    for (w1, r1), (w2, _) in zip(at_eps, at_half):
        k = w1.shape[1]
        proj = 2 * w2 @ w2.T - w1 @ w1.T
        vals, vecs = np.linalg.eigh(0.5 * (proj + proj.T))
        basis = vecs[:, np.argsort(vals)[::-1][:k]]
        rows.append((basis / sw, r1))
    compute_kinematics(model, data, q)
    return _assemble(mech, configuration, rows, data.oMf[mech.platform_id].translation, rtol, "paper")
